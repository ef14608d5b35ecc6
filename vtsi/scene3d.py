"""A 3-D scene of a train passage: the deformed bridge and the train on it, as a PNG or an
animation (GIF, MP4), rendered off-screen with pyvista (extra ``plot``; docs/scene3d.md).

The scene takes arrays only (it does not know how they were computed):

* the deck: node positions ``deck_x`` (n_nodes,) [m, increasing] and, per picture, their
  vertical displacements ``deck_uy`` (n_nodes,) [m, positive up], interpolated between the
  nodes by a cubic spline and exaggerated by ``scale``; optionally the ends of each of several
  decks ``deck_ends`` (n_decks, 2) [m]: one box and one spline per deck, the joints between
  them open (the track bridges them in a straight line);
* the supports: their positions ``supports_x`` [m] (abutments at the bridge's ends, piers
  between; supports closer than a pier's width, the bearings of two decks on one pier, share
  one pier, with a bearing under each deck);
* the train: wheel positions ``wheel_x`` (n_wheels,) [m] and optionally the front and rear
  ends of every car body ``car_bounds`` (n_cars, 2) [m].

Coordinates: x along the track, y up, z across it (the 2-D model is drawn extruded in z). The
rail top at rest is y = 0; a wheel on the deck rides on the deformed (exaggerated) rail, a wheel
off the deck on rigid ground at y = 0.

Off-screen rendering (docs/scene3d.md): VTK segfaults rather than raising when it finds no OpenGL
library, so :func:`rendering_available` first renders a tiny scene in a subprocess, with
``VTK_DEFAULT_OPENGL_WINDOW=vtkOSOpenGLRenderWindow`` (OSMesa, Debian's ``libosmesa6``) unless
the variable is set already, then VTK's own default window; the first that works is used in
this process too. Rendering calls raise a :class:`RuntimeError` with its reason when none does.
"""
import ctypes.util
import functools
import importlib.util
import logging
import math
import os
import re
import reprlib
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from vtsi.check import stored_check
from vtsi.errors import ModelError, SweepError, as_number, is_number, number_array
from vtsi.sweep_results import SweepResults, case_key, deck_first_frequencies, deck_ranges

logger = logging.getLogger(__name__)

WINDOW_VARIABLE = "VTK_DEFAULT_OPENGL_WINDOW"
OSMESA_WINDOW = "vtkOSOpenGLRenderWindow"
PROBE_TIMEOUT = 120.0   # [s]
MAX_PIXELS = 8192       # the largest window side [px]: VTK aborts the process when it cannot allocate
INSTALL_HINT = ("install OSMesa (Debian/Ubuntu: apt-get install libosmesa6) and pyvista "
                "(pip install 'vtsi[plot]'), and set VTK_DEFAULT_OPENGL_WINDOW=vtkOSOpenGLRenderWindow")

# Dimensions of the drawn track and train [m]: a standard-gauge track on a ballast bed, and
# car bodies of a European passenger coach. They only dress the picture.
GAUGE = 1.435
RAIL_HEIGHT = 0.17
TRACK_BED = 0.55            # rail top above the deck top (rail, sleeper, ballast)
BALLAST_WIDTH = 3.6
WHEEL_RADIUS = 0.46
WHEEL_WIDTH = 0.14
BODY_WIDTH = 2.9
BODY_FLOOR = 1.0            # body floor above the rail top
BODY_HEIGHT = 3.0
BEARING = 0.15              # bearing height under the deck
TARGET_DEPTHS = 0.5         # default scale: the largest |uy| shows as this many deck depths
BEARING_LENGTH = 0.6        # a bearing's length along x [m], under its deck
MAX_ANIMATION_FRAMES = 400  # animate_case's cap on the frames it chooses (4 n0 T + 1) by default
SCENE_CASE_KEYS = ("train", "speed_kmh", "seed", "time_s", "scale")   # what a scene draws: RenderedScene.case

# Colours (sRGB hex).
CONCRETE = "#b5b2aa"
CONCRETE_DARK = "#8f8c85"
GHOST = "#5a5d62"
GROUND = "#9fae84"
EMBANKMENT = "#8c9d74"
SOIL = "#8a7a62"
BALLAST = "#7d7a73"
RAIL = "#4a4d52"
WHEEL = "#50545a"
BOGIE = "#2e3136"
BODY = "#eef0f2"
BODY_BAND = "#1f4e79"
WINDOWS = "#39424e"
TEXT = "#1b1f24"
DECK_CMAP = "coolwarm"

PROBE = """
import sys
import pyvista as pv
pv.OFF_SCREEN = True
p = pv.Plotter(off_screen=True, window_size=(64, 48))
p.add_mesh(pv.Sphere(), color="red")
img = p.screenshot(return_img=True)
name = p.render_window.GetClassName()
p.close()
if img.shape[:2] != (48, 64) or float(img.std()) <= 0.0:
    sys.exit("the probe rendered a blank image of shape " + str(img.shape))
print("ok", name)
"""


def _installed(module):
    """Whether the top-level ``module`` can be imported (without importing it)."""
    return importlib.util.find_spec(module) is not None


def _log_message(line):
    """A line of VTK's log without its colour codes and its 'date (time) [thread] file:line WARN|'
    prefix."""
    line = re.sub(r"\x1b\[[0-9;]*m", "", line).strip()
    return line.rsplit("| ", 1)[-1].strip() if re.search(r"\b(WARN|ERR|INFO)\s*\|", line) else line


def _probe(window):
    """Render a tiny scene in a subprocess with ``VTK_DEFAULT_OPENGL_WINDOW=window`` (None: the
    variable unset, VTK's default). Returns ``(window class used or None, message)``."""
    env = dict(os.environ)
    if window is None:
        env.pop(WINDOW_VARIABLE, None)
    else:
        env[WINDOW_VARIABLE] = window
    label = window or "VTK's default window"
    try:
        done = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True,
                              timeout=PROBE_TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, f"{label}: the probe did not finish within {PROBE_TIMEOUT:g} s"
    out = done.stdout.strip().splitlines()
    if done.returncode == 0 and out and out[-1].startswith("ok "):
        used = out[-1].split()[-1]
        return used, f"off-screen rendering with {used}"
    if done.returncode < 0:
        try:
            how = f"crashed with {signal.Signals(-done.returncode).name}"
        except ValueError:
            how = f"was killed by signal {-done.returncode}"
    else:
        how = f"exited with code {done.returncode}"
    errors = [_log_message(line) for line in done.stderr.splitlines()]
    errors = [e for e in errors if e]
    detail = f": {errors[-1] if len(errors[-1]) <= 160 else errors[-1][:159] + '…'}" if errors else ""
    return None, f"{label}: the probe {how}{detail}"


@functools.cache
def rendering_available():
    """Whether pyvista can render off-screen here: ``(True, how)`` or ``(False, reason)``.

    Probes in a subprocess (VTK segfaults without a GL library): with the user's
    ``VTK_DEFAULT_OPENGL_WINDOW`` if set, else with ``vtkOSOpenGLRenderWindow`` (OSMesa), then
    with VTK's default window. The first window that renders is set in ``os.environ`` for this
    process (VTK may fall back to another window class than the one asked for: the class the
    probe used is set). Cached: ``rendering_available.cache_clear()`` probes again.
    """
    missing = [name for name in ("pyvista", "imageio") if not _installed(name)]
    if missing:
        return False, f"{' and '.join(missing)} not installed: pip install 'vtsi[plot]'"
    user = os.environ.get(WINDOW_VARIABLE)
    windows = [user] if user else [OSMESA_WINDOW, None]
    failures = []
    for window in windows:
        used, message = _probe(window)
        if used:
            os.environ[WINDOW_VARIABLE] = used
            logger.info("scene3d: %s", message)
            return True, message
        failures.append(message)
    osmesa = "" if ctypes.util.find_library("OSMesa") else "libOSMesa not found; "
    return False, f"off-screen rendering unavailable ({'; '.join(failures)}); {osmesa}{INSTALL_HINT}"


def _pyvista():
    """pyvista, set for off-screen rendering, or a RuntimeError naming why it cannot render."""
    ok, reason = rendering_available()
    if not ok:
        raise RuntimeError(f"vtsi.scene3d cannot render: {reason}")
    import pyvista

    pyvista.OFF_SCREEN = True
    return pyvista


