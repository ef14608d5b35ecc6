"""Ready-made models: cars, trains and rail irregularity (imported as ``vtsi.models``), built
from the core vehicle types of :mod:`vtsi.vehicle` (``Car``, ``Train``, ``moving_force`` and
``GRAVITY``, also importable from here).

Conventions: 2-D, x along the track (trains move in +x), y vertical positive up, rotations
counter-clockwise; SI units. See :mod:`vtsi.models.cars`, :mod:`vtsi.models.trains`,
:mod:`vtsi.models.catalogue` (trains by name, for sweeps) and :mod:`vtsi.models.irregularity`.
"""
from vtsi.vehicle import GRAVITY, Car, Train, moving_force

from .cars import (TEN_DOF_PARAMETERS, car_catalogue, car_from_catalogue, four_dof_car, moving_mass, sprung_mass,
                   ten_dof_car)
from .irregularity import Irregularity, fra_psd, german_psd, sample_profile
from .trains import hslm_a, hslm_b, ice3, ice3_axle_loads
from .catalogue import FIDELITIES, catalogue_train, train_names

__all__ = ['GRAVITY', 'TEN_DOF_PARAMETERS', 'Car', 'car_catalogue', 'car_from_catalogue', 'four_dof_car',
           'moving_force', 'moving_mass', 'sprung_mass', 'ten_dof_car', 'Irregularity', 'fra_psd',
           'german_psd', 'sample_profile', 'Train', 'hslm_a', 'hslm_b', 'ice3', 'ice3_axle_loads',
           'FIDELITIES', 'catalogue_train', 'train_names']
