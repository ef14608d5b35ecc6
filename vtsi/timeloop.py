"""The compiled time loop of a linear transient analysis (no Python per step).

One call runs a chunk of steps of any integrator described by stage coefficients (see
:mod:`vtsi.integrators.base`), with constant effective matrices factored beforehand, and
writes the requested responses of every step to ``out``. All vectors are padded
(:mod:`vtsi.banded`). It returns the 0-based index of the first step whose response is
non-finite or exceeds ``limit`` in absolute value, or -1.
"""
from typing import NamedTuple

import numpy as np
from numba import njit

from vtsi.banded import ldl_solve


@njit(cache=True)
def sparse_coefficients(coef):
    """Nonzero slots of each stage's coefficient rows: ``(slots, values, counts)``;
    the last column of ``coef`` (the unknown's coefficient) is left out."""
    n_stages, width = coef.shape
    slots = np.zeros((n_stages, width), dtype=np.int64)
    values = np.zeros((n_stages, width))
    counts = np.zeros(n_stages, dtype=np.int64)
    for s in range(n_stages):
        for j in range(width - 1):
            if coef[s, j] != 0.0:
                slots[s, counts[s]] = j
                values[s, counts[s]] = coef[s, j]
                counts[s] += 1
    return slots, values, counts


@njit(cache=True, inline='always')
def combine(dest, bank, slots, values, count, lo, hi):
    """``dest[lo:hi] = Σ_q values[q] bank[slots[q], lo:hi]`` in one pass (up to 4 terms; more
    terms add a pass each). Entry i is written after its terms are read, so with up to 4 terms
    ``dest`` may be one of them. One pass instead of a pass per term: these short vectors (~100
    entries) cost per pass, not per flop."""
    if count == 0:
        for i in range(lo, hi):
            dest[i] = 0.0
        return
    r0, c0 = bank[slots[0]], values[0]
    if count == 1:
        for i in range(lo, hi):
            dest[i] = c0 * r0[i]
        return
    r1, c1 = bank[slots[1]], values[1]
    if count == 2:
        for i in range(lo, hi):
            dest[i] = c0 * r0[i] + c1 * r1[i]
        return
    r2, c2 = bank[slots[2]], values[2]
    if count == 3:
        for i in range(lo, hi):
            dest[i] = c0 * r0[i] + c1 * r1[i] + c2 * r2[i]
        return
    r3, c3 = bank[slots[3]], values[3]
    for i in range(lo, hi):
        dest[i] = c0 * r0[i] + c1 * r1[i] + c2 * r2[i] + c3 * r3[i]
    for q in range(4, count):
        c, row = values[q], bank[slots[q]]
        for i in range(lo, hi):
            dest[i] += c * row[i]


@njit(cache=True, inline='always')
def add_pattern_loads(rhs, factors, load_ptr, load_dof, load_val, offset):
    for p in range(factors.shape[0]):
        f = factors[p]
        if f != 0.0:
            for k in range(load_ptr[p], load_ptr[p + 1]):
                rhs[offset + load_dof[k]] += f * load_val[k]


def stage_operators(k_rows, c_rows, ku, kv, m_rows=None, km=None):
    """The known part of each stage's equation, ``Σ_j (ku[s, j] K + kv[s, j] C + km[s, j] M) X_j``
    over the bank slots j (ku, kv, km (n_stages, n_slots + 1), see :mod:`vtsi.integrators.base`;
    M's band rows ``m_rows`` needed only where km ≠ 0), as one band product per matrix of a
    combination of the slots: ``K (Σ_j ku_j X_j) + C (Σ_j kv_j X_j) + M (Σ_j km_j X_j)``
    (:func:`stage_rhs`; C left out where it is zero).

    Returns ``ops (n_mats, 2 kd + 1, n)``, the matrices used by their diagonals (``ops[m, k, i] =
    A[i, i + k - kd]``, the band rows ``(n, 2 kd + 1)`` transposed, so that a band product runs
    along contiguous diagonals), and ``weights (n_stages, n_mats, n_slots)`` float64, the
    coefficient of each slot in each matrix's combination."""
    n_stages, width = ku.shape
    km = np.zeros_like(ku) if km is None else km
    used = [(rows, coef[:, : width - 1]) for rows, coef in ((k_rows, ku), (c_rows, kv), (m_rows, km))
            if coef[:, : width - 1].any() and rows is not None and rows.any()]
    ops = np.zeros((len(used), k_rows.shape[1], k_rows.shape[0]))
    weights = np.zeros((n_stages, len(used), width - 1))
    for m, (rows, coef) in enumerate(used):
        ops[m] = rows.T
        weights[:, m, :] = coef
    return ops, weights


