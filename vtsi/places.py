"""Places in words, as people count them (from 1, where the results file's indices count from 0):
a deck node with its x and its span, support or overhang ('node 26 (x = 62.5 m, span 3)'), a car
('car 1 of 8 (the leading car)'), a contact wheel ('wheel 3 of 32 (car 1 of 8)') and where a wheel
or car was at an envelope's extreme. The check's rows and the report name their places so
(docs/check.md). x along the track [m].
"""
import numpy as np

from vtsi.deck_record import overhangs, piers
from vtsi.sweep_results import ENVELOPE_ROWS, deck_ranges, x_tolerance


def car_label(car, n_cars):
    """A car as people count them: 'car 1 of 8 (the leading car)' for index ``car`` (0-based, as
    the results file keeps it)."""
    where = " (the leading car)" if car == 0 and n_cars > 1 else " (the last car)" if car == n_cars - 1 > 0 else ""
    return f"car {car + 1} of {n_cars}{where}"


def wheel_label(wheel, data):
    """A contact wheel as people count them: 'wheel 3 of 32 (car 1 of 8)' for its index ``wheel``
    (0-based, as the results file keeps it) in a train of stored data ``data``
    (:meth:`SweepResults.train_data`)."""
    contact = np.asarray(data["contact_wheels"])
    car = int(np.asarray(data["wheel_car"])[contact[wheel]])
    return f"wheel {wheel + 1} of {len(contact)} (car {car + 1} of {int(data['n_cars'])})"


def node_text(bridge, node):
    """A deck node in words: 'node 26 (x = 62.5 m, span 3)'; at a support, the support: 'node 11
    (x = 25 m, support of spans 1 and 2)' (one support line of two spans), 'node 12 (x = 14.7 m,
    support of span 1 on the pier of spans 1 and 2)' (a span's own bearing on a pier it shares
    with the next span: twin bearings, :func:`vtsi.deck_record.piers`), 'node 1 (x = 0 m, end
    support of span 1)' (its deck's end); between a pier's bearings 'pier of spans 1 and 2'; on
    an overhang 'node 2 (x = 1 m, overhang x = 0 to 4 m)' (on a pier: '... on the pier of spans
    1 and 2'); 'node 7' alone when the bridge record (/bridge/deck_nodes, deck_x_m) does not
    hold it."""
    deck_x = dict(zip(np.asarray(bridge["deck_nodes"]).tolist(), np.asarray(bridge["deck_x_m"]).tolist()))
    node = int(node)
    if node not in deck_x:
        return f"node {node}"
    x = float(deck_x[node])
    place = _deck_place(bridge, x)
    return f"node {node} (x = {x:g} m" + (f", {place})" if place else ")")


def _deck_place(bridge, x):
    """The place of ``x`` [m] on the decks in words (see :func:`node_text`); '' off them."""
    tol = x_tolerance(bridge)
    ends = np.asarray(bridge["span_ends_m"], dtype=float).reshape(-1, 2)
    inside = np.flatnonzero((ends[:, 0] - tol <= x) & (x <= ends[:, 1] + tol))
    if len(inside) > 1:
        return f"support of spans {' and '.join(str(k + 1) for k in inside)}"
    pier = next((f"the pier of spans {k + 1} and {k + 2}" for k, a, b in piers(bridge) if a - tol <= x <= b + tol),
                "")
    if len(inside):
        k = int(inside[0])
        if np.min(np.abs(ends[k] - x)) > tol:
            return f"span {k + 1}"
        return f"support of span {k + 1} on {pier}" if pier else f"end support of span {k + 1}"
    hang = [(a, b) for _, a, b in overhangs(bridge) if min(a, b) - tol <= x <= max(a, b) + tol]
    if hang:
        return f"overhang x = {min(hang[0]):g} to {max(hang[0]):g} m" + (f" on {pier}" if pier else "")
    return pier.removeprefix("the ")


def decks_text(bridge):
    """The decks' extents in words: 'x = 0 to 20 m; x = 20 to 40 m'."""
    return "; ".join(f"x = {a:g} to {b:g} m" for a, b in deck_ranges(bridge))


def wheel_or_car_place(results, name, idx, row, columns, whole_run=True):
    """Where the extreme of envelope row ``row`` (an index of
    :data:`~vtsi.sweep_results.ENVELOPE_ROWS`: min, max or absmax) of vehicle output ``name`` at
    ``idx`` (train, speed, seed, column) lies, in words: a wheel and its x, or a car and its
    wheels' x, at the extreme's time; of the whole-run envelope or (``whole_run=False``) the
    bridge's. ``results``: a :class:`~vtsi.sweep_results.SweepResults`; ``columns``: the
    output's columns (contact wheel or car indices)."""
    env, _ = results.column_envelopes(name, whole_run=whole_run)
    time = float(env[tuple(idx[:3]) + (ENVELOPE_ROWS.index("time_of_" + ENVELOPE_ROWS[row]), idx[3])])
    data = results.train_data(results.trains[idx[0]])
    offsets = np.asarray(data["axle_offsets_m"], dtype=float)
    k = int(columns[idx[3]])
    if results.describe(name)["kind"] == "car":
        x = _x_at(results, idx, time, offsets[np.asarray(data["wheel_car"]) == k])
        return f"{car_label(k, int(data['n_cars']))}, its wheels at x = {x.min():.1f} to {x.max():.1f} m"
    x = _x_at(results, idx, time, offsets[np.asarray(data["contact_wheels"])[k]])
    return f"{wheel_label(k, data)}, x = {float(x):.1f} m"


def _x_at(results, idx, time, offsets):
    """The x [m] of points ``offsets`` [m] behind the head of case ``idx`` (train, speed, seed)
    at ``time`` [s]."""
    x_head0 = results.start_positions()[tuple(idx[:3])]
    return x_head0 + float(results.speeds_kmh[idx[1]]) / 3.6 * time - np.asarray(offsets, dtype=float)
