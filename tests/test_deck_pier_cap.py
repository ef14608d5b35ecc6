"""Rule 1 of vtsi.deck: a structure a track node stands on may run level with the deck once it
has left the track node (a bearing's lower node tied by arms at the deck's level, within
CAP_REACH of its x, to a pier column's top), but not from the track node itself (a deck going
on off the track), nor along a second girder beyond a cap's reach."""
import numpy as np
import pytest

import vtsi
from vtsi.deck import deck_layout
from vtsi.errors import BridgeModelError
from vtsi.track import Track

DECK = dict(A=6.0, E=3.5e10, I=3.0, rho=18000.0)
RAIL = dict(A=0.0077, E=2.1e11, I=3.0e-5, rho=120.0)


def _viaduct(cap_y):
    """Five simply supported decks (bearings 24 m apart, 0.45 m of deck beyond each, 4
    elements between the bearings; nodes 100 d + 1 ... 100 d + 7), 0.1 m rail joints between
    them, on zeroLength bearings between coincident nodes at the deck's level: fixed at the
    abutments, on piers at x = 25, 50, 75, 100 m whose column (9000 + k, 8 m) meets 0.5 m arms
    to each bearing's lower node at y = ``cap_y`` [m] (0: the cap at the deck's level; -1: a
    cap 1 m below, reached by a short post under each bearing). Returns (model, track tags)."""
    model = vtsi.Model()
    track, ends = [], []
    for d in range(5):
        x0 = 25.0 * d
        xs = [x0 + 0.05, x0 + 0.5] + [x0 + 0.5 + 6.0 * i for i in range(1, 4)] + [x0 + 24.5, x0 + 24.95]
        tags = [100 * (d + 1) + i for i in range(len(xs))]
        for t, xn in zip(tags, xs):
            model.node(t, xn, 0.0)
        if ends:                                            # the rail joint from the previous deck
            model.element("elasticBeamColumn", 10 * tags[0], (ends[-1][-1], tags[0]), **RAIL)
            track.append(10 * tags[0])
        for a, b in zip(tags[:-1], tags[1:]):
            model.element("elasticBeamColumn", a, (a, b), cmass=1, **DECK)
            track.append(a)
        ends.append(tags)
    for k in range(6):
        bearings = ([(5000 + 10 * k, ends[k - 1][-2])] if k > 0 else []) + \
                   ([(5001 + 10 * k, ends[k][1])] if k < 5 else [])
        for low, deck_node in bearings:
            model.node(low, model.nodes[deck_node][0], 0.0)
            model.element("zeroLength", low, (low, deck_node), kx=5.0e6, ky=5.0e9)
            if k in (0, 5):
                model.fix(low, 1, 1, 1)
        if 0 < k < 5:
            top, foot = 9000 + k, 9100 + k
            model.node(top, 25.0 * k, cap_y)
            model.node(foot, 25.0 * k, cap_y - 8.0)
            model.fix(foot, 1, 1, 1)
            model.element("elasticBeamColumn", top, (foot, top), A=6.0, E=3.5e10, I=4.0, rho=15000.0)
            for low, _ in bearings:
                arm_end = low
                if cap_y < 0.0:                             # a post down from the bearing to the cap
                    arm_end = low + 500
                    model.node(arm_end, model.nodes[low][0], cap_y)
                    model.element("elasticBeamColumn", arm_end, (arm_end, low), A=2.0, E=3.5e10, I=2.0)
                model.element("elasticBeamColumn", 8000 + low, (top, arm_end), A=2.0, E=3.5e10, I=2.0)
    return model, track


@pytest.mark.parametrize("cap_y", [0.0, -1.0])
def test_a_pier_cap_at_the_decks_level_carries_its_decks(cap_y):
    """The cap at the deck's level read '1 deck; span 124.9 m' (L/600 of 124.9 m, Phi 1.0, a
    30 Hz cut-off for 43 Hz); 1 m below, five decks of 24 m. Both now: five decks of 24 m."""
    model, track = _viaduct(cap_y)
    layout = deck_layout(model, Track(model, track))
    assert layout.span_lengths == pytest.approx([24.0] * 5)
    assert np.allclose(layout.deck_ends, [(25.0 * d + 0.05, 25.0 * d + 24.95) for d in range(5)], rtol=0, atol=1e-9)
    assert layout.support_nodes == tuple(100 * (d + 1) + i for d in range(5) for i in (1, 5))
    assert layout.midspan_nodes == tuple(100 * (d + 1) + 3 for d in range(5))
    assert layout.pier_nodes == () and not layout.track_on_a_structure     # simply supported decks


