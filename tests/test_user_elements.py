"""User element types meet the build's checks of what their kernels return, and their kernels run
once per build.

A user's kernel can return anything; the build (:func:`vtsi.elements.base.element_matrices`)
refuses, with the element type, the element and what was expected, a matrix of the wrong shape
(which read and wrote past the CSR arrays: SIGSEGV, or a spring silently missing), a list or a
complex array (numba TypingError, AttributeError), a NaN (blamed on the parameters), a
non-symmetric matrix (one triangle used silently), a negative diagonal entry or a mass or damping
matrix that is not positive semi-definite (a negative mass ran), and ``rayleigh_weights`` of the
wrong length (a zero-length array read garbage memory). The element recorder computes element
forces from the matrices of the build (the stiffness kernel ran at every step for every element:
44 to 540 times slower runs).

Each type is registered for one test and removed after it, so the registry (and the contract
tests parametrised over it) is left as it was.
"""
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from vtsi.elements import ELEMENT_TYPES, ElementType, register
from vtsi.elements.base import MATRIX_RTOL, element_rayleigh_weights
from vtsi.elements.kernels import matrix_defects, semidefinite_defects

import vtsi
import vtsi.opensees as ops
from vtsi.errors import ModelError
from vtsi.recorders import ElementRecorder, NodeRecorder

N_EL = 10
FIRST_TAG = 3


def spring_matrices(k):
    """``(n_el, 2, 2)`` stiffness of vertical springs ``k (n_el,)`` [N/m] between two uy dofs."""
    out = np.zeros((len(k), 2, 2))
    out[:, 0, 0] = out[:, 1, 1] = k
    out[:, 0, 1] = out[:, 1, 0] = -k
    return out


@pytest.fixture
def user_type():
    """``user_type(name, stiffness=..., mass=..., damping=..., rayleigh_weights=...)``: registers a
    2-node type on uy (``ndof`` 2, parameter ``k``) whose kernels are the given functions of
    ``params`` (default: a spring, no mass, no damping); removed from the registry afterwards."""
    names = []

    def make(name, stiffness=None, mass=None, damping=None, rayleigh_weights=None):
        body = dict(name=name, n_nodes=2, node_dofs=(1,), param_names=("k",), positive=("k",),
                    stiffness=lambda self, c, p: (stiffness or (lambda q: spring_matrices(q[:, 0])))(p),
                    mass=lambda self, c, p: (mass or (lambda q: np.zeros((len(q), 2, 2))))(p),
                    check_geometry=lambda self, *args: None)
        if damping is not None:
            body["damping"] = lambda self, c, p: damping(p)
        if rayleigh_weights is not None:
            body["rayleigh_weights"] = lambda self, p: rayleigh_weights(p)
        names.append(name)
        return register(type(name, (ElementType,), body))

    yield make
    for name in names:
        ELEMENT_TYPES.pop(name, None)


def spring_diagonal(asm, name):
    """The diagonal of ``asm``'s free matrix ``name`` ('K', 'M', 'C') at the springs' uy dofs,
    spring by spring (the free dofs are in solver order)."""
    free = asm.free_of_full[[asm.full_dof(2 * e + 2, 2) for e in range(N_EL)]]
    return getattr(asm, name).diagonal()[free]


def springs_model(name, n_el=N_EL, k=4e6, mass=1000.0):
    """``n_el`` springs of type ``name`` (tags from FIRST_TAG) from fixed nodes to nodes that
    move in y only, each with a nodal mass."""
    m = vtsi.Model()
    for e in range(n_el):
        m.node(2 * e + 1, float(e), 0.0)
        m.node(2 * e + 2, float(e), 1.0)
        m.fix(2 * e + 1, 1, 1, 1)
        m.fix(2 * e + 2, 1, 0, 1)
        m.mass(2 * e + 2, mass, mass, 0.0)
        m.element(name, FIRST_TAG + e, (2 * e + 1, 2 * e + 2), k=k * (1 + 0.1 * e))
    return m


# -- 1. shape, dtype, finiteness ------------------------------------------------------------

