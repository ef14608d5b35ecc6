"""Small differences of the command layer from OpenSeesPy 3.7.1, fixed and checked against
OpenSeesPy itself (the oracle, relative 1e-7): ``rayleigh`` after ``eigen`` + ``modalDamping``
runs as OpenSees (both apply); ``fix`` of a dof already fixed is refused as OpenSees refuses it;
the element responses OpenSeesPy answers for linear elastic elements (``basicDeformation``,
``chordRotation``, ``basicStiffness``, ``xaxis``...) are answered with its numbers, by
``eleResponse`` and by ``recorder Element``.
"""
import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.errors import CommandError, ModelError  # noqa: E402

RTOL = 1e-7
pytestmark = pytest.mark.usefixtures("fresh_session")


def assert_close(reference, value, what=""):
    """``value`` equals ``reference`` to :data:`RTOL` of the largest magnitude of ``reference``
    (entries that are zero up to round-off compared to that floor)."""
    reference, value = np.asarray(reference, dtype=float), np.asarray(value, dtype=float)
    assert reference.shape == value.shape, (what, reference.shape, value.shape)
    scale = max(float(np.abs(reference).max()) if reference.size else 0.0, 1e-300)
    np.testing.assert_allclose(value, reference, rtol=RTOL, atol=RTOL * scale, err_msg=what)


# -- rayleigh after eigen + modalDamping -----------------------------------------------------

