"""The shipped element types against closed-form solutions, and the errors of bad input."""
import logging

import numpy as np
import pytest

import vtsi
from vtsi.errors import ModelError


def static_solution(m):
    """Run one linear static step under the model's patterns; return the full-dof u."""
    vtsi.StaticAnalysis(m).run(1)
    return m.state.u


def constant_pattern(m):
    return m.pattern(1, m.add_time_series(vtsi.Constant(tag=1)))


def element_response(m, tag, kind):
    """Response ``kind`` of element ``tag`` at the model's committed state."""
    asm = m.build()
    ((etype, coords, params, u_e, v_e, _),) = asm.element_state([tag], m.state.u, m.state.v)
    return etype.response(kind, coords, params, u_e, v_e)[0]


# -- elasticBeamColumn ----------------------------------------------------------------------

@pytest.mark.parametrize("n_el", [1, 4])
@pytest.mark.parametrize("angle", [0.0, 0.7, np.pi / 2])
def test_cantilever_tip_deflection_and_rotation(n_el, angle):
    """Tip load P normal to a cantilever: δ = PL³/3EI, θ = PL²/2EI (Euler-Bernoulli, exact for
    cubic elements), in any orientation of the beam."""
    L, E, I, P = 6.0, 2.1e11, 8e-5, 12e3
    c, s = np.cos(angle), np.sin(angle)
    m = vtsi.Model()
    for i in range(n_el + 1):
        m.node(i + 1, 1.0 + c * L * i / n_el, -2.0 + s * L * i / n_el)
    m.fix(1, 1, 1, 1)
    for i in range(n_el):
        m.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=0.01, E=E, I=I)
    constant_pattern(m).load(n_el + 1, -s * P, c * P, 0.0)
    u = static_solution(m)
    asm = m.build()
    tip = [u[asm.full_dof(n_el + 1, d)] for d in (1, 2, 3)]
    assert -s * tip[0] + c * tip[1] == pytest.approx(P * L ** 3 / (3 * E * I), rel=1e-10)
    assert c * tip[0] + s * tip[1] == pytest.approx(0.0, abs=1e-12)
    assert tip[2] == pytest.approx(P * L ** 2 / (2 * E * I), rel=1e-10)
    # support end of the first element: N1 = 0, V1 = -P... in local axes, moment P L
    local = element_response(m, 1, "localForce")
    np.testing.assert_allclose(local[:3], [0.0, -P, -P * L], atol=1e-6 * P * L)


def simply_supported_beam(n_el, L, A, E, I, rho, cmass):
    m = vtsi.Model()
    for i in range(n_el + 1):
        m.node(i + 1, L * i / n_el, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(n_el + 1, 1, 1, 0)
    for i in range(n_el):
        m.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=A, E=E, I=I, rho=rho, cmass=cmass)
    return m


def test_simply_supported_beam_frequencies():
    """ω_n = (nπ/L)² √(EI/μ), n = 1..3 (Euler-Bernoulli; e.g. Clough & Penzien, Dynamics of
    Structures, §18-3). With 20 consistent-mass (cubic Hermite) elements the discretisation error
    is O(h⁴): 4e-7, 7e-6 and 3e-5 for n = 1..3, from above (Rayleigh-Ritz). A tolerance of
    0.1 % leaves room above that and still catches a wrong coefficient in K or M (any such
    error shifts the frequencies by far more than 0.1 %)."""
    L, A, E, I, mu = 30.0, 4.0, 3.5e10, 2.5, 2.0e4
    omega2, shapes = vtsi.eigen(simply_supported_beam(20, L, A, E, I, mu, cmass=1), 3)
    exact = (np.arange(1, 4) * np.pi / L) ** 2 * np.sqrt(E * I / mu)
    np.testing.assert_allclose(np.sqrt(omega2), exact, rtol=1e-3)
    assert np.all(np.sqrt(omega2) >= exact)      # consistent mass: upper bounds


