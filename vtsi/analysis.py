"""Analyses of a linear model: static (load control), eigenvalues and transient.

The transient analysis factors each stage's effective matrix once (banded Cholesky) and runs
the steps in compiled chunks (:mod:`vtsi.timeloop`), handing each chunk to the recorders.
"""
import logging

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from vtsi.banded import pad, solve_band
from vtsi.errors import AnalysisError, DivergenceError, ModelError, as_number, as_positive, is_number
from vtsi.integrators import make_integrator
from vtsi.model import Model
from vtsi.recorders.sinks import check_own_files
from vtsi.subdomain import FEStages, factor
from vtsi.timeloop import run_from_state, run_linear_steps


log = logging.getLogger(__name__)
QUANTITY_SLOT = {"u": 0, "v": 1, "a": 2}
RUN_COLUMNS = 4          # a recorder's columns are copied run by run (slices) if its runs of consecutive
                         # columns hold this many on average, else gathered by index (_part)
BLOCK_STEPS = 512         # steps of a run's tables (load factors...) evaluated ahead for the runs that follow
ALL_MODES_MAX = 3000      # free dofs up to which eigen(model, 'all') solves the dense problem
DENSE_EIGEN_MAX = 200     # free dofs up to which eigen always solves the dense problem (_dense_for)


class DomainState:
    """Committed response of a model: time [s] and full-dof ``u, v, a`` (m, m/s, m/s²)."""

    def __init__(self, n_full):
        self.time = 0.0
        self.u, self.v, self.a = np.zeros(n_full), np.zeros(n_full), np.zeros(n_full)


def domain_state(model):
    """The model's committed state, a :class:`DomainState`: ``time`` [s] (a static analysis's
    pseudo-time), and ``u``, ``v``, ``a``, float64 ``(n_full,)`` [m, m/s, m/s²; rad, rad/s,
    rad/s² at rotations] over every dof, node after node in the order the nodes were added
    (``model.build().full_dof(node, dof)``), fixed dofs included. Created at rest (time 0) on
    first use; when the number of dofs changes (a node added or removed) it is made anew at
    rest, keeping its time."""
    n_full = model.build().n_full
    state = getattr(model, "state", None)
    if state is None or state.u.shape[0] != n_full:
        time = state.time if state is not None else 0.0
        state = model.state = DomainState(n_full)
        state.time = time
    return state






def component_labels(M, C, K):
    """Connected components of the couplings of M, C, K (their nonzeros): a label per dof."""
    coo = sp.coo_matrix(abs(M) + abs(C) + abs(K))
    return component_labels_of_entries(coo.row.astype(np.int64), coo.col.astype(np.int64), M.shape[0])


@njit(cache=True)
def component_labels_of_entries(rows, cols, n):
    """Connected components of the ``n`` dofs coupled by the entries ``(rows, cols)`` (int64):
    a label per dof (int64 (n,), the smallest dof of its component)."""
    parent = np.arange(n)
    for k in range(rows.shape[0]):
        a, b = rows[k], cols[k]
        while parent[a] != a:
            a = parent[a]
        while parent[b] != b:
            b = parent[b]
        if a < b:
            parent[b] = a
        elif b < a:
            parent[a] = b
    for i in range(n):            # parents come before their children: one pass settles every root
        parent[i] = parent[parent[i]]
    return parent


def dofs_with(labels, seeds):
    """The dofs (ascending) whose component (``labels``) holds a ``seeds`` dof (boolean per dof,
    or their indices)."""
    hit = np.zeros(len(labels), dtype=bool)
    hit[labels[seeds]] = True
    return np.flatnonzero(hit[labels]).astype(np.int64)


def moving_dofs(assembly, model, seeds=None, loaded=None):
    """Free dofs a linear time loop must integrate: the connected components (couplings of K, M,
    C) that hold a pattern load (``loaded``: the loaded free dofs, if known), a nonzero committed
    state or a ``seeds`` dof (boolean over the free dofs). The others stay exactly at rest (zero
    load, zero state, so zero forever), e.g. the axial dofs of a straight horizontal beam under
    vertical loads; their recorders read 0."""
    labels = getattr(assembly, "_component_labels", None)
    if labels is None:
        p = assembly.pattern
        labels = assembly._component_labels = component_labels_of_entries(p.rows, p.cols, assembly.n_free)
    state = domain_state(model)
    if loaded is None:
        loaded = _pattern_loads(assembly, list(model.patterns.values()))[1]
    seeds = NO_SEEDS if seeds is None else np.asarray(seeds, dtype=np.bool_)
    return moving_components(labels, loaded, seeds, state.u, state.v, state.a, assembly.full_of_free)


NO_SEEDS = np.zeros(0, dtype=np.bool_)


@njit(cache=True)
def same_entries(a, b):
    """Whether the 1-d arrays ``a`` and ``b`` have the same length and entries."""
    if a.shape[0] != b.shape[0]:
        return False
    for i in range(a.shape[0]):
        if a[i] != b[i]:
            return False
    return True


@njit(cache=True)
def any_nonzero(u, v, a, dofs):
    """Whether ``u``, ``v`` or ``a`` is not 0 (or NaN) at one of ``dofs`` (a dof at rest has moved)."""
    for d in dofs:
        if u[d] != 0.0 or v[d] != 0.0 or a[d] != 0.0:
            return True
    return False


@njit(cache=True)
def moving_components(labels, loaded, seeds, u, v, a, full_of_free):
    """The free dofs (int64, ascending) whose component (``labels``, one per free dof) holds a
    ``loaded`` free dof, a ``seeds`` dof (boolean per free dof, or empty) or a free dof whose
    full-dof ``u``, ``v`` or ``a`` (``full_of_free`` maps them) is not 0."""
    n = labels.shape[0]
    hit = np.zeros(n, dtype=np.bool_)
    for d in loaded:
        hit[labels[d]] = True
    for i in range(n):
        f = full_of_free[i]
        if (seeds.shape[0] > 0 and seeds[i]) or u[f] != 0.0 or v[f] != 0.0 or a[f] != 0.0:
            hit[labels[i]] = True
    count = 0
    for i in range(n):
        if hit[labels[i]]:
            count += 1
    out = np.empty(count, dtype=np.int64)
    k = 0
    for i in range(n):
        if hit[labels[i]]:
            out[k] = i
            k += 1
    return out


def _integer(who, what, value, low=None):
    """``value`` as an int (>= ``low``), or an AnalysisError naming ``who`` and the value."""
    try:
        ok = is_number(value) and float(value) == int(value)
    except (ValueError, OverflowError):          # NaN, inf
        ok = False
    if not ok or (low is not None and int(value) < low):
        bound = f" >= {low}" if low is not None else ""
        raise AnalysisError(f"{who}: {what} must be an integer{bound}, got {value!r}")
    return int(value)


