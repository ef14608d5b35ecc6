"""Speed sweeps (vtsi.sweep): speed grids, equality with single analyses, flat memory, resume
after SIGKILL, executors (process pool, dask LocalCluster), the results file and its xarray
view, and every bad input."""
import gc
import math
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
import tracemalloc
from concurrent.futures import ProcessPoolExecutor

import h5py
import numpy as np
import pytest
import scipy.linalg
from threadpoolctl import threadpool_info

import vtsi
import vtsi.sweep as sweep_module
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import SweepError
from vtsi.models.bridges import first_frequency, simply_supported_beam
from vtsi.models.catalogue import catalogue_train
from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
from vtsi.damping import rayleigh_coefficients
from vtsi.passage import Output, PassageSettings, body_runout
from vtsi.recorders import ContactRecorder, NodeRecorder, TrainRecorder
from vtsi.sweep import Sweep, beam_bridge, en_speed_grid, resonance_speeds, speeds
from vtsi.sweep_results import SweepResults
from vtsi.track import Track
from vtsi.train import TrainSubdomain

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
FAST = PassageSettings(dt=5e-3, damping=0.0125)


def small_bridge(n=4):
    return beam_bridge([L], EI, 1.0, MU, elements_per_span=n)


# -- speeds ---------------------------------------------------------------------------------------
def test_speed_range_includes_its_stop_and_lists_parse():
    v = speeds("140:420:5")
    assert len(v) == 57 and v[0] == 140 and v[-1] == 420
    assert list(speeds("300, 200,250")) == [200, 250, 300]
    assert list(speeds([160, 160.0, 170])) == [160, 170]
    assert list(speeds("140:150:4")) == [140, 144, 148]


@pytest.mark.parametrize("spec, words", [("420:140:5", "empty range"), ("140:420:0", "step"),
                                         ("0,100", "> 0"), ("-5", "> 0"), ("a:b", "START:STOP:STEP"),
                                         ("", "no speed"), ("1:2", "START:STOP:STEP"),
                                         ("300,1000", r"^speeds: 1000 km/h is faster than any train \(at most 720 km/h\)$")])
def test_bad_speeds_name_the_value(spec, words):
    with pytest.raises(SweepError, match=words):
        speeds(spec)


@pytest.mark.parametrize("dt, speeds_kmh, message", [
    (0.03, [300.0], r"^sweep: time step dt = 0\.03 s does not resolve the bridge's first mode \(5\.00\d Hz, period "
                    r"0\.\d+ s\): take dt <= 0\.025 s \(T1/8\)$"),
    (0.02, [300.0, 700.0], r"^sweep: HSLM-A1 at 700 km/h crosses the 20 m track in 0\.103 s, fewer than 10 steps "
                           r"of dt = 0\.02 s: lower the speed or dt$"),
    (1e-3, [0.01, 300.0], r"^sweep: HSLM-A1 at 0\.01 km/h needs 1\.5e\+08 steps of dt = 0\.001 s, more than "
                          r"1e\+07: raise the speed or dt$"),
])
def test_a_passage_its_time_step_cannot_resolve_is_refused(dt, speeds_kmh, message):
    """Δt = 10 s used to give all-zero envelopes (the bridge sampled at rest) and 1e9 km/h a
    passage of no step: refused when the sweep is built, naming the train, speed and Δt; just
    inside T₁/8 and 10 steps on the track the passage is accepted."""
    with pytest.raises(SweepError, match=message):
        Sweep(small_bridge(), ["HSLM-A1"], speeds_kmh, PassageSettings(dt=dt, damping=0.0125))
    Sweep(small_bridge(), ["HSLM-A1"], [200.0], PassageSettings(dt=0.0249, damping=0.0125))
    Sweep(small_bridge(), ["HSLM-A1"], [0.999 * 3.6 * 20.0 / 0.2], PassageSettings(dt=0.02, damping=0.0125))


def test_a_damping_percentage_typed_as_a_ratio_is_refused():
    """ζ = 0.5 meant as 0.5 % would damp the deck acceleration to nothing: above 20 % of critical
    the settings are refused; 20 % itself is accepted."""
    with pytest.raises(vtsi.ModelError, match=r"^sweep settings: damping 0\.5 is 50 % of critical, above the 20 % any "
                                              r"bridge has: it is a ratio \(0\.01 for 1 %\)$"):
        PassageSettings(damping=0.5)
    assert PassageSettings(damping=0.2).damping == 0.2


def test_a_bridge_in_gpa_is_refused_by_its_frequency():
    """E in GPa with the rest in SI: f₁ = 5 Hz × √1e-9 ≈ 1.6e-4 Hz, which no railway bridge has
    (its passage would run 1.5 periods of free vibration: 2.6 hours of bridge time)."""
    with pytest.raises(SweepError, match=r"^sweep: bridge: first vertical frequency 0\.000158 Hz, below 0\.2 x EN 1991-2 "
                                         r"Figure 6\.10's lower limit .*: are E, I or the mass in other units\? "):
        Sweep(beam_bridge([L], EI * 1e-9, 1.0, MU, elements_per_span=4), ["HSLM-A1"], [300.0], FAST)


def test_en_grid_runs_to_1_2_line_speed_with_fine_steps_at_resonances():
    """EN 1991-2 §6.4.6.2: up to 1.2 × the line speed, smaller steps near v = n₀ D / i."""
    grid = en_speed_grid(300.0, [F1], [18.0, 27.0], step_kmh=10.0, fine_step_kmh=2.0, band=0.1)
    assert grid[0] == 144.0 and grid[-1] == pytest.approx(360.0)
    res = resonance_speeds([F1], [18.0, 27.0])
    assert res == pytest.approx(sorted({round(3.6 * F1 * D / i, 9) for D in (18.0, 27.0) for i in (1, 2, 3, 4)}))
    inside = [v for v in res if 144.0 <= v <= 360.0]
    assert inside, "the test needs resonances in range"
    for v in inside:
        assert np.any(np.isclose(grid, v)), v                     # the resonance itself
        near = grid[(grid > v * 0.9) & (grid < v * 1.1)]
        assert np.max(np.diff(near)) <= 2.0 + 1e-9                # fine steps around it
    far = [v for v in grid if all(abs(v - r) > 0.1 * r for r in res)]
    assert np.all(np.isin(np.arange(144.0, 360.0, 10.0), grid))   # the coarse grid is kept
    assert len(far) < len(grid)


# -- one sweep equals separate analyses ---------------------------------------------------------
def _single_passage(name, speed_kmh, settings, n_elements):
    """The case as a user would compute it by hand: a fresh model, Rayleigh, one analysis; the
    EN-filtered deck acceleration by projecting the full acceleration history on the modes up
    to the cut-off (scipy's eigh, not vtsi's). Returns n_steps and {output: (min, max, absmax)}."""
    model = vtsi.Model()
    beam = simply_supported_beam(model, L, n_elements, EI, 1.0, MU)
    asm = model.build()
    w2, phi = scipy.linalg.eigh(asm.K.toarray(), asm.M.toarray())
    f = np.sqrt(w2) / (2 * np.pi)
    bending = [fi for fi in f if min(abs(fi - F1 * k * k) for k in (1, 2, 3)) < 0.05 * fi][:3]
    cutoff = acceleration_cutoff_hz(bending)
    model.rayleigh(*rayleigh_coefficients(settings.damping, bending[0], cutoff))
    train = catalogue_train(name, speed_kmh / 3.6, fidelity=settings.cars)
    approach = 0.0 if train.n_dof == 0 else 25.0
    sub = TrainSubdomain(train, -approach + float(train.wheel_offsets[0]))
    tie = MovingLoadConstraint(Track(model, beam.elements), sub, None, settings.interpolation)
    every = NodeRecorder(beam.nodes, [1, 2, 3], "accel")
    recs = {"deflection": NodeRecorder(beam.nodes, [2], "disp", envelope=True, history=False),
            "end_rotation": NodeRecorder([beam.nodes[0], beam.nodes[-1]], [3], "disp", envelope=True, history=False)}
    if train.n_dof:
        forces = ContactRecorder(tie)
        bodies = TrainRecorder(sub, [f"car{i}.{d}" for i in range(len(train.cars)) for d in ("body_y", "body_rz")],
                               "accel")
    analysis = CoupledAnalysis(model, tie, settings.integrator, dt=settings.dt,
                               recorders=[every, *recs.values()] + ([forces, bodies] if train.n_dof else []))
    analysis.static()
    end = (L + approach + train.length) / train.speed + 1.5 / bending[0]
    x_head0 = -approach + float(train.wheel_offsets[0])
    for i, car in enumerate(train.cars):      # the run holds each car body's window: last wheel off the deck + run-out
        if "body_y" in car.dof_names:
            end = max(end, (L - x_head0 + train.wheel_offsets[train.wheel_car == i].max()) / train.speed
                      + body_runout(car))
    n = int(np.ceil(end / settings.dt - 1e-9))
    analysis.run(n)
    out = {k: np.array([r.envelope.min, r.envelope.max, r.envelope.absmax]) for k, r in recs.items()}
    if train.n_dof:     # the sweep's contact force: its 10 ms centred mean, trapezoidal weights on 2m + 1 samples
        m = max(1, round(0.005 / settings.dt))
        lam = np.asarray(forces.values)
        padded = np.concatenate([np.repeat(lam[:1], m, axis=0), lam, np.repeat(lam[-1:], m, axis=0)])
        weights = np.r_[0.5, np.ones(2 * m - 1), 0.5] / (2 * m)
        mean = sum(w * padded[k: k + len(lam)] for k, w in enumerate(weights))
        out["contact_force"] = np.array([mean.min(0), mean.max(0), np.abs(mean).max(0)])
        # the car body: at its centre or over either bogie pivot (Lc/2 from it), the largest at each step
        acc = np.asarray(bodies.values)
        body = []
        for i, car in enumerate(train.cars):
            half = 0.5 * (car.wheel_offsets[2] - car.wheel_offsets[0])
            points = np.stack([acc[:, 2 * i], acc[:, 2 * i] + half * acc[:, 2 * i + 1],
                               acc[:, 2 * i] - half * acc[:, 2 * i + 1]])
            body.append(points[np.argmax(np.abs(points), axis=0), np.arange(len(acc))])
        body = np.stack(body, axis=1)
        out["car_body_acceleration"] = np.array([body.min(0), body.max(0), np.abs(body).max(0)])
    modes = phi[:, f <= cutoff]
    a_free = np.asarray(every.values)[:, asm.free_of_full[np.arange(asm.n_full)] >= 0]
    order = asm.free_of_full[asm.free_of_full >= 0]
    a_free = a_free[:, np.argsort(order)]                           # columns in free-dof order
    filtered = (a_free @ asm.M.toarray() @ modes) @ modes[[asm.free_of_full[asm.full_dof(nd, 2)] for nd in beam.nodes]].T
    out["acceleration"] = np.array([filtered.min(0), filtered.max(0), np.abs(filtered).max(0)])
    return n, out


