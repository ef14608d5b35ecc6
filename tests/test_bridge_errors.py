"""What is wrong with the bridge itself raises a :class:`~vtsi.errors.BridgeError`: a
``BridgeModelError`` (a ModelError) where the bridge is built or read, a ``BridgeSweepError`` (a
SweepError) where a Sweep refuses it. ``vtsi sweep`` and ``vtsi check`` name the bridge file of
exactly those errors. Before, they matched the start of the message ('bridge', 'track', 'modal
bridge', "the bridge's"): a reworded message lost the file's name, and a train's axle table
named track.csv got the bridge file's."""
import textwrap

import pytest

from vtsi.__main__ import main
from vtsi.bridge_file import read_bridge_file, script_bridge
from vtsi.errors import (BridgeError, BridgeModelError, BridgeSweepError, ModelError, PassageError, SweepError,
                         VtsiError)
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.sweep import Sweep, beam_bridge
from vtsi.track import Track

FEW_MODES_TCL = """
    model basic -ndm 2 -ndf 3
    for {set i 0} {$i <= 2} {incr i} { node [expr {$i + 1}] [expr {$i * 5.0}] 0.0 }
    fix 1 1 1 0
    fix 3 0 1 0
    geomTransf Linear 1
    for {set i 1} {$i <= 2} {incr i} { element elasticBeamColumn $i $i [expr {$i + 1}] 3.0 3.5e10 0.3 1 -mass 10000.0 }
    track 1 -eleRange 1 2
    """
FEW_MODES = "bridge (its track: 2 elements, x = 0 to 10 m): vertical frequencies: 3 asked"
SPEEDS = ["--speeds", "300:360:60"]

# each kind of bridge problem the analysis finds: (script tail or Tcl text, options, the message's start)
BRIDGE_PROBLEMS = {
    "too few vertical modes": (FEW_MODES_TCL, [], FEW_MODES),
    "a track stopping mid-deck": ("ops.track(2, '-eleRange', 1, 5)\n", ["--track", "2"],
                                  "track: its last node 6 (x = 10 m) carries no support, and the deck goes on"),
    "a first frequency in other units": (0.01, [], "bridge: first vertical frequency 0.6 Hz, below 0.2 x EN 1991-2 "
                                                   "Figure 6.10's lower limit"),
    "modalDamping on the FE bridge": ("ops.eigen(4)\nops.modalDamping(0.02)\n", [],
                                      "the bridge's modalDamping (0.02, 0.02, 0.02, 0.02) damps its modes"),
    "an overdamped mode of the modal bridge": ("ops.rayleigh(0.0, 0.0, 0.0, 0.1)\n", ["--bridge-model", "modal"],
                                               "modal bridge: mode 1 (5 Hz) has ζ = 1.571 >= 1"),
}


def _bridge_file(tmp_path, deck_script, problem):
    """The bridge file of ``problem`` (a key of BRIDGE_PROBLEMS) and the options it needs."""
    text, options, _ = BRIDGE_PROBLEMS[problem]
    if text is FEW_MODES_TCL:
        path = tmp_path / "few.tcl"
        path.write_text(textwrap.dedent(text))
    else:
        path = tmp_path / "deck.py"
        path.write_text(deck_script(text, "") if isinstance(text, float) else deck_script(0.6948, text))
    return path, options


def _run(command, *args, capsys, out):
    """``vtsi COMMAND ARGS`` -> (exit status, the lines of standard error)."""
    status = main([command, *map(str, args), "--workers", "1", "--out", str(out)])
    return status, [line for line in capsys.readouterr().err.splitlines() if line.strip()]


# -- (a) every bridge problem names the bridge file ---------------------------------------------
# (vtsi check always damps the bridge, --damping or Table 6.6's: its ratio replaces the script's
# modalDamping and Rayleigh damping, which cannot then be refused)
@pytest.mark.parametrize("command, problem", [("sweep", p) for p in BRIDGE_PROBLEMS]
                         + [("check", p) for p in list(BRIDGE_PROBLEMS)[:3]])