@njit(cache=True, fastmath={"contract"}, inline='always')
def stage_rhs(rhs, bank, ops, weights, s, band, scratch):
    """``rhs -= Σ_m A_m (Σ_j weights[s, m, j] bank[j])`` (band products of the matrices ``ops``,
    :func:`stage_operators`; padded vectors); ``scratch`` a padded vector with zero pads, its
    entries overwritten."""
    kd = len(band)
    n = ops.shape[2]
    lo, hi = kd, kd + n
    for m in range(ops.shape[0]):
        first = True
        for j in range(weights.shape[2]):
            c = weights[s, m, j]
            if c != 0.0:
                row = bank[j]
                if first:
                    for i in range(lo, hi):
                        scratch[i] = c * row[i]
                    first = False
                else:
                    for i in range(lo, hi):
                        scratch[i] += c * row[i]
        if first:
            continue
        for k in range(2 * kd + 1):
            diagonal = ops[m, k]
            for i in range(n):
                rhs[lo + i] -= diagonal[i] * scratch[i + k]


@njit(cache=True, inline='always')
def solve_stage(bank, rhs, fac, ops, weights, s, band, scratch):
    """The stage's acceleration: ``rhs`` (holding the loads) minus the known part (see
    :func:`stage_operators`), solved with the stage factor in place."""
    stage_rhs(rhs, bank, ops, weights, s, band, scratch)
    ldl_solve(fac[s], rhs, band)


@njit(cache=True)
def _merge_row(k0, k1, k2, slot):
    """Position (0..2) of bank row ``slot`` among the rows ``k0, k1, k2`` (-1 = free), taking a
    free one if needed: ``(k0, k1, k2, position)``, position -1 if all three are taken."""
    if k0 == slot or k0 < 0:
        return slot, k1, k2, 0
    if k1 == slot or k1 < 0:
        return k0, slot, k2, 1
    if k2 == slot or k2 < 0:
        return k0, k1, slot, 2
    return k0, k1, k2, -1


@njit(cache=True)
def _merge_terms(k0, k1, k2, slots, values, count):
    """The terms ``Σ values[q] X_slots[q]`` on the rows ``k0, k1, k2`` (taking free ones):
    ``(k0, k1, k2, c0, c1, c2, fits)``, fits False if they need a fourth row."""
    c0 = c1 = c2 = 0.0
    fits = True
    for q in range(count):
        k0, k1, k2, p = _merge_row(k0, k1, k2, slots[q])
        fits = fits and p >= 0
        if p == 0:
            c0 += values[q]
        elif p == 1:
            c1 += values[q]
        elif p == 2:
            c2 += values[q]
    return k0, k1, k2, c0, c1, c2, fits


class StageUpdates(NamedTuple):
    """The update coefficients of every stage (:func:`stage_updates`): ``su, vu, cu`` and ``sv,
    vv, cv`` the nonzero terms of ``du`` and ``dv`` (:func:`sparse_coefficients`); where u and v
    read at most three bank rows (``fits[s]``), ``rows[s]`` (3,) int64 those rows (-1: unused) and
    ``coefs[s]`` (6,) the coefficients of u, then of v, on them."""
    su: np.ndarray
    vu: np.ndarray
    cu: np.ndarray
    sv: np.ndarray
    vv: np.ndarray
    cv: np.ndarray
    rows: np.ndarray
    coefs: np.ndarray
    fits: np.ndarray


