"""How the check's table, the report and the command layer's messages write what they say: a
ratio without a '-' unit (it read as a minus sign), frequencies without a trailing dot ('1424.
Hz'), the deflection chart drawing the quantity the deflection row holds to L/600, the damping the
sweep ran with, and command hints in the syntax of the script that gave the command (Tcl or
Python)."""
import math
import re
import subprocess
import sys

import numpy as np
import pytest

import vtsi.opensees as ops
import vtsi.report
from vtsi.check import CheckResult, CheckRow, CheckSettings, check, node_deflections, stored_check
from vtsi.errors import CommandError
from vtsi.passage import PassageSettings
from vtsi.report import _Report, write_report
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import SweepResults

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
ZETA = 0.013


@pytest.fixture(scope="module")
def checked(tmp_path_factory):
    """A small sweep (HSLM-A1 near its resonance on a 20 m, 5 Hz span: the dynamic analysis
    governs the deflection) with its check stored, and its report: ``(results path, report dir)``."""
    root = tmp_path_factory.mktemp("report_text")
    path = root / "sweep.h5"
    sweep = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=4), ["HSLM-A1", "HSLM-A4"], "250,320,330",
                  PassageSettings(dt=5e-3, damping=ZETA))
    check(sweep.run(path, workers=1, progress=False)).store(path)
    write_report(path, root / "report")
    return path, root / "report"


def _report(path):
    results = SweepResults(str(path))
    return _Report(results, stored_check(str(path)), path)


# -- a. a ratio has no unit ------------------------------------------------------------------------
def test_a_ratio_has_no_dash_unit_in_the_table():
    """φ'_dyn and dynamic vs LM71 are ratios (units '-'): the table writes '6.934', never '6.934 -'."""
    rows = [CheckRow("dynamic_increment", "EN 1991-2 6.4.6.5(3)", 6.9341, "-", train="HSLM-A3", speed_kmh=360.0),
            CheckRow("dynamic_vs_lm71", "EN 1991-2 6.4.6.5(3), Annex C", 2.905, "-", 1.0, 2.905),
            CheckRow("deflection", "EN 1990 A2.4.4.2.3(1)", 0.03381, "m", 0.03333, 1.01, "fail")]
    text = CheckResult(CheckSettings(), rows, 1, 1).text()
    lines = {line.split()[0]: line for line in text.splitlines() if line.split()}
    assert re.match(r"dynamic_increment +6\.934 +INFO", lines["dynamic_increment"])
    assert re.match(r"dynamic_vs_lm71 +2\.905 +ref\. 1 +INFO", lines["dynamic_vs_lm71"])
    assert re.match(r"deflection +0\.03381 m +0\.03333", lines["deflection"])
    assert not re.search(r"\d -(\s|$)", text)


def test_a_the_text_table_and_the_report_write_a_ratio_alike(checked):
    """The value of each ratio row reads the same in the text table, the HTML and the Markdown,
    with no unit after it."""
    path, out = checked
    result = stored_check(str(path))
    ratios = [r for r in result.rows if r.units == "-" and not math.isnan(r.value)]
    assert {r.criterion for r in ratios} >= {"dynamic_increment", "dynamic_vs_lm71"}
    text = result.text().splitlines()
    html, markdown = (out / "report.html").read_text(), (out / "report.md").read_text()
    for r in ratios:
        number = f"{r.value:.4g}"
        line = next(line for line in text if line.startswith(r.criterion + " "))
        assert re.match(rf"{r.criterion} +{re.escape(number)}  ", line), line
        cell = re.search(rf'data-criterion="{r.criterion}".*?data-field="value"[^>]*>([^<]*)<', html).group(1)
        assert cell == number
        label = r.criterion.replace("_", " ").replace("lm71", "LM71")
        assert f"| {label} | {number} |" in markdown
    assert not re.search(r"\d -(\s|$)", "\n".join(text))


