"""The train catalogue: trains by name, for speed sweeps and the command line.

A catalogue entry is a named train the sweep can build at any speed, at one of the fidelities
it supports:

- ``'force'``: moving forces, one per axle (no train dofs);
- ``'full'``: the train's multibody cars, where the catalogue has their parameters (ICE3: the
  10-dof cars of :func:`~vtsi.models.trains.ice3`).

Names, in catalogue order (:func:`train_names`): 'HSLM-A1' … 'HSLM-A10', 'HSLM-B', 'ICE3'.
Lookup ignores case, and 'A3' or 'B' stand for 'HSLM-A3' and 'HSLM-B'. A name that is an
existing file path ending in '.csv' is an axle table read by
:meth:`~vtsi.vehicle.Train.from_csv` (force only). Units: speed in m/s, span in m, forces
in N (the CSV table is in m and kN).

Every built train carries ``characteristic_length`` D [m] (coach length; HSLM-B: the spacing d;
a CSV table: from its dynamic signature, :mod:`vtsi.signature`, None when it has no regular
spacing), from which a sweep places its resonance speeds v = n0 D / i.

Adding a train is adding one :class:`Entry` to the registry (:func:`register`); nothing in a
sweep branches on a name.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from vtsi.codes.en1991_2 import HSLM_B_SPAN_RANGE
from vtsi.errors import ModelError
from vtsi.vehicle import Train

from .trains import _hslm_table, hslm_a, hslm_b, ice3, ice3_axle_loads

FIDELITIES = ('force', 'full')
"""Train fidelities, coarsest first: 'force' (axle loads) and 'full' (multibody cars)."""


@dataclass(frozen=True)
class Entry:
    """One catalogue train.

    Attributes
    ----------
    name : str
        Catalogue name, e.g. 'HSLM-A3'.
    description : str
        One line with units (what :func:`describe` returns).
    builders : dict
        Fidelity name → ``builder(speed, span) -> Train``; ``speed`` [m/s], ``span`` [m] or None
        (used by trains that depend on the span, ignored by the others). Its keys, in
        :data:`FIDELITIES` order, are the fidelities the train supports.
    """

    name: str
    description: str
    builders: dict

    @property
    def fidelities(self) -> tuple:
        return tuple(f for f in FIDELITIES if f in self.builders)


_REGISTRY: dict = {}


def register(entry: Entry) -> Entry:
    """Add ``entry`` to the catalogue (after the existing ones); returns it.

    Raises
    ------
    ModelError
        If the name is taken (ignoring case) or a fidelity is not one of :data:`FIDELITIES`.
    """
    if entry.name.upper() in {name.upper() for name in _REGISTRY}:
        raise ModelError(f"catalogue: train {entry.name!r} is already registered")
    unknown = [f for f in entry.builders if f not in FIDELITIES]
    if unknown or not entry.builders:
        raise ModelError(f"catalogue: train {entry.name!r} has fidelities {list(entry.builders)}; "
                         f"each must be one of {list(FIDELITIES)}")
    _REGISTRY[entry.name] = entry
    return entry


def _hslm_a_entry(key, row):
    N, D, P = row['N'], row['D_m'], row['P_kN']
    return Entry(
        name=f"HSLM-{key}",
        description=(f"HSLM-{key}: EN 1991-2 high-speed load model, {N} coaches D = {D:g} m, "
                     f"{2 * N + 14} axles of {P:g} kN"),
        builders={'force': lambda speed, span, _n=key: hslm_a(_n, speed)})


def _hslm_b_force(speed, span):
    if span is None:
        lo, hi = HSLM_B_SPAN_RANGE
        raise ModelError(f"catalogue_train: 'HSLM-B' needs the span [m] ({lo:g} m <= L < {hi:g} m), "
                         f"got span=None")
    return hslm_b(span, speed)


def _populate():
    for key, row in _hslm_table().items():
        register(_hslm_a_entry(key, row))
    lo, hi = HSLM_B_SPAN_RANGE
    register(Entry(
        name='HSLM-B',
        description=(f"HSLM-B: EN 1991-2 high-speed load model, N forces of 170 kN at spacing d, "
                     f"by span ({lo:g} m <= L < {hi:g} m)"),
        builders={'force': _hslm_b_force}))
    register(Entry(
        name='ICE3',
        description=("ICE3: 8-car ICE3/AVE S103, 32 axles, 10-dof cars, "
                     "8 x 62 t, car length D = 24.775 m"),
        builders={'force': lambda speed, span: ice3_axle_loads(8, speed=speed),
                  'full': lambda speed, span: ice3(8, speed=speed)}))


_populate()


def train_names() -> list:
    """Catalogue names in catalogue order: 'HSLM-A1' … 'HSLM-A10', 'HSLM-B', 'ICE3'."""
    return list(_REGISTRY)


def _is_csv(name) -> bool:
    return isinstance(name, (str, os.PathLike)) and os.fspath(name).lower().endswith('.csv')


def _csv_entry(path) -> Entry:
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ModelError(f"catalogue: axle table {path!r} is not an existing file")
    return Entry(
        name=path,
        description=f"{path}: axle table from CSV (position_m [m], load_kN [kN]), moving forces",
        builders={'force': lambda speed, span: Train.from_csv(path, speed)})


def _lookup(name) -> Entry:
    if _is_csv(name):
        return _csv_entry(name)
    key = str(name).strip().upper()
    by_key = {n.upper(): entry for n, entry in _REGISTRY.items()}
    entry = by_key.get(key) or by_key.get(f"HSLM-{key}")
    if entry is None:
        raise ModelError(f"catalogue: unknown train {name!r}; valid names: {', '.join(_REGISTRY)} "
                         f"(case-insensitive; 'A1' … 'A10' and 'B' for HSLM; or a path to a .csv axle table)")
    return entry


def describe(name) -> str:
    """One-line description of a catalogue train (or a CSV axle table), with units.

    Raises
    ------
    ModelError
        For an unknown name (the message lists the valid ones).
    """
    return _lookup(name).description


def fidelities(name) -> tuple:
    """The fidelities ``name`` supports, in :data:`FIDELITIES` order.

    HSLM trains and CSV tables: ``('force',)``; ICE3: ``('force', 'full')``.
    """
    return _lookup(name).fidelities


def catalogue_train(name, speed, *, fidelity='force', span=None) -> Train:
    """Build a catalogue train.

    Parameters
    ----------
    name : str or path-like
        A catalogue name (case-insensitive; 'A3' for 'HSLM-A3', 'B' for 'HSLM-B'), or the path of
        an existing '.csv' axle table (:meth:`Train.from_csv`, force only).
    speed : float
        [m/s], ≥ 0.
    fidelity : {'force', 'full'}
        'force': moving forces, one per axle; 'full': multibody cars (ICE3 only).
    span : float, optional
        Span L [m] of the bridge; required by 'HSLM-B' (1 m <= L < 7 m), ignored by the others.

    Returns
    -------
    Train
        With ``characteristic_length`` D [m] (a CSV table's from its dynamic signature, None
        when it has no regular spacing).

    Raises
    ------
    ModelError
        Unknown name (the message lists the valid names); a fidelity that is not one of
        :data:`FIDELITIES` or that the train lacks (naming train, fidelity and what it supports);
        'HSLM-B' without a span or with a span outside its range; bad speed.
    """
    if fidelity not in FIDELITIES:
        raise ModelError(f"catalogue_train: unknown fidelity {fidelity!r} for train {str(name)!r}; "
                         f"valid: {list(FIDELITIES)}")
    entry = _lookup(name)
    if fidelity not in entry.builders:
        hint = ("; a sweep takes one fidelity for all its trains: sweep and check this train as moving forces "
                "(cars='force', --cars force) apart from the trains of cars" if fidelity == "full" else "")
        raise ModelError(f"catalogue_train: train {entry.name!r} has no fidelity {fidelity!r}; "
                         f"it supports {list(entry.fidelities)}{hint}")
    return entry.builders[fidelity](speed, span)
