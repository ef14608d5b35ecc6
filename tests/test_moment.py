"""Bending moments along the track (vtsi.recorders.moment) against the closed forms of a simply
supported beam: a static force at mid-span, the mid-span influence line at any x, two axles and
LM71 by statics, slow passages, a coupled analysis's contact forces, element loads."""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledLoads
from vtsi.influence import InfluenceLines
from vtsi.models import Train, moving_force, sprung_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.passage import Output, PassageSettings
from vtsi.recorders.moment import BendingMomentRecorder, fixed_end_moments, moment_rows
from vtsi.sweep import Sweep, beam_bridge
from vtsi.track import Track
from vtsi.train import TrainSubdomain

L, E, I, MU, P = 20.0, 3.5e10, 0.6948, 15000.0, 1e5


def beam(n):
    model = vtsi.Model()
    b = simply_supported_beam(model, L, n, E, I, MU)
    return model, b, Track(model, b.elements)


def test_static_force_at_midspan_gives_PL_over_4_sagging():
    model, b, track = beam(10)
    series = model.add_time_series(vtsi.Constant(1.0, tag=1))
    model.pattern(1, series)
    model.load(1, b.midspan_nodes[0], 0.0, -P, 0.0)
    rec = BendingMomentRecorder(track, [b.midspan_nodes[0], b.nodes[2], b.nodes[0]])
    vtsi.StaticAnalysis(model, recorders=[rec]).run(1)
    m = np.asarray(rec.values)[0]
    assert m == pytest.approx([P * L / 4, P * 0.2 * L / 2, 0.0], rel=1e-9, abs=1e-6)


def midspan_line(x):
    """The mid-span moment's influence line of a simply supported span [N·m per N]."""
    x = np.asarray(x, dtype=float)
    return np.where((x >= 0.0) & (x <= L), np.minimum(x, L - x) / 2, 0.0)


def lm71_midspan_max(span):
    """LM71's largest mid-span moment on a simply supported span (>= 8 m) by statics [N·m]. With
    its centre δ from mid-span, |δ| <= 0.8 m: two axles on either side, so the four 250 kN
    axles give 125 kN × (2L − 6.4 m) whatever δ, and 80 kN/m from 3.2 m beyond the centre on
    both sides (the line x/2) q/4 [(L/2 + δ − 3.2)² + (L/2 − δ − 3.2)²], largest at |δ| = 0.8 m
    (an axle on mid-span). Beyond, an axle on the other side takes 250 kN × (|δ| − 0.8) off
    while the distributed load adds at most q |δ| <= 192 kN per m: δ = 0.8 m is the maximum."""
    return 125e3 * (2 * span - 6.4) + 20e3 * ((span / 2 - 2.4) ** 2 + (span / 2 - 4.0) ** 2)


def test_influence_line_at_the_nodes_and_lm71():
    """On 20 elements: the mid-span moment's line x/2 … at every x, not only at the nodes, and
    LM71's largest mid-span moment (6075.2 kN·m, an axle on mid-span). This test read LM71 centred
    on the span (6049.6 kN·m, a smaller value) within 1 %, which the end moments alone met
    (6077.4); they now read the maximum to rounding."""
    model, b, track = beam(20)
    mid = b.midspan_nodes[0]
    lines = InfluenceLines(model, track, moments=[mid])
    x = np.linspace(-1.0, L + 1.0, 221)
    np.testing.assert_allclose(lines(x)[:, 0], midspan_line(x), rtol=1e-9, atol=1e-12)
    lm71 = lines.lm71_envelope()
    assert lm71[1, 0] == pytest.approx(lm71_midspan_max(L), rel=1e-9)
    assert abs(lm71[0, 0]) < 1e-9 * lm71[1, 0]


