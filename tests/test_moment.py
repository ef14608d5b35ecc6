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


def test_not_a_track_node_is_refused():
    model, b, track = beam(4)
    model.node(99, 5.0, 3.0)
    with pytest.raises(vtsi.ModelError, match="not a node of the track"):
        moment_rows(model.build(), track, [99])
