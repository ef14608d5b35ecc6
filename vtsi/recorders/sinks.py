"""Where recorded values go: memory (numpy), HDF5 (h5py) or an OpenSees-style text file.

Contract of a sink
------------------
1. ``check(recorder)``: called when the recorder is built; raise for a combination the sink
   cannot store (a text file holds a history *or* an envelope; a sink serves one recorder).
2. ``open(layout, recorder)``: called at every analysis start. The first call creates the
   storage; later calls continue the same record. ``layout`` holds ``n_columns``, ``units``
   (one str per column), ``quantity``, ``response``, ``columns`` (name -> array per column)
   and ``attrs`` (model and analysis metadata).
3. ``write(times, values, envelope)``: after every chunk with at least one recorded step;
   ``values (n, n_columns)`` or None (envelope-only recorder), ``envelope`` or None.
4. ``close(envelope)``: at the end of every run, also a failed one; the storage stays valid.
"""
import datetime
import os

import numpy as np
from numba import njit

from vtsi.errors import ModelError


class Sink:
    """Base class of the sinks (see the module docstring)."""

    def check(self, recorder):
        owner = getattr(self, "_owner", None)
        if owner is not None and owner is not recorder:
            raise ModelError(f"{type(self).__name__}: this sink already belongs to {owner!r}; give each "
                             "recorder its own sink")
        self._owner = recorder

    def open(self, layout, recorder):
        raise NotImplementedError

    def write(self, times, values, envelope):
        raise NotImplementedError

    def close(self, envelope):
        pass

    @property
    def time(self):
        raise AttributeError(f"{type(self).__name__} keeps no values in memory")

    @property
    def values(self):
        raise AttributeError(f"{type(self).__name__} keeps no values in memory")


class MemorySink(Sink):
    """Keeps the record in numpy arrays: ``time (n,)`` [s] and ``values (n, n_columns)``.

    Chunks are stored as they come and concatenated once, when read (then kept as one array),
    so recording costs no copy per step. ``layout`` describes the columns after the first run.
    """

    def __init__(self):
        self.layout = None
        self._times, self._chunks = [], []

    def open(self, layout, recorder):
        self.layout = layout

    def write(self, times, values, envelope):
        if values is not None:
            self._times.append(times)
            self._chunks.append(values)

    @property
    def time(self):
        if len(self._times) != 1:
            self._times = [np.concatenate(self._times) if self._times else np.zeros(0)]
        return self._times[0]

    @property
    def values(self):
        if len(self._chunks) != 1:
            n = self.layout["n_columns"] if self.layout else 0
            self._chunks = [np.concatenate(self._chunks) if self._chunks else np.zeros((0, n))]
        return self._chunks[0]


