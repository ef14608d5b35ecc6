"""Responses that contain the loads a coupled analysis applies (vtsi.coupled.CoupledLoads): the
``reactions``/``nodeReaction`` and ``eleForce``/``eleResponse`` commands after ``deadLoad`` and
``analyze``, the element recorders' end forces of a track element with a wheel inside it; the
reaction recorders refused with a modal bridge in a transient analysis as in a coupled one; the
contact recorder's ``gap_tol`` checked as the analysis's.

References: the statics of a simply supported beam of span L under a downward force P at x: the
supports carry R_A = P (L − x)/L and P x/L; the sagging moment is M(s) = R_A s − P ⟨s − x⟩ and
the shear just left of s is V(s⁻) = R_A − P [x < s]. An element from x₁ to x₂ then has
OpenSees's end forces (the forces its nodes exert on it, element axes = global axes for a beam
along +x): V₁ = V(x₁⁻) (a force on a node is inside the element that starts there, where the
track's Hermite rows put it), M₁ = −M(x₁), V₂ = −V(x₂⁻), M₂ = M(x₂); OpenSees's ``basicForce``
of ``elasticBeamColumn`` is (N, M₁, M₂). Before the fix the commands read 2746.8 N at each
support for 98 100 N (a force 0.1 m from one support and a 10 t mass 0.1 m from the other), and
the end forces of an element with a wheel inside it missed the wheel's fixed-end forces
(P a b²/ℓ² and P a² b/ℓ² of its end moments, a and b the wheel's distances to its ends).
"""
import numpy as np
import pytest

import vtsi
import vtsi.opensees as ops
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.elements.base import ELEMENT_TYPES, register
from vtsi.elements.beam_column import ElasticBeamColumn2d
from vtsi.errors import CommandError
from vtsi.modal_bridge import ModalBridge
from vtsi.models import Train, moving_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders import ContactRecorder, ElementRecorder, NodeRecorder, ReactionRecorder
from vtsi.recorders.moment import BendingMomentRecorder
from vtsi.tcl import Interpreter
from vtsi.track import Track
from vtsi.train import TrainSubdomain
from vtsi.vehicle import GRAVITY, moving_force

L, N_EL, E, I, MU = 20.0, 20, 3.5e10, 3.0, 2.0e4     # 1 m elements: element e from x = e − 1 to e
P = 98100.0                                          # [N] a 10 t axle
PLACES = {"near the supports": (19.9, 0.1), "inside the span": (7.3, 13.6)}   # x of the force, of the mass


def reactions_of(loads):
    """The supports' reactions [R_A, R_B] of downward forces ``[(P, x)]`` (statics)."""
    return [sum(p * (L - x) / L for p, x in loads), sum(p * x / L for p, x in loads)]


def moment_at(loads, s):
    """The sagging moment M(s) [N·m] of downward forces ``[(P, x)]`` (statics)."""
    return reactions_of(loads)[0] * s - sum(p * max(s - x, 0.0) for p, x in loads)


def shear_at(loads, s):
    """The shear V(s⁻) [N] just left of s of downward forces ``[(P, x)]``."""
    return reactions_of(loads)[0] - sum(p for p, x in loads if x < s)


def local_forces(loads, element):
    """OpenSees's ``localForce`` [N₁, V₁, M₁, N₂, V₂, M₂] of ``element`` (1-based) by statics."""
    x1, x2 = element - 1.0, float(element)
    return [0.0, shear_at(loads, x1), -moment_at(loads, x1), 0.0, -shear_at(loads, x2), moment_at(loads, x2)]


def script_span(span_20m_commands, session, x_force, x_mass, self_weight=False):
    """The 20 m span of 20 elements by commands (conftest's ``span_20m_commands``: its constants
    are this module's), a train at rest: the moving force P at ``x_force`` and the 10 t mass at
    ``x_mass``, then ``deadLoad``."""
    span_20m_commands(session)
    head, tail = sorted([(x_force, 1), (x_mass, 2)], reverse=True)       # offsets back from the head
    session.train(1, 0.0, "-cars", head[1], 0.0, tail[1], head[0] - tail[0])
    session.movingLoadConstraint(1, 1, 1, head[0])
    session.integrator("Newmark", 0.5, 0.25)
    session.analysis("Transient")
    session.deadLoad(*(["-selfWeight"] if self_weight else []))


