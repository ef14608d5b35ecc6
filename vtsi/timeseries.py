"""Time series: load factor as a function of time, evaluated on arrays of times.

Conventions follow OpenSees (``timeSeries Constant / Linear / Path / Trig / Triangle /
Rectangular / Pulse``) to the last bit: a :class:`Path` is OpenSees's PathSeries (``dt``) or
PathTimeSeries (``time``).
"""
import inspect

import numpy as np
from numba import njit

from vtsi.errors import ModelError, as_flag, as_number, as_numbers, number_array


class TimeSeries:
    """Contract: ``__call__(t)`` takes an array of times [s] and returns factors of its shape.

    Optional, for series of samples that many patterns share the grid of (a Path per loaded
    node): ``stack_key()`` (hashable; series with equal keys are evaluated together, None: not
    stackable), ``values``, ``factor`` and the classmethod ``stack_factors(key, table, times,
    scale, outer)`` -> the factors (len(times), n) ``outer[j] * (scale[j] * f_j(t))`` of the
    stacked values ``table`` (n, n_samples): ``scale`` the series' factors, ``outer`` the
    patterns' (in OpenSees's order of the products, so that the results are OpenSees's to the bit).

    ``label`` (:attr:`label`): how the series' messages name it; the built-in series take it as
    a keyword (``label=...``, default ``timeSeries <type> <tag>``)."""

    tag = None
    _label = None

    @property
    def label(self):
        """The name the series' messages begin with: the ``label`` it was built with (the command
        layer passes its command: ``timeSeries LinearSeries 1``, or for an inline series ``pattern
        Plain 7: series Path``), else ``timeSeries <type> <tag>`` (``timeSeries Path 1``; without a
        tag ``timeSeries Path``)."""
        if self._label is not None:
            return self._label
        return f"timeSeries {type(self).__name__}" + (f" {self.tag}" if self.tag is not None else "")

    def __call__(self, t):
        raise NotImplementedError

    def stack_key(self):
        return None

    def __repr__(self):
        """``Linear(factor=2.0, tag=1)``: the constructor's parameters held under their own names,
        the required ones, ``factor`` and those not at their default (arrays by their size)."""
        words, hidden = [], ("label", *self._hidden_in_repr())
        for name, p in _parameters(self).items():
            if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) or not hasattr(self, name) or name in hidden:
                continue
            value = getattr(self, name)
            if isinstance(value, np.ndarray):
                words.append(f"{name}=<{value.size} values>")
            elif p.default is p.empty or name == "factor" or (value is not None and value != p.default):
                words.append(f"{name}={value!r}")
        return f"{type(self).__name__}({', '.join(words)})"

    def _hidden_in_repr(self):
        return ()

    def required_tag(self):
        """The series' tag, for a model that names it (:meth:`vtsi.Model.add_time_series`); a
        ModelError saying how to give it if the series has none (``Linear(1)`` is a factor of 1:
        vtsi's positional arguments are the series' parameters, OpenSees's first word is the tag)."""
        if self.tag is not None:
            return self.tag
        kind = type(self).__name__
        given, first = repr(self)[:-1], next(iter(_parameters(self)), None)
        raise ModelError(f"timeSeries {self!r} has no tag: give it as tag=..., e.g. "
                         f"{given}{', ' * (not given.endswith('('))}tag=1)"
                         + (f"; {kind}'s first argument is {first}, not the tag as in OpenSees's "
                            f"'timeSeries {kind} <tag> ...'" if first not in (None, "tag") else ""))


class Constant(TimeSeries):
    """OpenSees ``timeSeries Constant``: the load factor ``factor`` [–] at every time.

    ``factor`` (finite) is the first argument and ``tag`` a keyword: ``Constant(2.0, tag=1)`` is
    OpenSees's ``timeSeries Constant 1 -factor 2.0``, and ``Constant(1)`` a factor of 1 without
    a tag (a model that names series by tag asks for one: :meth:`TimeSeries.required_tag`)."""

    def __init__(self, factor=1.0, tag=None, label=None):
        self.tag, self._label = tag, label
        self.factor = _finite(self, "factor", factor)

    def __call__(self, t):
        return np.full(np.shape(t), self.factor)


class Linear(TimeSeries):
    """OpenSees ``timeSeries Linear``: the load factor ``factor × t``, ``factor`` [1/s] (t the
    domain's time [s]; in a static analysis the pseudo-time, advanced by its load step).

    ``factor`` (finite) is the first argument and ``tag`` a keyword: ``Linear(2.0, tag=1)`` is
    OpenSees's ``timeSeries Linear 1 -factor 2.0``, and ``Linear(1)`` a factor of 1 without a
    tag (a model that names series by tag asks for one: :meth:`TimeSeries.required_tag`)."""

    def __init__(self, factor=1.0, tag=None, label=None):
        self.tag, self._label = tag, label
        self.factor = _finite(self, "factor", factor)

    def __call__(self, t):
        return self.factor * _times(self, t)


