"""vtsi.spline.UniformCubic: scipy's cubic splines evaluated by a compiled loop on uniform
breakpoints (and by scipy otherwise). The values must be scipy's to round-off."""
import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from vtsi.spline import UniformCubic


@pytest.mark.parametrize("nu", [0, 1, 2])
def test_uniform_breakpoints_match_scipy(nu):
    rng = np.random.default_rng(3)
    x = -7.3 + 0.1 * np.arange(400)
    spline = CubicSpline(x, rng.normal(size=x.size))
    fast = UniformCubic(spline)
    assert fast.uniform
    # inside, on the breakpoints themselves, and beyond both ends (scipy extrapolates the end pieces)
    points = np.concatenate([rng.uniform(x[0] - 1.0, x[-1] + 1.0, 5000), x, [x[0] - 3.0, x[-1] + 3.0]])
    expected = spline(points, nu)
    scale = np.abs(expected).max()
    assert np.abs(fast(points, nu) - expected).max() <= 1e-12 * scale


def test_shape_is_kept_and_nan_propagates():
    x = np.linspace(0.0, 1.0, 11)
    fast = UniformCubic(CubicSpline(x, x ** 2))
    points = np.array([[0.25, np.nan], [0.5, 0.75]])
    out = fast(points)
    assert out.shape == (2, 2) and np.isnan(out[0, 1])
    assert out[1, 0] == pytest.approx(0.25, rel=1e-12)


def test_non_uniform_breakpoints_use_scipy():
    x = np.array([0.0, 0.1, 0.3, 0.35, 1.0])
    spline = CubicSpline(x, np.sin(x))
    fast = UniformCubic(spline)
    assert not fast.uniform
    points = np.linspace(-0.2, 1.2, 57)
    assert np.array_equal(fast(points, 1), spline(points, 1))


@pytest.mark.parametrize("knots", [np.linspace(0.0, 2.0, 21), np.array([0.0, 0.3, 0.5, 1.2, 2.0])])
def test_zero_outside(knots):
    spline = CubicSpline(knots, np.cos(knots))
    fast = UniformCubic(spline, zero_outside=True)
    points = np.array([-0.5, -1e-12, 0.0, 1.0, 2.0, 2.0 + 1e-12, 3.0])
    out = fast(points, 1)
    inside = (points >= 0.0) & (points <= 2.0)
    assert np.all(out[~inside] == 0.0)
    assert np.allclose(out[inside], spline(points[inside], 1), rtol=1e-12, atol=1e-14)
