"""Support reactions in a coupled analysis (vtsi.recorders.node, vtsi.coupled.CoupledLoads): the
loads the analysis applies itself — the train's moving forces and contact forces, shared between
the dofs of the element under each wheel as the constraint's rows share them, and the bridge's own
weight — are taken off at the reaction dofs without being asked for.

References: the statics of a simply supported beam (a downward force P at x gives the supports
P (L − x)/L and P x/L; a nodal moment m at any x gives them m/L and −m/L), and the equation of
motion the analysis solves (at every free dof K u + C v + M a − P = 0 at the step's end for the
Newmark family and Bathe). Before the fix a 98.1 kN force 0.1 m from the left support of this
span read 2258 and 490 N for 97 609.5 and 490.5 N: the share of the wheel load on the support's
own fixed dof was left out, and ICE3 crawling over it lost up to 301 kN of the sum.
"""
import h5py
import numpy as np
import pytest
from scipy.integrate import quad

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.integrators import Newmark
from vtsi.modal_bridge import ModalBridge
from vtsi.models import Train, ice3, moving_mass, sprung_mass
from vtsi.models.bridges import continuous_beam, simply_supported_beam
from vtsi.recorders import ContactRecorder, NodeRecorder, ReactionRecorder
from vtsi.recorders.moment import BendingMomentRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain
from vtsi.vehicle import GRAVITY, moving_force
import vtsi.opensees as ops

L, N_EL, E, I, MU = 20.0, 20, 3.5e10, 3.0, 2.0e4     # 1 m elements, f1 = 9.0 Hz
P = 98100.0                                          # [N] a 10 t axle


def span(**kwargs):
    model = vtsi.Model()
    deck = simply_supported_beam(model, L, N_EL, E, I, MU, **kwargs)
    return model, deck, Track(model, deck.elements)


def cars(kind):
    """A car of static load P: a force, a rigid mass, a mass on a spring over a wheel."""
    return {"force": moving_force(P), "mass": moving_mass(P / GRAVITY),
            "sprung": sprung_mass(0.8 * P / GRAVITY, 2e6, m_w=0.2 * P / GRAVITY)}[kind]


def kernel_integral(x, knot, g):
    """∫₀ᴸ g(s) B₃((x − s)/κ)/κ ds: what reaches the span of a load spread by the 'bspline' rows
    (the cubic B-spline of knot spacing κ, clipped where the track ends); g(x) for κ = 0."""
    if knot == 0.0:
        return g(x) if 0.0 <= x <= L else 0.0
    def b3(s):
        a = abs(s)
        return 2 / 3 - a * a + 0.5 * a ** 3 if a < 1 else ((2 - a) ** 3 / 6 if a < 2 else 0.0)
    lo, hi = max(0.0, x - 2 * knot), min(L, x + 2 * knot)
    if hi <= lo:
        return 0.0
    breaks = [p for p in (x - knot, x, x + knot) if lo < p < hi]
    return quad(lambda s: g(s) * b3((x - s) / knot) / knot, lo, hi, points=breaks or None, epsabs=0, epsrel=1e-13)[0]


@pytest.mark.parametrize("contact", ["bilateral", "lcp"])
@pytest.mark.parametrize("kind", ["force", "mass", "sprung"])
def test_a_car_at_rest_gives_the_reactions_of_statics_anywhere_on_the_span(kind, contact):
    """A car of load P standing still (speed 0) at x: P (L − x)/L and P x/L on the supports
    (`ReactionRecorder` and `NodeRecorder(..., 'reaction')` alike), on a support, inside the end
    elements, on a node, mid-element, at mid-span; a wheel's share on the fixed dofs was missing."""
    for x in (0.0, 0.1, 0.5, 1.0, 5.0, 10.0, 13.7, 19.5, 19.9, 20.0):
        model, deck, track = span()
        con = MovingLoadConstraint(track, TrainSubdomain(Train([cars(kind)], [0.0], 0.0), x_head0=x))
        reaction = ReactionRecorder(deck.supports, [2])
        node = NodeRecorder(deck.supports, [1, 2, 3], "reaction")
        analysis = CoupledAnalysis(model, con, None, 1e-3, contact=contact, recorders=[reaction, node])
        analysis.static()
        analysis.run(3)
        expected = [P * (L - x) / L, P * x / L]
        np.testing.assert_allclose(reaction.values, np.tile(expected, (3, 1)), rtol=0, atol=1e-9 * P, err_msg=x)
        np.testing.assert_allclose(node.values[:, [1, 4]], reaction.values, rtol=0, atol=1e-9 * P)
        np.testing.assert_allclose(node.values[:, [0, 2, 3, 5]], 0.0, atol=1e-9 * P)    # no ux load; pins


