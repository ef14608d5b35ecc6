"""Dof numbering and assembly of K, M, C into scipy CSR through a precomputed position map.

For every element type the element dof indices are computed once; the union of all element
blocks (plus every diagonal entry) gives the CSR pattern, and ``positions[type]`` maps each
entry of the ``(n_el, nd, nd)`` element matrices to its slot in the CSR ``data`` array. A numba
kernel then adds all element matrices of a type in one call.

Dof indices: a *full* index is ``node_index * ndf + d`` (d = 0 ux, 1 uy, 2 rz). The free dofs
are renumbered for a small bandwidth (reverse Cuthill-McKee); ``free_of_full[j]`` is the free
index of full dof ``j`` or -1 where the dof is fixed.
"""
import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.sparse.csgraph import reverse_cuthill_mckee

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


def principal(coo, dofs, n):
    """Rows and columns ``dofs`` (in that order) of the ``n × n`` COO matrix ``coo``, as a COO
    matrix: one mask and one renumbering instead of two sparse slicings."""
    r, c, keep = _renumbered(coo.row, coo.col, dofs, n)
    return sp.coo_matrix((coo.data[keep], (r, c)), shape=(len(dofs), len(dofs)))


def _renumbered(rows, cols, dofs, n):
    """The entries ``(rows, cols)`` of an ``n × n`` pattern in rows and columns ``dofs``,
    renumbered by their position there: ``(rows, cols, kept mask)``."""
    position = np.full(n, -1, dtype=np.int64)
    position[dofs] = np.arange(len(dofs))
    r, c = position[rows], position[cols]
    keep = (r >= 0) & (c >= 0)
    return r[keep], c[keep], keep


