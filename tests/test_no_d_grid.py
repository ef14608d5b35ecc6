"""A train without a characteristic length D (an axle table whose dynamic signature shows no
regular spacing): its resonance speeds are unknown, so the EN 1991-2 6.4.6.2 series steps finely
(2 km/h) over its whole range, and a check of a coarser sweep gives no verdict. The train without
D here is a locomotive and seven vehicles of seven designs (coaches of 23-27.5 m on bogies
16-19.5 m apart, a 20 m baggage car): at its signature's peak an axle spacing recurs for 9 % of
its axles.

A regional train of 2 locomotives and 8 coaches of 26.4 m (bogie centres 17.2 m) had no D until vtsi
read its signature's peak in 12-30 m, 13.09 m, as the harmonic D/2. `vtsi check --line-speed 250` of
it on the beam below (dt 5 ms, damping 1 %): 10 km/h steps from 144 km/h read 2.363 m/s^2, NO
VERDICT (without D: its resonances unknown; with D: steps coarser than the series' around n0 D/3 =
158.4 km/h and n0 D/2 = 237.7 km/h); the 2 km/h series it had without D fails at 4.029 m/s^2 at 160
km/h (79 passages), the series of D = 26.4 m at 4.114 m/s^2 at 158.44 km/h (50 passages), and 1 km/h
steps at 4.135 m/s^2 at 159 km/h (157 passages)."""
import math

import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.check import CheckSettings, check, stored_check
from vtsi.signature import MIN_SHARE, principal_wavelength
from vtsi.sweep import en_speed_grid
from vtsi.sweep_results import SweepResults

LOCO = [0.0, 3.0, 10.0, 13.0]                    # a locomotive's axles [m]
COACH = [0.0, 2.5, 17.2, 19.7]                   # a 26.4 m coach's: bogie centres 17.2 m apart, 2.5 m bogies
COACH_M = 26.4                                   # [m] the regional train's coach length
VEHICLES = [(26.4, 19.0), (24.5, 17.2), (20.0, 14.0), (26.4, 17.2), (25.0, 18.0), (23.0, 16.0), (27.5, 19.5)]
"""(length, bogie centres) [m] of the mixed train's vehicles behind its locomotive, 2.5 m bogies."""


def regional_axles():
    """Axle positions [m] and loads [kN] of the regional train: a locomotive, 8 coaches, a locomotive."""
    x, F = [3.25 + p for p in LOCO], [210.0] * 4
    for k in range(8):
        x += [22.85 + COACH_M * k + p for p in COACH]
        F += [160.0] * 4
    x += [233.95 + p for p in LOCO]
    return np.array(x), np.array(F + [210.0] * 4)


def mixed_axles():
    """Axle positions [m] and loads [kN] of the mixed train: a locomotive and VEHICLES, each on two
    2.5 m bogies centred on the vehicle."""
    x, F, front = [3.25 + p for p in LOCO], [210.0] * 4, 19.5
    for length, centres in VEHICLES:
        first = front + (length - centres) / 2 - 1.25
        x += [first, first + 2.5, first + centres, first + centres + 2.5]
        F += [160.0] * 4
        front += length
    return np.array(x), np.array(F)


def _table(path, axles):
    x, F = axles
    path.write_text("position_m,load_kN\n" + "".join(f"{p:.2f},{f:g}\n" for p, f in zip(x, F)))
    return path


@pytest.fixture
def mixed(tmp_path):
    return _table(tmp_path / "mixed.csv", mixed_axles())


def test_the_mixed_train_has_no_d():
    """No spacing recurs at its peak for MIN_SHARE of its axles (its seven vehicles differ)."""
    peak = principal_wavelength(*mixed_axles())
    assert peak.length_m is None and peak.share < MIN_SHARE and "no characteristic length D" in peak.text()


def test_the_regional_train_gets_its_coach_length_at_the_harmonic_d_over_2():
    """Its bogie centres, 17.2 m of a 26.4 m coach, make each coach's phasor weaker at D than at D/2
    (two bogies of 2.5 m, 17.2 m apart: |2 cos(π 2.5/λ)| |2 cos(π 17.2/λ)|), so the signature
    peaks in 12-30 m at the harmonic D/2, inside its main lobe |2/D − 1/λ*| ≤ 1/L and outside
    the fundamental's; D is the spacing s with 2/s in that lobe that recurs for the most axles,
    those of 7 of the 8 coaches at least."""
    x, F = regional_axles()
    peak, span = principal_wavelength(x, F), x[-1] - x[0]

    def coach(lam):
        return abs(2 * np.cos(np.pi * 2.5 / lam)) * abs(2 * np.cos(np.pi * 17.2 / lam))
    assert coach(COACH_M) < coach(COACH_M / 2)
    assert abs(2 / COACH_M - 1 / peak.wavelength_m) <= 1 / span < abs(1 / COACH_M - 1 / peak.wavelength_m)
    assert peak.length_m == pytest.approx(COACH_M, abs=5e-4) and peak.repeats >= 7 * len(COACH)
    assert peak.text() == f"D = {COACH_M:g} m from its dynamic signature"


