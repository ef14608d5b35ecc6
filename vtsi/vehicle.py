"""Rail vehicles: a :class:`Car` (a small multibody system in the vertical plane, or a moving
force) and a :class:`Train` (cars in a row at a constant speed), the core types the coupled
analysis steps; :mod:`vtsi.models` builds catalogue cars and trains from them.

Conventions (OpenSees's 2-D frame, as docs/theory/coupled_step.md): x along the track, the train
moves in +x; y vertical, positive up; rotations rz counter-clockwise positive, so a point a metres
*ahead* of a body's centre (larger x) moves up by ``a * rz``. SI units (kg, kg·m², N/m, N·s/m, m,
N). A wheel's contact force λ ≥ 0 is compression and pushes the wheel up.

Positions along a train are *offsets* measured backwards from the train's head (the reference
point at offset 0): a car's offset locates its reference point (its leading wheel), and a
wheel's global offset is its car's offset plus the wheel's offset in the car. At time t a wheel
with offset o is at x = x_head0 + V t − o.
"""
from __future__ import annotations

import copy
import csv
import re
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.sparse

from vtsi.errors import ModelError, as_number, as_numbers, as_positive, is_count, is_int, is_number, number_array
from vtsi.signature import principal_wavelength

GRAVITY = 9.81
"""Default acceleration of gravity g [m/s²], the value the S2 reference solution (Yang & Yau 1997
data, docs/scenes.md) was computed with."""
MAX_TRAIN_SPEED = 200.0
"""[m/s] (720 km/h) The fastest train speed accepted: rail vehicles run slower (the record is
160 m/s); a speed in km/h given as a number of m/s reads 3.6 times faster."""
SIGNATURE = 'signature'
"""``characteristic_length=SIGNATURE``: D from the train's dynamic signature (:mod:`vtsi.signature`)."""


# What a CSV axle table may hold (Train.from_csv): outside these it is refused rather than run
# with loads 10× or 1000× off, naming the units (name, symbol, factor to kN or m) that would read
# the value at fault within them.
CSV_AXLE_LOAD_KN = (30.0, 500.0)     # [kN]: 3 t to 51 t per axle
CSV_AXLE_SPACING_M = (0.5, 100.0)    # [m] between consecutive axles
CSV_LOAD_UNITS = (("tonnes", "t", GRAVITY), ("kg", "kg", GRAVITY / 1e3), ("daN", "daN", 1e-2), ("N", "N", 1e-3))
CSV_LENGTH_UNITS = (("cm", "cm", 1e-2), ("mm", "mm", 1e-3), ("km", "km", 1e3))
DECIMAL_COMMA = re.compile(r"[-+]?\d*,\d+")   # '2,65': a spreadsheet's decimal comma in a ';'-separated table
DEFINITE_TOL = 1e-9
"""How far below 0 (relative to the largest) an eigenvalue of a car's M, C or K scaled to a unit
diagonal (D^-1/2 A D^-1/2: the signs of A's eigenvalues without its units, which differ by 10⁹
between a translation and a rotation in mm) may lie and still count as round-off: the catalogue
cars, in every unit system of :mod:`vtsi.units`, reach -5e-16 (their K and C have zero eigenvalues,
the car moving rigidly)."""
_MATRIX_KINDS = {'M': ('mass', 'kinetic energy ½ u̇ᵀMu̇', 'kg', 'kg·m²'),
                 'C': ('damping', 'dissipation u̇ᵀCu̇', 'N·s/m', 'N·m·s/rad'),
                 'K': ('stiffness', 'strain energy ½ uᵀKu', 'N/m', 'N·m/rad')}



def _frozen(values, dtype):
    a = np.array(values, dtype=dtype)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False, repr=False)
