"""Review probe 5's findings: the car rows at fewer than 4 steps a period of the rail, the default
approach of a lightly damped car, and the moment basis note of passages of cars."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

import vtsi.check as check_module
from vtsi.check import _moment_basis_note, _rail_step_note, check
from vtsi.errors import SettingError, SweepError
from vtsi.models import catalogue
from vtsi.models.cars import sprung_mass
from vtsi.models.trains import ice3
from vtsi.passage import CAR_APPROACH, MAX_SETTLE_TIME, PassageSettings
from vtsi.sweep import Sweep, beam_bridge
from vtsi.vehicle import Train

L, MU, F1 = 20.0, 15000.0, 5.0


def _bridge():
    return beam_bridge([L], MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2, 1.0, MU, elements_per_span=4)


def test_car_rows_at_fewer_than_4_steps_a_period_of_the_rail_are_not_checked():
    """dt = 10 ms at 300 km/h: 3.6 steps a period of the rail's 27.8 Hz. Before, the three rows
    passed. The rail sampled so coarsely reads the rows low by about 1 - cos(pi f dt) = 35.7 %:
    a FAIL stands, a PASS is not sure (not checked)."""
    settings = PassageSettings(dt=0.01, damping=0.013, cars="full", contact="lcp", irregularity="german-high",
                               approach=CAR_APPROACH)
    sweep = Sweep(_bridge(), ["ICE3"], "300", settings, seeds=[0])
    results = sweep.run(None, workers=1, progress=False)
    result = check(results)
    bound = 1.0 - math.cos(math.pi * 300 / 3.6 / 3.0 * 0.01)
    for criterion in ("car_body_acceleration", "wheel_unloading", "contact_loss"):
        row = result.row(criterion)
        assert row.status == "info", criterion
        assert f"; not checked: fewer than 4 steps a period of the rail's shortest wavelength may read it low by " \
               f"{100 * bound:.3g} % or so" in row.note, criterion
        assert "take dt <= 1 ms (the rail's 20 steps a period; the default of this bridge and sweep, 0.4 ms, is " \
               "finer" in row.note
    bridge = results.bridge()
    limit = 1.3
    assert _rail_step_note(results, bridge, limit * 1.01, limit, "fail")[0] == "fail"        # reads low: stands
    assert _rail_step_note(results, bridge, limit * (1 - bound) * 0.5, limit, "pass")[0] == "info"


def _mixed(zeta):
    def build(speed, span):
        base, k, m = ice3(2, speed=speed), 1.6e6, 40e3
        coach = sprung_mass(m, k, 2 * zeta * math.sqrt(k * m), 2e3, name="light coach")
        return Train(list(base.cars) + [coach], list(base.car_offsets) + [base.car_offsets[-1] + 30.0], speed,
                     name=f"G5MIX{zeta:g}")
    return build


@pytest.mark.parametrize("zeta", [1e-3, 0.0])
def test_a_lightly_damped_car_is_refused_by_the_default_approach(zeta, monkeypatch):
    """zeta 1e-3 at 1 Hz: sigma = 6.3e-3 1/s, 237 s to settle, 19.8 km before a 20 m bridge (before:
    silently run); undamped: refused by body_decay_rate, its rate printed 0, never -0."""
    name = f"G5MIX{zeta:g}"
    monkeypatch.setattr(catalogue, "_REGISTRY", dict(catalogue._REGISTRY))    # registered for this test only
    catalogue.register(catalogue.Entry(name, "mixed", {"full": _mixed(zeta)}))
    settings = PassageSettings(cars="full", irregularity="german-high", damping=0.013)
    with pytest.raises(SweepError if zeta == 0 else SettingError) as caught:
        Sweep(_bridge(), [name], [300], settings, seeds=[0])
    text = str(caught.value)
    assert "car 'light coach'" in text and "-0" not in text and "approach" in text
    if zeta:
        sigma = zeta * math.sqrt(1.6e6 / 40e3)
        assert caught.value.setting == "approach" and math.log(20) / 2 / sigma > MAX_SETTLE_TIME
        assert f"its 1.007 Hz mode with the wheels held decays at {sigma:.3g} 1/s" in text
        assert f"the default approach would be {20 + 300 / 3.6 * math.log(20) / 2 / sigma:.0f} m" in text
        assert "give the car damping" in text
        given = Sweep(_bridge(), [name], [300], PassageSettings(cars="full", irregularity="german-high",
                                                                damping=0.013, approach=50.0), seeds=[0])
        assert given.runner.approach(given.runner.train(name, 300 / 3.6)) == 50.0
    else:
        assert "decay rate 0 1/s" in text


@pytest.mark.parametrize("cars, said", [("force", "the static correction puts back only"),
                                        ("full", "get no static correction, so the higher modes' share is left out")])
def test_the_moment_basis_note_says_cars_get_no_static_correction(monkeypatch, cars, said):
    monkeypatch.setattr(check_module, "default_basis_hz", lambda results, bridge: 128.3)
    results = SimpleNamespace(identity={"settings": {"bridge": "modal", "modal_hz": 33.0, "cars": cars},
                                        "speeds_kmh": [420.0]})
    note = _moment_basis_note(results, {"frequencies_hz": np.array([5.0, 20.0, 45.0])})
    assert said in note and "modes stop at 33 Hz, below the 128.3 Hz" in note
