"""Reference solution R2: the bilateral train-bridge DAE with SUNDIALS IDA (scikit-sundae).

The full system (docs/theory/coupled_step.md §1), with u = [u_b; u_t], M = blkdiag(M_b, M_t)
(likewise C, K), G(t) = [−N(t), S] and P = [P_b(t); P_t],

    M ü + C u̇ + K u = P + Gᵀ λ,        G u = r(t)            (index 3),

is solved in the index-1 form that differentiates the constraint twice: with v = u̇,

    u̇ − v = 0
    M v̇ + C v + K u − P − Gᵀ λ = 0
    G v̇ + 2 Ġ v + G̈ u − r̈ = 0,        Ġ = [−V N'(x), 0],  G̈ = [−V² N''(x), 0],  r̈ = V² r''(x),

λ algebraic. The pencil [[M, −Gᵀ], [G, 0]] is regular whenever G has full row rank and M is
positive definite on the null space of G, so a massless contact point (Yang & Yau's sprung mass)
is allowed. IDA (variable-order BDF, dense direct linear solver, analytic Jacobian
J = ∂F/∂y + c_j ∂F/∂ẏ) integrates from one restart time to the next; the restarts are those of
R1 (:meth:`vtsi.reference.elimination.CoupledSystem.breakpoints`), and at each one the state is
made consistent again, independently of R1's code:

- position: the wheel dofs are reset to N u_b + r (removes the drift of the index-1 form);
- velocity: [[M, −Gᵀ], [G, 0]] [v⁺; ι] = [M v⁻; V N' u_b + V r'] (the impulse ι [N·s] of a
  perfectly inelastic bilateral constraint; nonzero where the rail line has a kink);
- acceleration and λ: [[M, −Gᵀ], [G, 0]] [a; λ] = [P − C v − K u; r̈ − 2Ġ v − G̈ u].

References
----------
Hindmarsh, A.C. et al. (2005) SUNDIALS: Suite of nonlinear and differential/algebraic equation
solvers. ACM TOMS 31(3), 363-396. Brenan, K.E., Campbell, S.L., Petzold, L.R. (1996) Numerical
Solution of Initial-Value Problems in Differential-Algebraic Equations, SIAM (index reduction).
"""
import numpy as np
from numba import njit

from vtsi.errors import AnalysisError, ModelError
from vtsi.reference.elimination import (IMPULSE_THRESHOLD, CoupledSystem, _check_times, _Histories, dead_load,
                                        hermite3, matvec, segment_points)
from vtsi.vehicle import GRAVITY

FORMULATIONS = ("index1",)


@njit(cache=True)
def dae_residual(t, Y, Yp, V, M, C, K, P, nb, x0, wdof, cols, x_e, l_e, r2, res):
    """Residual of the index-1 DAE (module docstring); ``P`` is the load at t (n,), ``r2`` r''."""
    n = M.shape[0]
    nc = x0.shape[0]
    for i in range(n):
        res[i] = Yp[i] - Y[n + i]
    u = Y[:n]
    v = Y[n: 2 * n]
    vp = Yp[n: 2 * n]
    f = -P.copy()
    matvec(M, vp, f, 1.0)
    matvec(C, v, f, 1.0)
    matvec(K, u, f, 1.0)
    for i in range(n):
        res[n + i] = f[i]
    h, d1, d2 = np.empty(4), np.empty(4), np.empty(4)
    for i in range(nc):
        lam = Y[2 * n + i]
        w = nb + wdof[i]
        res[n + w] -= lam
        g = vp[w] - V * V * r2[i]
        hermite3(x0[i] + V * t, x_e[i], l_e[i], h, d1, d2)
        for k in range(4):
            c = cols[i, k]
            if c >= 0:
                res[n + c] += h[k] * lam
                g -= h[k] * vp[c] + 2.0 * V * d1[k] * v[c] + V * V * d2[k] * u[c]
        res[2 * n + i] = g


