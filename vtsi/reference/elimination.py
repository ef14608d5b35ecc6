"""Reference solution R1: the bilateral train-bridge problem by constraint elimination.

The coupled equations (docs/theory/coupled_step.md §1; λ ≥ 0 is compression: it pushes the wheel
up, the rail down)

    M_b ü_b + C_b u̇_b + K_b u_b = P_b(t) − Nᵀ λ
    M_t ü_t + C_t u̇_t + K_t u_t = P_t + Sᵀ λ
    S u_t − N(t) u_b − r(t) = 0,      N's row i = Hermite row at x_i(t) = x_i0 + V t

are turned into an ODE by eliminating the wheel dofs. With the independent coordinates
y = [u_b; u_o] (u_o: the train dofs that are not wheel dofs of wheels in contact),

    u = B(t) y + b(t),    u_w = N(x(t)) u_b + r(x(t)),
    u̇ = B ẏ + Ḃ y + ḃ,   ü = B ÿ + 2 Ḃ ẏ + B̈ y + b̈,     Ḃ ∝ V N'(x),  B̈ ∝ V² N''(x),

and since G B = 0 for G = [−N, S], projecting the equations of motion on B removes λ:

    Bᵀ M B ÿ + Bᵀ (2 M Ḃ + C B) ẏ + Bᵀ (M B̈ + C Ḃ + K B) y = Bᵀ (P − M b̈ − C ḃ − K b).

λ is recovered from the wheel rows of the train equations,
λ_i = (M_t ü_t + C_t u̇_t + K_t u_t − P_t)[wheel dof i], with ü_w from the constraint.
The ODE is integrated with DOP853 (E. Hairer's Fortran code through scipy.integrate.ode by
default, or any :func:`scipy.integrate.solve_ivp` method), restarting at every time where a
wheel (contact or force-only) crosses a track node or a track end, and at the irregularity break
points: between restarts every wheel keeps its host element (or stays off the track), so the
right-hand side is a polynomial in t and the integrator sees no kink. At a restart y is
continuous and the velocity follows the impulse law of a perfectly inelastic bilateral
constraint,

    Bᵀ M B ẏ⁺ = Bᵀ M (u̇⁻ − Ḃ⁺ y − ḃ⁺),

the unique velocity that satisfies the new constraint and differs from the old one by an impulse
Gᵀι along the constraint. Across an element node N' is continuous and nothing jumps; at a span
entry or exit (the rail line has a kink at the support) the wheel's vertical velocity jumps by
V Δ(N' u_b + r') and the contact force holds the impulse ι = (M_t Δu̇_t)[wheel] [N·s], which the
solution lists in ``impulses``.

Also here: :class:`RigidGround` (a train on rigid ground, ``model=None``),
:func:`average_contact_force` (exact trailing averages of λ), and the pieces that R2
(:mod:`.ida`) and the contact-loss reference (:mod:`.events`) share. See
docs/theory/reference_solvers.md.

References
----------
Hairer, E., Nørsett, S.P., Wanner, G. (1993) Solving Ordinary Differential Equations I, 2nd ed.,
Springer (DOP853, §II.10). Fedorova, M., Sivaselvan, M.V. (2017) Engineering Structures 148
(the coupled problem; verified there with a generic DAE solver). Brogliato, B. (2016) Nonsmooth
Mechanics, 3rd ed., Springer (impulsive constraints, plastic impact: the restart law).
"""
from dataclasses import dataclass, field

import numpy as np
from numba import njit
from scipy.integrate import ode, solve_ivp
from scipy.sparse.linalg import spsolve

from vtsi.analysis import component_labels, dofs_with
from vtsi.constraint import MovingLoadConstraint
from vtsi.errors import AnalysisError, ModelError, as_number, as_numbers, as_positive
from vtsi.track import hermite, hermite_curvature, hermite_slope, host_element
from vtsi.train import TrainSubdomain
from vtsi.vehicle import GRAVITY

IMPULSE_THRESHOLD = 1e-10
"""Impulses smaller than this × the largest static wheel load × 1 s [N·s] are not listed."""


class RigidGround:
    """A train on rigid ground (no bridge): stands in for a MovingLoadConstraint when the
    reference solvers run with ``model=None``.

    Parameters
    ----------
    train : TrainSubdomain
    irregularity : None, or r(x, nu) as :class:`vtsi.models.Irregularity` (values and the first
        two derivatives) [m, 1, 1/m].
    """

    track = None
    interpolation = "hermite"

    def __init__(self, train, irregularity=None):
        if not isinstance(train, TrainSubdomain):
            raise ModelError(f"RigidGround: train must be a TrainSubdomain, got {type(train).__name__}")
        self.train, self.irregularity = train, irregularity
        self.x0 = train.wheel_x0(train.contact_wheels)
        self.x0_force = train.wheel_x0(train.force_wheels)

    @property
    def n_contact(self):
        return len(self.x0)

    def positions(self, t):
        return self.x0 + self.train.speed * np.asarray(t, dtype=float)[..., None]


