"""Analysis commands: ``constraints``, ``numberer``, ``system``, ``test``, ``algorithm``,
``integrator``, ``analysis``, ``analyze``, ``eigen``, ``modalDamping``, with OpenSees's time
bookkeeping (step times accumulated as OpenSees adds them) and its one-sub-step ``TRBDF2``."""
import logging

import numpy as np

from vtsi.analysis import StaticAnalysis, TransientAnalysis, _RecorderFeed, domain_state, factor
from vtsi.analysis import eigen as _eigen
from vtsi.banded import solve_band
from vtsi.errors import AnalysisError, CommandError, DivergenceError, ModelError
from vtsi.integrators import HHT, Bathe, CentralDifference, Newmark
from vtsi.modal_bridge import ModalBridge

from .args import Args
from .base import SessionBase

log = logging.getLogger(__name__)

ANALYSIS_COMMANDS = ("constraints", "numberer", "system", "test", "algorithm", "integrator", "analysis",
                     "analyze", "eigen", "modalDamping", "wipeAnalysis")
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


class CommandTransient(TransientAnalysis):
    """A :class:`~vtsi.TransientAnalysis` whose step times are accumulated as OpenSees does
    (``t += Δt`` each step; HHT: ``t += αΔt`` then ``t += (1-α)Δt``), so that a Path series
    evaluated at its last sample gives OpenSees's value to the last bit."""

    def _increments(self):
        if isinstance(self.integrator, HHT):
            a = self.integrator.alpha
            return (a * self.dt, (1.0 - a) * self.dt)
        return (self.dt,)

    def step_times(self, t0, n):
        """``(n + 1,)`` times ``t_0 .. t_n`` [s] accumulated in floating point like OpenSees."""
        inc = self._increments()
        seq = np.empty(n * len(inc) + 1)
        seq[0] = t0
        seq[1:] = np.tile(inc, n)
        return np.cumsum(seq)[:: len(inc)]


class OpenSeesTRBDF2:
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



class AnalysisCommands(SessionBase):
    """The analysis settings, ``analyze``, ``eigen`` and ``modalDamping``."""

    def _clear_results(self):
        self._eigen = None
        self._modal_damping = None  # (assembly, ratios, modal bridge) of the last modalDamping
        self._load_time = None      # time at which the domain last applied its loads

    def _clear_analysis(self):
        self._settings = {"constraints": "Plain", "numberer": "RCM", "system": "BandGeneral",
                          "test": None, "algorithm": ("Newton",)}
        self._static_integrator = None
        self._transient_integrator = None
        self._analysis = None
        self._transient = None
        self._trbdf2 = None
        self._repeat, self._repeat_run = None, None    # the last transient analyze (see _repeat_key)

    def constraints(self, *args):
        """``constraints('Plain'|'Transformation')`` (only single-point constraints exist: both
        eliminate the fixed dofs)."""
        a = Args("constraints", args)
        self._settings["constraints"] = a.word("handler", CONSTRAINT_HANDLERS)
        a.done()

    def numberer(self, *args):
        """``numberer('Plain'|'RCM'|'AMD')`` (vtsi always numbers by reverse Cuthill-McKee)."""
        a = Args("numberer", args)
        self._settings["numberer"] = a.word("numberer", NUMBERERS)
        a.done()

    def system(self, *args):
        """``system(...)``: any of :data:`SYSTEMS`; vtsi solves with its banded Cholesky solver."""
        a = Args("system", args)
        self._settings["system"] = a.word("system", SYSTEMS)
        a.done()

    def test(self, *args):
        """``test(type, tol, maxIter, [printFlag, normType])``: checked and kept; a linear model
        converges in one pass, so it never fails."""
        a = Args("test", args)
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
        a = Args("algorithm", args)
        kind = a.word("algorithm", tuple(ALGORITHMS))
        flags = []
        while a.more():
            flags.append(a.option(ALGORITHMS[kind] or ("(no options)",)))
        self._settings["algorithm"] = (kind, *flags)

    def integrator(self, *args):
        """``integrator('LoadControl', dλ)``, ``('Newmark', gamma, beta)``, ``('HHT', alpha, [gamma,
        beta])``, ``('CentralDifference')``, ``('TRBDF2')`` or vtsi's ``('Bathe', [gamma])``."""
        a = Args("integrator", args)
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
        self._trbdf2 = OpenSeesTRBDF2() if kind == "TRBDF2" else None

    def analysis(self, *args):
        """``analysis('Static'|'Transient')``."""
        a = Args("analysis", args)
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

    def _repeat_key(self, args):
        """What a transient ``analyze`` call resolves to besides the model's own state: the same
        key as the last call's means the same checks pass and the same analysis runs (a per-step
        loop), so :meth:`analyze` goes straight to it."""
        model = self.domain
        integrator, constraint, modal = self._transient_integrator, self._constraint, self._modal_damping
        return (args, model, model.build() if model is not None and model.nodes else None, self._analysis,
                id(integrator), integrator, id(constraint), constraint, id(modal), modal, self._recorder_count,
                len(self._kept))

    def analyze(self, *args):
        """``analyze(numSteps)`` (static) or ``analyze(numSteps, dt)`` (transient); returns 0.
        A failure raises (an :class:`~vtsi.errors.AnalysisError`) instead of returning a code."""
        key = self._repeat_key(args)
        if key == self._repeat:
            return self._run_transient(*self._repeat_run)
        model = self._model("analyze")
        a = Args("analyze", args)
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
            self._transient = CommandTransient(model, integ, bridge=bridge)
        analysis = self._transient
        analysis.set_dt(dt)
        analysis.recorders = self._recorder_list()
        self._repeat, self._repeat_run = None, (analysis, n, kind, integ, dt)
        self._run_transient(*self._repeat_run)
        self._repeat = key
        return 0

    def _run_transient(self, analysis, n, kind, integ, dt):
        state = analysis.run(n)
        if n > 0:   # when the domain last applied its loads (OpenSees: the nodes' unbalanced load)
            if kind == "HHT":
                self._load_time = analysis.last_step_start + integ.alpha * dt
            elif kind == "CentralDifference":
                self._load_time = analysis.last_step_start
            else:
                self._load_time = state.time
        return 0

    def eigen(self, *args):
        """``eigen([solver,] n)``: the ``n`` lowest eigenvalues ω² [rad²/s²] as a list; solvers
        ``'-genBandArpack'`` (default) and ``'-fullGenLapack'``. Vectors are mass-normalised."""
        model = self._model("eigen")
        a = Args("eigen", args)
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
        a = Args("modalDamping", args)
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

