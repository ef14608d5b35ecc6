"""A sweep's speeds read against the EN 1991-2 6.4.6.2 series (docs/check.md, "The speed grid").

EN 1991-2 6.4.6.2 asks for the speeds up to 1.2 × the line speed in steps fine enough to catch
each resonance v = n D / i; ``vtsi sweep --speeds en:V`` runs that series
(:func:`vtsi.sweep.en_speed_grid`). A sweep of other speeds is read against the series over its
own range (:func:`en_series`): the resonances it steps across more coarsely than the series
(:func:`coarse_resonances`), which the check names and which leave a passing deck acceleration or
deflection not checked. Speeds in km/h, frequencies in Hz, lengths in m.
"""
from dataclasses import dataclass

import numpy as np

from vtsi.codes import en1991_2
from vtsi.sweep import en_speed_grid, resonance_speeds
from vtsi.sweep_results import deck_first_frequencies


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


COARSE_LISTED = 4           # resonances a note or the verdict names (then: 'and k more')


def _grid_frequencies(bridge):
    """``[(f [Hz], mode)]``: each deck's n₀, n₂, n₃ (/bridge/deck_frequencies_hz, mode 0, 1, 2),
    the frequencies whose resonances the EN series of ``vtsi sweep --speeds en:V`` resolves; in a
    results file of an older vtsi each deck's n₀ only."""
    if "deck_frequencies_hz" in bridge:
        table = np.asarray(bridge["deck_frequencies_hz"], dtype=float).reshape(-1, 3)
    else:
        table = deck_first_frequencies(bridge)[:, None]
    found = {}
    for row in table:
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
    """``{train: D [m]}``: the characteristic lengths the results file holds (trains without one left out)."""
    lengths = {t: float(results.train_data(t)["characteristic_length_m"]) for t in results.trains}
    return {t: D for t, D in lengths.items() if np.isfinite(D) and D > 0}


def en_series(results, bridge, line_speed_kmh=None):
    """The EN 1991-2 6.4.6.2 speed series [km/h] up to the sweep's top speed, as ``vtsi sweep
    --speeds en:V`` builds it (:func:`vtsi.sweep.en_speed_grid`, V the top speed / 1.2; each
    deck's n₀, n₂, n₃; the trains' D), from the sweep's lowest speed, or with the line speed
    known from 40 m/s (:func:`_series_start`); None for trains without D, or for a sweep of one
    speed without the line speed."""
    grid = np.unique(np.asarray(results.speeds_kmh, dtype=float))
    lengths = _train_lengths(results)
    if not lengths or (len(grid) < 2 and not line_speed_kmh):
        return None
    return en_speed_grid(grid[-1] / 1.2, [f for f, _ in _grid_frequencies(bridge)], list(lengths.values()),
                         start_kmh=_series_start(grid, line_speed_kmh))


def _series_start(grid, line_speed_kmh=None):
    """Where the EN series a sweep is read against starts [km/h]: the sweep's lowest speed; with
    the line speed known (a design check for it, :attr:`vtsi.check.CheckSettings.line_speed_kmh`)
    40 m/s, where EN 1991-2 6.4.6.2(1) starts it, unless the sweep starts lower or stops below it."""
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
    named too (step inf). Trains without D, or a sweep of one speed without the line speed,
    have none: nothing to compare."""
    grid = np.unique(np.asarray(results.speeds_kmh, dtype=float))
    lengths, en = _train_lengths(results), en_series(results, bridge, line_speed_kmh)
    if en is None:
        return []
    lo, hi = _series_start(grid, line_speed_kmh), float(grid[-1])
    freqs = _grid_frequencies(bridge)
    out = []
    for f, mode in freqs:
        for t, D in lengths.items():
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
    return sorted(out, key=lambda c: (c.mode, c.order, c.speed_kmh, c.train))


def coarse_text(coarse, listed=COARSE_LISTED):
    """The resonances ``coarse`` (:func:`coarse_resonances`) in words, the first ``listed`` named."""
    named = "; ".join(c.text() for c in coarse[:listed])
    more = len(coarse) - listed
    return named + (f"; and {more} more" if more > 0 else "")