class Car:
    """An immutable vehicle description: constant matrices over the car's own dofs.

    Build cars with the constructors of this module (:func:`moving_force`, :func:`moving_mass`,
    :func:`sprung_mass`, :func:`four_dof_car`, :func:`ten_dof_car`, :func:`car_from_catalogue`).

    Attributes
    ----------
    name : str
    kind : str
        The constructor that built it: 'moving_force', 'moving_mass', 'sprung_mass', 'four_dof',
        'ten_dof' (or anything for a user-built car).
    M, C, K : ndarray, shape (n_dof, n_dof), float64
        Symmetric mass [kg, kg·m²], damping [N·s/m] and stiffness [N/m] matrices, each positive
        semidefinite (no negative energy; :data:`DEFINITE_TOL`), M definite on the
        :attr:`body_dofs` (a wheel's dof may be massless: the rail holds it).
    gravity_load : ndarray, shape (n_dof,)
        −g × mass on translational dofs, 0 on rotations [N].
    wheel_dofs : ndarray, shape (n_wheels,), int64
        Index into the car's dofs of each wheel's vertical dof, front wheel first, given as
        integers (a float, a text or a bool is refused). Empty for a
        force-only car (``n_dof == 0``): its wheels have no dofs and carry prescribed forces.
    wheel_offsets : ndarray, shape (n_wheels,)
        Distance of each wheel *behind* the car's reference point, the leading wheel (so the first
        offset is 0 and the offsets increase towards the rear) [m].
    dof_names : tuple of str
        e.g. ('body_y', 'body_rz', 'wheel1_y', 'wheel2_y').
    static_wheel_loads : ndarray, shape (n_wheels,)
        Contact forces λ > 0 in static equilibrium on rigid level ground [N]. Computed from the
        statics (``K u = gravity_load + Sᵀλ`` with the wheels held at 0) when ``n_dof > 0``, and
        then not accepted as an argument; for a force-only car they are the prescribed forces and
        must be given.
    """

    name: str
    kind: str
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    gravity_load: np.ndarray
    wheel_dofs: np.ndarray
    wheel_offsets: np.ndarray
    dof_names: tuple
    static_wheel_loads: np.ndarray = field(default=None)

    def __post_init__(self):
        set_ = object.__setattr__
        where = f"car {self.name!r}"
        for attr in ('M', 'C', 'K', 'gravity_load', 'wheel_offsets'):
            set_(self, attr, _frozen(as_numbers(getattr(self, attr), where, attr), np.float64))
        set_(self, 'wheel_dofs', _frozen(_wheel_dofs(self.wheel_dofs, where), np.int64))
        set_(self, 'dof_names', tuple(self.dof_names))
        n = len(self.dof_names)
        for attr in ('M', 'C', 'K'):
            a = getattr(self, attr)
            if a.shape != (n, n):
                raise ModelError(f"{where}: {attr} must be a finite ({n}, {n}) matrix, got shape {a.shape}")
            if not np.all(np.isfinite(a)):
                i, j = np.argwhere(~np.isfinite(a))[0]
                raise ModelError(f"{where}: {attr} must be a finite ({n}, {n}) matrix, got "
                                 f"{attr}[{i}, {j}] = {a[i, j]}")
            if not np.allclose(a, a.T, rtol=1e-12, atol=1e-12 * np.abs(a).max(initial=0.0)):
                raise ModelError(f"{where}: {attr} is not symmetric")
        if self.gravity_load.shape != (n,):
            raise ModelError(f"{where}: gravity_load must have shape ({n},), got {self.gravity_load.shape}")
        if self.wheel_offsets.ndim != 1 or self.wheel_offsets.size == 0:
            raise ModelError(f"{where}: wheel_offsets must be a non-empty 1-d array")
        if np.any(np.diff(self.wheel_offsets) <= 0) or not np.all(np.isfinite(self.wheel_offsets)):
            raise ModelError(f"{where}: wheel_offsets must be finite and increasing, got {self.wheel_offsets}")
        if n == 0:
            if self.wheel_dofs.size or self.static_wheel_loads is None:
                raise ModelError(f"{where}: a force-only car (no dofs) needs static_wheel_loads and no wheel_dofs")
            loads = _frozen(as_numbers(self.static_wheel_loads, where, 'static_wheel_loads'), np.float64)
        else:
            wd = self.wheel_dofs
            if (wd.shape != self.wheel_offsets.shape or np.unique(wd).size != wd.size
                    or np.any((wd < 0) | (wd >= n))):
                raise ModelError(f"{where}: wheel_dofs must be {self.wheel_offsets.size} distinct "
                                 f"indices in [0, {n}), got {wd}")
            if self.static_wheel_loads is not None:
                raise ModelError(f"{where}: static_wheel_loads are computed from the statics, do not pass them")
            for attr in ('M', 'C', 'K'):
                _check_semidefinite(where, attr, getattr(self, attr), self.dof_names,
                                    self.body_dofs if attr == 'M' else ())
            loads = _frozen(self._solve_statics(), np.float64)
        if loads.shape != self.wheel_offsets.shape or not np.all((loads > 0) & np.isfinite(loads)):
            raise ModelError(f"{where}: static wheel loads must be > 0 and finite for every wheel, got {loads}")
        set_(self, 'static_wheel_loads', loads)

    def __repr__(self):
        """Name, kind, counts and the mass [t] its wheels carry: their static loads over GRAVITY."""
        return (f"Car({self.name!r}, {self.kind}, {self.n_dof} dofs, {self.n_wheels} wheels, "
                f"{self.static_wheel_loads.sum() / GRAVITY / 1e3:.4g} t)")

    @property
    def n_dof(self) -> int:
        return len(self.dof_names)

    @property
    def n_wheels(self) -> int:
        return self.wheel_offsets.size

    @property
    def body_dofs(self) -> np.ndarray:
        """Indices of the dofs that are not wheels' (bodies, bogies), int64."""
        return np.setdiff1d(np.arange(self.n_dof), self.wheel_dofs)

    def _solve_statics(self) -> np.ndarray:
        """λ = K_wf u_f − P_w with K_ff u_f = P_f (wheels w held at 0, the rest f free)."""
        f, w, K, P = self.body_dofs, self.wheel_dofs, self.K, self.gravity_load
        if f.size == 0:
            return -P[w]
        try:
            u_f = scipy.linalg.solve(K[np.ix_(f, f)], P[f], assume_a='sym')
        except (np.linalg.LinAlgError, scipy.linalg.LinAlgError) as err:
            raise ModelError(f"car {self.name!r}: the bodies are not supported by the wheels "
                             "(singular stiffness with the wheels held)") from err
        return K[np.ix_(w, f)] @ u_f - P[w]

    def fixed_wheel_frequencies(self) -> np.ndarray:
        """Natural frequencies [Hz] with every wheel held fixed, ascending.

        The generalised eigenproblem of ``K`` and ``M`` restricted to :attr:`body_dofs`.
        """
        f = self.body_dofs
        lam = scipy.linalg.eigh(self.K[np.ix_(f, f)], self.M[np.ix_(f, f)], eigvals_only=True)
        return np.sqrt(lam) / (2.0 * np.pi)