@pytest.mark.parametrize("place", PLACES)
def test_the_reactions_command_takes_the_train_s_loads(place, span_20m_commands):
    """``reactions`` then ``nodeReaction`` after ``deadLoad`` and after ``analyze`` (static and
    ``-dynamic``: the train at rest): the statics of the force and the mass, near the supports
    (each wheel in an end element, its share on the support's own dof) and inside the span."""
    x_force, x_mass = PLACES[place]
    expected = reactions_of([(P, x_force), (P, x_mass)])
    session = ops.Session()
    script_span(span_20m_commands, session, x_force, x_mass)
    for step in ("deadLoad", "analyze"):
        if step == "analyze":
            session.analyze(3, 1e-3)
        for flag in ((), ("-dynamic",)):
            session.reactions(*flag)
            got = [session.nodeReaction(1, 2), session.nodeReaction(N_EL + 1, 2)]
            np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * P, err_msg=f"{step} {flag}")
            assert abs(session.nodeReaction(1, 1)) < 1e-9 * P           # no horizontal load


def test_the_reactions_command_takes_the_bridge_s_own_weight(span_20m_commands):
    """``deadLoad -selfWeight``: each support also carries half the deck's weight μ g L (the
    consistent mass's 1ᵀ M 1 = μ L) after ``deadLoad`` and after ``analyze``."""
    session = ops.Session()
    script_span(span_20m_commands, session, *PLACES["inside the span"], self_weight=True)
    half = MU * GRAVITY * L / 2
    expected = np.array(reactions_of([(P, 7.3), (P, 13.6)])) + half
    for step in ("deadLoad", "analyze"):
        if step == "analyze":
            session.analyze(2, 1e-3)
        session.reactions()
        got = [session.nodeReaction(1, 2), session.nodeReaction(N_EL + 1, 2)]
        np.testing.assert_allclose(got, expected, rtol=1e-12, err_msg=step)


@pytest.mark.parametrize("place", PLACES)
def test_element_forces_of_the_commands_take_the_wheel_loads_inside(place, span_20m_commands):
    """``eleForce``, ``eleResponse`` ``localForce`` and ``basicForce`` after ``deadLoad`` and
    ``analyze``: the loaded elements (a wheel inside each) and their neighbours read the statics,
    whose end forces at a shared node balance."""
    x_force, x_mass = PLACES[place]
    loads = [(P, x_force), (P, x_mass)]
    hosts = [int(np.floor(x)) + 1 for x in (x_force, x_mass)]
    elements = sorted({e for h in hosts for e in (h - 1, h, h + 1) if 1 <= e <= N_EL})
    session = ops.Session()
    script_span(span_20m_commands, session, x_force, x_mass)
    for step in ("deadLoad", "analyze"):
        if step == "analyze":
            session.analyze(3, 1e-3)
        for e in elements:
            expected = local_forces(loads, e)
            atol = 1e-9 * P * L
            np.testing.assert_allclose(session.eleResponse(e, "localForce"), expected, rtol=0, atol=atol,
                                       err_msg=f"{step} element {e}")
            np.testing.assert_allclose(session.eleForce(e), expected, rtol=0, atol=atol)     # global = local here
            np.testing.assert_allclose(session.eleResponse(e, "basicForce"), [0.0, expected[2], expected[5]],
                                       rtol=0, atol=atol)
    assert all(abs(local_forces(loads, h)[2] + local_forces(loads, h - 1)[5]) < 1e-9 * P for h in hosts if h > 1)


@pytest.mark.parametrize("response", ["localForce", "force"])
def test_the_element_recorder_command_takes_the_wheel_loads_inside(tmp_path, response, span_20m_commands):
    """``recorder Element`` (a command recorder of ElementRecorders of its own) over the loaded
    elements and their neighbours, a memory record and a file: each step's row reads the statics
    of the train at rest, as ``eleResponse`` does (global = local axes here)."""
    loads = [(P, 7.3), (P, 13.6)]
    elements = [7, 8, 9, 13, 14, 15]
    session = ops.Session()
    script_span(span_20m_commands, session, 7.3, 13.6)
    path = tmp_path / "forces.out"
    session.recorder("Element", "-file", str(path), "-precision", 16, "-ele", *elements, response)
    session.analyze(3, 1e-3)
    session.wipe()                                         # closes the file
    rows = np.loadtxt(path, ndmin=2)
    expected = np.concatenate([local_forces(loads, e) for e in elements])
    assert rows.shape == (3, expected.size)
    np.testing.assert_allclose(rows, np.tile(expected, (3, 1)), rtol=0, atol=1e-9 * P * L)


