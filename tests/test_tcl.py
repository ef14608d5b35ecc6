"""The Tcl bridge (vtsi.tcl) and ``python -m vtsi model.tcl``: a Tcl model gives the same results
as the same model written with the Python commands (vtsi and OpenSeesPy)."""
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("tkinter")

import vtsi.opensees as ops  # noqa: E402
from vtsi.__main__ import main  # noqa: E402
from vtsi.errors import CommandError, ModelError  # noqa: E402
from vtsi.opensees import Session, UnknownCommand  # noqa: E402
from vtsi.tcl import Interpreter, convert_word, run_file, split_list  # noqa: E402

try:
    import openseespy.opensees as oracle
except ImportError:
    oracle = None

SCRIPT = Path(__file__).parent / "scripts" / "beam.tcl"


def beam_python(o, outdir):
    """tests/scripts/beam.tcl written with the Python commands."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    nel, length = 8, 10.0
    for i in range(nel + 1):
        o.node(i + 1, i * length / nel, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(nel + 1, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for i in range(1, nel + 1):
        o.element("elasticBeamColumn", i, i, i + 1, 0.8, 3.0e10, 0.05, 1, "-mass", 2000.0, "-cMass")
    o.mass(5, 500.0, 500.0, 0.0)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    for i in range(2, nel + 1):
        o.load(i, 0.0, -2000.0 * 9.81 * length / nel, 0.0)
    o.constraints("Plain")
    o.numberer("RCM")
    o.system("BandSPD")
    o.test("NormDispIncr", 1.0e-10, 6)
    o.algorithm("Linear")
    o.integrator("LoadControl", 0.25)
    o.analysis("Static")
    o.analyze(4)
    static = o.nodeDisp(5, 2)
    o.loadConst("-time", 0.0)
    lam = o.eigen(3)
    w1 = math.sqrt(lam[0])
    o.rayleigh(0.0, 0.04 / w1, 0.0, 0.0)
    values = [math.sin(3.14159265358979 * k / 50.0) for k in range(51)]
    o.timeSeries("Path", 2, "-dt", 0.005, "-values", *values, "-factor", 1.0e5)
    o.pattern("Plain", 2, 2, "-fact", 1.5)
    o.load(4, 0.0, -1.0, 0.0)
    o.timeSeries("Path", 3, "-time", 0.0, 0.1, 0.2, "-values", 0.0, 2.0e4, 0.0)
    o.pattern("Plain", 3, 3)
    o.load(6, 1.0, -1.0, 0.0)
    o.recorder("Node", "-file", os.path.join(outdir, "tcl_disp.out"), "-time", "-node", 3, 5, "-dof", 2, "disp")
    o.wipeAnalysis()
    o.constraints("Transformation")
    o.numberer("RCM")
    o.system("BandGeneral")
    o.algorithm("Newton")
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")
    ok = o.analyze(60, 0.005)
    result = [static] + lam + [ok, o.getTime(), o.nodeDisp(5, 2), o.eleForce(4, 2)]
    o.wipe()
    return np.array(result, dtype=float)


def printed(stdout):
    """The numbers beam.tcl prints: static midspan, 3 eigenvalues, analyze code, t, disp, force."""
    lines = {line.split()[0]: line.split()[1:] for line in stdout.splitlines() if line.strip()}
    out = [float(lines["static"][1])] + [float(x) for x in lines["eigen"]]
    words = lines["analyze"]
    out += [float(words[0]), float(words[2]), float(words[4]), float(words[6])]
    return np.array(out)


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.abs(a - b).max() / np.abs(a).max())


def test_tcl_file_through_python_m_vtsi(tmp_path):
    """``python -m vtsi beam.tcl outdir`` equals the same model in Python commands (vtsi), and
    OpenSeesPy when installed: printed values and the recorder file."""
    (tmp_path / "tcl").mkdir()
    (tmp_path / "py").mkdir()
    proc = subprocess.run([sys.executable, "-m", "vtsi", str(SCRIPT), str(tmp_path / "tcl")], capture_output=True,
                          text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    tcl = printed(proc.stdout)
    py = beam_python(ops, str(tmp_path / "py"))
    assert rel(py, tcl) < 1e-12
    a = np.loadtxt(tmp_path / "tcl" / "tcl_disp.out")
    b = np.loadtxt(tmp_path / "py" / "tcl_disp.out")
    assert a.shape == (60, 3) and rel(b, a) < 1e-12
    if oracle is not None:
        (tmp_path / "osp").mkdir()
        ref = beam_python(oracle, str(tmp_path / "osp"))
        assert rel(ref, tcl) < 1e-9
        assert rel(np.loadtxt(tmp_path / "osp" / "tcl_disp.out"), a) < 1e-6


def test_tcl_file_in_process(tmp_path):
    """The same file through tkinter in this process, into a given session."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    session = Session()
    interp = run_file(SCRIPT, session=session, argv=[str(tmp_path / "a")])
    assert interp.session is session and interp.exit_code is None
    assert session.domain is None                         # the script ends with wipe
    assert interp.eval("set nel") == "8"
    a = np.loadtxt(tmp_path / "a" / "tcl_disp.out")
    beam_python(ops, str(tmp_path / "b"))
    assert rel(np.loadtxt(tmp_path / "b" / "tcl_disp.out"), a) < 1e-12


