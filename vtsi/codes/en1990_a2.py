"""EN 1990:2002 Annex A2 (application for bridges), A2.4.4: deck accelerations of railway
bridges.

Units: frequencies [Hz], accelerations [m/s²].
"""
import numpy as np

from vtsi.errors import ModelError


def acceleration_cutoff_hz(frequencies):
    """A2.4.4.2.1(4)P: deck accelerations count frequencies up to the largest of 30 Hz, 1.5 n₀
    and n₃ [Hz], from the bridge's first vertical frequencies (n₀ first; n₃ the third: the
    first three modes count, so fewer than three given is refused)."""
    f = np.asarray(frequencies, dtype=float).ravel()
    if f.size < 3 or not np.all(np.isfinite(f) & (f > 0)):
        raise ModelError(f"EN 1990 A2.4.4.2.1: the cut-off needs the first three vertical frequencies > 0 [Hz], "
                         f"got {f.tolist()}")
    return float(max(30.0, 1.5 * f[0], f[2]))
