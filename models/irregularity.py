"""Vertical rail irregularity: spectra, random sample profiles, and profiles as functions of x.

The irregularity r(x) is the rail's vertical deviation [m], positive upwards (as r(t) in
docs/theory/coupled_step.md): a wheel on a smooth, rigid rail at x sits at height r(x). Spectra
are one-sided power spectral densities S(Ω) [m²/(rad/m)] of the spatial angular frequency
Ω = 2π/wavelength [rad/m], so that the variance of r is ∫₀^∞ S(Ω) dΩ.

Each spectrum's constants are stated with it (:func:`german_psd`, :func:`fra_psd`), after [1].

References
----------
.. [1] Lei, X. (2017). High Speed Railway Track Dynamics, Springer, ch. 5 "Track irregularity
   power spectrum and numerical simulation": the German high-speed spectra (after the Deutsche
   Bundesbahn) and the FRA classes 1-6 (US Federal Railroad Administration).
.. [2] Shinozuka, M. & Jan, C.-M. (1972). Digital simulation of random processes and its
   applications. J. Sound Vib. 25(1), 111-128: the sum of cosines with random phases.
"""
from __future__ import annotations

import functools

import numpy as np
import scipy.fft
import scipy.interpolate

from vtsi.errors import ModelError, as_numbers, is_count, is_int
from vtsi.spline import UniformCubic

_GERMAN = {'low': 4.032e-7, 'high': 1.080e-6}  # A_v [m·rad], low / high interference
_GERMAN_OMEGA_C, _GERMAN_OMEGA_R = 0.8246, 0.0206  # [rad/m]
_FRA_AV = (1.2107, 1.0181, 0.6816, 0.5376, 0.2095, 0.0339)  # A_v [cm²·rad/m], classes 1..6
_FRA_OMEGA_C, _FRA_K = 0.8245, 0.25
WAVES_PER_BLOCK, POINTS_PER_BLOCK = 512, 4096   # sample_profile's work array: 512 × 4096 floats
WAVELENGTH_BAND = (3.0, 150.0)  # [m] the wavelengths a sample profile holds, shortest and longest (every spectrum)


def _omega(omega, where, allow_zero):
    omega = as_numbers(omega, where, "omega [rad/m]")
    bad = ~np.isfinite(omega) | (omega < 0 if allow_zero else omega <= 0)
    if np.any(bad):
        raise ModelError(f"{where}: omega must be finite and {'>=' if allow_zero else '>'} 0 [rad/m], "
                         f"got {omega[bad].ravel()[0]!r}")
    return omega


def german_psd(omega, level='low'):
    """German high-speed vertical profile spectrum, one-sided.

    S(Ω) = A_v Ω_c² / ((Ω² + Ω_r²)(Ω² + Ω_c²)), Ω_c = 0.8246 rad/m, Ω_r = 0.0206 rad/m,
    A_v = 4.032e-7 m·rad ('low' interference) or 1.080e-6 m·rad ('high').

    Parameters
    ----------
    omega : array_like
        Spatial angular frequency Ω ≥ 0 [rad/m].
    level : {'low', 'high'}

    Returns
    -------
    ndarray, shape of omega
        S(Ω) [m²/(rad/m)].

    References
    ----------
    Lei (2017), ch. 5.
    """
    if not (isinstance(level, str) and level in _GERMAN):
        raise ModelError(f"german_psd: unknown level {level!r}; valid: {list(_GERMAN)}")
    w2 = _omega(omega, 'german_psd', allow_zero=True) ** 2
    return _GERMAN[level] * _GERMAN_OMEGA_C ** 2 / ((w2 + _GERMAN_OMEGA_R ** 2) * (w2 + _GERMAN_OMEGA_C ** 2))


def fra_psd(omega, fra_class=6):
    """FRA (US Federal Railroad Administration) vertical profile spectrum, one-sided.

    S(Ω) = k A_v Ω_c² / (Ω² (Ω² + Ω_c²)) in cm²/(rad/m) with A_v in cm²·rad/m, k = 0.25,
    Ω_c = 0.8245 rad/m; returned converted to m²/(rad/m) (× 1e-4). Class 6 is the best track.

    Parameters
    ----------
    omega : array_like
        Spatial angular frequency Ω > 0 [rad/m] (S is singular at 0).
    fra_class : int
        1 … 6.

    Returns
    -------
    ndarray, shape of omega
        S(Ω) [m²/(rad/m)].

    References
    ----------
    Lei (2017), ch. 5.
    """
    if not (is_count(fra_class, 1) and fra_class <= 6):
        raise ModelError(f"fra_psd: unknown fra_class {fra_class!r}; valid: 1, 2, 3, 4, 5, 6")
    w2 = _omega(omega, 'fra_psd', allow_zero=False) ** 2
    return 1e-4 * _FRA_K * _FRA_AV[int(fra_class) - 1] * _FRA_OMEGA_C ** 2 / (w2 * (w2 + _FRA_OMEGA_C ** 2))


