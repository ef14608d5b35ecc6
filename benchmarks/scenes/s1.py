"""Scene S1: a constant force crossing a simply supported beam (Frýba), vtsi vs OpenSeesPy.

Model (docs/scenes.md S1; the scene of the speed anchors in benchmarks/README.md): span 25 m,
E = 2.943e10 Pa, I = 3.81 m⁴, A = 1 m², 36 t/m, consistent mass, ``n_el`` equal elasticBeamColumn
elements (20 and 200), pinned / roller supports, no damping; P = 100 kN downward at 100 km/h;
Newmark average acceleration, dt = 1 ms, 1400 steps (the crossing takes 900 ms).

Both codes get the *same* nodal loads: the peer's ``nodal_force_histories`` (hat-function
distribution of the force to the two nodes of its element) sampled at ``t_k = k dt``,
``k = 0..n_steps``, one ``Path`` series (``dt`` form) and one pattern per interior node with a
unit downward reference load: OpenSeesPy through ``timeSeries Path -dt``, vtsi through
``vtsi.Path(values, dt=dt)``.

What is timed (best of ``repeats``, the three codes interleaved so that a load burst from other
processes hits all of them alike):

- vtsi: ``TransientAnalysis.run(n_steps)`` of an analysis that has already run a short warm-up
  (numba compiled, effective matrix factored), from a reset state (u = v = a = 0, t = 0). It
  includes the evaluation of the Path series and the recorder feed.
- OpenSeesPy (the peer, ``benchmarks/peers/opensees_s1.py``, 'bulk' style = its fastest):
  ``analyze(n_steps, dt)`` with ``algorithm Linear -factorOnce``, system BandSPD, a midspan
  Node recorder to a file (reading the file is not timed).
- the floor (``baselines/floor.py``): S1 hand-written as one numba loop (banded Cholesky of the
  effective matrix factored once, Newmark, the same nodal forces, the bending dofs only): the
  limit a linear time loop is held to (``floor_*`` fields; ``vs_floor`` = vtsi's time / the
  floor's, 1 is the floor).
- baseline (``--baseline``): a plain Python loop over the steps with the effective matrix
  factored once by ``scipy.sparse.linalg.splu`` (factoring not timed), on vtsi's assembled free-dof
  matrices, loads ``B @ F[:, k]`` per step.
- the OpenSeesPy script (``peers/opensees_s1.py``) as a user runs it, with
  ``import openseespy.opensees`` and with ``import vtsi.opensees``: per step (``analyze(1, dt)``
  then ``nodeDisp`` and ``getTime``, the loop timed) and in one ``analyze(n_steps, dt)`` with a
  text recorder (the call timed: it includes what the first ``analyze`` prepares, numbering,
  assembly and factoring, in both codes).
"""
import math
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from baselines.floor import FloorLoop
from peers import opensees_s1 as peer
from scenes import Scene, register

DT = 1e-3
SIZES = (20, 200)
QUICK_SIZES = (20,)
QUICK_STEPS = 1000     # the force leaves the span at step 900
FAST_RUNS = 10         # runs of vtsi and of the floor per repeat: their best covers the measurement
GAMMA, BETA = 0.5, 0.25


def build_vtsi(n_elements, dt, n_steps):
    """vtsi model of S1 with the peer's nodal loads; returns ``(model, mid_node, node_x, F)``."""
    import vtsi

    n_nodes = n_elements + 1
    node_x = np.linspace(0.0, peer.L, n_nodes)
    F = peer.nodal_force_histories(node_x, peer.P, peer.V, dt * np.arange(n_steps + 1))
    model = vtsi.Model()
    for i, x in enumerate(node_x):
        model.node(i + 1, float(x), 0.0)
    model.fix(1, 1, 1, 0)
    model.fix(n_nodes, 0, 1, 0)
    for e in range(n_elements):
        model.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=peer.AREA, E=peer.E, I=peer.IZ,
                      rho=peer.MU, cmass=1)
    for i in range(1, n_nodes - 1):               # interior nodes, as the peer
        tag = i + 1
        model.pattern(tag, vtsi.Path(F[i], dt=dt, tag=tag))
        model.load(tag, tag, 0.0, -1.0, 0.0)
    return model, n_elements // 2 + 1, node_x, F


class VtsiRunner:
    """A prepared (warmed-up) vtsi analysis of S1 that can be re-run from rest."""

    def __init__(self, n_elements, dt, n_steps):
        import vtsi

        self.model, self.mid, _, self.F = build_vtsi(n_elements, dt, n_steps)
        self.n_steps = n_steps
        self.analysis = vtsi.TransientAnalysis(self.model, vtsi.integrators.Newmark(GAMMA, BETA), dt=dt)
        self.analysis.run(min(10, n_steps))        # warm-up: numba compilation, factorisation

    def _reset(self):
        from vtsi import domain_state

        state = domain_state(self.model)
        state.u[:] = 0.0
        state.v[:] = 0.0
        state.a[:] = 0.0
        state.time = 0.0

    def run(self):
        """Returns ``(seconds of the time loop, midspan uy after steps 1..n)``."""
        from vtsi.recorders import NodeRecorder

        self._reset()
        rec = NodeRecorder([self.mid], [2], "disp")
        self.analysis.recorders = [rec]
        t0 = time.perf_counter()
        self.analysis.run(self.n_steps)
        seconds = time.perf_counter() - t0
        return seconds, rec.values[:, 0].copy()


