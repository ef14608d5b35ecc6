"""A car body's counting window lies inside the run (vtsi.passage.PassageRunner.n_steps).

A car body counts while a wheel of its car is on a deck and for its run-out after
(vtsi.passage.body_runout: half a period of its lowest mode, 0.62 s for an ICE3 coach). The run
used to end 1.5 periods of n0 after the last wheel left the track (0.3 s for a 5 Hz span), which
cut the last car's window short: its envelope missed what came after, and the report drew the
window's end past the data. The windows below are computed from the wheels' positions, the deck's
ends and body_runout, not read from the runner's rule."""
import math

import h5py
import numpy as np
import pytest

from vtsi.errors import SweepError
from vtsi.passage import CAR_APPROACH, DEFAULT_OUTPUTS, FREE_VIBRATION_PERIODS, HISTORY_OUTPUTS, Output, PassageSettings, body_runout
from vtsi.report import _figure, _Report
from vtsi.sweep import Sweep, beam_bridge

L, MU, F1 = 20.0, 15000.0, 5.0
CARS = PassageSettings(dt=2e-3, damping=0.013, cars="full")
BODIES = (Output("deflection", "disp"), Output("car_body_acceleration", "car_body_accel", history=True))


def _bridge():
    """A 20 m simply supported beam of 15 t/m with n0 = 5 Hz (f = π/(2L²) √(EI/μ)), 4 elements; the
    track is the beam (x = 0 to 20 m, no approaches): the deck ends where the track does."""
    EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
    return beam_bridge([L], EI, 1.0, MU, elements_per_span=4)


def _times(runner, train):
    """``(x_head0, the last wheel off the track [s], the last car's window end [s])``: wheel i is
    at x_head0 + V t − offset_i; the last car counts until its last wheel passes x = L plus its
    run-out."""
    x0, V = runner.start_position(train), train.speed
    off_track = (runner.track.x_end - x0 + train.wheel_offsets[-1]) / V
    last = train.wheel_car == len(train.cars) - 1
    return x0, off_track, (L - x0 + train.wheel_offsets[last].max()) / V + body_runout(train.cars[-1])


def _brackets(n, dt, end):
    """n is the fewest steps of dt reaching ``end`` [s] (to rounding)."""
    return (n - 1) * dt < end - 1e-9 and end <= n * dt + 1e-9


def test_the_last_car_bodys_window_ends_inside_a_passage_of_cars():
    sweep = Sweep(_bridge(), ["ICE3"], "300", CARS, outputs=BODIES)
    runner = sweep.runner
    train = runner.train("ICE3", 300 / 3.6)
    x0, off_track, window_end = _times(runner, train)
    assert runner.track.x_begin == 0.0 and runner.track.x_end == L
    assert body_runout(train.cars[-1]) == pytest.approx(0.5 / 0.8037, rel=1e-3)   # half the coach's 0.804 Hz bounce
    free = FREE_VIBRATION_PERIODS / runner.frequencies[0]
    assert off_track + free < window_end - 0.3            # the old end came 0.32 s before the window's
    n = runner.n_steps(train)
    dt = runner.settings.dt
    assert _brackets(n, dt, window_end)
    result = runner.run("ICE3", 300.0)
    assert result.n_steps == n
    t = result.histories["car_body_acceleration"][0]
    assert t[-1] == pytest.approx(n * dt) and t[-1] >= window_end - 1e-9
    counted = runner.counted(BODIES[1], train, x0, t)
    assert t[counted[:, -1]].max() > window_end - 2 * dt      # the last car counts to its window's end
    # free_vibration is the bridge's: 0 s still holds the window, 2 s (past it) is kept as it is
    for free_vibration, end in ((0.0, window_end), (2.0, off_track + 2.0)):
        other = Sweep(_bridge(), ["ICE3"], "300", PassageSettings(dt=2e-3, damping=0.013, cars="full",
                                                                 free_vibration=free_vibration), outputs=BODIES).runner
        assert _brackets(other.n_steps(other.train("ICE3", 300 / 3.6)), dt, end), free_vibration


@pytest.mark.parametrize("train, settings, outputs", [
    ("HSLM-A1", PassageSettings(dt=2e-3, damping=0.013), DEFAULT_OUTPUTS),          # moving forces (a car-body output
    ("ICE3", PassageSettings(dt=2e-3, damping=0.013), DEFAULT_OUTPUTS),              # that they do not produce)
    ("ICE3", CARS, (Output("deflection", "disp"), Output("contact_force", "contact_force")))])   # no car body read
