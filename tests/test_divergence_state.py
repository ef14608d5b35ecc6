"""What a diverged run leaves (docs/bad_inputs.md, "What is not lost when a run diverges"): the
recorders hold steps 1 … step − 1 and the model is at step − 1 (time and state), so that a new
run goes on from the last step recorded. Object API against the same steps run without a limit;
the command layer (Newmark, and TRBDF2 resumed mid composite step) against OpenSeesPy, which
goes on where vtsi stops at ``|u| > 1e8``. A coupled analysis refuses to go on after one."""
import numpy as np
import pytest

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, DivergenceError
from vtsi.models.scenes import s2_model
from vtsi.recorders import NodeRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402

DT = 0.01


@pytest.mark.parametrize("chunk_steps", [4, 2000])
def test_a_diverged_run_leaves_the_model_at_the_last_step_recorded(chunk_steps, step_load_beam):
    free = NodeRecorder([3], [2])
    vtsi.TransientAnalysis(step_load_beam(), "Newmark", DT, recorders=[free]).run(12)
    limit = 0.999 * np.abs(free.values).max()                 # the run passes it at its largest deflection
    model, rec = step_load_beam(), NodeRecorder([3], [2])
    with pytest.raises(DivergenceError) as info:
        vtsi.TransientAnalysis(model, "Newmark", DT, recorders=[rec], chunk_steps=chunk_steps,
                               divergence_limit=limit).run(12)
    done = info.value.step - 1
    assert done >= 5 and len(rec.time) == done              # past two chunks of 4: the third is run again
    np.testing.assert_array_equal(rec.values, free.values[:done])
    reference = step_load_beam()
    vtsi.TransientAnalysis(reference, "Newmark", DT).run(done)
    state, expected = vtsi.domain_state(model), vtsi.domain_state(reference)
    assert state.time == rec.time[-1] == pytest.approx(expected.time, rel=1e-15)
    for got, want in ((state.u, expected.u), (state.v, expected.v), (state.a, expected.a)):
        np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-18)
    vtsi.TransientAnalysis(model, "Newmark", DT / 2, recorders=[rec]).run(3)     # a new run continues the record
    assert np.all(np.diff(rec.time) > 0) and rec.time[-1] == pytest.approx((done + 1.5) * DT)


def ramp_beam(o):
    """:func:`beam` in the command layer under a load ramping up 6e10 times per second: its
    midspan passes 1e8 m within a few steps of 10 ms."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(5):
        o.node(i + 1, 2.5 * i, 0.0)
        if 0 < i < 4:
            o.mass(i + 1, 2500.0, 2500.0, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(5, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for e in range(1, 5):
        o.element("elasticBeamColumn", e, e, e + 1, 0.5, 3e10, 0.04, 1)
    o.timeSeries("Linear", 1, "-factor", 6e10)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e6, 0.0)
    o.constraints("Plain")
    o.numberer("Plain")
    o.system("BandGeneral")
    o.test("NormDispIncr", 1e-12, 10)
    o.algorithm("Linear")


@pytest.mark.usefixtures("fresh_session")
@pytest.mark.parametrize("integrator, first", [(("Newmark", 0.5, 0.25), 0), (("TRBDF2",), 1), (("TRBDF2",), 2)])
def test_the_command_layer_stops_where_opensees_was_a_step_before(tmp_path, integrator, first):
    """``first`` sub-steps alone first (TRBDF2 resumes a composite step after an odd number);
    then ``analyze(20)`` diverges: time, state and the recorder's last line are OpenSeesPy's
    after the same number of steps, and the analysis goes on from there as OpenSees's does."""
    ramp_beam(vops)
    vops.recorder("Node", "-file", str(tmp_path / "mid.out"), "-time", "-node", 3, "-dof", 2, "disp")
    vops.integrator(*integrator)
    vops.analysis("Transient")
    if first:
        vops.analyze(first, DT)
    with pytest.raises(DivergenceError) as info:
        vops.analyze(20, DT)
    done = first + info.value.step - 1
    assert info.value.step > 2                                     # the run's good rows are run again
    ramp_beam(oracle)
    oracle.integrator(*integrator)
    oracle.analysis("Transient")
    if first:
        oracle.analyze(first, DT)
    oracle.analyze(done - first, DT)
    assert vops.getTime() == pytest.approx(oracle.getTime(), rel=1e-14)
    for node in (2, 3, 4):
        assert vops.nodeDisp(node, 2) == pytest.approx(oracle.nodeDisp(node, 2), rel=1e-9)
        assert vops.nodeVel(node, 2) == pytest.approx(oracle.nodeVel(node, 2), rel=1e-9)
    stopped = (oracle.getTime(), oracle.nodeDisp(3, 2))
    for o in (vops, oracle):               # and go on as OpenSees (TRBDF2: the BDF2 half after an odd count)
        o.remove("loadPattern", 1)
        o.analyze(3, DT)
    assert vops.getTime() == pytest.approx(oracle.getTime(), rel=1e-14)
    for node in (2, 3, 4):
        assert vops.nodeDisp(node, 2) == pytest.approx(oracle.nodeDisp(node, 2), rel=1e-9)
    vops.wipe()                                                    # closes the file
    rows = np.loadtxt(tmp_path / "mid.out", ndmin=2)
    assert rows[done - 1, 0] == pytest.approx(stopped[0], rel=1e-14)
    assert rows[done - 1, 1] == pytest.approx(stopped[1], rel=1e-6)
    assert np.all(np.diff(rows[:, 0]) > 0)


def test_a_diverged_coupled_analysis_refuses_to_go_on():
    """A coupled run's wheels, contact and records go on with time; after a divergence its
    model is at the start of the chunk (not the last recorded step), so a further run would
    record time going back: it is refused, naming the step."""
    model = vtsi.Model()
    bridge, train = s2_model(model, 10)
    con = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, 0.0))
    mid = NodeRecorder(bridge.midspan_nodes, [2])
    analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[mid], divergence_limit=1e-5)
    with pytest.raises(DivergenceError) as info:
        analysis.run(400)
    step = info.value.step
    assert 1 < step < 400 and len(mid.time) == step - 1 and np.abs(mid.values).max() <= 1e-5
    with pytest.raises(AnalysisError, match=rf"^CoupledAnalysis: it diverged \(step {step}, t = "
                                            rf"{info.value.time:.6g} s\); a coupled analysis does not go on"):
        analysis.run(10)
    assert len(mid.time) == step - 1
