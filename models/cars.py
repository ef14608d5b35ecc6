"""Catalogue cars: rail vehicles as small multibody systems in the vertical plane.

Every car is a :class:`vtsi.vehicle.Car` (its conventions and units there): constant matrices
``M, C, K`` over its own dofs, the gravity load, and which dofs are the wheels'. Rigid bodies are lumped at their centres of mass, so ``M`` is
diagonal; springs and dashpots are assembled by one helper, :func:`_assemble_springs`, for all
car types.

References
----------
.. [1] Fedorova, M. & Sivaselvan, M.V. (2017). An algorithm for dynamic vehicle-track-structure
   interaction analysis for high-speed trains. Engineering Structures 148, 857-877 (Eq. 2: the
   4-dof car).
.. [2] Cantero, D. TTB-2D, Train-Track-Bridge interaction 2-D (MATLAB),
   github.com/DanielCanteroNTNU/TTB-2D: the 10-dof car and the parameter sets in
   ``data/cars_2d.json`` (originals: Goicolea 2014, Wu & Yang 2003, Iwnicki 1998, Doménech 2014,
   Zhai et al. 2009).
"""
from __future__ import annotations

import json
from importlib import resources

import numpy as np

from vtsi.errors import ModelError, as_number
from vtsi.vehicle import GRAVITY, Car, moving_force  # noqa: F401 (the core types, importable from here as before)

TEN_DOF_PARAMETERS = (
    'body_mass', 'body_pitch_inertia', 'bogie_mass', 'bogie_pitch_inertia', 'wheelset_mass',
    'primary_stiffness', 'primary_damping', 'secondary_stiffness', 'secondary_damping',
    'bogie_centre_spacing', 'axle_spacing')
"""Keys of a 10-dof car's parameter mapping (units: kg, kg·m², N/m, N·s/m, m; 2-D values, i.e.
per-side springs and dampers already doubled)."""


def _check(where, positive=(), nonnegative=()):
    """Raise ValueError naming the first parameter that is not finite and > 0 (or ≥ 0)."""
    for params, bound, op in ((positive, '>', np.greater), (nonnegative, '>=', np.greater_equal)):
        for name, value in params:
            if not (np.isfinite(as_number(value, where, name)) and op(float(value), 0.0)):
                raise ModelError(f"{where}: {name} must be {bound} 0, got {value!r}")


def _point(y, rz=None, a=0.0):
    """Terms (dof, coefficient) of the vertical displacement of a point of a body.

    ``y`` is the body's vertical dof; for a body with a pitch dof ``rz``, the point lies ``a``
    metres ahead (+x) of the body's centre and moves by ``u[y] + a·u[rz]``.
    """
    return ((y, 1.0),) if rz is None else ((y, 1.0), (rz, float(a)))


def _spring(k, c, upper, lower):
    """A spring-dashpot between an upper and a lower point: elongation δ = u_upper − u_lower."""
    return k, c, upper + tuple((dof, -coef) for dof, coef in lower)


def _assemble_springs(n_dof, springs):
    """Stiffness and damping of linear spring-dashpots acting on linear combinations of dofs.

    Parameters
    ----------
    n_dof : int
    springs : iterable of (k, c, terms)
        ``k`` [N/m], ``c`` [N·s/m]; ``terms`` is a sequence of (dof, coefficient) defining the
        spring's elongation δ = Σ coefficient·u[dof] = bᵀu. Its strain energy ½kδ² = ½uᵀ(k b bᵀ)u.

    Returns
    -------
    K, C : ndarray, shape (n_dof, n_dof)
        Σ k b bᵀ and Σ c b bᵀ.
    """
    K = np.zeros((n_dof, n_dof))
    C = np.zeros((n_dof, n_dof))
    for k, c, terms in springs:
        b = np.zeros(n_dof)
        for dof, coef in terms:
            b[dof] += coef
        K += k * np.outer(b, b)
        C += c * np.outer(b, b)
    return K, C


def _multibody(name, kind, masses, dof_names, springs, wheel_dofs, wheel_offsets, g):
    """A car of lumped rigid bodies: M = diag(masses); translational dofs are named '*_y'."""
    masses = np.asarray(masses, dtype=np.float64)
    K, C = _assemble_springs(masses.size, springs)
    translational = np.array([dof.endswith('_y') for dof in dof_names])
    return Car(name=name, kind=kind, M=np.diag(masses), C=C, K=K,
               gravity_load=np.where(translational, -g * masses, 0.0),
               wheel_dofs=wheel_dofs, wheel_offsets=wheel_offsets, dof_names=dof_names)


