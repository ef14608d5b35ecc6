"""Kinks declared by a rail profile (Irregularity.from_function(..., kinks=...)) taken as events
with exact_events=True (docs/theory/contact.md §4, docs/theory/coupled_step.md §6).

Scene (probe C1): a rigid 1800 kg wheel on rigid ground at 30 m/s; the profile has a straight
0.5 % up-ramp from x = 1 m (r' jumps 0 -> 0.005). Closed form (perfectly inelastic impact): the
wheel's velocity jumps to V s = 0.15 m/s at t = 1/30 s, impulse m V s = 270 N·s, then it follows
the ramp with λ = m g; no flight. Undeclared, the LCP took that impulse as a force of one step and
the integrator's memory of it threw the wheel off (0.8 mm / 26 ms with HHT(0.9), whatever Δt).
"""
import numpy as np
import pytest

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, ModelError
from vtsi.integrators import HHT, GeneralizedAlpha
from vtsi.models import GRAVITY, Irregularity, Train, moving_mass, sprung_mass
from vtsi.models.scenes import rigid_ground, s3_model
from vtsi.track import Track
from vtsi.train import TrainSubdomain

M, V, SLOPE, X_KINK = 1800.0, 30.0, 0.005, 1.0


def _zero(x):
    return np.zeros_like(np.asarray(x, float))


def _ramp(x_kink=X_KINK, slope=SLOPE, kinks=(X_KINK,)):
    """r = slope (x - x_kink) beyond x_kink, 0 before [m]."""
    return Irregularity.from_function(lambda x: np.where(np.asarray(x, float) >= x_kink, slope * (np.asarray(x, float) - x_kink), 0.0),
                                      lambda x: np.where(np.asarray(x, float) >= x_kink, slope, 0.0), _zero, kinks=kinks)


def _crest(s, x1, xc):
    """Up at slope s from x1 to the crest xc, down to x2 = 2 xc - x1, flat after: three kinks."""
    x2 = 2 * xc - x1

    def f(x):
        x = np.asarray(x, float)
        return np.where((x >= x1) & (x <= xc), s * (x - x1), np.where((x > xc) & (x <= x2), s * (x2 - x), 0.0))

    def df(x):
        x = np.asarray(x, float)
        return np.where((x >= x1) & (x <= xc), s, np.where((x > xc) & (x <= x2), -s, 0.0))

    return Irregularity.from_function(f, df, _zero, kinks=(xc, x1, x2))


def _rigid_ground(car, profile, integrator, dt, t_end, contact="lcp", **kwargs):
    """``car`` from x = 0 at V over ``profile`` on rigid ground (the track, 1 m long, at x = 1000 m)."""
    model = vtsi.Model()
    con = MovingLoadConstraint(Track(model, rigid_ground(model)), TrainSubdomain(Train([car], [0.0], V), 0.0), irregularity=profile)
    analysis = CoupledAnalysis(model, con, integrator, dt=dt, contact=contact, **kwargs)
    analysis.static()
    analysis.run(int(round(t_end / dt)))
    return analysis


def test_kinks_are_validated_and_sorted():
    assert _ramp(kinks=(3.0, -1.0, 2)).kinks == (-1.0, 2.0, 3.0)
    assert Irregularity.from_function(_zero).kinks == ()
    assert _ramp(kinks=1.0).kinks == (1.0,) and _ramp(kinks=None).kinks == ()      # one kink, a number; none
    assert Irregularity(np.linspace(0, 1, 5), np.zeros(5)).kinks == ()
    assert "kinks at x = -1, 2, 3 m" in repr(_ramp(kinks=(3.0, -1.0, 2)))
    for kinks, words in [((1.0, np.nan), "kinks must be finite, got nan"), (np.inf, "kinks must be finite, got inf"),
                         ((2.0, 1.0, 2.0), "kink x = 2 m is given twice"),
                         ("1.0", "kinks [m] must be numbers, got '1.0'"), ([[1.0, 2.0]], "shape (1, 2)"),
                         ((True,), "kinks [m] must be numbers")]:
        with pytest.raises(ModelError, match="Irregularity.from_function: ") as err:
            _ramp(kinks=kinks)
        assert words in str(err.value)


def test_lcp_refuses_declared_kinks_without_exact_events():
    with pytest.raises(AnalysisError, match=r"kinks at x = 1 m; .*exact_events=True .* interpolation='bspline'"):
        _rigid_ground(moving_mass(M), _ramp(), HHT(0.9), 1e-3, 0.0)
    bilateral = _rigid_ground(moving_mass(M), _ramp(), "Newmark", 1e-3, 0.06, contact="bilateral")
    assert bilateral.train.v[0] == pytest.approx(V * SLOPE, rel=1e-9)


@pytest.mark.parametrize("dt", [1e-3, 2.5e-4, 6.25e-5])
@pytest.mark.parametrize("integrator", [HHT(0.9), "Bathe", GeneralizedAlpha()], ids=["HHT0.9", "Bathe", "GenAlpha"])
@pytest.mark.parametrize("contact", ["lcp", "bilateral"])
def test_wheel_follows_a_ramp_from_its_kink(contact, integrator, dt):
    """No flight; velocity V s after the kink; λ = m g on the ramp; Σ (λ − m g) Δt around the
    kink = m V s (measured: exact to 1e-9 for each scheme and Δt)."""
    a = _rigid_ground(moving_mass(M), _ramp(), integrator, dt, 0.06, contact=contact, exact_events=True)
    t, lam = a.time, a.contact_force[:, 0]
    k = int(np.searchsorted(t, X_KINK / V - 1e-12))              # the step holding the kink
    assert a.contact_events() == [] and a.gap.max() == 0.0
    assert a.contact_summary().unloading_ratio[0] < 1e-9
    impulse = (lam[k - 3: k + 4] - M * GRAVITY).sum() * dt
    assert impulse == pytest.approx(M * V * SLOPE, rel=1e-6)
    np.testing.assert_allclose(lam[k + 1:], M * GRAVITY, rtol=1e-9)
    np.testing.assert_allclose(lam[:k], M * GRAVITY, rtol=1e-9)
    assert a.train.v[0] == pytest.approx(V * SLOPE, rel=1e-9)


