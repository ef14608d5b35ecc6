"""What an integrator is given, and the checks an analysis makes once it is prepared.

From a probe of the integrators: an empty slot in an integrator's text moved the numbers after it
to the wrong parameters ('GeneralizedAlpha(,0.8)' took 0.8 for αM); a bool was a parameter
(Newmark(True, True) ran as γ = β = 1); Bathe took any γ in (0, 1) (γ = 1e-12 ran 2.9e-3 off its
own scheme); a user class without ``stages`` raised a bare NotImplementedError; HHT's refusal and
docs/theory/integrators.md gave different reasons. And from a speed probe (benchmarks S1): the
contract check of vtsi's own schemes is made once per (class, parameters, Δt), and the build's
check of element matrices is one compiled call per block; both refuse what they refused.

Nothing is registered here (tests/test_integrator_contract.py is parametrised over the registry).
"""
from fractions import Fraction

import numpy as np
import pytest

import vtsi
import vtsi.integrators.base as integrator_base
from vtsi.__main__ import main
from vtsi.elements import ELEMENT_TYPES
from vtsi.elements.base import MATRIX_RTOL, checked_matrix
from vtsi.errors import AnalysisError, ModelError
from vtsi.integrators import HHT, Bathe, GeneralizedAlpha, Integrator, Newmark, make_integrator, register
from vtsi.integrators.bathe import GAMMA_RANGE
from vtsi.recorders import NodeRecorder
from vtsi.timeseries import Constant

K, MASS, P = 400.0, 1.0, 400.0        # oscillator: ω = 20 rad/s [N/m, kg, N], static deflection 1 m
EPS = np.finfo(float).eps


def oscillator():
    """Node 2 on a vertical zeroLength spring K with mass MASS, under a constant load P at uy."""
    model = vtsi.Model()
    model.node(1, 0.0, 0.0)
    model.node(2, 0.0, 0.0)
    model.fix(1, 1, 1, 1)
    model.fix(2, 1, 0, 1)
    model.element("zeroLength", 1, (1, 2), ky=K)
    model.mass(2, MASS, MASS, 0.0)
    model.pattern(1, Constant(1.0))
    model.load(1, 2, 0.0, P, 0.0)
    return model


def run(integrator, n, dt):
    rec = NodeRecorder([2], [2])
    vtsi.TransientAnalysis(oscillator(), integrator, dt, recorders=[rec]).run(n)
    return rec.values[:, 0]


# -- 1. an empty argument in an integrator's text ----------------------------------------------------
@pytest.mark.parametrize("spec, position", [("Newmark(,0.3)", "1 of 2"), ("Newmark(0.6,,)", "2 of 3"),
                                            ("GeneralizedAlpha(,0.8)", "1 of 2"),
                                            ("GeneralizedAlpha(1.2,,0.9)", "2 of 3"), ("HHT(0.9,,0.35)", "2 of 3"),
                                            ("Bathe(,)", "1 of 2"), ("Newmark(0.5,)", "2 of 2"),
                                            ("Newmark(gamma=0.6, )", "2 of 2")])
def test_an_empty_argument_is_refused_naming_the_text_and_its_position(spec, position):
    """The probe's cases: each was accepted with the numbers shifted, or refused naming the wrong
    parameter ('Newmark(,0.3)': 'gamma = 0.3 is outside [0.5, 1]')."""
    with pytest.raises(AnalysisError) as info:
        make_integrator(spec)
    assert str(info.value) == (f"integrator {spec!r}: argument {position} is empty; give every number, or name the "
                               "ones after a parameter left at its default ('HHT(0.9, beta=0.35)')")


