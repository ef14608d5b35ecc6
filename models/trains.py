"""Trains: cars in a row, moving at constant speed in +x.

Positions along a train are *offsets* measured backwards from the train's head (the reference
point at offset 0): a car's offset locates its reference point (its leading wheel, see
:class:`~vtsi.models.cars.Car`), and a wheel's global offset is its car's offset plus the wheel's
offset in the car. At time t a wheel with offset o is at x = x_head0 + V t − o.

References
----------
.. [1] EN 1991-2:2003, Actions on structures — Traffic loads on bridges, §6.4.6.1.1, Table 6.3 and
   Fig. 6.12 (HSLM-A), Fig. 6.13 (HSLM-B).
.. [2] Cantero, D. TTB-2D (github.com/DanielCanteroNTNU/TTB-2D), AVE S103 / ICE3 train files
   (after Goicolea 2014): bogie-centre spacing 17.375 m, car-end overhangs 3.7 m, nose 4.76 m.
"""
from __future__ import annotations

import copy
import csv
import json
from importlib import resources

import numpy as np
import scipy.sparse

from vtsi.errors import ModelError, as_number, is_count

from .cars import Car, _frozen, car_from_catalogue, moving_force

# What a CSV axle table may hold (Train.from_csv): outside these a table is taken to be in other
# units (tonnes or N for kN, mm or km for m) rather than run with loads 10× or 1000× off.
CSV_AXLE_LOAD_KN = (30.0, 500.0)     # [kN]: 3 t to 51 t per axle
CSV_AXLE_SPACING_M = (0.5, 100.0)    # [m] between consecutive axles


