"""The results file of a sweep (HDF5, one file per sweep) and its reader.

Layout (docs/sweeps.md)::

    /                      attrs: format 'vtsi-sweep', format_version, vtsi_version, created,
                           identity (JSON: bridge, settings, outputs, trains, speeds, seeds)
    /train, /speed_kmh, /seed          the envelope tables' coordinates (seed -1: smooth rail)
    /bridge/               frequencies_hz, deck_nodes, deck_x_m, midspan_nodes, span_lengths_m,
                           span_ends_m (n_spans, 2: each span's supports' x), mode_shapes_uy,
                           track_on_a_structure (a rail on pads over the deck: outputs are the rail's)
    /envelopes/<q>         (n_train, n_speed, n_seed) the extreme of quantity q over the output's
                           columns per case (NaN: not run yet, or not produced by that train);
                           <q>_where (the column: node tag, contact wheel or car), <q>_time [s];
                           attrs units, output, statistic, dims
    /static/<name>         for displacement and rotation outputs: trains (n_train, 2, n_columns)
                           and lm71 (2, n_columns), static min and max under each train's static
                           axle loads and under Load Model 71 (α = 1) (vtsi.influence)
    /trains/               one row per train, in /train's order: name, n_cars, n_dof, length_m,
                           characteristic_length_m (n_train,); axle_offsets_m and
                           static_wheel_loads_N [N] of every train end to end, train i's axles
                           the rows axle_ptr[i]:axle_ptr[i + 1]; contact_wheels by contact_ptr
    /outputs/<name>        attrs response, units, kind of column ('node', 'contact wheel', 'car'),
                           rows (of an envelope), history; columns: the node tags (n_columns,)
                           of a node output, or per train its wheel or car indices (n_train,
                           n_columns) of a vehicle output (-1 pads a train with fewer; none: the
                           train does not produce it)
    /cases/                one table of every case, appended batch by batch: train (n,) (its
                           index in /train), speed_kmh, seed, n_steps, seconds (n,) and per
                           output <name> (n, 6, n_columns), each case's envelope (rows min, max,
                           absmax, time_of_min, time_of_max, time_of_absmax; NaN in the columns
                           its train does not have); with a history,
                           histories/<train>/<speed>kmh/<seed>/<name>_time (m,) [s] and
                           <name>_values (m, n_columns)

Quantities q are ``<output>_<statistic>``: 'min' and 'max' for displacements, rotations,
bending moments and contact forces, 'absmax' for velocities and accelerations (``deflection_min`` is the largest downward
deflection: y is positive up).

Writing is atomic per batch: the file is copied, the batch written to the copy, and the copy
renamed over the file (``os.replace``), so the file on disk is always a complete, readable
results file, whenever the writing process is killed.
"""
import datetime
import json
import os
import shutil
import uuid

import h5py
import numpy as np

from vtsi.version import __version__
from vtsi.errors import SweepError, as_number

FORMAT, FORMAT_VERSION = "vtsi-sweep", 5
ENVELOPE_ROWS = ("min", "max", "absmax", "time_of_min", "time_of_max", "time_of_absmax")
STATISTICS = {"disp": ("min", "max"), "vel": ("absmax",), "accel": ("absmax",), "rotation": ("min", "max"),
              "moment": ("min", "max"),
              "contact_force": ("min", "max"), "car_body_accel": ("absmax",)}
COLUMN_KIND = {"contact_force": "contact wheel", "car_body_accel": "car"}
UNITS = {"disp": "m", "vel": "m/s", "accel": "m/s^2", "rotation": "rad", "moment": "N m", "contact_force": "N",
         "car_body_accel": "m/s^2"}


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
    contact = [t.contact_wheels for t in trains]
    group["contact_ptr"] = np.cumsum([0] + [len(c) for c in contact]).astype(np.int64)
    group["contact_wheels"] = np.concatenate(contact)


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


