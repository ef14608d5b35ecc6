"""Node response recorders: displacement, velocity, acceleration of chosen node dofs."""
import numpy as np

from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder

QUANTITIES = {"disp": "u", "vel": "v", "accel": "a"}


class NodeRecorder(Recorder):
    """Records ``response`` ('disp', 'vel', 'accel') of ``dofs`` (1-based) at ``nodes`` to memory.

    After a run, ``time (n,)`` [s] and ``values (n, len(nodes) * len(dofs))`` (node-major columns:
    node 1 dof 1, node 1 dof 2, ..., as OpenSees writes them) hold every recorded step.
    """

    def __init__(self, nodes, dofs, response="disp", dt=None, tag=None):
        if response not in QUANTITIES:
            raise ModelError(f"node recorder: unknown response {response!r}; valid: {', '.join(QUANTITIES)}")
        self.nodes, self.dofs, self.response, self.dt, self.tag = list(nodes), list(dofs), response, dt, tag
        self._times, self._chunks = [], []

    def requests(self, assembly):
        q = QUANTITIES[self.response]
        return [(q, assembly.full_dof(n, d)) for n in self.nodes for d in self.dofs]

    def write(self, times, columns, assembly):
        keep = self._select(times)
        self._times.append(times[keep])
        self._chunks.append(columns[keep])

    @property
    def time(self):
        return np.concatenate(self._times) if self._times else np.zeros(0)

    @property
    def values(self):
        n = len(self.nodes) * len(self.dofs)
        return np.concatenate(self._chunks) if self._chunks else np.zeros((0, n))
