"""The compiled time loop of a coupled train-bridge analysis (docs/theory/coupled_step.md).

Each stage of each step, for bridge (b) and train (t) subdomains with constant factored
effective matrices K̂ (acceleration form, see :mod:`vtsi.integrators.base`):

1. free response of each subdomain: â = K̂⁻¹ R̂, û = ū + du_A â;
2. contact flexibility W = dv_A (N F Nᵀ + S K̂_t⁻¹ Sᵀ), with F = K̂_b⁻¹ on the track dofs
   (precomputed once per stage) and N the constraint rows at the stage time; on a modal bridge
   N F Nᵀ = Φ_w K̂_q⁻¹ Φ_wᵀ with the wheels' rows Φ_w on the modes (K̂_q diagonal), and with few
   modes the bilateral solve uses W⁻¹ by the Woodbury identity instead of a factor of W;
3. contact forces from the constraint at the velocity level (index 2),
   ġ = S v_t - N v_b - Ṅ û_b - ṙ = 0 with Ṅ = V dN/dx taken at the free response û (so that
   W stays symmetric): W λ = -q, q = S v̂_t - N v̂_b - Ṅ û_b - ṙ (bilateral), or the LCP
   λ >= 0, ġ = W λ + q >= 0, λ·ġ = 0 for the wheels whose free position gap is closed
   (contact loss; λ = 0 for the others);
4. correction: a = â + K̂⁻¹ Gᵀ λ (one more solve for the bridge; for the train the sum of
   the wheels' precomputed responses K̂_t⁻¹ Sᵀ, each within its car) and u, v updated.

Force-only wheels (moving forces) load the bridge through their Hermite rows; they come in the
train's order, so only the run of them on the track is visited (none of the others costs a step).

Why the velocity level: with the constraint imposed on positions (index 3), the trapezoidal
rule keeps an undamped period-2Δt mode in the wheels' accelerations, and a moving constraint
pumps it: λ grew without bound in our S3 runs (docs/theory/constraints.md). At the velocity
level the scheme is stable; its O(Δt²) position drift is removed after every stage by
projecting the wheels that are on the rail back onto it (positions only).
"""
import numpy as np
from numba import njit

from vtsi.banded import ldl_solve
from vtsi.lcp import cholesky_in_place, cholesky_substitute, solve_lcp
from vtsi.timeloop import (
    add_pattern_loads,
    solve_stage,
    stage_updates,
    update_stage,
)
from vtsi.track import constraint_rows, hermite, host_element


@njit(cache=True, inline='always')
def _free_stage(bank, base, fac, ops, weights, rhs, xk, xc, s, updates, ua, va, band):
    """Solve the stage for the (already loaded) ``rhs``; write û, v̂, â to the stage slots
    ``base..base + 2`` (slots 0..2 for the last stage: the step's result, in place)."""
    kd = len(band)
    lo, hi = kd, kd + ops.shape[2]
    solve_stage(bank, rhs, fac, ops, weights, s, band, xk)
    update_stage(bank, rhs, base, s, updates, ua, va, lo, hi, xk, xc)


@njit(cache=True, inline='always')
def _track_value(bank, slot, kd, track_free, basis, c):
    """The value of track dof ``c`` in the bridge bank's ``slot``: the coordinate
    ``track_free[c]`` (FE bridge: ``basis`` has no column) or ``basis[c] · q`` (modal bridge)."""
    if basis.shape[1] == 0:
        return bank[slot, kd + track_free[c]]
    acc = 0.0
    for j in range(basis.shape[1]):
        acc += basis[c, j] * bank[slot, kd + j]
    return acc


@njit(cache=True, inline='always')
def _track_add(rhs, kd, track_free, basis, c, f):
    """Add a force ``f`` on track dof ``c`` to the bridge's padded ``rhs`` (its coordinates)."""
    if basis.shape[1] == 0:
        rhs[kd + track_free[c]] += f
    else:
        for j in range(basis.shape[1]):
            rhs[kd + j] += f * basis[c, j]


