"""Scene S6 (cost side): the contact-loss strategy (LCP) against the bilateral one, same scene.

What a user pays for ``contact='lcp'`` when no wheel leaves the rail (the usual case in a
catalogue sweep): ICE3 trains (10-dof cars) over the S5 viaduct (3 × 30 m continuous, 20
elements per span), smooth rail, head starting 5 m before the bridge, until the last wheel is
10 m past it; Δt = 1 ms. Cases: 2 cars at 200 km/h (HHT(0.9), Bathe) and 8 cars at 250 km/h
(HHT(0.9), Bathe; contact='lcp' refuses Newmark's undamped trapezoidal rule). No wheel separates
in these runs, so both strategies must give the same
numbers (``max_rel_diff``, measured 0.0: the LCP's warm start is the bilateral free set and its
first factorisation is the bilateral solve).

What is timed (best of ``repeats``, the two strategies interleaved): ``CoupledAnalysis.run(n)``
of an analysis that has already run one step from the dead-load state (numba compiled,
effective matrices factored, flexibilities precomputed), in CPU time of the process
(``time.process_time``): the ratio of two runs of a few tens of milliseconds is what matters,
and on a shared machine wall time swung it between 0.6 and 1.6 from run to run, CPU time
between 0.9 and 1.15. The accuracy side of S6 (a wheel
thrown off by a bump, lift-off, ballistic flight and landing against the closed form) is in
tests/test_contact_loss.py.

Fields: ``lcp_us_per_step``, ``bilateral_us_per_step``, ``ratio`` = LCP / bilateral time
(target ≤ 1.5), ``max_rel_diff`` = max |λ_lcp - λ_bilateral| / max |λ_bilateral|; the scene
contract's ``vtsi_*`` fields are the LCP run and ``peer_*`` the bilateral run of vtsi itself.
"""
import math
import time

import numpy as np

from scenes import Scene, register

DT = 1e-3
CASES = ((2, 200.0, "HHT(0.9)"), (2, 200.0, "Bathe"), (8, 250.0, "HHT(0.9)"), (8, 250.0, "Bathe"))
QUICK_CASES = ((2, 200.0, "HHT(0.9)"),)
QUICK_STEPS = 600
CLOCK = time.process_time   # CPU time of this process: steadier than wall time on a loaded machine
APPROACH, RUN_OUT = 5.0, 10.0


def build(contact, n_cars, speed_kmh, integrator, dt=DT):
    """A warmed-up analysis (dead load, one step run) and the number of steps of the crossing."""
    import vtsi
    from vtsi.constraint import MovingLoadConstraint
    from vtsi.coupled import CoupledAnalysis
    from vtsi.models import ice3
    from vtsi.models.scenes import s5_viaduct
    from vtsi.track import Track
    from vtsi.train import TrainSubdomain

    model = vtsi.Model()
    bridge = s5_viaduct(model, elements_per_span=20)
    train = ice3(n_cars, speed=speed_kmh / 3.6)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, -APPROACH))
    from vtsi.integrators import HHT
    analysis = CoupledAnalysis(model, constraint, HHT(0.9) if integrator == "HHT(0.9)" else integrator, dt=dt,
                               contact=contact)
    analysis.static()
    analysis.run(1)
    head_to_tail = 3.51 + train.wheel_offsets[-1]
    n_steps = int(math.ceil((APPROACH + bridge.length + head_to_tail + RUN_OUT) / train.speed / dt))
    return analysis, n_steps


def run_case(n_cars, speed_kmh, integrator, repeats=3, n_steps=None):
    best = {"lcp": math.inf, "bilateral": math.inf}
    forces = {}
    for _ in range(repeats):
        for contact in ("bilateral", "lcp"):
            analysis, n_full = build(contact, n_cars, speed_kmh, integrator)
            n = n_full if n_steps is None else min(n_steps, n_full)
            start = CLOCK()
            analysis.run(n)
            best[contact] = min(best[contact], CLOCK() - start)
            forces[contact] = analysis.contact_force[1:]
            if contact == "lcp":
                separations = int(analysis.contact_summary().separations.sum())
    ref = forces["bilateral"]
    case = {
        "train": f"ICE3 x {n_cars}", "speed_kmh": speed_kmh, "integrator": integrator,
        "n_contact": int(ref.shape[1]), "steps": n, "dt": DT,
        "lcp_s": best["lcp"], "lcp_us_per_step": 1e6 * best["lcp"] / n,
        "bilateral_s": best["bilateral"], "bilateral_us_per_step": 1e6 * best["bilateral"] / n,
        "ratio": best["lcp"] / best["bilateral"],
        "max_rel_diff": float(np.abs(forces["lcp"] - ref).max() / np.abs(ref).max()),
        "separations": separations,
        "min_contact_force": float(ref.min()),
    }
    case.update({"vtsi_s": case["lcp_s"], "vtsi_us_per_step": case["lcp_us_per_step"], "peer": "bilateral (vtsi)",
                 "peer_s": case["bilateral_s"], "peer_us_per_step": case["bilateral_us_per_step"],
                 "speedup": 1.0 / case["ratio"]})
    return case


@register
class S6(Scene):
    name = "S6"
    description = ("contact loss: cost of the LCP contact strategy vs bilateral per step, ICE3 over the "
                   "S5 viaduct with no separation (same numbers expected)")
    columns = (
        ("train", "train", "{}"),
        ("integrator", "integrator", "{}"),
        ("n_contact", "wheels", "{:d}"),
        ("steps", "steps", "{:d}"),
        ("lcp_us_per_step", "LCP µs/step", "{:.1f}"),
        ("bilateral_us_per_step", "bilateral µs/step", "{:.1f}"),
        ("ratio", "LCP/bilateral", "{:.2f}"),
        ("max_rel_diff", "max rel diff", "{:.1e}"),
        ("separations", "separations", "{:d}"),
    )

    def run(self, quick=False, baseline=False, repeats=3):
        cases = [run_case(n, v, integ, repeats, QUICK_STEPS if quick else None)
                 for n, v, integ in (QUICK_CASES if quick else CASES)]
        result = {"scene": self.name, "description": self.description, "headline": "largest case"}
        result.update(cases[-1])
        result["max_rel_diff"] = max(c["max_rel_diff"] for c in cases)
        result["max_ratio"] = max(c["ratio"] for c in cases)
        result.update({"repeats": repeats, "quick": quick, "cases": cases})
        return result
