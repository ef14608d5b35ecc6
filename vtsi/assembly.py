"""Dof numbering and assembly of K, M, C into scipy CSR through a precomputed position map.

For every element type the element dof indices are computed once; the union of all element
blocks (plus every diagonal entry) gives the CSR pattern, and ``positions[type]`` maps each
entry of the ``(n_el, nd, nd)`` element matrices to its slot in the CSR ``data`` array. A numba
kernel then adds all element matrices of a type in one call.

Dof indices: a *full* index is ``node_index * ndf + d`` (d = 0 ux, 1 uy, 2 rz). The free dofs
are renumbered for a small bandwidth (reverse Cuthill-McKee); ``free_of_full[j]`` is the free
index of full dof ``j`` or -1 where the dof is fixed.
"""
import functools
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from numba import njit

from vtsi.elements.base import element_matrices, element_rayleigh_weights
from vtsi.errors import ModelError

DOF_NAMES = ("ux", "uy", "rz")


@njit(cache=True)
def scatter_add(data, positions, matrices, weights):
    """``data[positions[e, i, j]] += weights[e] * matrices[e, i, j]`` for all elements."""
    n_el, nd, _ = matrices.shape
    for e in range(n_el):
        w = weights[e]
        if w == 0.0:
            continue
        for i in range(nd):
            for j in range(nd):
                data[positions[e, i, j]] += w * matrices[e, i, j]


@njit(cache=True)
def renumbered(rows, cols, dofs, n):
    """The entries ``(rows, cols)`` of an ``n × n`` pattern in rows and columns ``dofs``,
    renumbered by their position there: ``(rows, cols, kept mask)`` (the principal submatrix on
    ``dofs``, in that order, of a matrix given by its entries)."""
    position = np.full(n, -1, dtype=np.int64)
    for k in range(dofs.shape[0]):
        position[dofs[k]] = k
    keep = np.empty(rows.shape[0], dtype=np.bool_)
    m = 0
    for k in range(rows.shape[0]):
        keep[k] = position[rows[k]] >= 0 and position[cols[k]] >= 0
        m += keep[k]
    r = np.empty(m, dtype=np.int64)
    c = np.empty(m, dtype=np.int64)
    m = 0
    for k in range(rows.shape[0]):
        if keep[k]:
            r[m], c[m] = position[rows[k]], position[cols[k]]
            m += 1
    return r, c, keep


@njit(cache=True)
def element_nodes(sorted_tags, by_tag, nodes, coords, node_dofs, ndf):
    """Coordinates ``(n_el, nen, 2)`` [m] and full dofs ``(n_el, nen · len(node_dofs))`` of the
    elements on the node tags ``nodes (n_el, nen)`` (int64), given the model's node tags sorted
    (``sorted_tags``, ``by_tag`` the node index of each) and node coordinates ``coords``; and the
    first element on a node the model does not have (-1: none)."""
    n_el, nen = nodes.shape
    nld = node_dofs.shape[0]
    out = np.empty((n_el, nen, 2))
    dofs = np.empty((n_el, nen * nld), dtype=np.int64)
    for e in range(n_el):
        for a in range(nen):
            k = np.searchsorted(sorted_tags, nodes[e, a])
            if k == sorted_tags.shape[0] or sorted_tags[k] != nodes[e, a]:
                return out, dofs, e
            i = by_tag[k]
            out[e, a, 0], out[e, a, 1] = coords[i, 0], coords[i, 1]
            for d in range(nld):
                dofs[e, a * nld + d] = i * ndf + node_dofs[d]
    return out, dofs, -1


@njit(cache=True)
def element_entries(dofs):
    """Rows and columns (int64 (n_el nd²,)) of the entries of the element matrices of the dofs
    ``(n_el, nd)``, element by element, each row by row."""
    n_el, nd = dofs.shape
    rows = np.empty(n_el * nd * nd, dtype=np.int64)
    cols = np.empty(n_el * nd * nd, dtype=np.int64)
    k = 0
    for e in range(n_el):
        for i in range(nd):
            for j in range(nd):
                rows[k], cols[k] = dofs[e, i], dofs[e, j]
                k += 1
    return rows, cols


