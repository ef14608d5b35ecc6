"""The output places 'deck' and 'track' (vtsi.passage.PLACES): 'deck' is the track's nodes on a
deck (its spans and overhangs, vtsi.deck.deck_layout), 'track' every node of the track, the
approaches' too. Before, 'deck' was every node of the track: a viaduct with 20 m approach slabs
on ballast springs read its 'deck' acceleration 61.4 m/s² at the approach slab's free end (x =
-20 m), and the sweep's summary named that node, where the deck's peak is 1.194 m/s² (x = 47.5 m,
what the check reads). A bridge without approaches gives the same nodes and the same numbers
as before; a results file written when 'deck' held the approaches is not resumed into the new
nodes."""
import textwrap

import h5py
import numpy as np
import pytest

from vtsi.bridge_file import script_bridge
from vtsi.errors import SweepError
from vtsi.passage import DEFAULT_OUTPUTS, Output, PassageSettings
from vtsi.scene3d import _recorded_case
from vtsi.sweep import Sweep, beam_bridge

DECK, TRACK = list(range(6, 27)), list(range(1, 32))     # approaches_tcl's deck nodes (x = 5 ... 25 m), all

# two 15 m simply supported decks and a 0.6 m rail joint between them (x = 14.7 to 15.3 m): every
# track node is a deck's (the joint's ends are the decks' ends)
JOINT = """
model basic -ndm 2 -ndf 3
for {set i 0} {$i <= 10} {incr i} { node [expr {$i + 1}] [expr {$i * 1.47}] 0.0 }
for {set i 0} {$i <= 10} {incr i} { node [expr {$i + 12}] [expr {15.3 + $i * 1.47}] 0.0 }
geomTransf Linear 1
for {set i 1} {$i <= 10} {incr i} {
  element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.9 1 -mass 15000.0 -cMass
}
element elasticBeamColumn 11 11 12 0.0077 2.1e11 3.05e-5 1 -mass 60.0 -cMass
for {set i 12} {$i <= 21} {incr i} {
  element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.9 1 -mass 15000.0 -cMass
}
fix 1 1 1 0
fix 11 0 1 0
fix 12 1 1 0
fix 22 0 1 0
track 1 -eleRange 1 21
"""
FAST = PassageSettings(dt=1e-3, damping=0.01)


def _script(tmp_path, text, name):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return script_bridge(path)


def test_the_deck_place_holds_the_decks_nodes_and_the_track_place_every_node(tmp_path, approaches_tcl):
    """On a deck with approaches on springs the default outputs read the deck's nodes, the end
    rotations its supports (not the approaches' springs), and the sweep's summary and critical
    cases name a deck node; an output at 'track' holds the approaches' nodes too, with the same
    values at the deck's nodes."""
    bridge = _script(tmp_path, approaches_tcl, "approaches.tcl")
    outputs = DEFAULT_OUTPUTS + (Output("track_acceleration", "accel", nodes="track", cutoff="en"),
                                 Output("track_deflection", "disp", nodes="track"))
    sweep = Sweep(bridge, ["HSLM-A1"], "300", FAST, outputs=outputs)
    runner = sweep.runner
    assert runner.deck_nodes == DECK and runner.track_nodes == TRACK and runner.support_nodes == [6, 26]
    results = sweep.run(tmp_path / "a.h5", workers=1, progress=False)
    with h5py.File(tmp_path / "a.h5", "r") as f:
        for name in ("deflection", "acceleration"):
            assert f[f"outputs/{name}/columns"][()].tolist() == DECK
        assert f["outputs/end_rotation/columns"][()].tolist() == [6, 26]
        for name in ("track_acceleration", "track_deflection"):
            assert f[f"outputs/{name}/columns"][()].tolist() == TRACK
        assert f["bridge/deck_nodes"][()].tolist() == TRACK            # the record: every track node, as before
        np.testing.assert_array_equal(f["bridge/deck_ends_m"][()], [[5.0, 25.0]])
    case = results.case("HSLM-A1", 300.0)
    on_deck = np.isin(case["track_acceleration"]["columns"], DECK)
    for deck, track in (("acceleration", "track_acceleration"), ("deflection", "track_deflection")):
        np.testing.assert_allclose(case[deck]["envelope"], case[track]["envelope"][:, on_deck], rtol=1e-12, atol=0)
    ground = case["track_acceleration"]["envelope"][2, ~on_deck]
    assert len(ground) == 10 and np.all(ground > 0)                 # the approaches move, and are read there
    worst = results.critical("acceleration_absmax")
    peak = case["track_acceleration"]["envelope"][2, on_deck]
    assert worst["where"] == DECK[int(np.argmax(peak))] and worst["value"] == pytest.approx(peak.max(), rel=1e-12)
    for q in ("deflection_min", "deflection_max", "acceleration_absmax", "end_rotation_min", "end_rotation_max"):
        assert results.critical(q)["where"] in DECK
    row = next(line for line in results.summary().splitlines() if line.startswith("acceleration_absmax"))
    assert f"node {worst['where']} " in row


