"""What a newcomer coming from OpenSees met (the newcomer probe): a Tcl script told to call
``model('basic', ...)``, ``Linear(1)`` silently a factor, a single-value uniform beam load refused,
``contact='LCP'`` refused without naming the spelling, a cut-off printed as '1424. Hz'."""
import re
import subprocess
import sys

import numpy as np
import pytest

import vtsi
import vtsi.opensees as ops
from vtsi.recorders import NodeRecorder
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, CommandError, ModelError
from vtsi.models import Train, sprung_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.sweep_results import significant_text
from vtsi.timeseries import Constant, Linear, Path, Pulse, Rectangular, Triangle, Trig
from vtsi.track import Track
from vtsi.train import TrainSubdomain

PYTHON_HINT = "node: no model; call model('basic', '-ndm', 2, '-ndf', 3) first"
TCL_HINT = 'node: no model; give the command "model basic -ndm 2 -ndf 3" first'


# -- a. the 'no model' hint in the syntax of the session ------------------------------------
def test_python_session_hints_python_syntax():
    session = ops.Session()
    with pytest.raises(CommandError, match=f"^{re.escape(PYTHON_HINT)}$"):
        session.node(1, 0.0, 0.0)


def test_vtsi_opensees_hints_python_syntax_also_after_a_tcl_script_on_its_session():
    pytest.importorskip("tkinter")
    from vtsi.tcl import Interpreter

    old = ops.set_session(ops.Session())
    try:
        with pytest.raises(CommandError) as info:
            Interpreter(ops.session).eval("node 1 0 0")
        assert str(info.value) == TCL_HINT
        with pytest.raises(CommandError, match=f"^{re.escape(PYTHON_HINT)}$"):
            ops.node(1, 0.0, 0.0)                 # the shared session is Python's again
    finally:
        ops.set_session(old)


