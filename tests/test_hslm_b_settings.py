"""HSLM-B's N and d given by the user (EN 1991-2 Figure 6.13 read from her copy of the standard):
``PassageSettings(hslm_b=(N, d))``, ``--hslm-b N,d``, ``[analysis] hslm_b``. vtsi's own N(L), d(L)
is a straight-line reading of the figure not verified against it, and ``vtsi check`` gave a PASS or
FAIL on it without a word (probe E1: FAIL 20.37 m/s^2 on a 4 m slab from N = 15, d = 3.0 m). Now
the verdict carries one sentence saying so, with the N, d and L it ran, and the report's trains
section gives N, d and their source; with the user's N and d there is no such sentence.

The bridge: probe E1's 4 m span (f1 = 25 Hz, 12 t/m), 4 elements, on the modal bridge (exact
passages: a sweep of a few speeds runs in seconds).
"""
import json

import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.check import check, stored_check
from vtsi.errors import ModelError, SweepError
from vtsi.passage import PassageSettings
from vtsi.report import write_report
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import SweepResults

E, MU, L = 3.3e10, 12000.0, 4.0
I = MU * (2 * 25.0 * L ** 2 / np.pi) ** 2 / E        # f1 = 25 Hz on the 4 m span
USER = (12, 2.8)
SPEEDS = "250,270"
CAVEAT = ("HSLM-B's N = 15 and d = 3 m (L = 4 m) are vtsi's straight-line reading of EN 1991-2 Figure 6.13, not "
          "verified against the printed figure: give the figure's with --hslm-b N,d (PassageSettings(hslm_b=(N, d)))")
TOML = f"""[bridge]
kind = "beam"
spans_m = [{L}]
E_Pa = {E}
f1_Hz = 25.0
mu_kg_m = {MU}
elements_per_span = 4
[analysis]
damping = 0.027
bridge_model = "modal"
"""


def settings(hslm_b=None):
    return PassageSettings(damping=0.027, bridge="modal", hslm_b=hslm_b)


