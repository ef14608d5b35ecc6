"""Reference solvers R1 (constraint elimination), R2 (SUNDIALS IDA) and R1 with contact loss.

What is checked, and the numbers measured when these tests were written (docs/theory/
reference_solvers.md has the full tables):

- the compiled right-hand side of R1 equals the long form Bᵀ M B ÿ + ... = ... (two code paths);
- R1's dead load equals CoupledAnalysis.static();
- R1 and R2 agree to 1e-6 relative on S2 and S3 (S3 at 300 km/h, 20 elements): midspan deflection,
  car-body accelerations, contact forces (S3: their exact 10 ms average, since the pointwise λ of
  a massive wheel carries bridge modes up to ~10 kHz whose phase both solvers resolve to ~1e-5 of
  λ only), impulses at span entry and exit;
- R1 on S2 against Yang & Yau (1997): max midspan deflection 2.4073 mm at 0.3711 s, max |sprung-mass
  acceleration| 0.148 m/s² (the modal solution of docs/scenes.md, S2, 20 modes);
- CoupledAnalysis converges to R1 on S3 (10 ms window averages of the midspan deflection: ~4×
  per halving of dt);
- contact loss: a wheel over a raised-cosine bump on rigid ground against the closed-form lift-off,
  ballistic flight and landing; on a flexible beam against the bilateral R1 (lift-off where its λ
  crosses zero) and the LCP analysis (lift-off and landing times).
"""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import trapezoid
from scipy.optimize import brentq

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.models.bridges import simply_supported_beam
from vtsi.models.cars import moving_mass, sprung_mass
from vtsi.models.irregularity import Irregularity
from vtsi.models.scenes import S2, S3, s2_model, s3_model
from vtsi.vehicle import Train, moving_force
from vtsi.recorders import NodeRecorder, TrainRecorder
from vtsi.reference import elimination, events, ida
from vtsi.track import Track
from vtsi.train import TrainSubdomain

S2_T_END = 0.5     # covers the maxima of S2 (deflection at 0.371 s, acceleration at 0.448 s)
S3_T_END = 0.6     # both wheels of the S3 car have left the span at 0.5685 s
S3_DT_OUT = 2.5e-4


def _s2(n_elements=20):
    model = vtsi.Model()
    bridge, train = s2_model(model, n_elements)
    sub = TrainSubdomain(train, 0.0)
    return model, bridge, sub, MovingLoadConstraint(Track(model, bridge.elements), sub)


def _s3(n_elements=20, approach=None, irregularity=None, interpolation="hermite"):
    model = vtsi.Model()
    bridge, train, x_head0 = s3_model(model, n_elements, **({} if approach is None else {"approach": approach}))
    sub = TrainSubdomain(train, x_head0)
    con = MovingLoadConstraint(Track(model, bridge.elements), sub, irregularity=irregularity,
                               interpolation=interpolation)
    return model, bridge, sub, con


def _rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max()


def _body(sub):
    return np.setdiff1d(np.arange(sub.n_dof), sub.wheel_dofs)


def _needs_sundials():
    pytest.importorskip("sksundae")      # R2 only: the 'test' extra


@pytest.fixture(scope="module")
def s2_r1():
    model, bridge, sub, con = _s2()
    return bridge, sub, elimination.solve(model, con, S2_T_END, np.linspace(0.0, S2_T_END, 1001), rtol=1e-9)


@pytest.fixture(scope="module")
def s3_r1():
    model, bridge, sub, con = _s3()
    t = np.linspace(0.0, S3_T_END, int(round(S3_T_END / S3_DT_OUT)) + 1)
    return bridge, sub, elimination.solve(model, con, S3_T_END, t, rtol=1e-10)


