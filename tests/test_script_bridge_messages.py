"""What ``vtsi sweep`` says of a user's bridge file: each message one line naming the file and
the value at fault, and the summary's bridge line the damping the passages had.

Before: a mechanism or an orphan node found by the bridge's eigen analysis did not name the
file ('vtsi sweep: stiffness matrix K is singular ...'); E in GPa was hinted as 'E in kPa
reads f1 31.6 times low' (it reads 31623 times low); a deck without mass was told of 't/m (0 t/m
is 0 kg/m)'; a script's command error showed its class ('CommandError: model: ...'); [analysis]
dt_s = 1 was refused naming neither the file nor the key; and a script without damping ran
undamped, which the summary did not say."""
import math
import re
import textwrap

import pytest

from vtsi.__main__ import main
from vtsi.bridge_file import script_bridge
from vtsi.codes.en1991_2 import frequency_limits
from vtsi.errors import BridgeError, SettingError
from vtsi.passage import E_UNITS, PassageSettings, e_unit_slip
from vtsi.sweep import Sweep, beam_bridge

SPEEDS = ["--speeds", "300"]

# a 10 m beam on two roller supports (uy fixed), nothing along x: a mechanism in ux
MECHANISM = """
model basic -ndm 2 -ndf 3
for {set i 0} {$i <= 4} {incr i} { node [expr {$i + 1}] [expr {$i * 2.5}] 0.0 }
fix 1 0 1 0
fix 5 0 1 0
geomTransf Linear 1
for {set i 1} {$i <= 4} {incr i} { element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.9 1 -mass 15000.0 }
track 1 -eleRange 1 4
"""


def _run(tmp_path, capsys, *args):
    """``vtsi sweep ARGS`` -> (exit status, standard output, the lines of standard error)."""
    status = main(["sweep", *map(str, args), "--workers", "1", "--quiet", "--out", str(tmp_path / "out.h5")])
    captured = capsys.readouterr()
    return status, captured.out, [line for line in captured.err.splitlines() if line.strip()]


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


# -- errors of the bridge's eigen analysis name the file ------------------------------------------
def test_a_mechanism_names_the_bridge_file(tmp_path, capsys):
    """No support along x: the eigen analysis's factor of K finds the mechanism at a ux dof; the
    refusal is the bridge's (a BridgeError), and the command line names the file."""
    path = _write(tmp_path, "mechanism.tcl", MECHANISM)
    with pytest.raises(BridgeError, match=r"^sweep: bridge \(its track: 4 elements, x = 0 to 10 m\): stiffness "
                                          r"matrix K is singular or not positive definite at node \d dof 1 \(ux\)"):
        Sweep(script_bridge(path), ["HSLM-A1"], "300")
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS)
    assert status == 2 and len(lines) == 1
    assert re.match(rf"^vtsi sweep: bridge file {re.escape(str(path))}: bridge \(its track: 4 elements, x = 0 to 10 "
                    r"m\): stiffness matrix K is singular or not positive definite at node \d dof 1 \(ux\): the "
                    r"structure is a mechanism", lines[0])


def test_an_orphan_node_names_the_bridge_file(tmp_path, capsys, deck_script):
    """A node no element holds (a pier's base left unbuilt) has neither stiffness nor mass."""
    path = _write(tmp_path, "orphan.py", deck_script(0.6948, "ops.node(999, 10.0, -12.0)\n"))
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS)
    assert status == 2 and len(lines) == 1
    assert lines[0].startswith(f"vtsi sweep: bridge file {path}: bridge (its track: 10 elements, x = 0 to 20 m): "
                               "stiffness matrix K is singular or not positive definite at node 999 dof ")


# -- E in other units --------------------------------------------------------------------------
@pytest.mark.parametrize("unit, factor", E_UNITS)
def test_e_in_other_units_names_the_unit_whose_factor_matches(unit, factor):
    """A 20 m beam of E = 35 GPa typed in kPa, MPa or GPa (the number 3.5e7, 3.5e4 or 35 as Pa):
    f1 ∝ √E reads √factor times low (31.6, 1000, 31623), and that unit is named, the one whose
    factor brings f1 back to the SI beam's."""
    si = Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], "300").runner.frequencies[0]
    low = si / math.sqrt(factor)
    ratio = f"{math.sqrt(factor):.3g}" if factor < 1e4 else f"{math.sqrt(factor):.0f}"
    assert e_unit_slip(low, frequency_limits(20.0)) == f"E in {unit} reads f1 {ratio} times low"
    with pytest.raises(BridgeError, match=rf"^sweep: bridge: first vertical frequency {low:.3g} Hz, below .*; E "
                                          rf"in {unit} reads f1 {ratio} times low\)$"):
        Sweep(beam_bridge([20.0], 3.5e10 / factor, 1.9, 15000.0), ["HSLM-A1"], "300")