def _first_difference(a, b, prefix=""):
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                return f"{prefix}{key}"
            diff = _first_difference(a[key], b[key], f"{prefix}{key}.")
            if diff:
                return diff
        return None
    if a != b:
        return f"{prefix.rstrip('.')} ({json.dumps(a)[:60]} here, {json.dumps(b)[:60]} in the file)"
    return None


class ResultsWriter:
    """Creates (or reopens, to resume) a sweep's results file and writes batches of cases."""

    def __init__(self, path, identity, runner, resume=False, overwrite=False):
        self.path = None if path is None else os.fspath(path)
        self.identity = json.loads(json.dumps(identity))
        self._memory = None
        if self.path is not None and os.path.isdir(self.path):
            raise SweepError(f"results file {self.path} is a directory")
        if self.path is not None and os.path.exists(self.path) and not overwrite:
            if not resume:
                raise SweepError(f"results file {self.path} exists; resume=True (--resume) continues its sweep, "
                                       "overwrite=True (--overwrite) replaces it")
            self._check(self.path)
            return
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
                b["deck_nodes"] = np.asarray(runner.deck_nodes, dtype=np.int64)
                b["deck_x_m"] = np.array([runner.model.nodes[n][0] for n in runner.deck_nodes])
                b["midspan_nodes"] = np.asarray(runner.midspan_nodes, dtype=np.int64)
                b["span_lengths_m"] = np.asarray(runner.span_lengths, dtype=float)
                b["span_ends_m"] = np.asarray(runner.span_ends, dtype=float).reshape(-1, 2)
                b["track_on_a_structure"] = bool(runner.track_on_a_structure)
                asm = runner.model.build()
                b["mode_shapes_uy"] = runner.mode_shapes[[asm.full_dof(n, 2) for n in runner.deck_nodes]]
                shape = (len(ident["trains"]), len(ident["speeds_kmh"]), len(ident["seeds"]))
                env = f.create_group("envelopes")
                for q, output, stat, units in quantities(ident["outputs"]):
                    ds = env.create_dataset(q, shape=shape, dtype=float, fillvalue=np.nan)
                    ds.attrs.update({"units": units, "output": output, "statistic": stat,
                                     "dims": ["train", "speed_kmh", "seed"]})
                    env.create_dataset(q + "_where", shape=shape, dtype=np.int64, fillvalue=-1)
                    env.create_dataset(q + "_time", shape=shape, dtype=float, fillvalue=np.nan).attrs["units"] = "s"
                catalogue = [runner.train(name, 1.0) for name in ident["trains"]]
                outs = f.create_group("outputs")
                for o, output in zip(ident["outputs"], runner.outputs):
                    g = outs.create_group(o["name"])
                    g.attrs.update({"response": o["response"], "units": UNITS[o["response"]],
                                    "kind": COLUMN_KIND.get(o["response"], "node"), "rows": list(ENVELOPE_ROWS),
                                    "history": bool(o["history"])})
                    g["columns"] = _column_table([runner.columns(output, train) for train in catalogue]) \
                        if o["response"] in COLUMN_KIND else runner.columns(output, catalogue[0])
                static = f.create_group("static")
                static.attrs["note"] = ("static responses (influence lines): per train its static axle loads, "
                                        "and Load Model 71 (alpha = 1); rows min, max")
                for o in runner.outputs:
                    env = runner.static_envelopes(o, ident["trains"])
                    if env is not None:
                        g = static.create_group(o.name)
                        g["trains"], g["lm71"] = env
                        g.attrs["units"] = UNITS[o.response]
                _train_table(f.create_group("trains"), catalogue)
                f.create_group("cases")
                if self.path is None:
                    self._memory = f
            if tmp is not None:
                os.replace(tmp, self.path)
        except BaseException:
            if tmp is not None and os.path.exists(tmp):
                os.remove(tmp)
            raise

    def _open_new(self):
        if self.path is None:
            f = h5py.File(f"vtsi-sweep-{uuid.uuid4().hex}.h5", "w", driver="core", backing_store=False)
            return _KeepOpen(f), None
        tmp = self.path + ".partial"
        folder = os.path.dirname(os.path.abspath(self.path))
        if not os.path.isdir(folder):
            raise SweepError(f"results file {self.path}: the directory {folder} does not exist")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise SweepError(f"results file {self.path}: cannot write in {folder}")
        try:
            return h5py.File(tmp, "w"), tmp
        except OSError as exc:
            raise SweepError(f"results file {self.path}: cannot write there ({exc.strerror or exc})") from None

    def _check(self, path):
        try:
            with h5py.File(path, "r") as f:
                fmt, stored, version = f.attrs.get("format"), f.attrs.get("identity"), f.attrs.get("format_version", 0)
        except OSError as exc:
            raise SweepError(f"results file {path}: not a readable HDF5 file ({exc})") from None
        if fmt != FORMAT or stored is None:
            raise SweepError(f"results file {path} is not a vtsi sweep results file")
        if int(version) != FORMAT_VERSION:
            raise SweepError(f"results file {path} is of format {version}, this vtsi writes format {FORMAT_VERSION}: "
                             "it cannot be resumed; use another file, or overwrite=True (--overwrite)")
        diff = _first_difference(self.identity, json.loads(stored))
        if diff:
            raise SweepError(f"results file {path} holds a different sweep (it differs in {diff}); "
                                   "use another file, or overwrite=True (--overwrite)")

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
        return _KeepOpen(self._memory) if self._memory is not None else h5py.File(self.path, "r")

    def write(self, results):
        """Add a batch of :class:`~vtsi.passage.CaseResult` (atomically, see the module docstring)."""
        if not results:
            return
        if self._memory is not None:
            self._write(self._memory, results)
            return
        tmp = self.path + ".partial"
        try:
            shutil.copyfile(self.path, tmp)
            with h5py.File(tmp, "a") as f:
                self._write(f, results)
            os.replace(tmp, self.path)
        except OSError as exc:              # a full disk, a lost drive: the file keeps what it had
            if os.path.exists(tmp):
                os.remove(tmp)
            raise SweepError(f"results file {self.path}: cannot write {len(results)} more cases "
                             f"({exc.strerror or exc}); the cases finished before them are in it: resume=True "
                             "(--resume) continues the sweep") from None

    def _write(self, f, results):
        ident = self.identity
        trains, speeds, seeds = ident["trains"], np.array(ident["speeds_kmh"]), ident["seeds"]
        cases, outputs = f["cases"], f["outputs"]
        n = len(results)
        train_index = np.array([trains.index(r.train) for r in results], dtype=np.int64)
        for name, dtype, values in (("train", np.int64, train_index),
                                    ("speed_kmh", float, [r.speed_kmh for r in results]),
                                    ("seed", np.int64, [r.seed for r in results]),
                                    ("n_steps", np.int64, [r.n_steps for r in results]),
                                    ("seconds", float, [r.seconds for r in results])):
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
        for r in results:
            for name, (time, values) in r.histories.items():
                h = cases.require_group("histories").require_group(train_key(r.train)).require_group(
                    _speed_seed(r.speed_kmh, r.seed))
                h[name + "_time"] = time
                h.create_dataset(name + "_values", data=values, compression="gzip", compression_opts=4)
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

    def write_histories(self, results):
        """Add the time histories of re-run cases (:meth:`vtsi.sweep.Sweep.record_histories`)
        under /histories/<case>: per output ``<name>_time``, ``<name>_values``, ``<name>_columns``;
        attrs train, speed_kmh, seed, x_head0 [m]. Atomic as :meth:`write`."""
        def put(f):
            for r in results:
                key = case_key(r.train, r.speed_kmh, r.seed)
                if "histories" in f and key in f["histories"]:
                    del f["histories"][key]
                g = f.require_group("histories").create_group(key)
                g.attrs.update({"train": r.train, "speed_kmh": r.speed_kmh, "seed": r.seed, "x_head0": r.x_head0,
                                "n_steps": r.n_steps})
                for name, (time, values) in r.histories.items():
                    g[name + "_time"] = time
                    g.create_dataset(name + "_values", data=values, compression="gzip", compression_opts=4)
                    g[name + "_columns"] = r.columns[name]
        if self._memory is not None:
            put(self._memory)
            return
        tmp = self.path + ".partial"
        shutil.copyfile(self.path, tmp)
        with h5py.File(tmp, "a") as f:
            put(f)
        os.replace(tmp, self.path)

    def results(self):
        return SweepResults(self._memory if self._memory is not None else self.path)