# -- R1 internals -----------------------------------------------------------------------------
@pytest.mark.parametrize("active", [[True, True], [True, False], [False, False]])
def test_compiled_rhs_equals_long_form(active):
    """Phase.accel (numba, Woodbury-type solve) vs A ÿ = F − D ẏ − E y with A = Bᵀ M B etc., and
    λ vs the wheel rows of the train equations; Jacobian vs the right-hand side (linear)."""
    model, bridge, sub, con = _s3(n_elements=10, approach=5.0)
    s = elimination.CoupledSystem(model, con)
    t = 0.12          # lead wheel on the span, rear wheel on the ground
    phase = elimination.Phase(s, t, active=active)
    rng = np.random.default_rng(1)
    y, yd = 1e-3 * rng.standard_normal(phase.n_y), 1e-2 * rng.standard_normal(phase.n_y)
    ydd, lam = phase.accel(t, y, yd)
    A, D, E, F = phase.linear_operator(t)
    assert _rel(ydd, np.linalg.solve(A, F - D @ yd - E @ y)) < 1e-12
    _, _, _, u_t, v_t, a_t, _ = phase.full(t, y, yd, ydd)
    wheel_rows = (sub.M @ a_t + sub.C @ v_t + sub.K @ u_t - sub.gravity_load)[phase.w]
    np.testing.assert_allclose(lam, wheel_rows, rtol=1e-10, atol=1e-6)
    z = phase.pack(y, yd)
    J = phase.jac(t, z)
    assert _rel(phase.fun(t, z) - phase.fun(t, 0 * z), J @ z) < 1e-10