def _wheel_dofs(value, where):
    """A car's ``wheel_dofs`` as an int64 array of its shape if every item is an integer (a Python
    or numpy int: not a float, a text nor a bool, which numpy would truncate, parse or take for
    1), else a ModelError naming the car (``where``) and the value."""
    items = np.asarray(value, dtype=object)
    if not all(is_int(item) and -2 ** 63 <= item < 2 ** 63 for item in items.flat):
        raise ModelError(f"{where}: wheel_dofs must be integers (indices of the car's dofs), got {value!r}")
    return items.astype(np.int64)


def _check_semidefinite(where, attr, a, dof_names, massive=()):
    """A ModelError unless the symmetric matrix ``a`` (a car's ``attr``: 'M', 'C' or 'K') is
    positive semidefinite and, on the dofs ``massive`` (M's body dofs), definite. It names the
    first negative diagonal entry (on ``massive``: or zero) and its dof, else the eigenvalue at
    fault and the dof its mode moves most. Eigenvalues are judged on ``a`` scaled to a unit
    diagonal, within :data:`DEFINITE_TOL`."""
    what, energy, unit, rotation_unit = _MATRIX_KINDS[attr]
    massive = np.asarray(massive, dtype=np.int64)
    diagonal = np.diag(a)
    for i, value in enumerate(diagonal):
        if value < 0 or (value == 0 and i in massive):
            why = ("every dof but a wheel's needs mass (only a wheel, held by the rail, may be massless)"
                   if value == 0 else f"a {what} matrix has no negative diagonal entry (its {energy} >= 0)")
            raise ModelError(f"{where}: {attr}[{i}, {i}] ({dof_names[i]}) is {value:g} "
                             f"{rotation_unit if dof_names[i].endswith('_rz') else unit}; {why}")
    scale = 1.0 / np.sqrt(np.where(diagonal > 0, diagonal, diagonal.max(initial=0.0) or 1.0))
    scaled = scale[:, None] * a * scale

    def lowest_mode(dofs):          # a's lowest eigenvalue on ``dofs``, its largest, the dof its mode moves most
        lam, modes = np.linalg.eigh(a[np.ix_(dofs, dofs)])
        dof = dof_names[dofs[np.argmax(np.abs(modes[:, 0]))]]
        return f"eigenvalue {lam[0]:.4g} (largest {lam[-1]:.4g}), its mode mostly {dof}"

    mu = np.linalg.eigvalsh(scaled)
    if mu[0] < -DEFINITE_TOL * max(mu[-1], 1.0):
        raise ModelError(f"{where}: {attr} is not positive semidefinite (its {energy} must be >= 0): "
                         f"{lowest_mode(np.arange(len(dof_names)))}")
    if massive.size and np.linalg.eigvalsh(scaled[np.ix_(massive, massive)])[0] <= DEFINITE_TOL:
        raise ModelError(f"{where}: M is singular on the body dofs ({', '.join(dof_names[d] for d in massive)}): "
                         f"{lowest_mode(massive)}; only a wheel dof may be massless")


