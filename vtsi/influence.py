"""Static responses of a bridge to loads on its track: influence lines, the static envelope of a
train of axle loads, of Load Model 71 (EN 1991-2 §6.3.2) and of Load Model SW/0 (§6.3.3).

By Maxwell's reciprocity the static response at dof d to a unit downward force at x on the track
is IL_d(x) = −N(x) · w_d with w_d = K⁻¹ e_d (one solve per response dof) and N(x) the Hermite row
of the track element under x (:class:`~vtsi.track.Track`): exact for any x, no sampling of the
load position. A bending moment at a node adds the fixed-end share of the load when it stands
in an element next to the node (:class:`~vtsi.recorders.moment.FixedEndMoments`), which makes its
influence line exact too (on a simply supported span the triangle x(L − a)/L, a the node's x,
at every x); that line kinks where the load crosses the node.

A train at head position h loads the track with its static axle loads P_i at x_i(h), so its
static response is r_d(h) = Σ_i P_i IL_d(x_i(h)); its envelope is scanned over h at a spacing of
1/20 of the shortest track element and refined by a parabola through the best three samples (the
response is C¹ and piecewise cubic in h between the kinks, so the scan's error is below 1e-4 of
the peak), and evaluated at every head position that puts an axle on a kink (a bending moment's
node), where a sagging maximum often is, or on a track end, beyond which the line drops to 0 (an
overhang's tip: a scan's axle 1e-14 m off the end lost its load; positions within round-off of
an end are put on it). LM71's scan adds the positions that put one of its four axles on a kink or
a track end alike, and integrates its distributed load by Simpson's rule on a grid through the
element ends (exact on the cubic pieces of a line; LM71's mid-span moment on a 20 m span:
6075.2 kN·m within 1e-11 on 8 to 40 elements). SW/0's two loaded lengths are one rigid pattern
(the same either way along the track: it is symmetric); its response r(s) = q [F(s + a) − F(s) +
F(s + 2a + c) − F(s + a + c)] at the pattern's start s, F the primitive of the influence line
(Simpson's rule on the same grid, exact: the whole line is loaded, nothing clipped), is C¹ in s,
so its extreme, bracketed by the scan (which also puts each load end on each kink and on the
track's ends), is where r'(s) = q Σ ± IL(s + end) vanishes, found by Brent's method: exact to
rounding (the mid-span moment of a 20 m span 6234.375 kN·m, 133 kN/m × (L²/8 − 2 × 2.5²/4)).

Units: forces N (downward positive), lengths m, responses in the dof's units (m, rad, N·m).
Signs: the responses are vtsi's (uy positive up), so a downward deflection is negative; a bending
moment is sagging positive.
"""
from typing import NamedTuple

import numpy as np
import scipy.sparse.linalg as spla
from numba import njit
from scipy.optimize import brentq

from vtsi.errors import ModelError, as_number, as_numbers, is_int
from vtsi.recorders.moment import fixed_end_moments, moment_rows
from vtsi.track import Track, hermite, host_element

LM71_AXLE = 250e3        # [N], EN 1991-2 §6.3.2(3), Figure 6.1
LM71_SPACING = 1.6       # [m] between the four axles
LM71_UDL = 80e3          # [N/m] on either side, from 0.8 m beyond the outer axles
SW0_LOAD = 133e3         # [N/m] q_vk of Load Model SW/0, EN 1991-2 §6.3.3, Table 6.1
SW0_LENGTH = 15.0        # [m] a: each of its two loaded lengths
SW0_GAP = 5.3            # [m] c: between them
SCAN_PER_ELEMENT = 20
BLOCK_BYTES = 4 * 2 ** 20
"""[B] The temporaries of one block of a scan of LM71's and SW/0's distributed loads (the line's
primitive at a block of positions): a scan takes its positions that many bytes at a time, so that
it holds at most about 2 × BLOCK_BYTES beyond its (positions, n_responses) arrays, whatever the
number of responses. The axle loads (:meth:`InfluenceLines.train_envelope`, LM71's axles) and
the lines themselves are summed in place by a compiled kernel, with no temporaries per position."""
PRIMITIVE_ARRAYS = 8
"""(n_responses,) float64 arrays that evaluating a line's primitive (``InfluenceLines._primitive``)
holds per position at its peak (measured: 8.2 when the lines gathered their four-entry rows per
position, which they no longer do: a bound now): what sizes the blocks of LM71's and SW/0's scans."""


