"""A sweep's speeds read against the EN 1991-2 6.4.6.2 series (docs/check.md, "The speed grid").

EN 1991-2 6.4.6.2 asks for the speeds up to 1.2 × the line speed in steps fine enough to catch
each resonance v = n D / i; ``vtsi sweep --speeds en:V`` runs that series
(:func:`vtsi.sweep.en_speed_grid`). A sweep of other speeds is read against the series over its
own range (:func:`en_series`): the resonances it steps across more coarsely than the series
(:func:`coarse_resonances`), and the trains without a characteristic length D, whose resonances
are unknown and for which the series steps finely throughout, over whose speeds it steps more
coarsely (:class:`UnknownResonances`); the check names them, and they leave a passing criterion
that peaks at resonance (deck acceleration, deflection, car-body acceleration, wheel unloading,
contact loss) not checked. Speeds in km/h, frequencies in Hz, lengths in m.
"""
from dataclasses import dataclass

import numpy as np

from vtsi.codes import en1991_2
from vtsi.damping import deck_frequencies_table
from vtsi.sweep import en_speed_grid, resonance_speeds


@dataclass(frozen=True)
class CoarseResonance:
    """A resonance speed v = n D / i inside a sweep's speeds that they step across more coarsely
    than the EN series (:func:`coarse_resonances`)."""

    train: str
    speed_kmh: float            # v = n D / i [km/h]
    frequency_hz: float         # n: a deck's n₀, n₂ or n₃ [Hz]
    mode: int                   # which of the deck's frequencies: 0 (n₀), 1 (n₂), 2 (n₃)
    order: int                  # i
    step_kmh: float             # the sweep's step across v [km/h]
    en_step_kmh: float          # the EN series' step there [km/h]

    def text(self):
        """'ICE3 D/3 at 232.4 km/h (n0 7.812 Hz): step 6 km/h'; a resonance below the speeds
        swept (step inf): '...: below the speeds swept'."""
        return (f"{self.train} D/{self.order} at {self.speed_kmh:.4g} km/h (n{('0', '2', '3')[self.mode]} "
                f"{self.frequency_hz:.4g} Hz): "
                + (f"step {self.step_kmh:.3g} km/h" if np.isfinite(self.step_kmh) else "below the speeds swept"))


@dataclass(frozen=True)
class UnknownResonances:
    """A train without a characteristic length D (its resonance speeds unknown, so that the EN
    series steps finely over its whole range, :func:`vtsi.sweep.en_speed_grid`) whose speeds a
    sweep steps more coarsely than that series (:func:`coarse_resonances`)."""

    train: str
    step_kmh: float             # the sweep's largest step over the range compared [km/h]; inf: it starts above it
    en_step_kmh: float          # the EN series' largest step there [km/h]
    first_kmh: float            # the sweep's first speed [km/h]

    def text(self):
        """'regional.csv has no characteristic length D (its resonances are unknown): step 10 km/h
        where the EN series steps 2 km/h'; a sweep that starts above the series (step inf): '...:
        the speeds swept start at 200 km/h, above the EN series' 144 km/h'."""
        return (f"{self.train} has no characteristic length D (its resonances are unknown): "
                + (f"step {self.step_kmh:.3g} km/h where the EN series steps {self.en_step_kmh:.3g} km/h"
                   if np.isfinite(self.step_kmh) else
                   f"the speeds swept start at {self.first_kmh:g} km/h, above the EN series' "
                   f"{en1991_2.SPEED_SERIES_START_KMH:g} km/h"))


COARSE_LISTED = 4           # resonances a note or the verdict names (then: 'and k more')


def _grid_frequencies(bridge):
    """``[(f [Hz], mode)]``: each deck's n₀, n₂, n₃ (:func:`~vtsi.damping.deck_frequencies_table`,
    mode 0, 1, 2), the frequencies whose resonances the EN series of ``vtsi sweep --speeds en:V``
    resolves."""
    found = {}
    for row in deck_frequencies_table(bridge):
        for mode, f in enumerate(row):
            if np.isfinite(f) and f > 0:
                found.setdefault(round(float(f), 9), mode)
    return sorted((f, m) for f, m in found.items())


def _step_across(grid, v, reach=0.0):
    """The largest step [km/h] of the sorted speeds ``grid`` across ``v`` [km/h]: between the last
    speed at or below v - ``reach`` and the first at or above v + ``reach`` (the ends of the grid
    where it stops short); a speed on v (within 1e-6 km/h) counts its steps on both sides."""
    tol = 1e-6
    lo = max(int(np.searchsorted(grid, v - reach + tol, side="right")) - 1, 0)
    hi = min(int(np.searchsorted(grid, v + reach - tol, side="left")), len(grid) - 1)
    if hi <= lo:
        lo, hi = max(lo - 1, 0), min(lo + 1, len(grid) - 1)
    return float(np.max(np.diff(grid[lo: hi + 1]))) if hi > lo else 0.0