def moving_force(P, name='moving force'):
    """A constant vertical force P [N] (> 0, downwards on the rail): no dofs, one wheel.

    The car has ``n_dof = 0``, empty ``wheel_dofs``, ``wheel_offsets = [0]`` and
    ``static_wheel_loads = [P]``; a coupled analysis applies P to the rail and solves no contact
    for it.
    """
    if not (np.isfinite(as_number(P, 'moving_force', 'P')) and float(P) > 0):
        raise ModelError(f"moving_force: P must be > 0, got {P!r}")
    return Car(name=name, kind='moving_force', M=np.zeros((0, 0)), C=np.zeros((0, 0)),
               K=np.zeros((0, 0)), gravity_load=np.zeros(0), wheel_dofs=np.zeros(0, np.int64),
               wheel_offsets=[0.0], dof_names=(), static_wheel_loads=[float(P)])



class Train:
    """A sequence of cars with their offsets and a constant speed; its arrays are read-only
    (the CSR matrices' ``data``, ``indices`` and ``indptr`` too: a train and its
    :meth:`with_speed` copies share them).

    Parameters
    ----------
    cars : sequence of Car
    car_offsets : array_like, shape (n_cars,)
        Offset of each car's reference point (its leading wheel) behind the train's head [m].
    speed : float
        Constant speed V ≥ 0 [m/s], in +x.
    name : str
    characteristic_length : float, 'signature' or None, keyword only
        The regular spacing D [m] (> 0) of the train's repeated load groups (coach length), or None
        when the train has none, or 'signature': D from the wheels' offsets and static loads
        (:func:`vtsi.signature.principal_wavelength`), None when they have no regular spacing.
        Speed sweeps place resonance speeds at v = n0 D / i (n0 the bridge frequency [Hz],
        i = 1, 2, …); the train's own geometry does not depend on it.
    max_speed : float, keyword only
        The fastest speed accepted, here and by :meth:`with_speed`: MAX_TRAIN_SPEED [m/s] for an
        SI train (the command layer's trains in other units pass it in theirs).

    Attributes
    ----------
    cars : tuple of Car
    car_offsets : ndarray, shape (n_cars,)
    speed : float
    name : str
    characteristic_length : float or None
        D [m], as given or as its signature gave it.
    signature_peak : SignaturePeak or None
        With characteristic_length='signature', the signature's peak D came from (or why there is
        none: :meth:`~vtsi.signature.SignaturePeak.text`); None when D was given. A train
        converted to a model's units (:meth:`vtsi.units.Units.train`) keeps its SI train's peak,
        its lengths in the model's units.
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
        True for a wheel of a force-only car (:func:`moving_force`): it has no
        dof and loads the rail with its constant force.
    wheel_dofs : ndarray, shape (n_contact_wheels,), int64
        Global dof of each wheel with a dof (the wheels where ``~force_wheels``, in wheel order):
        the rows of the Boolean matrix S.
    """

    def __init__(self, cars, car_offsets, speed, name='train', *, characteristic_length=None,
                 max_speed=MAX_TRAIN_SPEED):
        self.cars = tuple(cars)
        self.name = str(name)
        where = f"train {self.name!r}"
        offsets = number_array(car_offsets)
        if offsets is None:
            raise ModelError(f"{where}: car_offsets must be numbers [m], got {car_offsets!r}")
        self.car_offsets = _frozen(offsets, np.float64)
        self.max_speed = as_positive(max_speed, where, "max_speed")
        self.speed = _speed(speed, where, self.max_speed)
        length = _check_characteristic_length(characteristic_length, where)
        if not self.cars or not all(isinstance(car, Car) for car in self.cars):
            raise ModelError(f"{where}: cars must be a non-empty sequence of Car")
        if self.car_offsets.shape != (len(self.cars),) or not np.all(np.isfinite(self.car_offsets)):
            raise ModelError(f"{where}: car_offsets must be {len(self.cars)} finite numbers, "
                             f"got shape {self.car_offsets.shape}")
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
        self.signature_peak = (principal_wavelength(self.wheel_offsets, self.static_wheel_loads)
                               if length == SIGNATURE else None)
        self.characteristic_length = length if self.signature_peak is None else self.signature_peak.length_m
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
            matrix.sum_duplicates()        # canonical: sorted, so that scipy never rewrites it in place
            for array in (matrix.data, matrix.indices, matrix.indptr):
                array.setflags(write=False)
            setattr(self, attr, matrix)

    def __repr__(self):
        return (f"Train({self.name!r}, {len(self.cars)} cars, {self.n_wheels} wheels, {self.n_dof} dofs, "
                f"V = {self.speed:.4g} m/s)")

    def with_speed(self, speed):
        """The same train at another constant speed [m/s] (a shallow copy: cars, offsets and
        matrices are shared, read-only)."""
        speed = _speed(speed, f"train {self.name!r}", self.max_speed)
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
    def from_axle_table(cls, positions, loads, speed, name='axle table', *, characteristic_length=SIGNATURE):
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
        characteristic_length : float, 'signature' or None
            Regular spacing D of the repeated load groups [m], or None (no D); by default
            'signature': D from the table's dynamic signature, None when it has no regular
            spacing (see :class:`Train` and :attr:`Train.signature_peak`).

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
    def from_csv(cls, path, speed, name=None, *, characteristic_length=SIGNATURE):
        """A train of moving forces from a CSV table with a header and the columns ``position_m``
        (axle offset behind the head, m) and ``load_kN`` (axle load, kN).

        Other columns are ignored; the delimiter may be ',', ';' or a tab (spreadsheet exports);
        blank lines are skipped; the text may be UTF-8, UTF-16 with its byte-order mark
        (spreadsheets' "Unicode text") or an 8-bit code page (read as Latin-1: the header and the
        numbers are ASCII in each). Errors name the file and line. ``speed`` is in m/s;
        ``characteristic_length`` as in :meth:`from_axle_table` (a CSV table carries none: by
        default D comes from its dynamic signature).
        """
        text = _read_text(path)
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
        for column in ('position_m', 'load_kn'):
            if header.count(column) > 1:
                raise ModelError(f"{path} line {rows[0][0]}: the header names column {column!r} twice: {rows[0][1]}")
        columns = header.index('position_m'), header.index('load_kn')
        values, labels = [], []
        for line, row in rows[1:]:
            while len(row) > len(header) and not row[-1].strip():     # a trailing delimiter
                row = row[:-1]
            if len(row) > len(header):
                raise ModelError(f"{path} line {line}: {len(row)} cells under a header of {len(header)} ({row}): "
                                 "a decimal comma in a comma-separated table?")
            try:
                values.append([float(row[c]) for c in columns])
            except (ValueError, IndexError) as err:
                comma = [row[c].strip() for c in columns if c < len(row) and DECIMAL_COMMA.fullmatch(row[c].strip())]
                raise ModelError(f"{path} line {line}: cannot read position_m and load_kN from {row}"
                                 + (f": a decimal comma? write {comma[0].replace(',', '.')}, not {comma[0]}"
                                    if comma else "")) from err
            labels.append(f"{path} line {line}")
        if not values:
            raise ModelError(f"{path}: no axles below the header")
        values = np.array(values)
        positions, loads_kn = _check_axle_table(values[:, 0], values[:, 1], labels, 'Train.from_csv', 'kN')
        _check_csv_units(positions, loads_kn, labels)
        return cls([moving_force(1e3 * P) for P in loads_kn], positions, speed, name=name or str(path),
                   characteristic_length=characteristic_length)