class StaticEnvelopes(NamedTuple):
    """An output's static min and max (rows 0 and 1) at its columns, in its units, α = 1:
    ``trains`` (n_train, 2, n_columns) under each train's static axle loads, ``lm71`` and ``sw0``
    (2, n_columns) under Load Models 71 and SW/0 (:class:`InfluenceLines`); ``sw0`` None: read
    from a results file of an older vtsi, which kept none."""

    trains: np.ndarray
    lm71: np.ndarray
    sw0: np.ndarray = None


class InfluenceLines:
    """Influence lines of chosen responses of a bridge model along its track.

    Parameters
    ----------
    model : vtsi.Model (linear; its stiffness K is used).
    track : vtsi.track.Track.
    dofs : list of (node tag, dof) with dof 1-based (2 uy, 3 rz): the responses; or
    functionals : (free dofs (n,), P (n, n_responses)): responses u[free] @ P, linear in the
        nodal dofs only; or
    moments : node tags of the track: the bending moments there [N·m, sagging positive]
        (:mod:`vtsi.recorders.moment`: the end moments u[free] @ P of
        :func:`~vtsi.recorders.moment.moment_rows` and the fixed-end share of a load standing in
        an element next to the node).
    """

    def __init__(self, model, track, dofs=None, functionals=None, moments=None):
        if not isinstance(track, Track):
            raise ModelError(f"influence lines: track must be a vtsi.track.Track, got {track!r}")
        if sum(given is not None for given in (dofs, functionals, moments)) != 1:
            raise ModelError("influence lines: give the responses as dofs=[(node, dof), ...], as functionals or as "
                             "moments=[node, ...], one of the three")
        asm = model.build()
        self.track = track
        self._fixed = None                     # the moments' fixed-end share (FixedEndMoments)
        if moments is not None:
            items = list(moments) if np.iterable(moments) and not isinstance(moments, (str, bytes)) else []
            nodes = [int(n) for n in items] if all(is_int(n) for n in items) else []
            if not nodes:
                raise ModelError(f"influence lines: moments must be a non-empty list of node tags, got {moments!r}")
            functionals = moment_rows(asm, track, nodes)
            self._fixed = fixed_end_moments(asm, track, nodes)
        if functionals is not None:            # responses r = u[free] @ P: (free dofs, P)
            free, P = _functionals(functionals, asm.n_free)
            rhs = np.zeros((asm.n_free, P.shape[1]))
            rhs[free] = P
        else:
            try:
                pairs = [tuple(pair) for pair in dofs]
            except TypeError:
                pairs = None
            if not pairs or any(len(pair) != 2 for pair in pairs):
                raise ModelError(f"influence lines: dofs must be a non-empty list of (node, dof) pairs, got {dofs!r}")
            try:
                full = [asm.full_dof(n, d) for n, d in pairs]
            except ModelError as exc:
                raise ModelError(f"influence lines: {exc}") from None
            free = asm.free_of_full[full]
            rhs = np.zeros((asm.n_free, len(full)))
            rhs[free[free >= 0], np.flatnonzero(free >= 0)] = 1.0
        self.n_responses = rhs.shape[1]
        try:
            w = spla.splu(asm.K.tocsc()).solve(rhs)
        except RuntimeError:
            raise ModelError("influence lines: the bridge's stiffness matrix is singular (a mechanism)") from None
        self._element_lines = _element_lines(track, w[track.free_index], self._fixed)
        self.step = float(track.length.min()) / SCAN_PER_ELEMENT

    def __call__(self, x):
        """IL (len(x), n_responses) [response units per N] at positions x [m] (0 off the track)."""
        x = _finite_array("positions x [m]", x)
        return self._axle_response(x.ravel(), np.zeros(1), np.ones(1), 0.0)

    def kinks(self):
        """Where each response's influence line kinks [m], ``(n_kinks, n_responses)``: a bending
        moment's at its node (``(1, n_responses)``); the other responses' lines are C¹ (``(0,
        n_responses)``)."""
        if self._fixed is None:
            return np.zeros((0, self.n_responses))
        return self._fixed.node_x[None, :]

    def train_envelope(self, offsets, loads):
        """Static min and max (2, n_responses) of axles with ``offsets`` [m] behind the head and
        downward ``loads`` [N], over every head position from the first axle on the track's
        start to the last axle off its end."""
        offsets, loads = _finite_array("axle offsets [m]", offsets), _finite_array("axle loads [N]", loads)
        if offsets.ndim != 1 or offsets.size == 0 or loads.shape != offsets.shape:
            raise ModelError(f"influence lines: give one load per axle offset (at least one axle), got "
                             f"{offsets.size} offsets and {loads.size} loads")
        lo, hi = self.track.x_begin + offsets.min(), self.track.x_end + offsets.max()
        heads = np.arange(lo, hi + self.step, self.step)
        response = self._train_response(heads, offsets, loads)
        # the head positions that put an axle on a kink of a response or on a track end (each axle on
        # each): where the line kinks, or where it drops to 0 beyond an end that moves (an overhang's tip)
        kinks = np.concatenate([self.kinks(), np.repeat(self._ends()[:, None], self.n_responses, axis=1)])
        kink_heads = kinks[:, None, :] + offsets[None, :, None]         # (n_kinks + 2, n_axles, n_resp)
        on = np.unique(kink_heads[np.isfinite(kink_heads)])
        at_kinks = self._train_response(on, offsets, loads) if on.size else np.zeros((0, self.n_responses))
        out = np.stack([_refined(response, heads, np.argmin, kink_heads), _refined(response, heads, np.argmax, kink_heads)])
        if on.size:
            out[0] = np.minimum(out[0], at_kinks.min(axis=0))
            out[1] = np.maximum(out[1], at_kinks.max(axis=0))
        return out

    def _train_response(self, heads, offsets, loads):
        """The static response ``(len(heads), n_responses)`` of the axles with the head at ``heads``,
        an axle within round-off (1e-6 of :attr:`step`) of a track end put on it: a scan places a
        load on an end as a sum (head − offset), which may fall 1e-14 m off the track, where the
        line is 0 (an overhang's tip then lost LM71's axle on it: 0.823 mm for 0.841)."""
        return self._axle_response(heads, offsets, loads, 1e-6 * self.step)

    def _axle_response(self, heads, offsets, loads, snap):
        """Σ_i loads_i IL(heads − offsets_i), ``(len(heads), n_responses)``, positions within
        ``snap`` [m] of a track end put on it (:func:`_add_axle_loads`)."""
        order = np.argsort(offsets, kind="stable")
        out = np.zeros((heads.size, self.n_responses))
        _add_axle_loads(np.ascontiguousarray(heads, dtype=np.float64),
                        np.ascontiguousarray(offsets[order], dtype=np.float64),
                        np.ascontiguousarray(loads[order], dtype=np.float64), float(snap), self.track.x_start,
                        self.track.length, self._element_lines, out)
        return out

    def lm71_envelope(self, alpha=1.0):
        """Static min and max (2, n_responses) of Load Model 71 × ``alpha`` (the classification
        factor α of EN 1991-2 §6.3.2(3)): four 250 kN axles 1.6 m apart and 80 kN/m from 0.8 m
        beyond the outer axles on both sides, the distributed load only where it adds to the
        extreme sought (its influence of that sign), over every position of the axles.
        ``alpha`` > 0 and finite."""
        alpha = _classification_factor(alpha, "LM71")
        track = self.track
        axle_offsets = LM71_SPACING * np.array([-1.5, -0.5, 0.5, 1.5])
        centres = np.arange(track.x_begin - 2.4, track.x_end + 2.4 + self.step, self.step)
        kinks = self.kinks()                    # and the centres that put an axle on a kink or a track end
        where = np.concatenate([kinks[np.isfinite(kinks)], self._ends()])
        centres = np.union1d(centres, (where[:, None] - axle_offsets[None, :]).ravel())
        point = self._train_response(centres, -axle_offsets, np.full(axle_offsets.size, LM71_AXLE))
        reach = 1.5 * LM71_SPACING + 0.8                            # from the centre to the load's start [m]

        def extreme(sign, pick):
            # the distributed load on the favourable-to-the-extreme part of the line only (one
            # sign's primitive at a time: it holds two arrays the size of the scan)
            primitive = self._primitive(lambda values: np.where(sign * values > 0.0, values, 0.0))
            end = primitive(np.array([track.x_end]))
            extremes = []
            for part in _blocks(centres.size, 2 * 8 * PRIMITIVE_ARRAYS * self.n_responses):
                left, right = primitive(centres[part] - reach), end - primitive(centres[part] + reach)
                extremes.append(pick(point[part] + LM71_UDL * (left + right), axis=0))
            return pick(extremes, axis=0)
        out = np.stack([extreme(-1.0, np.min), extreme(1.0, np.max)])
        return alpha * out

    def sw0_envelope(self, alpha=1.0):
        """Static min and max (2, n_responses) of Load Model SW/0 × ``alpha`` (EN 1991-2 §6.3.3,
        α as LM71's, §6.3.2(3)): 133 kN/m on two lengths of 15 m, 5.3 m apart
        (Table 6.1), one rigid pattern over every position along the track (parts of it beyond
        the track's ends carry nothing), the whole pattern loaded. ``alpha`` > 0 and finite."""
        alpha = _classification_factor(alpha, "SW/0")
        track = self.track
        ends = np.array([0.0, SW0_LENGTH, SW0_LENGTH + SW0_GAP, 2 * SW0_LENGTH + SW0_GAP])   # behind the start s
        signs = np.array([-1.0, 1.0, -1.0, 1.0])            # r(s) = q Σ sign F(s + end)
        starts = np.arange(track.x_begin - ends[-1], track.x_end + self.step, self.step)
        kinks = self.kinks()
        where = np.concatenate([kinks[np.isfinite(kinks)], self._ends()])
        starts = np.union1d(starts, (where[:, None] - ends[None, :]).ravel())
        primitive = self._primitive()

        def response(s):                                    # (len(s), n_responses)
            at = primitive((np.asarray(s, dtype=float)[:, None] + ends[None, :]).ravel())
            return SW0_LOAD * np.einsum("j,ijk->ik", signs, at.reshape(-1, len(ends), self.n_responses))

        def slope(s, column):                               # r'(s) of one response
            return SW0_LOAD * float(signs @ self(s + ends)[:, column])

        scanned = np.empty((starts.size, self.n_responses))
        for part in _blocks(starts.size, len(ends) * 8 * PRIMITIVE_ARRAYS * self.n_responses):
            scanned[part] = response(starts[part])
        out = np.zeros((2, self.n_responses))
        for k, pick in enumerate((np.argmin, np.argmax)):
            for j in range(self.n_responses):
                i = int(pick(scanned[:, j]))
                out[k, j] = scanned[i, j]
                if 0 < i < len(starts) - 1:                 # the stationary point r'(s) = 0 the scan brackets
                    a, b = starts[i - 1], starts[i + 1]
                    if slope(a, j) * slope(b, j) < 0.0:
                        s = brentq(slope, a, b, args=(j,), xtol=1e-12, rtol=4 * np.finfo(float).eps)
                        value = response(np.array([s]))[0, j]
                        out[k, j] = min(out[k, j], value) if k == 0 else max(out[k, j], value)
        return alpha * out

    def _ends(self):
        """The track's ends [m], ``(2,)``."""
        return np.array([self.track.x_begin, self.track.x_end])

    def _primitive(self, part=None):
        """F(x) = ∫ part(IL) from the track's start to each of ``x`` (n,) [response units per N/m],
        ``(n, n_responses)``, as a function of x (clipped to the track): Simpson's rule on a
        grid through the element ends at most :attr:`step` apart, exact for the cubic pieces of
        an influence line (``part`` None: the line itself), and for a ``part`` of it (an
        elementwise function of its values, e.g. its part of one sign) up to where that clips it.
        Built and evaluated :data:`BLOCK_BYTES` at a time: an evaluation holds
        :data:`PRIMITIVE_ARRAYS` (n_responses,) arrays per position."""
        part = part or (lambda values: values)
        track = self.track
        pieces = np.maximum(np.ceil(track.length / self.step - 1e-9), 1).astype(int)
        x = np.append(np.concatenate([x0 + ell * np.arange(m) / m for x0, ell, m in
                                      zip(track.x_start, track.length, pieces)]), track.x_end)
        il, cumulative = np.empty((x.size, self.n_responses)), np.zeros((x.size, self.n_responses))
        for block in _blocks(x.size, 8 * PRIMITIVE_ARRAYS * self.n_responses):
            il[block] = part(self(x[block]))
        for block in _blocks(x.size - 1, 8 * PRIMITIVE_ARRAYS * self.n_responses):     # the grid's intervals
            a, b = x[:-1][block], x[1:][block]
            simpson = (b - a)[:, None] / 6.0 * (il[:-1][block] + 4.0 * part(self(0.5 * (b + a))) + il[1:][block])
            simpson[0] += cumulative[block.start]        # the sum so far, added as one running sum would
            cumulative[block.start + 1: block.stop + 1] = np.cumsum(simpson, axis=0)

        def at(ends):
            ends = np.clip(ends, x[0], x[-1])
            below = np.clip(np.searchsorted(x, ends, side="right") - 1, 0, len(x) - 2)
            return cumulative[below] + (ends - x[below])[:, None] / 6.0 * (
                il[below] + 4.0 * part(self(0.5 * (x[below] + ends))) + part(self(ends)))
        return at


