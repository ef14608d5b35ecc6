"""Scene S9: OpenSees-style stepping loops — what a script that calls ``analyze(1, dt)`` at every
step costs per call, against one ``analyze(n, dt)`` and against OpenSeesPy running the same script.

Model: the S1 beam (span 25 m, E = 2.943e10 Pa, I = 3.81 m⁴, 36 t/m, consistent mass, pinned /
roller), ``n_el`` elasticBeamColumn elements, Newmark average acceleration, dt = 1 ms. Scripts
(the same text runs with ``import vtsi.opensees`` and with ``import openseespy.opensees``):

- **coupled**: a sprung mass (10 t on 1 MN/m and 10 kN·s/m over a 1 t wheel) crossing at
  100 km/h (vtsi's ``track``, ``car``, ``train``, ``movingLoadConstraint``; OpenSees has none):
  800 calls of ``analyze(1, dt)`` against one ``analyze(800, dt)``, both from ``deadLoad``; the two
  final states (every node's displacement, velocity and acceleration, the time) must be
  identical (``max_rel_diff`` 0, ``identical``).
- **pattern swap** (a moving force the OpenSees way): at every step ``remove loadPattern``, a
  new ``pattern Plain`` of a Constant series, ``load`` 100 kN at the node the force has reached,
  ``analyze(1, dt)``; 300 steps, 20 and 200 elements, against OpenSeesPy (``algorithm Linear
  -factorOnce``, system BandSPD). The time of each call is split out (``*_remove_us`` …).
- **recorders**: a Path pattern at midspan, 0, 1 and 10 text recorders (``Node -file -time``,
  one node's uy each) in a loop of 500 ``analyze(1, dt)``, against OpenSeesPy; ``max_rel_diff``
  compares the recorded files (6 digits) with OpenSeesPy's.

Each case is a row: ``vtsi_*`` the vtsi loop, ``peer_*`` what it is compared with (OpenSeesPy's
loop, or vtsi's one ``analyze(n)`` for the coupled case), ``speedup`` = peer / vtsi time. Timed:
the loop only (the model built and one step run before: numba compiled, matrices factored),
best of ``repeats``, vtsi and the peer interleaved. Headline: the pattern swap at 20 elements.
"""
import os
import shutil
import tempfile
import time

import numpy as np

from scenes import Scene, register

L, E, IZ, MU = 25.0, 2.943e10, 3.81, 36000.0
DT = 1e-3
COUPLED_STEPS, SWAP_STEPS, RECORDER_STEPS = 800, 300, 500
QUICK_STEPS = 150
SWAP_SIZES, QUICK_SWAP_SIZES = (20, 200), (20,)
RECORDERS = (0, 1, 10)


def _vtsi():
    import vtsi.opensees
    return vtsi.opensees.Session()


def _openseespy():
    import openseespy.opensees
    return openseespy.opensees


def beam(o, n_el):
    """The S1 beam in session or module ``o``."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(n_el + 1):
        o.node(i + 1, L * i / n_el, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(n_el + 1, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for e in range(n_el):
        o.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0, E, IZ, 1, "-mass", MU, "-cMass")


def transient(o):
    o.constraints("Plain")
    o.numberer("RCM")
    o.system("BandSPD")
    o.test("NormDispIncr", 1e-8, 10)
    o.algorithm("Linear", "-factorOnce")
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")


# -- coupled: analyze(1) in a loop against one analyze(n) ------------------------------------------
def coupled(n_steps, per_step):
    """Seconds of the loop (or of the one call) from the dead load (``deadLoad``: factors ready),
    and the state then: every node's displacement, velocity and acceleration, and the time."""
    o = _vtsi()
    n_el = 20
    beam(o, n_el)
    o.track(1, "-eleRange", 1, n_el)
    o.car(1, "sprungMass", 10000.0, 1e6, "-c", 1e4, "-wheelMass", 1000.0)
    o.train(1, "100km/h", "-cars", 1, 0.0)
    o.movingLoadConstraint(1, 1, 1, 0.0)
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")
    o.deadLoad()
    clock = time.perf_counter()
    if per_step:
        for _ in range(n_steps):
            o.analyze(1, DT)
    else:
        o.analyze(n_steps, DT)
    seconds = time.perf_counter() - clock
    state = np.array([[o.nodeDisp(i + 1), o.nodeVel(i + 1), o.nodeAccel(i + 1)] for i in range(n_el + 1)])
    time_reached = o.getTime()
    o.wipe()
    return seconds, state, time_reached


def coupled_case(n_steps, repeats):
    best, runs = {}, {}
    for _ in range(repeats):
        for per_step in (True, False):
            seconds, state, time_reached = coupled(n_steps, per_step)
            best[per_step] = min(best.get(per_step, np.inf), seconds)
            runs[per_step] = (state, time_reached)
    (loop, t_loop), (bulk, t_bulk) = runs[True], runs[False]
    diff = max(_rel_diff(loop[:, k], bulk[:, k]) for k in range(3))      # displacements, velocities, accelerations
    return _row("coupled analyze(1) loop", 20, n_steps, best[True], "vtsi analyze(n)", best[False], diff,
                identical=bool(np.array_equal(loop, bulk) and t_loop == t_bulk))