@pytest.mark.parametrize("make", ["beam", "joint"])
def test_a_bridge_without_approaches_reads_every_track_node_as_before(tmp_path, make):
    """Without approaches every track node is a deck's (a continuous beam; two decks with a rail
    joint between them): 'deck' holds what 'track' holds, what 'deck' held before, and the
    envelopes are bitwise the same."""
    bridge = beam_bridge([15.0, 20.0], 3.5e10, 1.9, 15000.0) if make == "beam" else _script(tmp_path, JOINT, "j.tcl")
    outputs = (Output("deflection", "disp"), Output("track_deflection", "disp", nodes="track"),
               Output("acceleration", "accel", cutoff="en"),
               Output("track_acceleration", "accel", nodes="track", cutoff="en"),
               Output("rotation", "rotation", nodes="supports"))
    sweep = Sweep(bridge, ["HSLM-A1"], "250,300", FAST, outputs=outputs)
    runner = sweep.runner
    assert runner.deck_nodes == runner.track_nodes and not runner.ground_nodes
    results = sweep.run(None, workers=1)
    for speed in (250.0, 300.0):
        case = results.case("HSLM-A1", speed)
        for deck, track in (("deflection", "track_deflection"), ("acceleration", "track_acceleration")):
            np.testing.assert_array_equal(case[deck]["columns"], case[track]["columns"])
            np.testing.assert_array_equal(case[deck]["envelope"], case[track]["envelope"])
    supports = [n for n in runner.track_nodes if runner.model.fixities.get(n, (0, 0, 0))[1]]
    assert results.case("HSLM-A1", 250.0)["rotation"]["columns"].tolist() == supports


def test_a_results_file_whose_deck_held_the_approaches_is_not_resumed(tmp_path, approaches_tcl):
    """A results file of the same sweep written when 'deck' was every node of the track (its
    identity names the place, 'deck', not the nodes) is refused, naming the file, the output and
    both sets of nodes: resumed, its cases would hold other columns than the new ones."""
    bridge = _script(tmp_path, approaches_tcl, "approaches.tcl")
    outputs = (Output("deflection", "disp"),)
    path = tmp_path / "old.h5"
    sweep = Sweep(bridge, ["HSLM-A1"], "250,300", FAST, outputs=outputs)
    sweep.run(path, workers=1, progress=False)
    with h5py.File(path, "a") as f:              # as an older vtsi wrote it: 'deck' held every track node
        del f["outputs/deflection/columns"]
        f["outputs/deflection/columns"] = np.array(TRACK, dtype=np.int64)
    with pytest.raises(SweepError, match=rf"^results file {path}: its output 'deflection' at 'deck' holds 31 nodes "
                                         r"\(x = 0 to 30 m\), this vtsi's 'deck' 21 nodes \(x = 5 to 25 m\): the file "
                                         r"was written by a vtsi whose place held other nodes"):
        sweep.run(path, workers=1, progress=False, resume=True)


def test_the_scene_draws_the_deck_nodes_of_the_recorded_history(tmp_path, approaches_tcl):
    """The scene takes the x of the deck displacement history's own nodes (the decks', x = 5 to
    25 m here) from the bridge record, which holds every node of the track."""
    bridge = _script(tmp_path, approaches_tcl, "approaches.tcl")
    path = tmp_path / "s.h5"
    sweep = Sweep(bridge, ["HSLM-A1"], "300", FAST)
    sweep.run(path, workers=1, progress=False)
    sweep.record_histories(path, [("HSLM-A1", 300.0, -1)])
    _, _, _, _, history, scene = _recorded_case(path, "HSLM-A1", 300.0, -1)
    assert history["deck_displacement"][2].tolist() == DECK
    np.testing.assert_array_equal(scene.deck_x, np.arange(5.0, 26.0))
