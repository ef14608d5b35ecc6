"""The generalized-α method (Chung & Hulbert; OpenSees's ``integrator GeneralizedAlpha αM αF``).

- Against OpenSeesPy: the moving-force script (10-element simply supported beam, one Path per
  interior node) through ``vtsi.opensees`` and the same beam built with the object API, for
  (αM, αF) = (1.0, 0.8), (0.9, 0.7), (2/3, 5/9) with the default γ, β and with γ, β given.
  Measured (max difference / max value over 250 steps, worst case): displacements 3.6e-14
  through the commands and 3.8e-14 through the object API; accelerations, rotation rates and
  end moments 1.1e-11 and 8.7e-12 (they carry the beam's stiff high modes); the command layer's
  time accumulated as OpenSees does, to the bit.
- αM = αF = 1 is Newmark's method bit for bit; αM = 1 is HHT(αF) (measured bit for bit too).
- The compiled loop on a single-dof oscillator: second order (free, damped and under a ramp load,
  where a load taken at t_{n+1} instead of t_n + αF Δt shows as first order); the amplification
  matrix measured from one-step runs has the closed-form spectral radius at ωΔt → ∞.
- The modal bridge with every mode equals the FE bridge (coupled analyses: tests/test_coupled.py
  and tests/test_modal_bridge.py run the method with contact wheels too).
- Bad parameters raise AnalysisError naming the parameter and its range.
"""
import numpy as np
import openseespy.opensees as oracle
import pytest

import vtsi
import vtsi.opensees as vops
from vtsi.errors import AnalysisError, CommandError
from vtsi.integrators import HHT, GeneralizedAlpha, Newmark
from vtsi.modal_bridge import ModalBridge
from vtsi.recorders import NodeRecorder

# (αM, αF) and optionally OpenSees's third and fourth arguments, which its parser reads as β, γ
OPENSEES_CASES = [(1.0, 0.8), (0.9, 0.7), (2.0 / 3.0, 5.0 / 9.0),
                  (1.0, 0.8, 0.36, 0.7),          # the defaults, given
                  (0.9, 0.7, 0.4, 0.75), (1.0, 0.8, 0.45, 0.75), (0.95, 0.8, 0.4, 0.7)]


def run_script(script, ops, integrator, steps=250, dt=2e-3):
    """The moving-force script (``tests/scripts/moving_load_beam.py``, 10 elements, 20 m, a force
    at 25 m/s) with ``integrator``; returns the midspan displacement and acceleration, a
    rotation rate, an end moment and the time, every step."""
    script.build(ops, 10, 20.0, 1.2, dt, steps, 25.0, rayleigh=(0.15, 2e-4))
    script.transient(ops, integrator)
    rows = []
    for _ in range(steps):
        ops.analyze(1, dt)
        rows.append([ops.nodeDisp(6, 2), ops.nodeDisp(3, 2), ops.nodeAccel(6, 2), ops.nodeVel(3, 3),
                     ops.eleForce(2)[2], ops.getTime()])
    return np.array(rows)


@pytest.mark.parametrize("params", OPENSEES_CASES, ids=str)
def test_commands_equal_opensees(params, moving_load_beam):
    """``integrator('GeneralizedAlpha', αM, αF, [β, γ])`` through vtsi.opensees and OpenSeesPy."""
    integrator = ("GeneralizedAlpha",) + params
    ref = run_script(moving_load_beam, oracle, integrator)
    val = run_script(moving_load_beam, vops, integrator)
    np.testing.assert_array_equal(val[:, -1], ref[:, -1])          # the time, accumulated as OpenSees does
    scale = np.abs(ref[:, :-1]).max(axis=0)
    assert np.max(np.abs(val[:, :2] - ref[:, :2]) / scale[:2]) < 1e-9       # displacements
    assert np.max(np.abs(val[:, 2:-1] - ref[:, 2:-1]) / scale[2:]) < 1e-9