# -- b. no trailing dot ----------------------------------------------------------------------------
def test_b_frequencies_have_no_trailing_dot(checked, monkeypatch):
    """A deck's n₀, n₂, n₃ of 158.04, 632.2, 1424.3 Hz read '158, 632.2, 1424 Hz' in the bridge
    table, the cut-off '1424 Hz', the acceleration chart's title and the mode shapes' legend
    alike (the '#.4g' format wrote '1424.' and '5.000')."""
    path, out = checked
    report = _report(path)
    report.bridge = dict(report.bridge, frequencies_hz=np.array([158.04, 632.2, 1424.3]),
                         deck_frequencies_hz=np.array([[158.04, 632.2, 1424.3]]))
    table = report.bridge_section().blocks[0].rows
    values = {name: value for name, value in table}
    assert values["first vertical frequencies"] == "158, 632.2, 1424 Hz"
    assert values["EN cut-off max(30 Hz, 1.5 n₀, n₃)"] == "1424 Hz"
    drawn = []
    monkeypatch.setattr(vtsi.report, "_png", lambda fig: drawn.append(
        [ax.get_title() for ax in fig.axes] + [t.get_text() for ax in fig.axes if ax.get_legend()
                                               for t in ax.get_legend().get_texts()]) or b"")
    vtsi.report._mode_shapes_png(report.bridge)
    assert "mode 3: 1424 Hz" in drawn[-1]
    report.acceleration_png(report.output("accel", cutoff=True))
    assert "Peak deck acceleration (n₀ = 158 Hz)" in drawn[-1]
    for page in ((out / "report.html").read_text(), (out / "report.md").read_text()):
        assert "first vertical frequencies" in page
        assert not re.search(r"\d\. Hz|\d\.0+ Hz", page)


# -- c. the deflection chart draws the checked quantity --------------------------------------------
def test_c_the_deflection_chart_draws_what_the_row_checks(checked, monkeypatch):
    """The chart's curves are max |y_dyn| + φ''/2 |y_stat,train| over the spans' nodes: the
    governing train's curve at the governing speed is the row's value (33.82 mm in
    examples/design_check.py, where the raw |y_dyn| read ≈ 33.7); the star sits at the row's
    value with the value in its label. Its max |y_dyn| alone, φ''/2 |y_stat| = 0.11 mm under its
    curve on a 35 mm axis, would hide under it: it is not drawn, and the train's legend entry and
    the caption say what φ''/2 |y_stat| adds; drawn dotted where the gap can be seen."""
    path, _ = checked
    report = _report(path)
    row = report.row("deflection")
    assert row.train == "HSLM-A1" and "the dynamic analysis governs" in row.note
    checked_mm, dynamic_mm = report.deflection_curves("deflection")
    speeds, values = checked_mm[row.train]
    at = values[np.flatnonzero(speeds == row.speed_kmh)[0]]
    assert at == pytest.approx(1e3 * row.value, rel=1e-12)
    _, raw = dynamic_mm[row.train]
    assert np.all(values > raw)                          # + φ''/2 |y_stat| > 0 on a 20 m span
    nodes = [n for n in node_deflections(report.results, "deflection", report.bridge, report.checked.settings)
             if n.criterion == "deflection"]
    largest = np.max([n.checked[0] for n in nodes], axis=(0, 2))       # HSLM-A1: over nodes and rail samples
    assert np.allclose(values, 1e3 * largest, rtol=1e-12)
    drawn = {}
    monkeypatch.setattr(vtsi.report, "_png", lambda fig: drawn.setdefault("fig", fig) and b"")
    report.deflection_png(checked_mm, dynamic_mm)
    ax = drawn["fig"].axes[0]
    legend = [t.get_text().replace("\n", " ") for t in ax.get_legend().get_texts()]
    assert f"governing: {1e3 * row.value:.4g} mm, HSLM-A1 at {row.speed_kmh:g} km/h" in legend
    star = next(line for line in ax.lines if line.get_marker() == "*")
    assert star.get_ydata()[0] == pytest.approx(1e3 * row.value)
    assert "φ''/2" in ax.get_ylabel()
    gap = values - raw                                        # what φ''/2 |y_stat| adds, over the speeds
    assert gap.max() < vtsi.report.DISTINCT_SHARE * ax.get_ylim()[1]        # too close to the curve to be seen
    added = "–".join(dict.fromkeys(f"{g:.2g}" for g in (gap.min(), gap.max())))
    assert f"HSLM-A1 (φ''/2 |y_stat| adds {added} mm)" in legend and "HSLM-A1: max |y_dyn| alone" not in legend
    assert not [line for line in ax.lines if line.get_linestyle() == ":"]
    caption = report.deflection_caption("deflection", checked_mm, dynamic_mm)
    assert "max |y_dyn| + φ''/2 |y_stat,train|" in caption
    assert f"The governing train's max |y_dyn| alone lies {added} mm under its curve" in caption
    assert "Dotted" not in caption
    monkeypatch.setattr(vtsi.report, "DISTINCT_SHARE", 0.5 * gap.max() / ax.get_ylim()[1])   # a gap one can see
    drawn.clear()
    report.deflection_png(checked_mm, dynamic_mm)
    ax = drawn["fig"].axes[0]
    legend = [t.get_text().replace("\n", " ") for t in ax.get_legend().get_texts()]
    assert "HSLM-A1: max |y_dyn| alone" in legend and "HSLM-A1" in legend
    dotted = [line for line in ax.lines if line.get_linestyle() == ":"]
    assert len(dotted) == 1 and np.array_equal(dotted[0].get_ydata(), raw)
    assert "Dotted, in the governing train's colour: its max |y_dyn| alone." in \
        report.deflection_caption("deflection", checked_mm, dynamic_mm)