class Trig(TimeSeries):
    """OpenSees ``timeSeries Trig``: inside [t_start, t_end] ``factor sin(2π (t − t_start)/period
    + φ) + zero_shift`` with φ = shift − period/(2π) asin(zero_shift/factor) (OpenSees's
    definition), 0 outside."""

    def __init__(self, t_start, t_end, period, factor=1.0, shift=0.0, zero_shift=0.0, tag=None, label=None):
        _periodic(self, t_start, t_end, period, factor, shift, zero_shift, tag, label)
        if not self.period > 0.0:
            raise ModelError(f"{self.label}: period must be > 0, got {self.period}")
        if self.zero_shift and not abs(self.zero_shift) <= abs(self.factor):
            raise ModelError(f"{self.label}: |zeroShift| must not exceed |factor| (asin), got {self.zero_shift}")

    def __call__(self, t):
        t = _times(self, t)
        phi = self.shift - (self.period / (2 * np.pi) * np.arcsin(self.zero_shift / self.factor) if self.zero_shift else 0.0)
        value = self.factor * np.sin(2 * np.pi * (t - self.t_start) / self.period + phi) + self.zero_shift
        return np.where((t >= self.t_start) & (t <= self.t_end), value, 0.0)


class Rectangular(TimeSeries):
    """OpenSees ``timeSeries Rectangular``: ``factor`` inside [t_start, t_end], 0 outside."""

    def __init__(self, t_start, t_end, factor=1.0, tag=None, label=None):
        self.tag, self._label = tag, label
        self.t_start, self.t_end = _finite(self, "tStart", t_start), _finite(self, "tEnd", t_end)
        self.factor = _finite(self, "factor", factor)
        _interval(self)

    def __call__(self, t):
        t = _times(self, t)
        return np.where((t >= self.t_start) & (t <= self.t_end), self.factor, 0.0)


class Triangle(TimeSeries):
    """OpenSees ``timeSeries Triangle``: inside [t_start, t_end] a triangular wave of amplitude
    ``factor`` and ``period`` (rising from 0 at the phase origin), shifted by ``shift`` [s] and
    ``zero_shift`` as OpenSees: φ = shift − zero_shift/s with the slope s = 4 factor/period,
    k = frac((t + φ − t_start)/period); 0 outside."""

    def __init__(self, t_start, t_end, period, factor=1.0, shift=0.0, zero_shift=0.0, tag=None, label=None):
        _periodic(self, t_start, t_end, period, factor, shift, zero_shift, tag, label)
        if not self.period > 0.0 or self.factor == 0.0:
            raise ModelError(f"{self.label}: period must be > 0 and factor not 0, got "
                             f"{self.period}, {self.factor}")

    def __call__(self, t):
        t = _times(self, t)
        slope = self.factor / (self.period / 4.0)
        x = (t + self.shift - self.zero_shift / slope - self.t_start) / self.period
        k = x - np.floor(x)
        c, T = self.factor, self.period
        value = np.where(k < 0.25, slope * k * T,
                         np.where(k < 0.75, c - slope * (k - 0.25) * T, -c + slope * (k - 0.75) * T)) + self.zero_shift
        return np.where((t >= self.t_start) & (t <= self.t_end), value, 0.0)


class Pulse(TimeSeries):
    """OpenSees ``timeSeries Pulse``: inside [t_start, t_end], with k = frac((t + shift −
    t_start)/period), ``factor + zero_shift`` while k < ``width`` (a fraction of the period),
    ``zero_shift`` after it; 0 outside."""

    def __init__(self, t_start, t_end, period, width=0.5, factor=1.0, shift=0.0, zero_shift=0.0, tag=None,
                 label=None):
        _periodic(self, t_start, t_end, period, factor, shift, zero_shift, tag, label)
        self.width = _finite(self, "width", width)
        if not self.period > 0.0 or not 0.0 < self.width < 1.0:
            raise ModelError(f"{self.label}: period must be > 0 and width in (0, 1), got "
                             f"{self.period}, {self.width}")

    def __call__(self, t):
        t = _times(self, t)
        x = (t + self.shift - self.t_start) / self.period
        value = np.where(x - np.floor(x) < self.width, self.factor + self.zero_shift, self.zero_shift)
        return np.where((t >= self.t_start) & (t <= self.t_end), value, 0.0)


