"""S3 ringing study (docs/scenes.md S3, docs/theory/constraints.md §3-§4): the contact force λ
of the trapezoidal rule with the exact Hermite constraint rows rings with period 2Δt; remedy (a)
('bspline' rows) and remedy (b) (Bathe) remove it. Metrics and numbers:
docs/theory/constraints.md §6.

Scene: S3 (models/scenes.py: 30 m span, 20 elements, 4-dof car, 300 km/h), the car starting
2 m before the span on rigid ground (so that the smoothed rows of 'bspline' are zero at t = 0,
see docs/theory/constraints.md §5). λ_ref: the reference solver R1
(vtsi.reference.elimination, constraint elimination, rtol 1e-8, exact Hermite rows, impulses
at the span entries and exits), sampled every 0.5 ms. If R1 cannot be imported, Bathe 'bspline'
at Δt = 62.5 µs (0.5 ms / 8) stands in (it gives the same R10 to 2 %, R to 10 %).

Metrics (static wheel load Q = 304.11 kN; crossing = first entry to last exit; the impulse
instants are the entry and exit of each wheel):

- R = RMS over the crossing, both wheels, of (λ − λ_ref)/Q at the step times, leaving out
  ±5 ms around every impulse instant;
- R10 = the same for the 10 ms moving averages of λ and of λ_ref (sampled at the same step
  times), leaving out averaging windows that reach within 5 ms of an impulse instant.

Measured (R / R10), Δt = 2 | 1 | 0.5 ms:

    Newmark 'hermite'   9.94e-2 / 1.99e-2 | 2.01e-1 / 6.2e-4 | 3.41e-1 / 8.5e-4
    Newmark 'bspline'   1.60e-3 / 9.4e-4  | 1.30e-3 / 3.7e-4 | 1.20e-3 / 1.8e-4
    HHT(0.9) 'hermite'  5.54e-3 / 1.23e-3 | 3.38e-3 / 4.5e-4 | 1.33e-3 / 2.0e-4
    HHT(0.9) 'bspline'  1.60e-3 / 9.5e-4  | 1.30e-3 / 4.2e-4 | 1.18e-3 / 1.9e-4
    Bathe 'hermite'     1.65e-3 / 9.0e-4  | 1.25e-3 / 3.7e-4 | 1.26e-3 / 2.0e-4
    Bathe 'bspline'     1.49e-3 / 8.3e-4  | 1.22e-3 / 3.7e-4 | 1.22e-3 / 2.0e-4

(Bathe's record is the step mean (λ_n + λ_γ + λ_{n+1})/3 of its velocity update.)

Rear-wheel λ at Δt = 1 ms: Newmark 'hermite' 228–381 kN (ringing of ±66 kN still there after
the wheel has left the span), Newmark 'bspline' 292–309 kN, Bathe 'hermite' 266–309 kN
(spikes at the entry and exit, then decaying). The ringing is born at the span entries and exits:
Newmark 'hermite' with ``exact_events=True`` (each kink taken at its own time) gives R =
3.5e-3 / 2.5e-3 / 1.8e-3, a third remedy at the source (test_exact_events_remove_newmark_ringing_at_its_source). R of the remedies stops falling near 1.2e-3:
λ holds 100–1000 Hz content of the FE bridge's higher modes (excited at every element
crossing) that steps of 0.5–2 ms do not resolve (Bathe at 62.5 µs and at 31.25 µs differ by
R = 7e-4); the 10 ms average converges.
"""
import numpy as np
import pytest

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.integrators import HHT
from vtsi.models.scenes import S3, s3_model
from vtsi.track import Track
from vtsi.train import TrainSubdomain

APPROACH = 2.0
N_ELEMENTS = 20
T_END = 0.62
REF_GRID = 5e-4
INSTANTS = (APPROACH + np.array([0.0, S3["L"], S3["l_c"], S3["L"] + S3["l_c"]])) / S3["V"]
CROSSING = (INSTANTS.min(), INSTANTS.max())
VARIANTS = {"Newmark hermite": ("Newmark", "hermite"), "Newmark bspline": ("Newmark", "bspline"),
            "HHT hermite": (HHT(0.9), "hermite"), "HHT bspline": (HHT(0.9), "bspline"),
            "Bathe hermite": ("Bathe", "hermite"), "Bathe bspline": ("Bathe", "bspline")}
STEPS = (2e-3, 1e-3, 5e-4)


def _parts(interpolation):
    model = vtsi.Model()
    bridge, train, x_head0 = s3_model(model, N_ELEMENTS, approach=APPROACH)
    con = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x_head0),
                               interpolation=interpolation)
    return model, con


def _run(integrator, interpolation, dt, exact_events=False):
    model, con = _parts(interpolation)
    analysis = CoupledAnalysis(model, con, integrator, dt, exact_events=exact_events)
    static = analysis.static()
    analysis.run(int(round(T_END / dt)))
    return analysis.time, analysis.contact_force, static["contact_force"][0]