class Train:
    """A sequence of cars with their offsets and a constant speed; its arrays are read-only.

    Parameters
    ----------
    cars : sequence of Car
    car_offsets : array_like, shape (n_cars,)
        Offset of each car's reference point (its leading wheel) behind the train's head [m].
    speed : float
        Constant speed V ≥ 0 [m/s], in +x.
    name : str
    characteristic_length : float or None, keyword only
        The regular spacing D [m] (> 0) of the train's repeated load groups (coach length), or None
        when the train has none. Speed sweeps place resonance speeds at v = n0 D / i (n0 the
        bridge frequency [Hz], i = 1, 2, …); the train's own geometry does not depend on it.

    Attributes
    ----------
    cars : tuple of Car
    car_offsets : ndarray, shape (n_cars,)
    speed : float
    name : str
    characteristic_length : float or None
        D [m], as given.
    n_dof : int
        Total number of dofs; car i owns the dofs ``dof_start[i]:dof_start[i + 1]``.
    dof_start : ndarray, shape (n_cars + 1,), int64
    dof_names : tuple of str
        'car{i}.{car dof name}', e.g. 'car0.body_rz' (cars numbered from 0 at the head).
    M, C, K : scipy.sparse.csr_matrix, shape (n_dof, n_dof)
        Block-diagonal train matrices (one block per car).
    gravity_load : ndarray, shape (n_dof,)
        Gravity load P_t [N] (negative: downwards).
    n_wheels : int
    wheel_offsets : ndarray, shape (n_wheels,)
        Global wheel offsets behind the head [m], strictly increasing (front wheel first).
    wheel_car : ndarray, shape (n_wheels,), int64
        Index of each wheel's car.
    static_wheel_loads : ndarray, shape (n_wheels,)
        Static contact forces on rigid level ground, or the prescribed forces of force-only cars [N].
    force_wheels : ndarray, shape (n_wheels,), bool
        True for a wheel of a force-only car (:func:`~vtsi.models.cars.moving_force`): it has no
        dof and loads the rail with its constant force.
    wheel_dofs : ndarray, shape (n_contact_wheels,), int64
        Global dof of each wheel with a dof (the wheels where ``~force_wheels``, in wheel order):
        the rows of the Boolean matrix S.
    """

    def __init__(self, cars, car_offsets, speed, name='train', *, characteristic_length=None):
        self.cars = tuple(cars)
        self.name = str(name)
        where = f"train {self.name!r}"
        try:
            self.car_offsets = _frozen(car_offsets, np.float64)
        except (TypeError, ValueError):
            raise ModelError(f"{where}: car_offsets must be numbers [m], got {car_offsets!r}") from None
        self.speed = as_number(speed, where, "speed [m/s]")
        self.characteristic_length = _check_characteristic_length(characteristic_length, where)
        if not self.cars or not all(isinstance(car, Car) for car in self.cars):
            raise ModelError(f"{where}: cars must be a non-empty sequence of Car")
        if self.car_offsets.shape != (len(self.cars),) or not np.all(np.isfinite(self.car_offsets)):
            raise ModelError(f"{where}: car_offsets must be {len(self.cars)} finite numbers, "
                             f"got shape {self.car_offsets.shape}")
        if not (np.isfinite(self.speed) and self.speed >= 0):
            raise ModelError(f"{where}: speed must be finite and >= 0, got {speed!r}")
        n_dofs = [car.n_dof for car in self.cars]
        self.dof_start = _frozen(np.concatenate([[0], np.cumsum(n_dofs)]), np.int64)
        self.n_dof = int(self.dof_start[-1])
        self.dof_names = tuple(f"car{i}.{dof}" for i, car in enumerate(self.cars) for dof in car.dof_names)
        self.wheel_offsets = _frozen(np.concatenate(
            [off + car.wheel_offsets for off, car in zip(self.car_offsets, self.cars)]), np.float64)
        self.n_wheels = self.wheel_offsets.size
        self.wheel_car = _frozen(np.repeat(np.arange(len(self.cars)), [c.n_wheels for c in self.cars]), np.int64)
        steps = np.diff(self.wheel_offsets)
        if np.any(steps <= 0):
            i = int(np.argmax(steps <= 0)) + 1
            raise ModelError(f"{where}: wheel offsets must increase from head to tail; wheel {i} (car "
                             f"{self.wheel_car[i]}) at {self.wheel_offsets[i]} m is not behind wheel {i - 1} "
                             f"at {self.wheel_offsets[i - 1]} m")
        self.static_wheel_loads = _frozen(np.concatenate([car.static_wheel_loads for car in self.cars]),
                                          np.float64)
        self.force_wheels = _frozen(np.repeat([car.n_dof == 0 for car in self.cars],
                                              [car.n_wheels for car in self.cars]), bool)
        self.wheel_dofs = _frozen(np.concatenate(
            [start + car.wheel_dofs for start, car in zip(self.dof_start, self.cars)]), np.int64)
        self.gravity_load = _frozen(np.concatenate([car.gravity_load for car in self.cars]), np.float64)
        blocks = [car for car in self.cars if car.n_dof]
        for attr in ('M', 'C', 'K'):
            matrix = (scipy.sparse.block_diag([getattr(car, attr) for car in blocks], format='csr')
                      if blocks else scipy.sparse.csr_matrix((0, 0)))
            matrix.eliminate_zeros()
            setattr(self, attr, matrix)

    def __repr__(self):
        return (f"Train({self.name!r}, {len(self.cars)} cars, {self.n_wheels} wheels, {self.n_dof} dofs, "
                f"V = {self.speed} m/s)")

    def with_speed(self, speed):
        """The same train at another constant speed [m/s] (a shallow copy: cars, offsets and
        matrices are shared, read-only)."""
        speed = as_number(speed, f"train {self.name!r}", "speed [m/s]")
        if not (np.isfinite(speed) and speed >= 0):
            raise ModelError(f"train {self.name!r}: speed must be finite and >= 0, got {speed!r}")
        train = copy.copy(self)
        train.speed = speed
        return train

    @property
    def contact_wheels(self):
        """Indices of the wheels with a dof (the contact wheels, in wheel order), int64."""
        return np.flatnonzero(~self.force_wheels).astype(np.int64)

    @property
    def length(self) -> float:
        """Distance from the first to the last wheel [m]."""
        return float(self.wheel_offsets[-1] - self.wheel_offsets[0])

    def wheel_positions(self, t, x_head0=0.0):
        """Wheel positions x = x_head0 + V t − wheel_offsets [m].

        Parameters
        ----------
        t : float or array_like, shape (n_t,)
            Time [s].
        x_head0 : float
            Position of the head at t = 0 [m].

        Returns
        -------
        ndarray, shape (n_wheels,) for scalar t, else (n_t, n_wheels)
        """
        t = np.asarray(t, dtype=np.float64)
        return x_head0 + self.speed * t[..., None] - self.wheel_offsets

    @classmethod
    def uniform(cls, car, n_cars, car_length, speed, name=None):
        """``n_cars`` copies of ``car``, one every ``car_length`` metres (offsets 0, L, 2L, …);
        ``car_length`` is the train's characteristic length."""
        if not is_count(n_cars, 1):
            raise ModelError(f"Train.uniform: n_cars must be a positive integer, got {n_cars!r}")
        if not (np.isfinite(as_number(car_length, "Train.uniform", "car_length")) and car_length > 0):
            raise ModelError(f"Train.uniform: car_length must be > 0, got {car_length!r}")
        return cls([car] * int(n_cars), np.arange(int(n_cars)) * float(car_length), speed,
                   name=name or f"{int(n_cars)} x {car.name}", characteristic_length=float(car_length))

    @classmethod
    def from_axle_table(cls, positions, loads, speed, name='axle table', *, characteristic_length=None):
        """A train of moving forces, one per axle.

        Parameters
        ----------
        positions : array_like, shape (n_axles,)
            Axle offsets behind the head [m], strictly increasing.
        loads : array_like, shape (n_axles,)
            Axle loads [N], > 0 (downwards on the rail).
        speed : float
            [m/s]
        name : str
        characteristic_length : float or None
            Regular spacing D of the repeated load groups [m] (see :class:`Train`).

        Raises
        ------
        ValueError
            Naming the first bad row (0-based).
        """
        positions, loads = _check_axle_table(positions, loads, [f"row {i}" for i in range(np.size(positions))],
                                             'Train.from_axle_table')
        return cls([moving_force(P) for P in loads], positions, speed, name=name,
                   characteristic_length=characteristic_length)

    @classmethod
    def from_csv(cls, path, speed, name=None, *, characteristic_length=None):
        """A train of moving forces from a CSV table with a header and the columns ``position_m``
        (axle offset behind the head, m) and ``load_kN`` (axle load, kN).

        Other columns are ignored; the delimiter may be ',', ';' or a tab (spreadsheet exports);
        blank lines are skipped. Errors name the file and line. ``speed`` is in m/s;
        ``characteristic_length`` [m] as in :class:`Train` (a CSV table carries none).
        """
        with open(path, newline='', encoding='utf-8-sig') as handle:
            text = handle.read()
        try:
            dialect = csv.Sniffer().sniff(text.partition('\n')[0], delimiters=',;\t')
        except csv.Error:
            dialect = csv.excel
        rows = [(line, row) for line, row in enumerate(csv.reader(text.splitlines(), dialect), start=1)
                if any(cell.strip() for cell in row)]
        if not rows:
            raise ModelError(f"{path}: empty axle table")
        header = [cell.strip().lower() for cell in rows[0][1]]
        if 'position_m' not in header or 'load_kn' not in header:
            raise ModelError(f"{path} line {rows[0][0]}: header must name the columns 'position_m' and "
                             f"'load_kN', got {rows[0][1]}")
        columns = header.index('position_m'), header.index('load_kn')
        values, labels = [], []
        for line, row in rows[1:]:
            try:
                values.append([float(row[c]) for c in columns])
            except (ValueError, IndexError) as err:
                raise ModelError(f"{path} line {line}: cannot read position_m and load_kN from {row}") from err
            labels.append(f"{path} line {line}")
        if not values:
            raise ModelError(f"{path}: no axles below the header")
        values = np.array(values)
        positions, loads = _check_axle_table(values[:, 0], values[:, 1] * 1e3, labels, 'Train.from_csv')
        _check_csv_units(values[:, 0], values[:, 1], labels)
        return cls([moving_force(P) for P in loads], positions, speed, name=name or str(path),
                   characteristic_length=characteristic_length)