@pytest.mark.parametrize("what", ["stiffness", "mass", "damping"])
@pytest.mark.parametrize("wrong, got", [
    (lambda p: np.full((len(p), 1, 1), 4e6), r"\(10, 1, 1\) float64"),      # too small: the spring went missing
    (lambda p: spring_matrices(p[:, 0])[0], r"\(2, 2\) float64"),          # no batch axis: numba TypingError
    (lambda p: np.zeros((len(p), 2, 2, 1)), r"\(10, 2, 2, 1\) float64"),
], ids=["1x1", "no-batch-axis", "4-d"])
def test_a_matrix_of_the_wrong_shape_is_refused(user_type, what, wrong, got):
    user_type("userWrongShape", **{what: wrong})
    with pytest.raises(ModelError, match=rf"^element type userWrongShape \(element 3\): {what} must be "
                                         rf"\(n_el, 2, 2\) = \(10, 2, 2\) float64, got {got}$"):
        springs_model("userWrongShape").build()


def test_the_shapes_that_crashed_python_are_refused():
    """(n_el, 3, 3), (n_el, 4, 4), (n_el, 8, 8) and 2·n_el rows for a 2-dof element read and wrote
    past the CSR arrays inside ``scatter_add`` (SIGSEGV): each is now a ModelError. Run in a
    child process so that a regression kills it, not the test session."""
    script = textwrap.dedent("""
        import numpy as np, vtsi
        from vtsi.elements import ElementType, register
        from vtsi.errors import ModelError
        def spring(p):
            out = np.zeros((len(p), 2, 2)); out[:, 0, 0] = out[:, 1, 1] = p[:, 0]
            out[:, 0, 1] = out[:, 1, 0] = -p[:, 0]; return out
        cases = {"big3": lambda p: np.tile(np.eye(3), (len(p), 1, 1)) * 1e6,
                 "big4": lambda p: np.tile(np.eye(4), (len(p), 1, 1)) * 1e6,
                 "big8": lambda p: np.tile(np.eye(8), (len(p), 1, 1)) * 1e6,
                 "rows2": lambda p: np.repeat(spring(p), 2, axis=0)}
        for label, kernel in cases.items():
            register(type(label, (ElementType,), dict(
                name=label, node_dofs=(1,), param_names=("k",), check_geometry=lambda self, *a: None,
                stiffness=lambda self, c, p, kernel=kernel: kernel(p),
                mass=lambda self, c, p: np.zeros((len(p), 2, 2)))))
            m = vtsi.Model()
            for e in range(10):
                m.node(2 * e + 1, float(e), 0.0); m.node(2 * e + 2, float(e), 1.0)
                m.fix(2 * e + 1, 1, 1, 1); m.fix(2 * e + 2, 1, 0, 1); m.mass(2 * e + 2, 1.0, 1.0, 0.0)
                m.element(label, 3 + e, (2 * e + 1, 2 * e + 2), k=1e6)
            try:
                m.build()
                print(label, "built")
            except ModelError as exc:
                print(label, exc)
    """)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"child died with {run.returncode}: {run.stderr[-2000:]}"
    lines = dict(line.split(" ", 1) for line in run.stdout.splitlines())
    for label, got in (("big3", "(10, 3, 3)"), ("big4", "(10, 4, 4)"), ("big8", "(10, 8, 8)"),
                       ("rows2", "(20, 2, 2)")):
        assert lines[label] == (f"element type {label} (element 3): stiffness must be (n_el, 2, 2) = (10, 2, 2) "
                                f"float64, got {got} float64")


@pytest.mark.parametrize("wrong, got", [
    (lambda p: spring_matrices(p[:, 0]).tolist(), r"\(a numpy array\), got list"),
    (lambda p: 4e6, r"\(a numpy array\), got float"),
    (lambda p: spring_matrices(p[:, 0]).astype(complex), r"\(real numbers\), got \(10, 2, 2\) complex128"),
    (lambda p: spring_matrices(p[:, 0]) != 0, r"\(real numbers\), got \(10, 2, 2\) bool"),
    (lambda p: spring_matrices(p[:, 0]).astype(object), r"\(real numbers\), got \(10, 2, 2\) object"),
], ids=["list", "scalar", "complex", "bool", "object"])
def test_a_list_a_scalar_or_a_complex_array_is_refused(user_type, wrong, got):
    """No numba TypingError, no AttributeError: the same ModelError as a wrong shape."""
    user_type("userWrongType", stiffness=wrong)
    with pytest.raises(ModelError, match=rf"^element type userWrongType \(element 3\): stiffness must be "
                                         rf"\(n_el, 2, 2\) = \(10, 2, 2\) float64 {got}$"):
        springs_model("userWrongType").build()


