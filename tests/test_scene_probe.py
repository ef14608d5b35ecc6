"""The 3-D scene against the visual probe's findings (/tmp/probe_vis/FINDINGS.md) and the car
bodies' stored histories:

* M1: two simply supported decks on one pier are drawn as two decks (a box and a spline each,
  the joint open, a bearing under each deck's end), a continuous deck as before;
* M2: a train of cars is drawn with its car bodies, and the title names the rail sample;
* M3: animate_case takes ceil(4 n₀ T) + 1 frames by default (capped, with a warning), an
  explicit max_frames as before; a frame places copies of one wheelset (no cylinders per axle);
* M5: a car's stored acceleration history is one point's continuous signal, its envelopes
  unchanged;
* C1: the colour bar's labels are larger and the length bar stands clear of the footings.

What is drawn is checked on the meshes a frame is made of (PassageScene._moving) and on the
arguments render_case / animate_case hand to the scene, not on pixels. Rendering runs only where
off-screen rendering works (as tests/test_scene3d.py).
"""
import logging
import math
import os
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from vtsi import scene3d
from vtsi.passage import BodyPoints, Output, PassageRunner, PassageSettings
from vtsi.scene3d import PassageScene, _Frame, _Look, car_body_offsets
from vtsi.sweep import Sweep, beam_bridge



def require_rendering():
    """Skip with the reason when rendering is unavailable; fail instead on CI (CI=true)."""
    ok, reason = scene3d.rendering_available()
    if not ok:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"CI=true but off-screen rendering is unavailable: {reason}")
        pytest.skip(reason)

pv = pytest.importorskip("pyvista")

MU = 15000.0


def _ei(span, f1):
    return MU * (2 * np.pi * f1 * (span / np.pi) ** 2) ** 2


def _deck_regions(mesh):
    """(n boxes, their x extents) of the deck mesh of a frame: a box has two end faces (all their
    points at one x), one at each end."""
    x = np.asarray(mesh.points)[:, 0]
    faces = mesh.regular_faces                                  # the boxes' faces are quads
    caps = sorted(float(x[f[0]]) for f in faces if np.ptp(x[f]) < 1e-9 and np.ptp(mesh.points[f][:, 1]) > 0)
    return len(caps) // 2, [(a, b) for a, b in zip(caps[0::2], caps[1::2])]


def _meshes(scene, uy, wheels=(), cars=None):
    return scene._moving(pv, _Frame(np.asarray(uy, dtype=float), np.asarray(wheels, dtype=float), cars),
                         _Look(100.0, (-1.0, 1.0), (-30.0, 60.0)))


# --------------------------------------------------------------------------------------------
# M1: decks


TWO = np.r_[np.linspace(0.0, 17.7, 13), np.linspace(18.3, 36.0, 13)]    # the probe's b3: a 0.6 m joint
TWO_ENDS = [[0.0, 17.7], [18.3, 36.0]]


def test_two_decks_are_two_boxes_with_an_open_joint_and_a_bearing_each():
    """b3: one box 0-36 m, one spline through both decks' nodes, the two bearing lines one block.
    Now a box and a spline per deck, the joint open, both bearings on one pier, each under its
    own deck's end."""
    scene = PassageScene(TWO, [0.0, 17.7, 18.3, 36.0], deck_ends=TWO_ENDS)
    uy = np.r_[-0.002 * np.sin(np.pi * TWO[:13] / 17.7), 0.001 * np.sin(np.pi * (TWO[13:] - 18.3) / 17.7)]
    n, extents = _deck_regions(_meshes(scene, uy)["deck"])
    assert n == 2 and extents == [pytest.approx((0.0, 17.7)), pytest.approx((18.3, 36.0))]
    # each deck's line is its own spline: deck 2's displacements do not move deck 1's line
    x1 = np.linspace(0.0, 17.7, 50)
    other = uy.copy()
    other[13:] *= -5.0
    np.testing.assert_allclose(scene.deck_line(uy, x1), CubicSpline(TWO[:13], uy[:13])(x1), atol=1e-15)
    np.testing.assert_allclose(scene.deck_line(other, x1), scene.deck_line(uy, x1), atol=1e-15)
    # across the joint the rail runs straight from one deck's end to the next's start
    assert scene.rail_top(uy, 1.0, [18.0])[0] == pytest.approx(0.5 * (uy[12] + uy[13]), abs=1e-15)
    # one pier for the two bearing lines; a bearing under each deck, none in the joint
    assert [len(g) for g in scene._piers(1.0)] == [1, 2, 1]
    bearings = scene._bearings()
    assert len(bearings) == 4
    assert bearings[1] == pytest.approx((17.1, 17.7)) and bearings[2] == pytest.approx((18.3, 18.9))


