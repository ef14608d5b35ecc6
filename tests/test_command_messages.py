"""Six messages of the command layer that misled, and getLoadFactor, each checked against
OpenSeesPy 3.7.1 (the oracle), Tcl's own number syntax or a closed form: a number list with one
bad item (it said "the -values list is empty"), an inline series' error (it named an internal
negative tag), a series tag given as a str, ``eleLoad -range`` over missing elements (it loaded
the others silently), a Node or Element recorder's response before an option or taken for the
file name, and ``getLoadFactor`` before the loads are applied (it was not 0)."""
import subprocess
import sys

import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.errors import CommandError  # noqa: E402
from vtsi.tcl import Interpreter  # noqa: E402

pytestmark = pytest.mark.usefixtures("fresh_session")
RTOL = 1e-9


def solver(o, integrator=("Newmark", 0.5, 0.25), analysis="Transient"):
    o.constraints("Plain")
    o.numberer("Plain")
    o.system("BandGeneral")
    o.test("NormDispIncr", 1e-12, 10)
    o.algorithm("Linear")
    o.integrator(*integrator)
    o.analysis(analysis)


def tcl_error(script, one_line):
    """The one-line message of the vtsi error that stops the Tcl ``script`` (after a 2-D model)."""
    interp = Interpreter(vops.Session())
    with pytest.raises(CommandError) as exc:
        interp.eval("model basic -ndm 2 -ndf 3; node 1 0 0; node 2 10 0; " + script)
    return one_line(exc)


# -- 1. a number list with one bad item ----------------------------------------------------------
@pytest.mark.parametrize("script, message", [
    ("timeSeries Path 1 -dt 0.1 -values {0 1 abc}", "timeSeries Path 1: -values item 3 is 'abc', not a number"),
    ("timeSeries Path 1 -dt 0.1 -values {0.0 1.0 2,5}", "timeSeries Path 1: -values item 3 is '2,5', not a number"),
    ("timeSeries Path 1 -dt 0.1 -values {0, 1, 2}", "timeSeries Path 1: -values item 1 is '0,', not a number"),
    ("timeSeries Path 1 -dt 0.1 -values 0,1,2", "timeSeries Path 1: -values item 1 is '0,1,2', not a number"),
    ("timeSeries Path 1 -dt 0.1 -values {0 1 nan}", "timeSeries Path 1: -values item 3 must be finite, got nan"),
    ("timeSeries Path 1 -dt 0.1 -values {0 Inf}", "timeSeries Path 1: -values item 2 must be finite, got inf"),
    ("timeSeries Path 1 -dt 0.1 -values {-Infinity 0}", "timeSeries Path 1: -values item 1 must be finite, got -inf"),
    ("timeSeries Path 1 -time {0 0.1 x} -values {0 1 2}", "timeSeries Path 1: -time item 3 is 'x', not a number"),
    ("timeSeries Path 1 -dt 0.1 -values {}", "timeSeries Path 1: the -values list is empty; give its numbers after "
                                             "-values"),
    ("pattern Plain 7 {Path -dt 0.1 -values {0 1 Inf}} {load 2 0 -1 0}",
     "pattern Plain 7: series Path: -values item 3 must be finite, got inf"),
])
def test_a_tcl_number_list_names_its_bad_item(script, message, one_line):
    """OpenSees's Tcl series command reads each item with Tcl_GetDouble and stops at the first it
    cannot read ("problem reading path data value"); vtsi names it and its position."""
    assert tcl_error(script, one_line) == message


@pytest.mark.parametrize("values, message", [
    ((0.0, 1.0, "abc"), "-values item 3 is 'abc', not a number"),
    (([0, 1, "x"],), "-values item 3 is 'x', not a number"),
    ((0.0, 1.0, "2"), "-values item 3 is '2', not a number"),
    ((0.0, float("nan")), "-values item 2 must be finite, got nan"),
    ((np.array([0.0, 1.0, np.inf]),), "-values item 3 must be finite, got inf"),
])
def test_a_python_number_list_names_its_bad_item(values, message, one_line):
    """From Python a str among the values (even '2') is refused: OpenSeesPy drops a word that
    follows the values (measured: -values 0 1 'abc' or '2' gives the series [0, 1])."""
    vops.model("basic", "-ndm", 2, "-ndf", 3)
    with pytest.raises(CommandError) as exc:
        vops.timeSeries("Path", 1, "-dt", 0.1, "-values", *values, "-factor", 2.0)
    assert one_line(exc) == f"timeSeries Path 1: {message}"


