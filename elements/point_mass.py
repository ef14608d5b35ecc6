"""A point mass on one node: translational mass ``m`` and rotary inertia ``J``, no stiffness.

Dofs per element: ``[ux, uy, rz]``; ``M = diag(m, m, J)`` [kg, kg, kg·m²], ``K = C = 0``. It is the
element form of OpenSees's ``mass`` command (``mass node m m J``), so that masses can be batched,
recorded and removed like any other element.

References
----------
OpenSees ``SRC/domain/node/Node.cpp`` (``setMass``; the ``mass`` command fills the diagonal of
the nodal mass matrix).
"""
import numpy as np

from .base import ElementType, register


@register
class PointMass2d(ElementType):
    """Mass ``m`` [kg] (> 0) on ux and uy, rotary inertia ``J`` [kg·m²] (>= 0, default 0) on rz.

    Responses: ``'force'``/``'globalForce'``: the resisting force ``K u + C v``, which is zero
    (the inertia force ``M a`` is not a resisting force)."""

    name = "pointMass"
    n_nodes = 1
    node_dofs = (0, 1, 2)
    param_names = ("m", "J")
    positive = ("m",)
    non_negative = ("J",)
    defaults = {"J": 0.0}

    def stiffness(self, coords, params):
        return np.zeros((len(params), 3, 3))

    def mass(self, coords, params):
        m = np.zeros((len(params), 3, 3))
        m[:, 0, 0] = m[:, 1, 1] = params[:, 0]
        m[:, 2, 2] = params[:, 1]
        return m

    def check_geometry(self, coords, tags, node_tags):
        """A single node has no geometry to check."""
