"""A car passage's work outside the compiled time loop, against the algorithms it replaced.

Each fast path is checked against the straightforward computation written out here: the rail
profile's chirp z-transform against the direct cosine sum, the contact forces' running
trapezoidal mean against scipy's convolve1d, the windowed envelope against np.where over every
sample, the counted samples and car-body points against their per-array versions, and the
smoothed rail's node values against one profile call per Gauss point.
"""
import functools
import math

import numpy as np
import pytest
from scipy.ndimage import convolve1d

import vtsi
from vtsi.constraint import MovingLoadConstraint, SmoothedProfile
from vtsi.errors import ModelError
from vtsi.models.irregularity import WAVELENGTH_BAND, Irregularity, german_psd, sample_profile
from vtsi.passage import (BODY_ON_TWO_SUPPORTS, PROFILE_BLOCK, PROFILE_STEP, Output, PassageSettings,
                          contact_force_mean, contact_force_reach, windowed_envelope)
from vtsi.sweep import Sweep, beam_bridge
from vtsi.models import Train, four_dof_car
from vtsi.models.bridges import simply_supported_beam
from vtsi.track import GAUSS_POINTS, GAUSS_WEIGHTS, Track, bspline_kernel
from vtsi.train import TrainSubdomain

PSD = functools.partial(german_psd, level="high")


def direct_profile(x, n_waves, seed):
    """Σ_k √(2 S ΔΩ) cos(Ω_k x + φ_k) summed directly (sample_profile's definition)."""
    w_lo, w_hi = 2 * np.pi / WAVELENGTH_BAND[1], 2 * np.pi / WAVELENGTH_BAND[0]
    d_omega = (w_hi - w_lo) / n_waves
    omega = w_lo + d_omega * (np.arange(n_waves) + 0.5)
    phase = np.random.default_rng(seed).uniform(0.0, 2.0 * np.pi, n_waves)
    return np.sqrt(2.0 * PSD(omega) * d_omega) @ np.cos(np.outer(omega, x) + phase[:, None])


@pytest.mark.parametrize("seed", [0, 1, 7, 12345])
@pytest.mark.parametrize("start", [-2 * PROFILE_BLOCK, 0, 3 * PROFILE_BLOCK])
def test_profile_on_a_grid_is_the_cosine_sum(seed, start):
    x = PROFILE_STEP * np.arange(start, start + 300)          # evenly spaced: the chirp z-transform
    r = sample_profile(PSD, x, n_waves=4000, rng=seed)
    ref = direct_profile(x, 4000, seed)
    assert np.max(np.abs(r - ref)) <= 1e-12 * np.max(np.abs(ref))
    assert np.max(np.abs(ref)) > 1e-3                           # a German 'high' rail: millimetres


def test_profile_off_a_grid_and_across_blocks():
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(-50.0, 400.0, 200))                  # uneven: summed directly
    assert np.max(np.abs(sample_profile(PSD, x, n_waves=1500, rng=4) - direct_profile(x, 1500, 4))) \
        <= 1e-12 * np.max(np.abs(direct_profile(x, 1500, 4)))
    # a sweep's fixed block, and a part of it sampled alone: the same profile to round-off
    block = PROFILE_STEP * np.arange(PROFILE_BLOCK, 2 * PROFILE_BLOCK)
    whole = sample_profile(PSD, block, n_waves=4000, rng=9)
    part = sample_profile(PSD, block[1000:1400], n_waves=4000, rng=9)
    assert np.max(np.abs(whole[1000:1400] - part)) <= 1e-12 * np.max(np.abs(whole))
    assert np.array_equal(whole, sample_profile(PSD, block, n_waves=4000, rng=9))


def reference_mean(forces, dt, window=0.01):
    m = max(1, int(np.floor(0.5 * window / dt + 0.5)))
    weights = np.ones(2 * m + 1)
    weights[[0, -1]] = 0.5
    return convolve1d(forces, weights / (2 * m), axis=0, mode="mirror")


@pytest.mark.parametrize("n", [1, 2, 3, 40, 41, 700, 3000])
@pytest.mark.parametrize("dt", [2.5e-4, 1e-3, 2e-3, 0.02])
def test_contact_force_mean_is_the_trapezoidal_convolution(n, dt):
    forces = 1.5e5 + 3e4 * np.random.default_rng(n).standard_normal((n, 5))
    mean = contact_force_mean(forces, dt)
    assert mean.shape == forces.shape
    assert np.array_equal(mean, reference_mean(forces, dt))         # the same sums, to the bit


