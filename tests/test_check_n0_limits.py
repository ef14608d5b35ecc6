"""The check states each deck's n₀ against EN 1991-2 Figure 6.10 (information: no verdict changes).

Figure 6.10: lower limit 80 / L for L <= 20 m, 23.58 L^-0.592 above; upper 94.76 L^-0.748; 4 to
100 m. L is the span of a simply supported deck, L_Φ of a continuous one (Table 6.2: 1.2 × the
mean span of two). Outside the limits Figure 6.9 asks for a dynamic analysis; within them its
other tests decide, which the check does not read.

Decks: Euler-Bernoulli, 15 t/m, EI for f₁ on the longest span (f₁ = (π / 2L²) √(EI / μ)); modal
passages of moving forces (exact, milliseconds each).
"""
import numpy as np
import pytest

from vtsi.check import check, frequency_limits_text, stored_check
from vtsi.codes.en1991_2 import frequency_limits
from vtsi.codes.en1991_2 import frequency_limits_text as deck_text
from vtsi.errors import ModelError
from vtsi.passage import Output, PassageSettings
from vtsi.report import write_report
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import deck_first_frequencies

MU = 15000.0
OUTPUTS = [Output("deflection", "disp"), Output("acceleration", "accel", cutoff="en")]
WITHIN = "Figure 6.9's other tests (line speed, structure, Annex F) decide whether a dynamic analysis is needed"
OUTSIDE = "outside them Figure 6.9 asks for a dynamic analysis"


def lower(L):
    return 80.0 / L if L <= 20.0 else 23.58 * L ** -0.592


def upper(L):
    return 94.76 * L ** -0.748


def swept(spans, f1, train="HSLM-A1", speed="200", path=None):
    """The results of one passage of ``train`` over ``spans`` [m], f₁ = ``f1`` [Hz] on the longest
    (kept in ``path``, or in memory)."""
    ei = MU * (2 * np.pi * f1 * (max(spans) / np.pi) ** 2) ** 2
    sweep = Sweep(beam_bridge(spans, ei, 1.0, MU, elements_per_span=8), [train], speed,
                  PassageSettings(damping=0.02, bridge="modal"), outputs=OUTPUTS)
    return sweep.run(path, workers=1, progress=False)


def figure_line(result):
    lines = [line for line in result.text().splitlines() if line.startswith("EN 1991-2 Figure 6.10: ")]
    assert len(lines) == 1, result.text()
    return lines[0]


def test_a_20_m_span_within_the_limits(tmp_path):
    """n₀ = 5 Hz on a 20 m span: within 4 to 10.08 Hz; the stored check and the report read the
    line back."""
    path = tmp_path / "sweep.h5"
    results = swept([20.0], 5.0, path=path)
    n0 = float(deck_first_frequencies(results.bridge())[0])
    assert n0 == pytest.approx(5.0, rel=1e-3)
    checked = check(results)
    assert figure_line(checked) == (
        f"EN 1991-2 Figure 6.10: n0 {n0:.4g} Hz of the 20 m span is within the limits, "
        f"{lower(20.0):.4g} to {upper(20.0):.4g} Hz at L = 20 m (the span): {WITHIN}")
    checked.store(path)
    again = stored_check(path)
    assert again.frequency_limits == checked.frequency_limits and again.text() == checked.text()
    report = write_report(path, tmp_path / "report")["markdown"].read_text(encoding="utf-8")
    assert f"{checked.frequency_limits}." in report


def test_a_flexible_span_below_the_lower_limit():
    """n₀ = 3 Hz on a 20 m span, under Figure 6.10's 4 Hz: Figure 6.9 asks for a dynamic analysis."""
    results = swept([20.0], 3.0)
    n0 = float(deck_first_frequencies(results.bridge())[0])
    assert n0 == pytest.approx(3.0, rel=1e-3) and n0 < lower(20.0)
    assert figure_line(check(results)) == (
        f"EN 1991-2 Figure 6.10: n0 {n0:.4g} Hz of the 20 m span is below the limits, {lower(20.0):.4g} to "
        f"{upper(20.0):.4g} Hz at L = 20 m (the span): {OUTSIDE}")


def test_a_continuous_deck_is_read_at_its_determinant_length():
    """A 2 × 20 m continuous deck: L = L_Φ = 1.2 × 20 = 24 m (above 20 m: the lower limit's
    second branch)."""
    results = swept([20.0, 20.0], 5.0)
    n0 = float(deck_first_frequencies(results.bridge())[0])
    L_phi = 1.2 * (20.0 + 20.0) / 2
    assert lower(L_phi) <= n0 <= upper(L_phi)
    assert figure_line(check(results)) == (
        f"EN 1991-2 Figure 6.10: n0 {n0:.4g} Hz of the 20 + 20 m continuous deck is within the limits, "
        f"{lower(L_phi):.4g} to {upper(L_phi):.4g} Hz at L = {L_phi:.4g} m (its L_Phi, 6.4.4): {WITHIN}")


def test_a_3_m_span_lies_outside_figure_6_10():
    """A 3 m span (HSLM-B): Figure 6.10 starts at 4 m; the line says so and gives no limits
    (the limits of 4 m do not stand in for it); the plausibility floor of a sweep keeps its clamp."""
    results = swept([3.0], 40.0, train="HSLM-B", speed="250")
    n0 = float(deck_first_frequencies(results.bridge())[0])
    line = figure_line(check(results))
    assert line == (f"EN 1991-2 Figure 6.10: n0 {n0:.4g} Hz of the 3 m span: Figure 6.10 covers L = 4 to 100 m, "
                    "not L = 3 m (the span), and gives it no limits")
    assert f"{lower(4.0):.4g}" not in line
    assert frequency_limits(3.0) == frequency_limits(4.0) == pytest.approx((lower(4.0), upper(4.0)))


def test_decks_that_read_alike_are_given_once():
    """Two 15 m decks of n₀ 10.66 Hz on one pier and a 30 m deck of 2.666 Hz beside them."""
    bridge = {"span_lengths_m": [15.0, 15.0, 30.0], "span_ends_m": [[0, 15], [15.5, 30.5], [31, 61]],
              "deck_ends_m": [[0, 15], [15.5, 30.5], [31, 61]], "frequencies_hz": [2.666, 10.66, 10.66],
              "deck_frequencies_hz": [[10.66, 42.66, 96.03], [10.66, 42.66, 96.03], [2.666, 10.66, 24.0]]}
    line = frequency_limits_text(bridge)
    assert line == ("EN 1991-2 Figure 6.10: decks 1, 2: " + deck_text(10.66, [15.0])
                    + "; deck 3: " + deck_text(2.666, [30.0]))
    assert f"{lower(15.0):.4g} to {upper(15.0):.4g} Hz" in line and f"{lower(30.0):.4g} to {upper(30.0):.4g}" in line
    assert "10.66 Hz of the 15 m span is within" in line and "2.666 Hz of the 30 m span is below" in line


@pytest.mark.parametrize("args, message", [
    ((-1.0, [20.0]), "EN 1991-2 Figure 6.10: n0 [Hz] must be > 0 and finite, got -1.0"),
    ((5.0, ["20"]), "EN 1991-2 Figure 6.10: a deck's spans [m] must be numbers, got ['20']"),
])
def test_bad_inputs_are_named(args, message):
    with pytest.raises(ModelError) as info:
        deck_text(*args)
    assert str(info.value) == message
