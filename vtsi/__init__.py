"""vtsi: dynamic analysis of trains crossing railway bridges (vehicle-track-structure interaction).

Object API: :class:`Model`, analyses (:class:`StaticAnalysis`, :class:`TransientAnalysis`,
:func:`eigen`), integrators (:mod:`vtsi.integrators`), elements (:mod:`vtsi.elements`),
recorders (:mod:`vtsi.recorders`). OpenSees-style commands: :mod:`vtsi.opensees`.

Glossary (used throughout): K, C, M stiffness, damping, mass matrices; u, v, a displacement,
velocity, acceleration; P load; λ contact force (compression positive); SI units.
"""
from vtsi.analysis import StaticAnalysis, TransientAnalysis, domain_state, eigen
from vtsi.errors import AnalysisError, CommandError, DivergenceError, ModelError, VtsiError
from vtsi.model import Model
from vtsi.timeseries import Constant, Linear, Path
from vtsi.version import __version__
from vtsi import recorders  # vtsi.recorders.NodeRecorder etc.

__all__ = ["__version__", "recorders", "Model", "StaticAnalysis", "TransientAnalysis", "eigen", "domain_state",
           "Constant", "Linear", "Path",
           "VtsiError", "ModelError", "AnalysisError", "DivergenceError", "CommandError"]