# ---------------------------------------------------------------------------------------------
# Input checks


def _vector(name, value, size=None, min_size=0, of=""):
    a = number_array(value)
    if a is None:
        raise ModelError(f"{name}: not an array of numbers: {reprlib.repr(value)}")
    if a.ndim != 1:
        raise ModelError(f"{name}: expected a 1-D array, got shape {a.shape}")
    if size is not None and a.size != size:
        raise ModelError(f"{name}: expected {size} values{f' ({of})' if of else ''}, got shape {a.shape}")
    if a.size < min_size:
        raise ModelError(f"{name}: expected at least {min_size} values, got {a.size}")
    if not np.all(np.isfinite(a)):
        raise ModelError(f"{name}: non-finite value at index {int(np.flatnonzero(~np.isfinite(a))[0])}")
    return a


def _array(name, value, shape):
    """A float array of ``shape`` (None entries: any size)."""
    a = number_array(value)
    if a is None:
        raise ModelError(f"{name}: not an array of numbers: {reprlib.repr(value)}")
    want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
    if a.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, a.shape)):
        raise ModelError(f"{name}: expected shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ModelError(f"{name}: contains non-finite values")
    return a


def _positive(name, value):
    v = float(value) if is_number(value) else math.nan
    if not (math.isfinite(v) and v > 0):
        raise ModelError(f"{name}: expected a positive number, got {value!r}")
    return v


def _window(window_size):
    try:
        w, h = (int(v) for v in window_size)
    except (TypeError, ValueError):
        raise ModelError(f"window_size: expected (width, height) in pixels, got {window_size!r}") from None
    if not (16 <= w <= MAX_PIXELS and 16 <= h <= MAX_PIXELS) or (w, h) != tuple(window_size):
        raise ModelError(f"window_size: expected two integers from 16 to {MAX_PIXELS} pixels, got {window_size!r}")
    return w, h


def nodes_by_deck(deck_x, deck_ends, tol):
    """Per deck (a row of ``deck_ends`` (n_decks, 2) [m], in x order), the indices of the nodes of
    ``deck_x`` [m] on it: those within its ends ± ``tol`` [m]. ``deck_x`` is non-decreasing, nodes
    at one x in the track's order (as /bridge/deck_x_m of a results file); where two decks meet at
    one x (each on its own bearing on one pier) the first node there is the ending deck's, the
    last the starting deck's. Nodes on no deck (an approach, a joint's inner nodes) are in none."""
    x = np.asarray(deck_x, dtype=float)
    ends = np.asarray(deck_ends, dtype=float).reshape(-1, 2)
    decks = [np.flatnonzero((x >= a - tol) & (x <= b + tol)) for a, b in ends]
    for k in range(len(ends) - 1):
        if abs(ends[k + 1, 0] - ends[k, 1]) <= tol:               # two decks meet at one x
            at = np.flatnonzero(np.abs(x - ends[k, 1]) <= tol)
            if at.size >= 2:
                decks[k] = np.setdiff1d(decks[k], at[1:])
                decks[k + 1] = np.setdiff1d(decks[k + 1], at[:-1])
    return decks


def deck_spline(x, uy):
    """A deck's line through its nodes: a callable giving the value at any x [m] of the cubic
    spline (not-a-knot) through the node values ``uy`` at ``x`` [m] (non-decreasing; of nodes at
    one x, within 1e-9 of the deck's length, the first), a straight line through two nodes."""
    x, uy = np.asarray(x, dtype=float), np.asarray(uy, dtype=float)
    first = np.concatenate([[True], np.diff(x) > 1e-9 * max(1.0, float(x[-1] - x[0]))])
    x, uy = x[first], uy[first]
    return CubicSpline(x, uy) if x.size >= 3 else (lambda t: np.interp(t, x, uy))


def _nice(value, down=True, steps=(1, 2, 5, 10)):
    """The number ``step × 10^k`` at or below (``down``) / at or above ``value`` > 0."""
    exponent = math.floor(math.log10(value))
    mantissa = value / 10.0 ** exponent
    if down:
        m = max(s for s in steps if s <= mantissa * (1 + 1e-12))
    else:
        m = min(s for s in steps if s >= mantissa * (1 - 1e-12))
    return m * 10.0 ** exponent


def _one_digit(value):
    """``value`` > 0 rounded down to one significant digit (75.3 -> 70, 0.0123 -> 0.01)."""
    unit = 10.0 ** math.floor(math.log10(value))
    return math.floor(value / unit * (1 + 1e-12)) * unit


def _fmt(value):
    return f"{value:,.0f}".replace(",", " ") if value >= 10 else f"{value:.3g}"


@dataclass(frozen=True)
class _Frame:
    """One picture: the deck's displacements ``uy`` (n_nodes,) [m], the wheels ``wheel_x``
    (n_wheels,) [m], the car bodies ``car_bounds`` (n_cars, 2) [m] or None, the time [s] or None."""

    uy: np.ndarray
    wheel_x: np.ndarray
    car_bounds: object = None
    time: object = None


@dataclass(frozen=True)
class _Look:
    """What stays fixed over an animation: the exaggeration ``scale``, the colour range
    ``clim`` [mm], the ground's x extent [m], the title."""

    scale: float
    clim: tuple
    ground_x: tuple
    title: object = None


@dataclass
class _Stage:
    """The parts of a plotter a frame changes: the moving meshes by name, the legend text."""

    meshes: dict
    legend: object


class PassageScene:
    """A bridge deck on its supports, drawn in 3-D with a train on it.

    Parameters
    ----------
    deck_x : (n_nodes,) array [m]
        x of the deck nodes, increasing (the bridge runs from the first to the last); two nodes
        at one x (two decks ending on one pier) are drawn as one, at the first's displacement,
        unless ``deck_ends`` puts them on two decks.
    supports_x : (n_supports,) array [m]
        x of the supports, within the bridge; those at its ends (within 2 % of its length) are
        drawn as abutments, the others as piers (supports closer than a pier's width share one
        pier, a bearing under each deck).
    deck_depth, deck_width : float [m]
        The deck's depth (y) and width (z): a box under the track.
    approach : float [m], optional
        Length of the approach embankment framed by the camera at each end (default:
        max(10 m, 0.35 × the bridge's length)).
    deck_ends : (n_decks, 2) array [m], optional
        The x of each deck's ends (its spans and overhangs; /bridge/deck_ends_m of a results
        file), in x order, not overlapping, each holding at least two nodes of ``deck_x``
        (default: one deck from the first node to the last). Each deck is drawn as its own box
        whose displacement is a spline through its own nodes only; between two decks (a joint)
        the deck is open and the track runs straight from one deck's end to the next's start.

    Methods :meth:`render_png` and :meth:`animate` draw a time of a passage and a passage.
    """

    def __init__(self, deck_x, supports_x, deck_depth=1.5, deck_width=6.0, approach=None, deck_ends=None):
        x = _vector("deck_x", deck_x, min_size=2)
        steps = np.diff(x)
        if np.any(steps < 0):
            i = int(np.flatnonzero(steps < 0)[0])
            raise ModelError(f"deck_x: must increase, but deck_x[{i + 1}] = {x[i + 1]:g} < deck_x[{i}] = {x[i]:g}")
        if x[-1] <= x[0]:
            raise ModelError(f"deck_x: must increase, but every node is at x = {x[0]:g}")
        self.deck_x = x
        self.deck_ends = self._deck_ends(deck_ends)
        self.x0, self.x1 = float(self.deck_ends[0, 0]), float(self.deck_ends[-1, 1])
        length = self.x1 - self.x0
        s = _vector("supports_x", supports_x, min_size=2)
        outside = (s < self.x0 - 1e-9 * length) | (s > self.x1 + 1e-9 * length)
        if np.any(outside):
            raise ModelError(f"supports_x: {s[outside][0]:g} is off the bridge [{self.x0:g}, {self.x1:g}] m")
        self.supports_x = np.sort(s)
        self.deck_depth = _positive("deck_depth", deck_depth)
        self.deck_width = _positive("deck_width", deck_width)
        self.length = float(length)
        self.approach = max(10.0, 0.35 * self.length) if approach is None else _positive("approach", approach)
        self.clearance = max(3.0, 0.12 * self.length)          # deck soffit above the ground [m]
        self.ground_y = -TRACK_BED - self.deck_depth - BEARING - self.clearance
        self._decks = self._deck_nodes()                        # per deck, the nodes its line runs through
        n = int(np.clip(12 * (x.size - 1), 240, 1200))        # drawing abscissae over the bridge
        self._deck_xs = [_distinct(np.concatenate([np.linspace(a, b, max(24, int(round(n * (b - a) / length)))),
                                                   x[nodes]]), 1e-9 * length)
                         for (a, b), nodes in zip(self.deck_ends, self._decks)]
        self._xs = np.unique(np.concatenate(self._deck_xs))

    def _deck_ends(self, deck_ends):
        """``deck_ends`` checked, (n_decks, 2) sorted rows; one deck over every node without it."""
        x = self.deck_x
        if deck_ends is None:
            return np.array([[x[0], x[-1]]])
        ends = np.sort(_array("deck_ends", deck_ends, (None, 2)), axis=1)
        if not len(ends):
            raise ModelError("deck_ends: expected at least one deck, got shape (0, 2)")
        tol = 1e-6 * max(1.0, x[-1] - x[0])
        if np.any(ends[:, 1] - ends[:, 0] <= tol):
            k = int(np.flatnonzero(ends[:, 1] - ends[:, 0] <= tol)[0])
            raise ModelError(f"deck_ends: deck {k + 1} runs from {ends[k, 0]:g} to {ends[k, 1]:g} m: no length")
        if np.any(ends[1:, 0] < ends[:-1, 1] - tol):
            k = int(np.flatnonzero(ends[1:, 0] < ends[:-1, 1] - tol)[0])
            raise ModelError(f"deck_ends: deck {k + 2} ({ends[k + 1, 0]:g} to {ends[k + 1, 1]:g} m) starts before "
                             f"deck {k + 1} ({ends[k, 0]:g} to {ends[k, 1]:g} m) ends: decks in x order, not overlapping")
        return ends

    def _deck_nodes(self):
        """Per deck, the indices of the nodes of ``deck_x`` on it that its line runs through
        (:func:`nodes_by_deck`, then one per x: the first)."""
        x, ends = self.deck_x, self.deck_ends
        tol = 1e-6 * max(1.0, x[-1] - x[0])
        out = []
        for k, nodes in enumerate(nodes_by_deck(x, ends, tol)):
            nodes = nodes[np.concatenate([[True], np.diff(x[nodes]) > tol])] if nodes.size else nodes
            if nodes.size < 2:
                raise ModelError(f"deck_ends: deck {k + 1} ({ends[k, 0]:g} to {ends[k, 1]:g} m) holds "
                                 f"{nodes.size} node{'' if nodes.size == 1 else 's'} of deck_x; a deck needs two")
            out.append(nodes)
        return out

    # -----------------------------------------------------------------------------------------
    # public API

    def render_png(self, path, deck_uy, wheel_x, car_bounds=None, scale=None, time=None, title=None,
                   window_size=(1600, 700)):
        """Draw the bridge and train at one time into the PNG file ``path``; return its path.

        Parameters
        ----------
        deck_uy : (n_nodes,) array [m]
            Vertical displacements of the deck nodes (positive up).
        wheel_x : (n_wheels,) array [m]
            Wheel (axle) positions.
        car_bounds : (n_cars, 2) array [m], optional
            Front and rear x of each car body (either order); without it, only the axles.
        scale : float, optional
            Exaggeration of the displacements, > 0 (default: the largest |deck_uy| shown as
            half a deck depth, rounded down to one significant digit).
        time : float [s], optional
            Shown as 't = … s'.
        title : str, optional
        window_size : (width, height) [pixels]
        """
        path = self._path(path, (".png",))
        frame = self._frame(deck_uy, wheel_x, car_bounds, time)
        look = self._look([frame], scale, title)
        window = _window(window_size)
        pv = _pyvista()
        plotter = _plotter(pv, window)
        try:
            stage = self._setup(pv, plotter, look, window)
            self._draw(pv, stage, frame, look)
            plotter.screenshot(str(path))
        finally:
            plotter.close()
        return path

    def animate(self, path, times, deck_uy_history, wheel_x_history, car_bounds_history=None, scale=None,
                fps=20, max_frames=120, title=None, window_size=(1200, 528)):
        """Draw a passage into the animation ``path`` (.gif, or .mp4 with imageio-ffmpeg); return
        its path.

        Parameters
        ----------
        times : (n_t,) array [s], non-decreasing
        deck_uy_history : (n_t, n_nodes) array [m]
        wheel_x_history : (n_t, n_wheels) array [m]
        car_bounds_history : (n_t, n_cars, 2) array [m], optional
        scale : float, optional
            As in :meth:`render_png`, by default from the largest |uy| over the whole history:
            one scale and one colour range for every frame.
        fps : float
            Frames per second of the animation.
        max_frames : int
            At most this many frames, taken evenly from the history (first and last kept).
        title : str, optional
        window_size : (width, height) [pixels]
            For an MP4, multiples of 16 (else imageio-ffmpeg resizes the frames, with a warning).
        """
        path = self._path(path, (".gif", ".mp4"))
        t = _vector("times", times, min_size=1)
        if np.any(np.diff(t) < 0):
            raise ModelError(f"times: must not decrease, but times[{int(np.flatnonzero(np.diff(t) < 0)[0]) + 1}] "
                             "is smaller than the time before it")
        uy = _array("deck_uy_history", deck_uy_history, (t.size, self.deck_x.size))
        wx = _array("wheel_x_history", wheel_x_history, (t.size, None))
        cb = None if car_bounds_history is None else _array("car_bounds_history", car_bounds_history,
                                                            (t.size, None, 2))
        fps = _positive("fps", fps)
        if isinstance(max_frames, bool) or not isinstance(max_frames, (int, np.integer)) or max_frames < 1:
            raise ModelError(f"max_frames: expected an integer >= 1, got {max_frames!r}")
        keep = np.unique(np.round(np.linspace(0, t.size - 1, min(t.size, int(max_frames)))).astype(int))
        frames = [_Frame(uy[i], wx[i], None if cb is None else cb[i], float(t[i])) for i in keep]
        look = self._look(frames, scale, title)
        window = _window(window_size)
        _AnimationWriter.check(path)
        pv = _pyvista()
        writer = _AnimationWriter(path, fps)
        plotter = _plotter(pv, window)
        try:
            stage = self._setup(pv, plotter, look, window)
            for k, frame in enumerate(frames):
                self._draw(pv, stage, frame, look)
                writer.append(plotter.screenshot(return_img=True) if k == 0 else _grab(plotter))
        finally:
            plotter.close()
            writer.close()
        return path

    # -----------------------------------------------------------------------------------------
    # input handling

    @staticmethod
    def _path(path, suffixes):
        p = Path(path)
        if p.suffix.lower() not in suffixes:
            raise ModelError(f"path: {str(path)!r} must end in {' or '.join(suffixes)}")
        if not p.parent.is_dir():
            raise ModelError(f"path: the folder {str(p.parent)!r} does not exist")
        if p.is_dir():
            raise ModelError(f"path: {str(path)!r} is a directory, not a file to write")
        return p

    def _frame(self, deck_uy, wheel_x, car_bounds, time):
        uy = _vector("deck_uy", deck_uy, size=self.deck_x.size, of="one per node of deck_x")
        wx = _vector("wheel_x", wheel_x)
        cb = None if car_bounds is None else _array("car_bounds", car_bounds, (None, 2))
        if time is not None:
            if not is_number(time):
                raise ModelError(f"time: expected a number [s], got {time!r}")
            time = float(time)
            if not math.isfinite(time):
                raise ModelError(f"time: expected a finite number [s], got {time!r}")
        return _Frame(uy, wx, cb, time)

    def _look(self, frames, scale, title):
        peak = max(float(np.max(np.abs(f.uy))) for f in frames)
        if scale is None:
            scale = _one_digit(TARGET_DEPTHS * self.deck_depth / peak) if peak > 0 else 1.0
        else:
            scale = _positive("scale", scale)
        limit = _nice(1e3 * peak, down=False, steps=(1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10)) if peak > 0 else 1.0
        xs = [self.x0 - self.approach, self.x1 + self.approach]
        for f in frames:
            if f.wheel_x.size:
                xs += [f.wheel_x.min() - 3.0, f.wheel_x.max() + 3.0]
            if f.car_bounds is not None and f.car_bounds.size:
                xs += [f.car_bounds.min() - 2.0, f.car_bounds.max() + 2.0]
        return _Look(float(scale), (-limit, limit), (min(xs), max(xs)), title)

    # -----------------------------------------------------------------------------------------
    # geometry

    def deck_line(self, uy, x):
        """The deck's displacement [m] at ``x`` [m] from its node values ``uy``: on each deck a
        cubic spline (not-a-knot; linear for two nodes) through that deck's nodes only; in a
        joint between two decks a straight line from one deck's end to the next's start; beyond
        the bridge's ends the end decks' splines."""
        x, uy = np.asarray(x, dtype=float), np.asarray(uy, dtype=float)
        ends = self.deck_ends
        lines = [deck_spline(self.deck_x[n], uy[n]) for n in self._decks]
        deck = np.clip(np.searchsorted(ends[:, 0], x, side="right") - 1, 0, len(ends) - 1)
        out = np.empty(x.shape)
        for k, line in enumerate(lines):
            on = deck == k
            out[on] = line(x[on])
        for k in range(len(ends) - 1):
            a, b = ends[k, 1], ends[k + 1, 0]
            joint = (x > a) & (x < b)
            if np.any(joint):
                ya, yb = float(lines[k](a)), float(lines[k + 1](b))
                out[joint] = ya + (yb - ya) * (x[joint] - a) / (b - a)
        return out

    def rail_top(self, uy, scale, x):
        """y [m] of the rail top at ``x`` [m]: the deck line exaggerated by ``scale`` on the
        bridge (its joints included), 0 (rigid ground) off it."""
        x = np.asarray(x, dtype=float)
        on = (x >= self.x0) & (x <= self.x1)
        return np.where(on, scale * self.deck_line(uy, x), 0.0)

    def _setup(self, pv, plotter, look, window):
        """Add the still parts (ground, embankments, supports, scale bar, texts, camera) and the
        moving ones; return the moving ones (a :class:`_Stage`), which :meth:`_draw` updates."""
        x0, x1, w = self.x0, self.x1, self.deck_width
        g, bed = self.ground_y, -TRACK_BED
        gx0, gx1 = look.ground_x
        toe = self.deck_width / 2 + 0.5 + 1.5 * (bed - g)     # half-width of the embankments' base
        front, back = max(self.deck_width / 2 + 9.0, toe + 3.0), toe + 12.0
        plotter.set_background("#fbfcfd", top="#c3d3e4")
        plotter.enable_anti_aliasing("ssaa")

        # The site: a block of ground, cut at the framed extent (a section model).
        top = pv.PolyData(np.array([[gx0, g, -back], [gx0, g, front], [gx1, g, front], [gx1, g, -back]]),
                          faces=[4, 0, 1, 2, 3])
        plotter.add_mesh(top, color=GROUND, ambient=0.25, diffuse=0.7, specular=0.0)
        plotter.add_mesh(pv.Box((gx0, gx1, g - 1.2, g - 0.02, -back, front)), color=SOIL, ambient=0.3)

        # Abutments (back wall + seat) and embankments at the deck's ends; piers between.
        half = w / 2 + 0.5
        seat = bed - self.deck_depth - BEARING
        blocks = []
        for end, outward in ((x0, -1.0), (x1, 1.0)):
            wall = sorted((end + outward * 0.08, end + outward * 1.6))
            blocks.append(pv.Box((wall[0], wall[1], g, bed - 0.02, -half, half)))
            embankment = sorted((end + outward * 1.6, gx0 if outward < 0 else gx1))
            plotter.add_mesh(_prism(pv, embankment, g, bed - 0.02, half + 1.5 * (bed - g), half),
                             color=EMBANKMENT, ambient=0.2, diffuse=0.65)
        t = float(np.clip(0.05 * self.length, 0.8, 1.8)) / 2     # half a pier's thickness along x
        for group in self._piers(2 * t):
            if min(group[0] - x0, x1 - group[-1]) <= 0.02 * self.length:
                end = x0 if group[0] - x0 < x1 - group[-1] else x1
                inward = 1.0 if end == x0 else -1.0
                s = group[0] if end == x0 else group[-1]
                seat_x = sorted((end - inward * 1.6, max(s + inward * 0.8, end + inward * 0.8)))
                blocks.append(pv.Box((seat_x[0], seat_x[1], g, seat, -half, half)))
                plotter.add_mesh(pv.Box((seat_x[0], seat_x[1], g - 0.01, g + 0.6, -half - 0.4, half + 0.4)),
                                 color=CONCRETE_DARK, ambient=0.25)
            else:
                a, b = group[0] - t, group[-1] + t
                blocks.append(pv.Box((a, b, g, seat, -0.38 * w, 0.38 * w)))
                blocks.append(pv.Box((a - 0.25, b + 0.25, seat - 0.6, seat, -0.45 * w, 0.45 * w)))
                plotter.add_mesh(pv.Box((a - 0.6, b + 0.6, g - 0.01, g + 0.5, -0.42 * w, 0.42 * w)),
                                 color=CONCRETE_DARK, ambient=0.25)
        bearings = [pv.Box((xa, xb, seat, seat + BEARING, z - 0.4, z + 0.4))
                    for xa, xb in self._bearings() for z in (-0.3 * w, 0.3 * w)]
        plotter.add_mesh(pv.merge(blocks), color=CONCRETE, ambient=0.25, diffuse=0.75, specular=0.1)
        plotter.add_mesh(pv.merge(bearings), color="#3d3f43")

        # Track on the approaches (rigid, y = 0): ballast bed and rails.
        for xa, xb in ((gx0, x0), (x1, gx1)):
            plotter.add_mesh(_prism(pv, (xa, xb), bed - 0.02, -RAIL_HEIGHT - 0.1, BALLAST_WIDTH / 2 + 0.6,
                                    BALLAST_WIDTH / 2), color=BALLAST, ambient=0.3)
            for z in (-GAUGE / 2, GAUGE / 2):
                plotter.add_mesh(pv.Box((xa, xb, -RAIL_HEIGHT, 0.0, z - 0.04, z + 0.04)), color=RAIL,
                                 specular=0.6, specular_power=30)

        self._scale_bar(pv, plotter, window)

        # Moving parts: added once, their meshes replaced in place per frame (_draw).
        meshes = self._moving(pv, _Frame(np.zeros(self.deck_x.size), np.zeros(0)), look)
        fs = _font(window)
        plotter.add_mesh(meshes["deck"], scalars="uy [mm]", cmap=DECK_CMAP, clim=look.clim, smooth_shading=True,
                         ambient=0.25, diffuse=0.75, specular=0.15,
                         scalar_bar_args=dict(title="", vertical=False, n_labels=5, fmt="%.3g", position_x=0.66,
                                              position_y=0.035, width=0.31, height=0.075,
                                              label_font_size=int(round(1.8 * fs)), unconstrained_font_size=True,
                                              color=TEXT, font_family="arial"))
        # (VTK's embedded sans font draws square brackets round: no brackets on screen.)
        label = plotter.add_text("deck vertical displacement in mm", position=(int(0.97 * window[0]),
                                 int(0.14 * window[1])), font_size=fs + 2, color=TEXT, font="arial")
        label.GetTextProperty().SetJustificationToRight()
        plotter.add_mesh(pv.merge([_outline(pv, a, b, -TRACK_BED, -TRACK_BED - self.deck_depth, w / 2,
                                            dash=max(0.6, self.length / 60)) for a, b in self.deck_ends]),
                         color=GHOST, line_width=2.0)
        plotter.add_mesh(meshes["ballast"], color=BALLAST, ambient=0.3)
        plotter.add_mesh(meshes["rails"], color=RAIL, specular=0.6, specular_power=30)
        plotter.add_mesh(meshes["wheels"], color=WHEEL, specular=0.4, smooth_shading=True)
        plotter.add_mesh(meshes["bodies"], color=BODY, ambient=0.3, diffuse=0.7, specular=0.3)
        plotter.add_mesh(meshes["bands"], color=BODY_BAND, ambient=0.3)
        plotter.add_mesh(meshes["bogies"], color=BOGIE, specular=0.3)
        plotter.add_mesh(meshes["windows"], color=WINDOWS, specular=0.6, specular_power=40)
        margin = round(0.01 * window[0])      # of the texts from the upper corners
        if look.title:
            title = plotter.add_text(str(look.title), position=(margin, window[1] - margin), font_size=fs + 3,
                                     color=TEXT, font="arial")
            title.GetTextProperty().SetVerticalJustificationToTop()
        legend = plotter.add_text(" ", position=(window[0] - margin, window[1] - margin), font_size=fs + 1,
                                  color=TEXT, font="arial")
        legend.GetTextProperty().SetVerticalJustificationToTop()
        legend.GetTextProperty().SetJustificationToRight()

        # Camera: from the front (+z), above and a little from the left, framing the deck, the
        # approaches, the scale bar and a train's height.
        xa, xb = x0 - self.approach, x1 + self.approach
        _, bar_z, _, unit = self._scale_bar_place()
        box = np.array([[x, y, z] for x in (xa, xb) for y in (g, BODY_FLOOR + BODY_HEIGHT)
                        for z in (-0.5 * w, max(0.5 * w + 4.0, bar_z + 1.6 * unit))])
        _aim(plotter.camera, box, direction=(-0.25, 0.32, 1.0), view_angle=30.0, aspect=window[0] / window[1])
        return _Stage(meshes, legend)

    def _piers(self, width):
        """The supports grouped by the pier (or abutment) that carries them: runs of supports
        less than ``width`` [m] apart (the bearings of two decks on one pier cap)."""
        groups = [[self.supports_x[0]]]
        for s in self.supports_x[1:]:
            if s - groups[-1][-1] < width:
                groups[-1].append(s)
            else:
                groups.append([s])
        return groups

    def _bearings(self):
        """(x from, x to) [m] of each bearing: one under each deck at each of its supports,
        BEARING_LENGTH long, centred on the support but kept under its deck (at a deck's end
        it ends there, so a joint stays open between the bearings of its two decks)."""
        tol = 1e-6 * max(1.0, self.length)
        out = []
        for s in self.supports_x:
            for a, b in self.deck_ends:
                if a - tol <= s <= b + tol:
                    lo = float(np.clip(s - BEARING_LENGTH / 2, a, max(a, b - BEARING_LENGTH)))
                    out.append((lo, min(lo + BEARING_LENGTH, b)))
        return out

    def _scale_bar_place(self):
        """(x from, z, length, thickness) [m] of the length bar: on the ground in front of the
        bridge, clear of the piers' and abutments' footings (z up to half the deck's width + 0.9 m),
        its label in front of it."""
        bar = _nice(0.3 * self.length)
        unit = max(1.0, (self.length + 2 * self.approach) / 40.0)   # bar thickness grows with the scene
        return self.x0 + 0.5, self.deck_width / 2 + 4.0, bar, unit

    def _scale_bar(self, pv, plotter, window):
        """A black-and-white length bar on the ground in front of the bridge, labelled in front
        of it (lower on the screen, where no structure stands)."""
        x_start, z, bar, unit = self._scale_bar_place()
        n = 5 if bar / 5 >= 0.2 else 2
        y = self.ground_y + 0.02
        pieces = [pv.Box((x_start + k * bar / n, x_start + (k + 1) * bar / n, y, y + 0.08 * unit, z,
                          z + 0.35 * unit)) for k in range(n)]
        plotter.add_mesh(pv.merge(pieces[0::2]), color="#111111")
        plotter.add_mesh(pv.merge(pieces[1::2]), color="#ffffff")
        plotter.add_point_labels([(x_start + bar / 2, y, z + 0.9 * unit)], [f"{_fmt(bar)} m"],
                                 font_size=int(round(1.6 * _font(window))), text_color=TEXT, shape=None, show_points=False,
                                 always_visible=True, bold=True, font_family="arial",
                                 justification_horizontal="center", justification_vertical="top")

    def _moving(self, pv, frame, look):
        """The moving meshes of a frame by name: the deformed deck (point data 'uy [mm]'), its
        ballast and rails, the wheels and axles, the car bodies with their bands, windows and
        bogie frames."""
        xs, scale, half = self._xs, look.scale, self.deck_width / 2
        decks = []
        for deck_xs in self._deck_xs:                     # a box per deck, its joints open
            uy = self.deck_line(frame.uy, deck_xs)
            top = scale * uy
            deck = _ribbon(pv, deck_xs, top - TRACK_BED, top - TRACK_BED - self.deck_depth, -half, half)
            deck.point_data["uy [mm]"] = np.tile(1e3 * uy, 4)
            decks.append(deck.extract_surface(algorithm="dataset_surface").compute_normals(
                split_vertices=True, feature_angle=40.0, auto_orient_normals=False))
        deck = decks[0] if len(decks) == 1 else pv.merge(decks)
        top = self.rail_top(frame.uy, scale, xs)          # the track runs on over the joints
        ballast = _prism(pv, xs, top - TRACK_BED + 0.01, top - RAIL_HEIGHT - 0.1, BALLAST_WIDTH / 2 + 0.6,
                         BALLAST_WIDTH / 2)
        rails = pv.merge([_ribbon(pv, xs, top, top - RAIL_HEIGHT, z - 0.04, z + 0.04).extract_surface(
            algorithm="dataset_surface") for z in (-GAUGE / 2, GAUGE / 2)])

        wx = frame.wheel_x
        contact = self.rail_top(frame.uy, scale, wx)
        wheels = _copies(pv, _wheelset_parts(), np.stack([wx, contact + WHEEL_RADIUS, np.zeros_like(wx)], axis=1))
        bodies, bands, windows, bogies = [pv.PolyData()], [pv.PolyData()], [pv.PolyData()], [pv.PolyData()]
        if frame.car_bounds is not None:
            for front, rear in frame.car_bounds:
                a, b = min(front, rear), max(front, rear)
                mine = (wx >= a - 0.5) & (wx <= b + 0.5)
                if np.count_nonzero(mine) >= 2 and np.ptp(wx[mine]) > 0:
                    xa, xb = wx[mine].min(), wx[mine].max()
                    ya, yb = contact[mine][np.argmin(wx[mine])], contact[mine][np.argmax(wx[mine])]
                else:
                    xa, xb = a, b
                    ya, yb = self.rail_top(frame.uy, scale, [a, b]) if b > a else (0.0, 0.0)
                slope = (yb - ya) / (xb - xa) if xb > xa else 0.0
                for group in _bogies(np.sort(wx[mine])):
                    ga, gb = group[0] - 1.0, group[-1] + 1.0
                    yg = ya + slope * (0.5 * (ga + gb) - xa)
                    for z in (-GAUGE / 2 - 0.16, GAUGE / 2 + 0.16):
                        bogies.append(pv.Box((ga, gb, yg + 0.36, yg + 0.7, z - 0.05, z + 0.05)))
                lift = (lambda x, ya=ya, xa=xa, slope=slope: ya + slope * (x - xa))
                bodies.append(_sheared(pv.Box((a, b, BODY_FLOOR, BODY_FLOOR + BODY_HEIGHT, -BODY_WIDTH / 2,
                                               BODY_WIDTH / 2)), lift))
                bands.append(_sheared(pv.Box((a + 0.02, b - 0.02, BODY_FLOOR + 0.35, BODY_FLOOR + 0.7,
                                              -BODY_WIDTH / 2 - 0.02, BODY_WIDTH / 2 + 0.02)), lift))
                windows.append(_sheared(pv.Box((a + 1.2, b - 1.2, BODY_FLOOR + 1.45, BODY_FLOOR + 2.2,
                                                -BODY_WIDTH / 2 - 0.015, BODY_WIDTH / 2 + 0.015)), lift))
        return {"deck": deck, "ballast": ballast, "rails": rails, "wheels": wheels,
                "bodies": pv.merge(bodies), "bands": pv.merge(bands), "windows": pv.merge(windows),
                "bogies": pv.merge(bogies)}

    def _draw(self, pv, stage, frame, look):
        """Update the moving parts and the legend (time, scale) to ``frame``."""
        for name, mesh in self._moving(pv, frame, look).items():
            stage.meshes[name].copy_from(mesh, deep=True)
        stage.meshes["deck"].set_active_scalars("uy [mm]")
        lines = [f"displacements × {_fmt(look.scale)}"]
        if frame.time is not None:
            lines.insert(0, f"t = {frame.time:.3f} s")
        stage.legend.SetInput("\n".join(lines))


def _plotter(pv, window):
    """An off-screen plotter whose theme allows empty meshes (a frame without cars)."""
    theme = pv.themes.Theme()
    theme.allow_empty_mesh = True
    return pv.Plotter(off_screen=True, window_size=window, theme=theme)


def _grab(plotter):
    """Render ``plotter`` (already rendered once) and return its image (h, w, 3) uint8: one
    render, where ``screenshot`` renders twice."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    plotter.render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(plotter.render_window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()
    grab.Update()
    image = grab.GetOutput()
    width, height, _ = image.GetDimensions()
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, 3)[::-1]


class _AnimationWriter:
    """Frames (h, w, 3) uint8 into a GIF (each frame reduced to 256 colours by an octree, which
    keeps the colour bar's saturated ends) or an MP4 (imageio-ffmpeg)."""

    def __init__(self, path, fps):
        import imageio.v2 as imageio

        self.check(path)
        self.gif = path.suffix.lower() == ".gif"
        if self.gif:
            self._writer = imageio.get_writer(str(path), format="GIF", mode="I", duration=1000.0 / fps, loop=0)
        else:
            self._writer = imageio.get_writer(str(path), format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                              quality=8, macro_block_size=16)

    @staticmethod
    def check(path):
        """Raise a RuntimeError naming the fix if ``path`` cannot be written here."""
        if path.suffix.lower() == ".mp4" and not _installed("imageio_ffmpeg"):
            raise RuntimeError(f"writing {str(path)!r} needs an ffmpeg writer for imageio: pip install "
                               "imageio-ffmpeg (or write a .gif)")

    def append(self, image):
        image = np.ascontiguousarray(image[..., :3])
        if self.gif:
            from PIL import Image

            image = np.asarray(Image.fromarray(image).quantize(256, method=Image.Quantize.FASTOCTREE,
                                                               dither=Image.Dither.NONE).convert("RGB"))
        self._writer.append_data(image)

    def close(self):
        self._writer.close()


def _aim(camera, points, direction, view_angle, aspect, margin=1.04):
    """Point ``camera`` along -``direction`` (y up) at the nearest distance, and the centre, at
    which every one of ``points`` (n, 3) is in view, with a small ``margin``."""
    d = np.asarray(direction, dtype=float)
    d /= np.linalg.norm(d)
    right = np.cross((0.0, 1.0, 0.0), d)
    right /= np.linalg.norm(right)
    up = np.cross(d, right)
    tan_v = math.tan(math.radians(view_angle / 2)) / margin
    tan_h = tan_v * aspect
    focus = points.mean(axis=0)
    for _ in range(4):   # centre the projected extent, then refit the distance
        rel = points - focus
        along, h, v = rel @ d, rel @ right, rel @ up
        distance = max(np.max(along + np.abs(h) / tan_h), np.max(along + np.abs(v) / tan_v))
        depth = distance - along
        sh, sv = h / depth, v / depth           # screen coordinates (tangents)
        focus = focus + distance * (0.5 * (sh.max() + sh.min()) * right + 0.5 * (sv.max() + sv.min()) * up)
    rel = points - focus
    along, h, v = rel @ d, rel @ right, rel @ up
    distance = max(np.max(along + np.abs(h) / tan_h), np.max(along + np.abs(v) / tan_v))
    camera.focal_point = tuple(focus)
    camera.position = tuple(focus + distance * d)
    camera.up = (0.0, 1.0, 0.0)
    camera.view_angle = view_angle
    camera.clipping_range = (0.02 * distance, 20.0 * distance)


@functools.cache
def _wheelset_parts():
    """A wheelset at the origin (two wheels on an axle along z): (points (n, 3), legacy faces,
    point data by name), built once: a frame places copies of it (:func:`_copies`) instead of
    building 3 cylinders per axle (150 a frame for 50 axles, half the time of a frame)."""
    import pyvista as pv

    parts = [pv.Cylinder(center=(0.0, 0.0, z), direction=(0, 0, 1), radius=WHEEL_RADIUS, height=WHEEL_WIDTH,
                         resolution=28) for z in (-GAUGE / 2 - 0.03, GAUGE / 2 + 0.03)]
    parts.append(pv.Cylinder(center=(0.0, 0.0, 0.0), direction=(0, 0, 1), radius=0.09, height=GAUGE,
                             resolution=12))
    mesh = pv.merge(parts).extract_surface(algorithm="dataset_surface")
    data = {name: np.asarray(mesh.point_data[name]).copy() for name in mesh.point_data.keys()}
    faces = np.asarray(mesh.faces).copy()
    index = np.ones(faces.size, dtype=bool)          # the legacy faces' point indices (not their counts)
    k = 0
    while k < faces.size:
        index[k] = False
        k += int(faces[k]) + 1
    return np.asarray(mesh.points, dtype=float).copy(), faces, index, data


def _copies(pv, template, offsets):
    """One PolyData of copies of ``template`` (points, legacy faces, which of their entries are
    point indices, point data) moved by each row of ``offsets`` (n, 3) [m]."""
    points, faces, index, data = template
    n = len(offsets)
    if n == 0:
        return pv.PolyData()
    all_points = (points[None, :, :] + np.asarray(offsets, dtype=float)[:, None, :]).reshape(-1, 3)
    shift = (np.arange(n) * len(points))[:, None] * index[None, :]
    mesh = pv.PolyData(all_points, faces=(faces[None, :] + shift).ravel())
    for name, values in data.items():
        mesh.point_data[name] = np.tile(values, (n,) + (1,) * (values.ndim - 1))
    return mesh


def _distinct(x, tol):
    """``x`` sorted, without values within ``tol`` of the one before (a node a rounding error off
    a drawing abscissa made a zero-length slice of the deck)."""
    x = np.sort(x)
    return x[np.concatenate([[True], np.diff(x) > tol])]


def _bogies(x, gap=3.6):
    """Sorted axle positions grouped into bogies: runs of axles less than ``gap`` [m] apart."""
    groups, run = [], [x[0]] if x.size else []
    for a, b in zip(x[:-1], x[1:]):
        if b - a < gap:
            run.append(b)
        else:
            groups.append(run)
            run = [b]
    if run:
        groups.append(run)
    return [g for g in groups if len(g) >= 2]


def _font(window):
    return int(np.clip(round(window[1] / 64), 6, 18))


def _ribbon(pv, x, y_top, y_bottom, z0, z1):
    """A box swept along x: top and bottom lines y_top(x), y_bottom(x), between z0 and z1."""
    n = x.size
    X = np.broadcast_to(x[:, None, None], (n, 2, 2))
    Y = np.stack([y_bottom, y_top], axis=1)[:, :, None].repeat(2, axis=2)
    Z = np.broadcast_to(np.array([z0, z1])[None, None, :], (n, 2, 2))
    return pv.StructuredGrid(np.ascontiguousarray(X), np.ascontiguousarray(Y), np.ascontiguousarray(Z))


def _prism(pv, x, y_low, y_high, half_low, half_high):
    """A prism swept along ``x`` (n,) with a trapezoidal section: from ``y_low`` to ``y_high``
    (scalars or (n,) arrays), half-widths ``half_low`` at its base and ``half_high`` at its top."""
    x = np.asarray(x, dtype=float)
    n = x.size
    X = np.broadcast_to(x[:, None, None], (n, 2, 2))
    Y = np.stack([np.broadcast_to(y_low, (n,)), np.broadcast_to(y_high, (n,))], axis=1)[:, :, None].repeat(2, axis=2)
    Z = np.array([half_low, half_high])[None, :, None] * np.array([-1.0, 1.0])[None, None, :] * np.ones((n, 1, 1))
    return pv.StructuredGrid(np.ascontiguousarray(X), np.ascontiguousarray(Y),
                             np.ascontiguousarray(Z)).extract_surface(algorithm="dataset_surface")


def _outline(pv, x0, x1, y_top, y_bottom, half, dash=0.6):
    """The undeformed deck box's long edges (front and top), dashed every ``dash`` [m]."""
    n = max(2, int(round((x1 - x0) / dash)))
    edges = np.linspace(x0, x1, n + 1)
    lines = []
    for y, z in ((y_top, half + 0.05), (y_bottom, half + 0.05), (y_top, -half)):
        for a, b in zip(edges[0::2], edges[1::2]):
            lines.append(pv.Line((a, y, z), (b, y, z)))
    for x in (x0, x1):
        lines.append(pv.Line((x, y_bottom, half + 0.05), (x, y_top, half + 0.05)))
    return pv.merge(lines)


def _sheared(mesh, lift):
    """``mesh`` with every point raised by lift(x) (a car body following its wheels)."""
    points = np.array(mesh.points)
    points[:, 1] += lift(points[:, 0])
    mesh.points = points
    return mesh


def _named_case(results, train, speed_kmh, seed):
    """``(train, speed [km/h], seed)`` of a case named by its train and speed (``seed`` -1: the
    smooth rail) as the sweep of ``results`` (a SweepResults) has them, or a SweepError: a speed
    without its train, a train not in the sweep or without its speed, a speed or a seed the
    sweep does not have (:meth:`~vtsi.sweep_results.SweepResults.speed`, ``.seed``)."""
    if train is None:
        number = isinstance(speed_kmh, (int, float, np.integer, np.floating)) and not isinstance(speed_kmh, bool)
        shown = f"{speed_kmh:g} km/h" if number else repr(speed_kmh)
        raise SweepError(f"scene: speed_kmh = {shown} without a train: name the train too (or neither, for the "
                         "governing case)")
    if train not in results.trains:
        raise SweepError(f"scene: train {train!r} is not in the sweep of {results.path} "
                         f"(trains: {', '.join(results.trains)})")
    if speed_kmh is None:
        raise SweepError(f"scene: a case of train {train!r} needs its speed_kmh")
    return train, results.speed(speed_kmh), results.seed(seed)


def _checked_time(time, first, last, who):
    """``time`` [s] as a float within a case's record, ``first`` to ``last`` [s], or a ModelError
    naming ``who`` and the record."""
    value = as_number(time, who, "time [s]")
    if not first - 1e-9 <= value <= last + 1e-9:
        raise ModelError(f"{who}: time {value:g} s is outside the recorded passage ({first:g} to {last:g} s)")
    return value


def _record(results, train, speed_kmh, seed):
    """``(first, last)`` [s] of a case's record: the times of its recorded deck displacement (what
    :func:`render_case` draws from), else those of its passage in the results file (Δt to
    n_steps × Δt)."""
    if case_key(train, speed_kmh, seed) in results.histories():
        history = results.history(train, speed_kmh, seed)
        if "deck_displacement" in history:
            times = history["deck_displacement"][0]
            return float(times[0]), float(times[-1])
    dt = float(results.identity["settings"]["dt"])
    return dt, results.case(train, speed_kmh, seed)["attrs"]["n_steps"] * dt


def check_scene_case(results, case, who="report: the scene's case"):
    """``case``, what a scene image draws (keys :data:`SCENE_CASE_KEYS`, any left out or None:
    :attr:`RenderedScene.case`), checked against the sweep of ``results`` (a SweepResults) with
    :func:`render_case`'s own checks: the train, speed and seed one of the sweep's cases
    (``seed`` -1, the smooth rail, when left out), ``time_s`` [s] within that case's record
    (:func:`_record`), ``scale`` a finite number > 0. Returns the keys given, their values as the
    sweep has them (plus the seed of a case named). Raises a SweepError (an unknown key, a case
    the sweep does not have, a seed or time without its case) or a ModelError (a time outside the
    record, a scale not > 0), each naming ``who`` or the sweep and the value at fault."""
    unknown = [k for k in case if k not in SCENE_CASE_KEYS]
    if unknown:
        raise SweepError(f"{who}: unknown key{'s' * (len(unknown) > 1)} {', '.join(repr(k) for k in unknown)}; "
                         f"valid: {', '.join(SCENE_CASE_KEYS)}")
    given = {k: v for k, v in case.items() if v is not None}
    out = {}
    if "train" in given or "speed_kmh" in given:
        out["train"], out["speed_kmh"], out["seed"] = _named_case(results, given.get("train"), given.get("speed_kmh"),
                                                                  given.get("seed", -1))
    else:
        alone = [k for k in ("seed", "time_s") if k in given]
        if alone:
            raise SweepError(f"{who}: {alone[0]} = {given[alone[0]]!r} without its case: name its train and "
                             "speed_kmh too")
    if "time_s" in given:
        out["time_s"] = _checked_time(given["time_s"], *_record(results, out["train"], out["speed_kmh"], out["seed"]),
                                      who)
    if "scale" in given:
        out["scale"] = _positive(f"{who}: scale", given["scale"])
    return out


def _recorded_case(results_path, train, speed_kmh, seed):
    """(results, train, speed, seed, history, scene) of a case with recorded histories: by default
    the governing case of the stored check's deck acceleration (else of the envelope)."""
    results = SweepResults(results_path)
    if train is None and speed_kmh is None:
        stored = stored_check(results_path)
        rows = [r for r in (stored.rows if stored else []) if r.criterion == "deck_acceleration"]
        if rows:
            train, speed_kmh, seed = rows[0].train, rows[0].speed_kmh, rows[0].seed
        else:
            quantity = next((q for q in results.quantities if q.endswith("_absmax")), None)
            worst = results.critical(quantity) if quantity else None
            if worst is None:
                raise SweepError(f"scene: {results_path} holds no case to draw")
            train, speed_kmh, seed = worst["train"], worst["speed_kmh"], worst["seed"]
    else:
        train, speed_kmh, seed = _named_case(results, train, speed_kmh, seed)
    history = results.history(train, speed_kmh, seed)
    if "deck_displacement" not in history:
        raise SweepError(f"scene: case {train} at {speed_kmh:g} km/h has no deck displacement history")
    bridge = results.bridge()          # the x of the history's nodes: the decks' (an older vtsi's: the track's)
    x_of = dict(zip(np.asarray(bridge["deck_nodes"]).tolist(), np.asarray(bridge["deck_x_m"]).tolist()))
    columns = [int(n) for n in history["deck_displacement"][2]]
    missing = [n for n in columns if n not in x_of]
    if missing:
        raise SweepError(f"scene: the deck displacement history of {train} at {speed_kmh:g} km/h holds node "
                         f"{missing[0]}, which is not on the track (/bridge/deck_nodes)")
    scene = PassageScene([x_of[n] for n in columns], np.unique(bridge["span_ends_m"]), deck_ends=deck_ranges(bridge))
    return results, train, float(speed_kmh), seed, history, scene


def car_body_offsets(train_data):
    """(n_cars, 2) [m] the front and rear of each car body behind the train's head (its x at
    time t: x_head(t) − offsets), from a results file's train data
    (:meth:`~vtsi.sweep_results.SweepResults.train_data`), or None for a train of moving forces
    (n_dof = 0: axle loads, no vehicle) or of fewer than two axles a car. Car lengths are not
    stored: two cars meet half-way between the last axle of one and the first of the next
    (0.5 m apart); the first car's front is the head (offset 0) and the last car's rear lies as
    far behind its last axle as the first axle lies behind the head."""
    offsets = np.asarray(train_data["axle_offsets_m"], dtype=float)
    cars = np.asarray(train_data["wheel_car"], dtype=np.int64)
    ids, counts = np.unique(cars, return_counts=True)
    if int(train_data["n_dof"]) == 0 or not offsets.size or np.any(counts < 2):
        return None
    first = np.array([offsets[cars == c].min() for c in ids])
    last = np.array([offsets[cars == c].max() for c in ids])
    joints = 0.5 * (last[:-1] + first[1:])
    overhang = first[0] if first[0] > 0 else (float(np.median(first[1:] - joints)) if joints.size else 2.5)
    fronts = np.concatenate([[first[0] - overhang], joints + 0.25])
    rears = np.concatenate([joints - 0.25, [last[-1] + overhang]])
    return np.stack([fronts, rears], axis=1)


def _case_title(results, train, speed_kmh, seed):
    """'ICE3 at 360 km/h', with ', rail sample 1' on an irregular rail (seed >= 0)."""
    return f"{train} at {speed_kmh:g} km/h" + (f", rail sample {seed}" if seed is not None and seed >= 0 else "")


class _Written(os.PathLike):
    """A file written, with what it holds: os.PathLike as its ``path`` (``open``, ``os.fspath``
    and ``Path`` take it as that path; ``str`` gives it)."""

    def __fspath__(self):
        return os.fspath(self.path)

    def __str__(self):
        return os.fspath(self.path)


@dataclass(frozen=True)
class RenderedScene(_Written):
    """What :func:`render_case` drew: the PNG's ``path`` (the object is os.PathLike: ``open``,
    ``os.fspath`` and ``Path`` take it as that path; ``str`` gives it), the case (``train``,
    ``speed_kmh`` [km/h], ``seed``: -1 a smooth rail, else the rail sample), the time drawn
    ``time_s`` [s] and the displacements' exaggeration ``scale`` [-]."""

    path: Path
    train: str
    speed_kmh: float
    seed: int
    time_s: float
    scale: float

    @property
    def case(self):
        """``{train, speed_kmh, seed, time_s, scale}``: the scene's caption for
        :func:`vtsi.report.write_report` (``scene_case``)."""
        return {"train": self.train, "speed_kmh": self.speed_kmh, "seed": self.seed, "time_s": self.time_s,
                "scale": self.scale}


def render_case(results_path, path, train=None, speed_kmh=None, seed=-1, time=None, **kwargs):
    """A PNG of a case recorded in a sweep's results file (its deck-displacement history,
    :meth:`vtsi.sweep.Sweep.record_histories`): by default the case and time of the largest deck
    acceleration of the stored check (else of the envelope), the train's axles where they are
    then. ``kwargs`` go to :meth:`PassageScene.render_png`. Returns a :class:`RenderedScene`:
    the path written (os.PathLike), with the case, the time and the exaggeration drawn."""
    results, train, speed_kmh, seed, history, scene = _recorded_case(results_path, train, speed_kmh, seed)
    times, uy, _ = history["deck_displacement"]
    if time is None:
        _, accel, _ = history.get("deck_acceleration", history["deck_displacement"])
        time = float(times[int(np.argmax(np.max(np.abs(accel), axis=1)))])
    time = _checked_time(time, times[0], times[-1], "render_case")
    k = int(np.argmin(np.abs(times - time)))
    data = results.train_data(train)
    head = history["attrs"]["x_head0"] + speed_kmh / 3.6 * times[k]
    bodies = car_body_offsets(data)
    seed = int(history["attrs"].get("seed", seed))
    title = kwargs.pop("title", _case_title(results, train, speed_kmh, seed))
    wheels, bounds = head - data["axle_offsets_m"], None if bodies is None else head - bodies
    scale = scene._look([scene._frame(uy[k], wheels, bounds, None)], kwargs.pop("scale", None), title).scale
    written = scene.render_png(path, uy[k], wheels, bounds, time=float(times[k]), title=title, scale=scale, **kwargs)
    return RenderedScene(Path(written), str(train), float(speed_kmh), seed, float(times[k]), float(scale))


@dataclass(frozen=True)
class RenderedAnimation(_Written):
    """What :func:`animate_case` drew: the animation's ``path`` (os.PathLike, as
    :class:`RenderedScene`), its number of ``frames`` and their spacing ``spacing_s`` [s], the
    frequency ``n0_hz`` [Hz] the frames must resolve (the deck's n₀; of several decks the highest
    of theirs), the ``resolving_frames`` 4 n₀ T + 1 that do over the record's T seconds, and
    ``aliasing``: '' when the frames are at most a quarter period of n₀ apart, else what the
    warning says (:func:`vtsi.report.write_report` puts it in the scene's caption)."""

    path: Path
    frames: int
    spacing_s: float
    n0_hz: float
    resolving_frames: int
    aliasing: str


def _aliasing_text(spacing, n0s, first_hz, needed):
    """Why frames ``spacing`` [s] apart alias the deck's vibration: more than a quarter period of
    the highest n₀ of ``n0s`` [Hz] (each deck's), which is named, and why that one (of several
    decks, not the model's first frequency ``first_hz`` [Hz]), and the ``needed`` frames that
    resolve it."""
    n0 = float(np.max(n0s))
    which = (f"the stiffest deck's first vertical frequency ({n0:.3g} Hz, the highest of the decks' n0): each deck "
             f"vibrates at its own n0, so the frames must resolve the highest, not the model's first mode "
             f"({first_hz:.4g} Hz)" if len(n0s) > 1 else f"the deck's first vertical frequency (n0 = {n0:.4g} Hz)")
    return (f"frames {spacing:.3g} s apart, more than a quarter period ({0.25 / n0:.3g} s) of {which}; the deck's "
            f"vibration is aliased; max_frames >= {needed} resolves it (vtsi check: --animation-frames {needed})")


def animate_case(results_path, path, train=None, speed_kmh=None, seed=-1, max_frames=None, **kwargs):
    """A GIF (or MP4) of a recorded case's passage (the case chosen as :func:`render_case`
    chooses it) over the whole record. Returns a :class:`RenderedAnimation`: the path written
    (os.PathLike), with its frames and whether they alias the deck's vibration.

    Frames further apart than a quarter period of n₀ alias the deck's vibration (it appears
    slower, its peaks are missed). By default (``max_frames=None``) there are ceil(4 n₀ T) + 1
    frames over the record's duration T (every recorded sample if fewer), at most
    MAX_ANIMATION_FRAMES; an explicit ``max_frames`` takes at most that many. Either way a
    warning names the ``max_frames`` that resolves the vibration when the frames are further
    apart. Of several decks n₀ is the highest of the decks' own
    (:func:`~vtsi.sweep_results.deck_first_frequencies`: a 15 m deck beside a 30 m one, 10.66 Hz,
    where the model's first, the 30 m deck's 2.666 Hz, let frames 4 times too far apart pass).
    A train of cars is drawn with its car bodies (:func:`car_body_offsets`)."""
    results, train, speed_kmh, seed, history, scene = _recorded_case(results_path, train, speed_kmh, seed)
    times, uy, _ = history["deck_displacement"]
    bridge = results.bridge()
    n0s = deck_first_frequencies(bridge)
    n0 = float(np.max(n0s))
    needed = int(np.ceil(4 * n0 * (times[-1] - times[0]) * (1 - 1e-12))) + 1
    if max_frames is None:
        max_frames = min(needed, MAX_ANIMATION_FRAMES)
    frames = min(len(times), int(max_frames))
    spacing = (times[-1] - times[0]) / max(frames - 1, 1)
    aliasing = (_aliasing_text(spacing, n0s, float(np.ravel(bridge["frequencies_hz"])[0]), needed)
                if spacing > 0.25 / n0 * (1 + 1e-9) else "")
    if aliasing:
        logger.warning("animation of %s at %g km/h: %s", train, speed_kmh, aliasing)
    data = results.train_data(train)
    heads = history["attrs"]["x_head0"] + speed_kmh / 3.6 * times
    wheels = heads[:, None] - data["axle_offsets_m"][None, :]
    bodies = car_body_offsets(data)
    title = kwargs.pop("title", _case_title(results, train, speed_kmh, history["attrs"].get("seed", seed)))
    written = scene.animate(path, times, uy, wheels, None if bodies is None else heads[:, None, None] - bodies[None],
                            max_frames=max_frames, title=title, **kwargs)
    return RenderedAnimation(Path(written), frames, float(spacing), n0, needed, aliasing)
