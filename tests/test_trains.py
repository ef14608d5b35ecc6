"""Trains: assembly, wheel kinematics, HSLM-A against EN 1991-2, ICE3 geometry, axle tables."""
import numpy as np
import pytest
import scipy.linalg

from vtsi.errors import ModelError
from vtsi.models import GRAVITY, Train, car_from_catalogue, four_dof_car, hslm_a, ice3, moving_force

# EN 1991-2 Table 6.3: N coaches, D coach length [m], d bogie axle spacing [m], P axle load [kN]
HSLM_A = {1: (18, 18, 2.0, 170), 2: (17, 19, 3.5, 200), 3: (16, 20, 2.0, 180), 4: (15, 21, 3.0, 190),
          5: (14, 22, 2.0, 170), 6: (13, 23, 2.0, 180), 7: (13, 24, 2.0, 190), 8: (12, 25, 2.5, 190),
          9: (11, 26, 2.0, 210), 10: (11, 27, 2.0, 210)}


@pytest.mark.parametrize('number', sorted(HSLM_A))
def test_hslm_a_geometry(number):
    N, D, d, P = HSLM_A[number]
    train = hslm_a(number, 100.0)
    x = train.wheel_offsets
    assert train.n_wheels == 2 * N + 14 and train.n_dof == 0 and np.all(train.force_wheels)
    np.testing.assert_allclose(train.static_wheel_loads, P * 1e3)
    # EN 1991-2 Fig. 6.12: power car, end coach, articulated bogies D apart; symmetric train
    np.testing.assert_allclose(x[:6], [0, 3, 14, 17, 20.525, 20.525 + d], atol=1e-12)
    np.testing.assert_allclose(x[6:8], 18.7625 + D + np.array([-d / 2, d / 2]), atol=1e-12)
    np.testing.assert_allclose(np.diff(x[6:-6:2]), D, atol=1e-12)
    np.testing.assert_allclose(x[::-1], x[-1] - x, atol=1e-12)
    assert train.name == f'HSLM-A{number}'
    assert hslm_a(f'a{number}', 100.0).wheel_offsets.tolist() == x.tolist()


def test_hslm_a_family_ranges_match_en_1991_2():
    """Published: first-to-last axle 375.525 m (A9) to 398.525 m (A2); total load 7140 kN (A5) to
    9600 kN (A2). Exact decimal data, so only rounding tolerances."""
    trains = {n: hslm_a(n, 100.0) for n in HSLM_A}
    lengths = {n: t.length for n, t in trains.items()}
    loads = {n: t.static_wheel_loads.sum() / 1e3 for n, t in trains.items()}
    assert min(lengths, key=lengths.get) == 9 and lengths[9] == pytest.approx(375.525, abs=1e-9)
    assert max(lengths, key=lengths.get) == 2 and lengths[2] == pytest.approx(398.525, abs=1e-9)
    assert min(loads, key=loads.get) == 5 and loads[5] == pytest.approx(7140, abs=1e-9)
    assert max(loads, key=loads.get) == 2 and loads[2] == pytest.approx(9600, abs=1e-9)
    with pytest.raises(ValueError, match="unknown train 11"):
        hslm_a(11, 100.0)


def test_ice3_geometry_and_assembly():
    train = ice3(speed=300 / 3.6)
    car = car_from_catalogue('ICE3_coach')
    assert (len(train.cars), train.n_wheels, train.n_dof) == (8, 32, 80)
    # published ICE 3 car lengths: end cars 25.835 m, intermediate 24.775 m, bogie pivots 17.375 m
    nose_to_tail = train.wheel_offsets[-1] + 4.76 - 1.25
    assert nose_to_tail == pytest.approx(2 * 25.835 + 6 * 24.775, abs=1e-9)
    assert train.wheel_offsets[0] == pytest.approx(4.76 - 1.25)
    np.testing.assert_allclose(np.diff(train.car_offsets), 24.775, atol=1e-12)
    for attr in ('M', 'C', 'K'):
        np.testing.assert_array_equal(getattr(train, attr).toarray(), scipy.linalg.block_diag(*[getattr(car, attr)] * 8))
    np.testing.assert_array_equal(train.wheel_dofs, (10 * np.arange(8)[:, None] + [6, 7, 8, 9]).ravel())
    assert -train.gravity_load.sum() == pytest.approx(8 * 62000 * GRAVITY, rel=1e-14)
    assert train.static_wheel_loads.sum() == pytest.approx(8 * 62000 * GRAVITY, rel=1e-14)
    assert train.dof_names[11] == 'car1.body_rz'


