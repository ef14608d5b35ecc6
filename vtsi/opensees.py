"""OpenSees-style commands: ``import vtsi.opensees as ops`` runs OpenSeesPy bridge scripts.

The module offers OpenSeesPy's command names and argument orders (``model``, ``node``, ``fix``,
``mass``, ``geomTransf``, ``element``, ``uniaxialMaterial``, ``timeSeries``, ``pattern``,
``load``, ``rayleigh``, ``constraints``, ``numberer``, ``system``, ``test``, ``algorithm``,
``integrator``, ``analysis``, ``analyze``, ``eigen``, ``nodeDisp`` ..., ``recorder``, ``wipe``
and the queries around them, see :data:`COMMANDS` and ``docs/commands.md``) as a thin layer
over the object API (:class:`vtsi.Model`, :class:`vtsi.StaticAnalysis`,
:class:`vtsi.TransientAnalysis`, :func:`vtsi.eigen`, :mod:`vtsi.recorders`).

The commands act on a :class:`Session`. The module functions delegate to the module attribute
``session`` at every call, so ``ops.session = ops.Session()`` (or :func:`set_session`) replaces
the default one; a session's methods are the same commands (``s = Session(); s.node(1, 0, 0)``).
The session is a state machine like OpenSees's interpreter: the analysis is assembled at
``analyze`` from the last ``constraints``/``numberer``/``system``/``integrator``/``analysis``
settings, a change to the model between two ``analyze`` calls is taken into account, and every
analysis continues from the model's committed state (:func:`vtsi.domain_state`), so that "static
gravity analysis, ``loadConst('-time', 0.0)``, transient analysis" works as in OpenSees.

Where vtsi differs from OpenSees (errors are exceptions, every option is either honoured or
refused by name, ``system``/``numberer`` choices map to vtsi's banded Cholesky solver, ...), see
``docs/commands.md``. The conventions reproduced here were measured on OpenSeesPy 3.7.1
(``docs/opensees_conventions.md``).
"""
import atexit
import logging
import math
import os
import weakref

import numpy as np

from vtsi.analysis import StaticAnalysis, TransientAnalysis, _RecorderFeed, domain_state, factor
from vtsi.analysis import eigen as _eigen
from vtsi.banded import solve_band
from vtsi.errors import AnalysisError, CommandError, DivergenceError, ModelError
from vtsi.integrators import HHT, Bathe, CentralDifference, Newmark
from vtsi.modal_bridge import ModalBridge
from vtsi.model import Model
from vtsi.timeseries import Constant, Linear, Pulse, Rectangular, TimeSeries, Triangle, Trig, interpolate_rows
from vtsi.train_commands import TRAIN_COMMANDS, TrainCommands

log = logging.getLogger(__name__)

COMMANDS = (
    "model", "node", "fix", "mass", "geomTransf", "element", "uniaxialMaterial", "timeSeries", "pattern",
    "load", "rayleigh", "constraints", "numberer", "system", "test", "algorithm", "integrator", "analysis",
    "analyze", "eigen", "modalDamping", "nodeDisp", "nodeVel", "nodeAccel", "nodeReaction", "reactions", "eleForce",
    "eleResponse", "recorder", "wipe", "wipeAnalysis", "getTime", "setTime", "loadConst", "nodeCoord",
    "nodeEigenvector", "nodeResponse", "remove", "getNodeTags", "getEleTags", "getLoadFactor", "nodeMass",
    "nodeBounds",
) + TRAIN_COMMANDS
"""Every command this layer knows; anything else raises :class:`UnknownCommand`."""

ELEMENT_TYPES = ("elasticBeamColumn", "truss", "zeroLength")
MATERIAL_TYPES = ("Elastic", "Viscous")
SERIES_TYPES = ("Constant", "Linear", "Path", "Trig", "Triangle", "Rectangular", "Pulse")
CONSTRAINT_HANDLERS = ("Plain", "Transformation")
NUMBERERS = ("Plain", "RCM", "AMD")
SYSTEMS = ("BandSPD", "BandGeneral", "ProfileSPD", "SparseGeneral", "UmfPack", "FullGeneral", "SparseSYM")
TESTS = ("NormUnbalance", "NormDispIncr", "EnergyIncr", "RelativeNormUnbalance", "RelativeNormDispIncr",
         "RelativeTotalNormDispIncr", "RelativeEnergyIncr", "FixedNumIterations")
ALGORITHMS = {   # name -> accepted flags (a linear model is solved exactly in one pass by all of them)
    "Linear": ("-initial", "-secant", "-factorOnce"),
    "Newton": ("-initial", "-initialThenCurrent", "-secant"),
    "ModifiedNewton": ("-initial", "-secant", "-factorOnce"),
    "KrylovNewton": (),
    "NewtonLineSearch": (),
    "BFGS": (),
    "Broyden": (),
}
INTEGRATORS = ("LoadControl", "Newmark", "HHT", "CentralDifference", "TRBDF2", "Bathe")
ANALYSES = ("Static", "Transient")
EIGEN_SOLVERS = ("-genBandArpack", "-fullGenLapack")
NODE_RESPONSES = ("disp", "vel", "accel", "reaction", "reactionIncInertia")
RECORDER_TYPES = ("Node", "EnvelopeNode", "Element", "EnvelopeElement", "Contact", "Train")
ELEMENT_RESPONSE_ALIASES = {
    "forces": "force", "globalForces": "globalForce", "localForces": "localForce",
    "basicForces": "basicForce", "deformations": "deformation", "basicDeformations": "basicDeformation",
    "axialForces": "axialForce",
}
NODE_RESPONSE_IDS = {1: "disp", 2: "vel", 3: "accel", 6: "reaction", 7: "unbalance"}


class UnknownCommand(CommandError, AttributeError):
    """A command (or module attribute) that this layer does not offer."""


# ---------------------------------------------------------------------------------------------
# argument parsing
# ---------------------------------------------------------------------------------------------
def _is_int(x):
    return isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_))


def _is_number(x):
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def _flatten(args):
    """Arguments with lists, tuples and arrays spread out (Tcl lists arrive as Python lists)."""
    out = []
    for a in args:
        if isinstance(a, (list, tuple)):
            out.extend(_flatten(a))
        elif isinstance(a, np.ndarray):
            out.extend(_flatten(a.ravel().tolist()))
        else:
            out.append(a)
    return out


class _Args:
    """A cursor over one command's arguments; every error names the command and the argument."""

    def __init__(self, command, args):
        self.command = command
        self.items = _flatten(args)
        self.pos = 0

    def more(self):
        return self.pos < len(self.items)

    def peek(self):
        return self.items[self.pos] if self.more() else None

    def next_is_number(self):
        return self.more() and _is_number(self.peek())

    def take(self, what):
        if not self.more():
            raise CommandError(f"{self.command}: missing {what}")
        x = self.items[self.pos]
        self.pos += 1
        return x

    def int(self, what):
        x = self.take(what)
        if not _is_int(x):
            raise CommandError(f"{self.command}: {what} must be an integer, got {x!r}")
        return int(x)

    def float(self, what):
        x = self.take(what)
        if not _is_number(x):
            raise CommandError(f"{self.command}: {what} must be a number, got {x!r}")
        x = float(x)
        if not math.isfinite(x):
            raise CommandError(f"{self.command}: {what} must be finite, got {x}")
        return x

    def word(self, what, choices=None):
        x = self.take(what)
        if not isinstance(x, str):
            raise CommandError(f"{self.command}: {what} must be a name, got {x!r}")
        if choices is not None and x not in choices:
            raise CommandError(f"{self.command}: {what} {x!r} is not supported; supported: {', '.join(choices)}")
        return x

    def floats(self, what):
        out = []
        while self.next_is_number():
            out.append(self.float(what))
        return out

    def ints(self, what):
        out = []
        while self.next_is_number():
            out.append(self.int(what))
        return out

    def option(self, valid):
        """The next option name (a str); an unknown one raises naming it and the valid ones."""
        x = self.take("option")
        if not isinstance(x, str):
            raise CommandError(f"{self.command}: unexpected argument {x!r} (expected an option: {', '.join(valid)})")
        if x not in valid:
            raise CommandError(f"{self.command}: option {x!r} is not supported; supported: {', '.join(valid)}")
        return x

    def done(self):
        if self.more():
            raise CommandError(f"{self.command}: unexpected argument {self.peek()!r}")


def _dof_value(values, dof, what):
    """``values`` (list) or its 1-based component ``dof`` (-1: all), as OpenSeesPy returns them."""
    if dof == -1:
        return [float(v) for v in values]
    if not _is_int(dof) or not 1 <= dof <= len(values):
        raise CommandError(f"{what}: dof must be -1 (all) or 1..{len(values)}, got {dof!r}")
    return float(values[int(dof) - 1])