@njit(cache=True, inline='always')
def _position_gap(bank_t, bank_b, slot, i, wheel_dof, r, cols, vals, track_free, basis, kdt, kdb):
    """Position gap ``S u_t - N u_b - r`` of contact wheel ``i`` in the banks' ``slot`` [m]."""
    g = bank_t[slot, kdt + wheel_dof[i]] - r
    for a_ in range(cols.shape[1]):
        c_ = cols[i, a_]
        if c_ < 0:
            break
        g -= vals[i, a_] * _track_value(bank_b, slot, kdb, track_free, basis, c_)
    return g


@njit(cache=True, inline='always')
def _correct(bank, base, fac, rhs, s, ua, va, band, wa):
    """Add the response to the contact forces already scattered into ``rhs`` (the acceleration
    with weight ``wa``: 1 for a force, 0 for an impulse)."""
    kd = len(band)
    ldl_solve(fac[s], rhs, band)
    for i in range(kd, rhs.shape[0] - kd):
        bank[base, i] += ua * rhs[i]
        bank[base + 1, i] += va * rhs[i]
        bank[base + 2, i] += wa * rhs[i]


@njit(cache=True, inline='always')
def _modal_rows(phi, idx, m, cols, vals, on_bridge, basis):
    """The constraint rows of the wheels ``idx[:m]`` on the modal coordinates, ``phi[a] =
    Σ vals[i, a_] basis[cols[i, a_]]`` (zero for a wheel off the track)."""
    n = basis.shape[1]
    for a in range(m):
        i = idx[a]
        for k in range(n):
            phi[a, k] = 0.0
        if not on_bridge[i]:
            continue
        for a_ in range(cols.shape[1]):
            c_ = cols[i, a_]
            if c_ < 0:
                break
            v = vals[i, a_]
            for k in range(n):
                phi[a, k] += v * basis[c_, k]


@njit(cache=True, inline='always')
def _contact_flexibility(W, idx, m, flex, tflex, va, cols, vals, on_bridge, basis, mode_flex, phi):
    """``W[a, b] = va (S K̂_t⁻¹ Sᵀ + N F Nᵀ)`` for the wheels ``idx[a], idx[b]``, a, b < m
    (N F Nᵀ only between wheels on the track) [m/N]. On a modal bridge (``mode_flex`` (n_modes,)
    the diagonal K̂_q⁻¹, empty for the FE bridge) N F Nᵀ = Φ diag(mode_flex) Φᵀ with the wheels'
    modal rows Φ (:func:`_modal_rows`, into ``phi``), where that is fewer products per pair than
    the w² of N F Nᵀ (w the row width)."""
    nw = cols.shape[1]
    n_modes = mode_flex.shape[0] if mode_flex.shape[0] < nw * nw else 0
    if n_modes > 0:
        _modal_rows(phi, idx, m, cols, vals, on_bridge, basis)
    for a in range(m):
        i = idx[a]
        for b in range(a + 1):
            j = idx[b]
            acc = tflex[i, j]
            if on_bridge[i] and on_bridge[j]:   # unused entries (col -1) have value 0: no branches
                if n_modes > 0:
                    for k in range(n_modes):
                        acc += phi[a, k] * mode_flex[k] * phi[b, k]
                else:
                    for a_ in range(nw):
                        flex_row = flex[max(cols[i, a_], 0)]
                        row = 0.0
                        for b_ in range(nw):
                            row += flex_row[max(cols[j, b_], 0)] * vals[j, b_]
                        acc += vals[i, a_] * row
            W[a, b] = va * acc
            W[b, a] = va * acc


