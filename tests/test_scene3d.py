"""The 3-D passage scene (vtsi.scene3d, docs/scene3d.md).

Rendering tests run when off-screen rendering works here (``rendering_available()``, probed in a
subprocess: VTK segfaults without a GL library) and are skipped with its reason otherwise,
except on CI (``CI=true``), which installs libosmesa6 and where they must run: there an
unavailable renderer fails the test. The input checks need no renderer.

The synthetic case: a 20 m simply supported span, deck deflection a half-sine of 10 mm, a
2-car train (4 axles a car, 25 m cars) with its front car half on the bridge.
"""
import os

import numpy as np
import pytest

from vtsi import scene3d
from vtsi.errors import ModelError, SweepError
from vtsi.scene3d import PassageScene, rendering_available

SPAN, CAR, AXLES = 20.0, 25.0, (2.5, 5.0, 20.0, 22.5)   # [m]; axle offsets behind a car's front
WINDOW = (400, 180)                                      # [px] small: the tests stay fast
X = np.linspace(0.0, SPAN, 21)
SAG = -0.010 * np.sin(np.pi * X / SPAN)                  # [m] half-sine, 10 mm down at midspan


def train(front):
    """Wheel x (8,) and car bounds (2, 2) of the 2-car train whose front is at ``front`` [m]."""
    fronts = np.array([front, front - CAR - 0.5])
    wheels = (fronts[:, None] - np.array(AXLES)[None, :]).ravel()
    return wheels, np.stack([fronts, fronts - CAR], axis=1)


WHEELS, CARS = train(SPAN / 2 + CAR / 2)                 # front car: half of it on the bridge


def require_rendering():
    """Skip with the reason when rendering is unavailable; fail instead on CI (CI=true)."""
    ok, reason = rendering_available()
    if not ok:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"CI=true but off-screen rendering is unavailable: {reason}")
        pytest.skip(reason)


@pytest.fixture(scope="module")
def scene():
    return PassageScene(X, [0.0, SPAN], deck_depth=1.5, deck_width=6.0)


def _deck_box(scene, window):
    """Pixel box (rows, cols) around the deck: the picture of the deck line's midspan region."""
    return slice(int(0.25 * window[1]), int(0.85 * window[1])), slice(int(0.3 * window[0]), int(0.7 * window[0]))