class _Segment:
    """IDA residual and Jacobian on one interval between restarts (fixed host elements)."""

    def __init__(self, s, t_mid):
        self.s = s
        n = s.n_b + s.n_t
        self.n = n
        x_c, x_f = s.x0 + s.V * t_mid, s.x0_force + s.V * t_mid
        self.c_data = s.host_data(s.hosts(x_c)) if s.n_c else s.host_data(np.zeros(0, dtype=np.int64))
        self.f_data = s.host_data(s.hosts(x_f)) if len(x_f) else s.host_data(np.zeros(0, dtype=np.int64))
        self.load_varies = bool(s.patterns) or bool(len(s.x0_force) and s.n_b)
        self.P_const = np.concatenate([s.P_b0, s.P_t])
        self.zeros = np.zeros(s.n_c)
        m = 2 * n + s.n_c
        self.J0, self.J1 = np.zeros((m, m)), np.zeros((m, m))
        self.J0[:n, n: 2 * n] = -np.eye(n)
        self.J1[:n, :n] = np.eye(n)
        self.J0[n: 2 * n, :n] = s.K
        self.J0[n: 2 * n, n: 2 * n] = s.C
        self.J1[n: 2 * n, n: 2 * n] = s.M
        w = s.n_b + s.wheel_dofs
        self.J0[n + w, 2 * n + np.arange(s.n_c)] = -1.0
        self.J1[2 * n + np.arange(s.n_c), n + w] = 1.0

    def load(self, t):
        if not self.load_varies:
            return self.P_const
        return np.concatenate([self.s.bridge_load(t, *self.f_data), self.s.P_t])

    def profile2(self, t):
        s = self.s
        return self.zeros if s.smooth else s.profile(s.x0 + s.V * t, 2)

    def constraint(self, t):
        s = self.s
        x = s.x0 + s.V * t
        N, N1, N2 = s.rows(x, *self.c_data)
        return N, N1, N2, s.profile(x, 0), s.profile(x, 1), s.profile(x, 2)

    def residual(self, t, y, yp, res):
        s = self.s
        dae_residual(t, y, yp, s.V, s.M, s.C, s.K, self.load(t), s.n_b, s.x0, s.wheel_dofs, self.c_data[2],
                     self.c_data[0], self.c_data[1], self.profile2(t), res)

    def dense_jacobian(self, t, cj):
        s, n, nb = self.s, self.n, self.s.n_b
        J = self.J0 + cj * self.J1
        N, N1, N2, _, _, _ = self.constraint(t)
        lam = 2 * n + np.arange(s.n_c)
        J[n: n + nb, lam] = N.T
        J[2 * n:, :nb] = -s.V ** 2 * N2
        J[2 * n:, n: n + nb] = -2 * s.V * N1 - cj * N
        return J

    def jacobian(self, t, y, yp, res, cj, JJ):
        JJ[:, :] = self.dense_jacobian(t, cj)

    def consistent(self, t, u, v):
        """Consistent (u, v, a, λ, ι) at the start of the interval from (u, v⁻) (module docstring)."""
        s, n, nb = self.s, self.n, self.s.n_b
        N, N1, N2, r, r1, r2 = self.constraint(t)
        w = nb + s.wheel_dofs
        u = u.copy()
        u[w] = N @ u[:nb] + r
        G = np.zeros((s.n_c, n))
        G[:, :nb] = -N
        G[np.arange(s.n_c), w] = 1.0
        saddle = np.block([[s.M, -G.T], [G, np.zeros((s.n_c, s.n_c))]])
        V = s.V
        sol = np.linalg.solve(saddle, np.concatenate([s.M @ v, V * (N1 @ u[:nb] + r1)]))
        v, iota = sol[:n], sol[n:]
        rhs = np.concatenate([self.load(t) - s.C @ v - s.K @ u,
                              V * V * r2 + 2 * V * (N1 @ v[:nb]) + V * V * (N2 @ u[:nb])])
        sol = np.linalg.solve(saddle, rhs)
        return u, v, sol[:n], sol[n:], iota


