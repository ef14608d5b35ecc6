"""Integrator properties, measured through the object API and compared with theory.

Most tests run a single-dof oscillator (mass ``m`` on the uy dof of one node, grounded by the
test-local element :class:`GroundSpring`, which also exercises the custom-element path) and
compare two things:

* the **exact discrete solution**, from the eigenvalues of the integrator's amplification
  matrix built here from its :class:`~vtsi.integrators.Stage` coefficients alone (independent of
  the compiled time loop), and
* the **response the analysis computed** (recorded displacements), and both with the published
  formulas or the exact continuous solution.

Notation: ``Ω = ωΔt``; ``ρ`` spectral radius; the principal root of the amplification matrix is
``λ = exp((-ξ̄ + i) Ω̄)`` with ``Ω̄ = ω̄Δt``, so that ``T̄/T = Ω/Ω̄`` (period elongation) and
``ξ̄ = -ln|λ| / Ω̄`` (algorithmic damping ratio). HHT's α is OpenSees's (Hilber's α_H = α - 1).

References
----------
Hilber, Hughes, Taylor (1977) Earthq. Eng. Struct. Dyn. 5, 283-292 (ρ∞ of HHT).
Hughes (1987) The Finite Element Method, ch. 9 (Newmark: stability limit, period error
    ½(β - 1/12)Ω², energy conservation of the trapezoidal rule).
Chopra, Dynamics of Structures, ch. 5 (period elongation of average / linear acceleration).
Bathe, Baig (2005) Comput. Struct. 83, 2513-2524; Bathe (2007) Comput. Struct. 85, 437-445.
docs/theory/integrators.md (the stage form, the amplification matrix, the series used below).
"""
import numpy as np
import pytest

import vtsi
import vtsi.recorders
from vtsi.elements import ELEMENT_TYPES, ElementType, register
from vtsi.errors import AnalysisError, DivergenceError
from vtsi.integrators import INTEGRATORS, HHT, Bathe, CentralDifference, GeneralizedAlpha, Newmark, make_integrator



# -- the test-local element and the oscillator ---------------------------------------------------
class GroundSpring(ElementType):
    """A spring ``k`` [N/m] and dashpot ``c`` [N·s/m] from a node's uy dof to the ground."""

    name = "testGroundSpring"
    n_nodes = 1
    node_dofs = (1,)
    param_names = ("k", "c")
    non_negative = ("k",)
    defaults = {"c": 0.0}

    def stiffness(self, coords, params):
        return params[:, 0].reshape(-1, 1, 1).copy()

    def mass(self, coords, params):
        return np.zeros((len(params), 1, 1))

    def damping(self, coords, params):
        return params[:, 1].reshape(-1, 1, 1).copy()


@pytest.fixture(autouse=True, scope="module")
def ground_spring():
    """Register GroundSpring for this module only (the element contract test requires a sample
    of every type registered while it runs)."""
    register(GroundSpring)
    yield
    ELEMENT_TYPES.pop(GroundSpring.name, None)


class GrowingNewmark(Newmark):
    """Newmark with γ = 0.3 < ½, which amplifies every mode (Newmark refuses it: spectral radius
    1.0096 at ωΔt = 0.314): how the divergence tests make a response grow (a negative dashpot,
    their way before, is refused by the element contract). Not registered. It claims a stability
    limit above the tests' ωΔt, since the contract refuses its claim of unconditional stability
    (integrators/base.py, item 3)."""

    name = "testGrowingNewmark"

    def __init__(self):
        self.gamma, self.beta, self.explicit = 0.3, 0.25, False

    def stability_limit(self, dt):
        return 1e3


def oscillator(omega, xi=0.0, u0=1.0, v0=0.0, mass=2.0, ramp=0.0):
    """Single-dof model ``m ü + c u̇ + k u = ramp·m·t`` (``ramp`` [m/s³]) with ``k = m ω²``,
    ``c = 2 ξ m ω``, started from ``u0, v0`` and the consistent ``a0``."""
    k, c = mass * omega ** 2, 2.0 * xi * mass * omega
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.fix(1, 1, 0, 1)
    m.mass(1, 0.0, mass, 0.0)
    m.element("testGroundSpring", 1, (1,), k=k, c=c)
    if ramp:
        m.pattern(1, vtsi.Linear(ramp * mass))
        m.load(1, 1, 0.0, 1.0, 0.0)
    state = vtsi.domain_state(m)
    d = m.build().full_dof(1, 2)
    state.u[d], state.v[d], state.a[d] = u0, v0, -(k * u0 + c * v0) / mass
    return m


def simulate(integrator, omega, dt, n_steps, xi=0.0, u0=1.0, v0=0.0, ramp=0.0, **options):
    """Recorded displacement of the oscillator, with ``u0`` prepended: ``(n_steps + 1,)``."""
    m = oscillator(omega, xi, u0, v0, ramp=ramp)
    rec = vtsi.recorders.NodeRecorder([1], [2], "disp")
    vtsi.TransientAnalysis(m, integrator, dt, recorders=[rec], **options).run(n_steps)
    assert np.allclose(rec.time, dt * np.arange(1, n_steps + 1), rtol=1e-13, atol=0.0)
    return np.r_[u0, rec.values[:, 0]]


# -- the amplification matrix from the stage coefficients -----------------------------------------
def amplification(integrator, omega_dt, xi=0.0, dt=1.0):
    return make_integrator(integrator).amplification(omega_dt, xi, dt)


