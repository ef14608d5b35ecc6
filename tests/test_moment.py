"""Bending moments along the track (vtsi.recorders.moment) against the closed forms of a simply
supported beam: a static force at mid-span, the mid-span influence line at the nodes, LM71."""
import numpy as np
import pytest

import vtsi
from vtsi.influence import InfluenceLines
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders.moment import BendingMomentRecorder, moment_rows
from vtsi.track import Track

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


def test_influence_line_at_the_nodes_and_lm71():
    model, b, track = beam(20)
    mid = b.midspan_nodes[0]
    lines = InfluenceLines(model, track, functionals=moment_rows(model.build(), track, [mid]))
    x = np.linspace(0.0, L, 21)                                  # the nodes: exact there
    np.testing.assert_allclose(lines(x)[:, 0], np.minimum(x, L - x) / 2, rtol=1e-9, atol=1e-9)
    c, q = L / 2 - 3.2, 80e3                                     # LM71 centred: 4 × 250 kN and 80 kN/m
    exact = 250e3 * 2 * ((L / 2 - 2.4) / 2 + (L / 2 - 0.8) / 2) + 2 * q * c ** 2 / 4
    lm71 = lines.lm71_envelope()
    assert lm71[1, 0] == pytest.approx(exact, rel=1e-2)
    assert abs(lm71[0, 0]) < 1e-9 * lm71[1, 0]


def test_a_timoshenko_deck_gives_its_end_moments_not_ei_times_the_hermite_curvature():
    """A simply supported Timoshenko beam (G = 1.46e10 Pa, shear area 3 m², I = 1 m⁴, 1 m
    elements): the mid-span moment line is L/4 … at the nodes, statically determinate whatever
    the shear flexibility; EI times the Hermite curvature of the nodal values read 740 kN·m for
    PL/4 = 500 under a force at mid-span. A shear-rigid two-span deck's moment over its middle
    support is −P a b (L + a)/(4 L²), the Euler-Bernoulli value."""
    def deck(spans, G):
        model = vtsi.Model()
        xs = np.arange(0.0, sum(spans) + 0.5, 1.0)
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
    lines = InfluenceLines(model, track, functionals=moment_rows(model.build(), track, [11, 6]))
    x = np.linspace(0.0, L, 21)
    np.testing.assert_allclose(lines(x)[:, 0], np.minimum(x, L - x) / 2, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(lines(x)[:, 1], np.where(x <= 5.0, x * 0.75, 0.25 * (L - x)), rtol=1e-9, atol=1e-9)
    model, track = deck([L, L], 1.46e16)                             # shear-rigid: Euler-Bernoulli's
    hogging = InfluenceLines(model, track, functionals=moment_rows(model.build(), track, [21]))([7.0])[0, 0]
    a, b = 7.0, L - 7.0
    assert hogging == pytest.approx(-a * b * (L + a) / (4 * L ** 2), rel=1e-6)        # per unit force


def test_not_a_track_node_is_refused():
    model, b, track = beam(4)
    model.node(99, 5.0, 3.0)
    with pytest.raises(vtsi.ModelError, match="not a node of the track"):
        moment_rows(model.build(), track, [99])
