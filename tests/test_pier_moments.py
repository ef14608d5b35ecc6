"""The hogging moment over the intermediate supports of a continuous deck (docs/check.md): the
static moment over the middle support of a 2 × L continuous beam (EI constant) against its
textbook influence line and LM71 placed by hand, a slow passage against the influence line, the
check's ``_support_moment`` rows on a continuous deck (and none on simply supported decks), and
the report showing them.

The influence line of the moment over the middle support of two equal spans L, for a unit
downward force at s from the outer support of either span, is

    M_B(s) = −s (L² − s²) / (4 L²)

(three-moment equation; e.g. Ghali, Neville & Brown, Structural Analysis, 6th ed., the
two-span continuous beam; its largest ordinate −L / (6√3) at s = L / √3)."""
import math

import numpy as np
import pytest

import vtsi
from vtsi.check import MIN, CheckSettings, _design_factors, check, stored_check, support_ratios
from vtsi.deck_record import intermediate_supports, piers
from vtsi.influence import LM71_AXLE, LM71_SPACING, LM71_UDL, InfluenceLines
from vtsi.models.bridges import continuous_beam
from vtsi.passage import DEFAULT_OUTPUTS, Output, PassageSettings
from vtsi.places import node_text
from vtsi.report import write_report
from vtsi.sweep import Sweep, SweepBridge, beam_bridge
from vtsi.sweep_results import SweepResults
from vtsi.track import Track

E, I, MU = 3.5e10, 1.5, 18000.0
FAST = PassageSettings(dt=4e-3, damping=0.02)


def hogging_line(s, L):
    """M_B per unit downward force at x = s [m] on a 2 × L beam (0 off it) [N·m/N]."""
    s = np.asarray(s, dtype=float)
    a = np.where(s <= L, s, 2 * L - s)                    # from the outer support of its span
    return np.where((s >= 0) & (s <= 2 * L), -a * (L * L - a * a) / (4 * L * L), 0.0)


def lm71_hogging(L):
    """LM71's most unfavourable moment over the middle support of a 2 × L beam, by hand [N·m].

    The 80 kN/m acts wherever the line is negative (both spans whole) but under the four axles'
    6.4 m (EN 1991-2 Figure 6.1), so with the axles' centre at c in span 1 (η = −M_B ≥ 0)

        M(c) = −q L²/8 + q ∫_{c−3.2}^{c+3.2} η ds − P Σ η(c + o_i),  o_i = ±0.8, ±2.4 m.

    dM/dc = 0 with η'(s) = (L² − 3 s²)/(4 L²), Σ o_i² = 12.8 m² and (c + b)³ − (c − b)³ =
    6 b c² + 2 b³ (b = 3.2 m) gives c² = (4PL² − 38.4 P − 6.4 q L² + 65.536 q) / (12 P − 19.2 q)
    (valid while the 6.4 m lie in span 1: L ≥ 12 m or so)."""
    P, q = LM71_AXLE, LM71_UDL
    c = math.sqrt((4 * P * L * L - 38.4 * P - 6.4 * q * L * L + 65.536 * q) / (12 * P - 19.2 * q))
    assert 3.2 <= c <= L - 3.2

    def eta(s):
        return s * (L * L - s * s) / (4 * L * L)

    def area(s):                                           # ∫_0^s η
        return (L * L * s * s / 2 - s ** 4 / 4) / (4 * L * L)
    offsets = LM71_SPACING * np.array([-1.5, -0.5, 0.5, 1.5])
    return -q * L * L / 8 + q * (area(c + 3.2) - area(c - 3.2)) - P * sum(eta(c + o) for o in offsets)


def sw0_hogging(L):
    """SW/0's most unfavourable moment over the middle support of a 2 × L beam (L >= 17.65 m), by
    hand [N·m]: its pattern (15 m, 5.3 m, 15 m) centred on the support, loading s = L − 17.65 to
    L − 2.65 m from the outer support of both spans (the optimum: tests/test_sw0.py finds it by
    quadrature), −2 q ∫ s (L² − s²)/(4 L²) ds, q = 133 kN/m (EN 1991-2 Table 6.1)."""
    def area(s):
        return (L * L * s * s / 2 - s ** 4 / 4) / (4 * L * L)
    return -2 * 133e3 * (area(L - 2.65) - area(L - 17.65))