@pytest.fixture(scope="module")
def reference():
    """λ_ref on a 0.5 ms grid (and R1's impulses)."""
    try:
        from vtsi.reference import elimination
    except ImportError:
        elimination = None
    if elimination is not None:
        model, con = _parts("hermite")
        sol = elimination.solve(model, con, T_END, np.arange(int(round(T_END / REF_GRID)) + 1) * REF_GRID, rtol=1e-8)
        return dict(t=sol.t, force=sol.contact_force, impulses=sol.impulses, source="R1")
    t, force, _ = _run("Bathe", "bspline", REF_GRID / 8)
    keep = np.isclose(np.round(t / REF_GRID) * REF_GRID, t, rtol=0, atol=1e-9)
    return dict(t=t[keep], force=force[keep], impulses=None, source="Bathe bspline dt/8")


@pytest.fixture(scope="module")
def runs():
    return {(name, dt): _run(integ, interp, dt) for name, (integ, interp) in VARIANTS.items() for dt in STEPS}


def _at(times, reference):
    """λ_ref at ``times`` (all on the reference grid)."""
    i = np.searchsorted(reference["t"], times - 1e-9)
    assert np.allclose(reference["t"][i], times, rtol=0, atol=1e-9)
    return reference["force"][i]


def _kept(times, margin):
    return ((times >= CROSSING[0]) & (times <= CROSSING[1])
            & np.all(np.abs(times[:, None] - INSTANTS[None, :]) > margin, axis=1))


def ringing(run, reference, exclude=5e-3):
    """R: RMS of (λ − λ_ref)/Q over the crossing, ±``exclude`` around the impulse instants left out."""
    t, force, q = run
    keep = _kept(t, exclude)
    return float(np.sqrt(np.mean(((force - _at(t, reference))[keep] / q) ** 2)))


def averaged_error(run, reference, window=10e-3, exclude=5e-3):
    """R10: R of the ``window`` moving averages (λ_ref sampled at the run's steps)."""
    t, force, q = run
    dt = t[1] - t[0]
    k = int(round(window / dt))

    def average(x):
        c = np.cumsum(np.vstack([np.zeros((1, x.shape[1])), x]), axis=0)
        return (c[k:] - c[:-k]) / k

    centre = t[k - 1:] - 0.5 * (k - 1) * dt
    keep = _kept(centre, exclude + 0.5 * window) & (centre - 0.5 * window >= CROSSING[0]) \
        & (centre + 0.5 * window <= CROSSING[1])
    diff = average(force) - average(_at(t, reference))
    return float(np.sqrt(np.mean((diff[keep] / q) ** 2)))


# -- the tests ----------------------------------------------------------------------------------
@pytest.mark.parametrize("dt", [1e-3, 2e-3])
def test_newmark_hermite_rings_and_the_remedies_do_not(runs, reference, dt):
    """R(Newmark 'hermite') ≥ 10 × R(Newmark 'bspline') and ≥ 10 × R(Bathe 'hermite')
    (measured ratios: 155 and 167 at 1 ms, 62 and 65 at 2 ms)."""
    r = {name: ringing(runs[(name, dt)], reference) for name in VARIANTS}
    assert r["Newmark hermite"] > 0.05
    assert r["Newmark hermite"] >= 10 * r["Newmark bspline"]
    assert r["Newmark hermite"] >= 10 * r["Bathe hermite"]
    assert r["Newmark hermite"] >= 10 * r["Bathe bspline"]
    for name in ("Newmark bspline", "HHT bspline", "Bathe hermite", "Bathe bspline"):
        assert r[name] < 2e-3, name


def test_newmark_hermite_ringing_does_not_go_away(runs, reference):
    """Smaller steps make it worse (R 0.099, 0.20, 0.34 at 2, 1, 0.5 ms) and it outlives the
    crossing: after the rear wheel has left the span (on rigid ground) its λ still swings by
    66 kN at 1 ms, while every remedy agrees with λ_ref to < 1 kN there."""
    r = [ringing(runs[("Newmark hermite", dt)], reference) for dt in STEPS]
    assert r[0] < r[1] < r[2]
    for name in VARIANTS:
        t, force, q = runs[(name, 1e-3)]
        after = t > CROSSING[1] + 10e-3
        swing = np.abs(force[after, 1] - _at(t[after], reference)[:, 1]).max()
        if name == "Newmark hermite":
            assert swing > 30e3
        elif name != "HHT hermite":
            assert swing < 1e3, name