@pytest.mark.parametrize("name, cars", [("HSLM-A3", "force"), ("ICE3", "full")])
def test_sweep_equals_single_analyses_case_by_case(name, cars):
    settings = PassageSettings(dt=5e-3, damping=0.0125, cars=cars)
    sweep = Sweep(small_bridge(), [name], "200,340", settings)
    res = sweep.run(None, workers=1, progress=False)
    for v in (200.0, 340.0):
        n, expected = _single_passage(name, v, settings, 4)
        case = res.case(name, v)
        assert case["attrs"]["n_steps"] == n
        for out, env in expected.items():
            scale = np.max(np.abs(env))
            assert np.max(np.abs(case[out]["envelope"][:3] - env)) <= 1e-12 * scale, out


def test_the_bridge_is_factored_once_per_sweep():
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A9"], "150,250,350", FAST)
    sweep.run(None, workers=1, progress=False)
    assert len(sweep.runner.cache) == 1
    factors = sweep.runner.cache.stages()[0].fac
    sweep.runner.run("HSLM-A2", 300.0)
    assert len(sweep.runner.cache) == 1 and sweep.runner.cache.stages()[0].fac is factors


def test_memory_stays_flat_over_500_passages():
    """Nothing is kept per passage: after a warm-up (numpy's small-buffer caches fill), 400 more
    passages leave the traced memory where it was (garbage collected at both ends). Up to
    350 km/h: an axle then crosses the 20 m track in 10 steps of 0.02 s (CoupledAnalysis
    refuses fewer, vtsi.coupled.STEPS_ON_TRACK)."""
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "300", PassageSettings(dt=0.02, damping=0.0125))
    runner = sweep.runner
    speeds_ = np.linspace(200.0, 350.0, 500)
    for v in speeds_[:50]:
        runner.run("HSLM-A1", v)
    tracemalloc.start()
    try:
        for v in speeds_[50:100]:
            runner.run("HSLM-A1", v)
        gc.collect()
        early, _ = tracemalloc.get_traced_memory()
        for v in speeds_[100:]:
            runner.run("HSLM-A1", v)
        gc.collect()
        late, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert late - early < 64 * 1024, f"memory grew by {(late - early) / 1024:.0f} KiB over 400 passages"


# -- the results file ---------------------------------------------------------------------------
def test_results_file_layout_units_and_envelopes(tmp_path):
    path = tmp_path / "s.h5"
    outputs = [Output("deflection", "disp"), Output("acceleration", "accel"),
               Output("midspan", "accel", nodes="midspan", history=True)]
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A4"], "200:300:50", FAST, outputs=outputs)
    res = sweep.run(path, workers=1, progress=False)
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == "vtsi-sweep" and f.attrs["vtsi_version"] == vtsi.__version__
        identity = json.loads(f.attrs["identity"])
        assert identity["settings"]["dt"] == 5e-3 and identity["trains"] == ["HSLM-A1", "HSLM-A4"]
        assert f["envelopes/acceleration_absmax"].attrs["units"] == "m/s^2"
        assert f["envelopes/deflection_min"].shape == (2, 3, 1)
        assert f["outputs/acceleration"].attrs["units"] == "m/s^2"
        assert list(f["outputs/acceleration"].attrs["rows"])[:3] == ["min", "max", "absmax"]
        nodes = f["outputs/acceleration/columns"][()]
        np.testing.assert_array_equal(nodes, sweep.runner.deck_nodes)
        assert f.attrs["format_version"] == 6
        table = f["cases"]                         # one table of every case, a row each
        assert sorted(table["train"][()]) == [0, 0, 0, 1, 1, 1]
        mine = table["train"][()] == 1             # HSLM-A4, the second of /train
        assert sorted(table["speed_kmh"][()][mine]) == [200.0, 250.0, 300.0]
        row = int(np.flatnonzero(mine & (table["speed_kmh"][()] == 250.0))[0])
        assert table["seed"][row] == -1
        env = table["acceleration"][row]
        assert env.shape == (6, len(nodes))
        assert f["envelopes/acceleration_absmax"][1, 1, 0] == env[2].max()
        assert f["envelopes/acceleration_absmax_where"][1, 1, 0] == nodes[np.argmax(env[2])]
        case = table["histories/HSLM-A4/250kmh/smooth"]
        hist = case["midspan_values"][()]
        n_steps = table["n_steps"][row]
        assert hist.shape == (n_steps, 1) and case["midspan_time"].shape == (n_steps,)
        assert np.max(np.abs(hist)) == pytest.approx(table["midspan"][row][2, 0])
        trains = f["trains"]                       # the trains' axles end to end, a row each
        ptr = trains["axle_ptr"][()]
        a4 = sweep.runner.train("HSLM-A4", 1.0)
        np.testing.assert_array_equal(trains["axle_offsets_m"][ptr[1]:ptr[2]], a4.wheel_offsets)
        assert trains["n_cars"][1] == len(a4.cars) and ptr[-1] == len(trains["static_wheel_loads_N"])
    reread = SweepResults(path).case("HSLM-A4", 250.0)
    np.testing.assert_array_equal(reread["acceleration"]["columns"], nodes)
    assert reread["midspan"]["values"].shape == hist.shape
    crit = res.critical("acceleration_absmax")
    table = res.envelope("acceleration_absmax")
    assert crit["value"] == np.nanmax(table)
    assert crit["train"] in ("HSLM-A1", "HSLM-A4") and crit["units"] == "m/s^2"
    text = res.summary()
    assert "acceleration_absmax" in text and crit["train"] in text and "6 of 6 cases" in text


def test_xarray_view_of_the_envelopes(tmp_path):
    import xarray    # a test extra: its absence fails the test
    res = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200,300", FAST).run(tmp_path / "x.h5", workers=1,
                                                                              progress=False)
    ds = res.to_xarray()
    assert isinstance(ds, xarray.Dataset)
    assert ds["acceleration_absmax"].dims == ("train", "speed_kmh", "seed")
    assert ds["acceleration_absmax"].attrs["units"] == "m/s^2" and ds["speed_kmh"].attrs["units"] == "km/h"
    assert float(ds["acceleration_absmax"].sel(train="HSLM-A2", speed_kmh=300.0, seed=-1)) == \
        res.envelope("acceleration_absmax")[1, 1, 0]
    reread = SweepResults(tmp_path / "x.h5").to_xarray()
    assert reread.identical(ds)


# -- executors ---------------------------------------------------------------------------------
def test_process_pool_equals_serial(tmp_path):
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A5"], "160:400:60", FAST)
    serial = sweep.run(tmp_path / "a.h5", workers=1, progress=False)
    pooled = sweep.run(tmp_path / "b.h5", workers=2, progress=False, cases_per_task=2)
    for q in serial.quantities:
        np.testing.assert_array_equal(serial.envelope(q), pooled.envelope(q))