def two_span_lines(L, n):
    model = vtsi.Model()
    beam = continuous_beam(model, [L, L], n, E, I, MU)
    track = Track(model, beam.elements)
    return InfluenceLines(model, track, moments=[beam.supports[1]]), beam


@pytest.mark.parametrize("L, n", [(20.0, 10), (15.0, 6)])
def test_the_static_hogging_moment_over_the_pier_is_the_textbook_one(L, n):
    """The influence line at any x (not only the nodes) within 1e-9; a uniform q over both spans
    −q L²/8 (Simpson on each element's cubic pieces: exact); LM71's most unfavourable hogging
    moment (by hand, lm71_hogging: −4907.89 kN·m for L = 20 m) within 2e-6 (vtsi scans the
    axles' positions every 1/20 element: the error is the scan's, second order, and never past
    the true extreme), and α scales it."""
    lines, _ = two_span_lines(L, n)
    x = np.random.default_rng(7).uniform(-1.0, 2 * L + 1.0, 200)
    np.testing.assert_allclose(lines(x)[:, 0], hogging_line(x, L), rtol=0, atol=1e-9 * L)
    ends = np.linspace(0.0, 2 * L, 2 * n + 1)
    mids = 0.5 * (ends[1:] + ends[:-1])
    q = 80e3
    uniform = q * np.sum(np.diff(ends) / 6 * (lines(ends[:-1])[:, 0] + 4 * lines(mids)[:, 0] + lines(ends[1:])[:, 0]))
    assert uniform == pytest.approx(-q * L * L / 8, rel=1e-9)
    low, high = lines.lm71_envelope()[:, 0]
    hand = lm71_hogging(L)
    assert 1.0 - 2e-6 <= low / hand <= 1.0 + 1e-9, (low, hand)
    assert high == pytest.approx(0.0, abs=1e-6)              # no load position sags the pier
    assert lines.lm71_envelope(alpha=1.21)[0, 0] == pytest.approx(1.21 * low, rel=1e-12)
    if L == 20.0:
        assert hand == pytest.approx(-4907887.76, abs=0.01)


@pytest.mark.parametrize("kind", ["fe", "modal", "modal-stepped"])
def test_a_slow_axle_reads_the_influence_line_over_the_pier(tmp_path, kind):
    """One 100 kN axle at 1 km/h over a 2 × 20 m deck (n₀ = 6.7 Hz, ζ = 2 %), FE, exact modal and
    time-stepped modal (with their static correction): the support moment's history is P × the
    influence line at the axle's position within 1e-4 of the peak wherever the axle is (the
    start's free vibration aside, the first 2 m; measured 2.2e-5 FE, 3.2e-5 modal), and its
    envelope minimum the static one, −P L / (6√3), within 1e-4 (measured 0.8e-5, 1.6e-5)."""
    L, P = 20.0, 1e5
    path = tmp_path / "one.csv"
    path.write_text("position_m,load_kN\n0,100\n")
    bridge = beam_bridge([L, L], E, I, MU, elements_per_span=10)
    out = [Output("support_moment", "moment", "supports", history=True)]
    sweep = Sweep(bridge, [str(path)], "1", PassageSettings(dt=2e-3, damping=0.02, bridge=kind), outputs=out)
    static, lm71, _ = sweep.runner.static_envelopes(out[0], sweep.trains)
    peak = P * L / (6 * math.sqrt(3))
    assert static[0, MIN, 1] == pytest.approx(-peak, rel=1e-6)          # the scan, refined by a parabola
    assert lm71[MIN, 1] == pytest.approx(lm71_hogging(L), rel=2e-6)
    result = sweep.runner.run(sweep.trains[0], 1.0)
    t, m = result.histories["support_moment"]
    x = result.x_head0 + t / 3.6
    on = (x > 2.0) & (x < 2 * L)
    assert np.abs(m[on, 1] - P * hogging_line(x[on], L)).max() < 1e-4 * peak, kind
    assert result.envelopes["support_moment"][MIN, 1] == pytest.approx(-peak, rel=1e-4), kind


@pytest.fixture(scope="module")
def continuous(tmp_path_factory):
    """A 2 × 20 m continuous deck swept by HSLM-A1 and ICE3 (moving forces) with the default
    outputs, its check stored."""
    path = tmp_path_factory.mktemp("pier") / "two.h5"
    sweep = Sweep(beam_bridge([20.0, 20.0], E, I, MU, elements_per_span=10), ["HSLM-A1", "ICE3"], "200,250,300",
                  FAST)
    result = check(sweep.run(path, workers=1, progress=False))
    result.store(path)
    return path, result


