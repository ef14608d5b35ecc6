"""EN 1991-2 rules of vtsi.codes.en1991_2 against the clauses' formulas (reference/README.md)."""
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


@pytest.mark.parametrize("call, words", [(lambda: additional_damping(30.0), "below 30 m"),
                                         (lambda: additional_damping(-1.0), "> 0"),
                                         (lambda: damping_lower_bound("timber", 10.0), "timber"),
                                         (lambda: damping_lower_bound("steel", "ten"), "number")])
def test_out_of_range_is_refused(call, words):
    with pytest.raises(ModelError, match=words):
        call()


def test_en_1990_a2_acceleration_cutoff():
    """A2.4.4.2.1: max(30 Hz, 1.5 n0, n3)."""
    from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
    assert acceleration_cutoff_hz([5.0, 20.0, 45.0]) == 45.0          # n3 governs
    assert acceleration_cutoff_hz([4.0, 10.0, 20.0]) == 30.0          # 30 Hz governs
    assert acceleration_cutoff_hz([25.0, 60.0, 35.0]) == 37.5         # 1.5 n0 governs
    with pytest.raises(ModelError, match="three"):
        acceleration_cutoff_hz([5.0, 20.0])