@dataclass
class ReferenceSolution:
    """Histories of a reference solution at the output times.

    Attributes
    ----------
    t : (n_t,) output times [s].
    bridge_u, bridge_v, bridge_a : (n_t, n_free) bridge free-dof response (totals: dead load
        included) [m, rad; /s; /s²]; free-dof order of ``assembly``.
    train_u, train_v, train_a : (n_t, n_dof) train response.
    contact_force : (n_t, n_c) λ [N], compression positive (bilateral: may be negative).
    impulses : list of (time [s], contact wheel, impulse [N·s]) held by the contact force at the
        restarts where the rail line has a kink (span entry or exit).
    dead_load : dict with 'bridge_u' (n_free,), 'train_u' (n_dof,), 'contact_force' (n_c,).
    assembly : the bridge Assembly (None on rigid ground).
    breakpoints : (n_seg + 1,) restart times, 0 and t_end included.
    stats : dict of solver counters (function evaluations, steps ...).
    """

    t: np.ndarray
    bridge_u: np.ndarray
    bridge_v: np.ndarray
    bridge_a: np.ndarray
    train_u: np.ndarray
    train_v: np.ndarray
    train_a: np.ndarray
    contact_force: np.ndarray
    impulses: list
    dead_load: dict
    assembly: object
    breakpoints: np.ndarray
    stats: dict = field(default_factory=dict)

    def node(self, node, dof, quantity="u"):
        """History (n_t,) of ``quantity`` ('u', 'v' or 'a') of ``dof`` (1-based, OpenSees: 1 ux,
        2 uy, 3 rz) of bridge node ``node``; zeros for a fixed dof."""
        if self.assembly is None:
            raise ModelError("ReferenceSolution.node: there is no bridge (rigid ground)")
        if quantity not in ("u", "v", "a"):
            raise ModelError(f"ReferenceSolution.node: quantity must be 'u', 'v' or 'a', got {quantity!r}")
        free = self.assembly.free_of_full[self.assembly.full_dof(node, dof)]
        data = getattr(self, f"bridge_{quantity}")
        return np.zeros(len(self.t)) if free < 0 else data[:, free].copy()


def average_contact_force(solution, train, window):
    """Contact forces averaged over the trailing ``window`` [s]: λ̄(t) = (1/T) ∫_{t−T}^{t} λ dt.

    Computed from the wheel rows of the train equations, ∫ λ dt = [(M_t u̇_t + C_t u_t)_w] +
    ∫ (K_t u_t − P_t)_w dt (trapezoidal rule for the last, smooth term), so that the impulses at
    span entry and exit are included and the high-frequency content of λ (bridge modes up to
    ω_max, seen by a massive wheel) is averaged out without aliasing. ``solution.t`` must be
    uniform and ``window`` a multiple of its spacing.

    Returns (t (m,), λ̄ (m, n_c)) for the output times t ≥ t_0 + window [s, N].
    """
    t = solution.t
    dt = t[1] - t[0]
    n = int(round(window / dt))
    if n < 1 or abs(n * dt - window) > 1e-9 * window or np.ptp(np.diff(t)) > 1e-9 * dt:
        raise ModelError("average_contact_force: t must be uniform and window a multiple of its spacing")
    w = train.wheel_dofs
    u, v = solution.train_u, solution.train_v
    p = (train.M @ v.T + train.C @ u.T).T[:, w]
    f = (train.K @ u.T).T[:, w] - train.gravity_load[w]
    F = np.concatenate([np.zeros((1, f.shape[1])), np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t)[:, None], axis=0)])
    return t[n:], (p[n:] - p[:-n] + F[n:] - F[:-n]) / (t[n:] - t[:-n])[:, None]


def irregularity_functions(irregularity, x_probe):
    """r(x, nu) for nu = 0, 1, 2 from an irregularity (None: smooth rail). A callable must take
    ``nu`` like :class:`vtsi.models.Irregularity`: the reference solvers need r' and r''."""
    if irregularity is None:
        return lambda x, nu=0: np.zeros(np.shape(x))
    if not callable(irregularity):
        raise ModelError("reference solver: the irregularity must be callable r(x, nu)")
    probe = np.atleast_1d(np.asarray(x_probe, dtype=float))[:1]
    try:
        for nu in (1, 2):
            np.asarray(irregularity(probe, nu=nu), dtype=float)
    except TypeError:
        raise ModelError("reference solver: the irregularity must give its derivatives as r(x, nu) "
                         "(nu = 0, 1, 2), e.g. vtsi.models.Irregularity; a plain r(x) is not enough") from None

    def profile(x, nu=0):
        return np.asarray(irregularity(np.asarray(x, dtype=float), nu=nu), dtype=float) * np.ones(np.shape(x))
    return profile


@njit(cache=True)
def hermite3(x, x_e, l_e, h, d1, d2):
    """The track's Hermite row [H1, ℓH2, H3, ℓH4] (:mod:`vtsi.track`) and its first and second
    x-derivatives at one position ``x`` on an element starting at ``x_e`` of length ``l_e``:
    fills h, d1, d2 (4,) [1, 1/m, 1/m²] (rotation columns: [m, 1, 1/m])."""
    xi = (x - x_e) / l_e
    h[0], h[1], h[2], h[3] = hermite(xi, l_e)
    d1[0], d1[1], d1[2], d1[3] = hermite_slope(xi, l_e)
    d2[0], d2[1], d2[2], d2[3] = hermite_curvature(xi, l_e)


def hermite_rows(x, x_e, l_e):
    """:func:`hermite3` at positions ``x`` on elements ``x_e``, ``l_e`` (arrays of equal shape)
    -> three arrays (..., 4)."""
    x, x_e, l_e = (np.asarray(a, dtype=float) for a in (x, x_e, l_e))
    h, d1, d2 = (np.empty(x.shape + (4,)) for _ in range(3))
    for i in np.ndindex(x.shape):
        hermite3(x[i], x_e[i], l_e[i], h[i], d1[i], d2[i])
    return h, d1, d2


@njit(cache=True)
def add_wheel_loads(t, V, x0f, forces, cols, x_e, l_e, p):
    """p -= Σ_f f N_f(x_f(t))ᵀ: force-only wheels (downward force f > 0) on the bridge."""
    h, d1, d2 = np.empty(4), np.empty(4), np.empty(4)
    for i in range(x0f.shape[0]):
        hermite3(x0f[i] + V * t, x_e[i], l_e[i], h, d1, d2)
        for k in range(4):
            if cols[i, k] >= 0:
                p[cols[i, k]] -= forces[i] * h[k]


