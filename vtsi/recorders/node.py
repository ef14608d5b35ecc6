"""Node recorders: displacement, velocity, acceleration and reactions of chosen node dofs.

Columns are node-major, as OpenSees writes them: node 1 dof 1, node 1 dof 2, ..., node 2 dof 1...
"""
import numpy as np
import scipy.sparse as sp

from vtsi.assembly import DOF_NAMES
from vtsi.errors import ModelError, as_flag
from vtsi.recorders.base import Recorder

QUANTITIES = {"disp": "u", "vel": "v", "accel": "a"}
REACTIONS = ("reaction", "reactionIncInertia")
RESPONSES = tuple(QUANTITIES) + REACTIONS
DESCRIPTION = {"disp": "displacement", "vel": "velocity", "accel": "acceleration",
               "reaction": "reaction", "reactionIncInertia": "reaction including inertia and damping"}
UNITS = {"disp": ("m", "rad"), "vel": ("m/s", "rad/s"), "accel": ("m/s^2", "rad/s^2"),
         "reaction": ("N", "N m"), "reactionIncInertia": ("N", "N m")}


class NodeRecorder(Recorder):
    """Records ``response`` of ``dofs`` (1-based: 1 ux, 2 uy, 3 rz) at ``nodes``.

    Responses (OpenSees names): ``'disp'`` [m, rad], ``'vel'`` [m/s, rad/s], ``'accel'``
    [m/s², rad/s²], ``'reaction'`` and ``'reactionIncInertia'`` [N, N·m] (see
    :class:`ReactionRecorder`). Columns are node-major: ``(n, len(nodes) * len(dofs))``.

    With the default memory sink, ``time (n,)`` [s] and ``values`` hold every recorded step
    after (and during) a run. ``sink``, ``dt``, ``envelope``, ``history``, ``tag``: see
    :class:`~vtsi.recorders.base.Recorder`.
    """

    name = "node recorder"

    def __init__(self, nodes, dofs, response="disp", sink=None, dt=None, envelope=False, history=True, tag=None):
        if response not in RESPONSES:
            raise ModelError(f"node recorder: unknown response {response!r}; valid: {', '.join(RESPONSES)}")
        self.nodes, self.dofs = _int_list("node recorder", "nodes", nodes), _int_list("node recorder", "dofs", dofs)
        self.response = response
        super().__init__(sink=sink, dt=dt, envelope=envelope, history=history, tag=tag)
        self._reaction = None
        self._coupled = None        # the CoupledLoads of the analysis running (reactions)

    def requests(self, assembly):
        try:
            full = [assembly.full_dof(n, d) for n in self.nodes for d in self.dofs]
        except ModelError as exc:
            raise ModelError(f"{self.name}: {exc}") from None
        if self.response in QUANTITIES:
            q = QUANTITIES[self.response]
            return [(q, f) for f in full]
        self._reaction = _ReactionRows(assembly, np.array(full, dtype=np.int64),
                                       self.response == "reactionIncInertia")
        return self._reaction.requests

    def start(self, assembly, model, info=None):
        info = info or {}
        self._coupled = info.get("coupled_loads")
        truncated = info.get("bridge") == "modal, truncated" or (self._coupled is not None and self._coupled.modal)
        if self._reaction is not None and truncated:
            raise ModelError(f"{self.name}: {self.response} in a {info.get('analysis', 'transient')} analysis with a "
                             "modal bridge is not recorded: K Φ q leaves out the truncated modes' share of a "
                             "reaction (a 20 m span of 20 elements, 3 modes, a force at mid-span: 42.1 kN for "
                             "49.05 kN); record it with the FE bridge (bridge=None) or every mode")
        super().start(assembly, model, info)

    def prepare(self, assembly, model):
        if self._reaction is not None:
            self._reaction.set_loads(assembly, model, self._coupled)
        ndf = assembly.ndf
        dofs = self.dofs * len(self.nodes)            # node-major: each node's dofs in turn
        translation, rotation = UNITS[self.response]
        units = [rotation if d == 3 and ndf == 3 else translation for d in dofs]
        return {"response": self.response, "quantity": DESCRIPTION[self.response], "units": units,
                "columns": {"node": np.repeat(np.array(self.nodes, dtype=np.int64), len(self.dofs)),
                            "dof": np.array(dofs, dtype=np.int64), "dof_name": np.array([DOF_NAMES[d - 1] for d in dofs])}}

    def compute(self, times, columns, assembly):
        if self._reaction is None:
            return columns
        return self._reaction.compute(times, columns)