def _speed(value, where, max_speed):
    """A train's speed: finite, >= 0 and at most ``max_speed`` (MAX_TRAIN_SPEED [m/s] for an SI
    train), or a ModelError naming ``where`` and the value."""
    speed = as_number(value, where, "speed [m/s]")
    if not (np.isfinite(speed) and speed >= 0):
        raise ModelError(f"{where}: speed must be finite and >= 0, got {value!r}")
    if speed > max_speed and max_speed == MAX_TRAIN_SPEED:
        raise ModelError(f"{where}: speed {speed:g} m/s ({3.6 * speed:.4g} km/h) is faster than any train (at most "
                         f"{MAX_TRAIN_SPEED:g} m/s); speeds are in m/s here: {speed:g} km/h is {speed / 3.6:.4g} m/s")
    if speed > max_speed:                  # a train in a model's other units (the command layer's)
        raise ModelError(f"{where}: speed {speed:g} is faster than any train (at most {max_speed:g} in the train's "
                         f"units, {MAX_TRAIN_SPEED:g} m/s)")
    return speed


def _read_text(path):
    """The text of the file ``path``: UTF-16 by its byte-order mark, UTF-8 (with or without one),
    else Latin-1 (any 8-bit code page's ASCII part); a ModelError naming a file it cannot read."""
    try:
        with open(path, 'rb') as handle:
            raw = handle.read()
    except OSError as exc:
        raise ModelError(f"axle table {path}: cannot read it ({exc.strerror or exc})") from None
    if raw.startswith((b'\xff\xfe', b'\xfe\xff')):
        try:
            return raw.decode('utf-16')
        except UnicodeDecodeError as exc:
            raise ModelError(f"axle table {path}: not UTF-16 text, though it starts with its byte-order mark "
                             f"({exc.reason} at byte {exc.start})") from None
    try:
        return raw.decode('utf-8-sig')
    except UnicodeDecodeError:
        return raw.decode('latin-1')


