"""Load Model SW/0 (EN 1991-2 6.3.3, Table 6.1: 133 kN/m on two lengths of 15 m, 5.3 m apart, one
rigid pattern, × α) in vtsi.influence, and the check's static reference on continuous decks (the
more unfavourable of LM71 and SW/0: EN 1991-2 6.3.3(1)P, 6.4.6.5(3) Eq. 6.15, EN 1990
A2.4.4.2.3(1)).

The independent values:

- a simply supported span L (EI constant): influence lines of the moment at a (a triangle, peak
  a (L − a)/L) and of the mid-span deflection (x (3L² − 4x²)/(48 EI), x ≤ L/2); a 15 m length
  whose two ends read the same ordinate is the most unfavourable placement of one patch
  (d/ds ∫ = IL(s + 15) − IL(s) = 0), so on L = 20 m (the second patch 5.3 m beyond, off the
  span) the mid-span moment is q (L²/8 − 2 · 2.5²/4) = 6234.375 kN·m and the quarter-point one q ×
  the triangle's area less its ends beyond s = a (L − 15)/L and s + 15; L = 12 m is loaded whole
  (q L²/8, 5 q L⁴/(384 EI));
- a 2 × L continuous beam: the moment over the middle support per unit force at s from the outer
  support, −s (L² − s²)/(4 L²) (three-moment equation; tests/test_pier_moments.py), and the
  deflection at x₀ in span 1 the simply supported span's plus that of the end moment M_B(x),
  M_B x₀ (L² − x₀²)/(6 L EI) (superposition);
- a 3 × 25 m continuous beam (the audit's): the moment over the first pier by the three-moment
  equation for each load position;
- and for each, SW/0's most unfavourable position found independently: scipy.integrate.quad of
  the closed-form line over the pattern, scanned every 5 cm and refined by
  scipy.optimize.minimize_scalar.
"""
import h5py
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

import vtsi
from vtsi.check import CheckSettings, check
from vtsi.influence import SW0_GAP, SW0_LENGTH, SW0_LOAD, InfluenceLines
from vtsi.models.bridges import continuous_beam
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import SweepResults
from vtsi.track import Track

E, I, MU = 3.5e10, 1.0, 15000.0
EI = E * I
Q = 133e3                                   # [N/m] EN 1991-2 Table 6.1


def sw0_by_quadrature(line, x0, x1, kinks=()):
    """The largest 133 kN/m × ∫ ``line`` over SW/0's pattern (lengths 15 m, 5.3 m apart) over
    every position: ``line`` a function of x [m], 0 outside [x0, x1], integrated by quad between
    ``kinks``; the best of a scan every 5 cm refined by minimize_scalar (bounded)."""
    tiny = 1e-12 * max(abs(line(x)) for x in np.linspace(x0, x1, 101))      # quad's absolute tolerance

    def total(s):
        out = 0.0
        for a, b in ((s, s + 15.0), (s + 20.3, s + 35.3)):
            a, b = max(a, x0), min(b, x1)
            if b > a:
                points = [k for k in kinks if a < k < b]
                out += quad(line, a, b, points=points or None, epsabs=tiny, epsrel=1e-11, limit=200)[0]
        return out
    starts = np.arange(x0 - 35.3, x1 + 0.05, 0.05)
    best = starts[int(np.argmax([total(s) for s in starts]))]
    found = minimize_scalar(lambda s: -total(s), bounds=(best - 0.05, best + 0.05), method="bounded",
                            options={"xatol": 1e-10})
    return Q * max(total(best), -found.fun)


def beam_lines(spans, n, **responses):
    """(InfluenceLines of a continuous beam over ``spans`` [m], ``n`` elements a span, the beam)."""
    model = vtsi.Model()
    beam = continuous_beam(model, spans, n, E, I, MU)
    return InfluenceLines(model, Track(model, beam.elements), **responses), beam


def test_the_pattern_is_table_6_1():
    assert (SW0_LOAD, SW0_LENGTH, SW0_GAP) == (133e3, 15.0, 5.3)


