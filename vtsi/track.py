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

from vtsi.errors import BridgeModelError

LEVEL_TOLERANCE = 1e-9
"""How far the two ends of a track element may lie from one level: this share of the model's
size along the track [m] (the track's length, or its nodes' largest |x| or |y|, whichever is
larger: 0.1 µm on a 100 m track). Coordinates carry round-off of ~1e-16 of their size each time
they are computed (a model generated, moved or scaled by a script): far below it; a real
gradient's rise over an element, a few per mille of its length, is far above it. A gradient g
changes the vertical dynamics by about g² (a 30 m simply supported deck's n₀ falls by 1.0e-6 of
itself at g = 0.1 %, 6.3e-4 at 2.5 %), which a level model leaves out."""
MAX_GRADIENT = 0.1
"""A track element steeper than this (10 %, more than any railway's gradient) is refused without
the gradient's hint: it is no part of the deck's line (a pier's element)."""


class Track:
    """Wheels run along ``elements`` (tags of 2-node beam elements with uy and rz dofs, each
    listed once, in any order: they are sorted along +x, and an element whose nodes run in -x is
    read from its left end), which must form a straight horizontal chain (each element level
    within LEVEL_TOLERANCE of the model's size) without gaps or overlaps: otherwise a
    :class:`~vtsi.errors.BridgeModelError` (a ModelError) naming the element.

    Attributes
    ----------
    elements : list of int, the tags sorted along +x.
    x_start, length : (n_el,) element start coordinate and length [m].
    dofs : (n_el, 4) int64 track dof of [uy1, rz1, uy2, rz2] (-1 where fixed).
    free_index : (n_track,) int64 bridge free dof of each track dof.
    x_begin, x_end : extent of the chain [m].
    """

    def __init__(self, model, elements):
        asm = model.build()
        if asm.transformation is not None:
            raise BridgeModelError("track: the model has equalDOF/rigidLink constraints, which the train analyses do "
                                   "not take; model the connections with elements (zeroLength, stiff beams)")
        bad = [e for e in elements if isinstance(e, (bool, np.bool_)) or not isinstance(e, (int, np.integer))]
        if bad:
            raise BridgeModelError(f"track: element tags must be integers, got {bad[0]!r}")
        elements = [int(e) for e in elements]
        if not elements:
            raise BridgeModelError("track: no elements given")
        if len(set(elements)) != len(elements):
            twice = next(e for e in elements if elements.count(e) > 1)
            raise BridgeModelError(f"track: element {twice} is listed twice")
        ends, full, rises = [], [], []
        for tag in elements:
            if tag not in asm.element_location:
                raise BridgeModelError(f"track: element {tag} does not exist")
            b, i = asm.element_location[tag]
            etype = asm.blocks[b][0]
            if etype.n_nodes != 2 or tuple(etype.node_dofs) != (0, 1, 2):
                raise BridgeModelError(f"track: element {tag} ({etype.name}) is not a 2-node beam with ux, uy, rz "
                                       "dofs")
            coords = asm.blocks[b][2][i]
            dofs = asm.blocks[b][4][i]
            if coords[1, 0] < coords[0, 0]:
                coords, dofs = coords[::-1], dofs[[3, 4, 5, 0, 1, 2]]
            ends.append((coords[0, 0], coords[1, 0], tag))
            rises.append((coords[0, 1], coords[1, 1]))
            full.append(dofs[[1, 2, 4, 5]])
        x, y = np.array([e[:2] for e in ends]), np.array(rises)
        size = max(float(np.ptp(x)), float(np.max(np.abs(x))), float(np.max(np.abs(y))), 1.0)     # [m]
        for (x0, x1, tag), (y0, y1) in zip(ends, rises):
            if abs(y1 - y0) <= LEVEL_TOLERANCE * size:
                continue
            g = abs(y1 - y0) / (x1 - x0) if x1 > x0 else np.inf
            if g > MAX_GRADIENT:           # no railway gradient: an element off the deck's line (a pier's)
                raise BridgeModelError(f"track: element {tag} is not horizontal (y from {y0:g} to {y1:g})")
            where = f"y from {y0:g} to {y1:g} m over x = {x0:g} to {x1:g} m"
            raise BridgeModelError(f"track: element {tag} is not horizontal ({where}, a gradient of {100 * g:.3g} %); "
                                   "vtsi's track is level: give its nodes one level y (a gradient g changes the "
                                   f"vertical dynamics by about g², here {g * g:.1e}: a 30 m deck's n0 falls by "
                                   "1.0e-06 of itself at 0.1 %)")
        order = np.argsort([e[0] for e in ends], kind="stable")
        ends = [ends[i] for i in order]
        full = np.array([full[i] for i in order], dtype=np.int64)
        for (a0, a1, ta), (b0, b1, tb) in zip(ends[:-1], ends[1:]):
            if abs(a1 - b0) > 1e-9 * max(1.0, abs(a1)):
                raise BridgeModelError(f"track: elements {ta} and {tb} leave a gap or overlap between x = {a1:g} "
                                       f"and {b0:g}")
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

    def __repr__(self):
        return (f"Track({len(self.elements)} elements, x = {self.x_begin:g} to {self.x_end:g} m, "
                f"{self.n_track} track dofs)")

    @property
    def n_track(self):
        return len(self.free_index)

    def hermite_row(self, x):
        """``(dofs, values, slopes, curvatures)`` of the Hermite row at one position ``x`` [m]:
        the host element's 4 track dofs (-1 fixed) and N, dN/dx, d²N/dx² there; None off the chain."""
        e = host_element(float(x), self.x_start, self.length)
        if e < 0:
            return None
        xi, length = (x - self.x_start[e]) / self.length[e], self.length[e]
        return (self.dofs[e], np.array(hermite(xi, length)), np.array(hermite_slope(xi, length)),
                np.array(hermite_curvature(xi, length)))

    def rows(self, x, knot=0.0):
        """Constraint rows of wheels at ``x (n_w,)``: ``(cols, vals, slopes)`` each
        ``(n_w, width)`` (cols -1 where unused; ``slopes`` = dN/dx [1/m]); ``knot`` > 0 smooths
        them (see :func:`constraint_rows`)."""
        x = np.asarray(x, dtype=float)
        width = row_width(self.length.min(), knot)
        cols = np.empty((len(x), width), dtype=np.int64)
        vals = np.empty((len(x), width))
        slopes = np.empty((len(x), width))
        constraint_rows(x, float(knot), self.x_start, self.length, self.dofs, cols, vals, slopes)
        return cols, vals, slopes


