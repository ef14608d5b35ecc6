"""Numbers given as text, and parameters accepted but meaningless, in the Python object API.

A text where a number is expected is a value read from a file and not converted: it is refused in
one line naming the object and the value (``vtsi.errors.as_number``, ``as_numbers``), as a bool
already was; numpy's numbers (np.float64, np.int64, np.float32, 0-d arrays) stay numbers. The
command layer and the TOML/CLI readers convert their words before they call the objects
(tests/test_tcl.py, test_command*.py, test_cli*.py, test_sweep.py run them). A NaN, an inf or a
negative value where it means nothing is refused alike, and so is a Newmark β in (0, 10⁻⁶): its
round-off, not its scheme, is what a coupled run then shows (measured below).
"""
import math
import re
from fractions import Fraction

import numpy as np
import pytest

import vtsi
import vtsi.integrators.newmark as newmark
from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
from vtsi.codes.en1991_2 import damping_lower_bound, dynamic_factor, frequency_limits, hslm_b_refusal
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.damping import decks_cutoff_hz, rayleigh_coefficients, rayleigh_damping, rayleigh_ratio
from vtsi.errors import AnalysisError, ModelError, as_number, as_numbers, is_number
from vtsi.influence import InfluenceLines
from vtsi.integrators import HHT, Bathe, CentralDifference, GeneralizedAlpha, Newmark
from vtsi.analysis import modes_up_to
from vtsi.modal_bridge import ModalBridge
from vtsi.models import Train, four_dof_car, moving_force, moving_mass, sprung_mass, ten_dof_car
from vtsi.models.bridges import continuous_beam, first_frequency, simply_supported_beam
from vtsi.models.cars import TEN_DOF_PARAMETERS, car_from_catalogue
from vtsi.models.irregularity import Irregularity, fra_psd, german_psd, sample_profile
from vtsi.models.scenes import S2, s2_model, s3_model
from vtsi.models.trains import hslm_b
from vtsi.passage import Output, PassageRunner, PassageSettings, contact_force_mean, dt_resolving
from vtsi.recorders import TrainRecorder
from vtsi.reference import elimination
from vtsi.reference.fryba import daf, moving_force_midspan, speed_of_alpha, static_midspan
from vtsi.scene3d import PassageScene
from vtsi.track import Track
from vtsi.train import TrainSubdomain

NAN, INF = float("nan"), float("inf")
SPAN, E, I, MU = 20.0, 3e10, 2.0, 2e4           # a simply supported beam: f1 = 6.80 Hz
F = r"\d+\.\d+"                                  # a frequency [Hz] in a message


def beam(n_el=10):
    model = vtsi.Model()
    bridge = simply_supported_beam(model, SPAN, n_el, E, I, MU)
    return model, bridge, Track(model, bridge.elements)


@pytest.fixture(scope="module")
def modal():
    model, _, track = beam()
    return ModalBridge(model, track, n_modes=3, zeta=0.02)


@pytest.fixture(scope="module")
def lines():
    model, bridge, track = beam()
    return InfluenceLines(model, track, dofs=[(bridge.midspan_nodes[0], 2)])


def ten_dof(**change):
    params = {key: 1.0 for key in TEN_DOF_PARAMETERS}
    params.update(bogie_centre_spacing=17.5, axle_spacing=2.5, **change)
    return ten_dof_car(params)


def modal_bridge(**kwargs):
    model, _, track = beam()
    return ModalBridge(model, track, **kwargs)


def runner(**kwargs):
    model, bridge, _ = beam()
    return PassageRunner(model, bridge.elements, PassageSettings(), **kwargs)


CAR = moving_force(1e5)