# ---------------------------------------------------------------------------------------------
# time series with OpenSees's exact rules
# ---------------------------------------------------------------------------------------------
class PathSeries(TimeSeries):
    """OpenSees ``timeSeries Path -dt``: values at ``start_time + k dt``, exactly as
    ``PathSeries::getFactor``: ``x = (t - t0)/dt``, ``i = floor(x)``; zero before ``t0``;
    ``factor (v[i] + (v[i+1] - v[i]) (x - i))`` while ``i + 1 < n``; beyond (the last sample
    itself included), zero or, with ``use_last``, ``factor v[n-1]``. ``prepend_zero`` inserts a
    zero value at ``t0`` (the given values move one ``dt`` later)."""

    def __init__(self, tag, values, dt, factor=1.0, use_last=False, prepend_zero=False, start_time=0.0):
        self.tag = tag
        values = np.asarray(values, dtype=float).ravel()
        if prepend_zero:
            values = np.r_[0.0, values]
        self.values, self.dt, self.factor = values, float(dt), float(factor)
        self.use_last, self.start_time = bool(use_last), float(start_time)

    def stack_key(self):
        return ("PathSeries", self.dt, self.start_time, self.values.size, self.use_last)

    @classmethod
    def stack_factors(cls, key, table, times):
        """Unscaled factors of stacked series of one ``-dt`` grid, with ``getFactor``'s rules."""
        _, dt, start, size, use_last = key
        x = (times - start) / dt
        i = np.floor(x)
        started = times >= start
        inside = started & (i + 1 < size)
        k = i[inside].astype(np.int64)
        y = np.zeros((len(times), table.shape[1]))
        y[inside] = interpolate_rows(table, k, x[inside] - k)
        if use_last:
            y[started & ~inside] = table[-1]
        return y

    def at(self, t):
        """The factor at one time ``t`` (float)."""
        if t < self.start_time:
            return 0.0
        x = (t - self.start_time) / self.dt
        i = math.floor(x)
        if i + 1 >= self.values.size:
            return self.factor * float(self.values[-1]) if self.use_last else 0.0
        v1, v2 = float(self.values[i]), float(self.values[i + 1])
        return self.factor * (v1 + (v2 - v1) * (x - i))

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.size <= 4:
            return np.array([self.at(x) for x in t.ravel().tolist()]).reshape(t.shape)
        x = (t - self.start_time) / self.dt
        i = np.floor(x)
        n = self.values.size
        out = np.zeros(t.shape)
        started = t >= self.start_time
        inside = started & (i + 1 < n)
        k = i[inside].astype(np.int64)
        v1, v2 = self.values[k], self.values[k + 1]
        out[inside] = self.factor * (v1 + (v2 - v1) * (x[inside] - k))
        if self.use_last:
            out[started & ~inside] = self.factor * self.values[-1]
        return out


class PathTimeSeries(TimeSeries):
    """OpenSees ``timeSeries Path -time``: linear interpolation through ``(time, values)``;
    zero before the first time, ``factor v[-1]`` at the last time, zero after it or, with
    ``use_last``, ``factor v[-1]`` (``PathTimeSeries::getFactor``)."""

    def __init__(self, tag, time, values, factor=1.0, use_last=False):
        self.tag = tag
        self.time = np.asarray(time, dtype=float).ravel()
        self.values = np.asarray(values, dtype=float).ravel()
        self.factor, self.use_last = float(factor), bool(use_last)

    def at(self, t):
        """The factor at one time ``t`` (float)."""
        time = self.time
        if t < time[0]:
            return 0.0
        if t >= time[-1]:
            return self.factor * float(self.values[-1]) if (t == time[-1] or self.use_last) else 0.0
        k = int(np.searchsorted(time, t, side="right")) - 1
        t1, t2 = float(time[k]), float(time[k + 1])
        v1, v2 = float(self.values[k]), float(self.values[k + 1])
        return self.factor * (v1 + (v2 - v1) * (t - t1) / (t2 - t1))

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.size <= 4:
            return np.array([self.at(x) for x in t.ravel().tolist()]).reshape(t.shape)
        time, values = self.time, self.values
        n = time.size
        k = np.searchsorted(time, t, side="right") - 1
        out = np.zeros(t.shape)
        interior = (k >= 0) & (k < n - 1)
        kk = k[interior]
        t1, t2 = time[kk], time[np.minimum(kk + 1, n - 1)]
        v1, v2 = values[kk], values[np.minimum(kk + 1, n - 1)]
        out[interior] = self.factor * (v1 + (v2 - v1) * (t[interior] - t1) / (t2 - t1))
        last = k == n - 1
        out[last & (t == time[-1])] = self.factor * values[-1]
        if self.use_last:
            out[last & (t > time[-1])] = self.factor * values[-1]
        return out


def _read_numbers(command, path):
    try:
        with open(path) as fh:
            words = fh.read().split()
    except OSError as exc:
        raise CommandError(f"{command}: cannot read {path}: {exc.strerror}") from None
    try:
        return np.array([float(w) for w in words])
    except ValueError as exc:
        raise CommandError(f"{command}: {path} holds a word that is not a number ({exc})") from None


def _check_path_values(command, values, time=None):
    if values.size == 0:
        raise CommandError(f"{command}: no values given")
    if not np.all(np.isfinite(values)):
        bad = int(np.flatnonzero(~np.isfinite(values))[0])
        raise CommandError(f"{command}: value {bad} is {values[bad]} (NaN or inf)")
    if time is not None:
        if time.size != values.size:
            raise CommandError(f"{command}: {time.size} times (-time/-fileTime) but {values.size} values "
                               "(-values/-filePath); give one time per value")
        if not np.all(np.isfinite(time)):
            raise CommandError(f"{command}: the times contain NaN or inf")
        steps = np.diff(time)
        if np.any(steps <= 0.0):
            bad = int(np.flatnonzero(steps <= 0.0)[0])
            raise CommandError(f"{command}: times must increase strictly; time[{bad + 1}] = {time[bad + 1]:g} "
                               f"follows time[{bad}] = {time[bad]:g}")


# ---------------------------------------------------------------------------------------------
# analyses with OpenSees's time bookkeeping
# ---------------------------------------------------------------------------------------------
class _CommandTransient(TransientAnalysis):
    """A :class:`~vtsi.TransientAnalysis` whose step times are accumulated as OpenSees does
    (``t += Δt`` each step; HHT: ``t += αΔt`` then ``t += (1-α)Δt``), so that a Path series
    evaluated at its last sample gives OpenSees's value to the last bit."""

    def __init__(self, model, integrator, bridge=None):
        super().__init__(model, integrator, bridge=bridge)
        self._times = None

    def _increments(self):
        if isinstance(self.integrator, HHT):
            a = self.integrator.alpha
            return (a * self.dt, (1.0 - a) * self.dt)
        return (self.dt,)

    def step_times(self, t0, n):
        """``(n + 1,)`` times ``t_0 .. t_n`` accumulated in floating point like OpenSees (the last
        call's are kept: a run asks for them twice)."""
        inc = self._increments()
        if self._times is not None and self._times[0] == (t0, n, inc):
            return self._times[1]
        seq = np.empty(n * len(inc) + 1)
        seq[0] = t0
        seq[1:] = np.tile(inc, n)
        times = np.cumsum(seq)[:: len(inc)]
        self._times = ((t0, n, inc), times)
        return times

    def step_starts(self, t0, n):
        return self.step_times(t0, n)[:-1]

    def chunk_end(self, t0, n):
        return self.step_times(t0, n)[-1]


class _OpenSeesTRBDF2:
    """OpenSees's ``integrator TRBDF2``: every ``analyze`` step is one sub-step of Bathe's scheme
    (γ = ½) of size Δt, alternating trapezoidal and three-point backward (BDF2) sub-steps; a
    trapezoidal sub-step comes first and whenever Δt changes (``TRBDF2::newStep``). Loads at
    ``t_{n+1}``. (vtsi's own ``Bathe``/``TRBDF2`` integrators take both sub-steps in one step.)

    Trapezoidal:  ``(K + 2/Δt C + 4/Δt² M) u₁ = P + M (4u/Δt² + 4v/Δt + a) + C (2u/Δt + v)``,
    ``v₁ = 2(u₁ - u)/Δt - v``, ``a₁ = 4(u₁ - u)/Δt² - 4v/Δt - a``.
    BDF2: ``(K + 1.5/Δt C + 2.25/Δt² M) u₁ = P - M [3(u₋ - 4u)/(4Δt²) + (v₋ - 4v)/(2Δt)] - C (u₋ - 4u)/(2Δt)``,
    ``v₁ = (3u₁ - 4u + u₋)/(2Δt)``, ``a₁ = (3v₁ - 4v + v₋)/(2Δt)``; ``u₋, v₋`` at the start of the
    previous sub-step.
    """

    name = "TRBDF2"

    def __init__(self):
        self.dt = 0.0
        self.step = 0          # kind of the last sub-step: 0 trapezoidal, 1 BDF2
        self.previous = None   # full-dof (u, v) at the start of the last sub-step
        self._factors = {}

    def run(self, model, n_steps, dt, recorders, info):
        asm = model.build()
        state = domain_state(model)
        if self.previous is not None and self.previous[0].shape != state.u.shape:
            self.previous = None
        patterns = list(model.patterns.values())
        loads = [asm.load_vector(p) for p in patterns]
        free = asm.full_of_free
        C, M = asm.C, asm.M
        feed = _RecorderFeed(asm, model, recorders, info)
        chunk_t, chunk_rows = [], []
        try:
            for step in range(n_steps):
                kind = 0 if (dt != self.dt or self.step == 1) else 1
                self.dt = dt
                if kind == 1 and self.previous is None:
                    kind = 0
                u, v, a = state.u[free], state.v[free], state.a[free]
                t = state.time + dt
                rhs = np.zeros(asm.n_free)
                for p, vec in zip(patterns, loads):
                    rhs += p.factors(np.array([t]))[0] * vec
                if kind == 0:
                    c2, c3 = 2.0 / dt, 4.0 / (dt * dt)
                    rhs += M @ (c3 * u + (4.0 / dt) * v + a) + C @ (c2 * u + v)
                else:
                    um, vm = self.previous[0][free], self.previous[1][free]
                    c2, c3 = 1.5 / dt, 2.25 / (dt * dt)
                    rhs -= M @ (3.0 * (um - 4.0 * u) / (4.0 * dt * dt) + (vm - 4.0 * v) / (2.0 * dt))
                    rhs -= C @ ((um - 4.0 * u) / (2.0 * dt))
                lower = self._factor(asm, kind, c2, c3)
                kd = lower.shape[1] - 1
                padded = np.zeros(asm.n_free + 2 * kd)
                padded[kd: kd + asm.n_free] = rhs
                solve_band(lower, padded)
                u1 = padded[kd: kd + asm.n_free].copy()
                if kind == 0:
                    v1 = 2.0 * (u1 - u) / dt - v
                    a1 = 4.0 * (u1 - u) / (dt * dt) - 4.0 * v / dt - a
                else:
                    v1 = (3.0 * u1 - 4.0 * u + um) / (2.0 * dt)
                    a1 = (3.0 * v1 - 4.0 * v + vm) / (2.0 * dt)
                if not np.all(np.isfinite(u1)):
                    raise DivergenceError(f"TRBDF2 diverged at step {step + 1}, t = {t:.6g} s (NaN or inf)",
                                          step + 1, t)
                self.previous = (state.u.copy(), state.v.copy())
                self.step = kind
                state.u[free], state.v[free], state.a[free] = u1, v1, a1
                state.time = t
                chunk_t.append(t)
                chunk_rows.append(feed.state_row(state, asm))
                if len(chunk_t) >= 2000:
                    feed.deliver(np.array(chunk_t), np.array(chunk_rows), asm)
                    chunk_t, chunk_rows = [], []
            if chunk_t:
                feed.deliver(np.array(chunk_t), np.array(chunk_rows), asm)
        finally:
            feed.close()
        return state

    def _factor(self, asm, kind, c2, c3):
        key = (kind, c2, c3)
        cached = self._factors.get(key)
        if cached is not None and cached[0] is asm:
            return cached[1]
        if any(entry[0] is not asm for entry in self._factors.values()):
            self._factors = {}
        k_hat = (asm.K + c2 * asm.C + c3 * asm.M).tocsr()
        lower = factor(asm, k_hat, f"effective matrix of TRBDF2 ({'trapezoidal' if kind == 0 else 'BDF2'} sub-step)")
        self._factors[key] = (asm, lower)
        return lower


