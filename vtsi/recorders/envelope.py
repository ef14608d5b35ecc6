"""Running envelopes: min, max and absolute max of every column, with the time of each, and
optionally the concurrent values: every column of the recorder at the step each extreme was
reached (the shear that goes with the largest moment, the moment with the largest shear).

Updated once per chunk by one compiled pass over the chunk (:func:`_fold`), and readable at
any moment. Ties keep the first occurrence (a later value must be strictly smaller / larger to
replace it), which is what OpenSees's ``EnvelopeNode`` and ``EnvelopeElement`` recorders do:
their absmax row equals ``max(|min|, |max|)`` and its time is the time of that extreme.

NaN, as ``numpy.argmin``/``argmax`` along time take it: a chunk's extremes of a column with a
NaN are that NaN, at the time of its first NaN; the first chunk stores it, a later chunk's NaN
replaces nothing (it is not smaller or larger) and nothing replaces a stored NaN.
"""
import numpy as np
from numba import njit

from vtsi.errors import ModelError


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
        """Fold ``values (m, n)`` recorded at ``times (m,)`` [s] into the envelope (a ModelError
        if the shapes do not match ``m`` times and the envelope's ``n`` columns)."""
        times = np.ascontiguousarray(times, dtype=np.float64)
        values = np.ascontiguousarray(values, dtype=np.float64)
        m = len(times)
        if values.ndim != 2 or values.shape != (m, len(self.min)):
            raise ModelError(f"envelope: values of shape {values.shape} for {m} times and {len(self.min)} columns; "
                             f"({m}, {len(self.min)}) expected")
        if m == 0:
            return
        none = np.empty((0, 0))
        concurrent = [getattr(self, name) if self.concurrent else none for name in self.CONCURRENT]
        _fold(times, values, self.n_records == 0, self.min, self.max, self.absmax, self.time_of_min,
              self.time_of_max, self.time_of_absmax, *concurrent)
        self.n_records += m

    def as_dict(self):
        return {name: getattr(self, name).copy() for name in self.fields}


@njit(cache=True)
def _fold(times, values, first, low, high, peak, t_low, t_high, t_peak, c_low, c_high, c_peak):
    """Fold ``values (m, n)`` at ``times (m,)`` into the extremes ``low, high, peak (n,)`` (min,
    max, absmax) and their times ``t_* (n,)``, in place; ``first``: replace them all (the
    envelope's first chunk); ``c_* (n, n)`` the concurrent rows, or ``(0, 0)`` for none.

    One pass along time (rows), the chunk's extreme of each column found as ``argmin``/``argmax``
    find it (the first of equal values; the first NaN, for all three, in a column with one),
    then kept where strictly beyond the stored one (module docstring)."""
    m, n = values.shape
    at_low = np.zeros(n, dtype=np.int64)
    at_high = np.zeros(n, dtype=np.int64)
    at_peak = np.zeros(n, dtype=np.int64)
    v_low = values[0].copy()
    v_high = values[0].copy()
    v_peak = np.abs(values[0])
    nan = np.isnan(values[0])
    for i in range(1, m):                   # branch-free, so that the compiler vectorises it
        for j in range(n):
            x = values[i, j]
            a = abs(x)
            below, above, beyond = x < v_low[j], x > v_high[j], a > v_peak[j]
            v_low[j] = x if below else v_low[j]
            at_low[j] = i if below else at_low[j]
            v_high[j] = x if above else v_high[j]
            at_high[j] = i if above else at_high[j]
            v_peak[j] = a if beyond else v_peak[j]
            at_peak[j] = i if beyond else at_peak[j]
            nan[j] |= x != x
    for j in range(n):
        if nan[j]:                          # as argmin/argmax: the first NaN, in all three
            for i in range(m):
                if np.isnan(values[i, j]):
                    v_low[j], v_high[j], v_peak[j] = values[i, j], values[i, j], abs(values[i, j])
                    at_low[j], at_high[j], at_peak[j] = i, i, i
                    break
    concurrent = c_low.shape[0] > 0
    for j in range(n):
        if first or v_low[j] < low[j]:
            low[j], t_low[j] = v_low[j], times[at_low[j]]
            if concurrent:
                c_low[j, :] = values[at_low[j], :]
        if first or v_high[j] > high[j]:
            high[j], t_high[j] = v_high[j], times[at_high[j]]
            if concurrent:
                c_high[j, :] = values[at_high[j], :]
        if first or v_peak[j] > peak[j]:
            peak[j], t_peak[j] = v_peak[j], times[at_peak[j]]
            if concurrent:
                c_peak[j, :] = values[at_peak[j], :]