def test_a_changed_domain_time_is_refused_for_the_train_s_loads(span_20m_commands):
    """After ``setTime`` the train's loads are not known at the domain's time: ``reactions`` and
    ``eleForce`` say so (and ``setTime`` back gives the statics again)."""
    session = ops.Session()
    script_span(span_20m_commands, session, *PLACES["inside the span"])
    session.analyze(2, 1e-3)
    session.setTime(0.5)
    for query in (session.reactions, lambda: session.eleForce(8)):
        with pytest.raises(CommandError, match=r"the domain's time is t = 0.5 s, and the train's loads are known at "
                                               r"the coupled analysis's last step, t = 0.002 s .*setTime\(0.002\)"):
            query()
    session.setTime(0.002)
    session.reactions()
    np.testing.assert_allclose(session.nodeReaction(1, 2), reactions_of([(P, 7.3), (P, 13.6)])[0], rtol=1e-12)


def test_tcl_queries_take_the_train_s_loads():
    """The same through a Tcl script: ``reactions``, ``nodeReaction``, ``eleResponse localForce``."""
    pytest.importorskip("tkinter")
    tcl = Interpreter()
    tcl.eval(f"""
        model basic -ndm 2 -ndf 3
        for {{set i 0}} {{$i <= {N_EL}}} {{incr i}} {{ node [expr $i + 1] [expr {L} * $i / {N_EL}.0] 0.0 }}
        fix 1 1 1 0; fix {N_EL + 1} 0 1 0
        geomTransf Linear 1
        for {{set e 1}} {{$e <= {N_EL}}} {{incr e}} {{
            element elasticBeamColumn $e $e [expr $e + 1] 1.0 {E} {I} 1 -mass {MU} -cMass
        }}
        track 1 -eleRange 1 {N_EL}
        car 1 movingForce {P}
        car 2 movingMass {P / GRAVITY}
        train 1 0.0 -cars 1 0.0 2 19.8
        movingLoadConstraint 1 1 1 19.9
        integrator Newmark 0.5 0.25
        analysis Transient
        analyze 2 0.001
        reactions
    """)
    got = [float(tcl.eval(f"nodeReaction {n} 2")) for n in (1, N_EL + 1)]
    np.testing.assert_allclose(got, [P, P], rtol=1e-12)
    local = [float(x) for x in tcl.tcl.splitlist(tcl.eval(f"eleResponse {N_EL} localForce"))]
    np.testing.assert_allclose(local, local_forces([(P, 19.9), (P, 0.1)], N_EL), rtol=0, atol=1e-9 * P * L)


def span():
    model = vtsi.Model()
    deck = simply_supported_beam(model, L, N_EL, E, I, MU)
    return model, deck, Track(model, deck.elements)


@pytest.mark.parametrize("x", [7.3, 0.4, 12.0])
def test_element_recorders_read_a_force_at_rest_inside_an_element_as_statics(x):
    """A moving force at rest at x in a `CoupledAnalysis`: ``localForce``, ``force`` and
    ``globalForce`` of the host element (x inside it, or on a node: 12.0) and of its neighbours
    are the statics; the bending moments at the host's nodes are its localForce moments
    (−M₁, M₂), as `BendingMomentRecorder` computes them its own way."""
    model, deck, track = span()
    host = min(int(np.floor(x)) + 1, N_EL)
    elements = [e for e in (host - 1, host, host + 1) if 1 <= e <= N_EL]
    con = MovingLoadConstraint(track, TrainSubdomain(Train([moving_force(P)], [0.0], 0.0), x_head0=x))
    local = ElementRecorder(elements, "localForce")
    force = ElementRecorder(elements, "force")
    global_force = ElementRecorder(elements, "globalForce")
    moment = BendingMomentRecorder(track, [host, host + 1])          # node n at x = n − 1
    analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[local, force, global_force, moment])
    analysis.static()
    analysis.run(2)
    expected = np.concatenate([local_forces([(P, x)], e) for e in elements])
    for recorder in (local, force, global_force):
        np.testing.assert_allclose(recorder.values, np.tile(expected, (2, 1)), rtol=0, atol=1e-9 * P * L)
    k = elements.index(host)
    np.testing.assert_allclose(moment.values[-1], [-local.values[-1, 6 * k + 2], local.values[-1, 6 * k + 5]],
                               rtol=1e-12, atol=1e-9 * P)
    np.testing.assert_allclose(moment.values[-1], [moment_at([(P, x)], host - 1.0), moment_at([(P, x)], host)],
                               rtol=1e-9, atol=1e-9 * P)


