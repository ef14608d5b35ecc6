"""Element recorders: element forces of chosen elements, vectorised over steps and elements.

The recorder requests ``u`` and ``v`` at the dofs of its elements. ``'force'``/``'globalForce'``
(``K_e u_e + C_e v_e``, contract item 4 of :mod:`vtsi.elements.base`) and the kinds an element
type derives from those global end forces (its ``end_force_response`` takes them, e.g.
``elasticBeamColumn``'s ``'localForce'``) are computed from the element matrices the assembly
computed and checked once per build (``Assembly.element_matrices``): one batched product per
chunk of ``n`` steps, no element kernel called. Other kinds call the element type's
``response(kind, coords, params, u_e, v_e)`` once per chunk on ``n · n_el`` rows (in batches of
at most :data:`BATCH_ROWS`). Columns are element-major, as OpenSees writes them: element 1
component 1, element 1 component 2, ..., element 2 component 1...
"""
from typing import NamedTuple

import numpy as np
from numba import njit

from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder
from vtsi.recorders.moment import element_end_forces
from vtsi.recorders.node import _int_list, element_ground_loads

BATCH_ROWS = 20000
FORCE_NAMES = {"force": ("Px", "Py", "Mz"), "globalForce": ("Px", "Py", "Mz"), "localForce": ("N", "V", "M")}
DESCRIPTION = {"force": "element resisting force, global axes", "globalForce": "element resisting force, global axes",
               "localForce": "element end forces, element axes"}
FORCE_KINDS = ("force", "globalForce")


class _Group(NamedTuple):
    """The recorded elements of one element type (block).

    coords (n_g, n_nodes, 2), params (n_g, n_par): theirs; ucols, vcols (n_g, ndof) int64: the
    request columns of u and v at their dofs; order (n_g,): their places in the recorder's element
    list; width: values per element; columns (n_g, width): their output columns; stiffness,
    damping (n_g, ndof, ndof): their matrices of the build (damping None when zero), None when
    the response is not computed from them; end_forces: the response is ``end_force_response``
    of ``K u + C v`` (else ``K u + C v`` itself, or ``etype.response`` when stiffness is None);
    block, index (n_g,): their block of the assembly and places in it."""
    etype: object
    coords: np.ndarray
    params: np.ndarray
    ucols: np.ndarray
    vcols: np.ndarray
    order: np.ndarray
    width: int
    columns: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    end_forces: bool
    block: int
    index: np.ndarray


@njit(cache=True)
def element_products(matrices, columns, cols, out, accumulate):
    """``out[s, e, i] (+)= Σ_j matrices[e, i, j] · columns[s, cols[e, j]]``: the element forces of
    ``m`` steps from the recorder's columns ``(m, n_requests)`` (u or v at the element dofs
    ``cols (n_g, nd)``) and the element matrices ``(n_g, nd, nd)``; ``out (m, n_g, nd)``. Written
    out, gathering as it goes (numpy's batched products cost 10-20 µs of overhead per call, and a
    step at a time is a call)."""
    m = columns.shape[0]
    n_g, nd = cols.shape
    x = np.empty(nd)
    for s in range(m):
        for e in range(n_g):
            for j in range(nd):
                x[j] = columns[s, cols[e, j]]
            for i in range(nd):
                acc = out[s, e, i] if accumulate else 0.0
                for j in range(nd):
                    acc += matrices[e, i, j] * x[j]
                out[s, e, i] = acc


def end_force_width(etype, kind, coords):
    """Columns of ``kind`` when ``etype`` derives it from the global end forces (its
    ``end_force_response`` takes ``kind``, contract item 4), else None (it refuses the kind with
    a ModelError)."""
    try:
        return np.asarray(etype.end_force_response(kind, coords, np.zeros((len(coords), etype.ndof)))).shape[1]
    except ModelError:
        return None