def _train_lengths(results):
    """``{train: D [m]}``: the characteristic lengths the results file holds, NaN for a train without one."""
    lengths = {t: float(results.train_data(t)["characteristic_length_m"]) for t in results.trains}
    return {t: D if np.isfinite(D) and D > 0 else np.nan for t, D in lengths.items()}


def en_series(results, bridge, line_speed_kmh=None):
    """The EN 1991-2 6.4.6.2 speed series [km/h] up to the sweep's top speed, as ``vtsi sweep
    --speeds en:V`` builds it (:func:`vtsi.sweep.en_speed_grid`, V the top speed / 1.2; each
    deck's n₀, n₂, n₃; the trains' D, fine steps throughout when a train has none), from the
    sweep's lowest speed, or with the line speed known from 40 m/s (:func:`_series_start`); None
    for a sweep of one speed without the line speed."""
    grid = np.unique(np.asarray(results.speeds_kmh, dtype=float))
    lengths = _train_lengths(results)
    if len(grid) < 2 and not line_speed_kmh:
        return None
    return en_speed_grid(grid[-1] / 1.2, [f for f, _ in _grid_frequencies(bridge)], list(lengths.values()),
                         start_kmh=_series_start(grid, line_speed_kmh))


def _series_start(grid, line_speed_kmh=None):
    """Where the EN series a sweep is read against starts [km/h]: the sweep's lowest speed; with
    the line speed known (a design check for it, :attr:`vtsi.check.CheckSettings.line_speed_kmh`)
    40 m/s, where EN 1991-2 6.4.6.2(3) starts it, unless the sweep starts lower or stops below it."""
    start = en1991_2.SPEED_SERIES_START_KMH
    return float(min(start, grid[0]) if line_speed_kmh and grid[-1] > start else grid[0])


def coarse_resonances(results, bridge, line_speed_kmh=None):
    """The resonance speeds v = n D / i (:func:`vtsi.sweep.resonance_speeds`; n each deck's n₀,
    n₂, n₃, D each train's characteristic length) inside the sweep's speeds that they step across
    more coarsely than the EN 1991-2 6.4.6.2 series does (:func:`vtsi.sweep.en_speed_grid` over the
    same range: 10 km/h steps, finer ones near each resonance): ``[CoarseResonance]`` by n, then
    i, then v. The sweep's step across v is its largest between the speeds either side of it;
    the EN series' is its largest over that same stretch (so that a speed of the EN series on v
    itself does not count as a finer step). With ``line_speed_kmh`` (a design check for a line
    speed) the series starts at 40 m/s, and the resonances below the sweep's first speed are
    named too (step inf). A train without D, whose resonances are unknown and for which the
    series steps finely throughout, gives an :class:`UnknownResonances` (listed first) when the
    sweep's largest step over the range compared is coarser than the series' there (inf when,
    with the line speed, the sweep starts above the series). A sweep of one speed without the
    line speed has none: nothing to compare."""
    grid = np.unique(np.asarray(results.speeds_kmh, dtype=float))
    lengths, en = _train_lengths(results), en_series(results, bridge, line_speed_kmh)
    if en is None:
        return []
    lo, hi = _series_start(grid, line_speed_kmh), float(grid[-1])
    freqs = _grid_frequencies(bridge)
    step = np.inf if lo < grid[0] - 1e-6 else (float(np.max(np.diff(grid))) if len(grid) > 1 else 0.0)
    en_step = float(np.max(np.diff(en))) if len(en) > 1 else 0.0
    unknown = [UnknownResonances(t, step, en_step, float(grid[0])) for t, D in lengths.items()
               if np.isnan(D) and step > en_step * (1 + 1e-6) + 1e-9]
    known = {t: D for t, D in lengths.items() if not np.isnan(D)}
    out = []
    for f, mode in freqs:
        for t, D in known.items():
            for v in resonance_speeds([f], [D]):
                v = float(v)
                if not lo - 1e-6 <= v <= hi + 1e-6:
                    continue
                if v < grid[0] - 1e-6:          # below the speeds swept: not read at all
                    out.append(CoarseResonance(t, v, f, mode, int(round(3.6 * f * D / v)), np.inf, 0.0))
                    continue
                step = _step_across(grid, v) if len(grid) > 1 else 0.0
                en_step = _step_across(en, v, reach=step)
                if step > en_step * (1 + 1e-6) + 1e-9:
                    out.append(CoarseResonance(t, v, f, mode, int(round(3.6 * f * D / v)), step, en_step))
    return unknown + sorted(out, key=lambda c: (c.mode, c.order, c.speed_kmh, c.train))


def coarse_text(coarse, listed=COARSE_LISTED):
    """The resonances (and trains without D) ``coarse`` (:func:`coarse_resonances`) in words, the
    first ``listed`` named."""
    named = "; ".join(c.text() for c in coarse[:listed])
    more = len(coarse) - listed
    return named + (f"; and {more} more" if more > 0 else "")
