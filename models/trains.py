"""Catalogue trains: the ICE3 and EN 1991-2's high-speed load models HSLM-A and HSLM-B, each a
:class:`vtsi.vehicle.Train` (its conventions there: offsets behind the head, speed in +x).

References
----------
.. [1] EN 1991-2:2003, Actions on structures — Traffic loads on bridges, §6.4.6.1.1, Table 6.3 and
   Fig. 6.12 (HSLM-A), Fig. 6.13 (HSLM-B).
.. [2] Cantero, D. TTB-2D (github.com/DanielCanteroNTNU/TTB-2D), AVE S103 / ICE3 train files
   (after Goicolea 2014): bogie-centre spacing 17.375 m, car-end overhangs 3.7 m, nose 4.76 m.
"""
from __future__ import annotations

import json
from importlib import resources

import numpy as np

from vtsi.codes.en1991_2 import HSLM_B_SPAN_RANGE
from vtsi.errors import ModelError, is_count, is_number
from vtsi.vehicle import Train

from .cars import car_from_catalogue

# AVE S103 / ICE3 geometry (TTB-2D, after Goicolea 2014): distance from a bogie centre to the car end.
_ICE3_OVERHANG = 7.4 / 2
_ICE3_NOSE = 4.76


def ice3(n_cars=8, *, speed, name='ICE3'):
    """An ICE3 (AVE S103 / Velaro E) trainset of 10-dof cars.

    Every car uses the 'ICE3_coach' parameter set (coaches C2, C3, C6, C7). Assumptions: the end
    cars reuse the coach's masses, as in TTB-2D's C1/C8 files; the lighter coaches C4/C5 (41.2 t
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

    Each axle is a :func:`~vtsi.vehicle.moving_force` at the same offset as the corresponding
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
# end points (HSLM_B_SPAN_RANGE). NOT VERIFIED against the standard: see hslm_b's docstring and
# docs/trains.md before relying on it; this table is the only place to correct.
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
    L = float(span) if is_number(span) else float('nan')
    if not (np.isfinite(L) and lo <= L < hi):
        raise ModelError(f"hslm_b: span L = {span!r} m is outside the range of EN 1991-2 Figure 6.13, "
                         f"{lo:g} m <= L < {hi:g} m (HSLM-A covers L >= {hi:g} m)"
                         + ("" if is_number(span) else ": L must be a number"))
    s = (L - lo) / (hi - lo)
    N = int(np.floor(_HSLM_B_N[0] + s * (_HSLM_B_N[1] - _HSLM_B_N[0]) + 0.5))
    d = _HSLM_B_D[0] + s * (_HSLM_B_D[1] - _HSLM_B_D[0])
    return N, d


HSLM_B_MAX_FORCES = 100
"""The most forces an HSLM-B given by hand may have (Figure 6.13's N are some tens at most)."""
HSLM_B_MAX_SPACING = 100.0
"""[m] The spacing d an HSLM-B given by hand stays below (Figure 6.13's d are a few metres: a d
of 100 or more is in mm)."""


def hslm_b_given(value, where="hslm_b"):
    """HSLM-B's N and d read from EN 1991-2 Figure 6.13 by the user, checked: ``value`` a pair
    (N, d), N a whole number of forces, 1 <= N <= HSLM_B_MAX_FORCES, d their spacing [m],
    0 < d < HSLM_B_MAX_SPACING. Returns ``(int N, float d)``.

    Raises
    ------
    ModelError
        Naming ``where`` (the setting or option) and the value; a d of 100 or more is taken to be
        in mm and the message says so.
    """
    pair = tuple(value) if isinstance(value, (tuple, list, np.ndarray)) else None
    if pair is None or len(pair) != 2:
        raise ModelError(f"{where}: expected HSLM-B's (N, d), N forces at spacing d [m] read from EN 1991-2 "
                         f"Figure 6.13 for the span, e.g. (15, 3.0); got {value!r}")
    n, d = pair
    if not is_count(n, 1) or n > HSLM_B_MAX_FORCES:
        raise ModelError(f"{where}: N = {n!r} must be a whole number of forces, 1 <= N <= {HSLM_B_MAX_FORCES} "
                         f"(HSLM-B's N from EN 1991-2 Figure 6.13)")
    if not (is_number(d) and np.isfinite(float(d)) and float(d) > 0):
        raise ModelError(f"{where}: d = {d!r} must be a spacing > 0 [m] (HSLM-B's d from EN 1991-2 Figure 6.13)")
    if float(d) >= HSLM_B_MAX_SPACING:
        raise ModelError(f"{where}: d = {d!r} m is no spacing of HSLM-B's forces (a few metres): d is in m; "
                         f"{float(d):g} mm would be {float(d) / 1e3:g} m")
    return int(n), float(d)


def hslm_b(span, speed, parameters=None):
    """The HSLM-B high-speed load model of EN 1991-2 for a simply supported span L < 7 m.

    N point forces of 170 kN at uniform spacing d (EN 1991-2 §6.4.6.1.1(2)), N and d functions of
    the span L in Figure 6.13: ``parameters`` (N, d) as read from the figure by the user
    (:func:`hslm_b_given`), or None for vtsi's reading (:func:`hslm_b_parameters`: linear in L
    from N = 20, d = 2.5 m at L = 1 m to N = 10, d = 3.5 m at L = 7 m; N rounded to the nearest
    integer, halves up; **not verified**). Forces at offsets 0, d, …, (N − 1) d behind the head.

    Parameters
    ----------
    span : float
        L [m], 1 <= L < 7.
    speed : float
        [m/s]
    parameters : (int, float) or None
        (N, d [m]) from Figure 6.13 for this span; None: :func:`hslm_b_parameters`.

    Returns
    -------
    Train
        N force-only cars named 'HSLM-B'; characteristic length d.

    Raises
    ------
    ModelError
        For a span outside 1 m <= L < 7 m, naming the span and the range; bad ``parameters``
        (:func:`hslm_b_given`).

    Notes
    -----
    Source of the N(L), d(L) law: **not verified** against EN 1991-2 (see
    :func:`hslm_b_parameters` and docs/trains.md); give the figure's N and d as ``parameters``
    (a sweep's ``PassageSettings(hslm_b=(N, d))``, ``--hslm-b N,d``). Searches of public stores
    (pages, docs, code) for a statement of Figure 6.13's values found none; the only figures
    found were the MIDAS Civil default HSLM-B vehicle, N = 10 and d = 3.5 m.

    References
    ----------
    EN 1991-2:2003, §6.4.6.1.1(2) and Figure 6.13 (HSLM-B), Table 6.4 (HSLM-B for simply
    supported spans L < 7 m).
    """
    law = hslm_b_parameters(span)                    # the span is checked either way
    N, d = law if parameters is None else hslm_b_given(parameters)
    return Train.from_axle_table(d * np.arange(N), np.full(N, _HSLM_B_P), speed, name='HSLM-B',
                                 characteristic_length=d)
