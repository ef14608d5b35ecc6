"""Static responses of a bridge to loads on its track: influence lines, the static envelope of a
train of axle loads, and of Load Model 71 (EN 1991-2 §6.3.2).

By Maxwell's reciprocity the static response at dof d to a unit downward force at x on the track
is IL_d(x) = −N(x) · w_d with w_d = K⁻¹ e_d (one solve per response dof) and N(x) the Hermite row
of the track element under x (:class:`~vtsi.track.Track`): exact for any x, no sampling of the
load position. A train at head position h loads the track with its static axle loads P_i at
x_i(h), so its static response is r_d(h) = Σ_i P_i IL_d(x_i(h)); its envelope is scanned over h at
a spacing of 1/20 of the shortest track element (the response is C¹ and piecewise cubic in h,
so the scan's error is below 1e-4 of the peak) and refined by a parabola through the best three
samples.

Units: forces N (downward positive), lengths m, responses in the dof's units (m, rad). Signs:
the responses are vtsi's (uy positive up), so a downward deflection is negative.
"""
import numpy as np
import scipy.sparse.linalg as spla

from vtsi.errors import ModelError, as_number
from vtsi.track import Track

LM71_AXLE = 250e3        # [N], EN 1991-2 §6.3.2(3), Figure 6.1
LM71_SPACING = 1.6       # [m] between the four axles
LM71_UDL = 80e3          # [N/m] on either side, from 0.8 m beyond the outer axles
SCAN_PER_ELEMENT = 20


class InfluenceLines:
    """Influence lines of chosen responses of a bridge model along its track.

    Parameters
    ----------
    model : vtsi.Model (linear; its stiffness K is used).
    track : vtsi.track.Track.
    dofs : list of (node tag, dof) with dof 1-based (2 uy, 3 rz): the responses; or
    functionals : (free dofs (n,), P (n, n_responses)): responses u[free] @ P (e.g. bending
        moments, :func:`vtsi.recorders.moment.moment_rows`).
    """

    def __init__(self, model, track, dofs=None, functionals=None):
        if not isinstance(track, Track):
            raise ModelError(f"influence lines: track must be a vtsi.track.Track, got {track!r}")
        if (dofs is None) == (functionals is None):
            raise ModelError("influence lines: give the responses as dofs=[(node, dof), ...] or as functionals, "
                             "one of the two")
        asm = model.build()
        self.track = track
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
        self._w_track = w[track.free_index]           # (n_track, n_responses): w_d on the track dofs
        lengths = track.length
        self.step = float(lengths.min()) / SCAN_PER_ELEMENT

    def __call__(self, x):
        """IL (len(x), n_responses) [response units per N] at positions x [m] (0 off the track)."""
        x = _finite_array("positions x [m]", x)
        cols, vals, _ = self.track.rows(x)
        w = np.where((cols >= 0)[..., None], self._w_track[np.maximum(cols, 0)], 0.0)   # (n_x, width, n_resp)
        return -np.einsum("ij,ijk->ik", vals, w)

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
        response = np.zeros((heads.size, self.n_responses))
        for block in range(0, heads.size, 2048):
            h = heads[block: block + 2048]
            x = h[:, None] - offsets[None, :]
            il = self(x.ravel()).reshape(x.shape + (self.n_responses,))
            response[block: block + 2048] = np.einsum("j,ijk->ik", loads, il)
        return np.stack([_refined(response, heads, np.argmin), _refined(response, heads, np.argmax)])

    def lm71_envelope(self, alpha=1.0):
        """Static min and max (2, n_responses) of Load Model 71 × ``alpha`` (the classification
        factor α of EN 1991-2 §6.3.2(3)): four 250 kN axles 1.6 m apart and 80 kN/m from 0.8 m
        beyond the outer axles on both sides, the distributed load only where it adds to the
        extreme sought (its influence of that sign), over every position of the axles.
        ``alpha`` > 0 and finite."""
        alpha = as_number(alpha, "influence lines", "LM71 alpha")
        if not (np.isfinite(alpha) and alpha > 0.0):
            raise ModelError(f"influence lines: LM71 alpha must be > 0 and finite, got {alpha}")
        x = np.arange(self.track.x_begin, self.track.x_end + self.step / 2, self.step)
        il = self(x)                                                # (n_x, n_resp)
        out = np.zeros((2, self.n_responses))
        centres = np.arange(self.track.x_begin - 2.4, self.track.x_end + 2.4 + self.step, self.step)
        axles = centres[:, None] + LM71_SPACING * np.array([-1.5, -0.5, 0.5, 1.5])[None, :]
        point = LM71_AXLE * self(axles.ravel()).reshape(axles.shape + (self.n_responses,)).sum(axis=1)
        for k, sign in enumerate((-1.0, 1.0)):
            part = np.where(sign * il > 0.0, il, 0.0)               # the favourable-to-the-extreme part
            cumulative = np.concatenate([np.zeros((1, self.n_responses)),
                                         np.cumsum(0.5 * (part[1:] + part[:-1]) * np.diff(x)[:, None], axis=0)])
            total = cumulative[-1]
            reach = 1.5 * LM71_SPACING + 0.8                        # from the centre to the load's start [m]
            left = _cumulative_at(x, cumulative, centres - reach)
            right = total[None, :] - _cumulative_at(x, cumulative, centres + reach)
            response = point + LM71_UDL * (left + right)
            out[k] = response.min(axis=0) if sign < 0 else response.max(axis=0)
        return alpha * out


def _finite_array(what, values):
    """``values`` as a float array (at least 1-D), or a ModelError naming ``what`` and the values."""
    try:
        values = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"influence lines: {what} must be numbers, got {values!r}") from None
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


def _cumulative_at(x, cumulative, points):
    """The running integral ``cumulative`` (n_x, n_resp) over ``x`` interpolated at ``points``."""
    return np.stack([np.interp(points, x, cumulative[:, j]) for j in range(cumulative.shape[1])], axis=1)


def _refined(response, heads, pick):
    """The extreme of each column of a scan, refined by a parabola through its best three samples."""
    out = np.empty(response.shape[1])
    for j in range(response.shape[1]):
        i = int(pick(response[:, j]))
        out[j] = response[i, j]
        if 0 < i < len(heads) - 1:
            y0, y1, y2 = response[i - 1, j], response[i, j], response[i + 1, j]
            den = y0 - 2 * y1 + y2
            if den != 0.0:
                out[j] = y1 - 0.125 * (y2 - y0) ** 2 / den
    return out
