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
smoothed profile r̃ is tabulated once per run at spacing V h / 8 and interpolated by a cubic
spline (its derivative gives dr̃/dt); even a C² sampled profile benefits, since its third
derivative jumps at every sample.
"""
import numpy as np
from scipy.interpolate import CubicSpline

from vtsi.errors import ModelError
from vtsi.spline import UniformCubic
from vtsi.track import GAUSS_POINTS, GAUSS_WEIGHTS, Track, bspline_kernel, row_width
from vtsi.train import TrainSubdomain

INTERPOLATIONS = ("hermite", "bspline")


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
        """r (nu = 0), dr/dx (1) or d²r/dx² (2) at x; a plain callable r(x) gets central differences."""
        try:
            return np.asarray(self.irregularity(x, nu=nu), dtype=float)
        except TypeError:
            r = lambda z: np.asarray(self.irregularity(z), dtype=float)
            if nu == 0:
                return r(x)
            h = 1e-4 if nu == 1 else 1e-3
            if nu == 1:
                return (r(x + h) - r(x - h)) / (2 * h)
            return (r(x + h) - 2.0 * r(x) + r(x - h)) / (h * h)

    def irregularity_at(self, t, dt, nu=0):
        """``r̃`` (or r; ``nu = 1``: its rate dr̃/dt = V dr̃/dx) under the contact wheels at times
        ``t`` -> ``(..., n_c)`` [m, m/s]."""
        x = self.positions(t)
        if self.irregularity is None:
            return np.zeros_like(x)
        knot = self.knot(dt)
        if knot == 0.0:
            r = self._profile(x, nu)
        else:
            r = self._smoothed_profile(x.min(), x.max(), knot)(x, nu)
        if not np.all(np.isfinite(r)):
            where = np.argwhere(~np.isfinite(r))[0]
            raise ModelError(f"MovingLoadConstraint: the irregularity gives {r[tuple(where)]} under contact wheel "
                             f"{where[-1]} at x = {x[tuple(where)]:g} m")
        return r * self.train.speed ** nu

    def _smoothed_profile(self, x_lo, x_hi, knot):
        """r̃ as a C² cubic spline tabulated at knot/8 spacing (cached; rebuilt when the range
        grows): each node is the exact convolution by 4-point Gauss on the 4 kernel pieces."""
        cached = getattr(self, "_smoothed", None)
        if cached is not None and cached[0] == knot and cached[1] <= x_lo and x_hi <= cached[2]:
            return cached[3]
        lo, hi = x_lo - 50.0 * knot, x_hi + 50.0 * knot
        grid = np.linspace(lo, hi, int(np.ceil((hi - lo) / (knot / 8.0))) + 1)
        r = np.zeros_like(grid)
        for k in range(4):    # kernel pieces [(k-2) knot, (k-1) knot], 4-point Gauss each
            for z, w in zip(GAUSS_POINTS, GAUSS_WEIGHTS):
                xi = (k - 1.5 + 0.5 * z) * knot
                r += 0.5 * w * bspline_kernel(xi / knot) * self._profile(grid - xi, 0)
        table = UniformCubic(CubicSpline(grid, r))
        self._smoothed = (knot, lo, hi, table)
        return table

    def rows_at(self, t, dt):
        """Time hook: ``(cols, vals, slopes, r)`` of the contact wheels at time ``t``."""
        cols, vals, slopes = self.track.rows(self.positions(t), self.knot(dt))
        return cols, vals, slopes, self.irregularity_at(np.array(t), dt)