def spectral_radius(integrator, omega_dt, xi=0.0):
    return make_integrator(integrator).spectral_radius(omega_dt, xi)


def principal(roots):
    """The principal root (positive imaginary part, largest modulus) of a set of roots."""
    roots = np.asarray(roots)
    complex_ = roots[roots.imag > 1e-14]
    return complex_[np.argmax(np.abs(complex_))]


def period_and_damping(root, omega_dt):
    """``(T̄/T, ξ̄)`` of a principal root."""
    phase = np.angle(root)
    return omega_dt / phase, -np.log(np.abs(root)) / phase


def recurrence_roots(y, order):
    """Roots of the linear recurrence ``y_{n} = Σ_j c_j y_{n-j}`` (``order`` terms) fitted by least
    squares to a recorded free response (Prony): for a linear scheme they are the eigenvalues of
    its amplification matrix that the response contains. This is how the period and decay are
    *measured* from the simulation."""
    rows = np.column_stack([y[order - j - 1: len(y) - j - 1] for j in range(order)])
    c = np.linalg.lstsq(rows, y[order:], rcond=None)[0]
    return np.roots(np.r_[1.0, -c])


# -- 1. period elongation and algorithmic damping ---------------------------------------------------
# (integrator, D, C): leading terms T̄/T - 1 = D Ω² + O(Ω⁴), ξ̄ = C Ω³ + O(Ω⁵).
# Newmark γ = ½: D = ½(β - 1/12), ξ̄ = 0 (Hughes 1987 ch. 9; Chopra ch. 5: Ω²/12 for average,
# Ω²/24 for linear acceleration, -Ω²/24 for central difference, O(Ω⁴) for Fox-Goodwin β = 1/12).
# HHT (α_H = α - 1, default γ, β): ρ∞ from Hilber et al. (1977); the series coefficients
# D = 1/12 - α_H/4 - 3α_H²/8, C = -α_H (1 + α_H)²/8 and Bathe's (γ = ½) D = 1/24, C = 1/288 are
# the expansion of the principal root, derived in docs/theory/integrators.md (checked below).
def _hht_series(alpha):
    a_h = alpha - 1.0
    return 1.0 / 12.0 - a_h / 4.0 - 3.0 * a_h ** 2 / 8.0, -a_h * (1.0 + a_h) ** 2 / 8.0


SCHEMES = {
    "average-acceleration": (Newmark(0.5, 0.25), 1.0 / 12.0, 0.0),
    "linear-acceleration": (Newmark(0.5, 1.0 / 6.0), 1.0 / 24.0, 0.0),
    "fox-goodwin": (Newmark(0.5, 1.0 / 12.0), 0.0, 0.0),
    "central-difference": (CentralDifference(), -1.0 / 24.0, 0.0),
    "HHT-0.9": (HHT(0.9), *_hht_series(0.9)),
    "HHT-2/3": (HHT(2.0 / 3.0), *_hht_series(2.0 / 3.0)),
    "Bathe-0.5": (Bathe(0.5), 1.0 / 24.0, 1.0 / 288.0),
}


@pytest.mark.parametrize("name", SCHEMES)
@pytest.mark.parametrize("omega_dt", [0.1, 0.5])
def test_period_and_damping_simulated_match_amplification_matrix(name, omega_dt):
    """The period and decay measured from the recorded free vibration equal those of the principal
    root of the amplification matrix (to 1e-9: both are the same discrete solution, computed two
    independent ways; Prony's fit is exact up to roundoff for a linear recurrence)."""
    integrator = SCHEMES[name][0]
    omega = 2.0 * np.pi
    dt = omega_dt / omega
    n = int(6 * 2.0 * np.pi / omega_dt)                  # six periods
    y = simulate(integrator, omega, dt, n, u0=1.0, v0=0.3)
    measured = period_and_damping(principal(recurrence_roots(y[10:], 2)), omega_dt)   # skip spurious root
    theory = period_and_damping(principal(np.linalg.eigvals(amplification(integrator, omega_dt))), omega_dt)
    assert measured[0] == pytest.approx(theory[0], rel=1e-9, abs=0.0)
    assert measured[1] == pytest.approx(theory[1], abs=1e-9)


@pytest.mark.parametrize("name", SCHEMES)
def test_period_and_damping_match_published_leading_terms(name):
    """The amplification matrix's T̄/T - 1 and ξ̄ follow the published leading terms: checked at
    Ω = 0.1 to within 0.05 Ω⁴ and 0.05 Ω⁵ (the next terms), and the coefficients extrapolated to
    Ω → 0 (Richardson from Ω = 0.02, 0.01) to 1e-5 relative (absolute 1e-6 for zero terms)."""
    integrator, d_coef, c_coef = SCHEMES[name]

    def errors(omega_dt):
        ratio, xi = period_and_damping(principal(np.linalg.eigvals(amplification(integrator, omega_dt))), omega_dt)
        return ratio - 1.0, xi

    pe, xi = errors(0.1)
    assert abs(pe - d_coef * 0.1 ** 2) <= 0.05 * 0.1 ** 4
    assert abs(xi - c_coef * 0.1 ** 3) <= 0.05 * 0.1 ** 5
    (pe1, xi1), (pe2, xi2) = errors(0.02), errors(0.01)
    d_limit = (4.0 * pe2 / 0.01 ** 2 - pe1 / 0.02 ** 2) / 3.0
    c_limit = (4.0 * xi2 / 0.01 ** 3 - xi1 / 0.02 ** 3) / 3.0
    assert d_limit == pytest.approx(d_coef, rel=1e-5, abs=1e-6)
    assert c_limit == pytest.approx(c_coef, rel=1e-5, abs=1e-6)


