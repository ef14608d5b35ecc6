"""MovingLoadConstraint: the wheels of a TrainSubdomain follow the rail of a Track.

For contact wheel i at x_i(t) = x_i0 + V t the constraint is

    S u_t - N(t) u_b - r(t) = 0      (gap g = S u_t - N u_b - r; bilateral: g = 0),

with N's row the Hermite row of the track element under the wheel (zero off the track:
rigid ground) and r the rail irregularity. ``interpolation='bspline'`` (remedy (a)) replaces
the constraint data by their cubic B-spline smoothing in time with knot spacing h = 2Δt
(docs/theory/constraints.md):

    Ñ(t) = ∫ N(x(t - s)) B₃(s/h)/h ds,    r̃(t) = ∫ r(x(t - s)) B₃(s/h)/h ds,

so that the constraint is C⁴ in time (the Hermite rows are only C¹: N'' jumps when a wheel
crosses a node, and so do the wheel's acceleration and λ). The kernel's Fourier transform,
sinc⁴(f h), has fourth-order zeros at the Nyquist frequency 1/(2Δt) and at all its odd
multiples, so the constraint sampled at the steps carries no period-2Δt content: the mode the
trapezoidal rule leaves undamped is not excited. The smoothing is second-order accurate:
Ñ - N = (2Δt²/3) N̈ + O(Δt⁴) where N is smooth (the kernel's variance is h²/3). The
smoothed profile r̃ is tabulated at the nodes x_j = x_begin + j V h / 8 of a grid anchored at the
track's start and interpolated by a cubic B-spline whose coefficients are local
(:class:`SmoothedProfile`; its derivative gives dr̃/dt): its value at a position does not depend
on the range tabulated, so the rows of a run split anywhere are one run's. Even a C² sampled
profile benefits, since its third derivative jumps at every sample.
"""
import math

import numpy as np
from numba import njit

from vtsi.errors import ModelError
from vtsi.track import GAUSS_POINTS, GAUSS_WEIGHTS, Track, bspline_kernel, row_width
from vtsi.train import TrainSubdomain

INTERPOLATIONS = ("hermite", "bspline")
NODES_PER_KNOT = 8       # nodes of the smoothed profile's table per knot spacing
TABLE_MARGIN = 50        # [knot spacings] the table's reach beyond the positions asked