def test_the_bridge_s_own_weight_is_in_the_reactions():
    """With ``bridge_self_weight`` the deck's weight μ g L (consistent mass: 1ᵀ M 1 = μ L) splits
    in halves, on top of the car's share; the support's own share of −g M 1_y was missing."""
    model, deck, track = span()
    x = 0.3
    con = MovingLoadConstraint(track, TrainSubdomain(Train([cars("sprung")], [0.0], 0.0), x_head0=x))
    reaction = ReactionRecorder(deck.supports, [2])
    analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, bridge_self_weight=True, recorders=[reaction])
    analysis.static()
    analysis.run(2)
    half = MU * GRAVITY * L / 2
    np.testing.assert_allclose(reaction.values[-1], [half + P * (L - x) / L, half + P * x / L], rtol=1e-12)


def deck_inertia(asm, deck, accel):
    """The reactions ``(n, 2)`` [N] of the deck's inertia forces −M a at its free dofs, by statics
    (``accel`` of every node's ux, uy, rz ``(n, 3 n_nodes)``): a force f at x_k gives the supports
    −f (L − x_k)/L and −f x_k/L, a moment m at any node m/L and −m/L."""
    a = np.zeros((len(accel), asm.n_full))
    for j, tag in enumerate(deck.nodes):
        for d in range(3):
            a[:, asm.full_dof(tag, d + 1)] = accel[:, 3 * j + d]
    force = -(asm.M_full @ a.T).T
    out = np.zeros((len(accel), 2))
    for tag in deck.nodes:
        x = float(asm.coords[asm.node_index[tag], 0])
        uy, rz = asm.full_dof(tag, 2), asm.full_dof(tag, 3)
        if asm.free_of_full[uy] >= 0:
            out[:, 0] -= force[:, uy] * (L - x) / L
            out[:, 1] -= force[:, uy] * x / L
        out[:, 0] += force[:, rz] / L
        out[:, 1] -= force[:, rz] / L
    return out


@pytest.mark.parametrize("interpolation", ["hermite", "bspline"])
@pytest.mark.parametrize("kind", ["force", "mass"])
def test_a_crawl_over_the_span_reads_the_statics_of_the_wheel_load_and_of_the_deck_s_inertia(kind, interpolation):
    """One car crawling at 2 m/s over the span (Δt = 50 ms: 'bspline' rows spread a wheel over
    ±2κ = ±0.4 m): at every step each reaction is the statics of the wheel load where it stands
    (its contact force λ, spread by the B-spline clipped at the track's ends; a moving force P on
    its Hermite row) plus the statics of the deck's inertia forces −M a (nodal forces and moments,
    from the recorded accelerations), to 1e-9 P. The inertia part is the crawl's dynamics: below
    1 % of P (measured 0.07–0.7 %; Newmark's undamped ringing from the start, Δt being 0.45 of
    the first period)."""
    model, deck, track = span()
    V, dt = 2.0, 0.05
    con = MovingLoadConstraint(track, TrainSubdomain(Train([cars(kind)], [0.0], V), x_head0=-1.0),
                               interpolation=interpolation)
    reaction = ReactionRecorder(deck.supports, [2])
    accel = NodeRecorder(deck.nodes, [1, 2, 3], "accel")
    recorders = [reaction, accel] + ([ContactRecorder(con)] if kind == "mass" else [])
    analysis = CoupledAnalysis(model, con, "Newmark", dt, recorders=recorders)
    analysis.static()
    analysis.run(int((L + 2.0) / V / dt))
    t = reaction.time
    x = -1.0 + V * t
    load = recorders[2].values[:, 0] if kind == "mass" else np.full(len(t), P)
    knot = con.knot(dt) if kind == "mass" else 0.0
    wheel = np.array([[f * kernel_integral(xi, knot, lambda s: (L - s) / L),
                       f * kernel_integral(xi, knot, lambda s: s / L)] for f, xi in zip(load, x)])
    inertia = deck_inertia(model.build(), deck, accel.values)
    np.testing.assert_allclose(reaction.values, wheel + inertia, rtol=0, atol=1e-9 * P)
    assert 1e-4 * P < np.abs(inertia).max() < 1e-2 * P
    inside_end_elements = ((x > 0) & (x < 1)) | ((x > L - 1) & (x < L))
    assert inside_end_elements.sum() >= 2 * int(1.0 / (V * dt)) - 2