class SpluBaseline:
    """The 'straightforward Python loop with scipy splu' anchor, on vtsi's free-dof matrices."""

    def __init__(self, model, mid, F, dt, n_steps):
        asm = model.build()
        patterns = list(model.patterns.values())
        self.B = sp.csc_matrix(np.column_stack([asm.load_vector(p) for p in patterns]))
        self.F = np.ascontiguousarray(F[[p.tag - 1 for p in patterns]])   # pattern tag = node tag
        self.K, self.M, self.C = asm.K.tocsc(), asm.M.tocsc(), asm.C.tocsc()
        self.damped = asm.has_damping
        self.mid = int(asm.free_of_full[asm.full_dof(mid, 2)])
        self.dt, self.n_steps = dt, n_steps

    def run(self):
        dt, b, g = self.dt, BETA, GAMMA
        c0, c1, c2 = 1.0 / (b * dt * dt), 1.0 / (b * dt), 1.0 / (2.0 * b) - 1.0
        d0, d1, d2 = g / (b * dt), g / b - 1.0, dt * (g / (2.0 * b) - 1.0)
        lu = spla.splu((self.K + c0 * self.M + d0 * self.C).tocsc())
        n = self.K.shape[0]
        u, v, a = np.zeros(n), np.zeros(n), np.zeros(n)
        w = np.empty(self.n_steps)
        M, C, B, F = self.M, self.C, self.B, self.F
        t0 = time.perf_counter()
        for k in range(1, self.n_steps + 1):
            rhs = B @ F[:, k] + M @ (c0 * u + c1 * v + c2 * a)
            if self.damped:
                rhs += C @ (d0 * u + d1 * v + d2 * a)
            u_new = lu.solve(rhs)
            a_new = c0 * (u_new - u) - c1 * v - c2 * a
            v = v + dt * ((1.0 - g) * a + g * a_new)
            u, a = u_new, a_new
            w[k - 1] = u[self.mid]
        return time.perf_counter() - t0, w


def fryba_daf(n_steps, dt):
    """Max over the analysed window of Frýba's midspan deflection / (PL³/48EI) (101 modes)."""
    from vtsi.reference import moving_force_midspan, static_midspan

    t = np.linspace(0.0, n_steps * dt, 20 * n_steps + 1)
    w = moving_force_midspan(peer.P, peer.V, peer.L, peer.E * peer.IZ, peer.MU, t)
    return float(w.max()) / static_midspan(peer.P, peer.L, peer.E * peer.IZ)


def _rel_diff(w, ref):
    return float(np.max(np.abs(w - ref)) / np.max(np.abs(ref)))


