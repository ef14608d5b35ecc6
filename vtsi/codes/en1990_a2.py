"""EN 1990:2002 Annex A2 (application for bridges), A2.4.4: deck accelerations of railway
bridges.

Units: frequencies [Hz], accelerations [m/s²].
"""
import numpy as np

from vtsi.errors import ModelError, number_array


def acceleration_cutoff_hz(frequencies):
    """A2.4.4.2.1(4)P: deck accelerations count frequencies up to the largest of 30 Hz, 1.5 n₀
    and n₃ [Hz], from the bridge's first vertical frequencies (n₀ first; n₃ the third: the
    first three modes count, so fewer than three given is refused)."""
    f = number_array(frequencies)
    f = None if f is None else f.ravel()
    if f is None or f.size < 3 or not np.all(np.isfinite(f) & (f > 0)) or np.any(np.diff(f) < 0):
        raise ModelError(f"EN 1990 A2.4.4.2.1: the cut-off needs the first three vertical frequencies > 0 [Hz], "
                         f"in increasing order (n0 first), got {frequencies!r}")
    return float(max(30.0, 1.5 * f[0], f[2]))


# A2.4.4.2.1(4)P: peak deck acceleration limits [m/s²] by track form.
DECK_ACCELERATION_LIMITS = {"ballasted": 3.5, "direct_fastening": 5.0}
# A2.4.4.3.1, Table A2.9: vertical car-body acceleration b_v [m/s²] by level of comfort.
COMFORT_LIMITS = {"very_good": 1.0, "good": 1.3, "acceptable": 2.0}
# A2.4.4.2.3(1): total vertical deflection under the classified rail traffic actions ≤ L / 600.
DEFLECTION_SPAN_RATIO = 600.0


def deck_acceleration_limit(track):
    """A2.4.4.2.1(4)P: γ_bt = 3.5 m/s² (ballasted track) or γ_df = 5 m/s² (direct fastening)."""
    if not isinstance(track, str) or track not in DECK_ACCELERATION_LIMITS:
        raise ModelError(f"EN 1990 A2.4.4.2.1: unknown track form {track!r}; valid: {', '.join(DECK_ACCELERATION_LIMITS)}")
    return DECK_ACCELERATION_LIMITS[track]


def comfort_limit(level):
    """Table A2.9: b_v = 1.0 (very good), 1.3 (good), 2.0 (acceptable) m/s²."""
    if not isinstance(level, str) or level not in COMFORT_LIMITS:
        raise ModelError(f"EN 1990 A2 Table A2.9: unknown level of comfort {level!r}; valid: {', '.join(COMFORT_LIMITS)}")
    return COMFORT_LIMITS[level]