def test_passages_without_car_bodies_keep_their_length(train, settings, outputs):
    """The last wheel off the track plus 1.5 periods of n0, as before the windows were held; a case
    re-run with the histories' outputs (Sweep.record_histories, a car body's among them) runs as
    long as the sweep's passage."""
    runner = Sweep(_bridge(), [train], "300", settings, outputs=outputs).runner
    built = runner.train(train, 300 / 3.6)
    _, off_track, _ = _times(runner, built)
    n = runner.n_steps(built)
    assert _brackets(n, settings.dt, off_track + FREE_VIBRATION_PERIODS / runner.frequencies[0])
    assert runner.run(train, 300.0).n_steps == n
    assert runner.run(train, 300.0, outputs=HISTORY_OUTPUTS).n_steps == n


def test_the_last_car_counts_its_peak_after_the_old_end():
    """ICE3 at 300 km/h, 'german-high' seed 3: the last car's largest |a| in its window, 0.902
    m/s², comes at 3.43 s, on the ground within its run-out, after the old end (3.16 s), before
    which it read 0.892. Its envelope is the peak of its governing point's history over its
    window, computed here from the wheels."""
    settings = PassageSettings(dt=2e-3, damping=0.013, cars="full", irregularity="german-high",
                               approach=CAR_APPROACH)    # the start these numbers were read with
    sweep = Sweep(_bridge(), ["ICE3"], "300", settings, seeds=[3], outputs=BODIES)
    runner = sweep.runner
    train = runner.train("ICE3", 300 / 3.6)
    x0, off_track, window_end = _times(runner, train)
    old_end = off_track + FREE_VIBRATION_PERIODS / runner.frequencies[0]
    result = runner.run("ICE3", 300.0, 3)
    t, governing = result.histories["car_body_acceleration"]
    last = train.wheel_car == len(train.cars) - 1
    first_on = (0.0 - x0 + train.wheel_offsets[last].min()) / train.speed
    window = (t >= first_on) & (t <= window_end)
    peak = np.abs(governing[window, -1])
    envelope = result.envelopes["car_body_acceleration"]
    assert envelope[2, -1] == np.max(peak)
    assert envelope[5, -1] > old_end
    assert np.max(peak[t[window] <= old_end]) < envelope[2, -1]     # the old run's part of it missed the peak


def test_a_window_past_the_data_is_drawn_within_it():
    """The report's chart draws a counting window's lines within the data only (histories of a
    sweep without a car-body output, or of an older vtsi, may end inside a car's window)."""
    time = np.linspace(0.01, 3.0, 300)
    values = np.stack([np.sin(time), np.cos(time)], axis=1)
    for counted, lines, label in (((1.0, 2.5), [1.0, 2.5], "while it counts"),
                                  ((1.0, 3.4), [1.0], "while it counts (past the run's end)")):
        with _figure((11, 3)) as (_, ax):
            _Report._one_among_many(ax, time, values, 1, "tab:blue", "car 2", counted)
            drawn = [line for line in ax.get_lines() if line.get_linestyle() == ":"]
            assert [line.get_xdata()[0] for line in drawn] == lines
            assert drawn[0].get_label() == label
            assert ax.get_xlim()[1] < 3.2              # no line past the data widens the axis


def test_a_file_of_the_old_run_length_is_not_resumed(tmp_path):
    """A results file of the same sweep whose cases ran the old length (the last wheel off the
    track plus 1.5 periods of n0) would mix two rules: refused, naming the file, the case and both
    lengths. The file as this vtsi wrote it resumes."""
    path = tmp_path / "cars.h5"
    sweep = Sweep(_bridge(), ["ICE3"], "300", CARS, outputs=BODIES)
    sweep.run(path, workers=1, progress=False)
    assert Sweep(_bridge(), ["ICE3"], "300", CARS, outputs=BODIES).run(path, workers=1, progress=False,
                                                                       resume=True).n_done == 1
    runner = sweep.runner
    _, off_track, _ = _times(runner, runner.train("ICE3", 300 / 3.6))
    old = math.ceil((off_track + FREE_VIBRATION_PERIODS / runner.frequencies[0]) / CARS.dt - 1e-9)
    new = runner.n_steps(runner.train("ICE3", 300 / 3.6))
    with h5py.File(path, "a") as f:                   # as a vtsi before the windows were held wrote it
        f["cases/n_steps"][0] = old
    with pytest.raises(SweepError, match=f"results file {path}: its passage of ICE3 at 300 km/h ran {old} steps, "
                                         f"this vtsi runs {new}: the file was written by a vtsi whose passages ran "
                                         r"another length \(since 2026-11-27 a sweep reading car bodies runs .*\), "
                                         "and resuming would mix passages of both"):
        Sweep(_bridge(), ["ICE3"], "300", CARS, outputs=BODIES).run(path, workers=1, progress=False, resume=True)