class ReactionRecorder(NodeRecorder):
    """Support reactions ``R`` [N, N·m] at ``dofs`` of ``nodes``: the force the support exerts
    on the structure, ``R = F_resisting - P`` as OpenSees computes it (a beam loaded downwards
    has upward, positive reactions; in static equilibrium they sum to minus the applied load).

    ``include_inertia=False`` (default, OpenSees ``'reaction'`` / ``reactions()``):
    ``R = K u + C_el v - P``, with ``C_el`` the elements' own dashpots (no Rayleigh damping,
    no inertia). ``include_inertia=True`` (OpenSees ``'reactionIncInertia'`` /
    ``reactions('-dynamic')``): ``R = K u + C v + M a - P`` with the full C (Rayleigh
    included) and M. ``P`` is what the patterns apply at that dof at the recorded time
    (:class:`AppliedLoads`: nodal loads, the equivalent nodal loads of element loads and, under
    a ground acceleration, −M r a_g, also at the supports, so that their reaction accelerates
    their own mass), as OpenSees's ``Domain::calculateNodalReactions`` applies the loads again at
    the committed time before it sums. In a :class:`~vtsi.coupled.CoupledAnalysis` ``P`` also
    holds what the analysis applies (:class:`~vtsi.coupled.CoupledLoads`, handed over when it
    starts the recorder): the train's moving forces and contact forces λ_{n+1} at the step's end,
    as the constraint's rows share them between the dofs of the element under each wheel (a
    support's fixed dofs included: a wheel in an end element loads the support directly), and
    the bridge's own weight with ``bridge_self_weight``. With a modal bridge of fewer modes than
    free dofs (:attr:`~vtsi.modal_bridge.ModalBridge.truncated`), in a coupled or a transient
    analysis (whose run info says ``'bridge': 'modal, truncated'``), reactions are refused (a
    ModelError when the analysis starts): K Φ q leaves out the truncated modes' share. ``u``
    (``v``, ``a``) is every dof's that moves: free, prescribed (``sp``) and constrained
    (``equalDOF``, ``rigidLink``) dofs.
    """

    name = "reaction recorder"

    def __init__(self, nodes, dofs, include_inertia=False, sink=None, dt=None, envelope=False, history=True,
                 tag=None):
        response = "reactionIncInertia" if as_flag(include_inertia, self.name, "include_inertia") else "reaction"
        super().__init__(nodes, dofs, response=response, sink=sink, dt=dt, envelope=envelope, history=history,
                         tag=tag)


class _ReactionRows:
    """Rows of ``K, C, M`` at the reaction dofs, restricted to the dofs that move (free,
    prescribed and constrained ones: fixed dofs read 0), and the loads applied at those rows:
    the patterns' and a coupled analysis's own (:class:`~vtsi.coupled.CoupledLoads`)."""

    def __init__(self, assembly, rows, include_inertia):
        self.rows = rows
        parts = [("u", assembly.K_full[rows])]
        if include_inertia:
            parts += [("v", assembly.C_full[rows]), ("a", assembly.M_full[rows])]
        else:
            c_el = _element_damping_rows(assembly, rows)
            if c_el is not None:
                parts.append(("v", c_el))
        self.requests, self.blocks = [], []
        moving = moving_dofs(assembly)
        for quantity, matrix in parts:
            matrix = sp.csr_matrix(matrix)
            matrix.eliminate_zeros()
            cols = np.unique(matrix.indices)
            cols = cols[moving[cols]]
            if cols.size == 0:
                continue
            start = len(self.requests)
            self.requests += [(quantity, int(c)) for c in cols]
            self.blocks.append((slice(start, start + cols.size), matrix[:, cols].tocsr()))
        self.loads = None
        self.coupled, self.shares = None, None

    def set_loads(self, assembly, model, coupled=None):
        """The patterns' loads at the reaction rows (:class:`AppliedLoads`) and those of the
        coupled analysis running, ``coupled`` (its :class:`~vtsi.coupled.CoupledLoads`, or None)."""
        self.loads = AppliedLoads(assembly, model.patterns.values(), self.rows)
        self.coupled = coupled
        self.shares = None if coupled is None else coupled.shares(assembly, self.rows)

    def compute(self, times, columns):
        out = np.zeros((len(times), len(self.rows)))
        for cols, matrix in self.blocks:
            out += (matrix @ columns[:, cols].T).T
        if self.loads is not None:
            out -= self.loads.at(times)
        if self.coupled is not None:
            subtract_coupled_loads(self.coupled, self.shares, self.rows, times, out)
        return out


