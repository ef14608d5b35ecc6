"""The solvers behind vtsi.analysis.eigen and modes_up_to agree with each other and with the full
dense problem: LAPACK's subset of the lowest modes (gvx), LAPACK's every mode, ARPACK's
shift-invert about 0; lumped mass (massless rotations: M singular) and consistent mass.

The reference is scipy.linalg.eigh(M, K) of the assembled matrices, every mode, ω² = 1/μ.
Frequencies agree to 1e-10 relative, mass-normalised shapes to 1e-8 of their largest entry
(each path signs its shapes by one rule, so they agree with their sign; the reference up to sign).
"""
import numpy as np
import pytest
import scipy.linalg

import vtsi
import vtsi.analysis as analysis
from vtsi.analysis import DENSE_EIGEN_MAX, eigen, modes_up_to
from vtsi.errors import AnalysisError
from vtsi.models.bridges import continuous_beam

E, I, MU = 3.5e10, 1.9, 15000.0        # Pa, m⁴, kg/m: a concrete deck


def viaduct(spans, elements_per_span, consistent_mass):
    """A continuous beam over ``spans`` [m]: 3 dofs a node, pin then rollers."""
    model = vtsi.Model()
    continuous_beam(model, spans, elements_per_span, E, I, MU, consistent_mass=consistent_mass)
    return model


def reference(model):
    """Every mode of finite frequency of the full dense problem: ``(omega2 ascending, vectors
    (n_free, n) mass-normalised)``."""
    asm = model.build()
    mu, vec = scipy.linalg.eigh(asm.M.toarray(), asm.K.toarray())
    finite = mu > 1e-14 * mu.max()
    omega2, vec = 1.0 / mu[finite][::-1], vec[:, finite][:, ::-1]
    return omega2, vec / np.sqrt(np.einsum("ij,ij->j", vec, asm.M @ vec))


def assert_same_modes(omega2, shapes, ref_omega2, ref_vec, asm, up_to_sign=True):
    """Frequencies to 1e-10 relative; free-dof shapes to 1e-8 of their largest entry (up to sign
    against the reference)."""
    k = len(omega2)
    assert np.max(np.abs(np.sqrt(omega2 / ref_omega2[:k]) - 1.0)) < 1e-10
    vec, ref = shapes[asm.full_of_free], ref_vec[:, :k]
    scale = np.abs(ref).max(axis=0)
    diff = np.abs(vec - ref).max(axis=0)
    if up_to_sign:
        diff = np.minimum(diff, np.abs(vec + ref).max(axis=0))
    assert np.max(diff / scale) < 1e-8


@pytest.fixture(scope="module", params=[False, True], ids=["lumped", "consistent"])
def mid_model(request):
    """3 spans of 30 m in 102 elements: 304 free dofs, above DENSE_EIGEN_MAX (either path
    applies); lumped: the 103 rotations are massless."""
    model = viaduct([30.0] * 3, 34, request.param)
    asm = model.build()
    assert asm.n_free > DENSE_EIGEN_MAX
    return model, asm, reference(model)


def test_dense_subset_dense_full_and_sparse_agree(mid_model):
    model, asm, (ref_omega2, ref_vec) = mid_model
    n_mass = int(np.count_nonzero(asm.M.diagonal() > 0.0))
    rotation = asm.full_of_free % asm.ndf == 2
    assert np.array_equal(asm.M.diagonal() == 0.0, rotation) == (n_mass < asm.n_free)    # lumped: M singular
    assert len(ref_omega2) == n_mass            # one mode per dof with mass, none for a massless rotation
    k = 30
    subset = analysis._mode_shapes(asm, analysis._dense_modes(asm, lowest=k)[1])
    full = analysis._dense_modes(asm)
    sparse = analysis._sparse_modes(asm, k, n_mass)
    assert len(full[0]) == n_mass
    for omega2, vec in (analysis._dense_modes(asm, lowest=k), (full[0][:k], full[1][:, :k]), sparse):
        shapes = analysis._mode_shapes(asm, vec)
        assert_same_modes(omega2, shapes, ref_omega2, ref_vec, asm)
        assert np.max(np.abs(shapes - subset)) < 1e-8 * np.abs(subset).max()   # the same sign, whichever path
        assert np.allclose(np.einsum("ij,ij->j", shapes, asm.M_full @ shapes), 1.0, rtol=1e-12, atol=0.0)


