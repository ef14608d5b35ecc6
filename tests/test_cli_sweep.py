"""The ``vtsi`` command line: subcommands, ``vtsi sweep`` (bridge files, options, exit statuses,
nothing written on bad input), ``vtsi trains`` and the bridge-file loader (vtsi.bridge_file).

Every sweep here is tiny (a 20 m beam of 4 elements, Δt = 0.01-0.015 s, 1-3 speeds) so that each
run takes well under 2 s."""
import dataclasses
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.bridge_file import ANALYSIS_KEYS, BRIDGE_KINDS, load_bridge, mass_per_metre, read_bridge_file
from vtsi import errors as vtsi_errors
from vtsi.errors import ModelError
from vtsi.damping import vertical_frequencies
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.sweep import en_speed_grid
from vtsi.sweep_results import SweepResults

E, I, MU, L = 3.5e10, 1.9, 15000.0, 20.0

BEAM = {"f1_Hz": None, "I_m4": I}           # conftest's beam_toml with its I given (not f1) ...
ANALYSIS = {"damping": 0.0125, "dt_s": 0.01}   # ... and these [analysis] defaults

BEAM_TCL = f"""\
# the beam of the `beam` fixture's bridge file, as an OpenSees Tcl script
model basic -ndm 2 -ndf 3
for {{set i 0}} {{$i <= 4}} {{incr i}} {{ node [expr {{$i + 1}}] [expr {{$i * {L / 4}}}] 0.0 }}
fix 1 1 1 0
fix 5 0 1 0
geomTransf Linear 1
for {{set i 1}} {{$i <= 4}} {{incr i}} {{
    element elasticBeamColumn $i $i [expr {{$i + 1}}] 1.0 {E} {I} 1 -mass {MU} -cMass
}}
timeSeries Linear 1
pattern Plain 1 1 {{ load 3 0.0 -1.0e6 0.0 }}
track 1 -eleRange 1 4
puts "built the beam"
"""

BEAM_PY = f"""\
# the beam of the `beam` fixture's bridge file, as an OpenSeesPy script on vtsi's commands
import vtsi.opensees as ops
ops.wipe()
ops.model('basic', '-ndm', 2, '-ndf', 3)
for i in range(5):
    ops.node(i + 1, {L / 4} * i, 0.0)
ops.fix(1, 1, 1, 0)
ops.fix(5, 0, 1, 0)
ops.geomTransf('Linear', 1)
for i in range(1, 5):
    ops.element('elasticBeamColumn', i, i, i + 1, 1.0, {E}, {I}, 1, '-mass', MASS, '-cMass')
TRACKS
print('built the beam')
"""

FAST = ["--trains", "HSLM-A1", "--speeds", "200:300:50", "--workers", "1", "--quiet"]


def py_script(tmp_path, name="beam.py", mass=MU, tracks="ops.track(1, '-eleRange', 1, 4)"):
    path = tmp_path / name
    path.write_text(BEAM_PY.replace("MASS", repr(mass)).replace("TRACKS", tracks))
    return path


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def table_rows(text):
    """The summary table's rows as {quantity: [value, units, train, speed, seed, where..., t]}."""
    lines = text.strip().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("quantity"))
    return {line.split()[0]: line.split()[1:] for line in lines[start + 2:]}


@pytest.fixture
def beam(tmp_path, beam_toml):
    """``beam(name='bridge.toml', bridge=None, **analysis)``: writes ``tmp_path / name``, the 20 m
    beam of conftest's ``beam_toml`` with BEAM and ANALYSIS, its [bridge] keys updated by
    ``bridge`` and its [analysis] by ``analysis`` (a key given None is left out); returns its path."""
    def write_beam(name="bridge.toml", bridge=None, **analysis):
        keys = {key: value for key, value in {**ANALYSIS, **analysis}.items() if value is not None}
        return beam_toml(tmp_path / name, {**BEAM, **(bridge or {})}, **keys)
    return write_beam


def sweep(tmp_path, bridge, *args, out="out.h5"):
    return main(["sweep", str(bridge), *args, "--out", str(tmp_path / out)])


