"""OpenSees's ``ElasticTimoshenkoBeam`` (2-D): closed forms, and OpenSeesPy itself, both through
the same script (vtsi.opensees) and against models built with vtsi's object API (eigenvalues, a
transient history, a cantilever, element forces), lumped and consistent mass."""
import re

import numpy as np
import openseespy.opensees as oracle
import pytest

import vtsi
import vtsi.opensees as vops
from vtsi.errors import CommandError, ModelError

E, NU, RHO = 3.4e10, 0.2, 2500.0
G = E / (2.0 * (1.0 + NU))


def section(depth, width=1.0):
    A = width * depth
    return dict(A=A, I=width * depth ** 3 / 12.0, Avy=5.0 / 6.0 * A, rho=RHO * A)


def beam_script(ops, depth, cmass, span=8.0, n_el=10, inclined=0.0):
    """A pinned-roller beam of ``n_el`` Timoshenko elements (optionally inclined by ``inclined``
    rad), a point load ramped by a Linear series at its third point."""
    s = section(depth)
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    c, sn = np.cos(inclined), np.sin(inclined)
    for i in range(n_el + 1):
        ops.node(i + 1, span * i / n_el * c, span * i / n_el * sn)
    ops.fix(1, 1, 1, 0)
    ops.fix(n_el + 1, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    extra = ("-cMass",) if cmass else ()
    for e in range(n_el):
        ops.element("ElasticTimoshenkoBeam", e + 1, e + 1, e + 2, E, G, s["A"], s["I"], s["Avy"], 1,
                    "-mass", s["rho"], *extra)
    return s


@pytest.mark.parametrize("cmass", [0, 1])
@pytest.mark.parametrize("depth", [0.4, 2.5])
def test_eigenvalues_equal_opensees(depth, cmass):
    values = []
    for ops in (oracle, vops):
        beam_script(ops, depth, cmass)
        values.append(np.array(ops.eigen("-fullGenLapack", 6)))
    np.testing.assert_allclose(values[1], values[0], rtol=1e-9)


@pytest.mark.parametrize("cmass", [0, 1])
def test_transient_history_and_element_forces_equal_opensees(cmass):
    """A deep inclined beam under a ramped load, Newmark: displacement history and the global
    and local end forces of an element equal OpenSeesPy's to 1e-9."""
    out = []
    for ops in (oracle, vops):
        beam_script(ops, 2.0, cmass, inclined=0.3)
        ops.timeSeries("Linear", 1, "-factor", 1e5)
        ops.pattern("Plain", 1, 1)
        ops.load(4, 0.3, -1.0, 0.0)
        ops.rayleigh(0.2, 0.0, 0.0, 1e-4)
        ops.constraints("Plain")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.algorithm("Linear")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        rows = []
        for _ in range(60):
            ops.analyze(1, 2e-4)
            rows.append(ops.nodeDisp(6) + ops.nodeAccel(4) + ops.eleResponse(3, "globalForce")
                        + ops.eleResponse(3, "localForce"))
        out.append(np.array(rows))
    scale = np.maximum(np.abs(out[0]).max(axis=0), 1e-9 * np.abs(out[0]).max())
    assert np.max(np.abs(out[1] - out[0]) / scale) < 1e-9


def object_beam(depth, cmass, span=8.0, n_el=10, inclined=0.0):
    """The model of :func:`beam_script` built with vtsi's object API."""
    s = section(depth)
    m = vtsi.Model()
    c, sn = np.cos(inclined), np.sin(inclined)
    for i in range(n_el + 1):
        m.node(i + 1, span * i / n_el * c, span * i / n_el * sn)
    m.fix(1, 1, 1, 0)
    m.fix(n_el + 1, 0, 1, 0)
    for e in range(n_el):
        m.element("ElasticTimoshenkoBeam", e + 1, (e + 1, e + 2), A=s["A"], E=E, G=G, I=s["I"], Avy=s["Avy"],
                  rho=s["rho"], cmass=cmass)
    return m


def oracle_static(load_node, load):
    """One linear static step of the OpenSeesPy model in memory under ``load`` at ``load_node``."""
    oracle.timeSeries("Constant", 1)
    oracle.pattern("Plain", 1, 1)
    oracle.load(load_node, *load)
    oracle.constraints("Plain")
    oracle.numberer("Plain")
    oracle.system("FullGeneral")
    oracle.algorithm("Linear")
    oracle.integrator("LoadControl", 1.0)
    oracle.analysis("Static")
    assert oracle.analyze(1) == 0


def element_response(m, tag, kind):
    """Response ``kind`` of element ``tag`` of an object-API model at its committed state."""
    ((etype, coords, params, u_e, v_e, _),) = m.build().element_state([tag], m.state.u, m.state.v)
    return etype.response(kind, coords, params, u_e, v_e)[0]


@pytest.mark.parametrize("cmass", [0, 1])
@pytest.mark.parametrize("depth", [0.4, 2.5])
def test_object_api_eigenvalues_equal_opensees(depth, cmass):
    """Pinned-roller beam of 10 elements built with vtsi.Model: the 6 lowest eigenvalues equal
    OpenSeesPy's to 1e-9 (lumped: ρL/2 on the translations; consistent: translational and rotary)."""
    beam_script(oracle, depth, cmass)
    expected = np.array(oracle.eigen("-fullGenLapack", 6))
    omega2, _ = vtsi.eigen(object_beam(depth, cmass), 6)
    np.testing.assert_allclose(omega2, expected, rtol=1e-9)


@pytest.mark.parametrize("depth", [0.1, 1.5])
def test_cantilever_tip_deflection_with_shear(depth):
    """Tip load P on a cantilever: δ = PL³/3EI + PL/(G Avy), exact for any number of elements
    (Przemieniecki 1968, §5.6), and the tip displacements equal OpenSeesPy's to 1e-12."""
    L, P = 4.0, 2e5
    s = section(depth)
    for n_el in (1, 4):
        m = vtsi.Model()
        oracle.wipe()
        oracle.model("basic", "-ndm", 2, "-ndf", 3)
        oracle.geomTransf("Linear", 1)
        for i in range(n_el + 1):
            m.node(i + 1, L * i / n_el, 0.0)
            oracle.node(i + 1, L * i / n_el, 0.0)
        m.fix(1, 1, 1, 1)
        oracle.fix(1, 1, 1, 1)
        for i in range(n_el):
            m.element("ElasticTimoshenkoBeam", i + 1, (i + 1, i + 2), A=s["A"], E=E, G=G, I=s["I"], Avy=s["Avy"])
            oracle.element("ElasticTimoshenkoBeam", i + 1, i + 1, i + 2, E, G, s["A"], s["I"], s["Avy"], 1)
        m.pattern(1, m.add_time_series(vtsi.Constant(tag=1))).load(n_el + 1, 0.0, -P, 0.0)
        vtsi.StaticAnalysis(m).run(1)
        oracle_static(n_el + 1, (0.0, -P, 0.0))
        exact = -(P * L ** 3 / (3 * E * s["I"]) + P * L / (G * s["Avy"]))
        asm = m.build()
        tip = np.array([m.state.u[asm.full_dof(n_el + 1, d)] for d in (1, 2, 3)])
        assert tip[1] == pytest.approx(exact, rel=1e-10)
        np.testing.assert_allclose(tip, oracle.nodeDisp(n_el + 1), rtol=1e-12, atol=1e-12 * abs(exact))


def test_inclined_member_end_forces_equal_opensees():
    """Deep beam inclined by 0.3 rad, built with vtsi.Model, a static load with both components
    and a moment: 'force', 'globalForce' and 'localForce' of every element equal OpenSeesPy's
    eleResponse to 1e-9 of the largest end force."""
    load = (3e5, -1e6, 2e5)
    beam_script(oracle, 2.0, 0, inclined=0.3)
    oracle_static(4, load)
    m = object_beam(2.0, 0, inclined=0.3)
    m.pattern(1, m.add_time_series(vtsi.Constant(tag=1))).load(4, *load)
    vtsi.StaticAnalysis(m).run(1)
    for kind in ("force", "globalForce", "localForce"):
        expected = np.array([oracle.eleResponse(e, kind) for e in range(1, 11)])
        got = np.array([element_response(m, e, kind) for e in range(1, 11)])
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


@pytest.mark.parametrize("stiff", ["G", "Avy"])
def test_without_shear_flexibility_it_is_the_euler_bernoulli_beam(stiff):
    """G Avy → ∞ (φ → 0), by G or by Avy: stiffness equal to elasticBeamColumn's to 1e-9;
    consistent mass to within the rotary inertia it adds (ρ I / A), which the Euler-Bernoulli
    element leaves out."""
    coords = np.array([[[0.0, 0.0], [3.0, 1.0]]])
    s = section(0.5)
    timo = vtsi.elements.ElasticTimoshenkoBeam2d()
    eb = vtsi.elements.ElasticBeamColumn2d()
    g, avy = (G * 1e12, s["Avy"]) if stiff == "G" else (G, s["Avy"] * 1e12)
    p_timo = np.array([[s["A"], E, g, s["I"], avy, s["rho"], 1.0]])
    p_eb = np.array([[s["A"], E, s["I"], s["rho"], 1.0]])
    k_t, k_e = timo.stiffness(coords, p_timo), eb.stiffness(coords, p_eb)
    np.testing.assert_allclose(k_t, k_e, rtol=1e-9, atol=1e-9 * np.abs(k_e).max())
    m_t, m_e = timo.mass(coords, p_timo), eb.mass(coords, p_eb)
    assert np.abs(m_t - m_e).max() < 0.02 * np.abs(m_e).max()


@pytest.mark.parametrize("name, value", [("G", 0.0), ("G", -8e10), ("Avy", 0.0), ("Avy", -1.0)])
def test_object_api_refuses_non_positive_shear(name, value):
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 1.0, 0.0)
    args = dict(A=1.0, E=E, G=G, I=1.0, Avy=0.8)
    args[name] = value
    message = f"element 7 (ElasticTimoshenkoBeam): {name} must be > 0, got {value:g}"
    with pytest.raises(ModelError, match=f"^{re.escape(message)}$"):
        m.element("ElasticTimoshenkoBeam", 7, (1, 2), **args)