def _group_keys(group):
    """Paths of the groups below ``group`` that carry a case (attribute 'train')."""
    keys = []
    group.visititems(lambda name, obj: keys.append(name) if isinstance(obj, h5py.Group) and "train" in obj.attrs else None)
    return keys


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
    """

    def __init__(self, source):
        self._file = source if isinstance(source, h5py.File) else None
        self.path = None if self._file is not None else os.fspath(source)
        if self.path is not None and not os.path.isfile(self.path):
            raise SweepError(f"results file {self.path}: " + ("not a file" if os.path.exists(self.path) else "no such file"))
        try:
            handle = self._open()
        except OSError as exc:
            raise SweepError(f"results file {self.path}: not a readable HDF5 file ({exc})") from None
        with handle as f:
            if f.attrs.get("format") != FORMAT:
                raise SweepError(f"{self.path}: not a vtsi sweep results file")
            if int(f.attrs.get("format_version", 0)) != FORMAT_VERSION:
                raise SweepError(f"{self.path}: a vtsi sweep results file of format {f.attrs.get('format_version')}, "
                                 f"this vtsi reads format {FORMAT_VERSION}: run the sweep again, or read it with the "
                                 f"vtsi that wrote it ({f.attrs.get('vtsi_version')})")
            self.identity = json.loads(f.attrs["identity"])
            self.vtsi_version = str(f.attrs["vtsi_version"])
            self.trains = [t.decode() if isinstance(t, bytes) else str(t) for t in f["train"][()]]
            self.speeds_kmh = f["speed_kmh"][()]
            self.seeds = [int(s) for s in f["seed"][()]]
            self.frequencies_hz = f["bridge/frequencies_hz"][()]
            self.quantities = {q: units for q, _, _, units in quantities(self.identity["outputs"])}
            self._tables = {q: (f["envelopes"][q][()], f["envelopes"][q + "_where"][()], f["envelopes"][q + "_time"][()])
                            for q in self.quantities}
            self.n_done = f["cases"]["train"].shape[0] if "train" in f["cases"] else 0

    def _open(self):
        return _KeepOpen(self._file) if self._file is not None else h5py.File(self.path, "r")

    @property
    def n_cases(self):
        return len(self.trains) * len(self.speeds_kmh) * len(self.seeds)

    def envelope(self, quantity):
        """``(n_train, n_speed, n_seed)`` values of ``quantity`` (NaN where not computed)."""
        if quantity not in self._tables:
            raise SweepError(f"sweep results: unknown quantity {quantity!r}; valid: {', '.join(self._tables)}")
        return self._tables[quantity][0].copy()

    def critical(self, quantity):
        """The governing case of ``quantity`` (its largest value; smallest for a 'min'): a dict
        with value, units, train, speed_kmh, seed, where (node tag / wheel / car), time [s];
        None when no case produced it."""
        values, where, when = self._tables[quantity] if quantity in self._tables else (None, None, None)
        if values is None:
            raise SweepError(f"sweep results: unknown quantity {quantity!r}; valid: {', '.join(self._tables)}")
        if np.all(np.isnan(values)):
            return None
        idx = np.unravel_index(np.nanargmin(values) if quantity.endswith("_min") else np.nanargmax(values), values.shape)
        return {"quantity": quantity, "value": float(values[idx]), "units": self.quantities[quantity],
                "train": self.trains[idx[0]], "speed_kmh": float(self.speeds_kmh[idx[1]]), "seed": self.seeds[idx[2]],
                "where": int(where[idx]), "time": float(when[idx])}

    def case(self, train, speed_kmh, seed=-1):
        """One case: ``{output: {'envelope': (6, n), 'columns': (n,)[, 'time': (m,), 'values':
        (m, n)]}}`` (envelope rows: min, max, absmax and their times; only the outputs its train
        produces) plus 'attrs'."""
        key = case_key(train, speed_kmh, seed)
        row = self._row(train, speed_kmh, seed)
        if row is None:
            raise SweepError(f"sweep results: no case {key}")
        i = self.trains.index(train)
        with self._open() as f:
            g = f["cases"]
            out = {"attrs": {"train": train, "speed_kmh": float(g["speed_kmh"][row]), "seed": int(g["seed"][row]),
                             "n_steps": int(g["n_steps"][row]), "seconds": float(g["seconds"][row])}}
            h = g.get(f"histories/{train_key(train)}/{_speed_seed(speed_kmh, seed)}")
            for o in self.identity["outputs"]:
                name = o["name"]
                columns = f["outputs"][name]["columns"][()]
                if columns.ndim == 2:                 # a vehicle output: this train's columns
                    columns = columns[i][columns[i] >= 0]
                if len(columns) == 0:
                    continue
                out[name] = {"envelope": g[name][row][:, : len(columns)], "columns": columns}
                if h is not None and name + "_time" in h:
                    out[name]["time"], out[name]["values"] = h[name + "_time"][()], h[name + "_values"][()]
        return out

    def _row(self, train, speed_kmh, seed):
        """The row of the case (train, speed [km/h], seed) in /cases, or None."""
        if train not in self.trains:
            return None
        with self._open() as f:
            g = f["cases"]
            if "train" not in g:
                return None
            hits = np.flatnonzero((g["train"][()] == self.trains.index(train))
                                  & np.isclose(g["speed_kmh"][()], float(speed_kmh), rtol=0, atol=1e-9)
                                  & (g["seed"][()] == int(seed)))
        return int(hits[0]) if len(hits) else None

    def column_envelopes(self, output):
        """Every case's envelope of ``output``: (n_train, n_speed, n_seed, 6, n_columns) (NaN
        where a case is missing or did not produce it; rows as in :data:`ENVELOPE_ROWS`) and the
        columns (node tags; wheel or car indices: the columns of the train with most)."""
        names = [o["name"] for o in self.identity["outputs"]]
        if output not in names:
            raise SweepError(f"sweep results: unknown output {output!r}; valid: {', '.join(names)}")
        with self._open() as f:
            columns = f["outputs"][output]["columns"][()]
            g = f["cases"]
            width = columns.shape[-1]
            out = np.full((len(self.trains), len(self.speeds_kmh), len(self.seeds), len(ENVELOPE_ROWS), width), np.nan)
            if output in g:
                speed = np.argmin(np.abs(self.speeds_kmh[None, :] - g["speed_kmh"][()][:, None]), axis=1)
                seed = np.array([self.seeds.index(int(k)) for k in g["seed"][()]], dtype=np.int64)
                out[g["train"][()], speed, seed] = g[output][()]
        if columns.ndim == 2:          # a vehicle output: the columns of the train with most
            columns = columns[int(np.argmax(np.sum(columns >= 0, axis=1)))] if len(columns) else columns[:0]
            columns = columns[columns >= 0]
        return out, columns

    def static(self, output):
        """Static envelopes of ``output`` (rows min, max): ``(trains (n_train, 2, n_columns),
        lm71 (2, n_columns))`` or None (vtsi.influence; only displacement and rotation outputs)."""
        with self._open() as f:
            if "static" not in f or output not in f["static"]:
                return None
            return f["static"][output]["trains"][()], f["static"][output]["lm71"][()]

    def train_data(self, train):
        """The stored axle data of ``train``: dict with axle_offsets_m, static_wheel_loads_N,
        contact_wheels, name, n_cars, n_dof, length_m, characteristic_length_m."""
        if train not in self.trains:
            raise SweepError(f"sweep results: unknown train {train!r}; valid: {', '.join(self.trains)}")
        i = self.trains.index(train)
        with self._open() as f:
            g = f["trains"]
            axles = slice(int(g["axle_ptr"][i]), int(g["axle_ptr"][i + 1]))
            contact = slice(int(g["contact_ptr"][i]), int(g["contact_ptr"][i + 1]))
            name = g["name"][i]
            return {"axle_offsets_m": g["axle_offsets_m"][axles], "static_wheel_loads_N": g["static_wheel_loads_N"][axles],
                    "contact_wheels": g["contact_wheels"][contact],
                    "name": name.decode() if isinstance(name, bytes) else str(name),
                    **{k: g[k][i] for k in ("n_cars", "n_dof", "length_m", "characteristic_length_m")}}

    def bridge(self):
        """The stored bridge data: frequencies_hz, deck_nodes, deck_x_m, midspan_nodes, span_lengths_m,
        span_ends_m (n_spans, 2), mode_shapes_uy, track_on_a_structure."""
        with self._open() as f:
            return {k: f["bridge"][k][()] for k in f["bridge"]}

    def histories(self):
        """Keys of the cases with recorded time histories (/histories)."""
        with self._open() as f:
            return [] if "histories" not in f else [k for k in _group_keys(f["histories"])]

    def history(self, train, speed_kmh, seed=-1):
        """A case's recorded histories: ``{output: (time, values, columns)}`` plus 'attrs'."""
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
            raise SweepError(f"sweep results: a case's seed must be an integer (-1: smooth rail), got {seed!r}")
        key = case_key(train, as_number(speed_kmh, "sweep results", "speed [km/h]", SweepError), seed)
        with self._open() as f:
            if "histories" not in f or key not in f["histories"]:
                raise SweepError(f"sweep results: no histories of case {key} (Sweep.record_histories)")
            g = f["histories"][key]
            names = sorted({k.rsplit("_", 1)[0] for k in g})
            out = {n: (g[n + "_time"][()], g[n + "_values"][()], g[n + "_columns"][()]) for n in names}
            out["attrs"] = dict(g.attrs)
        return out

    def summary(self):
        """A text table: per quantity its extreme, the governing train, speed, place and time."""
        where_kind = {o["name"]: COLUMN_KIND.get(o["response"], "node") for o in self.identity["outputs"]}
        rows = [("quantity", "value", "units", "train", "speed km/h", "seed", "where", "t [s]")]
        for q in self.quantities:
            c = self.critical(q)
            if c is None:
                continue
            output = q.rsplit("_", 1)[0]
            rows.append((q, f"{c['value']:.5g}", c["units"], c["train"], f"{c['speed_kmh']:g}",
                         "smooth" if c["seed"] < 0 else str(c["seed"]), f"{where_kind[output]} {c['where']}",
                         f"{c['time']:.3f}"))
        widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
        lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        lines.insert(1, "  ".join("-" * w for w in widths))
        head = f"{self.n_done} of {self.n_cases} cases"
        return head + "\n" + "\n".join(lines)

    def to_xarray(self):
        """The envelope tables as an ``xarray.Dataset`` (dims train, speed_kmh, seed; units in
        each variable's attrs; ``<q>_where`` and ``<q>_time`` beside each quantity)."""
        import xarray
        coords = {"train": self.trains, "speed_kmh": ("speed_kmh", self.speeds_kmh, {"units": "km/h"}),
                  "seed": self.seeds}
        dims = ("train", "speed_kmh", "seed")
        data = {}
        for q, units in self.quantities.items():
            values, where, when = self._tables[q]
            data[q] = xarray.Variable(dims, values, {"units": units})
            data[q + "_where"] = xarray.Variable(dims, where)
            data[q + "_time"] = xarray.Variable(dims, when, {"units": "s"})
        return xarray.Dataset(data, coords=coords, attrs={"vtsi_version": self.vtsi_version,
                                                          "identity": json.dumps(self.identity)})
