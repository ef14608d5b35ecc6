"""What a probe of the command layer against OpenSeesPy 3.7.1 found, each fix checked against
OpenSeesPy itself (the oracle), Tcl's own reading of a word, or the command layer's own list:

* ``recorder Element``/``EnvelopeElement`` over elements of different types writes one row, each
  element's columns in turn, as OpenSees (it was refused); an element without the response gets
  no columns, as in OpenSees;
* a list where one number is expected (Tcl ``node 3 {4.0 1.0}``, ``$props``; Python
  ``node(3, [4.0, 1.0])``) is refused naming the command, the argument and the list (it was
  spread over several arguments); lists stay lists where OpenSees takes one (``-values {0 1 2}``);
* ``eleResponse 1 section 1 force`` gives [] as OpenSees, and its warning lists the names the
  element answers, those of ``eleResponse 1 foo`` (tests/test_command_cm.py);
* a user element's option without its value is named as the shipped elements name it.
"""
import logging
import re

import h5py
import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.errors import CommandError  # noqa: E402

RTOL = 1e-7
pytestmark = pytest.mark.usefixtures("fresh_session")


# -- recorder Element over elements of different types -----------------------------------------

def mixed(o, recorders):
    """A beam and a Timoshenko beam in line on a roller, a two-material zeroLength (one with eta)
    to the ground at the far end, two inclined trusses to the beams' joint; five Newmark steps
    under a ramp load with stiffness-proportional damping, recording ``recorders`` (argument
    tuples of ``recorder``). Returns after ``wipe`` (the files closed)."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0.0, 0.0), (2, 5.0, 0.0), (3, 10.0, 0.0), (4, 10.0, 0.0), (5, 5.0, -3.0), (6, 3.0, 4.0)):
        o.node(tag, x, y)
    o.fix(1, 1, 1, 0)
    for n in (4, 5, 6):
        o.fix(n, 1, 1, 1)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 1.0, 3e10, 0.1, 1, "-mass", 100.0)
    o.element("ElasticTimoshenkoBeam", 2, 2, 3, 3e10, 1.2e10, 1.0, 0.1, 0.8, 1, "-mass", 100.0)
    o.uniaxialMaterial("Elastic", 1, 1e9)
    o.uniaxialMaterial("Elastic", 2, 2e9, 1e6)
    o.element("zeroLength", 3, 4, 3, "-mat", 1, 2, "-dir", 1, 2)
    o.element("truss", 4, 5, 2, 0.01, 1)
    o.element("truss", 5, 6, 2, 0.02, 1)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.load(2, 1e4, -1e5, 3e3)
    for args in recorders:
        o.recorder(*args)
    o.rayleigh(0.0, 0.0, 0.0, 1e-3)
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")
    o.analyze(5, 0.01)
    o.wipe()


def assert_same_file(reference, value, envelope):
    """Two OpenSees text files with ``-time``: the same lines of the same number of words, the
    values equal to :data:`RTOL` of the file's largest magnitude and, in an envelope (``t v``
    pairs), the same times where a value is above round-off."""
    ref_lines, val_lines = reference.read_text().splitlines(), value.read_text().splitlines()
    assert [len(line.split()) for line in val_lines] == [len(line.split()) for line in ref_lines]
    ref, val = np.loadtxt(reference, ndmin=2), np.loadtxt(value, ndmin=2)
    times, values = (slice(0, None, 2), slice(1, None, 2)) if envelope else (slice(0, 1), slice(1, None))
    scale = np.abs(ref[:, values]).max()
    assert scale > 0.0
    np.testing.assert_allclose(val[:, values], ref[:, values], rtol=RTOL, atol=RTOL * scale)
    kept = np.abs(ref[:, values]) > 1e-6 * scale if envelope else np.ones(ref[:, times].shape, dtype=bool)
    np.testing.assert_array_equal(val[:, times][kept], ref[:, times][kept])


MIXED = [   # (elements, response, values per row OpenSees writes: each element's in turn)
    ((1, 4), "force", 6 + 6),                   # a beam, then a truss spanning the 3 dofs of its nodes
    ((1, 2, 4), "force", 6 + 6 + 6),            # two beams and a truss (the probe's 18 values)
    ((1, 3), "localForce", 6 + 2),              # a beam's N V M per node, the zeroLength's force per material
    ((4, 5, 1), "localForce", 6 + 6 + 6),       # two trusses (rearranged together) spanning the 3 dofs, a beam
    ((3, 4), "deformation", 2 + 1),             # one per material, the truss's elongation
    ((4, 1, 3), "basicForce", 1 + 3 + 2),       # in the order given
    ((1, 5, 3), "basicDeformation", 3 + 1 + 2),
]


@pytest.mark.parametrize("kind", ["Element", "EnvelopeElement"])
@pytest.mark.parametrize("elements, response, width", MIXED, ids=[f"{r}{e}" for e, r, _ in MIXED])
def test_a_recorder_over_several_element_types_equals_opensees(tmp_path, kind, elements, response, width):
    """Before: refused ('the elements [1, 4] need different responses; record them with separate
    recorders'). Now the file OpenSeesPy writes: its lines, its columns, its values (and in an
    envelope the times of the extremes)."""
    for label, o in (("ops", oracle), ("vtsi", vops)):
        mixed(o, [(kind, "-file", str(tmp_path / f"{label}.out"), "-time", "-precision", 10, "-ele", *elements,
                   response)])
    envelope = kind == "EnvelopeElement"
    ref = np.loadtxt(tmp_path / "ops.out", ndmin=2)
    assert ref.shape == ((3, 2 * width) if envelope else (5, 1 + width))
    assert_same_file(tmp_path / "ops.out", tmp_path / "vtsi.out", envelope)


def test_an_element_without_the_response_gets_no_columns_as_in_opensees(tmp_path, caplog):
    """The Timoshenko beam has no ``basicForce`` in OpenSees: OpenSeesPy writes the beam's 3 and
    the zeroLength's 2 values; vtsi too, and a warning names the element left out."""
    def recorder(label):
        return ("Element", "-file", str(tmp_path / f"{label}.out"), "-time", "-precision", 10, "-ele", 1, 2, 3,
                "basicForce")
    mixed(oracle, [recorder("ops")])
    with caplog.at_level(logging.WARNING, logger="vtsi.commands.recorder_commands"):
        mixed(vops, [recorder("vtsi")])
    assert np.loadtxt(tmp_path / "ops.out", ndmin=2).shape == (5, 1 + 3 + 2)
    assert_same_file(tmp_path / "ops.out", tmp_path / "vtsi.out", False)
    assert ("recorder Element basicForce: element 2 (ElasticTimoshenkoBeam) has no response 'basicForce' and gets no "
            "columns, as in OpenSees; the record holds those of elements 1, 3") in caplog.text