def test_tcl_number_syntax_in_a_list():
    """Exponents, a leading +, a bare point, hexadecimal, binary and 0o octal read as Tcl reads
    them: the expected values are Tcl's own (``expr {double($x)}``), not typed in."""
    words = "0 +1 1e0 0x1A .5 5. 1E-1 -0b101 0o17 2.5e+1"
    interp = Interpreter(vops.Session())
    interp.eval(f"model basic -ndm 2 -ndf 3; timeSeries Path 1 -dt 0.1 -values {{{words}}}")
    expected = [float(x) for x in interp.tcl.eval(f"lmap x {{{words}}} {{expr {{double($x)}}}}").split()]
    np.testing.assert_array_equal(interp.session.domain.time_series[1].values, expected)


# -- 2. an inline series' errors name the pattern --------------------------------------------------
@pytest.mark.parametrize("spec, message", [
    ("Path -dt 0.1 -values {0 1 0} -factor", "pattern Plain 7: series Path: missing -factor"),
    ("Path -time {0 0.2 0.1} -values {0 1 2}",
     "pattern Plain 7: series Path: times must increase strictly; time[2] = 0.1 follows time[1] = 0.2"),
    ("Trig 0 1 0", "pattern Plain 7: series Trig: period must be > 0, got 0.0"),
    ("Sine 0 1 0", "pattern Plain 7: series Sine: period must be > 0, got 0.0"),
    ("Linear -fact 2", "pattern Plain 7: series Linear: option '-fact' is not supported; supported: -factor"),
])
def test_an_inline_series_error_names_the_pattern(spec, message, one_line):
    """The same message at every attempt: the internal tag of an inline series (it counted -1,
    -2, ... from attempt to attempt) is not in it."""
    vops.model("basic", "-ndm", 2, "-ndf", 3)
    for _ in range(2):
        with pytest.raises(CommandError) as exc:
            vops.pattern("Plain", 7, spec)
        assert one_line(exc) == message


def test_an_inline_accel_series_error_names_the_pattern(one_line):
    script = 'mass 2 1 1 0; pattern UniformExcitation 9 2 -accel "Path -dt 0.1 -values {0 1 0} -factor"'
    assert tcl_error(script, one_line) == "pattern UniformExcitation 9: series Path: missing -factor"


# -- 3. a series tag given as a str ----------------------------------------------------------------
def test_a_series_tag_given_as_a_str_is_refused_as_openseespy_refuses_it(one_line):
    for o in (oracle, vops):
        o.wipe()
        o.model("basic", "-ndm", 2, "-ndf", 3)
        o.node(1, 0.0, 0.0)
        o.mass(1, 1.0, 1.0, 0.0)
        o.timeSeries("Linear", 1)
    for args in (("Plain", 2, "1"), ("UniformExcitation", 3, 1, "-accel", "1")):
        with pytest.raises(oracle.OpenSeesError):
            oracle.pattern(*args)
    with pytest.raises(CommandError) as exc:
        vops.pattern("Plain", 2, "1")
    assert one_line(exc) == "pattern Plain 2: the time series tag must be an integer, got '1'"
    with pytest.raises(CommandError) as exc:
        vops.pattern("UniformExcitation", 3, 1, "-accel", "1")
    assert one_line(exc) == "pattern UniformExcitation 3: the -accel time series tag must be an integer, got '1'"


def test_an_inline_series_string_still_works(mass_beam):
    """``'Constant -factor 2.0'`` with ``-fact 3``: the load factor 6 after a step (2 × 3)."""
    mass_beam(vops, n_el=2)
    vops.pattern("Plain", 2, "Constant -factor 2.0", "-fact", 3.0)
    vops.load(2, 0.0, -1.0, 0.0)
    solver(vops, ("LoadControl", 1.0), "Static")
    vops.analyze(1)
    assert vops.getLoadFactor(2) == 6.0


