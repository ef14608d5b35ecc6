"""Fast evaluation of a cubic spline on uniformly spaced breakpoints.

scipy builds the spline (:class:`scipy.interpolate.CubicSpline`); its evaluation searches the
breakpoints for every point, which dominated the per-run tables of a long train on a sampled
rail profile (~35 ns a point). On a uniform grid the piece is found by one division, so
:class:`UniformCubic` evaluates the same polynomials in a compiled loop (~3 ns a point) and
falls back to scipy for non-uniform breakpoints.
"""
import numpy as np
from numba import njit


class UniformCubic:
    """``spline(x, nu)``: the value (nu = 0) or derivative ``nu`` (1, 2) of a scipy cubic
    :class:`~scipy.interpolate.PPoly` (e.g. a CubicSpline), extrapolating with the end pieces as
    scipy does with ``extrapolate=True``, or 0 outside the breakpoints if ``zero_outside``."""

    def __init__(self, ppoly, zero_outside=False):
        self.ppoly, self.zero_outside = ppoly, bool(zero_outside)
        breaks = np.asarray(ppoly.x, dtype=float)
        steps = np.diff(breaks)
        h = (breaks[-1] - breaks[0]) / len(steps)
        self.uniform = ppoly.c.shape[0] == 4 and bool(np.all(np.abs(steps - h) <= 1e-9 * h))
        self._breaks, self._inv_h = breaks, 1.0 / h
        self._coef = np.ascontiguousarray(ppoly.c.T)

    def __call__(self, x, nu=0):
        x = np.asarray(x, dtype=float)
        if not self.uniform:
            out = np.asarray(self.ppoly(x, nu), dtype=float)
            if self.zero_outside:
                out = np.where((x >= self._breaks[0]) & (x <= self._breaks[-1]), out, 0.0)
            return out
        out = np.empty(x.size)
        _evaluate(self._coef, self._breaks, self._inv_h, np.ascontiguousarray(x).ravel(), nu, self.zero_outside, out)
        return out.reshape(x.shape)


@njit(cache=True)
def _evaluate(coef, breaks, inv_h, x, nu, zero_outside, out):
    """Piece k = floor((x - x₀)/h) (clamped), local t = x - breaks[k], Horner on ``coef[k]``
    (highest power first, scipy's layout)."""
    last = coef.shape[0] - 1
    for i in range(x.shape[0]):
        if not np.isfinite(x[i]):
            out[i] = np.nan
            continue
        if zero_outside and (x[i] < breaks[0] or x[i] > breaks[last + 1]):
            out[i] = 0.0
            continue
        k = int(np.floor((x[i] - breaks[0]) * inv_h))
        k = min(max(k, 0), last)
        t = x[i] - breaks[k]
        c3, c2, c1, c0 = coef[k, 0], coef[k, 1], coef[k, 2], coef[k, 3]
        if nu == 0:
            out[i] = ((c3 * t + c2) * t + c1) * t + c0
        elif nu == 1:
            out[i] = (3.0 * c3 * t + 2.0 * c2) * t + c1
        else:
            out[i] = 6.0 * c3 * t + 2.0 * c2
