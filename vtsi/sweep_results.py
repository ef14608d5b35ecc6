"""The results file of a sweep (HDF5, one file per sweep) and its reader.

Layout (docs/sweeps.md)::

    /                      attrs: format 'vtsi-sweep', format_version, vtsi_version, created,
                           identity (JSON: bridge, settings, outputs, trains, speeds, seeds)
    /train, /speed_kmh, /seed          the envelope tables' coordinates (seed -1: smooth rail)
    /bridge/               frequencies_hz (3,: the first vertical frequencies n₀, n₂, n₃ of a
                           single deck; of several, the model's first three), deck_frequencies_hz
                           (n_decks, 3: each deck's n₀, n₂, n₃), en_cutoff_hz (the EN 1990 A2 cut-off:
                           the largest of the decks', vtsi.passage.en_cutoff_hz),
                           frequencies_to_cutoff_hz (every vertical frequency of the model up to
                           en_cutoff_hz, the approaches' and axial modes left out; not in a file
                           of an older vtsi), deck_nodes and
                           deck_x_m (every node of the track, in x order, and its x: the approaches'
                           too; those on a deck lie within deck_ends_m, vtsi.deck_record.deck_nodes),
                           midspan_nodes, span_lengths_m, span_ends_m (n_spans, 2: each
                           span's supports' x), deck_ends_m (n_decks, 2: each deck's ends, spans
                           and overhangs), mode_shapes_uy (at deck_nodes), track_on_a_structure
                           (a rail on pads over the deck: outputs are the rail's), track_end_nodes,
                           track_end_x_m and track_end_sag_m (2,: the track's first and last node,
                           its x and its static sag [m] under track_end_load_n [N], the trains'
                           heaviest static wheel load; 0 for a node fixed in uy:
                           vtsi.track_ends)
    /envelopes/<q>         (n_train, n_speed, n_seed) the extreme of quantity q over the output's
                           columns per case (NaN: not run yet, or not produced by that train);
                           <q>_where (the column: node tag, contact wheel or car; attrs kind,
                           holds, missing -1), <q>_time [s]; attrs units, output, statistic, dims
    /static/<name>         for displacement, rotation and bending-moment outputs: trains (n_train,
                           2, n_columns), lm71 and sw0 (2, n_columns), static min and max under
                           each train's static axle loads and under Load Models 71 and SW/0 (α =
                           1) (vtsi.influence; a file of an older vtsi has no sw0)
    /trains/               one row per train, in /train's order: name, n_cars, n_dof, length_m,
                           characteristic_length_m, body_runout_s (n_train,); axle_offsets_m,
                           static_wheel_loads_N [N] and wheel_car (each wheel's car, 0: the
                           first) of every train end to end, train i's axles the rows
                           axle_ptr[i]:axle_ptr[i + 1]; contact_wheels by contact_ptr
    /outputs/<name>        attrs response, units, kind of column ('node', 'contact wheel', 'car'),
                           rows (of an envelope), history, cutoff_hz (a response in the modes up
                           to a cut-off [Hz]; absent: the full response); columns: the node tags (n_columns,)
                           of a node output, or per train its wheel or car indices (n_train,
                           n_columns) of a vehicle output (-1 pads a train with fewer; none: the
                           train does not produce it)
    /cases/                one table of every case, appended batch by batch: train (n,) (its
                           index in /train), speed_kmh, seed, n_steps, seconds, x_head0 [m],
                           deck_flights (n,) (contact wheels that flew on a deck, raw contact;
                           -1: not counted, contact other than 'lcp'; absent in a file of an
                           older vtsi) and per output <name> (n, 6, n_columns), each case's
                           envelope (rows min, max, absmax, time_of_min, time_of_max,
                           time_of_absmax; NaN in the columns its train does not have; a vehicle
                           output's counts the bridge only, vtsi.passage.PassageRunner.counted,
                           and <name>_whole_run holds its envelope over the whole run); with a history,
                           histories/<train>/<speed>kmh/<seed>/<name>_time (m,) [s] and
                           <name>_values (m, n_columns) (attrs response, units, kind, cutoff_hz
                           as /outputs; group attrs train, speed_kmh, seed, x_head0, n_steps)
    /histories/<train>/<speed>kmh/<seed>/   the cases Sweep.record_histories re-ran: per output
                           <name>_time [s], <name>_values (attrs as above), <name>_columns;
                           attrs train, speed_kmh, seed, x_head0 [m], n_steps

Quantities q are ``<output>_<statistic>``: 'min' and 'max' for displacements, rotations,
bending moments and contact forces, 'absmax' for velocities and accelerations (``deflection_min`` is the largest downward
deflection: y is positive up).

Writing is atomic per batch: the file is read into memory, the batch written there, the whole
written to ``<file>.partial`` by Python's own writes (HDF5 writes no file on disk: on a full
disk it lost the error) and renamed over the file (``os.replace``), so the file on disk is
always a complete, readable results file, whenever the writing process is killed or its disk
fills up.

One writer at a time: a writer holds ``<file>.lock`` (an OS lock, ``flock`` or ``msvcrt.locking``,
that dies with its process, so a killed run's lock is taken over; the file holds the pid) and a
second writer of the same file is refused naming the first one's pid (:class:`ResultsFileInUse`).
With ``overwrite``, an existing file is kept until the new sweep is complete: the new sweep is
written to ``<file>.new`` (a complete results file itself, resumed by the next ``overwrite`` of
the same sweep) and renamed over the file only then (:meth:`ResultsWriter.commit`).
"""
import datetime
import errno
import hashlib
import json
import numbers
import os
import socket
import uuid
import weakref

import h5py
import numpy as np

from vtsi.version import __version__
from vtsi.codes.en1991_2 import determinant_length
from vtsi.damping import deck_frequencies_table
from vtsi.errors import SweepError, as_number
from vtsi.influence import StaticEnvelopes
from vtsi.modal_bridge import CUTOFF_MARGIN
from vtsi.models.catalogue import train_names
from vtsi.passage import body_runout, en_cutoff_hz

try:                                    # POSIX
    import fcntl
except ImportError:                     # Windows
    fcntl = None
try:
    import msvcrt
except ImportError:
    msvcrt = None

FORMAT, FORMAT_VERSION = "vtsi-sweep", 6
PARTIAL, STAGING, LOCK = ".partial", ".new", ".lock"   # suffixes of the files beside a results file
IDENTITY_ORDER = ("bridge", "settings", "outputs", "trains", "speeds_kmh", "seeds", "train_fingerprints",
                  "bridge_fingerprint")
"""The order in which a resumed sweep's identity is compared with its file's: what a user sets,
the bridge's description before what is derived from it (the default dt, an output's
cutoff_hz), the hashes last (so that a changed damping is named as such, not as a matrices'
hash)."""
RUN_LISTS = {"trains": ("trains", ""), "speeds_kmh": ("speeds", " km/h"), "seeds": ("seeds", ""),
             "outputs": ("outputs", "")}
"""The identity's lists of what a sweep runs: the noun and unit a refusal counts their items in."""
ENVELOPE_ROWS = ("min", "max", "absmax", "time_of_min", "time_of_max", "time_of_absmax")
WHOLE_RUN = "_whole_run"   # /cases/<vehicle output>_whole_run: its envelope over the whole run, not only the bridge
STATISTICS = {"disp": ("min", "max"), "vel": ("absmax",), "accel": ("absmax",), "rotation": ("min", "max"),
              "moment": ("min", "max"),
              "contact_force": ("min", "max"), "car_body_accel": ("absmax",)}
COLUMN_KIND = {"contact_force": "contact wheel", "car_body_accel": "car"}
UNITS = {"disp": "m", "vel": "m/s", "accel": "m/s^2", "rotation": "rad", "moment": "N m", "contact_force": "N",
         "car_body_accel": "m/s^2"}


WHERE_HOLDS = {"node": "the node tag", "contact wheel": "the contact wheel's index in its train (0: the first)",
               "car": "the car's index in its train (0: the first)"}
"""What an envelope's ``<q>_where`` holds, by the kind of its output's columns (COLUMN_KIND)."""


def deck_ranges(bridge):
    """(n_decks, 2) the x [m] of each deck's ends, its spans and overhangs (/bridge/deck_ends_m,
    :mod:`vtsi.deck`); in a results file of an older vtsi, which kept none, from the first span's
    first support to the last span's last."""
    if "deck_ends_m" in bridge:
        return np.asarray(bridge["deck_ends_m"], dtype=float).reshape(-1, 2)
    ends = np.asarray(bridge["span_ends_m"], dtype=float).reshape(-1, 2)
    return np.array([[ends[0, 0], ends[-1, 1]]])


def x_tolerance(bridge):
    """[m] how far apart two x of the bridge record ``bridge`` may lie and be one (rounding)."""
    ends = np.asarray(bridge["span_ends_m"], dtype=float)
    return 1e-9 * max(float(np.ptp(ends)), 1.0)


def span_decks(bridge):
    """(n_spans,) the deck (row of :func:`deck_ranges`) of each span."""
    decks, tol = deck_ranges(bridge), x_tolerance(bridge)
    middle = np.asarray(bridge["span_ends_m"], dtype=float).reshape(-1, 2).mean(axis=1)
    return np.array([int(np.flatnonzero((decks[:, 0] - tol <= m) & (m <= decks[:, 1] + tol))[0]) for m in middle])


def deck_first_frequencies(bridge):
    """(n_decks,) each deck's first vertical frequency n₀ [Hz] (:func:`~vtsi.damping.deck_frequencies_table`)."""
    return deck_frequencies_table(bridge)[:, 0]