def test_a_sweep_of_less_than_a_task_runs_in_this_process_by_default(monkeypatch):
    """workers=None means every core, but a pool's start-up costs more than a sweep of at most
    TASK_STEPS steps takes: that one runs here (no pool is made) and gives the serial numbers."""

    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A5"], "160:400:60", FAST)
    assert sweep.case_cost(sweep.cases) * len(sweep.cases) <= sweep_module.TASK_STEPS
    serial = sweep.run(None, workers=1, progress=False)

    def no_pool(*args, **kwargs):
        raise AssertionError("a process pool was started for a sweep of less than one task")

    monkeypatch.setattr(sweep_module, "ProcessPoolExecutor", no_pool)
    default = sweep.run(None, progress=False)
    for q in serial.quantities:
        np.testing.assert_array_equal(serial.envelope(q), default.envelope(q))
    monkeypatch.setattr(sweep_module, "TASK_STEPS", 1)          # a sweep of many tasks: the pool
    with pytest.raises(AssertionError, match="process pool was started"):
        sweep.run(None, progress=False)


def test_dask_local_cluster_executor(tmp_path):
    import distributed    # a test extra: its absence fails the test
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200:320:40", FAST)
    serial = sweep.run(None, workers=1, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        res = sweep.run(tmp_path / "d.h5", executor=client.get_executor(), workers=2, progress=False,
                        cases_per_task=2)
    for q in serial.quantities:
        np.testing.assert_array_equal(serial.envelope(q), res.envelope(q))


# -- resume ------------------------------------------------------------------------------------
SCRIPT = """
import sys, numpy as np
from vtsi.sweep import Sweep, beam_bridge
from vtsi.passage import PassageSettings
L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
sweep = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=4), ["HSLM-A1", "HSLM-A2", "HSLM-A3"],
              "140:420:10", PassageSettings(dt=2e-3, damping=0.0125))
sweep.run(sys.argv[1], workers=int(sys.argv[2]), progress=False, resume=True, cases_per_task=3)
"""


def _done(path):
    try:
        with h5py.File(path, "r") as f:
            return f["cases"]["train"].shape[0]
    except (OSError, KeyError):
        return 0


@pytest.mark.parametrize("workers", [1, 2])
def test_resume_after_sigkill_equals_an_uninterrupted_run(tmp_path, workers):
    """With a process pool, the killed sweep's workers (forked: they shared the open file of its
    lock) outlived it, idle, and held the lock, so that --resume was refused until they were
    killed by hand. They end within seconds of the kill now, and the resume runs at once."""
    import psutil    # a dependency of dask.distributed, a test extra: its absence fails the test
    script = tmp_path / "sweep.py"
    script.write_text(textwrap.dedent(SCRIPT))
    killed, whole = tmp_path / "killed.h5", tmp_path / "whole.h5"
    proc = subprocess.Popen([sys.executable, str(script), str(killed), str(workers)], cwd=tmp_path)
    try:
        deadline = time.time() + 120
        while _done(killed) < 9 and time.time() < deadline and proc.poll() is None:
            time.sleep(0.02)
        assert proc.poll() is None, "the sweep ended before it could be killed"
        pool = psutil.Process(proc.pid).children(recursive=True)
        assert len(pool) == (workers if workers > 1 else 0)
        proc.send_signal(signal.SIGKILL)
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
    _, alive = psutil.wait_procs(pool, timeout=5)         # no worker outlives the sweep
    for worker in alive:
        worker.kill()
    assert not alive, f"{len(alive)} workers outlived the killed sweep by 5 s"
    done = _done(killed)                                  # the file is readable after the kill
    assert 9 <= done < 87
    subprocess.run([sys.executable, str(script), str(killed), str(workers)], cwd=tmp_path, check=True, timeout=300)
    subprocess.run([sys.executable, str(script), str(whole), "1"], cwd=tmp_path, check=True, timeout=300)
    assert not (tmp_path / "killed.h5.partial").exists()
    a, b = SweepResults(killed), SweepResults(whole)
    assert a.n_done == b.n_done == 87
    for q in a.quantities:                                # bitwise: the same passages, written once each
        np.testing.assert_array_equal(a.envelope(q), b.envelope(q))
    for train in a.trains:
        for v in a.speeds_kmh:
            ca, cb = a.case(train, v), b.case(train, v)
            for out in ("deflection", "acceleration"):
                np.testing.assert_array_equal(ca[out]["envelope"], cb[out]["envelope"])


def test_a_file_of_an_older_format_is_refused_with_its_version(tmp_path):
    path = tmp_path / "old.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200", FAST)
    sweep.run(path, workers=1, progress=False)
    with h5py.File(path, "a") as f:          # as a vtsi of format 4 wrote it
        f.attrs["format_version"] = 4
    with pytest.raises(SweepError, match="format 4, this vtsi reads format 6"):
        SweepResults(path)
    with pytest.raises(SweepError, match="format 4, this vtsi writes format 6: it cannot be resumed"):
        sweep.run(path, workers=1, progress=False, resume=True)


def test_resume_skips_finished_cases(tmp_path):
    path = tmp_path / "r.h5"
    Sweep(small_bridge(), ["HSLM-A1"], "200,300", FAST).run(path, workers=1, progress=False)
    with h5py.File(path, "a") as f:        # forget one case, as a killed run would
        table = f["cases"]
        keep = np.flatnonzero(table["speed_kmh"][()] != 300.0)
        for name in list(table):
            if isinstance(table[name], h5py.Dataset) and table[name].ndim and table[name].shape[0] == 2:
                data = table[name][()][keep]
                table[name].resize(len(keep), axis=0)
                table[name][...] = data
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200,300", FAST)
    calls = []
    run = sweep.runner.run
    sweep.runner.run = lambda *a: calls.append(a) or run(*a)
    res = sweep.run(path, workers=1, progress=False, resume=True)
    assert calls == [("HSLM-A1", 300.0, -1)] and res.n_done == 2


# -- bad inputs ---------------------------------------------------------------------------------
@pytest.mark.parametrize("trains, spec, words", [(["HSLM-A11"], "200", "HSLM-A11"),
                                                 (["HSLM-A1"], "300:200:10", "empty range"),
                                                 (["HSLM-A1"], "0", "> 0"),
                                                 ([], "200", "no train"),
                                                 (["HSLM-A1", "HSLM-A1"], "200", "twice"),
                                                 (5, "200", "trains must be catalogue names or axle-table paths, got 5"),
                                                 ([3.5], "200", r"axle-table paths, got \[3.5\]")])
def test_bad_sweep_inputs_raise_before_anything_is_written(tmp_path, trains, spec, words):
    with pytest.raises(SweepError, match=words):
        Sweep(small_bridge(), trains, spec, FAST).run(tmp_path / "bad.h5")
    assert list(tmp_path.iterdir()) == []


def test_a_bridge_without_track_and_bad_settings():
    bridge = small_bridge()
    bridge.track_elements = []
    with pytest.raises(SweepError, match="no track"):
        Sweep(bridge, ["HSLM-A1"], "200", FAST)
    with pytest.raises(vtsi.ModelError, match="dt"):
        PassageSettings(dt=0.0)
    with pytest.raises(vtsi.ModelError, match="cars"):
        PassageSettings(cars="bogie")
    with pytest.raises(SweepError, match="full"):
        Sweep(small_bridge(), ["HSLM-A1"], "200", PassageSettings(cars="full"))


