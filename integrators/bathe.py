"""Bathe's composite scheme: trapezoidal rule to ``t + γΔt``, then the three-point backward
Euler formula to ``t + Δt``. With γ = ½ it is second order and ``ρ∞ = 0``. (OpenSees's TRBDF2 is the same
scheme but advances one *sub-step* per analysis step.)

γ is taken in :data:`GAMMA_RANGE` = [10⁻³, 1 − 10⁻³]. Below it round-off grows like ε/γ through
``c₂ = −1/((1 − γ)γΔt)``: 500 steps of an undamped oscillator (ω = 20 rad/s, Δt = 1 ms, amplitude
1) differ from the scheme in 50-digit arithmetic by 2.8e-11 at γ = 10⁻³, 4e-10 at 10⁻⁴, 8e-8 at
10⁻⁸, 2.9e-3 at 10⁻¹² (where the contract's consistency check fails or passes with Δt). Near
either end the scheme damps little below ωΔt = 1/γ, resp. 1/(1 − γ) (spectral radius ρ = 0.89,
resp. 0.71, there, and → 1 below, as the trapezoidal rule): at γ = 10⁻⁶ or 1 − 10⁻⁶,
ρ(ωΔt = 10⁴) = 0.99999, no damping where Bathe is chosen for it, though
:attr:`Integrator.dissipative` would still say True. Inside the range ρ(10⁴) <= 0.2.

References
----------
Bathe, K.J., Baig, M.M.I. (2005) On a composite implicit time integration procedure for
nonlinear dynamics. Comput. Struct. 83, 2513-2524.
Bathe, K.J. (2007) Conserving energy and momentum in nonlinear dynamics: a simple implicit
time integration scheme. Comput. Struct. 85, 437-445.
"""
import numpy as np

from .base import Integrator, Stage, check_parameter, number, register

#: The γ that :class:`Bathe` takes (see the module docstring for why).
GAMMA_RANGE = (1e-3, 1.0 - 1e-3)


@register
class Bathe(Integrator):
    """Two stages per step; stage 2 uses ``v = c1 u_n + c2 u_γ + c3 u``, ``a = c1 v_n + c2 v_γ + c3 v``
    with ``c1 = (1-γ)/(γΔt)``, ``c2 = -1/((1-γ)γΔt)``, ``c3 = (2-γ)/((1-γ)Δt)``. ``gamma`` in
    :data:`GAMMA_RANGE` = [0.001, 0.999], else an AnalysisError (default ½, TRBDF2)."""

    name = "Bathe"
    n_stages = 2

    def __init__(self, gamma=0.5):
        self.gamma = number(self.name, "gamma", gamma)
        check_parameter(self.name, "gamma", self.gamma, *GAMMA_RANGE,
                        why="below it round-off grows like 1e-16/gamma through c2 = -1/((1 - gamma) gamma dt); "
                            "near either end the scheme damps little below omega*dt = 1/gamma, resp. 1/(1 - gamma)")

    def force_record_weights(self):
        """From the two stages' velocity updates, v_{n+1} = v_n + Δt (w₀ a_n + w₁ a_γ + w₂ a_{n+1})
        with w₀ = w₁ = 1/(2(2 − γ)), w₂ = (1 − γ)/(2 − γ) (1/3 each for γ = 1/2)."""
        g = self.gamma
        return np.array([0.5 / (2.0 - g), 0.5 / (2.0 - g), (1.0 - g) / (2.0 - g)])

    def stages(self, dt):
        g = self.gamma
        h = g * dt
        du1 = self.coefficients(u_n=1.0, v_n=h, a_n=h * h / 4.0, a=h * h / 4.0)
        dv1 = self.coefficients(v_n=1.0, a_n=h / 2.0, a=h / 2.0)
        c1 = (1.0 - g) / (g * dt)
        c2 = -1.0 / ((1.0 - g) * g * dt)
        c3 = (2.0 - g) / ((1.0 - g) * dt)
        dv2 = self.coefficients(v_n=-c1 / c3, slot4=-c2 / c3, a=1.0 / c3)
        du2 = self.coefficients(u_n=-c1 / c3, slot3=-c2 / c3) + dv2 / c3
        return [Stage(du=du1, dv=dv1, ku=du1, kv=dv1, load=[(g, 1.0)], theta=g),
                Stage(du=du2, dv=dv2, ku=du2, kv=dv2, load=[(1.0, 1.0)], theta=1.0)]