def bridge_text(bridge):
    """One line: what vtsi read of the bridge from its record ``bridge`` (/bridge): its decks,
    spans [m], each deck's n₀ [Hz], the EN cut-off [Hz] (:func:`~vtsi.passage.en_cutoff_hz`) and
    each deck's L_Φ [m] (EN 1991-2 Table 6.2); e.g. 'bridge: 2 decks; spans 15 + 15 m; n0 10.66
    Hz; EN cut-off 96.03 Hz; L_Phi 15 m' (a value the decks share is given once)."""
    spans = np.asarray(bridge["span_lengths_m"], dtype=float).ravel()
    decks, n_decks = span_decks(bridge), len(deck_ranges(bridge))
    L_phi = [determinant_length(spans[decks == d]) for d in range(n_decks) if np.any(decks == d)]
    if len(spans) <= 6:
        span_list = f"span{'s' * (len(spans) > 1)} {' + '.join(f'{x:g}' for x in spans)} m"
    else:
        span_list = f"{len(spans)} spans of {spans.min():g} to {spans.max():g} m"
    return (f"bridge: {n_decks} deck{'s' * (n_decks > 1)}; {span_list}; n0 "
            f"{_listed(deck_first_frequencies(bridge))} Hz; EN cut-off {significant_text(en_cutoff_hz(bridge))} Hz; "
            f"L_Phi {_listed(L_phi)} m")


def significant_text(value, digits=4):
    """``value`` to ``digits`` significant digits, without a trailing dot or zeros, never in
    exponent form from 10^digits up: 1424.3 -> '1424', 96.034 -> '96.03', 30.0 -> '30',
    12345.6 -> '12346'."""
    text = f"{float(value):.{digits}g}"
    return f"{float(value):.0f}" if "e+" in text else text


def _listed(values, most=4):
    """``values`` as :func:`significant_text`, comma-separated: once if they all read the same,
    as a range if more than ``most`` differ."""
    text = [significant_text(v) for v in values]
    if len(set(text)) == 1:
        return text[0]
    return ", ".join(text) if len(text) <= most else f"{significant_text(min(values))} to {significant_text(max(values))}"


def canonical_train_name(name):
    """A train's name as a sweep reads it: a catalogue name in the catalogue's spelling (case is
    ignored; 'A1' is 'HSLM-A1'), anything else (an axle-table path) as given, stripped. The one
    reading of a train's name (:func:`vtsi.sweep.train_list`, :class:`SweepResults`)."""
    item = str(name).strip()
    canonical = {n.upper(): n for n in train_names()}
    key = item.upper()
    return canonical.get(key) or canonical.get(f"HSLM-{key}") or item


def output_description(response, cutoff_hz=None):
    """The attributes that say what an output's values are: response, units, kind of column and,
    for a response in the modes up to a cut-off, cutoff_hz [Hz] (none: the full response)."""
    out = {"response": response, "units": UNITS[response], "kind": COLUMN_KIND.get(response, "node")}
    if cutoff_hz is not None:
        out["cutoff_hz"] = float(cutoff_hz)
    return out


def open_results(path, mode="r"):
    """``h5py.File(path, mode)``, or a SweepError naming the file: :class:`ResultsFileInUse` when
    another process holds it open for writing (HDF5's file lock), else 'not a readable HDF5
    file' with h5py's reason."""
    try:
        return h5py.File(path, mode)
    except OSError as exc:
        if exc.errno in (errno.EAGAIN, errno.EWOULDBLOCK, errno.EACCES) and "lock" in str(exc) \
                or "unable to lock file" in str(exc):
            raise ResultsFileInUse(f"results file {path} is in use by another process, which holds it open for "
                                   "writing (HDF5's file lock); wait for that process to close it") from None
        raise SweepError(f"results file {path}: not a readable HDF5 file ({exc})") from None


def case_key(train, speed_kmh, seed):
    """A case's name, '<train>/<speed>kmh/<seed>' ('smooth' for seed -1): its group path under
    /histories and under /cases/histories."""
    return f"{train_key(train)}/{_speed_seed(speed_kmh, seed)}"


def train_key(train):
    """The group name of a train ('/' is not allowed in a name)."""
    return str(train).replace("/", "|")


def _speed_seed(speed_kmh, seed):
    return f"{float(speed_kmh):.10g}kmh/{'smooth' if seed < 0 else f'seed{int(seed)}'}"


def _append(group, name, rows, dtype=float):
    """Append ``rows`` (n, ...) to the resizable dataset ``name`` of ``group`` (created on first use)."""
    rows = np.asarray(rows, dtype=dtype)
    if name not in group:
        group.create_dataset(name, data=rows, maxshape=(None,) + rows.shape[1:], chunks=True)
        return
    ds = group[name]
    n = ds.shape[0]
    ds.resize(n + rows.shape[0], axis=0)
    ds[n:] = rows


def _column_table(per_train):
    """Per train its vehicle-output columns as one (n_train, n_columns) table, -1 padding."""
    table = np.full((len(per_train), max([len(c) for c in per_train] + [0])), -1, dtype=np.int64)
    for i, columns in enumerate(per_train):
        table[i, : len(columns)] = columns
    return table


def _train_table(group, trains):
    """The trains' axle data as one row per train (ragged arrays end to end, with pointers)."""
    group["name"] = np.array([t.name for t in trains], dtype=h5py.string_dtype())
    group["n_cars"] = np.array([len(t.cars) for t in trains], dtype=np.int64)
    group["n_dof"] = np.array([t.n_dof for t in trains], dtype=np.int64)
    group["length_m"] = np.array([t.length for t in trains], dtype=float)
    group["characteristic_length_m"] = np.array([t.characteristic_length or np.nan for t in trains], dtype=float)
    group["axle_ptr"] = np.cumsum([0] + [len(t.wheel_offsets) for t in trains]).astype(np.int64)
    group["axle_offsets_m"] = np.concatenate([np.asarray(t.wheel_offsets, dtype=float) for t in trains])
    group["static_wheel_loads_N"] = np.concatenate([np.asarray(t.static_wheel_loads, dtype=float) for t in trains])
    group["wheel_car"] = np.concatenate([np.asarray(t.wheel_car, dtype=np.int64) for t in trains])
    contact = [t.contact_wheels for t in trains]
    group["contact_ptr"] = np.cumsum([0] + [len(c) for c in contact]).astype(np.int64)
    group["contact_wheels"] = np.concatenate(contact)
    runouts = [[body_runout(car) for car in t.cars if "body_y" in car.dof_names] for t in trains]
    group["body_runout_s"] = np.array([max(r) if r else np.nan for r in runouts], dtype=float)
    group["body_runout_s"].attrs["note"] = ("how long a car body's acceleration counts after its last wheel left a "
                                            "deck (half a period of its lowest mode, wheels held; the longest of "
                                            "the train's cars)")


def quantities(outputs):
    """``[(quantity, output, statistic, units)]`` of the envelope tables of ``outputs`` (dicts or
    Output objects)."""
    out = []
    for o in outputs:
        name, response = (o["name"], o["response"]) if isinstance(o, dict) else (o.name, o.response)
        units = UNITS[response]
        for stat in STATISTICS[response]:
            out.append((f"{name}_{stat}", name, stat, units))
    return out


def staging_path(path):
    """Where ``overwrite`` writes a new sweep while the results file ``path`` it replaces stays
    (renamed over it when the new sweep is complete)."""
    return os.fspath(path) + STAGING


class ResultsFileRefused(SweepError):
    """A results file a sweep cannot write, found before any passage runs (``vtsi sweep`` exits 2,
    a bad input): its folder missing or not writable, a lock file that cannot be created, an
    existing file without resume or overwrite, of another sweep or unreadable, a new file that
    cannot be written (:class:`ResultsWriter`)."""


class ResultsFileInUse(ResultsFileRefused):
    """Another process is writing the results file: another sweep (it holds the file's lock,
    ``<file>.lock``), or any process holding the file open for writing (HDF5's own file lock)."""


class ResultsFileLock:
    """The lock of the results file ``path``: ``<path>.lock``, locked by ``flock`` (POSIX) or
    ``msvcrt.locking`` (Windows). The OS drops such a lock when its process dies, so the lock
    of a killed run is taken over; the file holds the pid and host of the run that holds it,
    for the message that refuses a second run.

    A ``flock`` belongs to the open file, which a forked process shares: a child forked while
    the lock is held (a process pool's worker) closes its copy at once (:meth:`_leave_to_parent`),
    so that the lock dies with the process that took it, not with the last of its children."""

    WINDOWS_OFFSET = 4096        # msvcrt locks bytes: a byte past the pid, which stays readable
    _held = weakref.WeakSet()    # the locks this process holds (a forked child closes their files)

    def __init__(self, path):
        self.path, self.fd = path + LOCK, None
        for _ in range(100):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise SweepError(f"results file {path}: cannot create its lock file {self.path} "
                                 f"({exc.strerror or exc})") from None
            if not self._try_lock(fd):
                holder = self._holder(fd)
                os.close(fd)
                raise ResultsFileInUse(f"results file {path} is being written by another sweep ({holder}); "
                                       "wait for it to end, or use another file")
            if self._same_file(fd):
                break
            os.close(fd)        # a run that ended removed the lock file we locked: lock the new one
        else:
            raise SweepError(f"results file {path}: cannot lock {self.path}")
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, f"{os.getpid()} {socket.gethostname()}\n".encode())
        self.fd = fd
        ResultsFileLock._held.add(self)

    @classmethod
    def _leave_to_parent(cls):
        """In a child just forked: close the lock files it inherited, without unlocking them
        (the parent holds the locks; the child neither holds nor releases them)."""
        for lock in list(cls._held):
            if lock.fd is not None:
                os.close(lock.fd)
                lock.fd = None
        cls._held.clear()

    @classmethod
    def _try_lock(cls, fd):
        """Lock ``fd``; False when another process holds the lock."""
        try:
            if fcntl is not None:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            elif msvcrt is not None:
                os.lseek(fd, cls.WINDOWS_OFFSET, os.SEEK_SET)
                msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except (BlockingIOError, PermissionError):
            return False
        except OSError:          # POSIX: a file system without locks (ENOLCK): on unlocked; Windows: held
            return fcntl is not None
        return True

    def _same_file(self, fd):
        if fcntl is None:
            return True                  # Windows: an open file is not removed
        try:
            here, there = os.fstat(fd), os.stat(self.path)
        except OSError:
            return False
        return (here.st_dev, here.st_ino) == (there.st_dev, there.st_ino)

    @staticmethod
    def _holder(fd):
        try:
            os.lseek(fd, 0, os.SEEK_SET)
            words = os.read(fd, 256).decode(errors="replace").split()
        except OSError:
            words = []
        if not words:
            return "pid unknown"
        host = f" on {words[1]}" if len(words) > 1 and words[1] != socket.gethostname() else ""
        return f"pid {words[0]}{host}"

    def release(self):
        if self.fd is None:
            return
        fd, self.fd = self.fd, None
        ResultsFileLock._held.discard(self)
        if fcntl is not None:
            try:
                os.remove(self.path)     # while locked: a run waiting on it sees the file gone
            except OSError:
                pass
            os.close(fd)
            return
        try:
            if msvcrt is not None:
                os.lseek(fd, self.WINDOWS_OFFSET, os.SEEK_SET)
                msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        except OSError:
            pass
        os.close(fd)
        try:
            os.remove(self.path)
        except OSError:                  # another run holds it now
            pass