@njit(cache=True)
def matvec(A, x, out, scale):
    """out += scale · A x (dense, plain loops: compiles fast)."""
    for i in range(A.shape[0]):
        acc = 0.0
        for j in range(A.shape[1]):
            acc += A[i, j] * x[j]
        out[i] += scale * acc


@njit(cache=True)
def solve_small(A, b):
    """Solve A x = b in place (b <- x) by Gaussian elimination with partial pivoting; A is
    overwritten. For the few-unknown systems of the kernels."""
    m = b.shape[0]
    for k in range(m):
        p = k
        for i in range(k + 1, m):
            if abs(A[i, k]) > abs(A[p, k]):
                p = i
        if p != k:
            for j in range(m):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            b[k], b[p] = b[p], b[k]
        piv = A[k, k]
        for i in range(k + 1, m):
            f = A[i, k] / piv
            if f != 0.0:
                for j in range(k, m):
                    A[i, j] -= f * A[k, j]
                b[i] -= f * b[k]
    for k in range(m - 1, -1, -1):
        acc = b[k]
        for j in range(k + 1, m):
            acc -= A[k, j] * b[j]
        b[k] = acc / A[k, k]


@njit(cache=True)
def reduced_accel(t, y, yd, V, Minv, C_b, K_b, P_b, M_t, C_t, K_t, P_t, x0a, wdof, cols, x_e, l_e,
                  r, r1, r2, o, ydd, lam):
    """ÿ and λ of the reduced ODE (see :meth:`Phase.accel`), without forming Bᵀ M B.

    With z = N ÿ_b and μ = M_ww z + M_wo ÿ_o (so that ÿ_b = M_b⁻¹ (r_b − Nᵀ μ)):
    [[I + W M_ww, W M_wo], [M_ow, M_oo]] [z; ÿ_o] = [N M_b⁻¹ r_b; r_o], W = N M_b⁻¹ Nᵀ.
    ``P_b`` holds the bridge load at t (it is not modified).
    """
    nb = Minv.shape[0]
    na = x0a.shape[0]
    no = o.shape[0]
    nt = M_t.shape[0]
    H = np.zeros((na, 4))
    h, d1, d2 = np.empty(4), np.empty(4), np.empty(4)
    u_t, v_t, a_t = np.zeros(nt), np.zeros(nt), np.zeros(nt)
    for j in range(no):
        u_t[o[j]] = y[nb + j]
        v_t[o[j]] = yd[nb + j]
    for i in range(na):
        hermite3(x0a[i] + V * t, x_e[i], l_e[i], h, d1, d2)
        su, sv, sa = r[i], V * r1[i], V * V * r2[i]
        for k in range(4):
            c = cols[i, k]
            if c >= 0:
                H[i, k] = h[k]
                su += h[k] * y[c]
                sv += h[k] * yd[c] + V * d1[k] * y[c]
                sa += 2.0 * V * d1[k] * yd[c] + V * V * d2[k] * y[c]
        u_t[wdof[i]], v_t[wdof[i]], a_t[wdof[i]] = su, sv, sa
    q = -P_t.copy()
    matvec(M_t, a_t, q, 1.0)
    matvec(C_t, v_t, q, 1.0)
    matvec(K_t, u_t, q, 1.0)
    rb = P_b.copy()
    matvec(C_b, yd, rb, -1.0)
    matvec(K_b, y, rb, -1.0)
    for i in range(na):
        for k in range(4):
            if cols[i, k] >= 0:
                rb[cols[i, k]] -= H[i, k] * q[wdof[i]]
    xb = np.zeros(nb)
    matvec(Minv, rb, xb, 1.0)
    m = na + no
    A = np.zeros((m, m))
    sol = np.zeros(m)
    W = np.zeros((na, na))
    for i in range(na):
        acc = 0.0
        for k in range(4):
            if cols[i, k] >= 0:
                acc += H[i, k] * xb[cols[i, k]]
        sol[i] = acc
        for j in range(na):
            acc = 0.0
            for k in range(4):
                ck = cols[i, k]
                if ck < 0:
                    continue
                for l in range(4):
                    cl = cols[j, l]
                    if cl >= 0:
                        acc += H[i, k] * Minv[ck, cl] * H[j, l]
            W[i, j] = acc
    for i in range(na):
        A[i, i] = 1.0
        for j in range(na):
            for k in range(na):
                A[i, j] += W[i, k] * M_t[wdof[k], wdof[j]]
        for j in range(no):
            acc = 0.0
            for k in range(na):
                acc += W[i, k] * M_t[wdof[k], o[j]]
            A[i, na + j] = acc
    for i in range(no):
        sol[na + i] = -q[o[i]]
        for j in range(na):
            A[na + i, j] = M_t[o[i], wdof[j]]
        for j in range(no):
            A[na + i, na + j] = M_t[o[i], o[j]]
    solve_small(A, sol)
    # ÿ_b = M_b⁻¹ (r_b − Nᵀ μ), μ = M_ww z + M_wo ÿ_o
    for i in range(na):
        mu = 0.0
        for j in range(na):
            mu += M_t[wdof[i], wdof[j]] * sol[j]
        for j in range(no):
            mu += M_t[wdof[i], o[j]] * sol[na + j]
        if mu != 0.0:
            for k in range(4):
                c = cols[i, k]
                if c >= 0:
                    f = H[i, k] * mu
                    for a in range(nb):
                        xb[a] -= Minv[a, c] * f
    for a in range(nb):
        ydd[a] = xb[a]
    for j in range(no):
        ydd[nb + j] = sol[na + j]
    # λ = q_w + M_ww N ÿ_b + M_wo ÿ_o
    for i in range(na):
        acc = 0.0
        for k in range(4):
            if cols[i, k] >= 0:
                acc += H[i, k] * xb[cols[i, k]]
        sol[i] = acc
    for i in range(na):
        acc = q[wdof[i]]
        for j in range(na):
            acc += M_t[wdof[i], wdof[j]] * sol[j]
        for j in range(no):
            acc += M_t[wdof[i], o[j]] * sol[na + j]
        lam[i] = acc