# -- 4. eleLoad -range over missing elements ------------------------------------------------------
def midspan_under_range(mass_beam, o, first, last):
    mass_beam(o, n_el=20)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.eleLoad("-range", first, last, "-type", "-beamUniform", -1e4)
    solver(o, ("LoadControl", 1.0), "Static")
    o.analyze(1)
    return o.nodeDisp(11, 2)


def test_eleload_range_over_missing_elements_is_refused(one_line, mass_beam):
    """OpenSeesPy loads the elements of the range that exist and warns for each missing one
    (its result equals the range of those alone, asserted); vtsi refuses the range as it
    refuses ``-ele`` with a missing tag, naming the missing tags compactly."""
    existing = midspan_under_range(mass_beam, oracle, 18, 20)
    assert existing != 0.0
    assert midspan_under_range(mass_beam, oracle, 18, 25) == existing
    assert abs(midspan_under_range(mass_beam, vops, 18, 20) - existing) <= RTOL * abs(existing)
    for (first, last), message in [((18, 25), "elements 21-25 do not exist"),
                                   ((21, 21), "element 21 does not exist"),
                                   ((25, 18), "the last element is before the first")]:
        with pytest.raises(CommandError) as exc:
            vops.eleLoad("-range", first, last, "-type", "-beamUniform", -1e4)
        assert one_line(exc) == f"eleLoad -range {first} {last}: {message}"
    vops.remove("element", 5)
    vops.remove("element", 7)
    vops.remove("element", 8)
    with pytest.raises(CommandError) as exc:
        vops.eleLoad("-range", 1, 22, "-type", "-beamUniform", -1e4)
    assert one_line(exc) == "eleLoad -range 1 22: elements 5, 7-8, 21-22 do not exist"


# -- 5. recorder: the response before an option, or taken for the file name ----------------------
@pytest.mark.parametrize("args, message", [
    (("Node", "-node", 2, "-dof", 2, "disp", "-file", "x.out"),
     "-dof: 'disp' is a response; the response comes last, after every option (... -dof 2 -file x.out disp)"),
    (("Node", "-file", "x.out", "disp", "-node", 2, "-dof", 2),
     "'disp' is a response; the response comes last, after every option (-file x.out -node 2 -dof 2 disp)"),
    (("Node", "-node", 2, "-dof", 2, "disp", "-file"), "-file needs a file name, got none"),
    (("Node", "-node", 2, "-dof", 2, "dsip", "-file", "x.out"),
     "'dsip' is neither a -dof (an integer) nor a response (disp, vel, accel, reaction, reactionIncInertia)"),
    (("Element", "-ele", 1, 2, "localForce", "-time"),
     "-ele: 'localForce' is a response; the response comes last, after every option (-ele 1 2 -time localForce)"),
    (("Node", "-node", 2, "-dof", 2, "-file", "disp"),
     "no response given: -file took 'disp' for its file name; give the file name after -file, the response last "
     "(-file out.txt disp)"),
    (("Element", "-ele", 1, "-h5", "force"),
     "no response given: -h5 took 'force' for its file name; give the file name after -h5, the response last "
     "(-h5 out.h5 force)"),
    (("Node", "-node", 2, "-dof", 2, "-file", "x.out"),
     "no response given (one of disp, vel, accel, reaction, reactionIncInertia)"),
])
def test_a_recorder_response_out_of_place_is_named(tmp_path, monkeypatch, args, message, one_line, mass_beam):
    """No file is created by a refused line."""
    monkeypatch.chdir(tmp_path)
    mass_beam(vops)
    with pytest.raises(CommandError) as exc:
        vops.recorder(*args)
    assert one_line(exc) == f"recorder {args[0]}: {message}"
    assert list(tmp_path.iterdir()) == []


def test_the_train_recorder_shares_the_file_name_message(one_line):
    """One implementation for the bridge and the train recorders: the same words."""
    session = vops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    with pytest.raises(CommandError) as exc:
        session.recorder("Train", "-dof", 2, "-file", "disp")
    assert one_line(exc) == ("recorder Train: no response given: -file took 'disp' for its file name; give the file "
                             "name after -file, the response last (-file out.txt disp)")
    with pytest.raises(CommandError) as exc:
        session.recorder("Train", "-file", "x.out")
    assert one_line(exc) == "recorder Train: no response given (one of disp, vel, accel)"