@pytest.mark.parametrize("omega_dt", [0.1, 0.5, 1.0, 1.9])
def test_closed_form_periods(omega_dt):
    """Exact discrete periods: trapezoidal rule Ω̄ = 2 arctan(Ω/2), so T̄/T = (Ω/2)/arctan(Ω/2)
    (≈ 1 + Ω²/12); central difference cos Ω̄ = 1 - Ω²/2 (Hughes 1987 ch. 9). To 1e-12."""
    ratio, xi = period_and_damping(principal(np.linalg.eigvals(amplification(Newmark(), omega_dt))), omega_dt)
    assert ratio == pytest.approx((omega_dt / 2.0) / np.arctan(omega_dt / 2.0), rel=1e-12)
    assert abs(xi) < 1e-12
    ratio, xi = period_and_damping(principal(np.linalg.eigvals(amplification(CentralDifference(), omega_dt))), omega_dt)
    assert ratio == pytest.approx(omega_dt / np.arccos(1.0 - omega_dt ** 2 / 2.0), rel=1e-12)
    assert abs(xi) < 1e-12


# -- 2. order of convergence -------------------------------------------------------------------------
def exact_response(t, omega, xi, u0, v0, ramp=0.0):
    """Exact ``u(t)`` of ``ü + 2ξω u̇ + ω² u = ramp·t`` from ``u0, v0`` (ξ < 1)."""
    k, c = omega ** 2, 2.0 * xi * omega
    wd = omega * np.sqrt(1.0 - xi ** 2)
    up0, vp = -ramp * c / k ** 2, ramp / k                  # particular solution (ramp/k)(t - c/k)
    a = u0 - up0
    b = (v0 - vp + xi * omega * a) / wd
    return np.exp(-xi * omega * t) * (a * np.cos(wd * t) + b * np.sin(wd * t)) + ramp / k * (t - c / k)


OMEGA = 2.0 * np.pi
RAMP = 40.0
CASES = {   # (xi, u0, v0, ramp); the forced case starts near the ramp's particular solution, so a
            # load evaluated at the wrong time (an O(Δt) error) dominates the error.
    "free-undamped": (0.0, 1.0, 0.5, 0.0),
    "free-damped": (0.05, 1.0, 0.5, 0.0),
    "ramp-damped": (0.05, 0.1 - RAMP * 2 * 0.05 * OMEGA / OMEGA ** 4, RAMP / OMEGA ** 2, RAMP),
}
STEPS = 0.0125 / 2.0 ** np.arange(5)     # 4 halvings: Ω from 0.079 to 0.0049
T_END = 1.3                               # not a multiple of the period (no phase cancellation)


def observed_order(integrator, case):
    xi, u0, v0, ramp = CASES[case]
    errors = []
    for dt in STEPS:
        n = int(round(T_END / dt))
        u = simulate(integrator, OMEGA, dt, n, xi, u0, v0, ramp)
        errors.append(abs(u[-1] - exact_response(n * dt, OMEGA, xi, u0, v0, ramp)))
    return np.polyfit(np.log(STEPS), np.log(errors), 1)[0]


ORDER_2 = {"Newmark": Newmark(), "HHT-0.9": HHT(0.9), "HHT-2/3": HHT(2.0 / 3.0), "Bathe": Bathe(),
           "Bathe-0.3": Bathe(0.3), "CentralDifference": CentralDifference()}


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("name", ORDER_2)
def test_second_order_convergence(name, case):
    """Displacement error at t = 1.3 s against the exact SDOF solution, Δt halved 4 times:
    the least-squares slope of log(error) vs log(Δt) is 2 ± 0.1 (measured: 1.9999-2.0015)."""
    assert observed_order(ORDER_2[name], case) == pytest.approx(2.0, abs=0.1)


class _HHTLoadAtEnd(HHT):
    """HHT with the load (wrongly) at t_{n+1} instead of t_n + αΔt: first order."""

    def stages(self, dt):
        (stage,) = super().stages(dt)
        stage.load = [(1.0, 1.0)]
        return [stage]


class _BatheLoadAtEnd(Bathe):
    """Bathe with the first sub-step's load (wrongly) at t_{n+1}: first order."""

    def stages(self, dt):
        first, second = super().stages(dt)
        first.load = [(1.0, 1.0)]
        return [first, second]


@pytest.mark.parametrize("integrator", [_HHTLoadAtEnd(2.0 / 3.0), _BatheLoadAtEnd()], ids=["HHT", "Bathe"])
def test_convergence_test_detects_wrong_load_time(integrator):
    """Negative control: the forced case catches a load evaluated at the wrong stage time
    (slope about 1: measured 1.02 for both)."""
    assert observed_order(integrator, "ramp-damped") < 1.5


# -- 3. spectral radius at large ωΔt -------------------------------------------------------------------
# ρ∞: trapezoidal 1; HHT (1 + α_H)/(1 - α_H) = α/(2 - α) (Hilber et al. 1977); Bathe γ = ½: 0.
RHO_INF = {"Newmark": (Newmark(), 1.0, 1e-12), "HHT-0.9": (HHT(0.9), 0.9 / 1.1, 1e-6),
           "HHT-0.8": (HHT(0.8), 0.8 / 1.2, 1e-6), "HHT-2/3": (HHT(2.0 / 3.0), 0.5, 2e-3),
           "Bathe": (Bathe(0.5), 0.0, 1e-3)}


