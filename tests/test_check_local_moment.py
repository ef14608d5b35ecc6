"""Whose bending moment the check's moment rows read (docs/check.md, "Whose moment the moment
rows read"): on a truss whose bottom chord carries the track, the track elements' moment is the
chord's own bending between the panel points, a few % of the span's, so the moment rows are not
checked and say why, with the share against the span's free-body moment worked out here by hand
(M = R x − Σ P (x − x_P) over LM71's positions); a beam deck, simply supported or continuous,
gives the rows it gave before, to the last bit."""
import math
from dataclasses import asdict

import numpy as np
import pytest

import vtsi
import vtsi.check as check_module
from vtsi.check import LOCAL_MOMENT_SHARE, MAX, check, free_body_moment, moment_shares
from vtsi.influence import LM71_AXLE, LM71_SPACING, LM71_UDL
from vtsi.models.bridges import continuous_beam
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep, SweepBridge, beam_bridge

MODAL = PassageSettings(bridge="modal", dt=2e-3, damping=0.01)
PANEL, HEIGHT = 5.0, 6.0                      # [m] a Warren truss's panels and depth
MOMENT_ROWS = ("dynamic_increment_moment", "dynamic_vs_lm71_moment", "dynamic_increment_support_moment",
               "dynamic_vs_lm71_support_moment")


def warren_truss(model, spans, first_node=1, first_element=1, x0=0.0):
    """A steel Warren truss deck over ``spans`` [m] (multiples of the 5 m panel), supported at its
    bottom chord's nodes at each span's ends (pin, then rollers): the bottom chord carries the
    track in elements of half a panel (2.5 m, 8 t/m), the top chord 6 m above its panels' middles
    (beams), the diagonals ``truss`` bars. Returns the bottom chord's element tags."""
    n_panels = round(sum(spans) / PANEL)
    bottom = list(range(first_node, first_node + 2 * n_panels + 1))
    top = list(range(first_node + 1000, first_node + 1000 + n_panels))
    for k, tag in enumerate(bottom):
        model.node(tag, x0 + 0.5 * PANEL * k, 0.0)
    for k, tag in enumerate(top):
        model.node(tag, x0 + PANEL * (k + 0.5), HEIGHT)
    ends = np.cumsum([0.0] + list(spans))
    for j, x in enumerate(ends):
        model.fix(bottom[round(2 * x / PANEL)], 1 if j == 0 else 0, 1, 0)
    chord, tag = [], first_element
    for a, b in zip(bottom[:-1], bottom[1:]):
        model.element("elasticBeamColumn", tag, (a, b), A=0.08, E=2.1e11, I=0.02, rho=8000.0)
        chord.append(tag)
        tag += 1
    for a, b in zip(top[:-1], top[1:]):
        model.element("elasticBeamColumn", tag, (a, b), A=0.10, E=2.1e11, I=0.02, rho=785.0)
        tag += 1
    for k, t in enumerate(top):
        for b in (bottom[2 * k], bottom[2 * k + 2]):
            model.element("truss", tag, (b, t), A=0.04, E=2.1e11, rho=314.0)
            tag += 1
    return chord


def truss_bridge(spans):
    model = vtsi.Model()
    return SweepBridge(model, warren_truss(model, spans), {"kind": "Warren truss"})


def free_body_by_hand(L, x):
    """LM71's largest sagging moment [N·m] at x of a simply supported span L from its free body,
    M = R x − Σ P (x − x_P) (the 80 kN/m as loads q ds), over the axles' centre c every 1 mm
    (and at x ± 0.8 m, where an axle stands on x): R and the moment of the loads left of x in
    closed form for each c."""
    P, q, reach = LM71_AXLE, LM71_UDL, 1.5 * LM71_SPACING + 0.8
    c = np.union1d(np.arange(-3200, round(1e3 * L) + 3201) / 1e3, [x - 0.8, x + 0.8])
    R = np.zeros_like(c)
    left = np.zeros_like(c)
    for o in LM71_SPACING * np.array([-1.5, -0.5, 0.5, 1.5]):
        on = (c + o >= 0.0) & (c + o <= L)
        R += np.where(on, P * (L - (c + o)) / L, 0.0)
        left += np.where(on & (c + o < x), P * (x - (c + o)), 0.0)
    for s0, s1 in ((np.zeros_like(c), np.clip(c - reach, 0.0, L)), (np.clip(c + reach, 0.0, L), np.full_like(c, L))):
        R += q * ((L - s0) ** 2 - (L - s1) ** 2) / (2 * L)                        # ∫ q (L − s) / L ds
        upto = np.minimum(s1, x)
        left += np.where(s0 < x, q * ((x - s0) ** 2 - (x - upto) ** 2) / 2, 0.0)   # ∫ q (x − s) ds, s < x
    return float(np.max(R * x - left))