def moving_mass(m, g=GRAVITY, name='moving mass'):
    """A rigid mass m [kg] riding on the rail: one dof, 'wheel1_y'; static load m g."""
    _check('moving_mass', positive=[('m', m), ('g', g)])
    return _multibody(name, 'moving_mass', [m], ('wheel1_y',), (), [0], [0.0], g)


def sprung_mass(m_s, k_s, c_s=0.0, m_w=0.0, g=GRAVITY, name='sprung mass'):
    """A mass m_s [kg] on a spring k_s [N/m] and dashpot c_s [N·s/m] over a wheel of mass m_w [kg].

    Dofs ['body_y', 'wheel1_y']. With ``m_w = 0`` the wheel dof is massless; it is the constrained
    contact point, which the coupled solver eliminates. Static wheel load (m_s + m_w) g.
    """
    _check('sprung_mass', positive=[('m_s', m_s), ('k_s', k_s), ('g', g)],
           nonnegative=[('c_s', c_s), ('m_w', m_w)])
    springs = [_spring(k_s, c_s, _point(0), _point(1))]
    return _multibody(name, 'sprung_mass', [m_s, m_w], ('body_y', 'wheel1_y'), springs, [1], [0.0], g)


def four_dof_car(m_c, J_c, m_w, k_s, c_s, l_c, g=GRAVITY, name='four-dof car'):
    """The car of Fedorova & Sivaselvan (2017), Eq. 2: body bounce and pitch over two wheels.

    Dofs ['body_y', 'body_rz', 'wheel1_y', 'wheel2_y']. Wheel 1 leads, at +l_c/2 ahead of the body
    centre; wheel 2 trails at −l_c/2. Each wheel carries a suspension k_s, c_s to the body point
    above it, whose displacement is y ± (l_c/2)·rz (rz counter-clockwise: the front rises for
    rz > 0). Hence, with u = [y, rz, w1, w2],

    ``K = k_s [[2, 0, −1, −1], [0, l_c²/2, −l_c/2, l_c/2], [−1, −l_c/2, 1, 0], [−1, l_c/2, 0, 1]]``

    and C likewise with c_s; ``M = diag(m_c, J_c, m_w, m_w)``. Wheel offsets [0, l_c].

    Parameters
    ----------
    m_c : float
        Body mass [kg].
    J_c : float
        Body pitch inertia about its centre [kg·m²].
    m_w : float
        Mass of each wheel [kg].
    k_s, c_s : float
        Suspension stiffness [N/m] and damping [N·s/m] at each wheel.
    l_c : float
        Wheel (axle) spacing [m].
    g : float
        Gravity [m/s²].
    name : str

    References
    ----------
    Fedorova & Sivaselvan (2017), Eng. Struct. 148, Eq. (2).
    """
    _check('four_dof_car', positive=[('m_c', m_c), ('J_c', J_c), ('m_w', m_w), ('k_s', k_s),
                                     ('l_c', l_c), ('g', g)], nonnegative=[('c_s', c_s)])
    springs = [_spring(k_s, c_s, _point(0, 1, +l_c / 2), _point(2)),
               _spring(k_s, c_s, _point(0, 1, -l_c / 2), _point(3))]
    return _multibody(name, 'four_dof', [m_c, J_c, m_w, m_w],
                      ('body_y', 'body_rz', 'wheel1_y', 'wheel2_y'), springs, [2, 3], [0.0, l_c], g)