def _check_axle_table(positions, loads, labels, where):
    positions = np.asarray(positions, dtype=np.float64)
    loads = np.asarray(loads, dtype=np.float64)
    if positions.ndim != 1 or positions.shape != loads.shape or positions.size == 0:
        raise ModelError(f"{where}: positions and loads must be 1-d arrays of equal, non-zero length, "
                         f"got shapes {positions.shape} and {loads.shape}")
    for i, (x, P) in enumerate(zip(positions, loads)):
        if not np.isfinite(x):
            raise ModelError(f"{where}: {labels[i]}: position must be finite, got {x}")
        if not (np.isfinite(P) and P > 0):
            raise ModelError(f"{where}: {labels[i]}: load must be > 0, got {P}")
        if i and x <= positions[i - 1]:
            raise ModelError(f"{where}: {labels[i]}: position {x} m is not greater than the previous "
                             f"{positions[i - 1]} m; positions must increase from head to tail")
    return positions, loads


def _check_csv_units(positions, loads_kn, labels):
    """A ModelError at the first axle load [kN] or spacing [m] outside CSV_AXLE_LOAD_KN or
    CSV_AXLE_SPACING_M, suggesting the unit the table is probably in."""
    (p_lo, p_hi), (d_lo, d_hi) = CSV_AXLE_LOAD_KN, CSV_AXLE_SPACING_M
    for i, P in enumerate(loads_kn):
        if not p_lo <= P <= p_hi:
            hint = f"in tonnes? ({P:g} t = {9.81 * P:.4g} kN)" if P < p_lo else f"in N? ({P:g} N = {P / 1e3:.4g} kN)"
            raise ModelError(f"{labels[i]}: load_kN {P:g} is not a railway axle load ({p_lo:g} to {p_hi:g} kN); "
                             f"is the table {hint}")
    for i in range(1, len(positions)):
        d = positions[i] - positions[i - 1]
        if not d_lo <= d <= d_hi:
            hint = "in mm" if d > d_hi else "in km"
            raise ModelError(f"{labels[i]}: the axle is {d:g} m behind the previous one ({d_lo:g} to {d_hi:g} m "
                             f"between axles); is position_m {hint}?")