def element_response(assembly, block, rows, kind, u_e, v_e):
    """Response ``kind`` ``(n, width)`` of elements ``rows`` of ``assembly.blocks[block]`` at
    their dof values ``u_e, v_e`` ``(n, ndof)``: the force kinds (``K_e u_e + C_e v_e``) and
    those the type derives from the global end forces from the matrices of the build
    (``Assembly.element_matrices``, no element kernel called), other kinds by the type's
    ``response`` kernel. One element at a time for the command layer (``eleForce``,
    ``eleResponse``); :class:`ElementRecorder` does the same per chunk of steps."""
    etype, _tags, coords, params, _dofs = assembly.blocks[block]
    matrices = assembly.element_matrices[block]
    f = (matrices.stiffness[rows] @ u_e[:, :, None] + matrices.damping[rows] @ v_e[:, :, None])[:, :, 0]
    if kind in FORCE_KINDS:
        return f
    try:
        return np.asarray(etype.end_force_response(kind, coords[rows], f), dtype=float)
    except ModelError:                    # not derived from the end forces: the type's own kernel
        return np.asarray(etype.response(kind, coords[rows], params[rows], u_e, v_e), dtype=float)


class ElementRecorder(Recorder):
    """Records ``response`` of ``elements`` (OpenSees ``recorder Element ... -ele ... response``).

    ``response`` is any kind the element types list in ``response_kinds``; for
    ``elasticBeamColumn``: ``'force'`` = ``'globalForce'`` (``K_e u_e`` (+ the element's own
    dashpots ``C_e v_e``) in global axes: Px, Py, Mz at node 1 then node 2 [N, N·m], the force
    the nodes exert on the element) and ``'localForce'`` (N, V, M per node in element axes).

    Cost: force kinds (and those derived from the end forces) use ``K_e`` and ``C_e`` as the
    build computed them (the element kernels run once per build, not per step). Newmark on a
    200-element simply supported beam, Δt = 1 ms, every element recorded, µs/step (3.9 without
    an element recorder), before → after: ``'force'`` of ``elasticBeamColumn`` 63 → 17, of a
    user beam with a numba kernel 135 → 17, of a user beam whose kernel is a Python loop
    2013 → 17; ``'localForce'`` of ``elasticBeamColumn`` 64 → 22. Of the ~13 µs left, ~6 are
    this recorder's products and the rest the analysis handing 1206 columns over per step.

    An element type may describe its columns with an optional method
    ``response_labels(kind, width) -> (labels, units)``; otherwise force-like kinds with one
    value per element dof are named ``Px_1, Py_1, Mz_1, ...`` [N, N m] and others ``<kind>_k``.

    Element loads are in the end forces as OpenSees counts them (the element's resisting force
    less its load vector): the fixed-end forces of the patterns' element loads (``eleLoad``) and,
    in a :class:`~vtsi.coupled.CoupledAnalysis`, of the train's moving forces and contact forces
    λ_{n+1} (the step's end) standing inside a track element, spread as the constraint's rows
    spread them (:class:`~vtsi.coupled.CoupledLoads`, handed over when the analysis starts the
    recorder; a response of a track element that its type does not derive from the end forces,
    nor leaves unloaded, is then a ModelError).

    ``sink``, ``dt``, ``envelope``, ``history``, ``tag``: see :class:`~vtsi.recorders.base.Recorder`.
    """

    name = "element recorder"

    def __init__(self, elements, response="force", sink=None, dt=None, envelope=False, history=True, tag=None):
        if not isinstance(response, str) or not response:
            raise ModelError(f"element recorder: response must be a name, got {response!r}")
        self.elements = _int_list("element recorder", "elements", elements)
        self.response = response
        super().__init__(sink=sink, dt=dt, envelope=envelope, history=history, tag=tag)
        self._groups = None
        self._widths = None
        self._element_loads = []     # [(pattern, [equivalent loads (n_g, ndof) or None per group])]
        self._coupled = None         # the CoupledLoads of the coupled analysis running
        self._wheels = []            # per group: the end-force table of the wheel loads (FixedEndMoments) or None

    @property
    def widths(self):
        """Values per element ``(n_elements,)`` int64, in the order of ``elements`` (set by
        :meth:`requests`)."""
        return self._widths

    def requests(self, assembly):
        keys, requests = {}, []

        def column(quantity, dof):
            key = (quantity, int(dof))
            if key not in keys:
                keys[key] = len(requests)
                requests.append(key)
            return keys[key]

        by_block = {}
        for k, tag in enumerate(self.elements):
            if tag not in assembly.element_location:
                raise ModelError(f"element recorder: element {tag} does not exist")
            b, i = assembly.element_location[tag]
            by_block.setdefault(b, []).append((k, i))
        widths = np.zeros(len(self.elements), dtype=np.int64)
        groups = []
        for b, pairs in by_block.items():
            etype, _tags, coords, params, dofs = assembly.blocks[b]
            if self.response not in etype.response_kinds:
                raise ModelError(f"element recorder: element {self.elements[pairs[0][0]]} ({etype.name}) has no "
                                 f"response {self.response!r}; valid: {', '.join(etype.response_kinds)}")
            order = np.array([k for k, _ in pairs], dtype=np.int64)
            idx = np.array([i for _, i in pairs], dtype=np.int64)
            d = dofs[idx]
            ucols = np.array([[column("u", x) for x in row] for row in d], dtype=np.int64).reshape(d.shape)
            vcols = np.array([[column("v", x) for x in row] for row in d], dtype=np.int64).reshape(d.shape)
            g_coords, g_params = np.ascontiguousarray(coords[idx]), np.ascontiguousarray(params[idx])
            end_forces = False
            if self.response in FORCE_KINDS:             # K u + C v (contract item 4)
                width = d.shape[1]
            else:
                width = end_force_width(etype, self.response, g_coords[:1])
                end_forces = width is not None
            stiffness = damping = None
            if width is not None:                        # from the matrices of the build
                matrices = assembly.element_matrices[b]
                stiffness = np.ascontiguousarray(matrices.stiffness[idx])
                damping = np.ascontiguousarray(matrices.damping[idx]) if matrices.damping[idx].any() else None
            else:
                zeros = np.zeros((1, d.shape[1]))
                width = np.asarray(etype.response(self.response, g_coords[:1], g_params[:1], zeros, zeros)).shape[1]
            widths[order] = width
            groups.append(dict(etype=etype, coords=g_coords, params=g_params, ucols=ucols, vcols=vcols, order=order,
                               width=int(width), stiffness=stiffness, damping=damping, end_forces=end_forces,
                               block=b, index=idx))
        offsets = np.concatenate([[0], np.cumsum(widths)])
        self._groups = [_Group(columns=offsets[g["order"]][:, None] + np.arange(g["width"])[None, :], **g)
                        for g in groups]                     # output columns (n_g, width)
        self._widths, self._n_columns = widths, int(offsets[-1])
        self._coupled, self._wheels = None, [None] * len(self._groups)     # until take_coupled_loads
        return requests

    def start(self, assembly, model, info=None):
        self.take_coupled_loads(assembly, (info or {}).get("coupled_loads"))
        super().start(assembly, model, info)

    def take_coupled_loads(self, assembly, coupled):
        """Take the wheel loads of the coupled analysis that starts the recorder (``coupled``, its
        :class:`~vtsi.coupled.CoupledLoads`, or None) into the end forces of the track elements
        recorded (after :meth:`requests`); a recorder that wraps this one passes on what its
        ``start`` was handed."""
        self._coupled = coupled
        self._wheels = [None] * len(self._groups)
        if coupled is not None:
            track = coupled.constraint.track
            for g, group in enumerate(self._groups):
                tags = [self.elements[k] for k in group.order]
                on_track = [tag for tag in tags if tag in track.elements]
                if not on_track or self.response in group.etype.unloaded_responses:
                    continue
                if group.stiffness is None:
                    raise ModelError(f"{self.name}: response {self.response!r} of element {on_track[0]} "
                                     f"({group.etype.name}) is not available in a coupled analysis whose wheels run "
                                     "on it: its type does not derive it from the end forces, which take the wheel "
                                     "loads; record 'force' or 'globalForce'")
                self._wheels[g] = element_end_forces(assembly, track, tags)

    def prepare(self, assembly, model):
        # element loads on the recorded elements: their fixed-end forces are part of the element forces;
        # a ground acceleration's load on their own mass (−M_e r) is part of the global end forces
        self._element_loads = []
        for pattern in model.patterns.values():
            if pattern.ground_direction is not None:
                if self.response in FORCE_KINDS:
                    per_group = [element_ground_loads(assembly, g.block, g.index, pattern.ground_direction)
                                 for g in self._groups]
                    per_group = [eq if eq.any() else None for eq in per_group]
                    if any(eq is not None for eq in per_group):
                        self._element_loads.append((pattern, per_group))
                continue
            loads = assembly.element_equivalent_loads(pattern) if pattern.element_loads else {}
            per_group = []
            for g in self._groups:
                if self.response in g.etype.unloaded_responses:     # a deformation: element loads leave it be
                    per_group.append(None)
                    continue
                eq = np.zeros(g.ucols.shape)
                for row, k in enumerate(g.order):
                    if self.elements[k] in loads:
                        eq[row] = loads[self.elements[k]]
                per_group.append(eq if eq.any() else None)
            if any(eq is not None for eq in per_group):
                self._element_loads.append((pattern, per_group))
        labels, units, element, component = [], [], [], []
        per_element = [None] * len(self.elements)
        for g in self._groups:
            lab, uni = _labels(g.etype, self.response, g.width)
            for k in g.order:
                per_element[k] = (lab, uni)
        for k, tag in enumerate(self.elements):
            lab, uni = per_element[k]
            labels += lab
            units += uni
            element += [tag] * len(lab)
            component += list(range(1, len(lab) + 1))
        return {"response": self.response, "quantity": DESCRIPTION.get(self.response, f"element {self.response}"),
                "units": units,
                "columns": {"element": np.array(element, dtype=np.int64),
                            "component": np.array(component, dtype=np.int64),
                            "component_name": np.array(labels)}}

    def compute(self, times, columns, assembly):
        n = len(times)
        out = np.empty((n, self._n_columns))
        loads = [(pattern.factors(times - self.load_lag), per_group) for pattern, per_group in self._element_loads]
        for g, group in enumerate(self._groups):
            etype, coords, params = group.etype, group.coords, group.params
            n_g, nd = group.ucols.shape
            wheels = None
            if self._wheels[g] is not None:         # −f_eq of the wheel loads inside the elements (global)
                wheels = self._coupled.add(self._wheels[g], times, np.zeros((n, n_g * nd))).reshape(n, n_g, nd)
            width = group.width
            span = group.columns.ravel()
            target = slice(int(span[0]), int(span[0]) + span.size) if np.all(np.diff(span) == 1) else group.columns
            per = max(1, BATCH_ROWS // n_g)
            for s in range(0, n, per):
                m = min(per, n - s)
                rows = columns[s: s + m]
                c = None
                if group.end_forces or group.stiffness is None or any(pg[g] is not None for _, pg in loads):
                    c = np.broadcast_to(coords, (m,) + coords.shape).reshape((m * n_g,) + coords.shape[1:])
                if group.stiffness is not None:                        # K_e u_e + C_e v_e, matrices of the build
                    f = np.empty((m, n_g, nd))
                    element_products(group.stiffness, rows, group.ucols, f, False)
                    if group.damping is not None:
                        element_products(group.damping, rows, group.vcols, f, True)
                    if wheels is not None:
                        f += wheels[s: s + m]
                    if group.end_forces:
                        f = np.asarray(etype.end_force_response(self.response, c, f.reshape(m * n_g, nd)))
                    f = f.reshape(m, n_g, width)
                else:
                    p = np.broadcast_to(params, (m,) + params.shape).reshape(m * n_g, params.shape[1])
                    f = np.asarray(etype.response(self.response, c, p, rows[:, group.ucols].reshape(m * n_g, nd),
                                                  rows[:, group.vcols].reshape(m * n_g, nd))).reshape(m, n_g, width)
                for factors, per_group in loads:      # minus the element loads' equivalent nodal loads
                    if per_group[g] is not None:
                        eq = (factors[s: s + m, None, None] * per_group[g][None]).reshape(m * n_g, nd)
                        f = f - np.asarray(etype.end_force_response(self.response, c, eq)).reshape(m, n_g, width)
                if isinstance(target, slice):
                    out[s: s + m, target] = f.reshape(m, n_g * width)
                else:
                    out[s: s + m][:, target] = f
        return out


def _labels(etype, kind, width):
    """Column names and units of one element's response."""
    custom = getattr(etype, "response_labels", None)
    if custom is not None:
        labels, units = custom(kind, width)
        return list(labels), list(units)
    names = FORCE_NAMES.get(kind)
    per_node = len(etype.node_dofs)
    if names is not None and width == etype.n_nodes * per_node:
        labels = [f"{names[d]}_{node + 1}" for node in range(etype.n_nodes) for d in etype.node_dofs]
        units = ["N m" if d == 2 else "N" for _node in range(etype.n_nodes) for d in etype.node_dofs]
        return labels, units
    return [f"{kind}_{k + 1}" for k in range(width)], [""] * width