def test_a_mixed_hdf5_recorder_labels_each_column_with_its_element(tmp_path):
    """``-h5``: the values of the text file, each column labelled with its element and its
    component (1.. per element), as many per element as OpenSeesPy writes for it alone."""
    widths = []
    for e in (1, 4):
        mixed(oracle, [("Element", "-file", str(tmp_path / f"ops{e}.out"), "-ele", e, "force")])
        widths.append(np.loadtxt(tmp_path / f"ops{e}.out", ndmin=2).shape[1])
    mixed(vops, [("Element", "-file", str(tmp_path / "v.out"), "-precision", 17, "-ele", 1, 4, "force"),
                 ("Element", "-h5", str(tmp_path / "v.h5"), "-ele", 1, 4, "force")])
    with h5py.File(tmp_path / "v.h5", "r") as f:
        values = f["values"][:]
        element, component = f["columns/element"][:], f["columns/component"][:]
    np.testing.assert_allclose(values, np.loadtxt(tmp_path / "v.out", ndmin=2), rtol=1e-15)
    np.testing.assert_array_equal(element, np.repeat([1, 4], widths))
    np.testing.assert_array_equal(component, np.concatenate([np.arange(1, w + 1) for w in widths]))


# -- a list where one number is expected -------------------------------------------------------

def two_nodes(o):
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    o.node(1, 0.0, 0.0)
    o.node(2, 10.0, 0.0)
    o.fix(1, 1, 1, 1)
    o.geomTransf("Linear", 1)
    o.timeSeries("Constant", 1)
    o.pattern("Plain", 1, 1)