@pytest.mark.parametrize("interpolation", ["hermite", "bspline"])
def test_ice3_crawling_the_sum_of_the_reactions_is_the_load_on_the_span(interpolation):
    """ICE3 × 2 (10-dof cars, 8 axles of 152.1 kN) at 5 km/h over the span, Δt = 10 ms: the sum of
    the reactions is the wheels' contact forces on the span (λ times the share of its spread on
    the span) plus the deck's inertia Σ (M a)_uy at its free dofs, to 1e-9 of the largest load;
    against the static axle loads on the span it is off by the crawl's dynamics only, that
    inertia and Σ (λ − Q) on the span, together below 0.5 % of the load (measured 1.6 kN
    'hermite', 1.3 kN 'bspline', of 608 kN). It read up to 301 kN short with an axle in an end
    element."""
    model, deck, track = span()
    V, dt = 5 / 3.6, 0.01
    train = ice3(2, speed=V)
    con = MovingLoadConstraint(track, TrainSubdomain(train, x_head0=-2.0), interpolation=interpolation)
    reaction = ReactionRecorder(deck.supports, [2])
    force = ContactRecorder(con)
    accel = NodeRecorder(deck.nodes, [1, 2, 3], "accel")
    analysis = CoupledAnalysis(model, con, "Newmark", dt, recorders=[reaction, force, accel])
    analysis.static()
    analysis.run(int((L + train.length + 4.0) / V / dt))
    asm = model.build()
    t = reaction.time
    x = con.positions(t)
    on = np.array([[kernel_integral(xi, con.knot(dt), lambda s: 1.0) for xi in row] for row in x])
    a = np.zeros((len(t), asm.n_full))
    for j, tag in enumerate(deck.nodes):
        for d in range(3):
            a[:, asm.full_dof(tag, d + 1)] = accel.values[:, 3 * j + d]
    free_uy = [asm.full_dof(tag, 2) for tag in deck.nodes if asm.free_of_full[asm.full_dof(tag, 2)] >= 0]
    inertia = (asm.M_full @ a.T).T[:, free_uy].sum(axis=1)
    total = reaction.values.sum(axis=1)
    static = (train.static_wheel_loads * on).sum(axis=1)
    np.testing.assert_allclose(total, (force.values * on).sum(axis=1) + inertia, rtol=0, atol=1e-9 * static.max())
    dynamics = np.abs(((force.values - train.static_wheel_loads) * on).sum(axis=1)) + np.abs(inertia)
    assert np.all(np.abs(total - static) <= dynamics + 1e-9 * static.max())
    assert dynamics.max() < 5e-3 * static.max()
    in_end_element = np.any(((x > 0) & (x < 1)) | ((x > L - 1) & (x < L)), axis=1)
    assert in_end_element.sum() > 1000


@pytest.mark.parametrize("contact, integrator", [("bilateral", "Newmark"), ("bilateral", "Bathe"),
                                                 ("lcp", "Bathe"), ("lcp", Newmark(0.6, 0.3025))])
@pytest.mark.parametrize("interpolation", ["hermite", "bspline"])
def test_at_every_free_dof_the_reaction_with_inertia_is_the_zero_residual(interpolation, contact, integrator):
    """``reactionIncInertia`` at a free dof is the residual K u + C v + M a − P − (the wheels'
    shares) of the equation the step solved at its end (the Newmark family, Bathe): zero to
    round-off at every uy and rz of the deck through a passage at 40 m/s of a sprung car, a
    moving force and a sprung car entering and leaving the span (measured 1e-6 N of 5.8e5), so the
    wheel loads are taken off at every row as the analysis applied them (λ_{n+1}, not Bathe's
    recorded mean: 99 N)."""
    model, deck, track = span()
    train = Train([sprung_mass(2e4, 2e6, m_w=2e3), moving_force(1e5), sprung_mass(3e4, 3e6, m_w=2e3)],
                  [0.0, 2.3, 4.1], 40.0)
    con = MovingLoadConstraint(track, TrainSubdomain(train, -0.5), interpolation=interpolation)
    free = NodeRecorder([n for n in deck.nodes if n not in deck.supports], [2, 3], "reactionIncInertia")
    ends = ReactionRecorder(deck.supports, [2], include_inertia=True)
    analysis = CoupledAnalysis(model, con, integrator, 1e-3, contact=contact, recorders=[free, ends])
    analysis.static()
    analysis.run(700)
    scale = np.abs(ends.values).max()
    assert scale > 4e5
    assert np.abs(free.values).max() < 1e-10 * scale


