"""Exact passages of moving forces over a modal bridge: no time stepping.

A :class:`~vtsi.modal_bridge.ModalBridge` keeps the first modes of a FE bridge (mass-normalised, Φᵀ M Φ = I) up to
a frequency, each with its own damping ratio ζ_j (true modal damping). An axle of downward load
P at x(t) = x₀ + V t loads mode j with f_j(t) = −P φ_j(x(t)), φ_j the mode's Hermite
interpolation along the track element under the axle (:func:`shape_polynomials`): a cubic of the
time τ since the axle entered the element. For such a load

    q̈ + 2 ζ ω q̇ + ω² q = c₀ + c₁ τ + c₂ τ² + c₃ τ³

has the exact solution q = b(τ) + h(t): b the cubic particular solution (b₃ = c₃/ω²,
b₂ = (c₂ − 6ζω b₃)/ω², b₁ = (c₁ − 4ζω b₂ − 6 b₃)/ω², b₀ = (c₀ − 2ζω b₁ − 2 b₂)/ω²) and h a free
damped oscillation, h = Re(Z e^(λt)) with λ = −ζω + iω_d. The response is linear in the axles,
so each axle adds P b^e(τ) while it is on element e, where b^e is the particular solution of a
unit axle on that element (the same for every axle: computed once per element and mode). When
an axle crosses an element edge (an event) q and q̇ stay continuous, so the free part jumps by
the change of P b there: a phasor per edge, the same for every axle, carried to the next output
sample by e^(λs). With the axle's entry time α_i Δt − ε_i and the edge's time β_b Δt − η_b
(ε, η in [0, Δt)), s = ε_i + η_b (− Δt), so e^(λs) = e^(λε_i) e^(λη_b) (e^(−λΔt)): the
exponentials are computed once per axle and once per edge, an event costs a complex product.
At t = 0 the passage starts from rest (h = −b). Between events the samples are h = Re(Z ρ^i),
ρ = e^(λΔt), from a table of powers, and the particular part is one cubic per output column.
No time-step error, no ringing, whatever the sampling; a passage costs O(modes × (axles +
elements) exponentials + modes × events + columns × axles on the span × sample pieces +
(modes + columns) × samples), the events being axles × (elements + 1).

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
def _particular(c0, c1, c2, c3, w2, z2):
    """The cubic particular solution of q̈ + z2 q̇ + w2 q = c₀ + c₁τ + c₂τ² + c₃τ³."""
    b3 = c3 / w2
    b2 = (c2 - 3.0 * z2 * b3) / w2
    b1 = (c1 - 2.0 * z2 * b2 - 6.0 * b3) / w2
    b0 = (c0 - z2 * b1 - 2.0 * b2) / w2
    return b0, b1, b2, b3


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
    x_begin = x_start[0]
    # per mode: λ = −ζω + iω_d and the table rho[j, i] = e^(λ i dt), i <= POWERS
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
    # per element and mode: the particular solution b^e_j(τ) for a unit downward axle that
    # entered the element at τ = 0 (its modal load −φ_j(Vτ/ℓ) is a cubic in τ)
    part = np.empty((n_el, n_modes, 4))
    duration = np.empty(n_el)
    for e in range(n_el):
        rate = speed / length[e]
        duration[e] = length[e] / speed
        for j in range(n_modes):
            w2, z2 = omega[j] * omega[j], 2.0 * zeta[j] * omega[j]
            b0, b1, b2, b3 = _particular(-shapes[e, j, 0], -shapes[e, j, 1] * rate, -shapes[e, j, 2] * rate * rate,
                                         -shapes[e, j, 3] * rate * rate * rate, w2, z2)
            part[e, j, 0], part[e, j, 1], part[e, j, 2], part[e, j, 3] = b0, b1, b2, b3
    # per element and column: the unit axle's particular part of the column, a cubic in τ
    column = np.zeros((n_el, n_cols, 4))
    for e in range(n_el):
        for j in range(n_modes):
            b0, b1, b2, b3 = part[e, j, 0], part[e, j, 1], part[e, j, 2], part[e, j, 3]
            for col in range(n_cols):
                r0, r1, r2 = rows[0, j, col], rows[1, j, col], rows[2, j, col]
                column[e, col, 0] += r0 * b0 + r1 * b1 + r2 * 2.0 * b2
                column[e, col, 1] += r0 * b1 + r1 * 2.0 * b2 + r2 * 6.0 * b3
                column[e, col, 2] += r0 * b2 + r1 * 3.0 * b3
                column[e, col, 3] += r0 * b3
    G = np.empty((n_modes, n_cols, 2))  # per column, the free part's weight G₀ + G₁λ on Z (complex)
    for j in range(n_modes):
        for col in range(n_cols):
            g0 = rows[0, j, col] - omega[j] ** 2 * rows[2, j, col]
            g1 = rows[1, j, col] - 2.0 * zeta[j] * omega[j] * rows[2, j, col]
            G[j, col, 0], G[j, col, 1] = g0 + g1 * lam_re[j], g1 * lam_im[j]
    # per edge b (0 … n_el): the unit axle's jump of the free part as it crosses it, a phasor
    # (the change of the particular solution, negated), times e^(λη_b); the edge's time from the
    # track's start is β_b dt − η_b, η_b in [0, dt)
    edge_re, edge_im = np.empty((n_el + 1, n_modes)), np.empty((n_el + 1, n_modes))
    beta = np.empty(n_el + 1, dtype=np.int64)
    edge_lag = np.empty(n_el + 1)
    for b in range(n_el + 1):
        edge = x_start[b] if b < n_el else x_start[n_el - 1] + length[n_el - 1]
        s_b = (edge - x_begin) / speed
        beta[b] = np.int64(math.ceil(s_b / dt))
        edge_lag[b] = beta[b] * dt - s_b
        for j in range(n_modes):
            d0, d1 = 0.0, 0.0
            if b > 0:                        # leaving element b − 1 at its end
                e, tau = b - 1, duration[b - 1]
                d0 += part[e, j, 0] + tau * (part[e, j, 1] + tau * (part[e, j, 2] + tau * part[e, j, 3]))
                d1 += part[e, j, 1] + tau * (2.0 * part[e, j, 2] + 3.0 * tau * part[e, j, 3])
            if b < n_el:                     # entering element b
                d0 -= part[b, j, 0]
                d1 -= part[b, j, 1]
            pr, pi = d0, -(d1 - lam_re[j] * d0) / lam_im[j]
            decay = math.exp(lam_re[j] * edge_lag[b])
            er, ei = decay * math.cos(lam_im[j] * edge_lag[b]), decay * math.sin(lam_im[j] * edge_lag[b])
            edge_re[b, j], edge_im[b, j] = pr * er - pi * ei, pr * ei + pi * er
    # per axle: its entry time α_i dt − ε_i and P e^(λε_i)
    alpha = np.empty(n_ax, dtype=np.int64)
    entry_lag = np.empty(n_ax)
    axle_re, axle_im = np.empty((n_ax, n_modes)), np.empty((n_ax, n_modes))
    for i in range(n_ax):
        entry = (x_begin - x0[i]) / speed
        alpha[i] = np.int64(math.ceil(entry / dt))
        entry_lag[i] = alpha[i] * dt - entry
        for j in range(n_modes):
            decay = loads[i] * math.exp(lam_re[j] * entry_lag[i])
            axle_re[i, j] = decay * math.cos(lam_im[j] * entry_lag[i])
            axle_im[i, j] = decay * math.sin(lam_im[j] * entry_lag[i])
    back_re, back_im = np.empty(n_modes), np.empty(n_modes)     # e^(−λ dt)
    for j in range(n_modes):
        mod2 = rho_re[j, 1] ** 2 + rho_im[j, 1] ** 2
        back_re[j], back_im[j] = rho_re[j, 1] / mod2, -rho_im[j, 1] / mod2
    # the events (axle i crosses edge b), by the sample at which they act: m = α_i + β_b − wrap
    n_ev = n_ax * (n_el + 1)
    ev_m = np.empty(n_ev, dtype=np.int64)
    count = np.zeros(n_samples + 2, dtype=np.int64)
    for i in range(n_ax):
        for b in range(n_el + 1):
            k = i * (n_el + 1) + b
            m = alpha[i] + beta[b]
            if entry_lag[i] + edge_lag[b] >= dt:
                m -= 1
            m = max(m, np.int64(0))
            ev_m[k] = m
            if m <= n_samples:
                count[m + 1] += 1
    for m in range(1, n_samples + 2):
        count[m] += count[m - 1]
    order = np.empty(count[n_samples + 1], dtype=np.int64)
    fill = count.copy()
    for k in range(n_ev):
        m = ev_m[k]
        if m <= n_samples:
            order[fill[m]] = k
            fill[m] += 1
    element = np.full(n_ax, -1, dtype=np.int64)   # the element under each axle (-1 before, n_el after)
    entered, left = 0, 0                          # axles left … entered − 1 are on the track
    z_re, z_im = np.zeros(n_modes), np.zeros(n_modes)   # the free part's phasor at the next sample
    w_re, w_im = np.empty((n_modes, n_cols)), np.empty((n_modes, n_cols))
    poly = np.zeros((n_cols, 4))
    # events up to t = 0 only place the axles; the passage starts from rest: the free part
    # starts as −(the particular solution at t = 0), carried to the first sample
    for r in range(count[0], count[1]):
        k = order[r]
        i, b = k // (n_el + 1), k % (n_el + 1)
        element[i] = b
        if b == 0:
            entered = max(entered, i + 1)
        if b == n_el:
            left = max(left, i + 1)
    for i in range(left, entered):
        e = element[i]
        tau = -((x_start[e] - x0[i]) / speed)         # time since the axle entered its element
        for j in range(n_modes):
            b0 = part[e, j, 0] + tau * (part[e, j, 1] + tau * (part[e, j, 2] + tau * part[e, j, 3]))
            b1 = part[e, j, 1] + tau * (2.0 * part[e, j, 2] + 3.0 * tau * part[e, j, 3])
            pr, pi = -loads[i] * b0, loads[i] * (b1 - lam_re[j] * b0) / lam_im[j]
            z_re[j] += pr * rho_re[j, 1] - pi * rho_im[j, 1]
            z_im[j] += pr * rho_im[j, 1] + pi * rho_re[j, 1]
    sample = 1
    while sample <= n_samples:
        for r in range(count[sample], count[sample + 1]):    # the events acting from this sample on
            k = order[r]
            i, b = k // (n_el + 1), k % (n_el + 1)
            element[i] = b
            if b == 0:
                entered = max(entered, i + 1)
            if b == n_el:
                left = max(left, i + 1)
            wrap = entry_lag[i] + edge_lag[b] >= dt      # the same test that placed the event
            for j in range(n_modes):
                kr = axle_re[i, j] * edge_re[b, j] - axle_im[i, j] * edge_im[b, j]
                ki = axle_re[i, j] * edge_im[b, j] + axle_im[i, j] * edge_re[b, j]
                if wrap:
                    kr, ki = kr * back_re[j] - ki * back_im[j], kr * back_im[j] + ki * back_re[j]
                z_re[j] += kr
                z_im[j] += ki
        last = sample + 1                     # the piece: samples sample … last − 1
        while last <= n_samples and count[last + 1] == count[last]:
            last += 1
        ta = sample * dt
        poly[:, :] = 0.0
        for i in range(left, entered):
            e = element[i]
            if e < 0 or e >= n_el:
                continue
            off = ta - (x_start[e] - x0[i]) / speed     # the axle's time in its element at ta
            for col in range(n_cols):
                c0, c1, c2, c3 = column[e, col, 0], column[e, col, 1], column[e, col, 2], column[e, col, 3]
                poly[col, 0] += loads[i] * (c0 + off * (c1 + off * (c2 + off * c3)))
                poly[col, 1] += loads[i] * (c1 + off * (2.0 * c2 + 3.0 * off * c3))
                poly[col, 2] += loads[i] * (c2 + 3.0 * off * c3)
                poly[col, 3] += loads[i] * c3
        k0 = sample
        while k0 < last:
            n_block = min(last - k0, POWERS)
            for j in range(n_modes):
                for col in range(n_cols):
                    w_re[j, col] = z_re[j] * G[j, col, 0] - z_im[j] * G[j, col, 1]
                    w_im[j, col] = z_re[j] * G[j, col, 1] + z_im[j] * G[j, col, 0]
            for i in range(n_block):
                tau = (k0 + i) * dt - ta
                for col in range(n_cols):
                    value = poly[col, 0] + tau * (poly[col, 1] + tau * (poly[col, 2] + tau * poly[col, 3]))
                    for j in range(n_modes):
                        value += w_re[j, col] * rho_re[j, i] - w_im[j, col] * rho_im[j, i]
                    out[k0 + i - 1, col] += value
            for j in range(n_modes):
                zr, zi = z_re[j], z_im[j]
                z_re[j] = zr * rho_re[j, n_block] - zi * rho_im[j, n_block]
                z_im[j] = zr * rho_im[j, n_block] + zi * rho_re[j, n_block]
            k0 += n_block
        sample = last


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