if hasattr(os, "register_at_fork"):     # POSIX (Windows does not fork)
    os.register_at_fork(after_in_child=ResultsFileLock._leave_to_parent)


def _header(f, name):
    """``(format_version, identity)`` of the open results file ``f`` (``name``: its path), or a
    SweepError naming the file and what is wrong with it."""
    if f.attrs.get("format") != FORMAT:
        raise SweepError(f"results file {name} is not a vtsi sweep results file")
    version = f.attrs.get("format_version")
    if isinstance(version, (bool, np.bool_)) or not isinstance(version, numbers.Real) \
            or not float(version).is_integer():
        raise SweepError(f"results file {name}: its format_version {version!r} is not a whole number "
                         "(a damaged file)")
    version = int(version)
    if version != FORMAT_VERSION:
        return version, None
    if "identity" not in f.attrs:
        raise SweepError(f"results file {name}: it has no identity attribute (a damaged file)")
    try:
        identity = json.loads(f.attrs["identity"])
    except (TypeError, ValueError):
        raise SweepError(f"results file {name}: its identity attribute is not JSON (a damaged file)") from None
    missing = [k for k in ("outputs", "trains", "speeds_kmh", "seeds") if not isinstance(identity, dict)
               or k not in identity]
    if missing:
        raise SweepError(f"results file {name}: its identity lacks {missing[0]!r} (a damaged file)")
    return version, identity


def train_fingerprint(train, length_m=None):
    """A hash of what a sweep sees of ``train`` (a :class:`~vtsi.vehicle.Train`): its wheels'
    offsets, static loads and dofs, its cars' matrices and gravity loads, and its characteristic
    length D (0 without one), which places the resonance speeds; not its speed. ``length_m`` [m]:
    a D to hash in place of the train's (0.0: none), the hash of the train with another D."""
    digest = hashlib.sha256()
    length = train.characteristic_length if length_m is None else length_m
    for part in (train.wheel_offsets, train.static_wheel_loads, train.force_wheels, train.wheel_dofs,
                 train.gravity_load, [length or 0.0]):
        digest.update(np.ascontiguousarray(part, dtype=float).tobytes())
    for matrix in (train.M, train.C, train.K):
        m = matrix.tocsr()
        for part in (m.indptr, m.indices, m.data):
            digest.update(np.ascontiguousarray(part).tobytes())
    return digest.hexdigest()


def _first_difference(a, b, path=()):
    """The first difference between the identities ``a`` (this sweep's) and ``b`` (the file's):
    ``(path, value here, value in the file)`` (None: missing), or None when they are equal. Keys
    in IDENTITY_ORDER first, a dict's others sorted; the bridge's description is one value
    (:func:`_describe` names each of its keys that differ), and so is each list of what the
    sweep runs (:data:`RUN_LISTS`) unless both name the same items in the same order; other
    lists of one length are compared element by element."""
    if isinstance(a, dict) and isinstance(b, dict) and path != ("bridge",):
        keys = set(a) | set(b)
        first = [k for k in IDENTITY_ORDER if k in keys] if not path else []
        for key in first + sorted(keys - set(first)):
            if key not in a or key not in b:
                return path + (key,), a.get(key), b.get(key)
            diff = _first_difference(a[key], b[key], path + (key,))
            if diff:
                return diff
        return None
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b) \
            and (len(path) != 1 or path[0] not in RUN_LISTS or _item_names(a) == _item_names(b)):
        for k, (x, y) in enumerate(zip(a, b)):
            diff = _first_difference(x, y, path + (k,))
            if diff:
                return diff
        return None
    return None if a == b else (path, a, b)


def _axle_tables_as_stored(identity, stored):
    """``(identity, names)``: a sweep's ``identity`` with each axle table that the file's identity
    ``stored`` holds under another name, with the same content (its train_fingerprints: the same
    table by another path, 'tgv.csv' given as '../tgv.csv' from another folder), named as the
    file names it; ``names`` {name here: name in the file} of those. Catalogue trains, and
    tables whose content the file holds under none or several of its other names, are left as
    they are."""
    catalogue = set(train_names())
    mine, theirs = identity.get("train_fingerprints") or {}, stored.get("train_fingerprints")
    if not isinstance(theirs, dict) or not isinstance(stored.get("trains"), list):
        return identity, {}
    here = [t for t in identity["trains"] if t not in catalogue and t not in stored["trains"]]
    there = [t for t in stored["trains"] if t not in catalogue and t not in identity["trains"]]
    prints_here, prints_there = [mine.get(t) for t in here], [theirs.get(t) for t in there]
    names = {t: there[prints_there.index(p)] for t, p in zip(here, prints_here)
             if p is not None and prints_here.count(p) == 1 and prints_there.count(p) == 1}
    if not names:
        return identity, {}
    return dict(identity, trains=[names.get(t, t) for t in identity["trains"]],
                train_fingerprints={names.get(t, t): p for t, p in mine.items()}), names


def _modal_default_as_stored(identity, stored, cutoff_hz):
    """The file's identity ``stored`` with the modal_hz that a modal sweep of an older vtsi left
    None made the number it took, CUTOFF_MARGIN × the EN cut-off ``cutoff_hz`` [Hz] (or this
    sweep's ``identity``'s modal_hz where it equals that to 1e-9: the value the refusal names,
    given, continues the file); ``stored`` itself otherwise."""
    there = stored.get("settings")
    if not isinstance(there, dict) or there.get("bridge", "fe") == "fe" or there.get("modal_hz") is not None:
        return stored
    old = CUTOFF_MARGIN * cutoff_hz
    mine = (identity.get("settings") or {}).get("modal_hz")
    value = mine if isinstance(mine, float) and abs(mine - old) <= 1e-9 * old else old
    return dict(stored, settings=dict(there, modal_hz=value))


def _item_names(items):
    """A list's items as :func:`_describe` names them: an output by its name, others as they are."""
    return [x.get("name") if isinstance(x, dict) else x for x in items]


def _listing(items, noun, unit):
    """Items of a list in words: up to four named ('405, 410 and 415 km/h'), more counted: numbers
    with their range ('53 speeds from 142 to 418 km/h'), others by the first three ('HSLM-A2,
    HSLM-A3, HSLM-A4 and 6 more trains')."""
    numeric = all(isinstance(x, numbers.Real) and not isinstance(x, bool) for x in items)
    text = [f"{x:.10g}" if numeric else str(x) for x in items]
    if len(items) > 4 and numeric:
        return f"{len(items)} {noun} from {min(items):.10g} to {max(items):.10g}{unit}"
    if len(items) > 4:
        return f"{', '.join(text[:3])} and {len(items) - 3} more {noun}"
    return (f"{', '.join(text[:-1])} and {text[-1]}" if len(text) > 1 else text[0]) + unit


