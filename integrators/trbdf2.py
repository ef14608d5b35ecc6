"""TR-BDF2 (Bank et al. 1985): a trapezoidal sub-step to ``t + Δt/2``, then the three-point
backward (BDF2) formula to ``t + Δt``: Bathe's composite scheme with γ = ½ (second order,
``ρ∞ = 0``).

OpenSees's ``integrator TRBDF2`` counts each sub-step as an analysis step; the command layer
(:mod:`vtsi.commands.analysis_commands`) steps it as this integrator with twice OpenSees's Δt and
records every sub-step.

References
----------
Bank, R.E., Coughran, W.M., Fichtner, W., Grosse, E.H., Rose, D.J., Smith, R.K. (1985) Transient
simulation of silicon devices and circuits. IEEE Trans. Comput.-Aided Des. 4, 436-451.
"""
from .base import register
from .bathe import Bathe


@register
class TRBDF2(Bathe):
    """Bathe's scheme with γ = ½ under its other name; no parameter."""

    name = "TRBDF2"

    def __init__(self):
        super().__init__(0.5)