def test_wheel_positions_and_mixed_train():
    car = four_dof_car(40e3, 2e6, 2e3, 1.2e6, 3e4, 17.5)
    train = Train([moving_force(1e5), car, moving_force(2e5)], [0.0, 5.0, 30.0], speed=50.0)
    np.testing.assert_array_equal(train.wheel_offsets, [0.0, 5.0, 22.5, 30.0])
    np.testing.assert_array_equal(train.force_wheels, [True, False, False, True])
    np.testing.assert_array_equal(train.wheel_dofs, [2, 3])
    np.testing.assert_array_equal(train.wheel_car, [0, 1, 1, 2])
    assert train.n_dof == 4 and train.K.shape == (4, 4)
    np.testing.assert_allclose(train.wheel_positions(0.5, x_head0=-10.0), 15.0 - train.wheel_offsets)
    positions = train.wheel_positions(np.array([0.0, 0.5, 1.0]))
    assert positions.shape == (3, 4)
    np.testing.assert_allclose(positions[:, 2], [-22.5, 2.5, 27.5])


def test_uniform_train_and_validation():
    car = car_from_catalogue('Manchester_benchmark')
    train = Train.uniform(car, 3, 25.0, speed=120 / 3.6)
    np.testing.assert_array_equal(train.car_offsets, [0.0, 25.0, 50.0])
    with pytest.raises(ValueError, match="wheel 4 .* is not behind wheel 3"):
        Train.uniform(car, 2, 20.0, speed=10.0)  # cars overlap: Lc + Lb = 21.56 m > 20 m
    with pytest.raises(ValueError, match="speed must be finite and >= 0"):
        Train.uniform(car, 2, 25.0, speed=-1.0)


def test_axle_table_errors_name_the_row():
    train = Train.from_axle_table([0.0, 3.0, 14.0], [1e5, 1e5, 2e5], speed=20.0)
    np.testing.assert_array_equal(train.static_wheel_loads, [1e5, 1e5, 2e5])
    with pytest.raises(ValueError, match="row 2: position 2.0 m is not greater than the previous 3.0 m"):
        Train.from_axle_table([0.0, 3.0, 2.0], [1e5] * 3, speed=20.0)
    with pytest.raises(ValueError, match=r"row 1: load must be > 0 \[N\], got -5"):
        Train.from_axle_table([0.0, 3.0], [1e5, -5.0], speed=20.0)


@pytest.mark.parametrize("table, message", [
    ("0,17\n3,17\n", r"line 2: load_kN 17 is not a railway axle load \(30 to 500 kN\); is the table in tonnes\? "
                     r"\(17 t = 166\.8 kN\)$"),
    ("0,200\n3,170000\n", r"line 3: load_kN 170000 is not a railway axle load \(30 to 500 kN\); is the table in N\? "
                          r"\(170000 N = 170 kN\)$"),
    ("0,17000\n3,17000\n", r"line 2: load_kN 17000 is not a railway axle load \(30 to 500 kN\); is the table in kg or "
                           r"daN\? \(17000 kg = 166\.8 kN; 17000 daN = 170 kN\)$"),
    ("0,1000\n", r"line 2: load_kN 1000 is not a railway axle load \(30 to 500 kN\)$"),
    ("0,200\n2500,200\n", r"line 3: the axle is 2500 m behind the previous one \(0\.5 to 100 m between axles\); "
                          r"is position_m in cm or mm\? \(2500 cm = 25 m; 2500 mm = 2\.5 m\)$"),
    ("0,200\n0.0025,200\n", r"line 3: the axle is 0\.0025 m behind the previous one \(0\.5 to 100 m between axles\); "
                            r"is position_m in km\? \(0\.0025 km = 2\.5 m\)$"),
    ("0,200\n0.3,200\n", r"line 3: the axle is 0\.3 m behind the previous one \(0\.5 to 100 m between axles\)$"),
])
def test_a_csv_table_in_other_units_is_refused(tmp_path, table, message):
    """A CSV table in tonnes, kg, daN or N (loads 10× or 1000× off) or in cm, mm or km (spacings)
    is refused, naming the line and the units that would read the value as an axle load or a
    spacing (g = 9.81 m/s²: 17000 kg = 166.77 kN), and no unit where none does (1000 was 'in N?
    (1000 N = 1 kN)', 17000 kg 'in N? (17000 N = 17 kN)', a 0.3 m typo 'in km?'); the bounds
    themselves are accepted."""
    path = tmp_path / 'axles.csv'
    path.write_text('position_m,load_kN\n' + table)
    with pytest.raises(ModelError, match=r"^.*axles\.csv " + message):
        Train.from_csv(path, speed=50.0)
    path.write_text('position_m,load_kN\n0,30\n0.5,500\n100.5,30\n')
    np.testing.assert_array_equal(Train.from_csv(path, speed=50.0).static_wheel_loads, [3e4, 5e5, 3e4])


