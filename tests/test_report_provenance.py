"""What a checking engineer needs to know where the numbers came from (probe /tmp/probe_vis
N1, N6, N8): the 3-D scene's case, time and exaggeration in its caption, and its GIF; a modal
bridge's number of modes; where the damping came from and the line speed. Each is stored or
returned where it is made, and a results file of an older vtsi (without them) still reports."""
import json
import os
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

import vtsi.workflow
from vtsi.__main__ import main
from vtsi.check import CheckSettings, check, stored_check
from vtsi.errors import ModelError
from vtsi.passage import PassageSettings
from vtsi.report import PNG_MAGIC, write_report
from vtsi.scene3d import PassageScene, RenderedScene, render_case, rendering_available
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import SweepResults

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
# EN 1991-2 Table 6.6, steel, L = 20 m: 0.5 %; Eq. 6.13 at 20 m: Δζ = 0.118 / 0.398 % = 0.296 %
STEEL = "EN 1991-2 Table 6.6, steel, longest span L = 20 m: 0.5 % + Eq. 6.13 Δζ 0.296 % = 0.796 %"


def _sweep(**settings):
    return Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=4), ["HSLM-A1"], "300,340",
                 PassageSettings(dt=5e-3, **{"damping": 0.013, **settings}))


def _fake_png(self, path, *args, **kwargs):
    """PassageScene.render_png without rendering: a file with the PNG signature."""
    Path(path).write_bytes(PNG_MAGIC + b"not drawn")
    return Path(path)


def _settings_rows(markdown):
    return {line.split(" | ")[0].lstrip("| "): line.split(" | ", 1)[1].rstrip(" |")
            for line in markdown.splitlines() if line.startswith("| ") and " | " in line}


# -- N6: the scene's caption ---------------------------------------------------------------------
def test_render_case_returns_what_it_drew(tmp_path):
    """render_case returns a RenderedScene: a path (os.PathLike, str) with the case, the time
    drawn and the exaggeration, the scale it handed the scene."""
    ok, reason = rendering_available()
    if not ok:
        pytest.skip(reason)
    sweep, path = _sweep(), tmp_path / "r.h5"
    sweep.run(path, workers=1, progress=False)
    check(path).store(path)
    sweep.record_histories(path, [("HSLM-A1", 340.0, -1)])
    drawn = render_case(path, tmp_path / "s.png", train="HSLM-A1", speed_kmh=340, time=1.0, window_size=(200, 100))
    assert isinstance(drawn, RenderedScene) and isinstance(drawn, os.PathLike)
    assert os.fspath(drawn) == str(drawn) == str(tmp_path / "s.png") and Path(drawn).read_bytes()[:8] == PNG_MAGIC
    assert (drawn.train, drawn.speed_kmh, drawn.seed, drawn.time_s) == ("HSLM-A1", 340.0, -1, pytest.approx(1.0))
    assert drawn.scale > 0 and drawn.scale == float(f"{drawn.scale:.1g}")    # the default: one significant digit
    assert drawn.case == {"train": "HSLM-A1", "speed_kmh": 340.0, "seed": -1, "time_s": drawn.time_s,
                          "scale": drawn.scale}
    assert render_case(path, tmp_path / "t.png", train="HSLM-A1", speed_kmh=340, scale=7,
                       window_size=(200, 100)).scale == 7.0


