"""A bridge for a sweep from a file (``vtsi sweep BRIDGE``, docs/cli.md).

Two kinds of file:

- a **description** of a built-in bridge, TOML (``.toml``; Python >= 3.11, or the ``tomli``
  package on 3.10) or YAML (``.yaml``/``.yml``, when PyYAML is installed), with a ``[bridge]``
  table naming its ``kind`` (:data:`BRIDGE_KINDS`) and an optional ``[analysis]`` table of
  defaults for the sweep's settings (:data:`ANALYSIS_KEYS`; the command line overrides them)::

      [bridge]
      kind = "beam"            # continuous Euler-Bernoulli beam, pin then rollers
      spans_m = [20.0]
      E_Pa = 3.5e10
      I_m4 = 1.9               # or f1_Hz = 5.0: I from the first span's first frequency
      mu_kg_m = 15000.0
      elements_per_span = 10
      [analysis]
      damping = 0.0125
      dt_s = 0.002

  Units are in the key names; an unknown key or table is an error naming it.

- an OpenSees **model script**, Tcl (``.tcl``, :func:`vtsi.tcl.run_file`) or OpenSeesPy
  (``.py``, run with ``import vtsi.opensees as ops`` pointing at a fresh session), that builds
  the bridge and defines its track with vtsi's ``track`` command (exactly one, or pick one with
  ``track=TAG``). The script's load patterns are dropped (a sweep's loads are its trains); its
  trains, constraints, recorders and analyses are not used. The script must be in SI units
  (N, kg, m, s, Pa): a model in kN, t, m has the right frequencies but masses and stiffnesses
  1000 times too small for the trains' loads in N. A model lighter than
  :data:`MIN_MASS_PER_METRE` along its track is refused as such (no railway deck is that light).

Every problem of the file raises :class:`~vtsi.errors.BridgeModelError` (a ModelError: the bridge
is at fault) naming the file and the key, tag or line; a path of an unknown type or no file, a
missing reader (tomli, PyYAML, tkinter) and the arguments raise :class:`~vtsi.errors.ModelError`.
"""
import hashlib
import math
import os
import re
import runpy
import sys
import traceback
import types
from dataclasses import dataclass, field
from typing import Callable

from vtsi import opensees
from vtsi.commands.tcl import Interpreter, script_line
from vtsi.errors import BridgeModelError, CommandError, ModelError, VtsiError, is_int
from vtsi.models.bridges import MAX_ELEMENTS_PER_SPAN
from vtsi.passage import PassageSettings
from vtsi.sweep import SweepBridge, beam_bridge, check_deck_mass, check_span_lengths
from vtsi.track import Track
from vtsi.units import MIN_MASS_PER_METRE, Units, deck_mass_per_length

ANALYSIS_KEYS = {
    "dt_s": "dt", "integrator": "integrator", "cars": "cars", "contact": "contact",
    "interpolation": "interpolation", "damping": "damping", "damping_hz": "damping_hz",
    "irregularity": "irregularity", "approach_m": "approach", "free_vibration_s": "free_vibration",
    "exact_events": "exact_events", "bridge_self_weight": "bridge_self_weight",
    "bridge_model": "bridge", "modal_hz": "modal_hz", "static_correction": "static_correction",
    "hslm_b": "hslm_b",
}
"""Keys of the ``[analysis]`` table -> :class:`~vtsi.passage.PassageSettings` fields (see there
for their meaning and units), besides ``seeds`` (rail samples, a list of ints >= 0)."""

SCRIPT_SUFFIXES = (".tcl", ".py")
DESCRIPTION_SUFFIXES = (".toml", ".yaml", ".yml")


@dataclass(frozen=True)
class BridgeKind:
    """A kind of bridge a description file can name: ``build(table, base_dir)`` gets the
    ``[bridge]`` table (with ``kind`` removed; every key checked against ``required`` and
    ``optional``) and the description file's directory, and returns a SweepBridge."""

    name: str
    build: Callable
    required: tuple
    optional: tuple
    summary: str


BRIDGE_KINDS = {}
"""Registered bridge kinds, by name (:func:`bridge_kind`)."""