class _KeptOpen:
    """One command-layer recorder across many ``analyze`` calls, as in OpenSees: its record is
    opened once (again only when the model or its load patterns change) and closed by
    ``remove('recorder', tag)``, ``wipe()`` or the end of the process, not at the end of every
    ``analyze`` (scripts often call ``analyze(1, dt)`` in a loop). Follows the recorder
    contract of :mod:`vtsi.recorders.base` and delegates to the wrapped ``recorder``."""

    def __init__(self, recorder):
        self.recorder = recorder
        self._requests = None     # (assembly, requests)
        self._started = None      # (assembly, [(tag, pattern, n_loads)])

    @property
    def dt(self):
        return self.recorder.dt

    def requests(self, assembly):
        if self._requests is None or self._requests[0] is not assembly:
            self._requests = (assembly, self.recorder.requests(assembly))
        return self._requests[1]

    def start(self, assembly, model, info=None):
        patterns = [(tag, p, len(p.nodal)) for tag, p in model.patterns.items()]
        if self._started is not None:
            asm, old = self._started
            same = asm is assembly and len(old) == len(patterns) and all(
                a[0] == b[0] and a[1] is b[1] and a[2] == b[2] for a, b in zip(old, patterns))
            if same:
                return
            self.recorder.close()
        self.recorder.start(assembly, model, info)
        self._started = (assembly, patterns)

    def write(self, times, columns, assembly):
        self.recorder.write(times, columns, assembly)

    def close(self):
        """End of one analysis run: nothing to do (the sinks flush every chunk)."""

    def finish(self):
        """Close the record for good (OpenSees: the recorder is destroyed)."""
        if self._started is not None:
            self._started = None
            self.recorder.close()


_SESSIONS = weakref.WeakSet()


@atexit.register
def _close_recorders_at_exit():
    for s in list(_SESSIONS):
        for r in list(s._kept.values()):
            r.finish()