# -- the subcommands -----------------------------------------------------------------------------
def test_help_lists_the_subcommands(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for command in ("run", "sweep", "trains", "SCRIPT.tcl"):
        assert command in out
    with pytest.raises(SystemExit) as info:
        main(["sweep", "--help"])
    out = capsys.readouterr().out
    assert info.value.code == 0 and "--trains" in out and "SI units" in out and "en:LINE_SPEED" in out


def test_no_command_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as info:
        main([])
    err = capsys.readouterr().err.splitlines()
    assert info.value.code == 2 and len(err) == 1 and err[0].startswith("vtsi: error: a command") and "'vtsi -h'" in err[0]


def test_trains_lists_the_catalogue(capsys):
    assert main(["trains"]) == 0
    rows = {line.split()[0]: line for line in capsys.readouterr().out.splitlines() if line.strip()}
    assert "HSLM-A1" in rows and "ICE3" in rows and "HSLM-B" in rows
    assert rows["ICE3"].split()[1] == "force,full" and "D = 24.775 m" in rows["ICE3"]
    assert rows["HSLM-A1"].split()[1] == "force" and "kN" in rows["HSLM-A1"]


def test_trains_reads_axle_tables_as_a_sweep_does(tmp_path, capsys):
    """vtsi trains TABLE.csv: one line per table, its axles, total and per-axle load, length and
    where its D comes from (a CSV train's were seen only inside a sweep); a bad table gets one
    line naming the file and line, the others theirs, and the exit status 2."""
    table = tmp_path / "talgo.csv"
    table.write_text("position_m,load_kN\n" + "".join(f"{13.14 * k:.2f},{170 if k < 2 else 120}\n" for k in range(8)))
    assert main(["trains", str(table)]) == 0
    line, = capsys.readouterr().out.splitlines()
    assert line.startswith(f"{table}: 8 axles, 1060 kN in all (120 to 170 kN an axle), 91.98 m from the first axle "
                           "to the last; ")
    assert "13.14 m" in line                          # its D, read from its dynamic signature
    tonnes = tmp_path / "t.csv"
    tonnes.write_text("position_m,load_kN\n0,17\n3,17\n")
    assert main(["trains", str(tonnes), str(table)]) == 2         # the good one still read
    out, err = capsys.readouterr()
    assert out.splitlines() == [line] and err.splitlines() == [
        f"vtsi trains: {tonnes} line 2: load_kN 17 is not a railway axle load (30 to 500 kN); is the table in "
        "tonnes? (17 t = 166.8 kN)"]
    cut = tmp_path / "cut.csv"
    cut.write_bytes(b"\xff\xfe\x00\x01garbage\x80\x81")          # a UTF-16 mark, then no UTF-16
    assert main(["trains", str(cut)]) == 2
    assert capsys.readouterr().err.splitlines() == [f"vtsi trains: axle table {cut}: not UTF-16 text, though it "
                                                    "starts with its byte-order mark (truncated data at byte 12)"]


def test_run_subcommand_and_the_original_form(tmp_path, capfd):
    pytest.importorskip("tkinter")
    script = write(tmp_path, "args.tcl", 'puts "args [llength $argv] $argv"\nexit 3\n')
    assert main(["run", str(script), "x", "-y"]) == 3
    assert "args 2 x -y" in capfd.readouterr().out          # Tcl's puts writes to file descriptor 1
    assert main([str(script), "x", "-y"]) == 3
    assert "args 2 x -y" in capfd.readouterr().out
    with pytest.raises(SystemExit) as info:                    # a bad command line: one line, status 2
        main(["run", str(tmp_path / "missing.tcl")])
    err = capfd.readouterr().err.splitlines()
    assert info.value.code == 2 and len(err) == 1 and "missing.tcl: no such file" in err[0], err


# -- vtsi sweep ------------------------------------------------------------------------------------
def test_sweep_subprocess_prints_the_critical_case(tmp_path, beam):
    """A real ``python -m vtsi sweep`` in a fresh directory: default results file, the table."""
    bridge = beam()
    proc = subprocess.run([sys.executable, "-m", "vtsi", "sweep", "bridge.toml", "--trains", "HSLM-A1",
                           "--speeds", "200:300:50", "--dt", "0.01", "--workers", "1"],
                          capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert bridge.exists() and (tmp_path / "sweep.h5").exists()
    assert not (tmp_path / "sweep.h5.partial").exists()
    results = SweepResults(tmp_path / "sweep.h5")
    assert results.n_done == 3 and list(results.speeds_kmh) == [200.0, 250.0, 300.0]
    rows = table_rows(proc.stdout)
    assert proc.stdout.startswith("3 of 3 cases")
    for quantity in ("deflection_min", "acceleration_absmax"):
        critical = results.critical(quantity)
        value, units, train, speed = rows[quantity][:4]
        assert train == "HSLM-A1" and float(speed) == critical["speed_kmh"]
        assert math.isclose(float(value), critical["value"], rel_tol=1e-4)
    assert "Traceback" not in proc.stderr


def test_sweep_toml_in_process(tmp_path, capsys, beam):
    bridge = beam()
    assert sweep(tmp_path, bridge, *FAST) == 0
    out = capsys.readouterr().out
    assert out.startswith("3 of 3 cases") and "HSLM-A1" in table_rows(out)["deflection_min"]
    results = SweepResults(tmp_path / "out.h5")
    ident = results.identity
    assert ident["bridge"] == {"kind": "beam", "spans_m": [L], "E_Pa": E, "I_m4": I, "mu_kg_m": MU,
                               "elements_per_span": 4, "A_m2": 1.0}
    assert ident["settings"]["dt"] == 0.01 and ident["settings"]["damping"] == 0.0125   # from [analysis]
    # resume: nothing left to run, the same table; overwrite with other options: they win over [analysis]
    assert sweep(tmp_path, bridge, *FAST, "--resume") == 0
    assert capsys.readouterr().out == out
    options = ["--dt", "0.015", "--damping", "0.02", "--integrator", "HHT(0.9)"]
    assert sweep(tmp_path, bridge, *FAST, "--overwrite", *options) == 0
    settings = SweepResults(tmp_path / "out.h5").identity["settings"]
    assert settings["dt"] == 0.015 and settings["damping"] == 0.02 and settings["integrator"] == "HHT(0.9)"


def test_script_bridges_equal_the_described_beam(tmp_path, capsys, beam):
    """The same beam as a TOML description, an OpenSeesPy script and a Tcl script: the same
    envelopes; a script's prints go to stderr, its load pattern is dropped."""
    toml = beam()
    script = py_script(tmp_path)
    args = ["--trains", "HSLM-A1,ICE3", "--speeds", "250,300", "--dt", "0.01", "--damping", "0.0125", "--workers", "1",
            "--quiet"]
    assert sweep(tmp_path, toml, *args, out="toml.h5") == 0
    assert sweep(tmp_path, script, *args, out="py.h5") == 0
    captured = capsys.readouterr()
    assert "built the beam" not in captured.out and "built the beam" in captured.err
    reference, from_py = SweepResults(tmp_path / "toml.h5"), SweepResults(tmp_path / "py.h5")
    bridge = from_py.identity["bridge"]
    assert bridge["kind"] == "script" and bridge["path"] == str(script) and bridge["track"] == 1
    assert len(bridge["sha256"]) == 64
    for q in reference.quantities:
        np.testing.assert_allclose(from_py.envelope(q), reference.envelope(q), rtol=1e-9, atol=1e-15)
    pytest.importorskip("tkinter")
    tcl = write(tmp_path, "beam.tcl", BEAM_TCL)
    assert sweep(tmp_path, tcl, *args, out="tcl.h5") == 0
    assert "built the beam" not in capsys.readouterr().out
    from_tcl = SweepResults(tmp_path / "tcl.h5")
    assert from_tcl.identity["bridge"]["kind"] == "script"
    for q in reference.quantities:
        np.testing.assert_allclose(from_tcl.envelope(q), reference.envelope(q), rtol=1e-9, atol=1e-15)


def test_track_choice(tmp_path, capsys):
    two = "ops.track(1, '-eleRange', 1, 4)\nops.track(2, '-ele', 1, 2)"
    script = py_script(tmp_path, tracks=two)
    assert sweep(tmp_path, script, *FAST) == 2
    assert "defines tracks 1, 2; choose one (--track TAG)" in capsys.readouterr().err
    assert load_bridge(script, track=2).track_elements == [1, 2]
    assert sweep(tmp_path, script, *FAST, "--track", "1") == 0
    assert SweepResults(tmp_path / "out.h5").identity["bridge"]["track"] == 1


def test_hslm_a_shorthand_and_catalogue_spelling(tmp_path, capsys, beam):
    bridge = beam()
    assert sweep(tmp_path, bridge, "--trains", "hslm-a,ice3", "--speeds", "300", "--dt", "0.015", "--workers", "1",
                 "--quiet") == 0
    assert SweepResults(tmp_path / "out.h5").trains == [f"HSLM-A{k}" for k in range(1, 11)] + ["ICE3"]


def test_en_speed_grid(tmp_path, capsys, beam):
    bridge = beam()
    assert sweep(tmp_path, bridge, "--trains", "A1", "--speeds", "en:300", "--dt", "0.015", "--workers", "1",
                 "--quiet") == 0
    results = SweepResults(tmp_path / "out.h5")
    np.testing.assert_allclose(results.speeds_kmh, en_speed_grid(300.0, results.frequencies_hz, [18.0]))
    assert results.speeds_kmh[0] == 144.0 and results.speeds_kmh[-1] == 360.0


def test_csv_train(tmp_path, capsys, beam):
    bridge = beam()
    axles = write(tmp_path, "axles.csv", "position_m,load_kN\n0.0,200.0\n3.0,200.0\n")
    assert sweep(tmp_path, bridge, "--trains", str(axles), "--speeds", "200", "--workers", "1", "--quiet") == 0
    assert table_rows(capsys.readouterr().out)["deflection_min"][2] == str(axles)


def test_a_failing_passage_exits_1_and_keeps_the_cases_finished_before_it(tmp_path, capsys, monkeypatch, beam):
    """The sweep stops at the failing case with its one line; the case finished before it (in
    the same task: workers 1) is in the file, and the line says so."""
    bridge = beam()
    run = PassageRunner.run

    def failing(self, train, speed_kmh, seed=-1):
        if speed_kmh == 250.0:
            raise ModelError("no good at 250")
        return run(self, train, speed_kmh, seed)

    monkeypatch.setattr(PassageRunner, "run", failing)
    assert sweep(tmp_path, bridge, *FAST) == 1
    err = capsys.readouterr().err.strip().splitlines()
    out = tmp_path / "out.h5"
    assert len(err) == 1 and err[0].startswith("vtsi sweep: case HSLM-A1/250kmh/smooth: no good at 250") and \
        err[0].endswith(f"(1 of 3 cases are in {out})")
    assert sorted(os.listdir(tmp_path)) == ["bridge.toml", "out.h5"]
    kept = SweepResults(out)
    assert kept.n_done == 1 and not np.isnan(kept.start_positions()[0, 0, 0]) and kept.speeds_kmh[0] == 200.0


# -- bad input: exit 2, one line, nothing written ------------------------------------------------
def _other_sweep(tmp_path):
    """An existing results file of another sweep (other speeds), of the test's bridge.toml."""
    assert main(["sweep", str(tmp_path / "bridge.toml"), "--trains", "HSLM-A1", "--speeds", "300", "--workers", "1",
                 "--quiet", "--out", str(tmp_path / "out.h5")]) == 0


BAD = {
    "unknown train": (["--trains", "HSLM-X9", "--speeds", "200"], None, "unknown train 'HSLM-X9'"),
    "empty speed range": (["--trains", "A1", "--speeds", "420:140:5"], None, "empty range"),
    "speed zero": (["--trains", "A1", "--speeds=0,100"], None, "must be > 0 km/h"),
    "negative speed": (["--trains", "A1", "--speeds=-100:200:50"], None, "must be > 0 km/h"),
    "bad speeds": (["--trains", "A1", "--speeds", "fast"], None, "START:STOP:STEP"),
    "bad EN line speed": (["--trains", "A1", "--speeds", "en:fast"], None, "en:LINE_SPEED_KMH"),
    "no train": (["--trains", ",", "--speeds", "200"], None, "no train"),
    "missing bridge file": (["--trains", "A1", "--speeds", "200"], "missing.toml", "no such file"),
    "unknown bridge type": (["--trains", "A1", "--speeds", "200"], "bridge.txt", "unknown type '.txt'"),
    "script without a track": (["--trains", "A1", "--speeds", "200"], "notrack.py", "defines no track"),
    "script in t/m": (["--trains", "A1", "--speeds", "200"], "tonnes.py", "1000 times too small"),
    "script failing": (["--trains", "A1", "--speeds", "200"], "failing.py", "failing.py, line 2: NameError"),
    "script without vtsi's commands": (["--trains", "A1", "--speeds", "200"], "empty.py", "import vtsi.opensees"),
    "unknown key": (["--trains", "A1", "--speeds", "200"], "typo.toml", "unknown key 'I_m5' in [bridge]"),
    "unknown analysis key": (["--trains", "A1", "--speeds", "200"], "typo2.toml", "unknown key 'dt' in [analysis]"),
    "bad analysis value": (["--trains", "A1", "--speeds", "200"], "typo3.toml", "[analysis] sweep settings: dt"),
    "a file that is not UTF-8": (["--trains", "A1", "--speeds", "200"], "latin1.toml", "not valid TOML ('utf-8' codec"),
    "a kind that is not a name": (["--trains", "A1", "--speeds", "200"], "kind.toml",
                                  "kind must be one of 'beam', 'script', got ['beam']"),
    "too many elements": (["--trains", "A1", "--speeds", "200"], "fine.toml",
                          "elements_per_span must be an even integer from 2 to 1000, got 100000000"),
    "spans in mm": (["--trains", "A1", "--speeds", "200"], "mm.toml",
                    "spans_m: a span of 20000 m is not a railway span (1 to 1000 m); is spans_m in mm?"),
    "a damping percentage": (["--trains", "A1", "--speeds", "200", "--damping", "1.3"], None,
                             "damping 1.3 is 130 % of critical, above the 20 % any bridge has"),
    "a seed twice": (["--trains", "A1", "--speeds", "200"], "seeds.toml",
                     "seeds must be a list of different integers >= 0, got [1, 1]"),
    "a negative modal_hz on the FE bridge": (["--trains", "A1", "--speeds", "200"], "modal.toml",
                                             "modal_hz must be > 0 and finite, got -5.0"),
    "track of a beam": (["--trains", "A1", "--speeds", "200", "--track", "1"], None, "is for model scripts"),
    "unwritable output path": (["--trains", "A1", "--speeds", "200", "--out", "/nonexistent/x.h5"], None,
                               "/nonexistent does not exist"),
    "unknown integrator": (["--trains", "A1", "--speeds", "200", "--integrator", "Euler"], None, "unknown integrator"),
    "unknown irregularity": (["--trains", "A1", "--speeds", "200", "--irregularity", "bumpy"], None,
                             "unknown irregularity 'bumpy'"),
    "seeds on a smooth rail": (["--trains", "A1", "--speeds", "200", "--seeds", "0,1"], None, "--irregularity"),
    "a bridge file's seeds on a smooth rail": (["--trains", "A1", "--speeds", "200"], "smooth_seeds.toml",
                                               "[analysis] seeds: rail samples need an irregular rail"),
    "a train twice in two spellings": (["--trains", "HSLM-A1,hslm-a1", "--speeds", "200"], None,
                                       "train HSLM-A1 is listed twice (names ignore case; 'A1' is 'HSLM-A1'): "
                                       "'HSLM-A1,hslm-a1'"),                      # the text given, as typed
    "bad seeds": (["--trains", "ICE3", "--speeds", "200", "--cars", "full", "--irregularity", "german-low", "--seeds",
                   "-1"], None, "integers >= 0"),
    "a rough rail under moving forces": (["--trains", "A1", "--speeds", "200", "--irregularity", "german-low"], None,
                                         "an irregular rail (german-low) acts through the wheels of cars; moving forces "
                                         "(cars='force') do not feel it"),
    "no cars": (["--trains", "A1", "--speeds", "200", "--cars", "full"], None,
                "has no fidelity 'full'; it supports ['force']; a sweep takes one fidelity for all its trains"),
    "another sweep with --resume": (["--trains", "A1", "--speeds", "200", "--resume"], _other_sweep,
                                    "holds a different sweep (it differs in speeds_kmh (200 km/h is here, not in the "
                                    "file; 300 km/h is in the file, not here)); use another file, or --overwrite"),
    "an existing file": (["--trains", "A1", "--speeds", "300"], _other_sweep, "exists; --resume continues"),
}

def _latin1(path):
    """``path`` with a comment in Latin-1 (a byte that is not UTF-8) before its TOML."""
    path.write_bytes(("# a \u00b0 20 m beam\n" + path.read_text()).encode("latin-1"))
    return path


BAD_SCRIPTS = {
    "notrack.py": lambda p: py_script(p, "notrack.py", tracks=""),
    "tonnes.py": lambda p: py_script(p, "tonnes.py", mass=15.0),
    "failing.py": lambda p: write(p, "failing.py", "import vtsi.opensees as ops\nops.model(basic)\n"),
    "empty.py": lambda p: write(p, "empty.py", "x = 1\n"),
}
BAD_FILES = {                   # bridge files: the shared beam with one thing wrong
    "typo.toml": lambda beam: beam("typo.toml", {"I_m4": None, "I_m5": I}),
    "typo2.toml": lambda beam: beam("typo2.toml", dt_s=None, dt=0.01),
    "typo3.toml": lambda beam: beam("typo3.toml", dt_s=-1.0),
    "bridge.txt": lambda beam: beam("bridge.txt"),
    "latin1.toml": lambda beam: _latin1(beam("latin1.toml")),
    "kind.toml": lambda beam: beam("kind.toml", {"kind": ["beam"]}),
    "fine.toml": lambda beam: beam("fine.toml", {"elements_per_span": 100000000}),
    "mm.toml": lambda beam: beam("mm.toml", {"spans_m": [20000.0]}),
    "seeds.toml": lambda beam: beam("seeds.toml", seeds=[1, 1]),
    "smooth_seeds.toml": lambda beam: beam("smooth_seeds.toml", seeds=[0, 1]),
    "modal.toml": lambda beam: beam("modal.toml", modal_hz=-5.0),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_exits_2_with_one_line_and_writes_nothing(case, tmp_path, capsys, beam):
    args, setup, message = BAD[case]
    bridge = beam()
    if callable(setup):
        setup(tmp_path)
    elif setup in BAD_SCRIPTS:
        bridge = BAD_SCRIPTS[setup](tmp_path)
    elif setup in BAD_FILES:
        bridge = BAD_FILES[setup](beam)
    elif setup is not None:
        bridge = tmp_path / setup
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    capsys.readouterr()
    out = ["--out", str(tmp_path / "out.h5")] if "--out" not in args else []
    status = main(["sweep", str(bridge), *args, *out, "--workers", "1", "--quiet"])
    captured = capsys.readouterr()
    err = [line for line in captured.err.strip().splitlines() if line != "built the beam"]   # the script's print
    assert status == 2, captured.err
    assert len(err) == 1 and err[0].startswith("vtsi sweep: ") and message in err[0], err
    assert "=True" not in err[0], err                  # the command line's options, not the API's arguments
    assert captured.out == ""
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before      # nothing written or changed


@pytest.mark.parametrize("command", ["sweep", "check"])
@pytest.mark.parametrize("args, message", [
    (["--workers", "0"], "argument --workers: expected an integer >= 1, got '0'"),
    (["--resume", "--overwrite"], "argument --overwrite: not allowed with argument --resume"),
    (["--cars", "half"], "argument --cars: invalid choice: 'half'"),
    (["--bridge-model", "modl"], "argument --bridge-model: invalid choice: 'modl'"),
    (["--modes", "40"], "unrecognized arguments: --modes 40"),
    ([], "the following arguments are required: --speeds"),
], ids=["workers", "resume-overwrite", "cars", "bridge-model", "unknown-option", "missing"])
def test_usage_errors_exit_2_with_one_line(command, args, message, tmp_path, capsys, beam):
    """A bad command line is told as every other bad input: one line naming the argument,
    with where help is (not argparse's usage block), exit status 2, nothing written."""
    if command == "check" and not args:
        args, message = ["--speeds"], "argument --speeds: expected one argument"
    bridge = beam()
    needed = ["--trains", "A1", "--speeds", "200"] if args else ["--trains", "A1"]
    with pytest.raises(SystemExit) as info:
        main([command, str(bridge), *needed, *args, "--out", str(tmp_path / "out.h5")])
    err = capsys.readouterr().err.splitlines()
    assert info.value.code == 2 and len(err) == 1, err
    assert err[0].startswith(f"vtsi {command}: error: ") and message in err[0] and f"'vtsi {command} -h'" in err[0]
    assert sorted(os.listdir(tmp_path)) == ["bridge.toml"]


# -- the bridge-file loader ------------------------------------------------------------------------
def test_f1_gives_the_frequency(beam):
    bridge = load_bridge(beam("f1.toml", {"I_m4": None, "f1_Hz": 5.0, "elements_per_span": 20}))
    assert bridge.description["f1_Hz"] == 5.0
    f, _ = vertical_frequencies(bridge.model, 1)
    assert abs(f[0] / 5.0 - 1) < 1e-4
    with pytest.raises(ModelError, match="either I_m4 or f1_Hz"):
        load_bridge(beam("both.toml", {"f1_Hz": 5.0}))


@pytest.mark.parametrize("E, damping, dt", [("3.5e+10", "0.0125", "0.01"), ("35e9", "125e-4", "1e-2")],
                         ids=["yaml-1.1-floats", "exponents-without-a-dot"])
def test_yaml_description_equals_toml(tmp_path, beam, E, damping, dt):
    """YAML 1.2's floats: PyYAML (YAML 1.1) read ``35e9`` and ``1e-2`` as texts, refused as not
    numbers; a quoted one stays a text, refused."""
    pytest.importorskip("yaml")
    yaml_text = (f"bridge:\n  kind: beam\n  spans_m: [20.0]\n  E_Pa: {E}\n  I_m4: 1.9\n  mu_kg_m: 15000.0\n"
                 f"  elements_per_span: 4\nanalysis:\n  damping: {damping}\n  dt_s: {dt}\n")
    a = read_bridge_file(write(tmp_path, "b.yaml", yaml_text))
    b = read_bridge_file(beam("b.toml"))
    assert a.bridge.description == b.bridge.description and a.settings == b.settings == {"damping": 0.0125, "dt": 0.01}
    with pytest.raises(ModelError, match=f"dt must be a number, got '{dt}'"):
        read_bridge_file(write(tmp_path, "q.yaml", yaml_text.replace(f"dt_s: {dt}", f'dt_s: "{dt}"')))


def test_script_kind_in_a_description(tmp_path):
    """A description may point at a script (path relative to it) and carry [analysis] defaults."""
    (tmp_path / "models").mkdir()
    py_script(tmp_path / "models")
    text = '[bridge]\nkind = "script"\npath = "models/beam.py"\ntrack = 1\n[analysis]\ndt_s = 0.02\nseeds = [0, 1]\n'
    source = read_bridge_file(write(tmp_path, "s.toml", text))
    assert source.bridge.description["path"] == str(tmp_path / "models" / "beam.py")
    assert source.settings == {"dt": 0.02} and source.seeds == (0, 1)
    assert mass_per_metre(source.bridge) == pytest.approx(MU)


def test_analysis_keys_cover_the_passage_settings():
    assert set(ANALYSIS_KEYS.values()) == {f.name for f in dataclasses.fields(PassageSettings)}
    assert set(BRIDGE_KINDS) >= {"beam", "script"}


def test_mass_check_can_be_switched_off(tmp_path):
    script = py_script(tmp_path, "model.py", mass=15.0)
    with pytest.raises(ModelError, match="15 kg/m along its track"):
        load_bridge(script)
    assert mass_per_metre(load_bridge(script, min_mass_per_metre=0)) == pytest.approx(15.0)


def test_cli_doc_exists():
    text = (Path(__file__).parent.parent / "docs" / "cli.md").read_text()
    for word in ("vtsi sweep", "vtsi trains", "vtsi run", "--resume", "Exit status", "SI"):
        assert word in text


def test_tcl_runner_without_tkinter_names_the_package(tmp_path, capsys, monkeypatch):
    """``vtsi run`` on a Python without tkinter: one line naming python3-tk, exit status 1."""
    script = tmp_path / "m.tcl"
    script.write_text("model basic -ndm 2 -ndf 3\n")
    monkeypatch.setitem(sys.modules, "tkinter", None)          # import tkinter now fails
    assert main(["run", str(script)]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "python3-tk" in err and "tkinter" in err


def test_a_bridge_script_in_other_units_is_refused(tmp_path):
    """A sweep's trains and results are SI: a Tcl bridge script that declares units('kN', 'm') is
    refused, naming them (converting the bridge would change every result's units)."""
    script = write(tmp_path, "kn.tcl", BEAM_TCL.replace("model basic -ndm 2 -ndf 3\n", "model basic -ndm 2 -ndf 3\nunits kN m\n"))
    with pytest.raises(ModelError, match=r"declares units kN, m, t .*must be SI"):
        load_bridge(script)


# -- one writer, overwrite, a closed pipe, SIGTERM ---------------------------------------------------
def test_a_second_run_on_a_results_file_exits_2_naming_the_first(tmp_path, capsys, beam):
    """Two runs on one file corrupted it (empty train names, '882 of 570 cases', exit 0)."""
    from vtsi.sweep_results import ResultsFileLock
    bridge = beam()
    out = tmp_path / "out.h5"
    lock = ResultsFileLock(str(out))                       # as another run writing out.h5 holds it
    try:
        for extra in ([], ["--overwrite"]):
            assert sweep(tmp_path, bridge, *FAST, *extra) == 2
            err = capsys.readouterr().err.strip().splitlines()
            assert err == [f"vtsi sweep: results file {out} is being written by another sweep (pid {os.getpid()}); "
                           "wait for it to end, or use another file"]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["bridge.toml", "out.h5.lock"]
    finally:
        lock.release()
    assert sweep(tmp_path, bridge, *FAST) == 0


def test_an_interrupted_overwrite_keeps_the_old_file(tmp_path, capsys, monkeypatch, beam):
    """--overwrite deleted the old results before the new sweep had any; the message counted
    the old file's cases as the new sweep's."""
    from vtsi.sweep_results import ResultsWriter
    bridge = beam()
    out = tmp_path / "out.h5"
    assert sweep(tmp_path, bridge, "--trains", "HSLM-A1", "--speeds", "200,250,300,350", "--workers", "1",
                 "--quiet") == 0
    write_batch = ResultsWriter.write

    def interrupted(self, results):
        write_batch(self, results)
        raise KeyboardInterrupt
    monkeypatch.setattr(ResultsWriter, "write", interrupted)
    capsys.readouterr()
    assert sweep(tmp_path, bridge, *FAST, "--overwrite") == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"vtsi sweep: interrupted (3 of 3 cases of the new sweep are in {out}.new; {out} keeps the old "
                   "sweep until the new one is complete: --overwrite again continues it)"]
    assert SweepResults(out).n_done == 4                   # the old sweep, whole
    monkeypatch.undo()
    assert sweep(tmp_path, bridge, *FAST, "--overwrite") == 0
    assert SweepResults(out).n_done == 3 and len(SweepResults(out).speeds_kmh) == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bridge.toml", "out.h5"]


def test_a_closed_standard_output_is_not_an_error(tmp_path, beam):
    """'vtsi sweep ... | head -1' printed a BrokenPipeError traceback."""
    bridge = beam()
    proc = subprocess.Popen([sys.executable, "-m", "vtsi", "sweep", str(bridge), *FAST, "--out", "out.h5"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.stdout.close()                          # the reader is gone before the table is printed
    err = proc.stderr.read()
    assert proc.wait(120) == 0 and err == "", err
    assert SweepResults(tmp_path / "out.h5").n_done == 3



def test_a_closed_pipe_of_both_streams_is_not_an_error(tmp_path, beam):
    """'vtsi sweep ... 2>&1 | head -1' exited 1 ('a passage failed') now and then: the closing
    line on standard error ('results in ...') met the closed pipe."""
    bridge = beam()
    proc = subprocess.Popen([sys.executable, "-m", "vtsi", "sweep", str(bridge), *FAST[:-1], "--out", "out.h5"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    proc.stdout.close()                          # the reader is gone before anything is printed
    assert proc.wait(120) == 0
    assert SweepResults(tmp_path / "out.h5").n_done == 3

@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SIGTERM and /proc")
def test_sigterm_stops_like_ctrl_c(tmp_path, beam):
    """SIGTERM (Slurm, systemd) exited 143 without a word, leaving pool workers and out.h5.partial."""
    import signal
    import time
    psutil = pytest.importorskip("psutil")
    bridge = beam()
    out = tmp_path / "out.h5"
    proc = subprocess.Popen([sys.executable, "-m", "vtsi", "sweep", str(bridge), "--trains", "HSLM-A", "--speeds",
                             "140:420:5", "--dt", "0.0005", "--workers", "2", "--quiet", "--out", str(out)],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None:
            try:
                if SweepResults(out).n_done >= 1:
                    break
            except vtsi_errors.SweepError:
                pass
            time.sleep(0.05)
        workers = psutil.Process(proc.pid).children()
        assert proc.poll() is None and workers, "the sweep ended before it could be terminated"
        proc.send_signal(signal.SIGTERM)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    done = SweepResults(out).n_done
    assert proc.returncode == 143 and stdout == "", stderr
    assert stderr.strip() == f"vtsi sweep: terminated ({done} of 570 cases are in {out}; --resume runs the rest)"
    gone, alive = psutil.wait_procs(workers, timeout=10)
    assert not alive
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bridge.toml", "out.h5"]


def test_the_modal_settings_from_the_command_line(tmp_path, beam):
    """``--bridge-model`` offers every bridge model ('modal-stepped' was reachable only from a
    bridge file) and ``--modal-hz`` sets the basis; both are stored with the sweep's settings."""
    from vtsi.sweep_results import SweepResults
    bridge = beam()
    assert sweep(tmp_path, bridge, *FAST, "--bridge-model", "modal-stepped", "--modal-hz", "40", "--damping", "0.01") == 0
    settings = SweepResults(tmp_path / "out.h5").identity["settings"]
    assert settings["bridge"] == "modal-stepped" and settings["modal_hz"] == 40.0
