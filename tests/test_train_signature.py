"""A train's dynamic signature and the characteristic length D an axle table gets from it
(vtsi/signature.py; docs/trains.md, "D from the dynamic signature").

The signature is checked against closed forms (one axle, two axles, a uniform row of axles); D
against the coach lengths the trains are built with: HSLM-A1 … A10 (EN 1991-2 Table 6.3), HSLM-B
(its spacing d), the ICE3 (its published car length) and trains built here as repeated coaches
(an articulated TGV-like set, a Talgo-like set, a freight train, a three-car regional train).
Irregular random tables get no D. An axle table on the command line (``vtsi sweep --trains
a4.csv --speeds en:300``) runs the EN series of the catalogue's HSLM-A4.
"""
import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.errors import ModelError
from vtsi.models import Train, hslm_a, hslm_b, ice3, ice3_axle_loads
from vtsi.models.trains import hslm_b_parameters
from vtsi.signature import (DOMINANCE, HARMONICS, MIN_REPEATS, MIN_SHARE, SPACING_BAND_M, WAVELENGTH_RANGE_M,
                            principal_wavelength, signature)
from vtsi.sweep import en_speed_grid, resonance_speeds
from vtsi.sweep_results import SweepResults
from vtsi.units import Units

# EN 1991-2 Table 6.3: the coach length D [m] of HSLM-A1 … A10
HSLM_A_D = {1: 18.0, 2: 19.0, 3: 20.0, 4: 21.0, 5: 22.0, 6: 23.0, 7: 24.0, 8: 25.0, 9: 26.0, 10: 27.0}
ICE3_D = 24.775         # ICE3/AVE S103 car length: bogie centres 17.375 m + 2 × 3.7 m to the car ends (Goicolea 2014)
MM = 5e-4               # D is rounded to 1 mm


def coaches(n, length, axles, first=0.0):
    """Offsets [m] of ``n`` identical coaches of ``length`` whose axles sit at ``axles`` [m] from the
    coach's front, the first coach's front at ``first``."""
    return (first + length * np.arange(n)[:, None] + np.asarray(axles)[None, :]).ravel()


def bogie_train(length, centres, n=8):
    """(offsets [m], loads [kN]): a locomotive (16.5 m, axles 3 m and 10 m apart), ``n`` vehicles
    of ``length`` on two 2.5 m bogies ``centres`` apart, centred on the vehicle, and a locomotive."""
    loco = np.array([1.75, 4.75, 11.75, 14.75])
    first = (length - centres) / 2 - 1.25
    body = coaches(n, length, [first, first + 2.5, first + centres, first + centres + 2.5], first=16.5)
    x = np.concatenate([loco, body, 16.5 + n * length + loco])
    return x, np.concatenate([np.full(4, 210.0), np.full(4 * n, 160.0), np.full(4, 210.0)])


def built_trains():
    """{name: (offsets [m], loads [kN], D [m])}: trains of identical coaches of length D between
    locomotives or power cars whose own spacings differ (illustrative geometry, near the real
    trains'; D is the construction's coach length)."""
    power_car = np.array([0.0, 3.0, 14.0, 17.0])                   # two bogies of 3 m, 14 m apart
    jacobs = coaches(9, 18.7, [-1.5, 1.5], first=22.5)             # articulated trailers on 9 shared bogies
    tgv = np.concatenate([power_car, jacobs, jacobs[-1] + 5.5 + power_car])
    loco = np.array([0.0, 2.65, 11.0, 13.65])
    talgo_axles = coaches(13, 13.14, [0.0], first=21.65)           # one axle between consecutive coaches
    talgo = np.concatenate([loco, talgo_axles, talgo_axles[-1] + 8.0 + loco])
    wagons = coaches(20, 19.74, [2.47, 4.27, 16.87, 18.67], first=18.1)   # Sgns-like: 1.8 m bogies 14.4 m apart
    freight = np.concatenate([loco, wagons])
    regional = coaches(3, 26.4, [3.45, 5.95, 22.45, 24.95])        # bogie centres 19 m apart, 2.5 m wheelbase
    return {
        "TGV-like": (tgv, np.concatenate([np.full(4, 170.0), np.full(18, 160.0), np.full(4, 170.0)]), 18.7),
        "Talgo-like": (talgo, np.concatenate([np.full(4, 180.0), np.full(13, 120.0), np.full(4, 180.0)]), 13.14),
        "freight": (freight, np.concatenate([np.full(4, 210.0), np.full(80, 225.0)]), 19.74),
        "regional": (regional, np.full(12, 130.0), 26.4),
    }


