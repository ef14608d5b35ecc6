"""The standalone defaults on a bridge of several decks read each deck's own frequencies, as a
sweep's passage does (vtsi.damping.bridge_frequencies): Rayleigh damping's anchors
(rayleigh_damping), the modal bridge's basis (ModalBridge's f_max) and the 3-D animation's
aliasing warning (scene3d.animate_case).

The bridges: simply supported decks side by side, each on its own pin and roller, two decks
ending on one pier (their end nodes apart, at one x), as vtsi.models.bridges.continuous_beam
builds one span at a time: 35 GPa, 1 m⁴, 15 t/m, consistent mass, elements of about 1.5 m. The
independent values: a simply supported Euler-Bernoulli span's k-th frequency
n_k = k² (π / (2 L²)) √(EI/μ) (Clough & Penzien, Dynamics of Structures, the simple beam's
flexural modes: 10.66 Hz for 15 m, 2.666 Hz for 30 m), and the EN 1990 A2.4.4.2.1(4)P cut-off max(30 Hz, 1.5 n₀, n₃),
n₃ the third (= 9 n₀), of each deck, the bridge's the largest. The FE modes (Hermite cubics,
10 and 20 elements) lie within 0.06 % of n_k for k <= 3 and 0.3 % for k <= 6: the tolerances.
"""
import logging

import numpy as np
import pytest

import vtsi
from vtsi import scene3d
from vtsi.damping import bridge_frequencies, decks_cutoff_hz, rayleigh_damping, rayleigh_ratio
from vtsi.modal_bridge import CUTOFF_MARGIN, ModalBridge
from vtsi.models.bridges import continuous_beam
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.sweep import Sweep, SweepBridge
from vtsi.sweep_results import SweepResults
from vtsi.track import Track

E, I, MU, A = 3.5e10, 1.0, 15000.0, 5.0     # [Pa, m⁴, kg/m, m²]
ELEMENT = 1.5                               # [m]
ZETA = 0.02


def n_k(L, k=1):
    """k-th bending frequency [Hz] of a simply supported span of ``L`` [m] (module docstring)."""
    return k ** 2 * np.pi / (2 * L ** 2) * np.sqrt(E * I / MU)


def en_cutoff(n0, n3):
    """EN 1990 A2.4.4.2.1(4)P: max(30 Hz, 1.5 n₀, n₃)."""
    return max(30.0, 1.5 * n0, n3)


def decks(spans):
    """(model, track element tags) of simply supported decks of ``spans`` [m] side by side, each
    ending on the next one's pier (separate end nodes at one x)."""
    model, elements, node, tag, x0 = vtsi.Model(), [], 1, 1, 0.0
    for L in spans:
        n = 2 * round(L / (2 * ELEMENT))       # even: a node at midspan
        beam = continuous_beam(model, [L], n, E, I, MU, A=A, x0=x0, first_node=node, first_element=tag)
        elements += list(beam.elements)
        node, tag, x0 = node + n + 1, tag + n, x0 + L
    return model, elements


PAIRS = {"15 + 30 m": [15.0, 30.0], "15 + 15 m": [15.0, 15.0]}


@pytest.mark.parametrize("spans", PAIRS.values(), ids=PAIRS.keys())
def test_bridge_frequencies_are_each_decks_own(spans):
    """Each deck's n₀, n₂, n₃ are its own span's; the cut-off the largest of the decks' (both
    pairs: the 15 m deck's n₃ = 95.98 Hz; the model's first three frequencies gave 30 Hz
    (2.666, 10.66, 10.66) and 42.66 Hz (10.66, 10.66, 42.66)); the lower anchor is the bridge's
    first frequency (the longest span's n₀)."""
    model, track = decks(spans)
    f = bridge_frequencies(model, track)
    expected = np.array([[n_k(L, k) for k in (1, 2, 3)] for L in spans])
    np.testing.assert_allclose(f.deck_hz, expected, rtol=1e-3)
    np.testing.assert_allclose(f.deck_hz[:, 0], expected[:, 0], rtol=1e-5)
    cutoff = max(en_cutoff(n0, n3) for n0, _, n3 in expected)
    assert cutoff == pytest.approx(9 * n_k(15.0), rel=1e-12)
    assert f.cutoff_hz == pytest.approx(cutoff, rel=1e-3)
    assert f.first_hz == pytest.approx(n_k(max(spans)), rel=1e-5)
    assert bridge_frequencies(model, Track(model, track)).cutoff_hz == f.cutoff_hz      # a Track or its tags


