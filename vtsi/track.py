"""The track: a chain of beam elements that wheels run along, and the constraint rows N(x).

A wheel at position x on track element e (start x_e, length ℓ_e, ξ = (x - x_e)/ℓ_e) sees the
rail's vertical displacement through the cubic Hermite functions of an Euler-Bernoulli beam,

    w(x) = H1 v1 + ℓ H2 θ1 + H3 v2 + ℓ H4 θ2,
    H1 = 1 - 3ξ² + 2ξ³,  H2 = ξ - 2ξ² + ξ³,  H3 = 3ξ² - 2ξ³,  H4 = -ξ² + ξ³,

(θ = rz = dw/dx, counter-clockwise positive). Off the chain the row is zero: rigid ground.
The chain is stored per element, so two spans may end on different nodes at one pier.
Columns are *track dof* indices (0 .. n_track - 1); ``free_index[t]`` maps them to the
bridge's free dofs. Fixed dofs (supports) are dropped from the rows.
"""
import numpy as np
from numba import njit

from vtsi.errors import ModelError


class Track:
    """Wheels run along ``elements`` (tags of 2-node beam elements with uy and rz dofs), which
    must form a straight horizontal chain, ordered along +x and without gaps.

    Attributes
    ----------
    x_start, length : (n_el,) element start coordinate and length [m].
    dofs : (n_el, 4) int64 track dof of [uy1, rz1, uy2, rz2] (-1 where fixed).
    free_index : (n_track,) int64 bridge free dof of each track dof.
    x_begin, x_end : extent of the chain [m].
    """

    def __init__(self, model, elements):
        asm = model.build()
        elements = [int(e) for e in elements]
        if not elements:
            raise ModelError("track: no elements given")
        if len(set(elements)) != len(elements):
            raise ModelError("track: an element is listed twice")
        ends, full = [], []
        for tag in elements:
            if tag not in asm.element_location:
                raise ModelError(f"track: element {tag} does not exist")
            b, i = asm.element_location[tag]
            etype = asm.blocks[b][0]
            if etype.n_nodes != 2 or tuple(etype.node_dofs) != (0, 1, 2):
                raise ModelError(f"track: element {tag} ({etype.name}) is not a 2-node beam with ux, uy, rz dofs")
            coords = asm.blocks[b][2][i]
            dofs = asm.blocks[b][4][i]
            if coords[1, 0] < coords[0, 0]:
                coords, dofs = coords[::-1], dofs[[3, 4, 5, 0, 1, 2]]
            if abs(coords[0, 1] - coords[1, 1]) > 1e-9 * max(1.0, abs(coords[1, 0] - coords[0, 0])):
                raise ModelError(f"track: element {tag} is not horizontal (y from {coords[0, 1]:g} to {coords[1, 1]:g})")
            ends.append((coords[0, 0], coords[1, 0], tag))
            full.append(dofs[[1, 2, 4, 5]])
        order = np.argsort([e[0] for e in ends], kind="stable")
        ends = [ends[i] for i in order]
        full = np.array([full[i] for i in order], dtype=np.int64)
        for (a0, a1, ta), (b0, b1, tb) in zip(ends[:-1], ends[1:]):
            if abs(a1 - b0) > 1e-9 * max(1.0, abs(a1)):
                raise ModelError(f"track: elements {ta} and {tb} leave a gap or overlap between x = {a1:g} and {b0:g}")
        self.elements = [e[2] for e in ends]
        self.x_start = np.array([e[0] for e in ends])
        self.length = np.array([e[1] - e[0] for e in ends])
        free = asm.free_of_full[full]
        unique = np.unique(free[free >= 0])
        self.free_index = unique.astype(np.int64)
        lookup = -np.ones(asm.n_free, dtype=np.int64)
        lookup[unique] = np.arange(len(unique))
        self.dofs = np.where(free >= 0, lookup[np.maximum(free, 0)], -1).astype(np.int64)
        self.x_begin = float(self.x_start[0])
        self.x_end = float(self.x_start[-1] + self.length[-1])

    @property
    def n_track(self):
        return len(self.free_index)

    def rows(self, x, taps=None, weights=None):
        """Constraint rows of wheels at ``x (n_w,)``: ``(cols, vals)`` each ``(n_w, width)``
        (cols -1 where unused); see :func:`constraint_rows` for ``taps``/``weights``."""
        x = np.asarray(x, dtype=float)
        taps = np.zeros(1) if taps is None else np.asarray(taps, dtype=float)
        weights = np.ones(1) if weights is None else np.asarray(weights, dtype=float)
        width = row_width(self.length.min(), float(np.ptp(taps)))
        cols = np.empty((len(x), width), dtype=np.int64)
        vals = np.empty((len(x), width))
        constraint_rows(x, taps, weights, self.x_start, self.length, self.dofs, cols, vals)
        return cols, vals


def row_width(min_length, tap_span):
    """Fixed number of entries a row needs when its taps span ``tap_span`` metres."""
    spanned = int(np.ceil(tap_span / min_length)) + 1
    return 2 * (spanned + 1)


@njit(cache=True)
def hermite(xi, length):
    """Values of [H1, ℓ H2, H3, ℓ H4] at ξ (see the module docstring)."""
    x2 = xi * xi
    x3 = x2 * xi
    return (1.0 - 3.0 * x2 + 2.0 * x3, length * (xi - 2.0 * x2 + x3), 3.0 * x2 - 2.0 * x3, length * (x3 - x2))


@njit(cache=True)
def host_element(x, x_start, length):
    """Element under ``x`` (a node belongs to the element that starts there; the chain's last
    node to the last element), or -1 off the chain."""
    n = x_start.shape[0]
    if x < x_start[0] or x > x_start[n - 1] + length[n - 1]:
        return -1
    e = np.searchsorted(x_start, x, side="right") - 1
    return min(max(e, 0), n - 1)


@njit(cache=True)
def constraint_rows(x, taps, weights, x_start, length, dofs, cols, vals):
    """Row of each wheel: ``Σ_k weights[k] N(x + taps[k])``, merged by dof.

    ``taps`` [m] and ``weights`` describe a smoothing of the constraint (one tap of weight 1 for
    the plain Hermite row). ``cols``/``vals`` ``(n_w, width)`` are overwritten; unused slots get
    col -1 and value 0.
    """
    n_w, width = cols.shape
    for i in range(n_w):
        used = 0
        for j in range(width):
            cols[i, j] = -1
            vals[i, j] = 0.0
        for k in range(taps.shape[0]):
            xk = x[i] + taps[k]
            e = host_element(xk, x_start, length)
            if e < 0:
                continue
            xi = (xk - x_start[e]) / length[e]
            h = hermite(xi, length[e])
            for a in range(4):
                d = dofs[e, a]
                if d < 0:
                    continue
                value = weights[k] * h[a]
                slot = -1
                for j in range(used):
                    if cols[i, j] == d:
                        slot = j
                        break
                if slot < 0:
                    slot = used
                    used += 1
                    cols[i, slot] = d
                vals[i, slot] += value
