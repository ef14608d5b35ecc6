"""A train's dynamic signature and the characteristic length D it gives an axle table
(docs/trains.md, "D from the dynamic signature").

The signature of N axle loads F_k at positions x_k along the train (increasing; G does not
depend on their origin) is, for a wavelength λ [m],

    G(λ) = max over i = 1 … N of | Σ_{k=1..i} F_k exp(2πj x_k / λ) |,

in the units of F (N or kN): proportional to the largest free-vibration amplitude the axles
build up, one after the other, in a mode excited at wavelength λ = v / n (speed v [m/s],
frequency n [Hz]). ERRI D214's DER method (decomposition of the excitation at resonance) bounds a
span's resonant response by this signature with the bridge's damping ζ in it, term k decaying as
exp(−2πζ (x_i − x_k)/λ) over the distance since axle k passed; vtsi takes ζ = 0, where G depends
on the train alone. A single axle has G = F at every λ; two axles F a distance d apart have
G = max(F, 2F |cos(π d / λ)|).

A train of N_c identical coaches of length D adds their phasors in step at λ = D / i, so G peaks
there and grows with N_c. :func:`principal_wavelength` takes the signature's highest peak
between 12 and 30 m (:data:`WAVELENGTH_RANGE_M`) and, as D, the axle spacing s that recurs for
the most axles with s / i inside that peak, i = 1 … 4: the peak is D or one of its harmonics
(D/2 for coaches whose bogie centres, a third to two thirds of their length apart, weaken their
own phasor at D), and the train's period recurs most often; a table without a recurring spacing
there gets none. A peak below the range more than :data:`DOMINANCE` times higher is read the same
way, at orders up to 12 (two-axle wagons of 12-20 m peak at L/3), unless a spacing shorter than
the range recurs there as often (wagons shorter than the range: no D).

References
----------
ERRI D214 Committee (1999), Rail bridges for speeds higher than 200 km/h, Report RP9 (DER and
LIR methods, the signature of the train). Domínguez Barbero, J. (2001), Dinámica de puentes de
ferrocarril para alta velocidad: métodos de cálculo y estudio de la resonancia, PhD thesis, UPM
Madrid. Goicolea, J. M., Domínguez, J., Navarro, J. A., Gabaldón, F. (2002), New dynamic analysis
methods for railway bridges in codes IAPF and Eurocode 1, Railway Bridges Design, Construction
and Maintenance, Madrid.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from vtsi.errors import ModelError

WAVELENGTH_RANGE_M = (12.0, 30.0)
"""[m] Where :func:`principal_wavelength` looks for the signature's peak. Coaches run from 13.14 m
(Talgo) to 26.4-27.5 m (UIC-Z and double-deck coaches); EN 1991-2's HSLM-A spans D = 18-27 m
(Table 6.3), the trains its Annex E lets it stand for. The range adds about the half-width of a
100 m train's peak (D² / (2 × 100 m): 0.85 m at 13 m, 3.6 m at 27 m) at either end, so that such
a D is an interior peak, and starts at 12 m, below which lie the D/2 harmonics of coaches of up
to 24 m."""
SAMPLES_PER_LOBE = 8
"""Coarse samples of the signature per half-width of its peaks: in wavenumber 1/λ a peak's main
lobe reaches ±1/L from its top (L the distance from the first to the last axle), so the grid
steps 1/(8 L) and its highest sample lies on the highest peak's lobe, within 1/(16 L) of its top."""
SPACING_BAND_M = 0.2
"""[m] Axle spacings that agree within this band count as one spacing: axle positions read to
0.1 m (each rounded by up to 0.05 m) still repeat a coach length within it."""
MIN_SHARE = 0.4
"""A spacing is regular (the train has a D) when at least this share of the axles has another
axle that spacing behind it (spacings within :data:`SPACING_BAND_M` counted as one): N_c
identical coaches give (N_c − 1) / N_c of their axles, fewer with locomotives (two ICE3 cars 0.5,
HSLM-A10 0.61, 13 Talgo axles between two locomotives 0.57; 2518 sampled trains of 4-14 coaches
of 24-27.5 m with 0-2 locomotives at least 0.43, three coaches between two six-axle locomotives
0.33); 18000 seeded irregular random tables of 24-200 axles reached at most 0.33, 30000 of 24-40
axles in random bogies at most 0.385 (0.31 and 0.382 with D also read below the range, :data:`DOMINANCE`;
docs/trains.md; tests/test_train_signature.py runs 120)."""
BELOW_RANGE = 3
"""The signature is also read between low / BELOW_RANGE and low (4 to 12 m), where only the
harmonics D/i of coaches in the range peak, at most 0.96 of their peak in it (ICE3; HSLM-A
0.50-0.74, the trains of tests/test_train_signature.py 0.63-0.90), up to 1.86 where the coaches
cancel their own phasor at D (2160 trains of 24-27.5 m coaches on bogies 15-19 m apart; the
regional train of tests/test_no_d_grid.py 1.42), while a train of wagons shorter than low peaks
there 6 to 34 times higher than anywhere in the range (40 two-axle wagons of 7-11 m): then every
spacing recurs, multiples of the wagon length inside the range too, and the range's peak (a
sidelobe) would give a false D. So do two-axle wagons of the range whose wheelbase, about 2/3 of
their length L, makes their own phasor weaker at L than at L/3 (or L/5). The grid runs a peak
half-width 1/L past low / BELOW_RANGE, so that a peak at its end is interior."""
DOMINANCE = 2.0
"""A peak below the range this many times the range's highest is the train's own, and D is read
there instead: the spacing of at least low that recurs most at an order i ≤ HARMONICS ×
BELOW_RANGE of it (D ≤ 4 low at a peak down to low / 3), none when a spacing shorter than low
recurs for as many axles (wagons shorter than the range, every multiple of whose length recurs
too) or when the signature still rises at the grid's end (see BELOW_RANGE)."""
MIN_REPEATS = 4
"""... and at least this many axles (two identical four-axle coaches), so that a spacing met by
chance in a short table (a single coach's bogie spacing: 2 axles) is not a D."""
HARMONICS = 4
"""The signature's peak λ* may be a harmonic D/i of the train's D for i = 1 … HARMONICS, the
orders around whose resonance speeds v = n₀ D / i the EN 1991-2 6.4.6.2 series refines
(:func:`vtsi.sweep.resonance_speeds`): so the series of the D read at the peak refines around
n₀ λ*, the speed at which the signature is highest."""
_CHUNK = 1 << 16                       # terms per block of wavelengths (0.5 MB arrays)