@pytest.mark.parametrize("name", RHO_INF)
def test_spectral_radius_at_large_step(name):
    """ρ(Ω = 1e4) from the amplification matrix equals ρ∞ (tolerance in RHO_INF: HHT with α = 2/3
    has a double root at -ρ∞ and approaches it slowly, 1.7e-3 off at 1e4 but 4e-6 at 1e8); and
    the radius measured from the recorded high-frequency free response (recurrence fit) equals
    the matrix's to 1e-6."""
    integrator, rho_inf, tol = RHO_INF[name]
    rho = spectral_radius(integrator, 1e4)
    assert rho == pytest.approx(rho_inf, abs=tol)
    if name == "HHT-2/3":
        assert spectral_radius(integrator, 1e8) == pytest.approx(rho_inf, abs=1e-5)
    dt = 1e-3
    if isinstance(integrator, HHT) and integrator.alpha < 1.0:
        y, order = simulate(integrator, 1e4 / dt, dt, 40), 3          # three nonzero roots
    elif isinstance(integrator, Bathe):
        y, order = simulate(integrator, 1e4 / dt, dt, 5), 2           # gone after 4 steps
    else:
        y, order = simulate(integrator, 1e4 / dt, dt, 4000), 2        # near-double root at -1
    measured = np.max(np.abs(recurrence_roots(y, order)))
    # HHT α = 2/3: its three roots lie within 5e-3 of each other at Ω = 1e4, a cluster that
    # roundoff in either computation (|a| ~ ω² |u|) moves by ~1e-4: compare to 1e-3 there.
    assert measured == pytest.approx(rho, rel=1e-3 if name == "HHT-2/3" else 1e-6, abs=1e-9)
    if isinstance(integrator, Bathe):
        assert abs(y[4]) < 1e-12 * abs(y[0])             # ρ⁴ ≈ 6e-14: gone after four steps


@pytest.mark.parametrize("name", sorted(INTEGRATORS))
def test_stability_limit_is_where_the_spectral_radius_exceeds_one(name, required_args):
    """Contract item 3 checked on the amplification matrix: unconditionally stable schemes keep
    ρ <= 1 for Ω in [1e-3, 1e8]; a conditionally stable one has ρ <= 1 just below its limit
    and ρ > 1 just above it."""
    integrator = INTEGRATORS[name](*required_args(name))
    limit = integrator.stability_limit(1.0)
    if limit is None:
        radii = [spectral_radius(integrator, om) for om in np.logspace(-3, 8, 111)]
        assert max(radii) <= 1.0 + 1e-12
    else:
        assert spectral_radius(integrator, 0.999 * limit) <= 1.0 + 1e-12
        assert spectral_radius(integrator, 1.001 * limit) > 1.0 + 1e-6


@pytest.mark.parametrize("integrator", [Newmark(0.5, 1.0 / 6.0), Newmark(0.5, 1.0 / 12.0), Newmark(0.6, 0.2),
                                        Newmark(0.5, 0.0), Bathe(0.1), Bathe(0.9),
                                        HHT(0.8, 0.7, 0.3), HHT(0.9, 0.6, 0.2), HHT(0.8, 0.9, 0.1),
                                        HHT(0.8, 0.9, 0.14), HHT(0.9, 0.65, 0.0), HHT(0.8, 0.75, 0.45)],
                         ids=repr)
def test_stability_limit_of_parameter_variants(integrator):
    """Newmark's limit Ω = 1/√(γ/2 - β) (Hughes 1987 ch. 9), the unconditional stability of
    Bathe for any γ in (0, 1), and HHT with user γ, β (its limit is not Newmark's: λ = -1 is
    crossed at 1/√((2α-1)(γ/2-β)), or a complex pair leaves the unit disc earlier), checked on
    the amplification matrix as above."""
    limit = integrator.stability_limit(1.0)
    if limit is None:
        assert max(spectral_radius(integrator, om) for om in np.logspace(-3, 8, 111)) <= 1.0 + 1e-12
    else:
        assert spectral_radius(integrator, 0.999 * limit) <= 1.0 + 1e-12
        assert spectral_radius(integrator, 1.001 * limit) > 1.0 + 1e-6


# -- 4. central difference: stability limit and divergence ---------------------------------------------
def simply_supported_beam(n_el=8, length=10.0, cmass=1):
    """A simply supported elastic beam (consistent mass by default), unloaded."""
    m = vtsi.Model()
    for i in range(n_el + 1):
        m.node(i + 1, length * i / n_el, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(n_el + 1, 0, 1, 0)
    for i in range(n_el):
        m.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=0.5, E=3.0e10, I=0.05, rho=1.2e3, cmass=cmass)
    return m


def start_from(m, u_free):
    """Set the committed state to displacement ``u_free`` (free dofs), v = 0, a = -M⁻¹K u."""
    asm = m.build()
    state = vtsi.domain_state(m)
    state.u[:] = state.v[:] = state.a[:] = 0.0
    state.u[asm.full_of_free] = u_free
    state.a[asm.full_of_free] = -np.linalg.solve(asm.M.toarray(), asm.K @ u_free)
    return asm, state