def ten_dof_car(params, g=GRAVITY, name='ten-dof car'):
    """A body on two bogies on four wheelsets (Cantero's TTB-2D car).

    Dofs ['body_y', 'body_rz', 'bogie1_y', 'bogie1_rz', 'bogie2_y', 'bogie2_rz', 'wheel1_y', …,
    'wheel4_y'], front to rear. Bogie 1 is centred Lc/2 ahead of the body centre, bogie 2 Lc/2
    behind; the secondary suspension joins each bogie centre to the body point above it. Each
    bogie's two wheelsets sit at ±Lb/2 from its centre, joined by the primary suspension.
    Rotations counter-clockwise (see the module docstring). Wheel offsets [0, Lb, Lc, Lc + Lb].

    Parameters
    ----------
    params : mapping
        Exactly the keys of :data:`TEN_DOF_PARAMETERS`: body_mass [kg], body_pitch_inertia
        [kg·m²], bogie_mass, bogie_pitch_inertia, wheelset_mass, primary_stiffness [N/m] and
        primary_damping [N·s/m] per wheelset, secondary_stiffness and secondary_damping per bogie,
        bogie_centre_spacing Lc [m], axle_spacing Lb [m]. 2-D values (per-side springs doubled).
    g : float
        Gravity [m/s²].
    name : str

    References
    ----------
    Cantero, TTB-2D (github.com/DanielCanteroNTNU/TTB-2D).
    """
    where = 'ten_dof_car'
    missing = set(TEN_DOF_PARAMETERS) - set(params)
    unknown = set(params) - set(TEN_DOF_PARAMETERS)
    if missing or unknown:
        raise ModelError(f"{where}: missing parameters {sorted(missing)}, unknown {sorted(unknown)}; "
                         f"expected {list(TEN_DOF_PARAMETERS)}")
    p = {key: as_number(value, where, key) for key, value in params.items()}
    _check(where, positive=[(k, v) for k, v in p.items() if not k.endswith('damping')] + [('g', g)],
           nonnegative=[(k, v) for k, v in p.items() if k.endswith('damping')])
    Lc, Lb = p['bogie_centre_spacing'], p['axle_spacing']
    if Lc <= Lb:
        raise ModelError(f"{where}: bogie_centre_spacing ({Lc}) must exceed axle_spacing ({Lb})")
    springs = []
    for j, a in enumerate((Lc / 2, -Lc / 2)):
        bogie_y, bogie_rz = 2 + 2 * j, 3 + 2 * j
        springs.append(_spring(p['secondary_stiffness'], p['secondary_damping'],
                               _point(0, 1, a), _point(bogie_y)))
        for i, b in enumerate((Lb / 2, -Lb / 2)):
            springs.append(_spring(p['primary_stiffness'], p['primary_damping'],
                                   _point(bogie_y, bogie_rz, b), _point(6 + 2 * j + i)))
    masses = [p['body_mass'], p['body_pitch_inertia']] + 2 * [p['bogie_mass'], p['bogie_pitch_inertia']] \
        + 4 * [p['wheelset_mass']]
    dof_names = ('body_y', 'body_rz', 'bogie1_y', 'bogie1_rz', 'bogie2_y', 'bogie2_rz',
                 'wheel1_y', 'wheel2_y', 'wheel3_y', 'wheel4_y')
    return _multibody(name, 'ten_dof', masses, dof_names, springs, [6, 7, 8, 9],
                      [0.0, Lb, Lc, Lc + Lb], g)


def _catalogue():
    text = resources.files(__package__).joinpath('data', 'cars_2d.json').read_text(encoding='utf-8')
    return {key: value for key, value in json.loads(text).items() if not key.startswith('_')}


def car_catalogue() -> tuple:
    """Names of the 10-dof parameter sets shipped in ``data/cars_2d.json``."""
    return tuple(_catalogue())


def car_from_catalogue(name, g=GRAVITY):
    """A 10-dof car (:func:`ten_dof_car`) from the shipped parameter sets.

    Parameters
    ----------
    name : str
        'ICE3_coach', 'Shinkansen_300', 'Manchester_benchmark', 'Eurostar_coach' or
        'Chinese_Star_power_car' (see :func:`car_catalogue`).
    g : float
        Gravity [m/s²].

    Raises
    ------
    ValueError
        For an unknown name, listing the valid ones.

    References
    ----------
    Cantero, TTB-2D train files, citing Goicolea (2014) for the ICE3/AVE S103 coaches C2, C3, C6,
    C7; Wu & Yang (2003) for the Shinkansen 300; Iwnicki (1998) for the Manchester benchmark;
    Doménech (2014) for the Eurostar coach; Zhai et al. (2009) for the Chinese Star power car.
    """
    catalogue = _catalogue()
    if name not in catalogue:
        raise ModelError(f"car_from_catalogue: unknown car {name!r}; valid names: {list(catalogue)}")
    return ten_dof_car(catalogue[name], g=g, name=name)