def _describe(diff, runner):
    """A difference of :func:`_first_difference` in words; ``runner`` (a
    :class:`~vtsi.passage.PassageRunner`) builds a train whose fingerprint differs, to tell a D
    the file's run had not (an axle table's D from its signature, since 2026-11-27) from other
    changes. The bridge's description: each key that differs, in this sweep's order (a beam's
    spans before the I_m4 its f1_Hz gives); a list of what the sweep runs: what is only here
    and what only in the file, or the first item out of place."""
    path, here, there = diff
    if path[0] == "train_fingerprints" and len(path) == 2:
        train = runner.train(path[1], 1.0)
        if train.characteristic_length is not None and train_fingerprint(train, 0.0) == there:
            source = ("" if train.signature_peak is None else
                      ": from its dynamic signature, which vtsi reads from an axle table since 2026-11-27")
            return (f"train {path[1]} differs from the one it ran with in its characteristic length D only (none "
                    f"in the file, {train.characteristic_length:g} m here{source})")
        return (f"train {path[1]} differs from the one it ran with in its axles, loads, cars or characteristic "
                "length D: an edited axle table, or a catalogue train changed between vtsi versions")
    if path == ("bridge_fingerprint",):
        return "it differs in the bridge's matrices or track (bridge_fingerprint)"

    def show(value):
        text = "none" if value is None else json.dumps(value, sort_keys=True)
        return text if len(text) <= 60 else text[:57] + "..."
    if path == ("bridge",) and isinstance(here, dict) and isinstance(there, dict):
        keys = [k for k in list(here) + sorted(set(there) - set(here)) if here.get(k) != there.get(k)]
        return "it differs in " + ", ".join(f"bridge.{k} ({show(here.get(k))} here, {show(there.get(k))} in "
                                            "the file)" for k in keys)
    if len(path) == 1 and path[0] in RUN_LISTS and isinstance(here, list) and isinstance(there, list):
        a, b = _item_names(here), _item_names(there)
        parts = [f"{_listing(only, *RUN_LISTS[path[0]])} {'is' if len(only) == 1 else 'are'} {side}"
                 for only, side in (([x for x in a if x not in b], "here, not in the file"),
                                    ([x for x in b if x not in a], "in the file, not here")) if only]
        if parts:
            return f"it differs in {path[0]} ({'; '.join(parts)})"
        k = next(k for k in range(max(len(a), len(b))) if k >= min(len(a), len(b)) or a[k] != b[k])
        return (f"it differs in {path[0]}[{k}] ({show(a[k] if k < len(a) else None)} here, "
                f"{show(b[k] if k < len(b) else None)} in the file: the same {RUN_LISTS[path[0]][0]} in another order)")
    where = "".join(f"[{key}]" if isinstance(key, int) else f".{key}" for key in path).lstrip(".")
    hint = ""
    if path == ("settings", "dt") and there is not None:     # the default dt follows the bridge's cut-off
        hint = f" (to continue that file, give its dt = {there:g} s)"
    if path == ("settings", "modal_hz") and there is not None:   # the default basis follows the outputs and trains
        hint = f" (to continue that file, give its modal_hz = {there:.10g} Hz)"
    if path == ("settings", "exact_events"):
        hint = (" (to continue that file, give --exact-events or [analysis] exact_events = true)" if there else
                " (to continue that file, give --no-exact-events, or exact_events = false in [analysis])")
    if path == ("settings", "hslm_b"):                           # none: vtsi's reading of EN 1991-2 Figure 6.13
        hint = (" (to continue that file, give no --hslm-b: it ran vtsi's reading of EN 1991-2 Figure 6.13)"
                if there is None else f" (to continue that file, give its --hslm-b {there[0]},{there[1]:g})")
    return f"it differs in {where} ({show(here)} here, {show(there)} in the file){hint}"


