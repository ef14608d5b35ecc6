"""The check's car rows (car-body acceleration, wheel unloading, contact loss) on an irregular rail:
what the bridge does, counted on its decks; the time step they need; their histories and labels."""
import numpy as np
import pytest

from vtsi.check import check, stored_check
from vtsi.passage import (CAR_APPROACH, CONTACT_FORCE_WINDOW, HISTORY_OUTPUTS, Output, PassageSettings, body_runout,
                          contact_force_mean, contact_force_reach, rail_frequency_hz, windowed_envelope)
from vtsi.places import car_label, wheel_label
from vtsi.recorders.envelope import Envelope
from vtsi.report import write_report
from vtsi.sweep import Sweep, beam_bridge

L, MU = 20.0, 15000.0


def _bridge(f1=5.0, elements=10):
    EI = MU * (2 * np.pi * f1 * (L / np.pi) ** 2) ** 2
    return beam_bridge([L], EI, 1.0, MU, elements_per_span=elements)


def _irregular(dt=1e-3, rail="german-high", **kwargs):
    """The probe's settings, and its 25 m approach (CAR_APPROACH; the default on an irregular rail
    is now far longer, tests/test_car_approach.py): the rows' counting, not the cars' start, is
    what these tests read."""
    return PassageSettings(dt=dt, damping=0.013, cars="full", contact="lcp", irregularity=rail,
                           **{"approach": CAR_APPROACH, **kwargs})


@pytest.fixture(scope="module")
def rough(tmp_path_factory):
    """ICE3 at 300 km/h over a 20 m, 5 Hz span on a 'german-high' rail (seed 0), Δt = 1 ms: the
    probe's case (/tmp/probe_cars/repro_offbridge.sh)."""
    path = tmp_path_factory.mktemp("cars") / "rough.h5"
    sweep = Sweep(_bridge(), ["ICE3"], "300", _irregular(), seeds=[0])
    return sweep, path, sweep.run(path, workers=1, progress=False)


def test_the_car_rows_count_the_bridge_and_name_the_larger_peak_off_it(rough):
    """Before, the rows read the whole run, most of it rigid ground: ΔQ/Q 0.2363 with the wheel at
    x = 110.2 m and a car body's 1.013 m/s² with the head at x = 213 m (the bridge x = 0 to 20 m;
    an almost rigid bridge gave 0.240 and 1.003). Now they count a wheel on the deck (within the
    10 ms mean's reach) and a car body while a wheel of it is on the deck and half a period of its
    lowest mode after; the whole run's peaks are named in the notes."""
    _, path, res = rough
    result = check(res)
    unloading, body, loss = (result.row(k) for k in ("wheel_unloading", "car_body_acceleration", "contact_loss"))
    assert unloading.value == pytest.approx(0.1525, abs=5e-4)
    assert unloading.where == "wheel 4 of 32 (car 1 of 8), x = 6.4 m"
    assert "the largest over the whole run, 0.2363 (ICE3 300 km/h seed 0, wheel 3 of 32 (car 1 of 8), x = 110.2 m), " \
           "is off the bridge" in unloading.note
    assert body.value == pytest.approx(0.8024, abs=5e-4) and body.where == "car 2 of 8"
    # the ground's peak at x = 164.9 to 184.8 m: car 2 reaches it at 2.815 s, car 4 (1.01283 against car 2's
    # 1.01275) at 3.409 s, after the run's old end (3.160 s), inside the run that holds the last car's run-out
    assert "the largest over the whole run, 1.013 m/s^2 (ICE3 300 km/h seed 0, car 4 of 8, its wheels at x = 164.9 " \
           "to 184.8 m), is off the bridge" in body.note
    assert "for 0.622 s after its last wheel left it" in body.note
    assert loss.value == 0.0 and "0 of 1 passages" in result.text()
    assert "not converged in dt" not in unloading.note + body.note + loss.note      # 1 ms resolves 3 m at 300 km/h
    whole, _ = res.column_envelopes("contact_force", whole_run=True)
    bridge, _ = res.column_envelopes("contact_force")
    assert np.all(whole[..., 0, :] <= bridge[..., 0, :]) and np.nanmin(whole[..., 0, :]) < np.nanmin(bridge[..., 0, :])
    result.store(path)
    assert stored_check(path).text() == result.text()