def test_sw0_on_a_simply_supported_span_is_the_closed_form():
    """L = 20 m, 8 elements: the mid-span moment q (L²/8 − 2 · 2.5²/4) (a 15 m patch centred),
    the quarter-point moment (the patch from s = a (L − 15)/L; also by quadrature), the mid-span
    deflection (the span less its two 2.5 m ends), to 1e-9; α scales them; no position hogs or
    lifts (the max rows 0). L = 12 m, 6 elements, at x = 4 m: loaded whole, q x (L − x)/2 and
    q x (L³ − 2 L x² + x³)/(24 EI)."""
    L = 20.0
    lines, beam = beam_lines([L], 8, moments=[5, 3])             # x = 10 m and 5 m
    moments = lines.sw0_envelope()
    assert moments[1, 0] == pytest.approx(Q * (L ** 2 / 8 - 2 * 2.5 ** 2 / 4), rel=1e-9)
    assert moments[1, 0] == pytest.approx(6234375.0, rel=1e-12)
    a, b = L / 4, 3 * L / 4
    s = a * (L - 15.0) / L
    triangle = a * b / 2 - (b / L) * s ** 2 / 2 - (a / L) * (L - s - 15.0) ** 2 / 2
    assert moments[1, 1] == pytest.approx(Q * triangle, rel=1e-9)
    line = lambda x: (x * b / L if x <= a else a * (L - x) / L) if 0.0 <= x <= L else 0.0
    assert moments[1, 1] == pytest.approx(sw0_by_quadrature(line, 0.0, L, kinks=(a,)), rel=1e-9)
    assert np.all(moments[0] == 0.0)
    c = 2.5
    deflection = Q / EI * (5 * L ** 4 / 384 - 2 / 48 * (1.5 * L ** 2 * c ** 2 - c ** 4))
    lines, _ = beam_lines([L], 8, dofs=[(5, 2)])
    assert -lines.sw0_envelope()[0, 0] == pytest.approx(deflection, rel=1e-9)
    assert lines.sw0_envelope()[1, 0] == 0.0
    assert lines.sw0_envelope(alpha=1.21)[0, 0] == pytest.approx(1.21 * lines.sw0_envelope()[0, 0], rel=1e-12)
    L, x = 12.0, 4.0
    moment, _ = beam_lines([L], 6, moments=[3])
    deflection, _ = beam_lines([L], 6, dofs=[(3, 2)])
    assert moment.sw0_envelope()[1, 0] == pytest.approx(Q * x * (L - x) / 2, rel=1e-9)
    assert -deflection.sw0_envelope()[0, 0] == pytest.approx(Q * x * (L ** 3 - 2 * L * x ** 2 + x ** 3) / (24 * EI),
                                                             rel=1e-9)


def test_sw0_can_exceed_lm71_on_a_simply_supported_span():
    """Why the check weighs SW/0 on continuous decks only (EN 1991-2 6.3.3(1)P) rather than
    everywhere: on a simply supported 18 m span SW/0's mid-span moment, q (L²/8 − 2 · 1.5²/4) =
    5236.9 kN·m, is 3.3 % above LM71's (vtsi's LM71, checked against its closed forms in
    tests/test_influence.py and tests/test_moment.py), its mid-span deflection 6.1 % (a scan of
    closed-form lines from 1 to 300 m found up to 7 %, near 18 and 40 m): enveloping both
    everywhere would be stricter than EN 1990 A2.4.4.2.3(1) asks of a simply supported span."""
    L = 18.0
    moment, _ = beam_lines([L], 10, moments=[6])
    deflection, _ = beam_lines([L], 10, dofs=[(6, 2)])
    sw0 = Q * (L ** 2 / 8 - 2 * 1.5 ** 2 / 4)
    assert moment.sw0_envelope()[1, 0] == pytest.approx(sw0, rel=1e-9)
    assert sw0 / moment.lm71_envelope()[1, 0] == pytest.approx(1.033, abs=5e-4)
    assert deflection.sw0_envelope()[0, 0] / deflection.lm71_envelope()[0, 0] == pytest.approx(1.061, abs=5e-4)