def row_width(min_length, knot):
    """Fixed number of entries of a row smoothed over ``4 knot`` metres."""
    spanned = int(np.ceil(4.0 * knot / min_length)) + 1
    return 2 * (spanned + 1)


GAUSS_POINTS = np.array([-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526])
GAUSS_WEIGHTS = np.array([0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538])


@njit(cache=True, inline='always')
def bspline_kernel(s):
    """Centred cubic B-spline B₃(s) (support [-2, 2], integral 1)."""
    a = abs(s)
    if a < 1.0:
        return 2.0 / 3.0 - a * a + 0.5 * a * a * a
    if a < 2.0:
        return (2.0 - a) ** 3 / 6.0
    return 0.0


@njit(cache=True, inline='always')
def hermite(xi, length):
    """Values of [H1, ℓ H2, H3, ℓ H4] at ξ (see the module docstring)."""
    x2 = xi * xi
    x3 = x2 * xi
    return (1.0 - 3.0 * x2 + 2.0 * x3, length * (xi - 2.0 * x2 + x3), 3.0 * x2 - 2.0 * x3, length * (x3 - x2))


@njit(cache=True, inline='always')
def hermite_slope(xi, length):
    """d/dx of [H1, ℓ H2, H3, ℓ H4] at ξ [1/m, 1, 1/m, 1]."""
    x2 = xi * xi
    return ((6.0 * x2 - 6.0 * xi) / length, 1.0 - 4.0 * xi + 3.0 * x2, (6.0 * xi - 6.0 * x2) / length, 3.0 * x2 - 2.0 * xi)


