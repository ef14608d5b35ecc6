"""Where HSLM-B loads a bridge (EN 1991-2 6.4.6.1.1, Table 6.4, Annex E.2): a simply supported span
of 1 m <= L < 7 m, with the N and d of that L (Figure 6.13); a continuous deck takes HSLM-A1 to A10.
vtsi built HSLM-B from the first span and ran it on any bridge: a continuous 5 + 6.5 m deck got
the 5 m span's HSLM-B and the check said nothing (an audit of the EN rules). Now a sweep refuses it,
in one line naming the deck and pointing to HSLM-A, on a continuous deck and on several decks
unless they are all simply supported spans of one length under 7 m (each then takes that L's
HSLM-B); one simply supported span under 7 m takes it as before.

The decks: Euler-Bernoulli spans of 35 GPa, 15 t/m, I for f₁ = 20 Hz on a 5 m span, each deck
on its own pin and roller, the next one's first node at the same x (two decks ending on one pier).
"""
import numpy as np
import pytest

import vtsi
from vtsi.__main__ import main
from vtsi.check import check
from vtsi.codes.en1991_2 import hslm_b_refusal
from vtsi.errors import SweepError
from vtsi.models.bridges import continuous_beam
from vtsi.passage import Output, PassageSettings
from vtsi.sweep import Sweep, SweepBridge, beam_bridge

E, MU = 3.5e10, 15000.0
I = MU * (2 * np.pi * 20.0 * (5.0 / np.pi) ** 2) ** 2 / E       # f₁ = 20 Hz on 5 m
RULE = ("HSLM-B loads simply supported spans of 1 m <= L < 7 m only, each with the N and d of its L (EN 1991-2 "
        "6.4.6.1.1, Table 6.4): ")
FAST = PassageSettings(damping=0.02, bridge="modal")
OUTPUTS = [Output("deflection", "disp"), Output("acceleration", "accel", cutoff="en")]


def decks(spans):
    """A SweepBridge of simply supported decks of ``spans`` [m] side by side, 4 elements each."""
    model, elements, node, tag, x0 = vtsi.Model(), [], 1, 1, 0.0
    for L in spans:
        beam = continuous_beam(model, [L], 4, E, I, MU, x0=x0, first_node=node, first_element=tag)
        elements += list(beam.elements)
        node, tag, x0 = node + 5, tag + 4, x0 + L
    return SweepBridge(model, elements, {"kind": "decks", "spans_m": list(spans)})


def refusal(bridge, train="HSLM-B"):
    with pytest.raises(SweepError) as info:
        Sweep(bridge, [train], "300", FAST, outputs=OUTPUTS)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_a_continuous_deck_refuses_hslm_b():
    """5 + 6.5 m continuous (the audit's deck), by either name: refused, naming the deck and its
    spans and HSLM-A1 to A10 (it was run as the 5 m span's HSLM-B, d = 3.1667 m, N = 13)."""
    bridge = beam_bridge([5.0, 6.5], E, I, MU, elements_per_span=4)
    for name in ("HSLM-B", "b"):
        assert refusal(bridge, name) == (f"sweep: {RULE}the deck is continuous (spans 5 + 6.5 m); take HSLM-A1 to "
                                         "A10 (--trains HSLM-A), as Table 6.4 asks of a continuous deck")
    Sweep(bridge, ["HSLM-A1"], "300", FAST, outputs=OUTPUTS)      # HSLM-A is built on it as before


def test_decks_of_one_span_length_under_7_m_take_its_hslm_b():
    """One 5 m span, and two 5 m decks on one pier: HSLM-B of L = 5 m, N = 13 forces d = 3.1667 m
    apart (Figure 6.13 as docs/trains.md reads it: N from 20 at 1 m to 10 at 7 m, rounded; d from
    2.5 to 3.5 m, linear: 2.5 + 4/6)."""
    for bridge in (beam_bridge([5.0], E, I, MU, elements_per_span=4), decks([5.0, 5.0])):
        train = Sweep(bridge, ["HSLM-B"], "300", FAST, outputs=OUTPUTS).runner.train("HSLM-B", 80.0)
        assert train.n_wheels == 13 and train.characteristic_length == pytest.approx(2.5 + 4 / 6, rel=1e-12)
        assert np.allclose(np.diff(train.wheel_offsets), 2.5 + 4 / 6, rtol=1e-12)


