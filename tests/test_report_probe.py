"""What a checking engineer found missing or misleading in a check and its report (the probe of
/tmp/probe_vis/FINDINGS.md): a speed grid coarser than the EN series across a resonance (W1), the
speeds' steps (N2), places as bare node numbers (N4), history charts colouring a node that does
not govern (M4), n₂ resonances of a continuous deck (M6), what the end rotation reads (M7), default
values not shown (N5), the scene's caption (N6) and a modal model's cut-off (N8)."""
import copy
import shutil

import numpy as np
import pytest

from vtsi.check import CheckResult, CheckRow, CheckSettings, _coarse_speeds, bridge_model_text, check, stored_check
from vtsi.passage import PassageSettings
from vtsi.report import _Report, write_report
from vtsi.speed_grid import CoarseResonance
from vtsi.sweep import Sweep, beam_bridge, en_speed_grid, resonance_speeds
from vtsi.sweep_results import SweepResults

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
ICE3_D = 24.775


def _sweep(path, speeds, spans=(L,), trains=("ICE3",)):
    sweep = Sweep(beam_bridge(list(spans), EI, 1.0, MU, elements_per_span=4), list(trains), speeds,
                  PassageSettings(dt=5e-3, damping=0.013))
    results = sweep.run(path, workers=1, progress=False)
    result = check(results)
    result.store(path)
    return sweep, results, result


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    """ICE3 over a 20 m, 5 Hz span at 200 … 240 km/h in 8 km/h steps: its resonance n₀ D / 2 =
    223 km/h lies between 216 and 224 (the EN series steps 2 km/h there)."""
    path = tmp_path_factory.mktemp("probe") / "coarse.h5"
    return (path, *_sweep(path, "200:240:8"))


def test_a_speed_grid_coarser_than_the_en_series_across_a_resonance_is_said(coarse):
    """W1: before, a 6 km/h grid across ICE3's resonance read PASS at 3.47 m/s² where 1 km/h steps
    gave 3.77 (FAIL), and nothing said so."""
    path, sweep, results, result = coarse
    n0 = float(results.bridge()["deck_frequencies_hz"][0][0])          # 5.001 Hz: 4 elements
    v = float(resonance_speeds([n0], [ICE3_D], orders=(2,))[0])
    assert 216 < v < 224
    row = result.row("deck_acceleration")
    assert f"ICE3 D/2 at {v:.4g} km/h (n0 {n0:.4g} Hz): step 8 km/h" in row.note
    assert "more coarsely than the EN 1991-2 6.4.6.2 series" in row.note
    assert row.status == ("fail" if row.value > row.limit else "info")        # a PASS does not stand
    assert "the speeds step across" in result.verdict() and f"ICE3 D/2 at {v:.4g} km/h" in result.verdict()
    assert "see the deck_acceleration note" in result.row("dynamic_increment").note
    assert stored_check(path).speed_grid == result.speed_grid != ""          # kept with the check


def test_a_pass_on_a_coarse_grid_is_not_checked_and_a_fail_stays_fail():
    """A deck acceleration not checked on a coarse grid is no PASS, even when every other criterion
    passes (it read "PASS: every criterion checked is within its limit (not checked: ...)", and
    vtsi check exited 0): NO VERDICT, naming it; a FAIL stays FAIL."""
    settings = CheckSettings()
    missed = [CoarseResonance("ICE3", 232.3, 7.812, 0, 3, 6.0, 2.0)]
    body = CheckRow("car_body_acceleration", "EN 1990 A2.4.4.3.1, Table A2.9", 0.25, "m/s^2", 1.3, 0.25 / 1.3, "pass")
    for value, status in ((3.47, "info"), (3.77, "fail")):
        out = CheckResult(settings, [CheckRow("deck_acceleration", "EN 1990 A2.4.4.2.1(4)P", value, "m/s^2", 3.5,
                                              value / 3.5, "pass" if value <= 3.5 else "fail", "ICE3", 234.0), body],
                          cases_done=1, cases_total=1)
        _coarse_speeds(out, missed)
        assert out.rows[0].status == status and not out.passed
        assert out.rows[1].status == "info"          # the car body peaks at resonance too: its PASS does not stand
        assert "ICE3 D/3 at 232.3 km/h (n0 7.812 Hz): step 6 km/h" in out.rows[0].note
        assert "ICE3 D/3 at 232.3 km/h" in out.verdict()
        if status == "fail":
            assert out.verdict().startswith("FAIL: 1 of 1 criterion held to a limit fails: deck_acceleration "
                                            "(not checked: car_body_acceleration; see its note)")
        else:
            assert out.unchecked == ["deck_acceleration", "car_body_acceleration"]
            assert out.verdict().startswith("NO VERDICT: deck_acceleration, car_body_acceleration not checked (see "
                                            "their notes); no other criterion was held to a limit (not evaluated, "
                                            "the sweep kept no output for them: deflection, wheel_unloading, "
                                            "contact_loss); the speeds step across 1 resonance more coarsely than "
                                            "the EN series (ICE3 D/3 at 232.3 km/h")