# -- 1. a number given as text ------------------------------------------------------------------
TEXT = [   # (label, call, error class, the whole message)
    ("ModalBridge f_max", lambda: modal_bridge(f_max="60"), ModelError,
     r"modal bridge: f_max \[Hz\] must be a number, got '60'"),
    ("ModalBridge f_max as bytes", lambda: modal_bridge(f_max=b"60"), ModelError,
     r"modal bridge: f_max \[Hz\] must be a number, got b'60'"),
    ("ModalBridge f_max as numpy text", lambda: modal_bridge(f_max=np.str_("60")), ModelError,
     r"modal bridge: f_max \[Hz\] must be a number, got np.str_\('60'\)"),
    ("ModalBridge zeta", lambda: modal_bridge(n_modes=3, zeta="0.02"), ModelError,
     r"modal bridge: damping ratios must be numbers, got '0.02'"),
    ("ModalBridge zeta list", lambda: modal_bridge(n_modes=3, zeta=["0.02"] * 3), ModelError,
     r"modal bridge: damping ratios must be numbers, got \['0.02', '0.02', '0.02'\]"),
    ("ModalBridge zeta function", lambda: modal_bridge(n_modes=3, zeta=lambda f: "0.02"), ModelError,
     rf"modal bridge: the damping function's ratio at {F} Hz must be a number, got '0.02'"),
    ("Newmark gamma", lambda: Newmark("0.5"), AnalysisError, r"integrator Newmark: gamma must be a number, got '0.5'"),
    ("Newmark beta", lambda: Newmark(beta="0.25"), AnalysisError,
     r"integrator Newmark: beta must be a number, got '0.25'"),
    ("HHT alpha", lambda: HHT("0.9"), AnalysisError, r"integrator HHT: alpha must be a number, got '0.9'"),
    ("GeneralizedAlpha alpha_m", lambda: GeneralizedAlpha("1.0", 0.8), AnalysisError,
     r"integrator GeneralizedAlpha: alpha_m must be a number, got '1.0'"),
    ("Bathe gamma", lambda: Bathe("0.5"), AnalysisError, r"integrator Bathe: gamma must be a number, got '0.5'"),
    ("transient dt", lambda: vtsi.TransientAnalysis(beam()[0], "Newmark", "1e-3"), AnalysisError,
     r"transient analysis: dt must be a number, got '1e-3'"),
    ("LoadControl increment", lambda: vtsi.StaticAnalysis(beam()[0], "0.1"), AnalysisError,
     r"LoadControl: increment must be a number, got '0.1'"),
    ("modes_up_to f_max", lambda: modes_up_to(beam()[0], "60"), AnalysisError,
     r"modes_up_to: f_max \[Hz\] must be a number, got '60'"),
    ("damping ratio", lambda: rayleigh_damping(beam()[0], "0.02"), ModelError,
     r"damping: the ratio must be a number, got '0.02'"),
    ("Rayleigh frequencies", lambda: rayleigh_ratio("5", 0.1, 1e-3), ModelError,
     r"rayleigh ratio: frequencies must be numbers \[Hz\], got '5'"),
    ("cut-off of decks", lambda: decks_cutoff_hz(["5", "20", "45"]), ModelError,
     r"EN 1990 A2.4.4.2.1: the cut-off of decks needs each deck's n0, n2, n3 \[Hz\], \(n_decks, 3\), "
     r"got \['5', '20', '45'\]"),
    ("cut-off", lambda: acceleration_cutoff_hz(["5", "20", "45"]), ModelError,
     r"EN 1990 A2.4.4.2.1: the cut-off needs the first three vertical frequencies > 0 \[Hz\], in increasing "
     r"order \(n0 first\), got \['5', '20', '45'\]"),
    ("Table 6.6 span", lambda: damping_lower_bound("steel", "10"), ModelError,
     r"EN 1991-2 Table 6.6: span \[m\] must be a number, got '10'"),
    ("HSLM-B spans of the decks", lambda: hslm_b_refusal([["5"]]), ModelError,
     r"EN 1991-2 6.4.6.1.1: a deck's spans \[m\] must be numbers, got \['5'\]"),
    ("HSLM-B span", lambda: hslm_b("3", 50.0), ModelError,
     r"hslm_b: span L = '3' m is outside the range of EN 1991-2 Figure 6.13, 1 m <= L < 7 m \(HSLM-A covers "
     r"L >= 7 m\): L must be a number"),
    ("moving force", lambda: moving_force("1e5"), ModelError, r"moving_force: P must be a number, got '1e5'"),
    ("sprung mass", lambda: sprung_mass("5750", 1.6e6), ModelError, r"sprung_mass: m_s must be a number, got '5750'"),
    ("ten-dof car", lambda: ten_dof(body_mass="4e4"), ModelError,
     r"ten_dof_car: body_mass must be a number, got '4e4'"),
    ("catalogue car gravity", lambda: car_from_catalogue("ICE3_coach", g="9.81"), ModelError,
     r"ten_dof_car: g must be a number, got '9.81'"),
    ("train speed", lambda: Train([CAR], [0.0], "50"), ModelError,
     r"train 'train': speed \[m/s\] must be a number, got '50'"),
    ("train max_speed", lambda: Train([CAR], [0.0], 50.0, max_speed="300"), ModelError,
     r"train 'train': max_speed must be a number, got '300'"),
    ("train car offsets", lambda: Train([CAR], ["0"], 50.0), ModelError,
     r"train 'train': car_offsets must be numbers \[m\], got \['0'\]"),
    ("train characteristic length", lambda: Train([CAR], [0.0], 50.0, characteristic_length="20"), ModelError,
     r"train 'train': characteristic_length must be a finite length > 0 \[m\], 'signature' \(from the train's "
     r"dynamic signature\) or None, got '20'"),
    ("axle table", lambda: Train.from_axle_table(["0", "3"], [1e5, 1e5], 50.0), ModelError,
     r"Train.from_axle_table: positions \[m\] must be numbers, got \['0', '3'\]"),
    ("car matrix", lambda: vtsi.vehicle.Car("c", "user", [["1"]], [[0.0]], [[1.0]], [-9.81], [0], [0.0], ("y",)),
     ModelError, r"car 'c': M must be numbers, got \[\['1'\]\]"),
    ("continuous beam spans", lambda: continuous_beam(vtsi.Model(), ["20"], 10, E, I, MU), ModelError,
     r"continuous_beam: a span length \[m\] must be a number, got '20'"),
    ("continuous beam x0", lambda: continuous_beam(vtsi.Model(), [20.0], 10, E, I, MU, x0="0"), ModelError,
     r"continuous_beam: x0 \[m\] must be a number, got '0'"),
    ("beam frequency", lambda: first_frequency("20", E, I, MU), ModelError,
     r"first_frequency: L must be a number, got '20'"),
    ("S3 approach", lambda: s3_model(vtsi.Model(), approach="2"), ModelError,
     r"s3_model: approach \[m\] must be a number, got '2'"),
    ("Fryba speed", lambda: moving_force_midspan(1e5, "10", SPAN, E * I, MU, [0.1]), ModelError,
     r"moving force: V must be a number, got '10'"),
    ("Fryba times", lambda: moving_force_midspan(1e5, 10.0, SPAN, E * I, MU, ["0.1"]), ModelError,
     r"moving force: times t \[s\] must be numbers, got \['0.1'\]"),
    ("Fryba damping", lambda: daf(0.1, zeta="0.02"), ModelError,
     r"moving force: damping ratio must be a number, got '0.02'"),
    ("irregularity spectrum", lambda: fra_psd(["1.0"]), ModelError,
     r"fra_psd: omega \[rad/m\] must be numbers, got \['1.0'\]"),
    ("irregularity band", lambda: sample_profile(german_psd, [0.0, 1.0], ("3", "150")), ModelError,
     r"sample_profile: wavelength_band \[m\] must be numbers, got \('3', '150'\)"),
    ("irregularity samples", lambda: Irregularity(["0", "1"], [0.0, 0.0]), ModelError,
     r"Irregularity: x \[m\] must be numbers, got \['0', '1'\]"),
    ("sweep dt", lambda: PassageSettings(dt="0.001"), ModelError, r"sweep settings: dt must be a number, got '0.001'"),
    ("sweep damping_hz", lambda: PassageSettings(damping=0.01, damping_hz=("2", "30")), ModelError,
     r"sweep settings: damping_hz must be two different frequencies > 0 \[Hz\], got \('2', '30'\)"),
    ("output cut-off", lambda: Output("a", "accel", cutoff="60"), ModelError,
     r"output 'a': cutoff must be 'en' or a frequency > 0 \[Hz\], got '60'"),
    ("scene deck depth", lambda: PassageScene([0.0, SPAN], [0.0, SPAN], deck_depth="1.5"), ModelError,
     r"deck_depth: expected a positive number, got '1.5'"),
]