def test_central_difference_stability_limit_on_a_beam():
    """CD runs stably at Δt = 0.99·2/ω_max and is refused at 1.01·2/ω_max with an AnalysisError
    stating the limit (2/ω_max, ω_max from scipy's generalized eigenproblem, to 6 digits)."""
    import scipy.linalg

    m = simply_supported_beam()
    asm = m.build()
    omega_max = np.sqrt(scipy.linalg.eigvalsh(asm.K.toarray(), asm.M.toarray())[-1])
    dt_crit = 2.0 / omega_max
    rng = np.random.default_rng(7)
    u0 = 1e-3 * rng.standard_normal(asm.n_free)        # excites the highest mode
    start_from(m, u0)
    rec = vtsi.recorders.NodeRecorder([5], [2], "disp")
    vtsi.TransientAnalysis(m, "CentralDifference", 0.99 * dt_crit, recorders=[rec]).run(3000)
    assert np.all(np.isfinite(rec.values)) and np.max(np.abs(rec.values)) < 10 * np.max(np.abs(u0))
    start_from(m, u0)
    with pytest.raises(AnalysisError, match="stability limit") as err:
        vtsi.TransientAnalysis(m, CentralDifference, 1.01 * dt_crit).run(10)
    assert not isinstance(err.value, DivergenceError)
    assert f"{dt_crit:.6g} s" in str(err.value)