def test_free_body_moment_is_the_hand_free_body():
    """The span's free-body moment under LM71 at mid-span and off it, against the hand scan;
    SW/0's at mid-span of 20 m against its closed form q (L²/8 − 2 · 2.5²/4) (tests/test_sw0.py)."""
    for L, x in ((40.0, 20.0), (40.0, 12.5), (20.0, 10.0)):
        assert free_body_moment(0.0, L, x, "LM71") == pytest.approx(free_body_by_hand(L, x), rel=1e-9)
    assert free_body_moment(5.0, 45.0, 25.0, "LM71") == pytest.approx(free_body_by_hand(40.0, 20.0), rel=1e-9)
    assert free_body_moment(0.0, 20.0, 10.0, "SW/0") == pytest.approx(133e3 * (20.0 ** 2 / 8 - 2 * 2.5 ** 2 / 4),
                                                                      rel=1e-9)


@pytest.fixture(scope="module")
def truss_results():
    return Sweep(truss_bridge([40.0]), ["HSLM-A1", "ICE3"], "250,300", MODAL).run(None, workers=1, progress=False)


def test_a_truss_chords_moment_rows_are_not_checked(truss_results, monkeypatch):
    """The 40 m Warren truss: its chord carries 2 % of the span's moment at mid-span (a panel
    point), far below LOCAL_MOMENT_SHARE: both moment rows keep their values, not checked (no
    reference, no 'governs'), their notes giving the share, the chord's and the span's moments;
    the deflection and acceleration rows are those of the rule switched off."""
    results = truss_results
    bridge = results.bridge()
    columns = list(results.column_envelopes("bending_moment")[1])
    node = int(bridge["midspan_nodes"][0])
    assert dict(zip(bridge["deck_nodes"].tolist(), bridge["deck_x_m"].tolist()))[node] == 20.0
    track = results.static("bending_moment").lm71[MAX, columns.index(node)]
    span = free_body_by_hand(40.0, 20.0)
    share = track / span
    assert 0.005 < share < 0.05 < LOCAL_MOMENT_SHARE                      # the chord's own bending
    found = moment_shares(results, ["bending_moment"], bridge)
    assert found.share[0] == pytest.approx(share, rel=1e-9) and found.models[0] == "LM71"
    rows = {r.criterion: r for r in check(results).rows}
    said = f"span 1: {100 * share:.3g} %, {track / 1e3:.4g} of {span / 1e3:.5g} kN m under LM71"
    for key in ("dynamic_increment_moment", "dynamic_vs_lm71_moment"):
        row = rows[key]
        assert row.status == "info" and np.isfinite(row.value) and said in row.note, row
        assert "not checked: the track elements carry less than 10 % of the span's bending moment" in row.note
    versus = rows["dynamic_vs_lm71_moment"]
    assert math.isnan(versus.limit) and math.isnan(versus.utilisation) and "governs" not in versus.note
    monkeypatch.setattr(check_module, "LOCAL_MOMENT_SHARE", 0.0)           # the rule off: the rows as before
    before = {r.criterion: r for r in check(results).rows}
    assert before["dynamic_vs_lm71_moment"].limit == 1.0 and "not checked" not in before["dynamic_vs_lm71_moment"].note
    assert versus.value == before["dynamic_vs_lm71_moment"].value
    for key in set(rows) - set(MOMENT_ROWS):
        assert repr(asdict(rows[key])) == repr(asdict(before[key]))          # NaN-safe
    assert "dynamic_vs_lm71_moment" in check(results).text() and "ref. 1" not in [
        line for line in check(results).text().splitlines() if line.startswith("dynamic_vs_lm71_moment")]