def test_exact_events_remove_newmark_ringing_at_its_source(runs, reference):
    """S3's ringing comes from the span entries and exits: the velocity jump at a kink, taken at
    the end of its step, leaves the trapezoidal rule's undamped period-2Δt mode in λ. Taking
    each kink at its own time (``exact_events=True``, docs/theory/coupled_step.md §6) removes it
    for Newmark with the plain Hermite rows: R ≤ 5e-3 and ≥ 20× below the plain step at 2, 1
    and 0.5 ms (measured R 3.5e-3 / 2.5e-3 / 1.8e-3 against 0.099 / 0.20 / 0.34; R10 1.2e-3 /
    4.2e-4 / 1.9e-4, like the remedies'; after the crossing the rear wheel's λ is within 0.7 kN
    of λ_ref at 2 ms, against 66 kN of ringing for the plain step at 1 ms)."""
    exact = {dt: _run("Newmark", "hermite", dt, exact_events=True) for dt in STEPS}
    r = [ringing(exact[dt], reference) for dt in STEPS]
    plain = [ringing(runs[("Newmark hermite", dt)], reference) for dt in STEPS]
    assert max(r) < 5e-3, r
    assert all(p >= 20.0 * e for p, e in zip(plain, r)), (plain, r)
    r10 = [averaged_error(exact[dt], reference) for dt in STEPS]
    assert r10[0] > r10[1] > r10[2], r10


@pytest.mark.parametrize("name", ["Newmark bspline", "HHT bspline", "Bathe hermite", "Bathe bspline"])
def test_remedies_converge(runs, reference, name):
    """R10 falls by a factor ≥ 1.4 at every halving (measured 2.0–2.6); R falls from 2 to 1 ms
    and then stays near its floor of ~1.2e-3 (unresolved high-frequency content, module
    docstring)."""
    r10 = [averaged_error(runs[(name, dt)], reference) for dt in STEPS]
    assert r10[0] >= 1.4 * r10[1] and r10[1] >= 1.4 * r10[2], r10
    assert r10[2] < 3e-4
    r = [ringing(runs[(name, dt)], reference) for dt in STEPS]
    assert r[1] < r[0]
    assert max(r) < 2e-3


@pytest.mark.parametrize("name", ["Newmark bspline", "Bathe bspline"])
@pytest.mark.parametrize("dt", [1e-3, 5e-4])
def test_bspline_spreads_each_entry_and_exit_impulse(runs, reference, name, dt):
    """At a span entry or exit the exact λ holds an impulse (R1: −38.2 N·s rear entry, −67.1 N·s
    front exit, −20.9 N·s rear exit). 'bspline' spreads it over 8Δt: Σ (λ − λ_ref) Δt over
    ±6 ms equals it within 10 % (measured within 7 %)."""
    if reference["impulses"] is None:
        pytest.skip("needs R1's impulses")
    t, force, q = runs[(name, dt)]
    diff = force - _at(t, reference)
    assert len(reference["impulses"]) == 3
    for time, wheel, impulse in reference["impulses"]:
        near = np.abs(t - time) <= 6e-3
        assert np.sum(diff[near, wheel]) * dt == pytest.approx(impulse, rel=0.1), (time, wheel)


@pytest.mark.parametrize("integrator", ["Newmark", "Bathe", HHT(0.9)], ids=["Newmark", "Bathe", "HHT"])
def test_exact_events_record_the_impulses(reference, integrator):
    """With ``exact_events=True`` each kink's impulse is applied at its own time and recorded as
    impulse/Δt in its step's λ (the convention of a landing): Σ (λ − λ_ref) Δt over ±6 ms
    equals R1's impulse within 10 % or 3 N·s for every integrator, with the plain Hermite rows
    (Bathe's default record misses them: the xfail below). 3 N·s: the window also sums the
    unresolved high-frequency part of λ, R ≈ 1.2e-3 Q ≈ 0.37 kN over 12 ms ≈ 4 N·s at most.
    Measured at 1 ms (R1: −38.2, −67.1, −20.9 N·s): Newmark −38.1, −68.3, −21.4; Bathe −37.0,
    −68.4, −23.3; HHT(0.9) −37.9, −68.0, −21.2."""
    if reference["impulses"] is None:
        pytest.skip("needs R1's impulses")
    dt = 1e-3
    t, force, _ = _run(integrator, "hermite", dt, exact_events=True)
    diff = force - _at(t, reference)
    for time, wheel, impulse in reference["impulses"]:
        near = np.abs(t - time) <= 6e-3
        assert np.sum(diff[near, wheel]) * dt == pytest.approx(impulse, rel=0.1, abs=3.0), (time, wheel)


def test_bathe_hermite_record_carries_the_impulses(runs, reference):
    """Bathe's recorded λ of a step is the mean of the scheme's velocity update,
    (λ_n + λ_γ + λ_{n+1})/3 (Integrator.force_record_weights), so Σ λ Δt around each span entry
    and exit is R1's impulse (within 10 %) without exact_events. Measured at 1 ms: −37.4, −67.4,
    −21.2 N·s for R1's −38.2, −67.1, −20.9; a record of the second stage's λ alone missed the
    first stage's share and even had the wrong sign (+39.9 N·s for −38.2, +65.8 for −67.1;
    docs/theory/constraints.md §5)."""
    if reference["impulses"] is None:
        pytest.skip("needs R1's impulses")
    t, force, q = runs[("Bathe hermite", 1e-3)]
    diff = force - _at(t, reference)
    for time, wheel, impulse in reference["impulses"]:
        near = np.abs(t - time) <= 6e-3
        assert np.sum(diff[near, wheel]) * 1e-3 == pytest.approx(impulse, rel=0.1)