@njit(cache=True)
def csr_pattern(rows, cols, n):
    """The CSR pattern ``(indptr (n + 1,), indices)`` int64 of the entries ``(rows, cols)`` of an
    ``n × n`` matrix (each position once, columns sorted) and ``inverse``, the slot of each entry
    (entries bucketed by row, each row's sorted by column)."""
    m = rows.shape[0]
    start = np.zeros(n + 1, dtype=np.int64)
    for k in range(m):
        start[rows[k] + 1] += 1
    for i in range(n):
        start[i + 1] += start[i]
    fill = start[:n].copy()
    bucket = np.empty(m, dtype=np.int64)
    for k in range(m):
        bucket[fill[rows[k]]] = k
        fill[rows[k]] += 1
    for i in range(n):
        lo, hi = start[i], start[i + 1]
        if hi - lo > 32:
            bucket[lo:hi] = bucket[lo:hi][np.argsort(cols[bucket[lo:hi]], kind="mergesort")]
            continue
        for a in range(lo + 1, hi):           # insertion sort: a row holds a few element entries
            k = bucket[a]
            b = a
            while b > lo and cols[bucket[b - 1]] > cols[k]:
                bucket[b] = bucket[b - 1]
                b -= 1
            bucket[b] = k
    indptr = np.zeros(n + 1, dtype=np.int64)
    indices = np.empty(m, dtype=np.int64)
    inverse = np.empty(m, dtype=np.int64)
    u = -1
    for i in range(n):
        for a in range(start[i], start[i + 1]):
            k = bucket[a]
            if a == start[i] or cols[k] != cols[bucket[a - 1]]:
                u += 1
                indices[u] = cols[k]
            inverse[k] = u
        indptr[i + 1] = u + 1
    return indptr, indices[: u + 1], inverse


@njit(cache=True)
def nonzero_entries(indptr, indices, data):
    """``(rows, cols, values (m, nnz))`` of the positions of the CSR pattern ``(indptr, indices)``
    where any of the ``m`` value rows ``data (m, len(indices))`` is nonzero, in the pattern's order."""
    n_values, size = data.shape
    used = np.zeros(size, dtype=np.bool_)
    count = 0
    for k in range(size):
        for q in range(n_values):
            if data[q, k] != 0.0:
                used[k] = True
                count += 1
                break
    rows = np.empty(count, dtype=np.int64)
    cols = np.empty(count, dtype=np.int64)
    values = np.empty((n_values, count))
    m = 0
    for i in range(indptr.shape[0] - 1):
        for k in range(indptr[i], indptr[i + 1]):
            if used[k]:
                rows[m], cols[m] = i, indices[k]
                for q in range(n_values):
                    values[q, m] = data[q, k]
                m += 1
    return rows, cols, values


@njit(cache=True)
def permuted_entries(rows, cols, values, order):
    """The entries ``(rows, cols, values (m, nnz))`` in the numbering ``order`` (a permutation:
    new index k is old index ``order[k]``), sorted by row, then column."""
    n = order.shape[0]
    position = np.empty(n, dtype=np.int64)
    for k in range(n):
        position[order[k]] = k
    keys = np.empty(rows.shape[0], dtype=np.int64)
    for k in range(rows.shape[0]):
        keys[k] = position[rows[k]] * n + position[cols[k]]
    sort = np.argsort(keys)
    r = np.empty(rows.shape[0], dtype=np.int64)
    c = np.empty(rows.shape[0], dtype=np.int64)
    v = np.empty(values.shape)
    for k in range(sort.shape[0]):
        r[k], c[k] = keys[sort[k]] // n, keys[sort[k]] % n
        for q in range(values.shape[0]):
            v[q, k] = values[q, sort[k]]
    return r, c, v


