"""The command layer's other names of element responses (a beam's ``xlocal``, a truss's ``defo``),
OpenSees's partial uniform load, recorders of missing nodes and elements, and options given twice,
each checked against OpenSeesPy (the oracle; with VTSI_REQUIRE_ORACLES=1 a missing one fails:
tests/conftest.py)."""
import logging
import subprocess
import sys

import numpy as np
import pytest

import vtsi.opensees as vops
from vtsi.commands.analysis_commands import SYSTEMS
from vtsi.commands.responses import OPENSEES_ONLY_RESPONSES, TYPE_RESPONSE_ALIASES
from vtsi.errors import CommandError

oracle = pytest.importorskip("openseespy.opensees")

pytestmark = pytest.mark.usefixtures("fresh_session")


def static(ops, system="BandGeneral"):
    """One load step of a linear static analysis set up as OpenSees scripts do (``system`` as given)."""
    for command, args in (("system", (system,)), ("numberer", ("Plain",)), ("constraints", ("Plain",)),
                          ("integrator", ("LoadControl", 1.0)), ("algorithm", ("Linear",)), ("analysis", ("Static",))):
        getattr(ops, command)(*args)

TYPES = {1: "elasticBeamColumn", 2: "ElasticTimoshenkoBeam", 3: "truss", 4: "zeroLength"}
NAMES = sorted({"xaxis", "yaxis", "zaxis", "force", "localForce", "basicForce", "deformation", "basicDeformation",
                "offsets", "rigidOffsets"} | {a for aliases in TYPE_RESPONSE_ALIASES.values() for a in aliases})
VTSI_ONLY = {(3, "axialForces"), (4, "globalForce"), (4, "basicDeformations")}   # docs/commands.md


def four_elements(ops, steps=1):
    """One element of each type (a beam from (0,0) to (3,1)), loaded statically over ``steps`` steps."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0.0, 0.0), (2, 3.0, 1.0), (3, 6.0, 1.0), (4, 6.0, 1.0)):
        ops.node(tag, x, y)
    ops.fix(1, 1, 1, 1)
    ops.fix(4, 0, 0, 1)
    ops.geomTransf("Linear", 1)
    ops.element("elasticBeamColumn", 1, 1, 2, 0.1, 2e11, 1e-4, 1)
    ops.element("ElasticTimoshenkoBeam", 2, 2, 3, 2e11, 8e10, 0.1, 1e-4, 0.08, 1)
    ops.uniaxialMaterial("Elastic", 1, 1e6)
    ops.element("truss", 3, 1, 3, 0.01, 1)
    ops.element("zeroLength", 4, 3, 4, "-mat", 1, 1, "-dir", 1, 2)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(4, 1e3, 2e3, 0.0)
    ops.load(2, 0.0, -1e3, 10.0)
    static(ops)


@pytest.mark.parametrize("tag", sorted(TYPES), ids=TYPES.values())
def test_every_name_answers_as_opensees(tag, caplog):
    """Each name OpenSeesPy answers for the element, vtsi answers with its numbers (1e-9), refuses
    (OPENSEES_ONLY_RESPONSES) or, for three plurals, answers where OpenSees does not; a name
    OpenSeesPy answers with [] (a zeroLength's xlocal, a truss's xaxis) gives [] in vtsi too."""
    for ops in (oracle, vops):
        four_elements(ops)
        ops.analyze(1)
    answered = 0
    for name in NAMES:
        expected = oracle.eleResponse(tag, name)
        if name in OPENSEES_ONLY_RESPONSES.get(TYPES[tag], {}):
            assert expected, name
            with pytest.raises(CommandError, match=rf"response '{name}' of element {tag} .* is not supported"):
                vops.eleResponse(tag, name)
            continue
        with caplog.at_level(logging.WARNING):
            got = vops.eleResponse(tag, name)
        if (tag, name) in VTSI_ONLY:
            continue
        assert len(got) == len(expected), name
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9 * max(map(abs, expected), default=0.0))
        answered += bool(got)
    assert answered >= len(TYPE_RESPONSE_ALIASES[TYPES[tag]]) + 1


def test_beam_xlocal_is_its_axis():
    """The brief's case: a beam from (0,0) to (3,1), xlocal = (3, 1)/sqrt(10), as OpenSeesPy."""
    four_elements(vops)
    assert vops.eleResponse(1, "xlocal") == pytest.approx([3 / 10 ** 0.5, 1 / 10 ** 0.5, 0.0], rel=1e-12)
    assert vops.eleResponse(1, "ylocal") == pytest.approx([-1 / 10 ** 0.5, 3 / 10 ** 0.5, 0.0], rel=1e-12)
    assert vops.eleResponse(2, "zlocal") == pytest.approx([0.0, 0.0, 1.0])


