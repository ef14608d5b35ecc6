"""The per-call cost of an OpenSees-style stepping loop (docs/commands.md, "analyze in a loop";
benchmarks S9): what a run needs is kept from call to call, so that ``analyze(1, dt)`` costs one
compiled step and a constant, with the numbers of one ``analyze(n, dt)`` to the bit.

- Coupled analyses: n runs of one step give one run of n steps' records, recorders and states
  exactly (bilateral and LCP contact, Hermite and B-spline rows, kink crossings taken at their
  own time, chunk boundaries, lift-offs, an irregular rail; runs of other lengths:
  tests/test_coupled_splits.py); a
  pattern added between steps, a dof at rest moved between them, are taken into account as by
  the runs of a fresh count.
- A moving load the OpenSees way (a new pattern at every step): the kept plan gives a fresh
  analysis's numbers to the bit, factors nothing, and evaluates only the steps asked for.
- Text recorders: a per-step loop writes the bytes of one run, also on a full disk; a chunk of a
  few numbers is formatted by Python, whose text the compiled kernel gives for every double.
- A cars sweep factors each train once for all its speeds, with the numbers of a fresh
  factorisation per passage.
- The benchmark scene S9 runs, its loops agreeing with one run and with OpenSeesPy.
"""
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import vtsi
import vtsi.opensees as vops
from vtsi import subdomain
from vtsi.analysis import BLOCK_STEPS, domain_state
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis, TrainStages
from vtsi.integrators import HHT
from vtsi.models import Irregularity, Train, four_dof_car
from vtsi.models.bridges import simply_supported_beam
from vtsi.passage import Output, PassageSettings
from vtsi.recorders import ContactRecorder, NodeRecorder, TrainRecorder, number_text
from vtsi.recorders.sinks import TextSink
from vtsi.subdomain import BridgeStageCache
from vtsi.sweep import Sweep, beam_bridge
from vtsi.timeseries import Constant
from vtsi.track import Track
from vtsi.train import TrainSubdomain

DT = 1e-3
SPAN = 20.0                   # [m] 10 elements, nodes 1..11 (x = 0..20 m)
BUMP = (6.0, 1.0, 0.02)       # [m] start, length, depth of a cosine dip in the rail: the LCP wheels fly over it


def dip(start, length, depth):
    """A sampled rail profile with a cosine dip of ``depth`` [m] over [start, start + length] [m]."""
    x = np.linspace(-40.0, 80.0, 4801)
    inside = (x >= start) & (x <= start + length)
    r = np.where(inside, -0.5 * depth * (1.0 - np.cos(2.0 * np.pi * (x - start) / length)), 0.0)
    return Irregularity(x, r)


def coupled(contact, interpolation, integrator, exact_events=False, chunk_steps=2000, tmp_path=None, rail=True):
    """A 20 m span (kinks of the rail where it meets the ground), a two-car train of four-dof cars
    entering from the ground, a dip in the rail (``rail``; else a smooth one); recorders of the
    bridge, the train and the contact (a text file too when ``tmp_path``)."""
    model = vtsi.Model()
    bridge = simply_supported_beam(model, SPAN, 10, 3.0e10, 0.6, 1.2e4)
    car = four_dof_car(3.0e4, 1.5e6, 1.5e3, 1.0e6, 2.0e4, 8.0)
    train = Train([car, car], [0.0, 12.0], 40.0)
    sub = TrainSubdomain(train, -1.0)
    con = MovingLoadConstraint(Track(model, bridge.elements), sub, dip(*BUMP) if rail else None, interpolation)
    recorders = [NodeRecorder(bridge.midspan_nodes, [2], "disp"), NodeRecorder(bridge.midspan_nodes, [2], "accel"),
                 TrainRecorder(sub, ["car0.body_y", "car1.wheel2_y"], "accel"),
                 ContactRecorder(con, None, "force"), ContactRecorder(con, None, "gap")]
    if tmp_path is not None:
        recorders.append(NodeRecorder(bridge.midspan_nodes[:1], [2], "vel",
                                      sink=TextSink(tmp_path / "vel.txt", time=True, precision=17)))
    analysis = CoupledAnalysis(model, con, integrator, DT, contact=contact, recorders=recorders,
                               exact_events=exact_events, chunk_steps=chunk_steps)
    analysis.static()
    return analysis, recorders


