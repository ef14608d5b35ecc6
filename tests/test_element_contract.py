"""Every registered element type obeys the contract of :mod:`vtsi.elements.base`.

The tests are parametrised over ``vtsi.elements.ELEMENT_TYPES``; each of vtsi's own types
(defined in ``vtsi.elements``) needs a sample in ``SAMPLES`` below, and one without fails (a new
type cannot skip the contract). A type registered from outside vtsi is checked when it has a
sample here and skipped otherwise, so a user's registration does not break vtsi's tests: the
user-defined type of ``examples/custom_element.py`` is registered (tests/conftest.py) and has a
sample, so the contract holds for types added outside the core. What a build checks of every
type's matrices (shapes, symmetry, definiteness) is tested in tests/test_user_elements.py.
"""
import numpy as np
import pytest
from vtsi.elements import ELEMENT_TYPES, ElementType, register

import vtsi
from vtsi.errors import ModelError

# Two nodes in a general orientation (neither horizontal nor vertical, not through the origin).
P1, P2 = (0.3, -0.2), (2.1, 1.4)
LINE = [(P1, P2), ((4.0, 1.0), (3.2, -1.5)), ((-1.0, 2.0), (-1.0, 5.0))]
BEAM = dict(A=0.02, E=2.1e11, I=3e-4, rho=150.0)

# name -> list of (node coordinates, parameters); each type's samples are batched together.
SAMPLES = {
    "elasticBeamColumn": [(LINE[0], dict(BEAM, cmass=0)), (LINE[1], dict(BEAM, cmass=1)),
                          (LINE[2], dict(BEAM, rho=0.0))],
    "truss": [(LINE[0], dict(A=1e-3, E=2e11, rho=8.0, cmass=0)), (LINE[1], dict(A=2e-3, E=7e10, rho=5.0, cmass=1)),
              (LINE[2], dict(A=1e-3, E=2e11, do_rayleigh=1))],
    "zeroLength": [((P1, P1), dict(kx=1e6, ky=2e5, krz=3e4, cx=10.0, cy=20.0, crz=5.0, angle=0.4)),
                   ((P2, P2), dict(ky=5e5, angle=-2.0, do_rayleigh=1)),
                   (((0.0, 0.0), (0.0, 0.0)), dict(cx=3.0))],
    "pointMass": [((P1,), dict(m=120.0, J=7.0)), ((P2,), dict(m=3.0))],
    "ElasticTimoshenkoBeam": [(LINE[0], dict(A=0.02, E=2.1e11, G=8e10, I=3e-4, Avy=0.016, rho=150.0, cmass=0)),
                              (LINE[1], dict(A=0.5, E=3e10, G=1.2e10, I=0.1, Avy=0.42, rho=1200.0, cmass=1)),
                              (LINE[2], dict(A=0.3, E=3e10, G=1.2e10, I=0.02, Avy=0.25))],
    "timoshenkoBeam": [(LINE[0], dict(A=0.02, E=2.1e11, I=3e-4, G=8e10, kappa=5 / 6, rho=150.0)),
                       (LINE[1], dict(A=0.5, E=3e10, I=0.1, G=1.2e10, kappa=0.85, rho=1200.0))],
}


def translational_mass(name, coords, params):
    """Expected total mass [kg] an element carries on each of x and y."""
    if name == "pointMass":
        return params["m"]
    length = np.hypot(*np.subtract(coords[1], coords[0])) if len(coords) == 2 else 0.0
    return params.get("rho", 0.0) * length


def shipped(name):
    """Whether element type ``name`` is one of vtsi's own (defined in ``vtsi.elements``)."""
    return ELEMENT_TYPES[name].__module__.startswith("vtsi.elements.")


def samples(name):
    """``SAMPLES[name]``; a type from outside vtsi without a sample is skipped, one of vtsi's own
    fails."""
    if name not in SAMPLES:
        if not shipped(name):
            pytest.skip(f"element type {name!r} is registered from outside vtsi and has no sample here")
        pytest.fail(f"element type {name!r} is registered but has no sample in tests/test_element_contract.py "
                    "SAMPLES: add one so that it is checked against the contract")
    return SAMPLES[name]