class MovingLoadConstraint:
    """Ties ``train`` (a TrainSubdomain) to ``track`` (a Track).

    Parameters
    ----------
    track : Track
    train : TrainSubdomain
    irregularity : callable r(x) [m], vectorised, positive up (e.g. vtsi.models.Irregularity);
        None for a smooth rail.
    interpolation : 'hermite' (the exact rows) or 'bspline' (remedy (a), see module docstring).
    """

    def __init__(self, track, train, irregularity=None, interpolation="hermite"):
        if not isinstance(track, Track):
            raise ModelError(f"MovingLoadConstraint: track must be a Track, got {type(track).__name__}")
        if not isinstance(train, TrainSubdomain):
            raise ModelError(f"MovingLoadConstraint: train must be a TrainSubdomain, got {type(train).__name__}")
        if interpolation not in INTERPOLATIONS:
            raise ModelError(f"MovingLoadConstraint: unknown interpolation {interpolation!r}; "
                             f"valid: {', '.join(INTERPOLATIONS)}")
        if irregularity is not None and not callable(irregularity):
            raise ModelError(f"MovingLoadConstraint: irregularity must be callable r(x), got {type(irregularity).__name__}")
        self.track, self.train, self.irregularity, self.interpolation = track, train, irregularity, interpolation
        self.x0 = train.wheel_x0(train.contact_wheels)
        self.x0_force = train.wheel_x0(train.force_wheels)

    def __repr__(self):
        function = getattr(self.irregularity, "__qualname__", None)     # a plain function's name
        rail = ("smooth rail" if self.irregularity is None else
                f"rail r(x) = {function}" if function else f"rail {self.irregularity!r}")
        return (f"MovingLoadConstraint(train {self.train.train.name!r}: {self.n_contact} contact + "
                f"{len(self.x0_force)} force wheels on track x = {self.track.x_begin:g} to {self.track.x_end:g} m, "
                f"{self.interpolation} rows, {rail})")

    @property
    def n_contact(self):
        return len(self.x0)

    def knot(self, dt):
        """Knot spacing of the smoothing along the track [m]: 2 V Δt, or 0 for 'hermite'."""
        return 2.0 * self.train.speed * dt if self.interpolation == "bspline" else 0.0

    def width(self, dt):
        return row_width(self.track.length.min(), self.knot(dt))

    def check_travel(self, t_first, t_last, dt):
        """Refuse a run whose wheels leave the sampled range of the irregularity: the profile
        would jump to zero there (a position jump the wheels cannot follow)."""
        x_range = getattr(self.irregularity, "x_range", None)
        if x_range is None or self.n_contact == 0:
            return
        margin = 2.0 * self.knot(dt)
        x = self.positions(np.array([t_first, t_last]))
        lo, hi = x.min() - margin, x.max() + margin
        if lo < x_range[0] or hi > x_range[1]:
            raise ModelError(f"MovingLoadConstraint: the irregularity is sampled on [{x_range[0]:g}, {x_range[1]:g}] m "
                             f"but the wheels travel over [{lo:g}, {hi:g}] m in this run; sample the profile over "
                             "the whole travel (or build it with extrapolate=True)")

    def positions(self, t):
        """Contact-wheel positions at times ``t`` (array) -> ``(..., n_c)`` [m]."""
        return self.x0 + self.train.speed * np.asarray(t, dtype=float)[..., None]

    def _profile(self, x, nu):
        """r (nu = 0), dr/dx (1) or d²r/dx² (2) at positions x (any shape; a profile's single value
        holds at all of them, any other shape is a ModelError); a plain callable r(x) gets central
        differences."""
        x = np.asarray(x, dtype=float)
        try:
            r = np.asarray(self.irregularity(x, nu=nu), dtype=float)
        except TypeError:
            rail = lambda z: np.asarray(self.irregularity(z), dtype=float)
            h = 1e-4 if nu == 1 else 1e-3
            try:
                r = (rail(x) if nu == 0 else (rail(x + h) - rail(x - h)) / (2 * h) if nu == 1 else
                     (rail(x + h) - 2.0 * rail(x) + rail(x - h)) / (h * h))
            except (TypeError, ValueError) as exc:     # math.sin, 'if x < 5': a function of one number
                scalar = isinstance(exc, TypeError) or "truth value of an array" in str(exc)
                raise ModelError(f"MovingLoadConstraint: the irregularity "
                                 + ("must take an array of positions [m] (numpy functions, or np.vectorize): "
                                    if scalar else "") + f"r(x) of {x.shape} positions (x = {x.min():g} to "
                                 f"{x.max():g} m) raised {type(exc).__name__}: {exc}") from None
        try:
            return np.broadcast_to(r, x.shape)
        except ValueError:
            raise ModelError(f"MovingLoadConstraint: the irregularity gives values of shape {r.shape} for positions of "
                             f"shape {x.shape}: it must give one value [m] per position (or one for all)") from None

    def irregularity_at(self, t, dt, nu=0):
        """``r̃`` (or r; ``nu = 1``: its rate dr̃/dt = V dr̃/dx) under the contact wheels at times
        ``t`` (any shape) -> ``(..., n_c)`` [m, m/s]; a smoothed rail in one compiled pass over
        all times and wheels (:func:`_bspline_under_wheels`)."""
        t = np.asarray(t, dtype=float)
        if self.irregularity is None:
            return np.zeros_like(self.positions(t))
        knot = self.knot(dt)
        if knot == 0.0:
            x = self.positions(t)
            r = self._profile(x, nu)
            bad = np.flatnonzero(~np.isfinite(r))
            bad = bad[0] if bad.size else -1
        else:
            # positions are monotone in t (rounding is), so the ends of the travel are those of t's
            ends = self.positions(np.array([t.min(), t.max()])) if t.size else np.zeros(1)
            profile = self._smoothed_profile(float(ends.min()), float(ends.max()), knot)
            r = np.empty(t.shape + (self.n_contact,))
            bad = _bspline_under_wheels(profile.coef, profile.first, profile.origin, profile.inv_step, self.x0,
                                        self.train.speed, np.ascontiguousarray(t).ravel(), nu, r.reshape(-1, self.n_contact))
        if bad >= 0:
            where = np.unravel_index(bad, r.shape)
            x = self.positions(t)
            raise ModelError(f"MovingLoadConstraint: the irregularity gives {r[where]} under contact wheel "
                             f"{where[-1]} at x = {x[where]:g} m")
        return r * self.train.speed ** nu

    def _smoothed_profile(self, x_lo, x_hi, knot):
        """r̃ for knot spacing ``knot`` [m] over [x_lo, x_hi] [m] (a :class:`SmoothedProfile`
        anchored at the track's start; cached, and grown by the nodes it lacks when a block of
        steps asks beyond it: each node is tabulated once in a run)."""
        lo, hi = x_lo - TABLE_MARGIN * knot, x_hi + TABLE_MARGIN * knot
        cached = getattr(self, "_smoothed", None)
        if cached is None or cached.knot != knot:
            self._smoothed = SmoothedProfile(lambda x: self._profile(x, 0), knot, self.track.x_begin, lo, hi)
        elif not cached.covers(knot, x_lo, x_hi):
            cached.grow(lambda x: self._profile(x, 0), lo, hi)
        return self._smoothed

    def rows_at(self, t, dt):
        """Time hook: ``(cols, vals, slopes, r)`` of the contact wheels at time ``t``."""
        cols, vals, slopes = self.track.rows(self.positions(t), self.knot(dt))
        return cols, vals, slopes, self.irregularity_at(np.array(t), dt)


