"""Coupled train-bridge transient analysis (Fedorova & Sivaselvan 2017; docs/theory/coupled_step.md).

Bridge and train are separate subdomains; the wheel-rail contact forces are the Lagrange
multipliers of a :class:`~vtsi.constraint.MovingLoadConstraint`. Every effective matrix is
factored once per analysis, the bridge flexibility on the track dofs is precomputed once per
stage, and the steps run in compiled chunks (:mod:`vtsi.coupled_loop`).

References
----------
Fedorova, M., Sivaselvan, M.V. (2017) An algorithm for dynamic vehicle-track-structure
interaction analysis for high-speed trains. Engineering Structures 148, 857-877.
"""
import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csgraph

from vtsi.analysis import (
    BLOCK_STEPS,
    _integer,
    _pattern_loads,
    _RecorderFeed,
    _recorders,
    any_nonzero,
    component_labels,
    domain_state,
    load_factor_table,
    moving_dofs,
)
from vtsi.banded import (
    NotPositiveDefinite,
    band_rows,
    band_type,
    half_bandwidth,
    inverse_columns,
    ldl_band,
)
from vtsi.constraint import MovingLoadConstraint
from vtsi.contact import contact_events, contact_summary, gap_tolerance
from vtsi.coupled_loop import run_coupled_steps
from vtsi.errors import AnalysisError, DivergenceError, ModelError, as_flag, as_positive
from vtsi.integrators import HHT, make_integrator
from vtsi.lcp import lcp_workspace
from vtsi.recorders.moment import add_train_loads, fixed_end_forces
from vtsi.subdomain import BridgeStageCache, FEStages, stage_key
from vtsi.timeloop import stage_operators
from vtsi.vehicle import GRAVITY

CONTACT_STRATEGIES = ("bilateral", "lcp")
LCP_DEFAULT_ALPHA = 0.9      # HHT's α when contact='lcp' and no integrator is given
STEPS_ON_TRACK = 10          # an axle takes at least 10 steps of Δt to cross the track (a sweep's passage too)
CURVATURE_STEP = 1e-4        # [m] central-difference step of smoothed rows' curvature under a wheel at the start


def coupled_integrator(integrator, contact, who="CoupledAnalysis"):
    """The integrator of a coupled analysis: ``integrator`` (name, class or instance) or, for
    None, the default of the contact strategy — Newmark's average acceleration with bilateral
    contact, HHT(α = 0.9) with contact='lcp'. With contact='lcp' a scheme without numerical
    dissipation (not :attr:`~vtsi.integrators.Integrator.dissipative`: the Newmark family with
    γ = 1/2, as Newmark's trapezoidal rule, HHT with α = 1, central differences) is refused: its contact force rings undamped after any jump of the rail's curvature (a bump's
    edge, a span's end) and the LCP reads the negative swings as lift-offs (measured on a wheel
    over a 10 mm, 2 m cosine bump at 20–40 m/s and Δt = 1–0.25 ms: up to 46 lift-off and landing
    events instead of the two of its one flight, the first lift-off up to 20 % of the flight
    early; docs/theory/contact.md)."""
    if integrator is None:
        integrator = HHT(LCP_DEFAULT_ALPHA) if contact == "lcp" else "Newmark"
    integ = make_integrator(integrator)
    if contact == "lcp" and not integ.dissipative:
        raise AnalysisError(f"{who}: contact='lcp' needs a dissipative integrator; {integ!r} (no damping of the "
                            "highest frequencies, as Newmark's with γ = 1/2) lets the "
                            "contact force ring after a jump of the rail's curvature and gives spurious lift-offs. "
                            f"Use HHT({LCP_DEFAULT_ALPHA}) (the default with contact='lcp'), 'Bathe', or a damped "
                            "Newmark such as Newmark(0.6, 0.3025)")
    return integ
TRAIN_QUANTITIES = {"train_u": 0, "train_v": 1, "train_a": 2}
JOIN_CHUNKS = 512       # chunks of the records joined at a time while they are not read (CoupledAnalysis._keep)