@njit(cache=True, inline='always')
def _solve_low_rank(q, lam, idx, m, va, ground_inv, set_ptr, n_sets, cols, vals, on_bridge, basis, mode_flex,
                    phi, zmat, cap, zq, zl):
    """Bilateral ``λ = -W⁻¹ q`` of the wheels ``idx[:m]`` on a modal bridge, whose cars (the runs
    ``set_ptr[g]..set_ptr[g + 1]`` of ``idx``, ``g < n_sets``) all have an invertible train block:
    W = G⁻¹ + va Φ F Φᵀ with G = ``ground_inv`` (block diagonal by car), Φ the wheels' modal rows
    and F = diag(``mode_flex``), so by the Woodbury identity W⁻¹ = G − G Φ C⁻¹ Φᵀ G with the
    n_modes × n_modes C = (va F)⁻¹ + Φᵀ G Φ: O(m n_modes²) work instead of the O(m³) of a
    Cholesky factor of W. False if C is not positive definite."""
    n = mode_flex.shape[0]
    _modal_rows(phi, idx, m, cols, vals, on_bridge, basis)
    for g in range(n_sets):                  # y = G q (in zq), Z = G Φ, car by car
        for a in range(set_ptr[g], set_ptr[g + 1]):
            i = idx[a]
            y = 0.0
            for k in range(n):
                zmat[a, k] = 0.0
            for b in range(set_ptr[g], set_ptr[g + 1]):
                gij = ground_inv[i, idx[b]]
                y += gij * q[idx[b]]
                for k in range(n):
                    zmat[a, k] += gij * phi[b, k]
            zq[a] = y
    for k in range(n):                       # C and Φᵀ y (in zl)
        for l_ in range(k + 1):
            acc = 0.0
            for a in range(m):
                acc += phi[a, k] * zmat[a, l_]
            cap[k, l_] = acc
            cap[l_, k] = acc
        cap[k, k] += 1.0 / (va * mode_flex[k])
        acc = 0.0
        for a in range(m):
            acc += phi[a, k] * zq[a]
        zl[k] = acc
    if not cholesky_in_place(cap, n):
        return False
    cholesky_substitute(cap, zl, n)
    for a in range(m):
        acc = zq[a]
        for k in range(n):
            acc -= zmat[a, k] * zl[k]
        lam[idx[a]] = -acc
    return True


@njit(cache=True)
def _solve_system(W, q, lam, idx, m, va, flex, tflex, cols, vals, on_bridge, basis, mode_flex, phi, lcp, flight,
                  lcp_work, zq, zl):
    """Contact forces of the wheels ``idx[:m]`` (a set no other wheel is coupled to): bilateral
    ``W λ = -q`` by Cholesky, or the LCP with the wheels in flight decoupled (λ = 0). The LCP's
    free set is remembered per wheel in row ``n_c + 3`` of ``lcp_work``. False if singular."""
    _contact_flexibility(W, idx, m, flex, tflex, va, cols, vals, on_bridge, basis, mode_flex, phi)
    for a in range(m):
        zq[a] = q[idx[a]]
    if lcp:
        memory = lcp_work[lcp_work.shape[0] - 1]
        for a in range(m):
            if flight[idx[a]]:
                for b in range(m):
                    W[a, b] = 0.0
                    W[b, a] = 0.0
                W[a, a] = 1.0
                zq[a] = 1.0
            lcp_work[m + 2, a] = memory[idx[a]]
        if not solve_lcp(W, zq, zl, m, lcp_work):
            return False
        for a in range(m):
            memory[idx[a]] = lcp_work[m + 2, a]
            lam[idx[a]] = zl[a]
        return True
    if not cholesky_in_place(W, m):
        return False
    for a in range(m):
        zl[a] = -zq[a]
    cholesky_substitute(W, zl, m)
    for a in range(m):
        lam[idx[a]] = zl[a]
    return True