def test_vtsi_run_of_a_tcl_script_hints_tcl_syntax(tmp_path):
    pytest.importorskip("tkinter")
    script = tmp_path / "bad.tcl"
    script.write_text("node 1 0 0\n")
    run = subprocess.run([sys.executable, "-m", "vtsi", "run", str(script)], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 2
    assert run.stderr.strip().endswith(f"bad.tcl line 1: {TCL_HINT}"), run.stderr
    assert "model('basic'" not in run.stderr


def test_vtsi_opensees_in_a_subprocess_hints_python_syntax():
    code = "import vtsi.opensees as ops\ntry:\n    ops.node(1, 0.0, 0.0)\nexcept Exception as e:\n    print(e)\n"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.stdout.strip() == PYTHON_HINT, run.stderr


# -- b. a series without a tag says how to give it -------------------------------------------
@pytest.mark.parametrize("series, first", [
    (Linear(1), "factor"), (Constant(2.5), "factor"), (Path([0.0, 1.0], dt=0.1), "values"),
    (Trig(0.0, 1.0, 0.5), "t_start"), (Rectangular(0.0, 1.0), "t_start"), (Triangle(0.0, 2.0, 1.0), "t_start"),
    (Pulse(0.0, 1.0, 0.5), "t_start")])
def test_a_series_without_tag_names_itself_and_the_keyword(series, first):
    kind = type(series).__name__
    with pytest.raises(ModelError) as info:
        vtsi.Model().add_time_series(series)
    message = str(info.value)
    assert message.startswith(f"timeSeries {series!r} has no tag: give it as tag=..., e.g. {repr(series)[:-1]}, tag=1)")
    assert message.endswith(f"{kind}'s first argument is {first}, not the tag as in OpenSees's "
                            f"'timeSeries {kind} <tag> ...'")


def test_linear_1_names_its_factor_of_1():
    with pytest.raises(ModelError, match=r"^timeSeries Linear\(factor=1\.0\) has no tag: give it as tag=\.\.\., "
                                         r"e\.g\. Linear\(factor=1\.0, tag=1\); Linear's first argument is factor"):
        vtsi.Model().add_time_series(vtsi.Linear(1))
    assert vtsi.Model().add_time_series(vtsi.Linear(tag=1)).tag == 1     # the keyword works as before
    assert repr(Linear(2.0, tag=3)) == "Linear(factor=2.0, tag=3)"
    assert repr(Path([0.0, 1.0, 2.0], dt=0.1)) == "Path(values=<3 values>, dt=0.1, factor=1.0)"


def test_a_trig_given_the_tag_first_says_so():
    """``Trig(1, 0, 10, 0.5)`` (OpenSees's order tag tStart tEnd period) ends before it starts."""
    with pytest.raises(ModelError, match=r"^timeSeries Trig: tEnd = 0 is before tStart = 1 \(the series would be 0 "
                                         r"always\); if 1 was meant as the tag, give it as tag=1: Trig's first argument "
                                         r"is tStart"):
        Trig(1, 0, 10, 0.5)
    with pytest.raises(ModelError, match=r"^timeSeries Trig 3: tEnd = 0 is before tStart = 1 \(the series would be 0 always\)$"):
        Trig(1, 0, 10, 0.5, tag=3)


# -- c. the axial part of a beam load is optional, as OpenSees's ----------------------------
def _beam_with_pattern():
    model = vtsi.Model()
    bridge = simply_supported_beam(model, 10.0, 4, 3.0e10, 0.5, 1.0e4)
    model.pattern(1, model.add_time_series(vtsi.Constant(tag=1)))
    return model, bridge


def _static(model, bridge):
    rec = NodeRecorder(bridge.midspan_nodes, [2], "disp")
    vtsi.StaticAnalysis(model, recorders=[rec]).run(1)
    return np.asarray(rec.values)


@pytest.mark.parametrize("kind, short, full", [("uniform", (-1.0e5,), (-1.0e5, 0.0)),
                                               ("point", (-2.0e5, 0.3), (-2.0e5, 0.3, 0.0))])
def test_beam_load_without_its_axial_part_is_the_load_with_zero(kind, short, full):
    results = []
    for values in (short, full):
        model, bridge = _beam_with_pattern()
        model.beam_load(1, bridge.elements[1], kind, *values)
        assert model.patterns[1].element_loads == [(bridge.elements[1], kind, full)]
        results.append(_static(model, bridge))
    assert results[0][0, 0] < 0.0
    np.testing.assert_array_equal(results[0], results[1])


@pytest.mark.parametrize("kind, values, needs", [
    ("uniform", (), r"\(w_y\[, w_x\]\) finite \(w_x 0 if not given\), got \[\]"),
    ("uniform", (-1.0, 0.0, 2.0), r"\(w_y\[, w_x\]\) finite \(w_x 0 if not given\), got \[-1\.0, 0\.0, 2\.0\]"),
    ("point", (-1.0,), r"\(P_y, x/L\[, P_x\]\) finite \(P_x 0 if not given\), got \[-1\.0\]"),
    ("point", (-1.0, 0.5, 0.0, 1.0), r"\(P_y, x/L\[, P_x\]\) finite \(P_x 0 if not given\), got \[-1\.0, 0\.5, 0\.0, 1\.0\]"),
    ("uniform", (float("nan"),), r"\(w_y\[, w_x\]\) finite \(w_x 0 if not given\), got \[nan\]")])
def test_beam_load_of_a_wrong_count_is_refused(kind, values, needs):
    model, bridge = _beam_with_pattern()
    e = bridge.elements[0]
    with pytest.raises(ModelError, match=rf"^pattern 1: {kind} load on element {e} needs {needs}$"):
        model.beam_load(1, e, kind, *values)


def test_ele_load_command_and_object_api_give_the_same_loads():
    """The command layer's optional Wx / Px come from the same defaults as the object API's."""
    s = ops.Session()
    s.model("basic", "-ndm", 2, "-ndf", 3)
    s.node(1, 0.0, 0.0)
    s.node(2, 4.0, 0.0)
    s.fix(1, 1, 1, 1)
    s.geomTransf("Linear", 1)
    s.element("elasticBeamColumn", 1, 1, 2, 0.5, 3.0e10, 0.04, 1)
    s.timeSeries("Constant", 1)
    s.pattern("Plain", 1, 1)
    s.eleLoad("-ele", 1, "-type", "-beamUniform", -1.0e4)
    s.eleLoad("-ele", 1, "-type", "-beamPoint", -2.0e4, 0.5)
    assert s.domain.patterns[1].element_loads == [(1, "uniform", (-1.0e4, 0.0)), (1, "point", (-2.0e4, 0.5, 0.0))]


# -- d. the contact strategy's spelling ------------------------------------------------------
def test_a_contact_strategy_in_capitals_is_refused_naming_its_spelling():
    model = vtsi.Model()
    bridge = simply_supported_beam(model, 10.0, 4, 3.0e10, 0.5, 1.0e4)
    car = sprung_mass(1.0e4, 1.0e6, 1.0e3, 1.0e3)
    con = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(Train([car], [0.0], 20.0)))
    for given, right in (("LCP", "lcp"), ("Bilateral", "bilateral"), (" lcp ", "lcp")):
        with pytest.raises(AnalysisError, match=rf"^CoupledAnalysis: unknown contact strategy '{given}'; valid: "
                                                rf"bilateral, lcp \(names are case-sensitive: contact='{right}'\)$"):
            CoupledAnalysis(model, con, None, 1e-3, contact=given)
    with pytest.raises(AnalysisError, match=r"^CoupledAnalysis: unknown contact strategy 'hard'; valid: bilateral, lcp$"):
        CoupledAnalysis(model, con, None, 1e-3, contact="hard")
    assert CoupledAnalysis(model, con, None, 1e-3, contact="lcp").contact == "lcp"


# -- e. numbers of the bridge line without a trailing dot ------------------------------------
@pytest.mark.parametrize("value, text", [(1424.3, "1424"), (96.034, "96.03"), (10.6612, "10.66"), (2.6664, "2.666"),
                                         (30.0, "30"), (9999.7, "10000"), (12345.6, "12346"), (0.000158, "0.000158")])
def test_significant_text(value, text):
    assert significant_text(value) == text


def test_bridge_text_of_a_four_digit_cut_off():
    """A 20 m deck with n0, n2, n3 = 158.04, 632.2, 1424.3 Hz (a deck mass typed in t/m): the
    cut-off n3 read '1424. Hz'."""
    from vtsi.sweep_results import bridge_text

    record = {"span_lengths_m": [20.0], "span_ends_m": [[0.0, 20.0]], "deck_ends_m": [[0.0, 20.0]],
              "deck_frequencies_hz": [[158.04, 632.2, 1424.3]]}
    line = bridge_text(record)
    assert line == "bridge: 1 deck; span 20 m; n0 158 Hz; EN cut-off 1424 Hz; L_Phi 20 m"
    assert not re.search(r"\d\.\s", line)