def _model(who, model):
    """``model`` if it is a :class:`~vtsi.model.Model`, else an AnalysisError naming ``who``."""
    if not isinstance(model, Model):
        raise AnalysisError(f"{who}: model must be a vtsi.Model, got {model!r}")
    return model


def _recorders(who, recorders):
    """``recorders`` as a list, each checked to follow the recorder contract
    (:mod:`vtsi.recorders.base`: ``requests``, ``start``, ``write``, ``close``), else an
    AnalysisError naming ``who`` and the value; two recorders writing one file are a ModelError
    naming both and the path."""
    if isinstance(recorders, (str, bytes)) or not hasattr(recorders, "__iter__"):
        raise AnalysisError(f"{who}: recorders must be a list of recorders, got {recorders!r}")
    recorders = list(recorders)
    for i, rec in enumerate(recorders):
        if not all(callable(getattr(rec, name, None)) for name in ("requests", "start", "write", "close")):
            raise AnalysisError(f"{who}: recorders[{i}] is not a recorder (NodeRecorder, ElementRecorder...), "
                                f"got {rec!r}")
    check_own_files(who, recorders)      # two recorders writing one file
    return recorders


def _pattern_loads(assembly, patterns):
    """CSR of the free-dof load vectors of ``patterns``: (ptr, dof, val)."""
    return nonzero_rows(assembly.load_vectors(patterns))


@njit(cache=True)
def nonzero_rows(vectors):
    """CSR ``(ptr (n_rows + 1,), index, value)`` (int64, int64, float64) of the nonzeros of the rows
    of ``vectors (n_rows, n)``."""
    n_rows, n = vectors.shape
    ptr = np.zeros(n_rows + 1, dtype=np.int64)
    for r in range(n_rows):
        ptr[r + 1] = ptr[r]
        for j in range(n):
            if vectors[r, j] != 0.0:
                ptr[r + 1] += 1
    index = np.empty(ptr[n_rows], dtype=np.int64)
    value = np.empty(ptr[n_rows])
    k = 0
    for r in range(n_rows):
        for j in range(n):
            if vectors[r, j] != 0.0:
                index[k], value[k] = j, vectors[r, j]
                k += 1
    return ptr, index, value


def pattern_factors(patterns, times, cache=None):
    """``(len(times), len(patterns))`` load factors. Series that stack (the OpenSees idiom of
    one Path per loaded node on one time grid, :meth:`~vtsi.timeseries.TimeSeries.stack_key`)
    are evaluated together from their stacked values, kept in ``cache`` (a dict) from call to
    call with the grouping itself, so that a call costs no Python per pattern."""
    cache = {} if cache is None else cache
    key = tuple([(id(p.series), p.factor * getattr(p.series, "factor", 1.0), p.constant_time is None)
                 for p in patterns])
    plan = cache.get("plan")
    if plan is None or plan[0] != key:
        groups, single = {}, []
        for p, pattern in enumerate(patterns):
            stack = pattern.series.stack_key() if pattern.constant_time is None else None
            if stack is None:
                single.append(p)      # evaluated at every call (a frozen pattern reads its time then)
            else:
                groups.setdefault((type(pattern.series), stack), []).append(p)
        stacked = []
        for (cls, stack), members in groups.items():
            table = np.array([patterns[p].series.values for p in members])
            scale = np.array([patterns[p].series.factor for p in members])
            outer = np.array([patterns[p].factor for p in members])
            whole = members == list(range(len(patterns)))
            stacked.append((cls, stack, slice(None) if whole else np.array(members), table, scale, outer))
        plan = cache["plan"] = (key, single, stacked)
    _, single, stacked = plan
    if not single and len(stacked) == 1 and isinstance(stacked[0][2], slice):
        cls, stack, _, table, scale, outer = stacked[0]
        return cls.stack_factors(stack, table, times, scale, outer)      # one grid for all: no copy
    out = np.empty((len(times), len(patterns)))
    for p in single:
        out[:, p] = patterns[p].factors(times)
    for cls, stack, columns, table, scale, outer in stacked:
        out[:, columns] = cls.stack_factors(stack, table, times, scale, outer)
    return out


def settle_dependent_dofs(assembly, prescribed, state, at):
    """After a step whose free dofs are in ``state``: the dofs of prescribed displacements (sp;
    ``Assembly.prescribed_dofs``) at the time ``at`` [s] the step applied its loads (OpenSees:
    ``t_n + αΔt`` for HHT), ``u_c = Σ value × factor(at)``, their velocity and acceleration 0;
    then the equalDOF / rigidLink dofs from the free and prescribed ones."""
    for pattern, dofs, values in prescribed:
        state.u[dofs] = 0.0
    for pattern, dofs, values in prescribed:
        state.u[dofs] += float(pattern.factors(np.array([at]))[0]) * values
    for vec in (state.u, state.v, state.a):
        assembly.complete(vec)