def test_divergence_error_names_step_and_time_and_keeps_records():
    """A scheme that amplifies (GrowingNewmark) makes the undamped oscillator grow; with
    divergence_limit = 10 the run stops at the first step whose |u| > 10, found independently by
    powers of the amplification matrix. DivergenceError carries that step (1-based) and time, its
    message names both, and the recorder holds every step before it (across chunk boundaries:
    chunk_steps = 7), equal to the exact discrete solution (1e-12)."""
    omega, xi, dt = 2.0 * np.pi, 0.0, 0.05
    amp = amplification(GrowingNewmark(), omega * dt, xi, dt)
    x = np.array([1.0, 0.0, -omega ** 2])
    expected = []
    while abs(x[0]) <= 10.0:
        x = amp @ x
        expected.append(x[0])
    step = len(expected)                                    # the offending step
    m = oscillator(omega, xi, u0=1.0, v0=0.0)
    vtsi.domain_state(m).time = 2.5                          # the clock of a continued analysis
    rec = vtsi.recorders.NodeRecorder([1], [2], "disp")
    analysis = vtsi.TransientAnalysis(m, GrowingNewmark(), dt, recorders=[rec], divergence_limit=10.0, chunk_steps=7)
    with pytest.raises(DivergenceError) as err:
        analysis.run(10 * step)
    assert err.value.step == step
    assert err.value.time == pytest.approx(2.5 + step * dt, rel=1e-12)
    assert f"step {step} of this run," in str(err.value) and f"t = {2.5 + step * dt:.6g} s" in str(err.value)
    assert len(rec.values) == step - 1
    np.testing.assert_allclose(rec.values[:, 0], expected[:-1], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(rec.time, 2.5 + dt * np.arange(1, step), rtol=1e-13)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")      # overflow, when run with NUMBA_DISABLE_JIT=1
def test_divergence_to_overflow_is_caught_as_nan():
    """With no bound (divergence_limit = inf) a response that overflows to inf and then NaN is
    still caught: DivergenceError, records end just before the offending step."""
    m = oscillator(2.0 * np.pi, u0=1.0)                     # GrowingNewmark at ωΔt = 2π·0.3: × 1.17 a step
    rec = vtsi.recorders.NodeRecorder([1], [2], "disp")
    with pytest.raises(DivergenceError) as err:
        vtsi.TransientAnalysis(m, GrowingNewmark(), 0.3, recorders=[rec], divergence_limit=np.inf).run(100000)
    assert len(rec.values) == err.value.step - 1 and np.all(np.isfinite(rec.values))


# -- 5. energy conservation of the trapezoidal rule --------------------------------------------------------
def test_trapezoidal_rule_conserves_energy_of_undamped_beam():
    """Free vibration of an undamped beam (24 free dofs, from a smooth initial deflection): the
    trapezoidal rule conserves ½vᵀMv + ½uᵀKu exactly (Hughes 1987 ch. 9); to 1e-10 relative
    over 2000 steps of Δt = T1/50 (modes up to Ω ≈ 100 included)."""
    m = simply_supported_beam(n_el=8, cmass=1)
    asm = m.build()
    x = asm.coords[:, 0]
    u_full = np.zeros(asm.n_full)
    u_full[1::3] = 1e-3 * np.sin(np.pi * x / 10.0) + 2e-4 * np.sin(3 * np.pi * x / 10.0)
    u_full[2::3] = 1e-3 * np.pi / 10.0 * np.cos(np.pi * x / 10.0)
    u_free = u_full[asm.full_of_free]
    start_from(m, u_free)
    omega1 = np.sqrt(vtsi.eigen(m, 1)[0][0])
    nodes = [int(t) for t in asm.node_tags]
    disp = vtsi.recorders.NodeRecorder(nodes, [1, 2, 3], "disp")
    vel = vtsi.recorders.NodeRecorder(nodes, [1, 2, 3], "vel")
    vtsi.TransientAnalysis(m, "Newmark", 2 * np.pi / omega1 / 50, recorders=[disp, vel]).run(2000)
    cols = [asm.full_dof(n, d) for n in nodes for d in (1, 2, 3)]
    u = np.zeros((len(disp.values), asm.n_full))
    v = np.zeros_like(u)
    u[:, cols], v[:, cols] = disp.values, vel.values
    energy = 0.5 * np.einsum("ti,ti->t", v, (asm.M_full @ v.T).T) + 0.5 * np.einsum("ti,ti->t", u, (asm.K_full @ u.T).T)
    e0 = 0.5 * u_free @ (asm.K @ u_free)
    assert np.max(np.abs(energy - e0)) <= 1e-10 * e0


# -- 6. parameters and selection ------------------------------------------------------------------------------
@pytest.mark.parametrize("make, parameter", [
    (lambda: Newmark(0.49, 0.25), "gamma"),
    (lambda: Newmark(float("nan"), 0.25), "gamma"),
    (lambda: Newmark(0.5, -0.1), "beta"),
    (lambda: HHT(0.6), "alpha"),
    (lambda: HHT(1.01), "alpha"),
    (lambda: HHT(float("nan")), "alpha"),
    (lambda: Bathe(0.0), "gamma"),
    (lambda: Bathe(1.0), "gamma"),
    (lambda: Bathe(-0.5), "gamma"),
    (lambda: make_integrator("Newmark", 0.4, 0.25), "gamma"),
    (lambda: make_integrator("HHT", 0.5), "alpha"),
    (lambda: HHT(0.8, 0.5, 0.25), "gamma"),        # γ < 3/2 - α: slow modes grow (ρ > 1 at every Ω)
    (lambda: HHT(0.8, 0.7, 0.1), "beta"),          # second order but ρ > 1 already at Ω = 0.1
])
def test_parameter_validation(make, parameter):
    with pytest.raises(AnalysisError, match=f"{parameter} = "):
        make()


@pytest.mark.parametrize("spec, expected", [("HHT(0.9)", (0.9, 0.6, 0.3025)), ("HHT(alpha=0.8, gamma=0.75, beta=0.36)",
                                                                               (0.8, 0.75, 0.36)),
                                            ("Newmark(0.6, 0.3025)", (None, 0.6, 0.3025)), (" Bathe ( ) ", None)])
def test_integrators_by_text_with_their_parameters(spec, expected):
    """A name with its parameters as text (the command line's and the bridge file's form, and
    the repr a results file stores) builds that integrator; its repr builds it again."""
    integ = make_integrator(spec)
    if expected is not None:
        assert (getattr(integ, "alpha", None), integ.gamma, integ.beta) == pytest.approx(expected)
    assert repr(make_integrator(repr(integ))) == repr(integ)


def test_an_integrator_rebuilt_from_its_repr_keeps_its_parameters():
    """The repr a results file stores keeps 15 significant digits: HHT(2/3) comes back with α
    to 1e-15 (with 6 digits it came back as 0.666667, 5e-7 off), and 0.9 stays 0.9."""
    third = make_integrator(repr(HHT(2.0 / 3.0)))
    assert abs(third.alpha - 2.0 / 3.0) < 1e-15 and abs(third.beta - (4.0 / 3.0) ** 2 / 4.0) < 1e-15
    assert repr(HHT(0.9)) == "HHT(alpha=0.9, gamma=0.6, beta=0.3025)"


@pytest.mark.parametrize("spec, words", [
    ("HHT", r"^integrator HHT: give alpha \(OpenSees convention, 2/3 <= alpha <= 1; 1 is Newmark's undamped trapezoidal"),
    ("HHT()", "give alpha"),
    ("HHT(x)", r"^integrator 'HHT\(x\)': 'x' is not a number \(or name=number\)"),
    ("HHT(gamma=0.6, 0.9)", "'0.9' follows a named parameter"),
    ("HHT(alpha=0.9, alpha=0.8)", r"^integrator 'HHT\(alpha=0.9, alpha=0.8\)': alpha given twice$"),
    ("HHT(alpha=0.9, delta=1)", r"^integrator HHT: \(alpha=0.9, delta=1.0\) does not fit its parameters \(alpha=None"),
    ("HHT(0.9)(", "unknown integrator"),
    ("Wilson(1.4)", r"unknown integrator 'Wilson\(1.4\)'; known: .* \(parameters as 'HHT\(0.9\)'\)"),
])
def test_integrator_text_that_does_not_fit_is_named(spec, words):
    with pytest.raises(AnalysisError, match=words):
        make_integrator(spec)


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), float("inf"), "abc"])
def test_bad_time_step_is_refused(dt):
    m = oscillator(1.0)
    with pytest.raises(AnalysisError, match="dt"):
        vtsi.TransientAnalysis(m, "Newmark", dt)
    analysis = vtsi.TransientAnalysis(m, "Newmark")
    with pytest.raises(AnalysisError, match="dt"):
        analysis.set_dt(dt)
    with pytest.raises(AnalysisError, match="no time step"):
        analysis.run(1)


def test_unknown_integrator_lists_the_known_ones():
    with pytest.raises(AnalysisError) as err:
        vtsi.TransientAnalysis(oscillator(1.0), "Wilson", 0.01)
    for name in INTEGRATORS:
        assert name in str(err.value)
    assert "'Wilson'" in str(err.value)


@pytest.mark.parametrize("name", ["Newmark", "HHT", "Bathe", "CentralDifference", "TRBDF2"])
def test_integrator_by_name_class_or_instance(name, required_args):
    """A name, a class and an instance select the same scheme and give the same response."""
    if name not in INTEGRATORS:
        pytest.skip(f"{name} is not registered")
    cls, args = INTEGRATORS[name], required_args(name)
    specs = (f"{name}({', '.join(map(str, args))})" if args else name, cls if not args else make_integrator(cls, *args),
             cls(*args))
    runs = [simulate(spec, 2.0 * np.pi, 0.01, 20) for spec in specs]
    for spec in specs:
        assert type(vtsi.TransientAnalysis(oscillator(1.0), spec, 0.01).integrator) is cls
    np.testing.assert_array_equal(runs[0], runs[1])
    np.testing.assert_array_equal(runs[0], runs[2])
    with pytest.raises(AnalysisError, match="parameters given twice"):
        make_integrator(cls(*args), 0.5)