def test_lumped_mass_beam_frequencies_converge():
    """Lumped mass (ρL/2 per node, no rotary inertia): the same limit, approached from below
    (3e-4 low with 4 elements, 2e-5 with 8)."""
    L, A, E, I, mu = 30.0, 4.0, 3.5e10, 2.5, 2.0e4
    exact = (np.pi / L) ** 2 * np.sqrt(E * I / mu)
    ratios = [np.sqrt(vtsi.eigen(simply_supported_beam(n, L, A, E, I, mu, cmass=0), 1)[0][0]) / exact
              for n in (4, 8)]
    assert 1 - 1e-3 < ratios[0] < ratios[1] < 1.0 and 1 - ratios[1] < 1e-4


# -- truss ----------------------------------------------------------------------------------

def test_truss_stiffness_inclined_is_EA_over_L_along_the_axis():
    A, E = 3e-3, 2e11
    etype = vtsi.elements.ELEMENT_TYPES["truss"]()
    etype.add(1, (1, 2), A=A, E=E)
    coords = np.array([[[0.5, 1.0], [3.5, 5.0]]])          # L = 5, direction (0.6, 0.8)
    k = etype.stiffness(coords, etype.params)[0]
    e = np.array([0.6, 0.8])
    block = E * A / 5.0 * np.outer(e, e)
    np.testing.assert_allclose(k, np.block([[block, -block], [-block, block]]), rtol=1e-14, atol=1e-3)


@pytest.mark.parametrize("ndf", [2, 3])
def test_two_bar_truss(ndf):
    """Two bars from supports (∓a, 0) to the apex (0, −h), load P downward at the apex:
    each bar carries N = P/(2 cos θ) in tension (θ from vertical), the apex moves
    δ = P L/(2 EA cos² θ) down."""
    a, h, A, E, P = 3.0, 4.0, 2e-3, 2e11, 5e4
    L, cos_t = 5.0, 0.8
    m = vtsi.Model(ndf=ndf)
    m.node(1, -a, 0.0)
    m.node(2, a, 0.0)
    m.node(3, 0.0, -h)
    free_rotation = (1,) if ndf == 3 else ()
    m.fix(1, 1, 1, *free_rotation)
    m.fix(2, 1, 1, *free_rotation)
    if ndf == 3:
        m.fix(3, 0, 0, 1)     # a truss gives no rotational stiffness
    m.element("truss", 1, (1, 3), A=A, E=E)
    m.element("truss", 2, (2, 3), A=A, E=E)
    constant_pattern(m).load(3, 0.0, -P, *([0.0] if ndf == 3 else []))
    u = static_solution(m)
    asm = m.build()
    assert u[asm.full_dof(3, 1)] == pytest.approx(0.0, abs=1e-15)
    assert u[asm.full_dof(3, 2)] == pytest.approx(-P * L / (2 * E * A * cos_t ** 2), rel=1e-12)
    N = P / (2 * cos_t)
    for tag in (1, 2):
        assert element_response(m, tag, "axialForce") == pytest.approx([N], rel=1e-12)
        assert element_response(m, tag, "basicForce") == pytest.approx([N], rel=1e-12)
        assert element_response(m, tag, "deformation") == pytest.approx([N * L / (E * A)], rel=1e-12)
        np.testing.assert_allclose(element_response(m, tag, "localForce"), [-N, 0, N, 0], rtol=1e-12, atol=1e-9)
    # resisting force K u at the apex: N along bar 1's axis (node 1 -> node 3); both bars
    # together balance the applied load
    np.testing.assert_allclose(element_response(m, 1, "force")[2:], N * np.array([a, -h]) / L, rtol=1e-12)
    np.testing.assert_allclose(element_response(m, 1, "force")[2:] + element_response(m, 2, "force")[2:],
                               [0.0, -P], rtol=1e-12, atol=1e-9)