def solve(model, constraint, t_end, t_eval=None, rtol=1e-10, atol=None, method="index1",
          bridge_self_weight=False, gravity=GRAVITY, irregularity_breaks=(), max_num_steps=10 ** 7):
    """R2: the bilateral train-bridge DAE in index-1 form with SUNDIALS IDA (module docstring).

    Same parameters and result as :func:`vtsi.reference.elimination.solve`, except ``method``,
    the formulation: 'index1' (the only one). ``atol`` default: rtol × max(|dead-load u|, 1 mm)
    for u and v, rtol × the largest static wheel load for λ.
    """
    try:
        from sksundae.ida import IDA
    except ImportError as exc:  # optional dependency (the 'test' extra)
        raise ModelError("reference solver R2 needs scikit-sundae (pip install scikit-sundae)") from exc
    if method not in FORMULATIONS:
        raise ModelError(f"reference solver R2: unknown formulation {method!r}; valid: {', '.join(FORMULATIONS)}")
    t_end, t_eval = _check_times(t_end, t_eval)
    s = CoupledSystem(model, constraint, bridge_self_weight, gravity, irregularity_breaks)
    bounds = s.breakpoints(t_end)
    u_b, u_t, lam0 = dead_load(s, 0.5 * (bounds[0] + bounds[1]))
    n = s.n_b + s.n_t
    u, v = np.concatenate([u_b, u_t]), np.zeros(n)
    if atol is None:
        a_u = s.default_atol(rtol, u)
        atol = np.concatenate([np.full(2 * n, a_u), np.full(s.n_c, rtol * s.load_scale)])
    out = _Histories(len(t_eval), s)
    impulses, stats = [], {"segments": len(bounds) - 1, "nfev": 0, "njev": 0}
    algebraic = list(range(2 * n, 2 * n + s.n_c))
    for k, (ta, tb) in enumerate(zip(bounds[:-1], bounds[1:])):
        seg = _Segment(s, 0.5 * (ta + tb))
        if k == 0:
            # start at rest (bridge and bodies), wheels moving with the rail (as R1: ẏ(0) = 0)
            v, a, lam = _rest_start(seg, ta, u)
        else:
            u, v, a, lam, iota = seg.consistent(ta, u, v)
            for i, value in enumerate(iota):
                if abs(value) > IMPULSE_THRESHOLD * s.load_scale:
                    impulses.append((float(ta), int(i), float(value)))
        idx = segment_points(t_eval, ta, tb, k == len(bounds) - 2)
        times = np.unique(np.concatenate([[ta], t_eval[idx], [tb]]))
        times = times[np.concatenate([[True], np.diff(times) > 1e-13 * max(1.0, tb)])]
        times[-1] = tb
        if len(times) < 2:
            continue
        solver = IDA(seg.residual, jacfn=seg.jacobian, algebraic_idx=algebraic, rtol=rtol, atol=atol,
                     linsolver="dense", max_num_steps=max_num_steps)
        y0 = np.concatenate([u, v, lam])
        yp0 = np.concatenate([v, a, np.zeros(s.n_c)])
        sol = solver.solve(times, y0, yp0)
        if not sol.success:
            raise AnalysisError(f"reference solver R2: IDA failed on [{ta:.6g}, {tb:.6g}] s: {sol.message}")
        stats["nfev"] += int(sol.nfev)
        stats["njev"] += int(sol.njev)
        for i in idx:
            j = int(np.argmin(np.abs(sol.t - t_eval[i])))
            Y, Yp = sol.y[j], sol.yp[j]
            out.store(i, (Y[: s.n_b], Y[n: n + s.n_b], Yp[n: n + s.n_b], Y[s.n_b: n], Y[n + s.n_b: 2 * n],
                          Yp[n + s.n_b: 2 * n], None), np.arange(s.n_c), Y[2 * n:])
        u, v = sol.y[-1][:n].copy(), sol.y[-1][n: 2 * n].copy()
    return out.result(t_eval, impulses, s, (u_b, u_t, lam0), bounds, stats)


def _rest_start(seg, t, u):
    """Initial velocity with the bridge and the non-wheel train dofs at rest and the wheels
    moving with the rail (v_w = V N' u_b + V r'), and the matching (a, λ)."""
    s, n, nb = seg.s, seg.n, seg.s.n_b
    N, N1, N2, r, r1, r2 = seg.constraint(t)
    v = np.zeros(n)
    v[nb + s.wheel_dofs] = s.V * (N1 @ u[:nb] + r1)
    G = np.zeros((s.n_c, n))
    G[:, :nb] = -N
    G[np.arange(s.n_c), nb + s.wheel_dofs] = 1.0
    saddle = np.block([[s.M, -G.T], [G, np.zeros((s.n_c, s.n_c))]])
    V = s.V
    rhs = np.concatenate([seg.load(t) - s.C @ v - s.K @ u,
                          V * V * r2 + 2 * V * (N1 @ v[:nb]) + V * V * (N2 @ u[:nb])])
    sol = np.linalg.solve(saddle, rhs)
    return v, sol[:n], sol[n:]