def test_constant_load_is_integrated_exactly(required_args):
    """Consistency through the whole loop: a free mass under a constant force (no element:
    K = C = 0) moves as u0 + v0 t + f t²/2 exactly (to 1e-12) with every registered scheme."""
    for name, cls in INTEGRATORS.items():
        m = vtsi.Model()
        m.node(1, 0.0, 0.0)
        m.fix(1, 1, 0, 1)
        m.mass(1, 0.0, 4.0, 0.0)
        m.pattern(1, vtsi.Constant(1.0))
        m.load(1, 1, 0.0, 8.0, 0.0)                        # f = 8 N / 4 kg = 2 m/s²
        state = vtsi.domain_state(m)
        state.u[1], state.v[1], state.a[1] = 0.5, -1.0, 2.0
        rec = vtsi.recorders.NodeRecorder([1], [2], "disp")
        vtsi.TransientAnalysis(m, cls(*required_args(name)), 0.1, recorders=[rec]).run(30)
        t = rec.time
        np.testing.assert_allclose(rec.values[:, 0], 0.5 - t + t ** 2, rtol=1e-12, atol=1e-12, err_msg=name)
        assert state.v[1] == pytest.approx(-1.0 + 2.0 * 3.0, rel=1e-12), name


# -- the time loop: zero steps, continued runs, a changed step ---------------------------------------------
def test_zero_steps_changes_nothing():
    m = oscillator(2.0 * np.pi, u0=0.3, v0=0.1)
    state = vtsi.domain_state(m)
    before = (state.time, state.u.copy(), state.v.copy(), state.a.copy())
    rec = vtsi.recorders.NodeRecorder([1], [2], "disp")
    analysis = vtsi.TransientAnalysis(m, "Bathe", 0.01, recorders=[rec])
    assert analysis.run(0) is state
    assert state.time == before[0]
    for now, then in zip((state.u, state.v, state.a), before[1:]):
        np.testing.assert_array_equal(now, then)
    assert len(rec.values) == 0
    with pytest.raises(AnalysisError, match="steps"):
        analysis.run(-1)


@pytest.mark.parametrize("name", sorted(INTEGRATORS))
def test_second_run_continues_from_committed_state(name, required_args):
    """run(37) then run(63) is bit-for-bit run(100) (also across chunk boundaries), the clock
    continues, and a recorder reused by both runs holds all 100 steps."""
    m1, m2 = oscillator(2.0 * np.pi, xi=0.02, v0=0.4), oscillator(2.0 * np.pi, xi=0.02, v0=0.4)
    rec1, rec2 = vtsi.recorders.NodeRecorder([1], [2], "disp"), vtsi.recorders.NodeRecorder([1], [2], "disp")
    spec = INTEGRATORS[name](*required_args(name))
    vtsi.TransientAnalysis(m1, spec, 0.01, recorders=[rec1]).run(100)
    analysis = vtsi.TransientAnalysis(m2, spec, 0.01, recorders=[rec2], chunk_steps=16)
    analysis.run(37)
    assert vtsi.domain_state(m2).time == pytest.approx(0.37, rel=1e-14)
    analysis.run(63)
    np.testing.assert_array_equal(rec2.values, rec1.values)
    np.testing.assert_allclose(rec2.time, 0.01 * np.arange(1, 101), rtol=1e-13)
    s1, s2 = vtsi.domain_state(m1), vtsi.domain_state(m2)
    for a, b in ((s1.u, s2.u), (s1.v, s2.v), (s1.a, s2.a)):
        np.testing.assert_array_equal(a, b)
    assert s2.time == pytest.approx(1.0, rel=1e-14)


@pytest.mark.parametrize("name", ["Newmark", "HHT", "Bathe", "CentralDifference"])
def test_step_change_between_runs(name):
    """40 steps of Δt = 0.01, then set_dt(0.025) and 30 more: the state is the amplification
    matrices' product A(0.025)³⁰ A(0.01)⁴⁰ x0 (to 1e-12), the clock is 0.4 + 0.75 s, and a new
    analysis object on the same model continues the same way."""
    integrator = INTEGRATORS[name](0.8) if name == "HHT" else INTEGRATORS[name]()
    omega, xi = 2.0 * np.pi, 0.03
    x = np.array([1.0, 0.0, -omega ** 2])
    x = np.linalg.matrix_power(amplification(integrator, omega * 0.01, xi, 0.01), 40) @ x
    x = np.linalg.matrix_power(amplification(integrator, omega * 0.025, xi, 0.025), 30) @ x
    for reuse in (True, False):
        m = oscillator(omega, xi, u0=1.0, v0=0.0)
        analysis = vtsi.TransientAnalysis(m, integrator, 0.01)
        analysis.run(40)
        if reuse:
            analysis.set_dt(0.025)
        else:
            analysis = vtsi.TransientAnalysis(m, integrator, 0.025)
        state = analysis.run(30)
        np.testing.assert_allclose([state.u[1], state.v[1], state.a[1]], x, rtol=1e-12, atol=1e-12 * omega ** 2)
        assert state.time == pytest.approx(0.4 + 0.75, rel=1e-14)