@pytest.mark.parametrize("self_weight", [False, True])
def test_dead_load_equals_coupled_static(self_weight):
    model, bridge, sub, con = _s3(approach=-8.0)     # lead wheel 8 m into the span, rear wheel on the ground
    r1 = elimination.solve(model, con, 1e-4, [0.0, 1e-4], bridge_self_weight=self_weight)
    static = CoupledAnalysis(model, con, "Newmark", 1e-3, bridge_self_weight=self_weight).static()
    asm = model.build()
    np.testing.assert_allclose(r1.dead_load["bridge_u"], static["bridge_u"][asm.full_of_free], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(r1.dead_load["train_u"], static["train_u"], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(r1.dead_load["contact_force"], static["contact_force"], rtol=1e-9)
    np.testing.assert_allclose(r1.bridge_u[0], r1.dead_load["bridge_u"], rtol=0, atol=1e-15)


def test_node_helper_and_output_shapes(s2_r1):
    bridge, sub, r1 = s2_r1
    asm = r1.assembly
    mid = bridge.midspan_nodes[0]
    np.testing.assert_array_equal(r1.node(mid, 2), r1.bridge_u[:, asm.free_of_full[asm.full_dof(mid, 2)]])
    np.testing.assert_array_equal(r1.node(bridge.supports[0], 2), 0.0)     # fixed dof
    assert r1.bridge_u.shape == (len(r1.t), asm.n_free)
    assert r1.train_a.shape == (len(r1.t), sub.n_dof) and r1.contact_force.shape == (len(r1.t), 1)


def test_radau_and_fortran_dop853_agree():
    """The default ('dop853', scipy.integrate.ode) and solve_ivp's Radau with the analytic
    Jacobian solve the same ODE (short run: Radau is slow on this stiff, oscillatory problem)."""
    model, bridge, sub, con = _s3(n_elements=6, approach=-8.0)
    t = np.linspace(0.0, 0.03, 31)
    a = elimination.solve(model, con, 0.03, t, rtol=1e-9)
    b = elimination.solve(model, con, 0.03, t, rtol=1e-9, method="Radau")
    assert _rel(b.node(bridge.midspan_nodes[0], 2), a.node(bridge.midspan_nodes[0], 2)) < 1e-6
    assert _rel(b.contact_force, a.contact_force) < 1e-6


# -- R1 against R2 ----------------------------------------------------------------------------
def test_r1_r2_agree_s2(s2_r1):
    """R1 and R2 at rtol 1e-9, first 0.5 s. Measured (R2 against R1 at rtol 1e-12): deflection
    8.5e-10, body acceleration 9.8e-9, λ 9.8e-9 (relative to the max)."""
    _needs_sundials()
    bridge, sub, r1 = s2_r1
    model, _, _, con = _s2()
    r2 = ida.solve(model, con, S2_T_END, r1.t, rtol=1e-9)
    mid = bridge.midspan_nodes[0]
    assert _rel(r2.node(mid, 2), r1.node(mid, 2)) < 1e-6
    assert _rel(r2.train_a[:, _body(sub)], r1.train_a[:, _body(sub)]) < 1e-6
    assert _rel(r2.contact_force, r1.contact_force) < 1e-6


def test_r1_r2_agree_s3(s3_r1):
    """R1 at rtol 1e-10, R2 at 1e-11. Measured (against R1 at 1e-12): R1 deflection 4.0e-11, body
    accelerations 2.8e-7, 10 ms average of λ 2.8e-8, impulses 8e-9, pointwise λ 1.4e-5; R2
    1.0e-10, 4.1e-7, 3.1e-8, 7e-9, 1.2e-5."""
    _needs_sundials()
    bridge, sub, r1 = s3_r1
    model, _, _, con = _s3()
    r2 = ida.solve(model, con, S3_T_END, r1.t, rtol=1e-11)
    mid = bridge.midspan_nodes[0]
    assert _rel(r2.node(mid, 2), r1.node(mid, 2)) < 1e-6
    assert _rel(r2.train_a[:, _body(sub)], r1.train_a[:, _body(sub)]) < 1e-6
    _, avg1 = elimination.average_contact_force(r1, sub, 0.01)
    _, avg2 = elimination.average_contact_force(r2, sub, 0.01)
    assert _rel(avg2, avg1) < 1e-6
    assert _rel(r2.contact_force, r1.contact_force) < 1e-4      # pointwise: see the docstring
    # impulses at the rear wheel's entry and at both exits (the lead wheel enters an unloaded
    # span), tensile: the rail falls away from the wheel
    x0, V, L = sub.wheel_x0(sub.contact_wheels), sub.speed, S3["L"]
    expected = [(-x0[1] / V, 1), ((L - x0[0]) / V, 0), ((L - x0[1]) / V, 1)]
    assert len(r1.impulses) == 3
    for (t, w, _), (te, we) in zip(r1.impulses, expected):
        assert w == we and t == pytest.approx(te, abs=1e-9)
    assert [(t, w) for t, w, _ in r1.impulses] == [(t, w) for t, w, _ in r2.impulses]
    i1, i2 = (np.array([i for _, _, i in r.impulses]) for r in (r1, r2))
    assert np.all(i1 < 0) and _rel(i2, i1) < 1e-6


def test_r1_r2_agree_with_irregularity_and_force_wheels():
    """A 4-dof car behind a moving force, over a smooth rail profile (r, r', r'' given)."""
    _needs_sundials()
    k = 2 * np.pi / 7.0
    profile = Irregularity.from_function(lambda x: 1e-3 * np.sin(k * x), lambda x: 1e-3 * k * np.cos(k * x),
                                         lambda x: -1e-3 * k * k * np.sin(k * x))
    p = S3
    model = vtsi.Model()
    bridge = simply_supported_beam(model, p["L"], 6, p["E"], p["I"], p["mu"])
    from vtsi.models.cars import four_dof_car
    car = four_dof_car(p["m_c"], p["J_c"], p["m_w"], p["k_s"], p["c_s"], p["l_c"])
    train = Train([moving_force(2.0e5), car], [0.0, 4.0], p["V"])
    sub = TrainSubdomain(train, 2.0)
    con = MovingLoadConstraint(Track(model, bridge.elements), sub, irregularity=profile)
    t = np.linspace(0.0, 0.15, 151)
    r1 = elimination.solve(model, con, 0.15, t, rtol=1e-10)
    r2 = ida.solve(model, con, 0.15, t, rtol=1e-10)
    mid = bridge.midspan_nodes[0]
    assert _rel(r2.node(mid, 2), r1.node(mid, 2)) < 1e-6
    assert _rel(r2.train_a[:, _body(sub)], r1.train_a[:, _body(sub)]) < 1e-6
    _, a1 = elimination.average_contact_force(r1, sub, 0.01)
    _, a2 = elimination.average_contact_force(r2, sub, 0.01)
    assert _rel(a2, a1) < 1e-6


# -- R1 against published and converged numbers ----------------------------------------------
def test_s2_yang_yau(s2_r1):
    """Yang & Yau (1997) / Biggs: the modal solution of docs/scenes.md S2 (20 modes). Measured
    with 20 elements: 2.40733 mm at t = 0.3710 s (output every 0.5 ms), max |a| = 0.147956 m/s²
    (at 0.448 s)."""
    bridge, sub, r1 = s2_r1
    w = -r1.node(bridge.midspan_nodes[0], 2)
    i = int(np.argmax(w))
    assert w[i] == pytest.approx(S2["max_midspan_deflection"], rel=2e-3)
    assert r1.t[i] == pytest.approx(S2["time_of_max"], abs=2e-3)
    body = sub.train.dof_names.index("car0.body_y")
    assert np.abs(r1.train_a[:, body]).max() == pytest.approx(S2["max_sprung_acceleration"], rel=2e-2)


def _window_means(t, w, width, t_end):
    """Means of w over the windows [k width, (k + 1) width] (trapezoidal rule)."""
    out = []
    for a in np.arange(0.0, t_end - width / 2, width):
        s = (t >= a - 1e-12) & (t <= a + width + 1e-12)
        out.append(trapezoid(w[s], t[s]) / width)
    return np.array(out)


@pytest.mark.parametrize("integrator", ["Newmark", "Bathe"])
def test_coupled_analysis_converges_to_r1(s3_r1, integrator):
    """Midspan deflection of S3, 10 ms window means (pointwise, the undamped high bridge modes'
    phase error makes the ratios erratic: 2.3-3.4). Measured ratios per halving of dt
    (2e-3 -> 1e-3 -> 5e-4 -> 2.5e-4): Newmark 3.84, 4.08, 3.56; Bathe 4.27, 3.61, 4.24."""
    bridge, sub, r1 = s3_r1
    mid = bridge.midspan_nodes[0]
    ref = _window_means(r1.t, r1.node(mid, 2), 0.01, S3_T_END)
    scale = np.abs(r1.node(mid, 2)).max()
    errors = []
    for dt in (1e-3, 5e-4, 2.5e-4):
        model, bridge, sub, con = _s3()
        rec = NodeRecorder([mid], [2])
        analysis = CoupledAnalysis(model, con, integrator, dt, recorders=[rec])
        analysis.static()
        analysis.run(int(round(S3_T_END / dt)))
        t = np.concatenate([[0.0], np.asarray(rec.time)])
        w = np.concatenate([[r1.node(mid, 2)[0]], np.asarray(rec.values)[:, 0]])
        errors.append(np.abs(_window_means(t, w, 0.01, S3_T_END) - ref).max() / scale)
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert errors[-1] < 1e-4
    assert np.all(ratios > 3.2), (errors, ratios)


# -- contact loss -----------------------------------------------------------------------------
def _bump(h, length, x_b):
    k = 2 * np.pi / length

    def r(x, nu=0):
        x = np.asarray(x, dtype=float)
        phi = k * (x - x_b)
        on = (x >= x_b) & (x <= x_b + length)
        value = (h / 2 * (1 - np.cos(phi)), h / 2 * k * np.sin(phi), h / 2 * k * k * np.cos(phi))[nu]
        return np.where(on, value, 0.0)
    return r


def test_moving_mass_over_bump_on_rigid_ground():
    """A wheel of mass m on a raised-cosine bump of height h and length ℓ (on rigid ground) at
    speed V stays on while m (g + V² r''(x)) > 0: it leaves where V² r'' = −g, cos φ = −2g/(h k² V²)
    (k = 2π/ℓ), flies ballistically and lands where z(t) = r(x(t)) with an inelastic impulse
    m (V r'(x) − ż)."""
    g, m, V, h, length, x_b = 9.81, 1000.0, 30.0, 0.01, 2.0, 1.0
    r = _bump(h, length, x_b)
    sub = TrainSubdomain(Train([moving_mass(m, g=g)], [0.0], V), 0.0)
    t_end = 0.3
    t = np.linspace(0.0, t_end, 3001)
    sol = events.solve_single_wheel(None, elimination.RigidGround(sub, r), t_end, t,
                                    irregularity_breaks=[x_b, x_b + length])
    k = 2 * np.pi / length
    phi = np.arccos(-2 * g / (h * k * k * V * V))
    t_lift = (x_b + phi / k) / V
    z0, v0 = r(V * t_lift), V * r(V * t_lift, 1)
    z = lambda s: z0 + v0 * (s - t_lift) - g / 2 * (s - t_lift) ** 2
    f = lambda s: z(s) - r(V * s)
    grid = np.linspace(t_lift + 1e-4, t_end, 20001)
    j = int(np.flatnonzero(f(grid) < 0)[0])
    t_land = brentq(f, grid[j - 1], grid[j], xtol=1e-15)
    assert [e[0] for e in sol.events] == ["lift-off", "landing"]
    assert sol.events[0][1] == pytest.approx(t_lift, abs=1e-6)
    assert sol.events[1][1] == pytest.approx(t_land, abs=1e-6)
    assert sol.events[1][2] == pytest.approx(V * t_land, abs=1e-6 * V)
    flight = (t > t_lift) & (t < t_land)
    np.testing.assert_allclose(sol.train_u[flight, 0], z(t[flight]), rtol=0, atol=1e-9)
    assert np.all(sol.contact_force[flight] == 0) and np.all(sol.gap[flight] > 0)
    impulse = m * (V * r(V * t_land, 1) - (v0 - g * (t_land - t_lift)))
    assert sol.impulses[0][2] == pytest.approx(impulse, rel=1e-6)
    on = ~flight & (t < t_end)
    np.testing.assert_allclose(sol.contact_force[on & (t != t_lift), 0],
                               np.maximum(m * (g + V * V * r(V * t[on & (t != t_lift)], 2)), 0), rtol=1e-9, atol=1e-6)


def _bump_on_beam():
    """A sprung mass with a 2 t wheel at 40 m/s over a 5 mm, 1 m bump just after the S3 span's
    entry (6 elements: a short run)."""
    r = _bump(0.005, 1.0, 1.0)
    profile = Irregularity.from_function(lambda x: r(x, 0), lambda x: r(x, 1), lambda x: r(x, 2))
    model = vtsi.Model()
    bridge = simply_supported_beam(model, S3["L"], 6, S3["E"], S3["I"], S3["mu"])
    sub = TrainSubdomain(Train([sprung_mass(20000.0, 1.0e6, 2.0e4, m_w=2000.0)], [0.0], 40.0), -0.5)
    return model, bridge, sub, MovingLoadConstraint(Track(model, bridge.elements), sub, irregularity=profile)


def test_wheel_leaves_a_flexible_beam():
    """Measured: lift-off 0.0469950 s, landing 0.0602868 s (impulse 1274 N·s), no further
    separation (λ ≥ 153 kN after the landing). Bilateral R1: λ crosses zero at the same lift-off
    time; LCP analysis (Bathe, dt = 2.5e-5): lift-off 0.0469960 s, landing 0.0602868 s."""
    t_end = 0.1
    t = np.linspace(0.0, t_end, 1001)
    model, bridge, sub, con = _bump_on_beam()
    sol = events.solve_single_wheel(model, con, t_end, t, irregularity_breaks=[1.0, 2.0])
    assert [e[0] for e in sol.events] == ["lift-off", "landing"]
    t_lift, t_land = sol.events[0][1], sol.events[1][1]
    assert 0.04 < t_lift < t_land < 0.07
    assert len(sol.impulses) == 1 and sol.impulses[0][2] > 0
    flight = (t > t_lift) & (t < t_land)
    assert np.all(sol.contact_force[flight] == 0) and np.all(sol.gap[flight] > 0)
    assert np.all(sol.contact_force[~flight] >= 0)
    # before the lift-off the motion is the bilateral one; its λ crosses zero at t_lift
    bilateral = elimination.solve(model, con, 0.05, np.linspace(0.0, 0.05, 5001), irregularity_breaks=[1.0, 2.0])
    lam = bilateral.contact_force[:, 0]
    j = int(np.flatnonzero(lam < 0)[0])
    root = bilateral.t[j - 1] + lam[j - 1] / (lam[j - 1] - lam[j]) * (bilateral.t[j] - bilateral.t[j - 1])
    assert root == pytest.approx(t_lift, abs=1e-7)
    n = int((t < t_lift).sum())
    assert _rel(sol.train_u[:n], bilateral.train_u[::10][:n]) < 1e-8
    assert _rel(sol.bridge_u[:n], bilateral.bridge_u[::10][:n]) < 1e-7
    # the LCP time stepping finds the same flight
    model, bridge, sub, con = _bump_on_beam()
    lcp = CoupledAnalysis(model, con, "Bathe", 2.5e-5, contact="lcp")
    lcp.static()
    lcp.run(int(round(t_end / 2.5e-5)))
    found = lcp.contact_events()
    lift = min(e.time for e in found if e.kind == "lift-off" and e.time > 0.04)
    land = min(e.time for e in found if e.kind == "landing" and e.time > lift)
    assert lift == pytest.approx(t_lift, abs=2.5e-5)
    assert land == pytest.approx(t_land, abs=2.5e-5)


def test_single_wheel_needs_a_wheel_mass():
    model, bridge, sub, con = _s2()
    with pytest.raises(vtsi.ModelError, match="no mass"):
        events.solve_single_wheel(model, con, 0.01)


def test_irregularity_without_derivatives_is_refused():
    model = vtsi.Model()
    bridge, train, x0 = s3_model(model, 4)
    sub = TrainSubdomain(train, x0)
    con = MovingLoadConstraint(Track(model, bridge.elements), sub, irregularity=lambda x: 0 * x)
    with pytest.raises(vtsi.ModelError, match="derivatives"):
        elimination.solve(model, con, 0.01)


def test_r1_moving_force_matches_fryba():
    """S1 (a 100 kN force at 100 km/h over a 25 m span, 20 elements), force-only wheel: R1's
    midspan deflection against Frýba's modal series (101 modes, vtsi.reference; downward
    positive there). Measured over the first half of the passage: 9.5e-6 of the max (the FE
    discretisation; R2 agrees with R1 to 6e-10 over the whole passage)."""
    from vtsi.models.scenes import S1
    from vtsi.reference import moving_force_midspan
    model = vtsi.Model()
    bridge = simply_supported_beam(model, S1["L"], 20, S1["E"], S1["I"], S1["mu"])
    sub = TrainSubdomain(Train([moving_force(S1["P"])], [0.0], S1["V"]), 0.0)
    con = MovingLoadConstraint(Track(model, bridge.elements), sub)
    t_end = 0.5 * S1["L"] / S1["V"]
    t = np.linspace(0.0, t_end, 451)
    sol = elimination.solve(model, con, t_end, t, rtol=1e-9)
    series = moving_force_midspan(S1["P"], S1["V"], S1["L"], S1["E"] * S1["I"], S1["mu"], t)
    assert _rel(-sol.node(bridge.midspan_nodes[0], 2), series) < 2e-5
    assert sol.contact_force.shape == (len(t), 0)


@pytest.fixture(scope="module")
def s2_r2():
    _needs_sundials()
    model, bridge, sub, con = _s2()
    t = np.arange(0.0, S2_T_END + 1e-12, 2.5e-4)
    return bridge, sub, ida.solve(model, con, S2_T_END, t, rtol=1e-10)


@pytest.mark.parametrize("integrator", ["Newmark", "Bathe"])
def test_coupled_analysis_converges_to_r2(s2_r2, integrator):
    """vtsi's coupled analysis against the DAE solver R2 directly (not through R1, with which R2
    shares its system assembly: rows, restarts, dead load): S2, 10 ms window means of the mid-span
    deflection, the sprung mass's acceleration and the contact force (λ_{n+1}), Δt = 1, 0.5,
    0.25 ms. What is independent here: vtsi's own compiled step (its banded stages, its
    constraint rows, its velocity-level contact solve) against IDA's index-1 DAE on CoupledSystem.
    Measured (relative to each history's maximum): Newmark 1.9e-5, 8.4e-5, 1.2e-6 at 0.25 ms,
    Bathe 1.1e-5, 4.6e-5, and per halving of Δt the errors fall by 3.1–4.1 (second order; pointwise
    the bridge's undamped high modes make the ratios 2.2–2.8)."""
    bridge, sub_ref, r2 = s2_r2
    mid = bridge.midspan_nodes[0]
    body = sub_ref.train.dof_names.index("car0.body_y")
    refs = [r2.node(mid, 2), r2.train_a[:, body], r2.contact_force[:, 0]]
    means = [_window_means(r2.t, x, 0.01, S2_T_END) for x in refs]
    errors = []
    for dt in (1e-3, 5e-4, 2.5e-4):
        model, bridge, sub, con = _s2()
        deflection, accel = NodeRecorder([mid], [2]), TrainRecorder(sub, ["car0.body_y"], "accel")
        analysis = CoupledAnalysis(model, con, integrator, dt, recorders=[deflection, accel])
        analysis.static()
        analysis.run(int(round(S2_T_END / dt)))
        t = np.concatenate([[0.0], np.asarray(deflection.time)])
        runs = [np.asarray(deflection.values)[:, 0], np.asarray(accel.values)[:, 0], analysis.contact_force_end[:, 0]]
        errors.append([np.abs(_window_means(t, np.concatenate([[ref[0]], run]), 0.01, S2_T_END) - mean).max()
                       / np.abs(ref).max() for run, ref, mean in zip(runs, refs, means)])
    errors = np.array(errors)
    assert np.all(errors[-1] < [5e-5, 2e-4, 1e-5]), errors[-1]
    assert np.all(errors[:-1] / errors[1:] > 2.8), errors


def test_a_segment_ended_by_an_event_before_its_first_output_time():
    """A terminal event before the first output time (a short flight between two impacts):
    scipy gives t and y as empty lists, which raised numpy's TypeError; the segment is the event
    alone."""
    def reached(t, z):
        return z[0] - 0.05
    reached.terminal, reached.direction = True, 1
    phase = SimpleNamespace(fun=lambda t, z: np.array([1.0]))       # z = t
    t, z, hit = elimination.integrate_segment(phase, 0.0, 1.0, np.array([0.0]), np.array([0.5, 1.0]), "DOP853",
                                              1e-10, 1e-12, {}, events=[reached])
    assert hit == 0 and t == pytest.approx([0.05], abs=1e-12) and z.shape == (1, 1) and z[0, 0] == pytest.approx(0.05)