def bridge_kind(name, required, optional, summary):
    """Register ``build(table, base_dir) -> SweepBridge`` as the bridge kind ``name``."""
    def register(build):
        if name in BRIDGE_KINDS:
            raise ModelError(f"bridge kind {name!r} is already registered")
        BRIDGE_KINDS[name] = BridgeKind(name, build, tuple(required), tuple(optional), summary)
        return build
    return register


@dataclass
class BridgeFile:
    """What a bridge file gives a sweep: the bridge, and (description files only) the
    ``[analysis]`` defaults as PassageSettings keywords, and the rail samples."""

    path: str
    bridge: SweepBridge
    settings: dict = field(default_factory=dict)
    seeds: object = None


def load_bridge(path, track=None, min_mass_per_metre=MIN_MASS_PER_METRE):
    """The bridge of ``path`` (a description file or a model script, see the module docstring)
    as a :class:`~vtsi.sweep.SweepBridge`. ``track``: the tag of the script's track when it
    defines several. ``min_mass_per_metre`` [kg/m]: see :data:`MIN_MASS_PER_METRE` (0 accepts
    any mass, e.g. for a scale model)."""
    return read_bridge_file(path, track, min_mass_per_metre).bridge


def read_bridge_file(path, track=None, min_mass_per_metre=MIN_MASS_PER_METRE):
    """Like :func:`load_bridge`, with the file's ``[analysis]`` defaults (a :class:`BridgeFile`)."""
    if not isinstance(path, (str, os.PathLike)):
        raise ModelError(f"bridge file: expected a path, got {path!r}")
    if isinstance(min_mass_per_metre, bool) or not isinstance(min_mass_per_metre, (int, float)) \
            or not (math.isfinite(min_mass_per_metre) and min_mass_per_metre >= 0):
        raise ModelError(f"bridge file: min_mass_per_metre must be a number >= 0 [kg/m], got {min_mass_per_metre!r}")
    path = os.path.abspath(os.fspath(path))
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in SCRIPT_SUFFIXES + DESCRIPTION_SUFFIXES:
        raise ModelError(f"bridge file {path}: unknown type {suffix or '(no suffix)'!r}; expected a description "
                         f"({', '.join(DESCRIPTION_SUFFIXES)}) or a model script ({', '.join(SCRIPT_SUFFIXES)})")
    if not os.path.isfile(path):
        raise ModelError(f"bridge file {path}: no such file")
    if suffix in SCRIPT_SUFFIXES:
        result = BridgeFile(path, script_bridge(path, track))
    else:
        result = _description(path, suffix, track)
    _check_mass(result.bridge, path, min_mass_per_metre)
    return result


# -- description files -----------------------------------------------------------------------
def _read_table(path, suffix):
    if suffix == ".toml":
        try:
            import tomllib
        except ImportError:          # Python 3.10
            try:
                import tomli as tomllib
            except ImportError:
                raise ModelError(f"bridge file {path}: reading TOML needs Python >= 3.11 or the tomli package "
                                 "(pip install tomli)") from None
        try:
            with open(path, "rb") as f:
                return tomllib.load(f)
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise BridgeModelError(f"bridge file {path}: not valid TOML ({exc})") from None
    try:
        import yaml
    except ImportError:
        raise ModelError(f"bridge file {path}: reading YAML needs PyYAML (pip install pyyaml); or write the "
                         "bridge as TOML") from None
    try:
        with open(path, encoding="utf-8") as f:
            data = yaml.load(f, Loader=_yaml_1_2_floats(yaml))
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise BridgeModelError(f"bridge file {path}: not valid YAML ({' '.join(str(exc).split())})") from None
    if not isinstance(data, dict):
        raise BridgeModelError(f"bridge file {path}: expected a mapping with a 'bridge' table, got "
                               f"{type(data).__name__}")
    return data


def _yaml_1_2_floats(yaml):
    """PyYAML's safe loader that reads YAML 1.2's floats too: PyYAML follows YAML 1.1, whose
    floats need a dot, so ``dt_s: 1e-3`` and ``E_Pa: 3.5e10`` were texts (refused as not
    numbers); a quoted ``"1e-3"`` stays a text. ``yaml`` is the PyYAML module."""
    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver("tag:yaml.org,2002:float",
                                 re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
                                 list("-+0123456789."))
    return Loader