def subtract_coupled_loads(coupled, shares, rows, times, out):
    """``out (len(times), len(rows)) −= P``, what a coupled analysis applies at the full dofs
    ``rows`` at ``times`` [s], steps it delivered last (``coupled`` its
    :class:`~vtsi.coupled.CoupledLoads`, ``shares`` = ``coupled.shares(assembly, rows)``): the
    bridge's own weight (``bridge_self_weight``) and the train's moving forces and contact forces
    λ_{n+1}, shared between the dofs of the element under each wheel as the constraint's rows
    share them. The one reading of those loads of the reaction recorders and the ``reactions``
    command (``R = F_resisting − P``)."""
    if coupled.self_weight is not None:
        out -= coupled.self_weight[rows][None, :]
    return coupled.add(shares, times, out)       # − P of the downward wheel loads: + their shares


def moving_dofs(assembly):
    """Mask ``(n_full,)`` of the dofs that move: free, prescribed (``sp``) and constrained
    (``equalDOF``, ``rigidLink``) ones; False at fixed dofs."""
    moving = assembly.free_of_full >= 0
    moving[assembly.prescribed_full] = True
    if assembly.constrained_dofs is not None:
        moving[assembly.constrained_dofs] = True
    return moving


class AppliedLoads:
    """What the patterns apply at the full dofs ``rows`` (default: all) at any times [N, N·m]:
    ``P(t) = Σ_p factor_p(t) · P_p[rows]``, with ``P_p`` of ``Assembly.full_load_vectors`` (nodal
    and element loads; −M r of a ground acceleration at every dof, the supports' included). The
    one reading of "the loads at a time" shared by the reaction recorders and the ``reactions``
    command (``R = F_resisting − P``), as OpenSees's ``Domain::calculateNodalReactions`` applies
    the loads again at the committed time before it sums.

    ``patterns``: the model's patterns (their factors, frozen or not, at call time).
    """

    def __init__(self, assembly, patterns, rows=None):
        patterns = list(patterns)
        rows = np.arange(assembly.n_full) if rows is None else np.asarray(rows, dtype=np.int64)
        self.n_rows = len(rows)
        self.terms = []               # [(pattern, P_p[rows])], the patterns that load the rows
        for pattern, vec in zip(patterns, assembly.full_load_vectors(patterns)):
            vec = vec[rows]
            if np.any(vec != 0.0):
                self.terms.append((pattern, vec))

    def at(self, times):
        """``(len(times), len(rows))``: the loads at each of ``times`` [s] (a sequence)."""
        times = np.asarray(times, dtype=np.float64)
        out = np.zeros((len(times), self.n_rows))
        for pattern, vec in self.terms:
            out += pattern.factors(times)[:, None] * vec[None, :]
        return out


def element_ground_loads(assembly, block, rows, direction):
    """``−M_e r_e (len(rows), ndof)``: the share of a unit ground acceleration along
    ``direction`` that loads the own mass of elements ``rows`` of ``assembly.blocks[block]``
    (global axes, per unit a_g [kg]). OpenSees's elements keep it in their load vector and
    subtract it in ``getResistingForce`` (``Truss``, ``ElasticBeam2d``,
    ``ElasticTimoshenkoBeam2d``), so their ``force``/``globalForce`` and ``eleForce`` include
    ``+M_e r a_g``."""
    dofs = assembly.blocks[block][4][rows]
    r_e = assembly.ground_vector(direction)[dofs]
    return -np.einsum("eij,ej->ei", assembly.element_matrices[block].mass[rows], r_e)


def _element_damping_rows(assembly, rows):
    """Rows ``rows`` of the elements' own damping matrix (without Rayleigh), or None if zero."""
    wanted = np.zeros(assembly.n_full, dtype=bool)
    wanted[rows] = True
    r, c, v = [], [], []
    for etype, _tags, coords, params, dofs in assembly.blocks:
        touch = wanted[dofs].any(axis=1)
        if not touch.any():
            continue
        d = etype.damping(coords[touch], params[touch])
        if not np.any(d):
            continue
        sel = dofs[touch]
        nd = sel.shape[1]
        r.append(np.repeat(sel, nd, axis=1).ravel())
        c.append(np.tile(sel, (1, nd)).ravel())
        v.append(d.ravel())
    if not r:
        return None
    matrix = sp.coo_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                           shape=(assembly.n_full, assembly.n_full)).tocsr()
    return matrix[rows]


def _int_list(who, what, items):
    out = []
    for x in np.atleast_1d(np.asarray(items, dtype=object)):
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer, float, np.floating)) \
                or int(x) != x:
            raise ModelError(f"{who}: {what} must be integers, got {items!r}")
        out.append(int(x))
    if what == "dofs" and any(d < 1 for d in out):
        raise ModelError(f"{who}: dofs are 1-based (1 ux, 2 uy, 3 rz), got {out}")
    if not out:
        raise ModelError(f"{who}: no {what} given")
    return out