def active_bridge_dofs(M, C, K, track_dofs, loads):
    """Free bridge dofs that can move: those connected (through the nonzeros of M, C, K) to a
    track dof or to a loaded dof. The others start at rest with no load and stay at zero
    (e.g. the axial dofs of a straight beam), so the reference solvers drop them."""
    seeds = np.zeros(M.shape[0], dtype=bool)
    seeds[np.asarray(track_dofs, dtype=np.int64)] = True
    for vec in loads:
        seeds |= np.asarray(vec) != 0
    return dofs_with(component_labels(M, C, K), seeds)


class CoupledSystem:
    """Matrices, loads and constraint geometry of a train on a bridge, for the reference solvers.

    Dense matrices (the reference solvers target models of up to a few hundred dofs).

    Parameters
    ----------
    model : Model (the bridge), or None for rigid ground.
    constraint : MovingLoadConstraint (its ``interpolation`` is ignored: the reference uses the
        exact Hermite rows), or :class:`RigidGround` with ``model=None``.
    bridge_self_weight : add the deck's weight −g M 1_y, as CoupledAnalysis does: the rail is
        straight at the deck's self-weight state (track laid on the deflected deck), so the
        self-weight deflection u_sw = K⁻¹ P_sw is a static offset of the bridge response
        (``sag``), added to the outputs; the dynamics run without it.
    gravity : g [m/s²] for the bridge self weight (the train's gravity load is used as built).
    irregularity_breaks : positions [m] where r'' (or r', r) of the irregularity is not smooth;
        the solvers restart when a contact wheel passes one.
    """

    def __init__(self, model, constraint, bridge_self_weight=False, gravity=GRAVITY, irregularity_breaks=()):
        gravity = as_positive(gravity, "reference solver", "gravity [m/s²]", AnalysisError, allow_zero=True)
        if model is None:
            if not isinstance(constraint, RigidGround):
                raise ModelError("reference solver: model=None (rigid ground) needs a RigidGround constraint")
            self.assembly, self.track = None, None
            self.keep = np.zeros(0, dtype=np.int64)
            self.sag = np.zeros(0)
            n_b = 0
            self.M_b = self.C_b = self.K_b = np.zeros((0, 0))
            self.P_b0 = np.zeros(0)
            self.patterns = []
        else:
            if not isinstance(constraint, MovingLoadConstraint):
                raise ModelError(f"reference solver: constraint must be a MovingLoadConstraint, "
                                 f"got {type(constraint).__name__}")
            asm = model.build()
            self.assembly, self.track = asm, constraint.track
            M_b, C_b, K_b = asm.M, asm.C, asm.K
            self.sag = np.zeros(asm.n_free)
            if bridge_self_weight:
                # the rail is laid on the deck deflected by its own weight (as CoupledAnalysis):
                # u_b = u_sw + ũ_b with K u_sw = P_sw, and ũ_b obeys the equations without P_sw
                ones_y = np.zeros(asm.n_full)
                ones_y[1::asm.ndf] = 1.0
                p_sw = -gravity * (asm.M_full @ ones_y)[asm.full_of_free]
                self.sag = spsolve(K_b.tocsc(), p_sw)
            patterns = [(p, asm.load_vector(p)) for p in model.patterns.values()]
            self.keep = active_bridge_dofs(M_b, C_b, K_b, constraint.track.free_index,
                                           [vec for _, vec in patterns])
            keep = self.keep
            n_b = len(keep)
            self.M_b, self.C_b, self.K_b = (a[keep][:, keep].toarray() for a in (M_b, C_b, K_b))
            self.P_b0 = np.zeros(n_b)
            self.patterns = [(p, vec[keep]) for p, vec in patterns]
        train = constraint.train
        self.n_b, self.n_t = n_b, train.n_dof
        self.M_t, self.C_t, self.K_t = (np.asarray(a.toarray()) for a in (train.M, train.C, train.K))
        self.P_t = np.array(train.gravity_load, dtype=float)
        self.wheel_dofs = np.array(train.wheel_dofs, dtype=np.int64)
        self.V = float(train.speed)
        self.x0 = np.array(constraint.x0, dtype=float)
        self.x0_force = np.array(constraint.x0_force, dtype=float)
        self.wheel_forces = np.array(train.wheel_forces, dtype=float)
        self.n_c = len(self.x0)
        self.profile = irregularity_functions(constraint.irregularity, self.x0 if self.n_c else [0.0])
        self.smooth = constraint.irregularity is None
        self.Minv = np.linalg.inv(self.M_b) if n_b else np.zeros((0, 0))
        breaks = list(np.asarray(irregularity_breaks, dtype=float).ravel())
        x_range = getattr(constraint.irregularity, "x_range", None)
        if x_range is not None:     # a sampled profile drops to zero outside its range
            breaks.extend(x_range)
        self.irregularity_breaks = np.array(breaks, dtype=float)
        self.M = np.zeros((n_b + self.n_t,) * 2)
        self.C, self.K = self.M.copy(), self.M.copy()
        for big, b, t in ((self.M, self.M_b, self.M_t), (self.C, self.C_b, self.C_t), (self.K, self.K_b, self.K_t)):
            big[:n_b, :n_b], big[n_b:, n_b:] = b, t
        loads = np.asarray(train.train.static_wheel_loads, dtype=float)
        self.load_scale = float(loads.max()) if loads.size else 1.0
        if self.track is not None:
            tr = self.track
            self.nodes_x = np.append(tr.x_start, tr.x_end)
            local = -np.ones(self.assembly.n_free, dtype=np.int64)
            local[self.keep] = np.arange(n_b)
            self.el_cols = np.where(tr.dofs >= 0, local[tr.free_index[np.maximum(tr.dofs, 0)]], -1)
        else:
            self.nodes_x = np.zeros(0)

    # -- geometry ---------------------------------------------------------------------------
    def breakpoints(self, t_end):
        """Restart times in [0, t_end]: a wheel on a track node or end, a contact wheel on an
        irregularity break; times closer than 1e-10 (relative) are merged."""
        times = [0.0, float(t_end)]
        if self.V > 0:
            x0 = np.concatenate([self.x0, self.x0_force])
            if self.nodes_x.size and x0.size:
                times.extend(((self.nodes_x[None, :] - x0[:, None]) / self.V).ravel())
            if self.irregularity_breaks.size and self.x0.size:
                times.extend(((self.irregularity_breaks[None, :] - self.x0[:, None]) / self.V).ravel())
        times = np.array(sorted(t for t in times if 0.0 <= t <= t_end))
        keep = np.concatenate([[True], np.diff(times) > 1e-10 * max(1.0, t_end)])
        times = times[keep]
        times[-1] = t_end
        return times

    def hosts(self, x):
        """Host element of each position (-1 off the track); use inside a segment, not at a node."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if self.track is None:
            return -np.ones(x.shape, dtype=np.int64)
        tr = self.track
        return np.array([host_element(xi, tr.x_start, tr.length) for xi in x], dtype=np.int64)

    def host_data(self, hosts):
        """(x_e, l_e, cols) of host elements (cols: bridge free dofs, -1 where fixed or off)."""
        n = len(hosts)
        if self.track is None or n == 0:
            return np.zeros(n), np.ones(n), -np.ones((n, 4), dtype=np.int64)
        on = hosts >= 0
        h = np.maximum(hosts, 0)
        x_e = np.where(on, self.track.x_start[h], 0.0)
        l_e = np.where(on, self.track.length[h], 1.0)
        cols = np.where(on[:, None], self.el_cols[h], -1)
        return x_e, l_e, cols

    def rows(self, x, x_e, l_e, cols):
        """Dense N, N' = dN/dx, N'' (n_w, n_b) of wheels at ``x`` on the given hosts."""
        n = len(x)
        N, N1, N2 = np.zeros((n, self.n_b)), np.zeros((n, self.n_b)), np.zeros((n, self.n_b))
        if n == 0 or self.n_b == 0:
            return N, N1, N2
        h, d1, d2 = hermite_rows(np.asarray(x, dtype=float), x_e, l_e)
        mask = cols >= 0
        r = np.repeat(np.arange(n), 4).reshape(n, 4)[mask]
        c = cols[mask]
        N[r, c], N1[r, c], N2[r, c] = h[mask], d1[mask], d2[mask]
        return N, N1, N2

    def bridge_load(self, t, force_x_e, force_l_e, force_cols):
        """P_b(t): constant part, pattern loads and force-only wheels [N] (n_b,)."""
        p = self.P_b0.copy()
        for pattern, vec in self.patterns:
            p += pattern.factors(np.array([t]))[0] * vec
        if len(self.x0_force) and self.n_b:
            add_wheel_loads(t, self.V, self.x0_force, self.wheel_forces, force_cols, force_x_e, force_l_e, p)
        return p

    def default_atol(self, rtol, u_dead):
        """Absolute tolerance: rtol × max(|dead-load displacement|, 1 mm), for every state."""
        scale = max(float(np.abs(u_dead).max(initial=0.0)), 1e-3)
        return rtol * scale


