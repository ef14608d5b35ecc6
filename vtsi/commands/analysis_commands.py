"""Analysis commands: ``constraints``, ``numberer``, ``system``, ``test``, ``algorithm``,
``integrator``, ``analysis``, ``analyze``, ``eigen``, ``modalDamping``, with OpenSees's time
bookkeeping (step times accumulated as OpenSees adds them) and its one-sub-step ``TRBDF2``."""
import logging

import numpy as np

from vtsi.analysis import StaticAnalysis, TransientAnalysis, domain_state, pattern_factors
from vtsi.analysis import eigen as _eigen
from vtsi.errors import AnalysisError, CommandError, DivergenceError, ModelError
from vtsi.integrators import HHT, TRBDF2, Bathe, CentralDifference, GeneralizedAlpha, Newmark, make_integrator
from vtsi.integrators import INTEGRATORS as REGISTERED
from vtsi.modal_bridge import ModalBridge
from vtsi.recorders.node import REACTIONS

from .args import Args
from .base import Placeholder, SessionBase

log = logging.getLogger(__name__)

ANALYSIS_COMMANDS = ("constraints", "numberer", "system", "test", "algorithm", "integrator", "analysis",
                     "analyze", "eigen", "modalDamping", "wipeAnalysis")
CONSTRAINT_HANDLERS = ("Plain", "Transformation")
NUMBERERS = ("Plain", "RCM", "AMD")
SYSTEMS = ("BandSPD", "BandGeneral", "BandGen", "ProfileSPD", "SparseGeneral", "SparseGEN", "SparseSPD", "UmfPack",
           "Umfpack", "SuperLU", "Mumps", "FullGeneral", "SparseSYM")
"""OpenSees's direct solvers (OpenSeesPy 3.7.1 accepts each name); vtsi solves with its own."""
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
INTEGRATORS = ("LoadControl", "Newmark", "HHT", "GeneralizedAlpha", "CentralDifference", "TRBDF2", "Bathe")
# ^ the names with OpenSees's (and Bathe's) argument conventions; any other registered integrator
#   (vtsi.integrators.register) is built by name from its positional numbers
ANALYSES = ("Static", "Transient")
EIGEN_SOLVERS = ("-genBandArpack", "-fullGenLapack")


def equilibrium_point(integrator):
    """The fraction α of the step where HHT (α) and the generalized-α method (αF) balance the
    loads, None for the other schemes."""
    if isinstance(integrator, HHT):
        return integrator.alpha
    if isinstance(integrator, GeneralizedAlpha):
        return integrator.alpha_f
    return None


def same_modes(old, new):
    """Whether two builds of a model (:class:`~vtsi.assembly.Assembly`) have the same modes: the
    same nodes, free dofs, constraints, K and M, to the bit (they may differ in their damping C,
    which ``rayleigh`` changes, and in their loads)."""
    if old is new:
        return True
    if (old.n_full != new.n_full or old.node_index != new.node_index
            or not np.array_equal(old.full_of_free, new.full_of_free)):
        return False
    pairs = [(old.K, new.K), (old.M, new.M)]
    if old.transformation is not None or new.transformation is not None:
        if old.transformation is None or new.transformation is None:
            return False
        pairs.append((old.transformation, new.transformation))
    return all(a.shape == b.shape and (a != b).nnz == 0 for a, b in pairs)


class CommandTransient(TransientAnalysis):
    """A :class:`~vtsi.TransientAnalysis` whose step times are accumulated as OpenSees does
    (``t += Δt`` each step; HHT and GeneralizedAlpha: ``t += αΔt`` then ``t += (1-α)Δt``, α
    their equilibrium point αF), so that a Path series evaluated at its last sample gives
    OpenSees's value to the last bit."""

    accumulated_times = True

    def _increments(self):
        a = equilibrium_point(self.integrator)
        if a is not None:
            return (a * self.dt, (1.0 - a) * self.dt)
        return (self.dt,)

    def step_times(self, t0, n):
        """``(n + 1,)`` times ``t_0 .. t_n`` [s] accumulated in floating point like OpenSees."""
        inc = self._increments()
        seq = np.empty(n * len(inc) + 1)
        seq[0] = t0
        seq[1:].reshape(n, len(inc))[:] = inc
        return np.cumsum(seq)[:: len(inc)]


