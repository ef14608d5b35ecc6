"""Exact passages of moving forces over a modal bridge: no time stepping.

A :class:`~vtsi.modal_bridge.ModalBridge` keeps the first modes of a FE bridge (mass-normalised, Φᵀ M Φ = I) up to
a frequency, each with its own damping ratio ζ_j (true modal damping). An axle of downward load
P at x(t) = x₀ + V t loads mode j with f_j(t) = −P φ_j(x(t)), φ_j the mode's Hermite
interpolation along the track element under the axle (:func:`shape_polynomials`): a cubic of t
while the axle stays on one element. So between the instants at which any axle enters or leaves
an element (the breakpoints) each modal load is a cubic in τ = t − t_a, and

    q̈ + 2 ζ ω q̇ + ω² q = c₀ + c₁ τ + c₂ τ² + c₃ τ³

has the exact solution q = b(τ) + h(t): b the cubic particular solution (b₃ = c₃/ω²,
b₂ = (c₂ − 6ζω b₃)/ω², b₁ = (c₁ − 4ζω b₂ − 6 b₃)/ω², b₀ = (c₀ − 2ζω b₁ − 2 b₂)/ω²) and h a free
damped oscillation, h = Re(Z e^(λt)) with λ = −ζω + iω_d. At a breakpoint q and q̇ are
continuous, so h jumps by the change of b there (at t = 0 the passage starts from rest: h = −b);
the jump's phasor is carried to the next output sample by e^(λs), s < Δt (the only
transcendental functions: three per mode and breakpoint). Between breakpoints the samples are
h = Re(Z ρ^i), ρ = e^(λΔt), from a table of powers: no recurrence per sample, no time-step
error, no ringing, whatever the sampling. A passage costs O(modes × breakpoints × axles on the
span + (modes + columns) × samples).

Node responses are linear in the modal coordinates and their rates: the output columns are
given as weights on q, q̇, q̈ per mode (``rows (3, n_modes, n_columns)``: displacement Φ_d q,
acceleration Φ_d q̈, rotation, bending moment; in the kept modes only, the EN cut-off by
construction), summed in the kernel. Truncated modes are left out entirely: a displacement
misses their quasi-static part (for a simply supported span the first omitted symmetric mode,
the 5th, carries 1/625 of the first's static mid-span deflection), which
:func:`add_static_correction` adds back.

Peaks are taken on the samples and refined by a parabola through the largest sample and its
neighbours: a response of frequency f sampled every Δt is under-read by at most 1 − cos(π f Δt)
before the refinement (1 % at 45 Hz and Δt = 1 ms) and by O((π f Δt)⁴) after it.
"""
import math

import numpy as np
from numba import njit

from vtsi.track import hermite, host_element

POWERS = 64     # samples per block of the free part's table of powers e^(λ i Δt)


def shape_polynomials(track_modes, dofs, length):
    """The mode shapes along the track, element by element: ``(n_el, n_modes, 4)`` coefficients
    of φ_j(ξ) = h₀ + h₁ξ + h₂ξ² + h₃ξ³ on element e (ξ = (x − x_start)/ℓ ∈ [0, 1]), the Hermite
    interpolation of the mode's values ``track_modes (n_track, n_modes)`` at the element's track
    dofs ``dofs (n_el, 4)`` (displacement, rotation at each end; -1: a fixed dof, value 0);
    ``length (n_el,)`` [m]."""
    ell = np.asarray(length, dtype=float)[:, None]
    one, zero = np.ones_like(ell), np.zeros_like(ell)
    hermite_coefficients = np.stack([np.hstack([one, zero, -3 * one, 2 * one]), np.hstack([zero, ell, -2 * ell, ell]),
                                     np.hstack([zero, zero, 3 * one, -2 * one]), np.hstack([zero, zero, -ell, ell])],
                                    axis=1)                                          # (n_el, slot, power)
    values = np.where(dofs[:, :, None] >= 0, track_modes[np.maximum(dofs, 0)], 0.0)     # (n_el, slot, mode)
    return np.ascontiguousarray(np.einsum("esk,esj->ejk", hermite_coefficients, values))


def peaks(times, values):
    """Envelope rows (6, n_columns): min, max, absmax and their times of sampled ``values``
    (n, n_columns), each refined by a parabola through the extreme sample and its neighbours
    (the absmax only where both neighbours have the extreme's sign)."""
    out = np.empty((6, values.shape[1]))
    _peaks(np.ascontiguousarray(times, dtype=np.float64), np.ascontiguousarray(values, dtype=np.float64), out)
    return out


