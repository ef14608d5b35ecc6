"""The check's verdict when the sweep did not run every load model EN 1991-2 asks for.

EN 1991-2 6.4.6.1.1, Table 6.4: a continuous deck takes HSLM-A1 to A10; a simply supported span
of 7 m or more all ten too, or a single critical one chosen by Annex E (which vtsi does not
choose); a simply supported span under 7 m takes HSLM-B. A sweep of HSLM trains without all of
them read PASS with a note: its deck acceleration and deflection are now not checked (NO
VERDICT, `vtsi check` exits 1), a FAIL stays FAIL, and a sweep of real trains only keeps its
statuses. Eq. 6.13's Δζ is 0 from L = 30 m (6.4.6.3.1(3) gives it to shorter spans only).

Decks: Euler-Bernoulli, 15 t/m, EI for f₁ = 5 Hz (2 Hz on a 70 m span) on the longest span; modal passages of moving
forces (exact, milliseconds each).
"""
import numpy as np
import pytest

from vtsi.check import WITH_A_VERDICT, check
from vtsi.codes.en1991_2 import HSLM_A, HSLM_B, additional_damping, additional_damping_text, hslm_load_models
from vtsi.passage import Output, PassageSettings
from vtsi.sweep import Sweep, beam_bridge

MU, F1, L = 15000.0, 5.0, 20.0
OUTPUTS = [Output("deflection", "disp"), Output("acceleration", "accel", cutoff="en"),
           Output("end_rotation", "rotation", nodes="supports")]
SUBSET_NOTE = "not checked: a sweep of HSLM trains verifies the bridge to EN 1991-2 only with every train Table 6.4"


def checked(spans, trains, speeds="200", damping=0.02, f1=F1):
    """The results and check of ``trains`` over ``spans`` [m], f₁ = ``f1`` [Hz] on the longest span."""
    ei = MU * (2 * np.pi * f1 * (max(spans) / np.pi) ** 2) ** 2
    sweep = Sweep(beam_bridge(spans, ei, 1.0, MU, elements_per_span=4), trains, speeds,
                  PassageSettings(damping=damping, bridge="modal"), outputs=OUTPUTS)
    results = sweep.run(None, workers=1, progress=False)
    return results, check(results)


def test_table_6_4_by_deck():
    """Which HSLM each deck takes: a 3 × 25 m continuous deck and a 70 m span all ten HSLM-A, a
    6 m span HSLM-B, decks of 5 and 8 m one each."""
    assert hslm_load_models([[25.0, 25.0, 25.0]]) == [HSLM_A]
    assert hslm_load_models([[70.0]]) == [HSLM_A] and hslm_load_models([[7.0]]) == [HSLM_A]
    assert hslm_load_models([[6.0]]) == [(HSLM_B,)]
    assert hslm_load_models([[5.0], [8.0]]) == [(HSLM_B,), HSLM_A]
    assert len(HSLM_A) == 10 and HSLM_A[0] == "HSLM-A1" and HSLM_A[-1] == "HSLM-A10"


@pytest.mark.parametrize("spans, f1, trains, why", [
    ([L, L], F1, ["HSLM-A1", "HSLM-A5"], "Table 6.4 loads a continuous deck with all ten"),
    ([70.0], 2.0, ["HSLM-A1", "HSLM-A5", "HSLM-A10"], "Table 6.4 lets a single critical train chosen by Annex E "
                                                      "stand for them on a simply supported span, a choice vtsi does "
                                                      "not make")])
def test_a_subset_of_hslm_a_gives_no_verdict(spans, f1, trains, why):
    """A 2 × 20 m continuous deck with A1 and A5, a 70 m span with A1, A5 and A10: PASS before.
    The deck acceleration keeps its value, limit and governing case (the largest of the stored
    envelopes), is 'info' and names the trains missing and the remedy; the deflection is not
    checked either and refers to it; the verdict is NO VERDICT naming both."""
    results, result = checked(spans, trains, f1=f1)
    row = result.row("deck_acceleration")
    assert result.row("deflection").value < result.row("deflection").limit       # PASS before
    env, columns = results.column_envelopes("acceleration")
    assert row.value == pytest.approx(float(np.nanmax(env[..., 2, :])), rel=1e-12) and row.limit == 3.5
    assert row.value < row.limit and row.train in trains and row.speed_kmh == 200.0
    assert row.status == "info" and result.row("deflection").status == "info"
    held = ", ".join(t.removeprefix("HSLM-") for t in trains)
    lacking = ", ".join(n.removeprefix("HSLM-") for n in HSLM_A if n not in trains)
    assert f"this sweep holds {held} only, without {lacking} ({why})" in row.note
    unchecked = f"{SUBSET_NOTE} asks for, and this one lacks HSLM-{lacking}; sweep again with all ten HSLM-A " \
                "trains (--trains HSLM-A)"
    assert row.note.endswith(f"({why}); {unchecked}")
    assert result.row("deflection").note.endswith(f"limit L/600; {unchecked}")
    assert "Table 6.4" not in result.row("dynamic_increment").note            # no limit: its value stands as read
    assert result.unchecked == ["deck_acceleration", "deflection"] and not result.passed
    assert result.verdict().startswith("NO VERDICT: deck_acceleration, deflection not checked (see their notes)")


