"""Static responses along the track (vtsi.influence) against the closed forms of a simply
supported Euler-Bernoulli beam (Hermite elements give exact nodal displacements under loads
anywhere on an element)."""
from pathlib import Path

import numpy as np
import pytest

import vtsi
from vtsi.bridge_file import load_bridge
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


@pytest.fixture(scope="module")
def bridge():
    model = vtsi.Model()
    b = simply_supported_beam(model, L, 4, E, I, 15000.0)
    return model, Track(model, b.elements), InfluenceLines(model, Track(model, b.elements), [(3, 2)])


BAD_INFLUENCE = [
    ("no responses", lambda m, t, il: InfluenceLines(m, t),
     r"^influence lines: give the responses as dofs=\[\(node, dof\), \.\.\.\], as functionals or as "
     r"moments=\[node, \.\.\.\], one of the three$"),
    ("dofs and moments", lambda m, t, il: InfluenceLines(m, t, dofs=[(3, 2)], moments=[3]),
     r"^influence lines: give the responses as dofs=.*one of the three$"),
    ("no moment nodes", lambda m, t, il: InfluenceLines(m, t, moments=[]),
     r"^influence lines: moments must be a non-empty list of node tags, got \[\]$"),
    ("a moment off the track", lambda m, t, il: InfluenceLines(m, t, moments=[99]),
     r"^bending moment: node 99 does not exist$"),
    ("a dof without its node", lambda m, t, il: InfluenceLines(m, t, dofs=[(3,)]),
     r"^influence lines: dofs must be a non-empty list of \(node, dof\) pairs, got \[\(3,\)\]$"),
    ("no dofs", lambda m, t, il: InfluenceLines(m, t, dofs=[]),
     r"^influence lines: dofs must be a non-empty list of \(node, dof\) pairs, got \[\]$"),
    ("track not a Track", lambda m, t, il: InfluenceLines(m, "track", dofs=[(3, 2)]),
     r"^influence lines: track must be a vtsi.track.Track, got 'track'$"),
    ("functionals P 1-D", lambda m, t, il: InfluenceLines(m, t, functionals=([0], [1.0])),
     r"^influence lines: functionals must be \(free dofs \(n,\) integers, P \(n, n_responses\)\), got free \(1,\) int64, P \(1,\)$"),
    ("functionals on a dof out of range", lambda m, t, il: InfluenceLines(m, t, functionals=([999], np.ones((1, 1)))),
     r"^influence lines: functionals: free dofs must be in 0\.\.11, got 999\.\.999$"),
    ("LM71 alpha text", lambda m, t, il: il.lm71_envelope("x"), r"^influence lines: LM71 alpha must be a number, got 'x'$"),
    ("LM71 alpha None", lambda m, t, il: il.lm71_envelope(None), r"^influence lines: LM71 alpha must be a number, got None$"),
    ("LM71 alpha NaN", lambda m, t, il: il.lm71_envelope(np.nan), r"^influence lines: LM71 alpha must be > 0 and finite, got nan$"),
    ("LM71 alpha negative", lambda m, t, il: il.lm71_envelope(-1), r"^influence lines: LM71 alpha must be > 0 and finite, got -1.0$"),
    ("train without axles", lambda m, t, il: il.train_envelope([], []),
     r"^influence lines: give one load per axle offset \(at least one axle\), got 0 offsets and 0 loads$"),
    ("two offsets, one load", lambda m, t, il: il.train_envelope([0, 3], [1e5]),
     r"^influence lines: give one load per axle offset \(at least one axle\), got 2 offsets and 1 loads$"),
    ("NaN offset", lambda m, t, il: il.train_envelope([np.nan], [1e5]),
     r"^influence lines: axle offsets \[m\] must be finite, got \[nan\]$"),
    ("text offset", lambda m, t, il: il.train_envelope(["a"], [1e5]),
     r"^influence lines: axle offsets \[m\] must be numbers, got \['a'\]$"),
    ("NaN load", lambda m, t, il: il.train_envelope([0], [np.nan]), r"^influence lines: axle loads \[N\] must be finite, got \[nan\]$"),
    ("NaN position", lambda m, t, il: il([np.nan]), r"^influence lines: positions x \[m\] must be finite, got \[nan\]$"),
    ("text position", lambda m, t, il: il("x"), r"^influence lines: positions x \[m\] must be numbers, got 'x'$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in BAD_INFLUENCE], ids=[c[0] for c in BAD_INFLUENCE])
def test_bad_influence_input_is_named(bridge, bad, match):
    with pytest.raises(vtsi.ModelError, match=match):
        bad(*bridge)


OVERHANG = Path(__file__).parent / "scripts" / "overhang.py"   # a 20 m span, a 4 m overhang carrying the track


def test_an_axle_on_the_tip_of_an_overhang_loads_it(tmp_path):
    """A 20 m span with a 4 m overhang carrying the track from its tip (x = -4 m). LM71's scan
    put its axle on the tip as centre + offset = -4.0000000000000115, off the track, where the
    line is 0: the tip's deflection read 0.82282 mm. The closed form of a cantilever of length c
    beyond a span L (a force P at a from the support: P a [a (3c - a)/6 + L c/3] / EI downward at
    the tip) under the axles at 4, 2.4 and 0.8 m from the support (the fourth 1.6 m beyond the
    tip, the 80 kN/m beyond the axles both off the track or on the span, which lifts the tip)
    gives 0.84114 mm, as OpenSeesPy does. A train's scan alike: two axles 1.23 m apart, the rear
    one on the tip."""
    b = load_bridge(OVERHANG)
    lines = InfluenceLines(b.model, Track(b.model, b.track_elements), dofs=[(1, 2)])
    c, span, ei = 4.0, 20.0, 3.5e10 * 1.9

    def tip(a):                          # downward tip deflection [m/N] of a force a from the support
        return a * (a * (3 * c - a) / 6 + span * c / 3) / ei

    lm71 = 250e3 * sum(tip(a) for a in (4.0, 2.4, 0.8))
    assert lm71 == pytest.approx(0.84114e-3, abs=1e-8)
    assert -lines.lm71_envelope()[0, 0] == pytest.approx(lm71, rel=1e-9)
    pair = lines.train_envelope([0.0, 1.23], [200e3, 200e3])
    assert -pair[0, 0] == pytest.approx(200e3 * (tip(4.0) + tip(4.0 - 1.23)), rel=1e-9)     # it read 0.68199 mm
    # SW/0 integrates the line (no axle to lose): its second length over the overhang alone, q ∫ tip(a) da
    sw0 = 133e3 * (c ** 4 / 8 + span * c ** 3 / 6) / ei                                                     # 0.49067 mm
    assert -lines.sw0_envelope()[0, 0] == pytest.approx(sw0, rel=1e-9)