def test_design_check_captions_the_scene_and_names_the_gif(tmp_path, monkeypatch):
    """design_check hands the report what render_case drew: the caption names the case, the
    time and the exaggeration (it said 'The passage as a 3-D scene (scene.png)' only), and the
    GIF of animation=True. The check's provenance fields (Python API) reach the settings."""
    calls = []

    def capture(self, path, deck_uy, wheel_x, car_bounds=None, **kwargs):
        calls.append(kwargs)
        return _fake_png(self, path)

    def fake_animation(results_path, path, **kwargs):
        Path(path).write_bytes(b"GIF89a")
        return Path(path)

    monkeypatch.setattr(PassageScene, "render_png", capture)
    monkeypatch.setattr(vtsi.workflow, "rendering_available", lambda: (True, "test"))
    monkeypatch.setattr(vtsi.workflow, "animate_case", fake_animation)
    settings = CheckSettings(damping_source="--damping 0.013", line_speed_kmh=280)
    result, paths = vtsi.workflow.design_check(_sweep(), tmp_path / "d.h5", settings, workers=1, animation=True)
    scene = paths["scene"]
    assert isinstance(scene, RenderedScene) and scene.scale == calls[0]["scale"] and scene.time_s == calls[0]["time"]
    row = result.row("deck_acceleration")
    assert (scene.train, scene.speed_kmh, scene.seed) == (row.train, row.speed_kmh, row.seed)
    text = paths["markdown"].read_text(encoding="utf-8")
    assert (f"The passage of HSLM-A1 at {scene.speed_kmh:g} km/h, smooth rail at t = {scene.time_s:.4g} s as a 3-D "
            f"scene (scene.png): the deck's vertical displacements, drawn through a cubic spline between its nodes, "
            f"exaggerated × {scene.scale:g}; the axles where they are at that time. The whole passage as an "
            "animation: scene.gif (not embedded).") in text
    rows = _settings_rows(text)
    assert rows["damping from"] == "--damping 0.013"
    assert rows["line speed"] == "280 km/h: the speeds reach 1.2 × it = 336 km/h (EN 1991-2 6.4.6.2(1))"
    assert stored_check(tmp_path / "d.h5").settings == settings


# -- N8: the modal basis ---------------------------------------------------------------------------
def test_a_modal_sweep_stores_and_reports_its_number_of_modes(tmp_path):
    """The modal bridge's modes (their frequencies) are in /bridge; the report says '4 modes up
    to 103.9 Hz' (5, 20, 45.8 and 88.8 Hz below the moments' default basis, 1.1 × twice the
    47.22 Hz at which HSLM-A1's bogie axles, 2 m apart, pass at 340 km/h); an FE sweep has none."""
    path = tmp_path / "m.h5"
    sweep = _sweep(bridge="modal")
    check(sweep.run(path, workers=1, progress=False)).store(path)
    modes = SweepResults(os.fspath(path)).bridge()["modal_frequencies_hz"]
    np.testing.assert_allclose(modes, sweep.runner.modal.frequencies)
    basis = 1.1 * 2 * (340 / 3.6) / 2.0
    assert len(modes) == 4 and modes.max() < basis == pytest.approx(sweep.settings.modal_hz, rel=1e-12)
    text = write_report(path, tmp_path / "rep")["markdown"].read_text(encoding="utf-8")
    default = (f"{basis:.4g} Hz ({basis / 45.82:.3g} × the EN cut-off 45.82 Hz, the default for the moments: 1.1 × twice "
               f"the {340 / 3.6 / 2.0:.4g} Hz at which the trains' closest axles pass at 340 km/h")
    assert (f"| bridge model | modal: 4 modes up to {default}; the highest at {modes.max():.4g} Hz), exact passages "
            "of moving forces") in text
    fe = tmp_path / "fe.h5"
    _sweep().run(fe, workers=1, progress=False)
    assert "modal_frequencies_hz" not in SweepResults(os.fspath(fe)).bridge()

    older = tmp_path / "older.h5"           # a file of an older vtsi: no modes, a check without provenance
    shutil.copyfile(path, older)
    with h5py.File(older, "r+") as f:
        del f["bridge/modal_frequencies_hz"]
        stored = json.loads(f["checks"].attrs["settings"])
        f["checks"].attrs["settings"] = json.dumps({k: v for k, v in stored.items()
                                                    if k not in ("damping_source", "line_speed_kmh")})
    assert stored_check(older).settings == CheckSettings()
    text = write_report(older, tmp_path / "old")["markdown"].read_text(encoding="utf-8")
    assert f"modal: its modes up to {default}; the results file does not hold how many modes)" in text
    rows = _settings_rows(text)
    assert "damping from" not in rows and "line speed" not in rows


