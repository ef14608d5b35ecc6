"""Benchmark scenes: one module per scene (``s1.py`` … ``s7.py``), found automatically.

Contract of a scene (a subclass of :class:`Scene`, decorated with :func:`register`)
----------------------------------------------------------------------------------
1. ``name`` ('S1' …) and a one-line ``description`` (shown by ``run.py --list``).
2. ``requires``: importable modules the scene needs besides vtsi (e.g. ``('openseespy',)``
   for a scene measured against OpenSeesPy); ``run.py`` checks them first and stops with a
   message naming the missing one.
3. ``run(quick, baseline, repeats) -> dict``: measures the scene and returns a JSON-able dict
   with at least ``scene``, ``steps``, ``vtsi_s``, ``vtsi_us_per_step``, ``peer``, ``peer_s``,
   ``peer_us_per_step``, ``speedup``, ``max_rel_diff`` and a ``cases`` list (one dict per
   model size with the same fields). ``quick`` = a reduced size for tests (seconds, not
   minutes); ``baseline`` adds the ``baseline_*`` fields; ``repeats`` = best of how many.
   Nothing may be printed to stdout (``run.py --json`` prints one JSON object there).
4. ``columns``: ``(field, header, format)`` triples of the case table that ``run.py`` prints.
5. A scene that draws charts takes ``chart=None`` in ``run``: the path of a folder that exists
   (``run.py --chart DIR`` creates it before the run), where it writes its PNGs.

A new scene is a new module here; nothing else changes.
"""
import importlib
import pkgutil
import re

SCENES = {}


class Scene:
    """Base class of a benchmark scene; see the module docstring for the contract."""

    name = None
    description = ""
    requires = ()
    columns = ()

    def run(self, quick=False, baseline=False, repeats=3):
        raise NotImplementedError


def register(cls):
    """Class decorator: add a scene to :data:`SCENES` after checking the contract."""
    if not (isinstance(cls.name, str) and re.fullmatch(r"S\d+", cls.name)):
        raise TypeError(f"scene {cls.__name__}: name must look like 'S1', got {cls.name!r}")
    if cls.name in SCENES:
        raise TypeError(f"scene {cls.name} is registered twice ({SCENES[cls.name].__class__.__name__}, {cls.__name__})")
    if not cls.description or "\n" in cls.description:
        raise TypeError(f"scene {cls.name}: needs a one-line description")
    if cls.run is Scene.run:
        raise TypeError(f"scene {cls.name}: must implement run()")
    SCENES[cls.name] = cls()
    return cls


def discover():
    """Import every scene module of this package; returns ``{name: scene}`` in scene order."""
    for info in pkgutil.iter_modules(__path__):
        if re.fullmatch(r"s\d+", info.name):
            importlib.import_module(f"{__name__}.{info.name}")
    return dict(sorted(SCENES.items(), key=lambda kv: int(kv[0][1:])))