def test_bad_arguments_name_the_element():
    vops.wipe()
    vops.model("basic", "-ndm", 2, "-ndf", 3)
    vops.node(1, 0.0, 0.0)
    vops.node(2, 1.0, 0.0)
    vops.geomTransf("Linear", 1)
    with pytest.raises(ModelError, match=r"^element 5 \(ElasticTimoshenkoBeam\): G must be > 0, got 0$"):
        vops.element("ElasticTimoshenkoBeam", 5, 1, 2, E, 0.0, 1.0, 1.0, 0.8, 1)
    with pytest.raises(CommandError, match="element ElasticTimoshenkoBeam 5: geomTransf 9 does not exist"):
        vops.element("ElasticTimoshenkoBeam", 5, 1, 2, E, G, 1.0, 1.0, 0.8, 9)
    with pytest.raises(CommandError, match="^element ElasticTimoshenkoBeam 5: missing Avy$"):
        vops.element("ElasticTimoshenkoBeam", 5, 1, 2, E, G, 1.0, 1.0)
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 1.0, 0.0)
    with pytest.raises(ModelError, match=r"^element 1 \(ElasticTimoshenkoBeam\): Avy must be > 0, got -1$"):
        m.element("ElasticTimoshenkoBeam", 1, (1, 2), A=1.0, E=E, G=G, I=1.0, Avy=-1.0)