def test_two_decks_ending_at_one_x_split_their_nodes():
    """Two decks whose end nodes share x = 15 (two nodes there): each deck's line takes its own
    end node; without deck_ends the nodes are one deck, the first node's value drawn, as before."""
    x = np.r_[np.linspace(0.0, 15.0, 11), np.linspace(15.0, 30.0, 11)]
    uy = np.r_[np.full(11, -0.001), np.full(11, 0.002)]
    scene = PassageScene(x, [0.0, 15.0, 30.0], deck_ends=[[0.0, 15.0], [15.0, 30.0]])
    assert scene.deck_line(uy, [14.999999])[0] == pytest.approx(-0.001)
    assert scene.deck_line(uy, [15.000001])[0] == pytest.approx(0.002)
    assert len(scene._bearings()) == 4                      # at x = 15 one under each deck
    assert _deck_regions(_meshes(scene, uy)["deck"])[0] == 2
    one = PassageScene(x, [0.0, 15.0, 30.0])
    assert one.deck_line(uy, [15.0])[0] == pytest.approx(-0.001)


def test_a_continuous_deck_is_drawn_as_before():
    """b2 (3 × 25 m continuous): one box, one not-a-knot spline through every node; deck_ends of
    one deck change nothing."""
    x = np.linspace(0.0, 75.0, 31)
    uy = 0.004 * np.sin(2 * np.pi * x / 50.0)
    scene = PassageScene(x, [0.0, 25.0, 50.0, 75.0])
    same = PassageScene(x, [0.0, 25.0, 50.0, 75.0], deck_ends=[[0.0, 75.0]])
    xs = np.linspace(0.0, 75.0, 301)
    np.testing.assert_allclose(scene.deck_line(uy, xs), CubicSpline(x, uy)(xs), atol=1e-15)
    np.testing.assert_array_equal(scene._xs, same._xs)
    a, b = _meshes(scene, uy)["deck"], _meshes(same, uy)["deck"]
    np.testing.assert_array_equal(a.points, b.points)
    assert _deck_regions(a)[0] == 1
    assert [len(g) for g in scene._piers(1.8)] == [1, 1, 1, 1]


@pytest.mark.parametrize("ends, message", [
    ([[0.0, 20.0], [10.0, 36.0]], r"deck_ends: deck 2 \(10 to 36 m\) starts before deck 1"),
    ([[0.0, 0.5], [18.3, 36.0]], r"deck_ends: deck 1 \(0 to 0.5 m\) holds 1 node of deck_x; a deck needs two"),
    ([[5.0, 5.0]], r"deck_ends: deck 1 runs from 5 to 5 m: no length"),
    ([[0.0, 17.7, 3.0]], r"deck_ends: expected shape \(any, 2\)"),
])
def test_bad_deck_ends(ends, message):
    from vtsi.errors import ModelError

    with pytest.raises(ModelError, match=message):
        PassageScene(TWO, [0.0, 36.0], deck_ends=ends)