class CoupledAnalysis:
    """Transient analysis of a bridge model with a train tied to it.

    Parameters
    ----------
    model : Model (the bridge, with its track elements).
    constraint : MovingLoadConstraint (holds the Track and the TrainSubdomain).
    integrator : name, class or instance ('Newmark', HHT(0.9), 'Bathe', ...); None: Newmark
        (average acceleration) with bilateral contact, HHT(0.9) with contact='lcp', which refuses
        an integrator without numerical dissipation (:func:`coupled_integrator`).
    dt : time step [s] (required: finite, > 0). ``dt`` and ``integrator`` may be assigned
        between runs (or :meth:`set_dt`): the next run prepares the factors for them, as a new
        analysis from the committed state.
    contact : 'bilateral' (wheels always on the rail) or 'lcp' (contact loss allowed).
    gravity : g [m/s²] (finite, >= 0) for the bridge's weight ``-g M 1_y`` with
        ``bridge_self_weight`` (the train's weight is its gravity_load, used as built).
    bridge_self_weight : add the bridge's own weight to the dead load (results are then totals;
        without it — the default — they are the response to the train and the load patterns, the
        part a dynamic check of the deck uses; ``load_description`` says which). The
        rail is straight at the deck's self-weight state (the track is laid on the deflected
        deck): the constraint measures the rail from that deflected line.
    recorders : a list of bridge recorders (:mod:`vtsi.recorders`) and train/contact recorders
        (anything else, or one recorder not in a list: an AnalysisError when built), whose
        requests may name 'u', 'v', 'a' (bridge full dof), 'train_u', 'train_v', 'train_a'
        (train dof) or 'contact_force', 'gap' (contact wheel index). The analysis hands them
        ``coupled_loads`` (:class:`CoupledLoads`) when it starts them: reactions and bending
        moments take the train's loads and the bridge's own weight from there.
    divergence_limit : |u| [m] beyond which a step counts as diverged.
    gap_tol : position gap [m] above which a wheel counts as in flight (contact='lcp'); a wheel
        less high is put back on the rail. A round-off guard: 0 to vtsi.contact.MAX_GAP_TOL (1e-6 m, far
        below a lift-off of interest, >= 0.1 mm).
    exact_events : kinks of the rail line ('hermite' rows: a span's end on a support next to rigid
        ground or to another span's end, and the kinks the rail profile declares,
        :meth:`~vtsi.models.Irregularity.from_function`). False (default): a wheel takes the kink at the end of
        the step that contains it, a first-order error in the train's response (its dampers see
        the wheel's velocity jump at the wrong time). True: that step keeps the wheel on its old
        line, then its velocity jump (a perfectly inelastic impulse, as R1) is applied with a
        timing correction and a consistent restart of its car: second order, no extra
        factorisation; the impulse is recorded as impulse/Δt in that step's λ, and Newmark's
        λ no longer rings after a kink (docs/theory/coupled_step.md §6). contact='lcp' with
        'hermite' rows refuses a profile that declares kinks without it (an AnalysisError naming
        them): the LCP would take a kink's impulse as a force of one step, and the integrator's
        memory of it throws the wheel off (docs/theory/contact.md §4).
    bridge_cache : a :class:`~vtsi.subdomain.BridgeStageCache` shared by analyses of one bridge
        (a sweep's passages): the bridge's factors and track flexibilities are computed once per
        model version, integrator, Δt, track and set of moving dofs, whatever train crosses, and a
        train's (:class:`TrainStages`) once per integrator and Δt, whatever its speed.
    bridge : None (the FE model) or a :class:`~vtsi.modal_bridge.ModalBridge` of the model: the
        bridge is then stepped in its modal coordinates, the constraint rows become rows of Φ at
        the wheel positions (:mod:`vtsi.subdomain`), the recorders read Φ q.

    After :meth:`run`, ``time``, ``contact_force`` (n_steps, n_c) [N, compression positive:
    each step's mean force, its impulse / Δt — for Bathe (λ_n + λ_γ + λ_{n+1})/3, for the Newmark
    family λ_{n+1}, :meth:`~vtsi.integrators.base.Integrator.force_record_weights`],
    ``contact_force_end`` (the end of step's λ_{n+1}) and ``gap`` (n_steps, n_c) [m, end of step]
    hold every step of the run; :meth:`contact_events` and
    :meth:`contact_summary` derive lift-offs, landings and per-wheel figures from them
    (:mod:`vtsi.contact`).
    """

    def __init__(self, model, constraint, integrator=None, dt=None, contact="bilateral",
                 gravity=GRAVITY, bridge_self_weight=False, recorders=(), divergence_limit=1e3,
                 chunk_steps=2000, gap_tol=1e-9, exact_events=False, bridge_cache=None, bridge=None):
        if not isinstance(constraint, MovingLoadConstraint):
            raise ModelError(f"CoupledAnalysis: constraint must be a MovingLoadConstraint, got {type(constraint).__name__}")
        if contact not in CONTACT_STRATEGIES:
            spelt = [c for c in CONTACT_STRATEGIES if isinstance(contact, str) and c == contact.strip().lower()]
            hint = f" (names are case-sensitive: contact={spelt[0]!r})" if spelt else ""
            raise AnalysisError(f"CoupledAnalysis: unknown contact strategy {contact!r}; "
                                f"valid: {', '.join(CONTACT_STRATEGIES)}{hint}")
        self.model, self.constraint, self.contact = model, constraint, contact
        self.train = constraint.train
        offsets = self.train.train.car_offsets
        if np.any(offsets < 0.0):
            car = int(np.flatnonzero(offsets < 0.0)[0])
            raise ModelError(f"CoupledAnalysis: car {car} of train {self.train.train.name!r} has the offset "
                             f"{offsets[car]:g} m; car offsets are measured behind the train's head and must be >= 0")
        self._prepared = self._dt = self._integrator = None
        self.integrator = integrator
        self.gravity = as_positive(gravity, "CoupledAnalysis", "gravity [m/s²]", AnalysisError, allow_zero=True)
        self.bridge_self_weight = as_flag(bridge_self_weight, "CoupledAnalysis", "bridge_self_weight", AnalysisError)
        self.recorders = _recorders("CoupledAnalysis", recorders)   # also refuses two recorders writing one file
        self.chunk_steps = _integer("CoupledAnalysis", "chunk_steps", chunk_steps, 1)
        self.divergence_limit = as_positive(divergence_limit, "CoupledAnalysis", "divergence_limit", AnalysisError,
                                            finite=False)
        self.set_dt(dt)
        self._path_tables = {}
        self._sag = None
        self._diverged = None      # where a run diverged ("step N, t = … s"): no run goes on from there
        self.static_state = None
        self.reset_records()
        self._lcp_work = lcp_workspace(constraint.n_contact)
        self.gap_tol = gap_tolerance(gap_tol, "CoupledAnalysis", AnalysisError)
        if not isinstance(exact_events, (bool, np.bool_)):
            raise AnalysisError(f"CoupledAnalysis: exact_events must be True or False, got {exact_events!r}")
        self.exact_events = bool(exact_events)
        kinks = _declared_kinks(constraint)
        if contact == "lcp" and len(kinks) and constraint.interpolation == "hermite" and not self.exact_events:
            shown = ", ".join(f"{x:g}" for x in kinks[:4]) + (f", ... ({len(kinks)} kinks)" if len(kinks) > 4 else "")
            raise AnalysisError(f"CoupledAnalysis: the rail profile kinks at x = {shown} m; contact='lcp' with "
                                "'hermite' rows would take each kink's impulse as a force of one step and throw "
                                "the wheels off the rail: give exact_events=True (each kink an event) or "
                                "interpolation='bspline'")
        self.in_contact = np.ones(constraint.n_contact)
        if bridge_cache is None:
            bridge_cache = BridgeStageCache()
        if not isinstance(bridge_cache, BridgeStageCache):
            raise AnalysisError(f"CoupledAnalysis: bridge_cache must be a BridgeStageCache, got {type(bridge_cache).__name__}")
        self.bridge_cache = bridge_cache
        if bridge is not None and not hasattr(bridge, "stages"):
            raise AnalysisError(f"CoupledAnalysis: bridge must be None or a ModalBridge, got {type(bridge).__name__}")
        self.bridge = bridge
        self.stages = None
        self.coupled_loads = CoupledLoads(constraint)
        self._kept_plan = None     # what a run needs, kept for the runs that follow (_plan)

    def __repr__(self):
        steps = sum(len(chunk[0]) for chunk in self._records)
        run = f"{steps} steps to t = {self._records[-1][0][-1]:g} s" if steps else "0 steps"
        bridge = f", modal bridge of {self.bridge.n_modes} modes" if self.bridge is not None else ""
        return (f"CoupledAnalysis(train {self.train.train.name!r} on {len(self.constraint.track.elements)} track "
                f"elements{bridge}, {self.integrator!r}, dt = {self._dt:g} s, contact={self.contact!r}, {run}, "
                f"{len(self.recorders)} recorders)")

    @property
    def dt(self):
        """The time step [s]; assigning it is :meth:`set_dt`."""
        return self._dt

    @dt.setter
    def dt(self, dt):
        self.set_dt(dt)

    def set_dt(self, dt):
        """Set the time step ``dt`` [s] (a finite number > 0, else AnalysisError naming the value).
        A new value drops the prepared factors (the next run or :meth:`static` prepares them for
        it, as a new analysis from the committed state would); the same value changes nothing."""
        dt = as_positive(dt, "CoupledAnalysis", "dt", AnalysisError)
        if dt != self._dt:
            self._dt, self._prepared = dt, None

    @property
    def integrator(self):
        """The integrator (an instance); assigning a name, class or instance
        (:func:`coupled_integrator`, refused if explicit) drops the prepared factors as
        :meth:`set_dt` does."""
        return self._integrator

    @integrator.setter
    def integrator(self, integrator):
        integ = coupled_integrator(integrator, self.contact)
        if integ.explicit:
            why = " with beta = 0 (central differences)" if integ.name == "Newmark" else ""
            raise AnalysisError(f"CoupledAnalysis: {integ.name}{why} is explicit; a constrained "
                                "analysis needs an implicit integrator: Newmark with beta > 0 (e.g. Newmark(0.5, "
                                "0.25)), HHT or Bathe")
        if integ is not self._integrator:
            self._integrator, self._prepared = integ, None

    # -- preparation ----------------------------------------------------------------------
    def _bridge_constant_load(self, asm):
        """Bridge self weight on the free dofs (zero unless ``bridge_self_weight``)."""
        if not self.bridge_self_weight:
            return np.zeros(asm.n_free)
        return self._self_weight(asm)[asm.full_of_free]

    def _self_weight(self, asm):
        """The bridge's own weight ``-g M 1_y`` on every dof (n_full,) [N], supports included."""
        ones_y = np.zeros(asm.n_full)
        ones_y[1::asm.ndf] = 1.0
        return -self.gravity * (asm.M_full @ ones_y)

    def _rail_sag(self, t, nu):
        """``(N(x) u_sw)`` (nu = 0) or its rate (nu = 1) under the contact wheels at times ``t``
        (any shape) [m, m/s]: the deck's self-weight deflection, from which the rail is measured
        (the track is laid on the deflected deck, so the rail is straight at that state)."""
        return self._sag_at(self.constraint.positions(t), nu)

    def _sag_at(self, x, nu):
        """:meth:`_rail_sag` at positions ``x`` (any shape) [m]."""
        con = self.constraint
        if self._sag is None or con.n_contact == 0:
            return np.zeros_like(x)
        cols, vals, slopes = con.track.rows(x.ravel(), con.knot(self.dt))
        sag = np.where(cols >= 0, self._sag[np.maximum(cols, 0)], 0.0)
        rows = vals if nu == 0 else con.train.speed * slopes
        return np.einsum("ij,ij->i", rows, sag).reshape(x.shape)

    def _prepare(self, loaded=None):
        """The bridge stages (:mod:`vtsi.subdomain`, shared through ``bridge_cache``) and the
        train's factors, flexibilities and stage data. The FE bridge integrates the dofs that can
        move (:func:`vtsi.analysis.moving_dofs`: the components holding a track dof, a load — the
        self weight too, ``loaded`` the patterns' loaded dofs if known — or a nonzero state)."""
        asm = self.model.build()
        integ, dt, train, track = self.integrator, self.dt, self.train, self.constraint.track
        self_weight = self._bridge_constant_load(asm) if self.bridge_self_weight else None
        if self.bridge is not None:
            self.bridge.check_model(self.model)
            if self._prepared is asm and self.stages is not None:
                return asm
            bridge = self.bridge_cache.get(self.bridge, stage_key(integ, dt, track, None, self_weight),
                                           lambda: self.bridge.stages(integ, dt, track, self_weight))
        else:
            seeds = self._bridge_constant_load(asm) != 0.0
            seeds[track.free_index] = True
            active = moving_dofs(asm, self.model, seeds, loaded)
            if self._prepared is asm and np.array_equal(active, self.stages.active):
                return asm
            bridge = self.bridge_cache.get(asm, stage_key(integ, dt, track, active, self_weight),
                                           lambda: FEStages(asm, active, integ, dt, track, self_weight))
        self.stages = bridge
        stages = integ.checked_stages(dt)       # contract: force_weight > 0 (the loop divides by it), ...

        def build():                # the train's stability limit, then its factors: once per train in a sweep
            check_train_stability(train, integ, dt, bridge, track)
            return TrainStages(train, stages, integ.n_slots)

        source = asm if self.bridge is None else self.bridge     # the train's entry goes with the bridge's
        t = self.bridge_cache.get(source, train_stage_key(integ, dt, train, track), build) if train.n_dof else build()
        self.fac_t, self.tflex, self.ops_t, self.weights_t = t.fac, t.flex, t.ops, t.weights
        self.wheel_response, self.response_range = t.wheel_response, t.response_range
        self.group_ptr, self.group_wheel, self.ground_inv = t.group_ptr, t.group_wheel, t.ground_inv
        pack = lambda name: np.ascontiguousarray(np.stack([getattr(st, name) for st in stages]))
        self.du, self.dv = pack("du"), pack("dv")
        self.stage_theta = np.array([st.theta for st in stages])
        self.force_weight = np.array([st.force_weight for st in stages])
        self.mass_weight = np.array([st.mass_weight for st in stages])     # 1 but for generalized-α (1/αM)
        self.record_weights = np.ascontiguousarray(integ.force_record_weights(), dtype=np.float64)
        n_q = max(len(st.load) for st in stages)
        self.load_theta = np.zeros((len(stages), n_q))
        self.load_weight = np.zeros((len(stages), n_q))
        for s, st in enumerate(stages):
            for q, (theta, w) in enumerate(st.load):
                self.load_theta[s, q], self.load_weight[s, q] = theta, w
        self._sag = bridge.track_sag
        self._kinks, self._profile_kinks = self._kink_positions()
        self._cars = {}
        self._prepared = asm
        return asm

    def prepare(self):
        """Factor and precompute now (otherwise the first :meth:`static` or :meth:`run` does);
        with a shared ``bridge_cache`` the bridge's part is then ready for every analysis."""
        self._prepare()

    @property
    def active(self):
        """The free dofs the FE bridge integrates (after a run)."""
        return self.stages.active

    @property
    def load_description(self):
        """What the results contain (recorders store it with their metadata, ``loads``)."""
        return ("the train's weight and axle forces, the load patterns"
                + (" and the bridge's self weight (totals)" if self.bridge_self_weight
                   else "; not the bridge's self weight (bridge_self_weight=False)"))

    # -- dead load ------------------------------------------------------------------------
    def static(self, patterns_at=None):
        """Static equilibrium of bridge and train under the train's weight (and the patterns at the
        current time, or at ``patterns_at`` [s] when given; the bridge's own weight only with
        ``bridge_self_weight``) with the wheels on the rail where they are at the current time:
        sets the committed states and ``static_state`` (whose ``loads`` says what it contains).

        The bridge starts at rest. The wheels move with the rail (ġ = 0: v_w = V N'(x) u_b + ṙ
        where the rail under them is deflected, sloping or irregular), and the rest of the train
        follows them quasi-statically, v_o = −K_oo⁻¹ K_ow v_w (the train's stiffness split into
        its other dofs o and its wheels w), so that a train can start on a deflected or sloping
        rail without its suspension seeing a velocity jump at t = 0. The train's accelerations
        are consistent with that start (:meth:`_start_accelerations`: the wheels follow the
        rail's curvature; ``static_state['start_force']`` the contact forces they take, beside the
        static ``contact_force``); the bridge's accelerations start at 0."""
        asm = self.model.build()
        state = domain_state(self.model)
        train, con = self.train, self.constraint
        t = state.time
        self._prepare()
        bridge = self.stages
        n_b, n_t, n_c = bridge.stiffness.shape[0], train.n_dof, con.n_contact
        sol = self._static_solution(asm, t, t if patterns_at is None else patterns_at)
        state.u[:], state.v[:], state.a[:] = 0.0, 0.0, 0.0
        state.u[asm.full_of_free] = bridge.static_free(sol[:n_b])
        train.u[:] = sol[n_b: n_b + n_t]
        train.v[:] = 0.0
        train.a[:] = 0.0
        if n_c:
            cols, _, slopes, _ = con.rows_at(t, self.dt)
            u_track = np.where(cols >= 0, (bridge.track_operator @ sol[:n_b])[np.maximum(cols, 0)], 0.0)
            rate = con.irregularity_at(np.array(t), self.dt, 1) - self._rail_sag(np.array(t), 1)
            train.v[train.wheel_dofs] = train.speed * np.einsum("ij,ij->i", slopes, u_track) + rate
            train.v[:] = self._quasi_static_rates(train.v[train.wheel_dofs])
            train.a[:] = self._start_accelerations(t, bridge.track_operator @ sol[:n_b])
        contact = sol[n_b + n_t:].copy()
        self.coupled_loads.begin(con.knot(self.dt), self._self_weight(asm) if self.bridge_self_weight else None,
                                 self.bridge is not None and self.bridge.truncated)
        self.coupled_loads.deliver(np.array([t]), contact[None, :])     # the state's loads
        self.static_state = {"time": t, "bridge_u": state.u.copy(), "train_u": train.u.copy(),
                             "train_v": train.v.copy(), "train_a": train.a.copy(), "contact_force": contact,
                             "start_force": contact + (train.M @ train.a + train.C @ train.v)[train.wheel_dofs],
                             "loads": self.load_description}
        self._new_start()
        return self.static_state

    def _start_accelerations(self, t, track_u):
        """Train accelerations (n_t,) [m/s², rad/s²] consistent with the start at time ``t`` [s]:
        each contact wheel on the rail's curvature, a_w = V² (N''(x) u + r''(x)) (``track_u``
        the bridge's track dofs, held at rest; N'' u by :meth:`_rail_curvature`), and every
        other dof with mass from its equation of motion,
        M_oo a_o = −M_ow a_w − (C v)_o (its static forces balance). Zero accelerations on an
        irregular rail made the undamped trapezoidal rule ring at period 2Δt for ever: ±0.17
        m/s² on the wheels and up to 43 % of the contact force's response to a sine rail."""
        train, con = self.train, self.constraint
        x = con.positions(np.array(t))
        deflection = track_u if self._sag is None else track_u - self._sag     # the rail is laid on the sag
        a = np.zeros(train.n_dof)
        a[train.wheel_dofs] = (train.speed ** 2 * self._rail_curvature(x, deflection)
                               + con.irregularity_at(np.array(t), self.dt, 2))
        others = np.setdiff1d(np.arange(train.n_dof), train.wheel_dofs)
        M = train.M.toarray()              # a train's few dofs, once per start
        heavy = others[np.abs(M[others]).sum(axis=1) > 0.0]
        if len(heavy):
            a[heavy] = np.linalg.solve(M[np.ix_(heavy, heavy)], -(M[heavy] @ a + (train.C @ train.v)[heavy]))
        return a

    def _rail_curvature(self, x, values):
        """N''(x) · ``values`` (n_track,) under the contact wheels at ``x`` [m]: with Hermite rows
        their curvature in the element under each wheel (at a node the element that starts there,
        so the kink where the rail meets rigid ground or two spans meet is no curvature: central
        differences across it gave a wheel at a span's end V²θ/2h, −1868 m/s²); with smoothed
        rows central differences of their slopes (smooth across a kink)."""
        con = self.constraint
        track, knot = con.track, con.knot(self.dt)
        if knot > 0.0:
            h = CURVATURE_STEP
            slopes = []
            for z in (x + h, x - h):
                cols, _, rows = track.rows(z, knot)
                slopes.append(np.einsum("ij,ij->i", rows, np.where(cols >= 0, values[np.maximum(cols, 0)], 0.0)))
            return (slopes[0] - slopes[1]) / (2 * h)
        out = np.zeros(len(x))
        for i, xi in enumerate(x):
            row = track.hermite_row(xi)
            if row is not None:
                out[i] = sum(c * values[d] for c, d in zip(row[3], row[0]) if d >= 0)
        return out

    def _quasi_static_rates(self, wheel_v):
        """Train velocities (n_t,) [m/s, rad/s] with the contact wheels at ``wheel_v`` and every
        other dof following them statically: v_o = −K_oo⁻¹ K_ow v_w."""
        train = self.train
        v = np.zeros(train.n_dof)
        v[train.wheel_dofs] = wheel_v
        if not np.any(wheel_v):
            return v
        others = np.setdiff1d(np.arange(train.n_dof), train.wheel_dofs)
        if len(others):
            K = train.K.tocsr()
            k_oo, k_ow = K[others][:, others].tocsc(), K[others][:, train.wheel_dofs]
            with np.errstate(all="ignore"):
                try:
                    v[others] = -spla.spsolve(k_oo, k_ow @ wheel_v)
                except RuntimeError:
                    v[others] = np.nan
            if not np.all(np.isfinite(v)):
                raise AnalysisError("dead load: a train dof is held by no spring once its wheels are on the rail")
        return v

    def _static_solution(self, asm, t, t_patterns):
        """``(bridge coordinates, train dofs, contact forces)`` of the static equilibrium with the
        wheels where they are at time ``t`` [s] and the patterns' loads at ``t_patterns`` [s]."""
        train, con, track, bridge = self.train, self.constraint, self.constraint.track, self.stages
        p_b = self._bridge_constant_load(asm)
        for pattern in self.model.patterns.values():
            p_b = p_b + pattern.factors(np.array([t_patterns]))[0] * asm.load_vector(pattern)
        if len(con.x0_force):
            cols, vals, _ = track.rows(con.x0_force + train.speed * t)
            for i, f in enumerate(train.wheel_forces):
                keep = cols[i] >= 0
                np.add.at(p_b, track.free_index[cols[i][keep]], -f * vals[i][keep])
        K_b, p_b = bridge.stiffness, bridge.static_load(p_b)
        n_t, n_c = train.n_dof, con.n_contact
        cols, vals, _, r = con.rows_at(t, self.dt)
        r = r - self._rail_sag(np.array(t), 0)
        keep = cols >= 0
        N = sp.csr_matrix((vals[keep], (np.nonzero(keep)[0], cols[keep])), shape=(n_c, track.n_track)) \
            @ bridge.track_operator if n_c else None
        S = sp.csr_matrix((np.ones(n_c), (np.arange(n_c), train.wheel_dofs)), shape=(n_c, n_t))
        big = sp.bmat([[K_b, None, N.T], [None, train.K if n_t else None, -S.T if n_t else None],
                       [N, -S if n_t else None, None]], format="csc") if n_c else \
            sp.bmat([[K_b, None], [None, train.K]], format="csc") if n_t else sp.csc_matrix(K_b)
        rhs = np.concatenate([p_b, train.gravity_load, -r])[: big.shape[0]]
        with np.errstate(all="ignore"):
            try:
                sol = spla.spsolve(big, rhs)
            except RuntimeError:
                sol = np.full(big.shape[0], np.nan)
        if not np.all(np.isfinite(sol)) or np.linalg.norm(big @ sol - rhs) > 1e-8 * max(np.linalg.norm(rhs), 1.0):
            raise AnalysisError("dead load: the static train-bridge system is singular (a bridge mechanism, "
                                "or a train dof held by neither a spring nor a wheel)")
        return np.atleast_1d(sol)

    def start_from(self, static_state):
        """Set the committed states to a dead-load state that :meth:`static` returned for this
        model and train (a sweep computes one train's dead-load state once and starts each of
        its passages from it: valid while the wheels start at the same positions, on rigid
        ground, where the state does not depend on the speed)."""
        state = domain_state(self.model)
        train = self.train
        if (static_state["bridge_u"].shape != state.u.shape or static_state["train_u"].shape != train.u.shape
                or static_state["contact_force"].shape != (self.constraint.n_contact,)):
            raise AnalysisError("CoupledAnalysis.start_from: the dead-load state is of another model or train")
        state.time = static_state["time"]
        state.u[:], state.v[:], state.a[:] = static_state["bridge_u"], 0.0, 0.0
        train.u[:], train.v[:], train.a[:] = static_state["train_u"], static_state["train_v"], static_state["train_a"]
        self.static_state = static_state
        self._new_start()

    def _new_start(self):
        """A new start (:meth:`static`, :meth:`start_from`): the next run counts its steps from it
        and takes its contact forces as those of the step before (:meth:`_previous_forces`)."""
        self._prev = None
        if self._kept_plan is not None:
            self._kept_plan.clock = self._kept_plan.kept_state = None

    # -- time stepping --------------------------------------------------------------------
    def _plan(self):
        """What a run needs (:class:`_CoupledPlan`), kept from run to run while the model's
        assembly and patterns (``Model.load_version``), dt, the integrator, the self weight, the
        bridge stages and the dofs at rest stay the same (its recorder feed while the recorders do)."""
        asm = self.model.build()
        key = (asm, self.model.load_version, self.dt, self.integrator, self.bridge_self_weight, self.gravity)
        plan = self._kept_plan
        if plan is not None and plan.rest_full is not None:
            state = domain_state(self.model)
            moved = any_nonzero(state.u, state.v, state.a, plan.rest_full)    # a dof at rest has moved
        else:
            moved = False
        if plan is None or plan.key != key or self._prepared is not asm or plan.bridge is not self.stages or moved:
            self._check_resolution()
            patterns = list(self.model.patterns.values())
            loads = _pattern_loads(asm, patterns)
            asm = self._prepare(loads[1])
            plan = self._kept_plan = _CoupledPlan(self, key, asm, patterns, loads)
        recorders = tuple(self.recorders)
        if plan.recorders != recorders:
            plan.recorders, plan.feed = recorders, None
        return plan

    def _check_resolution(self):
        """An AnalysisError unless Δt resolves the passage by the sweep's rule: an axle crosses the
        track in at least STEPS_ON_TRACK steps (a train at rest takes any Δt)."""
        track, speed = self.constraint.track, self.train.speed
        crossing = (track.x_end - track.x_begin) / speed if speed > 0.0 else np.inf
        if crossing < STEPS_ON_TRACK * self.dt:
            raise AnalysisError(f"CoupledAnalysis: dt = {self.dt:g} s does not resolve the passage: the train at "
                                f"{speed:g} m/s crosses the {track.x_end - track.x_begin:g} m track in {crossing:.3g} s, "
                                f"fewer than {STEPS_ON_TRACK} steps of dt; take dt <= {crossing / STEPS_ON_TRACK:.3g} s")

    def run(self, n_steps):
        """Advance ``n_steps`` steps from the committed states (call :meth:`static` first for a
        start from the dead-load equilibrium). Returns the domain state. Refused after a run
        that diverged (its model stays at the start of the diverging chunk).

        The steps are counted in chunks of ``chunk_steps`` from a start t_c: stage θ of the
        chunk's step k is at t_o + ((k − o) + θ) Δt, t_o = t_c + o Δt, o = 0 or, with
        ``exact_events``, the step after the chunk's last kink crossing. A run that starts where
        the last one ended (at the time it committed, with the kept plan of :meth:`_plan`, no
        :meth:`static` or :meth:`start_from` since) continues that count, so that a run split
        into runs of any lengths (a script's ``analyze(1, dt)`` or ``analyze(10, dt)`` loop, a
        pause to read the state or change a recorder) gives one run's numbers to the bit: the
        same chunks, stage times and rows (each row a function of its time only,
        :meth:`_CoupledPlan.rows_of`); on a modal bridge it goes on from the modal coordinates
        the last run committed while the domain state is the one that run wrote
        (:meth:`_CoupledPlan.load_bridge`). Any other run counts from its own start. A per-step
        loop costs one compiled step and a constant per call: what a run needs and the coming
        steps' tables (load factors, rail data) are kept."""
        if not (type(n_steps) is int and n_steps >= 0):
            n_steps = _integer("CoupledAnalysis", "number of steps", n_steps, 0)
        if self._diverged is not None:
            raise AnalysisError(f"CoupledAnalysis: it diverged ({self._diverged}); a coupled analysis does not go on "
                                f"from a divergence (the recorders hold the steps before it, the model is at the "
                                f"start of their chunk): build a new one, e.g. with a smaller dt")
        plan = self._plan()
        state = domain_state(self.model)
        train, con, track = self.train, self.constraint, self.constraint.track
        con.check_travel(state.time, state.time + n_steps * self.dt, self.dt)
        asm, bridge, loads = plan.asm, plan.bridge, plan.loads
        kd_b, kd_t, n_t = bridge.kd, plan.kd_t, train.n_dof
        bank_b, bank_t = plan.bank_b, plan.bank_t
        plan.load_bridge(state)
        for slot, vec in enumerate((train.u, train.v, train.a)):
            bank_t[slot, kd_t: kd_t + n_t] = vec
        self.coupled_loads.begin(con.knot(self.dt), plan.self_weight, self.bridge is not None and self.bridge.truncated)
        feed = plan.start_feed()
        prev = self._previous_forces(plan.width)
        knot = con.knot(self.dt)

        def steps(lo, hi, origin, x0_c, r_part, rate_part):
            """Run the chunk's steps lo..hi - 1 (counted from the chunk's start, this call's from i)
            with the contact wheels at ``x0_c`` at t = 0 and the rail data ``r_part``,
            ``rate_part`` of those steps, their time counted from the chunk's step ``origin``; the
            loop's status, its step counted in this call."""
            a, b = lo - i, hi - i
            bad = run_coupled_steps(
                bank_b, bank_t, self.du, self.dv,
                bridge.fac, bridge.ops, bridge.weights, self.fac_t, self.ops_t, self.weights_t,
                table[a:b], *loads, train.gravity_load,
                bridge.flex, self.tflex, track.x_start, track.length, track.dofs, bridge.track_index,
                bridge.track_basis,
                x0_c, train.wheel_dofs, con.x0_force, train.wheel_forces, train.speed,
                knot, r_part, rate_part, t0 + origin * self.dt, lo - origin, self.dt, self.stage_theta,
                self.load_theta, self.load_weight, self.force_weight, self.mass_weight, self.record_weights,
                self.contact == "lcp",
                self.gap_tol,
                self.in_contact, plan.rec_slot, plan.rec_index, out_b[a:b], plan.t_slot, plan.t_index, out_t[a:b],
                out_force[a:b], out_force_end[a:b], out_gap[a:b], self.divergence_limit, plan.work_b, plan.work_t,
                *plan.rows, *plan.contact, self._lcp_work, plan.band_b, plan.band_t, *prev,
                self.group_ptr, self.group_wheel, self.ground_inv, self.wheel_response, self.response_range)
            return bad if bad == -1 else (bad + a if bad >= 0 else bad - a)

        done = 0
        try:
            while done < n_steps:
                t0, i, first = plan.chunk(state.time, self.chunk_steps)
                n = min(self.chunk_steps - i, n_steps - done)
                table, r_table, rate_table = plan.rows_of(t0, i, n, self.chunk_steps)
                out_b, out_t = np.zeros((n, len(plan.rec_slot))), np.zeros((n, len(plan.t_index)))
                out_force, out_gap, out_force_end = np.zeros((n, con.n_contact)), np.zeros((n, con.n_contact)), \
                    np.zeros((n, con.n_contact))
                events = [e for e in self._events(t0, i + n) if e[0] >= i]
                lo, bad = i, -1
                for k in sorted({e[0] for e in events}) + [i + n]:
                    if k > lo:
                        bad = steps(lo, k, first, con.x0, r_table[lo - i: k - i], rate_table[lo - i: k - i])
                        if bad != -1:
                            break
                    if k == i + n:
                        break
                    crossing = [e for e in events if e[0] == k and self.in_contact[e[2]] > 0.5]
                    x0_c, r_k, rate_k = self._old_line(crossing, t0 + k * self.dt, r_table[k - i: k - i + 1],
                                                       rate_table[k - i: k - i + 1])
                    bad = steps(k, k + 1, k, x0_c, r_k, rate_k)
                    if bad != -1:
                        break
                    for _, theta, w, x in crossing:
                        # recorded as its impulse spread over the step (as a landing, docs/theory/contact.md)
                        out_force[k - i, w] += self._cross(bank_b, bank_t, kd_b, kd_t, w, x, (1.0 - theta) * self.dt,
                                                           prev) / self.dt
                    lo = first = k + 1
                good = n if bad == -1 else (bad if bad >= 0 else -2 - bad)
                times = t0 + self.dt * np.arange(i + 1, i + good + 1)
                self._keep((times, out_force[:good], out_force_end[:good], out_gap[:good]))
                if bad == -1:           # the chunk committed before the recorders get it: one that raises
                    bridge.commit(state, bank_b, asm.full_of_free, t0 + (i + n) * self.dt)   # leaves the analysis
                    for slot, vec in enumerate((train.u, train.v, train.a)):              # at its last row
                        vec[:] = bank_t[slot, kd_t: kd_t + n_t]
                    plan.committed(t0, i + n, first, state)
                    done += n
                else:
                    step, t_bad = done + good + 1, t0 + (i + good + 1) * self.dt
                    self._diverged = f"step {step}, t = {t_bad:.6g} s"
                self.coupled_loads.deliver(times, out_force_end[:good])
                if feed.recorders:
                    feed.deliver(times, bridge.recorded(out_b[:good]), asm, train=out_t[:good],
                                 contact_force=out_force[:good][:, plan.force_wheels],
                                 gap=out_gap[:good][:, plan.gap_wheels])
                if bad != -1:
                    if bad >= 0:
                        what = (f"|u| > {self.divergence_limit:g} m or NaN" if np.isfinite(self.divergence_limit)
                                else "NaN or inf")
                        raise DivergenceError(f"coupled analysis diverged at step {step} of this run, "
                                              f"t = {t_bad:.6g} s ({what}) with "
                                              f"{self.integrator!r}, dt = {self.dt:g} s", step, t_bad)
                    raise DivergenceError(f"coupled analysis: contact flexibility W is singular at step {step} of this run, "
                                          f"t = {t_bad:.6g} s", step, t_bad)
        finally:
            feed.close()
        return state

    # -- kinks of the rail line (span entry and exit, the profile's), exact_events ----------
    def _kink_positions(self):
        """``(kinks, profile_kinks)``: positions [m] (increasing) where the rail line kinks and a
        bilateral wheel's velocity jumps: the track chain's ends and the interior element ends
        whose rotation dofs differ (two spans on their own nodes), where the rail's uy is fixed
        (a support: the rows have no free entry there, so the bridge takes no impulse); and the
        rail profile's declared kinks where the rail is held (:func:`_declared_kinks`: on the
        rigid ground before and after the track, where the wheels follow the profile too, or at
        a support; :meth:`_events` keeps those a run reaches), also given alone. A profile kink
        where the rail moves would share its impulse with the bridge, which :meth:`_cross` does
        not model: with contact='lcp' an AnalysisError, bilateral the step takes it as without
        events. Only with ``exact_events`` and 'hermite' rows ('bspline' smooths the kink)."""
        con, track = self.constraint, self.constraint.track
        if not self.exact_events or con.interpolation != "hermite" or con.n_contact == 0:
            return np.zeros(0), np.zeros(0)
        d = track.dofs
        kinks = [track.x_begin] if d[0, 0] < 0 else []
        kinks += [track.x_start[e + 1] for e in range(len(d) - 1)
                  if d[e, 3] != d[e + 1, 1] and d[e, 2] < 0 and d[e + 1, 0] < 0]
        if d[-1, 2] < 0:
            kinks.append(track.x_end)
        profile = _declared_kinks(con)
        if len(profile):        # (a run without them keeps the track's list as it was)
            x_node = np.append(track.x_start, track.x_end)
            held = np.append(d[:, 0], d[-1, 2]) < 0       # nodes whose uy is fixed
            on_span = (profile > track.x_begin) & (profile < track.x_end) & ~np.isin(profile, x_node[held])
            if np.any(on_span):
                x = profile[on_span]
                if self.contact == "lcp":
                    raise AnalysisError(f"CoupledAnalysis: the rail profile kinks at x = {x[0]:g} m on the track where "
                                        "the rail moves (not at a support); exact_events takes a kink's impulse on "
                                        "the wheel's car alone, the bridge's share missing: use "
                                        "interpolation='bspline' (which smooths the kink)")
                profile = profile[~on_span]     # bilateral: the step takes them, the bridge sharing the impulse
            return np.union1d(kinks, profile), profile
        return np.array(kinks), profile

    def _events(self, t0, n):
        """Kink crossings in the steps (t0, t0 + n Δt]: sorted (step k, θ in (0, 1], wheel, x),
        the crossing at t0 + (k + θ) Δt."""
        if not len(self._kinks):
            return []
        te = (self._kinks[None, :] - self.constraint.x0[:, None]) / self.train.speed     # (n_c, n_kinks)
        f = (te - t0) / self.dt
        out = []
        for i, j in zip(*np.nonzero((f > 1e-9) & (f <= n + 1e-9))):
            k = int(np.ceil(f[i, j] - 1e-9)) - 1
            out.append((k, min(max(f[i, j] - k, 0.0), 1.0), int(i), float(self._kinks[j])))
        return sorted(out)

    def _old_line(self, crossing, t_step, r_step, rate_step):
        """Wheel start positions and rail data of a step in which the wheels of ``crossing`` stay
        on their old line to the step's end: each is moved back by the V (1 - θ) Δt it travels
        past its kink (and a hair), its rows and the self weight's sag with it, and at a kink of
        the profile the profile's r, V r' too (the side before the kink). A wheel crossing two
        kinks in the step goes back before the first once (the shifts summed put a wheel over a
        3 cm ramp at 30 m/s, Δt = 1 ms, 6 cm back: its car's velocity 26 % off)."""
        con, V = self.constraint, self.train.speed
        x0_c, r_step, rate_step = con.x0.copy(), r_step.copy(), rate_step.copy()
        shifts, profile = {}, set()
        for _, theta, i, x in crossing:
            shifts[i] = max(shifts.get(i, 0.0), (1.0 - theta) * self.dt * V + 1e-9 * max(1.0, abs(x)))
            if x in self._profile_kinks:
                profile.add(i)
        for i, shift in shifts.items():
            x0_c[i] -= shift
            xs = con.x0[i] + V * (t_step + self.stage_theta * self.dt)
            if self._sag is not None:
                r_step[0, :, i] += self._sag_at(xs, 0) - self._sag_at(xs - shift, 0)
                rate_step[0, :, i] += self._sag_at(xs, 1) - self._sag_at(xs - shift, 1)
            if i in profile:
                r_step[0, :, i] += con._profile(xs - shift, 0) - con._profile(xs, 0)
                rate_step[0, :, i] += V * (con._profile(xs - shift, 1) - con._profile(xs, 1))
        return x0_c, r_step, rate_step

    def _car(self, i):
        """Dense matrices of the car (block of the train's matrices) of contact wheel ``i``:
        its train dofs, the local index of the wheel and of the car's other wheels and dofs, M,
        C, K, the pseudo-inverses of M and M_oo (a massless wheel has a zero row)."""
        if i not in self._cars:
            train = self.train
            label = component_labels(train.M, train.C, train.K)
            dofs = np.flatnonzero(label == label[train.wheel_dofs[i]])
            wheels = np.flatnonzero(np.isin(dofs, train.wheel_dofs))
            others = np.setdiff1d(np.arange(len(dofs)), wheels)
            M, C, K = (m.tocsr()[dofs][:, dofs].toarray() for m in (train.M, train.C, train.K))
            self._cars[i] = {"dofs": dofs, "j": int(np.flatnonzero(dofs == train.wheel_dofs[i])[0]), "w": wheels,
                             "o": others, "M": M, "C": C, "K": K, "M_inv": np.linalg.pinv(M),
                             "M_oo_inv": np.linalg.pinv(M[np.ix_(others, others)])}
        return self._cars[i]

    def _cross(self, bank_b, bank_t, kd_b, kd_t, i, x, tau, prev):
        """Wheel ``i`` crossed the kink at ``x`` a time ``tau`` before the state in the banks,
        which kept it on its old line. Onto the new line (docs/theory/coupled_step.md §6), the
        rows and the profile's r, r', r'' past the kink: its position; its car's momentum from the
        dampers since the crossing, -C e_w Δv tau; its velocity jump by a perfectly inelastic
        impulse along e_w (its car only: the bridge takes
        none at a support; lumped car masses); consistent accelerations (the wheel's from the
        new rail line, the rest of the car from its equations) and λ (HHT carries it). With
        contact='lcp' a new line that falls away (an impulse that would pull) leaves the wheel
        in flight instead. Returns the contact impulse [N·s] (compression positive)."""
        con, train, track, V = self.constraint, self.train, self.constraint.track, self.train.speed
        n_b, n_t = self.stages.n, train.n_dof
        u_b, v_b, a_b = (self.stages.track_values(bank_b[s, kd_b: kd_b + n_b]) for s in range(3))
        if self._sag is not None:
            u_b = u_b - self._sag
        xp = x + V * tau + 1e-9 * max(1.0, abs(x))
        row = track.hermite_row(xp)
        wu = wv = wa = 0.0
        if row is not None:
            dofs, h0, h1, h2 = row
            ub, vb, ab = (np.where(dofs >= 0, vec[np.maximum(dofs, 0)], 0.0) for vec in (u_b, v_b, a_b))
            wu, wv, wa = h0 @ ub, h0 @ vb + V * h1 @ ub, h0 @ ab + 2.0 * V * h1 @ vb + V * V * h2 @ ub
        if con.irregularity is not None:
            r = [float(np.ravel(con._profile(np.array([xp]), nu))[0]) for nu in range(3)]
            wu, wv, wa = wu + r[0], wv + V * r[1], wa + V * V * r[2]
        car = self._car(i)
        d, j, o = car["dofs"], car["j"], car["o"]
        u_t, v_t, a_t = (bank_t[s, kd_t: kd_t + n_t] for s in range(3))
        if self.contact == "lcp" and wv < v_t[d[j]]:
            return 0.0  # the new line falls away under the wheel: it flies (the LCP takes it from here)
        u_c, v_c, a_c = u_t[d].copy(), v_t[d].copy(), a_t[d].copy()
        u_c[j] = wu
        v_c -= car["M_inv"] @ (car["C"][:, j] * ((wv - v_c[j]) * tau))
        impulse = 0.0
        if car["M_inv"][j, j] > 0.0:
            impulse = (wv - v_c[j]) / car["M_inv"][j, j]
            v_c += car["M_inv"][:, j] * impulse
        v_c[j] = wv
        a_c[j] = wa
        p_c = train.gravity_load[d]
        if len(o):
            rhs = p_c[o] - (car["C"] @ v_c)[o] - (car["K"] @ u_c)[o] - car["M"][np.ix_(o, car["w"])] @ a_c[car["w"]]
            a_c[o] = car["M_oo_inv"] @ rhs
        u_t[d], v_t[d], a_t[d] = u_c, v_c, a_c
        lam_prev, cols_prev, vals_prev = prev
        lam_prev[i] = float(car["M"][j] @ a_c + car["C"][j] @ v_c + car["K"][j] @ u_c - p_c[j])
        cols_prev[i, :], vals_prev[i, :] = -1, 0.0
        if row is not None:
            keep = row[0] >= 0
            cols_prev[i, : keep.sum()], vals_prev[i, : keep.sum()] = row[0][keep], row[1][keep]
        return impulse

    def reset_records(self):
        """Forget the recorded steps (``time``, ``contact_force``, ``contact_force_end``, ``gap``),
        e.g. before a run from a new start."""
        n_c = self.constraint.n_contact
        self._records = [(np.zeros(0), np.zeros((0, n_c)), np.zeros((0, n_c)), np.zeros((0, n_c)))]
        self._unjoined = 0

    def _keep(self, chunk):
        """Keep a chunk's ``(time, contact_force, contact_force_end, gap)``; the chunks are joined
        when read, and every JOIN_CHUNKS of them before (a per-step loop's chunks of one step
        would take some 0.5 kB each)."""
        self._records.append(chunk)
        self._unjoined += 1
        if self._unjoined == JOIN_CHUNKS:
            last = self._records[-JOIN_CHUNKS:]
            self._records[-JOIN_CHUNKS:] = [tuple(np.concatenate(parts) for parts in zip(*last))]
            self._unjoined = 0

    def _recorded(self, field):
        """Field ``field`` (0 time, 1 contact_force, 2 contact_force_end, 3 gap) of the steps run
        so far (the chunks joined once, when read)."""
        if len(self._records) > 1:
            self._records = [tuple(np.concatenate(parts) for parts in zip(*self._records))]
            self._unjoined = 0
        return self._records[0][field]

    @property
    def time(self):
        """(n_steps,) [s] the end time of every step run so far."""
        return self._recorded(0)

    @property
    def contact_force(self):
        """(n_steps, n_c) [N, compression positive] each step's mean contact force (see the class docstring)."""
        return self._recorded(1)

    @property
    def contact_force_end(self):
        """(n_steps, n_c) [N] the contact force at each step's end, λ_{n+1}."""
        return self._recorded(2)

    @property
    def gap(self):
        """(n_steps, n_c) [m] each wheel's position gap at each step's end (> 0 in flight)."""
        return self._recorded(3)

    # -- contact results ------------------------------------------------------------------
    def contact_events(self, interpolate=True):
        """Lift-off and landing events of the steps run so far (:func:`vtsi.contact.contact_events`)."""
        return contact_events(self, interpolate=interpolate)

    def contact_summary(self, static_load=None, interpolate=True):
        """Per-wheel separations, longest flight, force extremes and unloading ratio ΔQ/Q of the
        steps run so far (:func:`vtsi.contact.contact_summary`)."""
        return contact_summary(self, static_load=static_load, interpolate=interpolate)

    def _previous_forces(self, width):
        """``(λ, cols, vals)``: the contact forces [N] at the end of the last committed step and
        its rows, for integrators that weight them (HHT); after a new start (:meth:`static`,
        :meth:`start_from`) its ``start_force`` and the rows at the current time (zero forces
        without one). The kernel updates them in place at every step."""
        con = self.constraint
        prev = getattr(self, "_prev", None)
        if prev is None or prev[1].shape[1] != width:
            t = domain_state(self.model).time
            cols, vals = np.full((con.n_contact, width), -1, dtype=np.int64), np.zeros((con.n_contact, width))
            if con.n_contact:
                c0, v0, _, _ = con.rows_at(t, self.dt)
                cols[:, : c0.shape[1]], vals[:, : v0.shape[1]] = c0, v0
            if prev is not None:            # the last step's end force λ_{n+1}, on rows of another width
                lam = prev[0].copy()
            elif self.static_state is not None:
                lam = self.static_state["start_force"].copy()
            else:
                lam = np.zeros(con.n_contact)
            prev = self._prev = (lam, cols, vals)
        return prev