def test_tcl_commands_return_values_and_forms():
    tcl = Interpreter()
    tcl.eval("""
        model basic -ndm 2 -ndf 3
        node 1 0.0 0.0; node 2 5.0 0.0; node 3 10.0 0.0
        fix 1 1 1 0; fix 3 0 1 0
        geomTransf Linear 1
        element elasticBeamColumn 1 1 2 1.0 2.0e11 1.0e-3 1 -mass 100.0
        element elasticBeamColumn 2 2 3 1.0 2.0e11 1.0e-3 1 -mass 100.0
        set values {0.0 1.0 2.0}
        timeSeries Path 1 -dt 0.01 -values $values
        pattern Plain 1 1 {
            load 2 0.0 -1.0 0.0
        }
        pattern Plain 2 Linear {
            for {set i 2} {$i <= 2} {incr i} { load $i 0.0 -2.0 0.0 }
        }
        pattern Plain 3 "Path -time {0.0 1.0} -values {0.0 4.0}" -fact 0.5 { load 2 1.0 0.0 0.0 }
        pattern Plain 4 1 -fact 2.0
    """)
    model = tcl.session.domain
    assert sorted(model.patterns) == [1, 2, 3, 4]
    assert list(model.patterns[1].nodal[2]) == [0.0, -1.0, 0.0]
    assert list(model.patterns[2].nodal[2]) == [0.0, -2.0, 0.0]
    assert model.patterns[3].factor == 0.5 and model.patterns[3].series(np.array([0.5]))[0] == 2.0
    assert model.patterns[4].nodal == {} and model.patterns[4].factor == 2.0
    lam = [float(x) for x in tcl.tcl.splitlist(tcl.eval("eigen 2"))]
    assert len(lam) == 2 and lam[0] < lam[1]
    assert tcl.eval("llength [nodeCoord 2]") == "2" and float(tcl.eval("nodeCoord 2 1")) == 5.0
    assert tcl.eval("getNodeTags") == "1 2 3"
    tag = tcl.eval("recorder Node -node 2 -dof 2 disp")
    assert tcl.eval("analysis Transient") == ""
    assert tcl.eval("analyze 3 0.01") == "0"
    assert math.isclose(float(tcl.eval("getTime")), 0.03)
    values = tcl.session.recorders[int(tag)].values
    assert values.shape == (3, 1) and values[-1, 0] == float(tcl.eval("nodeDisp 2 2"))


def test_tcl_errors():
    tcl = Interpreter()
    with pytest.raises(UnknownCommand, match="'foo'") as info:
        tcl.eval("model basic -ndm 2\nfoo 1 2")
    assert info.value.__notes__[0].startswith("Tcl traceback:") and "foo 1 2" in info.value.__notes__[0]
    tcl.eval("node 1 0 0")
    with pytest.raises(ModelError, match="node 1 already exists"):
        tcl.eval("node 1 0 0")
    assert tcl.eval("catch {node 1 0 0} msg; set msg") == "node 1 already exists"
    with pytest.raises(CommandError, match="'-foo'"):
        tcl.eval("timeSeries Path 1 -dt 0.1 -values {1 2} -foo")
    with pytest.raises(CommandError, match="3 times .* 2 values"):
        tcl.eval("timeSeries Path 1 -time {0 1 2} -values {1 2}")
    with pytest.raises(CommandError, match="Tcl error"):
        tcl.eval("set x [expr {1 +}]")
    assert tcl.eval("exit 4; puts never") == "" and tcl.exit_code == 4