@dataclass(frozen=True)
class SignaturePeak:
    """The highest peak of a train's signature in a range of wavelengths and the axle spacing that
    recurs inside it (:func:`principal_wavelength`).

    Attributes
    ----------
    wavelength_m : float or None
        λ* [m], the peak D is read at: the signature's highest interior peak in
        ``wavelength_range_m``, or the highest below it when the signature below the range
        dominates (``below_m``); None when the signature has no peak there (it rises or falls
        across the whole range, or, dominated, below it).
    signature : float
        G(λ*), in the units of the loads; NaN without a peak.
    length_m : float or None
        D [m], to 1 mm: the median of the axle spacings s within :data:`SPACING_BAND_M` that
        recur most often with s / i inside the peak's main lobe (|i/s − 1/λ*| ≤ 1/L for an order
        i = 1 … :data:`HARMONICS`: :func:`principal_wavelength`); None when fewer than
        :data:`MIN_SHARE` of the axles, or fewer than :data:`MIN_REPEATS`, have another axle
        that far behind them (no regular spacing), when a peak below the range gives a spacing
        shorter than the range (wagons shorter than it), or without a peak.
    repeats : int
        How many axles have another axle the recurring spacing behind them.
    share : float
        ``repeats`` / the number of axles [-].
    wavelength_range_m : tuple of float
        The range searched [m].
    below_m : float or None
        Where the signature's highest peak lies [m] when it lies below the range and is more
        than :data:`DOMINANCE` times the range's (wagons shorter than the range, or two-axle
        wagons in it peaking at a harmonic D/i: :data:`DOMINANCE`), λ* then; else None.
    length_unit : str
        The unit of the lengths above: 'm', unless :meth:`vtsi.units.Units.train` converted the
        peak into a model's units (then 'cm' or 'mm').
    """

    wavelength_m: float | None
    signature: float
    length_m: float | None
    repeats: int
    share: float
    wavelength_range_m: tuple
    below_m: float | None = None
    length_unit: str = "m"

    def text(self):
        """'D = 24.775 m from its dynamic signature', or why the signature gives no D (lengths in
        ``length_unit``)."""
        u = self.length_unit
        if self.length_m is not None:
            return f"D = {self.length_m:g} {u} from its dynamic signature"
        lo, hi = self.wavelength_range_m
        if self.below_m is not None and (self.wavelength_m is None or
                                         (self.share >= MIN_SHARE and self.repeats >= MIN_REPEATS)):
            where = "" if self.wavelength_m is not None else " or below"       # G rising to the grid's end
            why = (f"its signature peaks at {self.below_m:.4g} {u}{where}, below the {lo:g}-{hi:g} {u} of coaches, "
                   f"more than {DOMINANCE:g} times higher than within them: wagons shorter than {lo:g} {u}, whose D "
                   "is not read")
        elif self.wavelength_m is None:
            why = f"it has no peak between {lo:g} and {hi:g} {u}"
        elif self.share < MIN_SHARE:
            why = (f"no regular axle spacing at its peak, {self.wavelength_m:.4g} {u}: {100 * self.share:.0f} % of "
                   f"the axles repeat there, a D needs {100 * MIN_SHARE:.0f} %")
        else:
            why = (f"no regular axle spacing at its peak, {self.wavelength_m:.4g} {u}: {self.repeats} axles repeat "
                   f"there, a D needs {MIN_REPEATS}")
        return f"no characteristic length D from its dynamic signature ({why})"


