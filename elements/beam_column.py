"""2-D elastic Euler-Bernoulli beam-column with a linear geometric transformation.

Dofs per element: ``[ux1, uy1, rz1, ux2, uy2, rz2]`` in global axes (N, m, rad).

References
----------
Przemieniecki, J.S. (1968) Theory of Matrix Structural Analysis, ch. 5 and 11.
OpenSees ``SRC/element/elasticBeamColumn/ElasticBeam2d.cpp`` (mass conventions).
"""
import numpy as np
from numba import njit

from .base import AXIS_RESPONSES, ElementType, axis_vectors, register, rotation_2d
from .kernels import rotate_to_global


@njit(cache=True)
def _local_stiffness(A, E, I, L):
    n = A.shape[0]
    k = np.zeros((n, 6, 6))
    for e in range(n):
        ea = E[e] * A[e] / L[e]
        ei = E[e] * I[e]
        l1, l2, l3 = L[e], L[e] * L[e], L[e] * L[e] * L[e]
        k[e, 0, 0] = k[e, 3, 3] = ea
        k[e, 0, 3] = k[e, 3, 0] = -ea
        k[e, 1, 1] = k[e, 4, 4] = 12.0 * ei / l3
        k[e, 1, 4] = k[e, 4, 1] = -12.0 * ei / l3
        k[e, 1, 2] = k[e, 2, 1] = k[e, 1, 5] = k[e, 5, 1] = 6.0 * ei / l2
        k[e, 4, 2] = k[e, 2, 4] = k[e, 4, 5] = k[e, 5, 4] = -6.0 * ei / l2
        k[e, 2, 2] = k[e, 5, 5] = 4.0 * ei / l1
        k[e, 2, 5] = k[e, 5, 2] = 2.0 * ei / l1
    return k


@njit(cache=True)
def _local_consistent_mass(rho, L):
    n = rho.shape[0]
    m = np.zeros((n, 6, 6))
    for e in range(n):
        l1 = L[e]
        ax = rho[e] * l1 / 6.0
        m[e, 0, 0] = m[e, 3, 3] = 2.0 * ax
        m[e, 0, 3] = m[e, 3, 0] = ax
        b = rho[e] * l1 / 420.0
        m[e, 1, 1] = m[e, 4, 4] = 156.0 * b
        m[e, 1, 4] = m[e, 4, 1] = 54.0 * b
        m[e, 1, 2] = m[e, 2, 1] = 22.0 * l1 * b
        m[e, 4, 5] = m[e, 5, 4] = -22.0 * l1 * b
        m[e, 1, 5] = m[e, 5, 1] = -13.0 * l1 * b
        m[e, 2, 4] = m[e, 4, 2] = 13.0 * l1 * b
        m[e, 2, 2] = m[e, 5, 5] = 4.0 * l1 * l1 * b
        m[e, 2, 5] = m[e, 5, 2] = -3.0 * l1 * l1 * b
    return m


@njit(cache=True)
def _global_mass(rho, cmass, c, s, L):
    """Global mass matrices ``(n_el, 6, 6)`` [kg, kg m, kg m²]: consistent where ``cmass`` is 1,
    else lumped (ρL/2 on ux and uy of each node, invariant under rotation)."""
    m = rotate_to_global(_local_consistent_mass(rho, L), c, s, 2, 3)
    for e in range(rho.shape[0]):
        if cmass[e] == 0.0:
            m[e] = 0.0
            half = 0.5 * rho[e] * L[e]
            m[e, 0, 0] = m[e, 1, 1] = m[e, 3, 3] = m[e, 4, 4] = half
    return m


@njit(cache=True)
def _local_end_forces(coords, forces):
    """Global end forces ``(n_el, 6)`` of 2-node beams rotated into element axes (N, V, M per
    node)."""
    c, s, _ = rotation_2d(coords)
    out = np.empty_like(forces)
    for e in range(forces.shape[0]):
        for o in (0, 3):
            out[e, o] = c[e] * forces[e, o] + s[e] * forces[e, o + 1]
            out[e, o + 1] = -s[e] * forces[e, o] + c[e] * forces[e, o + 1]
            out[e, o + 2] = forces[e, o + 2]
    return out


@njit(cache=True)
def _basic_deformations(coords, u):
    """Basic deformations ``(n_el, 3)`` of 2-node beams from their global dof values ``u
    (n_el, 6)``: the elongation ``δ = ū2 − ū1`` [m] and the end rotations from the chord
    ``θ1 − ψ``, ``θ2 − ψ`` [rad], ``ψ = (v̄2 − v̄1)/L`` (ū, v̄ in element axes; OpenSees's
    ``LinearCrdTransf2d::getBasicTrialDisp``)."""
    local = _local_end_forces(coords, u)          # the same rotation into element axes
    _, _, L = rotation_2d(coords)
    out = np.empty((u.shape[0], 3))
    for e in range(u.shape[0]):
        chord = (local[e, 4] - local[e, 1]) / L[e]
        out[e, 0] = local[e, 3] - local[e, 0]
        out[e, 1] = local[e, 2] - chord
        out[e, 2] = local[e, 5] - chord
    return out