# -- the signature ---------------------------------------------------------------------------------
def test_a_single_axle_has_its_load_at_every_wavelength():
    lam = np.geomspace(0.5, 500.0, 301)
    np.testing.assert_allclose(signature([7.3], [170.0], lam), 170.0, rtol=1e-15)


def test_two_equal_axles_closed_form():
    """Axles F at 0 and d: the partial sums are F and F (1 + e^{2πj d/λ}), of modulus 2F|cos(π d/λ)|."""
    F, d = 2e5, 3.0
    lam = np.linspace(1.0, 40.0, 1001)
    np.testing.assert_allclose(signature([5.0, 5.0 + d], [F, F], lam),
                               np.maximum(F, 2 * F * np.abs(np.cos(np.pi * d / lam))), rtol=1e-12)


def test_a_uniform_row_of_axles_closed_form():
    """N axles F, d apart: |Σ_{k<i} e^{2πj k d/λ}| = |sin(iπd/λ) / sin(πd/λ)|, the partial sums of a
    geometric series; every partial sum counts (the maximum over i is not always the last)."""
    F, d, N = 170.0, 3.0, 12
    lam = np.linspace(2.0, 20.0, 997)
    lam = lam[np.abs(np.sin(np.pi * d / lam)) > 1e-3]
    i = np.arange(1, N + 1)[:, None]
    expected = F * np.max(np.abs(np.sin(i * np.pi * d / lam) / np.sin(np.pi * d / lam)), axis=0)
    np.testing.assert_allclose(signature(d * np.arange(N), np.full(N, F), lam), expected, rtol=1e-9)
    np.testing.assert_allclose(signature(d * np.arange(N), np.full(N, F), [d, d / 2, d / 3]), N * F, rtol=1e-12)


def test_the_signature_keeps_the_shape_of_the_wavelengths_and_ignores_the_origin():
    x, F = hslm_a(3, 1.0).wheel_offsets, np.full(46, 180.0)
    lam = np.linspace(10.0, 30.0, 12).reshape(3, 4)
    G = signature(x, F, lam)
    assert G.shape == (3, 4)
    np.testing.assert_allclose(signature(x + 123.4, F, lam), G, rtol=1e-10)


# -- D of trains whose coach length is known -------------------------------------------------------
@pytest.mark.parametrize("number", sorted(HSLM_A_D))
def test_every_hslm_a_gets_its_coach_length(number):
    """The peak itself lies off D (each coach's own phasor pulls it: HSLM-A7 at 23.857 m), inside
    the peak's main lobe |1/λ − 1/D| ≤ 1/L; D is the spacing that recurs there, exactly."""
    train = hslm_a(number, 1.0)
    x, F, D = train.wheel_offsets, train.static_wheel_loads, HSLM_A_D[number]
    peak = principal_wavelength(x, F)
    assert peak.length_m == pytest.approx(D, abs=MM)
    assert abs(1 / peak.wavelength_m - 1 / D) <= 1 / (x[-1] - x[0])
    assert peak.share >= MIN_SHARE
    assert Train.from_axle_table(x, F, 1.0).characteristic_length == pytest.approx(D, abs=MM)


def test_the_peak_is_refined_to_the_top_of_the_signature():
    """λ* beats every wavelength of a fine grid across its main lobe (the coarse grid steps
    1/(8 L) in 1/λ; the refinement is a bounded Brent search between its neighbours)."""
    train = hslm_a(7, 1.0)
    x, F = train.wheel_offsets, train.static_wheel_loads
    peak = principal_wavelength(x, F)
    k = np.linspace(1 / peak.wavelength_m - 1 / (x[-1] - x[0]), 1 / peak.wavelength_m + 1 / (x[-1] - x[0]), 20001)
    assert signature(x, F, 1 / k).max() <= peak.signature * (1 + 1e-12)
    assert peak.signature == pytest.approx(signature(x, F, [peak.wavelength_m])[0], rel=1e-14)