def test_the_modal_bridge_and_the_influence_lines_refuse_text_in_their_queries(modal, lines):
    with pytest.raises(ModelError, match=r"^modal bridge: axle loads must be numbers, got \['1e5'\]$"):
        modal.coordinates([0.0], ["1e5"], 10.0, 0.0, 3, 1e-3)
    with pytest.raises(ModelError, match=r"^modal bridge: passage dt must be a number, got '1e-3'$"):
        modal.coordinates([0.0], [1e5], 10.0, 0.0, 3, "1e-3")
    with pytest.raises(ModelError, match=r"^modal bridge: added ratios must be numbers, got \['0.01'\]$"):
        modal.add_ratios(["0.01"])
    with pytest.raises(ModelError, match=r"^influence lines: LM71 alpha must be a number, got '1.33'$"):
        lines.lm71_envelope("1.33")
    with pytest.raises(ModelError, match=r"^influence lines: axle loads \[N\] must be numbers, got \['1e5'\]$"):
        lines.train_envelope([0.0], ["1e5"])


def test_a_long_refused_value_is_shown_short_on_one_line():
    """A thousand text items (a column read from a file): the message shows the first eight."""
    with pytest.raises(ModelError) as info:
        as_numbers(["0.02"] * 1000, "modal bridge", "damping ratios")
    assert str(info.value) == ("modal bridge: damping ratios must be numbers, got ['0.02', '0.02', '0.02', '0.02', "
                               "'0.02', '0.02', '0.02', '0.02', ...]")
    with pytest.raises(ModelError) as info:
        as_number(np.arange(100.0), "modal bridge", "f_max [Hz]")
    assert str(info.value) == ("modal bridge: f_max [Hz] must be a number, got array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, "
                               "6.0, 7.0, ...])")


# -- numpy's numbers stay numbers -----------------------------------------------------------------
NUMBERS = [1, 2.5, np.float64(2.5), np.float32(2.5), np.int64(3), np.int8(3), np.array(2.5), np.array(3),
           Fraction(5, 2), np.longdouble(2.5)]