LIST_MESSAGE = r", got a list of {n} \({items}\); give each value as its own argument$"
PYTHON_LISTS = [   # (command, arguments, the argument named, the list's items)
    ("node", (3, [4.0, 1.0]), "node: coordinate 1 of node 3 must be a number", "4.0 1.0"),
    ("node", (3, 4.0, 1.0, "-mass", [1.0, 1.0, 1.0]), r"node 3: -mass \(one per dof\) must be a number",
     "1.0 1.0 1.0"),
    ("fix", (2, [0, 1, 0]), "fix: fix flag of node 2 must be an integer", "0 1 0"),
    ("mass", (2, [100.0, 100.0, 0.0]), "mass: mass of node 2 must be a number", "100.0 100.0 0.0"),
    ("element", ("elasticBeamColumn", 1, 1, 2, [5.0, 3e10], 1.0, 1), "element elasticBeamColumn 1: A must be a number",
     "5.0 30000000000.0"),
    ("load", (2, [0.0, -1000.0], 0.0), "load: load on node 2 must be a number", "0.0 -1000.0"),
]


@pytest.mark.parametrize("command, args, argument, items", PYTHON_LISTS, ids=[c[0] + str(i) for i, c in
                                                                              enumerate(PYTHON_LISTS)])
def test_a_python_list_for_one_number_is_refused_as_opensees_refuses_it(one_line, command, args, argument, items):
    """Before: the list was spread over the arguments (``node(3, [4.0, 1.0])`` made node 3 at
    (4, 1)). OpenSeesPy raises; vtsi names the command, the argument and the list."""
    two_nodes(oracle)
    with pytest.raises(oracle.OpenSeesError):
        getattr(oracle, command)(*args)
    two_nodes(vops)
    before = (vops.getNodeTags(), vops.getEleTags())
    with pytest.raises(CommandError) as exc:
        getattr(vops, command)(*args)
    assert re.match("^" + argument + LIST_MESSAGE.format(n=len(items.split()), items=items), one_line(exc))
    assert (vops.getNodeTags(), vops.getEleTags()) == before


TCL_LISTS = [   # (script, the argument named, the list's items)
    ("node 3 {4.0 1.0}", "node: coordinate 1 of node 3 must be a number", "4.0 1.0"),
    ("fix 2 {0 1 0}", "fix: fix flag of node 2 must be an integer", "0 1 0"),
    ("mass 2 {100 100 0}", "mass: mass of node 2 must be a number", "100 100 0"),
    ("element elasticBeamColumn 1 1 2 {5.0 3e10} 1.0 1", "element elasticBeamColumn 1: A must be a number",
     "5.0 30000000000.0"),
    ('set props "5.0 3e10 1.0"; element elasticBeamColumn 2 1 2 $props 1',
     "element elasticBeamColumn 2: A must be a number", "5.0 30000000000.0 1.0"),
    ("pattern Plain 2 1 { load 2 {0 -1000} 0 }", "load: load on node 2 must be a number", "0 -1000"),
    ("uniaxialMaterial Elastic 1 {2e6 5}", "uniaxialMaterial Elastic 1: E must be a number", "2000000.0 5"),
]


@pytest.mark.parametrize("script, argument, items", TCL_LISTS, ids=[c[0].split()[0] + str(i) for i, c in
                                                                    enumerate(TCL_LISTS)])
def test_a_tcl_list_for_one_number_is_refused_as_opensees_refuses_it(tcl, one_line, script, argument, items):
    """Before: accepted, the braced word spread over the arguments. OpenSees's Tcl reads a braced
    word as one word, with ``Tcl_GetDouble``, which fails on it (Tcl's own ``string is double``
    says so); vtsi names the command, the argument and the list."""
    two_nodes(vops)
    assert tcl.eval(f'string is double -strict "{items}"') == "0"
    before = (vops.getNodeTags(), vops.getEleTags())
    with pytest.raises(CommandError) as exc:
        tcl.eval(script)
    assert re.match("^" + argument + LIST_MESSAGE.format(n=len(items.split()), items=items), one_line(exc))
    assert (vops.getNodeTags(), vops.getEleTags()) == before