def test_a_continuous_truss_reads_its_support_rows_as_local():
    """A 2 × 40 m continuous truss: the chord's hogging moment over the middle support is local
    too (the spans beside it read 2 % each): the support rows not checked, naming both spans."""
    results = Sweep(truss_bridge([40.0, 40.0]), ["HSLM-A1"], "300", MODAL).run(None, workers=1, progress=False)
    shares = moment_shares(results, ["bending_moment", "support_moment"], results.bridge())
    assert np.all(shares.share < 0.05) and np.all(shares.share > 0.0)
    rows = {r.criterion: r for r in check(results).rows}
    for key in MOMENT_ROWS:
        assert "not checked: the track elements carry less than 10 %" in rows[key].note, key
    assert "at the middles of the spans beside the support (span 1: " in rows["dynamic_vs_lm71_support_moment"].note
    assert "span 2: " in rows["dynamic_vs_lm71_support_moment"].note
    assert math.isnan(rows["dynamic_vs_lm71_support_moment"].limit)


def test_a_beam_deck_beside_a_truss_is_read_alone():
    """A 40 m truss and a 20 m beam deck ending on one pier: the mid-span moment rows read the
    beam's span (its share 1) and say that the truss span is not read, and why."""
    model = vtsi.Model()
    chord = warren_truss(model, [40.0])
    beam = continuous_beam(model, [20.0], 10, 3.5e10, 1.5, 18000.0, x0=40.0, first_node=3001, first_element=3001)
    results = Sweep(SweepBridge(model, chord + beam.elements, {"kind": "truss and beam"}), ["HSLM-A1"], "300",
                    MODAL).run(None, workers=1, progress=False)
    shares = moment_shares(results, ["bending_moment"], results.bridge())
    assert shares.share[0] < 0.05 and shares.share[1] == pytest.approx(1.0, rel=1e-6)
    rows = {r.criterion: r for r in check(results).rows}
    for key in ("dynamic_increment_moment", "dynamic_vs_lm71_moment"):
        assert rows[key].where.startswith("node 3006 ") and "; span 1 not read: the track elements carry" in \
            rows[key].note and "not checked" not in rows[key].note
    assert rows["dynamic_vs_lm71_moment"].limit == 1.0


SW0_MID_SPAN_20 = 133e3 * (20.0 ** 2 / 8 - 2 * 2.5 ** 2 / 4)   # [N·m] SW/0 at mid-span of 20 m (tests/test_sw0.py)


@pytest.mark.parametrize("spans", [[20.0], [20.0, 20.0]])
def test_beam_decks_keep_their_rows(spans, monkeypatch):
    """A simply supported 20 m beam (its share 1 under LM71: the track is the span) and a 2 × 20
    m continuous one (under SW/0, its static reference at mid-span, 4718.6 of 6234.4 kN m, 0.76:
    continuity takes the rest to the support): every row, the support rows too, as with the rule
    switched off."""
    results = Sweep(beam_bridge(spans, 3.5e10, 1.5, 18000.0, elements_per_span=10), ["HSLM-A1", "ICE3"], "250,300",
                    MODAL).run(None, workers=1, progress=False)
    shares = moment_shares(results, ["bending_moment"], results.bridge())
    if len(spans) == 1:
        assert shares.models[0] == "LM71" and shares.share[0] == pytest.approx(1.0, rel=1e-9)
        assert shares.free_body[0] == pytest.approx(free_body_by_hand(20.0, 10.0), rel=1e-9)
    else:
        track = results.static("bending_moment").sw0[MAX]
        assert list(shares.models) == ["SW/0", "SW/0"] and shares.free_body == pytest.approx(SW0_MID_SPAN_20, rel=1e-9)
        assert shares.share == pytest.approx(track / SW0_MID_SPAN_20, rel=1e-12) and 0.75 < shares.share[0] < 0.77
    rows = check(results).rows
    monkeypatch.setattr(check_module, "LOCAL_MOMENT_SHARE", 0.0)
    assert repr(rows) == repr(check(results).rows)                           # NaN-safe
    criteria = {r.criterion for r in rows}
    assert {"dynamic_increment_moment", "dynamic_vs_lm71_moment"} <= criteria
    assert (len(spans) > 1) == ("dynamic_vs_lm71_support_moment" in criteria)