class _CoupledPlan:
    """One :class:`CoupledAnalysis`'s prepared run (as :class:`vtsi.analysis._RunPlan` is a
    transient analysis's): the loads on the bridge (the patterns' and its self weight), the state
    banks and scratch arrays of the compiled loop, the recorder feed and its columns; the count
    of the steps, ``clock`` = ``(t_c, i, origin, time)`` (the chunk's start [s], its steps run, its
    step the loop's time counts from, and the committed time [s] they reached), and a block of
    the chunk's tables (:meth:`rows_of`)."""

    def __init__(self, analysis, key, asm, patterns, loads):
        a = self.analysis = analysis
        self.key, self.asm, self.patterns = key, asm, patterns
        self.bridge = bridge = a.stages
        n_t, n_c = a.train.n_dof, a.constraint.n_contact
        constant = a._bridge_constant_load(asm)     # a last pattern of factor 1 (× the stage's mass weight)
        nz = np.flatnonzero(constant)
        ptr, dof, val = loads
        self.loads = bridge.loads(np.append(ptr, ptr[-1] + len(nz)), np.concatenate([dof, nz]).astype(np.int64),
                                  np.concatenate([val, constant[nz]]))
        self.self_weight = a._self_weight(asm) if a.bridge_self_weight else None
        self.kd_t = a.fac_t.shape[2] - 1
        size_b, size_t = bridge.n + 2 * bridge.kd, n_t + 2 * self.kd_t
        self.bank_b = np.zeros((a.integrator.n_slots, size_b))      # slots 0..2 loaded by every run
        self.bank_t = np.zeros((a.integrator.n_slots, size_t))
        self.work_b, self.work_t = np.zeros((3, size_b)), np.zeros((3, size_t))
        self.band_b, self.band_t = band_type(bridge.kd), band_type(self.kd_t)
        self.width = a.constraint.width(a.dt)
        self.rows = (np.empty((n_c, self.width), dtype=np.int64), np.empty((n_c, self.width)),
                     np.empty((n_c, self.width)))       # a stage's constraint rows: cols, vals, slopes
        self.contact = (np.zeros((n_c, n_c)), np.zeros(n_c), np.zeros(n_c))      # W, q, λ
        self.load_points = [st.load for st in a.integrator.stages(a.dt)]
        self.rest_full = bridge.rest_full if isinstance(bridge, FEStages) else None   # the dofs at rest a run checks
        self.info = {"analysis": "coupled", "integrator": repr(a.integrator), "dt": a.dt,
                     "loads": a.load_description, "coupled_loads": a.coupled_loads}
        self.recorders, self.feed = tuple(a.recorders), None
        self.clock = None
        self.kept_state = None      # (time, u, v, a) the last chunk committed (load_bridge)
        self.block = None       # (t_c, first row, table, r_table, rate_table) of chunk rows
        self.ahead = 1          # rows a run evaluates at least (the first its own, BLOCK_STEPS after it)

    def start_feed(self):
        """The recorder feed of a run: built (and its recorders started) once, restarted after."""
        if self.feed is not None:
            self.feed.start(self.info)
            return self.feed
        a = self.analysis
        n_t, n_c = a.train.n_dof, a.constraint.n_contact
        channels = {q: ("train", slot, n_t, "train dof") for q, slot in TRAIN_QUANTITIES.items()}
        channels.update({q: (q, 0, n_c, "contact wheel") for q in ("contact_force", "gap")})
        feed = self.feed = _RecorderFeed(self.asm, a.model, self.recorders, self.info, channels)
        self.t_slot, self.t_index = feed.group("train")
        self.force_wheels, self.gap_wheels = feed.group("contact_force")[1], feed.group("gap")[1]
        self.rec_slot, self.rec_index = self.bridge.record_plan(feed.rec_slot, feed.rec_index)
        return feed

    def chunk(self, time, chunk_steps):
        """``(t_c, i, origin)`` of the next step at the committed ``time`` [s]: the chunk of the
        steps before, when the run starts where they ended and the chunk of ``chunk_steps`` has
        room; else a new chunk from ``time``."""
        clock = self.clock
        if clock is not None and clock[3] == time and clock[1] < chunk_steps:
            return clock[:3]
        return time, 0, 0

    def committed(self, t_c, i, origin, state):
        """A chunk from ``t_c`` [s] committed its steps up to ``i`` (time counted from its step
        ``origin``) to the domain ``state``: the count the next run continues (:meth:`chunk`) and,
        for a bridge whose bank does not come back from the state to the bit, that state."""
        self.clock = (t_c, i, origin, state.time)
        if not self.bridge.exact_reload:
            self.kept_state = (state.time, state.u.copy(), state.v.copy(), state.a.copy())

    def load_bridge(self, state):
        """The committed domain ``state`` into the bridge bank's slots 0..2, unless they hold it
        already: a bridge without :attr:`~vtsi.subdomain.BridgeStages.exact_reload` (a modal
        bridge, whose q = Φᵀ M u gives back a commit's q to round-off only) goes on from the
        coordinates of the last commit while the domain state is the one it wrote."""
        kept = self.kept_state
        if kept is not None and kept[0] == state.time and all(
                np.array_equal(k, vec) for k, vec in zip(kept[1:], (state.u, state.v, state.a))):
            return
        self.bridge.load_bank(self.bank_b, state, self.asm.full_of_free)

    def rows_of(self, t_c, i, n, chunk_steps):
        """``(table (n, n_stages, n_patterns + 1), r_table, rate_table (n, n_stages, n_c))`` of the
        steps i..i + n - 1 of the chunk from ``t_c`` [s]: each stage's load factors (the patterns',
        then the self weight's mass weight), and the rail's position [m] and rate [m/s] under
        the contact wheels (irregularity less the deck's self-weight sag). From the kept block
        when it holds them; else a block from step i of the rows asked for, and of at least
        BLOCK_STEPS rows (within the chunk) after the plan's first run. Each row is a function of
        its step's time only (a smoothed irregularity too, :class:`~vtsi.constraint.SmoothedProfile`),
        so the rows of a block are those of any other that holds its steps, to the bit."""
        block = self.block
        if block is not None and block[0] == t_c and block[1] <= i and i + n <= block[1] + len(block[2]):
            k = i - block[1]
            return block[2][k: k + n], block[3][k: k + n], block[4][k: k + n]
        a, con = self.analysis, self.analysis.constraint
        m = min(max(n, self.ahead), chunk_steps - i)
        starts = t_c + a.dt * np.arange(i, i + m, dtype=float)
        table = np.concatenate([load_factor_table(self.patterns, starts, a.dt, self.load_points, a._path_tables),
                                np.tile(a.mass_weight[None, :, None], (m, 1, 1))], axis=2)
        times = starts[:, None] + a.stage_theta[None, :] * a.dt      # (m, n_stages) stage times [s]
        r_table, rate_table = (con.irregularity_at(times, a.dt, nu) for nu in (0, 1))
        if a._sag is not None:          # the rail is measured from the deck's self-weight sag
            r_table -= a._rail_sag(times, 0)
            rate_table -= a._rail_sag(times, 1)
        self.block, self.ahead = (t_c, i, table, r_table, rate_table), BLOCK_STEPS
        return table[:n], r_table[:n], rate_table[:n]