def modal_beam(o, ratios):
    """A simply supported beam with nodal masses, its lowest 4 modes damped by ``ratios``."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    n = 6
    for i in range(n + 1):
        o.node(i + 1, 20.0 * i / n, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(n + 1, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for i in range(n):
        o.element("elasticBeamColumn", i + 1, i + 1, i + 2, 2.0, 3.0e10, 1.5, 1)
    for i in range(2, n + 1):
        o.mass(i, 2000.0, 2000.0, 5.0)
    o.eigen(4)
    o.modalDamping(*ratios)
    o.timeSeries("Trig", 1, 0.0, 0.3, 0.1)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e5, 0.0)


def history(o, steps, dt=0.005):
    out = []
    for _ in range(steps):
        o.analyze(1, dt)
        out.append(o.nodeDisp(4) + o.nodeVel(3))
    o.reactions()
    return np.array(out), np.array(o.nodeReaction(1) + o.nodeReaction(7))


@pytest.mark.parametrize("ratios", [(0.02,), (0.01, 0.03, 0.05, 0.02)])
def test_rayleigh_after_modal_damping_applies_both_as_opensees(ratios):
    """Before: 'analyze: the model changed after eigen and modalDamping; call them again'
    (``rayleigh`` rebuilds the assembly though K and M did not change)."""
    results = []
    for o in (oracle, vops):
        modal_beam(o, ratios)
        o.rayleigh(0.1, 0.0, 0.0, 0.0)
        o.integrator("Newmark", 0.5, 0.25)
        o.analysis("Transient")
        results.append(history(o, 20))
    for ref, val in zip(*results):
        assert_close(ref, val)


def test_rayleigh_changed_between_analyze_calls_with_modal_damping():
    """A mid-run ``rayleigh`` (after some steps with modal damping alone) applies from then on, as
    OpenSees; so does one between ``eigen`` and ``modalDamping``."""
    results = []
    for o in (oracle, vops):
        modal_beam(o, (0.02,))
        o.integrator("Newmark", 0.5, 0.25)
        o.analysis("Transient")
        first = history(o, 8)
        o.rayleigh(0.2, 0.0, 0.0, 0.0)
        results.append(first + history(o, 8))
    for ref, val in zip(*results):
        assert_close(ref, val)


def test_rayleigh_between_eigen_and_modal_damping():
    results = []
    for o in (oracle, vops):
        o.wipe()
        modal_beam(o, (0.02,))
        o.rayleigh(0.1, 0.0, 0.0, 0.0)     # after eigen: the modes are the same
        o.modalDamping(0.03)
        o.integrator("Newmark", 0.5, 0.25)
        o.analysis("Transient")
        results.append(history(o, 10))
    for ref, val in zip(*results):
        assert_close(ref, val)


def test_modal_damping_still_refused_after_a_change_of_the_modes(one_line):
    modal_beam(vops, (0.02,))
    vops.mass(3, 4000.0, 4000.0, 5.0)        # the modes of eigen no longer hold
    vops.integrator("Newmark", 0.5, 0.25)
    vops.analysis("Transient")
    with pytest.raises(CommandError) as exc:
        vops.analyze(1, 0.005)
    assert one_line(exc) == ("analyze: the model changed after the last eigen (its dofs, stiffness or mass), "
                             "whose modes modalDamping damps; call eigen(n) again")
    modal_beam(vops, (0.02,))
    vops.eigen(4)
    vops.node(99, 3.0, 3.0)                  # a new node: new dofs
    vops.fix(99, 1, 1, 1)
    vops.modalDamping(0.02)                  # kept, as OpenSees keeps it, for the modes of a new eigen
    vops.analysis("Transient")
    with pytest.raises(CommandError, match="model changed after the last eigen") as exc:
        vops.analyze(1, 0.005)
    one_line(exc)


# -- fix of a dof already fixed ----------------------------------------------------------------

def two_nodes(o):
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    o.node(1, 0.0, 0.0)
    o.node(2, 5.0, 0.0)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 1.0, 1e9, 1.0, 1)


def test_fix_of_a_fixed_dof_is_refused_as_opensees(one_line):
    """Before: accepted silently. OpenSees: 'Domain::addSP_Constraint - cannot add as node
    already constrained in that dof by existing SP_Constraint'."""
    two_nodes(oracle)
    oracle.fix(1, 1, 1, 1)
    with pytest.raises(Exception):
        oracle.fix(1, 1, 1, 1)
    two_nodes(vops)
    vops.fix(1, 1, 1, 1)
    with pytest.raises(ModelError) as exc:
        vops.fix(1, 1, 1, 1)
    assert one_line(exc) == ("fix node 1: dof 1 is already fixed (a second fix of a dof is refused, as OpenSees); "
                             "fix each dof once, with 0 for the dofs fixed before")
    two_nodes(vops)
    vops.fix(1, 1, 0, 0)
    with pytest.raises(ModelError, match="fix node 1: dof 1 is already fixed"):
        vops.fix(1, 1, 1, 0)                 # OpenSees refuses it too (and then leaves uy free)
    assert vops.session.domain.fixities[1] == (1, 0, 0)    # unchanged by the refused call
    vops.fix(1, 0, 1, 0)
    vops.fix(1, 0, 0, 1)
    assert vops.session.domain.fixities[1] == (1, 1, 1)
    with pytest.raises(ModelError, match="fix node 1: dof 3 is already fixed"):
        vops.fix(1, 0, 0, 1)


def test_fix_of_a_prescribed_dof_and_sp_of_a_fixed_dof_are_refused(one_line):
    two_nodes(vops)
    vops.fix(1, 1, 0, 1)
    vops.timeSeries("Linear", 1)
    vops.pattern("Plain", 1, 1)
    vops.sp(1, 2, 0.01)
    with pytest.raises(ModelError) as exc:
        vops.fix(1, 0, 1, 0)
    assert one_line(exc) == ("fix node 1: dof 2 has a prescribed displacement (sp in pattern 1); it cannot "
                             "also be fixed")
    with pytest.raises(ModelError) as exc:
        vops.sp(1, 1, 0.02)
    assert one_line(exc) == "sp node 1 dof 1: the dof is already fixed or constrained"


def test_fixing_other_dofs_in_later_calls_equals_opensees():
    results = []
    for o in (oracle, vops):
        two_nodes(o)
        o.fix(1, 1, 0, 0)
        o.fix(1, 0, 1, 0)
        o.fix(1, 0, 0, 1)
        o.timeSeries("Linear", 1)
        o.pattern("Plain", 1, 1)
        o.load(2, 10.0, -1.0, 0.0)
        o.analysis("Static")
        o.analyze(1)
        o.reactions()
        results.append(o.nodeDisp(2) + o.nodeReaction(1))
    assert_close(*results)


