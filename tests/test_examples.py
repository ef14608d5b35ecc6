"""Examples are documentation: each runs here, as a newcomer would run it."""
import importlib.util
import pathlib

import numpy as np
import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parent.parent / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quickstart_runs_and_reports_engineering_checks(tmp_path, capsys):
    quickstart = load("quickstart")
    result = quickstart.main(str(tmp_path / "q.png"), n_cars=2)
    out = capsys.readouterr().out
    assert "peak deck acceleration" in out and "EN 1990" in out
    assert (tmp_path / "q.png").stat().st_size > 10_000
    # dead load: each wheel of the ICE3 coaches carries its static share on rigid ground
    assert np.allclose(result["static_contact_force"], 152055.0, rtol=1e-3)
    assert 0.0 < result["peak_acceleration"] < 3.5 and 0.0 < result["unloading"] < 0.5


def test_readme_snippet_runs():
    readme = (EXAMPLES.parent / "README.md").read_text()
    snippet = readme.split("```python\n")[1].split("```")[0]
    namespace = {}
    exec(compile(snippet, "README.md", "exec"), namespace)
    assert namespace["midspan"].values.min() < 0.0
    assert np.all(namespace["forces"].values > 0.0)


def test_readme_sweep_snippet_runs(tmp_path, monkeypatch):
    """The README's sweep (570 passages on every core) as written, in a scratch directory."""
    readme = (EXAMPLES.parent / "README.md").read_text()
    snippet = next(block.split("```")[0] for block in readme.split("```python\n")[1:] if "Sweep(" in block)
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(snippet, "README.md", "exec"), namespace)
    results = namespace["sweep"].run("hslm.h5", resume=True)     # the file is complete: nothing reruns
    assert results.n_done == 570
    worst = results.critical("acceleration_absmax")
    assert worst["train"].startswith("HSLM-A") and 140.0 <= worst["speed_kmh"] <= 420.0


def test_sweep_example_writes_results_and_chart(tmp_path, capsys):
    example = load("sweep_hslm")
    results = example.main(str(tmp_path / "s"), trains=["HSLM-A1", "HSLM-A4"], speeds="300:340:20", workers=1,
                           elements=4, dt=5e-3)
    out = capsys.readouterr().out
    assert "zeta = 1.30 %" in out and "EN 1990 A2 limit" in out
    assert (tmp_path / "s.png").stat().st_size > 10_000
    assert results.n_done == 6 and (tmp_path / "s.h5").exists()


def test_example_bridge_file_is_the_s4_bridge():
    """examples/bridge_20m.toml (the README's `vtsi sweep` command): 20 m, 15 t/m, f1 = 5 Hz."""
    from vtsi.bridge_file import read_bridge_file
    from vtsi.damping import vertical_frequencies
    loaded = read_bridge_file(EXAMPLES / "bridge_20m.toml")
    f = vertical_frequencies(loaded.bridge.model, 3)[0]
    assert f[0] == pytest.approx(5.0, rel=1e-4) and loaded.bridge.description["spans_m"] == [20.0]
    assert loaded.settings["damping"] == 0.013 and "dt" not in loaded.settings          # the default dt


def test_design_check_example(tmp_path, capsys):
    """The main example at a reduced size (2 trains, a 200 km/h line, 4 elements, Δt = 5 ms):
    results, checks, report; the printout names the governing case and the times."""
    example = load("design_check")
    result, paths = example.main(str(tmp_path / "dc"), workers=1, trains=["HSLM-A1", "ICE3"], line_speed=200.0,
                                 elements=4, dt=5e-3)
    out = capsys.readouterr().out
    speeds = example.sweep_of(trains=["HSLM-A1", "ICE3"], line_speed=200.0, elements=4).speeds_kmh
    assert speeds[0] == 144.0 and speeds[-1] == 240.0     # EN 1991-2 6.4.6.2: from 40 m/s to 1.2 x the line speed
    row = result.row("deck_acceleration")
    assert row.train in ("HSLM-A1", "ICE3") and f"{row.speed_kmh:g} km/h" in out
    assert "compiling or loading" in out and paths["html"].exists() and (tmp_path / "dc.h5").exists()