@pytest.mark.parametrize("convert", [
    lambda a: a.astype(np.float32), lambda a: a.astype(np.int64), np.asfortranarray,
    lambda a: np.zeros((a.shape[0], 4, 4))[:, ::2, ::2] + a,
], ids=["float32", "int64", "fortran", "strided"])
def test_real_arrays_of_other_dtypes_or_layouts_are_converted(user_type, convert):
    """float32 and integers are converted to float64 (exactly, for these values); any memory
    layout is taken."""
    user_type("userConverted", stiffness=lambda p: convert(spring_matrices(p[:, 0])))
    asm = springs_model("userConverted").build()
    assert asm.element_matrices[0].stiffness.dtype == np.float64
    np.testing.assert_allclose(spring_diagonal(asm, "K"), 4e6 * (1 + 0.1 * np.arange(N_EL)), rtol=1e-7)
    assert asm.K.nnz == N_EL


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("what", ["stiffness", "mass", "damping"])
def test_a_non_finite_entry_names_the_element_and_not_an_overflow(user_type, what, bad):
    def kernel(p):
        out = spring_matrices(p[:, 0]) if what != "mass" else np.tile(np.eye(2), (len(p), 1, 1))
        out[4, 1, 0] = bad                       # element 7 (the fifth)
        return out

    user_type("userNonFinite", **{what: kernel})
    with pytest.raises(ModelError, match=rf"^element type userNonFinite \(element 7\): {what} has a non-finite "
                                         rf"entry {bad} at row 1, column 0 \(its parameters \{{'k': 5600000.0\}}\): "
                                         "the element's kernel returned it"):
        springs_model("userNonFinite").build()


# -- 2. symmetry ----------------------------------------------------------------------------

@pytest.mark.parametrize("what", ["stiffness", "mass", "damping"])
def test_a_non_symmetric_matrix_is_refused_with_its_asymmetry(user_type, what):
    """Before: K = [[k, −k], [−1.5k, k]] was assembled with one triangle, silently (a static
    deflection 17 % off). The message gives max |A − Aᵀ| and its ratio to max |A|."""
    def kernel(p):
        out = spring_matrices(p[:, 0])
        out[2, 1, 0] -= 0.5 * p[2, 0]
        return out

    user_type("userAsymmetric", **{what: kernel})
    with pytest.raises(ModelError, match=rf"^element type userAsymmetric \(element 5\): {what} is not symmetric: "
                                         r"max \|A - Aᵀ\| = 2\.4e\+06 is 0\.333 of max \|A\| = 7\.2e\+06 "
                                         r"\(tolerance 1e-09\)"):
        springs_model("userAsymmetric").build()


def test_rounding_level_asymmetry_is_accepted(user_type):
    """An asymmetry of a few ulps (a kernel that rotates or inverts) is below MATRIX_RTOL; one
    of 1e-6 of the largest entry is a mistake."""
    def kernel(relative):
        def stiffness(p):
            out = spring_matrices(p[:, 0])
            out[:, 1, 0] *= 1 + relative
            return out
        return stiffness

    user_type("userRoundoff", stiffness=kernel(1e-13))
    springs_model("userRoundoff").build()
    user_type("userSkewed", stiffness=kernel(1e-6))
    with pytest.raises(ModelError, match="not symmetric"):
        springs_model("userSkewed").build()
    assert 1e-13 < MATRIX_RTOL < 1e-6


# -- 3. signs and definiteness --------------------------------------------------------------

@pytest.mark.parametrize("what", ["stiffness", "mass", "damping"])
def test_a_negative_diagonal_entry_is_refused(user_type, what):
    """A negative mass ran before (Newmark and CentralDifference gave a response); a negative
    damping fed energy in; a negative diagonal stiffness pushes its own dof away."""
    user_type("userNegative", **{what: lambda p: -spring_matrices(p[:, 0])})
    with pytest.raises(ModelError, match=rf"^element type userNegative \(element 3\): {what} has a negative "
                                         r"diagonal entry -4e\+06 \(row 0, uy of node 1\)"):
        springs_model("userNegative").build()


