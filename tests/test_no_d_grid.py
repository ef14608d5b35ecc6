"""A train without a characteristic length D (an axle table whose dynamic signature shows no
regular spacing): its resonance speeds are unknown, so the EN 1991-2 6.4.6.2 series steps finely
(2 km/h) over its whole range, and a check of a coarser sweep gives no verdict. A regional train
of 2 locomotives and 8 coaches of 26.4 m (bogie centres 17.2 m) passed `vtsi check --line-speed
250` at 2.595 m/s^2 on the 10 km/h series and failed at 4.148 m/s^2 at 159 km/h on 1 km/h steps."""
import math

import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.check import CheckSettings, check, stored_check
from vtsi.signature import principal_wavelength
from vtsi.sweep import en_speed_grid
from vtsi.sweep_results import SweepResults

LOCO = [0.0, 3.0, 10.0, 13.0]                    # a locomotive's axles [m]
COACH = [0.0, 2.5, 17.2, 19.7]                   # a 26.4 m coach's: bogie centres 17.2 m apart, 2.5 m bogies


def regional_axles():
    """Axle positions [m] and loads [kN] of the probe's train: a locomotive, 8 coaches, a locomotive."""
    x, F = [3.25 + p for p in LOCO], [210.0] * 4
    for k in range(8):
        x += [22.85 + 26.4 * k + p for p in COACH]
        F += [160.0] * 4
    x += [233.95 + p for p in LOCO]
    return np.array(x), np.array(F + [210.0] * 4)


@pytest.fixture
def regional(tmp_path):
    x, F = regional_axles()
    path = tmp_path / "regional.csv"
    path.write_text("position_m,load_kN\n" + "".join(f"{p:.2f},{f:g}\n" for p, f in zip(x, F)))
    return path


def test_the_regional_train_has_no_d():
    peak = principal_wavelength(*regional_axles())
    assert peak.length_m is None and "no characteristic length D" in peak.text()


@pytest.mark.parametrize("unknown", [None, math.nan])
def test_a_train_without_d_makes_the_en_series_fine_throughout(unknown):
    """From 144 km/h to 1.2 x 250 = 300 km/h in 2 km/h steps: (300 - 144) / 2 + 1 = 79 speeds; a
    train with D beside it adds its resonance speeds v = n D / i off that lattice."""
    grid = en_speed_grid(250.0, [5.0], [unknown])
    np.testing.assert_allclose(grid, np.arange(144.0, 300.0 + 1e-9, 2.0))
    with_d = en_speed_grid(250.0, [6.707], [unknown, 24.0])
    resonances = [3.6 * 6.707 * 24.0 / i for i in (2, 3, 4)]                # 289.74, 193.16, 144.87 km/h
    assert all(np.isclose(with_d, round(v, 2)).any() for v in resonances)
    np.testing.assert_allclose(np.setdiff1d(with_d, np.round(resonances, 2)), np.arange(144.0, 300.0 + 1e-9, 2.0))
    assert np.max(np.diff(with_d)) == pytest.approx(2.0)
    assert np.max(np.diff(en_speed_grid(250.0, [6.707], [24.0]))) == pytest.approx(10.0)  # D alone: 10 km/h steps


def test_a_train_without_d_on_10_kmh_steps_gives_no_verdict(tmp_path, beam_toml, regional, capsys, monkeypatch):
    """The probe in small (20 m, 5 Hz span): on 10 km/h steps the deck acceleration and the
    deflection are not checked and the verdict names the train (exit 1); on 2 km/h steps, the EN
    series' fine step, the check gives a verdict, and its deck acceleration is at least the one
    the 10 km/h steps read (the same passages, and more of them)."""
    monkeypatch.chdir(tmp_path)
    bridge = beam_toml(tmp_path / "bridge.toml", dt_s=0.005)
    argv = ["check", str(bridge), "--trains", str(regional), "--bridge-type", "prestressed_concrete",
            "--workers", "1", "--quiet"]
    assert main(argv + ["--speeds", "180:260:10", "--out", "coarse.h5"]) == 1
    out = capsys.readouterr().out
    coarse = stored_check(tmp_path / "coarse.h5")
    said = f"{regional} has no characteristic length D (its resonances are unknown): step 10 km/h where the EN " \
           "series steps 2 km/h"
    assert coarse.verdict().startswith("NO VERDICT") and said in coarse.verdict() and said in out
    assert coarse.row("deck_acceleration").status == coarse.row("deflection").status == "info"
    assert "not checked: " in coarse.row("deck_acceleration").note and said in coarse.row("deck_acceleration").note

    status = main(argv + ["--speeds", "180:260:2", "--out", "fine.h5"])
    fine = stored_check(tmp_path / "fine.h5")
    assert fine.verdict().startswith(("PASS", "FAIL")) and status == (0 if fine.passed else 1)
    assert fine.speed_grid == "" and "unknown" not in fine.row("deck_acceleration").note
    assert fine.row("deck_acceleration").status in ("pass", "fail")
    assert fine.row("deck_acceleration").value >= coarse.row("deck_acceleration").value

    # for a line speed of 200 km/h the series starts at 144 km/h (40 m/s), below the sweep's 180 km/h
    late = check(SweepResults(tmp_path / "fine.h5"), CheckSettings(line_speed_kmh=200.0))
    assert late.verdict().startswith("NO VERDICT") and late.row("deck_acceleration").status == "info"
    assert (f"{regional} has no characteristic length D (its resonances are unknown): the speeds swept start at "
            "180 km/h, above the EN series' 144 km/h") in late.speed_grid


def test_the_en_series_of_a_train_without_d_is_checked_and_reported_as_fine(tmp_path, beam_toml, regional,
                                                                             monkeypatch):
    """`vtsi check --line-speed 150` of the train without D runs the EN series at 2 km/h from 144 to
    180 km/h (19 speeds, computed here by en_speed_grid): a verdict, no speed-grid note, and the
    report says the series steps 2 km/h throughout (it said '10 km/h steps, finer ones within
    ±10 % of each resonance', of which there are none)."""
    monkeypatch.chdir(tmp_path)
    bridge = beam_toml(tmp_path / "bridge.toml", dt_s=0.005)
    status = main(["check", str(bridge), "--trains", str(regional), "--line-speed", "150", "--bridge-type",
                   "prestressed_concrete", "--workers", "1", "--quiet"])
    result = stored_check(tmp_path / "check.h5")
    speeds = SweepResults(tmp_path / "check.h5").speeds_kmh
    np.testing.assert_allclose(speeds, en_speed_grid(150.0, [5.0], [None]))
    assert len(speeds) == 19 and result.speed_grid == "" and status == (0 if result.passed else 1)
    page = (tmp_path / "check_report" / "report.html").read_text(encoding="utf-8")
    assert "the EN 1991-2 6.4.6.2 series (vtsi.sweep.en_speed_grid: steps of at most 2 km/h throughout, for a " \
           "train without D)" in page