class _RecorderFeed:
    """Maps the recorders' requests to output columns and hands chunks over.

    Each distinct request is one column of a chunk, in two tables: the *kernel's* columns, the
    quantities 'u', 'v', 'a' of free dofs, which a kernel reads from its state bank
    (``rec_slot``, ``rec_index`` over the free dofs), and the *extra* columns, filled here: fixed
    dofs (read 0), prescribed displacements (sp), equalDOF / rigidLink dofs and the further
    quantities an analysis records, its ``channels``: ``name -> (group, slot, size, label)`` (a
    coupled analysis: train dofs from slots 0..2 of the train's bank, contact wheels);
    :meth:`group` tells the kernel what to record for a group and :meth:`deliver` takes it back
    by name. A recorder whose columns lie side by side in one table is handed a view of it, the
    others their columns gathered.
    """

    def __init__(self, assembly, model, recorders, info=None, channels=None):
        channels = channels or {}
        self.recorders = list(recorders)
        keys, requested = {}, []
        for rec in self.recorders:
            cols = []
            for quantity, index in rec.requests(assembly):
                if quantity not in QUANTITY_SLOT:
                    if quantity not in channels:
                        raise ModelError(f"recorder: quantity {quantity!r} is not recorded by this analysis; "
                                         f"available: {', '.join(list(QUANTITY_SLOT) + list(channels))}")
                    _, _, size, label = channels[quantity]
                    if not 0 <= index < size:
                        raise ModelError(f"recorder: {label} {index} out of range 0..{size - 1}")
                cols.append(keys.setdefault((quantity, int(index)), len(keys)))
            requested.append(cols)
        # a constrained dof (equalDOF / rigidLink) is recorded as its row of T over free and prescribed dofs
        derived = []
        if assembly.constrained_rows is not None:
            row_of = {int(k): r for r, k in enumerate(assembly.constrained_dofs)}
            for (q, k), i in list(keys.items()):
                if q in QUANTITY_SLOT and k in row_of:
                    row = assembly.constrained_rows[row_of[k]]
                    tied = assembly.constrained_prescribed[row_of[k]]
                    sources = [keys.setdefault((q, int(assembly.full_of_free[j])), len(keys)) for j in row.indices]
                    sources += [keys.setdefault((q, int(assembly.prescribed_full[j])), len(keys)) for j in tied.indices]
                    derived.append((i, sources, np.r_[row.data, tied.data]))
        # the kernel's columns first, then the extra ones, each in the order first requested
        found = list(keys)
        on_kernel = np.array([q in QUANTITY_SLOT and assembly.free_of_full[k] >= 0 for q, k in found], dtype=bool)
        order = np.argsort(~on_kernel, kind="stable")
        position = np.empty(len(found), dtype=np.int64)
        position[order] = np.arange(len(found))
        self.items = [found[i] for i in order]
        nk = self.n_kernel = int(on_kernel.sum())
        self.rec_slot = np.array([QUANTITY_SLOT[q] for q, _ in self.items[:nk]], dtype=np.int64)
        self.rec_index = assembly.free_of_full[np.array([k for _, k in self.items[:nk]], dtype=np.int64)]
        self.parts = [_part(position[np.array(cols, dtype=np.int64)], nk) for cols in requested]
        # vtsi's own recorders read the chunk's table (a view); another package's get their own copy, as the
        # contract has always given them, which they may keep or change
        self.shared = [type(rec).__module__.split('.')[0] == 'vtsi' for rec in self.recorders]
        # sources over the kernel and the extra columns, coefficients of each
        self.derived = []
        for i, sources, coefficients in derived:
            sources = position[np.array(sources, dtype=np.int64)]
            k = sources < nk
            self.derived.append((position[i] - nk, sources[k], coefficients[k], sources[~k] - nk, coefficients[~k]))
        # a prescribed displacement (sp) is recorded as value × factor(t) (its v and a as 0)
        self.prescribed = []
        self.load_lag = 0.0    # [s] before the record times where the loads apply (HHT: (1 − α)Δt)
        for pattern, dofs, values in assembly.prescribed_dofs(model.patterns.values()):
            for k, value in zip(dofs, values):
                if ("u", int(k)) in keys:
                    self.prescribed.append((position[keys[("u", int(k))]] - nk, pattern, value))
        groups = {}
        for i, (q, k) in enumerate(self.items[nk:]):
            if q in channels:
                group, slot, _, _ = channels[q]
                for lst, value in zip(groups.setdefault(group, ([], [], [])), (i, slot, k)):
                    lst.append(value)
        self.groups = {g: tuple(np.array(x, dtype=np.int64) for x in v) for g, v in groups.items()}
        self.assembly, self.model = assembly, model
        self.start(info)

    def start(self, info=None):
        """Start the recorders for a run (again for each run of a kept feed)."""
        started = []
        try:
            for rec in self.recorders:
                rec.start(self.assembly, self.model, info)
                started.append(rec)
        except Exception:
            for rec in started:
                rec.close()
            raise

    def state_row(self, state, assembly):
        """The bridge columns ``(len(rec_index),)`` of a committed state (Python-stepped analyses)."""
        return np.stack((state.u, state.v, state.a))[self.rec_slot, assembly.full_of_free[self.rec_index]]

    def group(self, name):
        """``(slots, indices)`` of the columns of channel group ``name``, in :meth:`deliver`'s order."""
        empty = np.zeros(0, dtype=np.int64)
        return self.groups.get(name, (empty, empty, empty))[1:]

    def deliver(self, times, out, assembly, **groups):
        """Hand a chunk over: ``out (n, n_kernel)`` the kernel's columns, ``groups[name]`` the
        columns of each channel group (as :meth:`group` listed them). vtsi's own recorders get
        views of these tables where they can (read only, valid during the call), another
        package's recorder a copy of its own (:class:`~vtsi.recorders.base.Recorder` contract,
        item 3). A recorder that raises does not keep the others from the
        chunk (every completed step stays recorded); the first error is raised after all of them
        were served, with a note naming its recorder (and the others that raised) when there are
        several."""
        if not self.recorders or len(times) == 0:
            return
        extra = np.zeros((len(times), len(self.items) - self.n_kernel))    # fixed dofs read 0
        for name, values in groups.items():
            if name in self.groups:
                extra[:, self.groups[name][0]] = values
        for i, pattern, value in self.prescribed:
            extra[:, i] += value * pattern.factors(times - self.load_lag)
        for i, kernel, on_kernel, others, on_others in self.derived:
            extra[:, i] = out[:, kernel] @ on_kernel + extra[:, others] @ on_others

        def write(k, rec):
            rec.load_lag = self.load_lag
            rec.write(times, _columns(self.parts[k], out, extra, self.shared[k]), assembly)
        self._each(write, lambda: f"on the steps of t = {times[0]:.6g} to {times[-1]:.6g}; the other recorders "
                                  "hold these steps")

    def close(self):
        """Close every recorder, also after one raised (the others' files are complete and
        unlocked); then the first error, as :meth:`deliver`."""
        self._each(lambda k, rec: rec.close(), lambda: "when closed; the other recorders are closed")

    def _each(self, call, what):
        """``call(k, rec)`` for every recorder (``k`` its index), also after one raised; then the
        first error is raised, with a note naming its recorder (``what()``: when, and what the
        others did; formatted only then) and the others that raised too (with one recorder, its
        error as it is)."""
        failed = None
        for i, rec in enumerate(self.recorders):
            try:
                call(i, rec)
            except Exception as exc:        # raised below, once every recorder had its turn
                if len(self.recorders) == 1:
                    raise
                if failed is None:
                    failed = exc
                    note = f"raised by recorders[{i}] {rec!r} {what()}"
                else:
                    note = f"recorders[{i}] {rec!r} raised too: {type(exc).__name__}: {exc}"
                failed.__notes__ = [*getattr(failed, "__notes__", ()), note]   # add_note (3.11+)
        if failed is not None:
            raise failed


def _part(columns, n_kernel):
    """Where a recorder's ``columns`` (positions over the kernel's columns, then the extra ones)
    are read: ``('runs', [(table, to, start, length), ...])``, runs of consecutive columns of
    one table (0 the kernel's, 1 the extra), or, when they are scattered (fewer than
    RUN_COLUMNS a run on average), ``('index', (kernel positions, kernel columns, extra
    positions, extra columns))``."""
    runs = []
    for to, column in enumerate(columns.tolist()):
        table, start = (0, column) if column < n_kernel else (1, column - n_kernel)
        if runs and runs[-1][0] == table and runs[-1][2] + runs[-1][3] == start:
            runs[-1][3] += 1
        else:
            runs.append([table, to, start, 1])
    if len(runs) <= 1 or len(runs) * RUN_COLUMNS <= len(columns):
        return "runs", [tuple(run) for run in runs]
    on_kernel = columns < n_kernel
    return "index", (np.flatnonzero(on_kernel), columns[on_kernel], np.flatnonzero(~on_kernel),
                     columns[~on_kernel] - n_kernel)


