"""``modalDamping`` keeps its ratios, and they damp the modes of the latest ``eigen``, as in
OpenSees (``Domain::setModalDampingFactors`` stores them; ``IncrementalIntegrator::
addModalDampingForce`` damps the first min(number of ratios, number of modes) modes of the last
``eigen``, reading their vectors again, ``setupModal``, whenever the eigenvalues change). A script that changes its masses or elements,
calls ``eigen`` again and steps on runs with the same ratios on the new modes: before, vtsi
refused it ('the model changed after eigen and modalDamping'). Checked against OpenSeesPy
itself (the oracle; measured agreement 5e-14 .. 3e-13); OpenSeesPy's run of the same ratios on
other modes (the old model's, without the new eigen; more or fewer modes) differs by 0.016 ..
0.88, so that the agreement is not a coincidence of a response the change does not touch.
"""
import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.bridge_file import script_bridge  # noqa: E402
from vtsi.errors import BridgeModelError, CommandError  # noqa: E402
from vtsi.passage import PassageSettings  # noqa: E402
from vtsi.sweep import Sweep  # noqa: E402

RTOL = 1e-9
pytestmark = pytest.mark.usefixtures("fresh_session")


def beam(o):
    """A 20 m simply supported beam of six elements with nodal masses under a half-sine pulse at
    node 3, its Newmark analysis defined (OpenSeesPy 3.7.1 fails on a second ``eigen`` without
    one; OpenSees puts modal damping in the residual: Newton iterates to 1e-14)."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(7):
        o.node(i + 1, 20.0 * i / 6, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(7, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for i in range(6):
        o.element("elasticBeamColumn", i + 1, i + 1, i + 2, 2.0, 3.0e10, 1.5, 1)
    for i in range(2, 8):
        o.mass(i, 2000.0, 2000.0, 5.0)
    o.timeSeries("Trig", 1, 0.0, 0.3, 0.1)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e5, 0.0)
    o.constraints("Plain")
    o.numberer("Plain")
    o.system("FullGeneral")
    o.test("NormDispIncr", 1e-14, 50)
    o.algorithm("Newton")
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")


def heavier(o):
    o.mass(3, 8000.0, 8000.0, 5.0)


def spring(o):
    """A new node under node 3 and a vertical zeroLength spring to it: new dofs, new stiffness."""
    o.node(20, 20.0 / 3, 0.0)
    o.fix(20, 1, 1, 1)
    o.uniaxialMaterial("Elastic", 1, 5e7)
    o.element("zeroLength", 50, 3, 20, "-mat", 1, "-dir", 2)


def steps(o, n=10):
    for _ in range(n):
        o.analyze(1, 0.005)


def history(o, script, n_steps=80):
    """``script(o)`` on :func:`beam`, then ``n_steps`` of 5 ms: deflections at nodes 3 and 4,
    the vertical velocity of node 2 and the rotation of node 1 at every step."""
    beam(o)
    script(o)
    out = []
    for _ in range(n_steps):
        o.analyze(1, 0.005)
        out.append([o.nodeDisp(3, 2), o.nodeDisp(4, 2), o.nodeVel(2, 2), o.nodeDisp(1, 3)])
    return np.array(out)


# each case: (what the script does, the ratios on other modes: the old model's, without the new
# eigen, where OpenSees runs that; else more, fewer or other modes); both run by OpenSeesPy, the
# first by vtsi too
CASES = {
    "a heavier node, eigen again": (
        lambda o: (o.eigen(4), o.modalDamping(0.05), heavier(o), o.eigen(4)),
        lambda o: (o.eigen(4), o.modalDamping(0.05), heavier(o))),          # OpenSees: the old model's modes
    "a ratio per mode, a heavier node, eigen again": (
        lambda o: (o.eigen(4), o.modalDamping(0.01, 0.02, 0.03, 0.04), heavier(o), o.eigen(4)),
        lambda o: (heavier(o), o.eigen(4), o.modalDamping(0.01, 0.02, 0.0, 0.0))),
    "a spring on a new node, eigen again": (
        lambda o: (o.eigen(4), o.modalDamping(0.05), spring(o), o.eigen(4)),
        lambda o: (spring(o), o.eigen(4), o.modalDamping(0.05, 0.05, 0.0, 0.0))),
    "a spring, eigen with fewer modes: the first two ratios": (
        lambda o: (o.eigen(4), o.modalDamping(0.01, 0.02, 0.03, 0.04), spring(o), o.eigen(2)),
        lambda o: (spring(o), o.eigen(4), o.modalDamping(0.01, 0.02, 0.03, 0.04))),
    "the same model, eigen with fewer modes: the first two ratios": (
        lambda o: (o.eigen(4), o.modalDamping(0.01, 0.02, 0.03, 0.04), o.eigen(2)),
        lambda o: (o.eigen(4), o.modalDamping(0.01, 0.02, 0.03, 0.04))),
    "eigen with more modes: those beyond the ratios stay undamped": (
        lambda o: (o.eigen(2), o.modalDamping(0.05), o.eigen(6)),
        lambda o: (o.eigen(6), o.modalDamping(0.05))),
    "modalDamping between a change and the new eigen": (
        lambda o: (o.eigen(4), heavier(o), o.modalDamping(0.05), o.eigen(4)),
        lambda o: (heavier(o), o.eigen(4), o.modalDamping(0.05, 0.0, 0.0, 0.0))),
    "steps, then a heavier node and eigen again": (
        lambda o: (o.eigen(4), o.modalDamping(0.05), steps(o), heavier(o), o.eigen(4)),
        lambda o: (o.eigen(4), o.modalDamping(0.05), steps(o), heavier(o), o.eigen(4), o.modalDamping(0.0))),
}


@pytest.mark.parametrize("case", list(CASES))
def test_modal_damping_damps_the_modes_of_the_latest_eigen_as_opensees(case, difference):
    script, other = CASES[case]
    reference = history(oracle, script)
    assert difference(reference, history(vops, script)) < RTOL
    assert difference(reference, history(oracle, other)) > 1e3 * RTOL


def test_a_change_of_the_modes_without_eigen_again_is_refused(one_line):
    """OpenSees would damp, with the new masses, the eigenvectors of the old model (and exits on
    a node the last eigen did not know): vtsi asks for ``eigen`` again, in the script's syntax."""
    beam(vops)
    vops.eigen(4)
    vops.modalDamping(0.05)
    heavier(vops)
    with pytest.raises(CommandError) as exc:
        vops.analyze(1, 0.005)
    assert one_line(exc) == ("analyze: the model changed after the last eigen (its dofs, stiffness or mass), whose "
                             "modes modalDamping damps; call eigen(n) again")
    vops.eigen(4)
    assert vops.analyze(1, 0.005) == 0


