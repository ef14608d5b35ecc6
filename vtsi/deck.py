"""The layout of a bridge along its track: which track nodes carry it (supports), the spans
between them, the decks the spans make (with their overhangs), the joints between decks, and
the track's stretches on the ground (approaches). docs/sweeps.md, "Spans", states the rules;
a sweep stores the layout in its results file (/bridge) and the check reads it from there.

The rules, in order (:func:`deck_layout`):

1. **Supports.** A track node carries the deck when its uy is fixed, or when it stands on a
   vertical line of other elements (bearings, springs, piers: every node of the line within
   SUPPORT_X_TOLERANCE of its x, off the track) that reaches a node with uy fixed, or when it
   stands on a structure of its own that reaches one: off-track elements going from it to
   nodes below it (or under it, at its x: a bearing's lower node), none of them tied to another
   track node (one at its x excepted), down to a node with uy fixed, at any x (arms to bearings
   beside the node, a pier cap, a V-pier); at its level only a pier cap's arms: level elements
   from a node so reached, within CAP_REACH of its x, on to a node with uy fixed below it.
   Hangers and stays (going up), a deck going on at the track's level off the track (a level
   beam from the track node itself, or a second girder tied to it farther than CAP_REACH from
   that girder's support), the chords of a truss and the deck under a rail on pads (tied to
   other track nodes) are not. A cap at the deck's level reaching farther is not read either:
   model it below the deck.
2. **Support lines.** Supported nodes within SUPPORT_X_TOLERANCE of each other's x are one
   support (two deck ends on one pier).
3. **Ground.** Three or more support lines in a row, one element apart, are ground (an approach
   on springs or fixed nodes); the elements between them are no deck.
4. **Joints.** A stretch between two support lines holding a track element whose bending
   stiffness is below JOINT_STIFFNESS_SHARE of the track elements beside the stretch on both
   sides is a joint (a rail across the gap between two decks): that element is no deck, the
   decks on either side are separate, and the pieces between it and the support lines are those
   decks' overhangs. A stretch shorter than MIN_SPAN_LENGTH is no span either (its elements
   stay deck: a continuous deck over two close bearings).
5. **Spans.** Every other stretch between two support lines is a span.
6. **Decks.** The runs of deck elements, separated at ground, at joints, and at a support line
   where the track passes from one element to the next without a shared node (two decks ending
   on one pier). A deck is its spans and its overhangs: the track beyond its outermost support
   lines up to a free end (the track's end, or a joint). A piece of track with no span of its
   own is no deck.
7. **Track ends.** A track end on no support is a free end, unless the deck goes on off the
   track there (a horizontal beam element continuing beyond it): that is refused, for the
   track would stop mid-deck. A track end on a support is a deck's end, unless the deck's beam
   goes on from that node off the track over a span: the track extended by the level beams
   off it beyond its ends (the same node, so rotationally continuous) has that node over a pier
   of a continuous deck (``pier_nodes``), and it is refused, for the track would leave out a
   span of its deck. Another deck on the same pier (its own end node), a joint, approaches on
   the ground and an overhang off the track are no span of the deck: accepted. With fewer than
   two support lines the track's ends are the one span's (as before).

Units: m.
"""
from dataclasses import dataclass

import numpy as np

from vtsi.errors import BridgeModelError

SUPPORT_X_TOLERANCE = 0.01    # [m] how far off a node's x a vertical line under it may reach; supports as close: one
MIN_SPAN_LENGTH = 1.0         # [m] the shortest span: EN 1991-2's HSLM-B loads spans from 1 m (6.4.6.1.1, Fig. 6.13)
JOINT_STIFFNESS_SHARE = 0.01  # a track element this much less stiff in bending than the deck on both sides is a joint
CAP_REACH = 1.5               # [m] how far off a track node's x a pier cap at the deck's level may reach (its arms)