def hogging_line(L):
    """The moment over the middle support of a 2 × L beam per unit downward force at x [N·m/N]."""
    def line(x):
        s = x if x <= L else 2 * L - x
        return -s * (L * L - s * s) / (4 * L * L) if 0.0 <= x <= 2 * L else 0.0
    return line


def test_sw0_over_the_pier_of_a_two_span_beam():
    """2 × 20 m: SW/0 centred on the pier (its loads from 2.35 m to 17.35 m either side, the
    quadrature's optimum too) hogs −2 q ∫ s (L² − s²)/(4L²) ds = −6060.48 kN·m, 23.5 % more than
    LM71's −4907.89 kN·m (by hand in tests/test_pier_moments.py): to 1e-9 on 10 and 6 elements
    a span (load ends inside elements)."""
    L = 20.0
    area = lambda s: (L * L * s * s / 2 - s ** 4 / 4) / (4 * L * L)
    centred = -2 * Q * (area(17.35) - area(2.35))
    assert centred == pytest.approx(-sw0_by_quadrature(lambda x: -hogging_line(L)(x), 0.0, 2 * L, kinks=(L,)),
                                    rel=1e-10)
    for n in (10, 6):
        lines, _ = beam_lines([L, L], n, moments=[n + 1])          # the middle support's node
        low, high = lines.sw0_envelope()[:, 0]
        assert low == pytest.approx(centred, rel=1e-9) and high == pytest.approx(0.0, abs=1e-6)
    assert centred / -4907887.76 == pytest.approx(1.2348, abs=1e-4)


def test_sw0_over_the_first_pier_of_three_spans_is_the_audits():
    """3 × 25 m (the audit's deck): the moment over the first pier by the three-moment equation,
    SW/0's most unfavourable by quadrature, −7808.47 kN·m, against LM71's −7058.80 (+10.6 %)."""
    L = 25.0

    def first_pier(x):
        rhs = np.zeros(2)                                    # 2 M_B (2L) + M_C L = ..., M_B L + 2 M_C (2L) = ...
        if 0.0 < x < L:
            a = x
            rhs[0] = -a * (L - a) * (L + a) / L
        elif L <= x < 2 * L:
            a = x - L
            rhs[:] = -a * (L - a) * (2 * L - a) / L, -a * (L - a) * (L + a) / L
        elif 2 * L <= x < 3 * L:
            a = x - 2 * L
            rhs[1] = -a * (L - a) * (2 * L - a) / L
        return float(np.linalg.solve([[4 * L, L], [L, 4 * L]], rhs)[0])
    hand = -sw0_by_quadrature(lambda x: -first_pier(x), 0.0, 3 * L, kinks=(L, 2 * L))
    lines, _ = beam_lines([L, L, L], 16, moments=[17])
    assert lines.sw0_envelope()[0, 0] == pytest.approx(hand, rel=1e-9)
    assert hand == pytest.approx(-7808.47e3, abs=10.0)
    assert lines.sw0_envelope()[0, 0] / lines.lm71_envelope()[0, 0] == pytest.approx(1.1062, abs=1e-4)


def two_span_deflection_line(L, x0):
    """The downward deflection at x0 (span 1) of a 2 × L beam per unit downward force at x [m/N]:
    the simply supported span's, plus that of the moment over the middle support M_B(x) acting on
    span 1, M_B x0 (L² − x0²)/(6 L EI) (superposition)."""
    def line(x):
        if not 0.0 <= x <= 2 * L:
            return 0.0
        s = x if x <= L else 2 * L - x
        pier = -s * (L * L - s * s) / (4 * L * L) * x0 * (L * L - x0 * x0) / (6 * L * EI)
        if x > L:
            return pier
        b = L - x0
        simple = (x * b * (L * L - b * b - x * x) if x <= x0 else x0 * (L - x) * (L * L - x0 * x0 - (L - x) ** 2))
        return simple / (6 * L * EI) + pier
    return line


