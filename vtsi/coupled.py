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
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csgraph

from vtsi.analysis import (
    _integer,
    _pattern_loads,
    _RecorderFeed,
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
from vtsi.contact import contact_events, contact_summary
from vtsi.coupled_loop import run_coupled_steps
from vtsi.errors import AnalysisError, DivergenceError, ModelError, as_positive
from vtsi.integrators import HHT, make_integrator
from vtsi.lcp import lcp_workspace
from vtsi.recorders.moment import add_train_loads, fixed_end_forces
from vtsi.recorders.sinks import check_own_files
from vtsi.subdomain import BridgeStageCache, FEStages, stage_key
from vtsi.timeloop import stage_operators
from vtsi.vehicle import GRAVITY

CONTACT_STRATEGIES = ("bilateral", "lcp")
LCP_DEFAULT_ALPHA = 0.9      # HHT's α when contact='lcp' and no integrator is given
CURVATURE_STEP = 1e-4        # [m] central-difference step of smoothed rows' curvature under a wheel at the start
MAX_GAP_TOL = 1e-6
"""[m] The largest ``gap_tol`` accepted: a wheel at most gap_tol above the rail is put back on it,
so the tolerance is a round-off guard and must stay far below the smallest lift-off of interest
(0.1 mm). Measured (a four-dof car over a 20 mm, 1 m dip at 60 m/s, HHT(0.9), Δt = 0.25 ms): with
1e-6 m its wheels' flights of 0.067 and 0.090 mm start and peak as with 1e-9 m; with 1e-5 m they
start a step late and peak 10 % and 8 % lower."""


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


class CoupledAnalysis:
    """Transient analysis of a bridge model with a train tied to it.

    Parameters
    ----------
    model : Model (the bridge, with its track elements).
    constraint : MovingLoadConstraint (holds the Track and the TrainSubdomain).
    integrator : name, class or instance ('Newmark', HHT(0.9), 'Bathe', ...); None: Newmark
        (average acceleration) with bilateral contact, HHT(0.9) with contact='lcp', which refuses
        an integrator without numerical dissipation (:func:`coupled_integrator`).
    dt : time step [s].
    contact : 'bilateral' (wheels always on the rail) or 'lcp' (contact loss allowed).
    gravity : g [m/s²] (finite, >= 0) for the bridge's weight ``-g M 1_y`` with
        ``bridge_self_weight`` (the train's weight is its gravity_load, used as built).
    bridge_self_weight : add the bridge's own weight to the dead load (results are then totals;
        without it — the default — they are the response to the train and the load patterns, the
        part a dynamic check of the deck uses; ``load_description`` says which). The
        rail is straight at the deck's self-weight state (the track is laid on the deflected
        deck): the constraint measures the rail from that deflected line.
    recorders : bridge recorders (:mod:`vtsi.recorders`) and train/contact recorders, whose
        requests may name 'u', 'v', 'a' (bridge full dof), 'train_u', 'train_v', 'train_a'
        (train dof) or 'contact_force', 'gap' (contact wheel index). The analysis hands them
        ``coupled_loads`` (:class:`CoupledLoads`) when it starts them: reactions and bending
        moments take the train's loads and the bridge's own weight from there.
    divergence_limit : |u| [m] beyond which a step counts as diverged.
    gap_tol : position gap [m] above which a wheel counts as in flight (contact='lcp'); a wheel
        less high is put back on the rail. A round-off guard: 0 to MAX_GAP_TOL (1e-6 m, far
        below a lift-off of interest, >= 0.1 mm).
    exact_events : kinks of the rail line ('hermite' rows: a span's end on a support next to rigid
        ground or to another span's end). False (default): a wheel takes the kink at the end of
        the step that contains it, a first-order error in the train's response (its dampers see
        the wheel's velocity jump at the wrong time). True: that step keeps the wheel on its old
        line, then its velocity jump (a perfectly inelastic impulse, as R1) is applied with a
        timing correction and a consistent restart of its car: second order, no extra
        factorisation; the impulse is recorded as impulse/Δt in that step's λ, and Newmark's
        λ no longer rings after a kink (docs/theory/coupled_step.md §6).
    bridge_cache : a :class:`~vtsi.subdomain.BridgeStageCache` shared by analyses of one bridge
        (a sweep's passages): the bridge's factors and track flexibilities are computed once per
        model version, integrator, Δt, track and set of moving dofs, whatever train crosses.
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
        self.integrator = coupled_integrator(integrator, contact)
        if self.integrator.explicit:
            why = " with beta = 0 (central differences)" if self.integrator.name == "Newmark" else ""
            raise AnalysisError(f"CoupledAnalysis: {self.integrator.name}{why} is explicit; a constrained "
                                "analysis needs an implicit integrator: Newmark with beta > 0 (e.g. Newmark(0.5, "
                                "0.25)), HHT or Bathe")
        self.gravity = as_positive(gravity, "CoupledAnalysis", "gravity [m/s²]", AnalysisError, allow_zero=True)
        self.bridge_self_weight = bool(bridge_self_weight)
        self.recorders = list(recorders)
        check_own_files("CoupledAnalysis", self.recorders)      # two recorders writing one file
        self.chunk_steps = _integer("CoupledAnalysis", "chunk_steps", chunk_steps, 1)
        self.divergence_limit = as_positive(divergence_limit, "CoupledAnalysis", "divergence_limit", AnalysisError,
                                            finite=False)
        self.dt = as_positive(dt, "CoupledAnalysis", "dt", AnalysisError)
        self._prepared = None
        self._path_tables = {}
        self._sag = None
        self._diverged = None      # where a run diverged ("step N, t = … s"): no run goes on from there
        self.static_state = None
        self.reset_records()
        self._lcp_work = lcp_workspace(constraint.n_contact)
        self.gap_tol = as_positive(gap_tol, "CoupledAnalysis", "gap_tol [m]", AnalysisError, allow_zero=True)
        if self.gap_tol > MAX_GAP_TOL:
            raise AnalysisError(f"CoupledAnalysis: gap_tol [m] must be at most {MAX_GAP_TOL:g} m, got {gap_tol!r}: a "
                                "wheel less than gap_tol above the rail is put back on it, so a larger one hides and "
                                "delays lift-offs")
        if not isinstance(exact_events, (bool, np.bool_)):
            raise AnalysisError(f"CoupledAnalysis: exact_events must be True or False, got {exact_events!r}")
        self.exact_events = bool(exact_events)
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
        A = integ.n_slots
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
        self.fac_t = np.ascontiguousarray(np.stack(fac_t))
        self.tflex = np.ascontiguousarray(np.stack(tflex))
        self.wheel_response, self.response_range = _wheel_responses(response)
        kd_t = self.fac_t.shape[2] - 1
        pack = lambda name: np.ascontiguousarray(np.stack([getattr(st, name) for st in stages]))
        self.du, self.dv, ku, kv, km = pack("du"), pack("dv"), pack("ku"), pack("kv"), pack("km")
        rows = ((band_rows(train.K, kd_t), band_rows(train.C, kd_t), band_rows(train.M, kd_t)) if train.n_dof
                else (np.zeros((0, 1)),) * 3)
        self.ops_t, self.weights_t = stage_operators(rows[0], rows[1], ku, kv, rows[2], km)
        self.group_ptr, self.group_wheel, self.ground_inv = _wheel_groups(self.tflex, self.dv[:, A])
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
        self._kinks = self._kink_positions()
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
    def static(self):
        """Static equilibrium of bridge and train under the train's weight (and the patterns at the
        current time; the bridge's own weight only with ``bridge_self_weight``) with the wheels on
        the rail: sets the committed states and ``static_state`` (whose ``loads`` says what it
        contains).

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
        sol = self._static_solution(asm, t)
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
        self.static_state = {"time": t, "bridge_u": state.u.copy(), "train_u": train.u.copy(),
                             "train_v": train.v.copy(), "train_a": train.a.copy(), "contact_force": contact,
                             "start_force": contact + (train.M @ train.a + train.C @ train.v)[train.wheel_dofs],
                             "loads": self.load_description}
        self._prev = None
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

    def _static_solution(self, asm, t):
        """``(bridge coordinates, train dofs, contact forces)`` of the static equilibrium at time
        ``t`` [s] (the wheels where they are then, the patterns' loads then)."""
        train, con, track, bridge = self.train, self.constraint, self.constraint.track, self.stages
        p_b = self._bridge_constant_load(asm)
        for pattern in self.model.patterns.values():
            p_b = p_b + pattern.factors(np.array([t]))[0] * asm.load_vector(pattern)
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
        self._prev = None

    # -- time stepping --------------------------------------------------------------------
    def run(self, n_steps):
        """Advance ``n_steps`` steps from the committed states (call :meth:`static` first for a
        start from the dead-load equilibrium). Returns the domain state. Refused after a run
        that diverged (its model stays at the start of the diverging chunk)."""
        n_steps = _integer("CoupledAnalysis", "number of steps", n_steps, 0)
        if self._diverged is not None:
            raise AnalysisError(f"CoupledAnalysis: it diverged ({self._diverged}); a coupled analysis does not go on "
                                f"from a divergence (the recorders hold the steps before it, the model is at the "
                                f"start of their chunk): build a new one, e.g. with a smaller dt")
        patterns = list(self.model.patterns.values())
        load_ptr, load_dof, load_val = _pattern_loads(self.model.build(), patterns)
        asm = self._prepare(load_dof)
        state = domain_state(self.model)
        train, con, track = self.train, self.constraint, self.constraint.track
        con.check_travel(state.time, state.time + n_steps * self.dt, self.dt)
        bridge = self.stages
        constant = self._bridge_constant_load(asm)     # a last pattern of factor 1 (× the stage's mass weight)
        nz = np.flatnonzero(constant)
        load_ptr, load_dof, load_val = bridge.loads(np.append(load_ptr, load_ptr[-1] + len(nz)),
                                                    np.concatenate([load_dof, nz]).astype(np.int64),
                                                    np.concatenate([load_val, constant[nz]]))
        n_slots = self.integrator.n_slots
        kd_b, kd_t = bridge.kd, self.fac_t.shape[2] - 1
        n_b, n_t, n_c = bridge.n, train.n_dof, con.n_contact
        bank_b = bridge.bank(state, asm.full_of_free, n_slots)
        bank_t = np.zeros((n_slots, n_t + 2 * kd_t))
        for slot, vec in enumerate((train.u, train.v, train.a)):
            bank_t[slot, kd_t: kd_t + n_t] = vec
        channels = {q: ("train", slot, n_t, "train dof") for q, slot in TRAIN_QUANTITIES.items()}
        channels.update({q: (q, 0, n_c, "contact wheel") for q in ("contact_force", "gap")})
        self.coupled_loads.begin(con.knot(self.dt), self._self_weight(asm) if self.bridge_self_weight else None,
                                 self.bridge is not None)
        feed = _RecorderFeed(asm, self.model, self.recorders,
                             {"analysis": "coupled", "integrator": repr(self.integrator), "dt": self.dt,
                              "loads": self.load_description, "coupled_loads": self.coupled_loads}, channels)
        t_slot, t_index = feed.group("train")
        force_wheels, gap_wheels = feed.group("contact_force")[1], feed.group("gap")[1]
        width = con.width(self.dt)
        cols = np.empty((n_c, width), dtype=np.int64)
        vals = np.empty((n_c, width))
        slopes = np.empty((n_c, width))
        work_b = np.zeros((3, n_b + 2 * kd_b))
        work_t = np.zeros((3, n_t + 2 * kd_t))
        W, q, lam = np.zeros((n_c, n_c)), np.zeros(n_c), np.zeros(n_c)
        times_all, force_all, gap_all = [self.time], [self.contact_force], [self.gap]
        end_all = [self.contact_force_end]
        prev = self._previous_forces(width)
        rec_slot, rec_index = bridge.record_plan(feed.rec_slot, feed.rec_index)
        load_points = [st.load for st in self.integrator.stages(self.dt)]

        def steps(first, last, x0_c, r_part, rate_part):
            """Run the chunk's steps first..last - 1 with the contact wheels at ``x0_c`` at t = 0 and
            the rail data ``r_part``, ``rate_part`` of those steps; the loop's status, its step
            counted in the chunk."""
            bad = run_coupled_steps(
                bank_b, bank_t, self.du, self.dv,
                bridge.fac, bridge.ops, bridge.weights, self.fac_t, self.ops_t, self.weights_t,
                table[first:last], load_ptr, load_dof, load_val, train.gravity_load,
                bridge.flex, self.tflex, track.x_start, track.length, track.dofs, bridge.track_index,
                bridge.track_basis,
                x0_c, train.wheel_dofs, con.x0_force, train.wheel_forces, train.speed,
                con.knot(self.dt), r_part, rate_part, t0 + first * self.dt, self.dt, self.stage_theta,
                self.load_theta, self.load_weight, self.force_weight, self.mass_weight, self.record_weights,
                self.contact == "lcp",
                self.gap_tol,
                self.in_contact, rec_slot, rec_index, out[0][first:last], t_slot, t_index, out[1][first:last],
                out[2][first:last], out[4][first:last], out[3][first:last], self.divergence_limit, work_b, work_t, cols, vals, slopes,
                W, q, lam, self._lcp_work, band_type(kd_b), band_type(kd_t), *prev,
                self.group_ptr, self.group_wheel, self.ground_inv, self.wheel_response, self.response_range)
            return bad if bad == -1 else (bad + first if bad >= 0 else bad - first)

        done = 0
        try:
            while done < n_steps:
                n = min(self.chunk_steps, n_steps - done)
                t0 = state.time
                starts = t0 + self.dt * np.arange(n, dtype=float)
                table = np.concatenate([load_factor_table(patterns, starts, self.dt, load_points, self._path_tables),
                                        np.tile(self.mass_weight[None, :, None], (n, 1, 1))], axis=2)
                r_table, rate_table = (np.ascontiguousarray(np.stack(
                    [con.irregularity_at(starts + th * self.dt, self.dt, nu) - self._rail_sag(starts + th * self.dt, nu)
                     for th in self.stage_theta], axis=1)) for nu in (0, 1))
                out = (np.zeros((n, len(rec_slot))), np.zeros((n, len(t_index))), np.zeros((n, n_c)),
                       np.zeros((n, n_c)), np.zeros((n, n_c)))
                out_b, out_t, out_force, out_gap, out_force_end = out
                events = self._events(t0, n)
                first, bad = 0, -1
                for k in sorted({e[0] for e in events}) + [n]:
                    if k > first:
                        bad = steps(first, k, con.x0, r_table[first:k], rate_table[first:k])
                        if bad != -1 or k == n:
                            break
                    crossing = [e for e in events if e[0] == k and self.in_contact[e[2]] > 0.5]
                    x0_c, r_k, rate_k = self._old_line(crossing, t0 + k * self.dt, r_table[k:k + 1],
                                                       rate_table[k:k + 1])
                    bad = steps(k, k + 1, x0_c, r_k, rate_k)
                    if bad != -1:
                        break
                    for _, theta, i, x in crossing:
                        # recorded as its impulse spread over the step (as a landing, docs/theory/contact.md)
                        out_force[k, i] += self._cross(bank_b, bank_t, kd_b, kd_t, i, x, (1.0 - theta) * self.dt,
                                                       prev) / self.dt
                    first = k + 1
                good = n if bad == -1 else (bad if bad >= 0 else -2 - bad)
                times = t0 + self.dt * np.arange(1, good + 1)
                times_all.append(times)
                force_all.append(out_force[:good])
                end_all.append(out_force_end[:good])
                gap_all.append(out_gap[:good])
                if bad == -1:           # the chunk committed before the recorders get it: one that raises
                    bridge.commit(state, bank_b, asm.full_of_free, t0 + n * self.dt)     # leaves the analysis
                    for slot, vec in enumerate((train.u, train.v, train.a)):          # at its last row
                        vec[:] = bank_t[slot, kd_t: kd_t + n_t]
                    done += n
                else:
                    step, t_bad = done + good + 1, t0 + (good + 1) * self.dt
                    self._diverged = f"step {step}, t = {t_bad:.6g} s"
                self.coupled_loads.deliver(times, out_force[:good], out_force_end[:good])
                feed.deliver(times, bridge.recorded(out_b[:good]), asm, train=out_t[:good],
                             contact_force=out_force[:good][:, force_wheels], gap=out_gap[:good][:, gap_wheels])
                if bad != -1:
                    if bad >= 0:
                        raise DivergenceError(f"coupled analysis diverged at step {step}, t = {t_bad:.6g} s "
                                              f"(|u| > {self.divergence_limit:g} m or NaN) with "
                                              f"{self.integrator!r}, dt = {self.dt:g} s", step, t_bad)
                    raise DivergenceError(f"coupled analysis: contact flexibility W is singular at step {step}, "
                                          f"t = {t_bad:.6g} s", step, t_bad)
        finally:
            feed.close()
            self.time = np.concatenate(times_all)
            self.contact_force = np.concatenate(force_all)
            self.contact_force_end = np.concatenate(end_all)
            self.gap = np.concatenate(gap_all)
        return state

    # -- kinks of the rail line (span entry and exit), exact_events ------------------------
    def _kink_positions(self):
        """Positions [m] where the rail line kinks and a bilateral wheel's velocity jumps: the
        track chain's ends and the interior element ends whose rotation dofs differ (two spans
        on their own nodes), where the rail's uy is fixed (a support: the rows have no free
        entry there, so the bridge takes no impulse). Only with ``exact_events`` and 'hermite'
        rows ('bspline' smooths the kink)."""
        con, track = self.constraint, self.constraint.track
        if not self.exact_events or con.interpolation != "hermite" or con.n_contact == 0:
            return np.zeros(0)
        d = track.dofs
        kinks = [track.x_begin] if d[0, 0] < 0 else []
        kinks += [track.x_start[e + 1] for e in range(len(d) - 1)
                  if d[e, 3] != d[e + 1, 1] and d[e, 2] < 0 and d[e + 1, 0] < 0]
        if d[-1, 2] < 0:
            kinks.append(track.x_end)
        return np.array(kinks)

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
        """Wheel start positions and rail data (self weight) of a step in which the wheels of
        ``crossing`` stay on their old line to the step's end: each is moved back by the
        V (1 - θ) Δt it travels past its kink (and a hair)."""
        con, V = self.constraint, self.train.speed
        x0_c, r_step, rate_step = con.x0.copy(), r_step.copy(), rate_step.copy()
        for _, theta, i, x in crossing:
            shift = (1.0 - theta) * self.dt * V + 1e-9 * max(1.0, abs(x))
            x0_c[i] -= shift
            if self._sag is not None:
                xs = con.x0[i] + V * (t_step + self.stage_theta * self.dt)
                r_step[0, :, i] += self._sag_at(xs, 0) - self._sag_at(xs - shift, 0)
                rate_step[0, :, i] += self._sag_at(xs, 1) - self._sag_at(xs - shift, 1)
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
        which kept it on its old line. Onto the new line (docs/theory/coupled_step.md §6): its
        position; its car's momentum from the dampers since the crossing, -C e_w Δv tau; its
        velocity jump by a perfectly inelastic impulse along e_w (its car only: the bridge takes
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
        self.time = np.zeros(0)
        self.contact_force, self.contact_force_end, self.gap = (np.zeros((0, n_c)) for _ in range(3))

    # -- contact results ------------------------------------------------------------------
    def contact_events(self, interpolate=True):
        """Lift-off and landing events of the steps run so far (:func:`vtsi.contact.contact_events`)."""
        return contact_events(self, interpolate=interpolate)

    def contact_summary(self, static_load=None, interpolate=True):
        """Per-wheel separations, longest flight, force extremes and unloading ratio ΔQ/Q of the
        steps run so far (:func:`vtsi.contact.contact_summary`)."""
        return contact_summary(self, static_load=static_load, interpolate=interpolate)

    def _previous_forces(self, width):
        """Contact forces and rows of the last committed step (the dead-load forces and the rows
        at the current time before the first step), for integrators that weight them (HHT)."""
        con = self.constraint
        prev = getattr(self, "_prev", None)
        if prev is None or prev[1].shape[1] != width:
            t = domain_state(self.model).time
            cols, vals = np.full((con.n_contact, width), -1, dtype=np.int64), np.zeros((con.n_contact, width))
            if con.n_contact:
                c0, v0, _, _ = con.rows_at(t, self.dt)
                cols[:, : c0.shape[1]], vals[:, : v0.shape[1]] = c0, v0
            if len(self.contact_force):
                lam = self.contact_force[-1].copy()
            elif self.static_state is not None:
                lam = self.static_state["start_force"].copy()
            else:
                lam = np.zeros(con.n_contact)
            prev = self._prev = (lam, cols, vals)
        return prev


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
    modal : whether the bridge is a :class:`~vtsi.modal_bridge.ModalBridge` (recorded u = Φ q).
    """

    def __init__(self, constraint):
        self.constraint = constraint
        self.knot, self.self_weight, self.modal = 0.0, None, False
        n_c = constraint.n_contact
        self._times, self._force, self._force_end = np.zeros(0), np.zeros((0, n_c)), np.zeros((0, n_c))

    def begin(self, knot, self_weight, modal):
        """A run starts: its rows' ``knot`` [m], the bridge's ``self_weight`` (n_full,) [N] or None,
        ``modal`` or not."""
        self.knot, self.self_weight, self.modal = float(knot), self_weight, bool(modal)

    def deliver(self, times, force, force_end):
        """The steps a chunk hands its recorders: ``times (n,)`` [s] and the contact forces
        ``(n, n_contact)`` [N, compression positive] as recorded (``force``: the step's mean,
        ``CoupledAnalysis.contact_force``) and at the step's end (``force_end``, λ_{n+1})."""
        self._times, self._force, self._force_end = times, force, force_end

    def shares(self, assembly, rows):
        """The fixed-end forces of loads on the wheels' track at the full dofs ``rows``
        (:func:`~vtsi.recorders.moment.fixed_end_forces`), for :meth:`add`."""
        return fixed_end_forces(assembly, self.constraint.track, rows)

    def add(self, fixed, times, out, end=True):
        """Add to ``out (len(times), n_columns)`` the fixed-end share (a
        :class:`~vtsi.recorders.moment.FixedEndMoments` ``fixed``) of the train's loads at ``times``
        [s], steps of the last chunk: its moving forces where they stand then and its contact
        forces at each step's end (``end``: λ_{n+1}, which u_{n+1} balances) or as recorded (the
        step's mean for Bathe; the same for the Newmark family)."""
        if len(times) == 0:
            return out
        k = np.minimum(np.searchsorted(self._times, times), max(len(self._times) - 1, 0))
        if len(self._times) == 0 or not np.array_equal(self._times[k], times):
            raise AnalysisError(f"CoupledLoads: t = {times[0]:.6g} to {times[-1]:.6g} s are not steps of the chunk "
                                "the analysis last delivered")
        force = (self._force_end if end else self._force)[k]
        return add_train_loads(fixed, self.constraint, times, force, self.knot, out)


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