class Path(TimeSeries):
    """Piecewise-linear factor through samples: OpenSees's ``timeSeries Path``, with its rules.

    Parameters
    ----------
    values : array (n,) of factors.
    dt : sample step [s]: samples at ``start_time + k dt`` (OpenSees ``-dt``), or
    time : array (n,), strictly increasing [s] (OpenSees ``-time``).
    factor : scale applied to ``values``.
    use_last : hold the last value after the last sample (else zero).
    prepend_zero : (``dt`` form) a zero sample at ``start_time``, the given values one ``dt``
        later (OpenSees ``-prependZero``).
    start_time : (``dt`` form) time of the first sample [s].
    tag, label : the series' tag, and how its messages name it (:attr:`TimeSeries.label`).

    The ``dt`` form is evaluated as ``PathSeries::getFactor``: ``x = (t - t0)/dt``,
    ``i = floor(x)``; zero before ``t0``; ``factor (v[i] + (v[i+1] - v[i]) (x - i))`` while
    ``i + 1 < n``; beyond, the last sample itself included, zero or, with ``use_last``,
    ``factor v[n-1]``. The ``time`` form as ``PathTimeSeries::getFactor``: zero before the first
    time, ``factor v[n-1]`` at the last time, after it zero or, with ``use_last``, ``factor v[n-1]``.
    """

    def __init__(self, values, time=None, dt=None, factor=1.0, use_last=False, prepend_zero=False,
                 start_time=0.0, tag=None, label=None):
        self.tag, self._label = tag, label
        name = self.label
        values = _numbers(name, "values", values)
        if values.size == 0:
            raise ModelError(f"{name}: no values given")
        if not np.all(np.isfinite(values)):
            bad = int(np.flatnonzero(~np.isfinite(values))[0])
            raise ModelError(f"{name}: value {bad} is {values[bad]} (NaN or inf)")
        start_time = _finite(self, "start_time", start_time)
        use_last, prepend_zero = as_flag(use_last, name, "use_last"), as_flag(prepend_zero, name, "prepend_zero")
        if time is None:
            if dt is None:
                raise ModelError(f"{name}: give the sample times (time=...) or the step dt")
            dt = _finite(self, "dt", dt)
            if not dt > 0.0:
                raise ModelError(f"{name}: dt must be > 0, got {dt}")
            if prepend_zero:
                values = np.r_[0.0, values]
            time = start_time + dt * np.arange(values.size)
        else:
            if dt is not None:
                raise ModelError(f"{name}: give either the sample times or the step dt, not both")
            if prepend_zero or start_time != 0.0:
                raise ModelError(f"{name}: prepend_zero and start_time apply to the dt form only (OpenSees "
                                 "ignores them with -time); shift or extend the times instead")
            time = _numbers(name, "time", time)
            if time.size != values.size:
                raise ModelError(f"{name}: {time.size} times but {values.size} values")
            if not np.all(np.isfinite(time)):
                bad = int(np.flatnonzero(~np.isfinite(time))[0])
                raise ModelError(f"{name}: time[{bad}] is {time[bad]} (NaN or inf)")
            steps = np.diff(time)
            if np.any(steps <= 0.0):
                bad = int(np.flatnonzero(steps <= 0.0)[0])
                raise ModelError(f"{name}: times must increase strictly; time[{bad + 1}] = {time[bad + 1]:g} "
                                 f"follows time[{bad}] = {time[bad]:g}")
        self.time, self.values = time, values
        self.dt = None if dt is None else float(dt)        # the -dt form's step, None for the -time form
        self.start_time = start_time
        self.factor, self.use_last = _finite(self, "factor", factor), use_last

    def _hidden_in_repr(self):
        return ("time",) if self.dt is not None else ("dt",)

    def stack_key(self):
        """Series on the same grid stack (a Path per loaded node is evaluated in one gather)."""
        key = getattr(self, "_stack_key", None)
        if key is None:
            grid = ("dt", self.dt, self.start_time) if self.dt is not None else ("time", self.time.tobytes())
            key = self._stack_key = (self.values.size, self.use_last, grid)
        return key

    @classmethod
    def stack_factors(cls, key, table, times, scale, outer):
        """Factors ``(len(times), n)``, ``outer[j] (scale[j] v_j(t))``, of the stacked ``table``
        (n, n_samples) on the grid of ``key`` at ``times``, with the rules of the class docstring
        (compiled: one pass)."""
        size, use_last, grid = key
        times = np.ascontiguousarray(times, dtype=float)
        table = np.ascontiguousarray(table, dtype=float)
        scale, outer = np.asarray(scale, dtype=float), np.asarray(outer, dtype=float)
        out = np.empty((len(times), table.shape[0]))
        if grid[0] == "dt":
            _dt_grid_factors(table, times, grid[2], grid[1], use_last, scale, outer, out)
        else:
            _time_grid_factors(table, times, np.frombuffer(grid[1]), use_last, scale, outer, out)
        return out

    def __call__(self, t):
        t = _times(self, t)
        flat = t.reshape(-1)
        out = self.stack_factors(self.stack_key(), self.values[None, :], flat, [self.factor], [1.0])[:, 0]
        return out.reshape(t.shape)