class ResultsWriter:
    """Creates (or reopens, to resume) a sweep's results file and writes batches of cases.

    It holds the file's lock (:class:`ResultsFileLock`) from its start to :meth:`close`; with
    ``overwrite`` it writes the new sweep to :func:`staging_path` and :meth:`commit` puts it in
    place of the old file (see the module docstring). Every refusal of the file before a
    passage runs is a :class:`ResultsFileRefused`. ``adding_histories``: the writer of
    :meth:`~vtsi.sweep.Sweep.record_histories`, whose refusal of a file of another sweep says to
    build the Sweep as the file's (it cannot overwrite), and which refuses a missing file (it
    adds to a sweep's file, never creates one).

    An axle table is named in the file as it was first given: the same table (same content, its
    train_fingerprints) given by another path ('../tgv.csv' for 'tgv.csv', the sweep resumed from
    another folder) continues the file, and its cases and histories are written under the file's
    name; :attr:`stored_names` maps the one to the other."""

    def __init__(self, path, identity, runner, resume=False, overwrite=False, adding_histories=False):
        self.path = self.target = None if path is None else os.fspath(path)
        self.identity = json.loads(json.dumps(identity))
        self.runner = runner
        self.adding_histories = adding_histories
        self._memory = self._lock = None
        self.stored_names = {}          # an axle table's name here -> in the file, where they differ
        if self.path is None:
            self._create()
            return
        try:
            if os.path.isdir(self.path):
                raise SweepError(f"results file {self.path} is a directory")
            folder = os.path.dirname(os.path.abspath(self.path))
            if not os.path.isdir(folder):
                raise SweepError(f"results file {self.path}: the directory {folder} does not exist")
            if not os.access(folder, os.W_OK | os.X_OK):
                raise SweepError(f"results file {self.path}: cannot write in {folder}")
            self._lock = ResultsFileLock(self.path)
            self._start(resume, overwrite)
        except BaseException as exc:
            self.close()
            if isinstance(exc, SweepError) and not isinstance(exc, ResultsFileRefused):
                raise ResultsFileRefused(str(exc)) from None
            raise

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _start(self, resume, overwrite):
        if not os.path.exists(self.path) and self.adding_histories:
            raise SweepError(f"results file {self.path} does not exist: record_histories adds to the file of a "
                             "sweep that ran; run the sweep first")
        if not os.path.exists(self.path):
            self._create()
        elif not overwrite:
            if not resume:
                raise SweepError(f"results file {self.path} exists; resume=True (--resume) continues its sweep, "
                                 "overwrite=True (--overwrite) replaces it")
            try:
                self._check(self.path)
            except SweepError as exc:
                staged = staging_path(self.path)
                try:
                    self._check(staged)
                except SweepError:
                    raise exc from None
                raise SweepError(f"{exc}; {staged} holds this sweep, begun with overwrite=True (--overwrite): "
                                 "overwrite=True (--overwrite) continues it") from None
            self._add_modes()
        else:                    # the old file stays until the new sweep is complete (commit)
            self.path = staging_path(self.target)
            if os.path.exists(self.path):
                try:
                    self._check(self.path)     # an overwrite of this same sweep that was stopped: go on
                except SweepError:
                    pass                       # another sweep's, or unreadable: begun anew
                else:
                    self._add_modes()          # (a failure to add them is the file's, not another sweep's)
                    return
            self._create()

    def _add_modes(self):
        """A resumed file of an older vtsi gets /bridge/frequencies_to_cutoff_hz (the Rayleigh note
        reads them), the same as this sweep's (its bridge is the file's)."""
        with open_results(self.path) as f:
            missing = "frequencies_to_cutoff_hz" not in f["bridge"]
        if missing:
            modes = self.runner.frequencies_to_cutoff
            self._atomic(lambda f: f["bridge"].create_dataset("frequencies_to_cutoff_hz", data=modes),
                         "cannot add the bridge's frequencies up to the cut-off", "the file is as it was")

    def commit(self):
        """Once the sweep is complete: the new file in place of the one it overwrites."""
        if self.path != self.target:
            os.replace(self.path, self.target)
            self.path = self.target

    def close(self):
        """Release the file's lock (the results stay readable: :meth:`results`)."""
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def _create(self):
        runner = self.runner
        handle, tmp = self._open_new()
        try:
            with handle as f:
                f.attrs.update({"format": FORMAT, "format_version": FORMAT_VERSION, "vtsi_version": __version__,
                                "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                                "identity": json.dumps(self.identity, sort_keys=True)})
                ident = self.identity
                f.create_dataset("train", data=np.array(ident["trains"], dtype=h5py.string_dtype()))
                f.create_dataset("speed_kmh", data=np.array(ident["speeds_kmh"], dtype=float)).attrs["units"] = "km/h"
                f.create_dataset("seed", data=np.array(ident["seeds"], dtype=np.int64)).attrs["note"] = "-1: smooth rail"
                b = f.create_group("bridge")
                b["frequencies_hz"] = runner.frequencies
                b["deck_frequencies_hz"] = np.asarray(runner.deck_frequencies, dtype=float).reshape(-1, 3)
                b["frequencies_to_cutoff_hz"] = runner.frequencies_to_cutoff
                b["en_cutoff_hz"] = float(runner.en_cutoff_hz)
                # every node of the track (as every vtsi wrote them), those on a deck within deck_ends_m
                b["deck_nodes"] = np.asarray(runner.track_nodes, dtype=np.int64)
                b["deck_x_m"] = np.array([runner.model.nodes[n][0] for n in runner.track_nodes])
                b["midspan_nodes"] = np.asarray(runner.midspan_nodes, dtype=np.int64)
                b["span_lengths_m"] = np.asarray(runner.span_lengths, dtype=float)
                b["span_ends_m"] = np.asarray(runner.span_ends, dtype=float).reshape(-1, 2)
                b["deck_ends_m"] = np.asarray(runner.deck_ends, dtype=float).reshape(-1, 2)
                b["track_on_a_structure"] = bool(runner.track_on_a_structure)
                ends = runner.track_ends(ident["trains"])        # a free end is a step for the cars' wheels
                b["track_end_nodes"] = np.array([e.node for e in ends], dtype=np.int64)
                b["track_end_x_m"] = np.array([e.x_m for e in ends])
                b["track_end_sag_m"] = np.array([e.sag_m for e in ends])
                b["track_end_load_n"] = float(ends[0].load_n)
                asm = runner.model.build()
                b["mode_shapes_uy"] = runner.mode_shapes[[asm.full_dof(n, 2) for n in runner.track_nodes]]
                modal = getattr(runner, "modal", None)
                if modal is not None:                  # the modal bridge's basis: its modes' frequencies
                    b["modal_frequencies_hz"] = np.asarray(modal.frequencies, dtype=float)
                    b["modal_frequencies_hz"].attrs["units"] = "Hz"
                shape = (len(ident["trains"]), len(ident["speeds_kmh"]), len(ident["seeds"]))
                env = f.create_group("envelopes")
                for q, output, stat, units in quantities(ident["outputs"]):
                    ds = env.create_dataset(q, shape=shape, dtype=float, fillvalue=np.nan)
                    ds.attrs.update({"units": units, "output": output, "statistic": stat,
                                     "dims": ["train", "speed_kmh", "seed"]})
                    kind = COLUMN_KIND.get(_response(ident["outputs"], output), "node")
                    env.create_dataset(q + "_where", shape=shape, dtype=np.int64, fillvalue=-1).attrs.update(
                        {"kind": kind, "holds": WHERE_HOLDS[kind], "missing": -1})
                    env.create_dataset(q + "_time", shape=shape, dtype=float, fillvalue=np.nan).attrs["units"] = "s"
                catalogue = [runner.train(name, 1.0) for name in ident["trains"]]
                outs = f.create_group("outputs")
                for o, output in zip(ident["outputs"], runner.outputs):
                    g = outs.create_group(o["name"])
                    g.attrs.update(output_description(o["response"], o.get("cutoff_hz")))
                    g.attrs.update({"rows": list(ENVELOPE_ROWS), "history": bool(o["history"])})
                    g["columns"] = _column_table([runner.columns(output, train) for train in catalogue]) \
                        if o["response"] in COLUMN_KIND else runner.columns(output, catalogue[0])
                static = f.create_group("static")
                static.attrs["note"] = ("static responses (influence lines): per train its static axle loads, "
                                        "and Load Models 71 and SW/0 (alpha = 1); rows min, max")
                for o in runner.outputs:
                    env = runner.static_envelopes(o, ident["trains"])
                    if env is not None:
                        g = static.create_group(o.name)
                        g["trains"], g["lm71"], g["sw0"] = env.trains, env.lm71, env.sw0
                        g.attrs["units"] = UNITS[o.response]
                _train_table(f.create_group("trains"), catalogue)
                f.create_group("cases")
                if self.path is None:
                    self._memory = f
                else:
                    _save_image(f, tmp)
            if tmp is not None:
                os.replace(tmp, self.path)
        except BaseException as exc:
            if tmp is not None and os.path.exists(tmp):
                os.remove(tmp)
            if isinstance(exc, OSError):         # a full disk: nothing is left behind
                raise SweepError(f"results file {self.path}: cannot write there ({exc.strerror or exc})") from None
            raise

    def _open_new(self):
        """A new HDF5 file in memory and the path it is written to (:func:`_save_image`): the
        results file's ``<file>.partial``, or None for a sweep kept in memory."""
        f = h5py.File(f"vtsi-sweep-{uuid.uuid4().hex}.h5", "w", driver="core", backing_store=False)
        if self.path is None:
            return _KeepOpen(f), None
        return f, self.path + PARTIAL

    def _check(self, path):
        """A SweepError unless the file ``path`` holds this sweep (the first difference named),
        its node outputs hold the nodes this vtsi's places give them (the identity names a place,
        'deck', not its nodes: a file written when 'deck' was every node of the track, the
        approaches' too, holds other columns) and its cases ran as many steps as this vtsi's
        passages of them (:meth:`~vtsi.passage.PassageRunner.n_steps`; the identity does not hold
        the rule of a passage's length: a file of the same sweep written before the runs of cars
        held every car body's counting window ran the last cars' windows short)."""
        with open_results(path) as f:
            version, stored = _header(f, path)
            cases = f.get("cases") if version == FORMAT_VERSION else None
            done = None if cases is None or "n_steps" not in cases else \
                [cases[k][()] for k in ("train", "speed_kmh", "n_steps")]
            written = f.get("outputs") if version == FORMAT_VERSION else None
            columns = {o.name: written[o.name]["columns"][()] for o in self.runner.outputs
                       if not o.vehicle and written is not None and o.name in written}
        if version != FORMAT_VERSION:
            raise SweepError(f"results file {path} is of format {version}, this vtsi writes format {FORMAT_VERSION}: "
                             f"it cannot be resumed; {self._remedy()}")
        here, renamed = _axle_tables_as_stored(self.identity, stored)
        diff = _first_difference(here, _modal_default_as_stored(here, stored, self.runner.en_cutoff_hz))
        if diff:
            raise SweepError(f"results file {path} holds a different sweep ({_describe(diff, self.runner)}); "
                             f"{self._remedy(diff)}")
        before = {"deck": " ('deck' was every node of the track, the approaches' too: 'track' now)",
                  "supports": " ('supports' held the approaches' springs too)"}
        for o in self.runner.outputs:
            now = self.runner.columns(o, None) if o.name in columns else None
            if now is not None and not np.array_equal(columns[o.name], now):
                place = f"{o.nodes!r}" if isinstance(o.nodes, str) else "nodes"
                raise SweepError(f"results file {path}: its output {o.name!r} at {place} holds "
                                 f"{self._nodes_text(columns[o.name])}, this vtsi's {place} {self._nodes_text(now)}: "
                                 "the file was written by a vtsi whose place held other nodes"
                                 f"{before.get(o.nodes, '')}, and resuming would mix the two; {self._remedy()}")
        self.stored_names = renamed
        if done is None:
            return
        names, lengths = self.identity["trains"], {}
        for i, speed, n in zip(*done):
            key = (int(i), float(speed))
            if key not in lengths:
                lengths[key] = self.runner.n_steps(self.runner.train(names[key[0]], key[1] / 3.6))
            if lengths[key] != int(n):
                raise SweepError(f"results file {path}: its passage of {names[key[0]]} at {key[1]:g} km/h ran "
                                 f"{int(n)} steps, this vtsi runs {lengths[key]}: the file was written by a vtsi whose "
                                 "passages ran another length (since 2026-11-27 a sweep reading car bodies runs until "
                                 "the last car body stops counting; since 2026-11-28 cars on an irregular rail start "
                                 "far enough before the bridge for their bodies to settle, PassageRunner.approach, or "
                                 "give the file's approach: vtsi.passage.PassageRunner.n_steps), "
                                 f"and resuming would mix passages of both; {self._remedy()}")

    def _remedy(self, diff=None):
        """What to do with a file this writer cannot continue: ``diff``, the first difference of
        its sweep (:func:`_first_difference`), or None for a file another vtsi wrote."""
        if not self.adding_histories:
            return "use another file, or overwrite=True (--overwrite)"
        if diff is None:
            return ("record_histories adds to a file of this vtsi's sweep: run the sweep again (another file, or "
                    "overwrite=True), then record its histories")
        path = diff[0]
        what = ("settings." + str(path[1]) if path[0] == "settings" and len(path) > 1 else
                {"bridge_fingerprint": "bridge", "train_fingerprints": "trains"}.get(path[0], path[0]))
        return f"record_histories adds to the file of its own sweep: build the Sweep with the file's {what}"

    def _nodes_text(self, nodes):
        """Node tags ``nodes`` in words: '49 nodes (x = -20 to 100 m)'."""
        x = [float(self.runner.model.nodes[int(n)][0]) for n in nodes if int(n) in self.runner.model.nodes]
        where = f" (x = {min(x):g} to {max(x):g} m)" if x else ""
        return f"{len(nodes)} node{'s' * (len(nodes) != 1)}{where}"

    def done(self):
        """Keys of the cases already in the file (:func:`case_key`)."""
        with self._read() as f:
            cases = f["cases"]
            if "train" not in cases:
                return set()
            trains = self.identity["trains"]
            return {case_key(trains[i], v, int(k))
                    for i, v, k in zip(cases["train"][()], cases["speed_kmh"][()], cases["seed"][()])}

    def _read(self):
        return _KeepOpen(self._memory) if self._memory is not None else open_results(self.path)

    def write(self, results):
        """Add a batch of :class:`~vtsi.passage.CaseResult` (atomically, see the module docstring)."""
        if results:
            self._atomic(lambda f: self._write(f, results),
                         f"cannot write {len(results)} more cases", "the cases finished before them are in it: "
                         "resume=True (--resume) continues the sweep")

    def _atomic(self, put, what, kept):
        """``put(f)`` on the file as one step: on a copy in memory, written to ``<file>.partial``
        (:func:`_save_image`) and renamed over the file; a failure (a full disk) or an interrupt
        at any moment leaves the file as it was and no copy."""
        if self._memory is not None:
            put(self._memory)
            return
        tmp = self.path + PARTIAL
        try:
            # in memory (the file on disk is only read); readers may hold it open: no HDF5 file lock
            with h5py.File(self.path, "r+", driver="core", backing_store=False, locking=False) as f:
                put(f)
                _save_image(f, tmp)
            os.replace(tmp, self.path)
        except BaseException as exc:
            if os.path.exists(tmp):
                os.remove(tmp)
            if isinstance(exc, OSError):       # a full disk, a lost drive: the file keeps what it had
                raise SweepError(f"results file {self.path}: {what} ({exc.strerror or exc}); {kept}") from None
            raise

    def _write(self, f, results):
        ident = self.identity
        trains, speeds, seeds = ident["trains"], np.array(ident["speeds_kmh"]), ident["seeds"]
        cases, outputs = f["cases"], f["outputs"]
        n = len(results)
        train_index = np.array([trains.index(r.train) for r in results], dtype=np.int64)
        if "train" in cases and "deck_flights" not in cases:     # a file of an older vtsi: its cases not counted
            _append(cases, "deck_flights", np.full(cases["train"].shape[0], -1), np.int64)
        for name, dtype, values in (("train", np.int64, train_index),
                                    ("speed_kmh", float, [r.speed_kmh for r in results]),
                                    ("seed", np.int64, [r.seed for r in results]),
                                    ("n_steps", np.int64, [r.n_steps for r in results]),
                                    ("seconds", float, [r.seconds for r in results]),
                                    ("x_head0", float, [r.x_head0 for r in results]),
                                    ("deck_flights", np.int64, [r.deck_flights for r in results])):
            _append(cases, name, values, dtype)
        stacked = {}
        for o in ident["outputs"]:                  # a row per case; NaN where its train has no column
            name, width = o["name"], outputs[o["name"]]["columns"].shape[-1]
            if width == 0:
                continue                            # no train of the sweep produces it
            rows = np.full((n, len(ENVELOPE_ROWS), width), np.nan)
            for k, r in enumerate(results):
                if name in r.envelopes:
                    rows[k, :, : r.envelopes[name].shape[1]] = r.envelopes[name]
            _append(cases, name, rows)
            stacked[name] = rows
            if o["response"] in COLUMN_KIND:        # a vehicle output: its envelope over the whole run too
                whole = np.full((n, len(ENVELOPE_ROWS), width), np.nan)
                for k, r in enumerate(results):
                    if name in r.whole_run:
                        whole[k, :, : r.whole_run[name].shape[1]] = r.whole_run[name]
                _append(cases, name + WHOLE_RUN, whole)
        described = {o["name"]: output_description(o["response"], o.get("cutoff_hz")) for o in ident["outputs"]}
        for r in results:
            train = self.stored_names.get(r.train, r.train)        # as the file names it
            for name, (time, values) in r.histories.items():
                h = cases.require_group("histories").require_group(train_key(train)).require_group(
                    _speed_seed(r.speed_kmh, r.seed))
                h.attrs.update({"train": train, "speed_kmh": r.speed_kmh, "seed": r.seed, "x_head0": r.x_head0,
                                "n_steps": r.n_steps})
                _put_history(h, name, time, values, described[name])
        # the cases' cells of the envelope tables: the extreme over the columns, where and when
        env_group = f["envelopes"]
        index = (train_index, np.argmin(np.abs(speeds[None, :] - np.array([r.speed_kmh for r in results])[:, None]), axis=1),
                 np.array([seeds.index(r.seed) for r in results], dtype=np.int64))
        for q, name, stat, _ in quantities(ident["outputs"]):
            produced = np.array([name in r.envelopes for r in results])
            if name not in stacked or not np.any(produced):
                continue
            columns = outputs[name]["columns"][()]
            row = ENVELOPE_ROWS.index(stat)
            extreme = stacked[name][produced, row, :]
            j = (np.argmin(np.where(np.isnan(extreme), np.inf, extreme), axis=1) if stat == "min"
                 else np.argmax(np.where(np.isnan(extreme), -np.inf, extreme), axis=1))
            case = np.arange(len(j))
            where = columns[train_index[produced], j] if columns.ndim == 2 else columns[j]
            cell = tuple(axis[produced] for axis in index)
            for ds, values in ((q, extreme[case, j]), (q + "_where", where),
                               (q + "_time", stacked[name][produced, row + 3, :][case, j])):
                table = env_group[ds][()]
                table[cell] = values
                env_group[ds][...] = table

    def write_histories(self, results, outputs):
        """Add the time histories of re-run cases (:meth:`vtsi.sweep.Sweep.record_histories`)
        under /histories/<case>: per output ``<name>_time`` [s], ``<name>_values`` (attrs
        response, units, kind and, up to a cut-off, cutoff_hz: :func:`output_description`),
        ``<name>_columns``; group attrs train, speed_kmh, seed, x_head0 [m], n_steps. ``outputs``:
        the :class:`~vtsi.passage.Output` they were recorded with. Atomic as :meth:`write`."""
        described = {o.name: output_description(o.response, None if o.cutoff is None else
                                                self.runner.cutoff_hz(o.cutoff)) for o in outputs}

        def put(f):
            for r in results:
                train = self.stored_names.get(r.train, r.train)    # as the file names it
                key = case_key(train, r.speed_kmh, r.seed)
                if "histories" in f and key in f["histories"]:
                    del f["histories"][key]
                g = f.require_group("histories").create_group(key)
                g.attrs.update({"train": train, "speed_kmh": r.speed_kmh, "seed": r.seed, "x_head0": r.x_head0,
                                "n_steps": r.n_steps})
                for name, (time, values) in r.histories.items():
                    _put_history(g, name, time, values, described[name])
                    g[name + "_columns"] = r.columns[name]
                    g[name + "_columns"].attrs["kind"] = described[name]["kind"]
        self._atomic(put, f"cannot write the histories of {len(results)} cases", "the file holds what it held")

    def results(self):
        return SweepResults(self._memory if self._memory is not None else self.path)


def _response(outputs, name):
    """The response of the output ``name`` of ``outputs`` (the identity's dicts)."""
    return next(o["response"] for o in outputs if o["name"] == name)


def _save_image(f, path):
    """Write ``f``, an HDF5 file held in memory (driver 'core'), to the file ``path`` by Python's
    own writes: a full disk raises OSError here. (HDF5 writing a file on a full disk loses the
    error where h5py releases a dataset, leaves the dataset's data out of the file, then crashes
    the process when the file is closed.)"""
    f.flush()
    with open(path, "wb") as out:
        out.write(f.id.get_file_image())


def _put_history(group, name, time, values, description):
    """``<name>_time`` [s] and ``<name>_values`` (gzip; attrs: ``description``) in ``group``."""
    group[name + "_time"] = time
    group[name + "_time"].attrs["units"] = "s"
    ds = group.create_dataset(name + "_values", data=values, compression="gzip", compression_opts=4)
    ds.attrs.update(description)


def _plain(value):
    """An HDF5 attribute's value as a Python value (bytes as str, numpy scalars as Python's)."""
    if isinstance(value, bytes):
        return value.decode()
    return value.item() if isinstance(value, np.generic) else value


class _KeepOpen:
    """A context manager that leaves an (in-memory) h5py file open."""

    def __init__(self, f):
        self.f = f

    def __enter__(self):
        return self.f

    def __exit__(self, *exc):
        return False


class SweepResults:
    """A sweep's results (from its file, or the in-memory file of a sweep run without one).

    Attributes
    ----------
    trains : list of str; speeds_kmh : (n_speed,) [km/h]; seeds : list of int (-1: smooth)
    identity : dict (bridge, settings, outputs, trains, speeds, seeds)
    quantities : dict quantity -> units
    frequencies_hz : the bridge's first vertical frequencies [Hz]
    n_done, n_cases : the cases in the file, and in the sweep (fewer done: an interrupted sweep)

    A case is named as a sweep names it: a train by its name (case ignored, 'A1' is 'HSLM-A1',
    :func:`canonical_train_name`), a speed of the sweep [km/h], a seed of the sweep (-1: smooth
    rail); anything else is a SweepError listing what is valid.
    """

    def __init__(self, source):
        self._file = source if isinstance(source, h5py.File) else None
        self.path = None if self._file is not None else os.fspath(source)
        if self.path is not None and not os.path.isfile(self.path):
            raise SweepError(f"results file {self.path}: " + ("not a file" if os.path.exists(self.path) else "no such file"))
        handle = self._open()
        name = self.path or "(in memory)"
        with handle as f:
            version, self.identity = _header(f, name)
            if version != FORMAT_VERSION:
                raise SweepError(f"results file {name}: a vtsi sweep results file of format {version}, this vtsi "
                                 f"reads format {FORMAT_VERSION}: run the sweep again, or read it with the vtsi "
                                 f"that wrote it ({f.attrs.get('vtsi_version')})")
            try:
                self.vtsi_version = str(f.attrs.get("vtsi_version"))
                self.trains = [t.decode() if isinstance(t, bytes) else str(t) for t in f["train"][()]]
                self.speeds_kmh = f["speed_kmh"][()]
                self.seeds = [int(s) for s in f["seed"][()]]
                self.frequencies_hz = f["bridge/frequencies_hz"][()]
                deck_frequencies_table(f["bridge"])     # each deck's n0, n2, n3, which every reader of the decks takes
                self.quantities = {q: units for q, _, _, units in quantities(self.identity["outputs"])}
                self._tables = {q: (f["envelopes"][q][()], f["envelopes"][q + "_where"][()],
                                    f["envelopes"][q + "_time"][()]) for q in self.quantities}
                self.n_done = f["cases"]["train"].shape[0] if "train" in f["cases"] else 0
            except (KeyError, TypeError, ValueError) as exc:
                raise SweepError(f"results file {name}: damaged or incomplete ({exc})") from None
        self._outputs = {o["name"]: o for o in self.identity["outputs"]}

    def __repr__(self):
        where = self.path or "in memory"
        return (f"SweepResults({where}: {self.n_done} of {cases_text(self.trains, self.speeds_kmh, self.seeds)} done, "
                f"n0 = {self.frequencies_hz[0]:.4g} Hz)")

    def _open(self):
        return _KeepOpen(self._file) if self._file is not None else open_results(self.path)

    @property
    def n_cases(self):
        return len(self.trains) * len(self.speeds_kmh) * len(self.seeds)

    # -- naming a case ------------------------------------------------------------------------
    def train_name(self, train):
        """``train`` as the sweep spells it (:func:`canonical_train_name`), or a SweepError listing
        the sweep's trains."""
        name = canonical_train_name(train) if isinstance(train, (str, os.PathLike)) else None
        if name not in self.trains:
            hint = ("names ignore case; 'A1' is 'HSLM-A1'" if set(self.trains) <= set(train_names()) else
                    "catalogue names ignore case, 'A1' is 'HSLM-A1'; an axle table is named by its path as the sweep "
                    "was given it, case included")
            raise SweepError(f"sweep results: train {train!r} is not one of the sweep's: {', '.join(self.trains)} "
                             f"({hint})")
        return name

    def speed(self, speed_kmh):
        """The sweep's speed [km/h] equal to ``speed_kmh`` (to 1e-9), or a SweepError naming it and
        listing the sweep's speeds."""
        value = as_number(speed_kmh, "sweep results", "speed [km/h]", SweepError)
        k = speed_index(self.speeds_kmh, value)
        if k < 0:
            raise SweepError(f"sweep results: {value:g} km/h is not one of the sweep's {_speed_list(self.speeds_kmh, value)}")
        return float(self.speeds_kmh[k])

    def seed(self, seed):
        """``seed`` as an int if it is one of the sweep's, else a SweepError listing them."""
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
            raise SweepError(f"sweep results: a case's seed must be an integer (-1: smooth rail), got {seed!r}")
        if int(seed) not in self.seeds:
            raise SweepError(f"sweep results: seed {int(seed)} is not one of the sweep's: {seeds_text(self.seeds)}")
        return int(seed)

    def _case(self, train, speed_kmh, seed):
        """``(train, speed [km/h], seed)`` as the sweep names them (checked: see the class docstring)."""
        return self.train_name(train), self.speed(speed_kmh), self.seed(seed)

    def _output(self, output):
        if output not in self._outputs:
            raise SweepError(f"sweep results: unknown output {output!r}; valid: {', '.join(self._outputs)}")
        return self._outputs[output]

    def describe(self, output):
        """What the values of the sweep's ``output`` are: response, units, kind ('node', 'contact
        wheel', 'car') and, for a response in the modes up to a cut-off, cutoff_hz [Hz]."""
        o = self._output(output)
        return output_description(o["response"], o.get("cutoff_hz"))

    # -- the envelope tables ------------------------------------------------------------------
    def envelope(self, quantity):
        """``(n_train, n_speed, n_seed)`` values of ``quantity`` (NaN where not computed)."""
        if quantity not in self._tables:
            raise SweepError(f"sweep results: unknown quantity {quantity!r}; valid: {', '.join(self._tables)}")
        return self._tables[quantity][0].copy()

    def critical(self, quantity):
        """The governing case of ``quantity`` (its largest value; smallest for a 'min'): a dict
        with value, units, train, speed_kmh, seed, where (node tag / wheel / car: 'where_kind'),
        time [s], and cases_done and cases_total: fewer done than the sweep has (an interrupted
        sweep) and the case governs only those done. None when no case produced it."""
        values, where, when = self._tables[quantity] if quantity in self._tables else (None, None, None)
        if values is None:
            raise SweepError(f"sweep results: unknown quantity {quantity!r}; valid: {', '.join(self._tables)}")
        if np.all(np.isnan(values)):
            return None
        idx = np.unravel_index(np.nanargmin(values) if quantity.endswith("_min") else np.nanargmax(values), values.shape)
        output = quantity.rsplit("_", 1)[0]
        return {"quantity": quantity, "value": float(values[idx]), "units": self.quantities[quantity],
                "train": self.trains[idx[0]], "speed_kmh": float(self.speeds_kmh[idx[1]]), "seed": self.seeds[idx[2]],
                "where": int(where[idx]), "where_kind": self.describe(output)["kind"], "time": float(when[idx]),
                "cases_done": int(self.n_done), "cases_total": int(self.n_cases)}

    # -- one case -------------------------------------------------------------------------------
    def case(self, train, speed_kmh, seed=-1):
        """One case: ``{output: {'envelope': (6, n), 'columns': (n,), 'response', 'units', 'kind'[,
        'cutoff_hz'][, 'time': (m,) [s], 'values': (m, n)]}}`` (envelope rows: min, max, absmax and
        their times; only the outputs its train produces; time and values of the outputs kept with
        ``history=True``) plus 'attrs' (train, speed_kmh, seed, n_steps, seconds)."""
        train, speed_kmh, seed = self._case(train, speed_kmh, seed)
        key = case_key(train, speed_kmh, seed)
        row = self._row(train, speed_kmh, seed)
        if row is None:
            raise SweepError(f"sweep results: case {key} is not in the file yet ({self.n_done} of {self.n_cases} "
                             "cases: an interrupted sweep; resume=True (--resume) runs the rest)")
        i = self.trains.index(train)
        with self._open() as f:
            g = f["cases"]
            out = {"attrs": {"train": train, "speed_kmh": float(g["speed_kmh"][row]), "seed": int(g["seed"][row]),
                             "n_steps": int(g["n_steps"][row]), "seconds": float(g["seconds"][row]),
                             "x_head0": float(g["x_head0"][row])}}
            h = g.get(f"histories/{train_key(train)}/{_speed_seed(speed_kmh, seed)}")
            if h is not None and "x_head0" in h.attrs:
                out["attrs"]["x_head0"] = float(h.attrs["x_head0"])
            for name in self._outputs:
                columns = self._columns(f, name, i)
                if len(columns) == 0:
                    continue
                out[name] = {"envelope": g[name][row][:, : len(columns)], "columns": columns, **self.describe(name)}
                if h is not None and name + "_time" in h:
                    out[name]["time"], out[name]["values"] = h[name + "_time"][()], h[name + "_values"][()]
        return out

    @staticmethod
    def _columns(f, name, i):
        """The columns of output ``name`` for train ``i`` (a vehicle output's: that train's row)."""
        columns = f["outputs"][name]["columns"][()]
        if columns.ndim == 2:                 # a vehicle output: this train's columns
            columns = columns[i][columns[i] >= 0]
        return columns

    def _row(self, train, speed_kmh, seed):
        """The row of the case (train, speed [km/h], seed), as the sweep names them, in /cases, or None."""
        with self._open() as f:
            g = f["cases"]
            if "train" not in g:
                return None
            hits = np.flatnonzero((g["train"][()] == self.trains.index(train))
                                  & np.isclose(g["speed_kmh"][()], float(speed_kmh), rtol=0, atol=1e-9)
                                  & (g["seed"][()] == int(seed)))
        return int(hits[0]) if len(hits) else None

    def column_envelopes(self, output, whole_run=False):
        """Every case's envelope of ``output``: (n_train, n_speed, n_seed, 6, n_columns) (NaN
        where a case is missing or did not produce it; rows as in :data:`ENVELOPE_ROWS`) and the
        columns (node tags; wheel or car indices: the columns of the train with most). A
        vehicle output's envelope counts what happens on the bridge (a wheel on a deck, a car
        body with a wheel on one and a run-out after: :meth:`vtsi.passage.PassageRunner.counted`);
        ``whole_run=True`` gives its envelope over the whole run (ground before and after
        included)."""
        o = self._output(output)
        if whole_run and o["response"] not in COLUMN_KIND:
            raise SweepError(f"sweep results: output {output!r} ({o['response']}) has one envelope; a whole-run "
                             "envelope is kept for contact forces and car bodies")
        with self._open() as f:
            columns = f["outputs"][output]["columns"][()]
            g = f["cases"]
            width = columns.shape[-1]
            out = np.full((len(self.trains), len(self.speeds_kmh), len(self.seeds), len(ENVELOPE_ROWS), width), np.nan)
            name = output + WHOLE_RUN if whole_run else output
            if name in g:
                speed = np.argmin(np.abs(self.speeds_kmh[None, :] - g["speed_kmh"][()][:, None]), axis=1)
                seed = np.array([self.seeds.index(int(k)) for k in g["seed"][()]], dtype=np.int64)
                out[g["train"][()], speed, seed] = g[name][()]
        if columns.ndim == 2:          # a vehicle output: the columns of the train with most
            columns = columns[int(np.argmax(np.sum(columns >= 0, axis=1)))] if len(columns) else columns[:0]
            columns = columns[columns >= 0]
        return out, columns

    def start_positions(self):
        """(n_train, n_speed, n_seed) x_head0 [m] of every case, the train's head at t = 0 (wheel
        i is at x_head0 + V t − axle_offsets_m[i]; NaN where a case is not in the file)."""
        return self._per_case("x_head0")

    def deck_flights(self):
        """(n_train, n_speed, n_seed) how many contact wheels of each case flew on a deck (raw
        contact, however briefly: :attr:`vtsi.passage.CaseResult.deck_flights`), NaN where a case
        is not in the file or was not counted (contact other than 'lcp'); None for a file of an
        older vtsi, which did not count them."""
        with self._open() as f:
            if "train" in f["cases"] and "deck_flights" not in f["cases"]:
                return None
        flights = self._per_case("deck_flights")
        return np.where(flights < 0, np.nan, flights)

    def _per_case(self, name):
        """(n_train, n_speed, n_seed) the case table's column ``name`` as floats, NaN where a case
        is not in the file."""
        out = np.full((len(self.trains), len(self.speeds_kmh), len(self.seeds)), np.nan)
        with self._open() as f:
            g = f["cases"]
            if "train" in g:
                speed = np.argmin(np.abs(self.speeds_kmh[None, :] - g["speed_kmh"][()][:, None]), axis=1)
                seed = np.array([self.seeds.index(int(k)) for k in g["seed"][()]], dtype=np.int64)
                out[g["train"][()], speed, seed] = g[name][()]
        return out

    def static(self, output):
        """Static envelopes of the sweep's ``output`` (rows min, max) under the trains, LM71 and
        SW/0 (:class:`~vtsi.influence.StaticEnvelopes`; ``sw0`` None in a file of an older vtsi,
        which kept none), or None for an output that has none (only displacement, rotation and
        bending-moment outputs without a cut-off); an output the sweep does not have is a
        SweepError listing its outputs."""
        self._output(output)
        with self._open() as f:
            if "static" not in f or output not in f["static"]:
                return None
            g = f["static"][output]
            return StaticEnvelopes(g["trains"][()], g["lm71"][()], g["sw0"][()] if "sw0" in g else None)

    def train_data(self, train):
        """The stored axle data of ``train``: dict with axle_offsets_m, static_wheel_loads_N,
        wheel_car (each wheel's car, 0: the first), contact_wheels, name, n_cars, n_dof,
        length_m, characteristic_length_m, body_runout_s (NaN: no car body)."""
        i = self.trains.index(self.train_name(train))
        with self._open() as f:
            g = f["trains"]
            axles = slice(int(g["axle_ptr"][i]), int(g["axle_ptr"][i + 1]))
            contact = slice(int(g["contact_ptr"][i]), int(g["contact_ptr"][i + 1]))
            name = g["name"][i]
            return {"axle_offsets_m": g["axle_offsets_m"][axles], "static_wheel_loads_N": g["static_wheel_loads_N"][axles],
                    "wheel_car": g["wheel_car"][axles], "contact_wheels": g["contact_wheels"][contact],
                    "name": name.decode() if isinstance(name, bytes) else str(name),
                    **{k: g[k][i] for k in ("n_cars", "n_dof", "length_m", "characteristic_length_m",
                                            "body_runout_s")}}

    def bridge(self):
        """The stored bridge data: frequencies_hz, deck_frequencies_hz (n_decks, 3), en_cutoff_hz,
        frequencies_to_cutoff_hz (n,) (every vertical frequency up to the cut-off [Hz]:
        :attr:`~vtsi.passage.PassageRunner.frequencies_to_cutoff`; not in a file of an older vtsi), deck_nodes
        and deck_x_m (every node of the track and its x [m], x order; those on a deck:
        :func:`vtsi.deck_record.deck_nodes`), midspan_nodes, span_lengths_m, span_ends_m (n_spans,
        2), deck_ends_m (n_decks, 2; not in a file of an older vtsi), mode_shapes_uy (at
        deck_nodes), track_on_a_structure, track_end_nodes, track_end_x_m, track_end_sag_m and
        track_end_load_n (the track's two end nodes, their x [m] and static sag [m] under the
        trains' heaviest static wheel load [N]: :mod:`vtsi.track_ends`; not in a file of an older
        vtsi), and of a modal sweep modal_frequencies_hz (n_modes,): the frequencies of the modal
        bridge's modes (not in a file of an older vtsi)."""
        with self._open() as f:
            return {k: f["bridge"][k][()] for k in f["bridge"]}

    # -- time histories -----------------------------------------------------------------------
    def histories(self):
        """Keys of the cases with recorded time histories (:func:`case_key`, sorted): those kept by
        the sweep's outputs with ``history=True`` (/cases/histories, every case) and those added
        by :meth:`vtsi.sweep.Sweep.record_histories` (/histories)."""
        with self._open() as f:
            return sorted(set(_history_keys(f, "histories")) | set(_history_keys(f, "cases/histories")))

    def history(self, train, speed_kmh, seed=-1):
        """A case's recorded histories: ``{output: (time (m,) [s], values (m, n), columns (n,))}``
        of the sweep's outputs kept with ``history=True`` and of those Sweep.record_histories
        added (its own, e.g. 'deck_displacement', 'deck_acceleration'; where a name is in both,
        record_histories' is given: :meth:`case` has the sweep's), plus 'attrs': train,
        speed_kmh, seed, n_steps, x_head0 [m] where stored, and 'outputs': per output its
        response, units, kind, cutoff_hz (for a response in the modes up to a cut-off; None: the
        full response) and source ('sweep' or 'record_histories')."""
        train, speed_kmh, seed = self._case(train, speed_kmh, seed)
        key = case_key(train, speed_kmh, seed)
        with self._open() as f:
            places = [p for p in ("histories", "cases/histories") if p in f and len(_history_keys(f, p))]
            if not places:
                raise SweepError(f"sweep results: {self.path or 'the sweep'} holds no histories (an output with "
                                 "history=True keeps them for every case; Sweep.record_histories records them for "
                                 "chosen cases; vtsi check does for the governing cases)")
            out, attrs, outputs = {}, {}, {}
            row = self._row(train, speed_kmh, seed)
            if row is not None:
                g = f["cases"]
                attrs.update({"train": train, "speed_kmh": float(g["speed_kmh"][row]), "seed": int(g["seed"][row]),
                              "n_steps": int(g["n_steps"][row]), "seconds": float(g["seconds"][row]),
                              "x_head0": float(g["x_head0"][row])})
            h = f.get(f"cases/histories/{key}")
            if isinstance(h, h5py.Group):
                attrs.update({k: _plain(v) for k, v in h.attrs.items()})
                i = self.trains.index(train)
                for name in self._outputs:
                    if name + "_time" in h:
                        out[name] = (h[name + "_time"][()], h[name + "_values"][()], self._columns(f, name, i))
                        outputs[name] = dict(self.describe(name), source="sweep")
            h = f.get(f"histories/{key}")
            if isinstance(h, h5py.Group):
                attrs.update({k: _plain(v) for k, v in h.attrs.items()})
                for name in sorted({k.rsplit("_", 1)[0] for k in h}):
                    out[name] = (h[name + "_time"][()], h[name + "_values"][()], h[name + "_columns"][()])
                    outputs[name] = {k: _plain(v) for k, v in h[name + "_values"].attrs.items()}
                    for k in ("response", "units", "kind"):     # a file written before they were stored
                        outputs[name].setdefault(k, None)
                    outputs[name]["source"] = "record_histories"
            if not out:
                recorded = ", ".join(sorted(set(_history_keys(f, "histories")) | set(_history_keys(f, "cases/histories"))))
                raise SweepError(f"sweep results: no histories of case {key}; recorded: {recorded} "
                                 "(Sweep.record_histories adds a case's)")
        for description in outputs.values():
            description.setdefault("cutoff_hz", None)
        attrs["outputs"] = outputs
        out["attrs"] = attrs
        return out

    # -- views ----------------------------------------------------------------------------------
    def summary(self, damping=""):
        """The cases done, the bridge as vtsi read it (:func:`bridge_text`; ``damping``, the damping
        the passages had in words, on its line: ``vtsi sweep`` says it and where it came from),
        then a text table: per quantity its extreme, the governing train, speed, place and time."""
        rows = [("quantity", "value", "units", "train", "speed km/h", "seed", "where", "t [s]")]
        for q in self.quantities:
            c = self.critical(q)
            if c is None:
                continue
            rows.append((q, f"{c['value']:.5g}", c["units"], c["train"], f"{c['speed_kmh']:g}",
                         "smooth" if c["seed"] < 0 else str(c["seed"]), self._where_text(c), f"{c['time']:.3f}"))
        widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
        lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        lines.insert(1, "  ".join("-" * w for w in widths))
        head = f"{self.n_done} of {self.n_cases} cases\n{bridge_text(self.bridge())}{'; ' * bool(damping)}{damping}"
        return head + "\n" + "\n".join(lines)

    def _where_text(self, critical):
        """A critical case's place as people count it: 'node 6', 'wheel 3 of 32', 'car 2 of 8'
        (the file's indices count from 0)."""
        kind, where = critical["where_kind"], critical["where"]
        if kind == "node":
            return f"node {where}"
        data = self.train_data(critical["train"])
        count = len(data["contact_wheels"]) if kind == "contact wheel" else int(data["n_cars"])
        return f"{'wheel' if kind == 'contact wheel' else kind} {where + 1} of {count}"

    def to_xarray(self):
        """The envelope tables as an ``xarray.Dataset`` (dims train, speed_kmh, seed; units in
        each variable's attrs, and the output's response and cutoff_hz where it has one;
        ``<q>_where`` (attrs kind, holds: a node tag, a contact wheel's or a car's index; -1
        where not computed) and ``<q>_time`` [s] beside each quantity). Dataset attrs:
        vtsi_version, identity (JSON), cases_done and cases_total (fewer done: an interrupted
        sweep, NaN in the cases not run)."""
        import xarray
        coords = {"train": self.trains, "speed_kmh": ("speed_kmh", self.speeds_kmh, {"units": "km/h"}),
                  "seed": self.seeds}
        dims = ("train", "speed_kmh", "seed")
        data = {}
        for q, units in self.quantities.items():
            values, where, when = self._tables[q]
            described = self.describe(q.rsplit("_", 1)[0])
            attrs = {"units": units, "response": described["response"]}
            if "cutoff_hz" in described:
                attrs["cutoff_hz"] = described["cutoff_hz"]
            data[q] = xarray.Variable(dims, values, attrs)
            data[q + "_where"] = xarray.Variable(dims, where, {"kind": described["kind"],
                                                               "holds": WHERE_HOLDS[described["kind"]], "missing": -1})
            data[q + "_time"] = xarray.Variable(dims, when, {"units": "s"})
        return xarray.Dataset(data, coords=coords, attrs={"vtsi_version": self.vtsi_version,
                                                          "identity": json.dumps(self.identity),
                                                          "cases_done": int(self.n_done),
                                                          "cases_total": int(self.n_cases)})


def _history_keys(f, place):
    """Keys (:func:`case_key`) of the cases with histories under ``place`` of ``f`` ('histories'
    or 'cases/histories'): a case key's '/' nests its groups, the cases are the groups of data."""
    group = f.get(place)
    if not isinstance(group, h5py.Group):
        return []
    keys = []
    group.visititems(lambda name, node: keys.append(name) if isinstance(node, h5py.Group) and any(
        isinstance(v, h5py.Dataset) for v in node.values()) else None)
    return keys


def speed_index(speeds_kmh, value):
    """The index of the sweep's speed equal to ``value`` [km/h] (to 1e-9 km/h), or -1: the one
    reading of a case's speed (:class:`SweepResults`, :meth:`vtsi.sweep.Sweep.sweep_cases`)."""
    hit = np.flatnonzero(np.isclose(speeds_kmh, value, rtol=0.0, atol=1e-9))
    return int(hit[0]) if len(hit) else -1


def cases_text(trains, speeds_kmh, seeds):
    """A sweep's cases on one line, for a repr: '2 trains (HSLM-A1, ICE3) x 3 speeds 200 to 300
    km/h x a smooth rail = 6 cases'."""
    names = ", ".join(trains) if len(trains) <= 4 else ", ".join(trains[:3]) + ", ..."
    v = np.asarray(speeds_kmh, dtype=float)
    rail = "a smooth rail" if list(seeds) == [-1] else f"{len(seeds)} rail samples"
    return (f"{len(trains)} trains ({names}) x {len(v)} speeds {v.min():g} to {v.max():g} km/h x {rail} = "
            f"{len(trains) * len(v) * len(seeds)} cases")


def seeds_text(seeds):
    """The sweep's seeds for a message ('-1 (a smooth rail)' on a smooth rail)."""
    return "-1 (a smooth rail)" if list(seeds) == [-1] else ", ".join(map(str, seeds))


def _speed_list(speeds_kmh, value):
    """The sweep's speeds for a message: all of them when few, else their range and the two
    nearest ``value``."""
    v = np.asarray(speeds_kmh, dtype=float)
    text = f"{len(v)} speeds ({v.min():g} to {v.max():g} km/h"
    if len(v) <= 12:
        return text + ": " + ", ".join(f"{x:g}" for x in v) + ")"
    below, above = v[v < value], v[v > value]
    nearest = [f"{x:g}" for x in (below.max() if len(below) else None, above.min() if len(above) else None)
               if x is not None]
    return text + f"; nearest {' and '.join(nearest)})" if nearest and np.isfinite(value) else text + ")"