def signature(positions, loads, wavelengths):
    """The train's signature G(λ) (module docstring) at each wavelength.

    Parameters
    ----------
    positions : array_like, shape (n_axles,)
        Axle positions along the train [m], strictly increasing (offsets behind the head, or
        positions from the first axle: G does not depend on the origin).
    loads : array_like, shape (n_axles,)
        Axle loads F_k > 0 [N, kN or any force unit].
    wavelengths : array_like
        λ > 0 [m], any shape.

    Returns
    -------
    ndarray, the shape of ``wavelengths``
        G(λ), in the units of ``loads``.
    """
    x, F = _axles(positions, loads, "signature")
    lam = np.asarray(wavelengths, dtype=float)
    if lam.size == 0 or not np.all(np.isfinite(lam) & (lam > 0)):
        raise ModelError(f"signature: wavelengths must be finite and > 0 [m], got {wavelengths!r}")
    return _signature(x, F, lam.ravel()).reshape(lam.shape)


def principal_wavelength(positions, loads, wavelength_range=WAVELENGTH_RANGE_M) -> SignaturePeak:
    """The signature's highest peak in ``wavelength_range`` and the train's characteristic length D.

    The signature is sampled on a grid uniform in wavenumber 1/λ (:data:`SAMPLES_PER_LOBE`); its
    highest interior local maximum is refined by a bounded Brent search in 1/λ between the
    samples either side, to 1e-9 of 1/λ. The peak is not D itself: each coach's own phasor
    varies with λ and pulls the peak of the whole train off D (ICE3: 24.456 m for 24.775 m; a
    Talgo between two locomotives 12.64 m for 13.14 m), while D stays the spacing at which the
    coaches' phasors add exactly in step. N coaches of length D multiply their own phasor by
    sin(πND/λ) / sin(πD/λ), whose main lobes stand at 1/λ = i/D with their first zeros 1/(ND)
    either side: the same half-width, about 1/L (L from the first to the last axle), at every
    harmonic i. So λ* lies within 1/L of some i/D, and D is the axle spacing s that recurs for
    the most axles among those with |i/s − 1/λ*| ≤ 1/L for an order i = 1 … :data:`HARMONICS`.
    Most trains peak at D itself (i = 1); a coach of 24-30 m whose bogie centres lie a apart,
    D/3 < a < 2D/3, has |cos(π a/D)| < 1/2 < |cos(2π a/D)|, its own phasor weaker at D than at
    D/2, and the train may peak at D/2 (the regional train of tests/test_no_d_grid.py, coaches of
    26.4 m on bogies 17.2 m apart: at 13.09 m), where no spacing, or a bogie spacing of some of
    each coach's axles, recurs. Among the harmonics the
    train's period recurs most often: every axle of N − 1 of N identical coaches has one D
    behind it; 2D, those of N − 2; a bogie spacing, some of each coach's axles (as many as D
    with two coaches: ties go to the longer spacing, and no spacing inside a coach is longer
    than D). Spacings within :data:`SPACING_BAND_M` count as one, their median rounded to 1 mm;
    D is kept if it is regular (:data:`MIN_SHARE`, :data:`MIN_REPEATS`). When the signature
    between low / :data:`BELOW_RANGE` and low is more than :data:`DOMINANCE` times the range's, its
    highest peak there is λ* instead, read at orders up to HARMONICS × BELOW_RANGE (two-axle
    wagons of 15.5 m on a 10 m wheelbase peak at 5.17 m = D/3), and D is None when a spacing
    shorter than low recurs there for as many axles (wagons shorter than the range).

    Parameters
    ----------
    positions, loads : array_like, shape (n_axles,)
        As for :func:`signature`.
    wavelength_range : (float, float)
        [m], 0 < low < high.

    Returns
    -------
    SignaturePeak
    """
    x, F = _axles(positions, loads, "principal_wavelength")
    try:
        lo, hi = (float(v) for v in wavelength_range)
    except (TypeError, ValueError):
        lo = hi = math.nan
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ModelError(f"principal_wavelength: wavelength_range must be two lengths 0 < low < high [m], "
                         f"got {wavelength_range!r}")
    span = float(x[-1] - x[0])
    none = SignaturePeak(None, math.nan, None, 0, 0.0, (lo, hi))
    if span == 0.0:
        return none
    in_range = max(16, math.ceil(SAMPLES_PER_LOBE * span * (1 / lo - 1 / hi)) + 1)
    step = (1 / lo - 1 / hi) / (in_range - 1)
    k = np.concatenate([np.linspace(1 / hi, 1 / lo, in_range),           # the same grid on, to a lobe
                        np.arange(1 / lo + step, BELOW_RANGE / lo + 1 / span + step, step)])   # beyond lo / 3
    G = _signature(x, F, 1 / k)
    interior = np.flatnonzero((G[1:-1] > G[:-2]) & (G[1:-1] >= G[2:])) + 1
    if G[in_range:].max(initial=0.0) > DOMINANCE * G[:in_range].max():   # the range holds sidelobes only
        m = in_range + int(np.argmax(G[in_range:]))
        if m == k.size - 1:                         # its peak lies below lo / 3: wagons shorter than lo
            return SignaturePeak(None, math.nan, None, 0, 0.0, (lo, hi), below_m=float(1 / k[m]))
        k_peak, G_peak = _refined_peak(x, F, k, G, m)
    else:
        interior = interior[interior < in_range - 1]
        if interior.size == 0:
            return none
        k_peak, G_peak = _refined_peak(x, F, k, G, int(interior[np.argmax(G[interior])]))
    below_m = float(1 / k_peak) if k_peak > 1 / lo else None
    orders = HARMONICS if below_m is None else HARMONICS * BELOW_RANGE
    D, repeats = _recurring_spacing(x, k_peak, span, orders)
    if below_m is not None:
        short = _recurring_spacing(x, k_peak, span, orders, shorter_than=lo)[1]
        if short >= repeats:                # a spacing shorter than lo recurs most: wagons shorter than lo
            D, repeats = None, short
    share = repeats / x.size
    regular = share >= MIN_SHARE and repeats >= MIN_REPEATS
    return SignaturePeak(float(1 / k_peak), float(G_peak), D if regular else None, repeats, share, (lo, hi), below_m)


