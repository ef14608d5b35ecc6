"""Where recorded values go: memory (numpy), HDF5 (h5py) or an OpenSees-style text file.

Contract of a sink
------------------
1. ``check(recorder)``: called when the recorder is built; raise for a combination the sink
   cannot store (a text file holds a history *or* an envelope; a sink serves one recorder).
2. ``open(layout, recorder)``: called at every analysis start. The first call creates the
   storage; later calls continue the same record. ``layout`` holds ``n_columns``, ``units``
   (one str per column), ``quantity``, ``response``, ``columns`` (name -> array per column)
   ``attrs`` (model and analysis metadata) and ``run`` (this run's description: the ``info``
   the analysis gave, e.g. ``analysis``, ``integrator``, ``dt``, ``loads``; also in ``attrs``),
   all present: :meth:`Recorder.start <vtsi.recorders.base.Recorder.start>` checks the
   response's description and fills in ``n_columns``, ``attrs``, ``run`` and a missing
   ``response``.
3. ``write(times, values, envelope)``: after every chunk with at least one recorded step;
   ``values (n, n_columns)`` or None (envelope-only recorder), ``envelope`` or None. Storage
   that cannot be written (a full disk) raises :class:`~vtsi.errors.RecorderError` naming the
   recorder, its file, the OS's reason and what the file holds (:meth:`Sink.failure`).
4. ``close(envelope)``: at the end of every run, also a failed one; the storage stays valid.
   After a :class:`RecorderError` it raises no second one.
"""
import datetime
import errno
import os

import h5py
import numpy as np

from vtsi.errors import ModelError, RecorderError, as_flag, is_count
from vtsi.recorders.number_text import format_g_bytes, format_g_rows

try:
    import fcntl                 # POSIX: an HDF5 sink locks its file while it writes it, as HDF5 does
except ImportError:              # Windows
    fcntl = None

NO_LOCKS = (errno.ENOSYS, errno.ENOLCK, errno.EOPNOTSUPP)   # flock's errors where a file system has no locks
LINE_END = os.linesep.encode()   # text recorders end lines as OpenSees's text streams do here (CRLF on Windows)


class Sink:
    """Base class of the sinks (see the module docstring)."""

    def check(self, recorder):
        owner = getattr(self, "_owner", None)
        if owner is not None and owner is not recorder:
            raise ModelError(f"{type(self).__name__}: this sink already belongs to {owner!r}; give each "
                             "recorder its own sink")
        self._owner = recorder

    def failure(self, text):
        """A :class:`RecorderError` ``<recorder> (<KIND> file <path>): <text>`` (``KIND``, a class
        attribute of a sink with a file: 'HDF5', 'text'), the recorder named by its tag when it has
        one (the command layer's: ``recorder 2 (node, HDF5 file out.h5)``), else by its name
        (``node recorder (HDF5 file out.h5)``)."""
        recorder = getattr(self, "_owner", None)
        name, tag = getattr(recorder, "name", type(self).__name__), getattr(recorder, "tag", None)
        who = f"{name} ({self.KIND} file {self.path})" if tag is None else \
            f"recorder {tag} ({name.removesuffix(' recorder')}, {self.KIND} file {self.path})"
        return RecorderError(f"{who}: {text}")

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
    Reading is possible at any time: before the first record it gives empty arrays (``(0,)``
    and ``(0, n_columns)``, ``n_columns`` 0 before the first run), and nothing read is kept
    until there is something to keep, so a read never changes what later reads give.
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
        if not self._times:
            return np.zeros(0)
        if len(self._times) > 1:
            self._times = [np.concatenate(self._times)]
        return self._times[0]

    @property
    def values(self):
        if not self._chunks:            # nothing recorded yet: an empty array, not kept
            return np.zeros((0, self.layout["n_columns"] if self.layout else 0))
        if len(self._chunks) > 1:
            self._chunks = [np.concatenate(self._chunks)]
        return self._chunks[0]