def _columns(part, out, extra, shared):
    """A recorder's columns of a chunk, from the kernel's ``out`` and the ``extra`` table, as
    :func:`_part` placed them: with ``shared`` (vtsi's own recorders) a read-only view when they
    are one run, else a copy of its own."""
    kind, where = part
    tables = (out, extra)
    if kind == "runs" and len(where) == 1:
        table, _, start, length = where[0]
        view = tables[table][:, start: start + length]
        if not shared:
            return view.copy()
        view.flags.writeable = False            # shared with the other recorders
        return view
    if kind == "runs":
        values = np.empty((len(out), sum(run[3] for run in where)))
        for table, to, start, length in where:
            values[:, to: to + length] = tables[table][:, start: start + length]
        return values
    at_kernel, kernel, at_extra, others = where
    values = np.empty((len(out), len(at_kernel) + len(at_extra)))
    values[:, at_kernel] = out[:, kernel]
    values[:, at_extra] = extra[:, others]
    return values


class StaticAnalysis:
    """Linear static analysis with load control: step ``k`` applies the patterns at pseudo-time
    ``t0 + k dλ`` (OpenSees ``integrator LoadControl dλ``) and solves ``K u = P``.

    Parameters
    ----------
    model : the :class:`~vtsi.model.Model`.
    d_lambda : dλ, the pseudo-time added by each step (finite; default 1): each pattern's load
        is scaled by ``factor × series(t0 + k dλ)`` (a ``Linear`` series then grows by ``factor
        dλ`` a step). AnalysisError if not a finite number.
    recorders : recorders (:mod:`vtsi.recorders`), each given one row per step at its
        pseudo-time; an HDF5 sink stores ``analysis='static'``, ``integrator='LoadControl'`` and
        ``dt`` = dλ. AnalysisError if one is not a recorder."""

    def __init__(self, model, d_lambda=1.0, recorders=()):
        d_lambda = as_number(d_lambda, "LoadControl", "increment", AnalysisError)
        if not np.isfinite(d_lambda):
            raise AnalysisError(f"LoadControl: increment must be finite, got {d_lambda}")
        self.model, self.d_lambda = _model("static analysis", model), d_lambda
        self.recorders = _recorders("static analysis", recorders)

    def run(self, n_steps=1):
        """Take ``n_steps`` (an integer >= 0, else AnalysisError) load steps from the committed
        state's time t0: each solves ``K u = P(t0 + k dλ)`` from scratch (linear: no iteration),
        commits u with v = a = 0 and the pseudo-time, and feeds the recorders. Returns the
        committed :class:`DomainState` (:func:`domain_state`). A singular K (a mechanism) raises
        the AnalysisError of the factorisation, before any step."""
        n_steps = _integer("static analysis", "number of steps", n_steps, 0)
        model = self.model
        asm = model.build()
        lower = factor(asm, asm.K, "stiffness matrix K")
        state = domain_state(model)
        patterns = list(model.patterns.values())
        loads = asm.load_vectors(patterns)
        feed = _RecorderFeed(asm, model, self.recorders,
                             {"analysis": "static", "integrator": "LoadControl", "dt": self.d_lambda,
                              "loads": "the load patterns"})
        try:
            for _ in range(n_steps):
                t = state.time + self.d_lambda
                rhs = np.zeros(asm.n_free)
                for lam, vec in zip(pattern_factors(patterns, np.array([t]))[0], loads):
                    rhs += lam * vec
                kd = lower.shape[1] - 1
                padded = pad(rhs, kd)
                solve_band(lower, padded)
                state.u[:] = 0.0
                state.u[asm.full_of_free] = padded[kd: kd + asm.n_free]
                state.v[:] = 0.0
                state.a[:] = 0.0
                state.time = t
                settle_dependent_dofs(asm, asm.prescribed_dofs(patterns), state, t)
                out = feed.state_row(state, asm)[None, :]
                feed.deliver(np.array([t]), out, asm)
        finally:
            feed.close()
        return state


def eigen(model, n_modes):
    """Lowest ``n_modes`` eigenpairs of ``K φ = ω² M φ`` on the free dofs.

    Returns ``omega2 (n_modes,)`` [rad²/s²] ascending and ``shapes (n_full, n_modes)``
    mass-normalised (``φᵀ M φ = 1``), zero at fixed dofs, each signed so that its first free-dof
    entry above 1e-3 of its largest is positive (whichever solver found it). Dofs without mass are
    allowed; ``n_modes='all'``: every mode of finite frequency (as many as the mass matrix' rank; a
    dense solve, up to ALL_MODES_MAX free dofs). LAPACK finds only the modes asked on small
    problems or for many modes, ARPACK (shift-invert about 0) the others (:func:`_dense_for`),
    its modes checked complete by a Sturm count (:func:`_sparse_modes`).
    """
    asm = _model("eigen", model).build()
    n = asm.n_free
    every = isinstance(n_modes, str) and n_modes == "all"
    if every and n > ALL_MODES_MAX:
        raise AnalysisError(f"eigen: every mode of {n} free dofs is a dense problem beyond {ALL_MODES_MAX} dofs; "
                            "ask for the lowest modes")
    n_modes = n if every else _integer("eigen", "number of modes", n_modes)
    if not 1 <= n_modes <= n:
        raise AnalysisError(f"eigen: number of modes must be between 1 and {n} (the free dofs), got {n_modes}")
    n_mass = _dofs_with_mass("eigen", asm)
    if every:
        omega2, vec = _dense_modes(asm)
    elif _dense_for(n, n_modes, n_mass):
        if n > ALL_MODES_MAX:
            raise AnalysisError(f"eigen: {n_modes} modes of {n} free dofs, of which {n_mass} carry mass, are a dense "
                                f"problem beyond {ALL_MODES_MAX} dofs; ask for fewer modes than the dofs with mass")
        omega2, vec = _dense_modes(asm, lowest=n_modes)
    else:
        omega2, vec = _sparse_modes(asm, n_modes, n_mass)
    return omega2, _mode_shapes(asm, vec)


def lowest_modes_until(model, k, enough):
    """``(omega2, shapes)`` of :func:`eigen` for the lowest ``k`` modes (an int >= 1), then twice
    as many, and so on, until ``enough(omega2, shapes)`` is true or every mode of finite frequency
    is computed (one per free dof with mass): what a search for modes of some kind (vertical, on a
    deck, moving the track) asks when it cannot know beforehand how many lie below them.
    ``enough`` sees every pair computed, the last included, so that it may keep what it read."""
    asm = _model("eigen", model).build()
    most = int(np.count_nonzero(asm.M.diagonal() > 0.0))     # the modes of finite frequency at most
    k = max(1, min(k, most))
    while True:
        omega2, shapes = eigen(model, "all" if k == most < asm.n_free else k)
        if enough(omega2, shapes) or k >= most:
            return omega2, shapes
        k = min(most, 2 * k)