@dataclass(frozen=True)
class DeckLayout:
    """A bridge's layout along its track (see the module docstring).

    track_nodes : every node of the track, in x order (nodes at one x in the track's order).
    support_nodes : the track nodes that carry a deck, in x order (not those on the ground).
    span_ends : ((x_a, x_b), ...) [m] each span's supports.
    midspan_nodes : the track node nearest each span's middle.
    span_decks : the deck of each span (index into ``deck_ends``).
    deck_ends : ((x_0, x_1), ...) [m] each deck's ends: its spans and overhangs.
    nodes_by_deck : ((node tags), ...) each deck's track nodes, in x order (a deck's end nodes
        at a joint are its own; two decks ending on one pier each keep their end node).
    ground_nodes : the track's nodes on no deck (approaches on the ground, a joint's inner nodes).
    pier_nodes : the track nodes over the intermediate supports of continuous decks, in x order:
        where two spans of one deck meet (both bearings of a pier whose deck runs on over a short
        stretch); none where two decks end on one pier or at a joint.
    track_on_a_structure : the track stands on elements over another structure at most of its
        nodes (a rail on its pads over the deck): the deck outputs are the track's.
    """

    track_nodes: tuple
    support_nodes: tuple
    span_ends: tuple
    midspan_nodes: tuple
    span_decks: tuple
    deck_ends: tuple
    nodes_by_deck: tuple
    ground_nodes: frozenset
    pier_nodes: tuple
    track_on_a_structure: bool

    @property
    def span_lengths(self):
        return [b - a for a, b in self.span_ends]

    @property
    def deck_nodes(self):
        """The track's nodes on a deck (its spans and overhangs), in x order: every track node
        but those on no deck (``ground_nodes``)."""
        return tuple(n for n in self.track_nodes if n not in self.ground_nodes)


def deck_layout(model, track):
    """The :class:`DeckLayout` of ``model`` along ``track`` (a :class:`~vtsi.track.Track`); a
    BridgeModelError when the track stops mid-deck or on a support of a continuous deck that goes
    on over a span off the track (rule 7)."""
    asm = model.build()
    layout, supports = _layout(model, asm, list(track.elements))
    beams = _level_beams(model, asm, set(track.elements))
    for end, outward in ((layout.track_nodes[0], -1.0), (layout.track_nodes[-1], 1.0)):
        if end not in supports:
            _refuse_mid_deck_end(model, end, outward, _beam_beyond(model, beams, end, outward))
    _refuse_span_beyond(model, asm, track, layout, beams)
    return layout