def test_each_bridge_problem_names_the_bridge_file_on_the_command_line(tmp_path, capsys, deck_script, command,
                                                                       problem):
    """One line 'vtsi sweep: bridge file PATH: <the message>', exit 2, nothing written, for a
    problem the Sweep finds (a BridgeSweepError, 'sweep: ' dropped) in both commands."""
    extra = ["--damping", "0.01"] if command == "check" else []
    path, options = _bridge_file(tmp_path, deck_script, problem)
    out = tmp_path / "out.h5"
    status, lines = _run(command, path, "--trains", "HSLM-A1", *SPEEDS, *options, *extra, capsys=capsys, out=out)
    assert status == 2 and len(lines) == 1, lines
    assert lines[0].startswith(f"vtsi {command}: bridge file {path}: {BRIDGE_PROBLEMS[problem][2]}"), lines[0]
    assert not out.exists()


@pytest.mark.parametrize("options", [["--line-speed", "300", "--damping", "0.01"],   # the EN speeds' runner
                                     ["--speeds", "300", "--bridge-type", "steel"]])  # the Table 6.6 span's runner
def test_vtsi_check_names_the_bridge_file_of_a_bridge_problem_found_before_the_sweep(tmp_path, capsys, options):
    """vtsi check reads the bridge before it builds the sweep (the EN speed grid's resonances,
    Table 6.6's span): there the problem is a BridgeModelError, not the Sweep's, and still names
    the file."""
    path = tmp_path / "few.tcl"
    path.write_text(textwrap.dedent(FEW_MODES_TCL))
    status, lines = _run("check", path, "--trains", "HSLM-A1", *options, capsys=capsys, out=tmp_path / "out.h5")
    assert status == 2 and len(lines) == 1, lines
    assert lines[0].startswith(f"vtsi check: bridge file {path}: {FEW_MODES}"), lines[0]


def test_a_bridge_error_that_names_its_file_is_not_prefixed_again(tmp_path, capsys, deck_script):
    """A bridge script's own errors name it already ('bridge script PATH: ...'): once only."""
    path = tmp_path / "deck.py"
    path.write_text(deck_script(0.6948, "ops.track(2, '-ele', 1, 42)\n"))
    status, lines = _run("sweep", path, "--trains", "HSLM-A1", *SPEEDS, "--track", "2", capsys=capsys,
                         out=tmp_path / "out.h5")
    assert status == 2 and lines == [f"vtsi sweep: bridge script {path}: track 2: element 42 does not exist"]
    with pytest.raises(BridgeModelError):
        read_bridge_file(path, 2)


# -- (b) what is not the bridge's is not prefixed -------------------------------------------------
def test_an_axle_table_named_track_is_not_the_bridges(tmp_path, capsys, deck_script, monkeypatch):
    """A malformed axle table track.csv: 'vtsi sweep: track.csv line 2: ...' (before: 'vtsi sweep:
    bridge file deck.py: track.csv line 2: ...', its message starting with 'track')."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "track.csv").write_text("position_m,load_kN\n0,abc\n")
    path = tmp_path / "deck.py"
    path.write_text(deck_script(0.6948))
    status, lines = _run("sweep", path, "--trains", "track.csv", *SPEEDS, capsys=capsys, out=tmp_path / "out.h5")
    assert status == 2 and lines == ["vtsi sweep: track.csv line 2: cannot read position_m and load_kN from "
                                     "['0', 'abc']"]
    with pytest.raises(SweepError, match=r"^sweep: track\.csv line 2") as excinfo:
        Sweep(script_bridge(path), ["track.csv"], "300", PassageSettings())
    assert not isinstance(excinfo.value, BridgeError)


def test_what_the_sweep_refuses_of_its_settings_or_trains_is_not_a_bridge_error(tmp_path, deck_script):
    """The Sweep's other refusals (a speed the time step cannot resolve, a modal_hz below the
    bridge's first mode: both mention the bridge) stay plain SweepErrors."""
    path = tmp_path / "deck.py"
    path.write_text(deck_script(0.6948))
    bridge = script_bridge(path)
    for settings, words in ((PassageSettings(dt=0.3), r"sweep: time step dt = 0\.3 s does not resolve the bridge's"),
                            (PassageSettings(bridge="modal", modal_hz=1.0), r"sweep: modal_hz = 1 Hz is below")):
        with pytest.raises(SweepError, match=words) as excinfo:
            Sweep(bridge, ["HSLM-A1"], "300", settings)
        assert not isinstance(excinfo.value, BridgeError)