def _refined_peak(x, F, k, G, m):
    """(1/λ* [1/m], G(λ*)): the local maximum ``G[m]`` of the signature sampled at wavenumbers ``k``,
    refined by a bounded Brent search between its neighbours to 1e-9 of 1/λ (the sample if that
    is higher)."""
    found = minimize_scalar(lambda q: -_signature(x, F, np.array([1 / q]))[0], bounds=(k[m - 1], k[m + 1]),
                            method="bounded", options={"xatol": 1e-9 * k[m]})
    return (found.x, -found.fun) if -found.fun >= G[m] else (k[m], G[m])


def _recurring_spacing(x, k_peak, span, orders, shorter_than=math.inf):
    """(D [m] to 1 mm, repeats): the axle spacing s < ``shorter_than`` [m] with |i/s − k_peak| ≤
    1/span for an order i = 1 … ``orders`` that most axles have another axle behind them at
    (within SPACING_BAND_M), the longest of those tied, and how many axles do; (None, 0) when no
    spacing lies there."""
    first, second = np.triu_indices(x.size, 1)
    s = x[second] - x[first]
    keep = s < shorter_than
    s, first = s[keep], first[keep]
    lowest = np.maximum(np.ceil(s * (k_peak - 1 / span)), 1)            # the orders i in the lobe:
    highest = np.minimum(np.floor(s * (k_peak + 1 / span)), orders)       # s (k − 1/L) ≤ i ≤ s (k + 1/L)
    inside = lowest <= highest
    s, first = s[inside], first[inside]
    if s.size == 0:
        return None, 0
    order = np.argsort(s, kind="stable")
    s, first = s[order], first[order]
    end = np.searchsorted(s, s + SPACING_BAND_M, side="right")
    axles = np.array([np.unique(first[a:b]).size for a, b in zip(range(s.size), end)])
    best = np.flatnonzero(axles == axles.max())
    middle = np.array([np.median(s[a:end[a]]) for a in best])
    a = int(np.argmax(middle))                     # a tie: the longest
    return round(float(middle[a]), 3), int(axles[best[a]])


