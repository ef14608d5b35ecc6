"""vtsi.lcp.solve_lcp, the contact LCP: find λ >= 0 with g = W λ + q >= 0 and λ·g = 0.

Checked against two independent solutions:

- brute force: every one of the 2^n active sets F, ``W_FF λ_F = -q_F``, kept if λ_F >= 0 and
  g >= 0 off F (for SPD W exactly one set passes, up to degenerate ties);
- the equivalent bound-constrained least-squares problem: with W = L Lᵀ (Cholesky),
  ½λᵀWλ + qᵀλ = ½‖Lᵀλ + L⁻¹q‖² + const, so λ = argmin ‖Lᵀλ + L⁻¹q‖, λ >= 0, which
  ``scipy.optimize.nnls`` solves (docs/theory/contact.md §3, §6).

Random problems are seeded. W is built as J Jᵀ + δ I with a moderate condition number; q mixes
signs so that typically a part of the contacts separates.
"""
import itertools

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize

import vtsi.lcp as lcp_module
from vtsi.lcp import lcp_workspace, solve_lcp


def random_problem(rng, n, condition=1e3):
    """SPD W (n, n) with eigenvalues in [1/condition, 1] and q with both signs."""
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    eig = np.geomspace(1.0 / condition, 1.0, n)
    W = (Q * eig) @ Q.T
    W = 0.5 * (W + W.T)
    q = rng.standard_normal(n)
    return W, q


def solve(W, q, free=None):
    """Call solve_lcp on copies; ``free`` (bool (n,)) seeds the warm-start free set."""
    n = len(q)
    work = lcp_workspace(n)
    if free is not None:
        work[n + 2, :n] = np.asarray(free, dtype=float)
    lam = np.zeros(n)
    W0, q0 = W.copy(), q.copy()
    ok = solve_lcp(W0, q0, lam, n, work)
    assert ok
    assert np.array_equal(W0, W) and np.array_equal(q0, q)     # inputs untouched
    return lam, work


def brute_force(W, q):
    """The LCP solution by enumeration of the 2^n active sets."""
    n = len(q)
    best = None
    for k in range(n + 1):
        for F in itertools.combinations(range(n), k):
            F = list(F)
            lam = np.zeros(n)
            if F:
                lam[F] = np.linalg.solve(W[np.ix_(F, F)], -q[F])
            g = W @ lam + q
            scale = np.abs(q).max() + 1e-300
            if lam.min() >= -1e-12 * scale and g.min() >= -1e-12 * scale:
                if best is not None:
                    assert np.allclose(lam, best, atol=1e-9 * scale), "two LCP solutions for an SPD W"
                best = lam
    assert best is not None
    return best


def nnls_solution(W, q):
    """argmin ‖Lᵀλ + L⁻¹q‖ over λ >= 0, W = L Lᵀ (Cholesky + NNLS)."""
    L = np.linalg.cholesky(W)
    rhs = -scipy.linalg.solve_triangular(L, q, lower=True)
    lam, _ = scipy.optimize.nnls(L.T, rhs, maxiter=50 * len(q))
    return lam


def assert_complementary(W, q, lam, rtol=1e-12):
    """λ >= 0, g >= -tol, |λ_i g_i| <= tol (λ scale), tol relative to the problem's scale."""
    g = W @ lam + q
    scale_g = np.abs(q).max() + np.abs(W).max() * np.abs(lam).max()
    scale_l = np.abs(lam).max() + 1e-300
    assert lam.min() >= 0.0
    assert g.min() >= -rtol * scale_g
    assert np.abs(lam * g).max() <= rtol * scale_g * scale_l


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 12])
def test_matches_enumeration_of_all_active_sets(n):
    rng = np.random.default_rng(100 + n)
    trials = {1: 200, 2: 200, 3: 200, 5: 100, 8: 30, 12: 4}[n]
    n_mixed = 0
    for _ in range(trials):
        W, q = random_problem(rng, n)
        ref = brute_force(W, q)
        lam, work = solve(W, q)
        scale = np.abs(ref).max() + np.abs(q).max()
        assert np.allclose(lam, ref, rtol=0.0, atol=1e-10 * scale)
        assert_complementary(W, q, lam)
        # the workspace keeps the optimal free set for the next call
        assert np.array_equal(work[n + 2, :n] > 0.5, lam > 0.0)
        n_mixed += 0 < np.count_nonzero(ref) < n
    if n > 1:
        assert n_mixed >= trials // 4      # the trials exercise real mixtures of contact and separation