def test_a_modal_bridge_s_reactions_are_refused():
    """With a modal bridge the recorded u = Φ q of a few modes gives the supports K Φ q without
    the truncated modes' share (a force at mid-span, 3 modes: 42.1 kN for 49.05 kN): refused."""
    model, deck, track = span()
    con = MovingLoadConstraint(track, TrainSubdomain(Train([moving_force(P)], [0.0], 0.0), x_head0=L / 2))
    for recorder, who in ((ReactionRecorder(deck.supports, [2]), "reaction recorder: reaction"),
                          (NodeRecorder(deck.supports, [2], "reactionIncInertia"),
                           "node recorder: reactionIncInertia")):
        analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[recorder], bridge=ModalBridge(model, track))
        analysis.static()
        with pytest.raises(vtsi.ModelError, match=f"^{who} in a coupled analysis with a modal bridge is not recorded"):
            analysis.run(1)


def test_the_command_layer_s_reaction_recorder_takes_the_wheel_loads(tmp_path, span_20m_commands):
    """``recorder Node ... reaction`` of a script with a moving-load constraint, run by
    ``analyze(1, dt)`` calls (its record kept open), and to an HDF5 file, whose metadata the
    analysis's loads object stays out of: a force 0.1 m from the right support and a mass 0.1 m
    from the left one load each support with P (statics)."""
    session = ops.Session()
    span_20m_commands(session)          # conftest: this module's span, its track and the two cars
    session.train(1, 0.0, "-cars", 1, 0.0, 2, 19.8)
    session.movingLoadConstraint(1, 1, 1, 19.9)
    session.integrator("Newmark", 0.5, 0.25)
    session.analysis("Transient")
    path = tmp_path / "reactions.h5"
    memory = session.recorder("Node", "-node", 1, N_EL + 1, "-dof", 2, "reaction")
    session.recorder("Node", "-h5", str(path), "-node", 1, N_EL + 1, "-dof", 2, "reaction")
    for _ in range(3):
        session.analyze(1, 1e-3)
    np.testing.assert_allclose(session.recorders[memory].values, np.full((3, 2), P), rtol=1e-12)
    session.wipe()
    with h5py.File(path, "r") as f:
        np.testing.assert_allclose(f["values"][:], np.full((3, 2), P), rtol=1e-12)
        assert not any("coupled_loads" in key for key in f.attrs)


def test_bending_moments_take_the_analysis_s_wheel_loads_without_being_told():
    """A ``BendingMomentRecorder`` without ``constraint=`` in a coupled analysis: the moments of a
    force P at rest inside an element, P x (L − a)/L at a ≥ x and P a (L − x)/L at a ≤ x (the end
    moments alone miss half its fixed-end moment at the node next to it), as with ``constraint=``
    given, to the last bit; another
    constraint given is refused, a track partly on the wheels' refused, a deck the wheels do not
    run on (the next span, on its own nodes) takes no wheel load."""
    model = vtsi.Model()
    deck = simply_supported_beam(model, L, N_EL, E, I, MU)
    other = continuous_beam(model, [L], N_EL, E, I, MU, x0=L, first_node=101, first_element=101)
    track = Track(model, deck.elements)
    x = 7.3

    def constraint():
        return MovingLoadConstraint(track, TrainSubdomain(Train([moving_force(P)], [0.0], 0.0), x_head0=x))

    con = constraint()
    mid = deck.midspan_nodes[0]
    auto = BendingMomentRecorder(track, [mid, deck.nodes[7]])
    told = BendingMomentRecorder(track, [mid, deck.nodes[7]], constraint=con)
    apart = BendingMomentRecorder(Track(model, other.elements), [other.midspan_nodes[0]])
    analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[auto, told, apart])
    analysis.static()
    analysis.run(2)
    np.testing.assert_allclose(auto.values[-1], [P * x * (L / 2) / L, P * 7.0 * (L - x) / L], rtol=1e-9)
    np.testing.assert_array_equal(auto.values, told.values)
    assert np.abs(apart.values).max() < 1e-9 * P
    for recorder, message in ((BendingMomentRecorder(track, [mid], constraint=constraint()),
                               "its constraint= is another"),
                              (BendingMomentRecorder(Track(model, deck.elements[10:] + other.elements), [mid]),
                               r"its track runs partly on the wheels' track \(10 of its 30 elements; element 101 is")):
        analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[recorder])
        analysis.static()
        with pytest.raises(vtsi.ModelError, match=f"^bending moment recorder: {message}"):
            analysis.run(1)