@njit(cache=True)
def csr_pointers(rows, n):
    """CSR row pointers ``(n + 1,)`` int64 of entries sorted by their ``rows``."""
    ptr = np.zeros(n + 1, dtype=np.int64)
    for k in range(rows.shape[0]):
        ptr[rows[k] + 1] += 1
    for i in range(n):
        ptr[i + 1] += ptr[i]
    return ptr


@njit(cache=True)
def reverse_cuthill_mckee(indptr, indices):
    """Reverse Cuthill-McKee order (int64 (n,)) of the symmetric pattern ``(indptr, indices)``
    (CSR, n rows), as scipy's ``reverse_cuthill_mckee`` (``symmetric_mode``): a breadth-first
    search from each unvisited dof in increasing degree (a diagonal entry counts twice), each
    dof's new neighbours in increasing degree, the whole order reversed.

    References
    ----------
    Cuthill, E., McKee, J. (1969) Reducing the bandwidth of sparse symmetric matrices. Proc.
    24th ACM National Conference, 157-172. scipy ``sparse/csgraph/_reordering.pyx``.
    """
    n = indptr.shape[0] - 1
    degree = np.empty(n, dtype=np.int64)
    for i in range(n):
        degree[i] = indptr[i + 1] - indptr[i]
        for k in range(indptr[i], indptr[i + 1]):
            if indices[k] == i:
                degree[i] += 1
                break
    seeds = np.argsort(degree, kind="mergesort")
    visited = np.zeros(n, dtype=np.bool_)
    order = np.empty(n, dtype=np.int64)
    count = 0
    for seed in seeds:
        if visited[seed]:
            continue
        visited[seed] = True
        order[count] = seed
        count += 1
        level_start, level_end = count - 1, count
        while level_start < level_end:
            for q in range(level_start, level_end):
                i = order[q]
                first = count
                for k in range(indptr[i], indptr[i + 1]):
                    j = indices[k]
                    if not visited[j]:
                        visited[j] = True
                        order[count] = j
                        count += 1
                for a in range(first + 1, count):      # insertion sort of the new ones by degree
                    j = order[a]
                    b = a
                    while b > first and degree[j] < degree[order[b - 1]]:
                        order[b] = order[b - 1]
                        b -= 1
                    order[b] = j
            level_start, level_end = level_end, count
    return order[::-1].copy()


@njit(cache=True)
def solver_order(rows, cols, values, dofs, n):
    """The entries ``(rows, cols, values (m, nnz))`` of an ``n × n`` pattern (sorted by row, then
    column) on the rows and columns ``dofs`` (ascending), in solver order: ``(order, rows, cols,
    values)``, solver dof k being ``dofs[order[k]]`` (:func:`reverse_cuthill_mckee`), the entries
    renumbered and sorted by row, then column."""
    r, c, keep = renumbered(rows, cols, dofs, n)     # ``dofs`` ascending: still sorted
    kept = np.empty((values.shape[0], r.shape[0]))
    m = 0
    for k in range(keep.shape[0]):
        if keep[k]:
            kept[:, m] = values[:, k]
            m += 1
    order = reverse_cuthill_mckee(csr_pointers(r, dofs.shape[0]), c)
    r, c, kept = permuted_entries(r, c, kept, order)
    return order, r, c, kept


class FreePattern(NamedTuple):
    """K, M and C over the free dofs (solver order) on their one sparsity pattern.

    rows, cols : int64 (nnz,) the entries where any of the three is nonzero, sorted by row, then
        column; K, M, C : float64 (nnz,) their values there [N/m, kg, N s/m and the rotational
        counterparts]."""
    rows: np.ndarray
    cols: np.ndarray
    K: np.ndarray
    M: np.ndarray
    C: np.ndarray