# -- N1: the damping's source and the line speed ------------------------------------------------------
def test_vtsi_check_stores_and_reports_the_damping_source_and_line_speed(tmp_path, beam_toml, capsys, monkeypatch):
    """--bridge-type steel --additional-damping over a bridge file with [analysis] damping = 0.02:
    ζ = 0.796 % replaces it, a line on standard error says so, and the check stores and the
    report prints where ζ came from and the line speed. A resume with another line speed runs
    (they are not the sweep's identity); --quiet prints no note; --damping is named as such."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(vtsi.workflow, "rendering_available", lambda: (False, "test: no scene"))
    bridge = beam_toml(tmp_path / "b.toml", dt_s=0.005, damping=0.02)
    base = ["check", str(bridge), "--trains", "HSLM-A1", "--speeds", "340,360", "--bridge-type", "steel",
            "--additional-damping", "--workers", "1"]
    assert main(base + ["--line-speed", "300"]) in (0, 1)
    err = capsys.readouterr().err
    assert (f"vtsi check: --bridge-type steel replaces the bridge file's [analysis] damping = 0.02 (b.toml) by "
            f"ζ = 0.796 %: {STEEL}") in err
    settings = stored_check(tmp_path / "check.h5").settings
    source = f"{STEEL}; it replaces the bridge file's [analysis] damping = 0.02 (2 %)"
    assert settings.damping_source == source and settings.line_speed_kmh == 300.0
    rows = _settings_rows((tmp_path / "check_report" / "report.md").read_text(encoding="utf-8"))
    assert rows["damping"] == "ζ = 0.796 % (Rayleigh, through n₀ and the EN cut-off)"
    assert rows["damping from"] == source
    assert rows["line speed"] == "300 km/h: the speeds reach 1.2 × it = 360 km/h (EN 1991-2 6.4.6.2(1))"

    assert main(base + ["--line-speed", "290", "--resume", "--quiet"]) in (0, 1)    # same sweep, another line speed
    assert "replaces" not in capsys.readouterr().err
    assert stored_check(tmp_path / "check.h5").settings.line_speed_kmh == 290.0

    assert main(["check", str(bridge), "--trains", "HSLM-A1", "--speeds", "340,360", "--damping", "0.013",
                 "--workers", "1", "--out", "d.h5", "--quiet"]) in (0, 1)
    settings = stored_check(tmp_path / "d.h5").settings
    assert settings.damping_source == "--damping 0.013; it replaces the bridge file's [analysis] damping = 0.02 (2 %)"
    assert settings.line_speed_kmh is None
    assert "line speed" not in _settings_rows((tmp_path / "d_report" / "report.md").read_text(encoding="utf-8"))


def test_no_note_when_the_bridge_file_has_no_damping(tmp_path, beam_toml, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(vtsi.workflow, "rendering_available", lambda: (False, "test: no scene"))
    bridge = beam_toml(tmp_path / "b.toml", dt_s=0.005)
    assert main(["check", str(bridge), "--trains", "HSLM-A1", "--speeds", "360", "--bridge-type", "steel",
                 "--workers", "1"]) in (0, 1)
    assert "replaces" not in capsys.readouterr().err
    assert stored_check(tmp_path / "check.h5").settings.damping_source == \
        "EN 1991-2 Table 6.6, steel, longest span L = 20 m: 0.5 %"


@pytest.mark.parametrize("kwargs, words", [
    ({"line_speed_kmh": 0}, "line_speed_kmh must be a speed > 0 [km/h] or None, got 0"),
    ({"line_speed_kmh": "300"}, "line_speed_kmh must be a speed > 0 [km/h] or None, got '300'"),
    ({"damping_source": 0.01}, "damping_source must be text, got 0.01"),
])
def test_bad_provenance_settings(kwargs, words):
    with pytest.raises(ModelError, match=words.replace("[", r"\[").replace("]", r"\]")):
        CheckSettings(**kwargs)