def test_contact_force_mean_of_other_shapes_and_non_finite_values():
    forces = 1e5 * np.random.default_rng(1).standard_normal(2000)
    assert np.array_equal(contact_force_mean(forces, 5e-4), reference_mean(forces, 5e-4))
    assert contact_force_mean(np.zeros((0, 4)), 1e-3).shape == (0, 4)
    bad = 1e5 * np.random.default_rng(2).standard_normal((2000, 3))
    bad[100, 0], bad[700, 1], bad[900:905, 2] = np.nan, np.inf, -np.inf
    mean, ref = contact_force_mean(bad, 2.5e-4), reference_mean(bad, 2.5e-4)
    assert np.array_equal(mean, ref, equal_nan=True)
    with pytest.raises(ModelError, match="contact force mean: forces"):
        contact_force_mean(3.0, 1e-3)


def reference_envelope(time, values, counted):
    out = np.full((6, values.shape[1]), np.nan)
    if values.shape[0] == 0:
        return out
    columns, some = np.arange(values.shape[1]), counted.any(axis=0)
    for k, (source, fill, pick) in enumerate(((values, np.inf, np.argmin), (values, -np.inf, np.argmax),
                                              (np.abs(values), -np.inf, np.argmax))):
        at = pick(np.where(counted, source, fill), axis=0)
        out[k] = np.where(some, source[at, columns], np.nan)
        out[k + 3] = np.where(some, time[at], np.nan)
    return out


def test_windowed_envelope_is_the_whole_arrays_one():
    rng = np.random.default_rng(5)
    time = 1e-3 * np.arange(3000)
    values = np.round(rng.standard_normal((3000, 6)), 1)           # ties: the first one counts
    counted = np.zeros((3000, 6), dtype=bool)
    counted[1200:1500, 0] = counted[1400:2100, 1] = True
    counted[rng.integers(0, 3000, 40), 2] = True
    counted[:, 3] = True                                           # column 4: never counted
    counted[2999, 5] = True
    env = windowed_envelope(time, values, counted)
    assert np.array_equal(env, reference_envelope(time, values, counted), equal_nan=True)
    assert np.all(np.isnan(env[:, 4])) and not np.any(np.isnan(env[:, [0, 1, 2, 3, 5]]))
    assert np.all(np.isnan(windowed_envelope(time, values, np.zeros_like(counted))))
    assert windowed_envelope(time[:0], values[:0], counted[:0]).shape == (6, 6)


@pytest.fixture(scope="module")
def ice3():
    bridge = beam_bridge([20.0], E=3.5e10, I=1.2, mu=15000.0, damping=0.01)
    sweep = Sweep(bridge, ["ICE3"], [280.0], PassageSettings(cars="full", irregularity="german-high", damping=0.01),
                  seeds=[1])
    runner = sweep.runner
    train = runner.train("ICE3", 280.0 / 3.6)
    return runner, train, runner.start_position(train)


def reference_counted(runner, output, train, x_head0, t):
    x = x_head0 + train.speed * t[:, None] - np.asarray(train.wheel_offsets)[None, :]
    if output.response == "contact_force":
        return runner.on_deck(x[:, train.contact_wheels], margin=contact_force_reach(runner.settings.dt) * train.speed)
    on, runouts = runner.on_deck(x), runner.body_runouts(train)
    cars = runner.columns(output, train)
    out = np.zeros((len(t), len(cars)), dtype=bool)
    for c, i in enumerate(cars):
        last = np.maximum.accumulate(np.where(on[:, np.asarray(train.wheel_car) == i].any(axis=1), np.arange(len(t)), -1))
        out[:, c] = (last >= 0) & (t - t[np.maximum(last, 0)] <= runouts[i] * (1 + 1e-12) + 1e-12)
    return out


