"""MovingLoadConstraint: the wheels of a TrainSubdomain follow the rail of a Track.

For contact wheel i at x_i(t) = x_i0 + V t the constraint is

    S u_t - N(t) u_b - r(t) = 0      (gap g = S u_t - N u_b - r; bilateral: g = 0),

with N's row the Hermite row of the track element under the wheel (zero off the track:
rigid ground) and r the rail irregularity. ``interpolation='bspline'`` replaces the rows and
r by their cubic B-spline smoothing in time (docs/theory/constraints.md):

    Ñ(t) = Σ_{k=-3..3} w_k N(x(t + kΔt)),   r̃(t) = Σ_k w_k r(x(t + kΔt)),
    w = (1, 8, 23, 32, 23, 8, 1)/96 = B₃(k/2)/2 (cubic B-spline of knot spacing 2Δt),

which is second-order accurate (Ñ - N = (2/3) Δt² N̈ + O(Δt⁴)) and whose transfer function
has a fourth-order zero at z = -1, so the period-2Δt response that the trapezoidal rule
leaves undamped is not excited when a wheel crosses a node.
"""
import numpy as np

from vtsi.errors import ModelError
from vtsi.track import Track, row_width
from vtsi.train import TrainSubdomain

BSPLINE_WEIGHTS = np.array([1.0, 8.0, 23.0, 32.0, 23.0, 8.0, 1.0]) / 96.0
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
            raise ModelError("MovingLoadConstraint: irregularity must be callable r(x)")
        self.track, self.train, self.irregularity, self.interpolation = track, train, irregularity, interpolation
        self.x0 = train.wheel_x0(train.contact_wheels)
        self.x0_force = train.wheel_x0(train.force_wheels)

    @property
    def n_contact(self):
        return len(self.x0)

    def taps(self, dt):
        """Smoothing taps [m] along the track and weights (one tap for 'hermite')."""
        if self.interpolation == "bspline":
            return np.arange(-3, 4) * dt * self.train.speed, BSPLINE_WEIGHTS.copy()
        return np.zeros(1), np.ones(1)

    def width(self, dt):
        taps, _ = self.taps(dt)
        return row_width(self.track.length.min(), float(np.ptp(taps)))

    def positions(self, t):
        """Contact-wheel positions at times ``t`` (array) -> ``(..., n_c)`` [m]."""
        return self.x0 + self.train.speed * np.asarray(t, dtype=float)[..., None]

    def irregularity_at(self, t, dt):
        """``r̃`` (or r) under the contact wheels at times ``t`` -> ``(..., n_c)`` [m]."""
        x = self.positions(t)
        if self.irregularity is None:
            return np.zeros_like(x)
        taps, weights = self.taps(dt)
        r = np.zeros_like(x)
        for tap, w in zip(taps, weights):
            r += w * np.asarray(self.irregularity(x + tap), dtype=float)
        if not np.all(np.isfinite(r)):
            raise ModelError("MovingLoadConstraint: the irregularity gives NaN or inf under a wheel")
        return r

    def rows_at(self, t, dt):
        """Time hook: ``(cols, vals, r)`` of the contact wheels at time ``t``."""
        taps, weights = self.taps(dt)
        cols, vals = self.track.rows(self.positions(t), taps, weights)
        return cols, vals, self.irregularity_at(np.array(t), dt)