def test_the_regional_trains_en_series_fails_as_1_kmh_steps_do(tmp_path, beam_toml, monkeypatch):
    """`vtsi check --line-speed 150` of the regional train runs the EN series of D = 26.4 m: 10
    km/h steps with 2 km/h steps within ±10 % of its resonance n0 D / 3 (158.4 km/h on the 5 Hz
    beam), fewer passages than the 2 km/h steps throughout it had without D. It fails on the
    deck acceleration as a sweep in 1 km/h steps does, its governing speed within a step of
    the 1 km/h sweep's."""
    monkeypatch.chdir(tmp_path)
    bridge = beam_toml(tmp_path / "bridge.toml", dt_s=0.005)
    table = _table(tmp_path / "regional.csv", regional_axles())
    argv = ["check", str(bridge), "--trains", str(table), "--line-speed", "150", "--bridge-type",
            "prestressed_concrete", "--workers", "1", "--quiet"]
    assert main(argv + ["--out", "en.h5"]) == 1
    results = SweepResults(tmp_path / "en.h5")
    n0 = results.frequencies_hz[0]
    resonance = round(3.6 * n0 * COACH_M / 3, 2)
    np.testing.assert_allclose(results.speeds_kmh, en_speed_grid(150.0, results.frequencies_hz, [COACH_M]))
    assert np.isclose(results.speeds_kmh, resonance, rtol=0, atol=0.005).any()
    assert len(results.speeds_kmh) < len(en_speed_grid(150.0, results.frequencies_hz, [None]))
    en = stored_check(tmp_path / "en.h5")
    assert main(argv + ["--speeds", "144:180:1", "--out", "fine.h5"]) == 1
    fine = stored_check(tmp_path / "fine.h5")
    assert en.verdict().startswith("FAIL") and fine.verdict().startswith("FAIL")
    en_row, fine_row = en.row("deck_acceleration"), fine.row("deck_acceleration")
    assert en_row.status == fine_row.status == "fail"
    band = results.speeds_kmh[np.abs(results.speeds_kmh - resonance) <= 0.1 * resonance]
    assert abs(en_row.speed_kmh - fine_row.speed_kmh) <= np.max(np.diff(band))      # 2 km/h, the fine step


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


def test_a_train_without_d_on_10_kmh_steps_gives_no_verdict(tmp_path, beam_toml, mixed, capsys, monkeypatch):
    """The mixed train on a 20 m, 5 Hz span: on 10 km/h steps the deck acceleration and the
    deflection are not checked and the verdict names the train (exit 1); on 2 km/h steps, the EN
    series' fine step, the check gives a verdict, and its deck acceleration is at least the one
    the 10 km/h steps read (the same passages, and more of them)."""
    monkeypatch.chdir(tmp_path)
    bridge = beam_toml(tmp_path / "bridge.toml", dt_s=0.005)
    argv = ["check", str(bridge), "--trains", str(mixed), "--bridge-type", "prestressed_concrete",
            "--workers", "1", "--quiet"]
    assert main(argv + ["--speeds", "180:260:10", "--out", "coarse.h5"]) == 1
    out = capsys.readouterr().out
    coarse = stored_check(tmp_path / "coarse.h5")
    said = f"{mixed} has no characteristic length D (its resonances are unknown): step 10 km/h where the EN " \
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
    assert (f"{mixed} has no characteristic length D (its resonances are unknown): the speeds swept start at "
            "180 km/h, above the EN series' 144 km/h") in late.speed_grid


def test_the_en_series_of_a_train_without_d_is_checked_and_reported_as_fine(tmp_path, beam_toml, mixed, monkeypatch):
    """`vtsi check --line-speed 150` of the train without D runs the EN series at 2 km/h from 144 to
    180 km/h (19 speeds, computed here by en_speed_grid): a verdict, no speed-grid note, and the
    report says the series steps 2 km/h throughout (it said '10 km/h steps, finer ones within
    ±10 % of each resonance', of which there are none)."""
    monkeypatch.chdir(tmp_path)
    bridge = beam_toml(tmp_path / "bridge.toml", dt_s=0.005)
    status = main(["check", str(bridge), "--trains", str(mixed), "--line-speed", "150", "--bridge-type",
                   "prestressed_concrete", "--workers", "1", "--quiet"])
    result = stored_check(tmp_path / "check.h5")
    speeds = SweepResults(tmp_path / "check.h5").speeds_kmh
    np.testing.assert_allclose(speeds, en_speed_grid(150.0, [5.0], [None]))
    assert len(speeds) == 19 and result.speed_grid == "" and status == (0 if result.passed else 1)
    page = (tmp_path / "check_report" / "report.html").read_text(encoding="utf-8")
    assert "the EN 1991-2 6.4.6.2 series (vtsi.sweep.en_speed_grid: steps of at most 2 km/h throughout, for a " \
           "train without D)" in page