# -- element responses -------------------------------------------------------------------------

NEW_RESPONSES = ("basicDeformation", "basicDeformations", "chordRotation", "chordDeformation", "basicStiffness",
                 "xaxis", "yaxis", "zaxis")
ELEMENTS = {1: "elasticBeamColumn", 2: "zeroLength (3 materials, -orient)", 3: "truss",
            4: "ElasticTimoshenkoBeam", 5: "zeroLength (1 material)"}
ANSWERED = {   # what OpenSeesPy 3.7.1 answers with values (measured); the other NEW_RESPONSES it returns []
    1: NEW_RESPONSES,
    2: ("basicDeformation", "basicStiffness", "xaxis", "yaxis", "zaxis"),
    3: ("basicDeformation", "basicDeformations", "basicStiffness"),
    4: ("xaxis", "yaxis", "zaxis"),
    5: ("basicDeformation", "basicStiffness", "xaxis", "yaxis", "zaxis"),
}
VTSI_ONLY = {(2, "basicDeformations"), (5, "basicDeformations")}   # OpenSeesPy: [] (documented)


def frame(o, recorders=None):
    """An inclined beam, a Timoshenko beam, a truss and two zeroLength elements (one with an
    Elastic, an Elastic with eta and a Viscous material on directions 2, 1, 6 and 1, oriented
    with yp on the negative side) under static loads."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0.0, 0.0), (2, 4.0, 3.0), (3, 4.0, 3.0), (4, 8.0, 3.0), (5, 4.0, 3.0)):
        o.node(tag, x, y)
    o.fix(1, 1, 1, 1)
    o.fix(4, 1, 1, 1)
    o.fix(5, 1, 1, 1)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 0.01, 2e11, 1e-4, 1)
    o.uniaxialMaterial("Elastic", 1, 1e6)
    o.uniaxialMaterial("Elastic", 2, 3e6, 50.0)
    o.uniaxialMaterial("Viscous", 3, 70.0, 1.0)
    o.element("zeroLength", 2, 2, 3, "-mat", 1, 2, 1, 3, "-dir", 2, 1, 6, 1, "-orient", 0.6, 0.8, 0, 0.8, -0.6, 0)
    o.element("truss", 3, 3, 4, 0.01, 1)
    o.element("ElasticTimoshenkoBeam", 4, 1, 3, 2e11, 8e10, 0.01, 1e-4, 0.008, 1)
    o.element("zeroLength", 5, 3, 5, "-mat", 2, "-dir", 2)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.load(2, 1000.0, -2000.0, 50.0)
    o.load(3, 300.0, 400.0, 20.0)
    for args in recorders or ():
        o.recorder(*args)
    o.analysis("Static")
    o.analyze(3)


def test_element_responses_equal_opensees():
    """Before: every one refused ('has no response ...'); OpenSeesPy answers them. Where it
    returns [], vtsi does too (with a warning: tests/test_command_cm.py)."""
    frame(oracle)
    expected = {(e, n): oracle.eleResponse(e, n) for e in ELEMENTS for n in NEW_RESPONSES}
    frame(vops)
    for (e, name), ref in expected.items():
        if name in ANSWERED[e]:
            assert ref, (e, name)
            assert_close(ref, vops.eleResponse(e, name), f"element {e} ({ELEMENTS[e]}) {name}")
        elif (e, name) in VTSI_ONLY:
            assert ref == [], (e, name)
            assert_close(vops.eleResponse(e, "basicDeformation"), vops.eleResponse(e, name))
        else:
            assert ref == [] == vops.eleResponse(e, name), (e, name)


def test_zero_length_basic_stiffness_layout():
    """One row and column per material in -dir order: diag(1e6, 3e6, 1e6, 0) (the Viscous one has
    no stiffness), 4 x 4 row by row."""
    frame(vops)
    assert vops.eleResponse(2, "basicStiffness") == list(np.diag([1e6, 3e6, 1e6, 0.0]).ravel())
    assert vops.eleResponse(1, "basicStiffness") == [4e8, 0, 0, 0, 1.6e7, 8e6, 0, 8e6, 1.6e7]


@pytest.mark.parametrize("name", ["basicDeformation", "chordRotation", "basicStiffness", "xaxis", "yaxis"])
def test_element_recorder_of_the_new_responses_equals_opensees(tmp_path, name):
    """``recorder Element`` computes the new kinds vectorised over elements and steps (the type's
    response kernel) and writes OpenSees's columns; here the zeroLength elements (one column per
    material) go to a recorder of their own (mixed recorders: tests/test_command_compat.py)."""
    groups = [[e for e in ELEMENTS if name in ANSWERED[e] and (e in (2, 5)) == zero_length]
              for zero_length in (False, True)]
    groups = [g for g in groups if g]
    for label, o in (("ops", oracle), ("vtsi", vops)):
        frame(o, [("Element", "-file", str(tmp_path / f"{label}{k}.out"), "-time", "-precision", 12, "-ele", *g, name)
                  for k, g in enumerate(groups)])
        o.wipe()                        # closes the files
    for k in range(len(groups)):
        ref, val = (np.loadtxt(tmp_path / f"{label}{k}.out", ndmin=2) for label in ("ops", "vtsi"))
        assert ref.shape[0] == 3 and ref.shape[1] > 1
        assert_close(ref, val, f"{name} of elements {groups[k]}")


def loaded_frame(o, outdir):
    """An inclined propped cantilever under a uniform and a point element load (static, two
    load steps), recording ``basicDeformation`` of both elements; returns the responses of
    element 1 after each step and the recorder's file."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    o.node(1, 0.0, 0.0)
    o.node(2, 4.0, 3.0)
    o.node(3, 8.0, 6.0)
    o.fix(1, 1, 1, 1)
    o.fix(3, 1, 1, 0)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 0.02, 2e11, 3e-4, 1)
    o.element("elasticBeamColumn", 2, 2, 3, 0.02, 2e11, 3e-4, 1)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.eleLoad("-ele", 1, 2, "-type", "-beamUniform", -2000.0, 300.0)
    o.eleLoad("-ele", 1, "-type", "-beamPoint", -5000.0, 0.3, 800.0)
    o.recorder("Element", "-file", str(outdir / "deformation.out"), "-precision", 12, "-ele", 1, 2, "basicDeformation")
    o.integrator("LoadControl", 0.5)
    o.analysis("Static")
    rows = []
    for _ in range(2):
        assert o.analyze(1) == 0
        rows.append([x for name in ("localForce", "basicForce", "basicDeformation", "chordRotation", "basicStiffness",
                                    "xaxis", "yaxis") for x in o.eleResponse(1, name)])
    o.wipe()
    return np.array(rows), np.loadtxt(outdir / "deformation.out", ndmin=2)


