"""The track's two end nodes and how far a wheel standing on each sags it (docs/sweeps.md,
"Ground").

Off the track the wheels run on rigid ground. A track end node that is not held in uy (a rail end
on ground springs, a deck end on a soft bearing) sags under the wheel that rolls onto it from
that ground, or off it onto that ground: the wheel meets a step as deep as the node's static sag
under its load, and its car reads it as an impact, whose unloading of the contact forces lasts
onto the deck (from the first end) and reaches the wheels still on it (from the last). Moving
forces feel no step (no car reads the rail): over a 25 m deck with 6 m approaches of rail on
5e7 N/m springs a metre apart (ICE3 and HSLM-A1 as moving forces, 150-360 km/h, ζ = 1 %), free
end nodes moved the deck acceleration by 0.06 %, the deflection by 0.04 % and the bending
moments by 1 % of the fixed ends' envelopes.

Signs and units: a sag is downward positive [m], a wheel load downward positive [N].
"""
from dataclasses import dataclass

import numpy as np

from vtsi.influence import InfluenceLines

FREE_END_SAG = 0.25e-3
"""[m] A track end sagging more than this under the heaviest static wheel load is told
(:func:`free_end_text`). Measured: ICE3 cars (152.1 kN wheels) over a 25 m simply supported deck
(15 t/m, n₀ = 5 Hz) with 6 m approaches of rail (2 × UIC60: EI = 12.8 MN·m², 120 kg/m) on
5e7 N/m springs a metre apart, 150 to 360 km/h every 10 km/h, ζ = 1 %, bilateral contact. With
the end nodes on springs of 1e10, 1e9, 4e8, 2e8 or 1e8 N/m, or free on their 5e7 N/m (sag 0.015,
0.151, 0.373, 0.731, 1.41, 2.62 mm), the wheel unloading ΔQ/Q read at any one speed moved from
that of fixed ends by at most 0.004, 0.036, 0.069, 0.117, 0.21, 0.39 (by 0.0015, 0.025, 0.057,
0.105, 0.23, 0.34 on a deck of n₀ = 3 Hz): by 0.05, a material change, at 0.25 mm (0.33 mm on
the 3 Hz deck). The check's value, the largest over the speeds, went from 0.430 (fixed, PASS)
to 0.634 at 2.62 mm (FAIL against 0.6). A track end on a lone bearing stiffer than 6.1e8 N/m
(152.1 kN / 0.25 mm) is not told."""


@dataclass(frozen=True)
class TrackEnd:
    """One of the track's two end nodes: its tag ``node``, its ``x_m`` [m], its static ``sag_m``
    [m, downward positive] under ``load_n`` [N], the heaviest static wheel load of the trains (0
    for a node fixed in uy)."""

    node: int
    x_m: float
    sag_m: float
    load_n: float

    @property
    def free(self):
        """Whether the end sags more than FREE_END_SAG: a step for the cars' wheels."""
        return self.sag_m > FREE_END_SAG


def end_flexibility(model, track, nodes):
    """``(len(nodes),)`` [m/N]: each of ``nodes``' static sag under a unit downward wheel load
    standing on it (0 for a node whose uy is fixed), from the stiffness K of ``model`` (a
    :class:`vtsi.Model`) along ``track`` (a :class:`~vtsi.track.Track`): one factorisation of K
    and one solve (:class:`~vtsi.influence.InfluenceLines`, by reciprocity the influence line of
    the node's own uy at its x), none when every node is fixed in uy."""
    asm = model.build()
    moving = [k for k, n in enumerate(nodes) if asm.free_of_full[asm.full_dof(n, 2)] >= 0]
    out = np.zeros(len(nodes))
    if moving:
        lines = InfluenceLines(model, track, dofs=[(nodes[k], 2) for k in moving])
        out[moving] = -np.diag(lines([model.nodes[nodes[k]][0] for k in moving]))   # IL: uy (up) per N down
    return out


def free_end_text(ends):
    """'' when no end of ``ends`` (:class:`TrackEnd`) is :attr:`~TrackEnd.free`; else one line
    naming each free end's node, x and sag under the load, and the fix."""
    free = [e for e in ends if e.free]
    if not free:
        return ""
    one = len(free) == 1
    nodes = " and ".join(str(e.node) for e in free)
    where = " and ".join(f"{e.node} (x = {e.x_m:g} m)" for e in free)
    sags = " and ".join(f"{1e3 * e.sag_m:.3g}" for e in free)
    return (f"track end node{'' if one else 's'} {where} {'is' if one else 'are'} not fixed in uy and "
            f"sag{'s' if one else ''} {sags} mm under the trains' heaviest static wheel load "
            f"({max(e.load_n for e in free) / 1e3:.4g} kN), more than {1e3 * FREE_END_SAG:g} mm: the cars' "
            f"wheels pass between {'it' if one else 'each'} and the rigid ground beyond the track as over a step, "
            f"an impact that reads as wheel unloading (docs/sweeps.md, 'Ground'); fix node{'' if one else 's'} "
            f"{nodes} in uy, or extend the approach{'' if one else 'es'}")