def _layout(model, asm, chain):
    """(:class:`DeckLayout`, the set of supported track nodes, those on the ground too) of
    ``model`` along ``chain``, the tags of a track's 2-node beams in x order: rules 1 to 6."""
    x = {}
    ends = []                           # each track element's (left, right) node, in x order
    for tag in chain:
        b, i = asm.element_location[tag]
        a, c = (int(n) for n in asm.blocks[b][0].nodes[i])
        if model.nodes[a][0] > model.nodes[c][0]:
            a, c = c, a
        ends.append((a, c))
        x[a], x[c] = float(model.nodes[a][0]), float(model.nodes[c][0])
    deck = list(dict.fromkeys(n for pair in ends for n in pair))
    place = {n: k for k, n in enumerate(deck)}
    links = _links(model, set(chain))
    fixed_y = {n for n, flags in model.fixities.items() if flags[1]}
    supports = [n for n in deck if n in fixed_y or _stands(model, n, x, set(deck), links, fixed_y)]
    on_structure = _on_a_structure(model, deck, x, supports, links, fixed_y)

    lines = []                          # rule 2
    for n in supports:
        if lines and abs(x[n] - x[lines[-1][0]]) <= SUPPORT_X_TOLERANCE:
            lines[-1].append(n)
        else:
            lines.append([n])
    n_el = len(ends)
    whole = DeckLayout(tuple(deck), tuple(supports), ((x[deck[0]], x[deck[-1]]),),   # the track's ends are the span's
                       (_middle(deck, x, x[deck[0]], x[deck[-1]]),), (0,), ((x[deck[0]], x[deck[-1]]),),
                       (tuple(deck),), frozenset(), (), on_structure)
    if len(lines) < 2:
        return whole, set(supports)

    adjacent = [place[lines[k + 1][0]] - place[lines[k][-1]] == 1 for k in range(len(lines) - 1)]
    ground_line = [False] * len(lines)  # rule 3
    start = 0
    for k in range(1, len(lines) + 1):
        if k == len(lines) or not adjacent[k - 1]:
            if k - start >= 3:
                ground_line[start:k] = [True] * (k - start)
            start = k
    kind = ["deck"] * n_el              # per element: 'deck', 'ground' or 'joint'
    stiffness = _bending_stiffness(asm, chain, [x[c] - x[a] for a, c in ends])
    segments = []                       # (its left line, its elements, whether it is a span)
    for k in range(len(lines) - 1):
        a, b = lines[k][-1], lines[k + 1][0]
        elements = [e for e in range(n_el) if place[ends[e][0]] >= place[a] and place[ends[e][1]] <= place[b]]
        if ground_line[k] and ground_line[k + 1] and adjacent[k]:
            for e in elements:
                kind[e] = "ground"
            continue
        before = [e for e in range(n_el) if place[ends[e][1]] <= place[a]]
        after = [e for e in range(n_el) if place[ends[e][0]] >= place[b]]
        weak = []
        if before and after:            # rule 4
            beside = min(stiffness[before[-1]], stiffness[after[0]])
            weak = [e for e in elements if stiffness[e] < JOINT_STIFFNESS_SHARE * beside]
        for e in weak:
            kind[e] = "joint"
        segments.append((k, elements, not weak and x[b] - x[a] >= MIN_SPAN_LENGTH))

    on_line = {n: k for k, line in enumerate(lines) for n in line}
    deck_of = [-1] * n_el               # rule 6
    runs, current = [], None
    for e in range(n_el):
        if kind[e] != "deck":
            current = None
            continue
        if current is not None:
            joined = ends[e - 1][1] == ends[e][0]
            if not joined and ends[e - 1][1] in on_line and ends[e][0] in on_line:
                current = None          # two decks end on one support line
        if current is None:
            runs.append([])
            current = len(runs) - 1
        runs[current].append(e)
        deck_of[e] = current
    spans = [(lines[k][-1], lines[k + 1][0], deck_of[elements[0]])
             for k, elements, is_span in segments if is_span and elements]
    if not spans:                       # no stretch is a span (ground and joints only): as with < 2 supports
        return whole, set(supports)
    used = sorted({d for *_, d in spans})
    renumber = {d: j for j, d in enumerate(used)}
    deck_ends = tuple((x[ends[runs[d][0]][0]], x[ends[runs[d][-1]][1]]) for d in used)
    members = [{n for e in runs[d] for n in ends[e]} for d in used]
    on_deck = set().union(*members)
    piers = [n for (_, b, d), (a, _, e) in zip(spans, spans[1:]) if d == e for n in dict.fromkeys((b, a))]
    ground = frozenset(n for n in deck if n not in on_deck)
    return DeckLayout(tuple(deck), tuple(n for n in supports if n not in ground),
                      tuple((x[a], x[b]) for a, b, _ in spans),
                      tuple(_middle(deck, x, x[a], x[b]) for a, b, _ in spans),
                      tuple(renumber[d] for *_, d in spans), deck_ends,
                      tuple(tuple(n for n in deck if n in mine) for mine in members), ground, tuple(piers),
                      on_structure), set(supports)


def _middle(deck, x, a, b):
    """The node of ``deck`` nearest the middle of [a, b] (the first of two as near)."""
    return min(deck, key=lambda n: abs(x[n] - 0.5 * (a + b)))


def _links(model, track_elements):
    """``{node: set of nodes}`` tied to it by an element off the track (a model with
    equalDOF/rigidLink ties has no track: :class:`~vtsi.track.Track` refuses it)."""
    links = {}
    for etype, tags, *_ in model.build().blocks:
        for i, tag in enumerate(tags):
            if tag in track_elements:
                continue
            ends = [int(n) for n in etype.nodes[i]]
            for n in ends:
                links.setdefault(n, set()).update(m for m in ends if m != n)
    return links