def batch(name):
    """``(etype, coords (n, nen, 2), params (n, n_par), samples)`` of a type's samples
    (:func:`samples`)."""
    samples(name)
    etype = ELEMENT_TYPES[name]()
    for tag, (coords, params) in enumerate(SAMPLES[name], start=1):
        etype.add(tag, tuple(range(10 * tag, 10 * tag + len(coords))), **params)
    coords = np.array([c for c, _ in SAMPLES[name]], dtype=np.float64)
    return etype, coords, etype.params, SAMPLES[name]


def rigid_body_modes(etype, coords):
    """``(n_el, ndof, 3)``: translations x, y and a small rotation about the point (0.7, -1.3)."""
    n_el = coords.shape[0]
    full = np.zeros((n_el, etype.n_nodes, 3, 3))
    full[:, :, 0, 0] = 1.0
    full[:, :, 1, 1] = 1.0
    full[:, :, 0, 2] = -(coords[:, :, 1] + 1.3)
    full[:, :, 1, 2] = coords[:, :, 0] - 0.7
    full[:, :, 2, 2] = 1.0
    return full[:, :, list(etype.node_dofs), :].reshape(n_el, etype.ndof, 3)


TYPES = sorted(ELEMENT_TYPES)


def test_every_vtsi_type_has_a_sample():
    """vtsi's own types all have a sample (a user's registered type need not: it is skipped)."""
    missing = sorted(name for name in set(ELEMENT_TYPES) - set(SAMPLES) if shipped(name))
    assert not missing, f"vtsi element types without a contract sample: {missing}"
    assert shipped("elasticBeamColumn") and not shipped("timoshenkoBeam")


def test_a_user_type_without_a_sample_does_not_fail_the_contract_tests():
    """Registering a type of one's own (no sample here) skips it instead of failing vtsi's tests."""
    cls = register(_bare_type(name="contractUserType"))
    try:
        assert not shipped("contractUserType")
        test_every_vtsi_type_has_a_sample()
        for check in (batch, samples):
            with pytest.raises(pytest.skip.Exception, match="registered from outside vtsi"):
                check("contractUserType")
    finally:
        ELEMENT_TYPES.pop(cls.name, None)


@pytest.mark.parametrize("name", TYPES)
def test_class_attributes(name):
    cls = ELEMENT_TYPES[name]
    assert issubclass(cls, ElementType) and cls.name == name
    assert isinstance(cls.n_nodes, int) and cls.n_nodes >= 1
    assert len(set(cls.node_dofs)) == len(cls.node_dofs) and set(cls.node_dofs) <= {0, 1, 2}
    assert len(set(cls.param_names)) == len(cls.param_names)
    assert {"force", "globalForce"} <= set(cls.response_kinds)
    assert cls().ndof == cls.n_nodes * len(cls.node_dofs)
    assert vtsi.elements.element_type(name) is cls


@pytest.mark.parametrize("name", TYPES)
def test_matrices_shape_dtype_symmetry(name):
    etype, coords, params, _ = batch(name)
    n = len(params)
    for what in ("stiffness", "mass", "damping"):
        mat = getattr(etype, what)(coords, params)
        assert mat.shape == (n, etype.ndof, etype.ndof) and mat.dtype == np.float64, what
        assert np.all(np.isfinite(mat)), what
        scale = np.abs(mat).max(axis=(1, 2), keepdims=True) + 1e-300
        np.testing.assert_allclose(mat / scale, np.swapaxes(mat, 1, 2) / scale, atol=1e-13, err_msg=what)


@pytest.mark.parametrize("name", TYPES)
def test_matrices_positive_semidefinite(name):
    etype, coords, params, _ = batch(name)
    for what in ("stiffness", "mass", "damping"):
        mat = getattr(etype, what)(coords, params)
        for e in range(len(params)):
            eig = np.linalg.eigvalsh(mat[e])
            assert eig.min() >= -1e-12 * max(np.abs(eig).max(), 1e-300), (what, e, eig)