def test_eigen_takes_either_path_and_agrees(mid_model):
    """eigen's few modes (ARPACK here), many modes (LAPACK's subset: 8 k > n), n - 1 modes and 'all'."""
    model, asm, (ref_omega2, ref_vec) = mid_model
    n_mass = int(np.count_nonzero(asm.M.diagonal() > 0.0))
    assert not analysis._dense_for(asm.n_free, 6, n_mass) and analysis._dense_for(asm.n_free, 60, n_mass)
    for k in (6, 60):
        omega2, shapes = eigen(model, k)
        assert omega2.shape == (k,) and shapes.shape == (asm.n_full, k)
        assert_same_modes(omega2, shapes, ref_omega2, ref_vec, asm)
    omega2, shapes = eigen(model, "all")
    assert omega2.shape == (n_mass,)
    assert_same_modes(omega2, shapes, ref_omega2, ref_vec, asm)
    if n_mass == asm.n_free:                   # consistent mass: as many modes as free dofs
        omega2 = eigen(model, asm.n_free - 1)[0]
        # μ = 1/ω² to an absolute ε max μ in either LAPACK call: ω² to about ε ω²/ω₁² relative
        assert np.all(np.abs(omega2 / ref_omega2[:-1] - 1.0) < 1e-10 + 1e-14 * ref_omega2[:-1] / ref_omega2[0])
    else:
        with pytest.raises(AnalysisError, match=rf"^eigen: only {n_mass} dofs carry mass, {n_mass + 1} modes requested$"):
            eigen(model, n_mass + 1)


def test_sparse_modes_repeat_to_the_bit_and_are_signed_by_the_rule(mid_model):
    """ARPACK starts from a fixed vector: two calls give the same modes to the bit (from its own
    random start they differed by 1e-12, and two runs of one sweep with them), signed by the rule."""
    model, asm, _ = mid_model
    (w_first, first), (w_second, second) = eigen(model, 8), eigen(model, 8)
    assert np.array_equal(w_first, w_second) and np.array_equal(first, second)
    vec = first[asm.full_of_free]
    lead = np.argmax(np.abs(vec) > 1e-3 * np.abs(vec).max(axis=0), axis=0)
    assert np.all(vec[lead, np.arange(8)] > 0.0)


def test_small_model_dense_by_value():
    """Up to DENSE_EIGEN_MAX free dofs: one LAPACK call for the modes up to f_max; below the first
    mode, the first mode alone."""
    model = viaduct([20.0] * 2, 20, False)
    asm = model.build()
    assert asm.n_free <= DENSE_EIGEN_MAX
    ref_omega2, ref_vec = reference(model)
    ref_f = np.sqrt(ref_omega2) / (2 * np.pi)
    for f_max in (30.0, 0.5 * (ref_f[4] + ref_f[5])):
        f, shapes = modes_up_to(model, f_max)
        assert len(f) == np.sum(ref_f <= f_max) and f[-1] <= f_max
        assert_same_modes((2 * np.pi * f) ** 2, shapes, ref_omega2, ref_vec, asm)
    f, shapes = modes_up_to(model, 0.5 * ref_f[0])
    assert len(f) == 1
    assert_same_modes((2 * np.pi * f) ** 2, shapes, ref_omega2, ref_vec, asm)