def test_the_en_series_and_fine_steps_are_not_coarse(tmp_path):
    bridge = beam_bridge([L], EI, 1.0, MU, elements_per_span=4)         # the series vtsi sweep --speeds en:200 runs
    frequencies = Sweep(bridge, ["ICE3"], "200", PassageSettings(dt=5e-3)).runner.deck_frequencies.ravel()
    speeds = en_speed_grid(200.0, frequencies, [ICE3_D], start_kmh=200.0)
    _, results, result = _sweep(tmp_path / "en.h5", speeds)
    assert result.speed_grid == "" and "more coarsely" not in result.row("deck_acceleration").note
    page = write_report(tmp_path / "en.h5", tmp_path / "r")["markdown"].read_text()
    assert f"| speeds | {len(speeds)} speeds, 200–240 km/h: the EN 1991-2 6.4.6.2 series" in page
    _, _, fine = _sweep(tmp_path / "fine.h5", "219:227:2")          # 2 km/h across 223: as fine as EN's
    assert fine.speed_grid == ""
    # a design check for a line speed reads the series from 40 m/s: what lies below 219 km/h is named
    below = check(SweepResults(tmp_path / "fine.h5"), CheckSettings(line_speed_kmh=200.0))
    assert "): step" not in below.speed_grid and below.speed_grid.count("below the speeds swept") == 1   # D/3


def test_resonances_below_the_first_speed_are_named():
    """A sweep starting above 144 km/h (40 m/s) never reads the resonances below its first speed:
    a 3.5 Hz span swept at 250-300 km/h passed its deflection (0.71 of L/600) where the EN series
    fails it (1.63, HSLM-A1 at 227 km/h). They are named, and a PASS there is not checked."""
    coarse = CoarseResonance("HSLM-A1", 226.8, 3.5, 0, 4, float("inf"), 0.0)
    assert coarse.text() == "HSLM-A1 D/4 at 226.8 km/h (n0 3.5 Hz): below the speeds swept"
    out = CheckResult(CheckSettings(), [CheckRow("deflection", "EN 1990 A2.4.4.2.3(1)", 0.0237, "m", 0.0333,
                                                 0.71, "pass", "LM71")], cases_done=1, cases_total=1)
    _coarse_speeds(out, [coarse])
    assert out.rows[0].status == "info" and out.rows[0].note.startswith("; not checked: ")
    assert "1 of them below the speeds swept, which start above the series' 144 km/h" in out.rows[0].note


def test_report_gives_the_steps_places_defaults_and_end_rotation(coarse, tmp_path):
    """N2, N4, N5, M7 (end rotation): the settings give the speeds' step and the coarse
    resonances, places name x and the span, defaults their values."""
    path, sweep, results, result = coarse
    out = write_report(path, tmp_path / "r")
    md, html = out["markdown"].read_text(), out["html"].read_text()
    assert "| speeds | 6 speeds, 200–240 km/h in steps of 8 km/h; the speeds step across 1 resonance more " \
           "coarsely than the EN series (ICE3 D/2 at 223 km/h (n0 5.001 Hz): step 8 km/h) (see the check's notes) |" in md
    where = result.row("deck_acceleration").where
    x = dict(zip(results.bridge()["deck_nodes"].tolist(), results.bridge()["deck_x_m"].tolist()))
    node = int(where.split()[1])
    assert where == f"node {node} (x = {x[node]:g} m, span 1)"
    assert where in md and where in html and where in result.text()
    assert "| approach | 0 m (the default): the first axle's distance before the track's first node at t = 0 |" in md
    assert "| free vibration | 0.3 s (the default, 1.5 periods of the model's first vertical mode, 5.001 Hz)" in md
    assert "at the decks' end supports (x = 0 and 20 m)" in result.row("end_rotation").note


