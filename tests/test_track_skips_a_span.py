"""A track that leaves out a span of a continuous deck (vtsi.deck, rule 7; docs/sweeps.md "Track
ends"). A probe's viaduct of 25 + 32 + 25 m continuous over two piers, its track ending on pier 2
(x = 57 m), swept without a word: '1 deck; spans 25 + 32 m; L_Phi 34.2 m' (35.53 m over the
three spans), its last span never checked, its end rotation read over the pier. The track's end
on a support over which the deck's beam goes on (the same node, off the track) over a span is
refused; a track end at a deck's end stays as it was: decks on a shared pier, approaches and
joints off the track, an overhang off the track."""
import textwrap

import pytest

from vtsi.models.bridges import continuous_beam
from vtsi import Model
from vtsi.damping import rayleigh_damping
from vtsi.deck import deck_layout
from vtsi.errors import BridgeModelError, BridgeSweepError
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.sweep import Sweep, SweepBridge
from vtsi.track import Track

SPANS = [10.0, 10.0]     # a beam continuous over x = 0, 10, 20 m: nodes 1-21 and elements 1-20, 1 m each


def _two_spans():
    model = Model()
    beam = continuous_beam(model, SPANS, 10, 3.5e10, 1.0, 15000.0, A=5.0)
    return model, list(beam.elements)


def _refusal(side, node, x, span):
    """The refusal's words: the track's end, the span off the track, and the remedy."""
    return (rf"track: its {side} node {node} \(x = {x} m\) is on a support of a continuous deck that goes on beyond "
            rf"it off the track: the deck's span of 10 m \(x = {span} m\) is not on the track, which would read "
            r"that support as the deck's end \(its spans, L_Phi and the moment over the support\); run the track "
            r"over the whole deck \(x = 0 to 20 m: elements 1 to 20, -eleRange 1 20\)$")


@pytest.mark.parametrize("first, last, side, node, x, span", [
    (0, 10, "last", 11, 10, "10 to 20"),            # the track on span 1: it ends on the pier
    (10, 20, "first", 11, 10, "0 to 10"),           # on span 2: it begins on the pier
], ids=["span_1", "span_2"])
def test_a_track_on_one_span_of_a_continuous_beam_is_refused(first, last, side, node, x, span):
    """The track over one span of two: refused by the layout, by a sweep's passages and by the
    default damping read along it (each reads the layout), naming the end, the span left out and
    the elements of the whole deck. Over the whole beam: two spans of one deck, node 11 its pier."""
    model, elements = _two_spans()
    track = Track(model, elements[first:last])
    with pytest.raises(BridgeModelError, match=_refusal(side, node, x, span)):
        deck_layout(model, track)
    with pytest.raises(BridgeModelError, match=_refusal(side, node, x, span)):
        PassageRunner(model, elements[first:last], PassageSettings(), outputs=())
    with pytest.raises(BridgeModelError, match=_refusal(side, node, x, span)):
        rayleigh_damping(model, 0.01, track=elements[first:last])
    whole = deck_layout(model, Track(model, elements))
    assert whole.span_lengths == SPANS and whole.pier_nodes == (11,) and whole.deck_ends == ((0.0, 20.0),)


def test_a_sweep_refuses_a_track_on_one_span():
    """A sweep of the track over span 1 is refused when it is made (a BridgeSweepError)."""
    model, elements = _two_spans()
    bridge = SweepBridge(model, elements[:10], {"kind": "beam", "spans_m": SPANS})
    with pytest.raises(BridgeSweepError, match=_refusal("last", 11, 10, "10 to 20")[:-1]):
        Sweep(bridge, ["HSLM-A1"], "300", PassageSettings(dt=2e-3, damping=0.01))