class Phase:
    """The reduced ODE on one interval: a fixed set of wheels in contact (``active``, bool (n_c,))
    and fixed host elements (those at ``t_mid``). Wheels not in contact are free train dofs."""

    def __init__(self, system, t_mid, active=None):
        s = system
        self.s = s
        self.active = np.ones(s.n_c, dtype=bool) if active is None else np.asarray(active, dtype=bool)
        self.aw = np.flatnonzero(self.active)
        self.w = s.wheel_dofs[self.aw]
        self.o = np.setdiff1d(np.arange(s.n_t), self.w).astype(np.int64)
        nb, no = s.n_b, len(self.o)
        self.n_y = nb + no
        self.hosts_c = s.hosts(s.x0 + s.V * t_mid) if s.n_c else np.zeros(0, dtype=np.int64)
        self.hosts_f = s.hosts(s.x0_force + s.V * t_mid) if len(s.x0_force) else np.zeros(0, dtype=np.int64)
        self.c_data = s.host_data(self.hosts_c)
        self.f_data = s.host_data(self.hosts_f)
        self.a_data = tuple(a[self.aw] for a in self.c_data)
        M_t, w, o = s.M_t, self.w, self.o
        self.Mww, self.Mwo, self.Mow = M_t[np.ix_(w, w)], M_t[np.ix_(w, o)], M_t[np.ix_(o, w)]
        self.A0 = np.zeros((self.n_y, self.n_y))
        self.A0[:nb, :nb] = s.M_b
        self.A0[nb:, nb:] = M_t[np.ix_(o, o)]
        self.x0a = s.x0[self.aw].copy()
        self.zeros_a = np.zeros(len(self.aw))
        self.load_varies = bool(s.patterns) or bool(len(s.x0_force) and nb)

    # -- constraint data ------------------------------------------------------------------
    def constraint(self, t):
        """N, N', N'' (n_a, n_b) and r, r', r'' (n_a,) of the wheels in contact at time t."""
        s = self.s
        x = s.x0[self.aw] + s.V * t
        N, N1, N2 = s.rows(x, *self.a_data)
        return N, N1, N2, s.profile(x, 0), s.profile(x, 1), s.profile(x, 2)

    def full(self, t, y, yd, ydd=None):
        """Full response (u_b, v_b, a_b, u_t, v_t, a_t) of reduced state (y, ẏ[, ÿ]); without
        ÿ the accelerations hold only the constraint's ÿ-free part (2Ṅẏ + N̈y + r̈)."""
        s, nb, V, w, o = self.s, self.s.n_b, self.s.V, self.w, self.o
        N, N1, N2, r, r1, r2 = self.constraint(t)
        yb, ydb = y[:nb], yd[:nb]
        u_t, v_t, a_t = np.zeros(s.n_t), np.zeros(s.n_t), np.zeros(s.n_t)
        u_t[o], v_t[o] = y[nb:], yd[nb:]
        u_t[w] = N @ yb + r
        v_t[w] = N @ ydb + V * (N1 @ yb + r1)
        a_t[w] = 2 * V * (N1 @ ydb) + V * V * (N2 @ yb + r2)
        a_b = np.zeros(nb)
        if ydd is not None:
            a_b = ydd[:nb].copy()
            a_t[o] = ydd[nb:]
            a_t[w] += N @ ydd[:nb]
        return yb.copy(), ydb.copy(), a_b, u_t, v_t, a_t, N

    def accel(self, t, y, yd):
        """ÿ (n_y,) and the contact forces λ (n_a,) [N] of the wheels in contact."""
        s = self.s
        if s.smooth:
            r = r1 = r2 = self.zeros_a
        else:
            x = self.x0a + s.V * t
            r, r1, r2 = s.profile(x, 0), s.profile(x, 1), s.profile(x, 2)
        p_b = s.bridge_load(t, *self.f_data) if self.load_varies else s.P_b0
        ydd, lam = np.empty(self.n_y), np.empty(len(self.aw))
        y, yd = np.ascontiguousarray(y), np.ascontiguousarray(yd)
        reduced_accel(t, y, yd, s.V, s.Minv, s.C_b, s.K_b, p_b, s.M_t, s.C_t, s.K_t, s.P_t, self.x0a, self.w,
                      self.a_data[2], self.a_data[0], self.a_data[1], r, r1, r2, self.o, ydd, lam)
        return ydd, lam

    def mass(self, N):
        """Bᵀ M B."""
        nb = self.s.n_b
        A = self.A0.copy()
        if len(self.w) and nb:
            A[:nb, :nb] += N.T @ self.Mww @ N
            A[:nb, nb:] += N.T @ self.Mwo
            A[nb:, :nb] += self.Mow @ N
        return A

    def operators(self, t):
        """Dense B, Ḃ, B̈ (n_b + n_t, n_y) and b, ḃ, b̈ of u = B y + b at time t."""
        s, nb, V = self.s, self.s.n_b, self.s.V
        N, N1, N2, r, r1, r2 = self.constraint(t)
        n = nb + s.n_t
        B, Bd, Bdd = np.zeros((n, self.n_y)), np.zeros((n, self.n_y)), np.zeros((n, self.n_y))
        B[:nb, :nb] = np.eye(nb)
        B[nb + self.o, nb + np.arange(len(self.o))] = 1.0
        B[nb + self.w, :nb], Bd[nb + self.w, :nb], Bdd[nb + self.w, :nb] = N, V * N1, V * V * N2
        b, bd, bdd = np.zeros(n), np.zeros(n), np.zeros(n)
        b[nb + self.w], bd[nb + self.w], bdd[nb + self.w] = r, V * r1, V * V * r2
        return B, Bd, Bdd, b, bd, bdd

    def linear_operator(self, t):
        """(A, D, E, F) of the reduced ODE A ÿ + D ẏ + E y = F at time t (the long form, for the
        Jacobian and for checks of :meth:`accel`)."""
        s = self.s
        B, Bd, Bdd, b, bd, bdd = self.operators(t)
        P = np.concatenate([s.bridge_load(t, *self.f_data), s.P_t])
        A = B.T @ s.M @ B
        D = B.T @ (2 * s.M @ Bd + s.C @ B)
        E = B.T @ (s.M @ Bdd + s.C @ Bd + s.K @ B)
        F = B.T @ (P - s.M @ bdd - s.C @ bd - s.K @ b)
        return A, D, E, F

    # -- first-order form for solve_ivp ---------------------------------------------------
    def pack(self, y, yd):
        """First-order state [y; ẏ] (one dummy zero when there is nothing to integrate)."""
        return np.concatenate([y, yd]) if self.n_y else np.zeros(1)

    def unpack(self, z):
        return z[: self.n_y], z[self.n_y: 2 * self.n_y]

    def fun(self, t, z):
        y, yd = self.unpack(z)
        if not self.n_y:
            return np.zeros(1)
        ydd, _ = self.accel(t, y, yd)
        return np.concatenate([yd, ydd])

    def jac(self, t, z):
        n = self.n_y
        if not n:
            return np.zeros((1, 1))
        A, D, E, _ = self.linear_operator(t)
        J = np.zeros((2 * n, 2 * n))
        J[:n, n:] = np.eye(n)
        J[n:, :n] = -np.linalg.solve(A, E)
        J[n:, n:] = -np.linalg.solve(A, D)
        return J

    # -- restarts --------------------------------------------------------------------------
    def reduce(self, t, u_b, v_b, u_t, v_t):
        """(y, ẏ) of a full state: y = [u_b; u_o]; ẏ by the impulse law
        Bᵀ M B ẏ = Bᵀ M (u̇ − Ḃ y − ḃ) (perfectly inelastic for the wheels in contact)."""
        s, V, w = self.s, self.s.V, self.w
        y = np.concatenate([u_b, u_t[self.o]])
        N, N1, _, _, r1, _ = self.constraint(t)
        rel = v_t.copy()
        rel[w] -= V * (N1 @ u_b + r1)
        mt = s.M_t @ rel
        rhs = np.concatenate([s.M_b @ v_b + N.T @ mt[w], mt[self.o]])
        yd = np.linalg.solve(self.mass(N), rhs) if self.n_y else np.zeros(0)
        return y, yd