def _element_lines(track, w, fixed):
    """The lines element by element, ``(n_el, 4, n_responses)`` [response units per N]: a unit
    downward load at ξ in track element e gives Σ_a h_a(ξ) G[e, a] with h = [H₁, ℓH₂, H₃, ℓH₄]
    (:func:`vtsi.track.hermite`), G[e, a] = −w on e's track dof a (0 where fixed, ``w``
    (n_track, n_responses)) plus the fixed-end share of slot a (:class:`FixedEndMoments`
    ``fixed``, or None)."""
    table = np.zeros((len(track.length), 4, w.shape[1]))
    present = track.dofs >= 0
    table[present] = -w[track.dofs[present]]
    if fixed is not None:
        for e in range(len(track.length)):
            for k in range(fixed.ptr[e], fixed.ptr[e + 1]):
                table[e, fixed.slot[k], fixed.column[k]] += fixed.weight[k]
    return table


@njit(cache=True)
def _add_axle_loads(heads, offsets, loads, snap, x_start, length, element_lines, out):
    """Add to ``out (n_heads, n_responses)`` the response Σ_i loads_i IL(x_i) of downward axle
    loads [N] at x_i = heads_k − offsets_i [m] (``offsets`` increasing), an x_i within ``snap``
    [m] of a track end put on it: per head, the axles on the track only (found by binary search),
    each adding its load × its element's Hermite row · ``element_lines`` (:func:`_element_lines`)."""
    n_el = x_start.shape[0]
    x_begin, x_end = x_start[0], x_start[n_el - 1] + length[n_el - 1]
    reach = snap + 1e-9 * (abs(x_begin) + abs(x_end) + 1.0)         # beyond round-off of head − offset
    n_resp = out.shape[1]
    for k in range(heads.shape[0]):
        first = np.searchsorted(offsets, heads[k] - x_end - reach, side="left")
        last = np.searchsorted(offsets, heads[k] - x_begin + reach, side="right")
        for i in range(first, last):
            x = heads[k] - offsets[i]
            if abs(x - x_begin) <= snap:
                x = x_begin
            elif abs(x - x_end) <= snap:
                x = x_end
            e = host_element(x, x_start, length)
            if e < 0:
                continue
            h = hermite((x - x_start[e]) / length[e], length[e])
            for a in range(4):
                c = loads[i] * h[a]
                for r in range(n_resp):
                    out[k, r] += c * element_lines[e, a, r]