def test_without_a_track_the_model_is_read_as_one_deck():
    """No track, no decks: the model's first three frequencies (documented; right for one deck).
    15 + 30 m: 2.666, 10.66, 10.66 Hz, cut-off 30 Hz."""
    model, _ = decks([15.0, 30.0])
    f = bridge_frequencies(model)
    np.testing.assert_allclose(f.deck_hz, [[n_k(30.0), n_k(30.0, 2), n_k(15.0)]], rtol=1e-5)
    assert f.cutoff_hz == 30.0 and f.first_hz == pytest.approx(n_k(30.0), rel=1e-5)
    one, track = decks([20.0])          # one deck: the same with or without its track
    assert bridge_frequencies(one).cutoff_hz == pytest.approx(bridge_frequencies(one, track).cutoff_hz, rel=1e-12)
    assert bridge_frequencies(one).cutoff_hz == pytest.approx(en_cutoff(n_k(20.0), n_k(20.0, 3)), rel=1e-3)


@pytest.mark.parametrize("spans", PAIRS.values(), ids=PAIRS.keys())
def test_rayleigh_default_is_the_passages(spans):
    """rayleigh_damping(model, ζ, track=...) gives ζ at the longest span's n₀ and at the decks'
    cut-off 9 n₀(15 m), and the very factors a sweep's passage gives the same model (before:
    anchors 2.666 and 30 Hz, α, β = 0.615, 1.95e-4 for 15 + 30 m, where the passage has 0.652,
    6.45e-5; 10.66 and 42.66 Hz for 15 + 15 m)."""
    model, track = decks(spans)
    alpha, beta = rayleigh_damping(model, ZETA, track=track)
    assert model.rayleigh_factors == (alpha, beta)
    anchors = [n_k(max(spans)), 9 * n_k(15.0)]
    assert rayleigh_ratio(anchors, alpha, beta) == pytest.approx([ZETA, ZETA], rel=2e-3)
    runner = PassageRunner(decks(spans)[0], track, PassageSettings(damping=ZETA), outputs=())
    assert runner.en_cutoff_hz == pytest.approx(9 * n_k(15.0), rel=1e-3)
    np.testing.assert_allclose((alpha, beta), runner.model.rayleigh_factors, rtol=1e-9)


@pytest.mark.parametrize("spans", PAIRS.values(), ids=PAIRS.keys())
def test_modal_bridge_default_basis_is_the_passages(spans):
    """ModalBridge(model, track) keeps the modes up to 1.1 × the decks' cut-off (105.6 Hz): every
    bending mode k² n₀(L) of each deck below it (15 + 30 m: 6 + 3 = 9 modes, before 4, up to 24.0
    Hz; 15 + 15 m: 3 + 3, before 4, up to 42.66 Hz), the same as a modal sweep's basis."""
    model, track = decks(spans)
    modal = ModalBridge(model, Track(model, track), zeta=ZETA)
    f_max = CUTOFF_MARGIN * 9 * n_k(15.0)
    expected = np.sort([n_k(L, k) for L in spans for k in range(1, 10) if n_k(L, k) <= f_max])
    np.testing.assert_allclose(modal.frequencies, expected, rtol=3e-3)
    runner = PassageRunner(decks(spans)[0], track, PassageSettings(bridge="modal", damping=ZETA), outputs=())
    np.testing.assert_allclose(modal.frequencies, runner.modal.frequencies, rtol=1e-9)


