"""Bending moments at the nodes of a track (the deck's beam elements along it).

The moment at a node is the end moment of the track elements that meet there, sagging
positive, averaged over them (one element at the chain's ends). An element's end forces are
what OpenSees's ``localForce`` gives for an element carrying loads,

    f = K_e u_e − f_eq,e,

f_eq,e the consistent nodal loads of the loads standing inside the element (global axes; the
track is straight and horizontal), and M = −f_rz at the element's left node, M = +f_rz at its
right node. For an Euler-Bernoulli element K_e u_e is EI w'' of its Hermite shape,

    w''(ξ) = [6(2ξ − 1)/ℓ², (6ξ − 4)/ℓ, 6(1 − 2ξ)/ℓ², (6ξ − 2)/ℓ] · [v₁, θ₁, v₂, θ₂],

and the nodal displacements are exact under nodal and element loads, so the end moments are
exact (statically). Two parts, one for each term:

* :func:`moment_rows`: K_e u_e as a linear map of the free dofs (the dynamic recorder, the
  static influence lines of :mod:`vtsi.influence` and the modal rows of a sweep alike);
* :class:`FixedEndMoments` / :func:`add_fixed_end_moments`: −f_eq of the loads standing inside
  the elements next to each node. A downward load P at a = ξℓ from an element's start (b = ℓ − a)
  enters the model through the track's Hermite row (:mod:`vtsi.track`), f_eq = −P [H₁, ℓH₂, H₃, ℓH₄],
  so it takes P a b²/ℓ² (its fixed-end moment) off the moment at the element's start node and
  P a² b/ℓ² off the one at its end node, each divided by the number of elements at the node.
  A load on a node changes nothing (H₂ = H₄ = 0 there). The moving loads of a passage (its axles
  at x₀ + V t), the contact forces λ of a coupled analysis at the contact wheels (spread by the
  B-spline rows as the constraint spreads them) and the element loads of the load patterns
  (``eleLoad``) are corrected; a numba kernel, O(axles on the elements next to the nodes) per
  sample (:func:`add_train_loads` for a train's forces and contact forces, which a coupled
  analysis hands its recorders: :class:`~vtsi.coupled.CoupledLoads`). The same table and
  kernel give a support reaction the share −f_eq of the loads in the elements at its dof
  (:func:`fixed_end_forces`, the reaction recorders of :mod:`vtsi.recorders.node`) and an
  element's end forces the −f_eq of the loads inside it (:func:`element_end_forces`, the
  element recorders of :mod:`vtsi.recorders.element`).

Without the correction (K_e u_e alone, as earlier versions took it) a load inside an element
gave the end moments O(ℓ) wrong, halved by the averaging. On the 20 m simply supported span of
10 elements: two 100 kN axles 1 m apart, static mid-span maximum 978.1 kN·m for 950 (+3.0 %),
LM71 6121.6 for 6075.2 (+0.76 %), now both to rounding; their passage at 10 km/h (undamped)
986.7, now 959.5 (40 elements: 962.6, now 959.4); at 1 km/h with ζ = 2 % 950.007 (5 km/h,
ICE3's cars, 'bspline' rows: 1938.7 for a static 1915.9, now 1916.5).

Timoshenko elements: their end moments are K_e u_e too (EI times the Hermite curvature of the
nodal values read 740 kN·m at mid-span for PL/4 = 500), and a wheel loads them through the same
Hermite row, whose f_eq is subtracted: the element's end forces and its load are in equilibrium,
so the moment is exact on a statically determinate deck. On a continuous deck the row shares a
load inside an element between its ends as an Euler-Bernoulli element would, not as the
shear-flexible one (φ = 12EI/(G A_v ℓ²)): over the middle support of a 2 × 20 m deck with
φ = 9.6, 5e-4 to 8e-4 off the exact value (a node under the load) for a load in an element
next to the support, where the end moments alone were 10–26 % off (tests/test_moment.py).

Dynamics: the end forces leave out the inertia (and the damping) of the elements' distributed
mass, M_e a_e + C_e v_e, which with a consistent mass has fixed-end moments too: about
μ a ℓ²/12 (μ the mass per length, a the deck's acceleration, ℓ the element length), read as
more sagging while the deck swings up from a sagging peak. Measured at mid-span of the 10-element
20 m span (μ = 15 t/m, ℓ = 2 m, every mode): HSLM-A1 at resonance (324 km/h, 27 m/s²) 130 kN·m,
0.71 % of the 18.3 MN·m peak; HSLM-A4 at 250 km/h (1.7 m/s²) 6.8 kN·m, 0.2 %; it falls as ℓ²
(40 elements: 0.43 kN·m). A lumped mass has none (no rotary inertia at the nodes). The bridge's
own weight as −g M 1_y (``bridge_self_weight``) is such a load: with a consistent mass its
fixed-end moments, μ g ℓ²/12, are not taken off either (49 kN·m, 0.7 % of μgL²/8 there).
"""
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder
from vtsi.recorders.node import _int_list
from vtsi.track import GAUSS_POINTS, GAUSS_WEIGHTS, Track, bspline_kernel, hermite, host_element