@pytest.mark.parametrize("n", [10, 8])
def test_two_axles_and_lm71_give_the_static_maxima(n):
    """The documented example (10 elements of 2 m) and 8 elements of 2.5 m (nodes off the
    scan's grid): two 100 kN axles 1 m apart give 9.5 P = 950 kN·m at mid-span (both on the
    span's middle element pair, at 9.5 and 10.5 m or 10 and 11 m), LM71 6075.2 kN·m. The end
    moments alone read 978.1 and 6121.6 on 10 elements (+3.0 %, +0.76 %): the fixed-end moment
    P a b²/ℓ² of the axle inside an element next to mid-span, halved by the averaging."""
    model, b, track = beam(n)
    lines = InfluenceLines(model, track, moments=[b.midspan_nodes[0], b.nodes[0]])
    two = lines.train_envelope([0.0, 1.0], [P, P])
    assert two[1, 0] == pytest.approx(9.5 * P, rel=1e-9)
    assert two[0, 0] == pytest.approx(0.0, abs=1e-9 * P) and np.abs(two[:, 1]).max() < 1e-9 * P   # the pin: none
    assert lines.lm71_envelope()[1, 0] == pytest.approx(lm71_midspan_max(L), rel=1e-9)
    if n == 10:
        old = InfluenceLines(model, track, functionals=moment_rows(model.build(), track, [b.midspan_nodes[0]]))
        assert old.train_envelope([0.0, 1.0], [P, P])[1, 0] == pytest.approx(978.125e3, rel=1e-6)


def test_a_load_on_a_node_reads_as_before():
    """At the nodes the fixed-end share is zero (H₂ = H₄ = 0): the moment is the end moments'
    alone, as the recorder read it (PL/4 under a nodal force: the test above)."""
    model, b, track = beam(10)
    nodes = [b.midspan_nodes[0], b.nodes[3], b.nodes[0], b.nodes[-1]]
    asm = model.build()
    x = np.linspace(0.0, L, 11)
    assert np.all(fixed_end_moments(asm, track, nodes).at(x) == 0.0)
    new = InfluenceLines(model, track, moments=nodes)(x)
    old = InfluenceLines(model, track, functionals=moment_rows(asm, track, nodes))(x)
    np.testing.assert_array_equal(new, old)


def test_a_slow_passage_reads_the_static_moment(tmp_path):
    """Two 100 kN axles 1 m apart at 1 km/h over the 20 m span of 10 elements (f₁ = 5 Hz,
    ζ = 2 %), FE, exact modal and time-stepped modal passages: the largest mid-span moment is the
    static 950 kN·m within 1e-4 (measured 0.6–0.9e-5; the end moments alone read 978–987), and
    the history is the static moment at the axles' positions within 1e-4 of it while they cross
    the middle third (measured 2.8e-5). What remains is quasi-static: the damping force's lag,
    2ζ V/(ω₁ x) ≈ 3.5e-5 at mid-span, and the start's free vibration, decayed by e^(−ζω₁t)."""
    path = tmp_path / "two.csv"
    path.write_text("position_m,load_kN\n0,100\n1,100\n")
    f1 = 5.0
    bridge = beam_bridge([L], MU * (2 * np.pi * f1 * (L / np.pi) ** 2) ** 2, 1.0, MU, elements_per_span=10)
    out = [Output("moment", "moment", "midspan", history=True)]
    for kind in ("fe", "modal", "modal-stepped"):
        sweep = Sweep(bridge, [str(path)], "1", PassageSettings(dt=1e-3, damping=0.02, bridge=kind), outputs=out)
        static, lm71, _ = sweep.runner.static_envelopes(out[0], sweep.trains)
        assert static[0, 1, 0] == pytest.approx(9.5 * P, rel=1e-9) and lm71[1, 0] == pytest.approx(lm71_midspan_max(L))
        result = sweep.runner.run(sweep.trains[0], 1.0)
        assert result.envelopes["moment"][1, 0] == pytest.approx(9.5 * P, rel=1e-4), kind
        t, m = result.histories["moment"]
        x = result.x_head0 + t / 3.6
        middle = (x > 7.0) & (x < 14.0)
        static_history = P * (midspan_line(x) + midspan_line(x - 1.0))
        assert np.abs(m[middle, 0] - static_history[middle]).max() < 1e-4 * 9.5 * P, kind


