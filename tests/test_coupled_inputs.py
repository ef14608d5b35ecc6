"""Inputs of CoupledAnalysis and Car that were accepted and gave wrong results: a gap tolerance
that is negative, NaN, text or metres meant as millimetres; a gravity that is NaN or negative; a
user car with a negative or indefinite mass, damping or stiffness matrix. Each is refused in one
line naming the object, the setting and the value (docs/bad_inputs.md §5); what is legitimate
(gap_tol = 0, g = 0, a massless wheel, every catalogue car in every unit system) still runs.
"""
import re

import numpy as np
import pytest

import vtsi
from vtsi.analysis import domain_state
from vtsi.constraint import MovingLoadConstraint
from vtsi.contact import MAX_GAP_TOL
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, ModelError
from vtsi.integrators import HHT
from vtsi.models import Irregularity, Train, car_catalogue, car_from_catalogue, four_dof_car, moving_mass, sprung_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.track import Track
from vtsi.train import TrainSubdomain
from vtsi.units import COMMON_UNITS, Units
from vtsi.vehicle import GRAVITY, Car

L, E, I, MU = 20.0, 3.5e10, 3.0, 2e4          # [m, Pa, m⁴, kg/m]
NAMES = ("body_y", "wheel1_y")
K_SPRING = 1e6 * np.array([[1.0, -1.0], [-1.0, 1.0]])      # k b bᵀ, b = (1, -1): a spring body-wheel [N/m]
M_CAR = np.diag([1e4, 1e3])                                   # [kg]
P_CAR = -GRAVITY * np.diag(M_CAR)                             # [N]


def user_car(M=M_CAR, C=np.zeros((2, 2)), K=K_SPRING, names=NAMES, wheel=1, P=None):
    """A user-built Car: a body over one wheel unless told otherwise."""
    return Car("user", "user", M, C, K, P_CAR if P is None else P, [wheel], [0.0], names)


def analysis(car=None, x_head0=-1.0, speed=30.0, irregularity=None, dt=1e-3, **kwargs):
    """A coupled analysis of ``car`` (default a sprung mass) on a 20 m simply supported beam."""
    model = vtsi.Model()
    bridge = simply_supported_beam(model, L, 10, E, I, MU)
    train = Train([car or sprung_mass(1e4, 1e6, 1e4, 1800.0)], [0.0], speed)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x_head0=x_head0),
                                      irregularity=irregularity)
    return CoupledAnalysis(model, constraint, HHT(0.9), dt, **kwargs), model, bridge


# -- gap_tol -------------------------------------------------------------------------------------
@pytest.mark.parametrize("value, match", [
    (-1.0, r"^CoupledAnalysis: gap_tol \[m\] must be >= 0 and finite, got -1.0$"),     # the wheel fell through
    (float("nan"), r"^CoupledAnalysis: gap_tol \[m\] must be >= 0 and finite, got nan$"),   # false lift-offs
    (float("inf"), r"^CoupledAnalysis: gap_tol \[m\] must be >= 0 and finite, got inf$"),
    ("abc", r"^CoupledAnalysis: gap_tol \[m\] must be a number, got 'abc'$"),      # was a bare ValueError
    (True, r"^CoupledAnalysis: gap_tol \[m\] must be a number, got True$"),
    (0.5, r"^CoupledAnalysis: gap_tol \[m\] must be at most 1e-06 m, got 0.5: a wheel less than gap_tol above "
          r"the rail is put back on it, so a larger one hides and delays lift-offs$"),   # mm given as m
])
def test_a_gap_tolerance_that_is_not_a_small_length_is_refused(value, match):
    with pytest.raises(AnalysisError, match=match):
        analysis(contact="lcp", gap_tol=value)