def _even_step(x):
    """The step [m] of positions ``x`` (n,) evenly spaced to round-off (each within 4 ulp of max |x|
    of x[0] + j step), else None (fewer than 2)."""
    if x.size < 2:
        return None
    step = (x[-1] - x[0]) / (x.size - 1)
    tol = 4.0 * np.finfo(float).eps * float(np.max(np.abs(x)))
    return step if np.all(np.abs(x - (x[0] + step * np.arange(x.size))) <= tol) else None


def _chirp_sum(amplitude, omega, phase, d_omega, x0, step, n):
    """Σ_k a_k cos(Ω_k x_j + φ_k) at x_j = x0 + j step, j < n, for Ω_k = Ω_0 + k ΔΩ: a chirp
    z-transform, X_j = Σ_k c_k e^{i k j ΔΩ step} with c_k = a_k e^{i(Ω_k x0 + φ_k)}, by Bluestein's
    FFT convolution (k j = (k² + j² − (j − k)²)/2). The chirp e^{i θ k²/2} is computed from its
    phase (scipy.signal.czt's w**(k²/2) drifts in modulus: 2e-11 of a 4000-wave profile, here
    1e-13, the round-off of Ω_k x itself)."""
    half = 0.5 * d_omega * step
    size = scipy.fft.next_fast_len(omega.size + n - 1)
    k = np.arange(max(omega.size, n), dtype=float)
    chirp = np.exp(1j * half * k * k)
    kernel = np.zeros(size, dtype=complex)
    kernel[:n] = chirp[:n].conj()
    kernel[size - omega.size + 1:] = chirp[1:omega.size][::-1].conj()
    waves = amplitude * np.exp(1j * (omega * x0 + phase)) * chirp[:omega.size]
    y = scipy.fft.ifft(scipy.fft.fft(waves, size) * scipy.fft.fft(kernel))[:n]
    return (y * np.exp(1j * k[:n] * (omega[0] * step + half * k[:n]))).real


