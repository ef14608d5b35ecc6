"""Exact passages of moving forces over a modal bridge: no time stepping.

A :class:`~vtsi.modal_bridge.ModalBridge` keeps the first modes of a FE bridge (mass-normalised, Φᵀ M Φ = I) up to
a frequency, each with its own damping ratio ζ_j (true modal damping). An axle of downward load
P at x(t) = x₀ + V t loads mode j with f_j(t) = −P N(x(t)) · φ_j, N the Hermite row of the
track element under the axle: a cubic polynomial of t while the axle stays on one element. So
between the instants at which any axle enters or leaves an element (the breakpoints) each
modal load is a cubic in τ = t − t_a, and

    q̈ + 2 ζ ω q̇ + ω² q = c₀ + c₁ τ + c₂ τ² + c₃ τ³

has the exact solution q = p(τ) + e^(−ζωτ) (A cos ω_d τ + B sin ω_d τ), p the cubic particular
solution (b₃ = c₃/ω², b₂ = (c₂ − 6ζω b₃)/ω², b₁ = (c₁ − 4ζω b₂ − 6 b₃)/ω²,
b₀ = (c₀ − 2ζω b₁ − 2 b₂)/ω²), A and B from the state at the piece's start. The passage is
propagated piece by piece (O(modes × (axles × elements))) and sampled at the output times
(O(modes × samples)); no time-step error, no ringing, whatever the sampling.

Node responses are linear in the modal coordinates: displacement Φ_d q, acceleration Φ_d q̈
(in the kept modes only: the EN cut-off by construction), rotation, bending moment. Truncated
modes are left out entirely: a displacement misses their quasi-static part (for a simply
supported span the first omitted symmetric mode, the 5th, carries 1/625 of the first's static
mid-span deflection).

Peaks are taken on the samples and refined by a parabola through the largest sample and its
neighbours: a response of frequency f sampled every Δt is under-read by at most 1 − cos(π f Δt)
before the refinement (1 % at 45 Hz and Δt = 1 ms) and by O((π f Δt)⁴) after it.
"""
import math

import numpy as np
from numba import njit

from vtsi.track import hermite, host_element


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
    for c in range(n_c):
        for r in range(3):
            k = 0
            for i in range(1, n):                       # first extreme sample (as numpy's argmin/argmax)
                y, best = values[i, c], values[k, c]
                if (r == 0 and y < best) or (r == 1 and y > best) or (r == 2 and abs(y) > abs(best)):
                    k = i
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
def _in_tau(h0, h1, h2, h3, a, s):
    """h0 + h1 ξ + h2 ξ² + h3 ξ³ with ξ = a + s τ, as the coefficients of 1, τ, τ², τ³."""
    return (h0 + a * (h1 + a * (h2 + a * h3)), s * (h1 + a * (2.0 * h2 + 3.0 * a * h3)),
            s * s * (h2 + 3.0 * a * h3), h3 * s * s * s)