@pytest.mark.parametrize("integrator", ["Newmark", "Bathe"])
@pytest.mark.parametrize("interpolation", ["hermite", "bspline"])
def test_a_crawling_mass_s_element_forces_balance_the_reactions_and_make_the_moments(interpolation, integrator):
    """A mass crawling at 2 m/s over the span (Newmark or Bathe, whose recorded contact force is
    the step's mean while every response here takes λ_{n+1}, the force the displacements
    balance; Δt = 50 ms: 'bspline' rows spread its
    contact force over ±0.4 m, across element ends): at every step the end forces of the end
    elements at the supports are the support reactions (no mass at a fixed dof: R = K u − P there
    is the element's K_e u_e − f_eq, the wheel's share in it), and at every interior node the
    bending moment is the mean of the two elements' end moments (−M₁ of the one that starts
    there, M₂ of the one that ends there), the moment recorder's own fixed-end shares against
    the element recorder's."""
    model, deck, track = span()
    V, dt = 2.0, 0.05
    con = MovingLoadConstraint(track, TrainSubdomain(Train([moving_mass(P / GRAVITY)], [0.0], V), x_head0=-1.0),
                               interpolation=interpolation)
    local = ElementRecorder(deck.elements, "localForce")
    force = ElementRecorder([deck.elements[0], deck.elements[-1]], "force")
    reaction = ReactionRecorder(deck.supports, [2])
    moment = BendingMomentRecorder(track, deck.nodes[1:-1])
    analysis = CoupledAnalysis(model, con, integrator, dt, recorders=[local, force, reaction, moment])
    analysis.static()
    analysis.run(int((L + 2.0) / V / dt))
    np.testing.assert_allclose(force.values[:, [1, 10]], reaction.values, rtol=0, atol=1e-9 * P)
    ends = local.values.reshape(len(local.time), N_EL, 6)
    mean = 0.5 * (ends[:, :-1, 5] - ends[:, 1:, 2])
    np.testing.assert_allclose(moment.values, mean, rtol=0, atol=1e-9 * P * L)
    assert np.abs(reaction.values).max() > 0.9 * P                    # the mass was on the span


class EndRotationBeam(ElasticBeamColumn2d):
    """``elasticBeamColumn`` with one more response that its ``response`` computes itself: the
    end rotations [θ₁, θ₂] [rad] (not made of the end forces, and not declared unloaded)."""

    name = "endRotationBeamTest"
    response_kinds = ElasticBeamColumn2d.response_kinds + ("endRotations",)

    def response(self, kind, coords, params, u_e, v_e):
        if kind == "endRotations":
            return u_e[:, [2, 5]]
        return super().response(kind, coords, params, u_e, v_e)


def test_a_track_element_s_response_not_made_of_end_forces_is_refused():
    """A response of a track element that its type computes itself, not from the end forces
    (which take the wheel loads), is refused when the coupled analysis starts the recorder, naming
    the element; one the type leaves unloaded (``basicDeformation``) is recorded, as is the same
    response of an element off the track (no wheel loads it)."""
    register(EndRotationBeam)
    try:
        model = vtsi.Model()
        for i in range(N_EL + 2):
            model.node(i + 1, L * i / N_EL, 0.0)
        model.fix(1, 1, 1, 0)
        model.fix(N_EL + 1, 0, 1, 0)
        model.fix(N_EL + 2, 0, 1, 0)
        for e in range(N_EL + 1):
            model.element(EndRotationBeam.name, e + 1, (e + 1, e + 2), A=1.0, E=E, I=I, rho=MU, cmass=1.0)
        track = Track(model, list(range(1, N_EL + 1)))
        con = MovingLoadConstraint(track, TrainSubdomain(Train([moving_force(P)], [0.0], 0.0), x_head0=7.3))
        kept = [ElementRecorder([8], "basicDeformation"), ElementRecorder([N_EL + 1], "endRotations")]
        analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=kept)
        analysis.static()
        analysis.run(1)
        assert np.abs(kept[0].values).max() > 0.0 and kept[1].values.shape == (1, 2)
        analysis = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[ElementRecorder([3, 8], "endRotations")])
        analysis.static()
        with pytest.raises(vtsi.ModelError, match=r"^element recorder: response 'endRotations' of element 3 "
                                                  r"\(endRotationBeamTest\) is not available in a coupled analysis "
                                                  r"whose wheels run on it: .* record 'force' or 'globalForce'$"):
            analysis.run(1)
    finally:
        ELEMENT_TYPES.pop(EndRotationBeam.name, None)


