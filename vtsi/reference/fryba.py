"""Constant force crossing a simply supported Euler-Bernoulli beam (Frýba 1972, ch. 1).

A force ``P`` (positive downward) enters the span ``L`` at ``t = 0`` and moves at constant speed
``V``; it leaves at ``T = L / V``. With the modes ``sin(jπx/L)`` of the continuous beam
(bending stiffness ``EI``, mass per length ``mu``), ``ω_j = (jπ/L)² √(EI/mu)``, each modal
coordinate obeys

    q̈_j + 2 ζ ω_j q̇_j + ω_j² q_j = (2P / (mu L)) sin(j Ω t)   for 0 <= t <= T,  Ω = πV/L,

from rest, and vibrates freely (same damping) after the force has left. The deflection
(positive downward) is ``w(x, t) = Σ_j q_j(t) sin(jπx/L)``. Undamped, while the force is on
the span, this is Frýba's series

    w = w0 Σ_j 1/(j²(j² − α²)) [sin(jΩt) − (α/j) sin(ω_j t)] sin(jπx/L),  w0 = 2PL³/(π⁴EI),

with the dimensionless speed ``α = Ω/ω_1 = V/(2 f_1 L)``. The per-mode solutions below are exact
(no time stepping); the undamped one is written in a form that stays exact at and near
resonance (``α = j``).

Glossary: P force [N], V speed [m/s], L span [m], EI bending stiffness [N·m²], mu mass per
length [kg/m], ζ modal damping ratio [-], t time [s], w deflection [m] (positive downward).

References
----------
Frýba, L. (1972/1999) Vibration of Solids and Structures under Moving Loads, ch. 1
(Noordhoff / Thomas Telford).
"""
import math

import numpy as np
from scipy.optimize import minimize_scalar

from vtsi.errors import ModelError, as_number, as_numbers, as_positive, is_count

__all__ = ["moving_force_midspan", "daf", "first_frequency", "speed_of_alpha", "static_midspan"]


def first_frequency(L, EI, mu):
    """First bending frequency ``f_1 = (π/L)² √(EI/mu) / (2π)`` [Hz] (``L``, ``EI``, ``mu`` > 0 and
    finite, else a ModelError naming the one at fault)."""
    L, EI, mu = _positive("first_frequency", L=L, EI=EI, mu=mu)
    return (math.pi / L) ** 2 * math.sqrt(EI / mu) / (2.0 * math.pi)


def speed_of_alpha(alpha, L, EI, mu):
    """Speed [m/s] of the dimensionless speed ``α = V / (2 f_1 L)`` (all > 0 and finite)."""
    (alpha,) = _positive("speed_of_alpha", alpha=alpha)
    return 2.0 * alpha * first_frequency(L, EI, mu) * L


def static_midspan(P, L, EI):
    """Static midspan deflection ``P L³ / (48 EI)`` of a force at midspan [m] (``P`` finite,
    ``L``, ``EI`` > 0 and finite)."""
    P = as_number(P, "static_midspan", "P")
    L, EI = _positive("static_midspan", L=L, EI=EI)
    if not math.isfinite(P):
        raise ModelError(f"static_midspan: P must be finite, got {P}")
    return P * L ** 3 / (48.0 * EI)


def _positive(where, **values):
    """The ``values`` (by name) as floats > 0 and finite, or a ModelError naming ``where``, the
    first at fault and its value."""
    return [as_positive(value, where, name) for name, value in values.items()]