def test_main_exit_codes(tmp_path, capsys):
    """A script's failing command: one line naming the script, its line and vtsi's message, exit
    status 2; ``--traceback`` adds the Tcl traceback; a Python script is refused, naming python."""
    def run(name, text, *options):
        script = tmp_path / name
        script.write_text(text)
        status = main(["run", *options, str(script)])
        return status, script, capsys.readouterr().err.splitlines()

    status, bad, err = run("bad.tcl", "model basic -ndm 2 -ndf 3\nnode 1 0 0\nbogusCommand 3\n")
    assert status == 2 and len(err) == 1 and err[0].startswith(f"vtsi: {bad} line 3: unknown command 'bogusCommand'")
    status, nested, err = run("nested.tcl", "model basic -ndm 2 -ndf 3\nproc twice {} {\n  node 1 0 0\n  node 1 0 0\n}\n"
                                            "twice\n", "--traceback")
    assert status == 2 and err[0] == f"vtsi: {nested} line 6: node 1 already exists"
    assert err[1] == "Tcl traceback:" and '(procedure "twice" line 3)' in "\n".join(err)
    status, expr, err = run("expr.tcl", "puts ok\nset x [expr {1 +}]\n")
    assert status == 2 and len(err) == 1 and err[0].startswith(f"vtsi: {expr} line 2: Tcl error: missing operand")
    python = tmp_path / "model.py"
    python.write_text("import vtsi.opensees as ops\n")
    with pytest.raises(SystemExit) as info:
        main(["run", str(python)])
    assert info.value.code == 2 and f"run it with: python {python}" in capsys.readouterr().err
    good = tmp_path / "good.tcl"
    good.write_text("puts \"args [llength $argv] $argv\"\nexit 3\n")
    assert main([str(good), "x", "y"]) == 3
    with pytest.raises(SystemExit) as info:
        main([str(tmp_path / "missing.tcl")])
    err = capsys.readouterr().err.splitlines()
    assert info.value.code == 2 and err == [f"vtsi run: error: script {tmp_path / 'missing.tcl'}: no such file (see 'vtsi run -h')"]


def test_word_conversion():
    assert convert_word("3") == 3 and isinstance(convert_word("-3"), int)
    assert convert_word("2.5e3") == 2500.0 and convert_word(".5") == 0.5
    assert convert_word("-node") == "-node" and convert_word("disp") == "disp"
    assert convert_word("0 1.5 -2") == [0, 1.5, -2]
    assert convert_word(" load 2 0 -1 0 ") == " load 2 0 -1 0 "
    assert split_list('a {b c} "d e" {f {g h}}') == ["a", "b c", "d e", "f {g h}"]
    with pytest.raises(CommandError, match="unmatched"):
        split_list("a {b")


BEAM_TCL = """model basic -ndm 2 -ndf 3
node 1 0 0; node 2 10 0; node 3 20 0
fix 1 1 1 0; fix 3 0 1 0
geomTransf Linear 1
element elasticBeamColumn 1 1 2 5.0 3.5e10 2.5 1 -mass 15000.0
element elasticBeamColumn 2 2 3 5.0 3.5e10 2.5 1 -mass 15000.0
"""


@pytest.mark.parametrize("fact", ["", " -fact 2.0"])
def test_tcl_uniform_excitation_takes_an_inline_accel_series(fact):
    """OpenSees reads -accel's word as a series tag or an inline series, also as the last word."""
    tcl = Interpreter()
    tcl.eval(BEAM_TCL + f'pattern UniformExcitation 2 1 -accel "Path -dt 0.1 -values {{0 1 0}}"{fact}')
    assert 2 in tcl.session.domain.patterns


@pytest.mark.parametrize("script, message", [
    ("nodeDisp", r"nodeDisp: takes node \[dof\] \(1 to 2 arguments\), got 0"),
    ("nodeDisp 2 1 3", r"nodeDisp: takes node \[dof\] \(1 to 2 arguments\), got 3"),
    ("wipe 1", r"wipe: takes no arguments, got 1"),
    ("getTime 1", r"getTime: takes no arguments, got 1"),
])
def test_tcl_wrong_argument_count_names_the_command(script, message):
    tcl = Interpreter()
    tcl.eval(BEAM_TCL)
    with pytest.raises(CommandError, match=message):
        tcl.eval(script)


@pytest.mark.parametrize("script, message", [
    ("element elasticBeamColumn 7 1 3 5.0 3.5e10 2.5 1 -mass",
     r"^element elasticBeamColumn 7: -mass needs a value \(mass per unit length\), got none"),
    ("element elasticBeamColumn 7 1 3 A 3.5e10 2.5 1", r"^element elasticBeamColumn 7: A must be a number, got 'A'"),
    ("node 9 1 1 -mass 1.0", r"^node 9: -mass needs 3 values \(one per dof\), got 1"),
    ("timeSeries Linear 1; pattern Plain 1 1; eleLoad -ele 1 -beamUniform -1.0",
     r"^eleLoad: -type missing before -beamUniform"),
    ("integrator LoadControl 0.5 3 1.0 0.1", r"^integrator LoadControl: minLambda = 1 is above maxLambda = 0.1"),
])
def test_tcl_malformed_options_name_the_command_once(script, message):
    """A message carries one prefix (it said 'element: missing element elasticBeamColumn 7: -mass');
    the Tcl traceback follows it as a note."""
    tcl = Interpreter()
    tcl.eval(BEAM_TCL)
    with pytest.raises(CommandError, match=message):
        tcl.eval(script)