def _dofs_with_mass(who, asm):
    """The number of free dofs with mass (a bound on the modes of finite frequency), after checking
    that K is positive definite (the factor names the mechanism, if any) and that some dof has mass."""
    factor(asm, asm.K, "stiffness matrix K")
    n_mass = int(np.count_nonzero(asm.M.diagonal() > 0.0))
    if n_mass == 0:
        raise AnalysisError(f"{who}: no dof carries mass (every mode has an infinite frequency)")
    return n_mass


def _dense_for(n, k, n_mass):
    """Whether the lowest ``k`` modes of ``n`` free dofs (``n_mass`` of them with mass) are found
    dense. LAPACK's cost hardly depends on k (it reduces the whole matrix), ARPACK's grows with k;
    measured on beams (one BLAS thread, 2 shared cores): ARPACK faster from n ≈ 200 at k = 6 and up
    to k ≈ n/7 (0.8 s against 1.0 s at n = 1800, k = 300), LAPACK faster above. So: dense up to
    DENSE_EIGEN_MAX dofs, for k > n/8 up to ALL_MODES_MAX dofs, and for k ≥ n_mass - 1 (ARPACK's
    basis of k + 2 vectors or more must fit in the rank of M)."""
    return n <= DENSE_EIGEN_MAX or (8 * k > n and n <= ALL_MODES_MAX) or k >= n_mass - 1


def _dense_modes(asm, lowest=None, omega2_max=None):
    """Eigenpairs ``(omega2 (k,) ascending [rad²/s²], vectors (n_free, k))`` of LAPACK's dense
    ``M φ = μ K φ``, μ = 1/ω² (K positive definite, checked by the caller; M may be singular, a
    massless dof giving μ = 0: μ ≤ 1e-14 of the largest is an infinite frequency): the ``lowest``
    modes (an AnalysisError if some have no mass), those with ω² ≤ ``omega2_max`` (at least the
    lowest), or every mode of finite frequency (neither given). Only the modes asked are computed
    (``driver='gvx'``), every one for the last."""
    n = asm.n_free
    M, K = asm.M.toarray(), asm.K.toarray()
    if lowest is not None:
        mu, vec = scipy.linalg.eigh(M, K, subset_by_index=[n - lowest, n - 1], driver="gvx")
    elif omega2_max is not None:
        mu, vec = scipy.linalg.eigh(M, K, subset_by_value=[(1.0 - 1e-9) / omega2_max, np.inf], driver="gvx")
        if len(mu) == 0:                   # every mode above omega2_max: the lowest
            mu, vec = scipy.linalg.eigh(M, K, subset_by_index=[n - 1, n - 1], driver="gvx")
    else:
        mu, vec = scipy.linalg.eigh(M, K)
    finite = mu > 1e-14 * mu[-1]
    if lowest is not None and not finite.all():
        raise AnalysisError(f"eigen: only {int(finite.sum())} dofs carry mass, {lowest} modes requested")
    return 1.0 / mu[finite][::-1], vec[:, finite][:, ::-1]


def _sparse_modes(asm, k, n_mass):
    """The lowest ``k`` eigenpairs ``(omega2 (k,) ascending [rad²/s²], vectors (n_free, k))`` by
    ARPACK in shift-invert mode about 0 (K positive definite, checked by the caller), its Lanczos
    basis at most ``n_mass`` vectors (the dofs with mass: a larger basis breaks down on a singular
    M; ``k < n_mass - 1``, :func:`_dense_for`), from a fixed start vector (ARPACK's own is random:
    two runs of one model differed by 1e-12). Lanczos from one vector finds the copies of a
    repeated frequency by round-off only (30 identical decks: 3 of 30 copies of their second
    frequency were missed, the next frequency standing in for them): the modes found are checked
    complete by a Sturm count (:func:`_found_every_mode`). When they are not, or ARPACK does not
    converge, it runs again with a basis twice as large (30 identical decks of 40 elements, 60
    modes: complete with 180 vectors, not with 121), and then LAPACK solves the problem (an
    AnalysisError beyond ALL_MODES_MAX dofs)."""
    start = np.random.default_rng(0).standard_normal(asm.n_free)
    K, M = asm.K.tocsc(), asm.M.tocsc()
    for basis in (max(2 * k + 1, 20), max(4 * k + 1, 40)):
        try:
            omega2, vec = spla.eigsh(K, k=k, M=M, sigma=0.0, which="LM", ncv=min(n_mass, basis), v0=start)
        except (spla.ArpackNoConvergence, spla.ArpackError):
            why = "ARPACK did not converge"
            continue
        order = np.argsort(omega2)
        omega2, vec = omega2[order], vec[:, order]
        if _found_every_mode(asm, omega2):
            return omega2, vec
        why = "ARPACK missed modes of a repeated frequency (identical decks?)"
    return _dense_instead(asm, k, why)


CLUSTER = 1e-4     # relative spread of the eigenvalues ω² that _found_every_mode takes as one repeated value


def _found_every_mode(asm, omega2):
    """Whether no eigenvalue is missing from ``omega2`` (ascending [rad²/s²]) below its highest
    cluster (the values within CLUSTER of the highest: copies of a repeated frequency there may
    go on above, unseen): a Sturm count (:func:`_modes_below`) at σ = top (1 − CLUSTER), or in
    the middle of the gap below the cluster where that lies higher, equals the values found
    below σ. σ stays far from the eigenvalues found: ARPACK's lowest ω² of a deck of 1200
    elements (3598 dofs) is known to about 3e-8 only, its error growing with K's condition, and a
    count 1e-8 below it read 2 modes where there are none."""
    top = omega2[-1]
    lower = omega2[omega2 < top * (1.0 - CLUSTER)]
    if len(lower) == 0:
        return True
    sigma = max(top * (1.0 - CLUSTER), 0.5 * (lower[-1] + top))
    return _modes_below(asm, sigma) == len(lower)


def _modes_below(asm, omega2):
    """The number of eigenvalues of ``(K, M)`` below ``omega2`` [rad²/s²] (Sturm count): by
    Sylvester's law of inertia, the negative pivots of a symmetric LDLᵀ of K − ω² M (SuperLU with
    diagonal pivots); -1 when the factor fails (ω² on an eigenvalue)."""
    try:
        lu = spla.splu((asm.K - omega2 * asm.M).tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options=dict(SymmetricMode=True))
    except RuntimeError:
        return -1
    return int(np.count_nonzero(lu.U.diagonal() < 0.0))