@pytest.mark.parametrize("spans, why", [
    ([5.0, 6.0], "the decks' spans differ (5, 6 m) and a sweep runs one HSLM-B; check each deck as a bridge of its "
                 "own"),
    ([5.0, 8.0], "the span of deck 2 is 8 m; take HSLM-A1 to A10 (--trains HSLM-A), or the critical ones of Annex E "
                 "for a simply supported span; check the decks under 7 m as bridges of their own with HSLM-B"),
    ([9.5], "the span of the deck is 9.5 m; take HSLM-A1 to A10 (--trains HSLM-A), or the critical ones of Annex E "
            "for a simply supported span"),
])
def test_other_decks_refuse_hslm_b(spans, why):
    """Decks of two lengths (one HSLM-B cannot be both spans'), a deck of 7 m or more beside a short
    one, one span of 9.5 m (it was the catalogue's 'outside the range of Figure 6.13'): refused."""
    bridge = decks(spans) if len(spans) > 1 else beam_bridge(spans, E, I, MU, elements_per_span=4)
    assert refusal(bridge) == f"sweep: {RULE}{why}"
    assert hslm_b_refusal([[L] for L in spans]) == RULE + why


def test_the_command_line_refuses_hslm_b_on_a_continuous_deck(tmp_path, beam_toml, capsys):
    """`vtsi sweep` and `vtsi check` with --trains B on a 5 + 6.5 m deck: exit 2, one line, no file."""
    bridge = beam_toml(tmp_path / "two.toml", {"spans_m": [5.0, 6.5], "f1_Hz": 20.0, "mu_kg_m": 8000.0})
    for command, extra in (("sweep", []), ("check", ["--bridge-type", "reinforced_concrete"])):
        out = tmp_path / f"{command}.h5"
        status = main([command, str(bridge), "--trains", "B", "--speeds", "144:150:2", "--out", str(out), "--quiet",
                       *extra])
        err = capsys.readouterr().err.strip().splitlines()
        assert status == 2 and len(err) == 1 and not out.exists()
        assert err[0] == (f"vtsi {command}: {RULE}the deck is continuous (spans 5 + 6.5 m); take HSLM-A1 to A10 "
                          "(--trains HSLM-A), as Table 6.4 asks of a continuous deck")


def test_the_check_asks_for_hslm_b_on_short_simply_supported_decks():
    """Two 5 m decks swept with HSLM-A1 only: the deck acceleration's note says HSLM-B checks them
    (it said so for one span only), and not the ten-HSLM-A note of a continuous deck; decks of 5
    and 6 m, which one sweep's HSLM-B cannot load, are to be checked as bridges of their own."""
    def note(spans):
        sweep = Sweep(decks(spans), ["HSLM-A1"], "300", FAST, outputs=OUTPUTS)
        return check(sweep.run(None, workers=1, progress=False)).row("deck_acceleration").note
    said = ("EN 1991-2 6.4.6.1.1: a simply supported span under 7 m is checked with HSLM-B, which this sweep does not "
            "hold")
    same = note([5.0, 5.0])
    assert f"; {said};" in same + ";" and "HSLM-A is its ten trains" not in same
    assert (f"; {said} (a sweep runs one HSLM-B on decks of one span length under 7 m only: check decks 1, 2 as "
            "bridges of their own)") in note([5.0, 6.0])


def test_an_older_results_file_with_hslm_b_on_a_continuous_deck_is_told(monkeypatch):
    """A results file of an older vtsi, which ran HSLM-B on a continuous deck (built from its first
    span; made here by lifting the refusal): the check says HSLM-B is not a load model of that
    bridge, and why, in the deck acceleration's note."""
    monkeypatch.setattr("vtsi.passage.hslm_b_refusal", lambda decks: "")
    sweep = Sweep(beam_bridge([5.0, 6.5], E, I, MU, elements_per_span=4), ["HSLM-B"], "300", FAST, outputs=OUTPUTS)
    results = sweep.run(None, workers=1, progress=False)
    monkeypatch.undo()
    note = check(results).row("deck_acceleration").note
    assert (f"; HSLM-B is not a load model of this bridge: {RULE}the deck is continuous (spans 5 + 6.5 m); take "
            "HSLM-A1 to A10 (--trains HSLM-A), as Table 6.4 asks of a continuous deck") in note
