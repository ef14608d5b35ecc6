"""What ``vtsi check`` hands ``design_check``: the GIF's frame count (``--animation-frames N``,
an integer >= 2, passed to ``animate_case`` as ``max_frames``), and the up-front refusal, which
``vtsi check`` runs once before its own sweep (before, ``design_check`` ran it a second time,
0.2 s on the 4-element beam of ``beam_toml`` and about 1 s on a check's usual bridge), while
``design_check`` called directly still refuses before it writes anything."""
import os

import numpy as np
import pytest

import vtsi.workflow
from vtsi.__main__ import main
from vtsi.errors import SweepError
from vtsi.passage import PassageSettings
from vtsi.scene3d import rendering_available
from vtsi.sweep import Sweep, beam_bridge

CHECK = ["--trains", "HSLM-A1", "--speeds", "300", "--bridge-type", "steel", "--workers", "1", "--quiet"]
EI = 15000.0 * (2 * np.pi * 5.0 * (20.0 / np.pi) ** 2) ** 2       # f1 = 5 Hz: (π/L)² √(EI/μ) / 2π


@pytest.fixture
def bridge(tmp_path, beam_toml):
    return beam_toml(tmp_path / "bridge.toml", dt_s=0.005)


@pytest.fixture
def refusals(monkeypatch):
    """The calls of the up-front refusal's rule (vtsi.check.refuse_inputs as vtsi.workflow calls
    it), each with whether a results file existed then."""
    calls = []
    rule = vtsi.workflow.refuse_inputs

    def counted(results, settings=None):
        calls.append([path for path in ("check.h5", "d.h5") if os.path.exists(path)])
        return rule(results, settings)

    monkeypatch.setattr(vtsi.workflow, "refuse_inputs", counted)
    return calls


def test_vtsi_check_refuses_up_front_once(tmp_path, bridge, refusals, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(vtsi.workflow, "rendering_available", lambda: (False, "test: no scene"))
    assert main(["check", str(bridge), *CHECK]) in (0, 1)
    assert refusals == [[]]                                  # once, before the results file was written
    assert (tmp_path / "check.h5").exists() and (tmp_path / "check_report" / "report.html").exists()


def test_design_check_still_refuses_before_writing(tmp_path, refusals, monkeypatch):
    """Called directly, design_check refuses up front (a modal bridge whose modes stop at 20 Hz,
    below the 45.82 Hz EN cut-off): one call of the rule, the sweep never runs, nothing written."""
    monkeypatch.chdir(tmp_path)
    sweep = Sweep(beam_bridge([20.0], EI, 1.0, 15000.0, elements_per_span=4), ["HSLM-A1"], "300",
                  PassageSettings(dt=5e-3, damping=0.005, bridge="modal", modal_hz=20.0))
    with pytest.raises(SweepError, match=r"^check: the deck acceleration output 'acceleration' counts frequencies up "
                                         r"to 20 Hz, below the EN 1990 A2\.4\.4\.2\.1\(4\)P cut-off 45\.82 Hz"):
        vtsi.workflow.design_check(sweep, "d.h5", workers=1, progress=False)
    assert refusals == [[]]
    assert os.listdir(tmp_path) == []


def test_a_small_animation_frames_gives_a_gif_of_that_many_frames(tmp_path, bridge, monkeypatch):
    ok, reason = rendering_available()
    if not ok:
        pytest.skip(reason)
    PIL = pytest.importorskip("PIL.Image")
    monkeypatch.chdir(tmp_path)
    assert main(["check", str(bridge), *CHECK, "--animation", "--animation-frames", "3"]) in (0, 1)
    with PIL.open(tmp_path / "check_report" / "scene.gif") as gif:
        assert gif.n_frames == 3


@pytest.mark.parametrize("extra, line", [
    (["--animation", "--animation-frames", "1"],
     "vtsi check: error: argument --animation-frames: expected an integer >= 2, got '1' (see 'vtsi check -h')"),
    (["--animation", "--animation-frames", "0"],
     "vtsi check: error: argument --animation-frames: expected an integer >= 2, got '0' (see 'vtsi check -h')"),
    (["--animation", "--animation-frames", "2.5"],
     "vtsi check: error: argument --animation-frames: expected an integer >= 2, got '2.5' (see 'vtsi check -h')"),
    (["--animation", "--animation-frames", "many"],
     "vtsi check: error: argument --animation-frames: expected an integer >= 2, got 'many' (see 'vtsi check -h')"),
    (["--animation-frames", "40"],
     "vtsi check: --animation-frames 40: the frames of the GIF of --animation; give --animation too"),
])
def test_bad_animation_frames_is_one_line_exit_2_nothing_written(tmp_path, bridge, capsys, monkeypatch, extra, line):
    monkeypatch.chdir(tmp_path)
    try:
        status = main(["check", str(bridge), *CHECK, *extra])
    except SystemExit as exc:                   # argparse's errors exit
        status = exc.code
    assert status == 2
    assert capsys.readouterr().err.splitlines() == [line]
    assert os.listdir(tmp_path) == ["bridge.toml"]


@pytest.mark.parametrize("kwargs, words", [
    ({"animation": True, "animation_frames": 1}, "animation_frames must be an integer >= 2, got 1"),
    ({"animation": True, "animation_frames": True}, "animation_frames must be an integer >= 2, got True"),
    ({"animation": True, "animation_frames": 12.0}, "animation_frames must be an integer >= 2, got 12.0"),
    ({"animation": True, "animation_frames": "12"}, "animation_frames must be an integer >= 2, got '12'"),
    ({"animation_frames": 12}, "animation_frames = 12 is the GIF's: give animation=True"),
])
def test_design_check_refuses_a_bad_animation_frames_before_running(tmp_path, kwargs, words):
    sweep = Sweep(beam_bridge([20.0], EI, 1.0, 15000.0, elements_per_span=4), ["HSLM-A1"], "300",
                  PassageSettings(dt=5e-3, damping=0.005))
    with pytest.raises(SweepError) as exc:
        vtsi.workflow.design_check(sweep, tmp_path / "d.h5", **kwargs)
    assert str(exc.value) == f"design check: {words}"
    assert os.listdir(tmp_path) == []