def test_what_counts_is_where_the_wheels_are(rough):
    """PassageRunner.counted against the wheels' positions: a wheel's mean while x is within its
    reach V m Δt of the deck's ends, a car body from its first wheel on the deck to its last wheel's
    exit plus its run-out; the windowed envelope equals Envelope's where everything counts."""
    sweep = rough[0]
    runner = sweep.runner
    train = runner.train("ICE3", 300 / 3.6)
    x0, dt = runner.start_position(train), runner.settings.dt
    t = dt * np.arange(1, runner.n_steps(train) + 1)
    wheels = runner.counted(Output("f", "contact_force"), train, x0, t)
    reach = contact_force_reach(dt) * train.speed                  # 5 ms at 83.3 m/s: 0.417 m
    assert reach == pytest.approx(5e-3 * 300 / 3.6)
    x = x0 + train.speed * t[:, None] - train.wheel_offsets[None, :]
    np.testing.assert_array_equal(wheels, (x >= -reach - 1e-9) & (x <= L + reach + 1e-9))
    bodies = runner.counted(Output("b", "car_body_accel"), train, x0, t)
    runout = body_runout(train.cars[0])
    assert runout == pytest.approx(0.5 / 0.8037, rel=1e-3)         # half a period of the coach's bounce (0.804 Hz)
    car = train.wheel_car == 1
    first = (0.0 - x0 + train.wheel_offsets[car].min()) / train.speed
    last = (L - x0 + train.wheel_offsets[car].max()) / train.speed + runout
    inside = (t >= first - dt) & (t <= last + dt)
    assert np.all(bodies[:, 1] <= inside) and bodies[:, 1].sum() >= inside.sum() - 3
    rng = np.random.default_rng(1)
    values = rng.normal(size=(50, 3))
    env = Envelope(3)
    env.update(t[:50], values)
    np.testing.assert_array_equal(windowed_envelope(t[:50], values, np.ones((50, 3), bool)),
                                  [env.min, env.max, env.absmax, env.time_of_min, env.time_of_max, env.time_of_absmax])
    some = np.zeros((50, 3), bool)
    some[10:20, 1] = True
    part = windowed_envelope(t[:50], values, some)
    assert np.all(np.isnan(part[:, 0])) and part[0, 1] == values[10:20, 1].min()


def test_a_smooth_rail_keeps_its_car_rows():
    """On a smooth rail everything the cars feel comes from the bridge, and the peaks lie on it:
    counting the bridge only changes nothing (ICE3 over 20 m spans of 3 and 5 Hz, 140-360 km/h:
    the same to 1e-13). Here: the envelopes equal their whole-run ones."""
    res = Sweep(_bridge(3.0, elements=4), ["ICE3"], "300", PassageSettings(dt=2e-3, damping=0.013, cars="full")
                ).run(None, workers=1, progress=False)
    for name, row in (("contact_force", 0), ("car_body_acceleration", 2)):
        np.testing.assert_allclose(res.column_envelopes(name)[0][..., row, :],
                                   res.column_envelopes(name, whole_run=True)[0][..., row, :], rtol=1e-12)
    assert "whole run" not in check(res).row("wheel_unloading").note


def test_the_time_step_resolves_the_rails_shortest_wavelength():
    """The rail's 3 m at the top speed gets 20 steps a period by default (1 ms does up to 540 km/h);
    a coarser dt is noted in the car rows. Before, dt = 10 ms passed on 'fra-1' with contact_loss 0
    PASS (1 passage of 4 lifts on the bridge at 1 ms); 'german-high' at 300 km/h read ΔQ/Q 0.094
    at 10 ms, 0.149 at 1.8 ms, 0.154 at 0.25 ms."""
    assert rail_frequency_hz("german-high", "full", 300.0) == pytest.approx(300 / 3.6 / 3.0)
    assert rail_frequency_hz(None, "full", 300.0) is None and rail_frequency_hz("fra-1", "force", 300.0) is None
    # ζ = 8 %: the deck's own bound at its 45.8 Hz cut-off, sqrt(1.2 ζ) / (2π f) = 1.08 ms, leaves 1 ms
    fast = Sweep(_bridge(elements=4), ["ICE3"], "600", PassageSettings(cars="full", irregularity="german-low",
                                                                       damping=0.08))
    assert fast.settings.dt == 5e-4                                    # 600 km/h: 55.6 Hz, 1/20 of it 0.9 ms
    assert Sweep(_bridge(elements=4), ["ICE3"], "600", PassageSettings(cars="full", damping=0.08)).settings.dt == 1e-3
    assert Sweep(_bridge(elements=4), ["ICE3"], "600", PassageSettings(cars="full")).settings.dt == 2.5e-4  # ζ 0.5 %
    coarse = Sweep(_bridge(elements=4), ["ICE3"], "300", _irregular(dt=5e-3, rail="german-low"), seeds=[0])
    default = Sweep(_bridge(elements=4), ["ICE3"], "300", _irregular(dt=None, rail="german-low"), seeds=[0]).settings.dt
    assert default < 1e-3                               # the deck's cut-off asks more than the rail
    result = check(coarse.run(None, workers=1, progress=False))
    for criterion in ("car_body_acceleration", "wheel_unloading", "contact_loss"):
        assert "not converged in dt: dt = 5 ms steps the rail's shortest wavelength (3 m) at the top speed, 300 " \
               "km/h (27.8 Hz), 7.2 times a period" in result.row(criterion).note, criterion
        assert result.row(criterion).note.endswith(
            "take dt <= 1 ms (the rail's 20 steps a period; the default of this bridge and sweep, "
            f"{1e3 * default:g} ms, is finer: it also resolves the deck's cut-off)")