def _check_characteristic_length(value, where):
    if value is None:
        return None
    try:
        D = float(value)
    except (TypeError, ValueError):
        D = float('nan')
    if isinstance(value, bool) or not (np.isfinite(D) and D > 0):
        raise ModelError(f"{where}: characteristic_length must be a finite length > 0 [m] or None, "
                         f"got {value!r}")
    return D


# AVE S103 / ICE3 geometry (TTB-2D, after Goicolea 2014): distance from a bogie centre to the car end.
_ICE3_OVERHANG = 7.4 / 2
_ICE3_NOSE = 4.76


def ice3(n_cars=8, *, speed, name='ICE3'):
    """An ICE3 (AVE S103 / Velaro E) trainset of 10-dof cars.

    Every car uses the 'ICE3_coach' parameter set (coaches C2, C3, C6, C7). Assumptions: the end
    cars reuse the coach's masses, as the reference data state; the lighter coaches C4/C5 (41.2 t
    body in TTB-2D) are not distinguished. Geometry as in TTB-2D: bogie centres 17.375 m apart,
    3.7 m from a bogie centre to a coupled car end, 4.76 m from the nose to the nearest bogie
    centre. The end cars are then 25.835 m long and the others 24.775 m, the published ICE 3 car
    lengths, and 8 cars measure 200.32 m between the noses (not counting the nose couplers). The
    head (offset 0) is the leading nose; the first wheel is 4.76 − 1.25 = 3.51 m behind it. The
    characteristic length is the coach length 24.775 m = 17.375 + 2 × 3.7 (the spacing of
    consecutive cars' bogies).

    Parameters
    ----------
    n_cars : int
        ≥ 2 (two end cars).
    speed : float
        [m/s]
    name : str

    References
    ----------
    Cantero, TTB-2D, TrainProp_AVE_S103_ICE3_Velaro_E_C*.m; Goicolea (2014), Simplified
    mechanical description of AVE S-103 - ICE3 Velaro E high speed train, oa.upm.es/43946.
    """
    if not is_count(n_cars, 2):
        raise ModelError(f"ice3: n_cars must be an integer >= 2, got {n_cars!r}")
    car = car_from_catalogue('ICE3_coach')
    front_overhang = np.full(int(n_cars), _ICE3_OVERHANG)
    front_overhang[0] = _ICE3_NOSE
    bogie_spacing, half_axle = car.wheel_offsets[2], car.wheel_offsets[1] / 2
    car_fronts = np.concatenate([[0.0], np.cumsum(front_overhang + bogie_spacing + _ICE3_OVERHANG)[:-1]])
    return Train([car] * int(n_cars), car_fronts + front_overhang - half_axle, speed, name=name,
                 characteristic_length=bogie_spacing + 2 * _ICE3_OVERHANG)