def test_lists_stay_lists_where_opensees_takes_one(tcl):
    """``-values``/``-time`` take a list as one word (Tcl ``{...}``, ``$v``; a Python list or
    array too): the series of the spread numbers. Tcl's ``eval`` expands a list into words, as
    Tcl does: ``eval node 3 $xy`` is ``node 3 4.0 1.0``."""
    two_nodes(vops)
    tcl.eval("timeSeries Path 2 -dt 0.1 -values {0 1 0.5}; set v {0 2 1}; timeSeries Path 3 -time {0 1 3} -values $v")
    vops.timeSeries("Path", 4, "-dt", 0.1, "-values", 0.0, 1.0, 0.5)
    vops.timeSeries("Path", 5, "-time", np.array([0.0, 1.0, 3.0]), "-values", [0.0, 2.0, 1.0])
    series = vops.session.domain.time_series
    t = np.linspace(0.0, 3.0, 31)
    np.testing.assert_array_equal(series[2](t), series[4](t))
    np.testing.assert_array_equal(series[3](t), series[5](t))
    np.testing.assert_allclose(series[5](np.array([0.5, 2.0])), [1.0, 1.5], rtol=1e-15)
    tcl.eval("set xy {4.0 1.0}; eval node 3 $xy")
    assert vops.nodeCoord(3) == [4.0, 1.0]


# -- eleResponse of a part of the element ------------------------------------------------------

def test_a_section_response_lists_what_the_element_answers(tmp_path, tcl, one_line, caplog):
    """Before: 'supported: force, globalForce, localForce, basicForce, deformation, axialForce (as
    the element type offers)', which the beam does not all answer. Now the names of ``eleResponse
    1 foo`` (one list for both), in the warning of a response the element has not (it gives [], as
    OpenSees: tests/test_command_cm.py); a ``recorder Element`` of a response OpenSees answers and
    vtsi does not (a zeroLength's ``material 1 stress``) is refused naming that element's."""
    two_nodes(vops)
    vops.element("elasticBeamColumn", 1, 1, 2, 5.0, 3e10, 1.0, 1)
    vops.node(3, 10.0, 0.0)
    vops.uniaxialMaterial("Elastic", 1, 1e6)
    vops.element("zeroLength", 2, 2, 3, "-mat", 1, "-dir", 2)
    valid = {}
    for e in (1, 2):
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="vtsi.commands.query_commands"):
            assert vops.eleResponse(e, "foo") == []
        valid[e] = caplog.records[0].getMessage().split(" (it answers ")[1].rstrip(")").split(", ")
    assert "deformation" not in valid[1] and "axialForce" not in valid[1] and "basicDeformation" in valid[1]
    for e, kind in ((1, "elasticBeamColumn"), (2, "zeroLength")):
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="vtsi.commands.query_commands"):
            assert tcl.eval(f"eleResponse {e} section 1 force") == ""
        assert [r.getMessage() for r in caplog.records] == [
            f"eleResponse {e} section 1 force: element {e} ({kind}) has no response 'section 1 force' and gives [], "
            f"as in OpenSees (it answers {', '.join(valid[e])})"]
    with pytest.raises(CommandError) as exc:
        vops.recorder("Element", "-file", str(tmp_path / "x.out"), "-ele", 1, 2, "material", 1, "stress")
    assert one_line(exc).split("; supported: ")[1].split(", ") == valid[2]


# -- a user element's option without its value -------------------------------------------------

def test_a_user_elements_option_without_its_value_is_named_as_the_shipped_ones(custom_element, one_line):
    """Before: 'element timoshenkoBeam 1: missing -mass'. Now the shipped elements' form, with the
    parameter the option sets: '-mass needs a value (rho), got none'."""
    two_nodes(vops)
    messages = []
    for args in (("ElasticTimoshenkoBeam", 1, 1, 2, 2e11, 8e10, 0.01, 1e-4, 0.008, 1, "-mass"),
                 ("timoshenkoBeam", 1, 1, 2, 0.01, 2e11, 1e-4, 8e10, 5.0 / 6.0, "-mass"),
                 ("timoshenkoBeam", 1, 1, 2, 0.01, 2e11, 1e-4, 8e10, 5.0 / 6.0, "-mass", "-x")):
        with pytest.raises(CommandError) as exc:
            vops.element(*args)
        messages.append(one_line(exc))
    assert messages[0] == "element ElasticTimoshenkoBeam 1: -mass needs a value (mass per unit length), got none"
    assert messages[1] == "element timoshenkoBeam 1: -mass needs a value (rho), got none"
    assert messages[2] == "element timoshenkoBeam 1: -mass needs a value (rho), got 0 ('-x' follows)"
