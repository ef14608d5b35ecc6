"""OpenSees scripts that step with ``analyze(1, dt)`` in a Python loop (most published scripts):
each call costs one compiled step and a constant. What a run needs is kept from call to call
(stages, loads, recorder columns, a block of the coming load factors) and given up when the
model, its patterns, the time, dt, the integrator or a dof at rest change; the loop gives the
numbers of one ``analyze(n, dt)`` to the last bit, and OpenSeesPy's when the script changes
things between the steps."""
import numpy as np
import pytest

import vtsi.opensees as vops
from vtsi.analysis import domain_state
from vtsi.timeseries import Path

oracle = pytest.importorskip("openseespy.opensees")

N_EL, SPAN, DT = 10, 20.0, 2e-3


def beam(script, ops, n_steps=300):
    """The moving-force script (``tests/scripts/moving_load_beam.py``) on a 20 m, 10-element beam."""
    script.build(ops, N_EL, SPAN, 1.5, DT, n_steps, 20.0)


@pytest.mark.parametrize("integrator", [("Newmark", 0.5, 0.25), ("HHT", 0.9), ("Bathe",)], ids=lambda i: i[0])
def test_a_per_step_loop_equals_one_analyze(integrator, moving_load_beam):
    """200 calls of analyze(1, dt) (reading nodeDisp, nodeVel, nodeAccel and getTime each step)
    and one analyze(200, dt) with a recorder give identical histories."""
    session = vops.Session()
    beam(moving_load_beam, session)
    moving_load_beam.transient(session, integrator)
    rows, times = [], []
    for _ in range(200):
        session.analyze(1, DT)
        rows.append([session.nodeDisp(6, 2), session.nodeVel(6, 2), session.nodeAccel(6, 2)])
        times.append(session.getTime())
    beam(moving_load_beam, session)
    moving_load_beam.transient(session, integrator)
    tags = [session.recorder("Node", "-node", 6, "-dof", 2, q) for q in ("disp", "vel", "accel")]
    session.analyze(200, DT)
    bulk = np.column_stack([session.recorders[t].values[:, 0] for t in tags])
    np.testing.assert_array_equal(np.array(rows), bulk)
    np.testing.assert_array_equal(times, session.recorders[tags[0]].time)


def test_a_per_step_call_does_no_work_per_pattern(monkeypatch, moving_load_beam):
    """The series are evaluated a block of steps at a time, not at every call: 300 calls of a
    model with 9 Path patterns evaluate the stacked Paths once per 512-step block."""
    calls = []
    original = Path.stack_factors.__func__
    monkeypatch.setattr(Path, "stack_factors", classmethod(lambda cls, *a: calls.append(1) or original(cls, *a)))
    session = vops.Session()
    beam(moving_load_beam, session)
    moving_load_beam.transient(session)
    for _ in range(300):
        session.analyze(1, DT)
    assert len(calls) == 1
    assert session._transient._kept_plan.block[2] == 300      # the block's position: one step per call


def scripted_changes(ops, moving_load_beam):
    """A per-step loop whose script changes things between the steps: a load added to a
    pattern that exists, the time set back, the patterns frozen (loadConst) with a new constant pattern,
    another dt and another integrator. Returns the midspan history."""
    beam(moving_load_beam, ops)
    moving_load_beam.transient(ops)
    out = []
    for k in range(240):
        if k == 40:
            ops.load(4, 0.0, -0.5, 0.0)       # to the last pattern defined (10), as in OpenSees
        if k == 80:
            ops.setTime(ops.getTime() - 0.02)
        if k == 120:
            ops.loadConst()
            ops.timeSeries("Constant", 50)
            ops.pattern("Plain", 50, 50)
            ops.load(3, 0.0, 2e4, 0.0)
        if k == 160:
            ops.integrator("HHT", 0.85)
        dt = DT if k < 200 else 0.5 * DT
        ops.analyze(1, dt)
        out.append([ops.getTime(), ops.nodeDisp(6, 2), ops.nodeAccel(4, 2)])
    return np.array(out)


def test_changes_between_steps_are_taken_into_account_as_in_opensees(moving_load_beam):
    ref = scripted_changes(oracle, moving_load_beam)
    session = vops.Session()
    val = scripted_changes(session, moving_load_beam)
    np.testing.assert_allclose(val[:, 0], ref[:, 0], rtol=0, atol=1e-12)
    scale = np.abs(ref[:, 1:]).max(axis=0)
    assert np.max(np.abs(val[:, 1:] - ref[:, 1:]) / scale) < 1e-9


def test_a_dof_at_rest_set_between_steps_is_integrated(moving_load_beam):
    """The beam's axial dofs are at rest, so they are not integrated; a script (or the object
    API) that gives one a displacement between two steps gets it integrated from then on, as
    a fresh analysis from that state would."""
    runs = []
    for fresh in (False, True):
        session = vops.Session()
        beam(moving_load_beam, session)
        moving_load_beam.transient(session)
        for _ in range(20):
            session.analyze(1, DT)
        asm = session.domain.build()
        domain_state(session.domain).u[asm.full_dof(N_EL + 1, 1)] = 1e-4     # the roller's axial dof
        if fresh:
            session.wipeAnalysis()
            moving_load_beam.transient(session)
            session.analyze(30, DT)
        else:
            for _ in range(30):
                session.analyze(1, DT)
        runs.append(domain_state(session.domain).u.copy())
    assert np.abs(runs[0][asm.full_dof(N_EL + 1, 1)]) > 1e-6            # the axial wave moved it
    np.testing.assert_allclose(runs[0], runs[1], rtol=0, atol=1e-15 * np.abs(runs[1]).max())


def trbdf2_runs(ops, outdir, moving_load_beam):
    """OpenSees's TRBDF2 (one sub-step per analysis step) through runs of 1, 2 and 3 steps, a
    change of dt (a trapezoidal sub-step again) and a recorder file of every step."""
    beam(moving_load_beam, ops)
    moving_load_beam.transient(ops, ("TRBDF2",))
    ops.recorder("Node", "-file", str(outdir / "mid.out"), "-time", "-node", 6, "-dof", 2, "disp")
    out = []
    for n, dt in [(1, DT), (1, DT), (3, DT), (2, DT), (1, DT), (3, 0.5 * DT), (1, 0.5 * DT), (4, DT), (1, DT)] * 5:
        ops.analyze(n, dt)
        out.append([ops.getTime(), ops.nodeDisp(6, 2), ops.nodeVel(4, 2), ops.nodeAccel(5, 2)])
    ops.wipe()
    return np.array(out), np.loadtxt(outdir / "mid.out")


def test_trbdf2_sub_steps_equal_opensees(tmp_path, moving_load_beam):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    ref, ref_file = trbdf2_runs(oracle, tmp_path / "a", moving_load_beam)
    val, val_file = trbdf2_runs(vops.Session(), tmp_path / "b", moving_load_beam)
    np.testing.assert_array_equal(val[:, 0], ref[:, 0])
    assert np.max(np.abs(val[:, 1:] - ref[:, 1:]) / np.abs(ref[:, 1:]).max(axis=0)) < 1e-9
    assert val_file.shape == ref_file.shape == (85, 2)
    assert np.max(np.abs(val_file - ref_file) / np.abs(ref_file).max(axis=0)) < 1e-5     # 6 digits written