def test_the_ice3_gets_its_car_length_as_forces_and_as_cars():
    """From its axle loads, and from the static wheel loads of its 10-dof cars
    (characteristic_length='signature' works for any Train)."""
    forces = ice3_axle_loads(8, speed=1.0)
    peak = principal_wavelength(forces.wheel_offsets, forces.static_wheel_loads)
    assert peak.length_m == pytest.approx(ICE3_D, abs=MM) and peak.share == 28 / 32   # 7 of 8 cars' axles recur
    # the peak, off D: the whole train's sum in closed form, 8 cars' phasors C(λ) times the array
    # factor sin(8πD/λ) / sin(πD/λ), maximised on a grid of 1 mm
    car = forces.wheel_offsets[:4] - forces.wheel_offsets[0]
    lam = np.arange(22.0, 27.0, 1e-3)
    closed = (np.abs(np.exp(2j * np.pi * car[None, :] / lam[:, None]).sum(axis=1))
              * np.abs(np.sin(8 * np.pi * ICE3_D / lam) / np.sin(np.pi * ICE3_D / lam)))
    assert peak.wavelength_m == pytest.approx(lam[np.argmax(closed)], abs=1e-3) and peak.wavelength_m < ICE3_D - 0.3
    cars = ice3(8, speed=1.0)
    built = Train(cars.cars, cars.car_offsets, 1.0, characteristic_length="signature")
    assert built.characteristic_length == pytest.approx(ICE3_D, abs=MM)
    for n_cars in (2, 3, 4):     # two cars: the bogie spacing 17.375 m recurs as often, the longer D is chosen
        short = ice3_axle_loads(n_cars, speed=1.0)
        assert principal_wavelength(short.wheel_offsets, short.static_wheel_loads).length_m == pytest.approx(
            ICE3_D, abs=MM)


@pytest.mark.parametrize("span", (1.0, 4.0, 6.999))
def test_hslm_b_gets_its_spacing_in_its_own_range_and_none_among_coaches(span):
    """N equal forces d = 2.5-3.5 m apart: between 2 and 5 m (no harmonic d/i there) D = d; in
    the coaches' 12-30 m the signature only rises towards long wavelengths: no peak."""
    N, d = hslm_b_parameters(span)
    train = hslm_b(span, 1.0)
    assert principal_wavelength(train.wheel_offsets, train.static_wheel_loads, (2.0, 5.0)).length_m == pytest.approx(
        d, abs=MM)
    among_coaches = principal_wavelength(train.wheel_offsets, train.static_wheel_loads)
    assert among_coaches.wavelength_m is None and among_coaches.length_m is None
    if among_coaches.below_m is None:
        assert among_coaches.text() == ("no characteristic length D from its dynamic signature "
                                        "(it has no peak between 12 and 30 m)")
    else:       # d = 3.5 m: the grid below the range ends a lobe past 12 / 3 m, on the main lobe of d
        assert d < among_coaches.below_m < N * d / (N - 1) < WAVELENGTH_RANGE_M[0] / 3     # its first zero
        assert among_coaches.text() == (
            "no characteristic length D from its dynamic signature (its signature peaks at "
            f"{among_coaches.below_m:.4g} m or below, below the 12-30 m of coaches, more than 2 times higher than "
            "within them: wagons shorter than 12 m, whose D is not read)")


@pytest.mark.parametrize("name", sorted(built_trains()))
def test_trains_of_repeated_coaches_get_their_coach_length(name):
    x, F, D = built_trains()[name]
    peak = principal_wavelength(x, F)
    assert peak.length_m == pytest.approx(D, abs=MM)
    assert WAVELENGTH_RANGE_M[0] < peak.wavelength_m < WAVELENGTH_RANGE_M[1]


@pytest.mark.parametrize("length, centres", [(24.5, 15.5), (25.0, 16.0), (26.0, 16.5), (27.0, 17.0),
                                             (34.0, 15.5), (34.0, 17.5), (40.0, 19.0)])