@pytest.mark.parametrize("name", TYPES)
def test_batch_equals_one_element_at_a_time(name):
    """Each element's matrices depend on its own row only (kernels write their own slot)."""
    etype, coords, params, _ = batch(name)
    for what in ("stiffness", "mass", "damping"):
        whole = getattr(etype, what)(coords, params)
        for e in range(len(params)):
            np.testing.assert_allclose(whole[e], getattr(etype, what)(coords[e:e + 1], params[e:e + 1])[0],
                                       rtol=1e-14, atol=0.0, err_msg=what)


@pytest.mark.parametrize("name", TYPES)
def test_rigid_body_modes_in_null_space_of_K_and_C(name):
    """Translations and a rotation about an arbitrary point cause no force (zero-length
    elements: their nodes coincide, so the rotation is rigid for them too)."""
    etype, coords, params, _ = batch(name)
    modes = rigid_body_modes(etype, coords)
    for what in ("stiffness", "damping"):
        mat = getattr(etype, what)(coords, params)
        force = np.einsum("eij,ejm->eim", mat, modes)
        scale = np.abs(mat).max(axis=(1, 2)) * np.abs(modes).max(axis=(1, 2))
        assert np.all(np.abs(force).max(axis=(1, 2)) <= 1e-12 * scale), what


@pytest.mark.parametrize("name", TYPES)
def test_total_translational_mass(name):
    """A unit rigid translation carries the element's whole mass (ρL for line elements),
    with lumped and consistent mass alike, and no x-y coupling."""
    etype, coords, params, samples = batch(name)
    modes = rigid_body_modes(etype, coords)
    mass = etype.mass(coords, params)
    for e, (xy, p) in enumerate(samples):
        expected = translational_mass(name, xy, p)
        tx, ty = modes[e, :, 0], modes[e, :, 1]
        assert tx @ mass[e] @ tx == pytest.approx(expected, rel=1e-13, abs=1e-12)
        assert ty @ mass[e] @ ty == pytest.approx(expected, rel=1e-13, abs=1e-12)
        assert tx @ mass[e] @ ty == pytest.approx(0.0, abs=1e-12 * max(expected, 1.0))


@pytest.mark.parametrize("name", TYPES)
def test_responses(name):
    """Every declared response kind has one finite row per element; ``force`` is K u + C v;
    an unknown kind is refused with the valid names."""
    etype, coords, params, _ = batch(name)
    rng = np.random.default_rng(7)
    u, v = rng.normal(size=(2, len(params), etype.ndof))
    for kind in etype.response_kinds:
        out = etype.response(kind, coords, params, u, v)
        assert out.ndim == 2 and out.shape[0] == len(params) and np.all(np.isfinite(out)), kind
    expected = (np.einsum("eij,ej->ei", etype.stiffness(coords, params), u)
                + np.einsum("eij,ej->ei", etype.damping(coords, params), v))
    for kind in ("force", "globalForce"):
        np.testing.assert_allclose(etype.response(kind, coords, params, u, v), expected, rtol=1e-12, atol=1e-9)
    with pytest.raises(ModelError, match="unknown response 'nonsense'.*valid: force"):
        etype.response("nonsense", coords, params, u, v)


@pytest.mark.parametrize("name", TYPES)
def test_end_force_kinds_are_the_end_force_response_of_K_u_plus_C_v(name):
    """Contract item 4: a kind that ``end_force_response`` takes equals it applied to the global
    end forces ``K u + C v`` (the element recorder computes those kinds so, from the matrices of
    the build)."""
    etype, coords, params, _ = batch(name)
    rng = np.random.default_rng(11)
    u, v = rng.normal(size=(2, len(params), etype.ndof))
    force = (np.einsum("eij,ej->ei", etype.stiffness(coords, params), u)
             + np.einsum("eij,ej->ei", etype.damping(coords, params), v))
    for kind in etype.response_kinds:
        try:
            derived = etype.end_force_response(kind, coords, force)
        except ModelError:
            continue                        # not derived from the end forces: recorded through response()
        np.testing.assert_allclose(etype.response(kind, coords, params, u, v), derived, rtol=1e-12,
                                   atol=1e-12 * np.abs(force).max(), err_msg=kind)