def test_the_largest_gap_tolerance_leaves_a_rebound_flight_as_round_off_does():
    """MAX_GAP_TOL's reason (its docstring): a four-dof car over a 20 mm, 1 m cosine dip at 60 m/s
    rebounds after its long flight into a short one of about 0.07 mm; with gap_tol = MAX_GAP_TOL
    (and 0, also accepted) that flight starts and peaks as with the 1e-9 m round-off guard."""
    x = np.linspace(-20.0, 20.0, 4001)         # the wheels' travel
    dip = Irregularity(x, np.where(np.abs(x - 10.0) < 0.5, -0.01 * (1.0 + np.cos(2.0 * np.pi * (x - 10.0))), 0.0))
    car = four_dof_car(4e4, 2e6, 2e3, 1e6, 2e4, 17.5)
    flights = {}
    for tol in (1e-9, MAX_GAP_TOL, 0.0):
        an = analysis(car, speed=60.0, irregularity=dip, dt=2.5e-4, contact="lcp", gap_tol=tol)[0]
        an.static()
        an.run(1100)                       # wheel 1 (the leading wheel, column 0) over the dip and back
        gap = an.gap[:, 0]
        up = np.flatnonzero(np.diff((gap > 1e-9).astype(int)) == 1) + 1      # steps a flight starts
        down = np.flatnonzero(np.diff((gap > 1e-9).astype(int)) == -1) + 1
        short = [(a, gap[a:b].max()) for a, b in zip(up, down) if 1e-5 < gap[a:b].max() < 1e-4]
        assert len(short) == 1, (tol, short)
        flights[tol] = short[0]
    start, peak = flights[1e-9]
    assert 5e-5 < peak < 1e-4              # a flight well above the bound, below the 0.1 mm of interest
    for tol in (MAX_GAP_TOL, 0.0):
        assert flights[tol][0] == start
        assert flights[tol][1] == pytest.approx(peak, rel=1e-3)


# -- gravity -------------------------------------------------------------------------------------
@pytest.mark.parametrize("value, match", [
    (float("nan"), r"^CoupledAnalysis: gravity \[m/s²\] must be >= 0 and finite, got nan$"),
    (-9.81, r"^CoupledAnalysis: gravity \[m/s²\] must be >= 0 and finite, got -9.81$"),
    (float("inf"), r"^CoupledAnalysis: gravity \[m/s²\] must be >= 0 and finite, got inf$"),
    ("g", r"^CoupledAnalysis: gravity \[m/s²\] must be a number, got 'g'$"),
])
@pytest.mark.parametrize("self_weight", [False, True])
def test_a_gravity_that_is_not_a_finite_acceleration_is_refused(value, match, self_weight):
    """NaN with the self weight said 'the static train-bridge system is singular'; NaN or -9.81
    without it ran silently."""
    with pytest.raises(AnalysisError, match=match):
        analysis(gravity=value, bridge_self_weight=self_weight)


@pytest.mark.parametrize("g", [0.0, GRAVITY])
def test_gravity_scales_the_self_weight_deflection_and_zero_is_no_weight(g):
    """With the train still off the bridge, the self weight adds 5 μ g L⁴ / (384 EI) at midspan
    (Euler-Bernoulli beam under a uniform load; the consistent mass's load vector is exact at the
    nodes); g = 0 is legitimate and adds nothing (the analysis divides by no g)."""
    deflection = {}
    for self_weight in (False, True):
        an, model, bridge = analysis(x_head0=-30.0, gravity=g, bridge_self_weight=self_weight)
        an.static()
        deflection[self_weight] = domain_state(model).u[model.build().full_dof(bridge.midspan_nodes[0], 2)]
    assert deflection[True] - deflection[False] == pytest.approx(-5 * MU * g * L ** 4 / (384 * E * I), rel=1e-9,
                                                                 abs=1e-15)