def _check_times(t_end, t_eval):
    t_end = as_number(t_end, "reference solver", "t_end [s]", AnalysisError)
    if not (np.isfinite(t_end) and t_end > 0):
        raise AnalysisError(f"reference solver: t_end must be > 0, got {t_end}")
    if t_eval is None:
        t_eval = np.linspace(0.0, t_end, int(round(t_end / 1e-3)) + 1)
    t_eval = as_numbers(t_eval, "reference solver", "t_eval [s]", AnalysisError).ravel()
    if t_eval.size == 0 or np.any(np.diff(t_eval) <= 0) or t_eval[0] < 0 or t_eval[-1] > t_end * (1 + 1e-12):
        raise AnalysisError("reference solver: t_eval must be increasing, within [0, t_end]")
    return t_end, np.minimum(t_eval, t_end)


def segment_points(t_eval, ta, tb, last):
    """Indices of the output times that belong to segment [ta, tb) ([ta, tb] for the last)."""
    return np.flatnonzero((t_eval >= ta) & ((t_eval < tb) | (last & (t_eval <= tb))))


def dead_load(system, t_mid=0.0, active=None):
    """Static equilibrium at t = 0 with the ``active`` contact wheels (default all) on the rail:
    Bᵀ K B y = Bᵀ (P − K b), host elements those of time ``t_mid`` (the first segment's
    midpoint). Returns (u_b, u_t, λ of the active wheels)."""
    phase = Phase(system, t_mid, active)
    B, _, _, b, _, _ = phase.operators(0.0)
    P = np.concatenate([system.bridge_load(0.0, *phase.f_data), system.P_t])
    Kr = B.T @ system.K @ B
    rhs = B.T @ (P - system.K @ b)
    try:
        y = np.linalg.solve(Kr, rhs) if phase.n_y else np.zeros(0)
    except np.linalg.LinAlgError:
        raise AnalysisError("reference solver: the static train-bridge system is singular") from None
    u = B @ y + b
    u_b, u_t = u[: system.n_b], u[system.n_b:]
    lam = (system.K_t @ u_t - system.P_t)[phase.w]
    return u_b, u_t, lam