def test_the_responses_of_a_loaded_beam_equal_opensees(tmp_path):
    """Before: the deformations, axes and stiffness of a beam with element loads were refused
    (the command layer and the recorder subtracted fixed-end forces from every kind). Element
    loads change only the forces (``unloaded_responses``): equal to OpenSeesPy, forces too."""
    (tmp_path / "ref").mkdir()
    (tmp_path / "val").mkdir()
    (ref, ref_file), (val, val_file) = loaded_frame(oracle, tmp_path / "ref"), loaded_frame(vops, tmp_path / "val")
    assert_close(ref, val, "eleResponse of a loaded beam")
    assert_close(ref_file, val_file, "recorder Element basicDeformation of loaded beams")
    assert np.abs(ref_file).max() > 1e-6


def released_and_refixed(o):
    """OpenSees's staged idiom: a support clamped, its rotation released by ``remove sp`` (the
    fix, no pattern), a static load, then the rotation fixed again by a second ``fix``."""
    two_nodes(o)
    o.node(3, 10.0, 0.0)
    o.element("elasticBeamColumn", 2, 2, 3, 1.0, 1e9, 1.0, 1)
    o.fix(1, 1, 1, 1)
    o.fix(3, 0, 1, 0)
    o.remove("sp", 1, 3)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.load(2, 10.0, -1000.0, 50.0)
    o.constraints("Transformation")
    o.integrator("LoadControl", 1.0)
    o.analysis("Static")
    assert o.analyze(1) == 0
    o.reactions()
    released = o.nodeDisp(1) + o.nodeDisp(2) + o.nodeReaction(1) + o.nodeReaction(3)
    o.fix(1, 0, 0, 1)
    return released


