"""The coupled benchmark scenes through benchmarks/run.py: S3 (work-precision and stability map,
with charts) and S5 (vtsi against the straightforward implementation of the same step).

Speed is shown by the benchmarks, never asserted here: only the fields, the charts and the
agreement of the two implementations of S5 (same math: they agree to ~1e-12).
"""
import json
import math
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
RUN = ROOT / "benchmarks" / "run.py"
CONTRACT = {"scene", "steps", "vtsi_s", "vtsi_us_per_step", "peer", "peer_s", "peer_us_per_step",
            "speedup", "max_rel_diff", "cases"}
METHODS = ["Newmark", "HHT(0.9)", "Bathe", "Newmark+bspline", "Newmark+events"]


def run(*args, timeout=600):
    proc = subprocess.run([sys.executable, str(RUN), *args], capture_output=True, text=True, cwd=ROOT,
                          timeout=timeout)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)          # stdout holds the JSON object and nothing else


@pytest.fixture(scope="module")
def s3(tmp_path_factory):
    charts = tmp_path_factory.mktemp("charts")
    return run("S3", "--chart", str(charts), "--quick", "--repeats", "1"), charts


def test_s3_fields(s3):
    result, _ = s3
    assert CONTRACT <= set(result)
    assert result["scene"] == "S3" and result["quick"] is True
    assert result["reference"]
    rows = result["work_precision"]
    dts = sorted({r["dt"] for r in rows}, reverse=True)
    assert [r["method"] for r in rows] == [m for m in METHODS for _ in dts]
    for r in rows:
        assert {"method", "dt", "steps", "force_error", "force_error_smoothed", "deflection_error", "cpu_s",
                "us_per_step", "diverged"} <= set(r)
        assert not r["diverged"] and r["cpu_s"] > 0
        assert 0 <= r["deflection_error"] < 0.05        # every method is close to the reference in w
    assert result["us_per_step"]["Bathe"]


def test_s3_accuracy_ranks(s3):
    """What the charts show, in numbers: Newmark's λ rings (error grows as Δt shrinks), the
    damped schemes and the B-spline rows do not; every deflection converges."""
    rows = {(r["method"], r["dt"]): r for r in s3[0]["work_precision"]}
    dts = sorted({dt for _, dt in rows})
    fine, coarse = dts[0], dts[-1]
    assert rows["Newmark", fine]["force_error"] > rows["Newmark", coarse]["force_error"] > 0.03
    for method in ("Bathe", "Newmark+bspline", "Newmark+events"):
        assert rows[method, fine]["force_error"] < 0.01
    for method in METHODS:
        assert rows[method, fine]["deflection_error"] < rows[method, coarse]["deflection_error"]
        assert rows[method, fine]["force_error_smoothed"] < rows[method, coarse]["force_error_smoothed"]


def test_s3_stability_map_and_charts(s3):
    result, charts = s3
    stab = result["stability"]
    assert set(stab["methods"]) == set(METHODS)
    n_dt, n_v = len(stab["dts"]), len(stab["speeds_kmh"])
    for method in METHODS:
        grid, failed = stab["ringing"][method], stab["failed"][method]
        assert len(grid) == n_dt and all(len(line) == n_v for line in grid)
        for line, fails in zip(grid, failed):
            for value, fail in zip(line, fails):
                assert fail == (value is None or value > stab["fail_threshold"])
    assert any(map(any, stab["failed"]["Newmark"]))                  # Newmark's λ rings
    assert not any(map(any, stab["failed"]["Bathe"]))
    paths = result["charts"]
    assert set(paths) == {"work_precision", "stability_map"}
    for path in paths.values():
        p = pathlib.Path(path)
        assert p.parent == pathlib.Path(charts).resolve() and p.suffix == ".png"
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert p.stat().st_size < 300_000


def test_s5_json_quick():
    result = run("S5", "--json", "--quick", "--repeats", "1")
    assert CONTRACT <= set(result)
    assert result["scene"] == "S5" and result["peer"] == "straightforward"
    assert result["steps"] > 0 and result["vtsi_s"] > 0 and result["peer_s"] > 0
    assert result["max_wheels_on_bridge"] > 0                          # the run reaches the bridge
    assert result["max_rel_diff"] <= 1e-6                              # same math, two implementations
    assert result["max_rel_diff"] == max(result["deflection_rel_diff"], result["force_rel_diff"])
    # the step's cost with no wheel and with the most wheels on the viaduct, FE and modal
    pieces = [f"{b}_{p}_bridge_us_per_step" for b in ("fe", "modal") for p in ("off", "full")]
    assert all(math.isfinite(result[k]) and result[k] > 0 for k in pieces), {k: result[k] for k in pieces}
    common = result["modal_off_bridge_us_per_step"]
    assert result["modal_ratio_bound"] == pytest.approx(
        (result["fe_full_bridge_us_per_step"] - common) / (result["modal_full_bridge_us_per_step"] - common))


def test_chart_option_is_refused_by_a_scene_without_charts(tmp_path):
    proc = subprocess.run([sys.executable, str(RUN), "S5", "--chart", str(tmp_path)], capture_output=True,
                          text=True, cwd=ROOT, timeout=60)
    assert proc.returncode == 2 and "charts" in proc.stderr
