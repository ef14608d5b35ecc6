"""The HSLM-A envelope of a 20 m simply supported span: ten trains × every speed from 140 to
420 km/h, moving forces, EN 1991-2 damping; one resumable HDF5 file and a chart.

    python examples/sweep_hslm.py                 # all cores, writes hslm_sweep.h5 and hslm_sweep.png
    python examples/sweep_hslm.py --workers 1     # serial

Bridge (our own data, the S4 scene): L = 20 m, μ = 15 t/m, EI such that f₁ = 5 Hz, prestressed
concrete: ζ = 1.0 % (EN 1991-2 Table 6.6, L >= 20 m) + Δζ (Eq. 6.13, moving forces without
interaction) as Rayleigh damping through the two modes that carry the midspan response (1 and 3).
Deck accelerations count the frequencies up to the EN 1990 A2 cut-off max(30 Hz, 1.5 n₀, n₃)
(= n₃ = 45 Hz here), by modal projection (``Output(..., cutoff="en")``).
"""
import argparse

import numpy as np

from vtsi.codes.en1991_2 import additional_damping, damping_lower_bound
from vtsi.damping import vertical_frequencies
from vtsi.passage import Output, PassageSettings
from vtsi.sweep import Sweep, beam_bridge

L, F1, MU = 20.0, 5.0, 15000.0          # span [m], first frequency [Hz], mass [kg/m]
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2     # from f₁ = (π/L)² √(EI/μ) / 2π [N m²]
LIMIT = 3.5                                            # EN 1990 A2.4.4.2.1, ballasted track [m/s²]


def main(out="hslm_sweep", trains=None, speeds="140:420:5", workers=None, elements=10, dt=None):
    """Run the sweep into ``out``.h5, draw ``out``.png; returns the results. ``dt`` [s]: None, the
    bridge's default (0.4 ms here: Newmark's period error at its 45 Hz EN cut-off at most 0.1 ζ)."""
    bridge = beam_bridge([L], EI, 1.0, MU, elements_per_span=elements)
    f = vertical_frequencies(bridge.model, 3)[0]
    zeta = damping_lower_bound("prestressed_concrete", L) + additional_damping(L)
    settings = PassageSettings(dt=dt, damping=zeta, damping_hz=(f[0], f[2]))
    outputs = [Output("deflection", "disp"), Output("acceleration", "accel", cutoff="en")]
    trains = trains or [f"HSLM-A{i}" for i in range(1, 11)]
    sweep = Sweep(bridge, trains, speeds, settings, outputs)
    results = sweep.run(out + ".h5", workers=workers, resume=True)
    print(f"bridge: f = {', '.join(f'{x:.2f}' for x in f)} Hz, zeta = {100 * zeta:.2f} % (Rayleigh at modes 1 and 3)")
    print(results.summary())
    worst = results.critical("acceleration_absmax")
    verdict = "exceeds" if worst["value"] > LIMIT else "is within"
    print(f"peak deck acceleration {worst['value']:.2f} m/s^2 ({worst['train']} at {worst['speed_kmh']:g} km/h) "
          f"{verdict} the EN 1990 A2 limit of {LIMIT} m/s^2 for ballasted track")
    chart(results, out + ".png")
    return results


def chart(results, path):
    """Peak deck acceleration against speed, one line per train, with the limit."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    acc = results.envelope("acceleration_absmax")[:, :, 0]
    fig, ax = plt.subplots(figsize=(9, 5))
    for name, row in zip(results.trains, acc):
        ax.plot(results.speeds_kmh, row, label=name, lw=1.2)
    ax.axhline(LIMIT, color="k", ls="--", lw=1, label=f"{LIMIT} m/s² (ballasted)")
    ax.set_xlabel("speed [km/h]")
    ax.set_ylabel("peak deck acceleration [m/s²]")
    ax.set_title(f"HSLM-A over a {L:g} m span, f₁ = {results.frequencies_hz[0]:.2f} Hz")
    ax.grid(alpha=0.3)
    ax.legend(ncol=2, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=None, help="processes (default: every core)")
    parser.add_argument("--out", default="hslm_sweep", help="results file and chart name (without extension)")
    args = parser.parse_args()
    main(args.out, workers=args.workers)