# ---------------------------------------------------------------------------------------------
# the session
# ---------------------------------------------------------------------------------------------
class Session(TrainCommands):
    """One OpenSees-style interpreter state: a model under construction, materials, transforms,
    the analysis settings, recorders and the results of the last queries.

    Every command of :data:`COMMANDS` is a method with OpenSeesPy's name and argument order.
    ``domain`` is the :class:`vtsi.Model` being built (None before ``model(...)``), for mixing
    commands with the object API; ``recorders`` maps recorder tags to the recorder objects.
    """

    def __init__(self):
        self._recorder_count = 0   # OpenSees: a process-wide counter that wipe() does not reset
        self.recorders = {}        # tag -> vtsi recorder (memory sinks hold .time and .values)
        self._kept = {}            # tag -> _KeptOpen adapter handed to the analyses
        self._clear()
        _SESSIONS.add(self)

    def _clear(self):
        self.domain = None
        self._materials = {}
        self._transforms = {}
        self._zero_length = {}     # element tag -> [(dir, E, eta) per material]
        self._current_pattern = None
        self._series_count = 0
        self._eigen = None
        self._modal_damping = None  # (assembly, ratios) of the last modalDamping
        self._reactions = None
        self._load_time = None     # time at which the domain last applied its loads
        self._clear_analysis()
        self._clear_train()

    def _clear_analysis(self):
        self._settings = {"constraints": "Plain", "numberer": "RCM", "system": "BandGeneral",
                          "test": None, "algorithm": ("Newton",)}
        self._static_integrator = None
        self._transient_integrator = None
        self._analysis = None
        self._transient = None
        self._trbdf2 = None

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        raise UnknownCommand(f"Session has no command {name!r}; supported commands: {', '.join(COMMANDS)}")

    # -- helpers ------------------------------------------------------------------------------
    def _model(self, command):
        if self.domain is None:
            raise CommandError(f"{command}: no model; call model('basic', '-ndm', 2, '-ndf', 3) first")
        return self.domain

    def _state(self, command):
        model = self._model(command)
        if not model.nodes:
            raise CommandError(f"{command}: the model has no nodes")
        return model.build(), domain_state(model)

    def _node(self, command, tag):
        model = self._model(command)
        if not _is_int(tag):
            raise CommandError(f"{command}: node tag must be an integer, got {tag!r}")
        if int(tag) not in model.nodes:
            raise CommandError(f"{command}: node {tag} does not exist")
        return int(tag)

    def _node_values(self, command, tag, vector):
        asm, _ = self._state(command)
        i = asm.node_index[self._node(command, tag)] * asm.ndf
        return vector[i: i + asm.ndf]

    # -- model building -----------------------------------------------------------------------
    def model(self, *args):
        """``model('basic', '-ndm', 2, '-ndf', 3)`` (``-ndf`` defaults to 3 for ``-ndm 2``)."""
        a = _Args("model", args)
        kind = a.word("builder")
        if kind not in ("basic", "Basic", "BasicBuilder"):
            raise CommandError(f"model: builder {kind!r} is not supported; supported: basic")
        ndm, ndf = None, None
        while a.more():
            opt = a.option(("-ndm", "-ndf"))
            if opt == "-ndm":
                ndm = a.int("-ndm")
            else:
                ndf = a.int("-ndf")
        if ndm is None:
            raise CommandError("model: -ndm is required")
        if ndm != 2:
            raise CommandError(f"model: vtsi is 2-D, -ndm must be 2, got {ndm}")
        ndf = 3 if ndf is None else ndf
        if ndf not in (2, 3):
            raise CommandError(f"model: -ndf must be 2 or 3 with -ndm 2, got {ndf}")
        if self.domain is not None and self.domain.nodes:
            if self.domain.ndf != ndf:
                raise CommandError(f"model: the model already has nodes with {self.domain.ndf} dofs; "
                                   f"call wipe() before changing -ndf to {ndf}")
            return None
        if self.domain is None or self.domain.ndf != ndf:
            self.domain = Model(ndm, ndf)
        return None

    def node(self, *args):
        """``node(tag, x, y, ['-mass', *m])``."""
        model = self._model("node")
        a = _Args("node", args)
        tag = a.int("node tag")
        coords = [a.float(f"coordinate {k + 1} of node {tag}") for k in range(model.ndm)]
        mass = None
        while a.more():
            a.option(("-mass",))
            mass = [a.float(f"node {tag} -mass value") for _ in range(model.ndf)]
        model.node(tag, *coords)
        if mass is not None:
            model.mass(tag, *mass)

    def fix(self, *args):
        """``fix(node, *flags)`` with one 0/1 flag per dof."""
        model = self._model("fix")
        a = _Args("fix", args)
        tag = a.int("node tag")
        flags = a.ints(f"fix flag of node {tag}")
        a.done()
        self._node("fix", tag)
        model.fix(tag, *flags)

    def mass(self, *args):
        """``mass(node, *values)``: nodal mass, one value per dof [kg, kg·m²]."""
        model = self._model("mass")
        a = _Args("mass", args)
        tag = a.int("node tag")
        values = a.floats(f"mass of node {tag}")
        a.done()
        self._node("mass", tag)
        model.mass(tag, *values)

    def geomTransf(self, *args):
        """``geomTransf('Linear', tag)`` (vtsi is linear: PDelta and Corotational are refused)."""
        self._model("geomTransf")
        a = _Args("geomTransf", args)
        kind = a.word("transformation type")
        if kind != "Linear":
            raise CommandError(f"geomTransf: transformation {kind!r} is not supported (vtsi is linear); "
                               "supported: Linear")
        tag = a.int("transformation tag")
        if a.more():
            raise CommandError(f"geomTransf Linear {tag}: option {a.peek()!r} is not supported "
                               "(joint offsets and 3-D vectors are not)")
        self._transforms[tag] = kind

    def uniaxialMaterial(self, *args):
        """``uniaxialMaterial('Elastic', tag, E, eta=0, Eneg=E)`` or ``('Viscous', tag, C, alpha=1)``."""
        self._model("uniaxialMaterial")
        a = _Args("uniaxialMaterial", args)
        kind = a.word("material type")
        if kind not in MATERIAL_TYPES:
            raise CommandError(f"uniaxialMaterial: type {kind!r} is not supported (vtsi is linear); "
                               f"supported: {', '.join(MATERIAL_TYPES)}")
        tag = a.int("material tag")
        if tag in self._materials:
            raise CommandError(f"uniaxialMaterial {kind} {tag}: material {tag} already exists")
        name = f"uniaxialMaterial {kind} {tag}"
        if kind == "Elastic":
            E = a.float(f"{name}: E")
            eta = a.float(f"{name}: eta") if a.more() else 0.0
            e_neg = a.float(f"{name}: Eneg") if a.more() else E
            a.done()
            if e_neg != E:
                raise CommandError(f"{name}: Eneg = {e_neg:g} differs from E = {E:g}, which makes the material "
                                   "nonlinear (bilinear in tension/compression); vtsi is linear")
            if E < 0 or eta < 0:
                raise CommandError(f"{name}: E and eta must be >= 0, got E = {E:g}, eta = {eta:g}")
            self._materials[tag] = ("Elastic", E, eta)
        else:
            C = a.float(f"{name}: C")
            alpha = a.float(f"{name}: alpha") if a.more() else 1.0
            if a.more():
                a.float(f"{name}: minVel")   # only matters for alpha != 1
            a.done()
            if alpha != 1.0:
                raise CommandError(f"{name}: alpha = {alpha:g} makes the dashpot nonlinear "
                                   "(sigma = C |rate|^alpha); vtsi supports alpha = 1 only")
            if C < 0:
                raise CommandError(f"{name}: C must be >= 0, got {C:g}")
            self._materials[tag] = ("Viscous", 0.0, C)

    def _material(self, command, tag):
        if tag not in self._materials:
            raise CommandError(f"{command}: material {tag} does not exist")
        return self._materials[tag]

    def element(self, *args):
        """``element(type, tag, ...)`` with the argument order of OpenSees for
        ``'elasticBeamColumn'``, ``'truss'`` and ``'zeroLength'`` (see ``docs/commands.md``)."""
        model = self._model("element")
        a = _Args("element", args)
        kind = a.word("element type")
        if kind not in ELEMENT_TYPES:
            raise CommandError(f"element: type {kind!r} is not supported; supported: {', '.join(ELEMENT_TYPES)}")
        tag = a.int("element tag")
        name = f"element {kind} {tag}"
        i, j = a.int(f"{name}: node i"), a.int(f"{name}: node j")
        for n in (i, j):
            self._node(name, n)
        getattr(self, "_element_" + kind)(model, a, name, tag, i, j)

    def _element_elasticBeamColumn(self, model, a, name, tag, i, j):
        if model.ndf != 3:
            raise CommandError(f"{name}: needs -ndf 3 (the model has {model.ndf})")
        A, E, Iz = a.float(f"{name}: A"), a.float(f"{name}: E"), a.float(f"{name}: Iz")
        if not a.next_is_number():
            raise CommandError(f"{name}: missing transfTag (element('elasticBeamColumn', tag, i, j, A, E, Iz, "
                               "transfTag, ...))")
        transf = a.int(f"{name}: transfTag")
        if a.next_is_number():
            raise CommandError(f"{name}: the section form (secTag, transfTag) is not supported; give A, E, Iz")
        if transf not in self._transforms:
            raise CommandError(f"{name}: geomTransf {transf} does not exist")
        rho, cmass = 0.0, 0
        while a.more():
            opt = a.option(("-mass", "-cMass"))
            if opt == "-mass":
                rho = a.float(f"{name}: -mass")
            else:
                cmass = 1
        model.element("elasticBeamColumn", tag, (i, j), A=A, E=E, I=Iz, rho=rho, cmass=cmass)

    def _element_truss(self, model, a, name, tag, i, j):
        A = a.float(f"{name}: A")
        mat = a.int(f"{name}: matTag")
        kind, E, eta = self._material(name, mat)
        if kind != "Elastic" or eta != 0.0:
            raise CommandError(f"{name}: material {mat} must be Elastic without damping (eta = 0) for a truss "
                               "in vtsi; use a zeroLength dashpot for damping")
        rho, cmass, do_rayleigh = 0.0, 0, 0
        while a.more():
            opt = a.option(("-rho", "-cMass", "-doRayleigh"))
            if opt == "-rho":
                rho = a.float(f"{name}: -rho")
            elif opt == "-cMass":
                cmass = a.int(f"{name}: -cMass flag") if a.next_is_number() else 1
            else:
                do_rayleigh = a.int(f"{name}: -doRayleigh flag") if a.next_is_number() else 1
        model.element("truss", tag, (i, j), A=A, E=E, rho=rho, cmass=cmass, do_rayleigh=do_rayleigh)

    def _element_zeroLength(self, model, a, name, tag, i, j):
        if model.ndf != 3:
            raise CommandError(f"{name}: needs -ndf 3 (the model has {model.ndf})")
        mats, dirs, orient, do_rayleigh = [], [], None, 0
        while a.more():
            opt = a.option(("-mat", "-dir", "-orient", "-doRayleigh"))
            if opt == "-mat":
                mats = a.ints(f"{name}: -mat tag")
            elif opt == "-dir":
                dirs = a.ints(f"{name}: -dir")
            elif opt == "-orient":
                orient = a.floats(f"{name}: -orient")
            else:
                do_rayleigh = a.int(f"{name}: -doRayleigh flag") if a.next_is_number() else 1
        if not mats:
            raise CommandError(f"{name}: no materials (-mat tags ...)")
        if len(mats) != len(dirs):
            raise CommandError(f"{name}: {len(mats)} materials (-mat) but {len(dirs)} directions (-dir)")
        angle = 0.0
        if orient is not None:
            # 2-D: local x from the first vector; local y is x turned +90 degrees and rz is the
            # global rotation whatever the side of yp (measured on OpenSeesPy 3.7.1)
            if len(orient) != 6:
                raise CommandError(f"{name}: -orient needs 6 numbers (x1 x2 x3 yp1 yp2 yp3), got {len(orient)}")
            x, yp = np.array(orient[:3]), np.array(orient[3:])
            if x[2] != 0.0 or np.hypot(x[0], x[1]) == 0.0:
                raise CommandError(f"{name}: -orient x = {x.tolist()} must lie in the x-y plane (2-D model)")
            if np.linalg.norm(np.cross(x, yp)) <= 1e-12 * np.linalg.norm(x) * np.linalg.norm(yp):
                raise CommandError(f"{name}: -orient yp = {yp.tolist()} is parallel to x = {x.tolist()}")
            angle = math.atan2(x[1], x[0])
        params = dict(kx=0.0, ky=0.0, krz=0.0, cx=0.0, cy=0.0, crz=0.0)
        keys = {1: ("kx", "cx"), 2: ("ky", "cy"), 3: ("krz", "crz"), 6: ("krz", "crz")}
        for mat, d in zip(mats, dirs):
            if d not in keys:
                raise CommandError(f"{name}: -dir {d} is not a 2-D direction; valid: 1 (local x), 2 (local y), "
                                   "3 or 6 (rotation)")
            _, E, eta = self._material(name, mat)
            params[keys[d][0]] += E
            params[keys[d][1]] += eta
        model.element("zeroLength", tag, (i, j), angle=angle, do_rayleigh=do_rayleigh, **params)
        self._zero_length[tag] = [(3 if d == 6 else d, *self._material(name, m)[1:]) for m, d in zip(mats, dirs)]

    def timeSeries(self, *args):
        """``timeSeries('Constant'|'Linear', tag, ['-factor', f])`` or ``timeSeries('Path', tag, ...)``
        with OpenSees's options ``-dt``, ``-values``, ``-time``, ``-filePath``, ``-fileTime``,
        ``-factor``, ``-useLast``, ``-prependZero``, ``-startTime``."""
        model = self._model("timeSeries")
        a = _Args("timeSeries", args)
        kind = a.word("series type")
        if kind not in SERIES_TYPES:
            raise CommandError(f"timeSeries: type {kind!r} is not supported; supported: {', '.join(SERIES_TYPES)}")
        tag = a.int("series tag")
        series = self._make_series(kind, tag, a)
        if tag in model.time_series:
            raise CommandError(f"timeSeries {kind} {tag}: series {tag} already exists")
        model.add_time_series(series)

    def _make_series(self, kind, tag, a):
        name = f"timeSeries {kind} {tag}"
        a.command = name
        if kind in ("Constant", "Linear"):
            f = 1.0
            while a.more():
                a.option(("-factor",))
                f = a.float("-factor")
            return (Constant if kind == "Constant" else Linear)(f, tag=tag)
        if kind in ("Trig", "Triangle", "Rectangular", "Pulse"):
            t0, t1 = a.float("tStart"), a.float("tEnd")
            period = a.float("period") if kind != "Rectangular" else None
            extra = {"-factor": 1.0, "-shift": 0.0, "-zeroShift": 0.0, "-width": 0.5}
            valid = ("-factor",) if kind == "Rectangular" else tuple(extra) if kind == "Pulse" else tuple(extra)[:3]
            while a.more():
                opt = a.option(valid)
                extra[opt] = a.float(opt)
            try:
                if kind == "Rectangular":
                    return Rectangular(t0, t1, extra["-factor"], tag=tag)
                if kind == "Pulse":
                    return Pulse(t0, t1, period, extra["-width"], extra["-factor"], extra["-shift"], extra["-zeroShift"],
                                 tag=tag)
                return (Trig if kind == "Trig" else Triangle)(t0, t1, period, extra["-factor"], extra["-shift"],
                                                             extra["-zeroShift"], tag=tag)
            except ModelError as exc:
                raise CommandError(str(exc)) from None
        opts = {}
        valid = ("-dt", "-values", "-time", "-filePath", "-fileTime", "-factor", "-useLast", "-prependZero",
                 "-startTime")
        while a.more():
            opt = a.option(valid)
            if opt in opts:
                raise CommandError(f"{name}: option {opt} given twice")
            if opt in ("-dt", "-factor", "-startTime"):
                opts[opt] = a.float(opt)
            elif opt in ("-values", "-time"):
                opts[opt] = np.array(a.floats(opt))
            elif opt in ("-filePath", "-fileTime"):
                opts[opt] = _read_numbers(name, os.fspath(a.word(f"{opt} file")))
            else:
                opts[opt] = True
        if ("-values" in opts) == ("-filePath" in opts):
            raise CommandError(f"{name}: give the values with either -values or -filePath")
        if ("-time" in opts) and ("-fileTime" in opts):
            raise CommandError(f"{name}: give the times with either -time or -fileTime")
        values = opts.get("-values", opts.get("-filePath"))
        time = opts.get("-time", opts.get("-fileTime"))
        factor_ = opts.get("-factor", 1.0)
        if "-dt" in opts and time is not None:
            raise CommandError(f"{name}: give either -dt or -time/-fileTime, not both")
        if "-dt" in opts:
            dt = opts["-dt"]
            if not dt > 0.0:
                raise CommandError(f"{name}: -dt must be > 0, got {dt:g}")
            _check_path_values(name, values)
            return PathSeries(tag, values, dt, factor_, opts.get("-useLast", False),
                              opts.get("-prependZero", False), opts.get("-startTime", 0.0))
        if time is None:
            raise CommandError(f"{name}: give the sample times with -dt or -time/-fileTime")
        for opt in ("-prependZero", "-startTime"):
            if opt in opts:
                raise CommandError(f"{name}: option {opt} applies to the -dt form only (OpenSees ignores it "
                                   "with -time); shift or extend the -time list instead")
        _check_path_values(name, values, time)
        return PathTimeSeries(tag, time, values, factor_, opts.get("-useLast", False))

    def pattern(self, *args):
        """``pattern('Plain', tag, tsTag, ['-fact', f])``; following ``load`` commands go to it.
        ``tsTag`` may also be an inline series as in Tcl (``'Linear'``, ``'Path -dt 0.1 -values {...}'``)."""
        model = self._model("pattern")
        a = _Args("pattern", args)
        kind = a.word("pattern type")
        if kind == "UniformExcitation":
            return self._uniform_excitation(model, a)
        if kind != "Plain":
            raise CommandError(f"pattern: type {kind!r} is not supported; supported: Plain, UniformExcitation")
        tag = a.int("pattern tag")
        name = f"pattern Plain {tag}"
        spec = a.take(f"{name}: time series tag")
        if isinstance(spec, str):
            series = self._inline_series(name, spec)
        elif _is_int(spec):
            if int(spec) not in model.time_series:
                raise CommandError(f"{name}: time series {spec} does not exist")
            series = model.time_series[int(spec)]
        else:
            raise CommandError(f"{name}: time series tag must be an integer, got {spec!r}")
        fact = 1.0
        while a.more():
            a.option(("-fact", "-factor"))
            fact = a.float(f"{name}: -fact")
        if tag in model.patterns:
            raise CommandError(f"{name}: pattern {tag} already exists")
        model.pattern(tag, series, fact)
        self._current_pattern = tag

    def _uniform_excitation(self, model, a):
        """``pattern('UniformExcitation', tag, dir, '-accel', tsTag, ['-fact', f])``: a ground
        acceleration along dof ``dir`` (1 x, 2 y) [L/s²]; responses relative to the ground."""
        tag = a.int("pattern tag")
        name = f"pattern UniformExcitation {tag}"
        a.command = name
        direction = a.int("direction")
        series, fact = None, 1.0
        while a.more():
            opt = a.option(("-accel", "-fact", "-factor"))
            if opt == "-accel":
                spec = a.take("-accel time series tag")
                if isinstance(spec, str):
                    series = self._inline_series(name, spec)
                elif _is_int(spec) and int(spec) in model.time_series:
                    series = model.time_series[int(spec)]
                else:
                    raise CommandError(f"{name}: -accel time series {spec!r} does not exist")
            else:
                fact = a.float(opt)
        if series is None:
            raise CommandError(f"{name}: give the ground acceleration with -accel tsTag (-disp, -vel: not supported)")
        if direction not in (1, 2):
            raise CommandError(f"{name}: direction must be 1 (x) or 2 (y), got {direction}")
        if tag in model.patterns:
            raise CommandError(f"{name}: pattern {tag} already exists")
        model.uniform_excitation(tag, direction, series, fact)
        self._current_pattern = None

    def _inline_series(self, name, spec):
        words = _tcl_split(spec)
        if not words:
            raise CommandError(f"{name}: empty time series specification")
        self._series_count += 1
        a = _Args(f"{name} series", words[1:])
        kind = words[0]
        if kind not in SERIES_TYPES:
            raise CommandError(f"{name}: series type {kind!r} is not supported; supported: {', '.join(SERIES_TYPES)}")
        return self._make_series(kind, -self._series_count, a)

    def load(self, *args):
        """``load(node, *values)``: nodal load of the last pattern defined [N, N·m]."""
        model = self._model("load")
        a = _Args("load", args)
        tag = a.int("node tag")
        values = a.floats(f"load on node {tag}")
        pattern = self._current_pattern
        while a.more():
            a.option(("-pattern",))
            pattern = a.int("-pattern tag")
        self._node("load", tag)
        if pattern is None or pattern not in model.patterns:
            raise CommandError(f"load on node {tag}: no load pattern; define one with pattern('Plain', tag, tsTag)")
        model.load(pattern, tag, *values)

    def rayleigh(self, *args):
        """``rayleigh(alphaM, betaK, betaKinit, betaKcomm)``: ``C = αM M + (βK + βK0 + βKc) K``."""
        model = self._model("rayleigh")
        a = _Args("rayleigh", args)
        values = [a.float(n) for n in ("alphaM", "betaK", "betaKinit", "betaKcomm")]
        a.done()
        model.rayleigh(*values)

    # -- analysis settings ---------------------------------------------------------------------
    def constraints(self, *args):
        """``constraints('Plain'|'Transformation')`` (only single-point constraints exist: both
        eliminate the fixed dofs)."""
        a = _Args("constraints", args)
        self._settings["constraints"] = a.word("handler", CONSTRAINT_HANDLERS)
        a.done()

    def numberer(self, *args):
        """``numberer('Plain'|'RCM'|'AMD')`` (vtsi always numbers by reverse Cuthill-McKee)."""
        a = _Args("numberer", args)
        self._settings["numberer"] = a.word("numberer", NUMBERERS)
        a.done()

    def system(self, *args):
        """``system(...)``: any of :data:`SYSTEMS`; vtsi solves with its banded Cholesky solver."""
        a = _Args("system", args)
        self._settings["system"] = a.word("system", SYSTEMS)
        a.done()

    def test(self, *args):
        """``test(type, tol, maxIter, [printFlag, normType])``: checked and kept; a linear model
        converges in one pass, so it never fails."""
        a = _Args("test", args)
        kind = a.word("test type", TESTS)
        tol = a.float("tolerance")
        iters = a.int("maximum number of iterations") if a.more() else 1
        extra = a.ints("print flag / norm type")
        a.done()
        if len(extra) > 2 or tol < 0 or iters < 1:
            raise CommandError(f"test {kind}: expected tol >= 0, maxIter >= 1, [pFlag, nType], got {list(args)!r}")
        self._settings["test"] = (kind, tol, iters, *extra)

    def algorithm(self, *args):
        """``algorithm('Linear'|'Newton'|'ModifiedNewton'|..., [flags])``: for a linear model every
        algorithm gives the same solution, which vtsi computes exactly in one pass."""
        a = _Args("algorithm", args)
        kind = a.word("algorithm", tuple(ALGORITHMS))
        flags = []
        while a.more():
            flags.append(a.option(ALGORITHMS[kind] or ("(no options)",)))
        self._settings["algorithm"] = (kind, *flags)

    def integrator(self, *args):
        """``integrator('LoadControl', dλ)``, ``('Newmark', gamma, beta)``, ``('HHT', alpha, [gamma,
        beta])``, ``('CentralDifference')``, ``('TRBDF2')`` or vtsi's ``('Bathe', [gamma])``."""
        a = _Args("integrator", args)
        kind = a.word("integrator", INTEGRATORS)
        name = f"integrator {kind}"
        a.command = name
        if kind == "LoadControl":
            d_lambda = a.float("load increment")
            extra = a.floats("numIter, minLambda, maxLambda")
            a.done()
            if len(extra) > 3:
                raise CommandError(f"{name}: expected dLambda [numIter minLambda maxLambda], got {list(args)!r}")
            self._static_integrator = ("LoadControl", d_lambda)
            return
        if kind == "Newmark":
            gamma, beta = a.float("gamma"), a.float("beta")
            while a.more():
                a.option(("-form",))
                form = a.word("-form", ("D", "V", "A", "d", "v", "a", "displacement", "velocity", "acceleration"))
                log.debug("integrator Newmark -form %s: all forms give the same solution of a linear model", form)
            spec = (kind, Newmark(gamma, beta))
        elif kind == "HHT":
            alpha = a.float("alpha")
            if a.more():
                gamma, beta = a.float("gamma"), a.float("beta")
                spec = (kind, HHT(alpha, gamma, beta))
            else:
                spec = (kind, HHT(alpha))
        elif kind == "CentralDifference":
            spec = (kind, CentralDifference())
        elif kind == "TRBDF2":
            spec = (kind, None)
        else:
            spec = (kind, Bathe(a.float("gamma")) if a.more() else Bathe())
        a.done()
        self._transient_integrator = spec
        self._transient = None
        self._trbdf2 = _OpenSeesTRBDF2() if kind == "TRBDF2" else None

    def analysis(self, *args):
        """``analysis('Static'|'Transient')``."""
        a = _Args("analysis", args)
        kind = a.word("analysis type", ANALYSES)
        a.done()
        self._analysis = kind
        if kind == "Static" and self._static_integrator is None:
            log.info("analysis Static: no static integrator set, using LoadControl 1.0 (as OpenSees)")
            self._static_integrator = ("LoadControl", 1.0)
        if kind == "Transient" and self._transient_integrator is None:
            log.info("analysis Transient: no transient integrator set, using Newmark 0.5 0.25 (as OpenSees)")
            self._transient_integrator = ("Newmark", Newmark(0.5, 0.25))
            self._transient = None

    def wipeAnalysis(self):
        """Forget the analysis settings (the model, its state and the recorders stay)."""
        self._clear_analysis()

    # -- running --------------------------------------------------------------------------------
    def _recorder_list(self):
        return list(self._kept.values())

    def analyze(self, *args):
        """``analyze(numSteps)`` (static) or ``analyze(numSteps, dt)`` (transient); returns 0.
        A failure raises (an :class:`~vtsi.errors.AnalysisError`) instead of returning a code."""
        model = self._model("analyze")
        a = _Args("analyze", args)
        n = a.int("number of steps") if a.more() else 1
        if n < 0:
            raise CommandError(f"analyze: number of steps must be >= 0, got {n}")
        if self._analysis is None:
            raise CommandError("analyze: no analysis defined; call analysis('Static') or analysis('Transient') first")
        if not model.nodes:
            raise CommandError("analyze: the model has no nodes")
        if self._analysis == "Static":
            if a.more():
                a.float("dt")   # OpenSees accepts and ignores a dt in a static analysis
            a.done()
            d_lambda = self._static_integrator[1]
            recorders = self._recorder_list()
            StaticAnalysis(model, d_lambda, recorders).run(n)
            self._load_time = domain_state(model).time
            return 0
        if not a.more():
            raise CommandError("analyze: a transient analysis needs the time step: analyze(numSteps, dt)")
        dt = a.float("dt")
        a.done()
        if not dt > 0.0:
            raise CommandError(f"analyze: dt must be > 0, got {dt:g}")
        if self._constraint is not None:
            return self._analyze_coupled(n, dt)
        kind, integ = self._transient_integrator
        info = {"analysis": "transient", "integrator": kind, "dt": dt}
        if kind == "TRBDF2":
            self._trbdf2.run(model, n, dt, self._recorder_list(), info)
            self._load_time = domain_state(model).time
            return 0
        bridge = self._modal_bridge("analyze")
        if self._transient is None or self._transient.bridge is not bridge:
            self._transient = _CommandTransient(model, integ, bridge)
        analysis = self._transient
        analysis.set_dt(dt)
        analysis.recorders = self._recorder_list()
        t0 = domain_state(model).time
        analysis.run(n)
        if n > 0:   # when the domain last applied its loads (OpenSees: the nodes' unbalanced load)
            times = analysis.step_times(t0, n)
            if kind == "HHT":
                self._load_time = times[-2] + integ.alpha * dt
            elif kind == "CentralDifference":
                self._load_time = times[-2]
            else:
                self._load_time = times[-1]
        return 0

    def eigen(self, *args):
        """``eigen([solver,] n)``: the ``n`` lowest eigenvalues ω² [rad²/s²] as a list; solvers
        ``'-genBandArpack'`` (default) and ``'-fullGenLapack'``. Vectors are mass-normalised."""
        model = self._model("eigen")
        a = _Args("eigen", args)
        solver = "-genBandArpack"
        while a.more() and isinstance(a.peek(), str):
            opt = a.option(EIGEN_SOLVERS + ("-symmBandLapack", "-standard", "-findLargest"))
            if opt not in EIGEN_SOLVERS:
                raise CommandError(f"eigen: option {opt!r} is not supported (vtsi solves the generalized problem "
                                   f"K phi = omega^2 M phi for the lowest modes); supported: {', '.join(EIGEN_SOLVERS)}")
            solver = opt
        n = a.int("number of modes")
        a.done()
        if n < 1:
            raise CommandError(f"eigen: number of modes must be >= 1, got {n}")
        omega2, shapes = _eigen(model, n)
        self._eigen = (model.build(), omega2, shapes)
        log.debug("eigen %s: %d modes", solver, n)
        return [float(w) for w in omega2]

    def modalDamping(self, *args):
        """``modalDamping(zeta)`` or ``modalDamping(zeta_1, ..., zeta_n)``: damping ratios [-] of the
        modes of the last ``eigen`` (one for all, or one per mode), added to the model's own
        (Rayleigh) damping: C = M Φ diag(2ζω) Φᵀ M. vtsi then steps the model as a modal bridge of
        every mode of finite frequency (:class:`~vtsi.modal_bridge.ModalBridge`, ``n_modes='all'``):
        the model's own equations, a dof without mass following statically, so the model's own
        damping must be classical (Rayleigh) and no load may act on a dof without mass. Equal to
        OpenSees with nodal masses (``mass``); with element mass (``-mass``, ``-rho``) OpenSees's
        modal damping force differs from this C by a fraction of a percent (docs/commands.md)."""
        model = self._model("modalDamping")
        a = _Args("modalDamping", args)
        ratios = [a.float("damping ratio")]
        while a.more():
            ratios.append(a.float("damping ratio"))
        a.done()
        if self._eigen is None:
            raise CommandError("modalDamping: no modes; call eigen(n) first (the ratios apply to its modes)")
        asm, omega2, _ = self._eigen
        if asm is not model.build():
            raise CommandError("modalDamping: the model changed after the last eigen; call eigen(n) again")
        n = len(omega2)
        if len(ratios) not in (1, n):
            raise CommandError(f"modalDamping: give one ratio or one per mode of the last eigen ({n}), got {len(ratios)}")
        bad = [z for z in ratios if not (np.isfinite(z) and z >= 0.0)]
        if bad:
            raise CommandError(f"modalDamping: a damping ratio must be >= 0 (0.05 for 5 %), got {bad[0]:g}")
        self._modal_damping = (asm, np.broadcast_to(np.asarray(ratios, dtype=float), (n,)).copy(), None)
        self._transient = None

    def _modal_bridge(self, command):
        """The modal bridge that ``modalDamping`` asks for (None without it), built once."""
        if self._modal_damping is None:
            return None
        asm, ratios, bridge = self._modal_damping
        model = self._model(command)
        if asm is not model.build():
            raise CommandError(f"{command}: the model changed after eigen and modalDamping; call them again")
        if bridge is None:
            massless = np.flatnonzero(asm.M.diagonal() <= 0.0)
            damped = massless[np.abs(asm.C[massless]).sum(axis=1).A1 > 0.0] if len(massless) else massless
            if len(damped):
                raise CommandError(f"{command}: modalDamping: {asm.dof_label(damped[0])} has damping (rayleigh "
                                   "betaK) but no mass; vtsi steps the modes of the model, where a dof without "
                                   "mass follows statically (give it mass, or use rayleigh alphaM only)")
            try:
                bridge = ModalBridge(model, n_modes="all")
                bridge.add_ratios(ratios)
            except (ModelError, AnalysisError) as exc:
                raise CommandError(f"{command}: modalDamping: {exc}") from None
            self._modal_damping = (asm, ratios, bridge)
        return bridge

    # -- queries -------------------------------------------------------------------------------
    def nodeDisp(self, node, dof=-1):
        """Displacement of ``node`` [m, rad]: a list over its dofs, or one 1-based ``dof``."""
        _, state = self._state("nodeDisp")
        return _dof_value(self._node_values("nodeDisp", node, state.u), dof, f"nodeDisp {node}")

    def nodeVel(self, node, dof=-1):
        """Velocity of ``node`` [m/s, rad/s]."""
        _, state = self._state("nodeVel")
        return _dof_value(self._node_values("nodeVel", node, state.v), dof, f"nodeVel {node}")

    def nodeAccel(self, node, dof=-1):
        """Acceleration of ``node`` [m/s², rad/s²]."""
        _, state = self._state("nodeAccel")
        return _dof_value(self._node_values("nodeAccel", node, state.a), dof, f"nodeAccel {node}")

    def nodeCoord(self, node, dim=-1):
        """Coordinates ``[x, y]`` of ``node`` [m], or one 1-based coordinate."""
        tag = self._node("nodeCoord", node)
        return _dof_value(list(self.domain.nodes[tag]), dim, f"nodeCoord {node}")

    def nodeReaction(self, node, dof=-1):
        """Reaction at ``node`` as last computed by :meth:`reactions` (zeros before) [N, N·m]."""
        asm, _ = self._state("nodeReaction")
        if self._reactions is None or self._reactions.shape[0] != asm.n_full:
            values = np.zeros(asm.ndf)
            self._node("nodeReaction", node)
        else:
            values = self._node_values("nodeReaction", node, self._reactions)
        return _dof_value(values, dof, f"nodeReaction {node}")

    def nodeEigenvector(self, node, mode, dof=-1):
        """Mode ``mode`` (1-based) of the last ``eigen`` at ``node``: list over the dofs or one dof."""
        tag = self._node("nodeEigenvector", node)
        if self._eigen is None:
            raise CommandError("nodeEigenvector: no eigenvectors; call eigen(n) first")
        asm, _, shapes = self._eigen
        if not _is_int(mode) or not 1 <= mode <= shapes.shape[1]:
            raise CommandError(f"nodeEigenvector: mode must be 1..{shapes.shape[1]} (eigen computed "
                               f"{shapes.shape[1]}), got {mode!r}")
        if tag not in asm.node_index:
            raise CommandError(f"nodeEigenvector: node {tag} was added after the last eigen")
        i = asm.node_index[tag] * asm.ndf
        return _dof_value(shapes[i: i + asm.ndf, int(mode) - 1], dof, f"nodeEigenvector {node} {mode}")

    def nodeResponse(self, node, dof, response_id):
        """``nodeResponse(node, dof, id)``: id 1 disp, 2 vel, 3 accel, 6 reaction (as last
        computed), 7 applied nodal load."""
        if response_id not in NODE_RESPONSE_IDS:
            raise CommandError(f"nodeResponse: response id {response_id!r} is not supported; supported: "
                               + ", ".join(f"{k} ({v})" for k, v in NODE_RESPONSE_IDS.items()))
        kind = NODE_RESPONSE_IDS[response_id]
        if kind == "unbalance":
            asm, _ = self._state("nodeResponse")
            values = self._node_values("nodeResponse", node, self._applied_loads(asm))
            return _dof_value(values, dof, f"nodeResponse {node}")
        method = {"disp": self.nodeDisp, "vel": self.nodeVel, "accel": self.nodeAccel,
                  "reaction": self.nodeReaction}[kind]
        return method(node, dof)

    def getTime(self):
        """The current (committed) domain time [s]."""
        if self.domain is None or not self.domain.nodes:
            return 0.0
        return float(domain_state(self.domain).time)

    def setTime(self, t):
        """Set the domain time [s]; the next step goes to ``t + Δt``."""
        _, state = self._state("setTime")
        if not _is_number(t):
            raise CommandError(f"setTime: time must be a number, got {t!r}")
        state.time = float(t)

    def loadConst(self, *args):
        """``loadConst(['-time', t])``: freeze every existing pattern at its current factor (and
        set the time)."""
        model = self._model("loadConst")
        a = _Args("loadConst", args)
        new_time = None
        while a.more():
            a.option(("-time",))
            new_time = a.float("-time")
        at = self._load_time if self._load_time is not None else self.getTime()
        for p in model.patterns.values():
            if p.constant_time is None:
                p.constant_time = at
        if new_time is not None:
            _, state = self._state("loadConst")
            state.time = new_time

    def getLoadFactor(self, tag):
        """The load factor of pattern ``tag`` (its factor × its series' at the time the domain
        last applied its loads, as OpenSees)."""
        model = self._model("getLoadFactor")
        if not _is_int(tag) or tag not in model.patterns:
            raise CommandError(f"getLoadFactor: pattern {tag!r} does not exist")
        at = self._load_time if self._load_time is not None else self.getTime()
        return float(model.patterns[tag].factors(np.array([at]))[0])

    def nodeMass(self, node, dof=-1):
        """The nodal mass of ``node`` (``mass`` command or ``node -mass``; element mass not
        included, as OpenSees) [M, M·L²]: a list over its dofs, or one 1-based ``dof``."""
        tag = self._node("nodeMass", node)
        values = self.domain.nodal_mass.get(tag, np.zeros(self.domain.ndf))
        return _dof_value(list(map(float, values)), dof, f"nodeMass {node}")

    def nodeBounds(self):
        """``[x_min, y_min, 0, x_max, y_max, 0]`` of the nodes (OpenSees's 6 values in 2-D)."""
        model = self._model("nodeBounds")
        if not model.nodes:
            raise CommandError("nodeBounds: the model has no nodes")
        xy = np.array(list(model.nodes.values()), dtype=float)
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        return [float(lo[0]), float(lo[1]), 0.0, float(hi[0]), float(hi[1]), 0.0]

    def getNodeTags(self):
        """Node tags, ascending."""
        return sorted(self.domain.nodes) if self.domain is not None else []

    def getEleTags(self):
        """Element tags, ascending."""
        return self.domain.element_tags() if self.domain is not None else []

    # -- forces ------------------------------------------------------------------------------------
    def _applied_loads(self, asm):
        """Full-dof nodal load vector applied at the last load time (OpenSees's unbalanced load)."""
        p = np.zeros(asm.n_full)
        if self._load_time is None:
            return p
        ndf = asm.ndf
        for pattern in self.domain.patterns.values():
            f = float(pattern.factors(np.array([self._load_time]))[0])
            if f == 0.0:
                continue
            for tag, values in pattern.nodal.items():
                if tag in asm.node_index:
                    i = asm.node_index[tag] * ndf
                    p[i: i + ndf] += f * np.asarray(values)[:ndf]
        return p

    def _element_response(self, command, tag, kind, u, v):
        """One element's response as OpenSees returns it (see :meth:`_layout`)."""
        asm = self.domain.build()
        kind = ELEMENT_RESPONSE_ALIASES.get(kind, kind)
        if tag not in asm.element_location:
            raise CommandError(f"{command}: element {tag} does not exist")
        b, i = asm.element_location[tag]
        etype, _, coords, params, dofs = asm.blocks[b]
        layout = self._layout(etype, tag, kind, asm.ndf)
        source = layout[0] if layout is not None else kind
        if source not in etype.response_kinds:
            raise CommandError(f"{command}: element {tag} ({etype.name}) has no response {kind!r}; valid: "
                               f"{', '.join(etype.response_kinds)}")
        d = dofs[i]
        c, p, u_e, v_e = coords[i: i + 1], params[i: i + 1], u[d][None, :], v[d][None, :]
        values = np.asarray(etype.response(source, c, p, u_e, v_e), dtype=float)
        if layout is None:
            return values[0]
        rates = np.asarray(etype.response(source, c, p, v_e, v_e), dtype=float) if layout[2] else None
        return _apply_layout(layout, values, rates)[0]

    def _layout(self, etype, tag, kind, ndf):
        """How to build OpenSees's columns of an element response from vtsi's, or None when they
        agree: ``(source kind, [(index or -1, coefficient on the value, coefficient on its rate)],
        uses rates)``. A truss's ``force``/``localForce`` spans every dof of its nodes (rotations
        read 0); a zeroLength's basic forces and deformations come one per material, in ``-dir``
        order (a material's force: ``E δ + eta δ̇``); a beam's ``basicForce`` (N, M1, M2) comes from its
        ``localForce``."""
        per_node = len(etype.node_dofs)
        if etype.name == "elasticBeamColumn" and kind == "basicForce":   # (N, M1, M2) from the end forces
            return ("localForce", [(3, 1.0, 0.0), (2, 1.0, 0.0), (5, 1.0, 0.0)], False)
        if etype.name == "zeroLength" and tag in self._zero_length:
            materials = self._zero_length[tag]
            if kind in ("basicForce", "localForce"):
                return ("deformation", [(d - 1, E, eta) for d, E, eta in materials], True)
            if kind in ("deformation", "basicDeformation"):
                return ("deformation", [(d - 1, 1.0, 0.0) for d, _E, _eta in materials], False)
        if kind in ("force", "globalForce", "localForce") and per_node < ndf:
            columns = [(-1, 0.0, 0.0)] * (etype.n_nodes * ndf)
            for n in range(etype.n_nodes):
                for k, d in enumerate(etype.node_dofs):
                    columns[n * ndf + d] = (n * per_node + k, 1.0, 0.0)
            return (kind, columns, False)
        return None

    def eleForce(self, tag, dof=-1):
        """Resisting force of element ``tag`` in global axes (``K u`` plus the element's own
        dashpots; no Rayleigh damping, no inertia), the force the nodes exert on the element."""
        _, state = self._state("eleForce")
        if not _is_int(tag):
            raise CommandError(f"eleForce: element tag must be an integer, got {tag!r}")
        values = self._element_response("eleForce", int(tag), "force", state.u, state.v)
        return _dof_value(values, dof, f"eleForce {tag}")

    def eleResponse(self, tag, *args):
        """``eleResponse(tag, 'force'|'globalForce'|'localForce'|'basicForce'|...)`` as a list."""
        _, state = self._state("eleResponse")
        a = _Args(f"eleResponse {tag}", args)
        kind = a.word("response")
        a.done()
        if not _is_int(tag):
            raise CommandError(f"eleResponse: element tag must be an integer, got {tag!r}")
        return [float(x) for x in self._element_response("eleResponse", int(tag), kind, state.u, state.v)]

    def reactions(self, *args):
        """Compute the nodal reactions (read them with :meth:`nodeReaction`): ``R = F_resisting - P``
        with the elements' static resisting forces (default), ``'-dynamic'``: ``K u + C v + M a - P``
        (inertia and Rayleigh damping included), ``'-rayleigh'``: the Rayleigh damping forces only."""
        asm, state = self._state("reactions")
        a = _Args("reactions", args)
        flag = "-static"
        while a.more():
            flag = a.option(("-dynamic", "-rayleigh"))
        if flag == "-dynamic":
            r = asm.K_full @ state.u + asm.C_full @ state.v + asm.M_full @ state.a - self._applied_loads(asm)
        else:
            own = np.zeros(asm.n_full)   # elements' resisting forces K u + C_el v
            own_damping = np.zeros(asm.n_full)
            for etype, _tags, coords, params, dofs in asm.blocks:
                u_e, v_e = state.u[dofs], state.v[dofs]
                f = np.asarray(etype.response("force", coords, params, u_e, v_e))
                np.add.at(own, dofs, f)
                c_v = np.einsum("eij,ej->ei", etype.damping(coords, params), v_e)
                np.add.at(own_damping, dofs, c_v)
            if flag == "-rayleigh":
                r = asm.C_full @ state.v - own_damping
            else:
                r = own - self._applied_loads(asm)
        self._reactions = r

    # -- recorders ---------------------------------------------------------------------------------
    def recorder(self, *args):
        """``recorder('Node'|'EnvelopeNode'|'Element'|'EnvelopeElement', ...)``; returns its tag.
        Options: ``-file f`` (OpenSees text), vtsi's ``-h5 f``/``-hdf5 f`` (HDF5), ``-time``,
        ``-precision p``, ``-dT dt``, ``-closeOnWrite``, ``-node``, ``-nodeRange a b``, ``-dof``,
        ``-ele``, ``-eleRange a b``; then the response."""
        from vtsi import recorders as rec

        if args and args[0] in ("Contact", "Train"):
            return self._vehicle_recorder(*args)
        model = self._model("recorder")
        a = _Args("recorder", args)
        kind = a.word("recorder type", RECORDER_TYPES)
        name = f"recorder {kind}"
        a.command = name
        is_node = kind.endswith("Node")
        valid = ["-file", "-h5", "-hdf5", "-time", "-precision", "-dT", "-closeOnWrite"]
        valid += ["-node", "-nodeRange", "-dof"] if is_node else ["-ele", "-eleRange"]
        opts = {"-time": False, "-precision": 6, "-dT": None, "-closeOnWrite": False}
        targets = []
        response = []
        while a.more():
            x = a.peek()
            if isinstance(x, str) and x.startswith("-") and not response:
                opt = a.option(valid)
                if opt in ("-file", "-h5", "-hdf5"):
                    if "sink" in opts:
                        raise CommandError(f"{name}: give one output file (-file, -h5 or -hdf5)")
                    opts["sink"] = (opt, os.fspath(a.word(f"{opt} file name")))
                elif opt in ("-time", "-closeOnWrite"):
                    opts[opt] = True
                elif opt == "-precision":
                    opts[opt] = a.int("-precision")
                elif opt == "-dT":
                    opts[opt] = a.float("-dT")
                elif opt in ("-node", "-ele"):
                    targets += a.ints(f"{opt} tag")
                elif opt in ("-nodeRange", "-eleRange"):
                    lo, hi = a.int(f"{opt} start"), a.int(f"{opt} end")
                    pool = model.nodes if is_node else model.element_tags()
                    targets += [t for t in sorted(pool) if lo <= t <= hi]
                else:
                    opts["-dof"] = a.ints("-dof")
            else:
                response.append(a.take("response"))
        if not response:
            raise CommandError(f"{name}: no response given (e.g. 'disp' or 'force')")
        if len(response) > 1 or not isinstance(response[0], str):
            raise CommandError(f"{name}: response {' '.join(map(str, response))!r} is not supported; supported: "
                               + (", ".join(NODE_RESPONSES) if is_node else "force, globalForce, localForce, "
                                  "basicForce, deformation, axialForce (as the element type offers)"))
        response = response[0]
        envelope = kind.startswith("Envelope")
        if is_node:
            if response not in NODE_RESPONSES:
                raise CommandError(f"{name}: response {response!r} is not supported; supported: "
                                   f"{', '.join(NODE_RESPONSES)}")
            nodes = targets or sorted(model.nodes)
            for n in nodes:
                self._node(name, n)
            dofs = opts.get("-dof")
            if not dofs:
                raise CommandError(f"{name}: no dofs (-dof 1 2 ...)")
            for d in dofs:
                if not 1 <= d <= model.ndf:
                    raise CommandError(f"{name}: dof {d} is out of range 1..{model.ndf}")
            make = lambda s: rec.NodeRecorder(nodes, dofs, response, sink=s, dt=opts["-dT"],
                                              envelope=envelope, history=not envelope)
        else:
            response = ELEMENT_RESPONSE_ALIASES.get(response, response)
            elements = targets or model.element_tags()
            if not elements:
                raise CommandError(f"{name}: no elements to record")
            for e in elements:
                if e not in model._element_owner:
                    raise CommandError(f"{name}: element {e} does not exist")
            make = lambda s: _command_element_recorder(self, elements, response, sink=s, dt=opts["-dT"],
                                                       envelope=envelope, history=not envelope)
        return self._register_recorder(make(self._recorder_sink(name, opts)))

    def _register_recorder(self, recorder):
        """Give ``recorder`` the next tag (OpenSees: a counter wipe() does not reset), keep it open
        across analyze() calls, and return the tag."""
        tag = self._recorder_count
        self._recorder_count += 1
        recorder.tag = tag
        self.recorders[tag] = recorder
        self._kept[tag] = _KeptOpen(recorder)
        return tag

    def _recorder_sink(self, name, opts):
        from vtsi import recorders as rec

        if "sink" not in opts:
            return rec.MemorySink()
        opt, path = opts["sink"]
        if opt == "-file":
            if opts["-precision"] < 1:
                raise CommandError(f"{name}: -precision must be >= 1, got {opts['-precision']}")
            return rec.TextSink(path, time=opts["-time"], precision=opts["-precision"],
                                close_on_write=opts["-closeOnWrite"])
        return rec.HDF5Sink(path)

    # -- removal ---------------------------------------------------------------------------------
    def remove(self, *args):
        """``remove('recorders')`` (every recorder, files closed), ``remove('recorder', tag)``,
        ``remove('loadPattern', tag)`` or ``remove('element', tag)``."""
        a = _Args("remove", args)
        what = a.word("object type", ("recorders", "recorder", "loadPattern", "element"))
        if what == "recorders":
            a.done()
            for tag in list(self.recorders):
                del self.recorders[tag]
                self._kept.pop(tag).finish()
            return
        tag = a.int(f"{what} tag")
        a.done()
        if what == "recorder":
            if tag not in self.recorders:
                raise CommandError(f"remove recorder: recorder {tag} does not exist")
            del self.recorders[tag]
            self._kept.pop(tag).finish()
            return
        model = self._model("remove")
        if what == "loadPattern":
            if tag not in model.patterns:
                raise CommandError(f"remove loadPattern: pattern {tag} does not exist")
            model.remove_pattern(tag)
            if self._current_pattern == tag:
                self._current_pattern = None
        else:
            if tag not in model._element_owner:
                raise CommandError(f"remove element: element {tag} does not exist")
            model.remove_element(tag)
            self._zero_length.pop(tag, None)

    def wipe(self):
        """Delete everything: model, materials, series, patterns, analysis and recorders (their
        files are closed). Recorder tags keep counting up, as in OpenSees."""
        kept, self._kept, self.recorders = list(self._kept.values()), {}, {}
        try:
            for r in kept:
                r.finish()
        finally:
            self._clear()


