"""Running envelopes: min, max and absolute max of every column, with the time of each, and
optionally the concurrent values: every column of the recorder at the step each extreme was
reached (the shear that goes with the largest moment, the moment with the largest shear).

Updated once per chunk, vectorised over the chunk (``argmin``/``argmax`` along time), and
readable at any moment. Ties keep the first occurrence (a later value must be strictly
smaller / larger to replace it), which is what OpenSees's ``EnvelopeNode`` and
``EnvelopeElement`` recorders do: their absmax row equals ``max(|min|, |max|)`` and its time
is the time of that extreme.
"""
import numpy as np


class Envelope:
    """Running extremes of ``n`` columns.

    Attributes (float64; NaN until the first recorded step)
    -------------------------------------------------------
    min, max, absmax : ``(n,)`` extremes (absmax >= 0) in the recorder's units.
    time_of_min, time_of_max, time_of_absmax : ``(n,)`` time [s] at which each was first reached.
    concurrent_min, concurrent_max, concurrent_absmax : ``(n, n)``, with ``concurrent=True``
        only: row j holds every column's value at the step where column j reached its extreme
        (signed values; ``concurrent_max[j, j] == max[j]``, ``|concurrent_absmax[j, j]| ==
        absmax[j]``).
    n_records : number of steps folded in so far.
    """

    FIELDS = ("min", "max", "absmax", "time_of_min", "time_of_max", "time_of_absmax")
    CONCURRENT = ("concurrent_min", "concurrent_max", "concurrent_absmax")

    def __init__(self, n=0, concurrent=False):
        self.concurrent = bool(concurrent)
        self.n_records = 0
        self.resize(n)

    @property
    def fields(self):
        """The names of the arrays this envelope keeps: FIELDS, then CONCURRENT if it keeps them."""
        return self.FIELDS + (self.CONCURRENT if self.concurrent else ())

    def resize(self, n):
        """Set the number of columns (keeps the values when it does not change)."""
        if getattr(self, "min", None) is not None and len(self.min) == n:
            return
        for name in self.FIELDS:
            setattr(self, name, np.full(n, np.nan))
        for name in self.CONCURRENT if self.concurrent else ():
            setattr(self, name, np.full((n, n), np.nan))
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
            mask = np.ones(len(cols), dtype=bool) if self.n_records == 0 else better(value, current)
            current[mask], current_time[mask] = value[mask], when[mask]
            if self.concurrent:
                getattr(self, "concurrent_" + name)[mask] = values[idx[mask]]
        self.n_records += m

    def as_dict(self):
        return {name: getattr(self, name).copy() for name in self.fields}