def test_the_check_of_a_continuous_deck_has_the_pier_rows(continuous):
    """φ'_dyn = max M_dyn / M_stat − 1 over the cases at the pier (node 11, both hogging), and
    (1 + φ'_dyn + φ''/2) |M_train| / (Φ α |M_SW/0|) by hand (SW/0 hogs the pier 23.5 % more than
    LM71: the static reference on a continuous deck is the more unfavourable of the two), Φ and
    φ'' of the deck's L_Φ = 1.2 × 20 m; the rows in the text and in the stored check alike."""
    path, result = continuous
    results = SweepResults(path)
    assert [s[:2] for s in intermediate_supports(results.bridge())] == [(0, 20.0)]
    env, columns = results.column_envelopes("support_moment")
    assert list(columns) == [11]                                       # the default output's 'piers'
    trains, lm71, _ = results.static("support_moment")
    c = list(columns).index(11)
    assert trains[:, MIN, c].max() < 0 and lm71[MIN, c] == pytest.approx(lm71_hogging(20.0), rel=2e-6)
    ratio = env[..., MIN, c] / trains[:, MIN, c][:, None, None]
    increment = result.row("dynamic_increment_support_moment")
    assert increment.value == pytest.approx(np.nanmax(ratio) - 1.0, rel=1e-12)
    assert increment.where == "node 11 (x = 20 m, support of spans 1 and 2)" and increment.status == "info"
    i, j, _ = np.unravel_index(np.nanargmax(ratio), ratio.shape)
    assert (increment.train, increment.speed_kmh) == (results.trains[i], results.speeds_kmh[j])
    L_phi, Phi, phi2, share = _design_factors(results, results.bridge(), CheckSettings())
    assert L_phi[0] == pytest.approx(24.0) and share == 0.5
    per_train = np.nanmax(ratio.reshape(len(results.trains), -1), axis=1) - 1.0
    reference = sw0_hogging(20.0)
    assert reference < 1.2 * lm71[MIN, c]
    by_hand = (1 + per_train + 0.5 * phi2[0]) * np.abs(trains[:, MIN, c]) / (Phi[0] * abs(reference))
    versus = result.row("dynamic_vs_lm71_support_moment")
    assert versus.value == pytest.approx(by_hand.max(), rel=1e-9) and versus.limit == 1.0
    assert f"M_SW/0 = {reference / 1e3:.5g} kN m" in versus.note
    assert versus.train == results.trains[int(np.argmax(by_hand))] and versus.where.startswith("node 11 (x = 20 m, support of spans")
    assert "L_Phi = 24 m" in versus.note and "hogging" in versus.note
    ratios = support_ratios(results, "support_moment", results.bridge())
    assert ratios[1] == [c] and np.nanmax(ratios[0]) == pytest.approx(increment.value + 1.0, rel=1e-15)
    # the mid-span rows are still there, and every place agrees: the text, the stored check
    assert {"dynamic_increment_moment", "dynamic_vs_lm71_moment"} <= {r.criterion for r in result.rows}
    text = result.text()
    for row in (increment, versus):
        assert any(line.startswith(row.criterion) and f"{row.value:.4g}" in line for line in text.splitlines())
    stored = {r.criterion: r for r in stored_check(path).rows}
    for row in (increment, versus):
        assert stored[row.criterion].value == row.value and stored[row.criterion].note == row.note


def test_simply_supported_decks_have_no_pier_rows(tmp_path):
    """One 20 m span, and two 20 m decks ending on one pier (separate end nodes at x = 20 m: no
    continuity, no hogging moment): no pier (``'piers'``), so the default ``support_moment``
    output is not produced (at the end supports it read only ±6 kN m of noise) and no
    ``_support_moment`` row."""
    one = Sweep(beam_bridge([20.0], E, I, MU, elements_per_span=10), ["HSLM-A1"], "250", FAST)
    model = vtsi.Model()
    first = continuous_beam(model, [20.0], 10, E, I, MU)
    second = continuous_beam(model, [20.0], 10, E, I, MU, x0=20.0, first_node=12, first_element=11)
    two = Sweep(SweepBridge(model, first.elements + second.elements, {"kind": "two decks"}), ["HSLM-A1"], "250", FAST)
    for sweep in (one, two):
        assert sweep.runner.pier_nodes == [] and "support_moment" not in [o.name for o in sweep.outputs]
        results = sweep.run(None, workers=1, progress=False)
        assert intermediate_supports(results.bridge()) == []
        criteria = {r.criterion for r in check(results).rows}
        assert "dynamic_increment_moment" in criteria and not any("support" in c for c in criteria)


