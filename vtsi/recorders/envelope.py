"""Running envelopes: min, max and absolute max of every column, with the time of each.

Updated once per chunk, vectorised over the chunk (``argmin``/``argmax`` along time), and
readable at any moment. Ties keep the first occurrence (a later value must be strictly
smaller / larger to replace it), which is what OpenSees's ``EnvelopeNode`` and
``EnvelopeElement`` recorders do: their absmax row equals ``max(|min|, |max|)`` and its time
is the time of that extreme.
"""
import numpy as np


class Envelope:
    """Running extremes of ``n`` columns.

    Attributes (each ``(n,)`` float64; NaN until the first recorded step)
    ----------------------------------------------------------------------
    min, max, absmax : extremes (absmax >= 0) in the recorder's units.
    time_of_min, time_of_max, time_of_absmax : time [s] at which each was first reached.
    n_records : number of steps folded in so far.
    """

    FIELDS = ("min", "max", "absmax", "time_of_min", "time_of_max", "time_of_absmax")

    def __init__(self, n=0):
        self.n_records = 0
        self.resize(n)

    def resize(self, n):
        """Set the number of columns (keeps the values when it does not change)."""
        if getattr(self, "min", None) is not None and len(self.min) == n:
            return
        for name in self.FIELDS:
            setattr(self, name, np.full(n, np.nan))
        self.n_records = 0

    def update(self, times, values):
        """Fold ``values (m, n)`` recorded at ``times (m,)`` into the envelope."""
        m = len(times)
        if m == 0:
            return
        cols = np.arange(values.shape[1])
        absval = np.abs(values)
        candidates = (
            ("min", "time_of_min", np.argmin(values, axis=0), values, np.less),
            ("max", "time_of_max", np.argmax(values, axis=0), values, np.greater),
            ("absmax", "time_of_absmax", np.argmax(absval, axis=0), absval, np.greater),
        )
        for name, tname, idx, source, better in candidates:
            value, when = source[idx, cols], times[idx]
            current, current_time = getattr(self, name), getattr(self, tname)
            if self.n_records == 0:
                current[:], current_time[:] = value, when
            else:
                mask = better(value, current)
                current[mask], current_time[mask] = value[mask], when[mask]
        self.n_records += m

    def as_dict(self):
        return {name: getattr(self, name).copy() for name in self.FIELDS}