@njit(cache=True)
def stage_updates(du, dv):
    """The :class:`StageUpdates` of the stage coefficients ``du, dv`` (n_stages, n_slots + 1),
    worked out once per run instead of once per step."""
    su, vu, cu = sparse_coefficients(du)
    sv, vv, cv = sparse_coefficients(dv)
    n_stages = du.shape[0]
    rows = np.full((n_stages, 3), -1, dtype=np.int64)
    coefs = np.zeros((n_stages, 6))
    fits = np.zeros(n_stages, dtype=np.bool_)
    for s in range(n_stages):
        k0, k1, k2, cu0, cu1, cu2, fits_u = _merge_terms(-1, -1, -1, su[s], vu[s], cu[s])
        k0, k1, k2, cv0, cv1, cv2, fits_v = _merge_terms(k0, k1, k2, sv[s], vv[s], cv[s])
        rows[s, 0], rows[s, 1], rows[s, 2] = k0, k1, k2
        coefs[s, 0], coefs[s, 1], coefs[s, 2], coefs[s, 3], coefs[s, 4], coefs[s, 5] = cu0, cu1, cu2, cv0, cv1, cv2
        fits[s] = fits_u and fits_v
    return StageUpdates(su, vu, cu, sv, vv, cv, rows, coefs, fits)


@njit(cache=True, inline='always')
def update_stage(bank, rhs, out_base, s, updates, ua, va, lo, hi, tmp_u, tmp_v):
    """Stage update: ``u = Σ du_j X_j + du_A a``, ``v = Σ dv_j X_j + dv_A a``, ``a`` into the
    slots ``out_base..out_base+2`` (``updates``: :func:`stage_updates`). Returns max |u| (inf if
    any entry is NaN).

    One pass when u and v read at most three bank rows (Newmark, HHT, Bathe's first stage):
    entry i is written after it is read, so the last stage may overwrite the slots 0..2 it
    reads. Otherwise u and v are built in ``tmp_u``/``tmp_v`` first."""
    u_out, v_out, a_out = bank[out_base], bank[out_base + 1], bank[out_base + 2]
    worst = 0.0
    bad = 0.0     # u · 0 summed: NaN if any u is NaN or infinite (no branch in the loop)
    if updates.fits[s]:
        rows, c = updates.rows[s], updates.coefs[s]
        r0 = bank[max(rows[0], 0)]
        r1 = bank[max(rows[1], 0)]
        r2 = bank[max(rows[2], 0)]
        cu0, cu1, cu2, cv0, cv1, cv2 = c[0], c[1], c[2], c[3], c[4], c[5]
        for i in range(lo, hi):
            x0, x1, x2, a = r0[i], r1[i], r2[i], rhs[i]
            u = cu0 * x0 + cu1 * x1 + cu2 * x2 + ua * a
            v_out[i] = cv0 * x0 + cv1 * x1 + cv2 * x2 + va * a
            u_out[i] = u
            a_out[i] = a
            worst = max(worst, abs(u))
            bad += u * 0.0
        return worst if bad == 0.0 else np.inf
    combine(tmp_u, bank, updates.su[s], updates.vu[s], updates.cu[s], lo, hi)
    combine(tmp_v, bank, updates.sv[s], updates.vv[s], updates.cv[s], lo, hi)
    for i in range(lo, hi):
        a = rhs[i]
        u = tmp_u[i] + ua * a
        u_out[i] = u
        v_out[i] = tmp_v[i] + va * a
        a_out[i] = a
        worst = max(worst, abs(u))
        bad += u * 0.0
    return worst if bad == 0.0 else np.inf


