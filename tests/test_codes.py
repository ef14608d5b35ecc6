"""EN 1991-2 rules of vtsi.codes.en1991_2 against the clauses' formulas (named in each test)."""
import numpy as np
import pytest

from vtsi.codes.en1991_2 import additional_damping, damping_lower_bound
from vtsi.errors import ModelError


@pytest.mark.parametrize("kind, base, slope", [("steel", 0.5, 0.125), ("composite", 0.5, 0.125),
                                               ("prestressed_concrete", 1.0, 0.07),
                                               ("filler_beam", 1.5, 0.07), ("reinforced_concrete", 1.5, 0.07)])
def test_table_6_6_lower_bounds(kind, base, slope):
    """ζ = ζ₂₀ + slope (20 − L) [%] below 20 m, ζ₂₀ from 20 m on; continuous at 20 m."""
    for L in (20.0, 35.0, 100.0):
        assert damping_lower_bound(kind, L) == pytest.approx(base / 100)
    for L in (2.0, 10.0, 19.5):
        assert damping_lower_bound(kind, L) == pytest.approx((base + slope * (20 - L)) / 100)
    assert damping_lower_bound(kind, 20.0 - 1e-9) == pytest.approx(damping_lower_bound(kind, 20.0), abs=1e-10)


def test_eq_6_13_additional_damping():
    """Δζ = (0.0187 L − 0.00064 L²) / (1 − 0.0441 L − 0.0044 L² + 0.000255 L³) [%], L < 30 m:
    zero at L = 0, largest (about 0.65 %) near 15 m, back to zero at 29.2 m (the numerator's
    root), clipped at 0 between there and 30 m."""
    L = np.linspace(0.5, 29.0, 58)
    expected = (0.0187 * L - 0.00064 * L ** 2) / (1 - 0.0441 * L - 0.0044 * L ** 2 + 0.000255 * L ** 3) / 100
    got = np.array([additional_damping(x) for x in L])
    np.testing.assert_allclose(got, expected, rtol=1e-14)
    assert np.all(got > 0) and 0.006 < got.max() < 0.007 and 13.0 <= L[np.argmax(got)] <= 17.0
    assert additional_damping(0.0187 / 0.00064) == pytest.approx(0.0, abs=1e-15)
    assert additional_damping(29.8) == 0.0


@pytest.mark.parametrize("call, words", [(lambda: additional_damping(-1.0), "> 0"),
                                         (lambda: damping_lower_bound("timber", 10.0), "timber"),
                                         (lambda: damping_lower_bound("steel", "ten"), "number")])
def test_out_of_range_is_refused(call, words):
    with pytest.raises(ModelError, match=words):
        call()


def test_table_6_2_determinant_length():
    """Case 5.1: the span; case 5.2: k × the mean span, k = 1.2/1.3/1.4/1.5 for 2/3/4/≥ 5 spans,
    but not less than the longest span (30 + 10 + 10 m: 1.3 × 16.7 = 21.7 m < 30 m)."""
    from vtsi.codes.en1991_2 import determinant_length
    assert determinant_length([17.5]) == 17.5
    assert determinant_length([20.0, 20.0]) == pytest.approx(24.0)
    assert determinant_length([15.0, 20.0, 12.0]) == pytest.approx(1.3 * 47.0 / 3)
    assert determinant_length([25.0] * 4) == pytest.approx(35.0)
    assert determinant_length([25.0] * 7) == pytest.approx(37.5)
    assert determinant_length([30.0, 10.0, 10.0]) == 30.0
    assert determinant_length([10.0, 40.0]) == 40.0               # 1.2 × 25 = 30 m < 40 m


def test_en_1990_a2_acceleration_cutoff():
    """A2.4.4.2.1: max(30 Hz, 1.5 n0, n3)."""
    from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
    assert acceleration_cutoff_hz([5.0, 20.0, 45.0]) == 45.0          # n3 governs
    assert acceleration_cutoff_hz([4.0, 10.0, 20.0]) == 30.0          # 30 Hz governs
    assert acceleration_cutoff_hz([25.0, 30.0, 35.0]) == 37.5         # 1.5 n0 governs
    with pytest.raises(ModelError, match="three"):
        acceleration_cutoff_hz([5.0, 20.0])
    with pytest.raises(ModelError, match=r"in increasing order \(n0 first\), got \[25.0, 10.0, 5.0\]"):
        acceleration_cutoff_hz([25.0, 10.0, 5.0])                      # n0 is the lowest: not 37.5 Hz
    with pytest.raises(ModelError, match=r"got '5,10,20'"):
        acceleration_cutoff_hz("5,10,20")


@pytest.mark.parametrize("call, message", [
    (lambda c: c.en1991_2.dynamic_factor(0.03), None),
    (lambda c: c.en1991_2.determinant_length([]), r"Table 6.2: the determinant length needs at least one span"),
    (lambda c: c.en1991_2.track_irregularity_increment(20.0, None, 100.0), r"Annex C: n0 \[Hz\] must be a number, got None"),
    (lambda c: c.en1991_2.track_irregularity_increment(20.0, [5.0, 6.0], 100.0), r"Annex C: n0 \[Hz\] and speed"),
    (lambda c: c.en1991_2.damping_lower_bound(["steel"], 10.0), r"Table 6.6: unknown bridge type \['steel'\]"),
    (lambda c: c.en1990_a2.deck_acceleration_limit(["ballasted"]), r"unknown track form \['ballasted'\]"),
    (lambda c: c.en1990_a2.comfort_limit(["good"]), r"unknown level of comfort \['good'\]"),
], ids=["phi-short", "no-span", "n0-none", "n0-list", "kind-list", "track-list", "comfort-list"])
def test_code_rules_name_a_bad_argument(call, message):
    """A bad argument of an EN rule is a ModelError naming the clause and the value; below
    L_Φ = 0.04 m, where Φ's formula has no finite value, Φ is its upper limit (not the lower)."""
    import vtsi.codes as codes
    from vtsi.codes import en1990_a2, en1991_2            # noqa: F401 (the submodules, on codes)
    if message is None:
        assert call(codes) == 1.67 and codes.en1991_2.dynamic_factor(0.04) == 1.67
        assert codes.en1991_2.dynamic_factor(0.01, "standard") == 2.0
        return
    with pytest.raises(ModelError, match=message):
        call(codes)