@pytest.fixture(scope="module")
def continuous(tmp_path_factory):
    """A 2 × 18 m continuous deck (EI = 3.5e10 N·m², 15 t/m) swept by HSLM-A1 at 140 km/h: far
    from resonance (n₀ D = 133 m/s), so Φ α × the static reference governs its deflection."""
    path = tmp_path_factory.mktemp("sw0") / "two.h5"
    Sweep(beam_bridge([18.0, 18.0], E, I, MU, elements_per_span=10), ["HSLM-A1"], "140",
          PassageSettings(damping=0.02, bridge="modal")).run(path, workers=1, progress=False)
    return path


def test_sw0_governs_the_deflection_of_a_continuous_deck(continuous):
    """2 × 18 m: SW/0's deflection (by quadrature of the closed-form lines at the nodes of span 1,
    every 1.8 m) is 5.6 % above LM71's, so the deflection row reads Φ₂ α × SW/0's largest, Φ₂ =
    1.44/(√L_Φ − 0.2) + 0.82 of L_Φ = 1.2 × 18 m, names SW/0 as what governs and says why; the
    dynamic_vs_lm71 row divides by Φ α y_SW/0 and says so too."""
    L, alpha = 18.0, 1.21
    results = SweepResults(continuous)
    static = results.static("deflection")
    x0 = np.arange(1, 10) * L / 10
    sw0 = np.array([sw0_by_quadrature(two_span_deflection_line(L, x), 0.0, 2 * L, kinks=(x, L)) for x in x0])
    nodes = results.column_envelopes("deflection")[1].tolist()
    lm71 = -static.lm71[0, [nodes.index(k) for k in range(2, 11)]]       # nodes 2 to 10: x = 1.8 to 16.2 m
    assert np.all(sw0 / lm71 > 1.05)
    Phi = 1.44 / (np.sqrt(1.2 * L) - 0.2) + 0.82
    row = check(results, CheckSettings(alpha=alpha)).row("deflection")
    assert row.value == pytest.approx(Phi * alpha * sw0.max(), rel=1e-8) and row.limit == pytest.approx(L / 600)
    k = int(np.argmax(sw0)) + 2                                          # or its mirror in span 2, node 22 - k
    assert row.train == "SW/0" and row.where.split(" (")[0] in (f"node {k}", f"node {22 - k}")
    weighed = "SW/0 exceeds LM71 there, and a continuous deck takes the more unfavourable: EN 1991-2 6.3.3(1)P"
    assert row.note.startswith(f"SW/0 governs: the more unfavourable of Phi x alpha x SW/0 ({row.value:.4g} m; "
                               f"{weighed}; Phi = {Phi:.3f}, alpha = 1.21)")
    versus = check(results, CheckSettings(alpha=alpha)).row("dynamic_vs_lm71")
    assert "/ (Phi alpha y_SW/0) = " in versus.note and f"; {weighed}" in versus.note


def test_a_results_file_without_sw0_says_its_reference_is_lm71_alone(continuous, tmp_path):
    """A results file of an older vtsi holds no /static/<output>/sw0: it is still read, and the
    deflection and dynamic_vs_lm71 rows read LM71 alone and say so (they do not pass it off as
    the more unfavourable of LM71 and SW/0)."""
    older = tmp_path / "older.h5"
    older.write_bytes(continuous.read_bytes())
    with h5py.File(older, "r+") as f:
        for group in f["static"].values():
            del group["sw0"]
    results = SweepResults(older)
    static = results.static("deflection")
    assert static.sw0 is None
    rows = check(results)
    row = rows.row("deflection")
    Phi = 1.44 / (np.sqrt(1.2 * 18.0) - 0.2) + 0.82
    assert row.train == "LM71" and row.value == pytest.approx(Phi * -static.lm71[0].min(), rel=1e-12)
    said = "the static reference is LM71 alone: the results file, of an older vtsi, holds no SW/0"
    assert said in row.note and said in rows.row("dynamic_vs_lm71").note
    assert "SW/0 exceeds" not in row.note and "exceeds SW/0" not in row.note