def _dense_instead(asm, k, why):
    """The lowest ``k`` modes by LAPACK where ARPACK failed (``why``), up to ALL_MODES_MAX free
    dofs; an AnalysisError beyond."""
    if asm.n_free > ALL_MODES_MAX:
        raise AnalysisError(f"eigen: {why} for {k} modes of {asm.n_free} free dofs, and the dense solve is beyond "
                            f"{ALL_MODES_MAX} dofs")
    return _dense_modes(asm, lowest=k)


def _mode_shapes(asm, vec):
    """Free-dof eigenvectors ``vec (n_free, k)`` as mode shapes ``(n_full, k)``: mass-normalised,
    signed so that each one's first entry above 1e-3 of its largest is positive, zero at fixed
    dofs, equalDOF / rigidLink dofs following their retained ones."""
    vec = vec / np.sqrt(np.einsum("ij,ij->j", vec, asm.M @ vec))
    first = np.argmax(np.abs(vec) > 1e-3 * np.abs(vec).max(axis=0), axis=0)
    vec = vec * np.sign(vec[first, np.arange(vec.shape[1])])
    shapes = np.zeros((asm.n_full, vec.shape[1]))
    shapes[asm.full_of_free] = vec
    if asm.constrained_rows is not None:
        shapes[asm.constrained_dofs] = asm.constrained_rows @ vec
    return shapes


def modes_up_to(model, f_max):
    """Every mode of ``model`` up to ``f_max`` [Hz] (at least one): ``(frequencies (n,) [Hz],
    shapes (n_full, n))`` as :func:`eigen`'s (none of infinite frequency: fewer than the free dofs
    under lumped mass); ``f_max`` > 0 and finite. Small problems: one dense solve of the modes up
    to ``f_max``; larger ones: ARPACK for 8 modes, then for the count up to ``f_max`` extrapolated
    linearly in frequency from the last solve, 50 % over (a short count costs one more solve), until
    a mode lies above ``f_max`` (dense once the count is beyond ARPACK's worth, :func:`_dense_for`)."""
    f_max = as_number(f_max, "modes_up_to", "f_max [Hz]", AnalysisError)
    if not (np.isfinite(f_max) and f_max > 0.0):
        raise AnalysisError(f"modes_up_to: f_max must be > 0 and finite [Hz], got {f_max}")
    asm = _model("modes_up_to", model).build()
    n_mass = _dofs_with_mass("modes_up_to", asm)
    omega2_max = (2 * np.pi * f_max) ** 2
    k = min(n_mass, 8)
    while not _dense_for(asm.n_free, k, n_mass):
        omega2, vec = _sparse_modes(asm, k, n_mass)
        if omega2[-1] > omega2_max:
            break
        k = min(n_mass, int(np.ceil(1.5 * k * np.sqrt(omega2_max / omega2[-1]))) + 2)
    else:
        omega2, vec = _dense_modes(asm, omega2_max=omega2_max)
    f = np.sqrt(omega2) / (2 * np.pi)
    keep = max(1, int(np.sum(f <= f_max)))
    return f[:keep], _mode_shapes(asm, vec[:, :keep])




def load_factor_table(patterns, starts, dt, load_points, cache=None):
    """``(n, n_stages, n_patterns)`` stage load factors of the steps starting at ``starts`` (n,)
    [s]: stage s takes Σ weight × factor(t + θ Δt) over its ``load_points[s]`` ((θ, weight)
    pairs, :mod:`vtsi.integrators.base`); ``cache`` as for :func:`pattern_factors`. The one
    builder of every time loop's load table."""
    if len(load_points) == 1 and load_points[0] == [(1.0, 1.0)]:      # one stage, loads at the step's end
        table = pattern_factors(patterns, starts + dt, cache)[:, None, :]
    else:
        table = np.zeros((len(starts), len(load_points), len(patterns)))
        for s, points in enumerate(load_points):
            for theta, weight in points:
                if weight != 0.0:
                    table[:, s, :] += weight * pattern_factors(patterns, starts + theta * dt, cache)
    if not np.isfinite(table.sum()) and not np.isfinite(table).all():   # a finite sum: every entry finite
        raise AnalysisError("transient analysis: a load pattern gives NaN or inf load factors")
    return table