def _forced_from_rest(F, omega, Omega, zeta, t):
    """Modal coordinate and velocity of ``q̈ + 2ζωq̇ + ω²q = F sin(Ωt)`` from rest at ``t >= 0``.

    ``F, omega, Omega`` broadcast against ``t`` (modes along one axis, times along the other).
    """
    if zeta == 0.0:
        # q = F/(ω² − Ω²) [sin Ωt − (Ω/ω) sin ωt], rewritten without the 0/0 at ω = Ω:
        # sin Ωt − sin ωt = −2 cos(½(Ω+ω)t) sin(½δt), δ = ω − Ω, and sin(½δt)/δ = ½t sinc(δt/2π).
        s = omega + Omega
        half = 0.5 * t * np.sinc((omega - Omega) * t / (2.0 * np.pi))   # sin(½δt)/δ
        q = F / s * (np.sin(omega * t) / omega - 2.0 * np.cos(0.5 * s * t) * half)
        qd = F * Omega / s * 2.0 * np.sin(0.5 * s * t) * half
        return q, qd
    d = (omega ** 2 - Omega ** 2) ** 2 + (2.0 * zeta * omega * Omega) ** 2
    a = F * (omega ** 2 - Omega ** 2) / d          # particular: a sin Ωt + b cos Ωt
    b = -F * 2.0 * zeta * omega * Omega / d
    wd = omega * math.sqrt(1.0 - zeta ** 2)
    c1 = -b                                         # q(0) = 0
    c2 = (zeta * omega * c1 - a * Omega) / wd       # q̇(0) = 0
    decay = np.exp(-zeta * omega * t)
    cos_d, sin_d = np.cos(wd * t), np.sin(wd * t)
    q = a * np.sin(Omega * t) + b * np.cos(Omega * t) + decay * (c1 * cos_d + c2 * sin_d)
    qd = (a * Omega * np.cos(Omega * t) - b * Omega * np.sin(Omega * t)
          + decay * ((c2 * wd - zeta * omega * c1) * cos_d - (c1 * wd + zeta * omega * c2) * sin_d))
    return q, qd


def _free(q0, qd0, omega, zeta, tau):
    """Free vibration from ``(q0, q̇0)`` after a time ``tau >= 0``."""
    wd = omega * math.sqrt(1.0 - zeta ** 2)
    return np.exp(-zeta * omega * tau) * (q0 * np.cos(wd * tau) + (qd0 + zeta * omega * q0) / wd * np.sin(wd * tau))


def _damping_ratio(zeta):
    """``zeta`` as a float in [0, 1), or a ModelError naming the value."""
    zeta = as_number(zeta, "moving force", "damping ratio")
    if not 0.0 <= zeta < 1.0:
        raise ModelError(f"moving force: damping ratio must be in [0, 1), got {zeta!r}")
    return zeta


