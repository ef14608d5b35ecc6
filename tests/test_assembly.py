"""Assembly: the free-dof pattern of K, M, C (the arrays the analyses factor and step) against
the CSR matrices built from it and the full-dof assembly; dof components."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

import vtsi
from vtsi.analysis import component_labels, component_labels_of_entries
from vtsi.assembly import csr_pattern, reverse_cuthill_mckee


def frame(tied):
    """A two-span beam on a column (uy and rz of the beam, a tied node with ``tied``), with
    Rayleigh damping: K, M and C with different nonzeros."""
    m = vtsi.Model()
    for i in range(5):
        m.node(i + 1, 2.0 * i, 0.0)
    m.node(6, 4.0, -3.0)
    m.node(7, 4.0, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(5, 0, 1, 0)
    m.fix(6, 1, 1, 1)
    for i in range(4):
        m.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=1.0, E=2e11, I=1e-3, rho=100.0, cmass=1)
    m.element("elasticBeamColumn", 5, (6, 7), A=1.0, E=2e11, I=1e-3, rho=100.0)
    if tied:
        m.equal_dof(3, 7, 1, 2)
    m.rayleigh(0.1, 0.0, 1e-4, 0.0)
    return m


@pytest.mark.parametrize("tied", [False, True])
def test_free_pattern_holds_the_free_matrices(tied):
    """Every nonzero of the free K, M and C sits in the pattern with its value, sorted by row
    then column; without constraints they are the full matrices' free rows and columns."""
    asm = frame(tied).build()
    p = asm.pattern
    n = asm.n_free
    assert np.all(np.diff(p.rows * n + p.cols) > 0)
    for name in "KMC":
        dense = np.zeros((n, n))
        dense[p.rows, p.cols] = getattr(p, name)
        np.testing.assert_array_equal(getattr(asm, name).toarray(), dense)
        assert getattr(asm, name).nnz == np.count_nonzero(getattr(p, name))
        if not tied:
            full = getattr(asm, name + "_full").toarray()
            np.testing.assert_array_equal(full[np.ix_(asm.full_of_free, asm.full_of_free)], dense)
    used = (p.K != 0) | (p.M != 0) | (p.C != 0)
    assert np.all(used)


def test_component_labels_match_scipy():
    """The union-find labels give scipy's connected components (same partition), and the label
    of a dof is the smallest dof of its component."""
    rng = np.random.default_rng(5)
    for n in (1, 7, 40):
        a = sp.random(n, n, density=min(1.0, 2.0 / n), random_state=rng, format="coo")
        a = a + a.T
        labels = component_labels(a, a, a)
        ref = connected_components(a, directed=False)[1]
        assert len(set(zip(labels, ref))) == len(set(ref)) == len(set(labels))
        for i in range(n):
            assert labels[i] == np.flatnonzero(labels == labels[i])[0]
    empty = component_labels_of_entries(np.zeros(0, np.int64), np.zeros(0, np.int64), 3)
    np.testing.assert_array_equal(empty, [0, 1, 2])