def test_vehicles_whose_signature_peaks_at_half_their_length_get_it(length, centres):
    """Bogie centres a third to two thirds of the vehicle's length apart weaken its own phasor at D
    (two 2.5 m bogies: |2 cos(π 2.5/λ)| |2 cos(π centres/λ)|), so 8 of them between two locomotives peak at
    the harmonic D/2, inside its main lobe |2/D − 1/λ*| ≤ 1/L and outside the fundamental's:
    coaches of 24.5-27 m (the rule that read D in the fundamental's lobe alone gave them none)
    and wagons of 34-40 m, longer than the range (it gave two of them a spacing between bogies,
    17.5 m and 21 m, whose EN series misses D/3). D is the spacing that recurs for most axles at an
    order i ≤ HARMONICS; the EN series of that D refines around n₀ λ*, the signature's peak."""
    x, F = bogie_train(length, centres)
    peak, span = principal_wavelength(x, F), x[-1] - x[0]

    def vehicle(lam):
        return abs(2 * np.cos(np.pi * 2.5 / lam)) * abs(2 * np.cos(np.pi * centres / lam))
    assert vehicle(length) < vehicle(length / 2)
    assert abs(2 / length - 1 / peak.wavelength_m) <= 1 / span < abs(1 / length - 1 / peak.wavelength_m)
    assert peak.length_m == pytest.approx(length, abs=MM) and peak.share >= MIN_SHARE
    n0 = 5.0                                                         # [Hz] any frequency: v = n0 λ
    refined = resonance_speeds([n0], [peak.length_m]) / 3.6 / n0     # [m] the wavelengths D / i the series refines
    assert np.min(np.abs(1 / refined - 1 / peak.wavelength_m)) <= 1 / span
    assert len(refined) == HARMONICS


def test_positions_rounded_to_a_decimetre_give_d_within_a_rounding_step():
    """A table read to 0.1 m: the spacings D apart take the two values next to D on the 0.1 m
    lattice (all within SPACING_BAND_M); D is one of them or between."""
    for train in [hslm_a(n, 1.0) for n in HSLM_A_D] + [ice3_axle_loads(8, speed=1.0)]:
        x = np.round(train.wheel_offsets, 1)
        D = principal_wavelength(x, train.static_wheel_loads).length_m
        assert abs(D - train.characteristic_length) <= SPACING_BAND_M / 2       # 0.1 m, one rounding step