# -- Car matrices --------------------------------------------------------------------------------
@pytest.mark.parametrize("matrices, match", [
    # K = -k b bᵀ (the sign typo): the body 0.1 m up at rest, NaN frequencies, a passage diverging silently
    (dict(K=-K_SPRING), r"^car 'user': K\[0, 0\] \(body_y\) is -1e\+06 N/m; a stiffness matrix has no negative "
                        r"diagonal entry \(its strain energy ½ uᵀKu >= 0\)$"),
    # M = diag(-1e4, 1e3): 'a dof with neither mass nor stiffness' when the analysis was prepared
    (dict(M=np.diag([-1e4, 1e3])), r"^car 'user': M\[0, 0\] \(body_y\) is -10000 kg; a mass matrix has no "
                                   r"negative diagonal entry \(its kinetic energy ½ u̇ᵀMu̇ >= 0\)$"),
    (dict(C=np.diag([-5.0, 0.0])), r"^car 'user': C\[0, 0\] \(body_y\) is -5 N·s/m; a damping matrix has no "
                                   r"negative diagonal entry \(its dissipation u̇ᵀCu̇ >= 0\)$"),
    (dict(M=np.diag([0.0, 1e3])), r"^car 'user': M\[0, 0\] \(body_y\) is 0 kg; every dof but a wheel's needs "
                                  r"mass \(only a wheel, held by the rail, may be massless\)$"),
])
def test_a_car_matrix_with_a_negative_diagonal_entry_names_the_entry_and_its_dof(matrices, match):
    with pytest.raises(ModelError, match=match):
        user_car(**matrices)


def test_a_rotation_dof_entry_is_named_in_rotation_units():
    names = ("body_y", "body_rz", "wheel1_y")
    K = np.zeros((3, 3))
    K[np.ix_([0, 2], [0, 2])] = K_SPRING
    K[1, 1] = -2e6
    with pytest.raises(ModelError, match=r"^car 'user': K\[1, 1\] \(body_rz\) is -2e\+06 N·m/rad; "):
        user_car(M=np.diag([1e4, 1e5, 1e3]), C=np.zeros((3, 3)), K=K, names=names, wheel=2,
                 P=np.array([-1e5, 0.0, -1e4]))


@pytest.mark.parametrize("attr, energy", [("K", "strain energy ½ uᵀKu"), ("C", "dissipation u̇ᵀCu̇"),
                                          ("M", "kinetic energy ½ u̇ᵀMu̇")])
def test_an_indefinite_car_matrix_with_a_positive_diagonal_names_its_negative_eigenvalue(attr, energy):
    """[[a, -2a], [-2a, a]] has a positive diagonal and the eigenvalues -a (mode (1, 1)/√2) and 3a."""
    a = {"K": 1e6, "C": 1e4, "M": 1e4}[attr]
    matrices = {attr: a * np.array([[1.0, -2.0], [-2.0, 1.0]])}
    with pytest.raises(ModelError, match=rf"^car 'user': {attr} is not positive semidefinite \(its {energy} must be "
                                         rf">= 0\): eigenvalue {re.escape(f'{-a:.4g}')} \(largest "
                                         rf"{re.escape(f'{3 * a:.4g}')}\), its mode mostly (body_y|wheel1_y)$"):
        user_car(**matrices)


def test_a_body_mass_block_that_is_singular_is_refused():
    """Body bounce and pitch coupled by m_yr = √(m J): the block [[m, √(mJ)], [√(mJ), J]] has the
    eigenvalues 0 (mode (√J, -√m), mostly body_y for J > m) and m + J: the body has a direction
    without inertia."""
    m, J = 1e4, 4e4
    M = np.zeros((3, 3))
    M[:2, :2] = [[m, np.sqrt(m * J)], [np.sqrt(m * J), J]]
    K = 1e6 * np.array([[2.0, 0.0, -1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 1.0]])
    largest = re.escape(f"{m + J:.4g}")
    with pytest.raises(ModelError, match=r"^car 'user': M is singular on the body dofs \(body_y, body_rz\): "
                                         rf"eigenvalue \S+ \(largest {largest}\), its mode mostly body_y; "
                                         r"only a wheel dof may be massless$"):
        user_car(M=M, C=np.zeros((3, 3)), K=K, names=("body_y", "body_rz", "wheel1_y"), wheel=2,
                 P=np.array([-GRAVITY * m, 0.0, 0.0]))


def test_a_massless_wheel_is_legitimate_and_carries_the_body_weight():
    """A wheel dof may be massless (sprung_mass's default m_w = 0): the rail holds it. Its static
    load is the body's weight m g, and the passage runs."""
    car = user_car(M=np.diag([1e4, 0.0]), P=np.array([-GRAVITY * 1e4, 0.0]))
    assert car.static_wheel_loads == pytest.approx([GRAVITY * 1e4], rel=1e-12)
    assert car.fixed_wheel_frequencies() == pytest.approx([np.sqrt(1e6 / 1e4) / (2 * np.pi)], rel=1e-12)
    an = analysis(car)[0]
    an.static()
    an.run(20)
    assert np.all(np.isfinite(an.contact_force)) and np.all(an.contact_force > 0)


