"""``vtsi check``: sweep, check, histories, scene and report in one command; its one-screen
summary and exit status; bad input refused with one line and nothing written."""
import os

import h5py
import pytest

from vtsi.__main__ import main
from vtsi.check import CheckResult, CheckSettings, stored_check


@pytest.fixture
def bridge(tmp_path, beam_toml):
    return beam_toml(tmp_path / "bridge.toml", dt_s=0.005)


def test_check_writes_results_checks_histories_and_report(tmp_path, bridge, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status = main(["check", str(bridge), "--trains", "HSLM-A1,HSLM-A4", "--speeds", "300:380:40",
                   "--bridge-type", "prestressed_concrete", "--additional-damping", "--workers", "1", "--quiet"])
    out = capsys.readouterr().out
    result = stored_check(tmp_path / "check.h5")
    assert status == (0 if result.passed else 1)
    assert "deck_acceleration" in out and ("PASS" in out or "FAIL" in out)
    # the bridge line states the damping as vtsi sweep's does, with where it came from: EN 1991-2
    # Table 6.6's 1.0 % for prestressed concrete (L >= 20 m) and Eq. 6.13's Δζ at L = 20 m,
    # (0.0187 L - 0.00064 L²) / (1 - 0.0441 L - 0.0044 L² + 0.000255 L³) = 0.296 %
    assert out.splitlines()[0] == (f"{result.bridge}; damping ζ = 1.3 % (EN 1991-2 Table 6.6, prestressed concrete, "
                                   "longest span L = 20 m: 1 % + Eq. 6.13 Δζ 0.296 % = 1.3 %)")
    row = result.row("deck_acceleration")
    assert row.train in out and f"{row.speed_kmh:g} km/h" in out
    with h5py.File(tmp_path / "check.h5", "r") as f:
        assert f["checks/criterion"].shape[0] == len(result.rows)
        assert f["histories"]                        # the governing cases' histories
        zeta = f.attrs["identity"]
    assert '"damping": 0.0129648' in zeta            # Table 6.6 (1.0 %) + Eq. 6.13 (0.30 %) at 20 m
    assert (tmp_path / "check_report" / "report.html").stat().st_size > 50_000
    assert (tmp_path / "check_report" / "report.md").exists()


def test_a_criterion_not_checked_gives_no_verdict_and_exit_1(tmp_path, bridge, capsys, monkeypatch):
    """ICE3's cars over the 20 m, 5 Hz span at 200, 220 and 240 km/h: its resonance n0 D / 2 (D =
    24.775 m) lies between 220 and 240, where the EN series steps 2 km/h, so the deck acceleration,
    the deflection and the car rows, all peaking at resonance, are not checked (the car rows read
    PASS before). It printed "PASS: every criterion checked is within its limit (not checked: ...)"
    and exited 0; a design check it is not."""
    monkeypatch.chdir(tmp_path)
    status = main(["check", str(bridge), "--trains", "ICE3", "--speeds", "200:240:20", "--cars", "full",
                   "--bridge-type", "prestressed_concrete", "--workers", "1", "--quiet"])
    out = capsys.readouterr().out
    with h5py.File(tmp_path / "check.h5", "r") as f:
        assert 220 < 3.6 * float(f["bridge/frequencies_hz"][0]) * 24.775 / 2 < 240
        assert not f["checks"].attrs["passed"]
    result = stored_check(tmp_path / "check.h5")
    statuses = {r.criterion: r.status for r in result.rows}
    assert statuses["deck_acceleration"] == statuses["deflection"] == "info"
    assert [statuses[c] for c in ("car_body_acceleration", "wheel_unloading", "contact_loss")] == ["info"] * 3
    assert all(r.value <= r.limit for r in result.rows if r.criterion in result.unchecked)      # each read PASS
    assert status == 1 and not result.passed
    assert "\nNO VERDICT: deck_acceleration, deflection, car_body_acceleration, wheel_unloading, contact_loss not " \
           "checked (see their notes); no other criterion was held to a limit; the speeds step across" in out
    assert "PASS:" not in out
    rows = {line.split()[0]: line for line in out.splitlines() if line.startswith(("deck_acceleration", "deflection "))}
    assert "not checked 3.5" in rows["deck_acceleration"] and "ref." not in rows["deck_acceleration"]   # as the report
    assert "not checked 0.03333" in rows["deflection"]
    page = (tmp_path / "check_report" / "report.html").read_text(encoding="utf-8")
    assert '<p class="verdict none">NO VERDICT: deck acceleration, deflection, car body acceleration' in page


@pytest.mark.parametrize("extra, words", [
    (["--bridge-type", "timber"], "timber"),                                  # unknown bridge type (Table 6.6)
    (["--bridge-type", "steel", "--unloading-limit", "abc"], "--unloading-limit 'abc': expected a number"),
    (["--bridge-type", "steel", "--alpha", "x1"], "--alpha 'x1': expected a number"),
    (["--bridge-type", "steel", "--track-form", "slab"], "slab"),
    (["--bridge-type", "steel", "--comfort", "superb"], "superb"),
    ([], "damping is needed"),
    (["--bridge-type", "steel", "--damping", "0.01"], "not both"),
    (["--bridge-type", "steel", "--line-speed", "300"],                        # 300 km/h given, 360 asked
     "--speeds reach 300 km/h, short of 1.2 x --line-speed 300 = 360 km/h that EN 1991-2 6.4.6.2(1) asks"),
    (["--bridge-type", "steel", "--line-speed", "250", "--speeds", "en:300"], "name two line speeds"),
    (["--bridge-type", "steel", "--line-speed", "83.3", "NO_SPEEDS"],       # m/s typed: it named '(0, 99.96]'
     "line speed 83.3 km/h: 1.2 x it = 99.96 km/h is below 144 km/h, where the series starts (EN 1991-2 6.4.6.2(3): "
     "from 40 m/s); if 83.3 is in m/s, the line speed is 299.88 km/h"),
    (["--bridge-type", "steel", "--line-speed", "3000", "NO_SPEEDS"],       # it named '3600 km/h' only
     "line speed 3000 km/h: 1.2 x it = 3600 km/h is faster than any train (at most 720 km/h)"),
    (["--bridge-type", "steel", "SELF_WEIGHT"],                               # totals would be read as train effects
     "include the bridge's self weight (bridge_self_weight), and the EN criteria read the trains' effects"),
])
def test_bad_check_input_is_one_line_exit_2_nothing_written(tmp_path, bridge, beam_toml, capsys, monkeypatch, extra,
                                                            words):
    monkeypatch.chdir(tmp_path)
    if "SELF_WEIGHT" in extra:
        extra = [e for e in extra if e != "SELF_WEIGHT"]
        beam_toml(bridge, dt_s=0.005, bridge_self_weight=True)
    speeds = [] if "--speeds" in extra or "NO_SPEEDS" in extra else ["--speeds", "300"]
    extra = [e for e in extra if e != "NO_SPEEDS"]
    status = main(["check", str(bridge), "--trains", "HSLM-A1", *speeds, "--workers", "1", *extra])
    err = capsys.readouterr().err
    assert status == 2
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("vtsi check: ") and words in lines[0], err
    assert sorted(os.listdir(tmp_path)) == ["bridge.toml"]


def test_missing_line_speed(tmp_path, bridge, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status = main(["check", str(bridge), "--trains", "HSLM-A1", "--bridge-type", "steel"])
    err = capsys.readouterr().err.strip()
    assert status == 2 and err.startswith("vtsi check: the line speed is needed") and "\n" not in err
    assert sorted(os.listdir(tmp_path)) == ["bridge.toml"]


class _ClosedPipe:
    """A standard output whose reader is gone (``vtsi check ... | head -3``)."""

    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")

    def flush(self):
        pass


def test_a_closed_standard_output_keeps_the_verdict_status(tmp_path, bridge, capsys, monkeypatch):
    """'vtsi check ... | head -3' exited 3 ('a passage failed') with '[Errno 32] Broken pipe'."""
    import vtsi.workflow

    monkeypatch.chdir(tmp_path)
    verdict = CheckResult(CheckSettings(), bridge="bridge: ...")          # no row: no verdict (exit 1)
    monkeypatch.setattr(vtsi.workflow, "design_check", lambda *a, **k: (verdict, {"html": "r.html", "scene": None}))
    monkeypatch.setattr("sys.stdout", _ClosedPipe())
    status = main(["check", str(bridge), "--trains", "HSLM-A1", "--speeds", "300", "--bridge-type", "steel",
                   "--workers", "1", "--quiet"])
    assert status == 1 and capsys.readouterr().err == ""