def test_unwritable_path_and_existing_files(tmp_path):
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200", FAST)
    with pytest.raises(SweepError, match="does not exist"):
        sweep.run(tmp_path / "no" / "such" / "dir.h5", workers=1)
    path = tmp_path / "s.h5"
    sweep.run(path, workers=1, progress=False)
    with pytest.raises(SweepError, match="exists"):
        sweep.run(path, workers=1)
    other = Sweep(small_bridge(), ["HSLM-A1"], "200", PassageSettings(dt=4e-3, damping=0.0125))
    with pytest.raises(SweepError, match="different sweep.*dt"):
        other.run(path, workers=1, resume=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.h5"]
    assert other.run(path, workers=1, overwrite=True, progress=False).identity["settings"]["dt"] == 4e-3
    with pytest.raises(SweepError, match="is a directory"):
        sweep.run(tmp_path, workers=1)


def test_results_that_cannot_be_read_are_named(tmp_path):
    """A results path that is missing, a folder or not HDF5, and a case asked with a seed that
    is not an integer: a SweepError naming it (the CLI's one line), no h5py or numpy error."""
    with pytest.raises(SweepError, match=r"results file .*missing.h5: no such file"):
        SweepResults(tmp_path / "missing.h5")
    with pytest.raises(SweepError, match=r"results file .*: not a file"):
        SweepResults(tmp_path)
    (tmp_path / "notes.h5").write_text("not HDF5")
    with pytest.raises(SweepError, match=r"results file .*notes.h5: not a readable HDF5 file"):
        SweepResults(tmp_path / "notes.h5")
    res = Sweep(small_bridge(), ["HSLM-A1"], "200", FAST).run(None, workers=1, progress=False)
    with pytest.raises(SweepError, match=r"seed must be an integer \(-1: smooth rail\), got 'accel'"):
        res.history("HSLM-A1", 200, "accel")
    with pytest.raises(SweepError, match=r"speed \[km/h\] must be a number, got 'fast'"):
        res.history("HSLM-A1", "fast")


def test_a_failing_case_is_named_and_the_finished_ones_are_kept(tmp_path):
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200", FAST)
    run = sweep.runner.run

    def failing(train, speed, seed=-1):
        if train == "HSLM-A2":
            raise vtsi.DivergenceError("diverged at step 3, t = 0.015 s", 3, 0.015)
        return run(train, speed, seed)
    sweep.runner.run = failing
    with pytest.raises(SweepError, match=r"HSLM-A2/200kmh.*step 3"):
        sweep.run(tmp_path / "f.h5", workers=1, progress=False, cases_per_task=1)
    assert SweepResults(tmp_path / "f.h5").n_done == 1


def _deck_on_piers(rail=None):
    """3 × 20 m continuous deck (2 m elements, nodes 1–31) fixed at its ends and carried at x = 20
    and 40 m by 8 m piers (fixed at their feet) on zeroLength bearings; with ``rail`` [m] the
    track is a rail beam that high above the deck (0: pads between coincident nodes) on vertical
    springs at every node."""
    from vtsi.sweep import SweepBridge
    model = vtsi.Model()
    for i in range(31):
        model.node(i + 1, 2.0 * i, 0.0)
    model.fix(1, 1, 1, 0)
    model.fix(31, 0, 1, 0)
    deck = list(range(1, 31))
    for e in deck:
        model.element("elasticBeamColumn", e, (e, e + 1), A=8.0, E=3.5e10, I=1.9, rho=15000.0)
    for k, (top, x) in enumerate(((11, 20.0), (21, 40.0))):
        model.node(200 + k, x, 0.0)
        model.node(300 + k, x, -8.0)
        model.fix(300 + k, 1, 1, 1)
        model.element("zeroLength", 200 + k, (top, 200 + k), kx=1e12, ky=1e12)
        model.element("elasticBeamColumn", 300 + k, (300 + k, 200 + k), A=6.0, E=3.5e10, I=2.0, rho=15000.0)
    if rail is None:
        return SweepBridge(model, deck, {"kind": "script"})
    for i in range(31):
        model.node(1001 + i, 2.0 * i, rail)
        model.element("zeroLength", 2001 + i, (1001 + i, i + 1), ky=1e9)
        if i:
            model.element("elasticBeamColumn", 1000 + i, (1000 + i, 1001 + i), A=0.0077, E=2.1e11, I=3.05e-5,
                          rho=60.0)
    model.fix(1001, 1, 0, 0)
    return SweepBridge(model, list(range(1001, 1031)), {"kind": "script"})


def test_spans_end_at_piers_and_bearings_not_at_rail_springs():
    """A deck on piers is three spans, not one (a check read L_Φ = 60 m, Φ₂ = 1.011 and
    L/600 = 0.1 m instead of 26 m, 1.114 and 0.033 m, and never the outer mid-spans); a rail on
    springs over that deck keeps the deck's spans, not one per spring."""
    for rail in (None, 0.5, 0.0):
        runner = Sweep(_deck_on_piers(rail), ["HSLM-A1"], "300", FAST).runner
        assert runner.span_lengths == pytest.approx([20.0, 20.0, 20.0]), rail
        base = 0 if rail is None else 1000
        assert runner.support_nodes == [base + 1, base + 11, base + 21, base + 31]
        assert runner.pier_nodes == [base + 11, base + 21]                   # one continuous deck over two piers
        assert runner.midspan_nodes == [base + 6, base + 16, base + 26]
        assert runner.track_on_a_structure == (rail is not None)


def test_a_check_of_a_rail_on_pads_says_its_rows_read_the_rail():
    """A rail on springs over a deck: the deck outputs are the rail's (its moment was 19 kN·m
    against the deck's 8.9 MN·m), and every deck row of the check says so; a plain deck's do not."""
    from vtsi.check import check
    for rail in (None, 0.5):
        results = Sweep(_deck_on_piers(rail), ["HSLM-A1"], "300", FAST).run(None, workers=1, progress=False)
        assert results.bridge()["track_on_a_structure"] == (rail is not None)
        rows = check(results).rows
        marked = {r.criterion for r in rows if "this row reads the track, not that structure" in r.note}
        assert marked == (set() if rail is None else {r.criterion for r in rows})
        assert "deck_acceleration" in {r.criterion for r in rows}


def test_one_element_spans_are_spans():
    """2 + 20 + 2 m on 2 m elements: the side spans are one element each, and stay spans (a rule
    'both ends supported is ground' made it one 20 m span)."""
    from vtsi.sweep import SweepBridge
    model = vtsi.Model()
    for i in range(13):
        model.node(i + 1, 2.0 * i, 0.0)
        if i in (0, 1, 11, 12):
            model.fix(i + 1, int(i == 0), 1, 0)
    for e in range(1, 13):
        model.element("elasticBeamColumn", e, (e, e + 1), A=1.0, E=3.5e10, I=EI / 3.5e10, rho=MU)
    runner = Sweep(SweepBridge(model, list(range(1, 13)), {"kind": "script"}), ["HSLM-A1"], "300", FAST).runner
    assert runner.span_lengths == pytest.approx([2.0, 20.0, 2.0]) and runner.midspan_nodes[1] == 7


def test_an_approach_on_the_ground_is_no_span(tmp_path):
    """A 20 m span whose track runs on over 4 m of ground at each end (nodes with uy fixed, or on
    springs): one span from x = 0 to 20 m, not eleven (each ground element was a 'span' of its own,
    with an L/600 limit of 3 mm); the results file keeps the span's ends, and the deck
    acceleration is read on the span (an approach's end on springs governed: 11.8 m/s² against
    the span's 4.3)."""
    from vtsi.check import check
    from vtsi.sweep import SweepBridge
    for springs in (False, True):
        model = vtsi.Model()
        xs = np.arange(-4.0, 24.1, 2.0)
        for i, x in enumerate(xs):
            model.node(i + 1, float(x), 0.0)
            if x <= 0.0 or x >= 20.0:
                if springs and 0.0 < abs(x - 10.0) - 10.0:
                    model.node(100 + i, float(x), -1.0)
                    model.fix(100 + i, 1, 1, 1)
                    model.element("zeroLength", 100 + i, (i + 1, 100 + i), ky=2e8, cy=1e5)
                else:
                    model.fix(i + 1, int(x == 0.0), 1, 0)
        for e in range(1, len(xs)):
            model.element("elasticBeamColumn", e, (e, e + 1), A=1.0, E=3.5e10, I=EI / 3.5e10, rho=MU)
        sweep = Sweep(SweepBridge(model, list(range(1, len(xs))), {"kind": "script"}), ["HSLM-A1"], "300", FAST)
        assert sweep.runner.span_lengths == [20.0] and sweep.runner.midspan_nodes == [8], springs
        results = sweep.run(tmp_path / f"g{springs}.h5", workers=1, progress=False)
        assert results.bridge()["span_ends_m"].tolist() == [[0.0, 20.0]]
        row = check(results).row("deck_acceleration")        # an approach's springs are not the deck
        assert 3 <= int(row.where.split()[1]) <= 13 and "nodes only" not in row.note        # x = 0 … 20 m


def test_bridge_frequency_from_the_model():
    sweep = Sweep(small_bridge(8), ["HSLM-A1"], "200", FAST)
    assert sweep.runner.frequencies[0] == pytest.approx(first_frequency(L, EI, 1.0, MU), rel=1e-4)


def test_irregular_rail_seeds_with_cars():
    """An irregular rail: one case per seed, each seed its own sample (different contact forces),
    the same seed the same result in another sweep; the cars start at rest on the faded-in rail."""
    settings = PassageSettings(dt=5e-3, damping=0.0125, cars="full", irregularity="german-high")
    make = lambda seeds: Sweep(small_bridge(), ["ICE3"], "250", settings, seeds=seeds)
    res = make([3, 7]).run(None, workers=1, progress=False)
    assert res.seeds == [3, 7]
    low = res.envelope("contact_force_min")[0, 0]
    assert np.all(np.isfinite(low)) and low[0] != low[1]
    assert np.all(low > 0) and np.all(res.envelope("contact_force_max")[0, 0] > 152055.0)
    again = make([7]).run(None, workers=1, progress=False)
    assert again.envelope("contact_force_min")[0, 0, 0] == low[1]
    body = res.envelope("car_body_acceleration_absmax")[0, 0]
    assert np.all(body > 0) and np.all(body < 2.0)


def test_a_case_on_an_irregular_rail_does_not_depend_on_the_cases_before_it():
    """A worker runs many cases with one runner. A case on an irregular rail gives what it gives
    alone (to 1e-12: numpy sums a profile's cosines at x with a rounding that depends on x's
    place in the array) after a slower case of its train (its dead-load start was cached from that
    speed, but the wheels' rates V r', V² r'' and the B-spline smoothing over V Δt differ: the
    contact forces moved by 2.8 N), and a short train's case after a longer train's (the profile,
    sampled over the longer train's wider range, keeps its samples at whole multiples of its
    step: 0.085 N when they moved with the range's start)."""
    from vtsi.models import ice3
    from vtsi.models.catalogue import _REGISTRY, Entry, register
    settings = PassageSettings(dt=5e-3, damping=0.0125, cars="full", irregularity="german-high")
    register(Entry("ICE3-3", "ICE3 of 3 cars (test)", {"full": lambda speed, span: ice3(3, speed=speed)}))
    try:
        for before, case in ((("ICE3", 160.0), ("ICE3", 250.0)), (("ICE3", 250.0), ("ICE3-3", 250.0))):
            alone = Sweep(small_bridge(), ["ICE3"], "250", settings, seeds=[3]).runner.run(*case, 3)
            runner = Sweep(small_bridge(), ["ICE3"], "250", settings, seeds=[3]).runner
            runner.run(*before, 3)
            after = runner.run(*case, 3)
            for name in ("contact_force", "acceleration", "car_body_acceleration"):
                a, b = alone.envelopes[name][:3], after.envelopes[name][:3]
                assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a)), (before, name, np.max(np.abs(a - b)))
    finally:
        del _REGISTRY["ICE3-3"]