def _ends_by_node(asm, track):
    """The track elements meeting at each node of the track: ``{node: [(track element index e,
    sign)]}``, e increasing, with sign −1 where the node is the element's start (in x), +1 where
    it is its end."""
    ends = {}
    for e, tag in enumerate(track.elements):
        b, i = asm.element_location[tag]
        for node in asm.blocks[b][0].nodes[i]:
            x = float(asm.coords[asm.node_index[node], 0])
            ends.setdefault(node, []).append((e, -1.0 if abs(x - track.x_start[e]) <= 0.5 * track.length[e] else 1.0))
    return ends


def _node_ends(asm, ends_by_node, node):
    """The track elements meeting at ``node``, a node of the track (``ends_by_node``: the
    :func:`_ends_by_node` of the track; a ModelError for any other node)."""
    if node not in asm.node_index:
        raise ModelError(f"bending moment: node {node} does not exist")
    ends = ends_by_node.get(node, [])
    if not ends:
        x = float(asm.coords[asm.node_index[node], 0])
        raise ModelError(f"bending moment: node {node} (x = {x:g} m) is not a node of the track")
    return ends


def _dof_index(asm, track, e, node, dof=2):
    """Index of ``node``'s dof ``dof`` (0-based: 1 uy, 2 rz) in the dof vector of track element
    ``e`` (its own node order)."""
    tag = track.elements[e]
    b, i = asm.element_location[tag]
    etype = asm.blocks[b][0]
    if dof not in etype.node_dofs:
        raise ModelError(f"bending moment: element {tag} ({etype.name}) has no {('uy', 'rz')[dof - 1]} dofs")
    return list(etype.nodes[i]).index(node) * len(etype.node_dofs) + etype.node_dofs.index(dof)


def moment_rows(asm, track, nodes):
    """The end-moment part K_e u_e of the bending moment at ``nodes`` as a linear map of the free
    dofs of the assembly ``asm``: ``(free_dofs (n_req,), P (n_req, len(nodes)))`` with
    M = u[free_dofs] @ P [N·m]; loads standing inside the elements next to the nodes add their
    :class:`FixedEndMoments` (module docstring)."""
    coefficients = {}
    ends_by_node = _ends_by_node(asm, track)
    for j, node in enumerate(nodes):
        ends = _node_ends(asm, ends_by_node, node)
        for e, sign in ends:
            where = _dof_index(asm, track, e, node)
            b, i = asm.element_location[track.elements[e]]
            etype, _, coords, params, dofs = asm.blocks[b]
            row = sign * etype.stiffness(coords[i:i + 1], params[i:i + 1])[0, where] / len(ends)
            for d, c in zip(dofs[i], row):
                f = int(asm.free_of_full[d])
                if f >= 0 and c != 0.0:
                    coefficients.setdefault(f, np.zeros(len(nodes)))[j] += c
    free = np.array(sorted(coefficients), dtype=np.int64)
    P = np.array([coefficients[f] for f in free]).reshape(len(free), len(nodes))
    return free, P