def _description(path, suffix, track):
    data = _read_table(path, suffix)
    unknown = [k for k in data if k not in ("bridge", "analysis")]
    if unknown:
        raise BridgeModelError(f"bridge file {path}: unknown table {unknown[0]!r}; valid: bridge, analysis")
    table = data.get("bridge")
    if not isinstance(table, dict):
        raise BridgeModelError(f"bridge file {path}: no [bridge] table")
    table = dict(table)
    kind = table.pop("kind", None)
    if not isinstance(kind, str) or kind not in BRIDGE_KINDS:
        raise BridgeModelError(f"bridge file {path}: [bridge] kind must be one of "
                               f"{', '.join(map(repr, BRIDGE_KINDS))}, got {kind!r}")
    spec = BRIDGE_KINDS[kind]
    for key in table:
        if key not in spec.required + spec.optional:
            raise BridgeModelError(f"bridge file {path}: unknown key {key!r} in [bridge] (kind {kind!r}); valid: "
                                   f"{', '.join(spec.required + spec.optional)}")
    missing = [k for k in spec.required if k not in table]
    if missing:
        raise BridgeModelError(f"bridge file {path}: [bridge] (kind {kind!r}) needs {missing[0]!r}")
    if track is not None:
        table["track"] = track
    try:
        bridge = spec.build(table, os.path.dirname(path))
    except ModelError as exc:
        raise BridgeModelError(f"bridge file {path}: [bridge] {exc}") from None
    settings, seeds = _analysis(path, data.get("analysis", {}))
    return BridgeFile(path, bridge, settings, seeds)


def _analysis(path, table):
    if not isinstance(table, dict):
        raise BridgeModelError(f"bridge file {path}: [analysis] must be a table")
    settings, seeds = {}, None
    for key, value in table.items():
        if key == "seeds":
            if not (isinstance(value, list) and value and all(is_int(s) and s >= 0 for s in value)
                    and len(set(value)) == len(value)):
                raise BridgeModelError(f"bridge file {path}: [analysis] seeds must be a list of different integers "
                                       f">= 0, got {value!r}")
            seeds = tuple(value)
        elif key in ("exact_events", "bridge_self_weight") and not isinstance(value, bool):
            raise BridgeModelError(f"bridge file {path}: [analysis] {key} must be true or false, got {value!r}")
        elif key in ANALYSIS_KEYS:
            settings[ANALYSIS_KEYS[key]] = value
        else:
            raise BridgeModelError(f"bridge file {path}: unknown key {key!r} in [analysis]; valid: "
                                   f"{', '.join(list(ANALYSIS_KEYS) + ['seeds'])}")
    try:
        PassageSettings(**settings)
    except VtsiError as exc:
        raise BridgeModelError(f"bridge file {path}: [analysis] {exc}") from None
    return settings, seeds


def _number(table, key, positive=True):
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or (positive and not value > 0):
        raise ModelError(f"{key} must be a {'positive ' if positive else ''}number, got {value!r}")
    return float(value)


@bridge_kind("beam", required=("spans_m", "E_Pa", "mu_kg_m"), optional=("I_m4", "f1_Hz", "elements_per_span", "A_m2"),
             summary="continuous Euler-Bernoulli beam over spans_m, pin then rollers")