def test_png_of_a_passage(scene, tmp_path):
    require_rendering()
    iio = pytest.importorskip("imageio.v3")
    sagging = scene.render_png(tmp_path / "sag.png", SAG, WHEELS, CARS, time=1.234, title="test",
                               window_size=WINDOW)
    flat = scene.render_png(tmp_path / "flat.png", np.zeros_like(X), WHEELS, CARS, scale=50.0, time=1.234,
                            title="test", window_size=WINDOW)
    assert sagging == tmp_path / "sag.png"
    with open(sagging, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    a, b = iio.imread(sagging), iio.imread(flat)
    assert a.shape[:2] == (WINDOW[1], WINDOW[0]) and a.shape == b.shape
    assert a[..., :3].std() > 20.0                       # a picture, not a blank window
    rows, cols = _deck_box(scene, WINDOW)
    changed = np.any(a[rows, cols, :3] != b[rows, cols, :3], axis=-1)
    assert changed.mean() > 0.02                         # the deck sags (and changes colour)


def test_gif_of_a_passage(scene, tmp_path):
    require_rendering()
    iio = pytest.importorskip("imageio.v3")
    times = np.linspace(0.0, 1.0, 9)
    fronts = -5.0 + 40.0 * times
    wheels, cars = zip(*(train(f) for f in fronts))
    uy = np.outer(np.sin(np.pi * times), SAG)
    path = scene.animate(tmp_path / "passage.gif", times, uy, np.array(wheels), np.array(cars), fps=10,
                         max_frames=5, window_size=(240, 110))
    frames = iio.imread(path, index=None)
    assert frames.shape[:3] == (5, 110, 240)
    assert not np.array_equal(frames[0], frames[2])


def test_rendering_available_says_why():
    ok, reason = rendering_available()
    assert isinstance(ok, bool) and isinstance(reason, str) and reason
    assert rendering_available() is rendering_available()   # probed once, cached


@pytest.mark.parametrize("args, kwargs, name", [
    (([0.0, 10.0, 5.0], [0.0]), {}, "deck_x"),            # not increasing
    (([0.0, 10.0, 20.0], [25.0]), {}, "supports_x"),      # off the deck
    ((X, [0.0, SPAN]), {"deck_depth": 0.0}, "deck_depth"),
    ((X, [0.0, SPAN]), {"deck_width": -6.0}, "deck_width"),
    ((np.zeros((2, 3)), [0.0]), {}, "deck_x"),
    ((X, [0.0, SPAN]), {"deck_depth": True}, r"deck_depth: expected a positive number, got True"),
    ((X, []), {}, r"supports_x: expected at least 2 values, got 0"),
])
def test_bad_scene(args, kwargs, name):
    with pytest.raises(ModelError, match=name):
        PassageScene(*args, **kwargs)


@pytest.mark.parametrize("kwargs, name", [
    ({"deck_uy": SAG[:-1]}, "deck_uy"),                   # one node short
    ({"wheel_x": WHEELS.reshape(2, 4)}, "wheel_x"),
    ({"car_bounds": CARS[:, :1]}, "car_bounds"),
    ({"scale": 0.0}, "scale"),
    ({"scale": -50.0}, "scale"),
    ({"deck_uy": np.where(X == 10.0, np.nan, SAG)}, "deck_uy"),
    ({"path": "scene.jpg"}, "path"),
    ({"window_size": (400,)}, "window_size"),
    ({"window_size": (100000, 100000)}, r"window_size: expected two integers from 16 to 8192 pixels"),
    ({"path": "folder.png"}, r"path: .*folder.png' is a directory, not a file to write"),
])
def test_bad_picture(scene, tmp_path, kwargs, name):
    args = {"path": tmp_path / "x.png", "deck_uy": SAG, "wheel_x": WHEELS, "car_bounds": CARS} | kwargs
    if isinstance(args["path"], str):
        args["path"] = tmp_path / args["path"]
    (tmp_path / "folder.png").mkdir()
    with pytest.raises(ModelError, match=name):
        scene.render_png(**args)


@pytest.mark.parametrize("kwargs, name", [
    ({"times": [0.0, 1.0, 0.5]}, "times"),
    ({"deck_uy_history": np.zeros((3, X.size + 1))}, "deck_uy_history"),
    ({"wheel_x_history": np.zeros((2, 8))}, "wheel_x_history"),
    ({"car_bounds_history": np.zeros((3, 2, 3))}, "car_bounds_history"),
    ({"scale": -1.0}, "scale"),
    ({"max_frames": 0}, "max_frames"),
    ({"fps": 0}, "fps"),
    ({"path": "passage.avi"}, "path"),
])
def test_bad_animation(scene, tmp_path, kwargs, name):
    args = {"path": tmp_path / "x.gif", "times": [0.0, 0.5, 1.0], "deck_uy_history": np.zeros((3, X.size)),
            "wheel_x_history": np.zeros((3, 8)), "car_bounds_history": None} | kwargs
    if isinstance(args["path"], str):
        args["path"] = tmp_path / args["path"]
    (tmp_path / "folder.png").mkdir()
    with pytest.raises(ModelError, match=name):
        scene.animate(**args)


def test_mp4_without_ffmpeg_names_the_fix(scene, tmp_path, monkeypatch):
    monkeypatch.setattr(scene3d, "_installed", lambda module: module != "imageio_ffmpeg")
    with pytest.raises(RuntimeError, match="imageio-ffmpeg"):
        scene.animate(tmp_path / "x.mp4", [0.0, 1.0], np.zeros((2, X.size)), np.zeros((2, 8)))


def test_unavailable_rendering_raises_with_the_reason(scene, tmp_path, monkeypatch):
    monkeypatch.setattr(scene3d, "rendering_available", lambda: (False, "install libosmesa6"))
    with pytest.raises(RuntimeError, match="install libosmesa6"):
        scene.render_png(tmp_path / "x.png", SAG, WHEELS, CARS)


def test_scene_and_animation_of_a_recorded_case(tmp_path, caplog):
    """render_case / animate_case read a sweep's results file: the governing case's deck history;
    3 frames over the passage alias a 5 Hz deck's vibration, and a warning says so."""
    require_rendering()
    import imageio.v3 as iio

    from vtsi.check import check
    from vtsi.scene3d import animate_case, render_case
    from vtsi.passage import PassageSettings
    from vtsi.sweep import Sweep, beam_bridge

    EI = 15000.0 * (2 * np.pi * 5.0 * (SPAN / np.pi) ** 2) ** 2
    sweep = Sweep(beam_bridge([SPAN], EI, 1.0, 15000.0, 4), ["HSLM-A1"], "300,320", PassageSettings(dt=0.01))
    path = tmp_path / "r.h5"
    sweep.run(path, workers=1, progress=False)
    result = check(path)
    result.store(path)
    row = result.row("deck_acceleration")
    sweep.record_histories(path, [(row.train, row.speed_kmh, row.seed)])
    png = render_case(path, tmp_path / "s.png", window_size=(400, 180))
    assert iio.imread(png.path).shape[:2] == (180, 400)          # a RenderedScene: os.PathLike, imageio wants a Path
    gif = animate_case(path, tmp_path / "s.gif", max_frames=3, window_size=(400, 176))
    assert iio.imread(gif.path, index=None).shape[0] == 3 == gif.frames      # a RenderedAnimation, as above
    assert "the deck's vibration is aliased; max_frames >= " in caplog.text
    assert gif.aliasing and gif.aliasing in caplog.text
    with pytest.raises(ModelError, match=r"render_case: time 1e\+06 s is outside the recorded passage"):
        render_case(path, tmp_path / "t.png", time=1e6)
    with pytest.raises(ModelError, match=r"render_case: time \[s\] must be a number, got 'x'"):
        render_case(path, tmp_path / "t.png", time="x")
    with pytest.raises(SweepError, match=r"scene: train 'ICE9' is not in the sweep .* \(trains: HSLM-A1\)"):
        render_case(path, tmp_path / "t.png", train="ICE9")
    with pytest.raises(SweepError, match=r"scene: speed_kmh = 300 km/h without a train"):    # it drew another case
        render_case(path, tmp_path / "t.png", speed_kmh=300.0)
    assert not (tmp_path / "t.png").exists()