def beam_model(n_el=10, span=20.0, inertia=1.2, dt=2e-3, n_steps=250, speed=25.0, force=1e5,
               rayleigh=(0.15, 2e-4)):
    """The moving-force script's beam with the object API (vtsi.Model): consistent-mass
    elasticBeamColumn elements, one Path pattern per interior node, Rayleigh αM and βK."""
    m = vtsi.Model()
    x = np.linspace(0.0, span, n_el + 1)
    for i, xi in enumerate(x):
        m.node(i + 1, float(xi), 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(n_el + 1, 0, 1, 0)
    for e in range(n_el):
        m.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=1.0, E=3.0e10, I=inertia, rho=2.0e4, cmass=1)
    t = dt * np.arange(n_steps + 1)
    h = span / n_el
    for i in range(1, n_el):
        share = np.clip(1.0 - np.abs(speed * t - x[i]) / h, 0.0, None) * force
        m.pattern(i + 1, vtsi.Path(share, dt=dt)).load(i + 1, 0.0, -1.0, 0.0)
    m.rayleigh(rayleigh[0], rayleigh[1])
    return m


def run_object_api(integrator, steps=250, dt=2e-3, bridge=False):
    """Midspan and quarter-point uy, midspan acceleration, rotation rate at node 3, every step."""
    m = beam_model(dt=dt, n_steps=steps)
    recs = [NodeRecorder([6, 3], [2], "disp"), NodeRecorder([6], [2], "accel"), NodeRecorder([3], [3], "vel")]
    b = ModalBridge(m, n_modes="all") if bridge else None
    vtsi.TransientAnalysis(m, integrator, dt, recorders=recs, bridge=b).run(steps)
    return np.hstack([r.values for r in recs])


@pytest.mark.parametrize("params", OPENSEES_CASES, ids=str)
def test_object_api_equals_opensees(params, moving_load_beam):
    """``GeneralizedAlpha(αM, αF, gamma, beta)`` (γ, β by name: OpenSees reads its third and
    fourth arguments as β, γ) on the beam built with vtsi.Model, against OpenSeesPy running the
    script: displacements to 1e-9 of their maxima (measured 3.8e-14 or less), the rest too
    (8.7e-12)."""
    kwargs = {} if len(params) == 2 else {"beta": params[2], "gamma": params[3]}
    ref = run_script(moving_load_beam, oracle, ("GeneralizedAlpha",) + params)
    val = run_object_api(GeneralizedAlpha(*params[:2], **kwargs))
    ref = ref[:, [0, 1, 2, 3]]
    scale = np.abs(ref).max(axis=0)
    assert np.all(scale > 0.0)
    assert np.max(np.abs(val[:, :2] - ref[:, :2]) / scale[:2]) < 1e-9
    assert np.max(np.abs(val[:, 2:] - ref[:, 2:]) / scale[2:]) < 1e-9


def test_newmark_and_hht_are_special_cases():
    """αM = αF = 1 gives Newmark's coefficients exactly (km = 0, load weight 1, ku = du): the same
    numbers to the last bit. αM = 1 is HHT(αF) (γ = ½ + 1 − αF and β = ¼(2 − αF)² to rounding;
    measured identical at αF = 0.9 and 0.7)."""
    ga, nm = GeneralizedAlpha(1.0, 1.0), Newmark()
    (s_ga,), (s_nm,) = ga.stages(2e-3), nm.stages(2e-3)
    for name in ("du", "dv", "ku", "kv", "km"):
        assert np.array_equal(getattr(s_ga, name), getattr(s_nm, name)), name
    assert s_ga.load == s_nm.load and s_ga.force_weight == s_nm.force_weight == 1.0
    for bridge in (False, True):
        assert np.array_equal(run_object_api(ga, bridge=bridge), run_object_api(nm, bridge=bridge))
    for alpha in (0.9, 0.7):
        a, b = run_object_api(GeneralizedAlpha(1.0, alpha)), run_object_api(HHT(alpha))
        assert np.max(np.abs(a - b) / np.abs(b).max(axis=0)) < 1e-14