def _beam(table, base_dir):
    """A continuous beam (:func:`vtsi.sweep.beam_bridge`). ``I_m4`` or ``f1_Hz``: the first
    span's first frequency as a simply supported span, f1 = (π/L)² √(EI/μ) / 2π, gives
    EI = μ (2 f1 L² / π)²."""
    if "track" in table:
        raise ModelError(f"a beam has one track; --track (track = {table['track']!r}) is for model scripts")
    spans = table["spans_m"]
    spans = spans if isinstance(spans, list) else [spans]
    if not spans or any(isinstance(s, bool) or not isinstance(s, (int, float)) or not s > 0 for s in spans):
        raise ModelError(f"spans_m must be a list of positive numbers [m], got {table['spans_m']!r}")
    endless = next((s for s in spans if not math.isfinite(s)), None)
    if endless is not None:
        raise ModelError(f"spans_m: every span must be finite [m], got {endless:g}")
    check_span_lengths(spans, "spans_m")
    E, mu = _number(table, "E_Pa"), _number(table, "mu_kg_m")
    if ("I_m4" in table) == ("f1_Hz" in table):
        raise ModelError("give either I_m4 or f1_Hz (the first span's first bending frequency)")
    if "I_m4" in table:
        I = _number(table, "I_m4")
    else:
        L = float(spans[0])
        try:
            I = mu * (2.0 * _number(table, "f1_Hz") * L ** 2 / math.pi) ** 2 / E
        except OverflowError:
            I = math.inf
        if not (math.isfinite(I) and I > 0):
            raise ModelError(f"f1_Hz = {table['f1_Hz']!r} with spans_m[0] = {L:g} m gives I = {I:g} m^4, not a "
                             "finite second moment of area")
    n = table.get("elements_per_span", 10)
    if not is_int(n) or n < 2 or n % 2 or n > MAX_ELEMENTS_PER_SPAN:
        raise ModelError(f"elements_per_span must be an even integer from 2 to {MAX_ELEMENTS_PER_SPAN}, got {n!r}")
    A = _number(table, "A_m2") if "A_m2" in table else 1.0
    bridge = beam_bridge([float(s) for s in spans], E, I, mu, elements_per_span=n, A=A)
    if "f1_Hz" in table:
        bridge.description["f1_Hz"] = float(table["f1_Hz"])
    return bridge


@bridge_kind("script", required=("path",), optional=("track",),
             summary="an OpenSees model script (.tcl or .py; path relative to this file)")
def _script(table, base_dir):
    path = table["path"]
    if not isinstance(path, str) or os.path.splitext(path)[1].lower() not in SCRIPT_SUFFIXES:
        raise ModelError(f"path must name a {' or '.join(SCRIPT_SUFFIXES)} script, got {path!r}")
    path = os.path.join(base_dir, os.path.expanduser(path))
    if not os.path.isfile(path):
        raise ModelError(f"path: {path}: no such file")
    return script_bridge(path, table.get("track"))


# -- model scripts ---------------------------------------------------------------------------
def script_bridge(path, track=None):
    """Run the model script ``path`` (.tcl or .py) with vtsi's command layer in a fresh session
    and return its model and track as a SweepBridge (description: kind 'script', the absolute
    path, the file's sha256 and the track tag). The script's load patterns are dropped."""
    path = os.path.abspath(os.fspath(path))
    with open(path, "rb") as f:
        sha256 = hashlib.sha256(f.read()).hexdigest()
    session = opensees.Session()
    if path.lower().endswith(".tcl"):
        _run_tcl(path, session)
        session.syntax = "tcl"      # what is said of the script below names its commands in Tcl
    else:
        _run_python(path, session)
    model = session.domain
    if model is None or not model.nodes:
        hint = (" (an OpenSeesPy script must use vtsi's commands: import vtsi.opensees as ops)"
                if path.lower().endswith(".py") else "")
        raise BridgeModelError(f"bridge script {path}: defines no model (or ends with wipe){hint}")
    if session._units != Units():
        raise BridgeModelError(f"bridge script {path}: declares units {session._units}; a sweep's bridge must be SI "
                               "(N, kg, m, s): the sweep's trains and results are SI")
    tracks = dict(getattr(session, "_tracks", {}))
    if not tracks:
        raise BridgeModelError(f"bridge script {path}: defines no track; add one, e.g. 'track 1 -eleRange FIRST LAST' "
                               "(Tcl) or ops.track(1, '-eleRange', FIRST, LAST) (docs/commands.md)")
    if track is None:
        if len(tracks) > 1:
            raise BridgeModelError(f"bridge script {path}: defines tracks {', '.join(map(str, sorted(tracks)))}; "
                                   "choose one (--track TAG)")
        track = next(iter(tracks))
    if not is_int(track) or track not in tracks:
        raise BridgeModelError(f"bridge script {path}: no track {track!r}; it defines "
                               f"{', '.join(map(str, sorted(tracks)))}")
    for tag in list(model.patterns):
        model.remove_pattern(tag)
    try:
        Track(model, tracks[track])
    except ModelError as exc:     # Track's own messages begin 'track: '; the tag takes its place
        raise BridgeModelError(f"bridge script {path}: track {track}: {str(exc).removeprefix('track: ')}") from None
    description = {"kind": "script", "path": path, "sha256": sha256, "track": int(track)}
    modal_damping = ()
    if session._modal_damping is not None:      # modalDamping's ratios, on the modes of the latest eigen
        try:
            omega2, ratios = session._damped_modes(f"bridge script {path}")
        except CommandError as exc:
            raise BridgeModelError(str(exc)) from None
        modal_damping = tuple((math.sqrt(w2) / (2 * math.pi), float(z)) for w2, z in zip(omega2, ratios))
        description["modal_damping"] = [list(pair) for pair in modal_damping]
    return SweepBridge(model, list(tracks[track]), description, modal_damping)