def test_trains_with_different_wheel_counts_share_the_vehicle_tables():
    """A registered 4-car ICE3 beside the 8-car one: the contact-force tables of the file are
    as wide as the longer train's 32 wheels, the shorter's 16 padded; each case reads back its
    own wheels, and every envelope cell is the extreme of its own train's wheels."""
    from vtsi.models import ice3
    from vtsi.models.catalogue import _REGISTRY, Entry, register
    register(Entry("ICE3-4", "ICE3 of 4 cars (test)", {"full": lambda speed, span: ice3(4, speed=speed)}))
    try:
        res = Sweep(small_bridge(), ["ICE3-4", "ICE3"], "250", PassageSettings(dt=5e-3, cars="full")).run(
            None, workers=1, progress=False)
        env, columns = res.column_envelopes("contact_force")
        assert env.shape == (2, 1, 1, 6, 32) and list(columns) == list(range(32))
        assert np.all(np.isnan(env[0, 0, 0, :, 16:])) and np.all(np.isfinite(env[0, 0, 0, :, :16]))
        short, long = res.case("ICE3-4", 250.0)["contact_force"], res.case("ICE3", 250.0)["contact_force"]
        assert list(short["columns"]) == list(range(16)) and short["envelope"].shape == (6, 16)
        assert long["envelope"].shape == (6, 32)
        low = res.envelope("contact_force_min")[:, 0, 0]
        assert low[0] == np.min(short["envelope"][0]) and low[1] == np.min(long["envelope"][0])
        assert res.train_data("ICE3-4")["contact_wheels"].shape == (16,)
    finally:
        del _REGISTRY["ICE3-4"]


def test_integrators_and_contact_strategies_are_settings():
    from vtsi.integrators import HHT
    bridge = small_bridge()
    base = Sweep(bridge, ["ICE3"], "300", PassageSettings(dt=5e-3, cars="full")).run(None, workers=1, progress=False)
    for settings in (PassageSettings(dt=5e-3, cars="full", integrator=HHT(0.9)),
                     PassageSettings(dt=5e-3, cars="full", integrator="Bathe", interpolation="bspline"),
                     PassageSettings(dt=5e-3, cars="full", contact="lcp")):
        res = Sweep(bridge, ["ICE3"], "300", settings).run(None, workers=1, progress=False)
        a, b = res.envelope("deflection_min")[0, 0, 0], base.envelope("deflection_min")[0, 0, 0]
        assert a == pytest.approx(b, rel=0.03), settings
    assert json.loads(json.dumps(res.identity))["settings"]["contact"] == "lcp"
    with pytest.raises(vtsi.ModelError, match="unknown integrator"):
        PassageSettings(integrator="Euler")


def test_progress_bar_shows_cases_rate_and_time_left_only_when_asked(capsys):
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200:300:50", FAST)
    sweep.run(None, workers=1)                      # stderr is not a terminal here: quiet
    assert capsys.readouterr().err == ""
    sweep.run(None, workers=1, progress=True, cases_per_task=1)
    err = capsys.readouterr().err
    assert "3/3" in err and "case/s" in err and "<" in err      # done/total [elapsed<left, rate]


def test_histories_of_chosen_cases_are_added_to_the_file(tmp_path):
    path = tmp_path / "h.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200,300", FAST)
    res = sweep.run(path, workers=1, progress=False)
    res = sweep.record_histories(path, [("HSLM-A2", 300.0, -1)])
    assert res.histories() == ["HSLM-A2/300kmh/smooth"]
    h = res.history("HSLM-A2", 300.0)
    t, a, nodes = h["deck_acceleration"]
    np.testing.assert_array_equal(nodes, sweep.runner.deck_nodes)
    assert t.shape == (h["attrs"]["n_steps"],) and a.shape == (len(t), len(nodes))
    assert np.max(np.abs(a), axis=0) == pytest.approx(res.case("HSLM-A2", 300.0)["acceleration"]["envelope"][2])
    assert h["attrs"]["x_head0"] == 0.0
    with h5py.File(path, "r") as f:
        assert f["bridge/mode_shapes_uy"].shape == (5, 3)


def test_a_shared_bridge_cache_tells_self_weight_apart():
    """Two analyses of one bridge sharing a cache, with and without the deck's self weight, each
    get their own stages (the self-weight deflection is part of them)."""
    from vtsi.subdomain import BridgeStageCache
    model = vtsi.Model()
    beam = simply_supported_beam(model, L, 4, EI, 1.0, MU)
    cache = BridgeStageCache()
    train = catalogue_train("HSLM-A1", 80.0)
    for weight in (False, True, False):
        tie = MovingLoadConstraint(Track(model, beam.elements), TrainSubdomain(train, -1.0))
        analysis = CoupledAnalysis(model, tie, "Newmark", dt=5e-3, bridge_self_weight=weight, bridge_cache=cache)
        analysis.prepare()
        assert (analysis._sag is not None) == weight
    assert len(cache) == 2


# -- what a results file holds, and who writes it --------------------------------------------------
def _axle_table(path, load_kn):
    path.write_text("position_m,load_kN\n" + "".join(f"{3.0 * i},{load_kn}\n" for i in range(8)))
    return path


def test_resume_refuses_an_edited_axle_table_naming_the_train(tmp_path, monkeypatch):
    """The identity holds what each train is, not only its name: the edited CSV (170 -> 250 kN)
    was merged with the old cases into one envelope without a word."""
    monkeypatch.chdir(tmp_path)
    csv, path = _axle_table(tmp_path / "t.csv", 170), tmp_path / "csv.h5"
    Sweep(small_bridge(), ["t.csv"], "200", FAST).run(path, workers=1, progress=False)
    _axle_table(csv, 250)
    with pytest.raises(SweepError, match=r"csv.h5 holds a different sweep \(train t.csv differs from the one it "
                                         r"ran with in its axles, loads, cars or characteristic length D: an edited axle table"):
        Sweep(small_bridge(), ["t.csv"], "200", FAST).run(path, workers=1, progress=False, resume=True)


def test_a_changed_catalogue_train_is_another_sweep(tmp_path):
    """A catalogue train whose data changed between vtsi versions (here its fingerprint as an
    older vtsi stored it) is named."""
    path = tmp_path / "r.h5"
    Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200", FAST).run(path, workers=1, progress=False)
    with h5py.File(path, "a") as f:
        identity = json.loads(f.attrs["identity"])
        identity["train_fingerprints"]["HSLM-A2"] = "0" * 64
        f.attrs["identity"] = json.dumps(identity, sort_keys=True)
    with pytest.raises(SweepError, match="train HSLM-A2 differs from the one it ran with"):
        Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200", FAST).run(path, workers=1, resume=True)


def test_a_changed_setting_is_named_not_the_bridge_hash(tmp_path):
    """Damping changes the bridge's matrices too; the message names the setting the user changed."""
    path = tmp_path / "r.h5"
    Sweep(small_bridge(), ["HSLM-A1"], "200", FAST).run(path, workers=1, progress=False)
    other = Sweep(small_bridge(), ["HSLM-A1"], "200", PassageSettings(dt=5e-3, damping=0.02))
    with pytest.raises(SweepError, match=r"differs in settings.damping \(0.02 here, 0.0125 in the file\)") as info:
        other.run(path, workers=1, resume=True)
    assert "fingerprint" not in str(info.value)
    finer = Sweep(small_bridge(), ["HSLM-A1"], "200", PassageSettings(dt=2.5e-3, damping=0.0125))
    with pytest.raises(SweepError, match=r"differs in settings.dt \(0.0025 here, 0.005 in the file\) \(to continue "
                                         r"that file, give its dt = 0.005 s\)"):
        finer.run(path, workers=1, resume=True)     # as a file of the old 1 ms default under today's default
    stiffer = beam_bridge([L], 1.1 * EI, 1.0, MU, elements_per_span=4)
    stiffer.description = small_bridge().description        # as a script that reads an edited file would
    outputs = [Output("deflection", "disp")]
    Sweep(small_bridge(), ["HSLM-A1"], "200", FAST, outputs).run(path, workers=1, progress=False, overwrite=True)
    with pytest.raises(SweepError, match=r"differs in the bridge's matrices or track \(bridge_fingerprint\)"):
        Sweep(stiffer, ["HSLM-A1"], "200", FAST, outputs).run(path, workers=1, resume=True)
    with pytest.raises(SweepError, match=r"differs in outputs\[0\].nodes \("):
        Sweep(small_bridge(), ["HSLM-A1"], "200", FAST, [Output("deflection", "disp", nodes="midspan")]).run(
            path, workers=1, resume=True)


