"""Scene S10: a sweep of coupled cars — what a passage costs besides its compiled time loop.

Sweep: ICE3 with 10-dof cars (``PassageSettings(cars='full', irregularity='german-high',
damping=0.01)``) over a 20 m span (``beam_bridge([20.0], E=3.5e10, I=1.2, mu=15000.0,
damping=0.01)``), 250–290 km/h in 10 km/h steps, rail samples (seeds) 1 and 2: 10 passages,
``Sweep(...).run(workers=1, progress=False)`` after a warm-up sweep (seed 0, one speed: numba
compiled). ``--quick``: 2 speeds, seed 1.

What is timed (CPU time of the process, ``time.process_time``, best of ``repeats``, a new Sweep
each time so that every seed's rail profile is sampled again): the whole sweep, and inside it
the compiled time loop alone (every call of :func:`vtsi.coupled_loop.run_coupled_steps`, timed
by a wrapper in its place in :mod:`vtsi.coupled`). Per passage: ``passage_cpu_s`` (the sweep's
CPU / passages), ``loop_cpu_s`` (the loop's share), ``ratio`` = passage / loop (1 would be a
passage that costs only its time loop) and ``passages_per_s`` (1 / passage_cpu_s).
The scene contract's ``vtsi_*`` fields are the passage, ``peer_*`` the compiled loop alone.
``envelope_max`` fingerprints the results (each envelope quantity's largest |value| over the
sweep): equal before and after a change that keeps what is computed.
"""
import contextlib
import time

import numpy as np

from scenes import Scene, register

SPEEDS, QUICK_SPEEDS = (250.0, 260.0, 270.0, 280.0, 290.0), (250.0, 290.0)
SEEDS, QUICK_SEEDS = (1, 2), (1,)
CLOCK = time.process_time


@contextlib.contextmanager
def loop_timer():
    """Replace vtsi.coupled's run_coupled_steps with a wrapper adding its CPU time to ``spent[0]``."""
    import vtsi.coupled
    kernel, spent = vtsi.coupled.run_coupled_steps, [0.0]

    def timed(*args, **kwargs):
        clock = CLOCK()
        try:
            return kernel(*args, **kwargs)
        finally:
            spent[0] += CLOCK() - clock

    vtsi.coupled.run_coupled_steps = timed
    try:
        yield spent
    finally:
        vtsi.coupled.run_coupled_steps = kernel


def _sweep(speeds, seeds):
    from vtsi.passage import PassageSettings
    from vtsi.sweep import Sweep, beam_bridge
    bridge = beam_bridge([20.0], E=3.5e10, I=1.2, mu=15000.0, damping=0.01)
    settings = PassageSettings(cars="full", irregularity="german-high", damping=0.01)
    return Sweep(bridge, ["ICE3"], list(speeds), settings, seeds=list(seeds))


@register
class S10(Scene):
    name = "S10"
    timed = "CPU time of whole passages and of their compiled loop"
    description = "a sweep of coupled cars: a passage's CPU time against its compiled time loop's (ICE3, 20 m span, irregular rail)"
    columns = (("passages", "passages", "{:d}"), ("passage_cpu_s", "passage CPU [s]", "{:.3f}"),
               ("loop_cpu_s", "loop CPU [s]", "{:.3f}"), ("ratio", "passage/loop", "{:.2f}"),
               ("passages_per_s", "passages/s", "{:.2f}"))

    def run(self, quick=False, baseline=False, repeats=3):
        speeds, seeds = (QUICK_SPEEDS, QUICK_SEEDS) if quick else (SPEEDS, SEEDS)
        _sweep(speeds[:1], (0,)).run(workers=1, progress=False)       # warm-up: numba compiled
        cases, results = [], None
        for _ in range(repeats):
            sweep = _sweep(speeds, seeds)
            n = len(sweep.cases)
            with loop_timer() as spent:
                clock = CLOCK()
                results = sweep.run(workers=1, progress=False)
                total = CLOCK() - clock
            steps = sum(results.case("ICE3", v, s)["attrs"]["n_steps"] for v in speeds for s in seeds)
            cases.append({"passages": n, "steps": steps, "passage_cpu_s": total / n, "loop_cpu_s": spent[0] / n,
                          "ratio": total / spent[0], "passages_per_s": n / total})
        best = min(cases, key=lambda c: c["passage_cpu_s"])
        envelope_max = {q: float(np.nanmax(np.abs(results.envelope(q)))) for q in results.quantities}
        return {"scene": "S10", "quick": quick, "cases": cases, "steps": best["steps"],
                "vtsi_s": best["passage_cpu_s"], "vtsi_us_per_step": best["passage_cpu_s"] * best["passages"]
                / best["steps"] * 1e6, "peer": "the compiled time loop alone (run_coupled_steps)",
                "peer_s": best["loop_cpu_s"], "peer_us_per_step": best["loop_cpu_s"] * best["passages"]
                / best["steps"] * 1e6, "speedup": None, "max_rel_diff": None, "ratio": best["ratio"],
                "passages_per_s": best["passages_per_s"], "envelope_max": envelope_max}