def test_the_command_line_names_the_script_and_the_span_left_out(tmp_path, capsys):
    """``vtsi sweep`` of a Tcl script of the beam with 'track 1 -eleRange 1 10': exit 2, one line
    naming the bridge file, the end over the pier and the span off the track, nothing written."""
    pytest.importorskip("tkinter")
    from vtsi.__main__ import main

    path = tmp_path / "skip.tcl"
    path.write_text(textwrap.dedent("""
        model basic -ndm 2 -ndf 3
        for {set i 0} {$i <= 20} {incr i} { node [expr {$i + 1}] [expr {$i * 1.0}] 0.0 }
        fix 1 1 1 0
        fix 11 0 1 0
        fix 21 0 1 0
        geomTransf Linear 1
        for {set i 1} {$i <= 20} {incr i} { element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.0 1 -mass 15000.0 -cMass }
        track 1 -eleRange 1 10
        """))
    status = main(["sweep", str(path), "--trains", "HSLM-A1", "--speeds", "300", "--workers", "1",
                   "--out", str(tmp_path / "out.h5")])
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert status == 2 and len(lines) == 1, lines
    assert lines[0].startswith(f"vtsi sweep: bridge file {path}: track: its last node 11 (x = 10 m) is on a support "
                               "of a continuous deck that goes on beyond it off the track: the deck's span of 10 m "
                               "(x = 10 to 20 m) is not on the track"), lines[0]
    assert not (tmp_path / "out.h5").exists()


def test_a_track_ending_on_the_first_of_two_close_bearings_is_refused():
    """A continuous deck over two bearings 0.5 m apart on one pier (x = 10 and 10.5 m, one deck:
    the stretch between them is no span): the track ending on the first still leaves out the
    deck's span beyond the second."""
    model = Model()
    for i in range(22):
        model.node(i + 1, min(i, 10) + 0.5 * (i > 10) + max(i - 11, 0) * 1.0, 0.0)
    model.fix(1, 1, 1, 0)
    for n in (11, 12, 22):
        model.fix(n, 0, 1, 0)
    for e in range(1, 22):
        model.element("elasticBeamColumn", e, (e, e + 1), A=5.0, E=3.5e10, I=1.0, rho=15000.0, cmass=1)
    with pytest.raises(BridgeModelError, match=r"its last node 11 \(x = 10 m\) .* the deck's span of 10 m "
                                               r"\(x = 10.5 to 20.5 m\) is not on the track"):
        deck_layout(model, Track(model, list(range(1, 11))))


def test_a_track_ending_at_a_decks_end_stays_accepted(tmp_path, approaches_tcl):
    """What lies beyond a track's end on a support and is no span of its deck is not refused:
    another deck on the same pier (its own end node), approaches on springs (ground), a rail
    joint to the next deck, an overhang of the deck beyond its end bearing."""
    from vtsi.bridge_file import script_bridge

    def layout(text, name):
        path = tmp_path / name
        path.write_text(textwrap.dedent(text))
        bridge = script_bridge(path)
        return deck_layout(bridge.model, Track(bridge.model, bridge.track_elements))

    two_decks = """
        model basic -ndm 2 -ndf 3
        for {set i 0} {$i <= 10} {incr i} { node [expr {$i + 1}] [expr {$i * 1.5}] 0.0 }
        for {set i 0} {$i <= 10} {incr i} { node [expr {$i + 12}] [expr {15.0 + $i * 1.5}] 0.0 }
        fix 1 1 1 0
        fix 11 0 1 0
        fix 12 1 1 0
        fix 22 0 1 0
        geomTransf Linear 1
        for {set i 1} {$i <= 10} {incr i} { element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.0 1 -mass 15000.0 }
        for {set i 12} {$i <= 21} {incr i} { element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.0 1 -mass 15000.0 }
        """
    assert layout(two_decks + "track 1 -eleRange 1 10\n", "decks.tcl").span_lengths == [15.0]
    joint = two_decks.replace("node [expr {$i + 12}] [expr {15.0", "node [expr {$i + 12}] [expr {15.6") + \
        "element elasticBeamColumn 11 11 12 0.0154 2.1e11 6.1e-5 1 -mass 120.0\n"
    assert layout(joint + "track 1 -eleRange 1 10\n", "joint.tcl").span_lengths == [15.0]
    approaches = layout(approaches_tcl.replace("track 1 -eleRange 1 30", "track 1 -eleRange 6 25"), "approaches.tcl")
    assert approaches.span_lengths == [20.0] and approaches.ground_nodes == frozenset()
    overhang = """
        model basic -ndm 2 -ndf 3
        for {set i 0} {$i <= 12} {incr i} { node [expr {$i + 1}] [expr {$i * 1.0}] 0.0 }
        fix 1 1 1 0
        fix 11 0 1 0
        geomTransf Linear 1
        for {set i 1} {$i <= 12} {incr i} { element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.0 1 -mass 15000.0 }
        track 1 -eleRange 1 10
        """
    assert layout(overhang, "overhang.tcl").span_lengths == [10.0]