def test_a_changed_bridge_is_named_by_its_description_not_by_what_derives_from_it(tmp_path):
    """A bridge file's 21 m span on a file of its 20 m one (f1 = 5 Hz kept, I following the span)
    was named by an output's cut-off, which differed in round-off only (45.024046050939134 here,
    45.024046050939106 in the file), not by the span. Every key of the description that
    differs is named, in the description's order."""
    path = tmp_path / "r.h5"
    Sweep(small_bridge(), ["HSLM-A1"], "200", FAST).run(path, workers=1, progress=False)
    longer = beam_bridge([21.0], EI, 1.0, MU, elements_per_span=4)
    with pytest.raises(SweepError, match=r"holds a different sweep \(it differs in bridge\.spans_m \(\[21\.0\] here, "
                                         r"\[20\.0\] in the file\)\); use another file"):
        Sweep(longer, ["HSLM-A1"], "200", FAST).run(path, workers=1, resume=True)
    other = beam_bridge([21.0], 2 * EI, 1.0, MU, elements_per_span=6)
    words = (f"it differs in bridge.spans_m ([21.0] here, [20.0] in the file), bridge.E_Pa ({json.dumps(2 * EI)} "
             f"here, {json.dumps(EI)} in the file), bridge.elements_per_span (6 here, 4 in the file));")
    with pytest.raises(SweepError, match=re.escape(words)):
        Sweep(other, ["HSLM-A1"], "200", FAST).run(path, workers=1, resume=True)


@pytest.mark.parametrize("trains, speeds_kmh, words", [
    ("HSLM-A1", "200:300:50", "trains (HSLM-A2 is in the file, not here)"),
    ("HSLM-A1,HSLM-A2,HSLM-A3,HSLM-A4", "200:300:50", "trains (HSLM-A3 and HSLM-A4 are here, not in the file)"),
    ("HSLM-A1,HSLM-A3", "200:300:50", "trains (HSLM-A3 is here, not in the file; HSLM-A2 is in the file, not here)"),
    ("HSLM-A2,HSLM-A1", "200:300:50", 'trains[0] ("HSLM-A2" here, "HSLM-A1" in the file: the same trains in another '
                                      'order)'),
    ("HSLM-A1,HSLM-A2", "200:350:50", "speeds_kmh (350 km/h is here, not in the file)"),
    ("HSLM-A1,HSLM-A2", "200:250:50", "speeds_kmh (300 km/h is in the file, not here)"),
    ("HSLM-A1,HSLM-A2", "100:400:10", "speeds_kmh (28 speeds from 100 to 400 km/h are here, not in the file)"),
])
def test_a_changed_list_of_trains_or_speeds_says_what_differs(tmp_path, trains, speeds_kmh, words):
    """Two lists cut at 57 characters that read the same ('["HSLM-A1", ... here, ["HSLM-A1",
    ... in the file'): a refusal says what is only here and what only in the file, or the
    first item out of place (HSLM-A1, A2 at 200, 250, 300 km/h in the file; 100:400:10 is 31
    speeds, 28 of them not the file's)."""
    path = tmp_path / "r.h5"
    Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200:300:50", FAST).run(path, workers=1, progress=False)
    with pytest.raises(SweepError, match=re.escape(f"holds a different sweep (it differs in {words}); use another")):
        Sweep(small_bridge(), trains, speeds_kmh, FAST).run(path, workers=1, resume=True)


def test_an_added_output_is_named(tmp_path):
    path = tmp_path / "r.h5"
    Sweep(small_bridge(), ["HSLM-A1"], "200", FAST, [Output("deflection", "disp")]).run(path, workers=1, progress=False)
    more = [Output("deflection", "disp"), Output("acceleration", "accel")]
    with pytest.raises(SweepError, match=re.escape("(it differs in outputs (acceleration is here, not in the file))")):
        Sweep(small_bridge(), ["HSLM-A1"], "200", FAST, more).run(path, workers=1, resume=True)


class _Stop(KeyboardInterrupt):
    pass


def _interrupt_after(monkeypatch, batches):
    """ResultsWriter.write raises (as Ctrl-C would) once ``batches`` batches are written."""
    from vtsi.sweep_results import ResultsWriter
    write, count = ResultsWriter.write, [0]

    def stopping(self, results):
        write(self, results)
        count[0] += 1
        if count[0] == batches:
            raise _Stop()
    monkeypatch.setattr(ResultsWriter, "write", stopping)


def test_overwrite_keeps_the_old_file_until_the_new_sweep_is_complete(tmp_path, monkeypatch):
    """An interrupted overwrite left neither the old results nor... it had deleted the old file
    before the new sweep had any case. Now the new sweep goes to <file>.new, replaces the file
    when complete, and an overwrite of the same sweep again continues it."""
    path, staged = tmp_path / "r.h5", tmp_path / "r.h5.new"
    Sweep(small_bridge(), ["HSLM-A1"], "200,300", FAST).run(path, workers=1, progress=False)
    new = PassageSettings(dt=5e-3, damping=0.02)
    _interrupt_after(monkeypatch, 1)
    with pytest.raises(_Stop):
        Sweep(small_bridge(), ["HSLM-A1"], "200,250,300", new).run(path, workers=1, progress=False, overwrite=True,
                                                                   cases_per_task=1)
    monkeypatch.undo()
    old = SweepResults(path)
    assert old.n_done == 2 and old.identity["settings"]["damping"] == 0.0125      # untouched
    assert SweepResults(staged).n_done == 1 and SweepResults(staged).identity["settings"]["damping"] == 0.02
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200,250,300", new)
    calls = []
    run = sweep.runner.run
    sweep.runner.run = lambda *a: calls.append(a) or run(*a)
    res = sweep.run(path, workers=1, progress=False, overwrite=True)
    assert len(calls) == 2 and res.n_done == 3                                  # continued, not begun anew
    assert SweepResults(path).identity["settings"]["damping"] == 0.02
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]


HOLD_LOCK = "import sys, time; from vtsi.sweep_results import ResultsFileLock; ResultsFileLock(sys.argv[1]); print('held', flush=True); " \
            "time.sleep(120)"


def test_a_second_writer_is_refused_and_a_dead_writers_lock_taken_over(tmp_path):
    """Two runs on one file deleted each other's .partial and wrote a file of empty train names
    (or '882 of 570 cases'). The second run is refused naming the first one's pid; the lock of a
    killed run (SIGKILL: its lock file stays) is taken over."""
    from vtsi.sweep_results import ResultsFileInUse
    path = tmp_path / "r.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200", FAST)
    holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(path)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        for kwargs in ({}, {"resume": True}, {"overwrite": True}):
            with pytest.raises(ResultsFileInUse, match=rf"r.h5 is being written by another sweep \(pid {holder.pid}\)"):
                sweep.run(path, workers=1, progress=False, **kwargs)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5.lock"]      # nothing of the refused run
    finally:
        holder.kill()
        holder.wait()
    assert (tmp_path / "r.h5.lock").read_text().split()[0] == str(holder.pid)  # a dead run's lock file
    assert sweep.run(path, workers=1, progress=False).n_done == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]