def _deck_going_on():
    """A 20 m deck (nodes 1-11 at x = 0, 2 ... 20 m; the track) pinned at node 1, going on off
    the track from node 11 by a level beam (element 90) to node 90 at x = 22 m, which stands on
    a bearing (zeroLength to node 91, fixed)."""
    model = vtsi.Model()
    for i in range(11):
        model.node(i + 1, 2.0 * i, 0.0)
    model.fix(1, 1, 1, 0)
    for e in range(1, 11):
        model.element("elasticBeamColumn", e, (e, e + 1), cmass=1, **DECK)
    model.node(90, 22.0, 0.0)
    model.node(91, 22.0, 0.0)
    model.fix(91, 1, 1, 1)
    model.element("elasticBeamColumn", 90, (11, 90), **DECK)
    model.element("zeroLength", 91, (91, 90), kx=5.0e6, ky=5.0e9)
    return model


def test_a_level_beam_from_the_track_node_to_a_bearing_is_no_support():
    """The first step from a track node keeps its rule (below it, or under it at its x): a
    level beam off the track's last node to a bearing 2 m away is the deck going on, not a
    support of that node, and the track stopping mid-deck is refused (rule 7), as before."""
    model = _deck_going_on()
    with pytest.raises(BridgeModelError, match=r"^track: its last node 11 \(x = 20 m\) carries no support, and the "
                                               r"deck goes on beyond it off the track \(element 90 to node 90 at "
                                               r"x = 22 m\)"):
        deck_layout(model, Track(model, list(range(1, 11))))


@pytest.mark.parametrize("height", [0.0, 0.5])
def test_a_rail_on_pads_over_a_deck_keeps_the_decks_spans(height):
    """A rail on pads (0: between coincident nodes) over a 2 x 20 m continuous deck (nodes 1-21)
    pinned at its ends and on a bearing at x = 20 m whose lower node an arm at the deck's level
    ties to a column 1 m along: the deck nodes beside a rail node's own are tied to other rail
    nodes by their pads, so the walk at the deck's level stops there; the rail over the bearing
    stands on the pier, the others on the deck."""
    model = vtsi.Model()
    for i in range(21):
        model.node(i + 1, 2.0 * i, 0.0)
        model.node(101 + i, 2.0 * i, height)
        model.element("zeroLength", 201 + i, (101 + i, i + 1), kx=1.0e7, ky=1.0e9)
    model.fix(1, 1, 1, 0)
    model.fix(21, 0, 1, 0)
    for e in range(1, 21):
        model.element("elasticBeamColumn", e, (e, e + 1), cmass=1, **DECK)
        model.element("elasticBeamColumn", 100 + e, (100 + e, 101 + e), **RAIL)
    model.node(300, 20.0, 0.0)
    model.element("zeroLength", 300, (300, 11), kx=5.0e6, ky=5.0e9)
    model.node(301, 21.0, 0.0)
    model.node(302, 21.0, -8.0)
    model.fix(302, 1, 1, 1)
    model.element("elasticBeamColumn", 301, (300, 301), A=2.0, E=3.5e10, I=2.0)
    model.element("elasticBeamColumn", 302, (302, 301), A=6.0, E=3.5e10, I=4.0)
    layout = deck_layout(model, Track(model, list(range(101, 121))))
    assert layout.support_nodes == (101, 111, 121) and layout.span_lengths == [20.0, 20.0]
    assert layout.pier_nodes == (111,) and layout.track_on_a_structure