def test_modal_bridge_with_all_modes_equals_the_fe_bridge():
    """The beam under its moving force with ModalBridge(n_modes='all'): the same numbers as the
    FE bridge to rounding (measured 3.2e-14 of the maximum displacement, 3.2e-12 of the
    maximum acceleration)."""
    for params in ((0.9, 0.7), (1.0, 0.8)):
        fe = run_object_api(GeneralizedAlpha(*params))
        modal = run_object_api(GeneralizedAlpha(*params), bridge=True)
        scale = np.abs(fe).max(axis=0)
        assert np.max(np.abs(modal[:, :2] - fe[:, :2]) / scale[:2]) < 1e-9
        assert np.max(np.abs(modal[:, 2:] - fe[:, 2:]) / scale[2:]) < 1e-9


def test_modal_bridge_under_a_path_load():
    """A Path load on a node (not the moving force): modal (every mode) = FE to 1e-9."""
    fe, modal = [], []
    for out, bridge in ((fe, False), (modal, True)):
        m = vtsi.Model()
        for i in range(9):
            m.node(i + 1, 2.5 * i, 0.0)
        m.fix(1, 1, 1, 0)
        m.fix(9, 0, 1, 0)
        for e in range(8):
            m.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=1.0, E=3e10, I=1.2, rho=2e4, cmass=1)
        m.rayleigh(0.2, 1e-4)
        m.pattern(1, vtsi.Path([0.0, 1e5, 0.0, -5e4, 0.0], dt=0.01, tag=1)).load(4, 0.0, -1.0, 0.0)
        rec = NodeRecorder([5], [2], "disp")
        b = ModalBridge(m, n_modes="all") if bridge else None
        vtsi.TransientAnalysis(m, GeneralizedAlpha(0.9, 0.7), 1e-3, recorders=[rec], bridge=b).run(200)
        out.append(rec.values[:, 0])
    np.testing.assert_allclose(modal[0], fe[0], rtol=0, atol=1e-9 * np.abs(fe[0]).max())


# -- single-dof oscillator: order and spectral radius through the compiled loop -----------------------
def oscillator(omega, xi=0.0, mass=2.0, ramp=0.0, state=(1.0, 0.0, None)):
    """``m ü + c u̇ + k u = ramp·m·t`` on node 2's uy (a zeroLength spring and dashpot to a fixed
    node), ``k = m ω²``, ``c = 2 ξ m ω``, started from ``state`` = (u0, v0, a0) (a0 None: the
    consistent one)."""
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 0.0, 0.0)
    m.fix(1, 1, 1, 1)
    m.fix(2, 1, 0, 1)
    m.mass(2, 0.0, mass, 0.0)
    k, c = mass * omega ** 2, 2.0 * xi * mass * omega
    m.element("zeroLength", 1, (1, 2), ky=k, cy=c)
    if ramp:
        m.pattern(1, vtsi.Linear(ramp * mass)).load(2, 0.0, 1.0, 0.0)
    u0, v0, a0 = state
    dom = vtsi.domain_state(m)
    d = m.build().full_dof(2, 2)
    dom.u[d], dom.v[d] = u0, v0
    dom.a[d] = -(k * u0 + c * v0) / mass if a0 is None else a0
    return m


def simulate(integrator, omega, dt, n_steps, xi=0.0, ramp=0.0, state=(1.0, 0.0, None)):
    """``(n_steps, 3)``: u, v, a of the oscillator after each step."""
    m = oscillator(omega, xi, ramp=ramp, state=state)
    recs = [NodeRecorder([2], [2], q) for q in ("disp", "vel", "accel")]
    vtsi.TransientAnalysis(m, integrator, dt, recorders=recs).run(n_steps)
    return np.hstack([r.values for r in recs])


def exact_displacement(t, omega, xi, u0, v0, ramp):
    """``u(t)`` of ``ü + 2ξω u̇ + ω² u = ramp·t`` (ξ < 1)."""
    k, c = omega ** 2, 2.0 * xi * omega
    wd = omega * np.sqrt(1.0 - xi ** 2)
    up0, vp = -ramp * c / k ** 2, ramp / k
    a = u0 - up0
    b = (v0 - vp + xi * omega * a) / wd
    return np.exp(-xi * omega * t) * (a * np.cos(wd * t) + b * np.sin(wd * t)) + ramp / k * (t - c / k)