def test_model_change_between_runs_is_seen():
    """Changing the model (a stiffer spring added) between runs re-factors: the second run
    integrates the new ω (checked against the amplification matrix, 1e-12)."""
    omega, dt = 2.0 * np.pi, 0.01
    m = oscillator(omega, u0=1.0)
    analysis = vtsi.TransientAnalysis(m, "Newmark", dt)
    analysis.run(10)
    x = np.linalg.matrix_power(amplification(Newmark(), omega * dt, 0.0, dt), 10) @ np.array([1.0, 0.0, -omega ** 2])
    m.element("testGroundSpring", 2, (1,), k=3 * 2.0 * omega ** 2)      # k total = 4 m ω²: ω doubles
    state = vtsi.domain_state(m)
    state.a[1] = -(2 * omega) ** 2 * state.u[1]                          # consistent with the new K
    x[2] = -(2 * omega) ** 2 * x[0]
    analysis.run(10)
    x = np.linalg.matrix_power(amplification(Newmark(), 2 * omega * dt, 0.0, dt), 10) @ x
    np.testing.assert_allclose([state.u[1], state.v[1], state.a[1]], x, rtol=1e-12, atol=1e-10)


@pytest.mark.parametrize("name", ["Newmark", "Bathe"])
def test_dofs_at_rest_are_left_out_and_read_zero(name):
    """Components of the model with no load and no state stay exactly at rest, so the loop
    leaves them out (vtsi.analysis.moving_dofs): a vertical load on a straight beam moves only
    its bending dofs (the axial ones read 0, and the bending response is the same, to the last
    bit, as with an axial load added); an axial load or an axial initial velocity brings the
    axial dofs back in."""
    t = np.linspace(0.0, 0.2, 21)
    runs = {}
    for extra in ("none", "axial load", "axial velocity"):
        m = simply_supported_beam()
        m.pattern(1, vtsi.timeseries.Path(np.sin(40.0 * t), time=t)).load(5, 0.0, -1e5, 0.0)
        if extra == "axial load":
            m.pattern(2, vtsi.timeseries.Path(np.sin(25.0 * t), time=t)).load(9, 1e6, 0.0, 0.0)
        asm = m.build()
        if extra == "axial velocity":
            vtsi.domain_state(m).v[asm.full_dof(9, 1)] = 1e-3
        rec = vtsi.recorders.NodeRecorder([5, 9], [1, 2], "disp")
        analysis = vtsi.TransientAnalysis(m, name, 1e-3, recorders=[rec])
        analysis.run(150)
        axial = [asm.free_of_full[asm.full_dof(n, 1)] for n in range(2, 10)]
        assert set(axial) <= set(analysis.active.tolist()) if extra != "none" else \
            not set(axial) & set(analysis.active.tolist())
        runs[extra] = rec.sink.values.copy()
    assert np.all(runs["none"][:, [0, 2]] == 0.0)                 # ux of nodes 5 and 9
    assert np.abs(runs["axial load"][:, 2]).max() > 1e-6
    assert np.abs(runs["axial velocity"][:, 2]).max() > 1e-8          # v / ω_axial ~ 3.7e-7 m
    for extra in ("axial load", "axial velocity"):
        assert np.array_equal(runs[extra][:, [1, 3]], runs["none"][:, [1, 3]])


# -- the generalized-α method ---------------------------------------------------------------------------
def test_special_cases_newmark_and_hht():
    """αM = αF = 1 is Newmark's method, αM = 1 is HHT(αF), with their default γ, β."""
    pi2 = 2.0 * np.pi
    np.testing.assert_allclose(simulate(GeneralizedAlpha(1.0, 1.0), pi2, 0.05, 60),
                               simulate(Newmark(0.5, 0.25), pi2, 0.05, 60), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(simulate(GeneralizedAlpha(1.0, 0.85), pi2, 0.05, 60),
                               simulate(HHT(0.85), pi2, 0.05, 60), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("rho", [0.0, 0.5, 0.8, 1.0])
def test_spectral_radius_at_infinity(rho):
    """With αM = (2 − ρ∞)/(1 + ρ∞), αF = 1/(1 + ρ∞) and the default γ, β the spectral radius
    tends to ρ∞ as ωΔt → ∞ and stays ≤ 1 everywhere (unconditional stability)."""
    integ = GeneralizedAlpha((2.0 - rho) / (1.0 + rho), 1.0 / (1.0 + rho))
    assert spectral_radius(integ, 1e8) == pytest.approx(rho, abs=1e-5)
    assert max(spectral_radius(integ, om) for om in np.logspace(-3, 6, 60)) <= 1.0 + 1e-12


def test_second_order():
    """The error of a damped oscillator falls by 4 per halving of Δt (default γ, β)."""
    omega, xi, T = 2.0 * np.pi, 0.05, 2.0
    t = np.linspace(0.0, T, 9)[1:]
    wd = omega * np.sqrt(1.0 - xi ** 2)
    exact = np.exp(-xi * omega * t) * (np.cos(wd * t) + xi * omega / wd * np.sin(wd * t))
    errors = []
    for n in (200, 400, 800):
        u = simulate(GeneralizedAlpha(0.8, 0.6), omega, T / n, n, xi=xi)
        errors.append(np.max(np.abs(u[n // 8:: n // 8] - exact)))
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(rates > 1.9), rates