def test_counted_samples_and_car_body_points(ice3):
    runner, train, x_head0 = ice3
    t = runner.settings.dt * np.arange(runner.n_steps(train) + 1)
    for output in (Output("contact_force", "contact_force"), Output("body", "car_body_accel")):
        counted = runner.counted(output, train, x_head0, t)
        assert counted.any() and not counted.all()
        assert np.array_equal(counted, reference_counted(runner, output, train, x_head0, t))
    n_dofs = sum(2 if "body_rz" in train.cars[i].dof_names else 1 for i in runner.columns(output, train))
    values = np.round(np.random.default_rng(8).standard_normal((len(t), n_dofs)), 2)
    points = runner._body_points(train, values, counted)
    largest, governing, k = [], [], 0
    for c, i in enumerate(runner.columns(output, train)):
        car = train.cars[i]
        assert "body_rz" in car.dof_names and car.kind in BODY_ON_TWO_SUPPORTS
        offsets = car.wheel_offsets
        half = 0.5 * (np.mean(offsets[len(offsets) // 2:]) - np.mean(offsets[: len(offsets) // 2]))
        three = np.stack([values[:, k], values[:, k] + half * values[:, k + 1], values[:, k] - half * values[:, k + 1]])
        k += 2
        largest.append(np.take_along_axis(three, np.argmax(np.abs(three), axis=0)[None], axis=0)[0])
        governing.append(int(np.argmax(np.max(np.abs(three[:, counted[:, c]]), axis=1))))
    assert np.array_equal(points.largest, np.stack(largest, axis=1))
    assert np.array_equal(points.point, governing)


def test_smoothed_rail_nodes_are_one_call_per_gauss_point():
    x = PROFILE_STEP * np.arange(-2000, 4000)
    rail = Irregularity(x, sample_profile(PSD, x, rng=1))
    profile = lambda z: rail(z, nu=0)
    table = SmoothedProfile(profile, 0.07, 0.0, -50.0, 300.0)
    grid = table.origin + np.arange(-1000, 5001, dtype=float) * table.step
    ref = np.zeros_like(grid)
    for k in range(4):
        for z, w in zip(GAUSS_POINTS, GAUSS_WEIGHTS):
            xi = (k - 1.5 + 0.5 * z) * table.knot
            ref += 0.5 * w * bspline_kernel(xi / table.knot) * np.asarray(profile(grid - xi), dtype=float)
    assert np.array_equal(table._node_values(profile, -1000, 5000), ref)


@pytest.mark.parametrize("interpolation", ["bspline", "hermite"])
def test_a_profile_of_one_value_holds_everywhere_and_another_shape_is_named(interpolation):
    """A plain callable giving one number (a constant rail, ``lambda x: 0.001``) holds at every
    position, as before the smoothed rail's nodes were read in one call (which raised numpy's
    reshape error); one of another shape is refused naming both shapes, and a function of one
    number (math.sin: numpy's TypeError) is named so."""
    model = vtsi.Model()
    bridge = simply_supported_beam(model, L=30.0, n_elements=10, E=3.5e10, I=7.0, mu=3.0e4)
    car = four_dof_car(m_c=47800, J_c=1.96e6, m_w=7100, k_s=1.4e6, c_s=8e4, l_c=17.375)
    train = TrainSubdomain(Train([car], [0.0], speed=30.0), x_head0=-5.0)

    def tie(rail):
        return MovingLoadConstraint(Track(model, bridge.elements), train, interpolation=interpolation,
                                    irregularity=rail)

    rail = tie(lambda x: 0.001).irregularity_at(np.array([0.1, 0.2]), 1e-3)
    assert rail.shape == (2, 2) and np.max(np.abs(rail - 0.001)) <= 1e-15       # the B-spline's weights sum to 1
    with pytest.raises(ModelError, match=r"the irregularity gives values of shape \(3,\) for positions of shape "
                                         r"\((\d+,|2, 2)\): it must give one value \[m\] per position"):
        tie(lambda x: np.zeros(3)).irregularity_at(np.array([0.1, 0.2]), 1e-3)
    with pytest.raises(ModelError, match=r"the irregularity must take an array of positions \[m\] \(numpy functions, "
                                         r"or np.vectorize\): r\(x\) of .* positions \(x = .* m\) raised TypeError"):
        tie(lambda x: 1e-3 * math.sin(x)).irregularity_at(np.array([0.1, 0.2]), 1e-3)     # math, not numpy
    with pytest.raises(ModelError, match=r"must take an array of positions .* raised ValueError"):
        tie(lambda x: 1e-3 if x < 5 else 0.0).irregularity_at(np.array([0.1, 0.2]), 1e-3)     # a branch

    def measured(x):                    # vectorised, but raising on positions it has no data for
        raise ValueError("no data before x = 0")
    with pytest.raises(ModelError, match=r"the irregularity r\(x\) of .* positions \(x = -?[\d.]+ to [\d.]+ m\) "
                                         r"raised ValueError: no data before x = 0$"):
        tie(measured).irregularity_at(np.array([0.1, 0.2]), 1e-3)
