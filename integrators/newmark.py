"""Newmark's family: Newmark(γ, β), HHT-α (OpenSees's α in [2/3, 1]) and central difference.

References
----------
Newmark, N.M. (1959) A method of computation for structural dynamics. J. Eng. Mech. Div. 85(3).
Hilber, H.M., Hughes, T.J.R., Taylor, R.L. (1977) Improved numerical dissipation for time
integration algorithms in structural dynamics. Earthq. Eng. Struct. Dyn. 5, 283-292.
Hughes, T.J.R. (1987) The Finite Element Method, §9.3 (stability limits).

β is 0 (central differences, explicit) or at least :data:`BETA_MIN` = 10⁻⁶. A displacement the
step imposes (a wheel held to the rail in a coupled analysis) fixes ``β Δt² a``, so its
acceleration is that displacement's change divided by ``β Δt²``, and the round-off ε of the
displacement returns to the next step's as ``ε (½ − β)/β``: ε/(2β) of the response a step,
whatever Δt. The S2 sprung mass (Yang & Yau, tests/test_coupled.py, 10 elements) with γ = ½ and
Δt = 0.1 ms or 25 µs, each against β = 10⁻⁴: car body 3e-11 and contact force 9e-8 off at most
at β = 10⁻⁶ (as at 10⁻⁵), 4e-9 and 4e-6 at 10⁻⁸, 1e-4 and 7e-3 to 2e-2 at 10⁻¹², divergence at
10⁻¹⁴, NaN at 10⁻³⁰⁰. What β itself changes in a step is ``β Ω²`` against the mass's 1 (Ω = ωΔt,
below the stability limit 1/√(γ/2 − β), about 2 for a small β): at most 4·10⁻⁶ at 10⁻⁶, so a
smaller β buys nothing over β = 0 and costs the round-off above (and an implicit solve).
"""
import numpy as np

from vtsi.errors import AnalysisError

from .base import Integrator, Stage, check_parameter, number, register

#: The smallest β > 0 Newmark and HHT take (see the module docstring: β = 0 or β >= BETA_MIN).
BETA_MIN = 1e-6


