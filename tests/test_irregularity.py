"""Irregularity spectra, random profiles (variance = ∫S dΩ over the band) and profile functions."""
import functools

import numpy as np
import pytest
import scipy.integrate

from vtsi.errors import ModelError
from vtsi.models import Irregularity, fra_psd, german_psd, sample_profile


def test_german_psd_limits_and_levels():
    """S(0) = A_v/Ω_r² and S ~ A_v Ω_c²/Ω⁴ for Ω ≫ Ω_c (Lei 2017, ch. 5 constants)."""
    assert german_psd(0.0) == pytest.approx(4.032e-7 / 0.0206 ** 2, rel=1e-14)
    assert german_psd(1e3, 'low') == pytest.approx(4.032e-7 * 0.8246 ** 2 / 1e12, rel=1e-5)
    omega = np.geomspace(0.01, 10, 7)
    np.testing.assert_allclose(german_psd(omega, 'high') / german_psd(omega, 'low'), 1.080e-6 / 4.032e-7)
    with pytest.raises(ValueError, match=r"unknown level 'medium'; valid: \['low', 'high'\]"):
        german_psd(omega, 'medium')


def test_fra_psd_units():
    """Class 6 at Ω = Ω_c: k A_v / (2 Ω_c²) cm²/(rad/m) = that × 1e-4 m²/(rad/m)."""
    assert fra_psd(0.8245, 6) == pytest.approx(0.25 * 0.0339 / (2 * 0.8245 ** 2) * 1e-4, rel=1e-12)
    classes = np.array([fra_psd(1.0, c) for c in range(1, 7)])
    assert np.all(np.diff(classes) < 0)  # class 6 is the best track
    with pytest.raises(ValueError, match="unknown fra_class 7"):
        fra_psd(1.0, 7)
    with pytest.raises(ValueError, match="omega must be finite and > 0"):
        fra_psd([0.0, 1.0])


@pytest.mark.parametrize('psd', [german_psd, functools.partial(german_psd, level='high'),
                                 functools.partial(fra_psd, fra_class=5)])
def test_sample_variance_equals_band_integral(psd):
    """Band 3-150 m: Ω from 2π/150 to 2π/3, and Ω_lo/(Ω_hi − Ω_lo) = 1/49. With n_waves = 980 every
    Ω_k and every sum and difference of two of them is a non-zero multiple of ΔΩ/2, so on the
    window [0, 4π/ΔΩ) sampled at m equal steps (m = 12000 above the largest index, 2Ω_hi/(ΔΩ/2)
    ≈ 4000) all cross terms and the mean vanish exactly: the sample variance is Σ S(Ω_k)ΔΩ up to
    rounding, for any phases. What remains is the midpoint rule's error against ∫S dΩ, O(ΔΩ²S''),
    1.6e-4 (German) and 2.3e-4 (FRA) relative here, so rtol = 1e-3."""
    n_waves, band = 980, (3.0, 150.0)
    lo, hi = 2 * np.pi / band[1], 2 * np.pi / band[0]
    d_omega = (hi - lo) / n_waves
    x = np.linspace(0.0, 4 * np.pi / d_omega, 12000, endpoint=False)
    r = sample_profile(psd, x, band, n_waves=n_waves, rng=np.random.default_rng(7))
    exact = scipy.integrate.quad(psd, lo, hi, epsabs=0.0, epsrel=1e-12, limit=200)[0]
    assert abs(r.mean()) < 1e-9 * np.sqrt(exact)
    assert np.var(r) == pytest.approx(exact, rel=1e-3)


def test_sample_profile_is_reproducible_and_shaped():
    x = np.linspace(0.0, 500.0, 2001).reshape(1, -1)
    a = sample_profile(german_psd, x, rng=3)
    np.testing.assert_array_equal(a, sample_profile(german_psd, x, rng=np.random.default_rng(3)))
    assert a.shape == x.shape and not np.array_equal(a, sample_profile(german_psd, x, rng=4))
    with pytest.raises(ValueError, match="wavelength_band must be 0 < min < max"):
        sample_profile(german_psd, x, (150.0, 3.0))


def test_irregularity_spline_derivatives_and_support():
    """A 10 m cosine sampled every 0.05 m: the spline's errors scale as h⁴, h³, h² times the
    derivatives (2π/10)^k; the tolerances below are 10x those estimates."""
    wave = 2 * np.pi / 10.0
    x = np.arange(0.0, 100.0 + 1e-9, 0.05)
    profile = Irregularity(x, 1e-3 * np.cos(wave * x))
    xi = np.linspace(20.0, 80.0, 997)
    np.testing.assert_allclose(profile(xi), 1e-3 * np.cos(wave * xi), atol=1e-3 * 1e-7)
    np.testing.assert_allclose(profile(xi, 1), -1e-3 * wave * np.sin(wave * xi), atol=1e-3 * 1e-5)
    np.testing.assert_allclose(profile(xi, 2), -1e-3 * wave ** 2 * np.cos(wave * xi), atol=1e-3 * 1e-3)
    np.testing.assert_array_equal(profile(np.array([-1.0, 100.5])), 0.0)
    assert Irregularity(x, 1e-3 * np.cos(wave * x), extrapolate=True)(100.5) != 0.0
    assert profile(np.zeros((2, 3))).shape == (2, 3)
    with pytest.raises(ValueError, match="nu must be 0, 1 or 2"):
        profile(xi, 3)


def test_irregularity_from_function_and_psd():
    bump = Irregularity.from_function(lambda x: np.exp(-x ** 2), lambda x: -2 * x * np.exp(-x ** 2))
    assert bump(0.0) == 1.0 and bump(1.0, 1) == pytest.approx(-2 * np.exp(-1.0))
    with pytest.raises(ValueError, match="derivative 2 of this profile was not given"):
        bump(0.0, 2)
    x = np.linspace(0.0, 300.0, 3001)
    profile = Irregularity.from_psd(german_psd, x, rng=5)
    np.testing.assert_allclose(profile(x), sample_profile(german_psd, x, rng=5), atol=1e-15)


@pytest.mark.parametrize("call, message", [
    (lambda x: sample_profile(german_psd, x, rng="abc"), "rng must be a seed (an integer >= 0), a numpy Generator or None, got 'abc'"),
    (lambda x: sample_profile(german_psd, x, rng=1.5), "rng must be a seed (an integer >= 0), a numpy Generator or None, got 1.5"),
    (lambda x: sample_profile(german_psd, x, rng=-1), "rng must be a seed (an integer >= 0), a numpy Generator or None, got -1"),
    (lambda x: Irregularity.from_psd(german_psd, x, rng=2.5), "rng must be a seed (an integer >= 0), a numpy Generator or None, got 2.5"),
    (lambda x: sample_profile(3.0, x), "psd must be a function S(omega) [m²/(rad/m)], got 3.0"),
    (lambda x: german_psd(1.0, level=["low"]), "unknown level ['low']; valid: ['low', 'high']"),
], ids=["text-seed", "fractional-seed", "negative-seed", "from_psd-seed", "psd-not-callable", "level-list"])
def test_bad_profile_inputs_are_named(call, message):
    """A seed that is not an integer >= 0, a spectrum that is not a function and a level that is not
    a name: one ModelError line each (numpy's TypeError/ValueError, or 'unhashable type', before)."""
    with pytest.raises(ModelError) as caught:
        call(np.linspace(0.0, 100.0, 11))
    assert message in str(caught.value) and "\n" not in str(caught.value)
