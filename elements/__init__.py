"""Element library (``vtsi.elements``): importing it registers every shipped element type.

A new type subclasses :class:`ElementType`, follows the contract in :mod:`vtsi.elements.base`
and is registered with :func:`register` (see ``examples/custom_element.py``); the helpers
:func:`rotation_2d` and :func:`rotate_to_global` serve 2-D line elements.
"""
from .base import ELEMENT_TYPES, ElementType, command_element_types, element_type, register, rotation_2d
from .beam_column import ElasticBeamColumn2d
from .kernels import rotate_to_global
from .point_mass import PointMass2d
from .timoshenko import ElasticTimoshenkoBeam2d
from .truss import Truss2d
from .zero_length import ZeroLength2d

__all__ = ["ELEMENT_TYPES", "ElementType", "command_element_types", "element_type", "register", "rotation_2d", "rotate_to_global",
           "ElasticBeamColumn2d", "ElasticTimoshenkoBeam2d", "Truss2d", "ZeroLength2d", "PointMass2d"]