def _classification_factor(alpha, model):
    """``alpha`` as a float > 0, or a ModelError naming the load ``model`` and the value."""
    alpha = as_number(alpha, "influence lines", f"{model} alpha")
    if not (np.isfinite(alpha) and alpha > 0.0):
        raise ModelError(f"influence lines: {model} alpha must be > 0 and finite, got {alpha}")
    return alpha


def _blocks(n, bytes_each):
    """Slices of ``range(n)`` of at most :data:`BLOCK_BYTES` / ``bytes_each`` items (at least one):
    the blocks of a scan whose temporaries take ``bytes_each`` [B] per item."""
    size = max(1, BLOCK_BYTES // max(1, int(bytes_each)))
    return [slice(start, start + size) for start in range(0, n, size)]


def _finite_array(what, values):
    """``values`` as a float array (at least 1-D), or a ModelError naming ``what`` and the values
    (a text or a bool among them too: :func:`~vtsi.errors.as_numbers`)."""
    values = np.atleast_1d(as_numbers(values, "influence lines", what))
    if not np.all(np.isfinite(values)):
        raise ModelError(f"influence lines: {what} must be finite, got {values.tolist()}")
    return values


def _functionals(functionals, n_free):
    """``(free (n,) int64, P (n, n_responses) float64)`` of ``functionals``, checked: free dofs in
    0 .. n_free - 1, P finite with a row per free dof and at least one column."""
    try:
        free, P = functionals
        free, P = np.asarray(free), np.asarray(P, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"influence lines: functionals must be (free dofs (n,), P (n, n_responses)), got "
                         f"{functionals!r:.80}") from None
    if free.ndim != 1 or free.dtype.kind not in "iu" or P.ndim != 2 or P.shape[0] != free.size or P.shape[1] == 0:
        raise ModelError(f"influence lines: functionals must be (free dofs (n,) integers, P (n, n_responses)), got "
                         f"free {free.shape} {free.dtype}, P {P.shape}")
    if free.size and not (0 <= free.min() and free.max() < n_free):
        raise ModelError(f"influence lines: functionals: free dofs must be in 0..{n_free - 1}, got "
                         f"{int(free.min())}..{int(free.max())}")
    if not np.all(np.isfinite(P)):
        raise ModelError("influence lines: functionals: P has NaN or inf")
    return free.astype(np.int64), P


def _refined(response, heads, pick, kink_heads):
    """The extreme of each column of a scan, refined by a parabola through its best three samples
    unless a kink of the column (``kink_heads (n, n_axles, n_columns)``: head positions) lies
    between them."""
    out = np.empty(response.shape[1])
    for j in range(response.shape[1]):
        i = int(pick(response[:, j]))
        out[j] = response[i, j]
        if 0 < i < len(heads) - 1 and not np.any((kink_heads[..., j] >= heads[i - 1])
                                                  & (kink_heads[..., j] <= heads[i + 1])):
            y0, y1, y2 = response[i - 1, j], response[i, j], response[i + 1, j]
            den = y0 - 2 * y1 + y2
            if den != 0.0:
                out[j] = y1 - 0.125 * (y2 - y0) ** 2 / den
    return out
