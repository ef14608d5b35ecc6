"""Linear complementarity problems of contact: find λ with

    λ >= 0,   g = W λ + q >= 0,   λ·g = 0,

for a symmetric positive (semi-)definite W (the contact flexibility). For SPD W this is the
convex QP ``min ½ λᵀWλ + qᵀλ, λ >= 0``, solved exactly by an active-set method of the
Lawson-Hanson kind: a free set F, ``W_FF λ_F = -q_F`` by Cholesky, an interpolation step back
into the feasible region when an entry of λ_F turns non-positive, and the most violated
inactive contact (most negative g) added next. It terminates in finitely many steps.

Warm start: the previous call's free set is tried first; when it is still optimal (no wheel
changed state, the usual case) the cost is one Cholesky factorisation, as in the bilateral
solve. A semi-definite W_FF (redundant contacts) is regularised: ``W_FF + ε I`` with
ε = 1e-12 · max diag(W), raised ×100 until the factorisation succeeds (documented fallback:
it picks a force distribution among the redundant contacts, and g stays ≥ -ε‖λ‖).

References
----------
Lawson, C.L., Hanson, R.J. (1974) Solving Least Squares Problems, ch. 23 (NNLS).
Cottle, R.W., Pang, J.-S., Stone, R.E. (1992) The Linear Complementarity Problem.
"""
import numpy as np
from numba import njit


def lcp_workspace(n):
    """Scratch array for :func:`solve_lcp` with up to ``n`` contacts; row ``n + 2`` holds the
    free set flags between calls (1 = free), initialised to all free (bilateral guess). Row
    ``n + 3`` (also all free) is for a caller that solves subsets of the contacts
    (``solve_lcp(..., m, work)`` with m < n, its flags in row m + 2) to remember each contact's
    flag between calls."""
    work = np.zeros((n + 4, max(n, 1)))
    work[n + 2:, :n] = 1.0
    return work


@njit(cache=True)
def cholesky_in_place(a, m):
    """Cholesky factor of the leading ``m × m`` block of SPD ``a``, in place (lower triangle);
    returns False if that block is not positive definite.

    Profile (skyline) factorisation: row i's entries left of its first nonzero stay zero in the
    factor, so the dot products start there. W is mostly such zeros (a wheel on rigid ground is
    coupled only to its car-mates), which makes a 32-wheel train ~5× cheaper than a dense
    factorisation. The profile is kept in the (unused) upper triangle: ``a[0, i]``."""
    for i in range(1, m):
        f = 0
        while f < i and a[i, f] == 0.0:
            f += 1
        a[0, i] = f
    for j in range(m):
        fj = int(a[0, j]) if j > 0 else 0
        d = a[j, j]
        for k in range(fj, j):
            d -= a[j, k] * a[j, k]
        if not d > 0.0:
            return False
        d = np.sqrt(d)
        a[j, j] = d
        for i in range(j + 1, m):
            fi = int(a[0, i])
            if fi > j:
                continue
            s = a[i, j]
            for k in range(max(fi, fj), j):
                s -= a[i, k] * a[j, k]
            a[i, j] = s / d
    return True


@njit(cache=True)
def cholesky_substitute(a, b, m):
    """Solve ``L Lᵀ x = b`` in place with the factor left by :func:`cholesky_in_place`."""
    for i in range(m):
        s = b[i]
        for k in range(int(a[0, i]) if i > 0 else 0, i):
            s -= a[i, k] * b[k]
        b[i] = s / a[i, i]
    for i in range(m - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, m):
            if int(a[0, k]) <= i:
                s -= a[k, i] * b[k]
        b[i] = s / a[i, i]


@njit(cache=True)
def _solve_free(W, q, lam_free, free, n, fac):
    """``lam_free[F] = -W_FF⁻¹ q_F`` (0 elsewhere), regularised if W_FF is singular.

    Allocates nothing (it runs several times a step): W_FF is gathered into ``fac`` by walking
    the free flags, and the solution is computed packed at the front of ``lam_free``, then
    spread to the free positions from the last one down (the a-th free position is >= a, so
    every entry is read before it is overwritten)."""
    m = 0
    dmax = 0.0
    for i in range(n):
        if free[i] > 0.5:
            dmax = max(dmax, W[i, i])
            m += 1
    eps = 0.0
    ok = False
    for attempt in range(12):
        a = 0
        for i in range(n):
            if free[i] > 0.5:
                b = 0
                for j in range(i + 1):
                    if free[j] > 0.5:
                        fac[a, b] = W[i, j]
                        b += 1
                fac[a, a] += eps
                a += 1
        ok = cholesky_in_place(fac, m)
        if ok:
            break
        eps = 1e-12 * dmax if eps == 0.0 else eps * 100.0
    if not ok:
        return False
    a = 0
    for i in range(n):
        if free[i] > 0.5:
            lam_free[a] = -q[i]
            a += 1
    cholesky_substitute(fac, lam_free, m)
    a = m - 1
    for i in range(n - 1, -1, -1):
        if free[i] > 0.5:
            lam_free[i] = lam_free[a]
            a -= 1
        else:
            lam_free[i] = 0.0
    return True


@njit(cache=True)
def solve_lcp(W, q, lam, n, work):
    """Solve LCP(W, q) for the leading ``n`` contacts into ``lam``; ``W`` is not modified.

    ``work`` comes from :func:`lcp_workspace` and carries the free set from call to call.
    Returns False only if no factorisation succeeds.
    """
    if n == 0:
        return True
    fac = work[:n, :n]
    z = work[n, :n]
    grad = work[n + 1, :n]
    free = work[n + 2, :n]
    scale = 0.0
    for i in range(n):
        scale = max(scale, abs(q[i]), W[i, i])
    tol = 1e-14 * scale
    # warm start: the previous free set, kept if its solution is feasible
    if not _solve_free(W, q, z, free, n, fac):
        return False
    feasible = True
    for i in range(n):
        if free[i] > 0.5 and z[i] < 0.0:
            feasible = False
    for i in range(n):
        if feasible:
            lam[i] = z[i] if free[i] > 0.5 else 0.0
        else:
            lam[i] = 0.0
            free[i] = 0.0
    for outer in range(3 * n + 3):
        enter, worst = -1, -tol
        for i in range(n):
            g = q[i]
            for j in range(n):
                g += W[i, j] * lam[j]
            grad[i] = g
            if free[i] < 0.5 and g < worst:
                enter, worst = i, g
        if enter < 0:
            return True
        free[enter] = 1.0
        for inner in range(n + 1):
            if not _solve_free(W, q, z, free, n, fac):
                return False
            if inner == 0 and z[enter] <= 0.0:
                free[enter] = 0.0       # cannot carry load: optimal at zero (round-off case)
                return True
            alpha, blocked = 1.0, -1
            for i in range(n):
                if free[i] > 0.5 and z[i] <= 0.0:
                    a_i = lam[i] / (lam[i] - z[i])
                    if a_i < alpha:
                        alpha, blocked = a_i, i
            if blocked < 0:
                for i in range(n):
                    # z_i <= 0 here only by round-off (its step ratio rounded to 1): such a
                    # contact leaves the free set at exactly zero force, never at -1e-17
                    if free[i] > 0.5 and z[i] <= 0.0:
                        free[i] = 0.0
                    lam[i] = z[i] if free[i] > 0.5 else 0.0
                break
            for i in range(n):
                if free[i] > 0.5:
                    lam[i] += alpha * (z[i] - lam[i])
                    if lam[i] <= 0.0 or i == blocked:
                        lam[i] = 0.0
                        free[i] = 0.0
    return True