def loop_and_run(tmp_path, n, **kwargs):
    """The outcomes (and text files) of ``n`` runs of one step and of one run of ``n`` steps."""
    runs = {}
    for name, sizes in (("loop", [1] * n), ("run", [n])):
        (tmp_path / name).mkdir()
        analysis, recorders = coupled(tmp_path=tmp_path / name, **kwargs)
        for size in sizes:
            analysis.run(size)
        runs[name] = outcome(analysis, recorders)
        runs[name]["file"] = (tmp_path / name / "vel.txt").read_bytes()
    return runs["loop"], runs["run"]


def outcome(analysis, recorders):
    """Everything a run leaves: the records, the recorders' values and times, the states."""
    state = domain_state(analysis.model)
    out = {"time": analysis.time, "force": analysis.contact_force, "end": analysis.contact_force_end,
           "gap": analysis.gap, "u": state.u, "v": state.v, "a": state.a, "t": np.array([state.time]),
           "train": np.concatenate([analysis.train.u, analysis.train.v, analysis.train.a])}
    for k, rec in enumerate(recorders):
        if not isinstance(rec.sink, TextSink):
            out[f"rec{k}"], out[f"rec{k}_time"] = rec.values, rec.time
    return out


CASES = [("bilateral", "hermite", "Newmark", False, True), ("bilateral", "bspline", "Bathe", False, True),
         ("bilateral", "hermite", HHT(0.9), True, True), ("lcp", "hermite", HHT(0.9), True, True),
         ("lcp", "bspline", HHT(0.9), False, True)]


@pytest.mark.parametrize("contact, interpolation, integrator, exact_events, rail", CASES,
                         ids=[f"{c}-{i}-{g if isinstance(g, str) else 'HHT'}{'-events' if e else ''}"
                              f"{'-dip' if r else ''}" for c, i, g, e, r in CASES])
def test_coupled_steps_one_by_one_equal_one_run(tmp_path, contact, interpolation, integrator, exact_events, rail):
    """850 runs of one step and one run of 850 (chunks of 300 steps in both: the count carries
    over their boundaries), from the dead load: the same records, recorder values and times,
    text file and states, to the bit. The train crosses the span's ends (kinks; with
    ``exact_events`` each crossing is a step of its own) and, with LCP contact over the dip,
    its wheels fly."""
    loop, run = loop_and_run(tmp_path, 850, contact=contact, interpolation=interpolation, integrator=integrator,
                             exact_events=exact_events, chunk_steps=300, rail=rail)
    assert loop.keys() == run.keys()
    for key in run:
        assert np.array_equal(loop[key], run[key]), key
    assert run["time"].shape == (850,)
    if contact == "lcp" and rail:
        assert np.any(run["gap"] > 0.0)        # the dip made wheels fly


def test_coupled_runs_after_a_change_count_afresh():
    """A pattern added after 200 steps: 200 runs of one step, the pattern, 300 more, equal a run
    of 200, the pattern, a run of 300 (each new run counts its steps from its start; the
    step loop continues the count of the run it follows) and differ from the loop without it."""
    results = []
    for sizes in ([1] * 200 + ["load"] + [1] * 300, [200, "load", 300], [1] * 500):
        analysis, recorders = coupled("bilateral", "hermite", "Newmark")
        for n in sizes:
            if n == "load":
                analysis.model.add_time_series(Constant(1.0, tag=90))
                analysis.model.pattern(90, 90)
                analysis.model.load(90, 4, 0.0, -5e4, 0.0)
            else:
                analysis.run(n)
        results.append(outcome(analysis, recorders))
    for key in results[1]:
        assert np.array_equal(results[0][key], results[1][key]), key
    assert not np.array_equal(results[0]["u"], results[2]["u"])


def test_a_coupled_dof_at_rest_set_between_steps_is_integrated():
    """The spans' axial dofs are at rest (not integrated); one given a displacement between two
    steps is integrated from then on (the kept plan is given up), as each run of a fresh count
    would."""
    runs = []
    for sizes in ([1] * 20, [20]):
        analysis, recorders = coupled("bilateral", "hermite", "Newmark")
        analysis.run(30)
        asm = analysis.model.build()
        dof = asm.full_dof(11, 1)         # the roller's axial dof
        assert asm.free_of_full[dof] not in analysis.active
        domain_state(analysis.model).u[dof] = 1e-5
        for n in sizes:
            analysis.run(n)
        assert asm.free_of_full[dof] in analysis.active
        runs.append(domain_state(analysis.model).u.copy())
    assert runs[0][dof] != 1e-5
    assert np.array_equal(runs[0], runs[1])