@pytest.mark.parametrize("spans, f_max, rounds", [
    ([30.0] * 30, 30.0, [8, 98]),        # 871 dofs: 8 modes (to 3.78 Hz), then 1.5 × 8 × 30 / 3.78 + 2 (95 to 30 Hz)
    ([30.0] * 3, 60.0, [8, "dense"]),    # 268 dofs: 8 modes (to 20.6 Hz), then LAPACK's: 8 × 38 > 268 (17 to 60 Hz)
])
def test_modes_up_to_in_rounds(monkeypatch, spans, f_max, rounds):
    """modes_up_to on ARPACK asks 8 modes, then the count up to f_max extrapolated from them,
    until a mode lies above f_max (or the count is LAPACK's to find): the modes up to f_max of
    the full problem, whichever solve found them."""
    model = viaduct(spans, 10 if len(spans) > 3 else 30, True)
    asm = model.build()
    asked = []
    sparse, dense = analysis._sparse_modes, analysis._dense_modes
    monkeypatch.setattr(analysis, "_sparse_modes", lambda asm, k, n_mass: asked.append(k) or sparse(asm, k, n_mass))
    monkeypatch.setattr(analysis, "_dense_modes", lambda asm, **up_to: asked.append("dense") or dense(asm, **up_to))
    f, shapes = modes_up_to(model, f_max)
    assert asked == rounds
    ref_omega2, ref_vec = reference(model)
    ref_f = np.sqrt(ref_omega2) / (2 * np.pi)
    assert len(f) == np.sum(ref_f <= f_max) > rounds[0]
    assert_same_modes((2 * np.pi * f) ** 2, shapes, ref_omega2, ref_vec, asm)


def test_a_model_without_mass_is_refused():
    model = vtsi.Model()
    model.node(1, 0.0, 0.0)
    model.node(2, 10.0, 0.0)
    model.fix(1, 1, 1, 1)
    model.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=E, I=I)
    for call in (lambda: eigen(model, 1), lambda: modes_up_to(model, 30.0)):
        with pytest.raises(AnalysisError, match=r"^(eigen|modes_up_to): no dof carries mass \(every mode has an "
                                                r"infinite frequency\)$"):
            call()


def identical_decks(n_decks, elements_per_span=10):
    """``n_decks`` simply supported 30 m decks side by side, each its own beam: every frequency
    repeats n_decks times."""
    model, node, element = vtsi.Model(), 1, 1
    for d in range(n_decks):
        continuous_beam(model, [30.0], elements_per_span, 3.5e10, 1.9, 15000.0, consistent_mass=True,
                        x0=31.0 * d, first_node=node, first_element=element)
        node, element = max(model.nodes) + 1, max(model.element_tags()) + 1
    return model


def test_every_copy_of_a_repeated_frequency_is_found():
    """30 identical decks, 60 modes (ARPACK's path): Lanczos from one vector missed 3 of the 30
    copies of the second frequency and returned the third frequency in their place (15 % off,
    silently); the Sturm count finds that and LAPACK solves it. The count itself against the
    dense eigenvalues."""
    model = identical_decks(30)
    asm = model.build()
    assert not analysis._dense_for(asm.n_free, 60, asm.n_free)
    omega2, _ = eigen(model, 60)
    dense = scipy.linalg.eigh(asm.K.toarray(), asm.M.toarray(), eigvals_only=True)
    np.testing.assert_allclose(omega2, dense[:60], rtol=1e-9)
    for between in (0.5 * (dense[29] + dense[30]), 0.5 * (dense[59] + dense[60]), 1.5 * dense[89]):
        assert analysis._modes_below(asm, between) == np.count_nonzero(dense < between)


def test_modes_up_to_on_identical_decks_is_complete():
    """24 identical decks up to 20 Hz: every copy of their three frequencies below it (72 modes;
    ARPACK's first 8 did not converge on a 40-fold frequency and raised scipy's own error)."""
    model = identical_decks(24)
    f, shapes = modes_up_to(model, 20.0)
    asm = model.build()
    dense = np.sqrt(scipy.linalg.eigh(asm.K.toarray(), asm.M.toarray(), eigvals_only=True)) / (2 * np.pi)
    np.testing.assert_allclose(f, dense[dense <= 20.0], rtol=1e-9)
    assert len(f) == 72 and shapes.shape[1] == 72