# -- no D -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ("spacings 1.5-20 m", "spacings 1.5-10 m", "random bogies"))
def test_irregular_random_tables_get_no_d(kind):
    """Axles at random spacings, or two-axle bogies (2.5 m) at random spacings, 24-200 axles,
    loads 80-250 kN: no spacing recurs for MIN_SHARE of the axles at an order i ≤ HARMONICS of the
    peak (measured over 18000 such tables: at most 0.33; over 30000 tables of 24-40 axles in
    random bogies, the likeliest to meet a spacing by chance: at most 0.385)."""
    rng = np.random.default_rng(2024)
    for _ in range(40):
        n = int(rng.integers(24, 201))
        if kind == "random bogies":
            x = np.concatenate([c + np.array([0.0, 2.5]) for c in np.cumsum(rng.uniform(5.0, 25.0, n // 2))])
        else:
            x = np.concatenate([[0.0], np.cumsum(rng.uniform(1.5, 20.0 if "20" in kind else 10.0, n - 1))])
        peak = principal_wavelength(x, rng.uniform(80.0, 250.0, x.size))
        assert peak.length_m is None and peak.share < MIN_SHARE
        assert Train.from_axle_table(x, np.full(x.size, 2e5), 1.0).characteristic_length is None


@pytest.mark.parametrize("length, wheelbase", [(7.0, 4.0), (9.0, 5.5), (10.0, 6.0), (11.0, 6.5)])
def test_wagons_shorter_than_the_range_get_no_false_d(length, wheelbase):
    """40 two-axle wagons shorter than 12 m: every spacing recurs, multiples of the wagon inside
    12-30 m too, and the range holds only sidelobes of the wagons' own peak (a review found D =
    26 m for 10 m wagons, so that 'en:' refined around 117-234 km/h and stepped 10 km/h across
    the true resonance n0 x 10 m). The peak below the range, DOMINANCE times the range's or more,
    gives no D, and says so. Coaches' harmonics below the range stay under it (ICE3: 0.96)."""
    x = np.sort(np.concatenate([k * length + np.array([0.0, wheelbase]) for k in range(40)]))
    F = np.full(x.size, 2e5)
    peak = principal_wavelength(x, F)
    assert peak.length_m is None and peak.below_m is not None and peak.below_m < WAVELENGTH_RANGE_M[0]
    lam_in = np.linspace(*WAVELENGTH_RANGE_M, 4000)
    assert signature(x, F, [peak.below_m])[0] > DOMINANCE * signature(x, F, lam_in).max()
    assert peak.text() == (f"no characteristic length D from its dynamic signature (its signature peaks at "
                           f"{peak.below_m:.4g} m, below the 12-30 m of coaches, more than {DOMINANCE:g} times higher "
                           "than within them: wagons shorter than 12 m, whose D is not read)")
    assert Train.from_axle_table(x, F, 1.0).characteristic_length is None
    ice3 = ice3_axle_loads(8, speed=1.0)
    below = np.linspace(WAVELENGTH_RANGE_M[0] / 3, WAVELENGTH_RANGE_M[0], 4000)
    ratio = (signature(ice3.wheel_offsets, ice3.static_wheel_loads, below).max()
             / signature(ice3.wheel_offsets, ice3.static_wheel_loads, lam_in).max())
    assert 0.9 < ratio < 1 < DOMINANCE


def test_a_short_table_gets_no_d():
    """One four-axle coach: its bogie spacing recurs (2 axles, share 0.5) but fewer than
    MIN_REPEATS axles make it; a loco and a coach: nothing recurs."""
    coach = ice3_axle_loads(2, speed=1.0).wheel_offsets[:4]
    peak = principal_wavelength(coach, np.full(4, 150.0))
    assert peak.repeats == 2 and peak.share == 0.5 >= MIN_SHARE and MIN_REPEATS > 2 and peak.length_m is None
    assert peak.text() == ("no characteristic length D from its dynamic signature (no regular axle spacing at its "
                           f"peak, {peak.wavelength_m:.4g} m: 2 axles repeat there, a D needs {MIN_REPEATS})")
    loco_and_coach = Train.from_axle_table([0.0, 3.0, 14.0, 17.0, 21.0, 23.5, 40.5, 43.0], np.full(8, 2e5), 1.0)
    assert loco_and_coach.characteristic_length is None
    assert loco_and_coach.signature_peak.text().startswith(
        "no characteristic length D from its dynamic signature (no regular axle spacing at its peak, ")


def test_a_peak_in_a_models_units_says_its_lengths_in_them(tmp_path):
    """Units.train converts the peak's lengths into the model's, and its text names that unit:
    HSLM-A4's D = 21 m reads 21000 mm; a single axle's range, 12-30 m, reads 1200-3000 cm."""
    train = hslm_a(4, 1.0)
    derived = Train.from_axle_table(train.wheel_offsets, train.static_wheel_loads, 1.0)
    assert Units("kN", "mm").train(derived, 1000.0).signature_peak.text() == (
        f"D = {1000 * HSLM_A_D[4]:g} mm from its dynamic signature")
    single = Units("kN", "cm").train(Train.from_axle_table([0.0], [2e5], 1.0), 100.0).signature_peak
    assert single.text() == ("no characteristic length D from its dynamic signature (it has no peak between "
                             f"{100 * WAVELENGTH_RANGE_M[0]:g} and {100 * WAVELENGTH_RANGE_M[1]:g} cm)")


# -- the train's characteristic_length ------------------------------------------------------------
def test_axle_tables_derive_d_unless_told(tmp_path):
    train = hslm_a(4, 1.0)
    x, F = train.wheel_offsets, train.static_wheel_loads
    derived = Train.from_axle_table(x, F, 1.0)
    assert derived.characteristic_length == 21.0 and derived.signature_peak.text() == (
        "D = 21 m from its dynamic signature")
    assert derived.with_speed(50.0).signature_peak is derived.signature_peak
    assert Train.from_axle_table(x, F, 1.0, characteristic_length=None).characteristic_length is None
    given = Train.from_axle_table(x, F, 1.0, characteristic_length=20.5)
    assert given.characteristic_length == 20.5 and given.signature_peak is None
    assert hslm_a(4, 1.0).signature_peak is None          # the catalogue gives D
    path = tmp_path / "a4.csv"
    path.write_text("position_m,load_kN\n" + "".join(f"{p:.4f},190\n" for p in x))
    from_csv = Train.from_csv(path, 1.0)
    assert from_csv.characteristic_length == 21.0 and from_csv.signature_peak.length_m == 21.0
    assert Train.from_csv(path, 1.0, characteristic_length=None).characteristic_length is None
    with pytest.raises(ModelError, match=r"^train 'x': characteristic_length must be a finite length > 0 \[m\], "
                                         r"'signature' \(from the train's dynamic signature\) or None, "
                                         r"got 'Signature'$"):
        Train.from_axle_table(x, F, 1.0, name="x", characteristic_length="Signature")


@pytest.mark.parametrize("call, message", [
    (lambda: signature([0.0, 3.0, 3.0], [1.0, 1.0, 1.0], [20.0]),
     r"^signature: axle 2: position 3.0 m is not greater than the previous 3.0 m$"),
    (lambda: signature([0.0, 3.0], [1.0, -2.0], [20.0]), r"^signature: axle 1: load must be > 0, got -2$"),
    (lambda: signature([0.0, 3.0], [1.0, 1.0], [20.0, 0.0]),
     r"^signature: wavelengths must be finite and > 0 \[m\], got \[20.0, 0.0\]$"),
    (lambda: signature([0.0, 3.0], [1.0], [20.0]),
     r"^signature: positions and loads must be 1-d arrays of equal, non-zero length, got shapes \(2,\) and \(1,\)$"),
    (lambda: principal_wavelength([0.0, 3.0], [1.0, 1.0], (30.0, 12.0)),
     r"^principal_wavelength: wavelength_range must be two lengths 0 < low < high \[m\], got \(30.0, 12.0\)$"),
    (lambda: principal_wavelength([0.0, float("nan")], [1.0, 1.0]),
     r"^principal_wavelength: axle 1: position must be finite, got nan$"),
])
def test_bad_inputs_are_named(call, message):
    with pytest.raises(ModelError, match=message):
        call()


# -- the command line ------------------------------------------------------------------------------
@pytest.fixture
def bridge(tmp_path, beam_toml):
    """The 20 m beam of ``beam_toml`` with I = 1.9 m⁴ (not f1), [analysis] damping 1.25 %, dt 10 ms."""
    return beam_toml(tmp_path / "bridge.toml", {"f1_Hz": None, "I_m4": 1.9}, damping=0.0125, dt_s=0.01)


def test_an_axle_table_on_the_command_line_runs_the_en_series_of_its_catalogue_train(tmp_path, bridge):
    """'vtsi sweep --trains a4.csv --speeds en:300': the CSV of HSLM-A4's axles gets D = 21 m, so
    its series is the one of D = 21 m (EN 1991-2 Table 6.3), with the fine steps around each
    resonance that the series without a D lacks; the results file keeps D for the check and the
    report."""
    table = tmp_path / "a4.csv"
    table.write_text("position_m,load_kN\n" + "".join(f"{p:.4f},190\n" for p in hslm_a(4, 1.0).wheel_offsets))
    assert main(["sweep", str(bridge), "--trains", str(table), "--speeds", "en:300", "--dt", "0.015",
                 "--workers", "1", "--quiet", "--out", str(tmp_path / "out.h5")]) == 0
    results = SweepResults(tmp_path / "out.h5")
    series = en_speed_grid(300.0, results.frequencies_hz, [HSLM_A_D[4]])
    np.testing.assert_array_equal(results.speeds_kmh, series)
    assert results.train_data(str(table))["characteristic_length_m"] == HSLM_A_D[4]
    assert len(series) > len(en_speed_grid(300.0, results.frequencies_hz, []))


def test_the_command_line_says_once_where_each_axle_tables_d_came_from(tmp_path, bridge, capsys):
    """Standard error names, once per axle table, the D its signature gave (HSLM-A4's axles: 21 m,
    EN 1991-2 Table 6.3) or why it gave none (a locomotive and one coach: its bogie spacing recurs
    twice), and that such a train's resonances are unknown, so that the EN series steps finely; the
    catalogue's trains, whose D is given, get no line; --quiet says nothing."""
    a4, loco = tmp_path / "a4.csv", tmp_path / "loco.csv"
    a4.write_text("position_m,load_kN\n" + "".join(f"{p:.4f},190\n" for p in hslm_a(4, 1.0).wheel_offsets))
    loco.write_text("position_m,load_kN\n0,200\n3,200\n11,200\n14,200\n20,150\n22.5,150\n37,150\n39.5,150\n")
    argv = ["sweep", str(bridge), "--trains", f"{a4},{loco},A1", "--speeds", "200", "--workers", "1",
            "--out", str(tmp_path / "out.h5")]
    assert main(argv) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "dynamic signature" in line]
    assert lines[0] == f"vtsi sweep: {a4}: D = {HSLM_A_D[4]:g} m from its dynamic signature"
    assert lines[1].startswith(f"vtsi sweep: {loco}: no characteristic length D from its dynamic signature (")
    assert lines[1].endswith(": its resonances are unknown; the EN series steps 2 km/h throughout for it")
    assert len(lines) == 2
    assert main(argv[:-2] + ["--quiet", "--overwrite", "--out", str(tmp_path / "out.h5")]) == 0
    assert "dynamic signature" not in capsys.readouterr().err