class OpenSeesTRBDF2:
    """OpenSees's ``integrator TRBDF2``: every ``analyze`` step is one sub-step of size Δt,
    trapezoidal and BDF2 (three-point backward) alternating; a trapezoidal sub-step comes first
    and whenever Δt changes (``TRBDF2::newStep``); loads at each sub-step's end, time
    accumulated ``t += Δt``. A trapezoidal and the BDF2 sub-step after it are one composite step of
    :class:`vtsi.integrators.TRBDF2` (Bathe, γ = ½) of size 2Δt, so the compiled loop steps them,
    recording every sub-step; a run may start or end between the two, the bank keeping the
    composite step's start and first sub-step in between. As in OpenSees, the BDF2 sub-step
    follows whatever the loads did in between (``loadConst``, ``remove loadPattern``, a new
    pattern, ``setTime``): it needs only the two states before it. vtsi restarts with a
    trapezoidal sub-step where that history is gone: a new Δt (as OpenSees), a change of the
    model's dofs, K, C or M, or a committed state other than the one the trapezoidal sub-step
    left (:meth:`_resumes`)."""

    def __init__(self, model):
        self.analysis = CommandTransient(model, TRBDF2())
        self.resume = None      # the run plan whose bank holds the trapezoidal sub-step a run ended on

    def run(self, n, dt, recorders):
        """``n`` sub-steps of ``dt`` [s] from the model's committed state; returns the state."""
        analysis = self.analysis
        if 2.0 * dt != analysis.dt:
            self.resume = None
        analysis.set_dt(2.0 * dt)
        analysis.recorders = recorders
        plan = analysis._plan()
        state = domain_state(analysis.model)
        if not plan.fe:
            raise CommandError("analyze: integrator TRBDF2 does not step a modal bridge (modalDamping); "
                               "use Newmark, HHT or Bathe")
        first = 1 if self._resumes(plan, state) else 0
        plan.info.update(dt=dt, integrator="TRBDF2 (OpenSees: a sub-step per step)")
        feed = plan.start_feed()
        try:
            if n == 0:
                return state
            n_steps = (first + n + 1) // 2
            times = np.cumsum(np.r_[state.time, np.full(n, dt)])      # sub-step ends, as OpenSees adds them
            g = first + np.arange(n)                                  # (composite step, stage) of each sub-step
            table = np.zeros((n_steps, 2, len(plan.patterns)))
            table[g // 2, g % 2] = pattern_factors(plan.patterns, times[1:], analysis._path_tables)
            span = np.array([first, (first + n) - 2 * (n_steps - 1), 1], dtype=np.int64)
            try:
                moved = not plan.run_rows(state, times, table, span, 1, times[-1])
            except DivergenceError as exc:     # the model is at the last good sub-step: go on from it
                self.resume = plan if (first + exc.step - 1) % 2 == 1 else None
                raise
            if moved:
                raise CommandError("analyze: integrator TRBDF2: a dof at rest was moved between two analyze calls; "
                                   "call wipeAnalysis() and define the analysis again")
            self.resume = plan if (first + n) % 2 == 1 else None
        finally:
            feed.close()
        return state

    def _resumes(self, plan, state):
        """Whether the next sub-step is the BDF2 one of the composite step whose trapezoidal
        sub-step the last run ended on (OpenSees's ``TRBDF2::newStep``: Δt unchanged): that run's
        plan had the same assembly (same dofs, K, C, M; its patterns may differ) and left the
        committed free-dof state ``state``, and no dof moving in that step is at rest in ``plan``.
        Then the composite step's start and first sub-step (bank slots 0..5) are copied into
        ``plan``'s bank, dof by dof (its moving dofs may differ)."""
        old, self.resume = self.resume, None
        if old is None or old.asm is not plan.asm:
            return False
        free = plan.asm.full_of_free
        held = np.zeros((6, len(free)))
        b = old.bridge
        held[:, b.active] = old.bank[:6, b.kd: b.kd + b.n]
        if not all(np.array_equal(held[3 + i], x[free]) for i, x in enumerate((state.u, state.v, state.a))):
            return False
        b = plan.bridge
        outside = np.ones(len(free), dtype=bool)
        outside[b.active] = False
        if held[:, outside].any():
            return False
        plan.bank[:6, b.kd: b.kd + b.n] = held[:, b.active]
        return True


class LoadControl:
    """OpenSees's ``integrator LoadControl dλ [numIter minλ maxλ]`` (``LoadControl::newStep``):
    each step first scales the increment by ``numIter / J``, J the iterations (updates) of the last
    step (``numIter`` before the first), then clips it to [minλ, maxλ] (both dλ without the
    optional arguments: a constant increment), and the load factor (time) advances by it."""

    def __init__(self, d_lambda, num_iter=1, low=None, high=None):
        self.d_lambda, self.num_iter = float(d_lambda), float(num_iter)
        self.low = self.d_lambda if low is None else float(low)
        self.high = self.d_lambda if high is None else float(high)
        self.last_iterations = self.num_iter      # OpenSees's numIncrLastStep
        self.name = (f"integrator LoadControl {d_lambda:g}" if low is None else
                     f"integrator LoadControl {d_lambda:g} {num_iter} {self.low:g} {self.high:g}")

    @property
    def constant(self):
        """Whether every step's increment is the same whatever the iterations (minλ = maxλ)."""
        return self.low == self.high

    def next_increment(self, iterations):
        """The increment [-] of the next step, which then takes ``iterations`` updates (OpenSees
        counts them in ``LoadControl::update``; the first step scales by numIter / numIter)."""
        self.d_lambda *= self.num_iter / self.last_iterations
        if self.d_lambda < self.low:
            self.d_lambda = self.low
        elif self.d_lambda > self.high:
            self.d_lambda = self.high
        self.last_iterations = float(iterations)
        return self.d_lambda


class AnalysisCommands(SessionBase):
    """The analysis settings, ``analyze``, ``eigen`` and ``modalDamping``."""

    def _clear_results(self):
        self._eigen = None          # (assembly, omega2, shapes) of the last eigen
        self._modal_damping = None  # (ratios, eigen, assembly, modal bridge): see _modal_bridge
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
        """``constraints('Plain'|'Transformation')``: both eliminate the fixed dofs, and the dofs of
        ``equalDOF``/``rigidLink`` by OpenSees's transformation (OpenSees's Plain handler would
        refuse those; vtsi accepts them under either name)."""
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
        a.command = f"algorithm {kind}"
        if a.more() and not ALGORITHMS[kind]:
            raise CommandError(f"{a.command}: takes no options in vtsi (a linear model is solved exactly in one "
                               f"pass), got {a.peek()!r}")
        flags = []
        while a.more():
            flags.append(a.option(ALGORITHMS[kind]))
        self._settings["algorithm"] = (kind, *flags)

    def integrator(self, *args):
        """``integrator('LoadControl', dλ, [numIter, minλ, maxλ])`` (:class:`LoadControl`), ``('Newmark', gamma, beta)``, ``('HHT', alpha, [gamma,
        beta])``, ``('GeneralizedAlpha', alphaM, alphaF, [beta, gamma])`` (OpenSees's order), ``('CentralDifference')``, ``('TRBDF2')`` or vtsi's ``('Bathe', [gamma])``;
        any other integrator registered with :func:`vtsi.integrators.register` by its name and
        positional numbers, ``('WilsonTheta', 1.4)`` = ``WilsonTheta(1.4)``."""
        a = Args("integrator", args)
        user = sorted(set(REGISTERED) - set(INTEGRATORS))
        kind = a.word("integrator", INTEGRATORS + tuple(user))
        name = f"integrator {kind}"
        a.command = name
        if kind in user:
            params = a.floats("parameter")
            a.done()
            self._transient_integrator = (kind, make_integrator(kind, *params))   # its own checks: AnalysisError
            self._transient = None
            self._trbdf2 = None
            return
        if kind == "LoadControl":
            d_lambda = a.float("load increment")
            if not a.more():
                self._static_integrator = LoadControl(d_lambda)
                return
            extra = a.items[a.pos:]
            if len(extra) != 3:
                raise CommandError(f"{name}: expected dLambda [numIter minLambda maxLambda] (the three together; "
                                   f"OpenSees ignores one or two), got {list(args[1:])!r}")
            num_iter, low, high = a.int("numIter"), a.float("minLambda"), a.float("maxLambda")
            if num_iter < 1:
                raise CommandError(f"{name}: numIter must be >= 1, got {num_iter}")
            if low > high:
                raise CommandError(f"{name}: minLambda = {low:g} is above maxLambda = {high:g}")
            self._static_integrator = LoadControl(d_lambda, num_iter, low, high)
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
        elif kind == "GeneralizedAlpha":
            # OpenSees reads the optional pair as beta then gamma (its usage message says gamma beta)
            alpha_m, alpha_f = a.float("alphaM"), a.float("alphaF")
            beta, gamma = (a.float("beta"), a.float("gamma")) if a.more() else (None, None)
            spec = (kind, GeneralizedAlpha(alpha_m, alpha_f, gamma, beta))
        elif kind == "CentralDifference":
            spec = (kind, CentralDifference())
        elif kind == "TRBDF2":
            spec = (kind, None)
        else:
            spec = (kind, Bathe(a.float("gamma")) if a.more() else Bathe())
        a.done()
        self._transient_integrator = spec
        self._transient = None
        self._trbdf2 = None

    def analysis(self, *args):
        """``analysis('Static'|'Transient')``."""
        a = Args("analysis", args)
        kind = a.word("analysis type", ANALYSES)
        a.done()
        self._analysis = kind
        if kind == "Static" and self._static_integrator is None:
            log.info("analysis Static: no static integrator set, using LoadControl 1.0 (as OpenSees)")
            self._static_integrator = LoadControl(1.0)
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
                id(integrator), integrator, id(constraint), constraint, id(modal), modal, id(self._eigen),
                self._eigen, self._recorder_count, len(self._kept))

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
            raise CommandError(f"analyze: no analysis defined; "
                               f"{self._command_hint(('analysis', 'Static'), ('analysis', 'Transient'))} first")
        if not model.nodes:
            raise CommandError("analyze: the model has no nodes")
        if self._analysis == "Static":
            if self._constraint is not None:
                passage = (self._command_hint(("analysis", "Transient"), verb="") + " + "
                           + self._command_hint(("analyze", Placeholder("n"), Placeholder("dt")), verb=""))
                raise CommandError("analyze: a Static analysis would ignore the train of the movingLoadConstraint; "
                                   f"the train's dead load is {self._command_hint(('deadLoad',), verb='')} "
                                   f"(docs/commands.md, Trains), its passage {passage}")
            if a.more():
                a.float("dt")   # OpenSees accepts and ignores a dt in a static analysis
            a.done()
            control = self._static_integrator
            recorders = self._recorder_list()
            if control.constant:
                StaticAnalysis(model, control.low, recorders).run(n)
            else:
                if self._settings["algorithm"][0] != "Linear":
                    linear = self._command_hint(("algorithm", "Linear"), verb="")
                    raise CommandError(f"analyze: {control.name}: OpenSees scales dLambda by numIter / (the iterations "
                                       f"of the last step), and algorithm {self._settings['algorithm'][0]} takes a "
                                       "number that depends on its test and on round-off (vtsi solves each step "
                                       f"exactly in one pass); use {linear} (one iteration a step, as "
                                       "OpenSees's Linear), or minLambda = maxLambda (a constant increment)")
                for _ in range(n):
                    StaticAnalysis(model, control.next_increment(1), recorders).run(1)
            if n > 0:       # analyze(0) applies no loads, as OpenSees
                self._load_time = domain_state(model).time
            return 0
        if not a.more():
            usage = self._command_hint(("analyze", Placeholder("numSteps"), Placeholder("dt")), verb="")
            raise CommandError(f"analyze: a transient analysis needs the time step: {usage}")
        dt = a.float("dt")
        a.done()
        if not dt > 0.0:
            raise CommandError(f"analyze: dt must be > 0, got {dt:g}")
        if self._constraint is not None:
            return self._analyze_coupled(n, dt)
        kind, integ = self._transient_integrator
        if kind == "TRBDF2":
            if self._trbdf2 is None or self._trbdf2.analysis.model is not model:
                self._trbdf2 = OpenSeesTRBDF2(model)
            state = self._trbdf2.run(n, dt, self._recorder_list())
            if n > 0:
                self._load_time = state.time
            return 0
        bridge = self._modal_bridge("analyze")
        if self._transient is None or self._transient.bridge is not bridge:
            self._transient = CommandTransient(model, integ, bridge=bridge)
        analysis = self._transient
        analysis.set_dt(dt)
        analysis.recorders = self._recorder_list()
        reactions = [r for r in (getattr(kept, "recorder", kept) for kept in analysis.recorders)
                     if getattr(r, "response", None) in REACTIONS]
        self._repeat, self._repeat_run = None, (analysis, n, kind, integ, dt, reactions)
        self._run_transient(*self._repeat_run)
        self._repeat = key
        return 0

    def _run_transient(self, analysis, n, kind, integ, dt, reactions):
        """Run ``n`` steps of the transient ``analysis`` and set the load time; ``reactions``:
        its recorders of reactions (whose last record has OpenSees apply the loads again)."""
        state = analysis.run(n)
        if n > 0:   # when the domain last applied its loads (OpenSees: the nodes' unbalanced load)
            if kind in ("HHT", "GeneralizedAlpha"):
                t = analysis.last_step_start + equilibrium_point(integ) * dt
            elif kind == "CentralDifference":
                t = analysis.last_step_start
            else:
                t = state.time
            # a reaction recorder that recorded the last step had OpenSees apply the loads again at
            # its time first (Domain::calculateNodalReactions), as the reactions command does
            if reactions and any(r.last_time is not None and abs(r.last_time - state.time) <= 1e-9 * dt
                                 for r in reactions):
                t = state.time
            self._load_time = t
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
        self._assembly("eigen")
        omega2, shapes = _eigen(model, n)
        self._eigen = (model.build(), omega2, shapes)
        log.debug("eigen %s: %d modes", solver, n)
        return [float(w) for w in omega2]

    def modalDamping(self, *args):
        """``modalDamping(zeta)`` or ``modalDamping(zeta_1, ..., zeta_k)``: damping ratios [-], one
        for all or one per mode of the last ``eigen`` (its n modes: one ratio stands for n equal
        ones; k < n ratios damp the first k modes and leave the others undamped, as OpenSees's
        ``OPS_modalDamping`` sets them to 0; k > n is refused: OpenSees writes the extra ratios past
        the end of its vector). As in OpenSees, the ratios are kept and damp the modes of the
        latest ``eigen`` when the model is stepped: after a change of the model (masses, elements) and a new ``eigen``,
        the first min(n, that eigen's number of modes) of the new modes. The damping is added to
        the model's own (Rayleigh): C = M Φ diag(2ζω) Φᵀ M. vtsi then steps the model as a modal bridge of
        every mode of finite frequency (:class:`~vtsi.modal_bridge.ModalBridge`, ``n_modes='all'``):
        the model's own equations, a dof without mass following statically, so the model's own
        damping must be classical (Rayleigh) and no load may act on a dof without mass. Equal to
        OpenSees with nodal masses (``mass``); with element mass (``-mass``, ``-rho``) OpenSees's
        modal damping force differs from this C by a fraction of a percent (docs/commands.md)."""
        self._model("modalDamping")
        a = Args("modalDamping", args)
        ratios = [a.float("damping ratio")]
        while a.more():
            ratios.append(a.float("damping ratio"))
        a.done()
        if self._eigen is None:
            raise CommandError(f"modalDamping: no modes; {self._command_hint(('eigen', Placeholder('n')))} first "
                               "(the ratios apply to its modes)")
        n = len(self._eigen[1])
        if len(ratios) > n:
            raise CommandError(f"modalDamping: {len(ratios)} ratios for the {n} modes of the last eigen; give at most "
                               f"{n} (OpenSees warns that it ignores the extra ones, but writes them past the end of "
                               "its vector of ratios: a wrong damping and a corrupted heap)")
        bad = [z for z in ratios if not (np.isfinite(z) and z >= 0.0)]
        if bad:
            raise CommandError(f"modalDamping: a damping ratio must be >= 0 (0.05 for 5 %), got {bad[0]:g}")
        over = [z for z in ratios if z >= 1.0]
        if over:
            raise CommandError(f"modalDamping: damping ratio {over[0]:g} is {100 * over[0]:g} % of critical (an "
                               f"overdamped mode); a ratio is a fraction: {over[0] / 100:g} for {over[0]:g} %. "
                               "vtsi takes ratios in [0, 1), as its other damping inputs (OpenSees takes any)")
        if len(ratios) == 1:
            ratios *= n
        self._modal_damping = (np.array(ratios + [0.0] * (n - len(ratios))), None, None, None)
        self._transient = None

    def _damped_modes(self, command):
        """``(omega2 (k,) [rad²/s²], ratios (k,) [-])``: the modes that ``modalDamping``'s ratios
        damp, as OpenSees: the first k = min(number of ratios, n) of the n modes of the latest
        ``eigen``. A CommandError naming ``command`` when the model's modes changed after that
        ``eigen`` (OpenSees would damp the modes of a model that is no more)."""
        ratios = self._modal_damping[0]
        asm, omega2, _ = self._eigen
        if not same_modes(asm, self._model(command).build()):
            raise CommandError(f"{command}: the model changed after the last eigen (its dofs, stiffness or mass), "
                               f"whose modes modalDamping damps; {self._command_hint(('eigen', Placeholder('n')))} "
                               "again")
        k = min(len(ratios), len(omega2))
        return omega2[:k], ratios[:k]

    def _modal_bridge(self, command):
        """The modal bridge that ``modalDamping`` asks for (None without it), built once per
        ``eigen`` and build of the model (:meth:`_damped_modes`): a change that keeps the modes
        (``rayleigh``: only C) builds it again with the same ratios, as OpenSees applies both; a
        new ``eigen`` after a change of the modes gives the ratios to the new modes."""
        if self._modal_damping is None:
            return None
        ratios, eigen, asm, bridge = self._modal_damping
        model = self._model(command)
        current = model.build()
        if eigen is self._eigen and asm is current:
            return bridge
        damped = self._damped_modes(command)[1]
        massless = np.flatnonzero(current.M.diagonal() <= 0.0)
        with_c = massless[np.abs(current.C[massless]).sum(axis=1).A1 > 0.0] if len(massless) else massless
        if len(with_c):
            raise CommandError(f"{command}: modalDamping: {current.dof_label(with_c[0])} has damping (rayleigh "
                               "betaK) but no mass; vtsi steps the modes of the model, where a dof without "
                               "mass follows statically (give it mass, or use rayleigh alphaM only)")
        try:
            bridge = ModalBridge(model, n_modes="all")
            bridge.add_ratios(damped)
        except (ModelError, AnalysisError) as exc:
            raise CommandError(f"{command}: modalDamping: {exc}") from None
        self._modal_damping = (ratios, self._eigen, current, bridge)
        return bridge