@pytest.mark.parametrize("interpolation", ["hermite", "bspline"])
def test_a_coupled_analysis_s_contact_forces_inside_elements_are_corrected(interpolation):
    """The recorder in a coupled analysis takes the contact forces λ (the analysis's
    CoupledLoads) and places them at the wheels (spread by the B-spline rows as the constraint spreads them) with the train's moving
    forces: fed the static state of the forces it records, it gives the moment of statics at
    mid-span and at x = 6 m, to 1e-9 (the end moments alone read 0.5–0.8 % more)."""
    model, b, track = beam(10)
    cars = [sprung_mass(1000.0, 1e6, m_w=100.0), moving_force(5e4), sprung_mass(2000.0, 1e6, m_w=100.0)]
    train = Train(cars, [0.0, 1.3, 3.9], 50.0)
    dt, t = 4e-3, 0.1                                       # knot 2 V Δt = 0.4 m: spread over ±0.8 m
    con = MovingLoadConstraint(track, TrainSubdomain(train, 11.5 - 50.0 * t), interpolation=interpolation)
    nodes = [b.midspan_nodes[0], b.nodes[3]]
    rec = BendingMomentRecorder(track, nodes, constraint=con)
    asm = model.build()
    requests = rec.requests(asm)
    lam = np.array([7e4, 1.1e5])                             # the contact wheels at 11.5 and 7.6 m
    x_c, x_f = con.positions(t), con.x0_force + 50.0 * t      # the force at 10.2 m
    cols, vals, _ = track.rows(x_c, con.knot(dt))
    load = np.zeros(track.n_track)
    np.add.at(load, cols[cols >= 0], -(lam[:, None] * vals)[cols >= 0])
    fcols, fvals, _ = track.rows(x_f)
    np.add.at(load, fcols[fcols >= 0], -(5e4 * fvals)[fcols >= 0])
    u = np.zeros(asm.n_full)
    free = np.zeros(asm.n_free)
    free[track.free_index] = load
    u[asm.full_of_free] = spla.spsolve(asm.K.tocsc(), free)
    columns = np.array([[u[k] for q, k in requests]])
    loads = CoupledLoads(con)                               # what the analysis hands its recorders
    loads.begin(con.knot(dt), None, False)
    loads.deliver(np.array([t]), lam[None, :])
    rec.start(asm, model, {"analysis": "coupled", "dt": dt, "coupled_loads": loads})
    rec.write(np.array([t]), columns, asm)

    def line(x, a):                                          # the moment at a of a unit force at x
        return np.where((x >= 0) & (x <= L), np.where(x <= a, x * (L - a), a * (L - x)) / L, 0.0)

    knot = con.knot(dt)
    s = np.linspace(-2.0 * knot, 2.0 * knot, 40001) if knot else np.zeros(1)
    kernel = np.maximum(0, 2 / 3 - (s / knot) ** 2 + 0.5 * np.abs(s / knot) ** 3) * (np.abs(s) <= knot) \
        + (2 - np.abs(s / knot)) ** 3 / 6 * (np.abs(s) > knot) if knot else np.ones(1)
    weights = kernel / kernel.sum()
    exact = [sum(lam_i * np.sum(weights * line(x_i - s, a)) for lam_i, x_i in zip(lam, x_c)) + 5e4 * line(x_f[0], a)
             for a in (10.0, 6.0)]
    assert np.asarray(rec.values)[0] == pytest.approx(exact, rel=1e-9)
    old = columns[0, :len(moment_rows(asm, track, nodes)[0])] @ moment_rows(asm, track, nodes)[1]
    assert np.max(np.abs(old / exact - 1.0)) > 4e-3


def test_element_loads_of_the_patterns_are_corrected():
    """A uniform eleLoad w on every element of the 10-element span: w x (L − x)/2 at the nodes
    (the end moments alone read w ℓ²/12 more: 2.8 % at mid-span)."""
    model, b, track = beam(10)
    series = model.add_time_series(vtsi.Constant(1.0, tag=1))
    model.pattern(1, series)
    w = 2e4
    for e in b.elements:
        model.beam_load(1, e, "uniform", -w, 0.0)
    rec = BendingMomentRecorder(track, [b.midspan_nodes[0], b.nodes[2], b.nodes[0]])
    vtsi.StaticAnalysis(model, recorders=[rec]).run(1)
    assert np.asarray(rec.values)[0] == pytest.approx([w * L ** 2 / 8, w * 4.0 * 16.0 / 2, 0.0], rel=1e-9, abs=1e-6)


def test_the_rows_are_resolved_once_per_track_however_many_track_objects():
    """Each runner builds its own Track: the rows it resolves on the model's assembly are kept once
    per track's elements and nodes, not once per Track object (a notebook's hundred sweeps of a
    viaduct kept a hundred copies of its rows)."""
    model, b, _ = beam(10)
    series = model.add_time_series(vtsi.Constant(1.0, tag=1))
    model.pattern(1, series)
    model.load(1, b.midspan_nodes[0], 0.0, -P, 0.0)
    values = []
    for _ in range(3):
        rec = BendingMomentRecorder(Track(model, b.elements), [b.midspan_nodes[0]])
        vtsi.StaticAnalysis(model, recorders=[rec]).run(1)
        values.append(np.asarray(rec.values)[0, 0])
    assert values == [pytest.approx(P * L / 4, rel=1e-9)] * 3
    assert [key[0] for key in model.build().derived].count("bending moment") == 1


