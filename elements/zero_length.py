"""2-D zero-length spring and dashpot between two (usually coincident) nodes.

Dofs per element: ``[ux1, uy1, rz1, ux2, uy2, rz2]`` in global axes. The element's local x
axis makes the angle ``angle`` [rad] with the global x axis (counter-clockwise). With
``T = [[c, s, 0], [−s, c, 0], [0, 0, 1]]`` (``c, s = cos, sin angle``) the basic deformations
are the relative displacements in local axes, ``δ = T (u2 − u1) = B u`` with ``B = [−T, T]``, and

    K = Bᵀ diag(kx, ky, krz) B     [N/m, N·m/rad]
    C = Bᵀ diag(cx, cy, crz) B     [N·s/m, N·m·s/rad]

The element has no mass. Node positions do not enter (as in OpenSees, nodes a distance apart
are accepted with a warning, and the spring then carries no moment of its forces' offset).

References
----------
OpenSees ``SRC/element/zeroLength/ZeroLength.cpp`` (``setTran1d``: rows ``[−t, t]`` of the basic
transformation; ``getDamp``: Rayleigh damping only when ``useRayleighDamping == 1``;
``setResponse``: ``force``/``globalForce``, ``basicForce``/``localForce``, ``deformation``/
``basicDeformation``) and ``SRC/element/zeroLength/TclZeroLength.cpp`` (``-doRayleigh`` defaults to 0).
"""
import logging

import numpy as np
from numba import njit

from vtsi.errors import ModelError

from .base import AXIS_RESPONSES, ElementType, axis_vectors, register

log = logging.getLogger(__name__)


@njit(cache=True)
def _spring_matrices(kx, ky, krz, c, s):
    """``(n_el, 6, 6)`` global matrix ``Bᵀ diag(kx, ky, krz) B`` (stiffness or damping)."""
    n = kx.shape[0]
    out = np.zeros((n, 6, 6))
    for e in range(n):
        # T^T diag(kx, ky) T for the translations, krz on the rotation
        g00 = kx[e] * c[e] * c[e] + ky[e] * s[e] * s[e]
        g01 = (kx[e] - ky[e]) * c[e] * s[e]
        g11 = kx[e] * s[e] * s[e] + ky[e] * c[e] * c[e]
        block = ((g00, g01, 0.0), (g01, g11, 0.0), (0.0, 0.0, krz[e]))
        for i in range(3):
            for j in range(3):
                v = block[i][j]
                out[e, i, j] = v
                out[e, i + 3, j + 3] = v
                out[e, i, j + 3] = -v
                out[e, i + 3, j] = -v
    return out


@register
class ZeroLength2d(ElementType):
    """Springs ``kx, ky`` [N/m], ``krz`` [N·m/rad] and dashpots ``cx, cy`` [N·s/m], ``crz``
    [N·m·s/rad] along the local axes at ``angle`` [rad] from global x; ``do_rayleigh`` 1 to include
    the springs in the Rayleigh βK term, 0 (OpenSees's default) to leave them out. At least one
    spring or dashpot must be nonzero.

    Responses: ``'force'``/``'globalForce'`` ``K u + C v`` at the 6 dofs [N, N·m];
    ``'basicForce'``/``'localForce'`` ``[Px, Py, Mz]`` = ``k δ + c δ̇`` in local axes (force of
    node 2 on the element, positive in tension along local x); ``'deformation'``/
    ``'basicDeformation'`` ``δ = [δx, δy, θz]`` [m, m, rad]; ``'basicStiffness'`` the 3×3
    ``diag(kx, ky, krz)`` row by row (9 values); ``'xaxis'``, ``'yaxis'``, ``'zaxis'`` the local
    axes' unit vectors in global axes (3 values each).
    """

    name = "zeroLength"
    n_nodes = 2
    node_dofs = (0, 1, 2)
    param_names = ("kx", "ky", "krz", "cx", "cy", "crz", "angle", "do_rayleigh")
    non_negative = ("kx", "ky", "krz", "cx", "cy", "crz")
    flags = ("do_rayleigh",)
    defaults = {"kx": 0.0, "ky": 0.0, "krz": 0.0, "cx": 0.0, "cy": 0.0, "crz": 0.0,
                "angle": 0.0, "do_rayleigh": 0.0}
    response_kinds = ("force", "globalForce", "basicForce", "localForce", "deformation", "basicDeformation",
                      "basicStiffness", "xaxis", "yaxis", "zaxis")

    def add(self, tag, nodes, **params):
        super().add(tag, nodes, **params)
        if not any(self._params[-1][:6]):
            self.remove(int(tag))
            raise ModelError(f"element {tag} ({self.name}): every spring and dashpot (kx, ky, krz, cx, cy, crz) "
                             "is zero; give at least one")

    def _matrices(self, params, first):
        angle = params[:, 6]
        p = np.ascontiguousarray(params[:, first: first + 3].T)
        return _spring_matrices(p[0], p[1], p[2], np.cos(angle), np.sin(angle))

    def stiffness(self, coords, params):
        return self._matrices(params, 0)

    def damping(self, coords, params):
        return self._matrices(params, 3)

    def mass(self, coords, params):
        return np.zeros((len(params), 6, 6))

    def rayleigh_weights(self, params):
        """Factor on each element's stiffness in the Rayleigh βK term (its ``do_rayleigh``)."""
        return np.ascontiguousarray(params[:, 7])

    def check_geometry(self, coords, tags, node_tags):
        """Coincident nodes are the normal case; a distance apart is accepted with a warning."""
        gap = np.hypot(*(coords[:, 1] - coords[:, 0]).T)
        far = np.flatnonzero(gap > 1e-10 * np.maximum(1.0, np.abs(coords).max(axis=(1, 2))))
        if far.size:
            i = far[0]
            log.warning("element %d (%s): nodes %d and %d are %.6g apart (model length units); the springs act between them "
                        "as if they coincided", tags[i], self.name, node_tags[i][0], node_tags[i][1], gap[i])

    def response(self, kind, coords, params, u_e, v_e):
        if kind in ("basicForce", "localForce", "deformation", "basicDeformation"):
            c, s = np.cos(params[:, 6]), np.sin(params[:, 6])
            deformation, rate = (_basic(w, c, s) for w in (u_e, v_e))
            if kind in ("deformation", "basicDeformation"):
                return deformation
            return params[:, 0:3] * deformation + params[:, 3:6] * rate
        if kind == "basicStiffness":
            zero = np.zeros(len(params))
            return np.stack([params[:, 0], zero, zero, zero, params[:, 1], zero, zero, zero, params[:, 2]], axis=1)
        if kind in AXIS_RESPONSES:
            return axis_vectors(kind, np.cos(params[:, 6]), np.sin(params[:, 6]))
        return super().response(kind, coords, params, u_e, v_e)


def _basic(w, c, s):
    """Relative displacements (or velocities) of node 2 to node 1 in local axes, ``(n_el, 3)``."""
    d = w[:, 3:6] - w[:, 0:3]
    return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1], d[:, 2]], axis=1)