@njit(cache=True, fastmath={"contract"})
def run_linear_steps(bank, du, dv, factors, ops, weights,
                     load_factors, load_ptr, load_dof, load_val,
                     rec_slot, rec_index, out, limit, work, band, span):
    """Advance ``load_factors.shape[0]`` steps in place.

    bank : (n_slots, n + 2 kd) padded state bank; slots 0..2 = u, v, a at the chunk start
        (the last stage writes the new state there; stage s < last writes 3 + 3 s ...).
    du, dv : (n_stages, n_slots + 1) stage coefficients of the update.
    factors : (n_stages, n + kd, kd + 1) banded Cholesky factors of the stage matrices.
    ops, weights : the stages' known parts (:func:`stage_operators` of K, C, M and ku, kv, km).
    load_factors : (n_steps, n_stages, n_patterns) stage load factors of the patterns.
    load_ptr, load_dof, load_val : CSR of the pattern load vectors (free dof indices).
    rec_slot, rec_index : slot (0 u, 1 v, 2 a) and dof (index into the bank; -1: a dof at rest,
        read as 0) of each output column.
    out : (n_rows, n_columns) the recorded columns, a row per step (or per stage, see ``span``).
    work : (3, n + 2 kd) zeroed scratch vectors (their pads stay zero).
    band : ``band_type(kd)``, the half bandwidth as a type (the kernel is compiled for it).
    span : int64 array ``(first stage, stages of the last step, every stage)``: the first step
        starts at stage ``span[0]`` (the earlier ones already in the bank), the last runs
        ``span[1]`` stages (its state is then in the slots of its last stage), and with
        ``span[2] = 1`` a row is recorded after every stage (OpenSees's TRBDF2 counts the two
        sub-steps of a composite step as two steps). ``(0, n_stages, 0)``: whole steps.

    Returns the index of the first row whose response is non-finite or exceeds ``limit`` in
    absolute value, or -1.
    """
    kd = len(band)
    n_steps = load_factors.shape[0]
    n_stages, width = du.shape
    A = width - 1
    n = ops.shape[2]
    lo, hi = kd, kd + n
    rhs, xk, xc = work[0], work[1], work[2]
    updates = stage_updates(du, dv)
    row = 0
    for step in range(n_steps):
        first = span[0] if step == 0 else 0
        stop = span[1] if step == n_steps - 1 else n_stages
        base = 0
        for s in range(first, stop):
            rhs[lo:hi] = 0.0
            add_pattern_loads(rhs, load_factors[step, s], load_ptr, load_dof, load_val, kd)
            solve_stage(bank, rhs, factors, ops, weights, s, band, xk)
            base = 0 if s == n_stages - 1 else 3 + 3 * s
            worst = update_stage(bank, rhs, base, s, updates, du[s, A], dv[s, A], lo, hi, xk, xc)
            if span[2] == 1 or s == stop - 1:
                if not (worst <= limit and worst < np.inf):   # NaN and ±inf diverge even with limit = inf
                    return row
                for r in range(rec_slot.shape[0]):
                    out[row, r] = bank[base + rec_slot[r], lo + rec_index[r]] if rec_index[r] >= 0 else 0.0
                row += 1
    return -1


@njit(cache=True)
def run_from_state(u, v, a, coords_full, rest_full, bank, du, dv, factors, ops, weights,
                   load_factors, load_ptr, load_dof, load_val, rec_slot, rec_index, out, limit, work, band, span):
    """:func:`run_linear_steps` from and back to the full-dof state ``u, v, a`` (n_full,): the
    bank's coordinate k is full dof ``coords_full[k]``; read into slots 0..2 first (unless the
    run resumes a step, ``span[0] > 0``: the bank holds its start and earlier stages), written
    back after the steps (from the slots of the last stage run) unless they diverged (then the
    state is left as it was). The dofs ``rest_full`` are not integrated and must be at rest: if
    one is not, nothing is done and -2 is returned (the caller integrates them too). Otherwise
    returns as run_linear_steps."""
    for i in rest_full:
        if u[i] != 0.0 or v[i] != 0.0 or a[i] != 0.0:
            return -2
    kd = len(band)
    if span[0] == 0:
        for k in range(coords_full.shape[0]):
            i = coords_full[k]
            bank[0, kd + k] = u[i]
            bank[1, kd + k] = v[i]
            bank[2, kd + k] = a[i]
    bad = run_linear_steps(bank, du, dv, factors, ops, weights, load_factors, load_ptr, load_dof, load_val,
                           rec_slot, rec_index, out, limit, work, band, span)
    if bad >= 0:
        return bad
    last = span[1] - 1
    base = 0 if last == du.shape[0] - 1 else 3 + 3 * last
    for k in range(coords_full.shape[0]):
        i = coords_full[k]
        u[i] = bank[base, kd + k]
        v[i] = bank[base + 1, kd + k]
        a[i] = bank[base + 2, kd + k]
    return -1
