"""Static responses along the track (vtsi.influence) against the closed forms of a simply
supported Euler-Bernoulli beam (Hermite elements give exact nodal displacements under loads
anywhere on an element)."""
import numpy as np
import pytest

import vtsi
from vtsi.influence import InfluenceLines
from vtsi.models import hslm_a
from vtsi.models.bridges import simply_supported_beam
from vtsi.track import Track

L, E, I = 20.0, 3.5e10, 0.6948
EI = E * I


def beam(n=10):
    model = vtsi.Model()
    b = simply_supported_beam(model, L, n, E, I, 15000.0)
    lines = InfluenceLines(model, Track(model, b.elements), [(b.midspan_nodes[0], 2), (b.nodes[0], 3)])
    return lines


def midspan_influence(a):
    """Midspan deflection (downward positive) of a unit force at a (0 <= a <= L)."""
    a = np.minimum(a, L - a)
    return np.where((a >= 0) & (a <= L / 2), a * (3 * L ** 2 - 4 * a ** 2) / (48 * EI), 0.0)


def test_influence_lines_are_the_closed_forms():
    lines = beam()
    x = np.linspace(-2.0, 22.0, 241)
    il = lines(x)
    np.testing.assert_allclose(-il[:, 0], np.where((x >= 0) & (x <= L), midspan_influence(np.clip(x, 0, L)), 0.0),
                               rtol=1e-9, atol=1e-18)
    b = np.clip(L - x, 0, L)            # left end rotation, counter-clockwise positive: -P b (L² - b²)/(6 L EI)
    np.testing.assert_allclose(il[:, 1], np.where((x >= 0) & (x <= L), -b * (L ** 2 - b ** 2) / (6 * L * EI), 0.0),
                               rtol=1e-9, atol=1e-18)


def test_train_envelope_is_the_scan_of_the_closed_form():
    """HSLM-A1's static midspan deflection: every head position 1 mm apart, closed-form influence."""
    train = hslm_a(1, 1.0)
    offsets, loads = train.wheel_offsets, train.static_wheel_loads
    heads = np.arange(0.0, L + offsets[-1], 1e-3)
    brute = max(np.sum(loads * midspan_influence(np.clip(h - offsets, -1, L + 1)) * ((h - offsets >= 0) & (h - offsets <= L)))
                for h in heads[::7])
    env = beam().train_envelope(offsets, loads)
    assert -env[0, 0] == pytest.approx(brute, rel=2e-5)
    assert env[1, 0] == 0.0


def test_lm71_is_the_closed_form():
    """LM71 centred on a 20 m span: 4 × 250 kN at ±0.8 m and ±2.4 m, 80 kN/m beyond ±3.2 m."""
    c, q = L / 2 - 3.2, 80e3
    udl = 2 * q / (48 * EI) * (1.5 * L ** 2 * c ** 2 - c ** 4)
    points = 250e3 * sum(float(midspan_influence(np.array(a))) for a in (L / 2 - 2.4, L / 2 - 0.8, L / 2 + 0.8, L / 2 + 2.4))
    lm71 = beam().lm71_envelope()
    assert -lm71[0, 0] == pytest.approx(udl + points, rel=1e-5)
    assert beam().lm71_envelope(alpha=1.21)[0, 0] == pytest.approx(1.21 * lm71[0, 0], rel=1e-12)


def test_a_mechanism_is_refused():
    model = vtsi.Model()
    b = simply_supported_beam(model, L, 4, E, I, 15000.0)
    model.fixities.clear()
    model._changed()
    with pytest.raises(vtsi.ModelError):
        InfluenceLines(model, Track(model, b.elements), [(b.midspan_nodes[0], 2)])