def test_a_coarse_step_on_an_irregular_rail_runs():
    """300 km/h at dt = 19 ms passed validation, then every passage failed: the profile was
    sampled 5 + 1 m beyond the wheels, less than the B-spline rows' reach 4 V dt = 6.3 m."""
    res = Sweep(_bridge(elements=4), ["ICE3"], "300", _irregular(dt=0.019, rail="german-low"), seeds=[0]
                ).run(None, workers=1, progress=False)
    assert res.n_done == 1 and np.isfinite(res.critical("contact_force_min")["value"])


def test_histories_of_cars_keep_their_bodies_and_the_report_draws_them(rough, tmp_path):
    """record_histories kept the deck and the contact forces only: the report's section of the case
    that governs car_body_acceleration showed no car body."""
    sweep, path, res = rough
    assert "car_body_acceleration" in {o.name for o in HISTORY_OUTPUTS}
    result = check(res)
    result.store(path)
    recorded = sweep.record_histories(path, [("ICE3", 300, 0)])
    time, values, columns = recorded.history("ICE3", 300, 0)["car_body_acceleration"]
    assert values.shape == (len(time), 8) and list(columns) == list(range(8))
    assert np.max(np.abs(values)) == pytest.approx(1.0127, abs=1e-3)              # the whole run, ground included
    text = write_report(path, tmp_path / "report")["markdown"].read_text()
    assert "the car bodies' vertical acceleration [m/s²]" in text
    assert "black: car 2 of 8, the largest on the bridge" in text
    assert "black: wheel 4 of 32 (car 1 of 8), the lowest on the bridge" in text
    assert "| wheel 4 of 32 (car 1 of 8), x = 6.4 m |" in text and "| 0 of 1 passages |" in text


def test_labels_count_from_one():
    data = {"contact_wheels": np.arange(32), "wheel_car": np.repeat(np.arange(8), 4), "n_cars": 8}
    assert car_label(0, 8) == "car 1 of 8 (the leading car)" and car_label(7, 8) == "car 8 of 8 (the last car)"
    assert car_label(1, 8) == "car 2 of 8" and car_label(0, 1) == "car 1 of 1"
    assert wheel_label(2, data) == "wheel 3 of 32 (car 1 of 8)" and wheel_label(31, data) == "wheel 32 of 32 (car 8 of 8)"


@pytest.mark.parametrize("dt", [2e-3, 1e-3, 5e-4, 2.5e-4])
def test_the_contact_force_mean_cancels_a_ringing_at_2dt_up_to_the_record_ends(dt):
    """Newmark's rows may ring at period 2Δt (±500 kN under an ICE3 on a span with approaches on
    springs): the 10 ms mean cancels it everywhere. Repeating the last sample beyond the record
    did not (the mean fell to −112 kN in the last 5 samples: a false whole-run ΔQ/Q of 1.74);
    mirrored, a ramp's mean is off by less than its slope times the window at the ends only."""
    k = np.arange(400)
    slope = 10.0                                            # [N per step]
    smooth = 152e3 + slope * k
    mean = contact_force_mean((smooth + 500e3 * (-1.0) ** k)[:, None], dt)[:, 0]
    reach = int(np.ceil(0.5 * max(CONTACT_FORCE_WINDOW, 2 * dt) / dt))
    assert np.abs(mean - smooth)[reach:-reach].max() < 1e-9 * smooth.max()
    assert np.abs(mean - smooth).max() <= slope * reach