def test_all_ten_hslm_a_are_checked():
    """The same deck with all ten: checked (pass or fail by the value), no load-model note."""
    _, result = checked([L, L], ["HSLM-A"])
    row = result.row("deck_acceleration")
    assert row.status == ("pass" if row.value <= row.limit else "fail")
    assert all("Table 6.4" not in r.note and "6.4.6.1.1" not in r.note for r in result.rows)
    assert result.passed == all(r.status != "fail" for r in result.rows)


def test_a_short_span_without_hslm_b_gives_no_verdict_and_with_it_a_verdict():
    """A 6 m span (f₁ = 20 Hz) swept with HSLM-A1 only: HSLM-B is what Table 6.4 asks, so no verdict, naming
    it; with HSLM-B (its alias 'b') the rows are checked, the note saying that HSLM-A1 counts as a
    real train there."""
    span = 6.0
    _, result = checked([span], ["HSLM-A1"], speeds="300", f1=20.0)
    row = result.row("deck_acceleration")
    assert row.status == "info" and "deck_acceleration" in result.unchecked
    assert ("EN 1991-2 6.4.6.1.1: a simply supported span under 7 m is checked with HSLM-B, which this sweep does not "
            "hold; ") in row.note
    assert f"{SUBSET_NOTE} asks for, and this one lacks HSLM-B; sweep again with HSLM-B (--trains HSLM-B)" in row.note
    assert result.verdict().startswith("NO VERDICT")
    _, with_b = checked([span], ["HSLM-A1", "b"], speeds="300", f1=20.0)
    assert with_b.unchecked == [] and "which this sweep does not hold" not in with_b.row("deck_acceleration").note
    assert ("EN 1991-2 6.4.6.1.1, Table 6.4: HSLM-A is not a load model of a simply supported span under 7 m (HSLM-B "
            "is); the rows this sweep's HSLM-A trains govern count as a real train's") in with_b.row("deck_acceleration").note
    assert with_b.row("deck_acceleration").status in ("pass", "fail")


def test_a_failing_subset_stays_fail():
    """HSLM-A1 at its resonance on a simply supported 20 m span (v = n₀ D = 324 km/h, ζ = 0.5 %):
    the deck acceleration fails with one train, and the trains not run can only add to it."""
    _, result = checked([L], ["HSLM-A1"], speeds="324", damping=0.005)
    row = result.row("deck_acceleration")
    assert row.value > row.limit and row.status == "fail"
    assert "a FAIL stands: the trains not run can only add to it; sweep again with all ten HSLM-A" in row.note
    assert result.verdict().startswith("FAIL")


@pytest.mark.parametrize("spans", [[L, L], [6.0]])
def test_real_trains_only_keep_their_verdict(spans):
    """ICE3 alone (a check for a given line's trains, no HSLM): the statuses follow the values as
    before; on a 6 m span the note still says HSLM-B would check it (docs/check.md), not that
    the row is unchecked."""
    _, result = checked(spans, ["ICE3"])
    for row in result.rows:
        if row.criterion in WITH_A_VERDICT:
            assert row.status == ("pass" if row.value <= row.limit else "fail"), row.criterion
        assert "not checked" not in row.note and "HSLM-A is its ten trains" not in row.note
    note = result.row("deck_acceleration").note
    assert ("which this sweep does not hold" in note) == (spans == [6.0])


def test_end_rotation_names_its_clause():
    """The end_rotation row had '-' as its clause: EN 1990 A2.4.4.2.3 leaves end rotations to EN
    1991-2 6.5.4.5.2 (the deck end's displacement), which the row does not check."""
    _, result = checked([L], ["HSLM-A"])
    row = result.row("end_rotation")
    assert row.clause == "EN 1990 A2.4.4.2.3, EN 1991-2 6.5.4.5.2" and row.status == "info"
    assert "EN 1991-2 6.5.4.5.2" in row.note and row.value > 0


def test_additional_damping_is_zero_from_30_m():
    """Eq. 6.13 gives Δζ for L < 30 m only (6.4.6.3.1(3), Figure 6.15): 0 at and beyond (it was
    refused, stopping scripted span families), said so in words; below, the formula."""
    for span in (30.0, 45.0, 70.0):
        assert additional_damping(span) == 0.0
        assert additional_damping_text(span) == "Δζ = 0 (EN 1991-2 Eq. 6.13: L ≥ 30 m)"
    x = 20.0
    formula = (0.0187 * x - 0.00064 * x ** 2) / (1 - 0.0441 * x - 0.0044 * x ** 2 + 0.000255 * x ** 3) / 100
    assert additional_damping(x) == pytest.approx(formula, rel=1e-12) and formula > 0
    assert additional_damping_text(x) == f"Eq. 6.13 Δζ {100 * formula:.3g} %"