def test_transient_reactions_with_a_modal_bridge_are_refused():
    """`TransientAnalysis(bridge=ModalBridge(...))` of fewer modes than the model has refuses
    reaction recorders as the coupled analysis does (one message), and records displacements: with 3 modes K Φ q gives a force P
    at mid-span 42.09 kN per support for P/2 = 49.05 kN (the truncated modes' share is missing,
    computed here from the modal static solution q = Ω⁻² Φᵀ P), every mode 49.05 kN."""
    model, deck, track = span()
    asm = model.build()
    mid = deck.midspan_nodes[0]
    load = np.zeros(asm.n_full)
    load[asm.full_dof(mid, 2)] = -P
    support = asm.full_dof(deck.supports[0], 2)
    for n_modes, low in ((3, True), ("all", False)):
        modal = ModalBridge(model, track, n_modes=n_modes)
        u = modal.shapes @ (modal.shapes.T @ load / modal.omega ** 2)
        reaction = (asm.K_full @ u - load)[support]
        assert (abs(reaction - P / 2) > 0.1 * P / 2) == low
    model.pattern(1, vtsi.Constant())
    model.load(1, mid, 0.0, -P, 0.0)
    modal = ModalBridge(model, track, n_modes=3)
    disp = NodeRecorder([mid], [2])
    for recorder, who in ((ReactionRecorder(deck.supports, [2]), "reaction recorder: reaction"),
                          (NodeRecorder(deck.supports, [2], "reactionIncInertia"),
                           "node recorder: reactionIncInertia")):
        analysis = vtsi.TransientAnalysis(model, "Newmark", 1e-3, recorders=[recorder], bridge=modal)
        with pytest.raises(vtsi.ModelError, match=f"^{who} in a transient analysis with a modal bridge is not "
                                                  r"recorded: K Φ q leaves out .* \(bridge=None\) or every mode$"):
            analysis.run(1)
    vtsi.TransientAnalysis(model, "Newmark", 1e-3, recorders=[disp], bridge=modal).run(2)
    assert disp.values[-1, 0] < 0.0


@pytest.mark.parametrize("value, match", [
    (-1.0, r"^contact recorder: gap_tol \[m\] must be >= 0 and finite, got -1.0$"),
    (float("nan"), r"^contact recorder: gap_tol \[m\] must be >= 0 and finite, got nan$"),
    ("abc", r"^contact recorder: gap_tol \[m\] must be a number, got 'abc'$"),
    (True, r"^contact recorder: gap_tol \[m\] must be a number, got True$"),
    (2e-6, r"^contact recorder: gap_tol \[m\] must be at most 1e-06 m, got 2e-06: a wheel less than gap_tol "),
])
def test_the_contact_recorder_s_gap_tolerance_is_checked_as_the_analysis_s(value, match):
    """``ContactRecorder(gap_tol=...)`` takes 0 to MAX_GAP_TOL (1e-6 m) as `CoupledAnalysis`
    does; anything else is a ModelError naming it (it was a bare float())."""
    model, deck, track = span()
    con = MovingLoadConstraint(track, TrainSubdomain(Train([moving_mass(1e4)], [0.0], 0.0), x_head0=5.0))
    with pytest.raises(vtsi.ModelError, match=match):
        ContactRecorder(con, response="in_contact", gap_tol=value)
    for ok in (0, 1e-6):
        assert ContactRecorder(con, response="in_contact", gap_tol=ok).gap_tol == ok