@pytest.mark.parametrize("integrator", [HHT(0.9), "Bathe", GeneralizedAlpha()], ids=["HHT0.9", "Bathe", "GenAlpha"])
def test_a_crest_still_throws_the_wheel(integrator):
    """At the crest (the line falls away) the wheel flies: lift-off in the crest's step, the
    free parabola from there, landing on the flat part near the closed form (measured at 0.25
    ms: flight error 2.1e-5 m, landing −6e-5 / −1.2e-4 / −6e-5 s), one flight only (the up-ramp's
    kink at x1 no longer throws it off)."""
    s, x1, xc, dt = 0.005, 1.0, 2.0, 2.5e-4
    height, t_lift = s * (xc - x1), xc / V
    t_land = t_lift + (s * V + np.sqrt((s * V) ** 2 + 2 * GRAVITY * height)) / GRAVITY
    a = _rigid_ground(moving_mass(M), _crest(s, x1, xc), integrator, dt, 0.15, exact_events=True)
    events = a.contact_events()
    assert [e.kind for e in events] == ["lift-off", "landing"]
    assert t_lift <= events[0].time <= t_lift + dt
    assert events[1].time == pytest.approx(t_land, abs=2e-4)
    t = a.time
    fly = (t > t_lift + dt) & (t < t_land - 2e-4)
    u = a.gap[fly, 0] + np.where(V * t[fly] <= 2 * xc - x1, s * (2 * xc - x1 - V * t[fly]), 0.0)
    free = height + s * V * (t[fly] - t_lift) - 0.5 * GRAVITY * (t[fly] - t_lift) ** 2
    assert np.abs(u - free).max() < 5e-5


def test_sprung_car_over_the_ramp_lcp_is_bilateral():
    """A sprung car (10 t on 1 MN/m, 20 kN·s/m, 1.8 t wheel) over the ramp: no flight under
    contact='lcp', and the records are the bilateral analysis's (the same events and steps)."""
    car = sprung_mass(10000.0, 1e6, 2e4, M)
    runs = [_rigid_ground(car, _ramp(), HHT(0.9), 5e-4, 0.2, contact=c, exact_events=True) for c in ("lcp", "bilateral")]
    assert runs[0].contact_events() == [] and runs[0].gap.max() == 0.0
    np.testing.assert_allclose(runs[0].contact_force, runs[1].contact_force, rtol=0, atol=1e-6 * M * GRAVITY)
    np.testing.assert_allclose(runs[0].train.u, runs[1].train.u, rtol=0, atol=1e-12)


def _s3_over(profile, contact, integrator="Newmark", dt=1e-3, exact_events=True, steps=150):
    model = vtsi.Model()
    bridge, train, x0 = s3_model(model, 10)
    con = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x0), irregularity=profile)
    a = CoupledAnalysis(model, con, integrator, dt=dt, contact=contact, exact_events=exact_events)
    a.static()
    a.run(steps)
    return a


def test_a_kink_on_the_moving_rail_is_not_an_event():
    """Within a span the bridge takes a share of the kink's impulse, which the event (the car's
    alone) does not model (measured on S3, a 0.3 % ramp at x = 12.3 m: midspan deflection 12.7 %
    of its maximum off, whatever Δt): contact='lcp' refuses it, bilateral leaves it to the step,
    its records those of the kink undeclared to the bit."""
    with pytest.raises(AnalysisError, match=r"kinks at x = 12.3 m on the track where the rail moves .*'bspline'"):
        _s3_over(_ramp(12.3, 0.003, kinks=(12.3,)), "lcp", HHT(0.9))
    runs = [_s3_over(_ramp(12.3, 0.003, kinks=kinks), "bilateral") for kinks in ((12.3,), ())]
    assert np.array_equal(runs[0].contact_force, runs[1].contact_force)
    assert np.array_equal(runs[0].train.u, runs[1].train.u)


def test_two_kinks_in_one_step_put_the_wheel_back_once():
    """A 2 cm ramp (0.5 %) at 30 m/s: at Δt = 1 ms a wheel crosses both its kinks in one step.
    Its old line went back by the two shifts summed (6 cm), and its car's velocity at 0.1 s read
    22.8 % off, worse than without events (19.8 %); back once, before the first kink, it is no
    worse than the step (the kinks closer than V Δt are resolved as without events), and at 0.5 ms
    (one kink a step) within 0.01 %."""
    car = sprung_mass(10000.0, 1e6, 2e4, 1800.0)
    x1, x2 = X_KINK, X_KINK + 0.02
    short = Irregularity.from_function(lambda x: SLOPE * (np.clip(np.asarray(x, float), x1, x2) - x1),
                                       lambda x: np.where((np.asarray(x, float) >= x1) & (np.asarray(x, float) < x2),
                                                          SLOPE, 0.0), _zero, kinks=(x1, x2))
    ref = _rigid_ground(car, short, HHT(0.9), 2e-4, 0.1, contact="bilateral", exact_events=True).train.v[0]

    def error(dt, events):
        run = _rigid_ground(car, short, HHT(0.9), dt, 0.1, contact="bilateral", exact_events=events)
        return abs(run.train.v[0] - ref) / abs(ref)

    assert error(1e-3, True) <= error(1e-3, False) + 1e-3
    assert error(5e-4, True) < 1e-4
