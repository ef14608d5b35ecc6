"""Bending moments at the nodes of a track (the deck's beam elements along it).

The moment at a node is the end moment of the track elements that meet there, from their own
stiffness (what OpenSees's ``localForce`` gives), sagging positive, averaged over them (one
element at the chain's ends): with f = K_e u_e the forces on an element at its nodes (global
axes; the track is straight and horizontal), M = −f_rz at its left node and M = +f_rz at its
right node. For an Euler-Bernoulli element that is EI w'' of its Hermite shape,

    w''(ξ) = [6(2ξ − 1)/ℓ², (6ξ − 4)/ℓ, 6(1 − 2ξ)/ℓ², (6ξ − 2)/ℓ] · [v₁, θ₁, v₂, θ₂];

for a Timoshenko element it keeps its shear flexibility out of the moment (EI times the
Hermite curvature of its nodal values read 740 kN·m at mid-span for PL/4 = 500). Nodal
displacements are exact under nodal and element loads and the end moment of an unloaded element
is exact; an element carrying a load inside it gives its end moment to O(ℓ) — the mean of the
two sides halves that. A linear functional of the nodal dofs, so it serves the dynamic recorder
and the static influence lines (:mod:`vtsi.influence`) alike.
"""
import numpy as np

from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder
from vtsi.recorders.node import _int_list


def moment_rows(asm, track, nodes):
    """The bending moment at ``nodes`` as a linear map of the free dofs of the assembly ``asm``:
    ``(free_dofs (n_req,), P (n_req, len(nodes)))`` with M = u[free_dofs] @ P [N·m]."""
    coefficients = {}
    for j, node in enumerate(nodes):
        if node not in asm.node_index:
            raise ModelError(f"bending moment: node {node} does not exist")
        x = float(asm.coords[asm.node_index[node], 0])
        ends = []
        for e, tag in enumerate(track.elements):
            b, i = asm.element_location[tag]
            if node in asm.blocks[b][0].nodes[i]:
                ends.append((tag, -1.0 if abs(x - track.x_start[e]) <= 0.5 * track.length[e] else 1.0))
        if not ends:
            raise ModelError(f"bending moment: node {node} (x = {x:g} m) is not a node of the track")
        for tag, sign in ends:
            b, i = asm.element_location[tag]
            etype, _, coords, params, dofs = asm.blocks[b]
            if 2 not in etype.node_dofs:
                raise ModelError(f"bending moment: element {tag} ({etype.name}) has no rotation dofs")
            where = list(etype.nodes[i]).index(node) * len(etype.node_dofs) + etype.node_dofs.index(2)
            row = sign * etype.stiffness(coords[i:i + 1], params[i:i + 1])[0, where] / len(ends)
            for d, c in zip(dofs[i], row):
                f = int(asm.free_of_full[d])
                if f >= 0 and c != 0.0:
                    coefficients.setdefault(f, np.zeros(len(nodes)))[j] += c
    free = np.array(sorted(coefficients), dtype=np.int64)
    P = np.array([coefficients[f] for f in free]).reshape(len(free), len(nodes))
    return free, P


class BendingMomentRecorder(Recorder):
    """Bending moment M [N·m] (sagging positive) at ``nodes`` of ``track`` (see the module
    docstring), one column per node. ``sink``, ``dt``, ``envelope``, ``history``, ``tag``: see
    :class:`~vtsi.recorders.base.Recorder`."""

    name = "bending moment recorder"

    def __init__(self, track, nodes, sink=None, dt=None, envelope=False, history=True, tag=None):
        self.track, self.nodes = track, _int_list(self.name, "nodes", nodes)
        super().__init__(sink=sink, dt=dt, envelope=envelope, history=history, tag=tag)
        self._projection = None

    def requests(self, assembly):
        free, self._projection = moment_rows(assembly, self.track, self.nodes)
        return [("u", int(f)) for f in assembly.full_of_free[free]]

    def prepare(self, assembly, model):
        return {"response": "moment", "quantity": "bending moment, sagging positive",
                "units": ["N m"] * len(self.nodes), "columns": {"node": np.array(self.nodes, dtype=np.int64)}}

    def compute(self, times, columns, assembly):
        return columns @ self._projection