NOT_NUMBERS = ["2.5", b"2.5", np.str_("2.5"), True, np.bool_(False), np.array(True), np.array([2.5]),
               np.array("2.5"), 2.5 + 0j, np.complex128(2.5), None, [2.5], np.array(2.5, dtype=object)]


@pytest.mark.parametrize("value", NUMBERS, ids=repr)
def test_numpy_numbers_and_zero_d_arrays_are_numbers(value):
    """What numpy hands a user as a scalar (a reduction, ``np.asarray(x)`` of a scalar, a 0-d
    array), Python's ints, floats and Fractions: each is its float."""
    assert is_number(value)
    assert as_number(value, "w", "x") == float(value)
    assert as_numbers([value, value], "w", "x").tolist() == [float(value)] * 2


@pytest.mark.parametrize("value", NOT_NUMBERS, ids=repr)
def test_text_bools_complex_and_arrays_of_items_are_not_numbers(value):
    assert not is_number(value)
    with pytest.raises(ModelError, match=r"^w: x must be a number, got "):
        as_number(value, "w", "x")


def test_numpy_numbers_give_what_floats_give():
    """Rayleigh's closed form α = 2ζω_aω_b/(ω_a + ω_b), β = 2ζ/(ω_a + ω_b) from numpy numbers as
    from floats; an integrator from a 0-d array as from a float."""
    w_a, w_b = 2 * math.pi * 2.0, 2 * math.pi * 30.0
    expected = (2 * 0.02 * w_a * w_b / (w_a + w_b), 2 * 0.02 / (w_a + w_b))
    assert rayleigh_coefficients(np.float64(0.02), np.int64(2), np.array(30.0)) == pytest.approx(expected, rel=1e-15)
    scheme = Newmark(np.array(0.5), np.float32(0.25))
    assert (scheme.gamma, scheme.beta) == (0.5, 0.25) and type(scheme.beta) is float
    assert as_numbers([Fraction(1, 4), np.float32(0.5)], "w", "x").dtype == np.float64


# -- 2. Newmark's beta in (0, 1e-6): round-off, not the scheme ------------------------------------
BETA_REASON = ("a displacement the step imposes (a wheel held to the rail) gives an acceleration divided by beta "
               "dt^2, whose round-off returns as eps/(2 beta) of the response a step (contact forces 1e-2 off at "
               "beta = 1e-12)")


@pytest.mark.parametrize("make, name, beta", [
    (lambda: Newmark(0.5, 1e-300), "Newmark", 1e-300), (lambda: Newmark(0.6, 9.9e-7), "Newmark", 9.9e-7),
    (lambda: Newmark(0.5, 5e-324), "Newmark", 5e-324), (lambda: HHT(1.0, 0.5, 1e-12), "HHT", 1e-12),
    (lambda: HHT(0.9, 0.6, 1e-8), "HHT", 1e-8)])
def test_a_beta_between_0_and_the_floor_is_refused_with_the_reason(make, name, beta):
    with pytest.raises(AnalysisError) as info:
        make()
    assert str(info.value) == (f"integrator {name}: beta = {beta:g} is neither 0 (central differences) nor >= 1e-06: "
                               + BETA_REASON)


def test_beta_zero_and_the_floor_itself_are_taken():
    assert Newmark(0.5, 0.0).explicit and CentralDifference().explicit
    at_floor = Newmark(0.5, newmark.BETA_MIN)
    assert not at_floor.explicit and at_floor.beta == 1e-6
    assert HHT(1.0, 0.5, 1e-6).beta == 1e-6


def test_at_the_floor_beta_changes_a_step_by_at_most_four_times_itself():
    """docs/theory/integrators.md: what β changes in a step is βΩ² against the mass's 1, Ω below
    the stability limit (2 for γ = ½): the amplification matrix of Newmark(½, 10⁻⁶) differs from
    central differences' by at most 4·10⁻⁶ of its largest entry over Ω in (0, 2)."""
    for omega_dt in np.linspace(0.05, 1.99, 40):
        a, b = Newmark(0.5, newmark.BETA_MIN).amplification(omega_dt), CentralDifference().amplification(omega_dt)
        assert np.abs(a - b).max() <= 4 * newmark.BETA_MIN * np.abs(b).max()


def s2_passage(beta, dt=1e-4):
    """S2 (Yang & Yau's sprung mass on a massless wheel, 10 elements) with Newmark(½, β): the body's
    displacement and the contact force at each step's end."""
    model = vtsi.Model()
    bridge, train = s2_model(model, 10)
    sub = TrainSubdomain(train, 0.0)
    body = TrainRecorder(sub, ["car0.body_y"], "disp")
    run = CoupledAnalysis(model, MovingLoadConstraint(Track(model, bridge.elements), sub), Newmark(0.5, beta), dt,
                          recorders=[body])
    run.static()
    run.run(int(round(S2["L"] / S2["V"] / dt)))
    return body.values[:, 0], run.contact_force_end[:, 0]


