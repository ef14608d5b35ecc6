"""The train catalogue (models/catalogue.py), HSLM-B, ICE3 axle loads and Train.characteristic_length.

Every catalogue train is built at every fidelity it supports and its geometry and total load are
checked: HSLM-A against EN 1991-2 Table 6.3 (totals 7140 kN for A5 … 9600 kN for A2, the range
the standard states), HSLM-B as N × 170 kN, ICE3 as the trainset's weight.
"""
import numpy as np
import pytest

from vtsi.errors import ModelError
from vtsi.models import GRAVITY, Train, catalogue_train, hslm_a, hslm_b, ice3, ice3_axle_loads, train_names
from vtsi.models import catalogue
from vtsi.models.trains import hslm_b_parameters

# EN 1991-2 Table 6.3: N coaches, D coach length [m], d bogie axle spacing [m], P axle load [kN]
HSLM_A = {1: (18, 18, 2.0, 170), 2: (17, 19, 3.5, 200), 3: (16, 20, 2.0, 180), 4: (15, 21, 3.0, 190),
          5: (14, 22, 2.0, 170), 6: (13, 23, 2.0, 180), 7: (13, 24, 2.0, 190), 8: (12, 25, 2.5, 190),
          9: (11, 26, 2.0, 210), 10: (11, 27, 2.0, 210)}
ICE3_CAR_MASS = 47800 + 2 * 3500 + 4 * 1800     # body + 2 bogies + 4 wheelsets [kg] (TTB-2D)
SPEED = 300 / 3.6
SPANS_B = (1.0, 4.0, 6.999)

CASES = [(name, fidelity) for name in train_names() for fidelity in catalogue.fidelities(name)]


def test_names_and_fidelities():
    assert train_names() == [f'HSLM-A{i}' for i in range(1, 11)] + ['HSLM-B', 'ICE3']
    assert catalogue.FIDELITIES == ('force', 'full')
    assert all(catalogue.fidelities(name) == ('force',) for name in train_names()[:11])
    assert catalogue.fidelities('ICE3') == ('force', 'full')
    assert catalogue.describe('HSLM-A3') == ('HSLM-A3: EN 1991-2 high-speed load model, 16 coaches D = 20 m, '
                                             '46 axles of 180 kN')
    assert 'N forces of 170 kN at spacing d' in catalogue.describe('hslm-b')
    assert catalogue.describe('ice3').startswith('ICE3: 8-car ICE3/AVE S103, 32 axles, 10-dof cars')


@pytest.mark.parametrize('name, fidelity', CASES)
def test_every_train_builds_at_every_fidelity(name, fidelity):
    spans = SPANS_B if name == 'HSLM-B' else (None,)
    for span in spans:
        train = catalogue_train(name, SPEED, fidelity=fidelity, span=span)
        assert isinstance(train, Train) and train.speed == SPEED
        x, P = train.wheel_offsets, train.static_wheel_loads
        if fidelity == 'force':
            assert train.n_dof == 0 and np.all(train.force_wheels)
        if name.startswith('HSLM-A'):
            N, D, d, Pk = HSLM_A[int(name[6:])]
            assert train.name == name and train.n_wheels == 2 * N + 14
            np.testing.assert_allclose(P, Pk * 1e3)
            assert P.sum() == pytest.approx((2 * N + 14) * Pk * 1e3, rel=1e-14)
            np.testing.assert_allclose(np.diff(x[6:-6:2]), D, atol=1e-12)
            assert train.characteristic_length == D
        elif name == 'HSLM-B':
            N, d = hslm_b_parameters(span)
            assert train.name == 'HSLM-B' and train.n_wheels == N
            np.testing.assert_allclose(x, d * np.arange(N), atol=1e-12)
            assert P.sum() == pytest.approx(N * 170e3, rel=1e-14)
            assert train.characteristic_length == pytest.approx(d, rel=1e-15)
        else:
            reference = ice3(8, speed=SPEED)
            np.testing.assert_array_equal(x, reference.wheel_offsets)
            assert train.n_wheels == 32 and train.n_dof == (80 if fidelity == 'full' else 0)
            assert P.sum() == pytest.approx(8 * ICE3_CAR_MASS * GRAVITY, rel=1e-12)
            assert train.characteristic_length == pytest.approx(24.775, abs=1e-12)