@pytest.mark.parametrize("what", ["mass", "damping"])
def test_an_indefinite_mass_or_damping_with_a_positive_diagonal_is_refused(user_type, what):
    """[[1, 2], [2, 1]]: diagonal positive, eigenvalues −1 and 3."""
    user_type("userIndefinite", **{what: lambda p: np.tile([[1.0, 2.0], [2.0, 1.0]], (len(p), 1, 1))})
    with pytest.raises(ModelError, match=rf"^element type userIndefinite \(element 3\): {what} is not positive "
                                         r"semi-definite: eigenvalues -1 to 3"):
        springs_model("userIndefinite").build()


def test_semi_definite_matrices_and_negative_couplings_are_accepted(user_type):
    """A rigid-link mass [[m, m], [m, m]] (singular), a dashpot (negative off-diagonal) and a
    spring (negative off-diagonal stiffness) are all legitimate."""
    user_type("userLegit", mass=lambda p: np.tile([[5.0, 5.0], [5.0, 5.0]], (len(p), 1, 1)),
              damping=lambda p: spring_matrices(1e-3 * p[:, 0]))
    asm = springs_model("userLegit").build()
    assert spring_diagonal(asm, "M") == pytest.approx(1005.0 * np.ones(N_EL))
    assert spring_diagonal(asm, "C") == pytest.approx(4e3 * (1 + 0.1 * np.arange(N_EL)))


# -- 4. rayleigh_weights --------------------------------------------------------------------

@pytest.mark.parametrize("weights, got", [
    (lambda p: 0.0, "got float"),                                    # was a numba TypingError
    (lambda p: np.zeros(0), r"got \(0,\) float64"),                  # read garbage memory
    (lambda p: np.zeros(50), r"got \(50,\) float64"),
    (lambda p: np.zeros((len(p), 1)), r"got \(10, 1\) float64"),
    (lambda p: np.zeros(len(p), dtype=complex), r"got \(10,\) complex128"),
], ids=["scalar", "empty", "long", "2-d", "complex"])
def test_rayleigh_weights_of_the_wrong_shape_are_refused(user_type, weights, got):
    user_type("userWeights", rayleigh_weights=weights)
    m = springs_model("userWeights")
    m.rayleigh(0.0, 0.01)
    with pytest.raises(ModelError, match=rf"^element type userWeights \(element 3\): rayleigh_weights must be "
                                         rf"\(n_el,\) = \(10,\) float64 factors >= 0, one per element, {got}$"):
        m.build()


@pytest.mark.parametrize("bad", [np.nan, -1.0])
def test_rayleigh_weights_must_be_finite_and_not_negative(user_type, bad):
    user_type("userWeights", rayleigh_weights=lambda p: np.where(np.arange(len(p)) == 2, bad, 1.0))
    m = springs_model("userWeights")
    m.rayleigh(0.0, 0.01)
    with pytest.raises(ModelError, match=rf"^element type userWeights \(element 5\): rayleigh_weights must be "
                                         rf"finite and >= 0, got {bad}$"):
        m.build()


def test_rayleigh_weights_select_the_elements_in_the_rayleigh_terms(user_type):
    """A list is taken; weight 0 leaves an element out of βK (and αM), 1 keeps it."""
    user_type("userWeights", rayleigh_weights=lambda p: [float(i % 2) for i in range(len(p))],
              mass=lambda p: np.tile(np.eye(2), (len(p), 1, 1)))
    m = springs_model("userWeights")
    m.rayleigh(0.5, 0.01)
    c = spring_diagonal(m.build(), "C")
    k = 4e6 * (1 + 0.1 * np.arange(N_EL))
    odd = np.arange(N_EL) % 2
    np.testing.assert_allclose(c, 0.5 * (1000.0 + odd) + 0.01 * k * odd, rtol=1e-14)
    assert element_rayleigh_weights(ELEMENT_TYPES["elasticBeamColumn"](), np.zeros((3, 5)), [1, 2, 3]).tolist() \
        == [1.0, 1.0, 1.0]                                           # no rayleigh_weights: every element takes part


# -- 5. kernels once per build; the element recorder ----------------------------------------