def test_csr_pattern_is_numpys_unique():
    """The compiled CSR pattern of repeated entries: numpy's unique keys, and each entry's slot."""
    rng = np.random.default_rng(11)
    for n in (1, 5, 40):
        rows, cols = rng.integers(0, n, 500), rng.integers(0, n, 500)
        rows[:100] = 0                       # a long row (sorted another way)
        indptr, indices, inverse = csr_pattern(rows, cols, n)
        unique, slot = np.unique(rows * n + cols, return_inverse=True)
        np.testing.assert_array_equal(indices, unique % n)
        np.testing.assert_array_equal(inverse, slot)
        np.testing.assert_array_equal(indptr, np.searchsorted(unique // n, np.arange(n + 1)))


def test_reverse_cuthill_mckee_recovers_a_band():
    """A scrambled chain with a few components: the order is a permutation that gives every
    component back its bandwidth 1 (scipy's algorithm, ties broken by a stable sort)."""
    rng = np.random.default_rng(3)
    n = 60
    i = np.array([k for k in range(n - 1) if k % 20 != 19])         # three chains of 20
    label = rng.permutation(n)
    r, c = np.r_[label[i], label[i + 1], label], np.r_[label[i + 1], label[i], label]
    a = sp.coo_matrix((np.ones(len(r)), (r, c)), shape=(n, n)).tocsr()
    a.sort_indices()
    order = reverse_cuthill_mckee(a.indptr.astype(np.int64), a.indices.astype(np.int64))
    np.testing.assert_array_equal(np.sort(order), np.arange(n))
    b = a[order][:, order].tocoo()
    assert np.max(np.abs(b.row - b.col)) == 1


def test_reverse_cuthill_mckee_bands_a_mesh_as_scipys():
    """Scrambled triangulated grids: the compiled order's bandwidth is scipy's within the
    difference its tie-breaking makes (measured: 7/7, 8/7, 4/5, the same order on the first)."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee as scipy_rcm

    rng = np.random.default_rng(5)
    for nx, ny in ((6, 9), (12, 7), (30, 4)):
        n = nx * ny
        idx = np.arange(n).reshape(nx, ny)
        edges = np.array([(idx[i, j], idx[i + 1, j]) for i in range(nx - 1) for j in range(ny)]
                         + [(idx[i, j], idx[i, j + 1]) for i in range(nx) for j in range(ny - 1)]
                         + [(idx[i, j], idx[i + 1, j + 1]) for i in range(nx - 1) for j in range(ny - 1)])
        label = rng.permutation(n)
        r = np.r_[label[edges[:, 0]], label[edges[:, 1]], label]
        c = np.r_[label[edges[:, 1]], label[edges[:, 0]], label]
        a = sp.coo_matrix((np.ones(len(r)), (r, c)), shape=(n, n)).tocsr()
        a.sort_indices()

        def bandwidth(order):
            b = a[order][:, order].tocoo()
            return int(np.max(np.abs(b.row - b.col)))

        ours = reverse_cuthill_mckee(a.indptr.astype(np.int64), a.indices.astype(np.int64))
        np.testing.assert_array_equal(np.sort(ours), np.arange(n))
        assert bandwidth(ours) <= 1.25 * bandwidth(scipy_rcm(a, symmetric_mode=True))


def test_an_element_on_a_node_the_model_lost_is_named():
    """Elements refuse node removal (remove_node); a node table changed behind the model's back
    is found at assembly and named, not read from a neighbouring node."""
    m = frame(False)
    del m.nodes[7]
    m._changed()
    with pytest.raises(vtsi.ModelError, match=r"^element 5 \(elasticBeamColumn\): node 7 does not exist$"):
        m.build()


def test_an_element_whose_matrix_overflows_is_named():
    """Finite parameters whose products overflow (E A / L = inf) are named at build, with the
    element and its parameters; no NaN reaches a solver or an eigenvalue problem."""
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 10.0, 0.0)
    m.fix(1, 1, 1, 1)
    m.element("elasticBeamColumn", 3, (1, 2), E=1e300, A=1e300, I=1.0)
    with pytest.raises(vtsi.ModelError, match=r"^element type elasticBeamColumn \(element 3\): stiffness has a "
                                              r"non-finite entry inf at row 0, column 0 \(its parameters "
                                              r"\{'A': 1e\+300, 'E': 1e\+300"):
        m.build()


def test_a_tag_beyond_opensees_int_is_named():
    """Tags are OpenSees's C ints: a larger one is refused when given, not an OverflowError at build."""
    m = vtsi.Model()
    with pytest.raises(vtsi.ModelError, match=r"^node tag must be an integer from -2147483648 to 2147483647 "
                                              r"\(OpenSees's int\), got 1180591620717411303424$"):
        m.node(2 ** 70, 0.0, 0.0)
    assert not m.nodes


def test_removing_a_pattern_frees_its_prescribed_dofs():
    """An sp constrains its dof; removing its pattern must free the dof again (the cached
    numbering is rebuilt), as remove_sp does."""
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 10.0, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(2, 0, 1, 0)
    m.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=3e10, I=2.0)
    m.add_time_series(vtsi.Linear(tag=1))
    m.pattern(1, 1)
    m.sp(1, 1, 3, 0.01)
    assert m.build().prescribed_full.tolist() == [2]
    m.remove_pattern(1)
    assert m.build().prescribed_full.tolist() == []


@pytest.mark.parametrize("flag", [True, np.True_])
def test_a_bool_is_not_taken_for_a_number(flag):
    """dt=True is a slip, not 1 s: refused by the transient analysis (made and set_dt, which keeps
    the step it had), the sweep settings, the modal bridge's f_max and the EN 1991-2 rules, each
    naming the value (every positive number goes through vtsi.errors.as_positive)."""
    from vtsi.codes.en1991_2 import damping_lower_bound
    from vtsi.passage import PassageSettings
    true = r"got (np\.)?True_?$"
    with pytest.raises(vtsi.AnalysisError, match=r"^transient analysis: dt must be a number, " + true):
        vtsi.TransientAnalysis(frame(False), "Newmark", flag)
    analysis = vtsi.TransientAnalysis(frame(False), "Newmark", 1e-3)
    with pytest.raises(vtsi.AnalysisError, match=r"dt must be a number, " + true):
        analysis.set_dt(flag)
    assert analysis.dt == 1e-3
    with pytest.raises(vtsi.AnalysisError, match=r"divergence_limit \(inf: no bound\) must be a number, " + true):
        vtsi.TransientAnalysis(frame(False), "Newmark", 1e-3, divergence_limit=flag)
    with pytest.raises(vtsi.ModelError, match=r"^sweep settings: dt must be a number, " + true):
        PassageSettings(dt=flag)
    with pytest.raises(vtsi.ModelError, match=r"^EN 1991-2 Table 6.6: span \[m\] must be a number, " + true):
        damping_lower_bound("steel", flag)