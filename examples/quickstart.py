"""Quick start: an 8-car ICE3 train crossing a 3 x 30 m continuous viaduct at 300 km/h.

The bridge is a vtsi model (nodes, elements, supports); the train is a separate subdomain of
10-dof cars; the wheels are tied to the deck by a MovingLoadConstraint whose Lagrange
multipliers are the wheel-rail contact forces (Fedorova & Sivaselvan 2017). The run starts
from the dead-load equilibrium, uses Newmark's trapezoidal rule with the B-spline constraint
(no spurious contact-force ringing) and reports what a bridge engineer checks: peak deck
acceleration against EN 1990 A2 (3.5 m/s² on ballasted track), the largest midspan
deflection, and the wheel unloading.

Run: ``python examples/quickstart.py [out.png]`` (the plot is written only if matplotlib is
installed).
"""
import sys
import time

import numpy as np

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.models import Irregularity, german_psd, ice3
from vtsi.models.scenes import s5_viaduct
from vtsi.recorders import ContactRecorder, NodeRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain

SPEED = 300.0 / 3.6          # m/s
DT = 1.0e-3                  # s
APPROACH = 10.0              # m of rigid ground before the viaduct
ELEMENTS_PER_SPAN = 20


def warm_up(integrator, dt, elements_per_span):
    """Compile (or load from numba's cache) the kernels of this run: two ICE3 cars over the same
    mesh with the same recorder kinds, 2 steps (the coupled loop is compiled for each half
    bandwidth of the bridge's factor, vtsi.banded: a coarser mesh would leave it to the timed run).
    Returns the seconds."""
    t0 = time.perf_counter()
    model = vtsi.Model()
    span = s5_viaduct(model, elements_per_span=elements_per_span)
    tie = MovingLoadConstraint(Track(model, span.elements), TrainSubdomain(ice3(2, speed=SPEED), x_head0=-1.0),
                               interpolation="bspline")
    recorders = [NodeRecorder(span.midspan_nodes, [2], "disp"), NodeRecorder(span.midspan_nodes, [2], "accel",
                                                                             envelope=True), ContactRecorder(tie)]
    analysis = CoupledAnalysis(model, tie, integrator, dt, recorders=recorders)
    analysis.static()
    analysis.run(2)
    return time.perf_counter() - t0


def main(out=None, n_cars=8, speed=SPEED, integrator="Newmark", dt=DT):
    model = vtsi.Model()
    bridge = s5_viaduct(model, elements_per_span=ELEMENTS_PER_SPAN)  # 3 x 30 m, nodes 1..61
    train = ice3(n_cars, speed=speed)
    rng = np.random.default_rng(2017)
    # the train starts at rest on smooth track: the irregularity fades in over the approach,
    # ahead of the head (a wheel starting on an irregular rail would need the rail's vertical
    # velocity V r'(x) as an initial condition, which a dead-load state does not have)
    n_steps = int(np.ceil((APPROACH + train.length + bridge.length) / speed / dt))
    x = np.linspace(-APPROACH - train.length - 5.0, -APPROACH + speed * n_steps * dt + 5.0, 8001)
    fade = np.clip((x + APPROACH) / APPROACH, 0.0, 1.0)
    profile = Irregularity.from_psd(lambda w: german_psd(w, "low"), x, rng=rng)
    rail = Irregularity(x, profile(x) * fade * fade * (3.0 - 2.0 * fade))
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x_head0=-APPROACH),
                                      irregularity=rail, interpolation="bspline")
    deck = NodeRecorder(bridge.midspan_nodes, [2], "disp")
    deck_acc = NodeRecorder(bridge.midspan_nodes, [2], "accel", envelope=True)
    wheels = ContactRecorder(constraint)
    analysis = CoupledAnalysis(model, constraint, integrator, dt, recorders=[deck, deck_acc, wheels])
    compile_s = warm_up(integrator, dt, ELEMENTS_PER_SPAN)
    static = analysis.static()
    t0 = time.perf_counter()
    analysis.run(n_steps)
    elapsed = time.perf_counter() - t0

    q_static = train.static_wheel_loads
    unloading = np.max((q_static - wheels.values) / q_static)
    peak_acc = np.abs(deck_acc.values).max()
    print(f"ICE3 x {n_cars} at {speed * 3.6:.0f} km/h over 3 x 30 m: {n_steps} steps in {elapsed:.2f} s "
          f"({elapsed / n_steps * 1e6:.1f} us/step; {compile_s:.1f} s before it to compile or load the kernels)")
    print(f"peak deck acceleration {peak_acc:.2f} m/s^2 (EN 1990 A2 limit 3.5 m/s^2 ballasted: "
          f"{'OK' if peak_acc <= 3.5 else 'EXCEEDED'})")
    print(f"max midspan deflection {-deck.values.min() * 1e3:.2f} mm; "
          f"contact force {wheels.values.min() / 1e3:.0f} .. {wheels.values.max() / 1e3:.0f} kN "
          f"(static {q_static.mean() / 1e3:.0f} kN); max wheel unloading dQ/Q = {unloading:.3f}")
    if out:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("matplotlib is not installed: no plot (pip install 'vtsi[plot]')")
        else:
            fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
            ax[0].plot(deck.time, deck.values * 1e3)
            ax[0].set_ylabel("midspan deflection [mm]")
            ax[0].legend([f"span {i + 1}" for i in range(3)], loc="lower left")
            ax[1].plot(deck_acc.time, deck_acc.values)
            ax[1].axhline(3.5, color="r", ls="--"); ax[1].axhline(-3.5, color="r", ls="--")
            ax[1].set_ylabel("deck acceleration [m/s²]")
            car1 = np.flatnonzero(train.wheel_car[train.contact_wheels] == 0)   # car 1's contact wheels
            ax[2].plot(wheels.time, wheels.values[:, car1] / 1e3, lw=0.8)
            ax[2].legend([f"axle {k + 1}: {train.wheel_offsets[w]:.1f} m" for k, w in enumerate(train.contact_wheels[car1])],
                         title="axle (distance behind the head of the train)", loc="lower left", ncol=4, fontsize=8,
                         title_fontsize=8, framealpha=0.9)
            low, high = ax[2].get_ylim()
            ax[2].set_ylim(low - 0.35 * (high - low), high)                       # room for the legend
            ax[2].set_ylabel("contact force, car 1 [kN]")
            ax[2].set_xlabel("time [s]")
            fig.tight_layout()
            fig.savefig(out, dpi=90)
            print(f"plot written to {out}")
    return {"peak_acceleration": peak_acc, "unloading": unloading, "us_per_step": elapsed / n_steps * 1e6,
            "static_contact_force": static["contact_force"]}


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "quickstart.png")