def test_a_timoshenko_deck_gives_its_end_moments_not_ei_times_the_hermite_curvature():
    """A simply supported Timoshenko beam (G = 1.46e10 Pa, shear area 3 m², I = 1 m⁴, 1 m
    elements, φ = 12EI/(G A_v ℓ²) = 9.6): the mid-span moment line is x/2 … at every x,
    statically determinate whatever the shear flexibility (a wheel loads the element through the
    Hermite row, whose fixed-end share is taken off); EI times the Hermite curvature of the nodal
    values read 740 kN·m for PL/4 = 500 under a force at mid-span. A shear-rigid two-span deck's
    moment over its middle support is −P a b (L + a)/(4 L²), the Euler-Bernoulli value. On the
    shear-flexible two-span deck the row shares a load inside an element between its ends as an
    Euler-Bernoulli element would: against the deck with a node under the load (the Timoshenko
    beam's own answer) the support moment of a load in an element next to the support is 7.6e-4
    off at 19.3 m, 5.0e-4 at 20.6 m, 0 at 19.5 m (the element's middle); the end moments alone
    were 9.6 %, 17 % and 26 % off."""
    def deck(spans, G, xs=None):
        model = vtsi.Model()
        xs = np.arange(0.0, sum(spans) + 0.5, 1.0) if xs is None else xs
        for k, x in enumerate(xs):
            model.node(k + 1, float(x), 0.0)
        supports = np.concatenate([[0.0], np.cumsum(spans)])
        for k, x in enumerate(xs):
            if np.any(np.isclose(x, supports)):
                model.fix(k + 1, int(k == 0), 1, 0)
        for k in range(len(xs) - 1):
            model.element("ElasticTimoshenkoBeam", k + 1, (k + 1, k + 2), A=6.0, E=E, G=G, I=1.0, Avy=3.0, rho=MU)
        return model, Track(model, list(range(1, len(xs))))

    model, track = deck([L], 1.46e10)
    lines = InfluenceLines(model, track, moments=[11, 6])
    x = np.linspace(0.0, L, 161)
    np.testing.assert_allclose(lines(x)[:, 0], np.minimum(x, L - x) / 2, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(lines(x)[:, 1], np.where(x <= 5.0, x * 0.75, 0.25 * (L - x)), rtol=1e-9, atol=1e-9)
    model, track = deck([L, L], 1.46e16)                             # shear-rigid: Euler-Bernoulli's
    hogging = InfluenceLines(model, track, moments=[21])([7.0])[0, 0]
    a, b = 7.0, L - 7.0
    assert hogging == pytest.approx(-a * b * (L + a) / (4 * L ** 2), rel=1e-6)        # per unit force
    model, track = deck([L, L], 1.46e10)
    for a, error in ((19.3, 1e-3), (20.6, 1e-3), (19.5, 1e-9)):
        xs = np.sort(np.append(np.arange(0.0, 2 * L + 0.5, 1.0), a))
        exact = InfluenceLines(*deck([L, L], 1.46e10, xs), moments=[int(np.argmin(abs(xs - L))) + 1])([a])[0, 0]
        assert InfluenceLines(model, track, moments=[21])([a])[0, 0] == pytest.approx(exact, rel=error), a


def test_not_a_track_node_is_refused():
    model, b, track = beam(4)
    model.node(99, 5.0, 3.0)
    with pytest.raises(vtsi.ModelError, match="not a node of the track"):
        moment_rows(model.build(), track, [99])
    with pytest.raises(vtsi.ModelError, match="not a node of the track"):
        fixed_end_moments(model.build(), track, [99])
    with pytest.raises(vtsi.ModelError, match="^bending moment recorder: constraint must be a MovingLoadConstraint"):
        BendingMomentRecorder(track, [3], constraint="rails")
    other = Track(model, b.elements[:2])
    con = MovingLoadConstraint(other, TrainSubdomain(Train([moving_force(1e5)], [0.0], 10.0), 0.0))
    with pytest.raises(vtsi.ModelError, match="^bending moment recorder: the constraint's wheels run on elements"):
        BendingMomentRecorder(track, [3], constraint=con)