def test_no_argument_and_named_arguments_still_work():
    """``'Newmark()'`` is no argument (the defaults), and naming the parameter after one left at its
    default is what the message proposes: HHT(0.9, beta=0.35) keeps γ = 3/2 − α = 0.6."""
    for spec in ("Newmark()", "Newmark( )", "Newmark"):
        assert (make_integrator(spec).gamma, make_integrator(spec).beta) == (0.5, 0.25)
    hht = make_integrator("HHT(0.9, beta=0.35)")
    assert (hht.alpha, hht.gamma, hht.beta) == (0.9, pytest.approx(0.6, abs=1e-15), 0.35)


def test_the_command_line_refuses_an_empty_argument_in_one_line(tmp_path, beam_toml, capsys):
    bridge = beam_toml(tmp_path / "bridge.toml", damping=0.0125, dt_s=0.01)
    status = main(["sweep", str(bridge), "--trains", "A1", "--speeds", "200", "--integrator", "GeneralizedAlpha(,0.8)",
                   "--out", str(tmp_path / "out.h5"), "--workers", "1", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert len(err) == 1 and "integrator 'GeneralizedAlpha(,0.8)': argument 1 of 2 is empty" in err[0], err
    assert not (tmp_path / "out.h5").exists()


# -- 2. a bool is not a number -----------------------------------------------------------------------
@pytest.mark.parametrize("make, name, parameter, value", [
    (lambda: Newmark(True, True), "Newmark", "gamma", True),
    (lambda: Newmark(0.5, np.bool_(False)), "Newmark", "beta", np.bool_(False)),
    (lambda: HHT(True), "HHT", "alpha", True),
    (lambda: HHT(0.9, True), "HHT", "gamma", True),
    (lambda: GeneralizedAlpha(1.0, True), "GeneralizedAlpha", "alpha_f", True),
    (lambda: GeneralizedAlpha(1.0, 0.8, None, True), "GeneralizedAlpha", "beta", True),
    (lambda: Bathe(True), "Bathe", "gamma", True)])
def test_a_bool_parameter_is_refused_as_transient_analysis_refuses_dt_true(make, name, parameter, value):
    """Newmark(True, True) ran as γ = β = 1; TransientAnalysis(dt=True) was already refused."""
    with pytest.raises(AnalysisError) as info:
        make()
    assert str(info.value) == f"integrator {name}: {parameter} must be a number, got {value!r}"
    with pytest.raises(AnalysisError, match=r"^transient analysis: dt must be a number, got True$"):
        vtsi.TransientAnalysis(oscillator(), "Newmark", True)


# -- 3. Bathe's γ --------------------------------------------------------------------------------------
def bathe_exact(gamma, dt, n):
    """u_1..u_n of the oscillator from rest (a₀ = 0) by Bathe & Baig's two formulas, in exact
    rational arithmetic on the float inputs: the trapezoidal rule to γΔt, then v = c₁u_n + c₂u_γ + c₃u,
    a = c₁v_n + c₂v_γ + c₃v with M a + K u = P solved for u."""
    g, dt, k, m, p = Fraction(gamma), Fraction(dt), Fraction(K), Fraction(MASS), Fraction(P)
    h = g * dt
    c1, c2, c3 = (1 - g) / (g * dt), -1 / ((1 - g) * g * dt), (2 - g) / ((1 - g) * dt)
    u = v = a = Fraction(0)
    out = []
    for _ in range(n):
        a_g = (p - k * (u + h * v + h * h / 4 * a)) / (m + k * h * h / 4)
        u_g, v_g = u + h * v + h * h / 4 * (a + a_g), v + h / 2 * (a + a_g)
        v_known = c1 * u + c2 * u_g
        a_known = c1 * v + c2 * v_g + c3 * v_known
        u = (p - m * a_known) / (m * c3 * c3 + k)
        v, a = v_known + c3 * u, a_known + c3 * c3 * u
        out.append(float(u))
    return np.array(out)


@pytest.mark.parametrize("gamma", [GAMMA_RANGE[0], 0.5, GAMMA_RANGE[1]])
def test_bathe_at_the_ends_of_its_range_is_its_scheme_to_round_off(gamma):
    """Inside the range the round-off stays within n ε / γ of the amplitude (the growth through
    c₂ = −1/((1 − γ)γΔt) that the range bounds): 60 steps against exact arithmetic."""
    n, dt = 60, 1e-3
    exact = bathe_exact(gamma, dt, n)
    assert np.abs(run(Bathe(gamma), n, dt) - exact).max() <= n * EPS / gamma * np.abs(exact).max()


@pytest.mark.parametrize("gamma", [0.0, 1e-300, 1e-12, 1e-4, 9.99e-4, 0.9995, 1.0, 1.5,
                                   float("nan")])
def test_bathe_refuses_gamma_outside_its_range_with_the_reason(gamma):
    with pytest.raises(AnalysisError) as info:
        Bathe(gamma)
    assert str(info.value) == (f"integrator Bathe: gamma = {gamma:g} is outside [0.001, 0.999] (below it round-off "
                               "grows like 1e-16/gamma through c2 = -1/((1 - gamma) gamma dt); near either end the "
                               "scheme damps little below omega*dt = 1/gamma, resp. 1/(1 - gamma))")


def bathe_spectral_radius(gamma, omega_dt):
    """ρ of Bathe's step on ü + ω²u = 0 (Δt = 1), from the paper's formulas (not vtsi's stages):
    the step applied to the unit states (u, v, a)."""
    g, k = gamma, omega_dt ** 2
    c1, c2, c3 = (1 - g) / g, -1 / ((1 - g) * g), (2 - g) / (1 - g)
    amp = np.empty((3, 3))
    for j, (u, v, a) in enumerate(np.eye(3)):
        a_g = -k * (u + g * v + g * g / 4 * a) / (1 + k * g * g / 4)
        u_g, v_g = u + g * v + g * g / 4 * (a + a_g), v + g / 2 * (a + a_g)
        v_known = c1 * u + c2 * u_g
        a_known = c1 * v + c2 * v_g + c3 * v_known
        u1 = -a_known / (c3 * c3 + k)
        amp[:, j] = u1, v_known + c3 * u1, a_known + c3 * c3 * u1
    return np.max(np.abs(np.linalg.eigvals(amp)))


def test_beyond_the_range_bathe_no_longer_damps_what_it_is_chosen_for():
    """docs/theory/integrators.md: at γ = 1e-6 or 1 − 1e-6 the spectral radius at ωΔt = 10⁴ is
    0.99999 (the trapezoidal rule's 1), which Integrator.dissipative would still call dissipative;
    inside the range it is at most 0.2, the same from vtsi's stages as from the paper's formulas;
    ρ = 0.89 at ωΔt = 1/γ and 0.71 at 1/(1 − γ)."""
    for gamma in (1e-6, 1.0 - 1e-6):
        assert 0.9999 < bathe_spectral_radius(gamma, 1e4) < 1.0
    ends = np.geomspace(GAMMA_RANGE[0], 0.5, 7)           # γ from the lower end to ½, and 1 − γ likewise
    for gamma in np.concatenate([ends, 1.0 - ends]):
        rho = Bathe(gamma).spectral_radius(1e4)
        assert rho <= 0.2 and rho == pytest.approx(bathe_spectral_radius(gamma, 1e4), rel=1e-8), gamma
    low, high = GAMMA_RANGE
    assert bathe_spectral_radius(low, 1.0 / low) == pytest.approx(0.89, abs=0.005)
    assert bathe_spectral_radius(high, 1.0 / (1.0 - high)) == pytest.approx(0.71, abs=0.005)


# -- 4. a class without stages --------------------------------------------------------------------------
def test_a_class_without_stages_is_refused_at_registration_naming_it():
    class NoStages(Integrator):
        name, n_stages = "NoStages-test", 1

    with pytest.raises(TypeError) as info:
        register(NoStages)
    assert str(info.value) == "integrator NoStages: must define stages(dt), returning its n_stages Stage objects"
    assert "NoStages-test" not in integrator_base.INTEGRATORS


def test_an_unregistered_instance_without_stages_is_named_when_an_analysis_asks():
    """It raised a NotImplementedError with an empty message from inside the analysis."""
    class NoStages(Integrator):
        name, n_stages = "NoStages-test", 1

    with pytest.raises(AnalysisError) as info:
        vtsi.TransientAnalysis(oscillator(), NoStages(), 1e-3).run(1)
    assert str(info.value) == ("integrator NoStages: stages(dt) is not defined; an integrator class must define "
                               "stages(dt), returning its n_stages Stage objects (vtsi.integrators.base)")


# -- 5. HHT's γ below 3/2 − α: the message and the docs say the same ------------------------------------
def hht_spectral_radius(alpha, gamma, beta, omega_dt):
    """Largest root of docs/theory/integrators.md §2's characteristic polynomial of HHT."""
    tail = np.polymul([alpha, 1.0 - alpha], [beta, 0.5 - 2.0 * beta + gamma, 0.5 + beta - gamma])
    return np.max(np.abs(np.roots(np.polyadd([1.0, -2.0, 1.0, 0.0], omega_dt ** 2 * tail))))


def test_hht_gamma_below_three_halves_minus_alpha_names_the_growth_the_docs_state():
    """HHT(0.8, 0.5, 0.25): the message's ρ ≈ 1 + (3/2 − α − γ) Ω²/2 = 1 + 0.1 Ω² at small Ω, and
    the docs' 'ρ > 1 at every Ω, 10⁻³ to 10⁶', both from the characteristic polynomial."""
    with pytest.raises(AnalysisError) as info:
        HHT(0.8, 0.5, 0.25)
    assert str(info.value) == ("integrator HHT: gamma = 0.5 is below 3/2 - alpha = 0.7: its algorithmic damping is "
                               "negative and every slow mode grows (spectral radius 1 + 0.1 (omega*dt)^2 as "
                               "omega*dt -> 0)")
    for omega_dt in (1e-3, 1e-2):
        assert hht_spectral_radius(0.8, 0.5, 0.25, omega_dt) - 1.0 == pytest.approx(0.1 * omega_dt ** 2, rel=1e-2)
    assert all(hht_spectral_radius(0.8, 0.5, 0.25, om) > 1.0 for om in np.geomspace(1e-3, 1e6, 50))


# -- 6. the contract check of vtsi's own schemes, once per (class, parameters, Δt) ------------------
@pytest.fixture
def check_calls(monkeypatch):
    """The integrators check_stages was called for, with a fresh memory of checked keys."""
    calls = []
    original = integrator_base.check_stages

    def counting(integrator, stages, dt):
        calls.append((repr(integrator), dt))
        return original(integrator, stages, dt)

    monkeypatch.setattr(integrator_base, "check_stages", counting)
    monkeypatch.setattr(integrator_base, "_CHECKED", set())
    return calls


def test_a_shipped_scheme_is_checked_once_per_parameters_and_dt(check_calls):
    for _ in range(3):
        Newmark().checked_stages(1e-3)
        HHT(0.9).checked_stages(1e-3)
    Newmark().checked_stages(2e-3)
    Newmark(0.6, 0.3025).checked_stages(1e-3)
    assert check_calls == [("Newmark(gamma=0.5, beta=0.25)", 1e-3), ("HHT(alpha=0.9, gamma=0.6, beta=0.3025)", 1e-3),
                           ("Newmark(gamma=0.5, beta=0.25)", 2e-3), ("Newmark(gamma=0.6, beta=0.3025)", 1e-3)]
    assert [type(st) for st in Newmark().checked_stages(1e-3)] == [integrator_base.Stage]   # fresh stages each time


def test_a_shipped_scheme_changed_after_its_check_is_checked_again(check_calls, monkeypatch):
    """The key holds the instance's attributes and the class's methods: β set negative after a
    check, or a stages() patched on the class, is refused, not passed from memory."""
    newmark = Newmark()
    newmark.checked_stages(1e-3)
    newmark.beta = -0.1
    with pytest.raises(AnalysisError, match=r"^integrator Newmark\(gamma=0.5, beta=-0.1\): stage 1 of 1: "
                                            r"ku\[A\] = -1e-07, kv\[A\] = 0.0005; both must be >= 0"):
        newmark.checked_stages(1e-3)
    original = Newmark.stages

    def late_load(self, dt):
        stages = original(self, dt)
        stages[0].load = [(1.0, 0.5)]
        return stages

    monkeypatch.setattr(Newmark, "stages", late_load)
    with pytest.raises(AnalysisError, match="its load weights sum to 0.5"):
        Newmark().checked_stages(1e-3)


def test_a_user_scheme_is_checked_every_time(check_calls):
    """A subclass of a shipped scheme too: its stages may read anything."""
    class Mine(Newmark):
        name = "Mine-test"

    for _ in range(3):
        Mine().checked_stages(1e-3)
    assert len(check_calls) == 3


def test_the_memory_of_checked_keys_is_bounded(check_calls):
    for i in range(integrator_base.CHECKED_KEYS + 10):
        Newmark().checked_stages(1e-3 * (1.0 + i))
        assert len(integrator_base._CHECKED) <= integrator_base.CHECKED_KEYS
    assert len(check_calls) == integrator_base.CHECKED_KEYS + 10


# -- 7. the build's check of element matrices, one compiled call per block --------------------------
DEFECTS = {     # what is done to element e of a batch of semi-definite 6 × 6 matrices, and the message
    "non-finite": (lambda a, e, big: a[e].__setitem__((1, 4), np.nan), "has a non-finite entry nan at row 1, column 4"),
    "asymmetric": (lambda a, e, big: a[e].__setitem__((0, 5), a[e, 0, 5] + 1e-6 * big), "is not symmetric"),
    "negative diagonal": (lambda a, e, big: a[e].__setitem__((3, 3), -1e-6 * big), "has a negative diagonal entry"),
    "indefinite": (lambda a, e, big: a.__setitem__(e, a[e] - 1e-6 * big * np.eye(6)), "is not positive semi-definite"),
}


@pytest.mark.parametrize("what", ["stiffness", "mass"])
@pytest.mark.parametrize("defect", list(DEFECTS))
def test_the_element_matrix_check_refuses_the_defective_element_and_passes_the_rest(what, defect):
    """Rank-4 semi-definite 6 × 6 matrices (a beam's mass has null directions too) pass; one
    element made defective is named. Indefinite is refused for mass only (the stiffness's
    definiteness is the solvers' check), as numpy's eigenvalues say it is indefinite."""
    rng = np.random.default_rng(11)
    etype = ELEMENT_TYPES["elasticBeamColumn"]()
    tags = np.arange(101, 121)
    x = rng.standard_normal((len(tags), 6, 4))
    matrices = np.einsum("eik,ejk->eij", x, x)
    assert np.array_equal(checked_matrix(etype, what, matrices.copy(), tags), matrices)
    e = int(rng.integers(len(tags)))
    make, message = DEFECTS[defect]
    make(matrices, e, np.abs(matrices[e]).max())
    if defect == "indefinite":
        assert np.linalg.eigvalsh(matrices[e]).min() < -MATRIX_RTOL * np.abs(matrices[e]).max()
        if what == "stiffness":
            checked_matrix(etype, what, matrices, tags)
            return
    with pytest.raises(ModelError) as info:
        checked_matrix(etype, what, matrices, tags)
    assert str(info.value).startswith(f"element type elasticBeamColumn (element {tags[e]}): {what} {message}")