OMEGA, RAMP, T_END = 2.0 * np.pi, 40.0, 1.3
CASES = {   # (xi, u0, v0, ramp): the forced case starts near the ramp's particular solution, so
            # a load evaluated at the wrong time dominates its error
    "free-undamped": (0.0, 1.0, 0.5, 0.0),
    "free-damped": (0.05, 1.0, 0.5, 0.0),
    "ramp-damped": (0.05, 0.1 - RAMP * 2 * 0.05 * OMEGA / OMEGA ** 4, RAMP / OMEGA ** 2, RAMP),
}
STEPS = 0.0125 / 2.0 ** np.arange(4)


def observed_order(integrator, case):
    xi, u0, v0, ramp = CASES[case]
    errors = []
    for dt in STEPS:
        n = int(round(T_END / dt))
        u = simulate(integrator, OMEGA, dt, n, xi, ramp, (u0, v0, None))[-1, 0]
        errors.append(abs(u - exact_displacement(n * dt, OMEGA, xi, u0, v0, ramp)))
    return float(np.polyfit(np.log(STEPS), np.log(errors), 1)[0])


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("params", [(1.0, 0.8), (0.9, 0.7), (2.0 / 3.0, 5.0 / 9.0), (1.5, 0.8)], ids=str)
def test_second_order(params, case):
    """Displacement error at t = 1.3 s against the exact solution, Δt = 12.5 … 1.6 ms: slope 2 ±
    0.1 with the default γ, β (measured 1.9998–2.0058)."""
    assert observed_order(GeneralizedAlpha(*params), case) == pytest.approx(2.0, abs=0.1)


class _LoadAtEnd(GeneralizedAlpha):
    """The load (wrongly) at t_{n+1} instead of t_n + αF Δt."""

    def stages(self, dt):
        (stage,) = super().stages(dt)
        stage.load = [(1.0, stage.load[0][1])]
        return [stage]


def test_order_test_detects_a_wrong_load_time():
    """Negative control: the ramp case is first order with the load at t_{n+1} (measured 1.03),
    and so is any case with γ above ½ + αM − αF (the method's first-order branch; measured
    1.13)."""
    assert observed_order(_LoadAtEnd(0.9, 0.7), "ramp-damped") < 1.5
    assert observed_order(GeneralizedAlpha(0.9, 0.7, gamma=0.8, beta=0.45), "free-damped") < 1.5


def measured_amplification(integrator, omega_dt, dt=1e-3):
    """3×3 ``A`` with ``(u, v, a)_{n+1} = A (u, v, a)_n`` of the undamped oscillator, a column
    per one-step run of the compiled loop from a unit u, v or a."""
    omega = omega_dt / dt
    return np.column_stack([simulate(integrator, omega, dt, 1, state=tuple(e))[0] for e in np.eye(3)])


def rho_inf(alpha_m, alpha_f):
    """Closed form of the spectral radius at ωΔt → ∞ with the default γ, β: the roots of the
    amplification matrix tend to (αF − 1)/αF (from u_{n+αF} = 0) and, double, to
    (αM − αF − 1)/(αM − αF + 1) (derived from the stage equations; Chung & Hulbert 1993 in
    OpenSees's αM = 1 − α_m, αF = 1 − α_f)."""
    d = alpha_m - alpha_f
    return max(abs((alpha_f - 1.0) / alpha_f), abs((d - 1.0) / (d + 1.0)))