def test_below_the_floor_a_coupled_run_shows_round_off_growing_as_one_over_beta(monkeypatch):
    """The measurement behind the floor (docs/theory/integrators.md), the floor lifted: against
    β = 10⁻⁴, β = 10⁻⁶ moves the contact force by the scheme's own difference (2.6e-8) and the body
    by 3e-11; β = 10⁻¹² by ε/(2β) = 1.1e-4 of the body's response and 6.7e-3 of the force."""
    monkeypatch.setattr(newmark, "BETA_MIN", 0.0)
    body_ref, force_ref = s2_passage(1e-4)

    def off(beta):
        body, force = s2_passage(beta)
        return (np.abs(body - body_ref).max() / np.abs(body_ref).max(),
                np.abs(force - force_ref).max() / np.abs(force_ref).max())

    eps = np.finfo(float).eps
    body, force = off(1e-6)
    assert body < 1e-9 and force < 1e-7
    body, force = off(1e-12)
    assert body > 0.3 * eps / 2e-12 and force > 1e-3


@pytest.mark.parametrize("params, message", [
    ((1.0, 1.0, 1e300, 1e300), "gamma = 1e+300 is above 1 + alpha_m - alpha_f, 1/2 above its second-order value (1, "
                               "as Newmark's gamma <= 1): a larger one damps first-order beyond use"),
    ((0.9, 0.7, 1.3, 0.9), "gamma = 1.3 is above 1 + alpha_m - alpha_f, 1/2 above its second-order value (1.2, as "
                           "Newmark's gamma <= 1): a larger one damps first-order beyond use"),
    ((0.9, 0.7, 1.2, 1.5), "beta = 1.5 is above (1 + alpha_m - alpha_f)^2, 4 times its second-order value (1.44, as "
                           "Newmark's beta <= 1): a larger one lengthens the period beyond use")])
def test_generalized_alpha_refuses_gamma_and_beta_beyond_newmarks_ends(params, message):
    with pytest.raises(AnalysisError) as info:
        GeneralizedAlpha(*params[:2], gamma=params[2], beta=params[3])
    assert str(info.value) == (f"integrator GeneralizedAlpha: {message} (at 1e8 a step no longer moves the "
                               "response)")


def test_generalized_alpha_at_its_upper_ends_is_newmark_at_its():
    """αM = αF = 1 is Newmark (docs/theory/integrators.md): its new upper ends are Newmark's γ = β = 1,
    the same step; and at γ = β = 10⁸ (refused now) the response no longer moves: one step of
    the free oscillator at Ω = 2π/20 keeps u within 2e-7 of its start."""
    ga, nm = GeneralizedAlpha(1.0, 1.0, gamma=1.0, beta=1.0), Newmark(1.0, 1.0)
    assert np.array_equal(ga.amplification(0.3), nm.amplification(0.3))
    frozen = GeneralizedAlpha(1.0, 1.0, gamma=1.0, beta=1.0)
    frozen.gamma = frozen.beta = 1e8
    omega_dt = 2 * math.pi / 20
    u = frozen.amplification(omega_dt) @ np.array([1.0, 0.0, -omega_dt ** 2])
    assert abs(u[0] - 1.0) < 2e-7