def counting_type(user_type, calls, name="userCounted"):
    """A spring with a dashpot whose kernels count their calls and rows."""
    def count(what, kernel):
        def counted(p):
            calls[what] = calls.get(what, 0) + 1
            return kernel(p)
        return counted

    return user_type(name, stiffness=count("stiffness", lambda p: spring_matrices(p[:, 0])),
                     mass=count("mass", lambda p: np.zeros((len(p), 2, 2))),
                     damping=count("damping", lambda p: spring_matrices(1e-3 * p[:, 0])))


def test_the_kernels_run_once_per_build_and_the_element_recorder_reuses_their_matrices(user_type):
    """Before: the element recorder called the stiffness kernel at every chunk on every recorded
    element (p17: 204 calls in 200 steps); now once per build, whatever the recorders and steps."""
    calls = {}
    counting_type(user_type, calls)
    m = springs_model("userCounted")
    pattern = m.pattern(1, m.add_time_series(vtsi.Constant(tag=1)))
    for e in range(N_EL):
        pattern.load(2 * e + 2, 0.0, -1000.0 * (e + 1), 0.0)
    forces = ElementRecorder(list(range(FIRST_TAG, FIRST_TAG + N_EL)), "force")
    globals_ = ElementRecorder([FIRST_TAG + 4, FIRST_TAG], "globalForce")
    moving = list(range(2, 2 * N_EL + 1, 2))
    disp, vel = NodeRecorder(moving, [2]), NodeRecorder(moving, [2], "vel")
    analysis = vtsi.TransientAnalysis(m, "Newmark", 1e-3, recorders=[forces, globals_, disp, vel], chunk_steps=7)
    analysis.run(50)
    analysis.run(1)
    assert calls == {"stiffness": 1, "mass": 1, "damping": 1}
    k = 4e6 * (1 + 0.1 * np.arange(N_EL))
    u, v = disp.values, vel.values                            # node 2 of each spring; node 1 fixed
    expected = np.stack([-(k * u + 1e-3 * k * v), k * u + 1e-3 * k * v], axis=2).reshape(len(u), -1)
    np.testing.assert_allclose(forces.values, expected, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(globals_.values, expected[:, [8, 9, 0, 1]], rtol=1e-12, atol=1e-9)
    m.element("userCounted", 99, (1, 2), k=1.0)               # the model changed: one more build
    m.build()
    assert calls == {"stiffness": 2, "mass": 2, "damping": 2}


def test_element_queries_reuse_the_matrices_of_the_build(user_type):
    """``eleForce``/``eleResponse`` read K_e and C_e of the build: before, each query called the
    element kernels (a 200-element beam: 32 µs per ``eleResponse``, ~11 after)."""
    calls = {}
    counting_type(user_type, calls)
    session = ops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    m = session.domain
    for e in range(3):
        m.node(2 * e + 1, float(e), 0.0)
        m.node(2 * e + 2, float(e), 1.0)
        session.fix(2 * e + 1, 1, 1, 1)
        session.fix(2 * e + 2, 1, 0, 1)
        session.mass(2 * e + 2, 1000.0, 1000.0, 0.0)
        m.element("userCounted", FIRST_TAG + e, (2 * e + 1, 2 * e + 2), k=4e6 * (1 + e))
    session.timeSeries("Linear", 1)
    session.pattern("Plain", 1, 1)
    for node in (2, 4, 6):
        session.load(node, 0.0, -5e4 * node, 0.0)
    session.integrator("Newmark", 0.5, 0.25)
    session.analysis("Transient")
    for _ in range(5):
        session.analyze(1, 1e-3)
        for e in range(3):
            u, v = session.nodeDisp(2 * e + 2, 2), session.nodeVel(2 * e + 2, 2)
            f = 4e6 * (1 + e) * (u + 1e-3 * v)
            assert session.eleResponse(FIRST_TAG + e, "force") == pytest.approx([0.0, -f, 0.0, 0.0, f, 0.0], rel=1e-12,
                                                                          abs=1e-9)
            assert session.eleForce(FIRST_TAG + e, 5) == pytest.approx(f, rel=1e-12, abs=1e-9)
    assert calls == {"stiffness": 1, "mass": 1, "damping": 1}


@pytest.mark.parametrize("response", ["force", "localForce"])
def test_the_element_recorder_matches_the_element_response(response):
    """The recorder's batched K_e u_e (+ C_e v_e), and 'localForce' derived from it by
    ``end_force_response``, equal the element type's own ``response`` on the recorded state."""
    m = vtsi.Model()
    for i in range(5):
        m.node(i + 1, 2.0 * i, 0.3 * i)
    m.fix(1, 1, 1, 1)
    m.fix(5, 0, 1, 0)
    for i in range(4):
        m.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=0.1, E=2e11, I=1e-3, rho=500.0, cmass=i % 2)
    m.pattern(1, m.add_time_series(vtsi.Linear(tag=1))).load(3, 1e3, -5e4, 2e3)
    rec = ElementRecorder([3, 1], response)
    nodes = NodeRecorder([1, 2, 3, 4, 5], [1, 2, 3])
    vtsi.TransientAnalysis(m, "Newmark", 2e-3, recorders=[rec, nodes], chunk_steps=5).run(12)
    asm = m.build()
    etype, _, coords, params, dofs = asm.blocks[0]
    u = np.zeros((12, asm.n_full))
    u[:, [asm.full_dof(n, d) for n in range(1, 6) for d in (1, 2, 3)]] = nodes.values
    expected = np.concatenate([etype.response(response, coords[[e]].repeat(12, 0), params[[e]].repeat(12, 0),
                                              u[:, dofs[e]], np.zeros((12, 6))) for e in (2, 0)], axis=1)
    np.testing.assert_allclose(rec.values, expected, rtol=1e-10, atol=1e-6 * np.abs(expected).max())