class SmoothedProfile:
    """``profile(x, nu)``: the smoothed irregularity r̃ (nu = 0) or its derivative d^nu r̃/dx^nu
    (1, 2) [m, 1, 1/m] at positions ``x`` [m] in [x_lo, x_hi], for knot spacing ``knot`` [m].

    Node j, at x_j = origin + j s (s = knot / NODES_PER_KNOT, ``origin`` a fixed position: the
    track's start), holds r̃(x_j), the convolution of ``r`` (a vectorised r(x) [m]) with
    B₃(ξ/knot)/knot by 4-point Gauss on the kernel's 4 pieces. Between the nodes r̃ is the
    uniform cubic B-spline Σ c_j B₃((x − x_j)/s) with the local coefficients
    c_j = (8 r̃_j − r̃_{j−1} − r̃_{j+1}) / 6, the quasi-interpolant that reproduces cubics: C², error
    O(s⁴ d⁴r̃/dx⁴) (at a node −s⁴ d⁴r̃/dx⁴ / 36). The value at x in [x_j, x_j+1] depends on the
    nodes j − 2 … j + 3 only, each computed from its own position, so not on the range
    tabulated: a run's rows are the same whichever block of steps asked for them, and
    :meth:`grow` extends a table by the nodes it lacks only.
    """

    def __init__(self, r, knot, origin, x_lo, x_hi):
        self.knot, self.origin = float(knot), float(origin)
        self.step = self.knot / NODES_PER_KNOT
        self.inv_step = NODES_PER_KNOT / self.knot
        first, last = self._nodes_for(x_lo, x_hi)
        self._set(first, last, self._node_values(r, first - 1, last + 1))

    def _nodes_for(self, x_lo, x_hi):
        """``(first, last)``: the nodes whose coefficients the values in [x_lo, x_hi] [m] need."""
        return (math.floor((x_lo - self.origin) * self.inv_step) - 2,
                math.ceil((x_hi - self.origin) * self.inv_step) + 3)

    def _node_values(self, r, j_lo, j_hi):
        """r̃ of the profile ``r`` at the nodes j_lo .. j_hi (each from its own position only)
        -> (j_hi - j_lo + 1,) [m]."""
        grid = self.origin + np.arange(j_lo, j_hi + 1, dtype=float) * self.step
        # kernel pieces [(k-2) knot, (k-1) knot], 4-point Gauss each: the profile at all 16 shifts in one call
        shifts = [(k - 1.5 + 0.5 * z) * self.knot for k in range(4) for z in GAUSS_POINTS]
        weights = [0.5 * w * bspline_kernel(xi / self.knot) for xi, w in zip(shifts, 4 * list(GAUSS_WEIGHTS))]
        samples = np.asarray(r((grid[None, :] - np.array(shifts)[:, None]).ravel()), dtype=float)
        values = np.zeros_like(grid)
        for weight, sample in zip(weights, samples.reshape(len(shifts), grid.size)):
            values += weight * sample
        return values

    def _set(self, first, last, values):
        """The table of the coefficients of nodes first .. last from r̃ at nodes first - 1 .. last + 1."""
        self.first, self.last, self.values = first, last, values      # first: the node of coef[0]
        self.coef = (8.0 * values[1:-1] - values[:-2] - values[2:]) / 6.0
        self.x_lo = self.origin + (first + 2) * self.step
        self.x_hi = self.origin + (last - 3) * self.step

    def grow(self, r, x_lo, x_hi):
        """Extend the table of the profile ``r`` (the one it was built from) to hold [x_lo, x_hi]
        [m], tabulating only the nodes it lacks: its values are a table's built over the whole
        range, to the bit."""
        first, last = self._nodes_for(x_lo, x_hi)
        first, last = min(first, self.first), max(last, self.last)
        self._set(first, last, np.concatenate([self._node_values(r, first - 1, self.first - 2), self.values,
                                               self._node_values(r, self.last + 2, last + 1)]))

    def covers(self, knot, x_lo, x_hi):
        """Whether the table is for ``knot`` [m] and holds [x_lo, x_hi] [m]."""
        return knot == self.knot and self.x_lo <= x_lo and x_hi <= self.x_hi

    def __call__(self, x, nu=0):
        x = np.asarray(x, dtype=float)
        out = np.empty(x.size)
        _bspline_values(self.coef, self.first, self.origin, self.inv_step, np.ascontiguousarray(x).ravel(), nu, out)
        return out.reshape(x.shape)