def test_truss_compression_is_negative():
    m = vtsi.Model(ndf=2)
    m.node(1, 0.0, 0.0)
    m.node(2, 4.0, 0.0)
    m.fix(1, 1, 1)
    m.fix(2, 0, 1)
    m.element("truss", 1, (1, 2), A=1e-3, E=2e11)
    constant_pattern(m).load(2, -1e4, 0.0)
    static_solution(m)
    assert element_response(m, 1, "axialForce") == pytest.approx([-1e4], rel=1e-12)


@pytest.mark.parametrize("cmass, expected", [(0, [0.5, 0.0]), (1, [1 / 3, 1 / 6])])
def test_truss_mass_lumped_and_consistent(cmass, expected):
    """OpenSees Truss.cpp: lumped ρL/2 on each translation; -cMass ρL/6 [2 1; 1 2] on both
    translations (the transverse one included)."""
    rho, L = 12.0, 2.5
    etype = vtsi.elements.ELEMENT_TYPES["truss"]()
    etype.add(1, (1, 2), A=1e-3, E=2e11, rho=rho, cmass=cmass)
    mass = etype.mass(np.array([[[0.0, 0.0], [1.5, 2.0]]]), etype.params)[0]
    diag, off = expected
    for d in (0, 1):
        assert mass[d, d] == mass[d + 2, d + 2] == pytest.approx(diag * rho * L)
        assert mass[d, d + 2] == pytest.approx(off * rho * L)
    assert mass[0, 1] == mass[0, 3] == 0.0


def test_truss_axial_vibration():
    """A fixed-free bar of 30 consistent-mass trusses: ω₁ = (π/2L) √(EA/μ) within 0.1 %."""
    L, A, E, mu, n = 10.0, 1e-3, 2e11, 7.85, 30
    m = vtsi.Model(ndf=2)
    for i in range(n + 1):
        m.node(i + 1, L * i / n, 0.0)
        m.fix(i + 1, 1 if i == 0 else 0, 1)
    for i in range(n):
        m.element("truss", i + 1, (i + 1, i + 2), A=A, E=E, rho=mu, cmass=1)
    omega2, _ = vtsi.eigen(m, 1)
    assert np.sqrt(omega2[0]) == pytest.approx(np.pi / (2 * L) * np.sqrt(E * A / mu), rel=1e-3)


# -- zeroLength -----------------------------------------------------------------------------

@pytest.mark.parametrize("angle", [0.0, np.pi / 6, -2.0])
def test_zero_length_spring_in_rotated_axes(angle):
    """Node 2 on springs kx, ky (local axes at ``angle``) and krz: u = Tᵀ diag(1/k) T P."""
    kx, ky, krz = 2e6, 5e5, 3e4
    P = np.array([1e3, -4e3, 250.0])
    m = vtsi.Model()
    m.node(1, 2.0, 1.0)
    m.node(2, 2.0, 1.0)
    m.fix(1, 1, 1, 1)
    m.element("zeroLength", 1, (1, 2), kx=kx, ky=ky, krz=krz, angle=angle)
    constant_pattern(m).load(2, *P)
    u = static_solution(m)
    asm = m.build()
    c, s = np.cos(angle), np.sin(angle)
    T = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    expected = T.T @ np.diag([1 / kx, 1 / ky, 1 / krz]) @ T @ P
    np.testing.assert_allclose([u[asm.full_dof(2, d)] for d in (1, 2, 3)], expected, rtol=1e-12)
    np.testing.assert_allclose(element_response(m, 1, "deformation"), T @ expected, rtol=1e-12)
    np.testing.assert_allclose(element_response(m, 1, "basicForce"), T @ P, rtol=1e-12)
    np.testing.assert_allclose(element_response(m, 1, "force"), np.concatenate([-P, P]), rtol=1e-12, atol=1e-9)