def _apply_layout(layout, values, rates=None):
    """Columns ``(n, len(columns))`` of a :meth:`Session._layout` from ``values (n, width)`` (and
    their rates, the same response evaluated on velocities)."""
    _source, columns, _uses_rates = layout
    out = np.zeros((values.shape[0], len(columns)))
    for j, (src, cu, cv) in enumerate(columns):
        if src >= 0:
            out[:, j] = cu * values[:, src] + (cv * rates[:, src] if cv else 0.0)
    return out


_ELEMENT_RECORDER_CLASS = []


def _command_element_recorder(session, elements, response, **kwargs):
    """An :class:`~vtsi.recorders.ElementRecorder` whose columns are laid out as OpenSees writes
    them (see :meth:`Session._layout`)."""
    if not _ELEMENT_RECORDER_CLASS:
        from vtsi.recorders import ElementRecorder

        class CommandElementRecorder(ElementRecorder):
            """Records the vtsi response the layouts need (``deformation`` for a zeroLength's
            basic quantities, also on the velocities) and rearranges its columns."""

            def __init__(self, session, elements, response, layouts, **kw):
                self.opensees_response = response
                self._layouts = layouts
                source = {layout[0] for layout in layouts if layout is not None}
                if len(source) > 1 or (source and any(layout is None for layout in layouts)):
                    raise CommandError(f"recorder Element {response}: the elements {list(elements)} need different "
                                       "responses; record them with separate recorders")
                super().__init__(elements, source.pop() if source else response, **kw)
                self._rate_columns = None

            def requests(self, assembly):
                requests = super().requests(assembly)
                index = {key: k for k, key in enumerate(requests)}
                # the same columns with every displacement replaced by its velocity
                self._rate_columns = np.array([index.get(("v", full), k) if q == "u" else k
                                               for k, (q, full) in enumerate(requests)], dtype=np.int64)
                return requests

            def _spans(self):
                start, spans = 0, []
                for k in range(len(self.elements)):
                    width = int(self._widths[k])
                    spans.append((start, width))
                    start += width
                return spans

            def prepare(self, assembly, model):
                layout = super().prepare(assembly, model)
                if all(x is None for x in self._layouts):
                    return layout
                ref, names = [], []
                for (start, width), lay, tag in zip(self._spans(), self._layouts, self.elements):
                    for j, (src, _cu, _cv) in enumerate(lay[1]):
                        ref.append(start + (src if src >= 0 else 0))
                        names.append(f"{self.opensees_response}_{j + 1}")
                layout["response"] = self.opensees_response
                layout["units"] = [layout["units"][r] for r in ref]
                columns = {name: np.asarray(col)[ref] for name, col in layout["columns"].items()}
                if "component_name" in columns:
                    columns["component_name"] = np.array(names)
                if "component" in columns:
                    columns["component"] = np.concatenate([np.arange(1, len(lay[1]) + 1) for lay in self._layouts])
                layout["columns"] = columns
                return layout

            def compute(self, times, columns, assembly):
                values = super().compute(times, columns, assembly)
                if all(x is None for x in self._layouts):
                    return values
                rates = None
                if any(lay[2] for lay in self._layouts):
                    rates = super().compute(times, columns[:, self._rate_columns], assembly)
                parts = []
                for (start, width), lay in zip(self._spans(), self._layouts):
                    block = values[:, start: start + width]
                    parts.append(_apply_layout(lay, block, None if rates is None else rates[:, start: start + width]))
                return np.hstack(parts)

        _ELEMENT_RECORDER_CLASS.append(CommandElementRecorder)
    asm = session.domain.build()
    layouts = []
    for tag in elements:
        b, _ = asm.element_location[tag]
        layouts.append(session._layout(asm.blocks[b][0], tag, response, asm.ndf))
    return _ELEMENT_RECORDER_CLASS[0](session, elements, response, layouts, **kwargs)