@njit(cache=True)
def exact_passage(x0, loads, speed, x_start, length, tdofs, modes, omega, zeta, t_end, dt, q_out, qd_out, qdd_out):
    """Fill q, q̇, q̈ (n_samples, n_modes) at t = dt, 2 dt, …; x0 decreases (the train's order)."""
    n_el = x_start.shape[0]
    n_ax = x0.shape[0]
    n_modes = omega.shape[0]
    x_begin, x_end = x_start[0], x_start[n_el - 1] + length[n_el - 1]
    wd = np.empty(n_modes)                  # per mode, once: damped frequency, one sample's step
    step = np.empty((n_modes, 3))
    for j in range(n_modes):
        wd[j] = omega[j] * math.sqrt(1.0 - zeta[j] * zeta[j])
        step[j, 0] = math.exp(-zeta[j] * omega[j] * dt)
        step[j, 1], step[j, 2] = math.cos(wd[j] * dt), math.sin(wd[j] * dt)
    breaks = np.empty(n_ax * (n_el + 1) + 2)
    breaks[0], breaks[1] = 0.0, t_end
    n_breaks = 2
    for i in range(n_ax):
        for b in range(n_el + 1):
            edge = x_start[b] if b < n_el else x_end
            t = (edge - x0[i]) / speed
            if 0.0 < t < t_end:
                breaks[n_breaks] = t
                n_breaks += 1
    breaks = np.unique(breaks[:n_breaks])
    q = np.zeros(n_modes)
    v = np.zeros(n_modes)
    c = np.zeros((n_modes, 4))
    n_samples = q_out.shape[0]
    sample = 0
    first = 0                   # the axles before `first` have left the track
    for p in range(breaks.shape[0] - 1):
        ta, tb = breaks[p], breaks[p + 1]
        if tb <= ta:
            continue
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
            sc = speed / ell
            for slot in range(4):
                d = tdofs[e, slot]
                if d < 0:
                    continue
                if slot == 0:
                    poly = _in_tau(1.0, 0.0, -3.0, 2.0, a, sc)
                elif slot == 1:
                    poly = _in_tau(0.0, ell, -2.0 * ell, ell, a, sc)
                elif slot == 2:
                    poly = _in_tau(0.0, 0.0, 3.0, -2.0, a, sc)
                else:
                    poly = _in_tau(0.0, 0.0, -ell, ell, a, sc)
                for j in range(n_modes):
                    w = -loads[i] * modes[d, j]
                    c[j, 0] += w * poly[0]
                    c[j, 1] += w * poly[1]
                    c[j, 2] += w * poly[2]
                    c[j, 3] += w * poly[3]
        last = sample
        while last < n_samples and (last + 1) * dt <= tb + 1e-12 * t_end:
            last += 1
        for j in range(n_modes):
            q[j], v[j] = _piece(q[j], v[j], c[j], omega[j], zeta[j], wd[j], step[j], (sample + 1) * dt - ta, dt,
                                last - sample, tb - ta, q_out[sample:last, j], qd_out[sample:last, j],
                                qdd_out[sample:last, j])
        sample = last


@njit(cache=True)
def _piece(q0, v0, c, w, z, wd, step, tau0, dt, count, tau_end, q_out, v_out, a_out):
    """One mode over one piece, q̈ + 2zw q̇ + w² q = c₀ + c₁τ + c₂τ² + c₃τ³ from (q0, v0) at τ = 0:
    the samples at τ = tau0 + k dt, k < count, into the outputs (the homogeneous part advanced
    by the constant rotation and decay ``step`` = (e^(−zwΔt), cos ω_dΔt, sin ω_dΔt) per sample),
    and (q, q̇) at ``tau_end`` returned. The cubic particular solution is b₃ = c₃/w²,
    b₂ = (c₂ − 6zw b₃)/w², b₁ = (c₁ − 4zw b₂ − 6 b₃)/w², b₀ = (c₀ − 2zw b₁ − 2 b₂)/w²."""
    w2 = w * w
    b3 = c[3] / w2
    b2 = (c[2] - 6.0 * z * w * b3) / w2
    b1 = (c[1] - 4.0 * z * w * b2 - 6.0 * b3) / w2
    b0 = (c[0] - 2.0 * z * w * b1 - 2.0 * b2) / w2
    A = q0 - b0
    B = (v0 - b1 + z * w * A) / wd
    dA, dB = -z * w * A + wd * B, -z * w * B - wd * A
    if count > 0:
        decay = math.exp(-z * w * tau0)
        cs, sn = math.cos(wd * tau0), math.sin(wd * tau0)
        step_decay, step_cs, step_sn = step[0], step[1], step[2]
        for k in range(count):
            tau = tau0 + k * dt
            qq = b0 + tau * (b1 + tau * (b2 + tau * b3)) + decay * (A * cs + B * sn)
            vv = b1 + tau * (2.0 * b2 + tau * 3.0 * b3) + decay * (dA * cs + dB * sn)
            q_out[k], v_out[k] = qq, vv
            a_out[k] = c[0] + tau * (c[1] + tau * (c[2] + tau * c[3])) - 2.0 * z * w * vv - w2 * qq
            decay *= step_decay
            cs, sn = cs * step_cs - sn * step_sn, sn * step_cs + cs * step_sn
    tau = tau_end
    decay = math.exp(-z * w * tau)
    cs, sn = math.cos(wd * tau), math.sin(wd * tau)
    return (b0 + tau * (b1 + tau * (b2 + tau * b3)) + decay * (A * cs + B * sn),
            b1 + tau * (2.0 * b2 + tau * 3.0 * b3) + decay * (dA * cs + dB * sn))


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