@njit(cache=True)
def _peaks(times, values, out):
    n, n_c = values.shape
    extreme = np.empty(3, dtype=np.int64)
    if n == 0:
        out[:, :] = np.nan
        return
    for c in range(n_c):
        k_min, k_max, k_abs = 0, 0, 0               # first extreme samples (as numpy's argmin/argmax)
        low = high = values[0, c]
        large = abs(low)
        for i in range(1, n):
            y = values[i, c]
            if y < low:
                low, k_min = y, i
            if y > high:
                high, k_max = y, i
            if abs(y) > large:
                large, k_abs = abs(y), i
        extreme[0], extreme[1], extreme[2] = k_min, k_max, k_abs
        for r in range(3):
            k = extreme[r]
            y1 = values[k, c] if r < 2 else abs(values[k, c])
            value, when = y1, times[k]
            if 0 < k < n - 1 and (r < 2 or np.sign(values[k - 1, c]) == np.sign(values[k + 1, c])):
                y0 = values[k - 1, c] if r < 2 else abs(values[k - 1, c])
                y2 = values[k + 1, c] if r < 2 else abs(values[k + 1, c])
                den = y0 - 2.0 * y1 + y2
                if den != 0.0:
                    shift = 0.5 * (y0 - y2) / den
                    if abs(shift) <= 1.0:
                        value = y1 - 0.25 * (y0 - y2) * shift
                        when = times[k] + shift * (times[k + 1] - times[k])
            out[r, c], out[r + 3, c] = value, when