def solve(model, constraint, t_end, t_eval=None, rtol=1e-10, atol=None, method="dop853",
          bridge_self_weight=False, gravity=GRAVITY, irregularity_breaks=()):
    """R1: the bilateral train-bridge problem by constraint elimination (module docstring).

    Parameters
    ----------
    model : Model (the bridge), or None with a :class:`RigidGround` constraint.
    constraint : MovingLoadConstraint (its ``interpolation`` is ignored: exact Hermite rows).
    t_end : end time [s] (the analysis starts at t = 0 from the dead-load equilibrium, bridge
        and car bodies at rest: ẏ(0) = 0).
    t_eval : (n_t,) increasing output times in [0, t_end]; default every 1 ms. An output time
        that coincides with a restart gets the value just after it (the last one: just before).
    rtol, atol : tolerances of the integrator; atol default rtol × max(|dead-load u|, 1 mm).
    method : 'dop853' (default: E. Hairer's Fortran DOP853 through scipy.integrate.ode, the
        scheme of solve_ivp's 'DOP853' at a fraction of the overhead per step), or a solve_ivp
        method: 'DOP853', 'Radau' (analytic Jacobian; far slower here, see
        docs/theory/reference_solvers.md), 'BDF', 'RK45' ...
    bridge_self_weight, gravity : as in :class:`vtsi.coupled.CoupledAnalysis`.
    irregularity_breaks : positions [m] where the irregularity is not C² (restarts there).

    Returns
    -------
    ReferenceSolution
    """
    t_end, t_eval = _check_times(t_end, t_eval)
    s = CoupledSystem(model, constraint, bridge_self_weight, gravity, irregularity_breaks)
    bounds = s.breakpoints(t_end)
    u_b, u_t, lam0 = dead_load(s, 0.5 * (bounds[0] + bounds[1]))
    dead = (u_b.copy(), u_t.copy(), lam0)
    atol = s.default_atol(rtol, np.concatenate([u_b, u_t])) if atol is None else atol
    v_b, v_t = np.zeros(s.n_b), np.zeros(s.n_t)
    out = _Histories(len(t_eval), s)
    impulses, stats = [], {"segments": len(bounds) - 1}
    for k, (ta, tb) in enumerate(zip(bounds[:-1], bounds[1:])):
        phase = Phase(s, 0.5 * (ta + tb))
        if k == 0:
            y, yd = np.concatenate([u_b, u_t[phase.o]]), np.zeros(phase.n_y)
        else:
            y, yd = phase.reduce(ta, u_b, v_b, u_t, v_t)
            _record_impulses(impulses, s, phase, ta, v_t, y, yd)
        idx = segment_points(t_eval, ta, tb, k == len(bounds) - 2)
        times = np.unique(np.concatenate([t_eval[idx], [tb]]))
        sol_t, sol_y, _ = integrate_segment(phase, ta, tb, phase.pack(y, yd), times, method, rtol, atol, stats)
        for j, i in enumerate(idx):      # times[:len(idx)] are t_eval[idx]
            y, yd = phase.unpack(sol_y[:, j])
            ydd, lam = phase.accel(sol_t[j], y, yd)
            out.store(i, phase.full(sol_t[j], y, yd, ydd), phase.aw, lam)
        y, yd = phase.unpack(sol_y[:, -1])
        u_b, v_b, _, u_t, v_t, _, _ = phase.full(tb, y, yd)
    return out.result(t_eval, impulses, s, dead, bounds, stats)