def test_hslm_a_totals_match_en_1991_2_range():
    """EN 1991-2 (Table 6.3, Figure 6.12): total load 7140 kN (A5) to 9600 kN (A2)."""
    totals = {n: catalogue_train(f'A{n}', SPEED).static_wheel_loads.sum() / 1e3 for n in HSLM_A}
    assert min(totals, key=totals.get) == 5 and totals[5] == pytest.approx(7140, abs=1e-9)
    assert max(totals, key=totals.get) == 2 and totals[2] == pytest.approx(9600, abs=1e-9)


@pytest.mark.parametrize('span, N, d', [(1.0, 20, 2.5), (7.0 - 1e-9, 10, 3.5), (4.0, 15, 3.0),
                                        (3.1, 17, 2.85)])   # 16.5 rounds half up to 17
def test_hslm_b_figure_end_points_and_rounding(span, N, d):
    """EN 1991-2 Figure 6.13 as implemented in models/trains.py (N 20 -> 10, d 2.5 -> 3.5 m over
    1 <= L < 7 m). Not checked against the printed figure (docs/trains.md); these values pin the
    implemented law so that a correction is a deliberate change."""
    assert hslm_b_parameters(span) == (N, pytest.approx(d, abs=1e-8))
    train = hslm_b(span, SPEED)
    assert train.n_wheels == N and train.static_wheel_loads.sum() == pytest.approx(N * 170e3)
    np.testing.assert_allclose(np.diff(train.wheel_offsets), d, atol=1e-8)


@pytest.mark.parametrize('span', [0.99, 7.0, 12.0, -1.0, float('nan'), 'long'])
def test_hslm_b_refuses_spans_outside_the_figure(span):
    with pytest.raises(ModelError, match=r"hslm_b: span L = .* m is outside .* 1 m <= L < 7 m") as err:
        hslm_b(span, SPEED)
    assert repr(span) in str(err.value)


def test_ice3_axle_loads():
    full, forces = ice3(8, speed=SPEED), ice3_axle_loads(speed=SPEED)
    np.testing.assert_array_equal(forces.wheel_offsets, full.wheel_offsets)
    np.testing.assert_array_equal(forces.static_wheel_loads, full.static_wheel_loads)
    translational = [i for i, dof in enumerate(full.dof_names) if dof.endswith('_y')]
    mass = full.M.diagonal()[translational].sum()
    assert mass == pytest.approx(8 * ICE3_CAR_MASS, rel=1e-14)
    assert forces.static_wheel_loads.sum() == pytest.approx(mass * GRAVITY, rel=1e-14)
    assert forces.name == 'ICE3 axle loads' and forces.n_dof == 0
    short = ice3_axle_loads(3, speed=SPEED)
    np.testing.assert_array_equal(short.wheel_offsets, ice3(3, speed=SPEED).wheel_offsets)


@pytest.mark.parametrize('alias', ['hslm-a3', 'HSLM-A3', 'a3', ' Hslm-A3 '])
def test_lookup_is_case_insensitive(alias):
    assert catalogue_train(alias, SPEED).name == 'HSLM-A3'
    assert catalogue_train('ice3', SPEED, fidelity='full').n_dof == 80
    assert catalogue_train('b', SPEED, span=2.0).name == 'HSLM-B'