@pytest.mark.parametrize("response", ["xlocal", "ylocal", "deformatons", "defo", "globalforces"])
def test_recorder_of_an_alias_writes_opensees_file(tmp_path, response):
    """``recorder Element -time -ele 1 2 3 4 <alias>``: the same lines as OpenSeesPy's file (the
    elements that do not answer the name get no columns in both)."""
    texts = []
    for ops, where in ((oracle, tmp_path / "o.out"), (vops, tmp_path / "v.out")):
        four_elements(ops)
        ops.recorder("Element", "-file", str(where), "-time", "-ele", 1, 2, 3, 4, response)
        ops.analyze(2)
        ops.wipe()
        texts.append(np.loadtxt(where, ndmin=2))
    assert texts[0].shape == texts[1].shape and texts[0].shape[1] > 1
    np.testing.assert_allclose(texts[1], texts[0], rtol=1e-5, atol=1e-9 * np.abs(texts[0]).max())


def cantilever(ops, *extra):
    """A 4 m cantilever of one elasticBeamColumn under ``eleLoad -beamUniform -5e3 1e3 *extra``."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 4.0, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.geomTransf("Linear", 1)
    ops.element("elasticBeamColumn", 1, 1, 2, 0.1, 2e11, 1e-4, 1)
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    ops.eleLoad("-ele", 1, "-type", "-beamUniform", -5e3, 1e3, *extra)
    static(ops)
    ops.analyze(1)
    return ops.nodeDisp(2) + ops.eleResponse(1, "localForce")


@pytest.mark.parametrize("extra", [(0.0, 1.0), (0.0,)], ids=["aOverL 0 bOverL 1", "aOverL 0"])
def test_beam_uniform_over_the_whole_span_is_the_full_load(extra):
    """OpenSees builds its uniform load for aOverL 0 and bOverL 1 (or aOverL 0 alone): the same
    numbers as without them, in OpenSeesPy and in vtsi."""
    full = cantilever(oracle)
    assert cantilever(oracle, *extra) == pytest.approx(full, rel=1e-12)
    assert cantilever(vops, *extra) == pytest.approx(full, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("extra, message", [
    ((0.5, 1.0), r"eleLoad: -beamUniform with aOverL = 0.5, bOverL = 1 is a partial uniform load .* split the "
                 r"element at a and b"),
    ((0.0, 0.75), r"aOverL = 0, bOverL = 0.75 is a partial uniform load"),
    ((0.2,), r"aOverL = 0.2, bOverL = 1 is a partial uniform load"),
    ((0.0, 1.0, -2e3, 0.0), r"-beamUniform Wya Wxa aOverL bOverL Wyb Wxb \(a load varying"),
])
def test_partial_uniform_load_is_named(extra, message):
    """A partial (or varying) uniform load, which OpenSees applies and vtsi does not, is refused
    naming it and the remedy (it was 'unexpected argument 0.5'); OpenSees's numbers differ."""
    assert cantilever(oracle, *extra) != pytest.approx(cantilever(oracle), rel=1e-6)
    with pytest.raises(CommandError, match=message):
        cantilever(vops, *extra)