def _stands(model, node, x, on_track, links, fixed_y):
    """Whether track node ``node`` stands on a vertical line or on a structure of its own that
    reaches a node with uy fixed (rule 1)."""
    nodes = model.nodes
    seen, stack = {node}, [node]                  # a vertical line (any height), off the track
    while stack:
        for m in links.get(stack.pop(), ()):
            if m in seen or m in on_track or abs(nodes[m][0] - x[node]) > SUPPORT_X_TOLERANCE:
                continue
            if m in fixed_y:
                return True
            seen.add(m)
            stack.append(m)
    level = nodes[node][1]

    def below(m):
        return nodes[m][1] < level - SUPPORT_X_TOLERANCE

    def under(m):
        return abs(nodes[m][0] - x[node]) <= SUPPORT_X_TOLERANCE and nodes[m][1] <= level + SUPPORT_X_TOLERANCE

    seen, stack = {node}, [(node, False)]         # a structure of its own below it
    while stack:
        here, levelled = stack.pop()
        for m in links.get(here, ()):
            if m in seen or m in on_track:
                continue
            # a pier cap at its level: level steps from a node already reached, within CAP_REACH of its x
            level_step = (here != node and not (below(m) or under(m)) and nodes[m][1] <= level + SUPPORT_X_TOLERANCE
                          and abs(nodes[m][0] - x[node]) <= CAP_REACH)
            if not (below(m) or under(m) or level_step):
                continue
            seen.add(m)
            if any(k in on_track and k != node and abs(x[k] - x[node]) > SUPPORT_X_TOLERANCE
                   for k in links.get(m, ())):
                continue                          # shared with another track node: not its own
            levelled = levelled or level_step     # past a level step, only a fixed node below it counts
            if m in fixed_y and (below(m) or not levelled):
                return True
            stack.append((m, levelled))
    return False


def _on_a_structure(model, deck, x, supports, links, fixed_y):
    """True when most of the track's other nodes stand on elements over another structure
    (a node at or below them, within SUPPORT_X_TOLERANCE of their x, off the track and not
    fixed; pads between coincident nodes too): a rail on its pads over the deck, whose
    outputs are the rail's, not the deck's."""
    on_track, supported = set(deck), set(supports)
    inner = [n for n in deck if n not in supported]
    under = [n for n in inner if any(m not in on_track and m not in fixed_y
                                     and abs(model.nodes[m][0] - x[n]) <= SUPPORT_X_TOLERANCE
                                     and model.nodes[m][1] <= model.nodes[n][1]
                                     for m in links.get(n, ()))]
    return len(inner) > 0 and 2 * len(under) > len(inner)


def _bending_stiffness(asm, elements, lengths):
    """(n_el,) a bending stiffness EI [N·m²] of each of the beams ``elements`` (tags; ``lengths``
    [m]), from its own stiffness: k_θθ L / 4 (exact for an Euler-Bernoulli beam, a little less
    with shear flexibility), the mean of its two ends."""
    out = np.zeros(len(elements))
    for e, tag in enumerate(elements):
        b, i = asm.element_location[tag]
        etype, _, coords, params, _ = asm.blocks[b]
        k = etype.stiffness(coords[i:i + 1], params[i:i + 1])[0]
        rz = [j * len(etype.node_dofs) + list(etype.node_dofs).index(2) for j in range(2)]
        out[e] = 0.5 * (k[rz[0], rz[0]] + k[rz[1], rz[1]]) * lengths[e] / 4.0
    return out


def _level_beams(model, asm, track_elements):
    """``{node: [(tag, other node), ...]}``: the 2-node elements with an rz dof off the track
    (``track_elements``) from each node to another at its level (within SUPPORT_X_TOLERANCE):
    beams that carry a deck on from a track node, rotationally continuous with it."""
    beams = {}
    for etype, tags, *_ in asm.blocks:
        if etype.n_nodes != 2 or 2 not in tuple(etype.node_dofs):
            continue
        for i, tag in enumerate(tags):
            a, b = (int(n) for n in etype.nodes[i])
            if int(tag) in track_elements or abs(model.nodes[a][1] - model.nodes[b][1]) > SUPPORT_X_TOLERANCE:
                continue
            beams.setdefault(a, []).append((int(tag), b))
            beams.setdefault(b, []).append((int(tag), a))
    return beams