def _parameters(series):
    """The parameters of ``series``'s constructor by name, ``self`` left out."""
    params = dict(inspect.signature(type(series).__init__).parameters)
    params.pop("self", None)
    return params


def _numbers(name, what, values):
    """``values`` (a sequence of numbers, not texts nor bools) as a 1-D float64 array, or a
    ModelError naming the series."""
    out = as_numbers(values, name, what)
    if out.ndim != 1:
        raise ModelError(f"{name}: {what} must be a 1-D sequence, got shape {out.shape}")
    return out


def _times(series, t):
    """The times ``t`` [s] a series is evaluated at, as a float array (not texts nor bools), or
    a ModelError naming the series."""
    if isinstance(t, np.ndarray) and t.dtype == np.float64:        # (an analysis's times)
        return t
    times = number_array(t)
    if times is None:
        raise ModelError(f"{series.label}: times must be numbers [s], got {t!r}")
    return times


def _periodic(series, t_start, t_end, period, factor, shift, zero_shift, tag, label):
    """Set the parameters that OpenSees's periodic series (Trig, Triangle, Pulse) share on
    ``series``, each checked finite (:func:`_finite`) and the interval (:func:`_interval`)."""
    series.tag, series._label = tag, label
    series.t_start, series.t_end = _finite(series, "tStart", t_start), _finite(series, "tEnd", t_end)
    series.period = _finite(series, "period", period)
    series.factor, series.shift = _finite(series, "factor", factor), _finite(series, "shift", shift)
    series.zero_shift = _finite(series, "zeroShift", zero_shift)
    _interval(series)


def _interval(series):
    """A ModelError naming the series (its label) if its ``t_end`` < ``t_start`` (it would always give 0)."""
    t_start, t_end, tag, kind = series.t_start, series.t_end, series.tag, type(series).__name__
    if t_end < t_start:
        hint = (f"; if {t_start:g} was meant as the tag, give it as tag={t_start:g}: {kind}'s first argument is "
                f"tStart (OpenSees's 'timeSeries {kind} <tag> <tStart> ...')"
                if tag is None and float(t_start).is_integer() else "")
        raise ModelError(f"{series.label}: tEnd = {t_end:g} is before tStart = {t_start:g} (the series would be "
                         f"0 always){hint}")


@njit(cache=True)
def _dt_grid_factors(table, times, start, dt, use_last, scale, outer, out):
    """``out[r, j] = outer[j] (scale[j] v)`` with ``v`` row j of ``table`` at ``times[r]`` on
    the grid ``start + k dt`` as ``PathSeries::getFactor``: ``x = (t - start)/dt``, ``i =
    floor(x)``, ``v[i] + (v[i+1] - v[i]) (x - i)`` while ``i + 1 < n``; zero before ``start``;
    after, zero or (``use_last``) the last sample."""
    n = table.shape[1]
    for r in range(times.shape[0]):
        t = times[r]
        out[r, :] = 0.0
        if t < start:
            continue
        x = (t - start) / dt
        i = np.floor(x)
        if i + 1 < n:
            k = int(i)
            w = x - i
            for j in range(table.shape[0]):
                out[r, j] = outer[j] * (scale[j] * (table[j, k] + (table[j, k + 1] - table[j, k]) * w))
        elif use_last:
            for j in range(table.shape[0]):
                out[r, j] = outer[j] * (scale[j] * table[j, n - 1])


@njit(cache=True)
def _time_grid_factors(table, times, grid, use_last, scale, outer, out):
    """As :func:`_dt_grid_factors` on the sample times ``grid`` (``PathTimeSeries::getFactor``):
    linear inside, the last sample at the last time, after it zero or (``use_last``) the last sample."""
    n = grid.shape[0]
    for r in range(times.shape[0]):
        t = times[r]
        out[r, :] = 0.0
        k = np.searchsorted(grid, t, side="right") - 1
        if 0 <= k < n - 1:
            w = (t - grid[k]) / (grid[k + 1] - grid[k])
            for j in range(table.shape[0]):
                out[r, j] = outer[j] * (scale[j] * (table[j, k] + (table[j, k + 1] - table[j, k]) * w))
        elif t == grid[n - 1] or (t > grid[n - 1] and use_last):
            for j in range(table.shape[0]):
                out[r, j] = outer[j] * (scale[j] * table[j, n - 1])


def _finite(series, name, value):
    """``value`` as a finite float, or a ModelError naming the series (its label), ``name`` and
    the value (a text or a bool is no number: :func:`vtsi.errors.as_number`)."""
    value = as_number(value, series.label, name)
    if not np.isfinite(value):
        raise ModelError(f"{series.label}: {name} must be finite, got {value}")
    return value