class HDF5Sink(Sink):
    """One HDF5 file per recorder (h5py), appended chunk by chunk and flushed after each chunk.

    File layout::

        /                 attrs: recorder, response, quantity, vtsi_version, n_nodes,
                          n_elements, ndf, record_dt, created (UTC ISO 8601) and, when the
                          analysis gives them, analysis, integrator, dt
        /time             (n,) float64 [s], resizable, a dimension scale
        /values           (n, n_columns) float64, resizable along time, chunked;
                          dims[0] = /time, dims[1] = the /columns scales;
                          attrs: units (one str per column), quantity
        /columns/<name>   (n_columns,) per-column labels (node, dof, dof_name or element,
                          component, component_name), dimension scales of values' dim 1
        /envelope/<name>  (n_columns,) min, max, absmax, time_of_min, time_of_max,
                          time_of_absmax (with ``envelope=True``; attr n_records)

    Parameters
    ----------
    path : file to create. An existing file is refused (``FileExistsError`` naming it) when
        the sink is built, before any analysis work, unless ``overwrite=True``.
    overwrite : replace an existing file.
    flush_every : None (default): flush after every chunk; k: flush only once at least k
        recorded steps have accumulated since the last flush (fewer flushes when chunks are
        tiny, e.g. static steps; a killed run may then lose up to k - 1 steps).
    compression : h5py compression filter for /values (e.g. ``'gzip'``), default none.

    A run killed at any moment (even SIGKILL) leaves a readable file holding every step up
    to the last flush; a run that raises closes the file with every completed step.
    """

    def __init__(self, path, overwrite=False, flush_every=None, compression=None):
        self.path = os.fspath(path)
        if os.path.exists(self.path) and not overwrite:
            raise FileExistsError(f"HDF5 recorder: {self.path} already exists; pass overwrite=True "
                                  "to replace it")
        parent = os.path.dirname(os.path.abspath(self.path))
        if not os.path.isdir(parent):
            raise FileNotFoundError(f"HDF5 recorder: directory {parent} of {self.path} does not exist")
        if flush_every is not None and (int(flush_every) != flush_every or flush_every < 1):
            raise ModelError(f"HDF5 recorder {self.path}: flush_every must be an integer >= 1, got {flush_every!r}")
        self.overwrite = bool(overwrite)
        self.flush_every = None if flush_every is None else int(flush_every)
        self.compression = compression
        self._file = None
        self._created = False
        self._unflushed = 0

    def open(self, layout, recorder):
        import h5py

        if self._created:
            self._file = h5py.File(self.path, "r+")
            self._file.attrs.update(_h5_attrs(layout["attrs"]))
            return
        mode = "w" if self.overwrite else "w-"
        try:
            f = h5py.File(self.path, mode)
        except (OSError, FileExistsError) as exc:
            raise type(exc)(f"HDF5 recorder: cannot create {self.path}: {exc}") from None
        self._file, self._created = f, True
        n = layout["n_columns"]
        f.attrs.update(_h5_attrs(layout["attrs"]))
        f.attrs["response"] = layout["response"]
        f.attrs["quantity"] = layout["quantity"]
        f.attrs["created"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
        columns = f.create_group("columns")
        scales = []
        for name, data in layout["columns"].items():
            data = np.asarray(data)
            if data.dtype.kind in "US":
                ds = columns.create_dataset(name, data=data.astype(object), dtype=h5py.string_dtype())
            else:
                ds = columns.create_dataset(name, data=data)
            ds.make_scale(name)
            scales.append(ds)
        columns.create_dataset("units", data=np.array(layout["units"], dtype=object), dtype=h5py.string_dtype())
        if recorder.history:
            rows = int(np.clip(2 ** 18 // (8 * max(n, 1)), 64, 16384))
            time = f.create_dataset("time", shape=(0,), maxshape=(None,), chunks=(rows,), dtype="f8")
            time.attrs["units"] = "s"
            time.make_scale("time")
            values = f.create_dataset("values", shape=(0, n), maxshape=(None, n), chunks=(rows, max(n, 1)),
                                      dtype="f8", compression=self.compression)
            values.attrs["units"] = np.array(layout["units"], dtype=object)
            values.attrs["quantity"] = layout["quantity"]
            values.dims[0].label = "time"
            values.dims[0].attach_scale(time)
            values.dims[1].label = "column"
            for ds in scales:
                values.dims[1].attach_scale(ds)
        if recorder.envelope is not None:
            env = f.create_group("envelope")
            for name in recorder.envelope.FIELDS:
                env.create_dataset(name, data=np.full(n, np.nan))
                env[name].attrs["units"] = "s" if name.startswith("time") else np.array(layout["units"], dtype=object)
            env.attrs["n_records"] = 0
        f.flush()

    def write(self, times, values, envelope):
        f = self._file
        if values is not None:
            n0, n = f["time"].shape[0], len(times)
            f["time"].resize((n0 + n,))
            f["time"][n0:] = times
            f["values"].resize(n0 + n, axis=0)
            f["values"][n0:] = values
        if envelope is not None:
            env = f["envelope"]
            for name in envelope.FIELDS:
                env[name][...] = getattr(envelope, name)
            env.attrs["n_records"] = envelope.n_records
        self._unflushed += len(times)
        if self.flush_every is None or self._unflushed >= self.flush_every:
            f.flush()
            self._unflushed = 0

    def close(self, envelope):
        if self._file is not None:
            try:
                self._file.flush()
            finally:
                self._file.close()
                self._file = None
                self._unflushed = 0

    def _read(self, name, empty):
        if self._file is not None:
            return self._file[name][...] if name in self._file else empty
        if not self._created:
            return empty
        import h5py

        with h5py.File(self.path, "r") as f:
            return f[name][...] if name in f else empty

    @property
    def time(self):
        """Recorded times, read back from the file."""
        return self._read("time", np.zeros(0))

    @property
    def values(self):
        """Recorded values, read back from the file."""
        return self._read("values", np.zeros((0, 0)))


class TextSink(Sink):
    """OpenSees-style text file (``recorder Node/Element ... -file``).

    History recorder: one line per recorded step, ``[time] v1 v2 ...``, single spaces, each
    number as C++ ``ostream`` with ``precision`` significant digits (``'%.{p}g'``).
    Envelope-only recorder (``history=False``, OpenSees ``EnvelopeNode``/``EnvelopeElement``):
    three lines, min, max and absmax, written when the run ends (rewritten after each run);
    with ``time=True`` every value is preceded by the time it occurred (``t v`` pairs).

    The file is created, or truncated, when the sink is built (OpenSees truncates when the
    recorder command runs: scripts are re-run in place). Lines are flushed after every chunk;
    ``close_on_write`` reopens and closes the file for every chunk instead.
    """

    def __init__(self, path, time=False, precision=6, close_on_write=False):
        self.path = os.fspath(path)
        if isinstance(precision, bool) or int(precision) != precision or precision < 0:
            raise ModelError(f"text recorder {self.path}: precision must be an integer >= 0, got {precision!r}")
        self.echo_time, self.precision, self.close_on_write = bool(time), int(precision), bool(close_on_write)
        try:
            with open(self.path, "w"):
                pass
        except OSError as exc:
            raise type(exc)(f"text recorder: cannot create {self.path}: {exc.strerror}") from None
        self._handle = None
        self._recorder = None

    def check(self, recorder):
        super().check(recorder)
        if recorder.history and recorder.envelope is not None:
            raise ModelError(f"text recorder {self.path}: a text file holds the history (OpenSees Node/"
                             "Element recorder) or the envelope (EnvelopeNode/EnvelopeElement), not "
                             "both; use two recorders, or an HDF5Sink")

    def open(self, layout, recorder):
        self._recorder = recorder
        if recorder.history and not self.close_on_write:
            self._handle = open(self.path, "a")

    def write(self, times, values, envelope):
        if values is None:
            return
        text = format_rows(times if self.echo_time else None, values, self.precision)
        if self.close_on_write:
            with open(self.path, "a") as fh:
                fh.write(text)
        else:
            self._handle.write(text)
            self._handle.flush()

    def close(self, envelope):
        if self._handle is not None:
            self._handle.close()
            self._handle = None
        if self._recorder is not None and not self._recorder.history and envelope is not None:
            with open(self.path, "w") as fh:
                fh.write(format_envelope(envelope, self.echo_time, self.precision))

    @property
    def time(self):
        raise AttributeError(f"TextSink keeps no values in memory: read {self.path} (numpy.loadtxt)")

    @property
    def values(self):
        raise AttributeError(f"TextSink keeps no values in memory: read {self.path} (numpy.loadtxt)")


def format_rows(times, values, precision=6):
    """Lines as OpenSees's DataFileStream writes them: ``[t] v1 v2 ...\\n`` with ``%.{p}g``
    (Python's, which rounds correctly). Compiled (:func:`_format_block`) for precisions 1..17;
    a block with a number it cannot certify is formatted by Python."""
    values = np.asarray(values, dtype=np.float64)
    if times is not None:
        values = np.column_stack([np.asarray(times, dtype=np.float64), values])
    if values.shape[1] == 0:
        return "\n" * values.shape[0]
    if 1 <= precision <= MAX_COMPILED_PRECISION:
        text, length = _format_block(np.ascontiguousarray(values), precision, *_powers_of_ten())
        if length >= 0:
            return text[:length].tobytes().decode("ascii")
    line = " ".join([f"%.{precision}g"] * values.shape[1]) + "\n"
    return (line * values.shape[0]) % tuple(values.ravel().tolist())


MAX_COMPILED_PRECISION = 17
POWER_RANGE = (-260, 275)      # exponents k of the table of 10**k
CERTAIN_RANGE = (1e-250, 1e250)  # |x| formatted by the compiled path (outside: Python)
_POWERS = []


def _powers_of_ten():
    """``(first k, hi, lo)``: 10**k = hi + lo (float64 (n,) each, hi correctly rounded, lo the
    rest correctly rounded: |hi + lo - 10**k| <= 2**-105 10**k) for k in :data:`POWER_RANGE`;
    computed with Python's exact integers once."""
    if not _POWERS:
        ks = range(POWER_RANGE[0], POWER_RANGE[1] + 1)
        hi, lo = np.zeros(len(ks)), np.zeros(len(ks))
        for j, k in enumerate(ks):
            if k >= 0:
                hi[j] = float(10 ** k)
                lo[j] = float(10 ** k - int(hi[j]))
            else:
                hi[j] = 1 / 10 ** -k                                  # correctly rounded
                num, den = float(hi[j]).as_integer_ratio()
                lo[j] = (den - num * 10 ** -k) / (den * 10 ** -k)
        _POWERS.append((POWER_RANGE[0], hi, lo))
    return _POWERS[0]


@njit(cache=True)
def _two_product(a, b):
    """``(p, e)`` with ``p = fl(a b)`` and ``p + e = a b`` exactly (Dekker; no overflow for
    |a|, |b| < 1e290)."""
    p = a * b
    c = 134217729.0 * a
    ah = c - (c - a)
    al = a - ah
    c = 134217729.0 * b
    bh = c - (c - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@njit(cache=True)
def _digits(ax, precision, first, p_hi, p_lo):
    """``(D, X)``: the ``precision`` significant digits of ``ax`` (> 0, in :data:`CERTAIN_RANGE`)
    rounded to nearest as an integer 10**(p-1) <= D < 10**p, and the decimal exponent X of the
    rounded value; ``(-1, 0)`` where that is not certain.

    The scaled value y = ax 10**(p-1-E) is computed as hi + lo to |error| < 1e-13 (a double-double
    product, with ``10**k`` from the table); a rounding is certain when y lies farther than 1e-9
    from a half-integer (where to round) and from 10**(p-1) and 10**p (which exponent)."""
    low = np.int64(10) ** (precision - 1)
    high = low * 10
    e = np.int64(np.floor(np.log10(ax)))
    for _ in range(3):
        j = precision - 1 - e - first
        if j < 0 or j >= p_hi.shape[0]:
            return np.int64(-1), np.int64(0)
        hi, err = _two_product(ax, p_hi[j])
        lo = err + ax * p_lo[j]
        a = np.rint(hi)
        r = (hi - a) + lo          # y - a: hi - a exact, |r| < 9
        ia = np.int64(a)
        if abs(ia - low) < 100:    # 10**(p-1) <= y ?
            s = np.float64(ia - low) + r
            if abs(s) < 1e-9:
                return np.int64(-1), np.int64(0)
            if s < 0.0:
                e -= 1
                continue
        elif ia < low:
            e -= 1
            continue
        if abs(ia - high) < 100:   # y < 10**p ?
            s = np.float64(ia - high) + r
            if abs(s) < 1e-9:
                return np.int64(-1), np.int64(0)
            if s >= 0.0:
                e += 1
                continue
        elif ia > high:
            e += 1
            continue
        t = np.floor(r + 0.5)
        g = r + 0.5 - t
        if g < 1e-9 or g > 1.0 - 1e-9:
            return np.int64(-1), np.int64(0)
        d = ia + np.int64(t)
        if d == high:              # rounded up to the next power of ten
            return low, e + 1
        return d, e
    return np.int64(-1), np.int64(0)


@njit(cache=True)
def _put(out, pos, text):
    for c in text:
        out[pos] = ord(c)
        pos += 1
    return pos


@njit(cache=True)
def _format_g(out, pos, x, precision, first, p_hi, p_lo, digits):
    """Write ``'%.{precision}g' % x`` (Python's) at ``out[pos]``; returns the new position, -1
    where the digits are not certain (:func:`_digits`)."""
    if x != x:
        return _put(out, pos, "nan")
    if x < 0.0 or (x == 0.0 and np.copysign(1.0, x) < 0.0):
        out[pos] = 45      # '-'
        pos += 1
    ax = abs(x)
    if ax == np.inf:
        return _put(out, pos, "inf")
    if ax == 0.0:
        out[pos] = 48
        return pos + 1
    if not (CERTAIN_RANGE[0] <= ax <= CERTAIN_RANGE[1]):
        return -1
    d, e = _digits(ax, precision, first, p_hi, p_lo)
    if d < 0:
        return -1
    for i in range(precision - 1, -1, -1):
        digits[i] = 48 + d % 10
        d //= 10
    n = precision                     # significant digits kept: trailing zeros of the fraction go
    fixed = -4 <= e < precision
    keep = e + 1 if fixed and e >= 0 else 1
    while n > keep and digits[n - 1] == 48:
        n -= 1
    if fixed and e < 0:
        pos = _put(out, pos, "0.")
        for _ in range(-e - 1):
            out[pos] = 48
            pos += 1
        for i in range(n):
            out[pos] = digits[i]
            pos += 1
        return pos
    point = e + 1 if fixed else 1     # digits before the decimal point
    for i in range(n):
        if i == point:
            out[pos] = 46              # '.'
            pos += 1
        out[pos] = digits[i]
        pos += 1
    if fixed:
        return pos
    out[pos] = 101                     # 'e'
    out[pos + 1] = 45 if e < 0 else 43
    pos += 2
    ae = abs(e)
    if ae >= 100:
        out[pos] = 48 + ae // 100
        pos += 1
    out[pos] = 48 + (ae // 10) % 10
    out[pos + 1] = 48 + ae % 10
    return pos + 2


@njit(cache=True)
def _format_block(values, precision, first, p_hi, p_lo):
    """``(text uint8, length)``: the lines of :func:`format_rows` as ASCII; length -1 if a number
    needs Python's formatting."""
    n_rows, n_cols = values.shape
    out = np.empty(n_rows * (n_cols * (precision + 10) + 1), dtype=np.uint8)
    digits = np.empty(precision, dtype=np.uint8)
    pos = 0
    for i in range(n_rows):
        for j in range(n_cols):
            if j > 0:
                out[pos] = 32
                pos += 1
            pos = _format_g(out, pos, values[i, j], precision, first, p_hi, p_lo, digits)
            if pos < 0:
                return out, -1
        out[pos] = 10
        pos += 1
    return out, pos


def format_envelope(envelope, echo_time=False, precision=6):
    """The three lines of OpenSees's envelope recorders (min, max, absmax), empty if nothing
    was recorded; with ``echo_time`` each value is preceded by its time of occurrence."""
    if envelope.n_records == 0:
        return ""
    rows = []
    for name in ("min", "max", "absmax"):
        value = getattr(envelope, name)
        if echo_time:
            value = np.column_stack([getattr(envelope, "time_of_" + name), value]).ravel()
        rows.append(value)
    return format_rows(None, np.array(rows), precision)


def _h5_attrs(attrs):
    out = {}
    for key, value in attrs.items():
        if isinstance(value, (str, bool, int, float, np.integer, np.floating)):
            out[key] = value
        else:
            out[key] = str(value)
    return out