@register
class Newmark(Integrator):
    """Newmark's method; argument order ``(gamma, beta)`` as OpenSees's ``integrator Newmark``.

    ``u_{n+1} = u_n + Δt v_n + Δt² ((½ - β) a_n + β a_{n+1})``,
    ``v_{n+1} = v_n + Δt ((1 - γ) a_n + γ a_{n+1})``, equilibrium at ``t_{n+1}``.
    Unconditionally stable for ``2β >= γ >= ½``; else stable for ``ωΔt <= 1/√(γ/2 - β)``.
    ``γ`` in [½, 1], ``β`` 0 (central differences) or in [:data:`BETA_MIN`, 1] = [10⁻⁶, 1].
    Default: average acceleration (trapezoidal rule, γ = ½, β = ¼).
    """

    name = "Newmark"
    n_stages = 1

    def __init__(self, gamma=0.5, beta=0.25):
        self.gamma, self.beta = number(self.name, "gamma", gamma), number(self.name, "beta", beta)
        check_parameter(self.name, "gamma", self.gamma, 0.5, 1.0,
                        why="gamma < 1/2 amplifies every mode (unstable); gamma > 1 is first-order damped beyond use")
        check_parameter(self.name, "beta", self.beta, 0.0, 1.0)
        if 0.0 < self.beta < BETA_MIN:
            raise AnalysisError(f"integrator {self.name}: beta = {self.beta:g} is neither 0 (central differences) nor "
                                f">= {BETA_MIN:g}: a displacement the step imposes (a wheel held to the rail) gives an "
                                "acceleration divided by beta dt^2, whose round-off returns as eps/(2 beta) of the "
                                "response a step (contact forces 1e-2 off at beta = 1e-12)")
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
    (Hilber's α_H = α - 1). Defaults ``γ = 3/2 - α``, ``β = (2 - α)²/4`` give second order,
    unconditional stability and spectral radius ``ρ∞ = α/(2 - α)``, which is
    ``(1 + α_H)/(1 - α_H)`` in Hilber's form.

    Other ``γ, β`` (OpenSees's ``integrator HHT α γ β``) need ``γ >= 3/2 - α`` (else the algorithmic
    damping is negative and every slow mode grows: ``ρ ≈ 1 + (3/2 - α - γ) Ω²/2``); their stability
    limit is computed from the characteristic polynomial (see :func:`hht_stability_limit`) and a
    choice unstable at every practical step is refused.
    ``α`` has no default, as in OpenSees: ``'HHT'`` by name alone was the undamped trapezoidal
    rule (α = 1), which a user asking for HHT's dissipation did not get.
    """

    name = "HHT"

    def __init__(self, alpha=None, gamma=None, beta=None):
        if alpha is None:
            raise AnalysisError("integrator HHT: give alpha (OpenSees convention, 2/3 <= alpha <= 1; 1 is Newmark's "
                                "undamped trapezoidal rule), e.g. HHT(0.9) or 'HHT(0.9)'")
        self.alpha = number(self.name, "alpha", alpha)
        check_parameter(self.name, "alpha", self.alpha, 2.0 / 3.0, 1.0,
                        why="OpenSees convention; alpha = 1 is the trapezoidal rule")
        super().__init__(1.5 - self.alpha if gamma is None else gamma,
                         (2.0 - self.alpha) ** 2 / 4.0 if beta is None else beta)
        self._limit = None
        if gamma is None and beta is None:
            return                                   # Hilber et al. (1977): unconditionally stable
        if self.gamma < 1.5 - self.alpha - 1e-12:
            raise AnalysisError(f"integrator {self.name}: gamma = {self.gamma:g} is below 3/2 - alpha = "
                                f"{1.5 - self.alpha:g}: its algorithmic damping is negative and every slow mode grows "
                                f"(spectral radius 1 + {(1.5 - self.alpha - self.gamma) / 2:.3g} (omega*dt)^2 "
                                "as omega*dt -> 0)")
        self._limit = hht_stability_limit(self.alpha, self.gamma, self.beta)
        if self._limit == 0.0:
            raise AnalysisError(f"integrator {self.name}: beta = {self.beta:g} is too small for alpha = "
                                f"{self.alpha:g}, gamma = {self.gamma:g}: unstable already at omega*dt = 0.1 "
                                "(raise beta, or omit gamma and beta)")

    def stages(self, dt):
        du, dv = self._newmark_update(dt)
        a = self.alpha
        ku = a * du + self.coefficients(u_n=1.0 - a)
        kv = a * dv + self.coefficients(v_n=1.0 - a)
        return [Stage(du=du, dv=dv, ku=ku, kv=kv, load=[(a, 1.0)], force_weight=a)]

    def stability_limit(self, dt):
        return self._limit


def hht_stability_limit(alpha, gamma, beta, tol=1e-10):
    """Largest stable ``Ω = ωΔt`` of undamped HHT(α, γ, β) (OpenSees α), or None if stable for
    every Ω (up to 1e8).

    The roots of the characteristic polynomial (``u_n ∝ λⁿ``)

        λ (λ - 1)² + Ω² (αλ + 1 - α) (βλ² + (½ - 2β + γ) λ + ½ + β - γ) = 0

    leave the unit disc either through λ = -1, at ``Ω = 1/√((2α - 1)(γ/2 - β))`` (Newmark's
    limit when α = 1), or, for small β, earlier through a complex pair (and stay out: the
    unstable set is ``[limit, ∞)``); the limit is the first Ω in ``[0.1, ...]`` with spectral
    radius above ``1 + tol``, found on a log grid and refined by bisection. ``0.0`` means
    "unstable already at Ω = 0.1", the smallest Ω checked.
    """
    crossing = (2.0 * alpha - 1.0) * (0.5 * gamma - beta)
    top = 1.0 / np.sqrt(crossing) if crossing > 0.0 else 1e8
    tail = np.array([beta, 0.5 - 2.0 * beta + gamma, 0.5 + beta - gamma])
    forcing = np.polymul([alpha, 1.0 - alpha], tail)

    def unstable(omega_dt):
        poly = np.polyadd([1.0, -2.0, 1.0, 0.0], omega_dt * omega_dt * forcing)
        return np.max(np.abs(np.roots(poly))) > 1.0 + tol

    grid = np.geomspace(0.1, top, max(2, int(25 * np.log10(top / 0.1)) + 1))
    grid[-1] = top * (1.0 - 1e-9)               # just below the λ = -1 crossing
    bad = next((i for i, om in enumerate(grid) if unstable(om)), None)
    if bad is None:
        return None if crossing <= 0.0 else top
    if bad == 0:
        return 0.0
    lo, hi = grid[bad - 1], grid[bad]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if unstable(mid) else (mid, hi)
    return lo