@njit(cache=True, inline='always')
def _bspline_value(coef, first, origin, inv_step, x, nu):
    """The uniform cubic B-spline Σ coef[k] B₃(u − (first + k)), u = (x − origin)·inv_step, or its
    derivative ``nu`` in x, at ``x`` (NaN outside the nodes held or at a NaN)."""
    u = (x - origin) * inv_step
    if not np.isfinite(u):
        return np.nan
    j = math.floor(u)
    t = u - j
    k = j - first            # the piece [x_j, x_j+1] takes coef[k - 1 .. k + 2]
    if k < 1 or k + 2 >= coef.shape[0]:
        return np.nan
    c0, c1, c2, c3 = coef[k - 1], coef[k], coef[k + 1], coef[k + 2]
    s = 1.0 - t
    if nu == 0:
        return (c0 * s * s * s + c1 * (4.0 - 6.0 * t * t + 3.0 * t * t * t)
                + c2 * (1.0 + 3.0 * t + 3.0 * t * t - 3.0 * t * t * t) + c3 * t * t * t) / 6.0
    if nu == 1:
        return (-c0 * s * s + c1 * (3.0 * t * t - 4.0 * t) + c2 * (1.0 + 2.0 * t - 3.0 * t * t)
                + c3 * t * t) * (0.5 * inv_step)
    return (c0 * s + c1 * (3.0 * t - 2.0) + c2 * (1.0 - 3.0 * t) + c3 * t) * (inv_step * inv_step)


@njit(cache=True)
def _bspline_values(coef, first, origin, inv_step, x, nu, out):
    """:func:`_bspline_value` at each ``x``."""
    for i in range(x.shape[0]):
        out[i] = _bspline_value(coef, first, origin, inv_step, x[i], nu)


@njit(cache=True)
def _bspline_under_wheels(coef, first, origin, inv_step, x0, speed, t, nu, out):
    """:func:`_bspline_value` under wheel i at x0[i] + speed·t[k] [m] into ``out[k, i]``
    (``(n_t, n_c)``); the flat index of the first non-finite value, or -1."""
    bad = -1
    for k in range(t.shape[0]):
        for i in range(x0.shape[0]):
            value = _bspline_value(coef, first, origin, inv_step, x0[i] + speed * t[k], nu)
            out[k, i] = value
            if bad < 0 and not np.isfinite(value):
                bad = k * x0.shape[0] + i
    return bad