@dataclass(frozen=True)
class FixedEndMoments:
    """Where loads standing inside the track's elements change the bending moments at ``nodes``
    (the −f_eq term of the module docstring), built by :func:`fixed_end_moments`, or the
    reactions at some dofs (:func:`fixed_end_forces`), or the end forces of some elements
    (:func:`element_end_forces`).

    A downward load P at x inside track element e adds ``weight[k] · P · h[slot[k]](x)`` to
    column ``column[k]`` for each entry k in ``ptr[e]:ptr[e + 1]``, h = [H₁, ℓH₂, H₃, ℓH₄] the
    track's Hermite row in e. Moments: −(sign × f_eq,rz)/n with f_eq = −P h, sign and slot −1
    and 1 for the node at e's start, +1 and 3 for the node at its end, weight = sign/n, n the
    elements at the node. Reactions and end forces: −f_eq at the dof, weight 1, slot 0 to 3.

    Attributes
    ----------
    n_columns : the nodes' (or dofs', or the elements' dofs') count.
    x_start, length : (n_el,) the track's elements [m].
    ptr : (n_el + 1,) int64; column, slot (n_entries,) int64; weight (n_entries,) float64.
    runs : (n_runs, 2) [m] the stretches of consecutive elements with entries.
    dof_index : (n_entries,) int64 the entry's dof (the node's rz for a moment) in the element's
        own dof vector (for element loads given in the element's dofs, :meth:`element_load_columns`).
    node_x : (n_columns,) [m] each node's x: where a moving load's influence line kinks.
    """

    n_columns: int
    x_start: np.ndarray
    length: np.ndarray
    ptr: np.ndarray
    column: np.ndarray
    slot: np.ndarray
    weight: np.ndarray
    runs: np.ndarray
    dof_index: np.ndarray
    elements: tuple
    node_x: np.ndarray

    def at(self, x):
        """The share ``(len(x), n_columns)`` [N·m per N; N per N at a uy dof] of a unit downward
        load at each of the positions ``x`` [m] (0 off the track; a moment's 0 on the nodes): an
        influence line's local part."""
        x = np.ascontiguousarray(x, dtype=np.float64).ravel()
        out = np.zeros((x.size, self.n_columns))
        # a unit load at x is an axle at x0 = 0 moving at 1 m/s, sampled at t = x
        add_fixed_end_moments(self, np.zeros(1), np.ones(1), 1.0, x, out)
        return out

    def element_load_columns(self, equivalent_loads):
        """The share ``(n_columns,)`` [N·m] of element loads given as ``{element tag: global
        nodal loads (ndof,)}`` (:meth:`vtsi.assembly.Assembly.element_equivalent_loads`)."""
        out = np.zeros(self.n_columns)
        for e, tag in enumerate(self.elements):
            f = equivalent_loads.get(tag)
            if f is None:
                continue
            for k in range(self.ptr[e], self.ptr[e + 1]):
                out[self.column[k]] -= self.weight[k] * f[self.dof_index[k]]
        return out


def fixed_end_moments(asm, track, nodes):
    """The :class:`FixedEndMoments` of the bending moments at ``nodes`` of ``track``."""
    entries = []
    node_x = np.empty(len(nodes))
    ends_by_node = _ends_by_node(asm, track)
    for j, node in enumerate(nodes):
        ends = _node_ends(asm, ends_by_node, node)
        node_x[j] = float(asm.coords[asm.node_index[node], 0])
        for e, sign in ends:
            entries.append((e, j, 1 if sign < 0 else 3, sign / len(ends), _dof_index(asm, track, e, node)))
    return _shares_table(track, entries, node_x)