def ice3_axle_loads(n_cars=8, *, speed, name='ICE3 axle loads'):
    """The ICE3 trainset of :func:`ice3` as moving forces, one per axle.

    Each axle is a :func:`~vtsi.models.cars.moving_force` at the same offset as the corresponding
    wheel of ``ice3(n_cars)``, carrying that train's static wheel load on rigid level ground
    (``ice3(n_cars).static_wheel_loads``, 152 055 N per axle with the 'ICE3_coach' data and
    g = 9.81 m/s²): the total load is the trainset's weight, n_cars × 62 000 kg × g.

    Parameters
    ----------
    n_cars : int
        ≥ 2.
    speed : float
        [m/s]
    name : str

    Returns
    -------
    Train
        4 n_cars force-only cars, characteristic length 24.775 m (as :func:`ice3`).
    """
    cars = ice3(n_cars, speed=speed)
    return Train.from_axle_table(cars.wheel_offsets, cars.static_wheel_loads, speed, name=name,
                                 characteristic_length=cars.characteristic_length)


def _hslm_table():
    text = resources.files(__package__).joinpath('data', 'hslm_a.json').read_text(encoding='utf-8')
    return {key: value for key, value in json.loads(text).items() if not key.startswith('_')}


def hslm_a(number, speed):
    """The HSLM-A high-speed load model train A1 … A10 of EN 1991-2, as moving forces.

    Axle positions behind the leading axle: power car 0, 3, 14, 17 m; the leading end coach's outer
    bogie at 20.525 and 20.525 + d; N + 1 articulated bogies centred at 18.7625 + i·D
    (i = 1 … N + 1) with axles at ± d/2; the trailing end coach and power car mirror the front
    (the train is symmetric). That is 2N + 14 axles of load P over 37.525 + (N + 2)·D metres.

    Parameters
    ----------
    number : int or str
        1 … 10, or 'A1' … 'A10'.
    speed : float
        [m/s]

    Returns
    -------
    Train
        Force-only cars, one per axle, named 'HSLM-A<number>'; characteristic length D.

    References
    ----------
    EN 1991-2:2003, §6.4.6.1.1, Table 6.3 (N, D, d, P) and Fig. 6.12 (geometry).
    """
    table = _hslm_table()
    key = f"A{number}" if not str(number).upper().startswith('A') else str(number).upper()
    if key not in table:
        raise ModelError(f"hslm_a: unknown train {number!r}; valid: {list(table)} (or 1 … 10)")
    N, D, d, P = (table[key][k] for k in ('N', 'D_m', 'd_m', 'P_kN'))
    centres = 18.7625 + D * np.arange(1, N + 2)
    front = np.concatenate([[0.0, 3.0, 14.0, 17.0, 20.525, 20.525 + d],
                            (centres[:, None] + [-d / 2, d / 2]).ravel()])
    back = 37.525 + (N + 2) * D - front[:6][::-1]  # mirror about the train's centre
    positions = np.concatenate([front, back])
    return Train.from_axle_table(positions, np.full(positions.size, P * 1e3), speed, name=f"HSLM-{key}",
                                 characteristic_length=D)


# EN 1991-2:2003 Figure 6.13 (HSLM-B): N and d as straight lines in the span L between the figure's
# end points. NOT VERIFIED against the standard: see hslm_b's docstring and docs/trains.md before
# relying on it; this table is the only place to correct.
HSLM_B_SPAN_RANGE = (1.0, 7.0)
"""Spans L [m] for which EN 1991-2 defines HSLM-B: L_min <= L < L_max."""
_HSLM_B_N = (20.0, 10.0)     # N at L = 1 m and at L = 7 m (Figure 6.13; see hslm_b_parameters)
_HSLM_B_D = (2.5, 3.5)       # d [m] at L = 1 m and at L = 7 m
_HSLM_B_P = 170e3            # [N], EN 1991-2 §6.4.6.1.1(2)