def _run_tcl(path, session):
    try:
        interp = Interpreter(session)
    except ImportError as exc:
        raise ModelError(f"bridge script {path}: Tcl scripts need tkinter ({exc})") from None
    try:
        code = interp.source(path)
    except Exception as exc:      # the user's script: any error, re-raised naming the script and line
        line = script_line(exc, path)
        line = f", line {line}" if line else ""
        raise BridgeModelError(f"bridge script {path}{line}: {_first_line(exc)}") from None
    if code:
        raise BridgeModelError(f"bridge script {path}: exited with status {code}")


def _run_python(path, session):
    """Run the OpenSeesPy script ``path`` as ``__main__`` against ``session``; the classes and
    functions it defines (a user element type, a damping function) are then given a module of
    their own (:func:`_script_module`), so that a sweep's process pool can pickle the bridge."""
    old_session = opensees.set_session(session)
    old_argv, old_path = sys.argv, list(sys.path)
    sys.argv = [path]
    sys.path.insert(0, os.path.dirname(path))
    try:
        _script_module(path, runpy.run_path(path, run_name="__main__"))
    except SystemExit as exc:
        if exc.code not in (None, 0):
            raise BridgeModelError(f"bridge script {path}: exited with status {exc.code}") from None
    except Exception as exc:      # the user's script: any error, re-raised naming the script and line
        frames = [f for f in traceback.extract_tb(exc.__traceback__) if os.path.abspath(f.filename) == path]
        line = f", line {frames[-1].lineno}" if frames else ""
        raise BridgeModelError(f"bridge script {path}{line}: {_first_line(exc)}") from None
    finally:
        opensees.set_session(old_session)
        sys.argv, sys.path[:] = old_argv, old_path


def _script_module(path, namespace):
    """Make the script's own classes and functions (``__module__`` '__main__', which in the
    process that loads the bridge is vtsi's or the user's program, not the script) importable by
    pickle: they move to a module ``vtsi_bridge_script_<hash of the path>`` of the script's
    namespace, registered in ``sys.modules``. A sweep's workers forked from this process inherit
    it (``vtsi sweep``, and the Python API when no other thread runs, see
    :func:`vtsi.sweep._pool_context`)."""
    name = "vtsi_bridge_script_" + hashlib.sha256(path.encode()).hexdigest()[:16]
    module = types.ModuleType(name)
    module.__file__ = path
    module.__dict__.update(namespace)
    module.__name__ = name
    for value in namespace.values():
        if isinstance(value, (type, types.FunctionType)) and value.__module__ == "__main__":
            value.__module__ = name
    sys.modules[name] = module


def _first_line(exc):
    """The first line of a script's error: vtsi's own message as it is (it names the command and
    the value), any other error (Python's) after its class: 'NameError: name 'x' is not defined'."""
    text = str(exc).strip()
    text = text.splitlines()[0] if text else ""
    return text if isinstance(exc, VtsiError) else f"{type(exc).__name__}: {text}"


# -- the SI check ----------------------------------------------------------------------------
def mass_per_metre(bridge):
    """The model's whole vertical (uy) mass divided by its track's length [kg/m]."""
    return deck_mass_per_length(bridge.model, bridge.track_elements)


def _check_mass(bridge, path, minimum):
    """The sweep's own check (:func:`vtsi.sweep.check_deck_mass`), here as the file is read;
    ``minimum`` travels with the bridge, so that its sweep accepts what the file did."""
    check_deck_mass(bridge.model, bridge.track_elements, f"bridge file {path}", minimum)
    bridge.min_mass_per_metre = minimum