CATALOGUE = ([car_from_catalogue(name) for name in car_catalogue()]
             + [four_dof_car(4e4, 2e6, 2e3, 1e6, 2e4, 17.5), sprung_mass(1e4, 1e6), sprung_mass(1e4, 1e6, 1e4, 1800.0),
                moving_mass(1e3)])


@pytest.mark.parametrize("car", CATALOGUE, ids=lambda car: car.name)
@pytest.mark.parametrize("units", COMMON_UNITS, ids="-".join)
def test_every_catalogue_car_builds_in_every_unit_system(car, units):
    """The checks pass the catalogue cars (their K and C are singular: the car moves rigidly) in
    every unit system of the command layer (a rotation's entries then differ from a translation's
    by up to 10⁹); the static wheel loads add up to the car's weight Σ m_y g."""
    converted = Units(*units).car(car)
    weight = GRAVITY * sum(m for m, name in zip(np.diag(car.M), car.dof_names) if name.endswith("_y"))
    assert converted.static_wheel_loads.sum() == pytest.approx(Units(*units).f_force * weight, rel=1e-9)


# -- the train's stability limit -------------------------------------------------------------------
def test_a_car_too_stiff_for_a_conditionally_stable_scheme_is_refused_before_the_run():
    """Newmark(1/2, 1/6) is stable for ωΔt <= √12 = 3.464 (docs/theory/integrators.md). A sprung
    mass (m_s = 1000 kg on k_s, a 500 kg wheel) has ω² = k_s (1/m_s + 1/m_w) with its wheel free,
    a bound of the coupled system's (the constraint restricts it). The bridge's own check passed
    such a car (ωΔt = 3.6 of the body on a held wheel: contact forces of ±6e10 N in 60 steps, no
    error): it is refused before the run, naming ω_max; a softer car (ω_free Δt = 3.3) runs,
    and so does the stiff car with Newmark's average acceleration (unconditionally stable)."""
    dt, m_s, m_w = 1e-4, 1000.0, 500.0
    stiff = m_s * (3.6 / dt) ** 2
    omega = np.sqrt(stiff * (1 / m_s + 1 / m_w))
    an, _, _ = analysis(sprung_mass(m_s, stiff, 0.0, m_w), dt=dt)
    an.integrator = vtsi.integrators.Newmark(0.5, 1.0 / 6.0)
    with pytest.raises(AnalysisError, match=rf"^integrator Newmark: dt = 0.0001 s exceeds its stability limit "
                                            rf"{np.sqrt(12.0) / omega:.6g} s for the train .* omega_max = "
                                            rf"{omega:.6g} rad/s .* mostly car0\.wheel"):
        an.static()
    soft = (3.3 / dt) ** 2 / (1 / m_s + 1 / m_w)
    for car, integrator in ((sprung_mass(m_s, soft, 0.0, m_w), vtsi.integrators.Newmark(0.5, 1.0 / 6.0)),
                            (sprung_mass(m_s, stiff, 0.0, m_w), vtsi.integrators.Newmark(0.5, 0.25))):
        an, _, _ = analysis(car, dt=dt)
        an.integrator = integrator
        an.static()
        an.run(60)
        assert np.abs(an.contact_force).max() < 1.01 * car.static_wheel_loads[0]


@pytest.mark.parametrize("value", ["no", 1, None])
def test_bridge_self_weight_must_be_a_bool(value):
    """``bridge_self_weight='no'`` was taken for True (``bool('no')``) and added the deck's weight
    to results said to be the train's response: only True or False is taken."""
    with pytest.raises(AnalysisError, match=rf"^CoupledAnalysis: bridge_self_weight must be True or False, got "
                                            rf"{re.escape(repr(value))}"):
        analysis(bridge_self_weight=value)
