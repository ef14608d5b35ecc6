"""2-D elastic Timoshenko beam (shear deformable), OpenSees's ``ElasticTimoshenkoBeam``.

Dofs per element: ``[ux1, uy1, rz1, ux2, uy2, rz2]`` in global axes (N, m, rad). With
``φ = 12 E I / (G Avy L²)`` the bending stiffness is the exact two-node one of a uniform
Timoshenko beam (``φ → 0``: the Euler-Bernoulli ``elasticBeamColumn``); the lumped mass is
``ρL/2`` on the translations; the consistent mass (``cmass``) is the Timoshenko one, translational
plus rotary inertia (``ρ I / A``), as OpenSees's.

References
----------
Przemieniecki, J.S. (1968) Theory of Matrix Structural Analysis, §5.6 and §11.5.
OpenSees ``SRC/element/elasticBeamColumn/ElasticTimoshenkoBeam2d.cpp`` (``setUp``).
"""
import numpy as np
from numba import njit

from vtsi.errors import ModelError

from .base import register, rotation_2d
from .beam_column import ElasticBeamColumn2d
from .kernels import rotate_to_global


@njit(cache=True)
def _local_stiffness(A, E, G, I, Avy, L):
    """``(n_el, 6, 6)`` local stiffness [N/m, N, N·m]."""
    n = A.shape[0]
    k = np.zeros((n, 6, 6))
    for e in range(n):
        l1 = L[e]
        l2 = l1 * l1
        phi = 12.0 * E[e] * I[e] / (l2 * G[e] * Avy[e])
        b = E[e] * I[e] / (l2 * l1 * (1.0 + phi))
        ea = E[e] * A[e] / l1
        k[e, 0, 0] = k[e, 3, 3] = ea
        k[e, 0, 3] = k[e, 3, 0] = -ea
        k[e, 1, 1] = k[e, 4, 4] = 12.0 * b
        k[e, 1, 4] = k[e, 4, 1] = -12.0 * b
        k[e, 2, 2] = k[e, 5, 5] = (4.0 + phi) * l2 * b
        k[e, 2, 5] = k[e, 5, 2] = (2.0 - phi) * l2 * b
        k[e, 1, 2] = k[e, 2, 1] = k[e, 1, 5] = k[e, 5, 1] = 6.0 * l1 * b
        k[e, 2, 4] = k[e, 4, 2] = k[e, 4, 5] = k[e, 5, 4] = -6.0 * l1 * b
    return k


@njit(cache=True)
def _local_consistent_mass(A, E, G, I, Avy, rho, L):
    """``(n_el, 6, 6)`` local consistent mass [kg, kg·m, kg·m²]: axial linear, bending with the
    shear-deformable shape functions, translational and rotary (ρ I / A per length) inertia."""
    n = A.shape[0]
    m = np.zeros((n, 6, 6))
    for e in range(n):
        l1 = L[e]
        l2 = l1 * l1
        phi = 12.0 * E[e] * I[e] / (l2 * G[e] * Avy[e])
        p2 = phi * phi
        ax = rho[e] * l1 / 210.0
        m[e, 0, 0] = m[e, 3, 3] = 70.0 * ax
        m[e, 0, 3] = m[e, 3, 0] = 35.0 * ax
        t = ax / ((1.0 + phi) * (1.0 + phi))                       # translational inertia
        r = rho[e] / A[e] * I[e] / (30.0 * l1 * (1.0 + phi) * (1.0 + phi))   # rotary inertia
        m[e, 1, 1] = m[e, 4, 4] = t * (70.0 * p2 + 147.0 * phi + 78.0) + 36.0 * r
        m[e, 1, 4] = m[e, 4, 1] = t * (35.0 * p2 + 63.0 * phi + 27.0) - 36.0 * r
        m[e, 2, 2] = m[e, 5, 5] = t * l2 / 4.0 * (7.0 * p2 + 14.0 * phi + 8.0) + r * l2 * (10.0 * p2 + 5.0 * phi + 4.0)
        m[e, 2, 5] = m[e, 5, 2] = -t * l2 / 4.0 * (7.0 * p2 + 14.0 * phi + 6.0) + r * l2 * (5.0 * p2 - 5.0 * phi - 1.0)
        near = t * l1 / 4.0 * (35.0 * p2 + 77.0 * phi + 44.0) + r * l1 * (3.0 - 15.0 * phi)
        far = -t * l1 / 4.0 * (35.0 * p2 + 63.0 * phi + 26.0) + r * l1 * (3.0 - 15.0 * phi)
        m[e, 1, 2] = m[e, 2, 1] = near
        m[e, 4, 5] = m[e, 5, 4] = -near
        m[e, 1, 5] = m[e, 5, 1] = far
        m[e, 2, 4] = m[e, 4, 2] = -far
    return m


@register
class ElasticTimoshenkoBeam2d(ElasticBeamColumn2d):
    """Elastic Timoshenko beam: area ``A`` [m²], Young's modulus ``E`` [Pa], shear modulus ``G``
    [Pa], inertia ``I`` [m⁴], shear area ``Avy`` [m²] (κA), mass per length ``rho`` [kg/m];
    ``cmass`` 1 for the consistent mass, 0 for the lumped one. Responses as ``elasticBeamColumn``
    (``force``/``globalForce``, ``localForce``, ``xaxis``/``yaxis``/``zaxis``); OpenSees's
    ``ElasticTimoshenkoBeam2d`` has no basic deformations or basic stiffness, nor has this type."""

    name = "ElasticTimoshenkoBeam"
    param_names = ("A", "E", "G", "I", "Avy", "rho", "cmass")
    positive = ("A", "E", "G", "I", "Avy")
    non_negative = ("rho",)
    flags = ("cmass",)
    defaults = {"rho": 0.0, "cmass": 0.0}
    response_kinds = ("force", "globalForce", "localForce", "xaxis", "yaxis", "zaxis")
    unloaded_responses = ("xaxis", "yaxis", "zaxis")

    def stiffness(self, coords, params):
        c, s, L = rotation_2d(coords)
        A, E, G, I, Avy = (np.ascontiguousarray(params[:, k]) for k in range(5))
        return rotate_to_global(_local_stiffness(A, E, G, I, Avy, L), c, s, 2, 3)

    def equivalent_loads(self, coords, params, kind, values):
        """As ``elasticBeamColumn``'s for a ``'uniform'`` load (the fixed-end forces of a uniform
        load do not depend on the shear flexibility); a ``'point'`` load is refused (its fixed-end
        moments do)."""
        if kind != "uniform":
            raise ModelError(f"element type {self.name}: a point element load is not supported (its fixed-end "
                             "forces depend on the shear flexibility); split the element at the load")
        return super().equivalent_loads(coords, params, kind, values)

    def mass(self, coords, params):
        c, s, L = rotation_2d(coords)
        rho, consistent = params[:, 5], params[:, 6] != 0.0
        m = np.zeros((len(params), 6, 6))
        for d in (0, 1, 3, 4):
            m[:, d, d] = 0.5 * rho * L
        if consistent.any():
            A, E, G, I, Avy = (np.ascontiguousarray(params[:, k]) for k in range(5))
            mc = rotate_to_global(_local_consistent_mass(A, E, G, I, Avy, np.ascontiguousarray(rho), L), c, s, 2, 3)
            m[consistent] = mc[consistent]
        return m