# -- a moving load the OpenSees way: a new pattern at every step --------------------------------
N_EL = 10


def moving_load(ops, steps=120, integrator=("Newmark", 0.5, 0.25), series=(1,), fresh=False):
    """A 20 m beam of 10 elements; at every step the load pattern is removed and a new one, of
    the series ``series[k % len(series)]`` (1 Constant, 2 Path), loads the next node, then
    ``analyze(1, dt)`` (``fresh``: a new analysis at every step, nothing kept). Returns the
    history of time, midspan displacement, a velocity and an acceleration."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(N_EL + 1):
        ops.node(i + 1, 2.0 * i, 0.0)
    ops.fix(1, 1, 1, 0)
    ops.fix(N_EL + 1, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    for e in range(N_EL):
        ops.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0, 3.0e10, 0.5, 1, "-mass", 2.0e4, "-cMass")
    ops.rayleigh(0.1, 0.0, 0.0, 1e-4)
    ops.timeSeries("Constant", 1)
    ops.timeSeries("Path", 2, "-dt", DT, "-values", *(1.0 + 0.5 * np.sin(0.3 * np.arange(steps + 10))).tolist())
    ops.pattern("Plain", 1000, 1)
    ops.load(2, 0.0, -1e5, 0.0)
    out = []
    for k in range(steps):
        if fresh or k == 0:
            ops.wipeAnalysis()
            ops.integrator(*integrator)
            ops.analysis("Transient")
        ops.remove("loadPattern", 1000 + k)
        ops.pattern("Plain", 1001 + k, series[k % len(series)])
        ops.load(2 + (k * (N_EL - 1)) // steps, 0.0, -1e5, 0.0)
        ops.analyze(1, DT)
        out.append([ops.getTime(), ops.nodeDisp(6, 2), ops.nodeVel(4, 2), ops.nodeAccel(8, 2)])
    return np.array(out)


@pytest.mark.parametrize("integrator", [("Newmark", 0.5, 0.25), ("HHT", 0.9), ("Bathe",)], ids=lambda i: i[0])
@pytest.mark.parametrize("series", [(1,), (1, 2)], ids=["same series", "series alternating"])
def test_a_new_pattern_at_every_step_gives_a_fresh_analysis_numbers(integrator, series):
    """The kept plan takes each new pattern's loads (and, when its series changes, the load
    factors of the steps asked for): the history of a fresh analysis at every step, to the bit."""
    kept = moving_load(vops.Session(), integrator=integrator, series=series)
    fresh = moving_load(vops.Session(), integrator=integrator, series=series, fresh=True)
    assert np.array_equal(kept, fresh)
    assert np.abs(kept[:, 1]).max() > 0.0


def test_a_new_pattern_at_every_step_factors_nothing_and_keeps_the_plan(monkeypatch):
    """Over 120 pattern swaps: no effective matrix is factored again, the plan (its stages,
    bank and recorder feed) stays; the block of load factors stays while the series is the
    same; after a swap to another series the next block is of the one step asked for, and
    BLOCK_STEPS steps when the run continues with it."""
    session = vops.Session()
    moving_load(session, steps=2)
    plan = session._transient._kept_plan
    stages, bank, feed, block = plan.bridge, plan.bank, plan.feed, plan.block
    factors, factor = [], subdomain.ldl_band_of_storage
    monkeypatch.setattr(subdomain, "ldl_band_of_storage", lambda *a: factors.append(1) or factor(*a))
    for k in range(2, 122):
        session.remove("loadPattern", 1000 + k)
        session.pattern("Plain", 1001 + k, 1)
        session.load(2 + k % 9, 0.0, -1e5, 0.0)
        session.analyze(1, DT)
    plan = session._transient._kept_plan
    assert (plan.bridge, plan.bank, plan.feed, plan.block[0]) == (stages, bank, feed, block[0])
    assert factors == []
    session.remove("loadPattern", 1122)
    session.pattern("Plain", 1123, 2)           # another series: a block of the step asked for
    session.load(5, 0.0, -1e5, 0.0)
    session.analyze(1, DT)
    assert session._transient._kept_plan.block[0].shape == (2,)
    session.analyze(1, DT)                      # the run continues: a block ahead
    assert session._transient._kept_plan.block[0].shape == (BLOCK_STEPS + 1,)



# -- text recorders in a per-step loop ----------------------------------------------------------
def recorded_beam(ops, folder, sizes):
    """The moving-load beam under a Path pattern, three text recorders (displacements with the
    time, velocities at 12 digits, accelerations at 17), stepped by ``analyze`` calls of
    ``sizes`` steps; the files' bytes."""
    moving_load(ops, steps=1)
    ops.timeSeries("Path", 3, "-dt", DT, "-values", *np.cos(0.05 * np.arange(400)).tolist())
    ops.pattern("Plain", 7, 3)
    ops.load(5, 0.0, -2e5, 1e3)
    files = [folder / name for name in ("disp.out", "vel.out", "accel.out")]
    ops.recorder("Node", "-file", str(files[0]), "-time", "-node", 3, 6, "-dof", 2, "disp")
    ops.recorder("Node", "-file", str(files[1]), "-precision", 12, "-node", 6, "-dof", 1, 2, 3, "vel")
    ops.recorder("Node", "-file", str(files[2]), "-time", "-precision", 17, "-node", 8, "-dof", 2, "accel")
    for n in sizes:
        ops.analyze(n, DT)
    ops.wipe()
    return [f.read_bytes() for f in files]