def moving_force_midspan(P, V, L, EI, mu, t, n_modes=101, zeta=0.0):
    """Midspan deflection ``w(L/2, t)`` [m], positive downward, of the simply supported beam
    under the force ``P`` [N] (positive downward) entering at ``t = 0`` with speed ``V`` [m/s].

    Parameters
    ----------
    P, V, L, EI, mu : force [N], speed [m/s], span [m], bending stiffness [N·m²], mass per
        length [kg/m]; finite, all but P > 0.
    t : array of finite times [s] (any shape); ``w = 0`` for ``t <= 0``; free vibration after ``L/V``.
    n_modes : modes 1..n_modes are summed (the even ones vanish at midspan); an integer >= 1.
    zeta : modal damping ratio, the same for every mode, in [0, 1).

    A bad argument raises a ModelError naming it and its value.

    Returns
    -------
    w : array of the shape of ``t`` [m].
    """
    P = as_number(P, "moving force", "P")
    sizes = [as_number(value, "moving force", name) for name, value in (("V", V), ("L", L), ("EI", EI), ("mu", mu))]
    if not all(value > 0.0 for value in sizes):
        raise ModelError(f"moving force: V, L, EI, mu must be > 0, got {V!r}, {L!r}, {EI!r}, {mu!r}")
    if not all(math.isfinite(value) for value in [P] + sizes):
        raise ModelError(f"moving force: P, V, L, EI, mu must be finite, got {P!r}, {V!r}, {L!r}, {EI!r}, {mu!r}")
    V, L, EI, mu = sizes
    if not is_count(n_modes, 1):
        raise ModelError(f"moving force: n_modes must be an integer >= 1, got {n_modes!r}")
    zeta = _damping_ratio(zeta)
    t = as_numbers(t, "moving force", "times t [s]")
    if not np.all(np.isfinite(t)):
        raise ModelError(f"moving force: times t must be finite [s], got {t.ravel()[~np.isfinite(t.ravel())][0]}")
    shape = t.shape
    t = t.ravel()
    T = L / V
    j = np.arange(1, int(n_modes) + 1, 2, dtype=float)[:, None]   # odd modes: sin(jπ/2) = ±1
    sign = np.where(j % 4 == 1, 1.0, -1.0)
    omega = (j * np.pi / L) ** 2 * math.sqrt(EI / mu)
    Omega = j * np.pi * V / L
    F = 2.0 * P / (mu * L)
    out = np.zeros(t.size)
    for lo in range(0, t.size, 4096):            # bounded memory: (modes, 4096) blocks
        tb = t[lo: lo + 4096][None, :]
        on = np.clip(tb, 0.0, T)
        q, _ = _forced_from_rest(F, omega, Omega, zeta, on)
        if np.any(tb > T):
            qT, qdT = _forced_from_rest(F, omega, Omega, zeta, np.array([[T]]))
            q = np.where(tb > T, _free(qT, qdT, omega, zeta, np.maximum(tb - T, 0.0)), q)
        q = np.where(tb > 0.0, q, 0.0)
        out[lo: lo + 4096] = np.sum(sign * q, axis=0)
    return out.reshape(shape)


def daf(alpha, n_modes=101, zeta=0.0, free_periods=1.0):
    """Midspan dynamic amplification ``max_t w(L/2, t) / (P L³ / 48 EI)`` at the dimensionless
    speed ``α = V / (2 f_1 L)`` (> 0 and finite).

    The maximum is searched over the crossing and ``free_periods`` (>= 0) periods of the first mode
    after the force has left (the free vibration of the first mode peaks within one period),
    on a grid of 40 points per period of the first mode and per ``T/40`` (T the crossing time),
    then refined with a bounded scalar optimiser around the best grid maxima (resolved to far
    better than 1e-5 relative).
    """
    alpha = as_number(alpha, "daf", "alpha")
    if not alpha > 0.0:
        raise ModelError(f"daf: alpha must be > 0, got {alpha!r}")
    if not math.isfinite(alpha):
        raise ModelError(f"daf: alpha must be finite, got {alpha!r}")
    free_periods = as_positive(free_periods, "daf", "free_periods", allow_zero=True)
    zeta = _damping_ratio(zeta)
    # Dimensionless beam: L = EI = mu = P = 1, so ω_1 = π², V = α ω_1 L / π.
    L = EI = mu = P = 1.0
    w1 = math.pi ** 2
    V = alpha * w1 * L / math.pi
    T = L / V
    period = 2.0 * math.pi / w1
    t_end = T + free_periods * period
    h = min(period, T) / 40.0
    grid = np.linspace(0.0, t_end, int(math.ceil(t_end / h)) + 1)
    h = grid[1] - grid[0]
    w = moving_force_midspan(P, V, L, EI, mu, grid, n_modes=n_modes, zeta=zeta)
    interior = np.flatnonzero((w[1:-1] >= w[:-2]) & (w[1:-1] >= w[2:])) + 1
    candidates = np.r_[interior, len(w) - 1]
    candidates = candidates[np.argsort(w[candidates])[::-1][:6]]
    f = lambda s: -float(moving_force_midspan(P, V, L, EI, mu, np.array([s]), n_modes=n_modes, zeta=zeta)[0])
    best = w.max()
    for i in candidates:
        lo, hi = max(grid[i] - h, 0.0), min(grid[i] + h, t_end)
        res = minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12 * t_end})
        best = max(best, -res.fun)
    return best / static_midspan(P, L, EI)