def test_remove_sp_frees_a_fixed_dof_which_may_be_fixed_again():
    """Before: ``remove sp 1 3`` said 'node 1 dof 3 has no prescribed displacement' (vtsi looked
    in the patterns only) and the re-fix was refused as a second fix; OpenSees removes the
    domain's constraint (the support becomes a pin) and accepts the later fix."""
    ref, val = released_and_refixed(oracle), released_and_refixed(vops)
    assert abs(ref[2]) > 1e-6                     # the released rotation moves
    assert_close(ref, val, "released support")


def test_element_loads_are_computed_once_per_version_of_their_pattern(monkeypatch):
    """A query per element read every element's loads again (a 400-element beam: 3.4-4.1 ms per
    eleResponse, 1-2 µs in OpenSeesPy): now once per version of the pattern's loads."""
    from vtsi.elements.beam_column import ElasticBeamColumn2d
    calls = []
    original = ElasticBeamColumn2d.equivalent_loads
    monkeypatch.setattr(ElasticBeamColumn2d, "equivalent_loads",
                        lambda self, *args: calls.append(1) or original(self, *args))
    vops.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(9):
        vops.node(i + 1, float(i), 0.0)
    vops.fix(1, 1, 1, 0)
    vops.fix(9, 0, 1, 0)
    vops.geomTransf("Linear", 1)
    for e in range(1, 9):
        vops.element("elasticBeamColumn", e, e, e + 1, 1.0, 1e9, 1.0, 1)
    vops.timeSeries("Linear", 1)
    vops.pattern("Plain", 1, 1)
    vops.eleLoad("-range", 1, 8, "-type", "-beamUniform", -1000.0)
    vops.integrator("LoadControl", 1.0)
    vops.analysis("Static")
    calls.clear()
    vops.analyze(1)
    for _ in range(3):
        shears = [vops.eleResponse(e, "localForce")[1] for e in range(1, 9)]
        vops.reactions()
    assert len(calls) == 8                        # each element's load once, whatever the queries
    assert shears == pytest.approx([1000.0 * (5 - e) for e in range(1, 9)], rel=1e-9, abs=1e-6)   # q (L/2 - x)


def test_reactions_under_modal_damping_are_opensees_s(tmp_path):
    """A script's ``modalDamping`` steps every mode of the model (lumped masses: one per dof with
    mass, the massless rotation following statically), so its reactions are the FE model's and
    are recorded: the Node recorder's ``reaction`` file equals OpenSeesPy's running the same
    script (the beam of tests/test_opensees_small_fixes.py, a Trig load at node 3)."""
    files = {}
    for o, name in ((oracle, "ops"), (vops, "vtsi")):
        modal_beam(o, (0.02,))
        files[name] = tmp_path / f"{name}.out"
        o.recorder("Node", "-file", str(files[name]), "-time", "-precision", 12, "-node", 1, 7, "-dof", 1, 2,
                   "reaction")
        o.integrator("Newmark", 0.5, 0.25)
        o.analysis("Transient")
        for _ in range(40):
            o.analyze(1, 0.005)
        o.wipe()
    ref, got = (np.loadtxt(files[name]) for name in ("ops", "vtsi"))
    assert ref.shape == got.shape == (40, 5) and np.abs(ref[:, 1:]).max() > 1e4
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * np.abs(ref).max())