def test_a_recorded_case_of_two_decks_is_drawn_per_deck(tmp_path):
    """The results file's /bridge/deck_ends_m reaches the scene (b3 drew one deck)."""
    pytest.importorskip("tkinter")
    from vtsi.bridge_file import load_bridge

    script = tmp_path / "two.tcl"      # two 15 m decks (10 elements, 15 t/m), nodes 1-11 and 12-22, both at x = 15
    lines = ["model basic -ndm 2 -ndf 3", "geomTransf Linear 1"]
    for node, x0 in ((1, 0.0), (12, 15.0)):
        lines += [f"for {{set i 0}} {{$i <= 10}} {{incr i}} {{ node [expr {{$i + {node}}}] [expr {{{x0} + $i * 1.5}}] 0.0 }}",
                  f"fix {node} 1 1 0", f"fix {node + 10} 0 1 0",
                  f"for {{set i 0}} {{$i < 10}} {{incr i}} {{ element elasticBeamColumn [expr {{$i + {node}}}] "
                  f"[expr {{$i + {node}}}] [expr {{$i + {node + 1}}}] 5.0 3.5e10 1.0 1 -mass 15000.0 -cMass }}"]
    script.write_text("\n".join(lines + ["track 1 -eleRange 1 21", ""]))
    sweep = Sweep(load_bridge(script, min_mass_per_metre=0), ["HSLM-A1"], "300", PassageSettings(dt=4e-3, damping=0.01))
    path = tmp_path / "two.h5"
    sweep.run(path, workers=1, progress=False)
    sweep.record_histories(path, [("HSLM-A1", 300, -1)])
    *_, history, scene = scene3d._recorded_case(path, "HSLM-A1", 300, -1)
    np.testing.assert_allclose(scene.deck_ends, [[0.0, 15.0], [15.0, 30.0]], atol=1e-9)
    _, uy, _ = history["deck_displacement"]
    assert _deck_regions(_meshes(scene, uy[len(uy) // 2])["deck"])[0] == 2


# --------------------------------------------------------------------------------------------
# M2, M3, M5: a train of cars on an irregular rail


@pytest.fixture(scope="module")
def cars(tmp_path_factory):
    """ICE3 (multibody cars) at 300 km/h over a 20 m, 5 Hz span on a 'german-high' rail, two rail
    samples, with the histories of sample 1 recorded."""
    path = tmp_path_factory.mktemp("cars") / "cars.h5"
    settings = PassageSettings(dt=2e-3, damping=0.013, cars="full", contact="lcp", irregularity="german-high")
    sweep = Sweep(beam_bridge([20.0], _ei(20.0, 5.0), 1.0, MU, elements_per_span=4), ["ICE3"], "300", settings,
                  seeds=[0, 1])
    sweep.run(path, workers=1, progress=False)
    sweep.record_histories(path, [("ICE3", 300, 1)])
    return sweep, path


def _captured(monkeypatch, method):
    """Replace PassageScene.``method`` by a recorder of its arguments (nothing is rendered)."""
    calls = []

    def capture(self, path, *args, **kwargs):
        calls.append((self, args, kwargs))
        return path
    monkeypatch.setattr(PassageScene, method, capture)
    return calls


def test_car_body_offsets_from_the_train_data():
    """Two cars of 4 axles: the head is the first car's front, cars meet half-way between their
    axles (0.5 m apart), the last car's rear as far behind its last axle as the first axle is
    behind the head. Moving forces (n_dof = 0) have no bodies."""
    data = {"axle_offsets_m": np.array([3.0, 5.5, 20.0, 22.5, 28.0, 30.5, 45.0, 47.5]),
            "wheel_car": np.repeat([0, 1], 4), "n_dof": 20}
    np.testing.assert_allclose(car_body_offsets(data), [[0.0, 25.0], [25.5, 50.5]])
    assert car_body_offsets(data | {"n_dof": 0}) is None


def test_a_train_of_cars_is_drawn_with_its_bodies_and_its_rail_sample(cars, tmp_path, monkeypatch):
    """b5: bare wheelsets and 'ICE3 at 360 km/h' for a sweep of two rail samples. Now the bodies
    (one per car, around its axles) and ', rail sample 1'."""
    _, path = cars
    calls = _captured(monkeypatch, "render_png")
    scene3d.render_case(path, tmp_path / "c.png", train="ICE3", speed_kmh=300, seed=1)
    scene, (uy, wheels, bodies), kwargs = calls[0]
    assert kwargs["title"] == "ICE3 at 300 km/h, rail sample 1"
    assert bodies.shape == (8, 2)
    for car in range(8):              # each car's 4 axles lie within its body
        mine = wheels[4 * car: 4 * car + 4]
        assert np.all((mine < bodies[car, 0]) & (mine > bodies[car, 1]))
    meshes = _meshes(scene, uy, wheels, bodies)
    assert meshes["bodies"].connectivity().split_bodies().n_blocks == 8
    calls = _captured(monkeypatch, "animate")
    scene3d.animate_case(path, tmp_path / "c.gif", train="ICE3", speed_kmh=300, seed=1)
    scene, (times, uy, wheels, bodies), kwargs = calls[0]
    assert bodies.shape == (len(times), 8, 2) and kwargs["title"].endswith(", rail sample 1")


def test_the_default_animation_resolves_the_first_mode(cars, tmp_path, monkeypatch, caplog):
    """max_frames=60 aliased every passage longer than 15 periods of n₀ with a warning only. Now
    ceil(4 n₀ T) + 1 frames by default, capped at MAX_ANIMATION_FRAMES (then a warning), and an
    explicit max_frames kept."""
    _, path = cars
    calls = _captured(monkeypatch, "animate")
    from vtsi.sweep_results import SweepResults, deck_first_frequencies

    times = SweepResults(path).history("ICE3", 300, 1)["deck_displacement"][0]
    n0 = float(np.max(deck_first_frequencies(SweepResults(path).bridge())))
    needed = math.ceil(4 * n0 * (times[-1] - times[0])) + 1
    with caplog.at_level(logging.WARNING, logger="vtsi.scene3d"):
        scene3d.animate_case(path, tmp_path / "a.gif", train="ICE3", speed_kmh=300, seed=1)
        assert calls[-1][2]["max_frames"] == needed and needed > 60
        assert "aliased" not in caplog.text
        drawn = scene3d.animate_case(path, tmp_path / "a.gif", train="ICE3", speed_kmh=300, seed=1, max_frames=7)
        assert calls[-1][2]["max_frames"] == 7 and f"max_frames >= {needed} resolves it" in caplog.text
        assert os.fspath(drawn) == os.fspath(tmp_path / "a.gif")
        assert (drawn.frames, drawn.resolving_frames) == (7, needed)
        assert drawn.spacing_s == pytest.approx((times[-1] - times[0]) / 6) and drawn.n0_hz == n0
        assert drawn.aliasing and drawn.aliasing in caplog.text        # the report's caption repeats the warning
        caplog.clear()
        monkeypatch.setattr(scene3d, "MAX_ANIMATION_FRAMES", 20)
        scene3d.animate_case(path, tmp_path / "a.gif", train="ICE3", speed_kmh=300, seed=1)
        assert calls[-1][2]["max_frames"] == 20 and f"max_frames >= {needed} resolves it" in caplog.text


def test_a_frame_places_copies_of_one_wheelset():
    """A frame built 3 cylinders per axle (150 for 50 axles: half of a frame's time); now it
    places copies of one wheelset: the same wheels."""
    scene = PassageScene(np.linspace(0.0, 20.0, 11), [0.0, 20.0])
    uy = -0.002 * np.sin(np.pi * np.linspace(0.0, 20.0, 11) / 20.0)
    wheels = np.array([-3.0, 4.0, 12.5])
    mesh = _meshes(scene, uy, wheels)["wheels"]
    contact = scene.rail_top(uy, 100.0, wheels)
    parts = []
    for x, y in zip(wheels, contact):
        for z in (-scene3d.GAUGE / 2 - 0.03, scene3d.GAUGE / 2 + 0.03):
            parts.append(pv.Cylinder(center=(x, y + scene3d.WHEEL_RADIUS, z), direction=(0, 0, 1),
                                     radius=scene3d.WHEEL_RADIUS, height=scene3d.WHEEL_WIDTH, resolution=28))
        parts.append(pv.Cylinder(center=(x, y + scene3d.WHEEL_RADIUS, 0.0), direction=(0, 0, 1), radius=0.09,
                                 height=scene3d.GAUGE, resolution=12))
    built = pv.merge(parts)
    assert mesh.n_points == built.n_points and mesh.n_cells == built.n_cells
    np.testing.assert_allclose(mesh.bounds, built.bounds, atol=1e-9)
    assert mesh.connectivity().split_bodies().n_blocks == built.connectivity().split_bodies().n_blocks


def _old_body_points(self, train, values, counted):
    """PassageRunner._body_points before: the history was the envelopes' spliced signal."""
    largest = self._body_points_new(train, values, counted).largest
    return BodyPoints(largest, largest, np.zeros(largest.shape[1], dtype=np.int64))


def test_a_car_history_is_one_point_and_the_envelopes_are_unchanged(cars, monkeypatch):
    """b5: the stored history kept at each step the point with the largest |a|, and jumped by
    1.1 m/s² within 1 ms when another point took over. Now it is the governing point's own
    history; the envelopes (min, max, absmax and times, on the bridge and over the whole run)
    are exactly the same as before."""
    sweep, _ = cars
    runner = sweep.runner
    output = Output("car_body_acceleration", "car_body_accel", history=True)
    new = runner.run("ICE3", 300, 1, outputs=[output])
    monkeypatch.setattr(PassageRunner, "_body_points_new", PassageRunner._body_points, raising=False)
    monkeypatch.setattr(PassageRunner, "_body_points", _old_body_points)
    old = runner.run("ICE3", 300, 1, outputs=[output])
    name = output.name
    np.testing.assert_array_equal(new.envelopes[name], old.envelopes[name])
    np.testing.assert_array_equal(new.whole_run[name], old.whole_run[name])
    t, spliced = old.histories[name]
    _, kept = new.histories[name]
    assert not np.array_equal(kept, spliced)
    jump = lambda a: np.max(np.abs(np.diff(a, axis=0)))      # noqa: E731
    assert jump(kept) < 0.5 * jump(spliced)
    # each car's history is one point, the one with the car's largest |a| where the envelope counts
    train = runner.train("ICE3", 300 / 3.6)
    counted = runner.counted(output, train, runner.start_position(train), t)
    peak = np.array([np.max(np.abs(kept[counted[:, c], c])) for c in range(kept.shape[1])])
    np.testing.assert_allclose(peak, new.envelopes[name][2], rtol=0, atol=0)
    for c in range(kept.shape[1]):
        same = np.isclose(kept[:, c], spliced[:, c], rtol=0, atol=0)
        assert np.all(np.abs(kept[~same, c]) <= np.abs(spliced[~same, c]))    # never above the largest point


# --------------------------------------------------------------------------------------------
# C1: labels


def test_the_aliasing_warning_names_the_frequency_it_reads_and_why():
    """The warning called 13.1 Hz, the highest of two decks' n0, 'the first mode' when the model's
    first mode was 9.485 Hz: it names the stiffest deck's n0 and says why that one; one deck's,
    its n0. 40 frames over 3.44 s: 3.44 / 39 = 0.0882 s apart; a quarter period of 13.06 Hz is 0.0191 s."""
    text = scene3d._aliasing_text(3.44 / 39, np.array([13.06, 9.485]), 9.485, 182)
    assert text == ("frames 0.0882 s apart, more than a quarter period (0.0191 s) of the stiffest deck's first "
                    "vertical frequency (13.1 Hz, the highest of the decks' n0): each deck vibrates at its own n0, so "
                    "the frames must resolve the highest, not the model's first mode (9.485 Hz); the deck's vibration "
                    "is aliased; max_frames >= 182 resolves it (vtsi check: --animation-frames 182)")
    one = scene3d._aliasing_text(0.1, np.array([5.0]), 5.0, 91)
    assert "of the deck's first vertical frequency (n0 = 5 Hz); " in one and "first mode" not in one


def test_the_length_bar_is_the_round_length_the_docs_state():
    """docs/scene3d.md said 'about 0.3 × the bridge'; _nice rounds down: the largest 1, 2 or 5 ×
    10^k m not longer than 0.3 × the bridge, so 0.12 to 0.3 × it (5 m for 20 m, 10 m for 35 m)."""
    docs = (Path(__file__).parents[1] / "docs" / "scene3d.md").read_text(encoding="utf-8")
    assert "the largest 1, 2 or 5 × 10ᵏ m not longer than 0.3 × the bridge" in docs
    for length, bar in ((20.0, 5.0), (35.0, 10.0)):
        assert "5 m for a 20 m bridge, 10 m for 35 m" in docs
        assert PassageScene(np.linspace(0.0, length, 11), [0.0, length])._scale_bar_place()[2] == bar
    for length in np.geomspace(3.0, 3000.0, 57):
        bar = PassageScene(np.linspace(0.0, length, 11), [0.0, length])._scale_bar_place()[2]
        mantissa = bar / 10.0 ** math.floor(math.log10(bar))
        assert 0.12 * length < bar <= 0.3 * length * (1 + 1e-12)
        assert min(abs(mantissa - m) for m in (1.0, 2.0, 5.0)) < 1e-9


def test_the_length_bar_stands_clear_of_the_footings_and_labels_are_larger(tmp_path):
    """b4: the '5 m' label sat on a pier's footing; colour-bar labels were 8-10 px tall."""
    scene = PassageScene(np.linspace(0.0, 32.0, 17), [4.0, 28.0], deck_ends=[[0.0, 32.0]])
    _, z, _, _ = scene._scale_bar_place()
    assert z > scene.deck_width / 2 + 0.5 + 0.4 + 1.0          # in front of the widest footing (abutments')
    require_rendering()
    window = (800, 350)
    plotter = scene3d._plotter(scene3d._pyvista(), window)
    try:
        look = scene._look([scene._frame(np.zeros(17), np.zeros(0), None, None)], None, "t")
        scene._setup(pv, plotter, look, window)
        bar = next(iter(plotter.scalar_bars.values()))
        assert bar.GetLabelTextProperty().GetFontSize() >= 1.8 * scene3d._font(window) - 0.5
        assert bar.GetUnconstrainedFontSize()
    finally:
        plotter.close()
