"""The generalized-α method (``integrator GeneralizedAlpha αM αF [β γ]``): OpenSeesPy's numbers
through the same script, the modal bridge, the refusals and the coupled analysis's weights (its
special cases, spectral radius and order are in test_integrators.py)."""
import numpy as np
import pytest

import vtsi
import vtsi.opensees as vops
from vtsi.errors import AnalysisError, CommandError
from vtsi.integrators import GeneralizedAlpha
from vtsi.modal_bridge import ModalBridge

oracle = pytest.importorskip("openseespy.opensees")


def run_script(script, ops, integrator, steps=250, dt=2e-3):
    """The moving-force script (``tests/scripts/moving_load_beam.py``, 10 elements, 20 m, a force
    at 25 m/s) with ``integrator``; returns the midspan displacement and acceleration, a
    rotation rate, an end moment and the time, every step."""
    script.build(ops, 10, 20.0, 1.2, dt, steps, 25.0, rayleigh=(0.15, 2e-4))
    script.transient(ops, integrator)
    rows = []
    for _ in range(steps):
        ops.analyze(1, dt)
        rows.append([ops.nodeDisp(6, 2), ops.nodeAccel(6, 2), ops.nodeVel(3, 3), ops.eleForce(2)[2],
                     ops.getTime()])
    return np.array(rows)


@pytest.mark.parametrize("integrator", [("GeneralizedAlpha", 1.0, 0.8), ("GeneralizedAlpha", 0.9, 0.7),
                                        ("GeneralizedAlpha", 2.0 / 3.0, 5.0 / 9.0),
                                        ("GeneralizedAlpha", 0.95, 0.8, 0.4, 0.7)], ids=str)
def test_equals_opensees(integrator, moving_load_beam):
    """The optional pair is (β, γ) in OpenSees's reading of its arguments (β = 0.4, γ = 0.7 here)."""
    ref = run_script(moving_load_beam, oracle, integrator)
    val = run_script(moving_load_beam, vops, integrator)
    np.testing.assert_array_equal(val[:, -1], ref[:, -1])          # the time, accumulated as OpenSees does
    scale = np.abs(ref[:, :-1]).max(axis=0)
    assert np.max(np.abs(val[:, :-1] - ref[:, :-1]) / scale) < 1e-9


def test_modal_bridge_with_all_modes_equals_the_fe_bridge():
    fe, modal = [], []
    for out, bridge in ((fe, False), (modal, True)):
        m = vtsi.Model()
        for i in range(9):
            m.node(i + 1, 2.5 * i, 0.0)
        m.fix(1, 1, 1, 0)
        m.fix(9, 0, 1, 0)
        for e in range(8):
            m.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=1.0, E=3e10, I=1.2, rho=2e4, cmass=1)
        m.rayleigh(0.2, 1e-4)
        m.pattern(1, vtsi.Path([0.0, 1e5, 0.0, -5e4, 0.0], dt=0.01, tag=1)).load(4, 0.0, -1.0, 0.0)
        rec = vtsi.recorders.NodeRecorder([5], [2], "disp")
        b = ModalBridge(m, n_modes="all") if bridge else None
        vtsi.TransientAnalysis(m, GeneralizedAlpha(0.9, 0.7), 1e-3, recorders=[rec], bridge=b).run(200)
        out.append(rec.values[:, 0])
    np.testing.assert_allclose(modal[0], fe[0], rtol=0, atol=1e-9 * np.abs(fe[0]).max())


def test_refusals():
    with pytest.raises(AnalysisError, match=r"alpha_m = 0.6 is outside \[0.7, 2\]"):
        GeneralizedAlpha(0.6, 0.7)
    with pytest.raises(AnalysisError, match="alpha_f = 0.4 is outside"):
        GeneralizedAlpha(0.9, 0.4)
    with pytest.raises(AnalysisError, match=r"gamma = 0.5 is outside \[0.7, inf\] \(the unconditionally stable range"):
        GeneralizedAlpha(0.9, 0.7, 0.5, 0.3)
    with pytest.raises(AnalysisError, match=r"beta = 0.3 is outside \[0.375, inf\]"):
        GeneralizedAlpha(0.9, 0.7, 0.75, 0.3)
    with pytest.raises(AnalysisError, match="gamma = nan is outside"):
        GeneralizedAlpha(0.9, 0.7, float("nan"), 0.4)
    with pytest.raises(AnalysisError, match="beta must be a number, got 'x'"):
        GeneralizedAlpha(0.9, 0.7, 0.75, "x")
    vops.wipe()
    with pytest.raises(CommandError, match="integrator GeneralizedAlpha: missing alphaF"):
        vops.integrator("GeneralizedAlpha", 0.9)
    with pytest.raises(AnalysisError, match="alpha_m = 0.5 is outside"):
        vops.integrator("GeneralizedAlpha", 0.5, 0.7)


def test_the_coupled_analysis_takes_it():
    """The coupled analysis weights the contact forces like the other forces (αF/αM λ_{n+1} +
    (1 − αF)/αM λ_n) and the train's weight by 1/αM (tests/test_coupled.py checks the numbers)."""
    from vtsi.coupled import coupled_integrator
    integ = coupled_integrator(GeneralizedAlpha(0.9, 0.7), "bilateral")
    (stage,) = integ.stages(1e-3)
    assert stage.force_weight == pytest.approx(0.7 / 0.9, rel=1e-15)
    assert stage.mass_weight == pytest.approx(1.0 / 0.9, rel=1e-15)
    assert coupled_integrator(GeneralizedAlpha(0.9, 0.7), "lcp") is not None      # dissipative