class Assembly:
    """The assembled linear model: matrices, dof maps and element data, built by :meth:`Model.build`.

    Attributes
    ----------
    K_full, M_full, C_full : CSR (n_full, n_full) over all dofs (for reactions).
    K, M, C : CSR (n_free, n_free) over the free dofs in solver order.
    free_of_full : int64 (n_full,) free index of each full dof, -1 if fixed.
    full_of_free : int64 (n_free,) full index of each free dof.
    """

    def __init__(self, model):
        self.ndf = model.ndf
        self.node_tags = np.array(list(model.nodes), dtype=np.int64)
        self.node_index = {tag: i for i, tag in enumerate(self.node_tags)}
        self.coords = np.array([model.nodes[t] for t in self.node_tags], dtype=np.float64).reshape(-1, 2)
        self.n_full = len(self.node_tags) * self.ndf
        if self.n_full == 0:
            raise ModelError("model has no nodes")
        self._element_data(model)
        self._assemble(model)
        self._number_free_dofs(model)

    # -- element blocks -------------------------------------------------------------------
    def _element_data(self, model):
        self.blocks = []  # (etype, tags, coords, params, full dofs)
        for etype in model.element_types.values():
            if len(etype) == 0:
                continue
            tags = np.array(etype.tags, dtype=np.int64)
            conn = np.array([[self.node_index[n] for n in nodes] for nodes in etype.nodes], dtype=np.int64)
            coords = self.coords[conn]
            etype.check_geometry(coords, tags, etype.nodes)
            local = np.array(etype.node_dofs, dtype=np.int64)
            dofs = (conn[:, :, None] * self.ndf + local[None, None, :]).reshape(len(tags), -1)
            self.blocks.append((etype, tags, coords, etype.params, dofs))
        self.element_location = {}
        for b, (_, tags, *_rest) in enumerate(self.blocks):
            for i, tag in enumerate(tags):
                self.element_location[int(tag)] = (b, i)

    def _assemble(self, model):
        n = self.n_full
        rows = [np.arange(n)]
        cols = [np.arange(n)]
        for *_, dofs in self.blocks:
            nd = dofs.shape[1]
            rows.append(np.repeat(dofs, nd, axis=1).ravel())
            cols.append(np.tile(dofs, (1, nd)).ravel())
        keys = np.concatenate(rows) * n + np.concatenate(cols)
        unique, inverse = np.unique(keys, return_inverse=True)
        indptr = np.searchsorted(unique // n, np.arange(n + 1)).astype(np.int64)
        indices = (unique % n).astype(np.int64)
        offset = n
        k_data, m_data, c_data, kr_data, mr_data = (np.zeros(len(unique)) for _ in range(5))
        for etype, tags, coords, params, dofs in self.blocks:
            nd = dofs.shape[1]
            positions = inverse[offset: offset + dofs.shape[0] * nd * nd].reshape(-1, nd, nd).astype(np.int64)
            offset += dofs.shape[0] * nd * nd
            ones = np.ones(len(tags))
            rayleigh = etype.rayleigh_weights(params) if hasattr(etype, "rayleigh_weights") else ones
            ke, me = etype.stiffness(coords, params), etype.mass(coords, params)
            scatter_add(k_data, positions, ke, ones)
            scatter_add(kr_data, positions, ke, rayleigh)
            scatter_add(m_data, positions, me, ones)
            scatter_add(mr_data, positions, me, rayleigh)
            scatter_add(c_data, positions, etype.damping(coords, params), ones)
        diag = inverse[:n]
        nodal_mass = np.zeros(n)
        for tag, values in model.nodal_mass.items():
            i = self.node_index[tag]
            nodal_mass[i * self.ndf: i * self.ndf + len(values)] += values
        m_data[diag] += nodal_mass
        mr_data[diag] += nodal_mass
        alpha_m, beta_k = model.rayleigh_factors
        c_data += alpha_m * mr_data + beta_k * kr_data   # Rayleigh only on elements that take it
        make = lambda data: sp.csr_matrix((data, indices, indptr), shape=(n, n))
        self.K_full, self.M_full, self.C_full = make(k_data), make(m_data), make(c_data)
        # the one sparsity pattern of K, M, C (entries where any is nonzero), as (row, column) pairs
        used = (k_data != 0.0) | (m_data != 0.0) | (c_data != 0.0)
        self._pattern = (np.repeat(np.arange(n), np.diff(indptr))[used], indices[used], used)
        self.has_damping = bool(np.any(c_data != 0.0))

    def _number_free_dofs(self, model):
        fixed = np.zeros(self.n_full, dtype=bool)
        for tag, flags in model.fixities.items():
            i = self.node_index[tag]
            fixed[i * self.ndf: (i + 1) * self.ndf] |= np.asarray(flags[: self.ndf], dtype=bool)
        prescribed = np.zeros(self.n_full, dtype=bool)
        for pattern in model.patterns.values():       # prescribed displacements (sp) constrain their dofs
            for node, d in pattern.prescribed:
                prescribed[self.node_index[node] * self.ndf + d] = True
        fixed |= prescribed
        self.prescribed_full = np.flatnonzero(prescribed)
        constrained = np.zeros(self.n_full, dtype=bool)
        for node, d in model.mp_constraints:
            constrained[self.node_index[node] * self.ndf + d] = True
        free = np.flatnonzero(~fixed & ~constrained)
        if free.size == 0:
            raise ModelError("every dof of the model is fixed: nothing to analyse")
        n = self.n_full
        # T (n_full, len(free)): full dofs from the free ones (the identity, and the constrained rows)
        T, S = (None, None)
        if model.mp_constraints:
            TS = self._transformation(model, free, self.prescribed_full).tocsc()
            T, S = TS[:, :len(free)], TS[:, len(free):]
        if T is None:       # the free rows and columns of the one pattern of K, M, C
            rows, cols, _ = self._pattern
            r, c, _ = _renumbered(rows, cols, free, n)
            pattern = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(len(free), len(free)))
        else:
            pattern = (abs(T.T @ self.K_full @ T) + abs(T.T @ self.M_full @ T) + abs(T.T @ self.C_full @ T)).tocsr()
            pattern.eliminate_zeros()
        order = reverse_cuthill_mckee(pattern, symmetric_mode=True)
        self.full_of_free = free[order].astype(np.int64)
        self.free_of_full = -np.ones(self.n_full, dtype=np.int64)
        self.free_of_full[self.full_of_free] = np.arange(len(self.full_of_free))
        if T is None:
            self.transformation = self.constrained_rows = self.constrained_dofs = self.constrained_prescribed = None
            rows, cols, used = self._pattern
            r, c, keep = _renumbered(rows, cols, self.full_of_free, n)
            shape = (len(free), len(free))
            sub = lambda a: sp.csr_matrix((a.data[used][keep], (r, c)), shape=shape)
        else:
            self.transformation = T = T[:, order].tocsr()
            self.constrained_dofs = np.flatnonzero(constrained)
            self.constrained_rows = T[self.constrained_dofs]
            self.constrained_prescribed = S.tocsr()[self.constrained_dofs]    # on prescribed_full
            sub = lambda a: (T.T @ a @ T).tocsr()
        self.K, self.M, self.C = sub(self.K_full), sub(self.M_full), sub(self.C_full)
        for a in (self.K, self.M, self.C):
            a.eliminate_zeros()   # exact structural zeros (e.g. axial-bending of a straight beam)
            a.sort_indices()

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
        ``pattern`` (factor 1; :meth:`vtsi.loads.LoadPattern.beam_load`)."""
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
        return out

    def load_vector(self, pattern):
        """Free-dof load vector ``(n_free,)`` of a pattern's nodal and element loads (factor 1);
        of a ground acceleration (``pattern.ground_direction``), −M r with r the unit translation
        along it."""
        if pattern.ground_direction is not None:
            r = np.zeros(self.n_full)
            r[pattern.ground_direction - 1::self.ndf] = 1.0
            return self.reduce(-(self.M_full @ r))
        p = np.zeros(self.n_full)
        for tag, values in pattern.nodal.items():
            if tag not in self.node_index:
                raise ModelError(f"pattern {pattern.tag}: load on node {tag}, which does not exist")
            if len(values) > self.ndf:
                raise ModelError(f"pattern {pattern.tag}: load on node {tag} has {len(values)} values, "
                                 f"ndf is {self.ndf}")
            i = self.node_index[tag]
            p[i * self.ndf: i * self.ndf + len(values)] += values
        for tag, f in self.element_equivalent_loads(pattern).items():
            b, i = self.element_location[tag]
            p[self.blocks[b][4][i]] += f
        if pattern.prescribed:          # −K g of the prescribed displacements g (and of the dofs tied to them)
            g = np.zeros(self.n_full)
            for (node, d), value in pattern.prescribed.items():
                if node not in self.node_index:
                    raise ModelError(f"pattern {pattern.tag}: sp on node {node}, which does not exist")
                g[self.node_index[node] * self.ndf + d] = value
            self.complete(g)
            p -= self.K_full @ g
        return self.reduce(p)

    def prescribed_dofs(self, patterns):
        """``[(pattern, full dofs, values)]`` of the patterns' prescribed displacements (sp)."""
        return [(p, np.array([self.node_index[n] * self.ndf + d for n, d in p.prescribed], dtype=np.int64),
                 np.array(list(p.prescribed.values()))) for p in patterns if p.prescribed]

    def reduce(self, full_load):
        """The free-dof load ``Tᵀ p`` of a full-dof load (its free entries without constraints)."""
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