def _tcl_split(text):
    """Split a Tcl-like word list (``'Path -dt 0.1 -values {1 2 3}'``) into typed words."""
    from vtsi.tcl import convert_word, split_list

    return [convert_word(w) for w in split_list(text)]


# ---------------------------------------------------------------------------------------------
# module-level commands delegating to the current session
# ---------------------------------------------------------------------------------------------
session = Session()
"""The default session; replace it (``ops.session = ops.Session()``) to start afresh."""


def set_session(new):
    """Make ``new`` (a :class:`Session`) the target of the module-level commands; returns the old one."""
    global session
    if not isinstance(new, Session):
        raise TypeError(f"set_session: expected a Session, got {new!r}")
    old, session = session, new
    return old


def _delegate(name):
    method = getattr(Session, name)

    def command(*args, **kwargs):
        return getattr(session, name)(*args, **kwargs)

    command.__name__ = command.__qualname__ = name
    command.__doc__ = method.__doc__
    return command


for _name in COMMANDS:
    globals()[_name] = _delegate(_name)
del _name


def __getattr__(name):
    if name.startswith("__"):
        raise AttributeError(name)
    raise UnknownCommand(f"vtsi.opensees has no command {name!r}; supported commands: {', '.join(COMMANDS)}")


def __dir__():
    return sorted(list(globals()) + list(COMMANDS))