# -- a bridge script ------------------------------------------------------------------------
REEIGEN = ("ops.eigen(4)\nops.modalDamping(0.02, 0.01, 0.03, 0.04)\n"
           "ops.mass(6, 0.0, 30000.0, 0.0)\nops.eigen(3)\n")
IN_ORDER = "ops.mass(6, 0.0, 30000.0, 0.0)\nops.eigen(3)\nops.modalDamping(0.02, 0.01, 0.03)\n"


def test_a_bridge_scripts_modal_damping_after_a_new_eigen(tmp_path, deck_script):
    """A bridge script whose modalDamping comes before a change of the deck and a new eigen(3):
    the sweep's modal bridge damps the new modes with the first three ratios, as the same script
    with its modalDamping after the change and eigen does (before: the script was refused)."""
    (tmp_path / "reeigen.py").write_text(deck_script(0.6948, REEIGEN))
    (tmp_path / "in_order.py").write_text(deck_script(0.6948, IN_ORDER))
    (tmp_path / "before.py").write_text(deck_script(0.6948, "ops.eigen(4)\nops.modalDamping(0.02, 0.01, 0.03, 0.04)\n"))
    bridge, same = script_bridge(tmp_path / "reeigen.py"), script_bridge(tmp_path / "in_order.py")
    assert bridge.modal_damping == same.modal_damping
    assert [z for _, z in bridge.modal_damping] == [0.02, 0.01, 0.03]
    old = script_bridge(tmp_path / "before.py").modal_damping
    assert bridge.modal_damping[0][0] < 0.97 * old[0][0]          # the heavier deck's modes: new frequencies
    runs = [Sweep(b, ["HSLM-A1"], "300", PassageSettings(bridge="modal")).runner.modal for b in (bridge, same)]
    np.testing.assert_array_equal(runs[0].frequencies, runs[1].frequencies)
    np.testing.assert_array_equal(runs[0].zeta, runs[1].zeta)
    assert sorted(runs[0].zeta[runs[0].zeta > 0]) == [0.01, 0.02, 0.03]      # eigen(3)'s modes: all bend the deck


def test_a_bridge_script_that_changes_its_modes_after_modal_damping_is_refused(tmp_path, deck_tcl, one_line):
    path = tmp_path / "stale.tcl"
    path.write_text(deck_tcl("eigen 4\nmodalDamping 0.02\nmass 6 0.0 30000.0 0.0\n"))
    with pytest.raises(BridgeModelError) as exc:
        script_bridge(path)
    assert one_line(exc) == (f"bridge script {path}: the model changed after the last eigen (its dofs, stiffness or "
                             'mass), whose modes modalDamping damps; give the command "eigen n" again')