@pytest.mark.parametrize("diaphragms", [(6,), (2, 6, 10)])
def test_a_second_girder_tied_at_the_decks_level_is_no_support(diaphragms):
    """A 20 m track girder pinned at its ends and, at the same level, an off-track second girder on
    piers at its ends, tied to it by one diaphragm at mid-span: the diaphragm's walk along the
    second girder is no pier cap (a first version of the level rule read 2 × 10 m spans, a second
    2 + 16 + 2 m with diaphragms at 2, 10 and 18 m: a probe's twin girders). Level steps count
    within CAP_REACH (1.5 m) of the track node's x only."""
    deck = dict(A=6.0, E=3.5e10, I=3.0, rho=18000.0)
    model = vtsi.Model()
    for i in range(11):
        model.node(1 + i, 2.0 * i, 0.0)
        model.node(101 + i, 2.0 * i, 0.0)
    for e in range(10):
        model.element("elasticBeamColumn", 1 + e, (1 + e, 2 + e), cmass=1, **deck)
        model.element("elasticBeamColumn", 101 + e, (101 + e, 102 + e), cmass=1, **deck)
    model.fix(1, 1, 1, 0)
    model.fix(11, 0, 1, 0)
    for k, n in ((201, 101), (202, 111)):                  # the second girder on 8 m piers
        model.node(k, model.nodes[n][0], -8.0)
        model.fix(k, 1, 1, 1)
        model.element("elasticBeamColumn", k, (k, n), A=4.0, E=3.5e10, I=2.0, rho=10000.0)
    for n in diaphragms:            # at 2 m from the second girder's pier: beyond a cap's reach
        model.element("zeroLength", 500 + n, (n, 100 + n), kx=1e9, ky=1e9)
    layout = deck_layout(model, Track(model, list(range(1, 11))))
    assert layout.support_nodes == (1, 11) and layout.span_ends == ((0.0, 20.0),) and layout.pier_nodes == ()


@pytest.mark.parametrize("arm_elements", [1, 2])
def test_a_cap_arm_of_several_elements_carries_the_decks(arm_elements):
    """Two 20 m decks on zeroLength bearings whose lower nodes reach a column's top at x = 21 m by
    1 m level arms, meshed in one or two elements: two spans (the rule of one arm element read one
    42 m span from a two-element arm, a probe's hammerhead)."""
    deck = dict(A=6.0, E=3.5e10, I=3.0, rho=18000.0)
    model, track = vtsi.Model(), []
    for first, x0 in ((1, 0.0), (21, 22.0)):
        for i in range(11):
            model.node(first + i, x0 + 2.0 * i, 0.0)
        for i in range(10):
            model.element("elasticBeamColumn", first + i, (first + i, first + i + 1), cmass=1, **deck)
            track.append(first + i)
    model.element("elasticBeamColumn", 12, (11, 21), A=0.0077, E=2.1e11, I=3e-5, rho=120.0)   # the rail's joint
    track.append(12)
    for n, low in ((1, 301), (31, 302)):
        model.node(low, model.nodes[n][0], 0.0)
        model.fix(low, 1, 1, 1)
        model.element("zeroLength", low, (low, n), kx=5e6, ky=5e9)
    model.node(400, 21.0, 0.0)                       # the column's top, at the deck's level
    model.node(401, 21.0, -8.0)
    model.fix(401, 1, 1, 1)
    model.element("elasticBeamColumn", 400, (401, 400), A=4.0, E=3.5e10, I=2.0, rho=10000.0)
    for n, low, side in ((11, 311, -1.0), (21, 321, 1.0)):
        model.node(low, model.nodes[n][0], 0.0)
        model.element("zeroLength", low, (low, n), kx=5e6, ky=5e9)
        chain = [low] + [330 + low + k for k in range(arm_elements - 1)] + [400]
        for k, tag in enumerate(chain[1:-1], start=1):
            model.node(tag, 21.0 + side * (1.0 - k / arm_elements), 0.0)
        for a, b in zip(chain[:-1], chain[1:]):
            model.element("elasticBeamColumn", 1000 + a, (a, b), A=4.0, E=3.5e10, I=2.0)
    layout = deck_layout(model, Track(model, track))
    assert layout.span_ends == ((0.0, 20.0), (22.0, 42.0))