@pytest.mark.parametrize("n", [2, 5, 8, 12])
def test_any_warm_start_free_set_gives_the_same_solution(n):
    rng = np.random.default_rng(200 + n)
    for _ in range(20 if n < 12 else 5):
        W, q = random_problem(rng, n)
        ref, _ = solve(W, q)
        for free in (np.ones(n), np.zeros(n), rng.random(n) < 0.5, ref > 0.0, ref == 0.0):
            lam, _ = solve(W, q, free)
            scale = np.abs(ref).max() + np.abs(q).max()
            assert np.allclose(lam, ref, rtol=0.0, atol=1e-12 * scale)
            assert_complementary(W, q, lam)


@pytest.mark.parametrize("n", [1, 4, 12, 40])
def test_agrees_with_cholesky_and_nnls(n):
    """The LCP as min ‖Lᵀλ + L⁻¹q‖, λ >= 0, solved by scipy.optimize.nnls (docs/theory/contact.md
    §6); 1e-12."""
    rng = np.random.default_rng(300 + n)
    for _ in range(50 if n < 40 else 10):
        W, q = random_problem(rng, n, condition=1e2)
        lam, _ = solve(W, q)
        ref = nnls_solution(W, q)
        assert np.abs(lam - ref).max() <= 1e-12 * max(np.abs(ref).max(), 1.0)


def test_warm_start_second_call_factorises_once(monkeypatch):
    """The pure-Python body of solve_lcp with a counting ``_solve_free``: the cold call needs
    several factorisations, the warm call with the same problem exactly one, same answer."""
    calls = []
    inner = getattr(lcp_module._solve_free, "py_func", lcp_module._solve_free)   # plain under NUMBA_DISABLE_JIT

    def counting(*args):
        calls.append(1)
        return inner(*args)

    monkeypatch.setattr(lcp_module, "_solve_free", counting)
    rng = np.random.default_rng(7)
    n = 10
    W, q = random_problem(rng, n)
    work = lcp_workspace(n)
    work[n + 2, :n] = 0.0
    lam1, lam2 = np.zeros(n), np.zeros(n)
    body = getattr(lcp_module.solve_lcp, "py_func", lcp_module.solve_lcp)
    assert body(W, q, lam1, n, work)
    cold = len(calls)
    calls.clear()
    assert body(W, q, lam2, n, work)
    assert 0 < np.count_nonzero(lam1) < n
    assert cold > 1 and len(calls) == 1
    assert np.array_equal(lam1, lam2)
    # and the compiled function, called twice on one workspace, returns identical results
    work = lcp_workspace(n)
    a, _ = np.zeros(n), None
    b = np.zeros(n)
    assert solve_lcp(W, q, a, n, work) and solve_lcp(W, q, b, n, work)
    assert np.array_equal(a, b) and np.allclose(a, lam1, atol=1e-13 * np.abs(lam1).max())


def test_bilateral_case_is_a_plain_solve():
    """All gaps closing (q = -W λ* with λ* > 0): λ = λ*, one solve from the all-free start."""
    rng = np.random.default_rng(11)
    W, _ = random_problem(rng, 6)
    lam_star = rng.random(6) + 0.5
    lam, _ = solve(W, -W @ lam_star)
    assert np.allclose(lam, lam_star, rtol=1e-12, atol=0.0)


def test_all_separated_gives_zero():
    rng = np.random.default_rng(12)
    W, q = random_problem(rng, 6)
    lam, _ = solve(W, np.abs(q) + 0.1)
    assert np.array_equal(lam, np.zeros(6))


@pytest.mark.parametrize("seed", range(20))
def test_degenerate_zero_gap_and_zero_force(seed):
    """Strict complementarity fails: contacts with λ_i = 0 *and* g_i = 0 (exactly tangent),
    and q_i = 0 entries. The solution λ* (chosen) must come back, KKT to round-off."""
    rng = np.random.default_rng(400 + seed)
    n = 8
    W, _ = random_problem(rng, n, condition=1e2)
    lam_star = np.where(rng.random(n) < 0.5, rng.random(n) + 0.1, 0.0)
    slack = np.where(lam_star == 0.0, rng.random(n) + 0.1, 0.0)
    tangent = rng.choice(n, size=3, replace=False)
    lam_star[tangent] = 0.0
    slack[tangent] = 0.0                          # λ_i = 0 and g_i = 0 at once
    q = slack - W @ lam_star
    for free in (None, np.zeros(n), lam_star > 0.0, rng.random(n) < 0.5):
        lam, _ = solve(W, q, free)
        assert np.abs(lam - lam_star).max() <= 1e-12 * np.abs(lam_star).max() + 1e-14
        assert_complementary(W, q, lam)
    # q with exact zeros: those contacts touch with no load at the optimum when the rest leaves them
    q0 = np.abs(rng.standard_normal(n))
    q0[[1, 4]] = 0.0
    lam, _ = solve(W, q0)
    assert np.array_equal(lam, np.zeros(n))
    lam, _ = solve(W, np.zeros(n))
    assert np.array_equal(lam, np.zeros(n))