def integrate_segment(phase, ta, tb, z0, times, method, rtol, atol, stats, events=None):
    """Integrate ``phase``'s first-order ODE from ``ta`` to ``tb`` (or to the first terminal
    event) and return (t (m,), z (n_z, m)) at ``times`` (+ the event time, if one ended it), and
    the event's index (or None). ``method``: 'dop853' (E. Hairer's Fortran DOP853 through
    :class:`scipy.integrate.ode`: the same scheme as solve_ivp's, with far less overhead per
    step; no events) or a solve_ivp method name."""
    if method == "dop853" and not events:
        solver = ode(phase.fun).set_integrator("dop853", rtol=rtol, atol=atol, nsteps=10 ** 9)
        solver.set_initial_value(z0, ta)
        out = np.empty((len(z0), len(times)))
        count = [0]
        solver.set_solout(lambda t, z: count.__setitem__(0, count[0] + 1))
        for j, t in enumerate(times):
            if t - solver.t > 1e-13 * max(1.0, abs(t)):   # (closer: the state is kept)
                solver.integrate(t)
                if not solver.successful():
                    raise AnalysisError(f"reference solver: DOP853 failed at t = {solver.t:.6g} s "
                                        f"(return code {solver.get_return_code()})")
            out[:, j] = solver.y
        stats["nsteps"] = stats.get("nsteps", 0) + count[0]
        return np.asarray(times), out, None
    if method == "dop853":
        method = "DOP853"
    options = {"jac": phase.jac} if method in ("Radau", "BDF", "LSODA") else {}
    if events:
        options["max_step"] = (tb - ta) / 16.0   # sample the event functions finely enough
    sol = solve_ivp(phase.fun, (ta, tb), z0, method=method, t_eval=times, rtol=rtol, atol=atol,
                    events=events, **options)
    if sol.status < 0:
        raise AnalysisError(f"reference solver: solve_ivp failed on [{ta:.6g}, {tb:.6g}] s: {sol.message}")
    for key in ("nfev", "njev", "nlu"):
        stats[key] = stats.get(key, 0) + int(getattr(sol, key))
    hit = None
    if sol.status == 1:
        hit = next(i for i, te in enumerate(sol.t_events) if len(te))
        te, ze = sol.t_events[hit][0], sol.y_events[hit][0]
        # an event before the first output time: scipy gives t and y as empty lists
        t_out, y_out = np.asarray(sol.t, dtype=float), np.asarray(sol.y, dtype=float).reshape(len(z0), -1)
        keep = t_out < te
        return np.append(t_out[keep], te), np.column_stack([y_out[:, keep], ze]), hit
    return sol.t, sol.y, None


def _record_impulses(impulses, s, phase, t, v_t_before, y, yd):
    """Impulse ι = (M_t Δu̇_t)[wheel] of each wheel in contact at a restart, if not negligible."""
    _, _, _, _, v_t, _, _ = phase.full(t, y, yd)
    iota = (s.M_t @ (v_t - v_t_before))[phase.w]
    for i, value in zip(phase.aw, iota):
        if abs(value) > IMPULSE_THRESHOLD * s.load_scale:
            impulses.append((float(t), int(i), float(value)))


class _Histories:
    def __init__(self, n, s):
        z = lambda m: np.zeros((n, m))
        self.keep, self.sag = s.keep, s.sag
        n_free = s.assembly.n_free if s.assembly is not None else 0
        self.b = [z(n_free) + s.sag, z(n_free), z(n_free)]
        self.t = [z(s.n_t), z(s.n_t), z(s.n_t)]
        self.lam = z(s.n_c)

    def store(self, i, full, aw, lam):
        u_b, v_b, a_b, u_t, v_t, a_t, _ = full
        self.b[0][i, self.keep] = self.sag[self.keep] + u_b
        self.b[1][i, self.keep], self.b[2][i, self.keep] = v_b, a_b
        self.t[0][i], self.t[1][i], self.t[2][i] = u_t, v_t, a_t
        self.lam[i] = 0.0
        self.lam[i, aw] = lam

    def result(self, t_eval, impulses, s, dead, bounds, stats, **extra):
        u_dead = self.sag.copy()
        u_dead[self.keep] += dead[0]
        dead = (u_dead,) + tuple(dead[1:])
        return ReferenceSolution(
            t=t_eval.copy(), bridge_u=self.b[0], bridge_v=self.b[1], bridge_a=self.b[2],
            train_u=self.t[0], train_v=self.t[1], train_a=self.t[2], contact_force=self.lam,
            impulses=impulses, dead_load={"bridge_u": dead[0], "train_u": dead[1], "contact_force": dead[2]},
            assembly=s.assembly, breakpoints=bounds, stats=stats, **extra)
