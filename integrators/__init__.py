"""Time integrators (``vtsi.integrators``), chosen by name or class: see :mod:`.base`."""
from .base import INTEGRATORS, Integrator, Stage, make_integrator, register
from .bathe import Bathe
from .generalized_alpha import GeneralizedAlpha
from .newmark import HHT, CentralDifference, Newmark
from .trbdf2 import TRBDF2

__all__ = ["INTEGRATORS", "Integrator", "Stage", "make_integrator", "register",
           "Newmark", "HHT", "CentralDifference", "Bathe", "GeneralizedAlpha", "TRBDF2"]