def test_c_without_static_values_the_chart_draws_the_raw_deflection(checked, monkeypatch):
    """A results file without static deflections: the largest max |y_dyn| of the deck, so
    titled and captioned (the check's quantity needs y_stat)."""
    path, _ = checked
    report = _report(path)
    monkeypatch.setattr(report.results, "static", lambda name: None)
    checked_mm, dynamic_mm = report.deflection_curves("deflection")
    assert checked_mm is None and set(dynamic_mm) == {"HSLM-A1", "HSLM-A4"}
    drawn = {}
    monkeypatch.setattr(vtsi.report, "_png", lambda fig: drawn.setdefault("fig", fig) and b"")
    report.deflection_png(checked_mm, dynamic_mm)
    assert drawn["fig"].axes[0].get_title() == "Largest deck deflection"
    assert "cannot be drawn" in report.deflection_caption("deflection", checked_mm, dynamic_mm)


def test_c_where_lm71_governs_the_caption_says_so(checked):
    """Where Φ α × LM71 governs the deflection row, no train is starred and the caption names
    the grey line instead of the governing train's."""
    path, _ = checked
    report = _report(path)
    report.row("deflection").train = "LM71"
    caption = report.deflection_caption("deflection", *report.deflection_curves("deflection"))
    assert caption.endswith("Dotted grey: Φ α × LM71's static deflection, which governs.")
    assert "Star" not in caption


def test_c_standard_maintenance_counts_the_whole_phi2(checked):
    """With standard maintenance the chart and its caption count φ'' whole, as the check does."""
    path, _ = checked
    report = _report(path)
    report.checked.settings = CheckSettings(maintenance="standard")
    careful = _report(path).deflection_curves("deflection")[0]
    standard = report.deflection_curves("deflection")[0]
    extra = {t: standard[t][1] - careful[t][1] for t in careful}
    _, raw = report.deflection_curves("deflection")[1]["HSLM-A1"]
    assert np.allclose(extra["HSLM-A1"], careful["HSLM-A1"][1] - raw)       # φ''/2 |y_stat| once more
    assert report.share_text() == "φ''"
    assert "max |y_dyn| + φ'' |y_stat,train|" in report.deflection_caption("d", standard, {})


# -- d. the damping ------------------------------------------------------------------------------
def test_d_the_report_states_the_damping_the_sweep_ran_with(checked):
    """The bridge and settings tables name ζ and how it was applied. Where ζ came from (the
    bridge file, --damping, EN 1991-2 Table 6.6 for --bridge-type) is not in the results file
    (its identity keeps the number only), so the report cannot name it."""
    path, out = checked
    markdown = (out / "report.md").read_text()
    assert markdown.count("| damping | ζ = 1.3 % (Rayleigh, through n₀ and the EN cut-off) |") == 2
    assert set(SweepResults(str(path)).identity["settings"]) >= {"damping", "damping_hz"}


