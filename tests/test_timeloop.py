"""The compiled building blocks of the time loops (vtsi/timeloop.py): ``combine`` and
``update_stage`` against numpy, for every number of terms, with the output written over one of
the rows it reads (the last stage writes the new state in place)."""
import numpy as np
import pytest

from vtsi.timeloop import combine, stage_updates, update_stage

LO, HI = 2, 9


def _bank(seed=0):
    return np.random.default_rng(seed).normal(size=(9, 11))


@pytest.mark.parametrize("count", range(7))
def test_combine_is_the_weighted_sum(count):
    bank = _bank(count)
    slots = np.array([0, 3, 1, 5, 2, 4, 6][:count] + [0] * (7 - count))
    values = np.linspace(-1.5, 2.0, 7)
    dest = np.full(11, 7.0)
    combine(dest, bank, slots, values, count, LO, HI)
    expected = values[:count] @ bank[slots[:count]] if count else np.zeros(11)
    np.testing.assert_allclose(dest[LO:HI], expected[LO:HI], rtol=1e-14, atol=1e-14)
    assert np.all(dest[:LO] == 7.0) and np.all(dest[HI:] == 7.0)       # outside lo:hi untouched


@pytest.mark.parametrize("slots_u, slots_v", [
    ([0, 1, 2], [1, 2]),              # Newmark: three rows, one pass, in place
    ([0, 1, 2, 3], [1, 4]),           # five rows: the two-pass path
])
@pytest.mark.parametrize("out_base", [0, 6])
def test_update_stage(slots_u, slots_v, out_base):
    """u = Σ du X + ua a, v = Σ dv X + va a, a into out_base..out_base+2 (out_base = 0: over the
    rows it reads), and the largest |u|."""
    bank = _bank(1)
    before = bank.copy()
    rhs = np.random.default_rng(2).normal(size=11)
    ua, va = 0.3, -0.7
    du, dv = np.zeros((1, 7)), np.zeros((1, 7))          # 6 bank slots and the stage's acceleration
    du[0, slots_u], du[0, 6] = np.arange(1, len(slots_u) + 1) * 0.5, ua
    dv[0, slots_v], dv[0, 6] = -np.arange(1, len(slots_v) + 1) * 0.25, va
    updates = stage_updates(du, dv)
    assert updates.fits[0] == (len(set(slots_u) | set(slots_v)) <= 3)
    worst = update_stage(bank, rhs, out_base, 0, updates, ua, va, LO, HI, np.zeros(11), np.zeros(11))
    u = du[0, :6] @ before[:6] + ua * rhs
    v = dv[0, :6] @ before[:6] + va * rhs
    np.testing.assert_allclose(bank[out_base, LO:HI], u[LO:HI], rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(bank[out_base + 1, LO:HI], v[LO:HI], rtol=1e-14, atol=1e-14)
    np.testing.assert_array_equal(bank[out_base + 2, LO:HI], rhs[LO:HI])
    assert worst == pytest.approx(np.abs(u[LO:HI]).max(), rel=1e-14)


def test_update_stage_reports_nan_as_infinite():
    bank = _bank(3)
    rhs = np.zeros(11)
    rhs[5] = np.nan
    d = np.array([[1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0]])
    worst = update_stage(bank, rhs, 6, 0, stage_updates(d, d), 1.0, 1.0, LO, HI, np.zeros(11), np.zeros(11))
    assert worst == np.inf


@pytest.mark.parametrize("name", ["Newmark", "HHT", "Bathe", "GeneralizedAlpha", "undamped"])
def test_stage_rhs_is_the_known_part_of_each_stage(name):
    """``stage_rhs`` subtracts Σ_j (ku_j K + kv_j C + km_j M) X_j, as numpy computes it from the
    stage coefficients, for every stage of the integrator (Bathe's second stage reads more slots,
    the generalized-α method's M terms), also with C = 0 (left out of the operators)."""
    import scipy.sparse as sp
    from vtsi.banded import band_rows, band_type
    from vtsi.integrators import GeneralizedAlpha, make_integrator
    from vtsi.timeloop import stage_operators, stage_rhs
    rng = np.random.default_rng(3)
    n, kd = 9, 2
    dense = lambda: sp.csr_matrix(np.triu(np.tril(rng.normal(size=(n, n)), kd), -kd))
    K, C, M = dense(), dense(), dense()
    if name == "undamped":
        C = sp.csr_matrix((n, n))
    integ = GeneralizedAlpha(0.9, 0.8) if name == "GeneralizedAlpha" else make_integrator(
        {"undamped": "Newmark", "HHT": "HHT(0.9)"}.get(name, name))
    stages = integ.stages(1e-3)
    ku, kv, km = (np.stack([getattr(st, k) for st in stages]) for k in ("ku", "kv", "km"))
    ops, weights = stage_operators(band_rows(K, kd), band_rows(C, kd), ku, kv, band_rows(M, kd), km)
    assert ops.shape == ((2 if name == "undamped" else 3) if np.any(km[:, :-1]) else (1 if name == "undamped" else 2),
                         2 * kd + 1, n)
    bank = np.zeros((integ.n_slots, n + 2 * kd))
    bank[:, kd: kd + n] = rng.normal(size=(integ.n_slots, n))
    for s in range(len(stages)):
        rhs = np.zeros(n + 2 * kd)
        rhs[kd: kd + n] = rng.normal(size=n)
        expected = rhs[kd: kd + n] - sum(ku[s, j] * (K @ bank[j, kd: kd + n]) + kv[s, j] * (C @ bank[j, kd: kd + n])
                                         + km[s, j] * (M @ bank[j, kd: kd + n]) for j in range(integ.n_slots))
        scratch = np.zeros(n + 2 * kd)
        stage_rhs(rhs, bank, ops, weights, s, band_type(kd), scratch)
        np.testing.assert_allclose(rhs[kd: kd + n], expected, rtol=1e-12, atol=1e-12)
        assert not np.any(scratch[:kd]) and not np.any(scratch[kd + n:])
