"""Node responses restricted to chosen modes (modal projection): what EN 1990 A2.4.4.2.1 means
by deck accelerations "considering frequencies up to" a cut-off, computed from a FE model.

With mass-normalised modes Φ (Φᵀ M Φ = I), a response x (u, v or a of the free dofs and of the
dofs tied to them by equalDOF / rigidLink, whose mass counts too) has the modal coordinates
q = Φᵀ M x, and its part in those modes at a node dof d is

    x_d^Φ = Φ_d q = Φ_d Φᵀ M x,

the exact modal decomposition truncated to Φ: no filter delay, no edge effect, no phase error.
A chunk of n steps goes through the modal coordinates, q = x (M Φ) then q Φ_dᵀ: (n, n_req) ×
(n_req, n_modes) and (n, n_modes) × (n_modes, n_nodes) products, linear in the model's size
(a formed P = M Φ Φ_dᵀ, (n_req, n_nodes), grows with its square). It equals the response of the
modal model with only those modes when the loads excite no other mode's static part (for moving
forces on a beam: the dynamic part of the truncated modes is excluded, their quasi-static part
too).
"""
import numpy as np
import scipy.sparse as sp

from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder
from vtsi.recorders.node import DESCRIPTION, QUANTITIES, UNITS, _int_list


class ModalNodeRecorder(Recorder):
    """``response`` ('disp', 'vel', 'accel') of ``dof`` (1-based: 2 uy, 3 rz) at ``nodes``, in the
    modes ``shapes`` only.

    Parameters
    ----------
    nodes : node tags.
    dof : 1-based dof (2: vertical).
    response : 'disp' [m], 'vel' [m/s], 'accel' [m/s²] (rad for dof 3).
    shapes : (n_full, n_modes) mass-normalised mode shapes (:func:`vtsi.eigen`), zero at fixed dofs.
    label : what the modes are, stored with the record (e.g. 'modes up to 45.0 Hz').
    sink, dt, envelope, history, tag : see :class:`~vtsi.recorders.base.Recorder`.
    """

    name = "modal node recorder"

    def __init__(self, nodes, dof, response, shapes, label="", sink=None, dt=None, envelope=False, history=True,
                 tag=None):
        if response not in QUANTITIES:
            raise ModelError(f"{self.name}: unknown response {response!r}; valid: {', '.join(QUANTITIES)}")
        self.nodes = _int_list(self.name, "nodes", nodes)
        if isinstance(dof, (bool, np.bool_)) or not isinstance(dof, (int, np.integer)) or dof < 1:
            raise ModelError(f"{self.name}: dof must be an integer >= 1 (1 ux, 2 uy, 3 rz), got {dof!r}")
        self.dof, self.response, self.label = int(dof), response, str(label)
        try:
            self.shapes = np.asarray(shapes, dtype=float)
        except (TypeError, ValueError):
            raise ModelError(f"{self.name}: shapes must be an array of numbers (n_full, n_modes), got "
                             f"{type(shapes).__name__} {shapes!r:.60}") from None
        if self.shapes.ndim != 2 or self.shapes.shape[1] == 0:
            raise ModelError(f"{self.name}: shapes must be (n_full, n_modes) with n_modes >= 1, got {self.shapes.shape}")
        if not np.all(np.isfinite(self.shapes)):
            row, mode = np.argwhere(~np.isfinite(self.shapes))[0]
            raise ModelError(f"{self.name}: shapes have NaN or inf: row {row}, mode {mode} is "
                             f"{self.shapes[row, mode]}")
        super().__init__(sink=sink, dt=dt, envelope=envelope, history=history, tag=tag)
        self._weights = self._node_shapes = None     # M Φ rows requested (n_req, n_modes), Φ_dᵀ (n_modes, n_nodes)

    def requests(self, assembly):
        if self.shapes.shape[0] != assembly.n_full:
            raise ModelError(f"{self.name}: shapes have {self.shapes.shape[0]} rows, the model {assembly.n_full} dofs")
        weighted = sp.csr_matrix(assembly.M_full) @ self.shapes         # M Φ (n_full, n_modes)
        moving = assembly.free_of_full >= 0              # and the tied dofs: without their mass q is not Φᵀ M x
        if assembly.constrained_dofs is not None:
            moving[assembly.constrained_dofs] = True
        rows = np.flatnonzero(np.any(weighted != 0.0, axis=1) & moving)
        try:
            at = [assembly.full_dof(n, self.dof) for n in self.nodes]
        except ModelError as exc:
            raise ModelError(f"{self.name}: {exc}") from None
        self._weights, self._node_shapes = weighted[rows], self.shapes[at].T
        quantity = QUANTITIES[self.response]
        return [(quantity, int(r)) for r in rows]

    def prepare(self, assembly, model):
        translation, rotation = UNITS[self.response]
        unit = rotation if self.dof == 3 else translation
        return {"response": self.response, "quantity": f"{DESCRIPTION[self.response]} in {self.label or 'the given modes'}",
                "units": [unit] * len(self.nodes),
                "columns": {"node": np.array(self.nodes, dtype=np.int64),
                            "dof": np.full(len(self.nodes), self.dof, dtype=np.int64)},
                "attrs": {"modes": int(self.shapes.shape[1]), "modes_label": self.label}}

    def compute(self, times, columns, assembly):
        return (columns @ self._weights) @ self._node_shapes       # q = x M Φ, then Φ_d q