def test_history_highlights_only_the_governing_node(coarse):
    """M4: before, span 1's middle was drawn in the train's colour when the case governed a row
    at a node not drawn (an end rotation), and the caption called it the governing node."""
    path, sweep, results, result = coarse
    checked = stored_check(path)
    report = _Report(results, checked, path)
    rotation = checked.row("end_rotation")
    case = (rotation.train, rotation.speed_kmh, rotation.seed)
    for r in report.rows:                    # this case governs the end rotation only
        if r.criterion != "end_rotation":
            r.train = "other"
    assert not any(governing for _, _, governing in report._history_nodes("disp", *case))
    caption = report.history_caption("x", {"accel": "a", "disp": "d"}, {}, case)
    assert "train's colour" not in caption
    assert f"This case governs end rotation at {rotation.where}: the histories do not hold that quantity" in caption
    report = _Report(results, checked, path)
    acc = checked.row("deck_acceleration")
    case = (acc.train, acc.speed_kmh, acc.seed)
    nodes = report._history_nodes("accel", *case)
    assert [n for n, _, governing in nodes if governing] == [int(acc.where.split()[1])]
    assert f"in the train's colour: where this case governs deck acceleration at {acc.where}" in \
        report.history_caption("x", {"accel": "a"}, {}, case)


def test_continuous_deck_marks_n2_resonances(tmp_path):
    """M6: a continuous deck's n₂ resonances are marked (before: n₀ only, the n₂ peaks unlabelled);
    a simply supported deck's n₂ = 4 n₀ is not."""
    _, results, _ = _sweep(tmp_path / "two.h5", "200,240", spans=(L, L))
    report = _Report(results, stored_check(tmp_path / "two.h5"), tmp_path / "two.h5")
    n0, n2 = report.marked_frequencies()
    table = np.asarray(results.bridge()["deck_frequencies_hz"]).reshape(-1, 3)
    assert np.allclose(n0, table[:, 0]) and np.allclose(n2, table[:, 1])
    assert "dashed verticals, labelled 'train D/i (n₂)'" in report.acceleration_caption("deck_acceleration")


def test_scene_caption_and_modal_cutoff(coarse, tmp_path):
    """N6: the scene's caption names the case, time and exaggeration when told them; N8: a modal
    model's cut-off against the EN cut-off."""
    path, sweep, results, result = coarse
    scene = tmp_path / "scene.png"
    shutil.copyfile(write_report(path, tmp_path / "a")["images"][0], scene)
    md = write_report(path, tmp_path / "b", scene_png=scene,
                      scene_case={"train": "ICE3", "speed_kmh": 224.0, "seed": -1, "time_s": 1.25, "scale": 200})
    text = md["markdown"].read_text()
    assert ("The passage of ICE3 at 224 km/h, smooth rail at t = 1.25 s as a 3-D scene (scene.png): the deck's "
            "vertical displacements, drawn through a cubic spline between its nodes, exaggerated × 200") in text
    bridge = results.bridge()

    def as_modal(**settings):            # the results as a modal sweep's with these settings would read
        modal = copy.copy(results)
        modal.identity = {**results.identity, "settings": {**results.identity["settings"], "bridge": "modal", **settings}}
        return modal
    assert "(1.1 × the EN cut-off 45.82 Hz, the default of an older vtsi;" in bridge_model_text(as_modal(), bridge)    # an older file's
    assert "modes up to 20 Hz (below the EN cut-off 45.82 Hz;" in bridge_model_text(as_modal(modal_hz=20.0), bridge)