@register
class ElasticBeamColumn2d(ElementType):
    """Elastic beam-column: area ``A`` [m²], modulus ``E`` [Pa], inertia ``I`` [m⁴], mass per
    length ``rho`` [kg/m]; ``cmass`` 1 for the consistent mass matrix (cubic Hermite bending,
    linear axial), 0 for the lumped one (ρL/2 on ux and uy of each node, no rotary inertia),
    as OpenSees's ``elasticBeamColumn ... -mass rho [-cMass]``."""

    name = "elasticBeamColumn"
    param_names = ("A", "E", "I", "rho", "cmass")
    positive = ("A", "E", "I")
    non_negative = ("rho",)
    flags = ("cmass",)
    defaults = {"rho": 0.0, "cmass": 0.0}
    response_kinds = ("force", "globalForce", "localForce", "basicDeformation", "chordRotation", "chordDeformation",
                      "basicStiffness", "xaxis", "yaxis", "zaxis")
    unloaded_responses = ("basicDeformation", "chordRotation", "chordDeformation", "basicStiffness", "xaxis", "yaxis",
                          "zaxis")

    def stiffness(self, coords, params):
        c, s, L = rotation_2d(coords)
        return rotate_to_global(_local_stiffness(params[:, 0], params[:, 1], params[:, 2], L), c, s, 2, 3)

    def mass(self, coords, params):
        c, s, L = rotation_2d(coords)
        return _global_mass(params[:, 3], params[:, 4], c, s, L)

    def response(self, kind, coords, params, u_e, v_e):
        """``localForce``: ``[N1, V1, M1, N2, V2, M2]`` in element axes (forces the nodes exert
        on the element); ``basicDeformation`` (= ``chordRotation`` = ``chordDeformation``, as
        OpenSees's ``ElasticBeam2d``): ``[δ, θ1 − ψ, θ2 − ψ]`` [m, rad, rad], the elongation and the
        end rotations from the chord (ψ = (v2 − v1)/L, v transverse in element axes);
        ``basicStiffness``: the 3×3 ``[[EA/L, 0, 0], [0, 4EI/L, 2EI/L], [0, 2EI/L, 4EI/L]]`` row
        by row (9 values); ``xaxis``, ``yaxis``, ``zaxis``: the element axes' unit vectors in
        global axes (3 values each); other kinds as in the base class."""
        if kind == "localForce":
            return self.end_force_response(kind, coords, super().response("force", coords, params, u_e, v_e))
        if kind not in self.response_kinds:       # a subclass answers fewer kinds
            return ElementType.response(self, kind, coords, params, u_e, v_e)
        if kind in ("basicDeformation", "chordRotation", "chordDeformation"):
            return _basic_deformations(coords, np.ascontiguousarray(u_e, dtype=np.float64))
        c, s, L = rotation_2d(coords)
        if kind in AXIS_RESPONSES:
            return axis_vectors(kind, c, s)
        if kind == "basicStiffness":
            zero = np.zeros_like(L)
            ea, ei = params[:, 0] * params[:, 1] / L, params[:, 1] * params[:, 2] / L
            return np.stack([ea, zero, zero, zero, 4.0 * ei, 2.0 * ei, zero, 2.0 * ei, 4.0 * ei], axis=1)
        return super().response(kind, coords, params, u_e, v_e)

    def end_force_response(self, kind, coords, forces):
        """Global end forces ``(n_el, 6)`` as response ``kind``: 'localForce' rotates them into
        element axes."""
        if kind != "localForce":
            return super().end_force_response(kind, coords, forces)
        return _local_end_forces(coords, np.ascontiguousarray(forces, dtype=np.float64))

    def equivalent_loads(self, coords, params, kind, values):
        """Consistent (fixed-end) nodal loads, global [N, N·m], of a ``'uniform'`` ``(w_y, w_x)``
        [N/m] or ``'point'`` ``(P_y, x/L, P_x)`` [N] load in element axes: uniform w_y L/2 and
        ±w_y L²/12, w_x L/2; a point load at a = x L (b = L − a) P_y b²(3a + b)/L³, P_y a b²/L²,
        P_y a²(a + 3b)/L³, −P_y a² b/L², axial P_x b/L and P_x a/L (OpenSees ``ElasticBeam2d``)."""
        (c, s, L), = zip(*rotation_2d(coords[None]))
        if kind == "uniform":
            wy, wx = values
            local = np.array([wx * L / 2, wy * L / 2, wy * L * L / 12, wx * L / 2, wy * L / 2, -wy * L * L / 12])
        else:
            py, x, px = values
            a, b = x * L, (1.0 - x) * L
            local = np.array([px * b / L, py * b * b * (3 * a + b) / L ** 3, py * a * b * b / L ** 2,
                              px * a / L, py * a * a * (a + 3 * b) / L ** 3, -py * a * a * b / L ** 2])
        out = local.copy()
        for o in (0, 3):        # to global axes: [x, y] = R^T [local x, local y]
            out[o] = c * local[o] - s * local[o + 1]
            out[o + 1] = s * local[o] + c * local[o + 1]
        return out