@njit(cache=True)
def hermite_curvature(xi, length):
    """d²/dx² of [H1, ℓ H2, H3, ℓ H4] at ξ [1/m², 1/m, 1/m², 1/m]."""
    return ((12.0 * xi - 6.0) / length ** 2, (6.0 * xi - 4.0) / length, (6.0 - 12.0 * xi) / length ** 2,
            (6.0 * xi - 2.0) / length)


@njit(cache=True, inline='always')
def host_element(x, x_start, length):
    """Element under ``x`` (a node belongs to the element that starts there; the chain's last
    node to the last element), or -1 off the chain."""
    n = x_start.shape[0]
    if x < x_start[0] or x > x_start[n - 1] + length[n - 1]:
        return -1
    e = np.searchsorted(x_start, x, side="right") - 1
    return min(max(e, 0), n - 1)


@njit(cache=True, inline='always')
def _add_entry(cols, vals, slopes, i, used, d, value, slope):
    for j in range(used):
        if cols[i, j] == d:
            vals[i, j] += value
            slopes[i, j] += slope
            return used
    cols[i, used] = d
    vals[i, used] = value
    slopes[i, used] = slope
    return used + 1


@njit(cache=True)
def constraint_rows(x, knot, x_start, length, dofs, cols, vals, slopes):
    """Row of each wheel at ``x`` and its slope dN/dx: the Hermite row ``N(x)`` if
    ``knot == 0``, else its convolution with the cubic B-spline kernel of knot spacing ``knot`` [m],

        Ñ(x) = ∫ N(x - ξ) B₃(ξ / knot) / knot dξ,

    computed exactly: on every piece where both the kernel and N are one polynomial (kernel
    knots and element ends split the support), 4-point Gauss-Legendre integrates the degree-6
    product without error (the slope alike, degree 5). ``cols``/``vals``/``slopes``
    ``(n_w, width)`` are overwritten (col -1 unused).
    """
    n_w, width = cols.shape
    n_el = x_start.shape[0]
    x_end = x_start[n_el - 1] + length[n_el - 1]
    for i in range(n_w):
        for j in range(width):
            cols[i, j] = -1
            vals[i, j] = 0.0
            slopes[i, j] = 0.0
        used = 0
        if knot == 0.0:
            e = host_element(x[i], x_start, length)
            if e >= 0:
                xi = (x[i] - x_start[e]) / length[e]
                h = hermite(xi, length[e])
                dh = hermite_slope(xi, length[e])
                for a in range(4):
                    if dofs[e, a] >= 0:
                        used = _add_entry(cols, vals, slopes, i, used, dofs[e, a], h[a], dh[a])
            continue
        for k in range(4):
            # kernel piece ξ in [(k-2) knot, (k-1) knot]  <->  x' = x - ξ in [lo, hi]
            lo = max(x[i] - (k - 1) * knot, x_start[0])
            hi = min(x[i] - (k - 2) * knot, x_end)
            if hi <= lo:
                continue
            e = host_element(lo, x_start, length)
            while e < n_el and x_start[e] < hi:
                p = max(lo, x_start[e])
                q = min(hi, x_start[e] + length[e])
                if q > p:
                    half = 0.5 * (q - p)
                    for g in range(4):
                        xg = p + half * (1.0 + GAUSS_POINTS[g])
                        w = half * GAUSS_WEIGHTS[g] * bspline_kernel((x[i] - xg) / knot) / knot
                        xi = (xg - x_start[e]) / length[e]
                        h = hermite(xi, length[e])
                        dh = hermite_slope(xi, length[e])
                        for a in range(4):
                            if dofs[e, a] >= 0:
                                used = _add_entry(cols, vals, slopes, i, used, dofs[e, a], w * h[a], w * dh[a])
                e += 1