class HDF5Sink(Sink):
    """One HDF5 file per recorder (h5py), appended chunk by chunk and flushed after each chunk.

    File layout::

        /                 attrs: recorder, response, quantity, vtsi_version, n_nodes,
                          n_elements, ndf, record_dt, created (UTC ISO 8601) and, when the
                          analysis gives them, analysis ('static', 'transient', 'coupled'),
                          integrator, dt [s] (static: the load step), loads (a text: what
                          the response includes, e.g. 'the load patterns'; a coupled
                          analysis: the train's weight and axle forces, and whether the
                          bridge's self weight). These last hold what every run of the
                          file shares; one on which the runs differ is removed (/runs)
        /runs/<field>     one row per run (consecutive runs alike share a row): first_row,
                          rows (int64: the run's rows of /time), analysis, integrator, loads
                          (str, '' if not given), dt (float64, NaN if not given),
                          time_units (str: 's'; '' for a static run's pseudo-time)
        /time             (n,) float64, resizable, a dimension scale; attrs units: 's' or
                          '' (static runs: the pseudo-time), removed if the runs differ
        /values           (n, n_columns) float64, resizable along time, chunked;
                          dims[0] = /time, dims[1] = the /columns scales;
                          attrs: units (one str per column), quantity
        /columns/<name>   (n_columns,) per-column labels (node, dof, dof_name or element,
                          component, component_name), dimension scales of values' dim 1
        /envelope/<name>  (n_columns,) min, max, absmax, time_of_min, time_of_max,
                          time_of_absmax (with ``envelope=True``; attr n_records);
                          (n_columns, n_columns) concurrent_min, concurrent_max,
                          concurrent_absmax (with ``envelope="concurrent"``)

    Parameters
    ----------
    path : file to create. An existing file is refused (``FileExistsError`` naming it) when
        the sink is built, before any analysis work, unless ``overwrite=True``; a directory
        always (``IsADirectoryError``).
    overwrite : True: replace an existing file (a bool: anything else is a ModelError).
    flush_every : None (default): flush after every chunk; k: flush only once at least k
        recorded steps have accumulated since the last flush (fewer flushes when chunks are
        tiny, e.g. static steps; a killed run, or a full disk, may then lose up to k - 1
        steps and the chunk that failed).
    compression : h5py compression filter for /values (``'gzip'``, ``'lzf'``, a gzip level 0-9...),
        default none; checked with ``compression_opts`` when the sink is built (ModelError).
    compression_opts : the filter's options (gzip: level 0-9), default h5py's.

    A run killed at any moment (even SIGKILL) leaves a readable file holding every step up
    to the last flush, and so does a full disk: HDF5 writes through a :class:`_StagedFile`,
    and a flush that cannot be written leaves the file of the flush before, closes it and
    raises :class:`RecorderError` (the record stops there: a later write or run raises it
    again, ``close`` does not). A run that raises closes the file with every completed step.
    The file is open, and locked (``flock``), only during a run (from ``open`` to ``close``: a
    command-layer recorder's lasts until it is removed): another process reads it between runs
    and after them; during a run only with ``locking=False``, and then not reliably (no SWMR:
    docs/recorders.md says why and how).
    """

    KIND = "HDF5"
    RUN_FIELDS = ("analysis", "integrator", "dt", "loads")   # of the run's description, in /runs

    def __init__(self, path, overwrite=False, flush_every=None, compression=None, compression_opts=None):
        self.path = _path("HDF5 recorder", path)
        self.overwrite = as_flag(overwrite, f"HDF5 recorder {self.path}", "overwrite")
        if os.path.isdir(self.path):
            raise IsADirectoryError(f"HDF5 recorder: {self.path} is a directory; give a file name")
        if os.path.exists(self.path) and not self.overwrite:
            raise FileExistsError(f"HDF5 recorder: {self.path} already exists; pass overwrite=True "
                                  "to replace it")
        parent = os.path.dirname(os.path.abspath(self.path))
        if os.path.exists(parent) and not os.path.isdir(parent):
            raise NotADirectoryError(f"HDF5 recorder: {parent} of {self.path} is a file, not a directory")
        if not os.path.isdir(parent):
            raise FileNotFoundError(f"HDF5 recorder: directory {parent} of {self.path} does not exist")
        if flush_every is not None and not is_count(flush_every, 1):
            raise ModelError(f"HDF5 recorder {self.path}: flush_every must be an integer >= 1, got {flush_every!r}")
        self.flush_every = None if flush_every is None else int(flush_every)
        self.compression, self.compression_opts = compression, compression_opts
        _check_compression(self.path, compression, compression_opts)
        self._file = None
        self._staged = None      # the _StagedFile HDF5 writes through while the file is open
        self._created = False
        self._unflushed = 0
        self._unflushed_from = None   # [s] the first step not yet committed
        self._last_time = None   # [s] the last step handed over
        self._kept = None        # (rows, time [s] of the last) the file holds: its last commit
        self._stopped = None     # (the OS's reason, what the file holds) of the failed write that stopped the record
        self._shared = None      # the run attributes every run so far shares (the root's)
        self._run = None         # the /runs row of the current run, as a dict
        self._rows = 0           # rows recorded (steps the envelope saw, without a history)
        self._run_first = 0      # the current run's first row
        self._run_rows = None    # (dataset, memory space, file space) of the current run's /runs/rows
        self._open = None        # the datasets written at every chunk (name -> h5py object), open for the run

    def open(self, layout, recorder):
        if self._stopped is not None:
            raise self._stopped_error()
        if self._created:
            self._open_file("continue", "r+")
            run = layout["run"]
            self._file.attrs.update(_h5_attrs({k: v for k, v in layout["attrs"].items() if k not in run}))
            self._begin_run(run)
            self._hold_open()
            return
        f = self._open_file("replace" if self.overwrite else "new", "w")
        self._created = True
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
            time.attrs["units"] = _time_units(layout["run"])
            time.make_scale("time")
            # no columns (an Element recorder of elements without the response): HDF5 takes no chunk wider
            # than a fixed dimension, so the column dimension is left unlimited (it stays 0)
            values = f.create_dataset("values", shape=(0, n), maxshape=(None, n or None), chunks=(rows, max(n, 1)),
                                      dtype="f8", compression=self.compression,
                                      compression_opts=self.compression_opts)
            values.attrs.create("units", np.array(layout["units"], dtype=object), dtype=h5py.string_dtype())
            values.attrs["quantity"] = layout["quantity"]
            values.dims[0].label = "time"
            values.dims[0].attach_scale(time)
            values.dims[1].label = "column"
            for ds in scales:
                values.dims[1].attach_scale(ds)
        if recorder.envelope is not None:
            env = f.create_group("envelope")
            for name in recorder.envelope.fields:       # concurrent_*: (n, n), units per column (axis 1)
                env.create_dataset(name, data=np.full(getattr(recorder.envelope, name).shape, np.nan))
                if name.startswith("time"):
                    env[name].attrs["units"] = _time_units(layout["run"])
                else:       # a list of str, also an empty one (no columns), which h5py cannot type by itself
                    env[name].attrs.create("units", np.array(layout["units"], dtype=object),
                                           dtype=h5py.string_dtype())
            env.attrs["n_records"] = 0
        runs = f.create_group("runs")
        for name in ("first_row", "rows") + self.RUN_FIELDS + ("time_units",):
            dtype = "i8" if name in ("first_row", "rows") else "f8" if name == "dt" else h5py.string_dtype()
            runs.create_dataset(name, shape=(0,), maxshape=(None,), chunks=(64,), dtype=dtype)
        self._begin_run(layout["run"])
        self._hold_open()
        try:
            f.flush()
        except Exception as exc:
            self._stop(exc, "the new file")
            raise
        self._kept = (0, None)

    def _open_file(self, how, mode):
        """Open the file (``how``: a :class:`_StagedFile` mode) and HDF5 on it (h5py ``mode``),
        writing through that :class:`_StagedFile`; returns the h5py file. An OSError names the
        file."""
        staged = None
        try:
            staged = _StagedFile(self.path, how)
            self._file = h5py.File(staged, mode)
        except BaseException as exc:
            if staged is not None:
                staged.close()
            if not isinstance(exc, OSError):
                raise
            reason = "another process has it open (locked)" if isinstance(exc, BlockingIOError) else \
                exc.strerror or exc
            raise type(exc)(f"HDF5 recorder: cannot {'open' if mode == 'r+' else 'create'} {self.path}: "
                            f"{reason}") from None
        self._staged = staged
        return self._file

    def _begin_run(self, run):
        """Describe the run that starts (``layout['run']``): continue the last row of /runs if the
        run is described alike, else add one; keep on the root (and on the times, their units)
        only the description every run of the file shares."""
        f = self._file
        shown = _h5_attrs(run)
        if self._shared is None:
            self._shared = shown
        else:
            for key in [k for k, v in self._shared.items() if k not in shown or shown[k] != v]:
                del self._shared[key]
                if key in f.attrs:
                    del f.attrs[key]
        dt = run.get("dt")
        row = {name: str(run.get(name, "")) for name in self.RUN_FIELDS}
        row["dt"] = float(dt) if isinstance(dt, (int, float, np.integer, np.floating)) else np.nan
        row["time_units"] = _time_units(run)
        for name in ("time", *(f"envelope/time_of_{x}" for x in ("min", "max", "absmax"))):
            if name in f and f[name].attrs.get("units", row["time_units"]) != row["time_units"]:
                del f[name].attrs["units"]
        if self._run is None or not _same_run(row, self._run):    # else the same analysis goes on
            runs = f["runs"]
            n = runs["rows"].shape[0]
            for name, value in dict(row, first_row=self._rows, rows=0).items():
                runs[name].resize((n + 1,))
                runs[name][n] = value
            self._run, self._run_first = row, self._rows
        # the current run's element of /runs/rows, written at every flush: selected once (h5py's
        # ds[i] = x costs some 65 µs a call, this low-level write 8)
        rows = f["runs/rows"]
        space = rows.id.get_space()
        space.select_hyperslab((rows.shape[0] - 1,), (1,))
        self._run_rows = (rows.id, h5py.h5s.create_simple((1,)), space)

    def write(self, times, values, envelope):
        if self._stopped is not None:
            raise self._stopped_error()
        if not self._unflushed:
            self._unflushed_from = float(times[0])
        self._last_time = float(times[-1])
        try:
            self._write(times, values, envelope)
        except Exception as exc:
            self._stop(exc, self._unwritten())
            raise

    def _hold_open(self):
        """Keep the datasets written at every chunk open for the run: the chunk being filled stays
        in HDF5's cache, written once per flush (opened for every chunk, it was read back and
        written again each time, and the lookups cost more than the writes)."""
        f = self._file
        self._open = {name: f[name] for name in ("time", "values", "envelope") if name in f}
        if "envelope" in f:
            self._open.update({name: f["envelope"][name] for name in f["envelope"]})

    def _write(self, times, values, envelope):
        held = self._open
        if values is not None:
            n0, n = held["time"].shape[0], len(times)
            held["time"].resize((n0 + n,))
            held["time"][n0:] = times
            held["values"].resize(n0 + n, axis=0)
            held["values"][n0:] = values
        if envelope is not None:
            for name in envelope.fields:
                held[name][...] = getattr(envelope, name)
            held["envelope"].attrs["n_records"] = envelope.n_records
        self._rows += len(times)
        self._unflushed += len(times)
        if self.flush_every is None or self._unflushed >= self.flush_every:
            self._flush()

    def _flush(self):
        """Write the current run's number of rows into /runs, then flush the file: the commit
        of :class:`_StagedFile`, all that a killed run keeps."""
        dataset, memory, element = self._run_rows
        dataset.write(memory, element, np.array([self._rows - self._run_first], dtype=np.int64))
        self._file.flush()
        self._unflushed = 0
        self._kept = (self._rows, self._last_time)

    def close(self, envelope):
        if self._file is None:                  # not open, or closed by a failed write
            return
        what = self._unwritten() if self._unflushed else "the file's last changes"
        try:
            self._flush()
            self._file.close()
        except Exception as exc:
            self._stop(exc, what)
            raise
        finally:
            self._release()

    def _unwritten(self):
        """The records since the last commit, in words (a failed write's)."""
        what = "records" if self._owner.history else "envelope of the steps"
        return f"the {what} of t = {self._unflushed_from:.6g} to {self._last_time:.6g} s"

    def _held(self):
        """What the file holds (its last commit), in words."""
        if self._kept is None:
            return "the file is empty"
        rows, time = self._kept
        history = self._owner.history
        if not rows:
            return f"the file holds no {'rows' if history else 'envelope'}"
        return f"the file holds the {f'{rows} rows' if history else f'envelope of the {rows} steps'} up to " \
               f"t = {time:.6g} s"

    def _stop(self, exc, what):
        """After ``exc`` while writing ``what``: if it is a write that failed (the
        :class:`_StagedFile`'s error, or an OSError), close the file as its last commit left it
        and raise the :class:`RecorderError` that says so; else return (the caller raises
        ``exc``)."""
        error = self._staged.error or (exc if isinstance(exc, OSError) else None)
        if error is None:
            return
        self._staged.discard()                  # HDF5 closes without touching the file again
        self._release()
        self._stopped = (error.strerror or str(error), self._held())
        raise self.failure(f"cannot write {what} ({self._stopped[0]}); {self._stopped[1]}") from None

    def _release(self):
        """Close HDF5's file, then the file (and its lock), if open."""
        if self._file is not None:
            file, staged = self._file, self._staged
            self._file = self._staged = self._run_rows = self._open = None
            try:
                file.close()
            finally:
                staged.close()

    def _stopped_error(self):
        """The RecorderError of a write or a run after a failed write: the record stopped there."""
        reason, held = self._stopped
        return self.failure(f"stopped at a write that failed ({reason}); {held}; a new recorder records to a "
                            "new file")

    def _read(self, name, empty):
        if self._file is not None:
            return self._file[name][...] if name in self._file else empty
        if not self._created:
            return empty
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