def run_case(n_elements, n_steps, dt=DT, baseline=False, repeats=3):
    """One model size: vtsi, the peer (and the baseline) interleaved, best of ``repeats``; then
    the peer's own script run twice with each command module (``openseespy.opensees`` and
    ``vtsi.opensees``, the one line a user changes): per step (``analyze(1, dt)``, ``nodeDisp``
    and ``getTime`` every step) and in one ``analyze(n_steps, dt)`` with a file recorder."""
    vt = VtsiRunner(n_elements, dt, n_steps)
    floor = FloorLoop(n_elements, peer.L, peer.E * peer.IZ, peer.MU, vt.F, dt, n_steps)
    base = SpluBaseline(vt.model, vt.mid, vt.F, dt, n_steps) if baseline else None
    best = {"vtsi": math.inf, "peer": math.inf, "baseline": math.inf, "floor": math.inf}
    for _ in range(repeats):
        for _ in range(FAST_RUNS):     # the two compiled loops (~1-10 ms) over the peer's time
            s, w_vtsi = vt.run()
            best["vtsi"] = min(best["vtsi"], s)
            s, w_floor = floor.run()
            best["floor"] = min(best["floor"], s)
        r = peer.run(n_elements, dt=dt, style="bulk", n_steps=n_steps)
        best["peer"] = min(best["peer"], r["seconds"])
        w_ops = np.asarray(r["midspan"])
        if base is not None:
            s, w_base = base.run()
            best["baseline"] = min(best["baseline"], s)
    script = {}
    for _ in range(repeats):
        for style in ("step", "bulk"):
            for module in ("openseespy.opensees", "vtsi.opensees"):
                r = peer.run(n_elements, dt=dt, style=style, n_steps=n_steps, module=module)
                key = (style, module)
                if r["seconds"] < script.get(key, (math.inf,))[0]:
                    script[key] = (r["seconds"], np.asarray(r["midspan"]))
    static = peer.static_midspan()
    case = {
        "n_elements": n_elements,
        "steps": n_steps,
        "dt": dt,
        "vtsi_s": best["vtsi"],
        "vtsi_us_per_step": 1e6 * best["vtsi"] / n_steps,
        "peer": "openseespy",
        "peer_s": best["peer"],
        "peer_us_per_step": 1e6 * best["peer"] / n_steps,
        "speedup": best["peer"] / best["vtsi"],
        "floor_us_per_step": 1e6 * best["floor"] / n_steps,
        "vs_floor": best["vtsi"] / best["floor"],
        "floor_max_rel_diff": _rel_diff(w_floor, w_vtsi),
        "max_rel_diff": _rel_diff(w_vtsi, w_ops),
        "vtsi_daf": float(np.max(-w_vtsi)) / static,
        "fryba_daf": fryba_daf(n_steps, dt),
    }
    case["fryba_rel_diff"] = case["vtsi_daf"] / case["fryba_daf"] - 1.0
    us = {key: 1e6 * seconds / n_steps for key, (seconds, _) in script.items()}
    case.update({
        "script_step_peer_us_per_step": us["step", "openseespy.opensees"],
        "script_step_vtsi_us_per_step": us["step", "vtsi.opensees"],
        "script_step_speedup": us["step", "openseespy.opensees"] / us["step", "vtsi.opensees"],
        "script_bulk_peer_us_per_step": us["bulk", "openseespy.opensees"],
        "script_bulk_vtsi_us_per_step": us["bulk", "vtsi.opensees"],
        "script_bulk_speedup": us["bulk", "openseespy.opensees"] / us["bulk", "vtsi.opensees"],
        "script_max_rel_diff": max(_rel_diff(w, w_ops) for _, w in script.values()),
    })
    if base is not None:
        case.update({
            "baseline": "python loop + scipy splu",
            "baseline_s": best["baseline"],
            "baseline_us_per_step": 1e6 * best["baseline"] / n_steps,
            "speedup_vs_baseline": best["baseline"] / best["vtsi"],
            "baseline_max_rel_diff": _rel_diff(w_base, w_ops),
        })
    return case


@register
class S1(Scene):
    name = "S1"
    description = ("moving force over a 25 m simply supported beam (Frýba), 20 and 200 elements, "
                   "Newmark, 1400 steps: vtsi vs OpenSeesPy (same Path nodal loads)")
    requires = ("openseespy",)
    columns = (
        ("n_elements", "elements", "{:d}"),
        ("steps", "steps", "{:d}"),
        ("vtsi_us_per_step", "vtsi µs/step", "{:.2f}"),
        ("peer_us_per_step", "OpenSeesPy µs/step", "{:.1f}"),
        ("speedup", "speedup", "{:.0f}×"),
        ("floor_us_per_step", "floor µs/step", "{:.2f}"),
        ("vs_floor", "vtsi / floor", "{:.2f}"),
        ("baseline_us_per_step", "splu loop µs/step", "{:.1f}"),
        ("speedup_vs_baseline", "vs splu", "{:.0f}×"),
        ("script_step_vtsi_us_per_step", "script analyze(1) vtsi µs", "{:.1f}"),
        ("script_step_peer_us_per_step", "script analyze(1) OpenSeesPy µs", "{:.1f}"),
        ("script_step_speedup", "per step", "{:.1f}×"),
        ("script_bulk_vtsi_us_per_step", "script analyze(n) vtsi µs", "{:.1f}"),
        ("script_bulk_speedup", "analyze(n)", "{:.1f}×"),
        ("max_rel_diff", "max rel diff", "{:.1e}"),
        ("vtsi_daf", "DAF", "{:.4f}"),
        ("fryba_rel_diff", "DAF vs Frýba", "{:+.1e}"),
    )

    def run(self, quick=False, baseline=False, repeats=3):
        sizes = QUICK_SIZES if quick else SIZES
        n_steps = QUICK_STEPS if quick else peer.default_n_steps(DT)
        cases = [run_case(n, n_steps, DT, baseline, repeats) for n in sizes]
        result = {"scene": self.name, "description": self.description, "headline": "largest case"}
        result.update(cases[-1])
        result["max_rel_diff"] = max(c["max_rel_diff"] for c in cases)
        result["script_max_rel_diff"] = max(c["script_max_rel_diff"] for c in cases)
        result["floor_max_rel_diff"] = max(c["floor_max_rel_diff"] for c in cases)
        if baseline:
            result["baseline_max_rel_diff"] = max(c["baseline_max_rel_diff"] for c in cases)
        result.update({"repeats": repeats, "quick": quick, "peer_style": "bulk", "cases": cases})
        return result