# -- e. command hints in the script's syntax -------------------------------------------------------
TCL_SCRIPT = """
model basic -ndm 2 -ndf 3
node 1 0 0
node 2 10 0
fix 1 1 1 1
geomTransf Linear 1
foreach command {
    {load 2 0 -1 0}
    {sp 2 1 0.0}
    {eleLoad -ele 1 -beamUniform -1}
    {eleLoad -type -beamUniform -1}
    {element elasticBeamColumn 1 1 2 1 1 1}
    {analyze 1}
    {modalDamping 0.01}
    {model basic -ndm 2 -ndf 2}
} {
    if {[catch $command message]} { puts $message }
}
element elasticBeamColumn 1 1 2 1.0 2e11 1e-4 1 -mass 1000.0
timeSeries Linear 1
pattern Plain 1 1 { load 2 0 -1 0 }
integrator LoadControl 0.5 3 0.1 1
algorithm Newton
analysis Static
if {[catch {analyze 1} message]} { puts $message }
wipeAnalysis
analysis Transient
if {[catch {analyze 1} message]} { puts $message }
wipe
model basic -ndm 2 -ndf 3
node 1 0 0
node 2 10 0
node 3 20 0
fix 1 1 1 0
fix 3 0 1 0
geomTransf Linear 1
element elasticBeamColumn 1 1 2 1.0 3.5e10 0.7 1 -mass 15000.0
element elasticBeamColumn 2 2 3 1.0 3.5e10 0.7 1 -mass 15000.0
track 1 -eleRange 1 2
car 1 sprungMass 10000.0 1e6
train 1 30.0 -cars 1 0.0
movingLoadConstraint 1 1 1 0.0
analysis Static
if {[catch {analyze 1} message]} { puts $message }
"""

HINTS = [   # (Tcl, Python) of each message above, in order
    ('load on node 2: no load pattern; define one with "pattern Plain tag tsTag"',
     "load on node 2: no load pattern; define one with pattern('Plain', tag, tsTag)"),
    ('sp node 2: no load pattern; define one with "pattern Plain tag tsTag"',
     "sp node 2: no load pattern; define one with pattern('Plain', tag, tsTag)"),
    ("eleLoad: -type missing before -beamUniform (eleLoad -ele tags... -type -beamUniform ...)",
     "eleLoad: -type missing before -beamUniform (eleLoad('-ele', *tags, '-type', '-beamUniform', ...))"),
    ("eleLoad: no elements (give eleLoad -ele tags... -type ... or eleLoad -range first last -type ...)",
     "eleLoad: no elements (give eleLoad('-ele', *tags, '-type', ...) or eleLoad('-range', first, last, '-type', "
     "...))"),
    ("element elasticBeamColumn 1: missing transfTag (element elasticBeamColumn tag i j A E Iz transfTag ...)",
     "element elasticBeamColumn 1: missing transfTag (element('elasticBeamColumn', tag, i, j, A, E, Iz, transfTag, "
     "...))"),
    ('analyze: no analysis defined; give the command "analysis Static" or "analysis Transient" first',
     "analyze: no analysis defined; call analysis('Static') or analysis('Transient') first"),
    ('modalDamping: no modes; give the command "eigen n" first (the ratios apply to its modes)',
     "modalDamping: no modes; call eigen(n) first (the ratios apply to its modes)"),
    ('model: the model already has nodes with 3 dofs; give the command "wipe" before changing -ndf to 2',
     "model: the model already has nodes with 3 dofs; call wipe() before changing -ndf to 2"),
    ('use "algorithm Linear" (one iteration a step', "use algorithm('Linear') (one iteration a step"),
    ('analyze: a transient analysis needs the time step: "analyze numSteps dt"',
     "analyze: a transient analysis needs the time step: analyze(numSteps, dt)"),
    ('the train\'s dead load is "deadLoad" (docs/commands.md, Trains), its passage "analysis Transient" + '
     '"analyze n dt"',
     "the train's dead load is deadLoad() (docs/commands.md, Trains), its passage analysis('Transient') + "
     "analyze(n, dt)"),
]