@njit(cache=True)
def _contact_forces(W, q, lam, selected, va, flex, tflex, ground_inv, group_ptr, group_wheel,
                    cols, vals, on_bridge, basis, mode_flex, lcp, flight, landing, lcp_work, zq, zl,
                    phi, zmat, cap, set_ptr):
    """λ group by group (a group: the wheels the train couples, a car). A group with no wheel
    on the track has a constant W block whose inverse ``ground_inv`` was precomputed (a zero
    block where it is not positive definite): λ = -W⁻¹q, which is also the LCP's solution when
    none of its wheels is in flight or landing and every λ > 0; otherwise the group is solved
    alone (:func:`_solve_system`). The groups with a wheel on the track are coupled through the
    bridge and solved together: on a modal bridge with fewer than half as many modes as those
    wheels, bilateral, and every such car's block invertible, by :func:`_solve_low_rank`, else
    by a factor of their W (:func:`_solve_system`). Returns False if a system is singular."""
    m = 0
    n_sets = 0
    invertible = True
    for g in range(group_ptr.shape[0] - 1):
        lo, hi = group_ptr[g], group_ptr[g + 1]
        coupled = ground_inv[group_wheel[lo], group_wheel[lo]] == 0.0
        simple = True
        for k in range(lo, hi):
            i = group_wheel[k]
            coupled = coupled or on_bridge[i]
            if lcp and (flight[i] or landing[i] > 0.5):
                simple = False
        if coupled:
            invertible = invertible and ground_inv[group_wheel[lo], group_wheel[lo]] != 0.0
            set_ptr[n_sets] = m
            n_sets += 1
            for k in range(lo, hi):
                selected[m] = group_wheel[k]
                m += 1
            continue
        if simple:
            for k in range(lo, hi):
                i = group_wheel[k]
                acc = 0.0
                for l_ in range(lo, hi):
                    acc += ground_inv[i, group_wheel[l_]] * q[group_wheel[l_]]
                lam[i] = -acc
                if lcp and not lam[i] > 0.0:
                    simple = False
        if simple:
            if lcp:
                for k in range(lo, hi):
                    lcp_work[lcp_work.shape[0] - 1, group_wheel[k]] = 1.0
        elif not _solve_system(W, q, lam, group_wheel[lo:hi], hi - lo, va, flex, tflex, cols, vals, on_bridge,
                               basis, mode_flex, phi, lcp, flight, lcp_work, zq, zl):
            return False
    if m == 0:
        return True
    set_ptr[n_sets] = m
    if not lcp and invertible and 0 < 2 * mode_flex.shape[0] < m:
        return _solve_low_rank(q, lam, selected, m, va, ground_inv, set_ptr, n_sets, cols, vals, on_bridge, basis,
                               mode_flex, phi, zmat, cap, zq, zl)
    return _solve_system(W, q, lam, selected, m, va, flex, tflex, cols, vals, on_bridge, basis, mode_flex, phi,
                         lcp, flight, lcp_work, zq, zl)


@njit(cache=True, inline='always')
def _first_at_most(decreasing, value):
    """The first index i of the decreasing array with ``decreasing[i] <= value`` (its length if none)."""
    lo, hi = 0, decreasing.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if decreasing[mid] <= value:
            hi = mid
        else:
            lo = mid + 1
    return lo


