"""D of two kinds of trains whose signature peaks away from their coach length (vtsi/signature.py;
docs/trains.md, "D from the dynamic signature", items 4 and 5).

Regular two-axle wagons of 12.5-20 m whose wheelbase is about 2/3 of their length peak below the
range, at a harmonic L/i: D is read there as the wagon length L they are built with. Coaches of
24 m and 26 m alternating repeat every 50 m: D is that period, the sum of the two by construction.
"""
import numpy as np
import pytest

from vtsi.models import Train
from vtsi.signature import DOMINANCE, MIN_SHARE, WAVELENGTH_RANGE_M, principal_wavelength, signature

AXLE_KN = 22.5 * 9.81           # a 22.5 t axle [kN]
MM = 5e-4                       # D is rounded to 1 mm


def wagons(length, wheelbase, n=20):
    """Axle positions [m] of ``n`` two-axle wagons of ``length`` with their axles ``wheelbase`` apart,
    centred on the wagon."""
    return (length * np.arange(n)[:, None] + length / 2 + np.array([-wheelbase, wheelbase])[None, :] / 2).ravel()


@pytest.mark.parametrize("length, wheelbase", [(12.5, 8.0), (15.5, 10.0), (16.5, 10.0), (20.0, 12.0)])
def test_two_axle_wagons_of_the_range_get_their_length_from_a_peak_below_it(length, wheelbase):
    """A wagon's own phasor |2 cos(π wheelbase/λ)| is weaker at λ = L than at a harmonic L/i
    (i = 3, or 5 for 20 m on 12 m), so the train peaks there, more than DOMINANCE times its highest
    in 12-30 m; D is the spacing that recurs most at an order of that peak: L, every axle of 19 of
    the 20 wagons."""
    x = wagons(length, wheelbase)
    F = np.full(x.size, AXLE_KN)

    def own(lam):
        return abs(2 * np.cos(np.pi * wheelbase / lam))
    peak, span = principal_wavelength(x, F), x[-1] - x[0]
    assert peak.length_m == pytest.approx(length, abs=MM) and peak.share == pytest.approx(19 / 20)
    assert peak.below_m == peak.wavelength_m < WAVELENGTH_RANGE_M[0]
    i = round(length / peak.wavelength_m)
    assert i > 1 and abs(i / length - 1 / peak.wavelength_m) <= 1 / span and own(length / i) > 2 * own(length)
    assert peak.signature > DOMINANCE * signature(x, F, np.linspace(*WAVELENGTH_RANGE_M, 4000)).max()
    assert peak.text() == f"D = {length:g} m from its dynamic signature"
    assert Train.from_axle_table(x, 1e3 * F, 1.0).characteristic_length == pytest.approx(length, abs=MM)


def test_wagons_whose_axles_are_evenly_spaced_below_the_range_get_no_d():
    """16 m wagons on an 8 m wheelbase: every axle 8 m behind the last, a period shorter than the
    range, which recurs at the peak below it for as many axles as any multiple: no D, and the
    text says why."""
    x = wagons(16.0, 8.0)
    peak = principal_wavelength(x, np.full(x.size, AXLE_KN))
    assert peak.length_m is None and peak.below_m is not None and peak.share >= MIN_SHARE
    assert peak.text() == (f"no characteristic length D from its dynamic signature (its signature peaks at "
                           f"{peak.below_m:.4g} m, below the 12-30 m of coaches, more than {DOMINANCE:g} times higher "
                           "than within them: wagons shorter than 12 m, whose D is not read)")


def test_coaches_of_24_and_26_m_alternating_get_their_period():
    """A power car and five coaches of 24, 26, 24, 26, 24 m (bogies 3.5 m from each end): the axle
    table repeats every 24 + 26 = 50 m, while 24 m and 26 m each recur for a third of the axles;
    the signature peaks near their mean, 25 m = 50/2, and D is the period, 50 m."""
    x, front = [2.5, 5.5, 14.5, 17.5], 20.0
    for length in (24.0, 26.0, 24.0, 26.0, 24.0):
        x += [front + 2.25, front + 4.75, front + length - 4.75, front + length - 2.25]
        front += length
    x, F = np.array(x), np.array([190.0] * 4 + [150.0] * 20)
    peak, span = principal_wavelength(x, F), x[-1] - x[0]
    assert peak.length_m == pytest.approx(24.0 + 26.0, abs=MM) and peak.share == 12 / 24
    assert abs(2 / peak.length_m - 1 / peak.wavelength_m) <= 1 / span and peak.below_m is None