def test_e_a_tcl_script_reads_its_hints_in_tcl(tmp_path):
    """``vtsi run script.tcl``: every hint is a Tcl command (no parentheses, no quotes around
    words), one a line as the script's ``catch`` prints them."""
    script = tmp_path / "hints.tcl"
    script.write_text(TCL_SCRIPT)
    proc = subprocess.run([sys.executable, "-m", "vtsi", "run", str(script)], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == len(HINTS), lines
    for line, (tcl, _) in zip(lines, HINTS):
        assert tcl in line
        assert "('" not in line and "()" not in line


def _python_messages():
    """The messages of the same commands given through vtsi.opensees, in HINTS' order."""
    old = ops.set_session(ops.Session())
    messages = []

    def message(command, *args):
        with pytest.raises(CommandError) as info:
            getattr(ops, command)(*args)
        messages.append(str(info.value))
    try:
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        ops.node(1, 0.0, 0.0)
        ops.node(2, 10.0, 0.0)
        ops.fix(1, 1, 1, 1)
        ops.geomTransf("Linear", 1)
        for command, *args in (("load", 2, 0, -1, 0), ("sp", 2, 1, 0.0), ("eleLoad", "-ele", 1, "-beamUniform", -1),
                               ("eleLoad", "-type", "-beamUniform", -1),
                               ("element", "elasticBeamColumn", 1, 1, 2, 1, 1, 1), ("analyze", 1),
                               ("modalDamping", 0.01), ("model", "basic", "-ndm", 2, "-ndf", 2)):
            message(command, *args)
        ops.element("elasticBeamColumn", 1, 1, 2, 1.0, 2e11, 1e-4, 1, "-mass", 1000.0)
        ops.timeSeries("Linear", 1)
        ops.pattern("Plain", 1, 1)
        ops.load(2, 0, -1, 0)
        ops.integrator("LoadControl", 0.5, 3, 0.1, 1)
        ops.algorithm("Newton")
        ops.analysis("Static")
        message("analyze", 1)
        ops.wipeAnalysis()
        ops.analysis("Transient")
        message("analyze", 1)
        ops.wipe()
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        for tag, x in ((1, 0.0), (2, 10.0), (3, 20.0)):
            ops.node(tag, x, 0.0)
        ops.fix(1, 1, 1, 0)
        ops.fix(3, 0, 1, 0)
        ops.geomTransf("Linear", 1)
        for tag in (1, 2):
            ops.element("elasticBeamColumn", tag, tag, tag + 1, 1.0, 3.5e10, 0.7, 1, "-mass", 15000.0)
        ops.track(1, "-eleRange", 1, 2)
        ops.car(1, "sprungMass", 10000.0, 1e6)
        ops.train(1, 30.0, "-cars", 1, 0.0)
        ops.movingLoadConstraint(1, 1, 1, 0.0)
        ops.analysis("Static")
        message("analyze", 1)
    finally:
        ops.session.wipe()
        ops.set_session(old)
    return messages


def test_e_python_reads_its_hints_in_python():
    """The same commands through vtsi.opensees: each hint in OpenSeesPy's syntax, as before."""
    messages = _python_messages()
    assert len(messages) == len(HINTS)
    for text, (_, python) in zip(messages, HINTS):
        assert python in text


def test_e_the_syntax_is_the_sessions_while_a_tcl_command_runs():
    """A session that ran a Tcl script writes Python hints again to Python calls afterwards."""
    from vtsi.commands.tcl import Interpreter

    session = ops.Session()
    tcl = Interpreter(session)
    tcl.eval("model basic -ndm 2 -ndf 3; node 1 0 0; node 2 10 0")
    with pytest.raises(CommandError, match='define one with "pattern Plain tag tsTag"'):
        tcl.eval("load 2 0 -1 0")
    with pytest.raises(CommandError, match=re.escape("define one with pattern('Plain', tag, tsTag)")):
        session.load(2, 0, -1, 0)