def bridge():
    return beam_bridge([L], E, I, MU, elements_per_span=4)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Results files of HSLM-B at two speeds: 'law' (vtsi's reading) and 'user' (N, d = USER)."""
    folder = tmp_path_factory.mktemp("hslm_b")
    paths = {}
    for name, pair in (("law", None), ("user", USER)):
        paths[name] = str(folder / f"{name}.h5")
        Sweep(bridge(), ["HSLM-B"], SPEEDS, settings(pair)).run(paths[name], workers=1, progress=False)
    return paths


@pytest.mark.parametrize("value, words", [
    ((0, 3.0), "sweep settings: hslm_b: N = 0 must be a whole number of forces, 1 <= N <= 100"),
    ((15.5, 3.0), "sweep settings: hslm_b: N = 15.5 must be a whole number of forces"),
    ((True, 3.0), "sweep settings: hslm_b: N = True must be a whole number of forces"),
    ((15, 0.0), "sweep settings: hslm_b: d = 0.0 must be a spacing > 0 [m]"),
    ((15, float("nan")), "sweep settings: hslm_b: d = nan must be a spacing > 0 [m]"),
    ((15, "3"), "sweep settings: hslm_b: d = '3' must be a spacing > 0 [m]"),
    ((15, 3000), "sweep settings: hslm_b: d = 3000 m is no spacing of HSLM-B's forces (a few metres): d is in m; "
                 "3000 mm would be 3 m"),
    ((15,), "sweep settings: hslm_b: expected HSLM-B's (N, d)"),
    ("15,3", "sweep settings: hslm_b: expected HSLM-B's (N, d), N forces at spacing d [m] read from EN 1991-2 "
             "Figure 6.13 for the span, e.g. (15, 3.0); got '15,3'"),
])
def test_the_setting_refuses_bad_values_naming_it_and_the_value(value, words):
    with pytest.raises(ModelError) as info:
        PassageSettings(hslm_b=value)
    assert str(info.value).startswith(words)


def test_the_setting_is_a_count_and_a_length():
    """(15.0, 3) is N = 15 (int), d = 3.0 m; None (the default) is vtsi's reading, not stored."""
    assert PassageSettings(hslm_b=(15.0, 3)).hslm_b == (15, 3.0)
    assert type(PassageSettings(hslm_b=(15.0, 3)).hslm_b[0]) is int
    assert "hslm_b" not in PassageSettings().as_dict()
    assert PassageSettings(hslm_b=[15, 3.0]).as_dict()["hslm_b"] == (15, 3.0)


def test_a_sweep_builds_exactly_n_forces_at_d():
    """User (12, 2.8 m): 12 forces of 170 kN at offsets 0, 2.8, ..., 30.8 m, D = 2.8 m; without it
    the 4 m span's reading, 15 forces 3 m apart (N = 20 - 10 x 3/6, d = 2.5 + 3/6)."""
    train = Sweep(bridge(), ["B"], SPEEDS, settings(USER)).runner.train("B", 70.0)
    assert np.array_equal(train.wheel_offsets, 2.8 * np.arange(12))
    assert np.array_equal(train.static_wheel_loads, np.full(12, 170e3))
    assert train.characteristic_length == 2.8 and train.speed == 70.0
    law = Sweep(bridge(), ["HSLM-B"], SPEEDS, settings()).runner.train("HSLM-B", 70.0)
    assert np.allclose(law.wheel_offsets, 3.0 * np.arange(15), rtol=0, atol=1e-12)


def test_a_sweep_without_hslm_b_refuses_the_setting():
    with pytest.raises(SweepError) as info:
        Sweep(bridge(), ["HSLM-A1"], SPEEDS, settings(USER))
    assert str(info.value) == ("sweep: hslm_b = (12, 2.8) (--hslm-b) is HSLM-B's N and d, and the sweep runs no "
                               "HSLM-B (trains HSLM-A1): add HSLM-B to the trains, or leave hslm_b unset")
    assert info.value.setting == "hslm_b"


def test_the_results_file_keeps_it_and_a_resume_uses_it(files):
    """The file's settings hold [12, 2.8] and its train the 12 offsets; a resume with the setting
    continues it (every case done: nothing runs), one without it is refused naming the setting and
    what continues the file (and one with it, a file of vtsi's reading);
    vtsi's reading leaves no hslm_b in the file (as an older vtsi's file)."""
    user = SweepResults(files["user"])
    assert user.identity["settings"]["hslm_b"] == [12, 2.8]
    assert np.array_equal(user.train_data("HSLM-B")["axle_offsets_m"], 2.8 * np.arange(12))
    assert "hslm_b" not in SweepResults(files["law"]).identity["settings"]
    again = Sweep(bridge(), ["HSLM-B"], SPEEDS, settings(USER)).run(files["user"], resume=True, workers=1,
                                                                    progress=False)
    assert again.n_done == again.n_cases == 2
    with pytest.raises(SweepError) as info:
        Sweep(bridge(), ["HSLM-B"], SPEEDS, settings()).run(files["user"], resume=True, workers=1, progress=False)
    assert ("it differs in settings.hslm_b (none here, [12, 2.8] in the file) (to continue that file, give its "
            "--hslm-b 12,2.8)); use another file") in str(info.value)
    with pytest.raises(SweepError) as info:
        Sweep(bridge(), ["HSLM-B"], SPEEDS, settings(USER)).run(files["law"], resume=True, workers=1, progress=False)
    assert ("it differs in settings.hslm_b ([12, 2.8] here, none in the file) (to continue that file, give no "
            "--hslm-b: it ran vtsi's reading of EN 1991-2 Figure 6.13)); use another file") in str(info.value)


def test_the_check_says_the_verdict_rests_on_vtsis_reading(files):
    """With vtsi's reading the verdict line ends with the sentence, the N, d, L it ran; the stored
    check reads it again; with the user's N and d the check says nothing of it."""
    law = check(files["law"])
    assert law.hslm_b == CAVEAT
    assert law.verdict().endswith(f"; {CAVEAT}")
    assert law.verdict().startswith(("FAIL", "PASS", "NO VERDICT"))
    assert CAVEAT in law.text()
    law.store(files["law"])
    assert stored_check(files["law"]).verdict() == law.verdict()
    user = check(files["user"])
    assert user.hslm_b == "" and "Figure 6.13" not in user.text()


def test_the_report_gives_n_d_and_their_source(files, tmp_path):
    """The report's verdict carries the sentence with vtsi's reading; its trains section gives N,
    d and where they came from: 'as read by vtsi, not verified' or 'given by the user'."""
    out = {}
    for name in ("law", "user"):
        check(files[name]).store(files[name])
        out[name] = open(write_report(files[name], tmp_path / name)["markdown"]).read()
    assert CAVEAT in out["law"] and "not verified" not in out["user"]
    assert ("HSLM-B: N = 15 forces of 170 kN at d = D = 3 m; N and d: EN 1991-2 Figure 6.13 as read by vtsi, "
            "not verified (--hslm-b N,d gives the figure's).") in out["law"]
    assert ("HSLM-B: N = 12 forces of 170 kN at d = D = 2.8 m; N and d: given by the user (EN 1991-2 "
            "Figure 6.13).") in out["user"]


def run_cli(argv, capsys):
    status = main(argv)
    err = capsys.readouterr().err.strip()
    return status, err


@pytest.mark.parametrize("value, words", [
    ("15", "argument --hslm-b: expected N,d (N forces, spacing d in m, from EN 1991-2 Figure 6.13), e.g. 15,3.0; "
           "got '15'"),
    ("x,3", "argument --hslm-b: expected N,d"),
    ("0,3", "argument --hslm-b: N,d: N = 0.0 must be a whole number of forces"),
    ("15,3000", "argument --hslm-b: N,d: d = 3000.0 m is no spacing of HSLM-B's forces (a few metres): d is in m; "
                "3000 mm would be 3 m (got '15,3000')"),
])
@pytest.mark.parametrize("command", ["sweep", "check"])
def test_the_cli_refuses_a_bad_value_in_one_line(command, value, words, tmp_path, capsys):
    path = tmp_path / "s4.toml"
    path.write_text(TOML)
    with pytest.raises(SystemExit) as stop:
        main([command, str(path), "--trains", "B", "--speeds", SPEEDS, "--hslm-b", value,
              "--out", str(tmp_path / "r.h5")])
    err = capsys.readouterr().err.strip()
    assert stop.value.code == 2 and "\n" not in err and words in err
    assert not (tmp_path / "r.h5").exists()


def test_the_cli_and_the_bridge_file_give_it_to_the_sweep(tmp_path, capsys):
    """--hslm-b 12,2.8 reaches the results file; [analysis] hslm_b too (the option wins over it);
    a sweep without HSLM-B is refused in one line; a bad [analysis] value names the file's key."""
    path = tmp_path / "s4.toml"
    path.write_text(TOML)
    out = str(tmp_path / "r.h5")
    status, _ = run_cli(["sweep", str(path), "--trains", "B", "--speeds", SPEEDS, "--hslm-b", "12,2.8", "--out", out,
                         "--quiet"], capsys)
    assert status == 0 and json.loads(json.dumps(SweepResults(out).identity["settings"]["hslm_b"])) == [12, 2.8]
    path.write_text(TOML + "hslm_b = [11, 2.9]\n")
    status, _ = run_cli(["sweep", str(path), "--trains", "B", "--speeds", SPEEDS, "--out", out, "--overwrite",
                         "--quiet"], capsys)
    assert status == 0 and SweepResults(out).identity["settings"]["hslm_b"] == [11, 2.9]
    status, err = run_cli(["sweep", str(path), "--trains", "A1", "--speeds", SPEEDS, "--out", str(tmp_path / "a.h5"),
                           "--quiet"], capsys)
    assert status == 2 and "\n" not in err
    assert err.startswith(f"vtsi sweep: bridge file {path}: [analysis] hslm_b = [11, 2.9]: hslm_b = (11, 2.9) "
                          "(--hslm-b) is HSLM-B's N and d, and the sweep runs no HSLM-B")
    path.write_text(TOML + "hslm_b = [15, 3000]\n")
    status, err = run_cli(["sweep", str(path), "--trains", "B", "--speeds", SPEEDS, "--out", str(tmp_path / "b.h5")],
                          capsys)
    assert status == 2 and "\n" not in err and "[analysis] sweep settings: hslm_b: d = 3000 m" in err