def test_animation_aliasing_reads_the_stiffest_decks_n0(tmp_path, caplog, monkeypatch):
    """Frames 0.05 s apart resolve the 30 m deck's 2.666 Hz (a quarter period 0.094 s) and not
    the 15 m deck's 10.66 Hz (0.023 s): the warning names 10.66 Hz and the max_frames 4 n₀ T + 1
    that resolves it (before: no warning, the model's first frequency 2.666 Hz read)."""
    model, track = decks([15.0, 30.0])
    sweep = Sweep(SweepBridge(model, track, {"kind": "two decks"}), ["HSLM-A1"], "300",
                  PassageSettings(dt=2e-3, damping=0.01, bridge="modal"))
    path = tmp_path / "r.h5"
    sweep.run(path, workers=1, progress=False)
    sweep.record_histories(path, [("HSLM-A1", 300.0, -1)])
    drawn = []

    def animate(scene, out, times, *args, **kwargs):      # no rendering: the warning comes before it
        drawn.append(out)
        return out

    monkeypatch.setattr(scene3d.PassageScene, "animate", animate)
    times = SweepResults(path).history("HSLM-A1", 300.0, -1)["deck_displacement"][0]
    duration = times[-1] - times[0]
    frames = int(round(duration / 0.05)) + 1
    with caplog.at_level(logging.WARNING, logger="vtsi.scene3d"):
        scene3d.animate_case(path, tmp_path / "a.gif", max_frames=frames)
    assert drawn
    assert "(10.7 Hz, the highest of the decks' n0)" in caplog.text
    resolving = int(caplog.text.split("max_frames >= ")[1].split()[0])
    assert resolving == pytest.approx(4 * n_k(15.0) * duration + 1, abs=1.01)
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="vtsi.scene3d"):
        scene3d.animate_case(path, tmp_path / "a.gif", max_frames=resolving)
    assert "aliased" not in caplog.text


BAD = [
    ("a text track", lambda m, t: rayleigh_damping(m, ZETA, track="rail"),
     r"^bridge frequencies: track must be a vtsi.track.Track or the tags of its elements, got 'rail'$"),
    ("a missing element", lambda m, t: rayleigh_damping(m, ZETA, track=[1, 999]), r"^track: element 999 does not exist$"),
    ("frequencies and a track", lambda m, t: rayleigh_damping(m, ZETA, (3.0, 40.0), track=t),
     r"^damping: give frequencies_hz or track \(whose bridge frequencies give the default\), not both$"),
    ("no model", lambda m, t: bridge_frequencies(None, t), r"^bridge frequencies: model must be a vtsi.Model, got None$"),
    ("a modal bridge's track as tags", lambda m, t: ModalBridge(m, t[:2]),
     r"^modal bridge: track must be a vtsi.track.Track or None, got \[1, 2\]$"),
    ("two frequencies a deck", lambda m, t: decks_cutoff_hz([[10.0, 40.0]]),
     r"^EN 1990 A2.4.4.2.1: the cut-off of decks needs each deck's n0, n2, n3 \[Hz\], \(n_decks, 3\), got \[\[10.0, 40.0\]\]$"),
    ("text frequencies", lambda m, t: decks_cutoff_hz("fast"),
     r"^EN 1990 A2.4.4.2.1: the cut-off of decks needs each deck's n0, n2, n3 \[Hz\], \(n_decks, 3\), got 'fast'$"),
    ("a deck's frequencies out of order", lambda m, t: decks_cutoff_hz([[10.0, 40.0, 90.0], [3.0, 2.0, 24.0]]),
     r"^EN 1990 A2.4.4.2.1: the cut-off needs the first three vertical frequencies > 0 \[Hz\], in increasing order"),
]


@pytest.mark.parametrize("call, message", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_inputs_are_named(call, message):
    model, track = decks([15.0, 30.0])
    with pytest.raises(vtsi.ModelError, match=message):
        call(model, track)
