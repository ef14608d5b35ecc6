"""The design-check workflow (docs/check.md): the stages one after the other, each doing its own
job on the results file — sweep (passages), check (criteria), the governing cases' histories (the
sweep again, for them only), the 3-D scene and the report. Used by ``vtsi check`` and
``examples/design_check.py``."""
import logging
import os

import numpy as np

from vtsi.check import SELF_WEIGHT_REFUSED, CheckSettings, check, refuse_inputs
from vtsi.errors import SweepError
from vtsi.report import report_folder, write_report
from vtsi.scene3d import animate_case, render_case, rendering_available
from vtsi.sweep import Sweep
from vtsi.sweep_results import ResultsWriter

log = logging.getLogger(__name__)


def design_check(sweep, path, settings=None, report_dir=None, *, workers=None, progress=None, resume=False,
                 overwrite=False, animation=False, animation_frames=None, refuse_first=True):
    """Run ``sweep`` into ``path``, check it (``settings``: :class:`~vtsi.check.CheckSettings`),
    store the check, record the governing cases' histories, render the 3-D scene of the largest
    deck acceleration (when off-screen rendering works here) and write the report into
    ``report_dir`` (default: ``<path without .h5>_report``); with ``animation`` also a GIF of
    that passage (``scene.gif``, about 10-20 s) of ``animation_frames`` frames (an integer >= 2;
    default :func:`~vtsi.scene3d.animate_case`'s: 4 n₀ T + 1 over the record's T seconds, at
    most 400).

    What the check would refuse on the sweep's inputs alone is refused before the sweep runs or
    anything is written (:func:`refuse_before_sweep`); ``refuse_first=False`` leaves that out for
    a caller that has just done it (``vtsi check``, which runs the sweep itself first), and the
    check refuses the same inputs on the results after the sweep.

    Returns ``(CheckResult, report paths: dict html, markdown, images, scene (a
    :class:`~vtsi.scene3d.RenderedScene`: its path, case, time and exaggeration, which the
    report's caption names) and animation (or None))``."""
    if not isinstance(sweep, Sweep):
        raise SweepError(f"design check: sweep must be a vtsi.sweep.Sweep, got {type(sweep).__name__}")
    if not isinstance(path, (str, os.PathLike)):
        raise SweepError(f"design check: the results file must be a path, got {path!r}")
    if not (settings is None or isinstance(settings, CheckSettings)):
        raise SweepError(f"design check: settings must be CheckSettings, got {type(settings).__name__}")
    if animation_frames is not None:
        if isinstance(animation_frames, bool) or not isinstance(animation_frames, (int, np.integer)) \
                or animation_frames < 2:
            raise SweepError(f"design check: animation_frames must be an integer >= 2, got {animation_frames!r}")
        if not animation:
            raise SweepError(f"design check: animation_frames = {animation_frames} is the GIF's: give animation=True")
    if refuse_first:
        refuse_before_sweep(sweep, settings)
    path = os.path.abspath(os.fspath(path))
    report_dir = os.path.abspath(report_folder(report_dir or os.path.splitext(path)[0] + "_report"))
    results = sweep.run(path, workers=workers, progress=progress, resume=resume, overwrite=overwrite)
    result = check(path, settings)
    result.store(path)
    governing = sorted({(r.train, r.speed_kmh, r.seed) for r in result.rows      # trains as the file names them
                        if r.train in results.trains and np.isfinite(r.speed_kmh)})
    if governing:
        sweep.record_histories(path, governing)
    available, reason = rendering_available()
    scene = render_case(path, os.path.join(report_dir, "scene.png")) if available else None
    movie = (animate_case(path, os.path.join(report_dir, "scene.gif"), max_frames=animation_frames)
             if available and animation else None)
    if scene is None:
        log.info("no 3-D scene: %s", reason)
    paths = write_report(path, report_dir, scene_png=scene, scene_case=None if scene is None else scene.case,
                         scene_animation=movie)
    return result, {**paths, "scene": scene, "animation": movie}


def refuse_before_sweep(sweep, settings=None):
    """Raise, before ``sweep`` runs or writes anything, the refusals of :func:`vtsi.check.check`
    that the sweep's inputs alone decide (its settings, bridge and outputs), with the check's own
    words: a sweep holding the bridge's self weight, and a deck acceleration output that counts
    fewer frequencies than the EN cut-off (a modal bridge's ``modal_hz``, an output's cut-off)
    or holds no deck node. The check's rule reads them from the sweep's results record before
    any case (an in-memory file: the bridge's record and the outputs as the sweep will write
    them), where it finds nothing else to judge. Used by :func:`design_check` and ``vtsi check``.

    Not decided here: 'the sweep kept none of the outputs the criteria read', which the check
    finds from the finished cases."""
    if sweep.settings.bridge_self_weight:
        raise SweepError(f"design {SELF_WEIGHT_REFUSED}")
    with ResultsWriter(None, sweep.identity(), sweep.runner) as writer:
        refuse_inputs(writer.results(), settings)