@pytest.mark.parametrize("name", TYPES)
def test_parameters_are_validated(name):
    """Positive, non-negative and 0/1 parameters, NaN, unknown names and the node count are
    checked on ``add``, with the element tag, type and value in the message."""
    cls = ELEMENT_TYPES[name]
    coords, params = samples(name)[0]
    nodes = tuple(range(1, cls.n_nodes + 1))
    for pname in cls.param_names:
        bad_values = [float("nan"), float("inf")]
        bad_values += [0.0, -1.0] if pname in cls.positive else [-1.0] if pname in cls.non_negative else []
        bad_values += [0.5, 2.0] if pname in cls.flags else []
        for bad in bad_values:
            with pytest.raises(ModelError, match=rf"element 42 \({name}\): {pname} must be .*got {bad:g}"):
                cls().add(42, nodes, **dict(params, **{pname: bad}))
    with pytest.raises(ModelError, match=rf"element 42 \({name}\): unknown parameter\(s\) \['bogus'\]; valid: "):
        cls().add(42, nodes, **dict(params, bogus=1.0))
    with pytest.raises(ModelError, match=rf"element 42 \({name}\): needs {cls.n_nodes} nodes, got {cls.n_nodes + 1}"):
        cls().add(42, nodes + (99,), **params)
    for pname in set(cls.param_names) - set(cls.defaults):
        with pytest.raises(ModelError, match=rf"element 42 \({name}\): parameter '{pname}' is required"):
            cls().add(42, nodes, **{k: v for k, v in params.items() if k != pname})


@pytest.mark.parametrize("name", TYPES)
def test_assembles_in_a_model(name):
    """The sample elements assemble into a model: the global matrices hold their traces."""
    etype, coords, params, samples = batch(name)
    m = vtsi.Model()
    node_of = {}
    for tag, (xy, p) in enumerate(samples, start=1):
        nodes = []
        for point in xy:
            node = len(node_of) + 1
            node_of[node] = point
            m.node(node, *point)
            nodes.append(node)
        m.element(name, tag, tuple(nodes), **p)
    asm = m.build()
    for what, full in (("stiffness", asm.K_full), ("mass", asm.M_full)):
        assert full.diagonal().sum() == pytest.approx(np.trace(getattr(etype, what)(coords, params), axis1=1, axis2=2).sum(),
                                                      rel=1e-12)


# -- the registry itself ------------------------------------------------------------------

def _bare_type(**attributes):
    body = dict(name="contractProbe", param_names=("a",), stiffness=lambda self, c, p: None,
                mass=lambda self, c, p: None)
    body.update(attributes)
    return type("Probe", (ElementType,), body)


@pytest.mark.parametrize("attributes, message", [
    (dict(name=None), "name must be a non-empty str"),
    (dict(positive=("b",)), r"\['b'\] are not in param_names"),
    (dict(flags=("c",)), r"\['c'\] are not in param_names"),
    (dict(node_dofs=(0, 3)), r"node_dofs \(0, 3\) must be among 0, 1, 2"),
    (dict(param_names="kw"), r"param_names must be a tuple of str, got 'kw'"),
    (dict(positive="a"), r"positive must be a tuple of str, got 'a'"),
    (dict(stiffness=ElementType.stiffness), r"must override stiffness\(\)"),
    (dict(mass=ElementType.mass), r"must override mass\(\)"),
    (dict(name="elasticBeamColumn"), "'elasticBeamColumn' is already registered by vtsi.elements.beam_column"),
])
def test_register_rejects_a_broken_type(attributes, message):
    before = dict(ELEMENT_TYPES)
    with pytest.raises(TypeError, match=message):
        register(_bare_type(**attributes))
    assert ELEMENT_TYPES == before


def test_register_accepts_a_redefinition_of_the_same_class():
    """Running a script (or notebook cell) twice defines its element class again."""
    def define():
        class Redefined(ElementType):
            name = "contractRedefined"
            stiffness = mass = lambda self, c, p: None
        return Redefined

    try:
        first, second = register(define()), register(define())
        assert first is not second and ELEMENT_TYPES["contractRedefined"] is second
    finally:
        ELEMENT_TYPES.pop("contractRedefined", None)