def _declared_kinks(constraint):
    """The kinks [m] (increasing, (n,)) the rail profile of ``constraint`` declares (its
    ``kinks``, :meth:`~vtsi.models.Irregularity.from_function`); none for a plain callable."""
    return np.asarray(getattr(constraint.irregularity, "kinks", ()), dtype=np.float64).reshape(-1)


def check_train_stability(train, integrator, dt, bridge=None, track=None):
    """An AnalysisError if ``integrator`` is conditionally stable and ``dt`` [s] exceeds its limit
    for the train subdomain ``train``: the bridge's own check (:class:`~vtsi.subdomain.FEStages`)
    does not see a stiff car. ω_max is the train's with its wheels free where they have mass
    (the coupled system's highest frequency is at most the larger of the bridge's and this, the
    constraint restricting both: Rayleigh's quotient). A contact wheel without mass rides the
    rail, so it takes the rail's mass [kg], the smallest apparent mass of ``bridge`` (its
    :class:`~vtsi.subdomain.BridgeStages`) at a node of ``track``
    (:meth:`~vtsi.subdomain.BridgeStages.rail_point_mass`, computed only then; no bridge: held,
    as on rigid ground): the car on that point mass is the body-on-rail system whose frequency
    sqrt(k (1/m + 1/m_rail)) the coupled system has when the bridge's stiffness at the point is
    small against the suspension's (a stiff car over a light modal bridge: 4.03/Δt, where the car
    with its wheel held gave 3.29/Δt). Wheels sharing one part of the bridge share its mass, so
    with several it is an estimate, not a strict bound."""
    limit = integrator.stability_limit(dt)
    if limit is None or not train.n_dof:
        return
    M, K = train.M.toarray(), train.K.toarray()
    wheels = _massless_wheels(train)
    rail_mass = bridge.rail_point_mass(track) if len(wheels) and bridge is not None else np.inf
    on_bridge = bool(np.isfinite(rail_mass) and len(wheels))
    if on_bridge:
        M[wheels, wheels] = rail_mass
    keep = np.flatnonzero(np.diag(M) > 0.0)
    lam, modes = scipy.linalg.eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)])
    omega_max = float(np.sqrt(max(lam[-1], 0.0)))
    if omega_max * dt > limit * (1.0 + 1e-12):
        dof = train.train.dof_names[keep[np.argmax(np.abs(modes[:, -1]))]]
        on_rail = f", a wheel without mass on the rail's {rail_mass:.4g} kg" if on_bridge else ""
        raise AnalysisError(f"integrator {integrator.name}: dt = {dt:g} s exceeds its stability limit "
                            f"{limit / omega_max:.6g} s for the train (= {limit:.4g}/omega_max, omega_max = "
                            f"{omega_max:.6g} rad/s of the train with its wheels free{on_rail}: a bound of the "
                            f"coupled system's, its stiffest mode mostly {dof}); reduce dt or use an "
                            "unconditionally stable scheme")