def test_a_continuous_deck_swept_without_the_pier_moment_says_so():
    """A sweep whose outputs keep no moment over the pier (a results file of an older vtsi): no
    pier rows, and the mid-span moment rows say that the pier's hogging moment was not read."""
    outputs = [o for o in DEFAULT_OUTPUTS if o.name != "support_moment"]
    sweep = Sweep(beam_bridge([20.0, 20.0], E, I, MU, elements_per_span=10), ["HSLM-A1"], "250", FAST,
                  outputs=outputs)
    rows = {r.criterion: r for r in check(sweep.run(None, workers=1, progress=False)).rows}
    assert not any("support" in c for c in rows)
    assert "the hogging moment over the intermediate support (node 11) is not read" in \
        rows["dynamic_increment_moment"].note


def test_intermediate_supports_of_a_deck_over_two_close_bearings():
    """A continuous deck over two bearings 0.5 m apart (their stretch no span) reads both; a
    joint between two decks none. Either way the bearings stand on one pier, and their nodes
    are named so (before: 'span 1' and 'span 2'), a node between them too."""
    bridge = {"span_ends_m": np.array([[0.0, 20.0], [20.5, 40.5]]), "deck_ends_m": np.array([[0.0, 40.5]]),
              "deck_nodes": np.arange(1, 7), "deck_x_m": np.array([0.0, 10.0, 20.0, 20.5, 40.5, 20.25])}
    assert intermediate_supports(bridge) == [(0, 20.0, [3]), (0, 20.5, [4])]
    assert piers(bridge) == [(0, 20.0, 20.5)]
    assert [node_text(bridge, n) for n in range(1, 7)] == [
        "node 1 (x = 0 m, end support of span 1)", "node 2 (x = 10 m, span 1)",
        "node 3 (x = 20 m, support of span 1 on the pier of spans 1 and 2)",
        "node 4 (x = 20.5 m, support of span 2 on the pier of spans 1 and 2)",
        "node 5 (x = 40.5 m, end support of span 2)", "node 6 (x = 20.25 m, pier of spans 1 and 2)"]
    bridge["deck_ends_m"] = np.array([[0.0, 20.25], [20.25, 40.5]])
    assert intermediate_supports(bridge) == [] and piers(bridge) == [(0, 20.0, 20.5)]
    assert node_text(bridge, 6) == "node 6 (x = 20.25 m, overhang x = 20 to 20.25 m on the pier of spans 1 and 2)"
    assert node_text(bridge, 3) == "node 3 (x = 20 m, support of span 1 on the pier of spans 1 and 2)"
    bridge["span_ends_m"] = np.array([[0.0, 20.0], [21.0, 41.0]])        # 1 m apart: each deck's end support
    bridge["deck_ends_m"] = np.array([[0.0, 20.5], [20.5, 41.0]])
    assert piers(bridge) == [] and node_text(bridge, 3) == "node 3 (x = 20 m, end support of span 1)"


def test_the_report_shows_the_pier_rows(continuous, tmp_path):
    """The HTML check table and summary and the Markdown carry both pier rows with the stored values."""
    path, result = continuous
    out = write_report(path, tmp_path / "report")
    html = out["html"].read_text(encoding="utf-8")
    markdown = out["markdown"].read_text(encoding="utf-8")
    for criterion, label in (("dynamic_increment_support_moment", "dynamic increment support moment"),
                             ("dynamic_vs_lm71_support_moment", "dynamic vs LM71 support moment")):
        row = result.row(criterion)
        assert f'data-criterion="{criterion}"' in html
        assert f'data-field="value" data-value="{row.value!r}"' in html
        assert f"INFO {label}: {row.value:.4g}" in html and f"INFO {label}: {row.value:.4g}" in markdown
        assert f"| {label} | {row.value:.4g} |" in markdown