class _StagedFile:
    """The file of an :class:`HDF5Sink` as HDF5 sees it (h5py's file-object driver): HDF5's
    writes are held in memory and reach the file only when HDF5 flushes (:meth:`flush`, the
    commit), the file's new end first, then the bytes HDF5 rewrote within the old end.

    A commit that fails (a full disk, a file size limit) cuts the file back to its size before
    the commit and is raised (kept as ``error``); from then on HDF5's writes are dropped
    (:meth:`discard`), so HDF5 closes without touching the file again: the file on disk is the
    one its last commit left, a complete HDF5 file. A full disk cannot fail the rewrites of a
    file system that rewrites in place (ext4, XFS, NTFS: their blocks are the file's already);
    a copy-on-write one (btrfs, ZFS) can fail one, and the file is then as a kill in the
    middle of a flush leaves it. (HDF5 writing the file itself lost such an error where h5py
    released a dataset, left a file whose header claimed bytes never written, unreadable, and
    could crash the process at close.) The file is locked (``flock``, where the OS has it)
    while open, as HDF5 locks the files it writes.

    ``mode``: ``'new'`` (a file that must not exist), ``'replace'`` (emptied once locked: a
    file another process writes is refused, not emptied) or ``'continue'``.
    """

    FLAGS = {"new": os.O_CREAT | os.O_EXCL, "replace": os.O_CREAT, "continue": 0}

    def __init__(self, path, mode):
        self._raw = open(os.open(path, os.O_RDWR | getattr(os, "O_BINARY", 0) | self.FLAGS[mode], 0o666), "r+b",
                         buffering=0)
        try:
            if fcntl is not None:
                try:
                    fcntl.flock(self._raw.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
                except OSError as exc:          # a file system without locks (some NFS): unlocked, as HDF5
                    if exc.errno not in NO_LOCKS:
                        raise
            self._regular = os.path.isfile(path)      # not a device (/dev/full): one that can be cut back
            if mode == "replace" and self._regular:
                self._raw.truncate(0)
            self.committed = self._raw.seek(0, os.SEEK_END)     # [bytes] the file's size on disk
        except BaseException:
            self._raw.close()
            if mode == "new":
                os.remove(path)                 # made here, empty
            raise
        self._size = self.committed             # [bytes] the size HDF5 sees
        self._pending = {}                      # (address, length) -> bytes, the last written last
        self._position = 0
        self.error = None                       # the OSError of a failed commit
        self._discard = False

    def seek(self, offset, whence=os.SEEK_SET):
        base = {os.SEEK_SET: 0, os.SEEK_CUR: self._position, os.SEEK_END: self._size}[whence]
        self._position = base + offset
        return self._position

    def tell(self):
        return self._position

    def read(self, n):
        """``n`` bytes from the position as HDF5 wrote them: the file's, the pending writes over
        them, zeros past the end."""
        start, end = self._position, self._position + n
        data = bytearray(n)
        on_disk = min(end, self.committed) - start
        if on_disk > 0:
            self._raw.seek(start)
            view = memoryview(data)[:on_disk]
            while len(view):
                got = self._raw.readinto(view)
                if not got:
                    break
                view = view[got:]
        for (address, length), chunk in self._pending.items():
            lo, hi = max(address, start), min(address + length, end)
            if lo < hi:
                data[lo - start: hi - start] = chunk[lo - address: hi - address]
        self._position = end
        return bytes(data)

    def write(self, data):
        n = len(data)
        if not self._discard:
            key = (self._position, n)
            self._pending.pop(key, None)        # a rewrite of the same bytes: kept once, as the last
            self._pending[key] = bytes(data)    # a copy: h5py's driver may hand a view of HDF5's buffer
            self._size = max(self._size, self._position + n)
        self._position += n
        return n

    def truncate(self, size):
        if not self._discard:
            self._size = size
        return size

    def flush(self):
        """Commit: write the file's new end (one write, from its old end), then the rewritten
        bytes within the old end, then cut it to HDF5's size if that is smaller."""
        if self._discard or (not self._pending and self._size == self.committed):
            return
        old, new = self.committed, self._size
        try:
            if new > old:
                end = bytearray(new - old)
                for (address, length), chunk in self._pending.items():
                    lo, hi = max(address, old), min(address + length, new)
                    if lo < hi:
                        end[lo - old: hi - old] = memoryview(chunk)[lo - address: hi - address]
                self._write_at(old, end)
            for (address, length), chunk in self._pending.items():     # in the order written
                if address < old:
                    self._write_at(address, memoryview(chunk)[: old - address])
            if new < old:
                self._raw.truncate(new)
        except OSError as exc:
            self.error = exc
            self.discard()
            if self._regular and new > old:
                self._raw.truncate(old)         # what the failed write added past the old end
            raise
        self._pending.clear()
        self.committed = new

    def _write_at(self, address, data):
        view = memoryview(data)
        self._raw.seek(address)
        while len(view):
            view = view[self._raw.write(view):]

    def discard(self):
        """Drop HDF5's writes from now on (and those not committed)."""
        self._discard = True
        self._pending.clear()
        self._size = self.committed

    def close(self):
        self._raw.close()                       # and its lock


class TextSink(Sink):
    """OpenSees-style text file (``recorder Node/Element ... -file``).

    History recorder: one line per recorded step, ``[time] v1 v2 ...``, single spaces, each
    number as C++ ``ostream`` with ``precision`` significant digits (``'%.{p}g'``).
    Envelope-only recorder (``history=False``, OpenSees ``EnvelopeNode``/``EnvelopeElement``):
    three lines, min, max and absmax, written when the run ends (rewritten after each run);
    with ``time=True`` every value is preceded by the time it occurred (``t v`` pairs). A line
    of no numbers is not written, as OpenSees's ``DataFileStream`` writes none: a recorder of no
    columns (``recorder Element`` of elements without the response) leaves the file empty, or
    writes the times only (history with ``time=True``).

    The file is created, or truncated, when the sink is built (OpenSees truncates when the
    recorder command runs: scripts are re-run in place). Lines are flushed after every chunk;
    ``close_on_write`` reopens and closes the file for every chunk instead. A chunk that cannot
    be written (a full disk) is cut off the file again, so that it ends with the last whole
    line written, and raises :class:`RecorderError`; the next chunk tries the file again.
    """

    KIND = "text"

    def __init__(self, path, time=False, precision=6, close_on_write=False):
        self.path = _path("text recorder", path)
        if not is_count(precision, 0):
            raise ModelError(f"text recorder {self.path}: precision must be an integer >= 0, got {precision!r}")
        self.echo_time = as_flag(time, f"text recorder {self.path}", "time")
        self.close_on_write = as_flag(close_on_write, f"text recorder {self.path}", "close_on_write")
        self.precision = int(precision)
        try:
            with open(self.path, "w"):
                pass
        except OSError as exc:
            raise type(exc)(f"text recorder: cannot create {self.path}: {exc.strerror}") from None
        self._handle = None
        self._recorder = None
        self._size = 0           # [bytes] the file's whole lines
        self._rows = 0           # lines of history written
        self._last_time = None   # [s] the last step written (of the history) or handed over

    def check(self, recorder):
        super().check(recorder)
        if recorder.history and recorder.envelope is not None:
            raise ModelError(f"text recorder {self.path}: a text file holds the history (OpenSees Node/"
                             "Element recorder) or the envelope (EnvelopeNode/EnvelopeElement), not "
                             "both; use two recorders, or an HDF5Sink")
        if recorder.envelope is not None and recorder.envelope.concurrent:
            raise ModelError(f"text recorder {self.path}: a text file holds an envelope's three lines (OpenSees "
                             "EnvelopeNode/EnvelopeElement), not its concurrent values; use an HDF5Sink or memory")

    def open(self, layout, recorder):
        self._recorder = recorder
        if recorder.history and not self.close_on_write:
            self._handle = open(self.path, "ab")
            self._size = self._handle.seek(0, os.SEEK_END)     # whole lines: what the file holds now

    def write(self, times, values, envelope):
        if values is None or not (self.echo_time or values.shape[1]):   # the envelope's, or rows of no numbers:
            self._last_time = float(times[-1])                          # no line (OpenSees's DataFileStream::write)
            return
        text = format_g_bytes(values, self.precision, times if self.echo_time else None)
        if LINE_END != b"\n":
            text = text.replace(b"\n", LINE_END)
        try:
            if self.close_on_write:
                with open(self.path, "ab") as fh:
                    fh.write(text)
                    fh.flush()
                    size = fh.tell()
            else:
                if self._handle is None:        # after a failed write: try the file again
                    self._handle = open(self.path, "ab")
                self._handle.write(text)
                self._handle.flush()
                size = self._size + len(text)   # appended to the whole lines it held
        except OSError as exc:
            raise self._failed(f"the records of t = {times[0]:.6g} to {times[-1]:.6g} s", exc,
                               self._size) from None
        self._size, self._rows, self._last_time = size, self._rows + len(times), float(times[-1])

    def _failed(self, what, exc, size):
        """The RecorderError of a failed write of ``what``: the file closed without flushing
        what the write left in its buffer, and cut back to ``size`` bytes (whole lines)."""
        handle, self._handle = self._handle, None
        if handle is not None:
            try:
                handle.close()
            except OSError:
                pass                            # the same failure: its records are the ones reported
        held = self._held()
        if os.path.isfile(self.path):           # not a device (/dev/full)
            try:
                os.truncate(self.path, size)
            except OSError as cut:
                held += f" and part of the next ({cut.strerror or cut} when cutting it off)"
        return self.failure(f"cannot write {what} ({exc.strerror or exc}); {held}")

    def _held(self):
        """What the file holds, in words."""
        if not self._recorder.history:
            return "the file is empty (the recorder's envelope holds the values)"
        return f"the file holds the {self._rows} lines up to t = {self._last_time:.6g} s" if self._rows else \
            "the file holds no lines"

    def close(self, envelope):
        if self._handle is not None:
            self._handle.close()
            self._handle = None
        if self._recorder is not None and not self._recorder.history and envelope is not None:
            try:
                with open(self.path, "w") as fh:
                    fh.write(format_envelope(envelope, self.echo_time, self.precision))
            except OSError as exc:
                n = envelope.n_records
                what = f"the envelope of the {n} steps up to t = {self._last_time:.6g} s" if n else "the envelope"
                raise self._failed(what, exc, 0) from None

    @property
    def time(self):
        raise AttributeError(f"TextSink keeps no values in memory: read {self.path} (numpy.loadtxt)")

    @property
    def values(self):
        raise AttributeError(f"TextSink keeps no values in memory: read {self.path} (numpy.loadtxt)")


def check_own_files(who, recorders):
    """A ModelError naming ``who`` (the analysis), both recorders and the path when two of
    ``recorders`` write one file (their sinks' ``path``, compared as resolved absolute paths):
    two text recorders would interleave rows of different widths, two HDF5 recorders would
    fail at the analysis start. Called when an analysis is built; recorders without a file
    sink are skipped."""
    seen = {}
    for i, rec in enumerate(recorders):
        path = getattr(getattr(rec, "sink", None), "path", None)
        if not isinstance(path, str):
            continue
        key = os.path.normcase(os.path.realpath(path))
        if key in seen:
            j, first = seen[key]
            raise ModelError(f"{who}: recorders[{j}] {first!r} and recorders[{i}] {rec!r} both write {path}; "
                             "give each recorder its own file")
        seen[key] = (i, rec)


def format_rows(times, values, precision=6):
    """Lines as OpenSees's DataFileStream writes them: ``[t] v1 v2 ...\\n`` with ``%.{p}g``
    (compiled, :mod:`vtsi.recorders.number_text`)."""
    return format_g_rows(values, precision, times)


def format_envelope(envelope, echo_time=False, precision=6):
    """The three lines of OpenSees's envelope recorders (min, max, absmax), empty if nothing
    was recorded or there are no columns (OpenSees writes no line of no numbers); with
    ``echo_time`` each value is preceded by its time of occurrence."""
    if envelope.n_records == 0 or not len(envelope.min):
        return ""
    rows = []
    for name in ("min", "max", "absmax"):
        value = getattr(envelope, name)
        if echo_time:
            value = np.column_stack([getattr(envelope, "time_of_" + name), value]).ravel()
        rows.append(value)
    return format_rows(None, np.array(rows), precision)


def _time_units(run):
    """The units of the recorded times of the run described by ``run``: 's', or '' for a static
    run (its pseudo-time t0 + k dλ, the load factor under a Linear series)."""
    return "" if run.get("analysis") == "static" else "s"


def _same_run(a, b):
    """Whether two /runs rows describe the same analysis (a NaN dt equals a NaN dt)."""
    return a.keys() == b.keys() and all(
        a[k] == b[k] or (k == "dt" and np.isnan(a[k]) and np.isnan(b[k])) for k in a)


def _h5_attrs(attrs):
    out = {}
    for key, value in attrs.items():
        if isinstance(value, (str, bool, int, float, np.integer, np.floating)):
            out[key] = value
        else:
            out[key] = str(value)
    return out


def _path(who, path):
    """``path`` as a str, or a ModelError naming ``who`` and the value (not a name, or empty)."""
    try:
        name = os.fspath(path)
    except TypeError:
        name = None
    if not isinstance(name, str):
        raise ModelError(f"{who}: path must be a file name (str or os.PathLike), got {path!r}")
    if not name.strip():
        raise ModelError(f"{who}: path must be a non-empty file name, got {path!r}")
    return name


def _check_compression(path, compression, options):
    """A ModelError naming the filter and h5py's reason if h5py cannot compress /values with
    ``compression`` and ``options`` (tried on an in-memory file: nothing is written)."""
    if compression is None and options is None:
        return
    try:
        with h5py.File(f"{path}.check", "w", driver="core", backing_store=False) as f:
            f.create_dataset("values", shape=(0, 1), maxshape=(None, 1), chunks=(64, 1), dtype="f8",
                             compression=compression, compression_opts=options)
    except (ValueError, TypeError) as exc:
        raise ModelError(f"HDF5 recorder {path}: compression {compression!r} with options {options!r} is not "
                         f"available: {exc}") from None