@njit(cache=True)
def exact_response(x0, loads, speed, x_start, length, shapes, omega, zeta, dt, rows, out):
    """Add to ``out (n_samples, n_columns)`` the columns Σ_j rows[0, j, c] q_j + rows[1, j, c] q̇_j
    + rows[2, j, c] q̈_j at t = dt, 2 dt, … of a passage from rest: axles of downward ``loads`` [N]
    at ``x0`` [m] at t = 0 (decreasing: the train's order), ``speed`` [m/s]; the track's elements
    ``x_start``, ``length`` [m] with the modes' :func:`shape_polynomials` ``shapes``; modes of
    ``omega`` [rad/s] and ``zeta`` [-] (< 1); ``dt`` [s] the sampling step."""
    n_el = x_start.shape[0]
    n_ax = x0.shape[0]
    n_modes = omega.shape[0]
    n_samples, n_cols = out.shape
    x_begin, x_end = x_start[0], x_start[n_el - 1] + length[n_el - 1]
    t_stop = (n_samples + 0.5) * dt
    breaks = np.empty(n_ax * (n_el + 1) + 2)
    breaks[0], breaks[1] = 0.0, t_stop
    n_breaks = 2
    for i in range(n_ax):
        for b in range(n_el + 1):
            edge = x_start[b] if b < n_el else x_end
            t = (edge - x0[i]) / speed
            if 0.0 < t < t_stop:
                breaks[n_breaks] = t
                n_breaks += 1
    breaks = np.unique(breaks[:n_breaks])
    # per mode: the free part Re(Z e^(λt)), λ = −ζω + iω_d; rho[j, i] = e^(λ i dt), i <= POWERS
    lam_re, lam_im = np.empty(n_modes), np.empty(n_modes)
    rho_re, rho_im = np.empty((n_modes, POWERS + 1)), np.empty((n_modes, POWERS + 1))
    for j in range(n_modes):
        lam_re[j], lam_im[j] = -zeta[j] * omega[j], omega[j] * math.sqrt(1.0 - zeta[j] * zeta[j])
        decay = math.exp(lam_re[j] * dt)
        sr, si = decay * math.cos(lam_im[j] * dt), decay * math.sin(lam_im[j] * dt)
        rho_re[j, 0], rho_im[j, 0] = 1.0, 0.0
        for i in range(1, POWERS + 1):
            rho_re[j, i] = rho_re[j, i - 1] * sr - rho_im[j, i - 1] * si
            rho_im[j, i] = rho_re[j, i - 1] * si + rho_im[j, i - 1] * sr
    G = np.empty((n_modes, n_cols, 2))  # per column, the free part's weight G₀ + G₁λ on Z (complex)
    for j in range(n_modes):
        for col in range(n_cols):
            g0 = rows[0, j, col] - omega[j] ** 2 * rows[2, j, col]
            g1 = rows[1, j, col] - 2.0 * zeta[j] * omega[j] * rows[2, j, col]
            G[j, col, 0], G[j, col, 1] = g0 + g1 * lam_re[j], g1 * lam_im[j]
    z_re, z_im = np.zeros(n_modes), np.zeros(n_modes)   # the free part's phasor at the next sample
    w_re, w_im = np.empty((n_modes, n_cols)), np.empty((n_modes, n_cols))
    c = np.zeros((n_modes, 4))      # the modal load c₀ + c₁τ + c₂τ² + c₃τ³ of the piece, τ = t − t_a
    b_prev = np.zeros((n_modes, 4))
    poly = np.zeros((n_cols, 4))      # per column: Σ_j of the rows' weights on b_j, ḃ_j, b̈_j
    first = 0                       # the axles before `first` have left the track
    sample = 1                      # the next sample to emit
    ta_prev = 0.0
    for p in range(breaks.shape[0] - 1):
        ta, tb = breaks[p], breaks[p + 1]
        mid = 0.5 * (ta + tb)
        while first < n_ax and x0[first] + speed * mid > x_end:
            first += 1
        c[:, :] = 0.0
        for i in range(first, n_ax):
            x = x0[i] + speed * mid
            if x < x_begin:
                break               # not on the track yet, nor any axle behind it
            e = host_element(x, x_start, length)
            ell = length[e]
            a = (x0[i] + speed * ta - x_start[e]) / ell
            rate = speed / ell           # dξ/dτ: φ(a + rate τ) as a cubic in τ
            force = -loads[i]
            for j in range(n_modes):
                h0, h1, h2, h3 = shapes[e, j, 0], shapes[e, j, 1], shapes[e, j, 2], shapes[e, j, 3]
                c[j, 0] += force * (h0 + a * (h1 + a * (h2 + a * h3)))
                c[j, 1] += force * rate * (h1 + a * (2.0 * h2 + 3.0 * a * h3))
                c[j, 2] += force * rate * rate * (h2 + 3.0 * a * h3)
                c[j, 3] += force * rate * rate * rate * h3
        last = sample                   # samples sample … last − 1 lie in [ta, tb)
        while last <= n_samples and last * dt < tb:
            last += 1
        poly[:, :] = 0.0
        s = sample * dt - ta                    # from ta to the next sample, in [0, dt)
        tau = ta - ta_prev
        for j in range(n_modes):
            w2, z2 = omega[j] * omega[j], 2.0 * zeta[j] * omega[j]
            b3 = c[j, 3] / w2
            b2 = (c[j, 2] - 3.0 * z2 * b3) / w2
            b1 = (c[j, 1] - 2.0 * z2 * b2 - 6.0 * b3) / w2
            b0 = (c[j, 0] - z2 * b1 - 2.0 * b2) / w2
            # the free part jumps by the change of the particular solution at ta (from rest at t = 0)
            d0 = b_prev[j, 0] + tau * (b_prev[j, 1] + tau * (b_prev[j, 2] + tau * b_prev[j, 3])) - b0
            d1 = b_prev[j, 1] + tau * (2.0 * b_prev[j, 2] + 3.0 * tau * b_prev[j, 3]) - b1
            dr, di = d0, -(d1 - lam_re[j] * d0) / lam_im[j]
            decay = math.exp(lam_re[j] * s)
            er, ei = decay * math.cos(lam_im[j] * s), decay * math.sin(lam_im[j] * s)
            z_re[j] += dr * er - di * ei
            z_im[j] += dr * ei + di * er
            b_prev[j, 0], b_prev[j, 1], b_prev[j, 2], b_prev[j, 3] = b0, b1, b2, b3
            for col in range(n_cols):
                r0, r1, r2 = rows[0, j, col], rows[1, j, col], rows[2, j, col]
                poly[col, 0] += r0 * b0 + r1 * b1 + r2 * 2.0 * b2
                poly[col, 1] += r0 * b1 + r1 * 2.0 * b2 + r2 * 6.0 * b3
                poly[col, 2] += r0 * b2 + r1 * 3.0 * b3
                poly[col, 3] += r0 * b3
        k0 = sample
        while k0 < last:
            count = min(last - k0, POWERS)
            for j in range(n_modes):
                for col in range(n_cols):
                    w_re[j, col] = z_re[j] * G[j, col, 0] - z_im[j] * G[j, col, 1]
                    w_im[j, col] = z_re[j] * G[j, col, 1] + z_im[j] * G[j, col, 0]
            for i in range(count):
                tau = (k0 + i) * dt - ta
                for col in range(n_cols):
                    value = poly[col, 0] + tau * (poly[col, 1] + tau * (poly[col, 2] + tau * poly[col, 3]))
                    for j in range(n_modes):
                        value += w_re[j, col] * rho_re[j, i] - w_im[j, col] * rho_im[j, i]
                    out[k0 + i - 1, col] += value
            for j in range(n_modes):
                zr, zi = z_re[j], z_im[j]
                z_re[j] = zr * rho_re[j, count] - zi * rho_im[j, count]
                z_im[j] = zr * rho_im[j, count] + zi * rho_re[j, count]
            k0 += count
        sample = last
        ta_prev = ta


@njit(cache=True)
def add_static_correction(x0, loads, speed, x_start, length, tdofs, G, dt, out):
    """Add the truncated modes' quasi-static response of a passage to ``out`` (n_samples,
    n_columns) at t = dt, 2 dt, …: Σ over the axles on the track of −P N(x(t)) G, with ``G``
    (n_track, n_columns) the residual flexibility (K⁻¹ − Φ Ω⁻² Φᵀ) from the track dofs to the
    output columns; x0 decreases (the train's order)."""
    n_el = x_start.shape[0]
    x_begin, x_end = x_start[0], x_start[n_el - 1] + length[n_el - 1]
    n_ax = x0.shape[0]
    first = 0
    for k in range(out.shape[0]):
        t = (k + 1) * dt
        while first < n_ax and x0[first] + speed * t > x_end:
            first += 1
        for i in range(first, n_ax):
            x = x0[i] + speed * t
            if x < x_begin:
                break
            e = host_element(x, x_start, length)
            h = hermite((x - x_start[e]) / length[e], length[e])
            for slot in range(4):
                d = tdofs[e, slot]
                if d < 0:
                    continue
                w = -loads[i] * h[slot]
                for c in range(out.shape[1]):
                    out[k, c] += w * G[d, c]