@pytest.mark.parametrize("kwargs, words", [
    ({"cases_per_task": -1}, "cases_per_task must be an integer >= 1 (or None), got -1"),
    ({"cases_per_task": 0}, "cases_per_task must be an integer >= 1 (or None), got 0"),
    ({"cases_per_task": 1.5}, "cases_per_task must be an integer >= 1 (or None), got 1.5"),
    ({"cases_per_task": True}, "cases_per_task must be an integer >= 1 (or None), got True"),
    ({"workers": True}, "workers must be an integer >= 1 (or None), got True"),
    ({"workers": 0}, "workers must be an integer >= 1 (or None), got 0"),
])
def test_bad_run_arguments_are_refused(tmp_path, kwargs, words):
    """cases_per_task=-1 ran nothing and returned; 1.5 gave a bare TypeError; workers=True ran."""
    with pytest.raises(SweepError, match=re.escape(words)):
        Sweep(small_bridge(), ["HSLM-A1"], "200,300", FAST).run(tmp_path / "r.h5", progress=False, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_seeds_and_train_spellings_are_checked():
    """seeds=[0.5, 0.7] became [0]; 'HSLM-A1, hslm-a1' were two trains; a seed of 2⁶³ or more
    gave an OverflowError traceback when the results file was made; seeds on a smooth rail were
    dropped without a word, and a seed given twice was run once."""
    rough = PassageSettings(dt=5e-3, damping=0.0125, cars="full", irregularity="german-low")
    for seeds, bad in (([0.5, 0.7], "0.5"), ([True], "True"), ([-1], "-1"), ([2 ** 63], str(2 ** 63))):
        words = f"sweep: a seed is an integer in [0, 2^63), got {bad}"      # the whole message, as docs/bad_inputs.md
        with pytest.raises(SweepError, match=f"^{re.escape(words)}$"):
            Sweep(small_bridge(), ["ICE3"], "200", rough, seeds=seeds)
    words = "sweep: seeds must be a list of integers >= 0, got '01'"
    with pytest.raises(SweepError, match=f"^{re.escape(words)}$"):
        Sweep(small_bridge(), ["ICE3"], "200", rough, seeds="01")
    with pytest.raises(SweepError, match=r"^sweep: seed 0 is given twice$"):
        Sweep(small_bridge(), ["ICE3"], "200", rough, seeds=[0, 0])
    with pytest.raises(SweepError, match=r"^sweep: an irregular rail needs 1 to 10000 seeds, got 10001$"):
        Sweep(small_bridge(), ["ICE3"], "200", rough, seeds=range(10001))
    with pytest.raises(SweepError, match=r"^sweep: seeds \[0, 1\] select samples of an irregular rail, and the rail "
                                         r"is smooth"):
        Sweep(small_bridge(), ["ICE3"], "200", PassageSettings(dt=5e-3, cars="full"), seeds=[0, 1])
    assert Sweep(small_bridge(), ["ICE3"], "200", rough).seeds == [0]
    assert Sweep(small_bridge(), ["ICE3"], "200", rough, seeds=[2 ** 63 - 1, 3]).seeds == [3, 2 ** 63 - 1]
    for trains in ("HSLM-A1, hslm-a1", ["A1", "HSLM-A1"]):
        with pytest.raises(SweepError, match="train HSLM-A1 is listed twice"):
            Sweep(small_bridge(), trains, "200", FAST)
    assert Sweep(small_bridge(), "hslm-a1,a2", "200", FAST).trains == ["HSLM-A1", "HSLM-A2"]


def test_one_axle_table_under_two_paths_is_listed_twice(tmp_path, monkeypatch):
    """'emu.csv,./emu.csv' ran the same table twice, as two trains; the paths are resolved
    (os.path.realpath) before the test, the names stay as given and the refusal quotes them."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "emu.csv").write_text("position_m,load_kN\n0,150\n2.5,150\n17.5,150\n20,150\n")
    (tmp_path / "other.csv").write_text("position_m,load_kN\n0,150\n2.5,150\n")
    (tmp_path / "sub").mkdir()
    words = (f"sweep: train ./emu.csv is listed twice (emu.csv and ./emu.csv are one file, "
             f"{os.path.realpath(tmp_path / 'emu.csv')}): 'emu.csv,./emu.csv'")
    with pytest.raises(SweepError, match=f"^{re.escape(words)}$"):
        Sweep(small_bridge(), "emu.csv,./emu.csv", "200", FAST)
    with pytest.raises(SweepError, match=r"^sweep: train \S+emu\.csv is listed twice \(emu\.csv and "):
        Sweep(small_bridge(), ["emu.csv", str(tmp_path / "sub" / ".." / "emu.csv")], "200", FAST)
    assert Sweep(small_bridge(), "emu.csv,other.csv", "200", FAST).trains == ["emu.csv", "other.csv"]


@pytest.mark.parametrize("damage, words", [
    (lambda f: f.attrs.__setitem__("identity", "{not json"), "its identity attribute is not JSON"),
    (lambda f: f.attrs.__delitem__("identity"), "it has no identity attribute"),
    (lambda f: f.attrs.__setitem__("format_version", "five"), "its format_version 'five' is not a whole number"),
    (lambda f: f.attrs.__setitem__("identity", "[1, 2]"), "its identity lacks 'outputs'"),
], ids=["identity-not-json", "no-identity", "version-not-a-number", "identity-not-a-dict"])
def test_a_damaged_header_is_one_error_naming_the_file(tmp_path, damage, words):
    path = tmp_path / "r.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200", FAST)
    sweep.run(path, workers=1, progress=False)
    with h5py.File(path, "a") as f:
        damage(f)
    with pytest.raises(SweepError, match=re.escape(f"results file {path}: {words}")):
        SweepResults(path)
    with pytest.raises(SweepError, match=re.escape(f"results file {path}: {words}")):
        sweep.run(path, workers=1, resume=True)


def test_a_bridge_with_e_in_kpa_is_refused_by_en_1991_2_figure_6_10():
    """E in kPa (the rest SI) puts a 5 Hz 20 m span at 0.158 Hz, above the absolute 0.1 Hz floor:
    it ran and FAILed with an 11.6 m deflection. Below a fifth of EN 1991-2 Figure 6.10's lower
    limit (4 Hz at 20 m) a bridge is refused as one in other units."""
    from vtsi.codes.en1991_2 import frequency_limits
    assert frequency_limits(20.0) == pytest.approx((4.0, 94.76 * 20.0 ** -0.748))
    assert frequency_limits(50.0)[0] == pytest.approx(23.58 * 50.0 ** -0.592)
    with pytest.raises(SweepError, match=r"first vertical frequency 0\.158 Hz, below 0\.2 x EN 1991-2 Figure 6\.10's "
                                         r"lower limit for its 20 m span \(4 Hz\).*E in kPa"):
        Sweep(beam_bridge([L], EI / 1e3, 1.0, MU, elements_per_span=4), ["HSLM-A1"], "300", FAST)


def test_a_missing_history_is_named_as_what_it_is(tmp_path):
    """Asking a file for a history said 'no histories of case …' for a speed the sweep never ran
    and for a file with no histories at all; each is now said as it is."""
    path = tmp_path / "h.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200,300", FAST)
    res = sweep.run(path, workers=1, progress=False)
    with pytest.raises(SweepError, match=r"250 km/h is not one of the sweep's 2 speeds \(200 to 300 km/h: 200, 300\)"):
        res.history("HSLM-A1", 250.0)
    with pytest.raises(SweepError, match=r"h\.h5 holds no histories \(an output with history=True keeps them for every "
                                         r"case; Sweep\.record_histories records them for chosen cases"):
        res.history("HSLM-A1", 200.0)
    sweep.record_histories(path, [("HSLM-A1", 200.0, -1)])
    with pytest.raises(SweepError, match=r"no histories of case HSLM-A1/300kmh/smooth; recorded: HSLM-A1/200kmh/smooth"):
        SweepResults(path).history("HSLM-A1", 300.0)


def test_record_histories_takes_only_the_sweep_s_cases(tmp_path):
    """record_histories stored 'ice3' as its own group beside 'ICE3' (history('ICE3', 250) missed
    it), and stored a train, a speed (later refused by the reader) and a seed the sweep does not
    have. Names are read as the sweep reads them; a case not in the sweep is refused, naming it
    and what is valid, before anything runs or is written."""
    path = tmp_path / "h.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1", "ICE3"], "200,250", FAST)
    sweep.run(path, workers=1, progress=False)
    res = sweep.record_histories(path, [("ice3", 250, -1)])
    assert res.histories() == ["ICE3/250kmh/smooth"]
    assert res.history("ICE3", 250)["attrs"]["train"] == "ICE3"
    before = path.read_bytes()
    for case, words in [
        (("HSLM-A5", 250, -1), "case ('HSLM-A5', 250, -1): train 'HSLM-A5' is not in the sweep; its trains: HSLM-A1, ICE3"),
        (("ICE3", 275, -1), "case ('ICE3', 275, -1): speed 275 km/h is not one of the sweep's (200, 250 km/h)"),
        (("ICE3", 250, 3), "case ('ICE3', 250, 3): seed 3 is not one of the sweep's: -1 (a smooth rail)"),
        (("ICE3", 250), "a case is (train, speed_kmh, seed), got ('ICE3', 250)"),
    ]:
        with pytest.raises(SweepError, match=re.escape(f"record_histories: {words}")):
            sweep.record_histories(path, [("HSLM-A1", 200, -1), case])
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["h.h5"]


def test_history_finds_the_histories_the_sweep_s_outputs_keep(tmp_path):
    """history() and histories() saw only Sweep.record_histories' /histories: a file whose
    outputs kept histories (Output(..., history=True), /cases/histories) 'held no histories'."""
    path = tmp_path / "h.h5"
    outputs = [Output("deflection", "disp", "midspan", history=True), Output("acceleration", "accel")]
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200,300", FAST, outputs=outputs)
    res = sweep.run(path, workers=1, progress=False)
    assert res.histories() == ["HSLM-A1/200kmh/smooth", "HSLM-A1/300kmh/smooth"]
    h = res.history("HSLM-A1", 300)
    t, d, nodes = h["deflection"]
    case = res.case("HSLM-A1", 300)
    np.testing.assert_array_equal(d, case["deflection"]["values"])
    np.testing.assert_array_equal(nodes, case["deflection"]["columns"])
    assert "acceleration" not in h and h["attrs"]["n_steps"] == len(t)
    assert h["attrs"]["outputs"]["deflection"] == {"response": "disp", "units": "m", "kind": "node",
                                                   "cutoff_hz": None, "source": "sweep"}
    res = sweep.record_histories(path, [("HSLM-A1", 300, -1)])     # both kinds of one case, together
    assert res.histories() == ["HSLM-A1/200kmh/smooth", "HSLM-A1/300kmh/smooth"]
    h = res.history("HSLM-A1", 300)
    assert {"deflection", "deck_displacement", "deck_acceleration"} <= set(h)
    assert h["attrs"]["outputs"]["deck_acceleration"]["source"] == "record_histories"


def test_a_case_is_named_as_a_sweep_names_it(tmp_path):
    """case('hslm-a1', 300) and case('A1', 300) said 'no case' (a sweep takes those names),
    case('HSLM-A1', 275) did not list the speeds, case('HSLM-A1', None) was a TypeError
    traceback and static('nonsense') returned None."""
    res = Sweep(small_bridge(), ["HSLM-A1", "ICE3"], "200,300", FAST).run(tmp_path / "r.h5", workers=1,
                                                                          progress=False)
    reference = res.case("HSLM-A1", 300)["deflection"]["envelope"]
    for name in ("hslm-a1", "A1", " HSLM-A1 "):
        np.testing.assert_array_equal(res.case(name, 300)["deflection"]["envelope"], reference)
    assert res.case("ice3", 200)["attrs"]["train"] == "ICE3"
    np.testing.assert_array_equal(res.train_data("ice3")["axle_offsets_m"], res.train_data("ICE3")["axle_offsets_m"])
    for call, words in [
        (lambda: res.case("HSLM-A2", 300), "train 'HSLM-A2' is not one of the sweep's: HSLM-A1, ICE3 (names "
                                           "ignore case; 'A1' is 'HSLM-A1')"),
        (lambda: res.case("HSLM-A1", 275), "275 km/h is not one of the sweep's 2 speeds (200 to 300 km/h: 200, 300)"),
        (lambda: res.case("HSLM-A1", None), "speed [km/h] must be a number, got None"),
        (lambda: res.case("HSLM-A1", 300, 0), "seed 0 is not one of the sweep's: -1 (a smooth rail)"),
        (lambda: res.history("A2", 300), "train 'A2' is not one of the sweep's: HSLM-A1, ICE3"),
        (lambda: res.static("nonsense"), "unknown output 'nonsense'; valid: deflection, acceleration, end_rotation"),
    ]:
        with pytest.raises(SweepError, match=re.escape(f"sweep results: {words}")):
            call()
    assert res.static("acceleration") is None and res.static("deflection") is not None


HOLD_OPEN = "import h5py, sys, time; f = h5py.File(sys.argv[1], 'r+'); print('open', flush=True); time.sleep(120)"


def test_a_results_file_open_for_writing_elsewhere_is_said_to_be_in_use(tmp_path):
    """A results file another process holds open for writing was 'not a readable HDF5 file
    ([Errno 11] … unable to lock file …)'."""
    from vtsi.sweep_results import ResultsFileInUse
    path = tmp_path / "r.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "200", FAST)
    sweep.run(path, workers=1, progress=False)
    holder = subprocess.Popen([sys.executable, "-c", HOLD_OPEN, str(path)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "open"
        words = f"results file {path} is in use by another process, which holds it open for writing"
        with pytest.raises(ResultsFileInUse, match=re.escape(words)):
            SweepResults(path)
        with pytest.raises(ResultsFileInUse, match=re.escape(words)):
            sweep.run(path, workers=1, progress=False, resume=True)
    finally:
        holder.kill()
        holder.wait()
    assert SweepResults(path).n_done == 1


def test_units_and_cut_offs_of_histories_and_where_are_in_the_file_and_returned(tmp_path):
    """Histories had no units attribute and case()/history() returned none; record_histories'
    outputs were nowhere in the file, nor whether its acceleration was cut off at the EN
    frequency; to_xarray's <q>_where did not say whether it held a node, a wheel or a car."""
    from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
    path = tmp_path / "u.h5"
    outputs = [Output("deflection", "disp", "midspan", history=True),
               Output("acceleration", "accel", cutoff="en", history=True)]
    sweep = Sweep(small_bridge(), ["HSLM-A1"], "300", FAST, outputs=outputs)
    sweep.run(path, workers=1, progress=False)
    res = sweep.record_histories(path, [("HSLM-A1", 300, -1)])
    cutoff = acceleration_cutoff_hz(res.frequencies_hz)
    with h5py.File(path, "r") as f:
        case = f["cases/histories/HSLM-A1/300kmh/smooth"]
        assert case["deflection_values"].attrs["units"] == "m" and case["deflection_time"].attrs["units"] == "s"
        assert "cutoff_hz" not in case["deflection_values"].attrs
        assert case["acceleration_values"].attrs["cutoff_hz"] == pytest.approx(cutoff)
        assert f["outputs/acceleration"].attrs["cutoff_hz"] == pytest.approx(cutoff)
        kept = f["histories/HSLM-A1/300kmh/smooth"]
        assert kept["deck_acceleration_values"].attrs["units"] == "m/s^2"
        assert kept["deck_acceleration_values"].attrs["cutoff_hz"] == pytest.approx(cutoff)
        assert kept["deck_displacement_values"].attrs["units"] == "m"
        assert "cutoff_hz" not in kept["deck_displacement_values"].attrs
        assert f["envelopes/deflection_min_where"].attrs["kind"] == "node"
    c = res.case("HSLM-A1", 300)
    assert (c["deflection"]["units"], c["acceleration"]["units"]) == ("m", "m/s^2")
    assert c["acceleration"]["cutoff_hz"] == pytest.approx(cutoff) and "cutoff_hz" not in c["deflection"]
    described = res.history("HSLM-A1", 300)["attrs"]["outputs"]
    assert described["deck_acceleration"]["units"] == "m/s^2"
    assert described["deck_acceleration"]["cutoff_hz"] == pytest.approx(cutoff)
    assert described["deck_displacement"]["cutoff_hz"] is None
    assert described["acceleration"]["cutoff_hz"] == pytest.approx(cutoff)
    ds = res.to_xarray()
    assert ds["deflection_min_where"].attrs["kind"] == "node" and "node tag" in ds["deflection_min_where"].attrs["holds"]
    assert ds["acceleration_absmax"].attrs["cutoff_hz"] == pytest.approx(cutoff)
    cars = Sweep(small_bridge(), ["ICE3"], "300", PassageSettings(dt=5e-3, damping=0.0125, cars="full"))
    ds = cars.run(None, workers=1, progress=False).to_xarray()
    assert ds["contact_force_min_where"].attrs["kind"] == "contact wheel"
    assert ds["car_body_acceleration_absmax_where"].attrs["kind"] == "car"


def test_an_interrupted_sweep_says_so_in_critical_and_to_xarray(tmp_path, monkeypatch):
    """A file of an interrupted sweep gave a governing case without a word, and its xarray
    view had no completeness attribute."""
    path = tmp_path / "p.h5"
    sweep = Sweep(small_bridge(), ["HSLM-A1", "HSLM-A2"], "200,300", FAST)
    _interrupt_after(monkeypatch, 1)
    with pytest.raises(_Stop):
        sweep.run(path, workers=1, progress=False, cases_per_task=1)
    res = SweepResults(path)
    worst = res.critical("deflection_min")
    assert (worst["cases_done"], worst["cases_total"]) == (1, 4)
    ds = res.to_xarray()
    assert (ds.attrs["cases_done"], ds.attrs["cases_total"]) == (1, 4)
    with pytest.raises(SweepError, match=re.escape("case HSLM-A2/300kmh/smooth is not in the file yet (1 of 4 cases: "
                                                   "an interrupted sweep; resume=True (--resume) runs the rest)")):
        res.case("HSLM-A2", 300)


def test_tasks_of_cars_hold_fewer_cases():
    """A coupled step of cars costs several steps of moving forces (CAR_STEP_COST, measured in
    its comment): a task of an ICE3 sweep of cars held 50 cases (~30 s of work, all lost to a
    Ctrl-C) where one of moving forces holds the same steps' worth."""
    from vtsi.sweep import CAR_STEP_COST, TASK_STEPS
    forces = Sweep(small_bridge(), ["ICE3"], "200:300:10", PassageSettings(dt=5e-3))
    cars = Sweep(small_bridge(), ["ICE3"], "200:300:10", PassageSettings(dt=5e-3, cars="full"))
    ratio = cars.case_cost(cars.cases) / forces.case_cost(forces.cases)     # cars run a little longer (their approach)
    assert CAR_STEP_COST <= ratio <= 1.25 * CAR_STEP_COST
    cost = cars.case_cost(cars.cases)
    assert Sweep.task_size(10_000, cost, 1) == math.ceil(TASK_STEPS / cost)


def test_pool_workers_run_blas_on_one_thread():
    """A pool worker's BLAS runs one thread (sweep._worker_start): two workers of a two-core
    machine, each on two BLAS threads, took 3.9 s for 110 passages of a 3 × 30 m FE deck where one
    thread each takes 1.8 s. Under a fork server (another thread runs here) the worker imports
    what it runs: threadpoolctl's own function, not one of this module."""
    context = sweep_module._pool_context()
    with ProcessPoolExecutor(max_workers=1, mp_context=context, initializer=sweep_module._worker_start,
                             initargs=(context.RawValue("b", 0),)) as pool:
        pools = pool.submit(threadpool_info).result(timeout=60)
    threads = [p["num_threads"] for p in pools if p["user_api"] == "blas"]
    assert threads and set(threads) == {1}
