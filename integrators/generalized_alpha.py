"""The generalized-α method (Chung & Hulbert) in OpenSees's convention.

Newmark's update of ``u`` and ``v`` with equilibrium at intermediate points,

    M a_{n+αM} + C v_{n+αF} + K u_{n+αF} = P(t_n + αF Δt),   x_{n+α} = (1 - α) x_n + α x_{n+1},

so that ``αM = αF = 1`` is Newmark's method and ``αM = 1`` is HHT (OpenSees's α). In the stage
form of :mod:`.base` the equation is divided by ``αM``: the unknown is ``a_{n+1}`` with mass
coefficient 1, the mass also weights ``a_n`` by ``km = (1 - αM)/αM`` and the load by ``1/αM``.
In a coupled analysis the contact forces enter like every other force, at ``t_n + αF Δt`` and
divided by αM: ``(αF λ_{n+1} + (1 − αF) λ_n)/αM`` (``force_weight`` αF/αM, mass weight 1/αM).

Defaults ``γ = ½ + αM − αF``, ``β = ¼ (1 + αM − αF)²`` give second order; with
``αM ≥ αF ≥ ½`` the method is unconditionally stable. For a spectral radius ``ρ∞`` in [0, 1]:
``αM = (2 − ρ∞)/(1 + ρ∞)``, ``αF = 1/(1 + ρ∞)`` (OpenSees's convention of Chung & Hulbert's).

References
----------
Chung, J., Hulbert, G.M. (1993) A time integration algorithm for structural dynamics with improved
numerical dissipation: the generalized-α method. J. Appl. Mech. 60, 371-375.
OpenSees ``SRC/analysis/integrator/GeneralizedAlpha.cpp``.
"""
import numpy as np

from vtsi.errors import AnalysisError

from .base import Stage, check_parameter, number, register
from .newmark import Newmark


@register
class GeneralizedAlpha(Newmark):
    """``GeneralizedAlpha(alpha_m, alpha_f, gamma=None, beta=None)``: αM, αF in OpenSees's order,
    then γ, β as OpenSees documents them (``integrator GeneralizedAlpha αM αF <γ β>``; its parser
    reads the third and fourth argument as β then γ, and :mod:`vtsi.opensees` follows the parser).
    Defaults: ``ρ∞ = 0.8`` (αM = 2/3, αF = 5/9), γ, β of second order. Refused (AnalysisError
    naming the parameter and its range): αF outside [½, 1], αM outside [αF, 2], γ < ½ + αM − αF,
    β < γ/2, anything not finite, and, as Newmark's γ <= 1 and β <= 1 from its second-order ½ and
    ¼, γ > 1 + αM − αF and β > (1 + αM − αF)²."""

    name = "GeneralizedAlpha"

    def __init__(self, alpha_m=2.0 / 3.0, alpha_f=5.0 / 9.0, gamma=None, beta=None):
        self.alpha_m = number(self.name, "alpha_m", alpha_m)
        self.alpha_f = number(self.name, "alpha_f", alpha_f)
        check_parameter(self.name, "alpha_f", self.alpha_f, 0.5, 1.0, why="1 gives equilibrium at t_{n+1}")
        check_parameter(self.name, "alpha_m", self.alpha_m, self.alpha_f, 2.0,
                        why="alpha_m >= alpha_f keeps the method unconditionally stable; "
                            "alpha_m = 2, alpha_f = 1 is rho_inf = 0")
        d = self.alpha_m - self.alpha_f
        gamma = 0.5 + d if gamma is None else number(self.name, "gamma", gamma)
        beta = 0.25 * (1.0 + d) ** 2 if beta is None else number(self.name, "beta", beta)
        # OpenSees: unconditionally stable for αM >= αF >= 1/2, β >= 1/4 + (αM - αF)/2 (= γ/2 at the
        # second-order γ); a larger γ (first order, more damping) needs β >= γ/2 (Newmark's 2β >= γ).
        why = ("the unconditionally stable range is gamma >= 1/2 + alpha_m - alpha_f, beta >= gamma/2; "
               "omit gamma and beta for the second-order defaults")
        check_parameter(self.name, "gamma", gamma, 0.5 + d - 1e-12, np.inf, why=why)
        check_parameter(self.name, "beta", beta, 0.5 * gamma - 1e-12, np.inf, why=why)
        # Newmark's upper ends (gamma <= 1, beta <= 1) from the second-order values: at 20 steps a
        # period (αM = αF = 1) beta = 1e4 lengthens the period 31 times, 1e8 3142 times (the response
        # stands still), and gamma = beta = 1e8 too; gamma = beta = 1 (Newmark's ends) takes 37 % of
        # the amplitude a period
        for name, value, most, text, why in (
                ("gamma", gamma, 1.0 + d, "1 + alpha_m - alpha_f, 1/2 above", "damps first-order beyond use"),
                ("beta", beta, (1.0 + d) ** 2, "(1 + alpha_m - alpha_f)^2, 4 times",
                 "lengthens the period beyond use")):
            if value > most:
                raise AnalysisError(f"integrator {self.name}: {name} = {value:g} is above {text} its second-order "
                                    f"value ({most:g}, as Newmark's {name} <= 1): a larger one {why} (at 1e8 a step "
                                    "no longer moves the response)")
        self.gamma, self.beta = gamma, beta      # Newmark's update; its own range of gamma does not apply
        self.explicit = False

    def stages(self, dt):
        du, dv = self._newmark_update(dt)
        am, af = self.alpha_m, self.alpha_f
        ku = (af * du + self.coefficients(u_n=1.0 - af)) / am
        kv = (af * dv + self.coefficients(v_n=1.0 - af)) / am
        km = self.coefficients(a_n=(1.0 - am) / am)
        # a coupled analysis's constraint forces at αF like every force: (αF λ_{n+1} + (1 − αF) λ_n)/αM
        return [Stage(du=du, dv=dv, ku=ku, kv=kv, km=km, load=[(af, 1.0 / am)], force_weight=af / am)]

    def stability_limit(self, dt):
        return None