def test_lowest_modes_until_doubles_and_shows_every_pair():
    """lowest_modes_until asks k, 2k, 4k … modes until ``enough`` holds, and at most one mode per
    dof with mass (lumped: the 103 rotations of 3 × 30 m in 102 elements are massless); ``enough``
    sees every pair, the last included, as eigen gives it."""
    model = viaduct([30.0] * 3, 34, False)
    asm = model.build()
    n_mass = int(np.count_nonzero(asm.M.diagonal() > 0.0))
    ref_omega2, _ = reference(model)
    seen = []

    def above(limit):
        return lambda omega2, shapes: seen.append(len(omega2)) or omega2[-1] > limit

    omega2, shapes = analysis.lowest_modes_until(model, 5, above(ref_omega2[30]))
    assert seen == [5, 10, 20, 40] and shapes.shape[1] == 40
    np.testing.assert_allclose(omega2, ref_omega2[:40], rtol=1e-10)
    seen.clear()
    omega2, _ = analysis.lowest_modes_until(model, 150, above(np.inf))      # never enough: every mode
    assert seen == [150, n_mass] and 150 < n_mass < 300 and len(omega2) == n_mass == len(ref_omega2)


def test_no_false_alarm_of_missed_modes_on_a_fine_mesh(monkeypatch):
    """25 + 32 + 25 m in 1200 elements (3598 dofs): ARPACK's lowest ω² is known to about 3e-8
    only, and a Sturm count 1e-8 below the highest found read modes missing where none were (for
    2, 4 and 8 modes: refused beyond ALL_MODES_MAX dofs, a 9 s dense solve below). The count is
    now taken mid-gap: every k on ARPACK's path, each k's modes the lowest of the next."""
    model = vtsi.Model()
    continuous_beam(model, [25.0, 32.0, 25.0], 400, 3.5e10, 7.0, 2.0e4, A=8.0)
    asm = model.build()
    assert asm.n_free > analysis.ALL_MODES_MAX
    monkeypatch.setattr(analysis, "_dense_modes", lambda *a, **k: pytest.fail("the dense solve was taken"))
    previous = None
    for k in (1, 2, 3, 4, 8):
        omega2, _ = eigen(model, k)
        if previous is not None:
            np.testing.assert_allclose(omega2[:len(previous)], previous, rtol=1e-7)
        previous = omega2
    for j in range(1, 8):
        assert analysis._modes_below(asm, 0.5 * (omega2[j - 1] + omega2[j])) == j


def test_a_larger_basis_before_the_dense_solve(monkeypatch):
    """30 identical decks of 40 elements (3600 dofs), 60 modes: a basis of 121 Lanczos vectors
    misses copies of the repeated frequencies, and the dense solve is beyond ALL_MODES_MAX; the
    second run's basis of 241 finds all 30 copies of each of the two lowest frequencies."""
    model = identical_decks(30, 40)
    verdicts, complete = [], analysis._found_every_mode
    monkeypatch.setattr(analysis, "_found_every_mode", lambda asm, omega2: verdicts.append(complete(asm, omega2))
                        or verdicts[-1])
    omega2, _ = eigen(model, 60)
    assert verdicts == [False, True]
    single = eigen(identical_decks(1, 40), 2)[0]
    np.testing.assert_allclose(omega2, np.repeat(single, 30), rtol=1e-8)


def test_a_mode_missing_just_below_the_highest_is_found_missing():
    """The Sturm count sits just below the highest cluster (CLUSTER under it), not in the middle
    of the gap below it, which let a mode missing in the gap's upper half pass: the lowest modes
    of a 3 × 30 m beam with the fifth left out."""
    model = viaduct([30.0] * 3, 10, True)
    asm = model.build()
    omega2, _ = eigen(model, 8)
    assert analysis._found_every_mode(asm, omega2[:6])
    found = np.delete(omega2[:6], 4)
    assert omega2[4] > 0.5 * (omega2[3] + omega2[5])          # the fifth lies in the gap's upper half
    assert not analysis._found_every_mode(asm, found)