def test_a_frequency_no_unit_explains_lists_them_all():
    assert e_unit_slip(1e-9, frequency_limits(20.0)) == ("E in kPa, MPa or GPa reads f1 31.6, 1000 or 31623 "
                                                         "times low")


# -- a deck without mass, a script's own errors ------------------------------------------------------
def test_a_deck_without_mass_is_told_so(tmp_path, capsys, deck_script):
    path = _write(tmp_path, "no_mass.py", deck_script(0.6948).replace("'-mass', 15000.0", "'-mass', 0.0"))
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS)
    assert status == 2 and lines == [f"vtsi sweep: bridge file {path}: the model has no vertical mass (0 kg/m along "
                                     "its track): give its elements their mass per metre [kg/m] (elasticBeamColumn "
                                     "... -mass MU) or its nodes theirs (mass)"]


def test_a_scripts_command_error_shows_no_class_name(tmp_path, capsys):
    """vtsi's own message as every other CLI error; Python's own errors keep their class."""
    path = _write(tmp_path, "ndm3.tcl", "model basic -ndm 3 -ndf 6\n")
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS)
    assert status == 2 and lines == [f"vtsi sweep: bridge script {path}, line 1: model: vtsi is 2-D, -ndm must be 2, "
                                     "got 3"]
    path = _write(tmp_path, "typo.py", "import vtsi.opensees as ops\nops.wipe()\nspans = spanz\n")
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS)
    assert status == 2 and lines == [f"vtsi sweep: bridge script {path}, line 3: NameError: name 'spanz' is not "
                                     "defined"]


# -- a bridge file's time step ----------------------------------------------------------------
# the 20 m beam of beam_toml, its I given (not f1) and its elements per span vtsi's default
BEAM = {"f1_Hz": None, "I_m4": 1.9, "elements_per_span": None}


def test_a_bridge_files_time_step_is_named_by_its_key(tmp_path, capsys, beam_toml):
    """[analysis] dt_s = 1 does not resolve the 20 m beam's first mode, (π / 2L²) √(EI/μ) =
    8.27 Hz: the refusal names the file and the key; --dt on the command line is named as it
    was (not the file's)."""
    path = beam_toml(tmp_path / "dt.toml", BEAM, dt_s=1)
    f1 = math.pi / (2 * 20.0 ** 2) * math.sqrt(3.5e10 * 1.9 / 15000.0)
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS)
    assert status == 2 and len(lines) == 1
    found = re.match(rf"^vtsi sweep: bridge file {re.escape(str(path))}: \[analysis\] dt_s = 1: time step dt = 1 s "
                     r"does not resolve the bridge's first mode \(([\d.]+) Hz, period [\d.]+ s\): take dt <= "
                     r"[\d.]+ s \(T1/8\)$", lines[0])
    assert found and float(found.group(1)) == pytest.approx(f1, rel=2e-3)
    status, _, lines = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS, "--dt", "0.5")
    assert status == 2 and lines[0].startswith("vtsi sweep: time step dt = 0.5 s does not resolve")
    with pytest.raises(SettingError, match=r"^sweep: time step dt = 1 s") as info:
        Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], "300", PassageSettings(dt=1.0))
    assert info.value.setting == "dt"


# -- the summary's damping ---------------------------------------------------------------------
@pytest.mark.parametrize("case", ["none", "--damping", "rayleigh", "rayleigh and --damping", "file"])
def test_the_summary_says_the_damping_the_sweep_used(tmp_path, capsys, deck_script, beam_toml, case):
    """The summary's bridge line ends with the damping the passages had: none (a script without
    damping runs undamped), the sweep's ratio and where it came from, or the script's own (with
    the ratios its rayleigh gives at n0 and the EN cut-off: tests/test_damping_source.py)."""
    if case == "file":
        path = beam_toml(tmp_path / "beam.toml", BEAM, damping=0.0125)
    else:
        path = _write(tmp_path, "deck.py", deck_script(0.6948, "ops.rayleigh(0.1, 0.0, 0.0, 0.002)\n"
                                                       if case.startswith("rayleigh") else ""))
    options = ["--damping", "0.01"] if case.endswith("--damping") else []
    status, out, _ = _run(tmp_path, capsys, path, "--trains", "HSLM-A1", *SPEEDS, *options)
    line = out.splitlines()[1]
    assert status == 0 and line.startswith("bridge: 1 deck; span 20 m; n0 ")
    assert line.endswith({"none": "; damping: none (the script defines none; --damping ZETA)",
                          "--damping": "; damping ζ = 1 % (--damping)",
                          "rayleigh": "; damping: the bridge script's rayleigh αM = 0.1 1/s, βK = 0.002 s (ζ = 3.3 % "
                                      "at n0 = 5 Hz, 28.3 % at the EN cut-off 45.02 Hz) (deck.py)",
                          "rayleigh and --damping": "; damping ζ = 1 % (--damping, over the script's own)",
                          "file": "; damping ζ = 1.25 % (the bridge file's [analysis] damping)"}[case])