def test_text_recorders_of_a_per_step_loop_write_the_bytes_of_one_run(tmp_path):
    """300 ``analyze(1, dt)`` and one ``analyze(300, dt)``: the same three files, byte for byte
    (a chunk of a few numbers is formatted by Python, a large one by the compiled kernel)."""
    (tmp_path / "loop").mkdir()
    (tmp_path / "run").mkdir()
    loop = recorded_beam(vops.Session(), tmp_path / "loop", [1] * 300)
    run = recorded_beam(vops.Session(), tmp_path / "run", [300])
    assert loop == run
    assert [text.count(b"\n") for text in run] == [300] * 3


DOUBLES = [0.0, -0.0, 1.0, -2.5, 0.1, 1.0 / 3.0, 2.0 ** -24, 5e-324, 2.2250738585072014e-308, 1e300, -1e-300,
           123456789.0, 2.0 ** 53 + 2.0, 9.9999995e-5, 0.00012345678, 0.5e-4, np.nan, np.inf, -np.inf]


@pytest.mark.parametrize("precision", [1, 6, 12, 17])
def test_a_chunk_of_a_few_numbers_is_written_as_the_compiled_kernel_writes_it(monkeypatch, precision):
    """The shapes a per-step loop hands a text sink (a row, or a few, of up to PYTHON_NUMBERS
    numbers with the time), of doubles of every kind (ties, subnormals, -0, NaN, infinities):
    Python's text equals the compiled kernel's, to which every chunk went before."""
    rng = np.random.default_rng(7)
    pool = np.concatenate([DOUBLES, rng.standard_normal(40) * 10.0 ** rng.integers(-12, 12, 40)])
    cases = []
    for n, m, timed in [(1, 1, True), (1, 3, True), (2, 3, False), (3, 0, True), (1, 7, True), (1, 8, False)]:
        values = rng.choice(pool, (n, m))
        times = rng.choice(pool, n) if timed else None
        assert values.size + (n if timed else 0) <= number_text.PYTHON_NUMBERS
        cases.append((values, times))
    python = [number_text.format_g_bytes(v, precision, t) for v, t in cases]
    monkeypatch.setattr(number_text, "PYTHON_NUMBERS", 0)
    assert python == [number_text.format_g_bytes(v, precision, t) for v, t in cases]