def test_bad_name_fidelity_and_span():
    with pytest.raises(ModelError, match=r"unknown train 'HSLM-C'; valid names: HSLM-A1, .*, HSLM-B, ICE3") as err:
        catalogue_train('HSLM-C', SPEED)
    assert '\n' not in str(err.value)
    with pytest.raises(ModelError, match="unknown train 'A11'"):
        catalogue.describe('A11')
    with pytest.raises(ModelError, match=r"train 'HSLM-A3' has no fidelity 'full'; it supports \['force'\]"):
        catalogue_train('a3', SPEED, fidelity='full')
    with pytest.raises(ModelError, match=r"unknown fidelity 'exact' .* valid: \['force', 'full'\]"):
        catalogue_train('ICE3', SPEED, fidelity='exact')
    with pytest.raises(ModelError, match=r"'HSLM-B' needs the span \[m\] .* got span=None"):
        catalogue_train('HSLM-B', SPEED)
    with pytest.raises(ModelError, match=r"span L = 9.5 m is outside"):
        catalogue_train('HSLM-B', SPEED, span=9.5)
    with pytest.raises(ModelError, match="speed must be finite and >= 0, got -1"):
        catalogue_train('ICE3', -1.0)


def test_csv_path_lookup(tmp_path):
    path = tmp_path / 'loco.csv'
    path.write_text('position_m,load_kN\n0,200\n3.0,200\n14.5,150\n')
    for name in (str(path), path):
        train = catalogue_train(name, 50.0, span=3.0)      # span is ignored by non-HSLM-B trains
        np.testing.assert_array_equal(train.wheel_offsets, [0.0, 3.0, 14.5])
        np.testing.assert_array_equal(train.static_wheel_loads, [2e5, 2e5, 1.5e5])
        assert train.characteristic_length is None and train.speed == 50.0
    assert catalogue.fidelities(str(path)) == ('force',)
    assert 'axle table from CSV' in catalogue.describe(path)
    with pytest.raises(ModelError, match=r"has no fidelity 'full'; it supports \['force'\]"):
        catalogue_train(str(path), 50.0, fidelity='full')
    with pytest.raises(ModelError, match=r"axle table '.*missing.csv' is not an existing file"):
        catalogue_train(str(tmp_path / 'missing.csv'), 50.0)


def test_characteristic_length_validation_and_pass_through(tmp_path):
    assert Train.from_axle_table([0.0, 3.0], [1e5, 1e5], 20.0).characteristic_length is None
    assert Train.from_axle_table([0.0, 3.0], [1e5, 1e5], 20.0, characteristic_length=3).characteristic_length == 3.0
    path = tmp_path / 't.csv'
    path.write_text('position_m;load_kN\n0;100\n2.5;100\n')
    assert Train.from_csv(path, 20.0, characteristic_length=2.5).characteristic_length == 2.5
    assert hslm_a(7, 20.0).characteristic_length == 24.0
    for bad in (0.0, -3.0, float('nan'), float('inf'), 'abc', True):
        with pytest.raises(ModelError, match=rf"train 'axle table': characteristic_length must be .* got {bad!r}"):
            Train.from_axle_table([0.0, 3.0], [1e5, 1e5], 20.0, characteristic_length=bad)
    with pytest.raises(ModelError, match="train 'x': characteristic_length .* got -1"):
        Train.from_csv(path, 20.0, name='x', characteristic_length=-1)


def test_registry_refuses_duplicates_and_unknown_fidelities():
    build = {'force': lambda speed, span: hslm_a(1, speed)}
    with pytest.raises(ModelError, match="train 'hslm-a1' is already registered"):
        catalogue.register(catalogue.Entry('hslm-a1', 'dup', build))
    with pytest.raises(ModelError, match=r"fidelities \['exact'\]"):
        catalogue.register(catalogue.Entry('new', 'x', {'exact': build['force']}))
    assert 'new' not in train_names()


def test_with_speed_copies_the_train_at_another_speed():
    """Train.with_speed: the same cars and arrays (shared, read-only), the new speed; the
    original is unchanged; a bad speed names the train."""
    train = catalogue_train('ICE3', 50.0, fidelity='full')
    fast = train.with_speed(80.0)
    assert fast.speed == 80.0 and train.speed == 50.0
    assert fast.wheel_offsets is train.wheel_offsets and fast.cars is train.cars
    with pytest.raises(ModelError, match="ICE3.*speed"):
        train.with_speed(-1.0)