def hslm_b_parameters(span):
    """N and d of HSLM-B for a span L (EN 1991-2 Figure 6.13, as read here).

    N and d vary linearly in L between the figure's end points, N from 20 (L = 1 m) down to 10
    (L = 7 m) and d from 2.5 m (L = 1 m) up to 3.5 m (L = 7 m). N is rounded to the nearest
    integer, halves upwards (floor(N + 1/2)); d is not rounded.

    Parameters
    ----------
    span : float
        L [m], 1 <= L < 7.

    Returns
    -------
    (int, float)
        N, the number of forces, and d [m], their spacing.

    Raises
    ------
    ModelError
        For a span outside 1 m <= L < 7 m (HSLM-A covers L >= 7 m), naming the span.

    Notes
    -----
    **Not checked against the printed figure here** (the standard is not in this project's
    sources; docs/trains.md, "HSLM-B: source"). The end values 10/20 and 2.5/3.5 m are the
    commonly quoted ranges; the MIDAS Civil default 'HSLM B' vehicle (N = 10, d = 3.5 m) pairs
    them as here at the L = 7 m end. The direction follows the model's purpose: resonance at
    v = n₀ d must fall within the speed range for the short spans' high n₀ (so d shrinks with L),
    and the higher damping of short spans (Table 6.6) needs more forces to build resonance up
    (so N grows as L shrinks). Check Figure 6.13 before design use.
    """
    lo, hi = HSLM_B_SPAN_RANGE
    try:
        L = float(span)
    except (TypeError, ValueError):
        L = float('nan')
    if not (np.isfinite(L) and lo <= L < hi):
        raise ModelError(f"hslm_b: span L = {span!r} m is outside the range of EN 1991-2 Figure 6.13, "
                         f"{lo:g} m <= L < {hi:g} m (HSLM-A covers L >= {hi:g} m)")
    s = (L - lo) / (hi - lo)
    N = int(np.floor(_HSLM_B_N[0] + s * (_HSLM_B_N[1] - _HSLM_B_N[0]) + 0.5))
    d = _HSLM_B_D[0] + s * (_HSLM_B_D[1] - _HSLM_B_D[0])
    return N, d


def hslm_b(span, speed):
    """The HSLM-B high-speed load model of EN 1991-2 for a simply supported span L < 7 m.

    N point forces of 170 kN at uniform spacing d (EN 1991-2 §6.4.6.1.1(2)), N and d functions of
    the span L read from Figure 6.13 (:func:`hslm_b_parameters`: linear in L from N = 10,
    d = 3.5 m at L = 1 m to N = 20, d = 2.5 m at L = 7 m; N rounded to the nearest integer, halves
    up). Forces at offsets 0, d, …, (N − 1) d behind the head.

    Parameters
    ----------
    span : float
        L [m], 1 <= L < 7.
    speed : float
        [m/s]

    Returns
    -------
    Train
        N force-only cars named 'HSLM-B'; characteristic length d.

    Raises
    ------
    ModelError
        For a span outside 1 m <= L < 7 m, naming the span and the range.

    Notes
    -----
    Source of the N(L), d(L) law: **not verified** against EN 1991-2 (see
    :func:`hslm_b_parameters` and docs/trains.md). Searches of public stores (pages, docs, code)
    for a statement of Figure 6.13's values found none; the only figures found were the MIDAS
    Civil default HSLM-B vehicle, N = 10 and d = 3.5 m.

    References
    ----------
    EN 1991-2:2003, §6.4.6.1.1(2) and Figure 6.13 (HSLM-B), Table 6.4 (HSLM-B for simply
    supported spans L < 7 m).
    """
    N, d = hslm_b_parameters(span)
    return Train.from_axle_table(d * np.arange(N), np.full(N, _HSLM_B_P), speed, name='HSLM-B',
                                 characteristic_length=d)