def recorded(ops, path, kind, *args):
    """The text of a recorder ``kind`` with ``args`` on four_elements after 2 steps, and its tag."""
    four_elements(ops)
    tag = ops.recorder(kind, "-file", str(path), *args)
    ops.analyze(2)
    ops.wipe()
    return path.read_text(), tag


@pytest.mark.parametrize("kind, args", [
    ("Element", ("-ele", 77, "force")), ("Element", ("-time", "-ele", 77, "force")),
    ("Element", ("-time", "-ele", 1, 77, 3, "force")), ("Node", ("-time", "-node", 2, 77, "-dof", 1, 2, "disp")),
], ids=["element", "element -time", "elements 1 77 3", "nodes 2 77"])
def test_recorder_of_a_missing_tag_is_opensees_file(tmp_path, caplog, kind, args):
    """A missing element or node gets no columns, as in OpenSeesPy (which says nothing; vtsi
    warns): a file of no values (with -time, the times), or the others' columns."""
    expected, _ = recorded(oracle, tmp_path / "o.out", kind, *args)
    with caplog.at_level(logging.WARNING):
        got, _ = recorded(vops, tmp_path / "v.out", kind, *args)
    assert any("77 does not exist and gets no columns, as in OpenSees" in r.getMessage() for r in caplog.records)
    assert got.count("\n") == expected.count("\n") == (2 if "-time" in args else 0)
    if expected.strip():
        np.testing.assert_allclose(np.loadtxt(tmp_path / "v.out", ndmin=2), np.loadtxt(tmp_path / "o.out", ndmin=2),
                                   rtol=1e-5, atol=1e-12)
    else:
        assert got == expected == ""


def test_node_recorder_of_missing_nodes_only_is_refused(tmp_path):
    """OpenSeesPy writes a file of no values; vtsi's node recorder needs a node: refused, named."""
    expected, _ = recorded(oracle, tmp_path / "o.out", "Node", "-node", 77, "-dof", 1, "disp")
    assert expected == ""
    with pytest.raises(CommandError, match=r"^recorder Node: node 77 does not exist \(OpenSees writes"):
        recorded(vops, tmp_path / "v.out", "Node", "-node", 77, "-dof", 1, "disp")


def first_frequency(ops, element):
    """ω² of a 2 m bar along x (node 2 free in x only) made by ``element(ops)``."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 2.0, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 0, 1, 1)
    ops.geomTransf("Linear", 1)
    ops.uniaxialMaterial("Elastic", 1, 1e6)
    element(ops)
    return ops.eigen("-fullGenLapack", 1)[0]


@pytest.mark.parametrize("element", [
    lambda o: o.element("elasticBeamColumn", 1, 1, 2, 0.1, 2e11, 1e-4, 1, "-mass", 10.0, "-mass", 20.0),
    lambda o: o.element("elasticBeamColumn", 1, 1, 2, 0.1, 2e11, 1e-4, 1, "-mass", 10.0, "-cMass", "-cMass"),
    lambda o: o.element("ElasticTimoshenkoBeam", 1, 1, 2, 2e11, 8e10, 0.1, 1e-4, 0.08, 1, "-mass", 10.0, "-mass", 20.0),
    lambda o: o.element("truss", 1, 1, 2, 0.1, 1, "-rho", 10.0, "-rho", 20.0),
    lambda o: o.element("truss", 1, 1, 2, 0.1, 1, "-rho", 10.0, "-cMass", 1, "-cMass", 0),
], ids=["beam -mass twice", "beam -cMass twice", "Timoshenko -mass twice", "truss -rho twice", "truss -cMass twice"])
def test_an_option_given_twice_takes_the_last_as_opensees(element):
    """OpenSees takes the last of an element's -mass, -rho or -cMass: so does vtsi (ω² equal)."""
    assert first_frequency(vops, element) == pytest.approx(first_frequency(oracle, element), rel=1e-9)