# -- (c) the old except clauses catch what they caught -------------------------------------------
def test_the_bridge_classes_keep_the_classes_they_were():
    assert issubclass(BridgeModelError, ModelError) and issubclass(BridgeModelError, ValueError)
    assert issubclass(BridgeSweepError, SweepError) and issubclass(BridgeSweepError, ValueError)
    for cls in (BridgeModelError, BridgeSweepError):
        assert issubclass(cls, BridgeError) and issubclass(cls, VtsiError)
    assert not issubclass(BridgeModelError, SweepError) and not issubclass(BridgeSweepError, ModelError)
    assert not issubclass(BridgeSweepError, PassageError) and not issubclass(PassageError, BridgeError)


def _caught_by(cls, call):
    """The exception that ``except cls`` catches from ``call()`` (a failure if none)."""
    try:
        call()
    except cls as exc:
        return exc
    pytest.fail(f"{call} raised no {cls.__name__}")


def test_a_tracks_error_is_caught_as_a_model_error_and_a_sweeps_as_a_sweep_error(tmp_path):
    """Track (and PassageRunner) raise BridgeModelError, caught by ``except ModelError`` and not
    by ``except SweepError``; the Sweep re-raises it as a BridgeSweepError ('sweep: ...'), caught
    by ``except SweepError`` and not by ``except ModelError``, as before; ``except BridgeError``
    catches both."""
    model = beam_bridge([20.0], 3.5e10, 1.9, 15000.0, elements_per_span=4).model
    few = tmp_path / "few.tcl"
    few.write_text(textwrap.dedent(FEW_MODES_TCL))
    bridge = script_bridge(few)
    track = lambda: Track(model, [1, 2, 42])                                                # noqa: E731
    runner = lambda: PassageRunner(bridge.model, bridge.track_elements, PassageSettings(), outputs=())  # noqa: E731
    sweep = lambda: Sweep(bridge, ["HSLM-A1"], "300", PassageSettings())                      # noqa: E731
    for call, words in ((track, "track: element 42 does not exist"), (runner, FEW_MODES)):
        exc = _caught_by(ModelError, call)
        assert type(exc) is BridgeModelError and str(exc).startswith(words) and not isinstance(exc, SweepError)
    exc = _caught_by(SweepError, sweep)
    assert type(exc) is BridgeSweepError and str(exc).startswith(f"sweep: {FEW_MODES}")
    assert not isinstance(exc, ModelError)
    for call in (track, runner, sweep):
        assert isinstance(_caught_by(BridgeError, call), (ValueError, VtsiError))


def test_a_bridge_files_errors_are_model_errors_of_the_bridge(tmp_path):
    """read_bridge_file's problems of the file stay ModelErrors (BridgeModelError); a path of an
    unknown type is the caller's, a plain ModelError."""
    path = tmp_path / "b.toml"
    path.write_text("[bridge]\nkind = 'beam'\nspans_m = [20.0]\nE_Pa = 3.5e10\nmu_kg_m = 15000.0\nI_m4 = 1.9\n"
                    "colour = 'red'\n")
    with pytest.raises(ModelError, match=r"unknown key 'colour' in \[bridge\]") as excinfo:
        read_bridge_file(path)
    assert isinstance(excinfo.value, BridgeModelError)
    with pytest.raises(ModelError, match=r"unknown type '\.txt'") as excinfo:
        read_bridge_file(tmp_path / "b.txt")
    assert not isinstance(excinfo.value, BridgeError)