@pytest.mark.parametrize("seed", range(20))
def test_semidefinite_flexibility_redundant_contacts(seed):
    """Redundant contacts (duplicate rows of G): W = G Gᵀ is singular. The documented fallback
    (W_FF + εI, ε = 1e-12·max diag W, ×100 until Cholesky succeeds) still returns a solution:
    λ >= 0, W λ + q >= -tol, λ·g <= tol, with tol relative to the problem's scale; and the
    total force of each redundant group and the gaps equal those of the reduced problem."""
    rng = np.random.default_rng(500 + seed)
    m, n_dof = 5, 7
    G = rng.standard_normal((m, n_dof))
    dup = rng.choice(m, size=3, replace=True)
    Gr = np.vstack([G, G[dup]])                 # rows m.. duplicate rows dup
    W = Gr @ Gr.T
    assert np.linalg.matrix_rank(W) == m
    q_red = rng.standard_normal(m)
    q = np.concatenate([q_red, q_red[dup]])     # duplicated contacts have the same free gap
    for free in (None, np.zeros(len(q)), rng.random(len(q)) < 0.5):
        lam, _ = solve(W, q, free)
        assert np.all(np.isfinite(lam))
        assert_complementary(W, q, lam, rtol=1e-9)
        # physics is unique even if the split among duplicates is not
        total = lam[:m].copy()
        np.add.at(total, dup, lam[m:])
        ref = brute_force(G @ G.T, q_red)
        assert np.allclose(total, ref, atol=1e-8 * (np.abs(ref).max() + 1.0))
        assert np.allclose(W @ lam + q, np.concatenate([G @ G.T @ ref + q_red, (G @ G.T @ ref + q_red)[dup]]),
                           atol=1e-8 * (np.abs(q).max() + 1.0))


@pytest.mark.parametrize("seed", range(10))
def test_semidefinite_all_loaded_from_the_bilateral_start(seed):
    """Every contact loaded (q = -W λ*, duplicates included): the all-free warm start factors the
    singular W_FF itself (round-off pivots ~1e-6 here, or the ε-regularisation when a pivot is
    exactly 0). The result is feasible to round-off and carries the same total load per
    redundant group (how it splits among coincident contacts is arbitrary: any split solves the
    LCP; here it is close to even, set by round-off)."""
    rng = np.random.default_rng(600 + seed)
    m, n_dof = 5, 7
    G = rng.standard_normal((m, n_dof))
    dup = rng.choice(m, size=3, replace=False)
    Gr = np.vstack([G, G[dup]])
    W = Gr @ Gr.T
    lam_red = rng.random(m) + 0.5
    q_red = -(G @ G.T) @ lam_red
    q = np.concatenate([q_red, q_red[dup]])
    lam, _ = solve(W, q)
    assert_complementary(W, q, lam, rtol=1e-9)
    total = lam[:m].copy()
    np.add.at(total, dup, lam[m:])
    assert np.allclose(total, lam_red, rtol=1e-8)
    assert np.allclose(lam[dup], lam[m:], rtol=1e-2)


def test_exactly_singular_uses_the_regularisation():
    """Contacts 0 and 2 coincide and the Cholesky pivot is exactly 0: the fallback W_FF + εI
    (ε = 1e-12 max diag W) splits the load evenly, and the gaps are >= -ε‖λ‖."""
    W = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 1.0]])
    q = np.array([-1.0, -1.0, -1.0])
    lam, _ = solve(W, q)
    assert np.allclose(lam, [0.5, 1.0, 0.5], rtol=1e-10)
    g = W @ lam + q
    assert g.min() >= -1e-12 * np.abs(lam).max() * 1.0001
    assert_complementary(W, q, lam, rtol=1e-11)


def test_semidefinite_duplicate_with_different_gaps():
    """Two coincident contacts where one is already 1 mm closer: the closer one carries the load."""
    W = np.array([[2.0, 2.0, 1.0], [2.0, 2.0, 1.0], [1.0, 1.0, 3.0]])
    q = np.array([-1.0, -1.0 + 1e-3, -0.5])
    lam, _ = solve(W, q)
    assert_complementary(W, q, lam, rtol=1e-9)
    assert lam[1] == 0.0 and lam[0] > 0.0


def test_zero_contacts():
    work = lcp_workspace(0)
    assert solve_lcp(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 0, work)


def test_leading_block_only():
    """``n`` < the arrays' size: only the leading n contacts are solved."""
    rng = np.random.default_rng(13)
    W, q = random_problem(rng, 6)
    big_W = np.zeros((9, 9))
    big_W[:6, :6] = W
    big_q = np.zeros(9)
    big_q[:6] = q
    lam = np.full(9, -7.0)
    assert solve_lcp(big_W, big_q, lam, 6, lcp_workspace(6))
    assert np.allclose(lam[:6], brute_force(W, q), atol=1e-10)
    assert np.array_equal(lam[6:], np.full(3, -7.0))