def sample_profile(psd, x, wavelength_band=WAVELENGTH_BAND, n_waves=None, rng=None):
    """A random profile with one-sided spectrum ``psd`` over a wavelength band.

    r(x) = Σ_k √(2 S(Ω_k) ΔΩ) cos(Ω_k x + φ_k), with n_waves frequencies Ω_k at the midpoints of
    equal intervals ΔΩ spanning [2π/λ_max, 2π/λ_min], and phases φ_k uniform in [0, 2π). Its
    variance over x is Σ S(Ω_k) ΔΩ ≈ ∫ S dΩ over the band. The profile repeats its pattern with
    period 2π/ΔΩ; the default n_waves keeps that period at least as long as the span of x. The
    points are summed in fixed blocks of POINTS_PER_BLOCK: an evenly spaced block (a sweep's) as a
    chirp z-transform through FFTs (4096 points of 4000 waves in 1 ms, 0.35 s summed directly;
    the two agree to 1e-13 of the profile), any other directly.

    Parameters
    ----------
    psd : callable
        S(Ω) [m²/(rad/m)], vectorised, e.g. ``german_psd`` or
        ``functools.partial(fra_psd, fra_class=5)``.
    x : array_like
        Positions [m], any shape.
    wavelength_band : (float, float)
        Shortest and longest wavelength λ_min < λ_max [m]; default WAVELENGTH_BAND, 3 to 150 m
        (a sweep's rail samples: a wheel at speed V passes the shortest at V / 3 m, 27.8 Hz at
        300 km/h, which its default time step resolves, :func:`vtsi.passage.default_dt`).
    n_waves : int, optional
        Number of cosines. Default: max(1000, ⌈(Ω_max − Ω_min)(x_max − x_min)/(2π)⌉).
    rng : numpy.random.Generator or int or None
        Random source (or seed) for the phases.

    Returns
    -------
    ndarray, shape of x
        r(x) [m], positive upwards.

    References
    ----------
    Shinozuka & Jan (1972).
    """
    x = as_numbers(x, "sample_profile", "x [m]")
    band = as_numbers(wavelength_band, "sample_profile", "wavelength_band [m]")
    if band.shape != (2,) or not (np.isfinite(band[1]) and 0 < band[0] < band[1]):
        raise ModelError(f"sample_profile: wavelength_band must be 0 < min < max [m], got {wavelength_band!r}")
    lam_min, lam_max = band
    if not np.all(np.isfinite(x)):
        raise ModelError("sample_profile: x must be finite")
    w_lo, w_hi = 2 * np.pi / lam_max, 2 * np.pi / lam_min
    if n_waves is None:
        span = x.max() - x.min() if x.size else 0.0
        n_waves = max(1000, int(np.ceil((w_hi - w_lo) * span / (2 * np.pi))))
    if not is_count(n_waves, 1):
        raise ModelError(f"sample_profile: n_waves must be a positive integer, got {n_waves!r}")
    d_omega = (w_hi - w_lo) / int(n_waves)
    omega = w_lo + d_omega * (np.arange(int(n_waves)) + 0.5)
    if not callable(psd):
        raise ModelError(f"sample_profile: psd must be a function S(omega) [m²/(rad/m)], got {psd!r}")
    density = as_numbers(psd(omega), "sample_profile", "psd(omega) [m²/(rad/m)]")
    if density.shape != omega.shape or not np.all(np.isfinite(density) & (density >= 0.0)):
        bad = density.ravel()[~(np.isfinite(density.ravel()) & (density.ravel() >= 0.0))]
        raise ModelError(f"sample_profile: psd(omega) must give a finite value >= 0 [m²/(rad/m)] for each of the "
                         f"{omega.size} omega, got shape {density.shape}" + (f", {bad[0]:g}" if bad.size else ""))
    amplitude = np.sqrt(2.0 * density * d_omega)
    if not (rng is None or isinstance(rng, np.random.Generator) or (is_int(rng) and rng >= 0)):
        raise ModelError(f"sample_profile: rng must be a seed (an integer >= 0), a numpy Generator or None, "
                         f"got {rng!r}")
    phase = np.random.default_rng(rng).uniform(0.0, 2.0 * np.pi, omega.size)
    flat = x.ravel()
    r = np.zeros(flat.size)
    # fixed blocks of points: each r(x) is computed from its block's points only, so a seed's
    # profile at x does not depend on the range sampled but to round-off (1e-13 of the profile); a
    # sweep samples fixed blocks of points (vtsi.passage.PROFILE_BLOCK), the same to the bit
    for p in range(0, flat.size, POINTS_PER_BLOCK):
        at = slice(p, p + POINTS_PER_BLOCK)
        step = _even_step(flat[at])
        if step is not None:
            r[at] = _chirp_sum(amplitude, omega, phase, d_omega, flat[p], step, flat[at].size)
            continue
        for s in range(0, omega.size, WAVES_PER_BLOCK):     # a work array of 512 waves x the block
            k = slice(s, s + WAVES_PER_BLOCK)
            r[at] += amplitude[k] @ np.cos(np.outer(omega[k], flat[at]) + phase[k, None])
    return r.reshape(x.shape)


