"""Newmark's family: Newmark(γ, β), HHT-α (OpenSees's α in [2/3, 1]) and central difference.

References
----------
Newmark, N.M. (1959) A method of computation for structural dynamics. J. Eng. Mech. Div. 85(3).
Hilber, H.M., Hughes, T.J.R., Taylor, R.L. (1977) Improved numerical dissipation for time
integration algorithms in structural dynamics. Earthq. Eng. Struct. Dyn. 5, 283-292.
Hughes, T.J.R. (1987) The Finite Element Method, §9.3 (stability limits).
"""
import numpy as np

from .base import Integrator, Stage, check_parameter, register


@register
class Newmark(Integrator):
    """Newmark's method; argument order ``(gamma, beta)`` as OpenSees's ``integrator Newmark``.

    ``u_{n+1} = u_n + Δt v_n + Δt² ((½ - β) a_n + β a_{n+1})``,
    ``v_{n+1} = v_n + Δt ((1 - γ) a_n + γ a_{n+1})``, equilibrium at ``t_{n+1}``.
    Unconditionally stable for ``2β >= γ >= ½``; else stable for ``ωΔt <= 1/√(γ/2 - β)``.
    Default: average acceleration (trapezoidal rule, γ = ½, β = ¼).
    """

    name = "Newmark"
    n_stages = 1

    def __init__(self, gamma=0.5, beta=0.25):
        self.gamma, self.beta = float(gamma), float(beta)
        check_parameter(self.name, "gamma", self.gamma, 0.5, 1.0,
                        why="gamma < 1/2 amplifies every mode (unstable); gamma > 1 is first-order damped beyond use")
        check_parameter(self.name, "beta", self.beta, 0.0, 1.0)
        self.explicit = self.beta == 0.0

    def _newmark_update(self, dt):
        g, b = self.gamma, self.beta
        du = self.coefficients(u_n=1.0, v_n=dt, a_n=dt * dt * (0.5 - b), a=dt * dt * b)
        dv = self.coefficients(v_n=1.0, a_n=dt * (1.0 - g), a=dt * g)
        return du, dv

    def stages(self, dt):
        du, dv = self._newmark_update(dt)
        return [Stage(du=du, dv=dv, ku=du, kv=dv)]

    def stability_limit(self, dt):
        margin = 0.5 * self.gamma - self.beta
        return None if margin <= 0.0 else 1.0 / np.sqrt(margin)


@register
class CentralDifference(Newmark):
    """Explicit central difference (Newmark γ = ½, β = 0): stable for ``Δt <= 2/ω_max``.
    ``K̂ = M + Δt/2 C`` must be positive definite: every free dof needs mass."""

    name = "CentralDifference"

    def __init__(self):
        super().__init__(0.5, 0.0)


@register
class HHT(Newmark):
    """Hilber-Hughes-Taylor α-method in OpenSees's convention: equilibrium at ``t_n + αΔt`` with
    ``ũ = (1 - α) u_n + α u_{n+1}``, ``ṽ`` alike, inertia at ``t_{n+1}``; ``α`` in [2/3, 1]
    (Hilber's α_H = α - 1). Defaults ``γ = 3/2 - α``, ``β = (2 - α)²/4`` give second order and
    spectral radius ``ρ∞ = α/(2 - α)``, which is ``(1 + α_H)/(1 - α_H)`` in Hilber's form."""

    name = "HHT"

    def __init__(self, alpha=1.0, gamma=None, beta=None):
        self.alpha = float(alpha)
        check_parameter(self.name, "alpha", self.alpha, 2.0 / 3.0, 1.0,
                        why="OpenSees convention; alpha = 1 is the trapezoidal rule")
        super().__init__(1.5 - self.alpha if gamma is None else gamma,
                         (2.0 - self.alpha) ** 2 / 4.0 if beta is None else beta)

    def stages(self, dt):
        du, dv = self._newmark_update(dt)
        a = self.alpha
        ku = a * du + self.coefficients(u_n=1.0 - a)
        kv = a * dv + self.coefficients(v_n=1.0 - a)
        return [Stage(du=du, dv=dv, ku=ku, kv=kv, load=[(a, 1.0)])]
