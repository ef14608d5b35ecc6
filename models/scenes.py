"""The benchmark scenes of docs/scenes.md as data and builders, shared by tests, benchmarks and
examples. Every number here is either from a published source or an independent computation
(named beside it and in docs/scenes.md) or our own choice, stated as such.
"""

import math

from vtsi.errors import ModelError, as_number

from .bridges import continuous_beam, simply_supported_beam
from .cars import four_dof_car, sprung_mass
from .trains import Train

# S1: constant force over a simply supported beam (Frýba 1972, ch. 1). Our own numbers: the scene
# of the speed anchors quoted in benchmarks/README.md.
S1 = dict(L=25.0, E=2.943e10, I=3.81, mu=36000.0, P=1.0e5, V=100.0 / 3.6, dt=1.0e-3)

# S2: Yang & Yau (1997) sprung mass, after Biggs (1964); the maxima are a modal solution computed
# for this project (20 modes, docs/scenes.md).
S2 = dict(L=25.0, E=2.87e9, I=2.9, mu=2303.0, m_s=5750.0, k_s=1595.0e3, V=100.0 / 3.6,
          max_midspan_deflection=2.4073e-3, time_of_max=0.3711, max_sprung_acceleration=0.148)

# S3: the paper's 4-dof car over a simply supported beam. Our own data (documented in
# docs/scenes.md): a 30 m prestressed-concrete span and a car with the mass, pitch inertia and
# suspension of an ICE3 coach lumped to two wheel groups (bogie + wheelsets) at ± l_c / 2.
S3 = dict(L=30.0, E=3.5e10, I=7.0, mu=30000.0, n_elements=20,
          m_c=47800.0, J_c=1.957888e6, m_w=3500.0 + 2 * 1800.0, k_s=2 * 7.0e5, c_s=2 * 4.0e4,
          l_c=17.375, V=300.0 / 3.6)


def s2_model(model, n_elements=20):
    """Beam and train of S2 (vehicle at the left support at t = 0). Returns (bridge, train)."""
    p = S2
    bridge = simply_supported_beam(model, p["L"], n_elements, p["E"], p["I"], p["mu"])
    train = Train([sprung_mass(p["m_s"], p["k_s"])], [0.0], p["V"], name="S2 sprung mass")
    return bridge, train


def s3_model(model, n_elements=None, speed=None, approach=2.0):
    """Beam and 4-dof car of S3. The car's leading wheel starts ``approach`` metres before the
    span, so both wheels start on rigid ground in equilibrium (2 m: beyond the reach 8 V Δt of
    the B-spline constraint for Δt ≤ 2 ms at 400 km/h, so the dead-load state is exact for it
    too). Returns (bridge, train, x_head0)."""
    p = S3
    approach = as_number(approach, "s3_model", "approach [m]")
    if not math.isfinite(approach):
        raise ModelError(f"s3_model: approach must be finite [m], got {approach}")
    bridge = simply_supported_beam(model, p["L"], n_elements or p["n_elements"], p["E"], p["I"], p["mu"])
    car = four_dof_car(p["m_c"], p["J_c"], p["m_w"], p["k_s"], p["c_s"], p["l_c"])
    train = Train([car], [0.0], p["V"] if speed is None else speed, name="S3 four-dof car")
    return bridge, train, -approach


def s5_viaduct(model, elements_per_span=20):
    """S5 bridge: a 3 × 30 m continuous viaduct (our own section: E = 3.5e10 Pa, I = 7 m⁴,
    μ = 30 t/m, as S3's span)."""
    p = S3
    return continuous_beam(model, [30.0, 30.0, 30.0], elements_per_span, p["E"], p["I"], p["mu"])


def rigid_ground(model):
    """A model's only track for wheels that run on rigid ground (the contact-loss scenes of
    docs/theory/contact.md §8 and the rail profiles' kinks): a short stiff beam far ahead, nodes 1
    and 2 at x = 1000 and 1001 m, element 1 (a wheel before it has a zero row, and its constraint
    is u_w = r(x)). Returns the track's elements, [1]."""
    model.node(1, 1000.0, 0.0)
    model.node(2, 1001.0, 0.0)
    model.fix(1, 1, 1, 0)
    model.fix(2, 0, 1, 0)
    model.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=2e11, I=1.0, rho=100.0, cmass=1)
    return [1]