def fixed_end_forces(asm, track, rows):
    """The :class:`FixedEndMoments` table of the fixed-end forces at the full dofs ``rows``
    (:meth:`~vtsi.assembly.Assembly.full_dof`) of ``track``'s elements: a downward load P at x in
    track element e enters the model as the nodal loads f = −P h on e's [uy₁, rz₁, uy₂, rz₂]
    (h the track's Hermite row, :mod:`vtsi.track`), so a reaction R = F_resisting − f at one of
    those dofs takes +P h there (weight 1, slot its place in h). Rows off the track's uy and rz
    dofs (ux, nodes of no track element) take nothing."""
    entries = []
    node_x = np.empty(len(rows))
    ends = _ends_by_node(asm, track)
    for j, row in enumerate(rows):
        node, dof = int(asm.node_tags[row // asm.ndf]), int(row % asm.ndf)
        node_x[j] = float(asm.coords[asm.node_index[node], 0])
        if dof in (1, 2):
            for e, sign in ends.get(node, []):
                entries.append((e, j, dof - 1 + (0 if sign < 0 else 2), 1.0, _dof_index(asm, track, e, node, dof)))
    return _shares_table(track, entries, node_x)


def element_end_forces(asm, track, elements):
    """The :class:`FixedEndMoments` table of the end forces of ``elements`` (tags): column
    ``offset_k + j`` is element k's dof j in its own dof vector (global axes; ``offset_k`` the
    dof counts of the elements before it). A downward load P at x in track element e is an
    element load of e, f_eq = −P h on its [uy₁, rz₁, uy₂, rz₂] (h the track's Hermite row,
    :mod:`vtsi.track`), and e's end forces are its resisting force less its load vector (as
    OpenSeesPy's ``eleForce``, ``localForce``), so they take +P h there (weight 1, slot its
    place in h); an element off the track takes nothing, nor does one next to e."""
    entries, node_x = [], []
    ends = _ends_by_node(asm, track)
    for tag in elements:
        b, i = asm.element_location[tag]
        etype = asm.blocks[b][0]
        offset = len(node_x)
        node_x += [float(asm.coords[asm.node_index[node], 0]) for node in etype.nodes[i] for _ in etype.node_dofs]
        if tag not in track.elements:
            continue
        e = track.elements.index(tag)
        for node in etype.nodes[i]:
            sign = next(s for k, s in ends[node] if k == e)
            for dof in (1, 2):
                j = _dof_index(asm, track, e, node, dof)
                entries.append((e, offset + j, dof - 1 + (0 if sign < 0 else 2), 1.0, j))
    return _shares_table(track, entries, np.array(node_x))


def _shares_table(track, entries, node_x):
    """The :class:`FixedEndMoments` of ``entries`` ``[(track element e, column, slot, weight, dof
    index)]`` on ``track``, ``node_x (n_columns,)`` [m]."""
    entries.sort(key=lambda entry: entry[0])
    n_el = len(track.elements)
    ptr = np.zeros(n_el + 1, dtype=np.int64)
    for e, *_ in entries:
        ptr[e + 1] += 1
    ptr = np.cumsum(ptr).astype(np.int64)
    column, slot, weight, dof = (np.array([entry[k] for entry in entries], dtype=dtype).reshape(len(entries))
                                 for k, dtype in ((1, np.int64), (2, np.int64), (3, np.float64), (4, np.int64)))
    loaded = ptr[1:] > ptr[:-1]
    runs = []
    for e in np.flatnonzero(loaded):
        lo, hi = track.x_start[e], track.x_start[e] + track.length[e]
        if runs and e > 0 and loaded[e - 1]:
            runs[-1][1] = hi
        else:
            runs.append([lo, hi])
    return FixedEndMoments(len(node_x), np.ascontiguousarray(track.x_start, dtype=np.float64),
                           np.ascontiguousarray(track.length, dtype=np.float64), ptr, column, slot, weight,
                           np.array(runs, dtype=np.float64).reshape(len(runs), 2), dof, tuple(track.elements), node_x)


def add_fixed_end_moments(fixed, x0, loads, speed, times, out, knot=0.0):
    """Add to ``out (len(times), n_columns)`` the fixed-end share (:class:`FixedEndMoments`
    ``fixed``) of downward loads [N] standing at x0 + speed · t at ``times`` [s]: ``x0 (n_loads,)``
    [m], ``loads`` (n_loads,) constant or (len(times), n_loads) one row per time (contact forces),
    ``speed`` [m/s]; ``knot`` [m] > 0: each load spread by the cubic B-spline of that knot spacing
    as the constraint's 'bspline' rows spread it (:func:`vtsi.track.constraint_rows`)."""
    x0 = np.asarray(x0, dtype=np.float64)
    loads = np.asarray(loads, dtype=np.float64)
    loads = loads.reshape((1, -1) if loads.ndim == 1 else loads.shape)
    if loads.shape[1] != x0.shape[0] or loads.shape[0] not in (1, len(times)) or out.shape != (len(times), fixed.n_columns):
        raise ModelError(f"bending moment: loads {loads.shape} do not match x0 {x0.shape}, times ({len(times)},) "
                         f"and the output {out.shape}")
    if x0.size == 0 or len(times) == 0 or fixed.runs.shape[0] == 0:
        return out
    if np.any(np.diff(x0) > 0.0):            # the kernel's binary search needs them in decreasing order
        order = np.argsort(-x0, kind="stable")
        x0, loads = x0[order], loads[:, order]
    _add_fixed_end(np.ascontiguousarray(x0), np.ascontiguousarray(loads), float(speed),
                   np.ascontiguousarray(times, dtype=np.float64), float(knot), fixed.x_start, fixed.length,
                   fixed.ptr, fixed.column, fixed.slot, fixed.weight, fixed.runs, out)
    return out


def add_train_loads(fixed, constraint, times, contact_force, knot, out):
    """Add to ``out (len(times), n_columns)`` the fixed-end share (:class:`FixedEndMoments`
    ``fixed``) of what the train of ``constraint`` (a :class:`~vtsi.constraint.MovingLoadConstraint`)
    puts on the track at ``times`` [s]: its moving forces (Hermite rows) and the contact forces
    ``contact_force (len(times), n_contact)`` [N, compression positive] at its contact wheels,
    spread as rows of knot spacing ``knot`` [m] spread them (:meth:`MovingLoadConstraint.knot`)."""
    speed = constraint.train.speed
    if len(constraint.x0_force):
        add_fixed_end_moments(fixed, constraint.x0_force, constraint.train.wheel_forces, speed, times, out)
    if constraint.n_contact:
        add_fixed_end_moments(fixed, constraint.x0, contact_force, speed, times, out, knot)
    return out


@njit(cache=True, inline="always")
def _add_load(x, p, k, knot, x_start, length, ptr, column, slot, weight, out):
    """Add the share of a downward load ``p`` [N] at ``x`` (spread over 4 ``knot`` if > 0) to row k."""
    if knot == 0.0:
        e = host_element(x, x_start, length)
        if e < 0 or ptr[e] == ptr[e + 1]:
            return
        h = hermite((x - x_start[e]) / length[e], length[e])
        for j in range(ptr[e], ptr[e + 1]):
            out[k, column[j]] += weight[j] * p * h[slot[j]]
        return
    n_el = x_start.shape[0]
    x_begin, x_end = x_start[0], x_start[n_el - 1] + length[n_el - 1]
    for piece in range(4):                      # as vtsi.track.constraint_rows, element by element
        lo = max(x - (piece - 1) * knot, x_begin)
        hi = min(x - (piece - 2) * knot, x_end)
        if hi <= lo:
            continue
        e = host_element(lo, x_start, length)
        while e < n_el and x_start[e] < hi:
            if ptr[e] < ptr[e + 1]:
                a = max(lo, x_start[e])
                b = min(hi, x_start[e] + length[e])
                if b > a:
                    half = 0.5 * (b - a)
                    for g in range(4):
                        xg = a + half * (1.0 + GAUSS_POINTS[g])
                        w = half * GAUSS_WEIGHTS[g] * bspline_kernel((x - xg) / knot) / knot
                        h = hermite((xg - x_start[e]) / length[e], length[e])
                        for j in range(ptr[e], ptr[e + 1]):
                            out[k, column[j]] += weight[j] * p * w * h[slot[j]]
            e += 1


@njit(cache=True)
def _add_fixed_end(x0, loads, speed, times, knot, x_start, length, ptr, column, slot, weight, runs, out):
    """The kernel of :func:`add_fixed_end_moments` (x0 decreasing): per time, per stretch of
    elements with entries, the loads on it found by binary search."""
    neg = -x0                                   # increasing
    per_time = loads.shape[0] > 1
    reach = 2.0 * knot
    n_runs = runs.shape[0]
    for k in range(times.shape[0]):
        shift = speed * times[k]
        r = 0
        while r < n_runs:
            lo, hi = runs[r, 0] - reach, runs[r, 1] + reach
            r += 1
            while r < n_runs and runs[r, 0] - reach <= hi:      # stretches that the spreading joins
                hi = runs[r, 1] + reach
                r += 1
            first = np.searchsorted(neg, shift - hi, side="left")       # x0 + shift <= hi
            last = np.searchsorted(neg, shift - lo, side="right")       # x0 + shift >= lo
            for i in range(first, last):
                p = loads[k, i] if per_time else loads[0, i]
                if p != 0.0:
                    _add_load(x0[i] + shift, p, k, knot, x_start, length, ptr, column, slot, weight, out)


class _Resolved(NamedTuple):
    """What a :class:`BendingMomentRecorder` reads, resolved once per assembly, track and nodes."""
    requests: tuple             # ("u", full dof) of the free dofs the moments read
    projection: np.ndarray      # (len(requests), n_nodes) [N·m per m or rad], read-only: M = u @ projection
    fixed: FixedEndMoments


def _resolve(asm, track, nodes):
    """The :class:`_Resolved` of the moments at ``nodes`` (a tuple of tags) of ``track`` on the
    assembly ``asm``, computed on the first request for them on ``asm`` and kept in its
    ``derived``: a sweep's passages share the model's assembly, and a changed model has a new one
    (:meth:`vtsi.model.Model.build`). Keyed by the track's elements, not the :class:`Track`
    object, which each runner builds anew: one entry per track, however many sweeps."""
    key = ("bending moment", tuple(track.elements), nodes)
    if key not in asm.derived:
        free, projection = moment_rows(asm, track, nodes)
        projection.flags.writeable = False
        requests = tuple(("u", int(f)) for f in asm.full_of_free[free])
        asm.derived[key] = _Resolved(requests, projection, fixed_end_moments(asm, track, nodes))
    return asm.derived[key]


class BendingMomentRecorder(Recorder):
    """Bending moment M [N·m] (sagging positive) at ``nodes`` of ``track`` (see the module
    docstring), one column per node, with the fixed-end share of the element loads of the load
    patterns and, in a :class:`~vtsi.coupled.CoupledAnalysis`, of its train's moving forces and
    contact forces at each step's end, λ_{n+1}, which the recorded displacements balance (the
    same as the recorded force for the Newmark family; Bathe records the step's mean)
    (:class:`~vtsi.coupled.CoupledLoads`, handed over when the analysis starts the recorder;
    none where the track is not the wheels' or a stretch of it, a ModelError where it is
    partly). ``constraint``: None, or the analysis's :class:`~vtsi.constraint.MovingLoadConstraint`
    (checked: another is a ModelError when the analysis starts; the recorder then records in
    coupled analyses only). ``sink``, ``dt``, ``envelope``, ``history``, ``tag``: see
    :class:`~vtsi.recorders.base.Recorder`. What it reads (the moment rows, the fixed-end table)
    is resolved once per assembly and shared by every recorder of the same nodes on it (a
    sweep's passages); a changed model has a new assembly, resolved anew."""

    name = "bending moment recorder"

    def __init__(self, track, nodes, sink=None, dt=None, envelope=False, history=True, tag=None, constraint=None):
        if not isinstance(track, Track):
            raise ModelError(f"{self.name}: track must be a vtsi.track.Track, got {track!r}")
        if constraint is not None and not all(hasattr(constraint, a) for a in ("track", "x0", "x0_force", "train", "knot",
                                                                          "n_contact", "interpolation")):
            raise ModelError(f"{self.name}: constraint must be a MovingLoadConstraint, got {constraint!r}")
        if constraint is not None and list(constraint.track.elements) != list(track.elements):
            raise ModelError(f"{self.name}: the constraint's wheels run on elements {list(constraint.track.elements)}, "
                             f"the recorder's track is {list(track.elements)}")
        self.track, self.nodes = track, _int_list(self.name, "nodes", nodes)
        self.constraint = constraint
        super().__init__(sink=sink, dt=dt, envelope=envelope, history=history, tag=tag)
        self._projection = None
        self._fixed = None
        self._pattern_loads = []
        self._coupled = None        # the CoupledLoads of the analysis running

    def requests(self, assembly):
        resolved = _resolve(assembly, self.track, tuple(self.nodes))
        self._projection, self._fixed = resolved.projection, resolved.fixed
        return list(resolved.requests)

    def start(self, assembly, model, info=None):
        coupled = (info or {}).get("coupled_loads")
        self._coupled = None
        if self.constraint is not None:
            if coupled is None:
                raise ModelError(f"{self.name}: constraint= is given, so it records in a coupled analysis only, "
                                 f"got a {(info or {}).get('analysis', 'transient')} analysis")
            if coupled.constraint is not self.constraint:
                raise ModelError(f"{self.name}: its constraint= is another MovingLoadConstraint than the one of "
                                 "the coupled analysis that records it; give the analysis's own constraint or none "
                                 "(the recorder then takes the analysis's)")
            self._coupled = coupled
        elif coupled is not None:
            wheels = set(coupled.constraint.track.elements)
            shared = [tag for tag in self.track.elements if tag in wheels]
            if len(shared) == len(self.track.elements):
                self._coupled = coupled
            elif shared:
                other = next(tag for tag in self.track.elements if tag not in wheels)
                raise ModelError(f"{self.name}: its track runs partly on the wheels' track ({len(shared)} of its "
                                 f"{len(self.track.elements)} elements; element {other} is not on it); record the "
                                 "moments on the wheels' track or a stretch of it")
        super().start(assembly, model, info)

    def prepare(self, assembly, model):
        self._pattern_loads = []
        for pattern in model.patterns.values():
            if pattern.element_loads:
                share = self._fixed.element_load_columns(assembly.element_equivalent_loads(pattern))
                if share.any():
                    self._pattern_loads.append((pattern, share))
        return {"response": "moment", "quantity": "bending moment, sagging positive",
                "units": ["N m"] * len(self.nodes), "columns": {"node": np.array(self.nodes, dtype=np.int64)}}

    def compute(self, times, columns, assembly):
        out = columns @ self._projection
        for pattern, share in self._pattern_loads:      # element loads: at the time the steps applied them
            out += pattern.factors(times - self.load_lag)[:, None] * share[None, :]
        if self._coupled is not None:
            self._coupled.add(self._fixed, times, out)
        return out
