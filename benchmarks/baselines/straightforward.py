"""The coupled train-bridge step of vtsi written the straightforward way: a Python loop over the
steps, constraint rows assembled with numpy, scipy's sparse solver for every bridge solve.

Same algorithm as :mod:`vtsi.coupled_loop` (docs/theory/coupled_step.md), same
integrator (Newmark, acceleration form, one stage), same velocity-level constraint and the same
projection; the math is re-derived here, not the code copied. Per step, with γ, β Newmark's
parameters and K̂ = M + γΔt C + βΔt² K for each subdomain:

1. predictors ū = u + Δt v + (½ − β)Δt² a, v̄ = v + (1 − γ)Δt a; free accelerations
   â = K̂⁻¹ (P − C v̄ − K ū) (bridge: P = 0; train: its gravity load), û = ū + βΔt² â, v̂ = v̄ + γΔt â;
2. the rows N (n_c × n_bridge, Hermite functions of the element under each wheel, zero for a
   wheel off the bridge: rigid ground) and their slopes dN/dx at t_{n+1}, assembled with numpy
   as (wheels × 4) arrays of values and bridge dof indices; X = K̂_b⁻¹ N_onᵀ by sparse solves
   (one right-hand side per wheel on the bridge);
   W = γΔt (N X + S K̂_t⁻¹ Sᵀ) (the train part is constant: computed once);
3. the velocity-level constraint ġ = S v_t − N v_b − V (dN/dx) û_b − ṙ = 0 after the correction
   gives W λ = −q, q = S v̂_t − N v̂_b − V (dN/dx) û_b − ṙ (dense solve, n_c × n_c);
4. correction: Δa_b = −X λ_on, Δa_t = K̂_t⁻¹ Sᵀ λ; a = â + Δa, u = û + βΔt² Δa, v = v̂ + γΔt Δa;
   then the wheels are projected onto the rail: u_t[wheel] −= S u_t − N u_b − r (positions only).

What a careful straightforward coder does, and so does this: ``scipy.sparse.linalg.splu`` factors
each effective matrix ONCE (outside the loop; the factorisation is not timed), and the loop calls
the factor's ``.solve`` (the bridge: once for the free response and once, with one right-hand
side per wheel on the bridge, for X); products with N are numpy gathers over the 4 dofs of
each row (``rows='sparse'``, which rebuilds N as scipy sparse matrices every step, is the
slower first way, kept for comparison); the irregularity r and its rate ṙ = V r'(x) under every
wheel are evaluated for all steps at once with numpy before the loop (timed).
"""
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

GAMMA, BETA = 0.5, 0.25


