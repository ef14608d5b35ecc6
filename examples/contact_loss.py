"""Contact loss: a sprung wheel jumps over a rail bump on a 30 m bridge span and lands again.

A quarter-car (a 10 t sprung mass on a 1 MN/m suspension over a 1.8 t wheelset) crosses the
S3 span (30 m, simply supported) at 300 km/h. A 5 mm, 3 m long bump (r = h sin⁴(π(x - x_b)/ℓ))
sits at midspan: at its crest the rail falls away with V² h (2π/ℓ)² = 152 m/s², faster than
the wheel's load can pull the wheel down (Q/m_w ≈ 64 m/s²), so the wheel leaves the rail, flies
and lands again. The analysis runs with ``contact='lcp'`` (Bathe's scheme, Δt = 0.25 ms) and
reports the lift-off and landing events and the per-wheel summary (vtsi.contact); the plot shows
the contact force and the gap against time with the events marked.

Run: ``python examples/contact_loss.py [out.png]`` (default ``contact_loss.png`` in the current
directory; needs matplotlib).
"""
import sys

import numpy as np

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.contact import LIFT_OFF
from vtsi.coupled import CoupledAnalysis
from vtsi.models import Irregularity, Train, sprung_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.models.scenes import S3
from vtsi.track import Track
from vtsi.train import TrainSubdomain

SPEED = 300.0 / 3.6            # m/s
DT = 2.5e-4                    # s
BUMP = dict(h=0.005, length=3.0, start=13.5)   # m: height, length, start (crest at midspan)
APPROACH = 5.0                 # m of rigid ground before the span


def bump(h, length, start):
    """r(x) = h sin⁴(π (x - start)/length) on [start, start + length] with r' and r''."""
    k = np.pi / length

    def part(x, values):
        x = np.asarray(x, float)
        return np.where((x >= start) & (x <= start + length), values(k * (x - start)), 0.0)

    return Irregularity.from_function(
        lambda x: part(x, lambda s: h * np.sin(s) ** 4),
        lambda x: part(x, lambda s: 4 * h * k * np.sin(s) ** 3 * np.cos(s)),
        lambda x: part(x, lambda s: 4 * h * k * k * (3 * np.sin(s) ** 2 * np.cos(s) ** 2 - np.sin(s) ** 4)))


def build(integrator="Bathe", dt=DT, speed=SPEED):
    """The bridge, the quarter car and the analysis (dead load applied)."""
    model = vtsi.Model()
    p = S3
    bridge = simply_supported_beam(model, p["L"], p["n_elements"], p["E"], p["I"], p["mu"])
    car = sprung_mass(m_s=10000.0, k_s=1.0e6, c_s=2.0e4, m_w=1800.0)
    train = Train([car], [0.0], speed, name="quarter car")
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x_head0=-APPROACH),
                                      irregularity=bump(**BUMP))
    analysis = CoupledAnalysis(model, constraint, integrator, dt=dt, contact="lcp")
    analysis.static()
    return analysis


def plot(analysis, events, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = analysis.time
    lam = analysis.contact_force[:, 0] / 1e3
    gap = analysis.gap[:, 0] * 1e3
    q_static = analysis.constraint.train.train.static_wheel_loads[0] / 1e3
    speed = analysis.constraint.train.speed
    t_bump = (np.array([BUMP["start"], BUMP["start"] + BUMP["length"]]) + APPROACH) / speed
    lifts = [e for e in events if e.kind == LIFT_OFF]
    lands = [e for e in events if e.kind != LIFT_OFF]
    window = (t_bump[0] - 0.01, max([e.time for e in events] + [t_bump[1]]) + 0.03)
    top = 3.0 * q_static                      # force axis clipped here; the landing peak is labelled

    fig, axes = plt.subplots(3, 1, figsize=(9, 8.5), constrained_layout=True)
    ax = axes[0]
    ax.plot(t, lam, lw=0.8, color="C0")
    ax.axhline(q_static, color="0.5", lw=0.8, ls="--", label=f"static wheel load Q = {q_static:.0f} kN")
    ax.axvspan(*window, color="0.9", zorder=0, label="zoomed below")
    ax.set(xlabel="time [s]", ylabel="contact force λ [kN]", ylim=(-0.1 * q_static, top), xlim=(t[0], t[-1]),
           title=f"Quarter car over a 5 mm bump at midspan of a 30 m span, {speed * 3.6:.0f} km/h")
    ax.legend(loc="upper left", fontsize=8)
    for ax, values, label, color in ((axes[1], lam, "contact force λ [kN]", "C0"), (axes[2], gap, "gap [mm]", "C2")):
        keep = (t >= window[0]) & (t <= window[1])
        ax.plot(t[keep], values[keep], ".-", ms=2.5, lw=0.8, color=color)
        ax.axvspan(*t_bump, color="C1", alpha=0.12, label="wheel on the bump")
        for e in lifts:
            ax.axvline(e.time, color="C3", lw=1.0)
        for e in lands:
            ax.axvline(e.time, color="C4", lw=1.0, ls="--")
        ax.set(ylabel=label, xlim=window)
    axes[1].axhline(q_static, color="0.5", lw=0.8, ls="--")
    axes[1].set_ylim(-0.1 * q_static, top)
    if lands:                                 # the largest impact, spread over its landing step
        e = max(lands, key=lambda e: lam[e.step])
        peak = lam[e.step]
        if peak > top:
            axes[0].annotate(f"{peak:.0f} kN", (t[e.step], top), xytext=(8, -12), textcoords="offset points",
                             fontsize=8, color="C4")
            axes[1].annotate(f"landing step: λ = {peak:.0f} kN\n(the impact spread over one step)",
                             (t[e.step], top), xytext=(10, -30), textcoords="offset points", fontsize=8,
                             color="C4", arrowprops=dict(arrowstyle="->", color="C4"))
    axes[1].plot([], [], color="C3", lw=1.0, label="lift-off")
    axes[1].plot([], [], color="C4", lw=1.0, ls="--", label="landing")
    axes[1].legend(loc="upper left", fontsize=8)
    axes[1].set_title("zoom on the bump: λ falls to 0, the wheel flies, the landing carries an impact", fontsize=9)
    axes[2].set_xlabel("time [s]")
    axes[2].set_title("position gap between wheel and rail (> 0: in flight)", fontsize=9)
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(out=None):
    out = "contact_loss.png" if out is None else out
    analysis = build()
    crossing = (vtsi.models.scenes.S3["L"] + 2 * APPROACH) / analysis.constraint.train.speed
    analysis.run(int(np.ceil(crossing / analysis.dt)))
    events = analysis.contact_events()
    summary = analysis.contact_summary()
    print(f"{len(events)} contact events (time [s], wheel position x [m]):")
    for e in events:
        print(f"  {e.kind:8s}  wheel {e.wheel}  t = {e.time:.5f} s  x = {e.position:.3f} m")
    print(summary.table())
    plot(analysis, events, out)
    print(f"plot written to {out}")
    return {"analysis": analysis, "events": events, "summary": summary}


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