def _check_axle_table(positions, loads, labels, where, load_unit='N'):
    positions = as_numbers(positions, where, "positions [m]")
    loads = as_numbers(loads, where, f"loads [{load_unit}]")
    if positions.ndim != 1 or positions.shape != loads.shape or positions.size == 0:
        raise ModelError(f"{where}: positions and loads must be 1-d arrays of equal, non-zero length, "
                         f"got shapes {positions.shape} and {loads.shape}")
    for i, (x, P) in enumerate(zip(positions, loads)):
        if not np.isfinite(x):
            raise ModelError(f"{where}: {labels[i]}: position must be finite, got {x}")
        if not (np.isfinite(P) and P > 0):
            raise ModelError(f"{where}: {labels[i]}: load must be > 0 [{load_unit}], got {P:g}")
        if i and x <= positions[i - 1]:
            raise ModelError(f"{where}: {labels[i]}: position {x} m is not greater than the previous "
                             f"{positions[i - 1]} m; positions must increase from head to tail")
    return positions, loads


def _check_csv_units(positions, loads_kn, labels):
    """A ModelError at the first axle load [kN] or spacing [m] outside CSV_AXLE_LOAD_KN or
    CSV_AXLE_SPACING_M, naming the units (CSV_LOAD_UNITS, CSV_LENGTH_UNITS) that would read it
    within that range, or none when no unit does."""
    (p_lo, p_hi), (d_lo, d_hi) = CSV_AXLE_LOAD_KN, CSV_AXLE_SPACING_M
    for i, P in enumerate(loads_kn):
        if not p_lo <= P <= p_hi:
            raise ModelError(f"{labels[i]}: load_kN {P:g} is not a railway axle load ({p_lo:g} to {p_hi:g} kN)"
                             + _unit_hint("the table", P, CSV_LOAD_UNITS, "kN", CSV_AXLE_LOAD_KN))
    spacings = np.diff(positions)
    for i, d in enumerate(spacings, start=1):
        if not d_lo <= d <= d_hi:
            raise ModelError(f"{labels[i]}: the axle is {d:g} m behind the previous one ({d_lo:g} to {d_hi:g} m "
                             "between axles)"
                             + _unit_hint("position_m", d, CSV_LENGTH_UNITS, "m", CSV_AXLE_SPACING_M))


def _unit_hint(what, value, units, si, bounds):
    """'; is {what} in kg or daN? (17000 kg = 166.8 kN; 17000 daN = 170 kN)': the ``units``
    ``(name, symbol, factor to si)`` under which ``value`` lies within ``bounds`` [si]; '' when
    none does (a typo, or a load per bogie: no unit to guess)."""
    fits = [(name, symbol, factor) for name, symbol, factor in units if bounds[0] <= factor * value <= bounds[1]]
    if not fits:
        return ""
    return (f"; is {what} in {' or '.join(name for name, _, _ in fits)}? ("
            + "; ".join(f"{value:g} {symbol} = {factor * value:.4g} {si}" for _, symbol, factor in fits) + ")")


def _check_characteristic_length(value, where):
    """D [m] as a float, None, or SIGNATURE; else a ModelError naming ``where`` and the value."""
    if value is None or (isinstance(value, str) and value == SIGNATURE):
        return value
    D = float(value) if is_number(value) else float('nan')
    if not (np.isfinite(D) and D > 0):
        raise ModelError(f"{where}: characteristic_length must be a finite length > 0 [m], "
                         f"'{SIGNATURE}' (from the train's dynamic signature) or None, got {value!r}")
    return D
