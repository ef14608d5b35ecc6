"""The main example: the EN 1990 A2 / EN 1991-2 dynamic design check of a 20 m simply supported
prestressed-concrete railway bridge for HSLM-A1 … A10 and the ICE3, from 144 km/h (40 m/s) to
1.2 × the 300 km/h line speed, with its report.

    python examples/design_check.py                # writes design_check.h5 and design_check_report/

Bridge (our own data, a typical high-speed-line span): L = 20 m, μ = 15 t/m, E = 35 GPa and I
(0.695 m⁴) such that the first bending frequency is 5 Hz, 10 elements; ballasted track. Damping: EN 1991-2 Table 6.6
(prestressed concrete: 1.0 % for L ≥ 20 m) + Δζ of Eq. 6.13 (0.30 %: moving forces) as Rayleigh
damping through n₀ and the EN cut-off. Trains: moving axle loads (HSLM-A1 … A10, ICE3). Speeds:
the EN 1991-2 §6.4.6.2 series as ``vtsi check --line-speed 300`` builds it, every 10 km/h and every
2 km/h within ±10 % of each resonance v = n D / i of the first three frequencies n (5, 20, 45 Hz).
Δt: the default, 0.4 ms (the deck accelerations count the modes up to the cut-off, 45 Hz here,
and Newmark's period error there is kept at most 0.1 ζ: √(1.2 ζ)/(2π 45 Hz) = 0.44 ms, rounded down).

The first run on a fresh install compiles vtsi's kernels (numba, cached afterwards); the
printout reports that time apart from the check's.
"""
import argparse
import time

import numpy as np

from vtsi.check import CheckSettings
from vtsi.codes.en1991_2 import additional_damping, damping_lower_bound
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep, beam_bridge, en_speed_grid
from vtsi.workflow import design_check

L, F1, MU = 20.0, 5.0, 15000.0                         # span [m], first frequency [Hz], mass [kg/m]
E = 3.5e10                                             # prestressed concrete [Pa]
I = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2 / E  # f₁ = (π/L)² √(EI/μ) / 2π: I = 0.695 m⁴
LINE_SPEED = 300.0                                     # [km/h]
TRAINS = [f"HSLM-A{i}" for i in range(1, 11)] + ["ICE3"]


def sweep_of(trains=TRAINS, line_speed=LINE_SPEED, elements=10, dt=None):
    """The sweep of this example (bridge, damping by the rules, EN speed series)."""
    bridge = beam_bridge([L], E, I, MU, elements_per_span=elements)
    zeta = damping_lower_bound("prestressed_concrete", L) + additional_damping(L)
    settings = PassageSettings(dt=dt, damping=zeta)
    sweep = Sweep(bridge, trains, [200.0], settings)          # the bridge's frequencies for the grid
    lengths = [sweep.runner.train(t, 40.0).characteristic_length for t in trains]
    speeds = en_speed_grid(line_speed, sweep.runner.deck_frequencies.ravel(), lengths)
    return Sweep(bridge, trains, speeds, settings)


def warm_up():
    """Compile (or load from numba's cache) the kernels a check runs: one tiny passage."""
    clock = time.perf_counter()
    Sweep(beam_bridge([L], E, I, MU, elements_per_span=2), ["HSLM-A1"], [300.0],
          PassageSettings(dt=0.02)).run(None, workers=1, progress=False)
    return time.perf_counter() - clock


def main(out="design_check", workers=None, **kwargs):
    compile_s = warm_up()
    sweep = sweep_of(**kwargs)
    clock = time.perf_counter()
    result, paths = design_check(sweep, out + ".h5", CheckSettings(track="ballasted"), out + "_report",
                                 workers=workers, overwrite=True)
    seconds = time.perf_counter() - clock
    print(f"{len(sweep.trains)} trains x {len(sweep.speeds_kmh)} speeds ({sweep.speeds_kmh[0]:g}-"
          f"{sweep.speeds_kmh[-1]:g} km/h) = {len(sweep.cases)} passages over a {L:g} m span "
          f"(f1 = {sweep.runner.frequencies[0]:.2f} Hz, zeta = {100 * sweep.settings.damping:.2f} %)")
    print(result.text())
    print(f"\nreport: {paths['html']} (and report.md)")
    print(f"time: {seconds:.1f} s for the check (sweep, histories, scene, report); "
          f"{compile_s:.1f} s compiling or loading vtsi's kernels")
    return result, paths


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=None, help="processes (default: every core)")
    parser.add_argument("--out", default="design_check", help="results file and report name (no extension)")
    args = parser.parse_args()
    main(args.out, workers=args.workers)