@pytest.mark.parametrize("params", [(1.0, 0.8), (0.9, 0.7), (1.2, 0.6), (1.5, 0.8), (1.0, 1.0)], ids=str)
def test_spectral_radius_at_infinity(params):
    """Distinct roots at infinity: ρ(ωΔt = 10⁶) equals the closed form to 1e-8 (measured
    4.4e-10 or less); ρ ≤ 1 over ωΔt = 10⁻² … 10⁶ (unconditional stability)."""
    integ = GeneralizedAlpha(*params)
    rho = np.max(np.abs(np.linalg.eigvals(measured_amplification(integ, 1e6))))
    assert rho == pytest.approx(rho_inf(*params), abs=1e-8)
    for omega_dt in np.logspace(-2, 6, 17):
        assert np.max(np.abs(np.linalg.eigvals(measured_amplification(integ, omega_dt)))) <= 1.0 + 1e-9


@pytest.mark.parametrize("rho", [0.0, 0.5, 0.8])
def test_spectral_radius_of_the_rho_parametrisation(rho):
    """αM = (2 − ρ∞)/(1 + ρ∞), αF = 1/(1 + ρ∞): the closed form gives ρ∞ back, and the three
    roots meet at −ρ∞ so ρ approaches it slowly (measured 7.6e-6 off at ωΔt = 10⁸)."""
    params = ((2.0 - rho) / (1.0 + rho), 1.0 / (1.0 + rho))
    assert rho_inf(*params) == pytest.approx(rho, abs=1e-15)
    measured = np.max(np.abs(np.linalg.eigvals(measured_amplification(GeneralizedAlpha(*params), 1e8))))
    assert measured == pytest.approx(rho, abs=1e-4)


# -- refusals --------------------------------------------------------------------------------------------
def test_refusals():
    with pytest.raises(AnalysisError, match=r"alpha_m = 0.6 is outside \[0.7, 2\]"):
        GeneralizedAlpha(0.6, 0.7)
    with pytest.raises(AnalysisError, match="alpha_f = 0.4 is outside"):
        GeneralizedAlpha(0.9, 0.4)
    with pytest.raises(AnalysisError, match=r"alpha_f = 1.1 is outside \[0.5, 1\]"):
        GeneralizedAlpha(1.2, 1.1)
    with pytest.raises(AnalysisError, match=r"alpha_m = 2.5 is outside \[0.7, 2\]"):
        GeneralizedAlpha(2.5, 0.7)
    with pytest.raises(AnalysisError, match=r"gamma = 0.5 is outside \[0.7, inf\] \(the unconditionally stable range"):
        GeneralizedAlpha(0.9, 0.7, 0.5, 0.3)
    with pytest.raises(AnalysisError, match=r"beta = 0.3 is outside \[0.375, inf\]"):
        GeneralizedAlpha(0.9, 0.7, 0.75, 0.3)
    with pytest.raises(AnalysisError, match="gamma = nan is outside"):
        GeneralizedAlpha(0.9, 0.7, float("nan"), 0.4)
    with pytest.raises(AnalysisError, match="beta must be a number, got 'x'"):
        GeneralizedAlpha(0.9, 0.7, 0.75, "x")
    with pytest.raises(AnalysisError, match="alpha_m must be a number"):
        GeneralizedAlpha(None, 0.7)
    vops.wipe()
    with pytest.raises(CommandError, match="integrator GeneralizedAlpha: missing alphaF"):
        vops.integrator("GeneralizedAlpha", 0.9)
    with pytest.raises(AnalysisError, match="alpha_m = 0.5 is outside"):
        vops.integrator("GeneralizedAlpha", 0.5, 0.7)


def test_the_coupled_analysis_takes_it():
    """The coupled analysis weights the contact forces like the other forces (αF/αM λ_{n+1} +
    (1 − αF)/αM λ_n) and the train's weight by 1/αM (tests/test_coupled.py checks the numbers)."""
    from vtsi.coupled import coupled_integrator
    integ = coupled_integrator(GeneralizedAlpha(0.9, 0.7), "bilateral")
    (stage,) = integ.stages(1e-3)
    assert stage.force_weight == pytest.approx(0.7 / 0.9, rel=1e-15)
    assert stage.mass_weight == pytest.approx(1.0 / 0.9, rel=1e-15)
    assert coupled_integrator(GeneralizedAlpha(0.9, 0.7), "lcp") is not None      # dissipative
