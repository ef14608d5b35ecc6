"""The decks' layout as a sweep's results file records it (/bridge, :meth:`SweepResults.bridge`
of :mod:`vtsi.sweep_results`; :mod:`vtsi.deck` finds it in the model): the track's nodes on a
deck, the overhangs, the piers carrying two spans' ends, the intermediate supports of continuous
decks, and the output columns at the spans' middles and over those supports. x along the track
[m]; spans and decks are counted from 0 (rows of /bridge/span_ends_m and deck_ends_m).
"""
import numpy as np

from vtsi.deck import MIN_SPAN_LENGTH
from vtsi.sweep_results import deck_ranges, span_decks, x_tolerance


def deck_nodes(bridge):
    """The track's nodes on a deck (its spans and overhangs): the track's nodes on an approach
    (ground) or on a joint between two decks are no deck."""
    x, tol = np.asarray(bridge["deck_x_m"]), x_tolerance(bridge)
    inside = np.zeros(len(x), dtype=bool)
    for a, b in deck_ranges(bridge):
        inside |= (x >= a - tol) & (x <= b + tol)
    return set(np.asarray(bridge["deck_nodes"])[inside].tolist())


def overhangs(bridge):
    """The decks' overhangs: ``[(deck, x of its support, x of its free end)]`` [m], the stretches
    of a deck beyond its outermost spans' supports."""
    ends, tol = np.asarray(bridge["span_ends_m"], dtype=float).reshape(-1, 2), x_tolerance(bridge)
    out, of = [], span_decks(bridge)
    for d, (a, b) in enumerate(deck_ranges(bridge)):
        mine = ends[of == d]
        if not len(mine):
            continue
        if mine[0, 0] > a + tol:
            out.append((d, float(mine[0, 0]), float(a)))
        if mine[-1, 1] < b - tol:
            out.append((d, float(mine[-1, 1]), float(b)))
    return out


def piers(bridge):
    """The piers that carry the ends of two spans side by side: ``[(span, x_a, x_b)]`` [m], x_a
    the last support of span ``span``, x_b the first of the next span, less than the shortest
    span (:data:`vtsi.deck.MIN_SPAN_LENGTH`, 1 m) apart: one support line of two spans (x_a =
    x_b: a continuous deck's support, or two decks ending on one pier), a continuous deck's two
    bearings on one pier cap (their stretch no span), or two decks' end bearings either side of a
    joint. Every other end of a span is its deck's end support (an abutment, or a pier whose
    other deck's bearing stands 1 m or more away)."""
    ends = np.asarray(bridge["span_ends_m"], dtype=float).reshape(-1, 2)
    return [(k, float(ends[k, 1]), float(ends[k + 1, 0])) for k in range(len(ends) - 1)
            if ends[k + 1, 0] - ends[k, 1] < MIN_SPAN_LENGTH]


def span_columns(columns, bridge):
    """For each span: the output column (of node tags ``columns``) of its middle node (or -1)."""
    return [int(np.flatnonzero(columns == m)[0]) if np.any(columns == m) else -1 for m in bridge["midspan_nodes"]]


def intermediate_supports(bridge):
    """The intermediate supports of the continuous decks: ``[(span, x [m], node tags)]``, one per
    support line between two spans of one deck (span: the one before it, whose deck gives L_Φ, Φ
    and φ''); a pier with two bearings closer than a span (their stretch no span, the deck
    continuous over it, :func:`piers`) is two, one at each bearing. Two decks ending on one pier
    (or separated by a joint) have none there: their spans are of different decks. The node tags
    are the deck's track nodes at that x (/bridge/deck_nodes, deck_x_m)."""
    decks = span_decks(bridge)
    nodes, xs, tol = np.asarray(bridge["deck_nodes"]), np.asarray(bridge["deck_x_m"], dtype=float), x_tolerance(bridge)
    return [(k, x, [int(n) for n in nodes[np.abs(xs - x) <= tol]])
            for k, a, b in piers(bridge) if decks[k] == decks[k + 1] for x in ((a, b) if b - a > tol else (a,))]


def support_columns(columns, bridge):
    """The output columns (node tags ``columns``) over the intermediate supports of continuous
    decks: ``[(column, span, x [m])]`` (:func:`intermediate_supports`)."""
    columns, out = np.asarray(columns), []
    for k, x, nodes in intermediate_supports(bridge):
        held = [int(np.flatnonzero(columns == n)[0]) for n in nodes if np.any(columns == n)]
        if held:
            out.append((held[0], k, x))
    return out