class TrainStages:
    """The train subdomain's share of a coupled analysis's preparation for one integrator and Δt;
    it does not depend on the speed, so a sweep computes it once per train (the analyses'
    ``bridge_cache`` keeps it by :func:`train_stage_key`). Per integrator stage: ``fac``
    (n_stages, n_t + kd, kd + 1) the banded factor of the train's effective matrix
    K̂_t = M + kv C + ku K, ``flex`` (n_stages, n_c, n_c) its flexibility on the contact wheels
    S K̂_t⁻¹ Sᵀ, ``wheel_response`` and ``response_range`` the train's response to a unit wheel
    force (:func:`_wheel_responses`), ``ops`` and ``weights`` the operators of the stage's known
    part (:func:`vtsi.timeloop.stage_operators`), and the wheel groups ``group_ptr``,
    ``group_wheel``, ``ground_inv`` (:func:`_wheel_groups`).

    Parameters: ``train`` a :class:`~vtsi.train.TrainSubdomain`, ``stages`` the integrator's
    checked stages for Δt, ``n_slots`` its state slots."""

    def __init__(self, train, stages, n_slots):
        A = n_slots
        fac_t, tflex, response = [], [], []
        kd_t = max(half_bandwidth(train.K), half_bandwidth(train.M), half_bandwidth(train.C)) if train.n_dof else 0
        for s, st in enumerate(stages):
            if train.n_dof:
                kt_hat = (train.M + st.kv[A] * train.C + st.ku[A] * train.K).tocsr()
                try:
                    ft = ldl_band(kt_hat, kd_t)
                except NotPositiveDefinite as exc:
                    raise AnalysisError(f"train effective matrix of stage {s + 1} is singular at train dof "
                                        f"{train.train.dof_names[exc.pivot]}: a dof with neither mass nor "
                                        "stiffness") from None
                cols = inverse_columns(ft, train.wheel_dofs)
                tflex.append(cols[train.wheel_dofs])
                response.append(cols.T)
            else:
                ft = np.zeros((0, 1))
                tflex.append(np.zeros((0, 0)))
                response.append(np.zeros((0, 0)))
            fac_t.append(ft)
        self.fac = np.ascontiguousarray(np.stack(fac_t))
        self.flex = np.ascontiguousarray(np.stack(tflex))
        self.wheel_response, self.response_range = _wheel_responses(response)
        kd_t = self.fac.shape[2] - 1
        pack = lambda name: np.ascontiguousarray(np.stack([getattr(st, name) for st in stages]))
        rows = ((band_rows(train.K, kd_t), band_rows(train.C, kd_t), band_rows(train.M, kd_t)) if train.n_dof
                else (np.zeros((0, 1)),) * 3)
        self.ops, self.weights = stage_operators(rows[0], rows[1], pack("ku"), pack("kv"), rows[2], pack("km"))
        self.group_ptr, self.group_wheel, self.ground_inv = _wheel_groups(self.flex, pack("dv")[:, A])