def _union_pattern(matrices):
    """``(rows, cols, values (len(matrices), nnz))`` of square sparse matrices on the entries
    where any of them is nonzero, sorted by row, then column."""
    coos = [sp.coo_matrix(a) for a in matrices]
    n = matrices[0].shape[0]
    keys = np.concatenate([a.row.astype(np.int64) * n + a.col for a in coos])
    unique, inverse = np.unique(keys, return_inverse=True)
    values = np.zeros((len(coos), len(unique)))
    start = 0
    for k, a in enumerate(coos):
        np.add.at(values[k], inverse[start: start + a.nnz], a.data)
        start += a.nnz
    used = np.any(values != 0.0, axis=0)
    return unique[used] // n, unique[used] % n, values[:, used]


class Assembly:
    """The assembled linear model: matrices, dof maps and element data, built by :meth:`Model.build`.

    Attributes
    ----------
    K_full, M_full, C_full : CSR (n_full, n_full) over all dofs (for reactions).
    K, M, C : CSR (n_free, n_free) over the free dofs in solver order.
    pattern : :class:`FreePattern`, the values of K, M, C over the free dofs as arrays (what the
        analyses factor and step; the CSR matrices above are built from it, and the full ones from
        the element assembly, on first use).
    free_of_full : int64 (n_full,) free index of each full dof, -1 if fixed.
    full_of_free : int64 (n_free,) full index of each free dof.
    blocks : ``[(etype, tags, coords, params, full dofs)]``, one per element type with elements.
    element_matrices : ``[ElementMatrices]`` (:class:`vtsi.elements.base.ElementMatrices`), one per
        block: each type's stiffness, mass and damping kernels are called once per build, their
        output checked (:func:`vtsi.elements.base.checked_matrix`: shape, dtype, finite, symmetric,
        no negative diagonal, mass and damping semi-definite) and kept here for the element
        recorders (``K_e u_e + C_e v_e`` without calling a kernel again). Memory: 3 · n_el · ndof²
        float64 (2000 beams: 1.7 MB).
    derived : dict, what a reader of the assembly derives from it once, by the reader's own key
        (the bending moment recorders' rows, :mod:`vtsi.recorders.moment`): a sweep's passages
        share the model's assembly, and a changed model builds a new one.
    """

    def __init__(self, model):
        self.ndf = model.ndf
        self.node_tags = np.array(list(model.nodes), dtype=np.int64)
        self.node_index = {tag: i for i, tag in enumerate(model.nodes)}
        self.coords = np.array(list(model.nodes.values()), dtype=np.float64).reshape(-1, 2)
        self.n_full = len(self.node_tags) * self.ndf
        if self.n_full == 0:
            raise ModelError("model has no nodes")
        self._matrices = {}
        self.derived = {}
        self._equivalent_loads = {}     # id(pattern) -> (pattern, its version, element_equivalent_loads)
        self._element_data(model)
        self._assemble(model)
        self._number_free_dofs(model)

    # -- element blocks -------------------------------------------------------------------
    def _element_data(self, model):
        self.blocks = []  # (etype, tags, coords, params, full dofs)
        by_tag = np.argsort(self.node_tags)
        sorted_tags = self.node_tags[by_tag]
        for etype in model.element_types.values():
            if len(etype) == 0:
                continue
            tags = np.array(etype.tags, dtype=np.int64)
            coords, dofs, missing = element_nodes(sorted_tags, by_tag, np.array(etype.nodes, dtype=np.int64),
                                                  self.coords, np.array(etype.node_dofs, dtype=np.int64), self.ndf)
            if missing >= 0:
                node = next(n for n in etype.nodes[missing] if n not in self.node_index)
                raise ModelError(f"element {etype.tags[missing]} ({etype.name}): node {node} does not exist")
            etype.check_geometry(coords, tags, etype.nodes)
            self.blocks.append((etype, tags, coords, etype.params, dofs))

    @functools.cached_property
    def element_location(self):
        """``{element tag: (block, index in the block)}``."""
        return {tag: (b, i) for b, (etype, *_rest) in enumerate(self.blocks) for i, tag in enumerate(etype.tags)}

    def _assemble(self, model):
        n = self.n_full
        rows = [np.arange(n)]
        cols = [np.arange(n)]
        for *_, dofs in self.blocks:
            r, c = element_entries(dofs)
            rows.append(r)
            cols.append(c)
        indptr, indices, inverse = csr_pattern(np.concatenate(rows), np.concatenate(cols), n)
        offset = n
        alpha_m, beta_k = model.rayleigh_factors
        rayleigh = alpha_m != 0.0 or beta_k != 0.0
        data = np.zeros((5 if rayleigh else 3, len(indices)))   # K, M, C (and K, M of the elements taking Rayleigh)
        self.element_matrices = []
        k_data, m_data, c_data = data[:3]
        for etype, tags, coords, params, dofs in self.blocks:
            nd = dofs.shape[1]
            positions = inverse[offset: offset + dofs.shape[0] * nd * nd].reshape(-1, nd, nd)
            offset += dofs.shape[0] * nd * nd
            ones = np.ones(len(tags))
            matrices = element_matrices(etype, coords, params, tags)    # the kernels, once; shapes and values checked
            self.element_matrices.append(matrices)
            ke, me, ce = matrices
            scatter_add(k_data, positions, ke, ones)
            scatter_add(m_data, positions, me, ones)
            scatter_add(c_data, positions, ce, ones)
            if rayleigh:
                weights = ones if model.rayleigh_every_element else element_rayleigh_weights(etype, params, tags)
                scatter_add(data[3], positions, ke, weights)
                scatter_add(data[4], positions, me, weights)
        if model.nodal_mass:
            diag = inverse[:n]
            nodal_mass = np.zeros(n)
            for tag, values in model.nodal_mass.items():
                i = self.node_index[tag]
                nodal_mass[i * self.ndf: i * self.ndf + len(values)] += values
            for row in data[1::3]:                   # M, and M of the elements taking Rayleigh
                row[diag] += nodal_mass
        if rayleigh:
            c_data += alpha_m * data[4] + beta_k * data[3]   # Rayleigh on the elements that take it (or all)
        self._full = (indptr, indices, {"K": k_data, "M": m_data, "C": c_data})
        # the one sparsity pattern of K, M, C (entries where any is nonzero), as (row, column) pairs
        self._used = nonzero_entries(indptr, indices, data[:3])
        self.has_damping = bool(self._used[2][2].any())

    def _number_free_dofs(self, model):
        index, ndf = self.node_index, self.ndf
        fixed = [index[tag] * ndf + d for tag, flags in model.fixities.items() for d in range(ndf) if flags[d]]
        prescribed = sorted({index[node] * ndf + d for pattern in model.patterns.values()   # sp constrain their dofs
                             for node, d in pattern.prescribed})
        constrained = sorted(index[node] * ndf + d for node, d in model.mp_constraints)
        self.prescribed_full = np.array(prescribed, dtype=np.int64)
        taken = np.zeros(self.n_full, dtype=bool)
        taken[np.array(fixed + prescribed + constrained, dtype=np.int64)] = True
        free = np.flatnonzero(~taken)
        if free.size == 0:
            raise ModelError("every dof of the model is fixed: nothing to analyse")
        n_free = len(free)
        # the free rows and columns of K, M, C (T (n_full, n_free): full dofs from the free ones, the
        # identity and the constrained rows), numbered as ``free``, on their one pattern
        if model.mp_constraints:
            TS = self._transformation(model, free, self.prescribed_full).tocsc()
            T, S = TS[:, :n_free], TS[:, n_free:]
            rows, cols, values = _union_pattern([T.T @ self._full_matrix(name) @ T for name in "KMC"])
            order, rows, cols, values = solver_order(rows, cols, values, np.arange(n_free), n_free)
        else:
            order, rows, cols, values = solver_order(*self._used, free, self.n_full)
        self.full_of_free = free[order]
        self.free_of_full = np.full(self.n_full, -1, dtype=np.int64)
        self.free_of_full[self.full_of_free] = np.arange(n_free)
        self.pattern = FreePattern(rows, cols, *values)
        if model.mp_constraints:
            self.transformation = T = T[:, order].tocsr()
            self.constrained_dofs = np.array(constrained, dtype=np.int64)
            self.constrained_rows = T[self.constrained_dofs]
            self.constrained_prescribed = S.tocsr()[self.constrained_dofs]    # on prescribed_full
        else:
            self.transformation = self.constrained_rows = self.constrained_dofs = self.constrained_prescribed = None

    def _full_matrix(self, name):
        """CSR (n_full, n_full) of ``name`` ('K', 'M', 'C') over all dofs, built on first use."""
        key = name + "_full"
        if key not in self._matrices:
            indptr, indices, data = self._full
            self._matrices[key] = sp.csr_matrix((data[name], indices, indptr), shape=(self.n_full, self.n_full))
        return self._matrices[key]

    def _free_matrix(self, name):
        """CSR (n_free, n_free) of ``name`` ('K', 'M', 'C') over the free dofs (its nonzeros of
        :attr:`pattern`, sorted), built on first use."""
        if name not in self._matrices:
            p = self.pattern
            values = getattr(p, name)
            nonzero = values != 0.0    # exact structural zeros (e.g. axial-bending of a straight beam) left out
            a = sp.csr_matrix((values[nonzero], p.cols[nonzero], csr_pointers(p.rows[nonzero], self.n_free)),
                              shape=(self.n_free, self.n_free))
            a.has_sorted_indices = True
            self._matrices[name] = a
        return self._matrices[name]

    K = property(lambda self: self._free_matrix("K"))
    M = property(lambda self: self._free_matrix("M"))
    C = property(lambda self: self._free_matrix("C"))
    K_full = property(lambda self: self._full_matrix("K"))
    M_full = property(lambda self: self._full_matrix("M"))
    C_full = property(lambda self: self._full_matrix("C"))

    def _transformation(self, model, free, prescribed):
        """``[T S]`` (n_full, len(free) + len(prescribed)), ``u_full = T u_free + S u_prescribed``,
        of the equalDOF / rigidLink constraints (OpenSees's Transformation handler): a constrained
        dof's row is its coefficients times the rows of its retained dofs (free and prescribed
        ones: their column, fixed ones: zero, constrained ones in turn)."""
        column = -np.ones(self.n_full, dtype=np.int64)
        column[free] = np.arange(len(free))
        column[prescribed] = len(free) + np.arange(len(prescribed))
        full = lambda node, d: self.node_index[node] * self.ndf + d
        rows, resolving = {}, set()

        def row(k):
            if k in rows:
                return rows[k]
            if column[k] >= 0:
                return {int(column[k]): 1.0}
            node, d = int(self.node_tags[k // self.ndf]), k % self.ndf
            if (node, d) not in model.mp_constraints:
                return {}                                     # fixed
            if k in resolving:
                raise ModelError(f"equalDOF/rigidLink: node {node} dof {d + 1} is constrained in a circle")
            resolving.add(k)
            out = {}
            for r_node, r_d, coef in model.mp_constraints[(node, d)]:
                for j, c in row(full(r_node, r_d)).items():
                    out[j] = out.get(j, 0.0) + coef * c
            resolving.discard(k)
            rows[k] = out
            return out

        r, c, v = list(free), list(range(len(free))), [1.0] * len(free)
        for node, d in model.mp_constraints:
            k = full(node, d)
            for j, coef in row(k).items():
                r.append(k)
                c.append(j)
                v.append(coef)
        r += list(prescribed)
        c += list(len(free) + np.arange(len(prescribed)))
        v += [1.0] * len(prescribed)
        return sp.csr_matrix((v, (r, c)), shape=(self.n_full, len(free) + len(prescribed)))

    def complete(self, vector):
        """Set the constrained dofs of the full-dof ``vector`` from its free and prescribed dofs
        (in place)."""
        if self.constrained_rows is not None:
            vector[self.constrained_dofs] = (self.constrained_rows @ vector[self.full_of_free]
                                             + self.constrained_prescribed @ vector[self.prescribed_full])

    # -- helpers --------------------------------------------------------------------------
    @property
    def n_free(self):
        return len(self.full_of_free)

    def dof_label(self, free_index):
        """``'node 5 dof 2 (uy)'`` for a free dof index (OpenSees's 1-based dof numbers)."""
        full = int(self.full_of_free[free_index])
        node, d = divmod(full, self.ndf)
        return f"node {self.node_tags[node]} dof {d + 1} ({DOF_NAMES[d]})"

    def full_dof(self, node_tag, dof):
        """Full index of ``dof`` (1-based, OpenSees) of node ``node_tag``."""
        if node_tag not in self.node_index:
            raise ModelError(f"node {node_tag} does not exist")
        if not 1 <= dof <= self.ndf:
            raise ModelError(f"node {node_tag}: dof {dof} out of range 1..{self.ndf}")
        return self.node_index[node_tag] * self.ndf + dof - 1

    def element_equivalent_loads(self, pattern):
        """``{element tag: (ndof,) global nodal loads}`` equivalent to the element loads of
        ``pattern`` (factor 1; :meth:`vtsi.loads.LoadPattern.beam_load`), computed once per
        version of the pattern's loads (a query per element reads them: OpenSees's cost)."""
        cached = self._equivalent_loads.get(id(pattern))
        if cached is not None and cached[0] is pattern and cached[1] == pattern.version:
            return dict(cached[2])
        out = {}
        for tag, kind, values in pattern.element_loads:
            if tag not in self.element_location:
                raise ModelError(f"pattern {pattern.tag}: load on element {tag}, which does not exist")
            b, i = self.element_location[tag]
            etype, _, coords, params, _dofs = self.blocks[b]
            try:
                f = etype.equivalent_loads(coords[i], params[i], kind, values)
            except ModelError as exc:
                raise ModelError(f"pattern {pattern.tag}: element {tag}: {exc}") from None
            out[tag] = out.get(tag, 0.0) + f
        self._equivalent_loads[id(pattern)] = (pattern, pattern.version, out)
        return dict(out)

    def load_vector(self, pattern):
        """Free-dof load vector ``(n_free,)`` of a pattern (:meth:`load_vectors`)."""
        return self.load_vectors([pattern])[0]

    def load_vectors(self, patterns):
        """Free-dof load vectors ``(len(patterns), n_free)`` of the patterns' loads
        (:meth:`full_load_vectors`) and, of prescribed displacements g (``sp``), −K g. A pattern
        of nodal loads alone, in a model without constraints, goes straight into the free dofs
        (``free_of_full``: no full vector, the same numbers), as a script that moves a load by a
        new pattern at every step makes them."""
        out = np.zeros((len(patterns), self.n_free))
        general = []            # the rows of the patterns that need a full vector
        direct = self.transformation is None
        for row, pattern in enumerate(patterns):
            if direct and pattern.ground_direction is None and not pattern.element_loads and not pattern.prescribed:
                self._set_nodal_loads(out, row, pattern, self._free_places)
            else:
                general.append(row)
        if not general:
            return out
        chosen = [patterns[row] for row in general]
        full = self.full_load_vectors(chosen)
        for p, pattern in zip(full, chosen):
            if pattern.prescribed:          # −K g of the prescribed displacements g (and of the dofs tied to them)
                g = np.zeros(self.n_full)
                for (node, d), value in pattern.prescribed.items():
                    if node not in self.node_index:
                        raise ModelError(f"pattern {pattern.tag}: sp on node {node}, which does not exist")
                    g[self.node_index[node] * self.ndf + d] = value
                self.complete(g)
                p -= self.K_full @ g
        out[general] = self.reduce(full.T).T
        return out

    def full_load_vectors(self, patterns):
        """Full-dof loads ``(len(patterns), n_full)`` [N, N·m] the patterns apply at factor 1, fixed
        dofs included (a reaction needs the supports' rows): nodal loads plus the equivalent nodal
        loads of element loads (the fixed-end forces negated); of a ground acceleration
        (``pattern.ground_direction``) −M r over every dof, r the unit translation along it, as
        OpenSees's ``EarthquakePattern`` loads every node's mass (a fixed node's too) and every
        element's. A prescribed displacement (``sp``) is not a load: it moves its dof."""
        full = np.zeros((len(patterns), self.n_full))
        for row, pattern in enumerate(patterns):
            if pattern.ground_direction is not None:
                full[row] -= self.M_full @ self.ground_vector(pattern.ground_direction)
                continue
            self._set_nodal_loads(full, row, pattern, range(self.n_full))
            if pattern.element_loads:
                for tag, f in self.element_equivalent_loads(pattern).items():
                    b, i = self.element_location[tag]
                    full[row, self.blocks[b][4][i]] += f
        return full

    @functools.cached_property
    def _free_places(self):
        """``free_of_full`` as a list (read an entry at a time)."""
        return self.free_of_full.tolist()

    def _set_nodal_loads(self, vectors, row, pattern, places):
        """Set the nodal loads of ``pattern`` [N, N·m] into row ``row`` of ``vectors`` (zero
        there), full dof ``j`` at ``places[j]``, none where that is negative (a fixed dof of a
        free-dof vector); each dof takes one value (a node's loads are one entry of the
        pattern). A ModelError names a node that does not exist or a load of more than ndf values."""
        index, ndf = self.node_index, self.ndf
        for tag, values in pattern.nodal.items():
            i = index.get(tag)
            if i is None:
                raise ModelError(f"pattern {pattern.tag}: load on node {tag}, which does not exist")
            if len(values) > ndf:
                raise ModelError(f"pattern {pattern.tag}: load on node {tag} has {len(values)} values, ndf is {ndf}")
            for j, value in zip(places[i * ndf: i * ndf + len(values)], values.tolist()):
                if j >= 0:
                    vectors[row, j] = 0.0 + value     # (0.0 + a -0.0 load is 0.0, as a sum onto the zeros)

    def ground_vector(self, direction):
        """``r (n_full,)``: 1 at the translations along ``direction`` (1 x, 2 y), 0 elsewhere."""
        r = np.zeros(self.n_full)
        r[direction - 1::self.ndf] = 1.0
        return r

    def prescribed_dofs(self, patterns):
        """``[(pattern, full dofs, values)]`` of the patterns' prescribed displacements (sp)."""
        return [(p, np.array([self.node_index[n] * self.ndf + d for n, d in p.prescribed], dtype=np.int64),
                 np.array(list(p.prescribed.values()))) for p in patterns if p.prescribed]

    def reduce(self, full_load):
        """The free-dof load ``Tᵀ p`` of a full-dof load ``(n_full, ...)`` (its free entries without
        constraints)."""
        return full_load[self.full_of_free] if self.transformation is None else self.transformation.T @ full_load

    def element_state(self, tags, u_full, v_full):
        """Group element tags by type: yields ``(etype, coords, params, u_e, v_e, order)``."""
        by_block = {}
        for k, tag in enumerate(tags):
            if tag not in self.element_location:
                raise ModelError(f"element {tag} does not exist")
            b, i = self.element_location[tag]
            by_block.setdefault(b, []).append((k, i))
        for b, pairs in by_block.items():
            etype, _, coords, params, dofs = self.blocks[b]
            order = np.array([k for k, _ in pairs])
            idx = np.array([i for _, i in pairs])
            d = dofs[idx]
            yield etype, coords[idx], params[idx], u_full[..., d], v_full[..., d], order