def _signature(x, F, lam):
    """G(λ) for validated axles ``x`` [m], ``F`` and wavelengths ``lam`` (1-d) [m], in blocks of
    wavelengths of at most _CHUNK terms (cos and sin in place: half the time of complex exp)."""
    out = np.empty(lam.size)
    rel = x - x[0]
    step = max(1, _CHUNK // x.size)
    for start in range(0, lam.size, step):
        phase = (2 * np.pi / lam[start:start + step])[:, None] * rel[None, :]
        re = np.cos(phase)
        re *= F
        np.cumsum(re, axis=1, out=re)
        im = np.sin(phase, out=phase)
        im *= F
        np.cumsum(im, axis=1, out=im)
        re *= re
        im *= im
        re += im
        out[start:start + step] = np.sqrt(re.max(axis=1))
    return out


def _axles(positions, loads, where):
    """(x, F) as float arrays: equal 1-d shapes, x finite and strictly increasing, F finite and > 0;
    else a ModelError naming ``where`` and the first bad value."""
    try:
        x = np.asarray(positions, dtype=float)
        F = np.asarray(loads, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{where}: positions and loads must be numbers, got {positions!r} and {loads!r}") from None
    if x.ndim != 1 or x.shape != F.shape or x.size == 0:
        raise ModelError(f"{where}: positions and loads must be 1-d arrays of equal, non-zero length, "
                         f"got shapes {x.shape} and {F.shape}")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ModelError(f"{where}: axle {bad[0]}: position must be finite, got {x[bad[0]]}")
    bad = np.flatnonzero(np.diff(x) <= 0)
    if bad.size:
        i = bad[0] + 1
        raise ModelError(f"{where}: axle {i}: position {x[i]} m is not greater than the previous {x[i - 1]} m")
    bad = np.flatnonzero(~(np.isfinite(F) & (F > 0)))
    if bad.size:
        raise ModelError(f"{where}: axle {bad[0]}: load must be > 0, got {F[bad[0]]:g}")
    return x, F