def test_zero_length_dashpots_and_do_rayleigh():
    """C holds the dashpots; Rayleigh βK takes the springs only with do_rayleigh = 1 (OpenSees
    zeroLength's default is 0)."""
    beta, k, c = 0.01, 4e5, 300.0
    totals = []
    for do_rayleigh in (0, 1):
        m = vtsi.Model()
        m.node(1, 0.0, 0.0)
        m.node(2, 0.0, 0.0)
        m.element("zeroLength", 1, (1, 2), ky=k, cy=c, do_rayleigh=do_rayleigh)
        m.rayleigh(0.0, beta)
        asm = m.build()
        uy = [asm.full_dof(n, 2) for n in (1, 2)]
        totals.append(asm.C_full.toarray()[np.ix_(uy, uy)])
    pair = np.array([[1.0, -1.0], [-1.0, 1.0]])
    np.testing.assert_allclose(totals[0], c * pair)
    np.testing.assert_allclose(totals[1], (c + beta * k) * pair)


def test_zero_length_dashpot_velocity_response():
    etype = vtsi.elements.ELEMENT_TYPES["zeroLength"]()
    etype.add(1, (1, 2), kx=1e3, cx=20.0, angle=np.pi / 2)
    coords = np.zeros((1, 2, 2))
    u = np.array([[0.0, 0.0, 0.0, 0.0, 0.01, 0.0]])
    v = np.array([[0.0, 0.0, 0.0, 0.0, 0.5, 0.0]])
    # local x is global y: force 1e3·0.01 + 20·0.5 = 20
    np.testing.assert_allclose(etype.response("basicForce", coords, etype.params, u, v)[0], [20.0, 0.0, 0.0],
                               atol=1e-12)


def test_zero_length_needs_a_spring_or_dashpot():
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 0.0, 0.0)
    with pytest.raises(ModelError, match=r"element 5 \(zeroLength\): every spring and dashpot .* is zero"):
        m.element("zeroLength", 5, (1, 2), angle=0.3)
    m.element("zeroLength", 5, (1, 2), krz=1.0)        # the failed attempt left nothing behind
    assert m.element_tags() == [5] and len(m.element_types["zeroLength"]) == 1


def test_zero_length_nodes_apart_are_accepted_with_a_warning(caplog):
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 0.5, 0.0)
    m.element("zeroLength", 9, (1, 2), kx=1.0)
    with caplog.at_level(logging.WARNING, logger="vtsi.elements.zero_length"):
        m.build()
    assert "element 9 (zeroLength): nodes 1 and 2 are 0.5 apart (model length units)" in caplog.text


def test_truss_do_rayleigh():
    beta, EA_L = 0.02, 2e11 * 1e-3 / 2.0
    for flag in (0, 1):
        m = vtsi.Model(ndf=2)
        m.node(1, 0.0, 0.0)
        m.node(2, 2.0, 0.0)
        m.element("truss", 1, (1, 2), A=1e-3, E=2e11, do_rayleigh=flag)
        m.rayleigh(0.0, beta)
        assert m.build().C_full[0, 0] == pytest.approx(flag * beta * EA_L)


# -- pointMass ------------------------------------------------------------------------------

@pytest.mark.parametrize("krz", [3e3, 1e5])
def test_point_mass_on_springs_frequencies(krz):
    """A pointMass (m, J) on a zeroLength (kx, ky, krz): ω² = kx/m, ky/m, krz/J (the lowest two,
    with the rotation first or last)."""
    mass, J, k = 250.0, 12.0, 4e5
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 0.0, 0.0)
    m.fix(1, 1, 1, 1)
    m.element("zeroLength", 1, (1, 2), kx=k, ky=2 * k, krz=krz)
    m.element("pointMass", 2, (2,), m=mass, J=J)
    omega2, _ = vtsi.eigen(m, 2)
    np.testing.assert_allclose(omega2, np.sort([k / mass, 2 * k / mass, krz / J])[:2], rtol=1e-12)