FULL_DISK = """
import os, resource, signal, sys
import numpy as np
import vtsi.opensees as ops
from vtsi.errors import RecorderError
sys.path.insert(0, sys.argv[3])
from test_per_call import moving_load

moving_load(ops, steps=1)
ops.recorder("Node", "-file", sys.argv[1], "-time", "-precision", 17, "-node", 3, 6, "-dof", 2, "disp")
for k in range(int(sys.argv[2])):
    ops.analyze(1, 1e-3)
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (os.path.getsize(sys.argv[1]) + 9, resource.RLIM_INFINITY))
try:
    ops.analyze(1, 1e-3)
except RecorderError as exc:
    print(exc)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE and SIGXFSZ")
def test_a_per_step_loop_on_a_full_disk_keeps_whole_lines(tmp_path):
    """The text sink counts the bytes it appends instead of asking the file: after 200 steps of
    one, a write the disk takes 9 bytes of (a file size limit) leaves the 200 whole lines of one
    run of 200 steps, and names them (docs/recorders.md, A full disk)."""
    script, path = tmp_path / "full.py", tmp_path / "full.out"
    script.write_text(FULL_DISK)
    done = subprocess.run([sys.executable, str(script), str(path), "200", str(pathlib.Path(__file__).parent)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stderr == "", done.stderr[-2000:]
    assert "the file holds the 200 lines up to t = 0.201 s" in done.stdout
    session = vops.Session()
    moving_load(session, steps=1)
    session.recorder("Node", "-file", str(tmp_path / "run.out"), "-time", "-precision", 17, "-node", 3, 6, "-dof", 2,
                     "disp")
    session.analyze(200, DT)
    session.wipe()
    assert path.read_bytes() == (tmp_path / "run.out").read_bytes()


# -- a cars sweep: the train factored once -------------------------------------------------------
def test_a_cars_sweep_factors_each_train_once_with_the_numbers_of_a_fresh_factor(monkeypatch):
    """Three speeds of an ICE3 (cars with dofs) over two 20 m spans: the train's share of the
    preparation (TrainStages: its factors and wheel flexibilities) is built once and kept in the
    runner's cache with the bridge's; each passage gives the envelopes and histories of a
    passage whose cache is new (everything factored again), to the bit."""
    built, init = [], TrainStages.__init__
    monkeypatch.setattr(TrainStages, "__init__", lambda self, *a: built.append(1) or init(self, *a))
    sweep = Sweep(beam_bridge([20.0, 20.0], 2.432e10, 1.0, 15000.0, elements_per_span=10), ["ICE3"], "250",
                  PassageSettings(damping=0.013, cars="full", dt=1e-3),
                  outputs=[Output("deflection", "disp", history=True), Output("wheels", "contact_force", history=True)])
    speeds = (250.0, 275.0, 300.0)
    shared = [sweep.runner.run("ICE3", v) for v in speeds]
    assert len(built) == 1
    fresh = []
    for v in speeds:
        sweep.runner.cache = BridgeStageCache()
        fresh.append(sweep.runner.run("ICE3", v))
    assert len(built) == 1 + len(speeds)
    for a, b in zip(shared, fresh):
        assert a.envelopes.keys() == b.envelopes.keys() == {"deflection", "wheels"}
        for name in a.envelopes:
            assert np.array_equal(a.envelopes[name], b.envelopes[name]), name
            assert np.array_equal(a.histories[name][1], b.histories[name][1]), name


# -- the benchmark of these loops ------------------------------------------------------------------
def test_the_s9_benchmark_runs_and_agrees():
    """``benchmarks/run.py S9 --json --quick``: every case's fields; the coupled loop and the one
    ``analyze(n)`` identical, the pattern swap and the text files as OpenSeesPy's (speed is
    shown by the benchmark, not asserted)."""
    pytest.importorskip("openseespy.opensees")
    root = pathlib.Path(__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, str(root / "benchmarks" / "run.py"), "S9", "--json", "--quick",
                           "--repeats", "1"], capture_output=True, text=True, cwd=root, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout)
    keys = {"case", "n_elements", "steps", "dt", "vtsi_s", "vtsi_us_per_step", "peer", "peer_s", "peer_us_per_step",
            "speedup", "max_rel_diff"}
    assert result["scene"] == "S9" and keys <= set(result)
    cases = {(c["case"], c["n_elements"]): c for c in result["cases"]}
    assert all(keys <= set(c) and c["vtsi_s"] > 0 and c["peer_s"] > 0 for c in cases.values())
    coupled = cases["coupled analyze(1) loop", 20]
    assert coupled["identical"] and coupled["max_rel_diff"] == 0.0
    assert cases["pattern swap (moving force)", 20]["max_rel_diff"] < 1e-9           # OpenSeesPy's history
    for k in (1, 10):
        assert cases[f"{k} text recorders", 20]["max_rel_diff"] <= 1e-5              # 6 digits written