class Irregularity:
    """A rail profile r(x) [m] (positive up) with derivatives, vectorised over x.

    Built from samples (a C² cubic spline through them, zero outside the sampled range unless
    ``extrapolate``) or from functions (:meth:`from_function`).

    Parameters
    ----------
    x : array_like, shape (n,)
        Strictly increasing positions [m], n ≥ 2.
    r : array_like, shape (n,)
        Profile values [m].
    extrapolate : bool
        Continue the end polynomials outside [x[0], x[-1]] instead of returning 0.

    Notes
    -----
    With the default, r jumps to 0 at the ends of the sampled range unless the samples end at 0:
    sample beyond the region the wheels cross, or taper the ends.
    """

    def __init__(self, x, r, extrapolate=False):
        x, r = as_numbers(x, "Irregularity", "x [m]"), as_numbers(r, "Irregularity", "r [m]")
        if x.ndim != 1 or x.shape != r.shape or x.size < 2:
            raise ModelError(f"Irregularity: x and r must be two 1-d arrays of the same length >= 2, "
                             f"got shapes {x.shape} and {r.shape}")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(r))):
            raise ModelError("Irregularity: x and r must be finite (NaN or inf found)")
        steps = np.diff(x)
        if np.any(steps <= 0):
            i = int(np.flatnonzero(steps <= 0)[0]) + 1
            raise ModelError(f"Irregularity: x must increase strictly; x[{i}] = {x[i]:g} follows x[{i - 1}] = {x[i - 1]:g}")
        spline = UniformCubic(scipy.interpolate.CubicSpline(x, r, extrapolate=True), zero_outside=not extrapolate)
        self._funcs = tuple(functools.partial(spline, nu=nu) for nu in range(3))
        self._range = None if extrapolate else (x[0], x[-1])
        self._sampled = True
        self._kinks = ()

    def __repr__(self):
        if not self._sampled:
            more = f", ... ({len(self._kinks)} kinks)" if len(self._kinks) > 4 else ""
            kinks = f", kinks at x = {', '.join(f'{x:g}' for x in self._kinks[:4])}{more} m" if self._kinks else ""
            return f"Irregularity(r(x) = {getattr(self._funcs[0], '__qualname__', repr(self._funcs[0]))}{kinks})"
        x = self._funcs[0].func.ppoly.x
        extent = "zero outside" if self._range is not None else "extrapolated outside"
        return (f"Irregularity({len(x)} samples, x = {x[0]:g} to {x[-1]:g} m ({extent}), "
                f"max |r| = {1e3 * np.abs(self(x)).max():.3g} mm)")

    @property
    def x_range(self):
        """Sampled range ``(x_first, x_last)`` [m] outside which r = 0, or None (defined everywhere)."""
        return None if self._range is None else (float(self._range[0]), float(self._range[1]))

    @property
    def kinks(self):
        """Positions [m] where r' jumps (r continuous), increasing: those :meth:`from_function`
        was told of; none for a sampled profile (a C² spline)."""
        return self._kinks

    @classmethod
    def from_function(cls, f, df=None, d2f=None, kinks=()):
        """A profile given by vectorised functions r = f(x), r' = df(x), r'' = d2f(x) (m, m/m, 1/m);
        the derivatives are optional, needed only if asked for.

        ``kinks``: the positions [m] where r' jumps (a ramp's start, a crest, the corners of a
        trapezoidal bump), finite and distinct, in any order (kept sorted). A coupled analysis
        with 'hermite' rows and ``exact_events=True`` takes each kink on rigid ground or at a
        support as an event, a wheel's velocity jump V Δr' by a perfectly inelastic impulse at
        its own time; with contact='lcp' and 'hermite' rows it refuses declared kinks without
        ``exact_events`` and kinks within a span (docs/theory/contact.md §4). A kink not declared
        cannot be seen: the analysis samples f, df, d2f at its stage times only, and under
        contact='lcp' an undeclared upward kink throws the wheel off the rail (a false flight that
        does not shrink with Δt). r itself must be continuous: a step in r is no kink."""
        values = as_numbers(() if kinks is None else kinks, "Irregularity.from_function", "kinks [m]")
        values = values.reshape(-1) if values.ndim == 0 else values          # one kink
        if values.ndim != 1:
            raise ModelError(f"Irregularity.from_function: kinks must be a sequence of positions [m], "
                             f"got an array of shape {values.shape}")
        if not np.all(np.isfinite(values)):
            bad = float(values[~np.isfinite(values)][0])
            raise ModelError(f"Irregularity.from_function: kinks must be finite, got {bad} m")
        values = np.sort(values)
        twice = values[1:][np.diff(values) == 0.0]
        if twice.size:
            raise ModelError(f"Irregularity.from_function: kink x = {twice[0]:g} m is given twice")
        self = cls.__new__(cls)
        self._funcs = (f, df, d2f)
        self._range = None
        self._sampled = False
        self._kinks = tuple(float(x) for x in values)
        return self

    @classmethod
    def from_psd(cls, psd, x, extrapolate=False, **kwargs):
        """``Irregularity(x, sample_profile(psd, x, **kwargs), extrapolate)``."""
        return cls(x, sample_profile(psd, x, **kwargs), extrapolate=extrapolate)

    def __call__(self, x, nu=0):
        """r(x) (``nu = 0``), r'(x) (1) or r''(x) (2); same shape as x [m, 1, 1/m]."""
        if nu not in (0, 1, 2):
            raise ModelError(f"Irregularity: derivative order nu must be 0, 1 or 2, got {nu!r}")
        func = self._funcs[nu]
        if func is None:
            raise ModelError(f"Irregularity: derivative {nu} of this profile was not given (from_function)")
        x = np.asarray(x, dtype=np.float64)
        if self._sampled:    # zero outside the sampled range unless extrapolating: UniformCubic does it
            return func(x)
        return np.asarray(func(x), dtype=np.float64) * np.ones_like(x)
