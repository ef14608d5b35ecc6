"""Element recorders: element forces of chosen elements, vectorised over steps and elements.

The recorder requests ``u`` and ``v`` at the dofs of its elements; for a chunk of ``n`` steps
it calls each element type's ``response(kind, coords, params, u_e, v_e)`` once on ``n * n_el``
rows (in batches of at most :data:`BATCH_ROWS`). Columns are element-major, as OpenSees
writes them: element 1 component 1, element 1 component 2, ..., element 2 component 1...
"""
import numpy as np

from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder
from vtsi.recorders.node import _int_list

BATCH_ROWS = 20000
FORCE_NAMES = {"force": ("Px", "Py", "Mz"), "globalForce": ("Px", "Py", "Mz"), "localForce": ("N", "V", "M")}
DESCRIPTION = {"force": "element resisting force, global axes", "globalForce": "element resisting force, global axes",
               "localForce": "element end forces, element axes"}


class ElementRecorder(Recorder):
    """Records ``response`` of ``elements`` (OpenSees ``recorder Element ... -ele ... response``).

    ``response`` is any kind the element types list in ``response_kinds``; for
    ``elasticBeamColumn``: ``'force'`` = ``'globalForce'`` (``K_e u_e`` (+ the element's own
    dashpots ``C_e v_e``) in global axes: Px, Py, Mz at node 1 then node 2 [N, N·m], the force
    the nodes exert on the element) and ``'localForce'`` (N, V, M per node in element axes).
    An element type may describe its columns with an optional method
    ``response_labels(kind, width) -> (labels, units)``; otherwise force-like kinds with one
    value per element dof are named ``Px_1, Py_1, Mz_1, ...`` [N, N m] and others ``<kind>_k``.

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
            ucols = np.array([[column("u", x) for x in row] for row in d], dtype=np.int64)
            vcols = np.array([[column("v", x) for x in row] for row in d], dtype=np.int64)
            zeros = np.zeros((1, d.shape[1]))
            width = np.asarray(etype.response(self.response, coords[idx[:1]], params[idx[:1]], zeros, zeros)).shape[1]
            widths[order] = width
            groups.append([etype, np.ascontiguousarray(coords[idx]), np.ascontiguousarray(params[idx]),
                           ucols.reshape(d.shape), vcols.reshape(d.shape), order, width])
        offsets = np.concatenate([[0], np.cumsum(widths)])
        for g in groups:
            order, width = g[5], g[6]
            g.append(offsets[order][:, None] + np.arange(width)[None, :])   # output columns (n_g, width)
        self._groups, self._widths, self._n_columns = groups, widths, int(offsets[-1])
        return requests

    def prepare(self, assembly, model):
        # element loads on the recorded elements: their fixed-end forces are part of the element forces
        self._element_loads = []
        for pattern in model.patterns.values():
            loads = assembly.element_equivalent_loads(pattern) if pattern.element_loads else {}
            per_group = []
            for etype, coords, _params, ucols, _vcols, order, _width, _cols in self._groups:
                eq = np.zeros(ucols.shape)
                for row, k in enumerate(order):
                    if self.elements[k] in loads:
                        eq[row] = loads[self.elements[k]]
                per_group.append(eq if eq.any() else None)
            if any(eq is not None for eq in per_group):
                self._element_loads.append((pattern, per_group))
        labels, units, element, component = [], [], [], []
        per_element = [None] * len(self.elements)
        for etype, *_rest, order, width, _cols in self._groups:
            lab, uni = _labels(etype, self.response, width)
            for k in order:
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
        for g, (etype, coords, params, ucols, vcols, _order, width, out_cols) in enumerate(self._groups):
            n_g, nd = ucols.shape
            per = max(1, BATCH_ROWS // n_g)
            for s in range(0, n, per):
                m = min(per, n - s)
                u = columns[s: s + m][:, ucols].reshape(m * n_g, nd)
                v = columns[s: s + m][:, vcols].reshape(m * n_g, nd)
                c = np.broadcast_to(coords, (m,) + coords.shape).reshape((m * n_g,) + coords.shape[1:])
                p = np.broadcast_to(params, (m,) + params.shape).reshape(m * n_g, params.shape[1])
                f = np.asarray(etype.response(self.response, c, p, u, v)).reshape(m, n_g, width)
                for factors, per_group in loads:      # minus the element loads' equivalent nodal loads
                    if per_group[g] is not None:
                        eq = (factors[s: s + m, None, None] * per_group[g][None]).reshape(m * n_g, nd)
                        f = f - np.asarray(etype.end_force_response(self.response, c, eq)).reshape(m, n_g, width)
                out[s: s + m][:, out_cols] = f
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