def _beam_beyond(model, beams, node, outward, used=()):
    """(tag, other node) of the first beam of ``beams`` (:func:`_level_beams`), none of ``used``,
    from ``node`` to a node further out (``outward`` +1 right, -1 left), or None."""
    x = model.nodes[node][0]
    return next(((tag, other) for tag, other in beams.get(node, ())
                 if tag not in used and outward * (model.nodes[other][0] - x) > SUPPORT_X_TOLERANCE), None)


def _refuse_mid_deck_end(model, node, outward, beam):
    """A BridgeModelError when the deck goes on off the track beyond its unsupported end ``node``
    (``beam``: the horizontal beam off the track reaching further out from it, ``outward`` +1
    right, -1 left; None: nothing goes on, a free end)."""
    if beam is None:
        return
    tag, other = beam
    side = "last" if outward > 0 else "first"
    raise BridgeModelError(f"track: its {side} node {node} (x = {model.nodes[node][0]:g} m) carries no support, and "
                           f"the deck goes on beyond it off the track (element {tag} to node {other} at x = "
                           f"{model.nodes[other][0]:g} m): a track stopping mid-deck would read that end as a "
                           "support; run the track over the whole deck, or end it on a support")


def _refuse_span_beyond(model, asm, track, layout, beams):
    """A BridgeModelError when the track ends on a support of a continuous deck that goes on over
    a span off the track: the track's end node is a pier node (``pier_nodes``) of the layout of
    the track extended by the beams off it that carry on at its level from its ends (the same
    node, rotationally continuous): that span's deck ends there for the track's layout, read
    without the span (its L_Φ, its checks, the moment over that support)."""
    chains = []                        # the beams off the track beyond each end, outward
    for end, outward in ((layout.track_nodes[0], -1.0), (layout.track_nodes[-1], 1.0)):
        chain, node = {}, end          # (a dict: ordered, and a quick test of a tag in it)
        while (beam := _beam_beyond(model, beams, node, outward, chain)) is not None:
            chain[beam[0]] = beam[1]
            node = beam[1]
        chains.append(list(chain))
    if not any(chains):
        return
    whole, _ = _layout(model, asm, chains[0][::-1] + list(track.elements) + chains[1])
    for end, outward in ((layout.track_nodes[0], -1.0), (layout.track_nodes[-1], 1.0)):
        if end not in whole.pier_nodes:
            continue
        x_end = model.nodes[end][0]
        beyond = [k for k, (a, b) in enumerate(whole.span_ends)      # the spans beyond the support, off the track
                  if outward * ((a if outward > 0 else b) - x_end) >= -SUPPORT_X_TOLERANCE]
        k = beyond[0] if outward > 0 else beyond[-1]
        a, b = whole.span_ends[k]
        lo, hi = whole.deck_ends[whole.span_decks[k]]
        deck = set(whole.nodes_by_deck[whole.span_decks[k]])
        add = [tag for tag in chains[0][::-1] + chains[1] if all(int(n) in deck for n in _nodes(asm, tag))]
        tags = sorted(set(track.elements) | set(add))
        fix = (f"elements {tags[0]} to {tags[-1]}, -eleRange {tags[0]} {tags[-1]}"
               if tags == list(range(tags[0], tags[-1] + 1)) else
               f"add elements {', '.join(map(str, add[:3]))}{', ...' if len(add) > 3 else ''} ({len(add)})")
        raise BridgeModelError(f"track: its {'last' if outward > 0 else 'first'} node {end} (x = {x_end:g} m) is on "
                               f"a support of a continuous deck that goes on beyond it off the track: the deck's span "
                               f"of {b - a:g} m (x = {a:g} to {b:g} m) is not on the track, which would read that "
                               "support as the deck's end (its spans, L_Phi and the moment over the support); run "
                               f"the track over the whole deck (x = {lo:g} to {hi:g} m: {fix})")


def _nodes(asm, tag):
    """The nodes of element ``tag``."""
    b, i = asm.element_location[tag]
    return asm.blocks[b][0].nodes[i]