# -- a moving force the OpenSees way: a new pattern at every step ----------------------------------
def pattern_swap(o, n_el, n_steps):
    """Seconds of each command over the loop and the midspan history."""
    beam(o, n_el)
    o.timeSeries("Constant", 1)
    transient(o)
    o.pattern("Plain", 1000, 1)
    o.load(2, 0.0, -1e5, 0.0)
    o.analyze(1, DT)
    split = dict.fromkeys(("remove", "pattern", "load", "analyze"), 0.0)
    w = []
    for k in range(n_steps):
        t0 = time.perf_counter()
        o.remove("loadPattern", 1000 + k)
        t1 = time.perf_counter()
        o.pattern("Plain", 1001 + k, 1)
        t2 = time.perf_counter()
        o.load(2 + (k * (n_el - 1)) // n_steps, 0.0, -1e5, 0.0)
        t3 = time.perf_counter()
        o.analyze(1, DT)
        t4 = time.perf_counter()
        w.append(o.nodeDisp(n_el // 2 + 1, 2))
        for key, dt in zip(split, (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
            split[key] += dt
    o.wipe()
    return split, np.array(w)


def swap_case(n_el, n_steps, repeats):
    best = {}
    for _ in range(repeats):
        for name, make in (("vtsi", _vtsi), ("peer", _openseespy)):
            split, w = pattern_swap(make(), n_el, n_steps)
            if sum(split.values()) < sum(best.get(name, ({"x": np.inf}, None))[0].values()):
                best[name] = (split, w)
    (vs, vw), (ps, pw) = best["vtsi"], best["peer"]
    row = _row("pattern swap (moving force)", n_el, n_steps, sum(vs.values()), "openseespy", sum(ps.values()),
               _rel_diff(vw, pw))
    for who, split in (("vtsi", vs), ("peer", ps)):
        row.update({f"{who}_{key}_us": 1e6 * seconds / n_steps for key, seconds in split.items()})
    return row


# -- text recorders in an analyze(1) loop -----------------------------------------------------------
def recorder_loop(o, n_recorders, n_steps, folder):
    """Seconds of the loop and the recorded files' values."""
    n_el = 20
    beam(o, n_el)
    o.timeSeries("Path", 1, "-dt", DT, "-values", *np.sin(0.01 * np.arange(n_steps + 10)).tolist())
    o.pattern("Plain", 1, 1)
    o.load(n_el // 2 + 1, 0.0, -1e5, 0.0)
    files = [os.path.join(folder, f"r{i}.out") for i in range(n_recorders)]
    for i, path in enumerate(files):
        o.recorder("Node", "-file", path, "-time", "-node", 2 + i, "-dof", 2, "disp")
    transient(o)
    o.analyze(1, DT)
    clock = time.perf_counter()
    for _ in range(n_steps):
        o.analyze(1, DT)
    seconds = time.perf_counter() - clock
    o.wipe()
    return seconds, [np.loadtxt(path) for path in files]


def recorder_case(n_recorders, n_steps, repeats):
    best, values = {}, {}
    for _ in range(repeats):
        for name, make in (("vtsi", _vtsi), ("peer", _openseespy)):
            folder = tempfile.mkdtemp(prefix="vtsi_s9_")
            try:
                seconds, recorded = recorder_loop(make(), n_recorders, n_steps, folder)
            finally:
                shutil.rmtree(folder, ignore_errors=True)
            best[name] = min(best.get(name, np.inf), seconds)
            values[name] = recorded
    diff = max([_rel_diff(a, b) for a, b in zip(values["vtsi"], values["peer"])], default=0.0)
    return _row(f"{n_recorders} text recorders", 20, n_steps, best["vtsi"], "openseespy", best["peer"], diff,
                recorders=n_recorders)


def _rel_diff(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = np.abs(b).max()
    return float(np.abs(a - b).max() / scale) if scale > 0 else float(np.abs(a - b).max())


def _row(case, n_el, n_steps, vtsi_s, peer, peer_s, diff, **extra):
    row = {"case": case, "n_elements": n_el, "steps": n_steps, "dt": DT, "vtsi_s": vtsi_s,
           "vtsi_us_per_step": 1e6 * vtsi_s / n_steps, "peer": peer, "peer_s": peer_s,
           "peer_us_per_step": 1e6 * peer_s / n_steps, "speedup": peer_s / vtsi_s, "max_rel_diff": diff}
    row.update(extra)
    return row


@register
class S9(Scene):
    name = "S9"
    description = ("OpenSees-style stepping loops (analyze(1, dt) per call): coupled loop vs analyze(n), "
                   "pattern-swap moving force and text recorders vs OpenSeesPy")
    requires = ("openseespy",)
    columns = (
        ("case", "case", "{}"),
        ("n_elements", "elements", "{:d}"),
        ("steps", "steps", "{:d}"),
        ("vtsi_us_per_step", "vtsi µs/call", "{:.1f}"),
        ("peer", "against", "{}"),
        ("peer_us_per_step", "against µs/call", "{:.1f}"),
        ("speedup", "against / vtsi", "{:.2f}"),
        ("vtsi_remove_us", "vtsi remove", "{:.1f}"),
        ("vtsi_pattern_us", "pattern", "{:.1f}"),
        ("vtsi_load_us", "load", "{:.1f}"),
        ("vtsi_analyze_us", "analyze", "{:.1f}"),
        ("peer_analyze_us", "OpenSeesPy analyze", "{:.1f}"),
        ("max_rel_diff", "max rel diff", "{:.1e}"),
    )

    def run(self, quick=False, baseline=False, repeats=3):
        steps = (lambda n: QUICK_STEPS) if quick else (lambda n: n)
        cases = [coupled_case(steps(COUPLED_STEPS), repeats)]
        cases += [swap_case(n, steps(SWAP_STEPS), repeats) for n in (QUICK_SWAP_SIZES if quick else SWAP_SIZES)]
        cases += [recorder_case(k, steps(RECORDER_STEPS), repeats) for k in RECORDERS]
        result = {"scene": self.name, "description": self.description, "headline": "pattern swap, 20 elements"}
        result.update(cases[1])
        result.update({"repeats": repeats, "quick": quick, "cases": cases})
        return result