# -- 3. NaN, inf or a negative value where it means nothing -------------------------------------
MEANINGLESS = [   # (label, call, error class, the whole message)
    ("ModalBridge f_max NaN", lambda: modal_bridge(f_max=NAN), ModelError,
     r"modal bridge: f_max \[Hz\] must be > 0 and finite, got nan"),
    ("ModalBridge f_max negative", lambda: modal_bridge(f_max=-60.0), ModelError,
     r"modal bridge: f_max \[Hz\] must be > 0 and finite, got -60.0"),
    ("ModalBridge f_max inf", lambda: modal_bridge(f_max=INF), ModelError,
     r"modal bridge: f_max \[Hz\] must be > 0 and finite, got inf"),
    ("ModalBridge n_modes 0", lambda: modal_bridge(n_modes=0), ModelError,
     r"modal bridge: n_modes must be an integer >= 1 or 'all', got 0"),
    ("ModalBridge n_modes NaN", lambda: modal_bridge(n_modes=NAN), ModelError,
     r"modal bridge: n_modes must be an integer >= 1 or 'all', got nan"),
    ("ModalBridge n_modes 2.5", lambda: modal_bridge(n_modes=2.5), ModelError,
     r"modal bridge: n_modes must be an integer >= 1 or 'all', got 2.5"),
    ("ModalBridge n_modes True", lambda: modal_bridge(n_modes=True), ModelError,
     r"modal bridge: n_modes must be an integer >= 1 or 'all', got True"),
    ("ModalBridge zeta NaN", lambda: modal_bridge(n_modes=3, zeta=NAN), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got nan"),
    ("ModalBridge zeta negative", lambda: modal_bridge(n_modes=3, zeta=-0.01), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got -0.01"),
    ("ModalBridge zeta list with NaN", lambda: modal_bridge(n_modes=3, zeta=[0.02, NAN, 0.02]), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got \[0.02, nan, 0.02\]"),
    ("ModalBridge zeta list too short", lambda: modal_bridge(n_modes=3, zeta=[0.02, 0.02]), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got \[0.02, 0.02\]"),
    ("ModalBridge zeta bools", lambda: modal_bridge(n_modes=3, zeta=[True, False, True]), ModelError,
     r"modal bridge: damping ratios must be numbers, got \[True, False, True\]"),
    ("ModalBridge zeta function NaN", lambda: modal_bridge(n_modes=3, zeta=lambda f: NAN), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got a function giving "
     r"\[nan, nan, nan\]"),
    ("ModalBridge zeta function negative", lambda: modal_bridge(n_modes=3, zeta=lambda f: -0.01), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got a function giving "
     r"\[-0.01, -0.01, -0.01\]"),
    ("ModalBridge zeta function inf", lambda: modal_bridge(n_modes=3, zeta=lambda f: INF), ModelError,
     r"modal bridge: damping ratios must be finite and >= 0, one per kept mode \(3\), got a function giving "
     r"\[inf, inf, inf\]"),
    ("ModalBridge zeta function None", lambda: modal_bridge(n_modes=3, zeta=lambda f: None), ModelError,
     rf"modal bridge: the damping function's ratio at {F} Hz must be a number, got None"),
    ("ModalBridge zeta function True", lambda: modal_bridge(n_modes=3, zeta=lambda f: True), ModelError,
     rf"modal bridge: the damping function's ratio at {F} Hz must be a number, got True"),
    ("damping ratio NaN", lambda: rayleigh_damping(beam()[0], NAN), ModelError,
     r"damping: the ratio must be in \[0, 1\) \(0.01 for 1 %\), got nan"),
    ("damping frequency NaN", lambda: rayleigh_coefficients(0.02, NAN, 30.0), ModelError,
     r"damping: frequencies must be > 0 and finite \[Hz\], got \(nan, 30\)"),
    ("Rayleigh alpha NaN", lambda: rayleigh_ratio(5.0, NAN, 1e-3), ModelError,
     r"rayleigh ratio: alpha \[1/s\] and beta \[s\] must be finite and >= 0, got \(nan, 0.001\)"),
    ("Rayleigh alpha negative", lambda: rayleigh_ratio(5.0, -1.0, 1e-3), ModelError,
     r"rayleigh ratio: alpha \[1/s\] and beta \[s\] must be finite and >= 0, got \(-1, 0.001\)"),
    ("Rayleigh beta inf", lambda: rayleigh_ratio(5.0, 0.1, INF), ModelError,
     r"rayleigh ratio: alpha \[1/s\] and beta \[s\] must be finite and >= 0, got \(0.1, inf\)"),
    ("moving mass gravity NaN", lambda: moving_mass(1e4, g=NAN), ModelError, r"moving_mass: g must be > 0, got nan"),
    ("sprung mass damper negative", lambda: sprung_mass(1e4, 1e6, c_s=-1.0), ModelError,
     r"sprung_mass: c_s must be >= 0, got -1.0"),
    ("sprung mass wheel inf", lambda: sprung_mass(1e4, 1e6, m_w=INF), ModelError,
     r"sprung_mass: m_w must be >= 0, got inf"),
    ("four-dof car axle spacing inf", lambda: four_dof_car(4e4, 2e6, 3e3, 1e6, 1e4, INF), ModelError,
     r"four_dof_car: l_c must be > 0, got inf"),
    ("ten-dof car damping negative", lambda: ten_dof(primary_damping=-1.0), ModelError,
     r"ten_dof_car: primary_damping must be >= 0, got -1.0"),
    ("moving force inf", lambda: moving_force(INF), ModelError, r"moving_force: P must be > 0, got inf"),
    ("train speed NaN", lambda: Train([CAR], [0.0], NAN), ModelError,
     r"train 'train': speed must be finite and >= 0, got nan"),
    ("train speed negative", lambda: Train([CAR], [0.0], -1.0), ModelError,
     r"train 'train': speed must be finite and >= 0, got -1.0"),
    ("train speed inf", lambda: Train([CAR], [0.0], 50.0).with_speed(INF), ModelError,
     r"train 'train': speed must be finite and >= 0, got inf"),
    ("train max_speed NaN (any speed passed)", lambda: Train([CAR], [0.0], 1000.0, max_speed=NAN), ModelError,
     r"train 'train': max_speed must be > 0 and finite, got nan"),
    ("train car length NaN", lambda: Train.uniform(CAR, 2, NAN, 50.0), ModelError,
     r"Train.uniform: car_length must be > 0, got nan"),
    ("Fryba alpha NaN", lambda: daf(NAN), ModelError, r"daf: alpha must be > 0, got nan"),
    ("Fryba alpha inf", lambda: daf(INF), ModelError, r"daf: alpha must be finite, got inf"),
    ("Fryba alpha 0", lambda: daf(0.0), ModelError, r"daf: alpha must be > 0, got 0.0"),
    ("Fryba damping NaN", lambda: daf(0.1, zeta=NAN), ModelError,
     r"moving force: damping ratio must be in \[0, 1\), got nan"),
    ("Fryba damping negative", lambda: daf(0.1, zeta=-0.01), ModelError,
     r"moving force: damping ratio must be in \[0, 1\), got -0.01"),
    ("Fryba modes 0 (a deflection of 0)", lambda: daf(0.1, n_modes=0), ModelError,
     r"moving force: n_modes must be an integer >= 1, got 0"),
    ("Fryba modes 2.5", lambda: daf(0.1, n_modes=2.5), ModelError,
     r"moving force: n_modes must be an integer >= 1, got 2.5"),
    ("Fryba free periods negative", lambda: daf(0.1, free_periods=-1.0), ModelError,
     r"daf: free_periods must be >= 0 and finite, got -1.0"),
    ("Fryba force NaN", lambda: moving_force_midspan(NAN, 10.0, SPAN, E * I, MU, [0.1]), ModelError,
     r"moving force: P, V, L, EI, mu must be finite, got nan, 10.0, 20.0, 60000000000.0, 20000.0"),
    ("Fryba speed inf", lambda: moving_force_midspan(1e5, INF, SPAN, E * I, MU, [0.1]), ModelError,
     r"moving force: P, V, L, EI, mu must be finite, got 100000.0, inf, 20.0, 60000000000.0, 20000.0"),
    ("Fryba time NaN (read as before the entry: w = 0)",
     lambda: moving_force_midspan(1e5, 10.0, SPAN, E * I, MU, [NAN]), ModelError,
     r"moving force: times t must be finite \[s\], got nan"),
    ("Fryba alpha of a speed NaN", lambda: speed_of_alpha(NAN, SPAN, E * I, MU), ModelError,
     r"speed_of_alpha: alpha must be > 0 and finite, got nan"),
    ("Fryba static deflection EI 0", lambda: static_midspan(1e5, SPAN, 0.0), ModelError,
     r"static_midspan: EI must be > 0 and finite, got 0.0"),
    ("beam frequency of a negative span", lambda: first_frequency(-SPAN, E, I, MU), ModelError,
     r"first_frequency: L must be > 0 and finite, got -20.0"),
    ("continuous beam x0 NaN", lambda: continuous_beam(vtsi.Model(), [20.0], 10, E, I, MU, x0=NAN), ModelError,
     r"continuous_beam: x0 must be finite \[m\], got nan"),
    ("S3 approach inf", lambda: s3_model(vtsi.Model(), approach=INF), ModelError,
     r"s3_model: approach must be finite \[m\], got inf"),
    ("Phi2 of a NaN length", lambda: dynamic_factor(NAN), ModelError,
     r"EN 1991-2 6.4.5.2: span \[m\] must be > 0 and finite, got nan"),
    ("frequency limits of a negative span", lambda: frequency_limits(-5.0), ModelError,
     r"EN 1991-2 Figure 6.10: span \[m\] must be > 0 and finite, got -5.0"),
    ("FRA class True (was class 1)", lambda: fra_psd(1.0, True), ModelError,
     r"fra_psd: unknown fra_class True; valid: 1, 2, 3, 4, 5, 6"),
    ("FRA class 1.0 (was a crash)", lambda: fra_psd(1.0, 2.5), ModelError,
     r"fra_psd: unknown fra_class 2.5; valid: 1, 2, 3, 4, 5, 6"),
    ("profile waves True (was one wave)", lambda: sample_profile(german_psd, [0.0, 1.0], n_waves=True), ModelError,
     r"sample_profile: n_waves must be a positive integer, got True"),
    ("profile waves NaN (was a crash)", lambda: sample_profile(german_psd, [0.0, 1.0], n_waves=NAN), ModelError,
     r"sample_profile: n_waves must be a positive integer, got nan"),
    ("profile of a negative spectrum (was NaN)", lambda: sample_profile(lambda w: -german_psd(w), [0.0, 1.0],
                                                                        n_waves=4), ModelError,
     r"sample_profile: psd\(omega\) must give a finite value >= 0 \[m²/\(rad/m\)\] for each of the 4 omega, "
     r"got shape \(4,\), -[0-9.e-]+"),
    ("sweep damping_hz NaN", lambda: PassageSettings(damping=0.01, damping_hz=(NAN, 30.0)), ModelError,
     r"sweep settings: damping_hz must be two different frequencies > 0 \[Hz\], got \(nan, 30.0\)"),
    ("output cut-off negative", lambda: Output("a", "accel", cutoff=-5.0), ModelError,
     r"output 'a': cutoff must be 'en' or a frequency > 0 \[Hz\], got -5.0"),
    ("output node 3.7 (was node 3)", lambda: Output("a", "disp", nodes=(3.7,)), ModelError,
     r"output 'a': nodes must be 'deck', 'track', 'midspan', 'supports', 'piers' or node tags, got \(3.7,\)"),
    ("output history 'no' (was True)", lambda: Output("a", "disp", history="no"), ModelError,
     r"output 'a': history must be True or False, got 'no'"),
    ("contact force mean over dt 0 (was a ZeroDivisionError)", lambda: contact_force_mean(np.ones((5, 2)), 0.0),
     ModelError, r"contact force mean: dt \[s\] must be > 0 and finite, got 0.0"),
    ("time step of 0 Hz (was a ZeroDivisionError)", lambda: dt_resolving(0.0), ModelError,
     r"time step: frequency \[Hz\] must be > 0 and finite, got 0.0"),
    ("time step at damping 0 (was Python's math domain error)", lambda: dt_resolving(30.0, 0.0), ModelError,
     r"time step: damping ratio must be > 0 and finite, got 0.0"),
    ("sweep modal damping NaN", lambda: runner(modal_damping=[(NAN, 0.02)]), ModelError,
     r"sweep: modal damping \(nan Hz, 0.02\): the frequency must be > 0 and the ratio >= 0, both finite"),
    ("sweep modal damping as text", lambda: runner(modal_damping=[("5", "0.02")]), ModelError,
     r"sweep: modal damping \(frequency \[Hz\], ratio\) pairs must be numbers, got \[\('5', '0.02'\)\]"),
    ("sweep top speed NaN", lambda: runner(top_speed_kmh=NAN), ModelError,
     r"sweep: top speed \[km/h\] must be > 0 and finite, got nan"),
    ("reference solver gravity negative", lambda: elimination.solve(*s2_constraint(), 0.1, gravity=-9.81),
     AnalysisError, r"reference solver: gravity \[m/s²\] must be >= 0 and finite, got -9.81"),
    ("reference solver end time as text", lambda: elimination.solve(*s2_constraint(), "0.1"), AnalysisError,
     r"reference solver: t_end \[s\] must be a number, got '0.1'"),
]


def s2_constraint():
    """S2's beam and the constraint of its sprung mass (a reference solver's arguments)."""
    model = vtsi.Model()
    bridge, train = s2_model(model, 10)
    return model, MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, 0.0))


@pytest.mark.parametrize("call, error, message", [row[1:] for row in TEXT + MEANINGLESS],
                         ids=[row[0] for row in TEXT + MEANINGLESS])
def test_a_number_given_as_text_or_a_meaningless_value_is_refused_naming_it(call, error, message):
    with pytest.raises(error) as info:
        call()
    assert type(info.value) is error and "\n" not in str(info.value)
    assert re.fullmatch(message, str(info.value)), str(info.value)


@pytest.mark.parametrize("call, message", [
    (lambda m: m.coordinates([0.0], [1e5], True, 0.0, 3, 1e-3),
     r"modal bridge: passage speed must be a number, got True"),
    (lambda m: m.coordinates([0.0], [1e5], 10.0, True, 3, 1e-3),
     r"modal bridge: passage x_head0 \[m\] must be a number, got True"),
    (lambda m: m.coordinates([0.0], [1e5], 10.0, 0.0, True, 1e-3),
     r"modal bridge: passage n_samples must be an integer >= 0, got True"),
    (lambda m: m.coordinates([0.0], [1e5], INF, 0.0, 3, 1e-3),
     r"modal bridge: passage speed must be > 0 and finite, got inf"),
], ids=["speed True (was 1 m/s)", "x_head0 True (was 1 m)", "n_samples True (was 1)", "speed inf"])
def test_a_modal_passage_refuses_a_bool_or_an_infinite_speed(modal, call, message):
    with pytest.raises(ModelError) as info:
        call(modal)
    assert re.fullmatch(message, str(info.value)), str(info.value)


@pytest.mark.parametrize("alpha, shown", [(NAN, "nan"), (-1.0, "-1.0"), (0.0, "0.0"), (INF, "inf")])
def test_the_classification_factor_of_the_influence_lines(lines, alpha, shown):
    for envelope, model in ((lines.lm71_envelope, "LM71"), (lines.sw0_envelope, "SW/0")):
        with pytest.raises(ModelError) as info:
            envelope(alpha)
        assert str(info.value) == f"influence lines: {model} alpha must be > 0 and finite, got {shown}"