def test_openseespy_with_the_response_before_an_option(tmp_path):
    """What docs/commands.md says OpenSeesPy 3.7.1 does with these lines: an Element recorder
    records to the screen, not to the file after its response; a Node recorder creates the file,
    takes '-file' for its response ('dataToStore -file not recognized'), and the next analyze ends
    the Python process without an error (status 0), the file empty."""
    script = f"""
import os, sys
import openseespy.opensees as o
os.chdir({str(tmp_path)!r})
o.model('basic', '-ndm', 2, '-ndf', 3)
o.node(1, 0.0, 0.0); o.node(2, 10.0, 0.0); o.fix(1, 1, 1, 0); o.fix(2, 0, 1, 0)
o.geomTransf('Linear', 1); o.element('elasticBeamColumn', 1, 1, 2, 1.0, 2e11, 1e-2, 1)
o.timeSeries('Linear', 1); o.pattern('Plain', 1, 1); o.load(2, 0.0, 0.0, 1e3)
o.integrator('LoadControl', 0.5); o.analysis('Static')
if sys.argv[1] == 'Node':
    o.recorder('Node', '-node', 2, '-dof', 3, 'disp', '-file', 'x.out')
else:
    o.recorder('Element', '-ele', 1, 'force', '-file', 'x.out')
o.analyze(2)
print('analyzed', flush=True)
"""
    element = subprocess.run([sys.executable, "-c", script, "Element"], capture_output=True, text=True, timeout=120)
    assert "analyzed" in element.stdout and not (tmp_path / "x.out").exists()
    node = subprocess.run([sys.executable, "-c", script, "Node"], capture_output=True, text=True, timeout=120)
    assert node.returncode == 0 and "analyzed" not in node.stdout and (tmp_path / "x.out").read_text() == ""


# -- 6. getLoadFactor and the loads applied -------------------------------------------------------
def load_factors(mass_beam, o):
    """getLoadFactor of two patterns before any step, after setTime, after a step and loadConst,
    and of a pattern defined after a step (with its nodal and element load: nodeResponse 7,
    eleForce) before and after ``reactions`` applies the loads again."""
    mass_beam(o)
    o.timeSeries("Constant", 1, "-factor", 2.0)
    o.pattern("Plain", 1, 1, "-fact", 3.0)
    o.load(6, 0.0, -1e5, 0.0)
    o.timeSeries("Linear", 2)
    o.pattern("Plain", 2, 2, "-fact", 3.0)
    o.load(6, 0.0, -1e5, 0.0)
    out = [o.getLoadFactor(1), o.getLoadFactor(2)]
    o.setTime(0.5)
    out += [o.getLoadFactor(1), o.getLoadFactor(2)]
    solver(o)
    o.analyze(1, 0.01)
    out += [o.getLoadFactor(1), o.getLoadFactor(2)]
    o.loadConst("-time", 0.0)
    o.analyze(1, 0.01)
    out += [o.getLoadFactor(1), o.getLoadFactor(2), o.getTime()]
    o.timeSeries("Constant", 3)
    o.pattern("Plain", 3, 3, "-fact", 2.0)
    o.load(6, 0.0, -1e5, 0.0)
    o.eleLoad("-ele", 5, "-type", "-beamUniform", -1e4)
    out += [o.getLoadFactor(3), o.nodeResponse(6, 2, 7), o.eleForce(5, 2)]
    o.reactions()
    out += [o.getLoadFactor(3), o.nodeResponse(6, 2, 7), o.eleForce(5, 2)]
    return out


def test_get_load_factor_is_what_openseespy_returns(mass_beam):
    """0 before the first step and after setTime alone (OpenSees's LoadPattern::getLoadFactor
    returns the factor of the last Domain::applyLoad, 0 before it); 6 and 3 × 0.51 after a step
    from t = 0.5; a pattern defined after a step reads 0 and loads nothing (nodeResponse 7,
    eleForce) until reactions applies the loads again."""
    reference, value = load_factors(mass_beam, oracle), load_factors(mass_beam, vops)
    np.testing.assert_allclose(value, reference, rtol=RTOL, atol=0.0)
    assert reference[:4] == [0.0] * 4 and reference[4] == 6.0 and reference[9] == 0.0