def zero_length(ops, *options):
    """Node 2's displacement under (1, 2) N on a zeroLength of materials 1 (1e6) and 2 (4e6)."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 0.0, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 0, 0, 1)
    ops.uniaxialMaterial("Elastic", 1, 1e6)
    ops.uniaxialMaterial("Elastic", 2, 4e6)
    ops.element("zeroLength", 1, 1, 2, "-mat", 1, 2, "-dir", 1, 2, *options)
    ops.timeSeries("Constant", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(2, 1.0, 2.0, 0.0)
    static(ops, "FullGeneral")
    ops.analyze(1)
    return ops.nodeDisp(2)


@pytest.mark.parametrize("options", [("-orient", 0.0, 1.0, 0.0), ("-orient", 1.0, 0.0, 0.0, "-orient", 0.0, 1.0, 0.0),
                                     ("-doRayleigh", 1, "-doRayleigh", 0)],
                         ids=["-orient x only", "-orient twice", "-doRayleigh twice"])
def test_zero_length_orient_as_opensees(options):
    """A 2-D -orient of x alone (OpenSees reads no yp in 2-D) and a second -orient or
    -doRayleigh (the last one counts) give OpenSeesPy's displacements."""
    assert zero_length(vops, *options) == pytest.approx(zero_length(oracle, *options), rel=1e-12, abs=1e-15)


def test_repeated_options_opensees_refuses_are_refused():
    """OpenSeesPy fails on a zeroLength's second -mat and a Linear or Constant series' second
    -factor (it reads their words by count): vtsi refuses them, naming the option."""
    for ops in (oracle, vops):
        ops.wipe()
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        ops.node(1, 0.0, 0.0)
        ops.node(2, 0.0, 0.0)
        ops.uniaxialMaterial("Elastic", 1, 1e6)
        ops.uniaxialMaterial("Elastic", 2, 4e6)
    for call in (lambda: oracle.element("zeroLength", 1, 1, 2, "-mat", 1, "-mat", 2, "-dir", 1),
                 lambda: oracle.timeSeries("Linear", 1, "-factor", 2.0, "-factor", 3.0),
                 lambda: oracle.timeSeries("Constant", 2, "-factor", 2.0, "-factor", 3.0)):
        with pytest.raises(oracle.OpenSeesError):
            call()
    with pytest.raises(CommandError, match=r"^element zeroLength 1: -mat given twice"):
        vops.element("zeroLength", 1, 1, 2, "-mat", 1, "-mat", 2, "-dir", 1)
    with pytest.raises(CommandError, match=r"^timeSeries Linear 1: option -factor given twice$"):
        vops.timeSeries("Linear", 1, "-factor", 2.0, "-factor", 3.0)
    with pytest.raises(CommandError, match=r"^timeSeries Constant 2: option -factor given twice$"):
        vops.timeSeries("Constant", 2, "-factor", 2.0, "-factor", 3.0)
    with pytest.raises(CommandError, match=r"^timeSeries Path 3: option -values given twice$"):
        vops.timeSeries("Path", 3, "-dt", 0.1, "-values", 0.0, 1.0, "-values", 2.0)


def test_every_system_name_is_one_opensees_accepts():
    """``system`` takes the names of OpenSees's direct solvers, each of which OpenSeesPy accepts
    (run one per process: OpenSeesPy has crashed setting several in one)."""
    script = ("import openseespy.opensees as ops\nops.wipe()\nops.model('basic', '-ndm', 2, '-ndf', 3)\n"
              "ops.system({!r})\nprint('accepted')\n")
    for name in SYSTEMS:
        vops.wipe()
        vops.model("basic", "-ndm", 2, "-ndf", 3)
        vops.system(name)
        run = subprocess.run([sys.executable, "-c", script.format(name)], capture_output=True, text=True, timeout=60)
        assert "accepted" in run.stdout and "unknown system" not in run.stdout + run.stderr, (name, run.stderr[-500:])