def test_point_mass_adds_to_nodal_mass():
    m = vtsi.Model()
    m.node(1, 1.0, 2.0, mass=(1.0, 2.0, 3.0))
    m.element("pointMass", 1, (1,), m=10.0)
    np.testing.assert_allclose(m.build().M_full.diagonal(), [11.0, 12.0, 3.0])


# -- geometry and input errors --------------------------------------------------------------

@pytest.mark.parametrize("name, params", [
    ("elasticBeamColumn", dict(A=1.0, E=1.0, I=1.0)),
    ("truss", dict(A=1.0, E=1.0)),
])
def test_line_element_with_coincident_nodes(name, params):
    m = vtsi.Model()
    m.node(3, 1.5, 2.0)
    m.node(4, 1.5, 2.0)
    m.element(name, 7, (3, 4), **params)
    with pytest.raises(ModelError) as info:
        m.build()
    assert str(info.value) == f"element 7 ({name}): zero length between nodes 3 and 4"


def beam_model():
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 5.0, 0.0)
    return m


@pytest.mark.parametrize("pname, value", [("E", 0.0), ("E", -2e11), ("A", -0.5), ("I", 0.0)])
def test_non_positive_section_value(pname, value):
    params = dict(A=0.1, E=2e11, I=1e-3)
    params[pname] = value
    with pytest.raises(ModelError) as info:
        beam_model().element("elasticBeamColumn", 3, (1, 2), **params)
    assert str(info.value) == f"element 3 (elasticBeamColumn): {pname} must be > 0, got {value:g}"


def test_nan_parameter():
    with pytest.raises(ModelError, match=r"element 3 \(truss\): E must be finite, got nan"):
        beam_model().element("truss", 3, (1, 2), A=1.0, E=float("nan"))


def test_non_numeric_parameter():
    with pytest.raises(ModelError, match=r"element 3 \(truss\): A must be a number, got 'big'"):
        beam_model().element("truss", 3, (1, 2), A="big", E=1.0)


def test_unknown_parameter():
    with pytest.raises(ModelError, match=r"element 3 \(elasticBeamColumn\): unknown parameter\(s\) \['Iz'\]; "
                                         r"valid: A, E, I, rho, cmass"):
        beam_model().element("elasticBeamColumn", 3, (1, 2), A=1.0, E=1.0, Iz=1.0)


def test_wrong_node_count():
    m = beam_model()
    with pytest.raises(ModelError, match=r"element 3 \(pointMass\): needs 1 nodes, got 2"):
        m.element("pointMass", 3, (1, 2), m=1.0)
    with pytest.raises(ModelError, match=r"element 4 \(truss\): needs 2 nodes, got 1"):
        m.element("truss", 4, (1,), A=1.0, E=1.0)


def test_unknown_element_type_lists_the_valid_names():
    with pytest.raises(ModelError) as info:
        beam_model().element("elasticBeam", 3, (1, 2), A=1.0, E=1.0, I=1.0)
    message = str(info.value)
    assert message.startswith("unknown element type 'elasticBeam'; known types: ")
    for name in ("elasticBeamColumn", "pointMass", "truss", "zeroLength"):
        assert name in message


def test_duplicate_element_tag():
    m = beam_model()
    m.element("truss", 3, (1, 2), A=1.0, E=1.0)
    with pytest.raises(ModelError, match="element 3 already exists"):
        m.element("elasticBeamColumn", 3, (1, 2), A=1.0, E=1.0, I=1.0)
    assert m.element_tags() == [3]


def test_element_on_missing_node():
    with pytest.raises(ModelError, match=r"element 3 \(truss\): node 9 does not exist"):
        beam_model().element("truss", 3, (1, 9), A=1.0, E=1.0)


def test_mass_switch_must_be_0_or_1():
    with pytest.raises(ModelError, match=r"element 3 \(elasticBeamColumn\): cmass must be 0 or 1, got 2"):
        beam_model().element("elasticBeamColumn", 3, (1, 2), A=1.0, E=1.0, I=1.0, cmass=2)