@njit(cache=True, fastmath={"contract"})
def run_coupled_steps(bank_b, bank_t, du, dv,
                      fac_b, ops_b, weights_b, fac_t, ops_t, weights_t,
                      load_factors, load_ptr, load_dof, load_val, p_train,
                      flex, tflex, x_start, length, tdofs, track_free, track_basis,
                      x0_c, wheel_dof, x0_f, force_f, speed, knot, r_table, rate_table,
                      t0, first, dt, stage_theta, load_theta, load_weight, force_weight, mass_weight, record_weights,
                      lcp, gap_tol,
                      in_contact,
                      rec_b_slot, rec_b_index, out_b, rec_t_slot, rec_t_index, out_t,
                      out_force, out_force_end, out_gap, limit, work_b, work_t, cols, vals, slopes, W, q, lam, lcp_work, band_b, band_t,
                      lam_prev, cols_prev, vals_prev, group_ptr, group_wheel, ground_inv, wheel_response,
                      response_range):
    """Advance ``out_b.shape[0]`` coupled steps; returns the first diverged step or -1
    (-2 - step when the contact problem is singular at that step).

    Step ``step`` of the call is step ``first + step`` (int) counted from ``t0`` [s]: its stage s
    is at t0 + ((first + step) + stage_theta[s]) Δt, the step's number summed as an integer
    first, so that a run split into calls anywhere has one call's stage times to the bit.

    The bridge is a subdomain of :mod:`vtsi.subdomain`: track dof c is the coordinate
    ``track_free[c]`` (FE) or ``track_basis[c] · q`` (modal, ``track_basis`` (n_track, n)).
    Shapes: banks (n_slots, n + 2 kd); fac_* (n_stages, n + kd, kd + 1); ops_*, weights_* the
    stages' known parts (:func:`vtsi.timeloop.stage_operators`); flex (n_stages,
    n_track, n_track); tflex (n_stages, n_c, n_c); r_table (n_steps, n_stages, n_c);
    load_theta/load_weight (n_stages, n_q) (weight 0 pads); out_force/out_gap (n_steps, n_c)
    (band_b, band_t: the half bandwidths of the bridge and train factors as types, see vtsi.banded).
    ``force_weight`` (n_stages): ω of each stage (HHT: α; generalized-α: αF/αM): the stage solves
    for μ = ω λ_s with (m - ω) times the previous step's forces ``lam_prev`` on rows
    ``cols_prev``/``vals_prev`` as a known load; λ_s = μ / ω. Those three arrays are updated at
    every step. ``mass_weight`` (n_stages): m = 1 + Σ km of each stage (1 but for generalized-α:
    1/αM), the weight of the train's constant load ``p_train`` (:attr:`vtsi.integrators.base.Stage.mass_weight`).
    out_force/out_gap: contact force [N] and position gap [m] of each step: the force is the
    mean Σ record_weights · (λ_n, λ_stage 1, …) of the scheme's velocity update (n_stages + 1
    weights, :meth:`vtsi.integrators.base.Integrator.force_record_weights`; the last stage's λ
    for the Newmark family), so that Σ λ Δt is the impulse the steps transferred; the gap the
    end of step's; ``out_force_end`` the end of step's λ_{n+1} (the same for the Newmark family);
    ``in_contact`` (n_c) carries each wheel's contact state (1.0 on the rail, 0.0 in flight)
    from step to step. ``group_ptr``/``group_wheel``: the contact wheels grouped by the train's
    coupling (CSR-like; a group is a car); ``ground_inv`` (n_stages, n_c, n_c): per stage, the
    inverse of each group's constant W block for when none of its wheels is on the track (a zero
    block where it is not positive definite), see :func:`_contact_forces`. ``wheel_response``
    (n_stages, n_c, n_t): K̂_t⁻¹ Sᵀ as rows, nonzero within ``response_range`` (n_c, 2).
    """
    kdb, kdt = len(band_b), len(band_t)
    n_steps = out_b.shape[0]
    n_stages, width = du.shape
    A = width - 1
    n_b = ops_b.shape[2]
    n_t = ops_t.shape[2]
    n_c = x0_c.shape[0]
    n_f = x0_f.shape[0]
    rb, xkb, xcb = work_b[0], work_b[1], work_b[2]
    rt, xkt, xct = work_t[0], work_t[1], work_t[2]
    updates = stage_updates(du, dv)
    x_begin, x_end = x_start[0], x_start[-1] + length[-1]
    x = np.empty(n_c)
    landing = np.zeros(n_c)
    on_bridge = np.zeros(n_c, dtype=np.bool_)
    flight = np.zeros(n_c, dtype=np.bool_)
    selected = np.empty(n_c, dtype=np.int64)
    lam_rec = np.zeros(n_c)
    zq, zl = np.empty(n_c), np.empty(n_c)
    # a modal bridge (diagonal factors, kd = 0): its stages' K̂_q⁻¹ as the factors' diagonals
    n_modes = n_b if kdb == 0 and track_basis.shape[1] > 0 else 0
    mode_flex = fac_b[:, :n_modes, 0]
    phi, zmat = np.empty((n_c, n_modes)), np.empty((n_c, n_modes))
    cap = np.empty((n_modes, n_modes))
    set_ptr = np.empty(group_ptr.shape[0], dtype=np.int64)
    for step in range(n_steps):
        for s in range(n_stages):
            base = 0 if s == n_stages - 1 else 3 + 3 * s     # the last stage writes the new state
            ua, va = du[s, A], dv[s, A]
            # 1. free responses
            rb[kdb: kdb + n_b] = 0.0
            add_pattern_loads(rb, load_factors[step, s], load_ptr, load_dof, load_val, kdb)
            for q_ in range(load_theta.shape[1]):
                w_q = load_weight[s, q_]
                if w_q == 0.0:
                    continue
                tq = t0 + ((first + step) + load_theta[s, q_]) * dt
                # x0_f decreases (the train's order), so the forces on the track are a run of them
                for f in range(_first_at_most(x0_f, x_end - speed * tq), n_f):
                    xf = x0_f[f] + speed * tq
                    if xf < x_begin:
                        break
                    e = host_element(xf, x_start, length)
                    if e < 0:
                        continue
                    h = hermite((xf - x_start[e]) / length[e], length[e])
                    for a_ in range(4):
                        d = tdofs[e, a_]
                        if d >= 0:
                            _track_add(rb, kdb, track_free, track_basis, d, -w_q * force_f[f] * h[a_])
            w_prev = mass_weight[s] - force_weight[s]
            if w_prev != 0.0:
                for i in range(n_c):
                    for a_ in range(cols_prev.shape[1]):
                        c_ = cols_prev[i, a_]
                        if c_ < 0:
                            break
                        _track_add(rb, kdb, track_free, track_basis, c_, -w_prev * lam_prev[i] * vals_prev[i, a_])
            _free_stage(bank_b, base, fac_b, ops_b, weights_b, rb, xkb, xcb, s, updates, ua, va, band_b)
            rt[kdt: kdt + n_t] = 0.0
            for i in range(n_t):
                rt[kdt + i] = mass_weight[s] * p_train[i]
            if w_prev != 0.0:
                for i in range(n_c):
                    rt[kdt + wheel_dof[i]] += w_prev * lam_prev[i]
            if n_t > 0:
                _free_stage(bank_t, base, fac_t, ops_t, weights_t, rt, xkt, xct, s, updates, ua, va, band_t)
            if n_c == 0:
                continue
            # 2. rows, free gap and contact flexibility
            ts = t0 + ((first + step) + stage_theta[s]) * dt
            for i in range(n_c):
                x[i] = x0_c[i] + speed * ts
            constraint_rows(x, knot, x_start, length, tdofs, cols, vals, slopes)
            nw = cols.shape[1]
            for i in range(n_c):
                g = bank_t[base + 1, kdt + wheel_dof[i]] - rate_table[step, s, i]
                for a_ in range(nw):
                    c_ = cols[i, a_]
                    if c_ >= 0:
                        g -= (vals[i, a_] * _track_value(bank_b, base + 1, kdb, track_free, track_basis, c_)
                              + speed * slopes[i, a_] * _track_value(bank_b, base, kdb, track_free, track_basis, c_))
                q[i] = g
            for i in range(n_c):
                on_bridge[i] = cols[i, 0] >= 0
            # 3. contact forces
            for i in range(n_c):
                landing[i] = 0.0
            if lcp:
                for i in range(n_c):
                    gp = _position_gap(bank_t, bank_b, base, i, wheel_dof, r_table[step, s, i], cols, vals,
                                       track_free, track_basis, kdt, kdb)
                    # in flight: no force, decoupled; a wheel landing in this step takes its
                    # impact at the last stage (a multi-stage scheme's memory of the pre-impact
                    # velocity would undo an impact taken at an earlier stage)
                    flight[i] = gp > gap_tol or (in_contact[i] < 0.5 and s < n_stages - 1)
                    if not flight[i] and in_contact[i] < 0.5:  # landing: inelastic impact, velocity level (ġ >= 0)
                        landing[i] = 1.0
            ok = _contact_forces(W, q, lam, selected, va, flex[s], tflex[s], ground_inv[s], group_ptr, group_wheel,
                                 cols, vals, on_bridge, track_basis, mode_flex[s], lcp, flight, landing, lcp_work,
                                 zq, zl, phi, zmat, cap, set_ptr)
            if not ok:
                return -2 - step
            for i in range(n_c):     # the step's recorded force: the scheme's mean of λ_n and its stages' λ
                if s == 0:
                    lam_rec[i] = record_weights[0] * lam_prev[i]
                lam_rec[i] += record_weights[s + 1] * lam[i] / force_weight[s]
            # 4. corrections; a landing wheel's impulse changes u and v but not the (smooth)
            # acceleration that the next step's predictor uses
            for part in range(2):
                if part == 1:
                    impact = False
                    for i in range(n_c):
                        if landing[i] > 0.5 and lam[i] > 0.0:
                            impact = True
                    if not impact:
                        break
                wa = 1.0 if part == 0 else 0.0
                rb[:] = 0.0
                touched = False
                for i in range(n_c):
                    if (landing[i] > 0.5) != (part == 1):
                        continue
                    for a_ in range(nw):
                        c_ = cols[i, a_]
                        if c_ >= 0:
                            _track_add(rb, kdb, track_free, track_basis, c_, -lam[i] * vals[i, a_])
                            touched = True
                if touched:
                    _correct(bank_b, base, fac_b, rb, s, ua, va, band_b, wa)
                for i in range(n_c):    # K̂_t⁻¹ Sᵀ λ from the wheels' precomputed responses
                    if (landing[i] > 0.5) != (part == 1) or lam[i] == 0.0:
                        continue
                    for d in range(response_range[i, 0], response_range[i, 1]):
                        da = lam[i] * wheel_response[s, i, d]
                        bank_t[base, kdt + d] += ua * da
                        bank_t[base + 1, kdt + d] += va * da
                        bank_t[base + 2, kdt + d] += wa * da
            # position gaps; wheels on the rail are projected onto it (removes the O(Δt²)
            # drift of the velocity-level constraint; velocities and accelerations untouched)
            for i in range(n_c):
                g = _position_gap(bank_t, bank_b, base, i, wheel_dof, r_table[step, s, i], cols, vals,
                                  track_free, track_basis, kdt, kdb)
                if not lcp or lam[i] > 0.0 or g <= gap_tol:
                    bank_t[base, kdt + wheel_dof[i]] -= g
                    g = 0.0
                if s == n_stages - 1:
                    # an impact is recorded as its impulse ι = va λ spread over the step: ι/Δt
                    # a wheel in flight at the step's end records 0 (λ·gap = 0 holds for the record)
                    out_force[step, i] = lam[i] * va / dt if landing[i] > 0.5 else (0.0 if g > gap_tol else lam_rec[i])
                    out_force_end[step, i] = lam[i] * va / dt if landing[i] > 0.5 else lam[i] / force_weight[s]
                    out_gap[step, i] = g
                    if lcp:
                        in_contact[i] = 1.0 if g <= gap_tol else 0.0
        if n_c > 0:
            for i in range(n_c):
                # an impact is no force of the step: the next one does not carry it over
                lam_prev[i] = 0.0 if landing[i] > 0.5 else lam[i] / force_weight[n_stages - 1]
                for a_ in range(cols.shape[1]):
                    cols_prev[i, a_] = cols[i, a_]
                    vals_prev[i, a_] = vals[i, a_]
        worst = 0.0
        bad = 0.0       # u · 0 summed: NaN if any u is NaN or ±inf (vtsi.timeloop.update_stage)
        for bank in (bank_b, bank_t):
            for i in range(bank.shape[1]):
                worst = max(worst, abs(bank[0, i]))
                bad += bank[0, i] * 0.0
        if not (worst <= limit and bad == 0.0):     # NaN and ±inf diverge even with limit = inf
            return step
        for r in range(rec_b_slot.shape[0]):   # index -1: a dof at rest (not integrated)
            out_b[step, r] = bank_b[rec_b_slot[r], kdb + rec_b_index[r]] if rec_b_index[r] >= 0 else 0.0
        for r in range(rec_t_slot.shape[0]):
            out_t[step, r] = bank_t[rec_t_slot[r], kdt + rec_t_index[r]]
    return -1