def test_from_csv(tmp_path):
    good = tmp_path / 'train.csv'
    good.write_text('name;position_m;load_kN\nloco;0;200\n\nloco;3.0;200\ncoach;14.5;150\n', encoding='utf-8-sig')
    train = Train.from_csv(good, speed=50.0)
    np.testing.assert_array_equal(train.wheel_offsets, [0.0, 3.0, 14.5])
    np.testing.assert_array_equal(train.static_wheel_loads, [2e5, 2e5, 1.5e5])
    bad = tmp_path / 'bad.csv'
    bad.write_text('position_m,load_kN\n0,200\n3,0\n')
    with pytest.raises(ValueError, match="bad.csv line 3: load must be > 0"):
        Train.from_csv(bad, speed=50.0)
    bad.write_text('position_m,load_kN\n0,200\n3,abc\n')
    with pytest.raises(ValueError, match="bad.csv line 3: cannot read"):
        Train.from_csv(bad, speed=50.0)
    bad.write_text('x,P\n0,200\n')
    with pytest.raises(ValueError, match="line 1: header must name the columns"):
        Train.from_csv(bad, speed=50.0)


def test_csv_tables_from_spreadsheets_and_their_slips(tmp_path):
    """Excel's 'CSV' is an 8-bit code page and its 'Unicode text' UTF-16: both read (before, a
    UnicodeDecodeError traceback, exit 1 at the command line). A negative load is named in the
    table's kN (it said -200000.0); a header naming a column twice, a row with more cells than
    the header (a decimal comma), a decimal comma in a ';'-separated table (said so) and a
    missing file are refused, naming the file and line."""
    table = 'Fahrzeug;position_m;load_kN\nTriebkopf;0;200\nTriebkopf;3;200\nWagen;14,5;150\n'
    for encoding in ('cp1252', 'utf-16'):
        path = tmp_path / f'{encoding}.csv'
        path.write_bytes(table.replace('Triebkopf', 'Triebköpf').replace('14,5', '14.5').encode(encoding))
        train = Train.from_csv(path, speed=50.0)
        np.testing.assert_array_equal(train.wheel_offsets, [0.0, 3.0, 14.5])
        np.testing.assert_array_equal(train.static_wheel_loads, [2e5, 2e5, 1.5e5])
    trailing = tmp_path / 'trailing.csv'
    trailing.write_text('position_m,load_kN\n0,170,\n3,170,\n')              # a trailing delimiter: read
    np.testing.assert_array_equal(Train.from_csv(trailing, speed=50.0).static_wheel_loads, [1.7e5, 1.7e5])
    bad = tmp_path / 'bad.csv'
    for text, message in (('position_m,load_kN\n0,200\n3,-200\n', r"bad\.csv line 3: load must be > 0 \[kN\], got -200$"),
                          ('position_m,load_kN,position_m\n0,200,0\n', "line 1: the header names column 'position_m' twice"),
                          ('position_m,load_kN\n0,200\n3,170,5\n', r"line 3: 3 cells under a header of 2 .*decimal comma"),
                          ('name;position_m;load_kN\nx;0;170\ny;2,65;170\n',     # ';'-separated, decimal comma
                           r"line 3: cannot read position_m and load_kN from \['y', '2,65', '170'\]: a decimal comma\? "
                           r"write 2\.65, not 2,65$"),
                          ('position_m;load_kN\n0;abc\n', r"line 2: cannot read position_m and load_kN from "
                                                         r"\['0', 'abc'\]$")):
        bad.write_text(text)
        with pytest.raises(ModelError, match=message):
            Train.from_csv(bad, speed=50.0)
    with pytest.raises(ModelError, match=r"axle table .*missing\.csv: cannot read it \(No such file"):
        Train.from_csv(tmp_path / 'missing.csv', speed=50.0)


def test_a_speed_in_km_h_given_as_m_s_is_refused():
    """Train speeds are m/s: 300 (km/h meant) read 1080 km/h and ran; above 200 m/s (720 km/h)
    a train is refused naming both units, also at another speed."""
    train = hslm_a(1, 300 / 3.6)
    with pytest.raises(ModelError, match=r"speed 300 m/s \(1080 km/h\) is faster than any train .* 300 km/h is 83\.33 m/s"):
        Train(train.cars, train.car_offsets, 300.0)
    with pytest.raises(ModelError, match=r"speed 250 m/s \(900 km/h\)"):
        train.with_speed(250.0)
    assert train.with_speed(200.0).speed == 200.0