class TransientAnalysis:
    """Linear transient analysis with any registered integrator and a constant step.

    Parameters
    ----------
    model : Model
    integrator : name, class or instance (``'Newmark'``, ``HHT(0.9)``, ``'Bathe'`` ...).
    dt : time step [s], > 0.
    recorders : recorders fed every chunk.
    divergence_limit : [m] (> 0; default 1e8): a step whose largest |u| over the integrated
        dofs exceeds this (rotations [rad] compared with the same number; with ``bridge`` the
        modal coordinates q [m·√kg]), or is NaN or inf, stops the run with a
        :class:`~vtsi.errors.DivergenceError` naming the step and the time; ``inf``: NaN and inf
        only.
    chunk_steps : steps per compiled call (recorders receive chunks of this size).
    bridge : None (the FE model) or a :class:`~vtsi.modal_bridge.ModalBridge` of the model: the
        steps then integrate its modal coordinates (the recorders read Φ q).

    The model is stepped as a bridge subdomain (:mod:`vtsi.subdomain`). With the FE model only
    the dofs that can move are integrated (:func:`moving_dofs`, listed in ``active`` after a
    run): a component of the model with no load and no state stays exactly at rest, e.g. the
    axial dofs of a straight beam under vertical loads; its recorders read 0.

    The first step starts from the model's committed state: at rest, a₀ = 0, not the equilibrium
    acceleration M⁻¹(P(t₀) − C v₀ − K u₀) (OpenSees's convention too, pinned by the OpenSees
    cross-checks). A load already present at t₀ (a ``Constant`` series) then makes the response
    lag by about half a step. To start in static equilibrium, run ``StaticAnalysis(model).run(1)``
    first (then u₀ = K⁻¹P and a₀ = 0 is exact; it advances the time by 1: set
    ``domain_state(model).time`` back if the series depend on time); for a sudden load, start its
    series at 0, or set ``domain_state(model).a`` (full dofs) before :meth:`run`
    (docs/commands.md, "The initial acceleration").
    """

    def __init__(self, model, integrator="Newmark", dt=None, recorders=(), divergence_limit=1e8,
                 chunk_steps=2000, bridge=None):
        self.model = _model("transient analysis", model)
        self.integrator = make_integrator(integrator)
        self.recorders = _recorders("transient analysis", recorders)
        self.divergence_limit = as_positive(divergence_limit, "transient analysis", "divergence_limit (inf: no bound)",
                                            AnalysisError, finite=False)
        self.chunk_steps = _integer("transient analysis", "chunk_steps", chunk_steps, 1)
        if bridge is not None and not hasattr(bridge, "stages"):
            raise AnalysisError(f"transient analysis: bridge must be None or a ModalBridge, got {type(bridge).__name__}")
        self.bridge = bridge
        self.dt = None
        self.stages = None
        self._loaded_for = None
        self._kept_plan = None
        self._path_tables = {}         # the stacked Path values (pattern_factors' cache), across plans
        self.last_step_start = None    # start time [s] of the last step run
        if dt is not None:
            self.set_dt(dt)

    def set_dt(self, dt):
        """Set the time step ``dt`` [s]: a finite number > 0 (a bool is refused, not read as
        1.0 s). A new value drops the prepared stages (the integrator's factored effective
        matrices, FE or modal: the next run prepares them for the new dt) and, dt being part of
        its key, the kept plan of a run; the same value changes nothing.

        Raises AnalysisError naming the value if ``dt`` is not such a number."""
        dt = as_positive(dt, "transient analysis", "dt", AnalysisError)
        if dt != self.dt:
            self.dt, self.stages = dt, None

    def _prepare(self, loaded=None):
        """The bridge stages (:mod:`vtsi.subdomain`): factored once per model version, dt and set
        of moving dofs (see :func:`moving_dofs`; ``loaded``: the loaded free dofs, if known)."""
        asm = self.model.build()
        if self.bridge is not None:
            self.bridge.check_model(self.model)
            if self.stages is None:
                self.stages = self.bridge.stages(self.integrator, self.dt)
            return asm
        stages = self.stages
        if stages is not None and stages.assembly is asm and loaded is self._loaded_for:
            state = domain_state(self.model)       # the same stages unless a dof at rest has moved
            if not any_nonzero(state.u, state.v, state.a, self._rest_full):
                return asm
        active = moving_dofs(asm, self.model, loaded=loaded)
        if stages is None or stages.assembly is not asm or not same_entries(active, stages.active):
            self.stages = FEStages(asm, active, self.integrator, self.dt)
            self._rest_full = self.stages.rest_full
        self._loaded_for = loaded
        return asm

    @property
    def active(self):
        """The free dofs the FE bridge integrates (known once a run has prepared it)."""
        if self.stages is None:
            raise AnalysisError("transient analysis: active (the dofs that can move) is known once a run has "
                                "started; call run() first")
        return self.stages.active

    accumulated_times = False
    """Whether :meth:`step_times` adds the steps up (t += Δt, OpenSees's bookkeeping): then the
    times of steps from any time of a block of them are the block's own, and the block of the
    coming steps' load factors is kept across a change of the patterns that leaves their series,
    factors and freezing as they were (:meth:`_RunPlan.take_patterns`)."""

    def step_times(self, t0, n):
        """``(n + 1,)`` times [s] ``t_0 .. t_n`` of the next ``n`` steps from ``t0`` (the load table
        is evaluated from them); a subclass may keep another time bookkeeping."""
        return t0 + self.dt * np.arange(n + 1, dtype=float)

    def _plan(self):
        """What a run needs, kept from run to run while the assembly, dt and the bridge stages
        stay the same (the recorder feed while the recorders do); a change of the patterns
        (``Model.load_version``) only gives it their loads (:meth:`_RunPlan.take_patterns`)."""
        asm = self.model.build()
        key = (asm, self.model.load_version, self.dt)
        plan = self._kept_plan
        if plan is None or plan.key != key or plan.bridge is not self.stages:
            patterns = list(self.model.patterns.values())
            loads = _pattern_loads(asm, patterns)
            asm = self._prepare(loads[1])
            if plan is not None and plan.key[0] is asm and plan.key[2] == self.dt and plan.bridge is self.stages:
                plan.take_patterns(key, patterns, loads)
            else:
                plan = self._kept_plan = _RunPlan(self, key, asm, patterns, loads)
        recorders = tuple(self.recorders)
        if plan.recorders != recorders:
            plan.recorders, plan.feed = recorders, None
        return plan

    def run(self, n_steps):
        """Advance ``n_steps`` steps from the model's committed state; returns the state.

        Repeated short runs (a script's ``analyze(1, dt)`` loop) cost one compiled step and a
        constant: the plan of a run (stages, loads, recorder columns) and the load factors of the
        coming steps are kept while the model, dt and the recorders stay the same; a change of
        the patterns rebuilds their loads (:meth:`_RunPlan.take_patterns`)."""
        if self.dt is None:
            raise AnalysisError("transient analysis: no time step set")
        if not (type(n_steps) is int and n_steps >= 0):
            n_steps = _integer("transient analysis", "number of steps", n_steps, 0)
        plan = self._plan()
        state = domain_state(self.model)
        feed = plan.start_feed()
        try:
            done = 0
            while done < n_steps:
                chunk = min(self.chunk_steps, n_steps - done)
                times, table = plan.load_rows(state.time, chunk)
                if not plan.run_rows(state, times, table, plan.span, done + 1,
                                     times[chunk - 1] + plan.load_point * self.dt):
                    self._prepare(plan.loads[1])   # a dof at rest has moved (the state was set): integrate it too
                    plan = self._plan().adopt_feed(feed)
                    continue
                self.last_step_start = float(times[chunk - 1])
                done += chunk
        finally:
            feed.close()
        return state