# -- the check kernels against numpy --------------------------------------------------------

def test_matrix_defects_match_numpy():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(50, 5, 5))
    a[7, 2, 3] = np.nan
    a[9, 4, 0] = -np.inf
    nonfinite, scale, asymmetry, min_diagonal, min_at = matrix_defects(a)
    assert np.flatnonzero(nonfinite >= 0).tolist() == [7, 9] and nonfinite[[7, 9]].tolist() == [13, 20]
    ok = np.setdiff1d(np.arange(50), [7, 9])
    np.testing.assert_array_equal(scale[ok], np.abs(a[ok]).max(axis=(1, 2)))
    np.testing.assert_array_equal(asymmetry[ok], np.abs(a[ok] - a[ok].transpose(0, 2, 1)).max(axis=(1, 2)))
    diagonal = np.diagonal(a, axis1=1, axis2=2)
    np.testing.assert_array_equal(min_diagonal, diagonal.min(axis=1))
    np.testing.assert_array_equal(min_at, diagonal.argmin(axis=1))


@pytest.mark.parametrize("nd", [1, 2, 3, 6, 12])
def test_semidefinite_defects_match_the_eigenvalues(nd):
    """Semi-definite matrices of every rank pass (no false alarm from rounding); singular ones
    shifted by −1e-6 of their largest entry are all caught, as eigvalsh says."""
    rng = np.random.default_rng(nd)
    for rank in range(nd + 1):
        b = rng.normal(size=(200, nd, rank)) * rng.uniform(1e-3, 1e3, size=(200, 1, 1))
        psd = b @ b.transpose(0, 2, 1)
        perm = rng.permutation(nd)
        psd = np.ascontiguousarray(psd[:, perm][:, :, perm])
        assert not semidefinite_defects(psd, MATRIX_RTOL).any(), rank
        if 1 < nd and rank < nd:
            shifted = psd - 1e-6 * np.abs(psd).max(axis=(1, 2), keepdims=True) * np.eye(nd)
            shifted[:, 0, 1] += 1e-300                             # not diagonal: the kernel factors it
            shifted[:, 1, 0] += 1e-300
            assert np.linalg.eigvalsh(shifted).min(axis=1).max() < 0
            assert semidefinite_defects(shifted, MATRIX_RTOL).all(), rank
    if nd == 1:
        return                          # no off-diagonal entry: the sign of the diagonal is matrix_defects' check
    indefinite = rng.normal(size=(200, nd, nd))
    indefinite = indefinite + indefinite.transpose(0, 2, 1)
    eig = np.linalg.eigvalsh(indefinite)
    flagged = semidefinite_defects(indefinite, MATRIX_RTOL) > 0
    np.testing.assert_array_equal(flagged, eig.min(axis=1) < -MATRIX_RTOL * np.abs(indefinite).max(axis=(1, 2)))