def _massless_wheels(train):
    """The contact wheel dofs of the train subdomain ``train`` without mass (they ride the rail)."""
    return train.wheel_dofs[train.M.diagonal()[train.wheel_dofs] <= 0.0]


def train_stage_key(integrator, dt, train, track):
    """What :class:`TrainStages` and the train's stability check (:func:`check_train_stability`,
    run as they are built) depend on, the bridge aside (hashable): the integrator, Δt [s], the
    train's M, C, K (CSR) and its contact wheels' dofs, equal for the trains of one catalogue entry
    at any speed; and ``track`` (its dofs, :func:`~vtsi.subdomain.stage_key`) where the check reads
    the rail's mass there: a contact wheel without mass under a conditionally stable integrator
    (a track over a lighter span gives another verdict)."""
    matrices = tuple((m.shape, m.indptr.tobytes(), m.indices.tobytes(), m.data.tobytes())
                     for m in (train.M, train.C, train.K))
    on_rail = integrator.stability_limit(dt) is not None and len(_massless_wheels(train)) > 0
    return ("train", repr(integrator), float(dt), matrices, train.wheel_dofs.tobytes(),
            stage_key(integrator, dt, track) if on_rail else None)


class CoupledLoads:
    """The loads a :class:`CoupledAnalysis` puts on its bridge besides the load patterns: the
    train's moving forces and contact forces on the track, and the bridge's own weight. The
    analysis hands it to its recorders as ``info['coupled_loads']`` when it starts them (item 2
    of the recorder contract, :mod:`vtsi.recorders.base`), so that the recorders whose values
    contain the applied loads (reactions ``R = F_resisting - P``, bending moments) take them
    without being told.

    Attributes
    ----------
    constraint : the analysis's :class:`~vtsi.constraint.MovingLoadConstraint`.
    knot : [m] the knot spacing of the run's rows (0: 'hermite').
    self_weight : (n_full,) [N] the bridge's own weight ``-g M 1_y`` (``bridge_self_weight``), or None.
    modal : whether the bridge is a :class:`~vtsi.modal_bridge.ModalBridge` of fewer modes than the
        model has (:attr:`~vtsi.modal_bridge.ModalBridge.truncated`: K Φ q misses the others' share).
    """

    def __init__(self, constraint):
        self.constraint = constraint
        self.knot, self.self_weight, self.modal = 0.0, None, False
        self._times, self._force_end = np.zeros(0), np.zeros((0, constraint.n_contact))

    def begin(self, knot, self_weight, modal):
        """A run starts: its rows' ``knot`` [m], the bridge's ``self_weight`` (n_full,) [N] or None,
        ``modal`` (a truncated modal bridge) or not."""
        self.knot, self.self_weight, self.modal = float(knot), self_weight, bool(modal)

    def deliver(self, times, force_end):
        """The steps a chunk hands its recorders: ``times (n,)`` [s] and the contact forces at
        each step's end, λ_{n+1} ``(n, n_contact)`` [N, compression positive], which the step's
        displacements balance (Bathe records the step's mean, ``CoupledAnalysis.contact_force``);
        after :meth:`CoupledAnalysis.static`, its dead-load state as one step."""
        self._times, self._force_end = times, force_end

    @property
    def time(self):
        """[s] The last step delivered (the dead-load state's time after
        :meth:`CoupledAnalysis.static`), None before any: the committed state's loads are
        ``add(fixed, [time], out)``."""
        return float(self._times[-1]) if len(self._times) else None

    def shares(self, assembly, rows):
        """The fixed-end forces of loads on the wheels' track at the full dofs ``rows``
        (:func:`~vtsi.recorders.moment.fixed_end_forces`), for :meth:`add`."""
        return fixed_end_forces(assembly, self.constraint.track, rows)

    def add(self, fixed, times, out):
        """Add to ``out (len(times), n_columns)`` the fixed-end share (a
        :class:`~vtsi.recorders.moment.FixedEndMoments` ``fixed``) of the train's loads at ``times``
        [s], steps of the last chunk: its moving forces where they stand then and its contact
        forces at each step's end, λ_{n+1}, which u_{n+1} balances."""
        if len(times) == 0:
            return out
        k = np.minimum(np.searchsorted(self._times, times), max(len(self._times) - 1, 0))
        if len(self._times) == 0 or not np.array_equal(self._times[k], times):
            raise AnalysisError(f"CoupledLoads: t = {times[0]:.6g} to {times[-1]:.6g} s are not steps of the chunk "
                                "the analysis last delivered")
        return add_train_loads(fixed, self.constraint, times, self._force_end[k], self.knot, out)