class _RunPlan:
    """One :class:`TransientAnalysis`'s prepared run: the bridge stages and its loads, the load
    points of the integrator's stages, the recorder columns, a state bank and scratch vectors,
    and a block of the load factors of the coming steps (:meth:`load_rows`)."""

    def __init__(self, analysis, key, asm, patterns, loads):
        self.analysis, self.asm = analysis, asm
        self.recorders = tuple(analysis.recorders)
        self.bridge = bridge = analysis.stages
        self.feed = self.prescribed = self.factors = None
        self.take_patterns(key, patterns, loads)
        self.ahead = BLOCK_STEPS   # a new plan's first block looks ahead: a run from it usually goes on
        self.load_points = bridge.load_points
        self.info = {"analysis": "transient", "integrator": repr(analysis.integrator), "dt": analysis.dt,
                     "loads": "the load patterns", "bridge": None if analysis.bridge is None else
                     "modal, truncated" if analysis.bridge.truncated else "modal, every mode"}
        self.bank = np.zeros((analysis.integrator.n_slots, bridge.n + 2 * bridge.kd))   # run_from_state loads the state
        self.work = np.zeros((3, self.bank.shape[1]))
        self.fe = isinstance(bridge, FEStages)
        if self.fe:
            self.coords_full = asm.full_of_free[bridge.active]
            self.rest_full = analysis._rest_full
        self.no_columns = np.zeros((analysis.chunk_steps, 0))
        last = self.load_points[-1]      # where the last stage applies its loads, as a fraction of the step
        self.load_point = last[0][0] if len(last) == 1 else 1.0
        self.span = np.array([0, analysis.integrator.n_stages, 0], dtype=np.int64)   # whole steps

    def take_patterns(self, key, patterns, loads):
        """Take the load patterns of ``key`` (the analysis' assembly, load version and dt): their
        loads (``loads``, CSR over the free dofs) on the bridge and their prescribed
        displacements. With :attr:`TransientAnalysis.accumulated_times` the block of load factors
        stays while each pattern has the series, factor and freezing (``loadConst``) of the one it
        replaces (OpenSees's moving load: a new pattern of the same series at every step);
        otherwise the next one is of only the steps a run asks for, as a script that changes its
        patterns at every step uses one. The stages, bank, work arrays, info and recorder feed
        stay (the feed is built again when the patterns prescribe displacements, which it
        records)."""
        self.key, self.patterns, self.loads = key, patterns, loads
        self.mapped = self.bridge.loads(*loads)
        prescribed = self.asm.prescribed_dofs(patterns)
        if prescribed or self.prescribed:
            self.feed = None
        self.prescribed = prescribed
        self.settles = bool(prescribed) or self.asm.constrained_rows is not None     # dofs that follow others
        factors = tuple([(id(p.series), getattr(p.series, "factor", None), p.factor, p.constant_time)
                         for p in patterns])
        if factors != self.factors or not self.analysis.accumulated_times:     # a new block
            self.factors = factors
            self.block = None    # (times (B + 1,), table (B, n_stages, n_patterns), position)
            self.ahead = 0       # steps the next block evaluates at least (BLOCK_STEPS after it)
        if self.feed is not None:
            self._kernel_args()

    def start_feed(self):
        """The recorder feed of a run: built (and its recorders started) once, restarted after."""
        if self.feed is None:
            a = self.analysis
            feed = _RecorderFeed(self.asm, a.model, self.recorders, self.info)
            feed.load_lag = (1.0 - self.load_point) * a.dt
            self.adopt_feed(feed)
        else:
            self.feed.start(self.info)
        return self.feed

    def adopt_feed(self, feed):
        """Take over the started ``feed`` of a run that this plan continues; returns self."""
        self.feed = feed
        self.rec_slot, self.rec_index = self.bridge.record_plan(feed.rec_slot, feed.rec_index)
        self._kernel_args()
        return self

    def _kernel_args(self):
        """run_from_state's arguments around (u, v, a), the load table and the output (FE bridge)."""
        if self.fe:
            b = self.bridge
            self.kernel_args = ((self.coords_full, self.rest_full, self.bank, b.du, b.dv, b.fac, b.ops, b.weights),
                                self.mapped + (self.rec_slot, self.rec_index),
                                (self.analysis.divergence_limit, self.work, b.band))

    def load_rows(self, t0, n):
        """``(times (n + 1,), table (n, n_stages, n_patterns))`` of the ``n`` steps from ``t0``,
        from the kept block when the run continues where the last one ended."""
        block = self.block
        if block is not None:
            times, table, pos = block
            if pos + n < len(times) and times[pos] == t0:
                self.block = (times, table, pos + n)
                return times[pos: pos + n + 1], table[pos: pos + n]
        m = max(n, self.ahead)
        times = self.analysis.step_times(t0, m)
        table = load_factor_table(self.patterns, times[:-1], self.analysis.dt, self.load_points,
                                  self.analysis._path_tables)
        self.block, self.ahead = (times, table, n), BLOCK_STEPS
        return times[: n + 1], table[:n]

    def advance(self, state, table, out, span):
        """Run the steps of ``table`` (``span`` as :func:`~vtsi.timeloop.run_linear_steps`) from
        ``state`` (written back unless they diverge); returns -1, the index of the diverging
        row, or -2 if a dof at rest has moved."""
        if self.fe:
            head, loads, tail = self.kernel_args
            return run_from_state(state.u, state.v, state.a, *head, table, *loads, out, *tail, span)
        a, b = self.analysis, self.bridge
        ptr, dof, val = self.mapped
        bank = b.bank(state, self.asm.full_of_free, a.integrator.n_slots)
        bad = run_linear_steps(bank, b.du, b.dv, b.fac, b.ops, b.weights, table, ptr, dof, val, self.rec_slot,
                               self.rec_index, out, a.divergence_limit, self.work, b.band, span)
        if bad < 0:
            b.commit(state, bank, self.asm.full_of_free, state.time)
        return bad

    def run_rows(self, state, times, table, span, first_step, settle_time):
        """Run ``table`` from ``state`` (:meth:`advance`), its rows recorded at ``times[1:]`` [s]
        (a row per step, or per stage: ``span``): the feed gets every row computed, also when
        the run diverges; then the rows before the diverging one are run again, so that
        ``state`` is that of the last row recorded, and a DivergenceError names the row
        (counted from ``first_step``) and its time. After a good run ``state.time`` is
        ``times[-1]``; the dependent dofs follow their loads at ``settle_time`` [s] (at the
        same distance before the last row's time after a divergence). Returns False, having
        done nothing, when a dof at rest has moved (the caller integrates it too)."""
        n = len(times) - 1
        feed = self.feed
        out = np.zeros((n, len(self.rec_slot))) if feed.recorders else self.no_columns[:n]
        start_bank = self.bank.copy() if span[0] > 0 else None     # a resumed step's start: overwritten by the run
        bad = self.advance(state, table, out, span)
        if bad == -2:
            return False
        good = n if bad < 0 else bad
        if bad >= 0 and start_bank is not None:
            self.bank[:] = start_bank
        if bad > 0:
            self.advance(state, *self._rows_before(table, out, span, bad))   # deterministic: the same rows again
        if good > 0:
            state.time = float(times[good])
            if self.settles:
                settle_dependent_dofs(self.asm, self.prescribed, state, times[good] - (times[n] - settle_time))
        if feed.recorders:              # after the state: a recorder that raises leaves it at its last row
            feed.deliver(times[1: good + 1], self.bridge.recorded(out[:good]), self.asm)
        if bad >= 0:
            limit = self.analysis.divergence_limit
            size = "|u|" if self.fe else "a modal coordinate |q| [m·√kg]"      # what the kernel bounds
            what = f"{size} > {limit:g} or NaN" if np.isfinite(limit) else "NaN or inf"
            step = first_step + bad
            raise DivergenceError(f"transient analysis diverged at step {step} of this run, "
                                  f"t = {times[bad + 1]:.6g} s ({what}) "
                                  f"with {self.info['integrator']}, dt = {self.info['dt']:g} s", step, times[bad + 1])
        return True

    def _rows_before(self, table, out, span, rows):
        """``(table, out, span)`` of the first ``rows`` rows of a run of ``table`` with ``span``
        (:func:`~vtsi.timeloop.run_linear_steps`): whole steps, or stages when a row is recorded
        after every stage."""
        if span[2] == 0:
            return table[:rows], out[:rows], np.array([span[0], table.shape[1], 0], dtype=np.int64)
        last = int(span[0]) + rows - 1                       # the last row's stage, counted from the first step's
        steps, stages = divmod(last, table.shape[1])
        return table[: steps + 1], out[:rows], np.array([span[0], stages + 1, 1], dtype=np.int64)
