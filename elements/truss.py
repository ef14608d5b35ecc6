"""2-D elastic truss: axial stiffness only, on the nodes' translations.

Dofs per element: ``[ux1, uy1, ux2, uy2]`` in global axes [m]. With ``c, s`` the direction
cosines of node 1 → node 2 and ``e = (c, s)``, the elongation is ``δ = e·(u2 − u1)`` and

    K = EA/L [ e eᵀ  −e eᵀ ; −e eᵀ  e eᵀ ]                               [N/m]
    M = ρL/2 I₄ (lumped)   or   ρL/6 [2 I₂  I₂ ; I₂  2 I₂] (consistent)   [kg]

The consistent mass couples the two nodes on both translations, the transverse one included
(a rigid-body translation across the bar carries the whole mass ρL either way), so M is the same
in every orientation.

References
----------
OpenSees ``SRC/element/truss/Truss.cpp``: ``getTangentStiff``, ``getMass`` (lumped ``0.5*rho*L``
on each translation; ``-cMass``: ``rho*L/6 * [2 1; 1 2]`` per translation), ``getDamp``
(Rayleigh damping only with ``-doRayleigh 1``, default 0) and ``setResponse`` (``axialForce`` =
``basicForce``, ``basicDeformation``, ``localForce``).
"""
import numpy as np
from numba import njit

from .base import ElementType, register, rotation_2d


@njit(cache=True)
def _global_stiffness(axial, c, s):
    """``(n_el, 4, 4)`` global stiffness of bars of axial stiffness ``axial = EA/L`` [N/m]."""
    n = axial.shape[0]
    k = np.zeros((n, 4, 4))
    for e in range(n):
        d = (c[e], s[e])
        for i in range(2):
            for j in range(2):
                v = axial[e] * d[i] * d[j]
                k[e, i, j] = v
                k[e, i + 2, j + 2] = v
                k[e, i, j + 2] = -v
                k[e, i + 2, j] = -v
    return k


@njit(cache=True)
def _mass(rho, L, consistent):
    """``(n_el, 4, 4)`` lumped (``consistent[e] == 0``) or consistent translational mass [kg]."""
    n = rho.shape[0]
    m = np.zeros((n, 4, 4))
    for e in range(n):
        total = rho[e] * L[e]
        for i in range(2):
            if consistent[e] != 0.0:
                m[e, i, i] = m[e, i + 2, i + 2] = total / 3.0
                m[e, i, i + 2] = m[e, i + 2, i] = total / 6.0
            else:
                m[e, i, i] = m[e, i + 2, i + 2] = total / 2.0
    return m


@register
class Truss2d(ElementType):
    """Elastic truss bar: area ``A`` [m²], modulus ``E`` [Pa], mass per length ``rho`` [kg/m];
    ``cmass`` 0 lumped, 1 consistent mass (OpenSees ``-cMass``); ``do_rayleigh`` 1 to include the
    bar's stiffness in the Rayleigh βK term, 0 (OpenSees's default) to leave it out.

    Responses: ``'force'``/``'globalForce'`` ``[Fx1, Fy1, Fx2, Fy2]`` [N] (global resisting force);
    ``'axialForce'``/``'basicForce'`` ``[N]`` [N], tension positive; ``'localForce'``
    ``[−N, 0, N, 0]`` [N] in element axes; ``'basicDeformation'``/``'deformation'`` ``[δ]`` [m],
    elongation positive; ``'basicStiffness'`` ``[EA/L]`` [N/m].
    """

    name = "truss"
    node_dofs = (0, 1)
    param_names = ("A", "E", "rho", "cmass", "do_rayleigh")
    positive = ("A", "E")
    non_negative = ("rho",)
    flags = ("cmass", "do_rayleigh")
    defaults = {"rho": 0.0, "cmass": 0.0, "do_rayleigh": 0.0}
    response_kinds = ("force", "globalForce", "axialForce", "basicForce", "localForce",
                      "basicDeformation", "deformation", "basicStiffness")

    def stiffness(self, coords, params):
        c, s, L = rotation_2d(coords)
        return _global_stiffness(params[:, 0] * params[:, 1] / L, c, s)

    def mass(self, coords, params):
        _, _, L = rotation_2d(coords)
        return _mass(np.ascontiguousarray(params[:, 2]), L, np.ascontiguousarray(params[:, 3]))

    def rayleigh_weights(self, params):
        """Factor on each bar's stiffness in the Rayleigh βK term (its ``do_rayleigh``)."""
        return np.ascontiguousarray(params[:, 4])

    def response(self, kind, coords, params, u_e, v_e):
        if kind == "basicStiffness":
            _, _, L = rotation_2d(coords)
            return (params[:, 0] * params[:, 1] / L)[:, None]
        if kind in ("axialForce", "basicForce", "localForce", "basicDeformation", "deformation"):
            c, s, L = rotation_2d(coords)
            elongation = c * (u_e[:, 2] - u_e[:, 0]) + s * (u_e[:, 3] - u_e[:, 1])
            if kind in ("basicDeformation", "deformation"):
                return elongation[:, None]
            axial = params[:, 0] * params[:, 1] / L * elongation
            if kind == "localForce":
                zero = np.zeros_like(axial)
                return np.stack([-axial, zero, axial, zero], axis=1)
            return axial[:, None]
        return super().response(kind, coords, params, u_e, v_e)