def _wheel_responses(response):
    """``K̂_t⁻¹ Sᵀ`` per stage as rows (n_stages, n_c, n_t): the train's acceleration under a
    unit force on each contact wheel, and the dof range ``[lo, hi)`` (n_c, 2) where each is
    nonzero in some stage (its car's dofs)."""
    response = np.ascontiguousarray(np.stack(response))
    nonzero = np.any(response != 0.0, axis=0)
    span = np.zeros((response.shape[1], 2), dtype=np.int64)
    for i, row in enumerate(nonzero):
        where = np.flatnonzero(row)
        if len(where):
            span[i] = where[0], where[-1] + 1
    return response, span


def _wheel_groups(tflex, va):
    """Contact wheels grouped by the train's coupling (connected components of the train
    flexibility S K̂_t⁻¹ Sᵀ over all stages: a car's wheels), as ``(group_ptr, group_wheel)``,
    and per stage the inverse of each group's W block ``va S K̂_t⁻¹ Sᵀ`` (valid while none of the
    group's wheels is on the track; a zero block if it is not positive definite)."""
    n_stages, n_c = tflex.shape[0], tflex.shape[1]
    if n_c == 0:     # a train of moving forces
        return np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros((n_stages, 0, 0))
    _, label = csgraph.connected_components(sp.csr_matrix(np.any(tflex != 0.0, axis=0)), directed=False)
    group_wheel = np.argsort(label, kind="stable").astype(np.int64)
    group_ptr = np.concatenate([[0], np.cumsum(np.bincount(label))]).astype(np.int64)
    ground_inv = np.zeros((n_stages, n_c, n_c))
    for s in range(n_stages):
        for g in range(len(group_ptr) - 1):
            idx = group_wheel[group_ptr[g]: group_ptr[g + 1]]
            block = va[s] * tflex[s][np.ix_(idx, idx)]
            try:
                factor_ = np.linalg.cholesky(block)
            except np.linalg.LinAlgError:
                continue
            inverse = np.linalg.inv(factor_)
            ground_inv[s][np.ix_(idx, idx)] = inverse.T @ inverse
    return group_ptr, group_wheel, ground_inv
