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
:func:`add_static_correction` adds back. A bending moment's columns are its elements' end
moments K_e u_e (:func:`vtsi.recorders.moment.moment_rows`); the fixed-end share of the axles
standing inside the elements next to its node is no function of the modes
(:class:`vtsi.recorders.moment.FixedEndMoments`). Both are quasi-static: Σ over the axles on
the track of P times a cubic of ξ on the axle's element, piecewise cubic in t between the same
events, which :func:`add_quasi_static` accumulates per piece as the particular part is (no
search for the element under each axle at each sample; :meth:`vtsi.passage.PassageRunner.run`
adds both to every output's columns in one pass).

Peaks are taken on the samples and refined by a parabola through the largest sample and its
neighbours, where the two samples beyond them bend the same way (not across a jump between
samples, :func:`_smooth_around`): a response of frequency f sampled every Δt is under-read by
at most 1 − cos(π f Δt) (1 % at 45 Hz and Δt = 1 ms), and by O((π f Δt)⁴) once refined, which
it is from about 8 samples a period (a passage's default Δt takes 20 of the EN cut-off's; at 5–6
samples a period the guard leaves a peak unrefined).
"""
import math

import numpy as np
from numba import njit

from vtsi.errors import ModelError

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


def peaks(values, dt):
    """Envelope rows (6, n_columns): min, max, absmax and their times [s] of ``values``
    (n, n_columns) sampled at t = dt, 2 dt, …, each refined by a parabola through the extreme
    sample and its neighbours (the absmax only where both neighbours have the extreme's sign;
    none across a jump, :func:`_smooth_around`)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ModelError(f"peaks: values must be (n_samples, n_columns), got shape {values.shape}")
    if not (math.isfinite(dt) and dt > 0):
        raise ModelError(f"peaks: the sampling step dt must be > 0 and finite [s], got {dt!r}")
    out = np.empty((6, values.shape[1]))
    _peaks(values, float(dt), out)
    return out


@njit(cache=True)
def first_bad_axle(offsets, loads):
    """The first axle whose offset behind the head [m] or load [N] is not finite, or whose
    offset is smaller than the previous axle's (the train's order); -1 if none."""
    for i in range(offsets.shape[0]):
        if not (math.isfinite(offsets[i]) and math.isfinite(loads[i])):
            return i
        if i > 0 and offsets[i] < offsets[i - 1]:
            return i
    return -1


@njit(cache=True)
def _smooth_around(column, k, r, den):
    """Whether the samples k − 2 … k + 2 of ``column`` (those there are) bend as a smooth peak
    of kind ``r`` (0 min, 1 max, 2 absmax) at sample k, whose second difference is ``den``: the
    second differences at k − 1 and k + 1 of the sign of ``den``. A jump between two samples (an
    axle stepping on or off a track end on bearings jumps the deck's acceleration) bends the
    other way on one side: a parabola through it read an HSLM-A1's peak 6 % high."""
    n = column.shape[0]
    for j in (k - 1, k + 1):
        if 0 < j < n - 1:
            a, b, d = column[j - 1], column[j], column[j + 1]
            if r == 2:
                a, b, d = abs(a), abs(b), abs(d)
            if (a - 2.0 * b + d) * den <= 0.0:
                return False
    return True


@njit(cache=True)
def _peaks(values, dt, out):
    n, n_c = values.shape
    if n == 0:
        out[:, :] = np.nan
        return
    extreme = np.zeros((n_c, 3), dtype=np.int64)    # first extreme samples (as numpy's argmin/argmax)
    low, high, large = values[0].copy(), values[0].copy(), np.abs(values[0])
    for i in range(1, n):                           # row by row: the samples in memory order
        for c in range(n_c):
            y = values[i, c]
            if y < low[c]:
                low[c], extreme[c, 0] = y, i
            if y > high[c]:
                high[c], extreme[c, 1] = y, i
            if abs(y) > large[c]:
                large[c], extreme[c, 2] = abs(y), i
    for c in range(n_c):
        for r in range(3):
            k = extreme[c, r]
            y1 = values[k, c] if r < 2 else abs(values[k, c])
            value, shift = y1, 0.0
            if 0 < k < n - 1 and (r < 2 or np.sign(values[k - 1, c]) == np.sign(values[k + 1, c])):
                y0 = values[k - 1, c] if r < 2 else abs(values[k - 1, c])
                y2 = values[k + 1, c] if r < 2 else abs(values[k + 1, c])
                den = y0 - 2.0 * y1 + y2
                vertex = 0.5 * (y0 - y2) / den if den != 0.0 else 2.0
                if abs(vertex) <= 1.0 and _smooth_around(values[:, c], k, r, den):
                    shift = vertex
                    value = y1 - 0.25 * (y0 - y2) * shift
            out[r, c], out[r + 3, c] = value, (k + 1 + shift) * dt


@njit(cache=True)
def _particular(c0, c1, c2, c3, w2, z2):
    """The cubic particular solution of q̈ + z2 q̇ + w2 q = c₀ + c₁τ + c₂τ² + c₃τ³."""
    b3 = c3 / w2
    b2 = (c2 - 3.0 * z2 * b3) / w2
    b1 = (c1 - 2.0 * z2 * b2 - 6.0 * b3) / w2
    b0 = (c0 - z2 * b1 - 2.0 * b2) / w2
    return b0, b1, b2, b3


@njit(cache=True)
def _cubic(p, tau):
    """Value and rate at τ of the cubic p[0] + p[1]τ + p[2]τ² + p[3]τ³."""
    return p[0] + tau * (p[1] + tau * (p[2] + tau * p[3])), p[1] + tau * (2.0 * p[2] + 3.0 * tau * p[3])


@njit(cache=True)
def _rotate(re, im, lam_re, lam_im, s):
    """(re + i im) e^(λ s), λ = lam_re + i lam_im."""
    decay = math.exp(lam_re * s)
    er, ei = decay * math.cos(lam_im * s), decay * math.sin(lam_im * s)
    return re * er - im * ei, re * ei + im * er


@njit(cache=True)
def _modes(omega, zeta, dt):
    """Per mode λ = −ζω + iω_d and the table of its powers ρ^i = e^(λ i dt), i = 0 … POWERS."""
    n_modes = omega.shape[0]
    lam_re, lam_im = -zeta * omega, omega * np.sqrt(1.0 - zeta * zeta)
    power_re, power_im = np.empty((n_modes, POWERS + 1)), np.empty((n_modes, POWERS + 1))
    for j in range(n_modes):
        sr, si = _rotate(1.0, 0.0, lam_re[j], lam_im[j], dt)
        power_re[j, 0], power_im[j, 0] = 1.0, 0.0
        for i in range(1, POWERS + 1):
            power_re[j, i] = power_re[j, i - 1] * sr - power_im[j, i - 1] * si
            power_im[j, i] = power_re[j, i - 1] * si + power_im[j, i - 1] * sr
    return lam_re, lam_im, power_re, power_im


@njit(cache=True)
def _tau_cubics(speed, length, shapes):
    """``shapes (n_el, n, 4)``, cubics of ξ on each element, as cubics of the time τ = ξ ℓ / V
    since an axle of ``speed`` [m/s] entered the element: ``(n_el, n, 4)``."""
    out = np.empty(shapes.shape)
    for e in range(shapes.shape[0]):
        rate = speed / length[e]
        for j in range(shapes.shape[1]):
            out[e, j, 0] = shapes[e, j, 0]
            out[e, j, 1] = shapes[e, j, 1] * rate
            out[e, j, 2] = shapes[e, j, 2] * rate * rate
            out[e, j, 3] = shapes[e, j, 3] * rate * rate * rate
    return out


@njit(cache=True)
def _unit_axle(speed, length, shapes, omega, zeta, rows):
    """A unit downward axle on each element e (entered at τ = 0): the particular solutions
    ``part (n_el, n_modes, 4)`` of its modal loads −φ_j(Vτ/ℓ) (cubics in τ), and the output
    columns' particular parts ``column (n_el, n_columns, 4)`` (cubics in τ)."""
    n_el, n_modes, n_cols = length.shape[0], omega.shape[0], rows.shape[2]
    load = _tau_cubics(speed, length, shapes)           # φ_j under the axle, cubics of τ
    part = np.empty((n_el, n_modes, 4))
    column = np.zeros((n_el, n_cols, 4))
    for e in range(n_el):
        for j in range(n_modes):
            b0, b1, b2, b3 = _particular(-load[e, j, 0], -load[e, j, 1], -load[e, j, 2], -load[e, j, 3],
                                         omega[j] * omega[j], 2.0 * zeta[j] * omega[j])
            part[e, j, 0], part[e, j, 1], part[e, j, 2], part[e, j, 3] = b0, b1, b2, b3
            for col in range(n_cols):
                r0, r1, r2 = rows[0, j, col], rows[1, j, col], rows[2, j, col]
                column[e, col, 0] += r0 * b0 + r1 * b1 + r2 * 2.0 * b2
                column[e, col, 1] += r0 * b1 + r1 * 2.0 * b2 + r2 * 6.0 * b3
                column[e, col, 2] += r0 * b2 + r1 * 3.0 * b3
                column[e, col, 3] += r0 * b3
    return part, column


@njit(cache=True)
def _edge_times(speed, x_start, length, dt):
    """Per edge b = 0 … n_el (the start of element b; n_el: the track's end) its time from the
    track's start as β_b dt − η_b (η_b in [0, dt)): ``(beta, edge_lag)``."""
    n_el = length.shape[0]
    beta = np.empty(n_el + 1, dtype=np.int64)
    edge_lag = np.empty(n_el + 1)
    for b in range(n_el + 1):
        edge = x_start[b] if b < n_el else x_start[n_el - 1] + length[n_el - 1]
        since_start = (edge - x_start[0]) / speed
        beta[b] = np.int64(math.ceil(since_start / dt))
        edge_lag[b] = beta[b] * dt - since_start
    return beta, edge_lag


@njit(cache=True)
def _edges(speed, length, part, lam_re, lam_im, edge_lag):
    """Per edge b (:func:`_edge_times`) the unit axle's jump of the free part as it crosses the
    edge (minus the change of the particular solution), as a phasor times e^(λη_b):
    ``(edge_re, edge_im)`` (n_el + 1, n_modes)."""
    n_el, n_modes = length.shape[0], lam_re.shape[0]
    edge_re, edge_im = np.empty((n_el + 1, n_modes)), np.empty((n_el + 1, n_modes))
    for b in range(n_el + 1):
        for j in range(n_modes):
            d0, d1 = 0.0, 0.0
            if b > 0:                                   # leaving element b − 1 at its end
                d0, d1 = _cubic(part[b - 1, j], length[b - 1] / speed)
            if b < n_el:                                # entering element b
                d0 -= part[b, j, 0]
                d1 -= part[b, j, 1]
            edge_re[b, j], edge_im[b, j] = _rotate(d0, -(d1 - lam_re[j] * d0) / lam_im[j], lam_re[j], lam_im[j],
                                                   edge_lag[b])
    return edge_re, edge_im


@njit(cache=True)
def _entry_times(x0, speed, x_begin, dt):
    """Per axle at ``x0`` [m] at t = 0 its entry time on the track (at ``x_begin``) as
    α_i dt − ε_i (ε_i in [0, dt)): ``(alpha, entry_lag)``."""
    alpha = np.empty(x0.shape[0], dtype=np.int64)
    entry_lag = np.empty(x0.shape[0])
    for i in range(x0.shape[0]):
        entry = (x_begin - x0[i]) / speed
        alpha[i] = np.int64(math.ceil(entry / dt))
        entry_lag[i] = alpha[i] * dt - entry
    return alpha, entry_lag


@njit(cache=True)
def _axles(loads, entry_lag, lam_re, lam_im):
    """Per axle P_i e^(λε_i) (:func:`_entry_times`): ``(axle_re, axle_im)`` (n_axles, n_modes)."""
    n_ax, n_modes = loads.shape[0], lam_re.shape[0]
    axle_re, axle_im = np.empty((n_ax, n_modes)), np.empty((n_ax, n_modes))
    for i in range(n_ax):
        for j in range(n_modes):
            axle_re[i, j], axle_im[i, j] = _rotate(loads[i], 0.0, lam_re[j], lam_im[j], entry_lag[i])
    return axle_re, axle_im


@njit(cache=True)
def _events_by_sample(alpha, entry_lag, beta, edge_lag, dt, n_samples):
    """The events k = i (n_el + 1) + b (axle i crosses edge b) by the first sample at or after
    them, m = α_i + β_b (− 1 when ε_i + η_b >= dt; 0 for the events up to t = 0): those of
    sample m are ``order[start[m]:start[m + 1]]``, in k order (an axle's edges in order)."""
    n_edges = beta.shape[0]
    start = np.zeros(n_samples + 2, dtype=np.int64)
    sample = np.empty(alpha.shape[0] * n_edges, dtype=np.int64)
    for i in range(alpha.shape[0]):
        for b in range(n_edges):
            m = alpha[i] + beta[b] - (1 if entry_lag[i] + edge_lag[b] >= dt else 0)
            m = max(m, np.int64(0))
            sample[i * n_edges + b] = m
            if m <= n_samples:
                start[m + 1] += 1
    for m in range(1, n_samples + 2):
        start[m] += start[m - 1]
    order = np.empty(start[n_samples + 1], dtype=np.int64)
    fill = start.copy()
    for k in range(sample.shape[0]):
        m = sample[k]
        if m <= n_samples:
            order[fill[m]] = k
            fill[m] += 1
    return start, order


@njit(cache=True)
def _cross(k, n_el, element, entered, left):
    """Event k of :func:`_events_by_sample`: axle i = k // (n_el + 1) crosses edge
    b = k % (n_el + 1) onto element b (n_el: off the track's end). Sets ``element[i] = b`` and
    returns ``(i, b, entered, left)``, axles left … entered − 1 being those on the track."""
    i, b = k // (n_el + 1), k % (n_el + 1)
    element[i] = b
    entered = max(entered, i + 1) if b == 0 else entered
    left = max(left, i + 1) if b == n_el else left
    return i, b, entered, left


@njit(cache=True)
def _piece(ta, x0, loads, speed, x_start, element, left, entered, column, poly):
    """Set ``poly (n_columns, 4)`` to the share of the axles left … entered − 1 (on ``element``)
    in the columns from ``ta`` [s] on, cubics of τ = t − ta: Σ_i P_i column[e_i](τ + ta − t_i),
    ``column (n_el, n_columns, 4)`` a unit axle's cubics of the time since it entered element e,
    t_i the time axle i entered e_i. Exact until the next event."""
    poly[:, :] = 0.0
    for i in range(left, entered):
        e = element[i]
        offset = ta - (x_start[e] - x0[i]) / speed    # the axle's time in its element at ta
        for col in range(poly.shape[0]):
            c0, c1, c2, c3 = column[e, col, 0], column[e, col, 1], column[e, col, 2], column[e, col, 3]
            poly[col, 0] += loads[i] * (c0 + offset * (c1 + offset * (c2 + offset * c3)))
            poly[col, 1] += loads[i] * (c1 + offset * (2.0 * c2 + 3.0 * offset * c3))
            poly[col, 2] += loads[i] * (c2 + 3.0 * offset * c3)
            poly[col, 3] += loads[i] * c3


@njit(cache=True)
def exact_response(x0, loads, speed, x_start, length, shapes, omega, zeta, dt, rows, out):
    """Add to ``out (n_samples, n_columns)`` the columns Σ_j rows[0, j, c] q_j + rows[1, j, c] q̇_j
    + rows[2, j, c] q̈_j at t = dt, 2 dt, … of a passage from rest: axles of downward ``loads`` [N]
    at ``x0`` [m] at t = 0 (decreasing: the train's order), ``speed`` [m/s]; the track's elements
    ``x_start``, ``length`` [m] with the modes' :func:`shape_polynomials` ``shapes``; modes of
    ``omega`` [rad/s] and ``zeta`` [-] (< 1); ``dt`` [s] the sampling step."""
    n_el, n_modes = x_start.shape[0], omega.shape[0]
    n_samples, n_cols = out.shape
    lam_re, lam_im, power_re, power_im = _modes(omega, zeta, dt)
    part, column = _unit_axle(speed, length, shapes, omega, zeta, rows)
    beta, edge_lag = _edge_times(speed, x_start, length, dt)
    edge_re, edge_im = _edges(speed, length, part, lam_re, lam_im, edge_lag)
    alpha, entry_lag = _entry_times(x0, speed, x_start[0], dt)
    axle_re, axle_im = _axles(loads, entry_lag, lam_re, lam_im)
    start, order = _events_by_sample(alpha, entry_lag, beta, edge_lag, dt, n_samples)
    back_re = power_re[:, 1] / (power_re[:, 1] ** 2 + power_im[:, 1] ** 2)      # e^(−λ dt)
    back_im = -power_im[:, 1] / (power_re[:, 1] ** 2 + power_im[:, 1] ** 2)
    weight = np.empty((n_modes, n_cols, 2))     # per column, the free part's weight G₀ + G₁λ on Z
    for j in range(n_modes):
        for col in range(n_cols):
            g0 = rows[0, j, col] - omega[j] ** 2 * rows[2, j, col]
            g1 = rows[1, j, col] - 2.0 * zeta[j] * omega[j] * rows[2, j, col]
            weight[j, col, 0], weight[j, col, 1] = g0 + g1 * lam_re[j], g1 * lam_im[j]
    element = np.full(x0.shape[0], -1, dtype=np.int64)   # the element under each axle (n_el: left)
    entered, left = 0, 0                                  # axles left … entered − 1 are on the track
    z_re, z_im = np.zeros(n_modes), np.zeros(n_modes)     # the free part's phasor at the next sample
    w_re, w_im = np.empty((n_modes, n_cols)), np.empty((n_modes, n_cols))
    poly = np.empty((n_cols, 4))                          # the columns' particular part, τ from ta
    block = np.empty(POWERS)                              # a column's samples of a block
    m = 0
    while m <= n_samples:                                 # m: sample 0, 1, then each with events
        for r in range(start[m], start[m + 1]):           # the events acting from sample m on
            i, b, entered, left = _cross(order[r], n_el, element, entered, left)
            if m == 0:
                continue                                  # up to t = 0: the axles are only placed
            wrap = entry_lag[i] + edge_lag[b] >= dt        # the test that placed the event
            for j in range(n_modes):
                kr = axle_re[i, j] * edge_re[b, j] - axle_im[i, j] * edge_im[b, j]
                ki = axle_re[i, j] * edge_im[b, j] + axle_im[i, j] * edge_re[b, j]
                if wrap:
                    kr, ki = kr * back_re[j] - ki * back_im[j], kr * back_im[j] + ki * back_re[j]
                z_re[j] += kr
                z_im[j] += ki
        if m == 0:          # from rest at t = 0: the free part starts as −(the particular solution)
            for i in range(left, entered):
                e = element[i]
                tau = (x0[i] - x_start[e]) / speed           # time since the axle entered its element
                for j in range(n_modes):
                    b0, b1 = _cubic(part[e, j], tau)
                    kr, ki = _rotate(-loads[i] * b0, loads[i] * (b1 - lam_re[j] * b0) / lam_im[j], lam_re[j],
                                     lam_im[j], dt)
                    z_re[j] += kr
                    z_im[j] += ki
            m = 1
            continue
        last = m + 1                                      # the piece: samples m … last − 1
        while last <= n_samples and start[last + 1] == start[last]:
            last += 1
        ta = m * dt
        _piece(ta, x0, loads, speed, x_start, element, left, entered, column, poly)
        k0 = m
        while k0 < last:                                  # blocks of at most POWERS samples
            n_block = min(last - k0, POWERS)
            for j in range(n_modes):
                for col in range(n_cols):
                    w_re[j, col] = z_re[j] * weight[j, col, 0] - z_im[j] * weight[j, col, 1]
                    w_im[j, col] = z_re[j] * weight[j, col, 1] + z_im[j] * weight[j, col, 0]
            for col in range(n_cols):                     # a column's block, sample by sample in
                p0, p1, p2, p3 = poly[col, 0], poly[col, 1], poly[col, 2], poly[col, 3]   # contiguous passes
                for i in range(n_block):
                    tau = (k0 + i) * dt - ta
                    block[i] = p0 + tau * (p1 + tau * (p2 + tau * p3))
                for j in range(n_modes):
                    wr, wi = w_re[j, col], w_im[j, col]
                    row_re, row_im = power_re[j], power_im[j]
                    for i in range(n_block):
                        block[i] += wr * row_re[i] - wi * row_im[i]
                for i in range(n_block):
                    out[k0 + i - 1, col] += block[i]
            for j in range(n_modes):
                zr, zi = z_re[j], z_im[j]
                z_re[j] = zr * power_re[j, n_block] - zi * power_im[j, n_block]
                z_im[j] = zr * power_im[j, n_block] + zi * power_re[j, n_block]
            k0 += n_block
        m = last


@njit(cache=True)
def add_quasi_static(x0, loads, speed, x_start, length, shapes, dt, out):
    """Add to ``out (n_samples, n_columns)`` at t = dt, 2 dt, … the columns' quasi-static share
    of a passage, Σ over the axles on the track of P_i s_e(ξ_i(t)): axles of downward ``loads``
    [N] at ``x0`` [m] at t = 0 (decreasing: the train's order), ``speed`` [m/s]; the track's
    elements ``x_start``, ``length`` [m]; ``shapes (n_el, n_columns, 4)`` the share of a unit
    axle at ξ on element e, a cubic of ξ per column (:func:`shape_polynomials`). Piecewise cubic
    in t between the axles' crossings of the element edges (:func:`exact_response`'s events:
    an axle on an edge at a sample is on the element after it): one cubic per column and piece,
    O(pieces × axles on the track × columns + samples × columns)."""
    n_el = x_start.shape[0]
    n_samples = out.shape[0]
    column = _tau_cubics(speed, length, shapes)
    beta, edge_lag = _edge_times(speed, x_start, length, dt)
    alpha, entry_lag = _entry_times(x0, speed, x_start[0], dt)
    start, order = _events_by_sample(alpha, entry_lag, beta, edge_lag, dt, n_samples)
    element = np.full(x0.shape[0], -1, dtype=np.int64)   # the element under each axle (n_el: left)
    entered, left = 0, 0                                  # axles left … entered − 1 are on the track
    poly = np.empty((out.shape[1], 4))
    m = 0
    while m <= n_samples:                                 # m: sample 0, 1, then each with events
        for r in range(start[m], start[m + 1]):           # the events acting from sample m on
            _, _, entered, left = _cross(order[r], n_el, element, entered, left)
        if m == 0:                                        # up to t = 0: the axles are only placed
            m = 1
            continue
        last = m + 1                                      # the piece: samples m … last − 1
        while last <= n_samples and start[last + 1] == start[last]:
            last += 1
        if left < entered:
            ta = m * dt
            _piece(ta, x0, loads, speed, x_start, element, left, entered, column, poly)
            for k in range(m, last):
                tau = k * dt - ta
                for col in range(out.shape[1]):
                    out[k - 1, col] += poly[col, 0] + tau * (poly[col, 1] + tau * (poly[col, 2] + tau * poly[col, 3]))
        m = last


def add_static_correction(x0, loads, speed, x_start, length, tdofs, G, dt, out):
    """Add the truncated modes' quasi-static response of a passage to ``out`` (n_samples,
    n_columns) at t = dt, 2 dt, …: Σ over the axles on the track of −P N(x(t)) G, with ``G``
    (n_track, n_columns) the residual flexibility (K⁻¹ − Φ Ω⁻² Φᵀ) from the track dofs to the
    output columns, ``tdofs (n_el, 4)`` each element's track dofs (-1 fixed); x0 decreases (the
    train's order); :func:`add_quasi_static`."""
    add_quasi_static(x0, loads, speed, x_start, length, -shape_polynomials(G, tdofs, length), dt, out)