class StraightforwardCoupled:
    """Bilateral coupled analysis, Newmark (γ = 1/2, β = 1/4), on vtsi's assembled matrices.

    Parameters
    ----------
    M_b, C_b, K_b : bridge free-dof matrices (sparse, n_b × n_b).
    M_t, C_t, K_t : train matrices (sparse, n_t × n_t); ``p_t`` the train's gravity load (n_t,).
    wheel_dofs : (n_c,) train dof of each contact wheel; ``x0`` (n_c,) their positions at t = 0 [m];
    speed : [m/s].
    x_start, length : (n_el,) track elements, ordered along x; ``elem_dofs`` (n_el, 4) bridge free
        dof of [uy1, rz1, uy2, rz2] of each track element (-1 where fixed).
    irregularity : None or r(x, nu=0|1) [m, 1] (e.g. vtsi.models.Irregularity).
    dt : step [s].
    """

    def __init__(self, M_b, C_b, K_b, M_t, C_t, K_t, p_t, wheel_dofs, x0, speed, x_start, length,
                 elem_dofs, irregularity, dt):
        self.M_b, self.C_b, self.K_b = (sp.csr_matrix(m) for m in (M_b, C_b, K_b))
        self.M_t, self.C_t, self.K_t = (sp.csr_matrix(m) for m in (M_t, C_t, K_t))
        self.damped_b = self.C_b.nnz > 0 and abs(self.C_b).max() > 0
        self.damped_t = self.C_t.nnz > 0 and abs(self.C_t).max() > 0
        self.p_t = np.asarray(p_t, dtype=float)
        self.wd = np.asarray(wheel_dofs, dtype=np.int64)
        self.x0 = np.asarray(x0, dtype=float)
        self.V = float(speed)
        self.x_start, self.length = np.asarray(x_start, float), np.asarray(length, float)
        self.x_end = self.x_start[-1] + self.length[-1]
        self.elem_dofs = np.asarray(elem_dofs, dtype=np.int64)
        self.irregularity = irregularity
        self.dt = float(dt)
        g, b = GAMMA, BETA
        self.n_b, self.n_t, self.n_c = self.K_b.shape[0], self.K_t.shape[0], len(self.wd)
        # factored once (not timed)
        self.lu_b = spla.splu((self.M_b + g * dt * self.C_b + b * dt * dt * self.K_b).tocsc())
        self.lu_t = spla.splu((self.M_t + g * dt * self.C_t + b * dt * dt * self.K_t).tocsc())
        S_T = np.zeros((self.n_t, self.n_c))
        S_T[self.wd, np.arange(self.n_c)] = 1.0
        self.F_t = self.lu_t.solve(S_T)                 # K̂_t⁻¹ Sᵀ (constant)
        self.W_t = self.F_t[self.wd, :]                 # S K̂_t⁻¹ Sᵀ

    def rows(self, x):
        """Rows of the wheels at x: ``(on, cols, H, dH)``: the wheels on the bridge, and for each of
        them the 4 bridge dofs of its element (``n_b``, a dump slot, where fixed), the Hermite
        values and their slopes dN/dx."""
        on = np.flatnonzero((x >= self.x_start[0]) & (x <= self.x_end))
        e = np.clip(np.searchsorted(self.x_start, x[on], side="right") - 1, 0, len(self.x_start) - 1)
        ell = self.length[e][:, None]
        xi = ((x[on] - self.x_start[e]) / self.length[e])[:, None]
        x2, x3 = xi * xi, xi * xi * xi
        H = np.hstack([1 - 3 * x2 + 2 * x3, ell * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, ell * (x3 - x2)])
        dH = np.hstack([(6 * x2 - 6 * xi) / ell, 1 - 4 * xi + 3 * x2, (6 * xi - 6 * x2) / ell, 3 * x2 - 2 * xi])
        cols = self.elem_dofs[e]
        fixed = cols < 0
        H[fixed] = 0.0
        dH[fixed] = 0.0
        cols = np.where(fixed, self.n_b, cols)
        return on, cols, H, dH

    def sparse_rows(self, x):
        """The same rows as scipy sparse matrices N, dN/dx (n_c × n_b) (the ``rows='sparse'`` variant)."""
        on, cols, H, dH = self.rows(x)
        keep = cols < self.n_b
        r_idx = np.repeat(on, 4).reshape(-1, 4)[keep]
        N = sp.csr_matrix((H[keep], (r_idx, cols[keep])), shape=(self.n_c, self.n_b))
        dN = sp.csr_matrix((dH[keep], (r_idx, cols[keep])), shape=(self.n_c, self.n_b))
        return on, N, dN

    def _free_response(self, u_b, v_b, a_b, u_t, v_t, a_t):
        """Newmark free response (no contact force) of bridge and train: (â, û, v̂) of each."""
        dt, b, g = self.dt, BETA, GAMMA
        out = []
        for u, v, a, K, C, lu, p, damped in ((u_b, v_b, a_b, self.K_b, self.C_b, self.lu_b, None, self.damped_b),
                                             (u_t, v_t, a_t, self.K_t, self.C_t, self.lu_t, self.p_t, self.damped_t)):
            u_p = u + dt * v + (0.5 - b) * dt * dt * a
            v_p = v + (1 - g) * dt * a
            rhs = -(K @ u_p) if p is None else p - K @ u_p
            if damped:
                rhs -= C @ v_p
            a_h = lu.solve(rhs)
            out += [a_h, u_p + b * dt * dt * a_h, v_p + g * dt * a_h]
        return tuple(out)

    def _correct(self, ab_h, ub_h, vb_h, at_h, ut_h, vt_h, X, lam, on):
        """Add the response to the contact forces λ: bridge through ``X = K̂_b⁻¹ N_onᵀ`` (wheels
        ``on`` the bridge), train through ``F_t = K̂_t⁻¹ Sᵀ``."""
        dt, b, g = self.dt, BETA, GAMMA
        if len(on):
            dab = -(X @ lam[on])
            ab_h, ub_h, vb_h = ab_h + dab, ub_h + b * dt * dt * dab, vb_h + g * dt * dab
        dat = self.F_t @ lam
        return ab_h, ub_h, vb_h, at_h + dat, ut_h + b * dt * dt * dat, vt_h + g * dt * dat

    def run(self, u_b, v_b, a_b, u_t, v_t, a_t, n_steps, record_b=(), rows="dense"):
        """Advance ``n_steps`` from the given state (copied) at t = 0. Returns
        ``(λ (n_steps, n_c), bridge free dofs ``record_b`` (n_steps, k), final state tuple)``.

        ``rows='dense'``: the rows as (wheels × 4) numpy arrays of values and dof indices,
        products by gather/scatter (the careful way); ``rows='sparse'``: as scipy sparse
        matrices rebuilt every step (the first way that comes to mind; slower)."""
        if rows == "sparse":
            return self._run_sparse(u_b, v_b, a_b, u_t, v_t, a_t, n_steps, record_b)
        dt, g, V = self.dt, GAMMA, self.V
        n_b, wd = self.n_b, self.wd
        (u_b, v_b, a_b, u_t, v_t, a_t), record_b, lam_out, rec_out, X_all, r_all, rdot_all = \
            self._start((u_b, v_b, a_b, u_t, v_t, a_t), n_steps, record_b)
        ext = np.zeros(n_b + 1)               # a bridge vector with the dump slot n_b (always 0)
        for k in range(n_steps):
            # 1. free responses
            ab_h, ub_h, vb_h, at_h, ut_h, vt_h = self._free_response(u_b, v_b, a_b, u_t, v_t, a_t)
            X = None                              # K̂_b⁻¹ N_onᵀ, set when a wheel is on the bridge
            # 2. rows, free velocity gap and contact flexibility
            on, cols, H, dH = self.rows(X_all[k])
            q = vt_h[wd] - rdot_all[k]
            W = self.W_t.copy()
            if len(on):
                ext[:n_b] = vb_h
                q[on] -= np.sum(H * ext[cols], axis=1)
                ext[:n_b] = ub_h
                q[on] -= V * np.sum(dH * ext[cols], axis=1)
                NT = np.zeros((n_b + 1, len(on)))
                NT[cols, np.arange(len(on))[:, None]] = H
                X = self.lu_b.solve(NT[:n_b])            # K̂_b⁻¹ N_onᵀ, one column per wheel on the bridge
                W[np.ix_(on, on)] += NT[:n_b].T @ X
            W *= g * dt
            # 3. contact forces (velocity level)
            lam = -sla.solve(W, q, assume_a="pos")
            # 4. corrections
            a_b, u_b, v_b, a_t, u_t, v_t = self._correct(ab_h, ub_h, vb_h, at_h, ut_h, vt_h, X, lam, on)
            # projection of the wheels onto the rail (positions only): u_w = N u_b + r
            rail = r_all[k].copy()
            if len(on):
                ext[:n_b] = u_b
                rail[on] += np.sum(H * ext[cols], axis=1)
            u_t[wd] = rail
            lam_out[k] = lam
            rec_out[k] = u_b[record_b]
        return lam_out, rec_out, (u_b, v_b, a_b, u_t, v_t, a_t)

    def _start(self, state, n_steps, record_b):
        """Copies of the state, the recorded dofs, the output arrays, and the wheel positions
        and rail data r, ṙ of every step (outside the timed loop's per-step work)."""
        state = [np.array(z, dtype=float) for z in state]
        record_b = np.asarray(record_b, dtype=np.int64)
        X_all = self.x0[None, :] + self.V * self.dt * np.arange(1, n_steps + 1)[:, None]
        if self.irregularity is None:
            r_all, rdot_all = np.zeros_like(X_all), np.zeros_like(X_all)
        else:
            r_all, rdot_all = self.irregularity(X_all), self.V * self.irregularity(X_all, nu=1)
        return (state, record_b, np.zeros((n_steps, self.n_c)), np.zeros((n_steps, len(record_b))), X_all,
                r_all, rdot_all)

    def _run_sparse(self, u_b, v_b, a_b, u_t, v_t, a_t, n_steps, record_b=()):
        dt, g, V = self.dt, GAMMA, self.V
        (u_b, v_b, a_b, u_t, v_t, a_t), record_b, lam_out, rec_out, X_all, r_all, rdot_all = \
            self._start((u_b, v_b, a_b, u_t, v_t, a_t), n_steps, record_b)
        for k in range(n_steps):
            ab_h, ub_h, vb_h, at_h, ut_h, vt_h = self._free_response(u_b, v_b, a_b, u_t, v_t, a_t)
            X = None                              # K̂_b⁻¹ N_onᵀ, set when a wheel is on the bridge
            on, N, dN = self.sparse_rows(X_all[k])
            W = self.W_t.copy()
            if len(on):
                N_on = N[on]
                X = self.lu_b.solve(N_on.T.toarray())
                W[np.ix_(on, on)] += N_on @ X
            W *= g * dt
            q = vt_h[self.wd] - rdot_all[k] - N @ vb_h - V * (dN @ ub_h)
            lam = -sla.solve(W, q, assume_a="pos")
            a_b, u_b, v_b, a_t, u_t, v_t = self._correct(ab_h, ub_h, vb_h, at_h, ut_h, vt_h, X, lam, on)
            u_t[self.wd] = r_all[k] + N @ u_b
            lam_out[k] = lam
            rec_out[k] = u_b[record_b]
        return lam_out, rec_out, (u_b, v_b, a_b, u_t, v_t, a_t)
