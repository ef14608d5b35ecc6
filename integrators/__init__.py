"""Time integrators (``vtsi.integrators``), chosen by name or class: see :mod:`.base`."""
from .base import INTEGRATORS, Integrator, Stage, make_integrator, register
from .bathe import Bathe
from .newmark import HHT, CentralDifference, Newmark

__all__ = ["INTEGRATORS", "Integrator", "Stage", "make_integrator", "register",
           "Newmark", "HHT", "CentralDifference", "Bathe"]
