"""The report of a sweep and its check: one self-contained HTML file and the same content as
Markdown with PNG charts (docs/report.md).

    from vtsi.report import write_report
    paths = write_report("hslm.h5", "report/")     # report/report.html, report/report.md, report/img/*.png

A report lays out what the check found, the last stage of sweep → check → report
(docs/check.md): it reads everything from the results file
(:class:`~vtsi.sweep_results.SweepResults` and the check stored there,
:func:`~vtsi.check.stored_check`), runs no passage and evaluates no criterion. The only numbers it
derives are plotting quantities from stored values: the peak over rail samples of each train's
envelope, DAF = y_dyn / y_stat (the stored dynamic mid-span deflection over the stored static one
under the same train), the deflection as the check reads it at each speed (max |y_dyn| +
φ''/2 |y_stat|, :func:`~vtsi.check.node_deflections`), the resonance speeds v = n₀ D / i (EN
1991-2 §6.4.6.2, i = 1 … :data:`~vtsi.signature.HARMONICS`) marked on the acceleration chart (n₀
each deck's, and n₂ of each continuous deck), the approach the passages started from and how long
they ran after the last axle left the track (the stored n_steps × Δt: the free vibration, or a
car body's run-out), and the times at which an axle is on a deck in a history chart (not on the
approaches).

Sections, in this order (each an HTML ``<section id=...>`` and a Markdown ``##`` heading):

===========  ======================================================================================
summary      the verdict (the check's one line: PASS, FAIL or NO VERDICT), the sweep's
             extent, one line per criterion with its governing case
checks       the check's table: criterion, value, limit, utilisation, status, governing train,
             speed [km/h], place, clause; every number also as ``data-value`` (its ``repr``, the
             stored float exactly) in the HTML; an info row has no utilisation and shows its
             limit as a reference ('ref.', data-field ``reference``) or as not checked; the
             rows' notes and the check's settings (those about cars only if cars ran)
bridge       its description, spans, deck (of several decks each deck's own nodes), first
             vertical frequencies [Hz] (of several decks each deck's too), the EN cut-off [Hz],
             damping, a chart of the first mode shapes along the deck (a spline per deck)
trains       name, axles, total static load [kN], length [m], characteristic length D [m] (to
             the mm), fidelity
settings     the passages' settings, the acceleration cut-off, the vtsi version, the results
             file (contact and car outputs only if cars ran)
envelopes    charts against speed [km/h], one line per train: peak deck acceleration [m/s²] with
             the check's limit and the resonance speeds; the largest span deflection as the
             check reads it, max |y_dyn| + φ''/2 |y_stat| [mm], with L/600; DAF
histories    per governing case recorded with :meth:`~vtsi.sweep.Sweep.record_histories`: the
             acceleration [m/s²] and deflection [mm] at each span's middle (a style per span),
             and the contact forces [kN] (their 10 ms mean) and car bodies' accelerations
             [m/s²] if present (in black the wheel and the car the check's envelopes name on
             the bridge, counted from 1), against time [s]; the caption names only what is drawn
scene        (optional) a 3-D scene image rendered elsewhere (:mod:`vtsi.scene3d`)
===========  ======================================================================================

Every train has one colour in every chart and in the trains table. The HTML embeds its charts as
base64 PNGs and its style sheet inline: it loads nothing and needs no JavaScript. Charts are drawn
with matplotlib (the extra ``plot``) through its object API (no pyplot state).
"""
import base64
import datetime
import html
import io
import math
import os
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vtsi.version import __version__
from vtsi.check import (ABSMAX, STATIC_LOAD_MODELS, bridge_model_text, hslm_b_source, mid_span_ratios,
                        node_deflections, stored_check)
from vtsi.codes.en1990_a2 import DEFLECTION_SPAN_RATIO
from vtsi.codes.en1991_2 import HSLM_B
from vtsi.damping import deck_frequencies_table
from vtsi.deck_record import deck_nodes
from vtsi.errors import SweepError
from vtsi.passage import FREE_VIBRATION_PERIODS, HISTORY_OUTPUTS, contact_force_reach, en_cutoff_hz
from vtsi.places import car_label, wheel_label
from vtsi.scene3d import car_body_offsets, check_scene_case, deck_spline, nodes_by_deck
from vtsi.signature import HARMONICS
from vtsi.speed_grid import en_series
from vtsi.sweep import resonance_speeds
from vtsi.sweep_results import (ENVELOPE_ROWS, SweepResults, case_key, deck_ranges, open_results, significant_text,
                                span_decks, x_tolerance)

SECTIONS = ("summary", "checks", "bridge", "trains", "settings", "envelopes", "histories", "scene")
RESONANCE_ORDERS = tuple(range(1, HARMONICS + 1))   # v = n0 D / i marked: the orders of the EN series' resonances
RESONANCE_RANGE_TOLERANCE = 0.005     # a resonance this fraction of the speed range past its end is marked
RESONANCE_LABEL_BAND = 0.6            # resonance labels stay in this upper fraction of the chart
MODES_SHOWN = 3
# Two lines of the deflection chart closer than this share of its axis cannot be told apart: a
# 2 px gap between a 1.6 pt and a 1.4 pt line on its 3.5 in axis at 110 dpi needs 1.1 % of it.
DISTINCT_SHARE = 0.012
CAR_RESPONSES = ("contact_force", "car_body_accel")   # outputs a sweep of moving forces does not fill
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
MIN = ENVELOPE_ROWS.index("min")

# Distinct colours, one per train (tab10, then ten more that stay apart from them); past twenty
# trains the colours repeat with dashed lines.
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
           "#bcbd22", "#17becf", "#000000", "#b8860b", "#4b0082", "#00a087", "#ff1493", "#556b2f",
           "#8b0000", "#4682b4", "#a0522d", "#708090")
LIMIT_COLOUR = "#c0392b"
# A history chart's spans other than the governing one (drawn in the train's colour): one style
# each, colours at least 27 CIELAB ΔE76 units from every colour of PALETTE (a train's) and from
# LIMIT_COLOUR, and 24 from one another, so that no span reads as a train or a limit.
SPAN_STYLES = (("#992255", "-."), ("#ccaa77", "--"), ("#99aaff", (0, (1, 1.2))), ("#77bb77", (0, (6, 2, 1, 2))),
               ("#ccaadd", (0, (3, 1))), ("#ff9999", (0, (8, 2))))
HISTORY_PANELS = ("accel", "disp", "contact_force", "car_body_accel")
# The rows read at a node whose quantity a history panel draws: {panel: criteria}.
HISTORY_CRITERIA = {"accel": ("deck_acceleration",),
                    "disp": ("dynamic_increment", "deflection", "deflection_overhang")}
UNIT_TEXT = {"m/s^2": "m/s²", "-": "", "rad": "rad", "m": "m", "passages": "passages"}
CHART_STYLE = {"font.size": 11, "axes.titlesize": 12, "axes.labelsize": 11, "legend.fontsize": 9,
               "xtick.labelsize": 10, "ytick.labelsize": 10, "axes.grid": True, "grid.alpha": 0.3,
               "axes.spines.top": False, "axes.spines.right": False, "savefig.dpi": 110,
               "font.family": "DejaVu Sans"}


# -- the content: blocks rendered both as HTML and as Markdown -------------------------------------
@dataclass
class Cell:
    """A table cell: its text and the HTML attributes it carries (e.g. data-value)."""

    text: str
    attrs: dict = field(default_factory=dict)
    cls: str = ""


@dataclass
class Table:
    head: list
    rows: list                               # lists of Cell (or str)
    row_attrs: list = None                   # per row: dict of HTML attributes
    table_id: str = ""
    cls: str = ""


@dataclass
class Paragraph:
    text: str
    cls: str = ""


@dataclass
class Items:
    items: list
    cls: str = ""


@dataclass
class Chart:
    """A PNG figure: ``name`` is its file name stem under img/ (and its data-chart attribute)."""

    name: str
    png: bytes
    caption: str
    alt: str


@dataclass
class Heading:
    text: str


@dataclass
class Section:
    id: str
    title: str
    blocks: list


# -- the report ------------------------------------------------------------------------------------
def write_report(results_path, out_dir, *, title=None, scene_png=None, scene_case=None, scene_animation=None):
    """Write the report of the sweep and check stored in ``results_path``.

    Parameters
    ----------
    results_path : a sweep's results file (HDF5) holding a check (:meth:`CheckResult.store`).
    out_dir : directory (made if missing) of report.html, report.md and img/*.png; those files
        are overwritten, any other file there is left alone.
    title : the report's title (default: "Dynamic analysis: <file name>").
    scene_png : optional path of a 3-D scene image (PNG) rendered elsewhere; embedded in the
        "3-D scene" section. A :class:`~vtsi.scene3d.RenderedScene` (what
        :func:`~vtsi.scene3d.render_case` returns) brings its case for the caption.
    scene_case : optional mapping of what ``scene_png`` draws, for its caption: ``train``,
        ``speed_kmh``, ``seed`` (-1: smooth rail), ``time_s`` (the time drawn) and ``scale`` (the
        displacements' exaggeration); any key may be left out. Default: ``scene_png.case`` where
        it has one; without either the caption says the image alone names them. Checked against
        the sweep as :func:`~vtsi.scene3d.render_case` checks its arguments
        (:func:`~vtsi.scene3d.check_scene_case`).
    scene_animation : optional path of an animation of the scene's passage (GIF or MP4, e.g.
        :func:`~vtsi.scene3d.animate_case`'s); the caption names it (by its name when it lies in
        ``out_dir``, else by its path) and, for a :class:`~vtsi.scene3d.RenderedAnimation`
        whose frames alias the deck's vibration, says so. It is not copied or embedded.

    Returns
    -------
    dict with ``html`` (Path), ``markdown`` (Path) and ``images`` (list of Path, the PNGs).

    Raises
    ------
    SweepError : the file is missing, not a results file, or holds no check; an argument of the
        wrong kind; a scene image not found or not a PNG; a scene case the sweep does not have.
    ModelError : the scene case's time outside its record, or its scale not a number > 0 (as
        :func:`~vtsi.scene3d.render_case`).
    """
    if not isinstance(results_path, (str, os.PathLike)):
        raise SweepError(f"report: the results file must be a path, got {results_path!r}")
    if not (title is None or isinstance(title, str)):
        raise SweepError(f"report: the title must be text, got {title!r}")
    if not (scene_png is None or isinstance(scene_png, (str, os.PathLike))):
        raise SweepError(f"report: the scene image must be a path, got {scene_png!r}")
    if scene_case is None and isinstance(getattr(scene_png, "case", None), dict):
        scene_case = scene_png.case                    # a RenderedScene names what it drew
    if not (scene_case is None or isinstance(scene_case, dict)):
        raise SweepError(f"report: the scene's case must be a dict (train, speed_kmh, seed, time_s, scale), got "
                         f"{scene_case!r}")
    if not (scene_animation is None or isinstance(scene_animation, (str, os.PathLike))):
        raise SweepError(f"report: the scene's animation must be a path, got {scene_animation!r}")
    if scene_animation is not None and not Path(scene_animation).is_file():
        raise SweepError(f"report: the scene's animation {Path(scene_animation)} is not a file")
    if scene_animation is not None and scene_png is None:
        raise SweepError("report: a scene animation needs its scene image (scene_png): the caption names it")
    path = Path(results_path)
    if not path.is_file():
        raise SweepError(f"report: results file {path} not found")
    try:
        results = SweepResults(os.fspath(path))
        checked = stored_check(os.fspath(path))
    except OSError as exc:
        raise SweepError(f"report: results file {path} is not a readable HDF5 file ({exc})") from None
    if checked is None:
        raise SweepError(f"report: results file {path} holds no check; run the check first "
                         "(vtsi.check.check(results).store(path))")
    scene = None
    if scene_png is not None:
        scene = Path(scene_png)
        if not scene.is_file():
            raise SweepError(f"report: scene image {scene} not found")
        if scene.read_bytes()[:8] != PNG_MAGIC:
            raise SweepError(f"report: scene image {scene} is not a PNG file")
    title = title or f"Dynamic analysis: {path.name}"
    report = _Report(results, checked, path.resolve())
    report.scene_case = check_scene_case(results, scene_case or {})
    if scene_animation is not None:
        movie = Path(scene_animation).resolve()
        beside = isinstance(out_dir, (str, os.PathLike)) and movie.parent == Path(out_dir).resolve()
        report.scene_animation = movie.name if beside else str(movie)
        report.scene_aliasing = getattr(scene_animation, "aliasing", "")
    sections = report.sections(scene)

    out = report_folder(out_dir)
    img = out / "img"
    img.mkdir(exist_ok=True)
    images = []
    for chart in _charts(sections):
        target = img / f"{chart.name}.png"
        target.write_bytes(chart.png)
        images.append(target)
    meta = (f"Results file {path.resolve()} · sweep by vtsi {results.vtsi_version} · report by vtsi "
            f"{__version__} on {datetime.date.today().isoformat()}")
    html_path, md_path = out / "report.html", out / "report.md"
    html_path.write_text(_html(title, meta, sections), encoding="utf-8")
    md_path.write_text(_markdown(title, meta, sections), encoding="utf-8")
    return {"html": html_path, "markdown": md_path, "images": images}


def report_folder(out_dir):
    """The report's directory ``out_dir`` as a Path, made if missing (with its parents); a
    SweepError naming it when it is not a path, is a file or cannot be made."""
    if not isinstance(out_dir, (str, os.PathLike)):
        raise SweepError(f"report: the report directory must be a path, got {out_dir!r}")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SweepError(f"report: {out} is a file, not a directory for the report")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepError(f"report: cannot make the report directory {out} ({exc.strerror or exc})") from None
    return out


class _Report:
    """The sections of one report, from a results file and its check."""

    def __init__(self, results, checked, path):
        self.results, self.checked, self.path = results, checked, path
        self.bridge = results.bridge()
        self.outputs = {o["name"]: o for o in results.identity["outputs"]}
        self.settings = results.identity["settings"]
        self.colours = {t: PALETTE[i % len(PALETTE)] for i, t in enumerate(results.trains)}
        self.styles = {t: "-" if i < len(PALETTE) else "--" for i, t in enumerate(results.trains)}
        self.trains = {t: results.train_data(t) for t in results.trains}
        self.rows = checked.rows

    def sections(self, scene):
        """The sections in the order of :data:`SECTIONS`; the scene only with a ``scene`` PNG."""
        build = {"summary": self.summary, "checks": self.checks, "bridge": self.bridge_section,
                 "trains": self.trains_section, "settings": self.settings_section,
                 "envelopes": self.envelopes, "histories": self.histories,
                 "scene": lambda: self.scene_section(scene)}
        return [build[name]() for name in SECTIONS if name != "scene" or scene is not None]

    scene_case = {}
    scene_animation = None      # the animation's name (in the report's directory) or path, for the caption
    scene_aliasing = ""         # how the animation's frames alias the deck's vibration ('' when they do not)

    def scene_section(self, scene):
        return Section("scene", "3-D scene", [
            Chart("scene", scene.read_bytes(), self.scene_caption(scene.name), "3-D scene")])

    def scene_caption(self, name):
        """What the scene image ``name`` draws: the case, the time and the exaggeration as far as
        :attr:`scene_case` gives them (checked: :func:`~vtsi.scene3d.check_scene_case`), how the
        deck and a train of cars are drawn (:mod:`vtsi.scene3d`), and the animation, with how its
        frames alias the deck's vibration when they do (:attr:`scene_aliasing`)."""
        c = self.scene_case
        what = []
        if "train" in c:
            seed = c["seed"]
            what.append(f"{c['train']} at {_fmt_speed(c['speed_kmh'])} km/h"
                        + (f", rail sample {seed}" if seed >= 0 else ", smooth rail"))
        if "time_s" in c:
            what.append(f"at t = {c['time_s']:.4g} s")
        text = f"The passage{' of ' + ' '.join(what) if what else ''} as a 3-D scene ({name})"
        drawn = "the deck's vertical displacements, drawn through a cubic spline between its nodes"
        drawn += (f", exaggerated × {c['scale']:g}" if "scale" in c else
                  ", exaggerated (the factor is written in the image)")
        cars = "train" in c and car_body_offsets(self.trains[c["train"]]) is not None
        train = ("the axles where they are at that time, the car bodies drawn rigid on their wheels (the results file "
                 "holds their accelerations, not their motion)" if cars else "the axles where they are at that time")
        unnamed = "" if what else "; the case and time are written in the image's title and legend"
        movie = ""
        if self.scene_animation:
            movie = f" The whole passage as an animation: {self.scene_animation} (not embedded)."
            if self.scene_aliasing:
                movie += f" In it, {self.scene_aliasing}."
        return f"{text}: {drawn}; {train}{unnamed}.{movie}"

    # -- helpers ------------------------------------------------------------------------------
    def row(self, criterion):
        return next((r for r in self.rows if r.criterion == criterion), None)

    def governing_cases(self):
        """The distinct (train, speed, seed) the check names, with the criteria each governs."""
        cases = {}
        for r in self.rows:
            if r.train and r.train in self.results.trains and not math.isnan(r.speed_kmh):
                cases.setdefault((r.train, float(r.speed_kmh), int(r.seed)), []).append(r.criterion)
        return cases

    def case_text(self, train, speed, seed):
        text = f"{train} at {_fmt_speed(speed)} km/h"
        return text + (f", rail sample {seed}" if seed >= 0 else "")

    def output(self, response, cutoff=None):
        """The first output of ``response`` (with a cut-off first when ``cutoff``, without one when
        False): as the check picks it."""
        names = [n for n, o in self.outputs.items() if o["response"] == response]
        if cutoff:
            names = [n for n in names if self.outputs[n].get("cutoff_hz") is not None] or names
        elif cutoff is False:
            names = [n for n in names if self.outputs[n].get("cutoff_hz") is None]
        return names[0] if names else None

    # -- sections -----------------------------------------------------------------------------
    def summary(self):
        res, passed = self.results, self.checked.passed
        verdict = self.checked.verdict(_label)
        kind = "pass" if passed else "fail" if any(r.status == "fail" for r in self.rows) else "none"
        v = res.speeds_kmh
        seeds = "smooth rail" if res.seeds == [-1] else f"{len(res.seeds)} rail samples"
        extent = (f"{_plural(len(res.trains), 'train')} × {_plural(len(v), 'speed')} "
                  f"({_fmt_speed(v.min())}–{_fmt_speed(v.max())} km/h) "
                  f"× {seeds}: {res.n_done} of {res.n_cases} passages in the file.")
        blocks = [Paragraph(verdict, "verdict " + kind), Paragraph(extent)]
        if res.n_done < res.n_cases:
            blocks.append(Paragraph(f"The sweep is incomplete ({res.n_cases - res.n_done} passages missing): "
                                    "the check covers the passages in the file only.", "warning"))
        lines = []
        for r in self.rows:
            value = self.value_text(r)
            bound = self.bound_text(r)
            if bound:
                value += f" ({bound}" + (f", utilisation {_num(r.utilisation)})" if self.held(r) and
                                         not math.isnan(r.utilisation) else ")")
            where = []
            if r.train:
                where.append(self.case_text(r.train, r.speed_kmh, r.seed) if not math.isnan(r.speed_kmh) else r.train)
            if r.where:
                where.append(r.where)
            lines.append(f"{r.status.upper()} {_label(r.criterion)}: {value}"
                         + (f" — {', '.join(where)}" if where else ""))
        blocks += [Heading("Governing cases"), Items(lines, "governing")]
        return Section("summary", "Summary", blocks)

    def value_text(self, row):
        """A row's value with its units (4 significant digits); a count of passages as 'k of n
        passages' (:meth:`~vtsi.check.CheckResult.value_text`)."""
        return self.checked.value_text(row, _num(row.value), _units)

    def held(self, row):
        """Whether ``row`` is held to its limit (pass or fail): only then has it a utilisation."""
        return row.status != "info"

    def bound_text(self, row):
        """What the row's limit is, in words: 'limit 3.5 m/s²' for a row held to it; for an info
        row 'reference 1' (a value to compare with, e.g. dynamic vs LM71/SW/0: above 1 the dynamic
        analysis governs) or 'limit 0.6, not checked' (the check cannot hold the value to it);
        '' without one."""
        if math.isnan(row.limit):
            return ""
        number = f"{_num(row.limit)} {_units(row.units)}".strip()
        if self.held(row):
            return f"limit {number}"
        if row.criterion in self.checked.unchecked:
            return f"limit {number}, not checked"
        return f"reference {number}"

    def checks(self):
        head = ["criterion", "value", "limit / ref.", "utilisation", "status", "governing train", "speed km/h",
                "place", "clause"]
        rows, attrs = [], []
        for r in self.rows:
            rows.append([
                Cell(_label(r.criterion), {"data-field": "criterion"}),
                Cell(self.value_text(r), {"data-field": "value", "data-value": repr(float(r.value)),
                                          "data-units": r.units}, "num"),
                self.limit_cell(r),
                Cell(_num(r.utilisation), {"data-field": "utilisation", "data-value": repr(float(r.utilisation))},
                     "num") if self.held(r) else Cell("—", {"data-field": "utilisation"}, "num"),
                Cell(r.status.upper(), {"data-field": "status"}, "status " + r.status),
                Cell(r.train + (f" (rail sample {r.seed})" if r.train and r.seed >= 0 else "") or "—",
                     {"data-field": "train", "data-seed": str(int(r.seed))}),
                Cell(_fmt_speed(r.speed_kmh), {"data-field": "speed_kmh", "data-value": repr(float(r.speed_kmh))},
                     "num"),
                Cell(r.where or "—", {"data-field": "where"}),
                Cell(r.clause, {"data-field": "clause"}),
            ])
            attrs.append({"data-criterion": r.criterion, "data-status": r.status})
        blocks = [Table(head, rows, attrs, "check-table", "checks")]
        kinds = {"ref.": "a value to compare with (dynamic vs LM71/SW/0: above 1 the dynamic analysis, not Φ × "
                         "LM71/SW/0, governs the design)",
                 "not checked": "a limit the check cannot hold the value to (see the row's note)"}
        shown = [k for k in kinds if any(not self.held(r) and not math.isnan(r.limit)
                                         and (r.criterion in self.checked.unchecked) == (k == "not checked")
                                         for r in self.rows)]
        if shown:
            blocks.append(Paragraph("INFO rows are not held to a limit and have no utilisation; "
                                    + "; ".join(f"'{k}': {kinds[k]}" for k in shown) + "."))
        blocks.append(Paragraph(f"Check settings: {self.checked.settings_text()}."))
        if self.checked.frequency_limits:
            blocks.append(Paragraph(f"{self.checked.frequency_limits}."))
        notes = [f"{_label(r.criterion)}: {r.note}" for r in self.rows if r.note]
        if notes:
            blocks += [Heading("Notes"), Items(notes, "notes")]
        return Section("checks", "Checks", blocks)

    def limit_cell(self, row):
        """The limit of a row held to it (data-field 'limit'); an info row's value to compare with
        as 'ref. …' (data-field 'reference') or its limit as '… (not checked)'; '—' without one."""
        units = _units(row.units)
        number = f"{_num(row.limit)} {units}".strip()
        if math.isnan(row.limit) or self.held(row):
            return Cell(number if not math.isnan(row.limit) else "—",
                        {"data-field": "limit", "data-value": repr(float(row.limit))}, "num")
        if row.criterion in self.checked.unchecked:
            return Cell(f"{number} (not checked)", {"data-field": "limit", "data-value": repr(float(row.limit))}, "num")
        return Cell(f"ref. {number}", {"data-field": "reference", "data-value": repr(float(row.limit))}, "num")

    def bridge_section(self):
        b, desc = self.bridge, self.results.identity["bridge"]
        spans = np.asarray(b["span_lengths_m"], dtype=float)
        freqs = np.asarray(b["frequencies_hz"], dtype=float)
        several = len(deck_ranges(b)) > 1
        keys = sorted(desc, key=lambda k: k != "kind")        # spans_m: the 'spans' row below
        rows = [[DESCRIPTION_TEXT[k][0], f"{_value_text(desc[k])} {DESCRIPTION_TEXT[k][1]}"] if k in DESCRIPTION_TEXT
                else [_key_text(k), _value_text(desc[k])] for k in keys if k != "spans_m"]
        x = np.asarray(b["deck_x_m"], dtype=float)     # every node of the track, the approaches' too
        rows += [["spans", " + ".join(f"{s:g}" for s in spans) + f" m ({len(spans)} span{'s' * (len(spans) > 1)})"]]
        decks = nodes_by_deck(x, deck_ranges(b), x_tolerance(b))     # each deck: its extent and its own nodes
        rows += [[f"deck {d + 1}" if several else "deck", f"{e - a:.4g} m, {len(mine)} nodes (x = {a:g} … {e:g} m)"]
                 for d, ((a, e), mine) in enumerate(zip(deck_ranges(b), decks))]
        if several or len(deck_nodes(b)) < len(x):      # the track runs beyond the decks: on the approaches
            rows += [["track nodes", f"{x.max() - x.min():.4g} m, {len(x)} nodes (x = {x.min():g} … "
                                     f"{x.max():g} m)"]]
        rows += [["mid-span nodes", ", ".join(str(int(n)) for n in b["midspan_nodes"])],
                 ["first vertical frequencies" + (" of the model" if several else ""),
                  ", ".join(significant_text(f) for f in freqs) + " Hz"]]
        if several:                                     # each deck's n₀, n₂, n₃
            rows += [[f"deck {d + 1} (x = {a:g} … {e:g} m): n₀, n₂, n₃",
                      ", ".join(significant_text(f) for f in row) + " Hz"]
                     for d, ((a, e), row) in enumerate(zip(deck_ranges(b), deck_frequencies_table(b)))]
        rows += [["EN cut-off max(30 Hz, 1.5 n₀, n₃)",
                  f"{significant_text(en_cutoff_hz(b))} Hz" + (" (the largest of the decks')" if several else "")],
                 ["damping", _damping_text(self.settings)]]
        blocks = [Table(["property", "value"], rows, cls="properties")]
        if "mode_shapes_uy" in b and np.size(b["mode_shapes_uy"]):
            line = ("on each deck a cubic spline through its own nodes" if several else
                    "a cubic spline through the deck's nodes")
            off = len(_off_deck_steps(x, decks)) > 0            # approaches, joints
            blocks.append(Chart("mode_shapes", _mode_shapes_png(b), "The first vertical mode shapes along the deck: "
                                f"dots the nodal values, lines {line}"
                                + (" (straight between the nodes off the decks)" if off else "")
                                + ", each mode scaled so that its line's largest value is 1; triangles: the supports.",
                                "mode shapes"))
        else:
            blocks.append(Paragraph("The results file holds no mode shapes."))
        return Section("bridge", "Bridge", blocks)

    def trains_section(self):
        cars = self.settings.get("cars")
        rows, attrs = [], []
        for t in self.results.trains:
            d = self.trains[t]
            loads = np.asarray(d["static_wheel_loads_N"], dtype=float)
            D = float(d.get("characteristic_length_m", np.nan))
            fidelity = "axle loads (moving forces)" if cars == "force" else \
                f"{int(d['n_cars'])} cars, {int(d['n_dof'])} DOF ({cars})"
            rows.append([Cell("", {"style": f"background:{self.colours[t]}"}, "swatch"), Cell(t),
                         Cell(str(len(d["axle_offsets_m"])), cls="num"), Cell(f"{loads.sum() / 1e3:.5g}", cls="num"),
                         Cell(_length(d["length_m"]), cls="num"), Cell(_length(D), cls="num"), Cell(fidelity)])
            attrs.append({"data-train": t})
        head = ["", "train", "axles", "total static load kN", "length m", "D m", "fidelity"]
        hslm_b = [f"{t}: N = {len(d['axle_offsets_m'])} forces of {float(d['static_wheel_loads_N'][0]) / 1e3:g} kN at "
                  f"d = D = {_length(float(d['characteristic_length_m']))} m; N and d: {hslm_b_source(self.results)}."
                  for t, d in self.trains.items() if d["name"] == HSLM_B]
        return Section("trains", "Trains", [
            Table(head, rows, attrs, "train-table", "trains"),
            Paragraph("Length: from the first to the last axle. D: the characteristic length (coach length) "
                      "of EN 1991-2 §6.4.6.2, used for the resonance speeds v = n₀ D / i.")]
            + [Paragraph(text) for text in hslm_b])

    def settings_section(self):
        s, res = self.settings, self.results
        cutoffs = [f"{n}: {significant_text(o['cutoff_hz'])} Hz" for n, o in self.outputs.items()
                   if o.get("cutoff_hz") is not None]
        irregularity = s.get("irregularity")
        cars = s.get("cars") != "force"
        rows = [["bridge model", bridge_model_text(res, res.bridge())],
                ["time step dt", f"{s['dt']:g} s"],
                ["integrator", str(s["integrator"])],
                ["cars (fidelity)", "force (moving axle loads)" if not cars else str(s["cars"])],
                ["contact", str(s["contact"]) if cars else "not used (no cars in the sweep)"],
                ["interpolation", str(s["interpolation"])],
                ["exact events", "yes" if s.get("exact_events") else "no"],
                ["damping", _damping_text(s)],
                ["rail", "smooth" if irregularity is None else
                 f"irregular, {irregularity}, samples {', '.join(str(k) for k in res.seeds)}"],
                ["approach", self.approach_text()],
                list(self.run_end_text()),
                ["bridge self weight", "included" if s.get("bridge_self_weight") else "not included"],
                ["acceleration cut-off", "; ".join(cutoffs) if cutoffs else "none (the FE model's full response)"],
                ["outputs", ", ".join(f"{n} ({o['response']})" for n, o in self.outputs.items()
                                      if cars or o["response"] not in CAR_RESPONSES)],
                ["speeds", self.speeds_text()],
                ["vtsi version", f"{res.vtsi_version} (sweep), {__version__} (report)"],
                ["results file", str(self.path)]]
        checked = self.checked.settings                 # provenance stored with the check (none by an older vtsi)
        if checked.damping_source:
            rows.insert([r[0] for r in rows].index("damping") + 1, ["damping from", checked.damping_source])
        if checked.line_speed_kmh is not None:
            rows.insert([r[0] for r in rows].index("speeds"), ["line speed", self.line_speed_text()])
        return Section("settings", "Settings", [Table(["setting", "value"], rows, cls="properties")])

    def line_speed_text(self):
        """The line speed stored with the check and whether the speeds reach 1.2 × it (EN 1991-2
        6.4.6.2(1))."""
        line = self.checked.settings.line_speed_kmh
        top, needed = float(np.max(self.results.speeds_kmh)), 1.2 * line
        reach = (f"the speeds reach 1.2 × it = {_fmt_speed(needed)} km/h" if top >= needed - 1e-6 else
                 f"the speeds stop at {_fmt_speed(top)} km/h, short of 1.2 × it = {_fmt_speed(needed)} km/h")
        return f"{_fmt_speed(line)} km/h: {reach} (EN 1991-2 6.4.6.2(1))"

    def approach_text(self):
        """Where the trains start: the first axle's distance before the track at t = 0 [m], from the
        stored start positions (x_head0) and the trains' first axle offsets, and whether it is the
        default (:meth:`vtsi.passage.PassageRunner.approach`: 0 for moving forces, 25 m for cars on
        a smooth rail, on an irregular one the rail's fade-in plus the run in which the car bodies
        settle: 212 m for an ICE3 at 300 km/h)."""
        s = self.settings
        x0 = np.asarray(self.results.start_positions(), dtype=float)      # (n_train, n_speed, n_seed)
        begin = float(np.min(np.asarray(self.bridge["deck_x_m"], dtype=float)))
        gaps = set()
        for i, t in enumerate(self.results.trains):
            first = float(np.asarray(self.trains[t]["axle_offsets_m"], dtype=float)[0])
            for x in np.ravel(x0[i]):
                if np.isfinite(x):
                    gaps.add(round(begin - (x - first), 3))
        how = "the default" if s.get("approach") is None else "set"
        if not gaps:
            return how if s.get("approach") is None else f"{s['approach']:g} m"
        value = " to ".join(f"{g:g}" for g in sorted(gaps)[:: max(len(gaps) - 1, 1)])
        return f"{value} m ({how}): the first axle's distance before the track's first node at t = 0"

    def run_end_text(self):
        """``(label, text)`` of the settings row saying how long each passage ran after its last
        axle left the track [s]: each case's stored record, n_steps × Δt, past that time (the
        stored x_head0, axle offsets and speed); the free vibration (the setting, or its default
        FREE_VIBRATION_PERIODS periods of the model's first mode) and, where the records run
        longer (a sweep reading car bodies runs until the last one stops counting:
        :meth:`vtsi.passage.PassageRunner.n_steps`), the car bodies' run-out they run on to (the
        trains' stored body_runout_s)."""
        s = self.settings
        f1 = float(np.ravel(self.bridge["frequencies_hz"])[0])
        if s.get("free_vibration") is None:
            free = FREE_VIBRATION_PERIODS / f1
            free_text = (f"{free:.3g} s (the default, {FREE_VIBRATION_PERIODS:g} periods of the model's first vertical "
                         f"mode, {significant_text(f1)} Hz)")
        else:
            free = float(s["free_vibration"])
            free_text = f"{free:g} s"
        after = self.run_after_track()
        runouts = {t: float(self.trains[t].get("body_runout_s", np.nan)) for t in after}
        longer = [t for t, a in after.items() if np.max(a) > free + float(s["dt"]) and np.isfinite(runouts[t])]
        if not longer:
            return "free vibration", f"{free_text} after the last axle leaves the track"
        values = np.concatenate(list(after.values()))
        span = " to ".join(sorted({_num(values.min()), _num(values.max())}, key=float))
        each = ", ".join(f"{t} {_num(runouts[t], 3)} s" for t in longer)
        return ("free vibration and car-body run-out",
                f"{span} s after the last axle leaves the track (each record's end, n_steps × Δt): the free vibration, "
                f"{free_text}, run on until the last car body stops counting, its run-out after the train's last "
                f"wheel leaves the decks ({each}: half a period of the car's lowest mode, wheels held, how long the "
                "check counts a car body's acceleration after it leaves)")

    def run_after_track(self):
        """``{train: (n_case,) [s]}``: how long each stored passage of the train ran after its last
        axle left the track, n_steps × Δt − (x_end − x_head0 + its last axle's offset) / V, x_end
        the track's last node."""
        dt, x_end = float(self.settings["dt"]), float(np.max(self.bridge["deck_x_m"]))
        with open_results(self.path) as f:
            g = f["cases"]
            if "train" not in g:
                return {}
            trains, speeds, steps, heads = (g[k][()] for k in ("train", "speed_kmh", "n_steps", "x_head0"))
        out = {}
        for i, t in enumerate(self.results.trains):
            mine = trains == i
            if np.any(mine):
                last = float(np.max(self.trains[t]["axle_offsets_m"]))
                out[t] = steps[mine] * dt - (x_end - heads[mine] + last) / (speeds[mine] / 3.6)
        return out

    def speeds_text(self):
        """The sweep's speeds: how many, their range and steps, or that they are the EN 1991-2
        6.4.6.2 series (:func:`~vtsi.speed_grid.en_series`), and where the check found them coarser
        than it (:attr:`~vtsi.check.CheckResult.speed_grid`)."""
        v = np.unique(self.results.speeds_kmh)
        text = f"{_plural(len(v), 'speed')}, {_fmt_speed(v.min())}–{_fmt_speed(v.max())} km/h"
        if len(v) < 2:
            return text
        en = en_series(self.results, self.bridge)
        steps = np.unique(np.round(np.diff(v), 2))
        if en is not None and len(en) == len(v) and np.allclose(en, v, atol=0.01):
            fine = any(not float(d["characteristic_length_m"]) > 0 for d in self.trains.values())   # no D: fine
            text += (": the EN 1991-2 6.4.6.2 series (vtsi.sweep.en_speed_grid: " +
                     (f"steps of at most {_fmt_speed(steps.max())} km/h throughout, for a train without D)" if fine
                      else "10 km/h steps, finer ones within ±10 % of each resonance v = n D / i)"))
        elif len(steps) == 1:
            text += f" in steps of {_fmt_speed(steps[0])} km/h"
        else:
            text += f" in steps of {_fmt_speed(steps.min())} to {_fmt_speed(steps.max())} km/h"
        if self.checked.speed_grid:
            text += f"; {self.checked.speed_grid} (see the check's notes)"
        return text

    def envelopes(self):
        blocks = []
        accel = self.output("accel", cutoff=True)
        if accel is not None:
            blocks.append(Chart("acceleration", self.acceleration_png(accel), self.acceleration_caption(accel),
                                "peak deck acceleration against speed"))
        disp = self.output("disp", cutoff=False)
        if disp is not None:
            checked, dynamic = self.deflection_curves(disp)
            blocks.append(Chart("deflection", self.deflection_png(checked, dynamic),
                                self.deflection_caption(disp, checked, dynamic),
                                "largest deflection against speed"))
            daf = self.daf_png(disp)
            if daf is not None:
                blocks.append(Chart("daf", daf, "DAF = y_dyn / y_stat: the largest dynamic mid-span deflection "
                                    "over the static deflection under the same train (the check's φ'_dyn + 1). "
                                    "Star: the governing case.", "dynamic amplification against speed"))
        if not blocks:
            blocks.append(Paragraph("The sweep kept no deck acceleration or deflection output."))
        return Section("envelopes", "Envelopes", blocks)

    def histories(self):
        recorded = set(self.results.histories())
        blocks, shown = [], set()
        for (train, speed, seed), criteria in self.governing_cases().items():
            key = case_key(train, speed, seed)
            text = self.case_text(train, speed, seed)
            if key not in recorded:
                blocks.append(Paragraph(f"{text} (governs {', '.join(_label(c) for c in criteria)}): no time "
                                        "histories recorded (Sweep.record_histories)."))
                continue
            shown.add(key)
            panels = self.history_panels(train, speed, seed)
            marked = self.history_marks(train, speed, seed, panels)
            blocks += [Heading(f"{text}: governs {', '.join(_label(c) for c in criteria)}"),
                       Chart(f"history_{len(shown)}", self.history_png(train, speed, seed, panels, marked),
                             self.history_caption(text, panels, marked, (train, speed, seed)),
                             f"time histories of {text}")]
        if not self.governing_cases():
            blocks.append(Paragraph("The check names no governing passage."))
        elif not shown:
            blocks.insert(0, Paragraph("No time histories of the governing cases are recorded in the results file: "
                                       "Sweep.record_histories(path, cases) adds them."))
        others = sorted(recorded - shown)
        if others:
            blocks.append(Paragraph("Other cases with recorded histories (not shown): " + ", ".join(others) + "."))
        return Section("histories", "Time histories", blocks)

    # -- charts -------------------------------------------------------------------------------
    def _per_train(self, values, pick):
        """``{train: (speeds, values)}`` of ``values`` (n_train, n_speed, n_seed, ...) reduced by
        ``pick`` over every axis after speed, trains without any value left out."""
        out = {}
        for i, t in enumerate(self.results.trains):
            v = values[i].reshape(len(self.results.speeds_kmh), -1)
            ok = ~np.all(np.isnan(v), axis=1)
            if ok.any():
                out[t] = (self.results.speeds_kmh[ok], pick(v[ok], axis=1))
        return out

    def _lines(self, ax, curves):
        for t, (v, y) in curves.items():
            ax.plot(v, y, self.styles[t], color=self.colours[t], lw=1.6, marker="o", ms=2.5, label=t)

    def _speed_axis(self, ax):
        """The same speed axis [km/h] on every chart against speed."""
        lo, hi = float(self.results.speeds_kmh.min()), float(self.results.speeds_kmh.max())
        pad = 0.015 * (hi - lo) if hi > lo else 0.05 * hi
        ax.set_xlim(lo - pad, hi + pad)
        ax.set_xlabel("speed [km/h]")

    def _governing_star(self, ax, row, y, what=""):
        """The governing case of ``row`` at ``y``, labelled with its train, speed and ``what`` (its
        value as text, '' for none)."""
        if row is not None and row.train in self.results.trains and not math.isnan(row.speed_kmh):
            ax.plot([row.speed_kmh], [y], "*", color=self.colours[row.train], mec="black", ms=15, zorder=5,
                    label=f"governing: {what + ', ' if what else ''}{row.train}\n"
                          f"at {_fmt_speed(row.speed_kmh)} km/h")

    def acceleration_png(self, name):
        res = self.results
        env, columns = res.column_envelopes(name)       # the deck's nodes, as the check reads them
        on_deck = np.isin(columns, np.asarray(sorted(deck_nodes(self.bridge))))
        curves = self._per_train(env[..., ABSMAX, :][..., on_deck] if on_deck.any() else
                                 res.envelope(f"{name}_absmax"), np.nanmax)
        row = self.row("deck_acceleration")
        with _figure((11, 5.6)) as (fig, ax):
            self._lines(ax, curves)
            if row is not None and not math.isnan(row.limit):
                ax.axhline(row.limit, color=LIMIT_COLOUR, ls="--", lw=2,
                           label=f"limit {_num(row.limit)} m/s²")
                self._governing_star(ax, row, row.value)
            top = max([np.nanmax(y) for _, y in curves.values()] + [row.limit if row is not None else 0.0])
            if top > 0:
                ax.set_ylim(0, 1.22 * top)
            n0, n2 = self.marked_frequencies()
            lengths = {t: float(self.trains[t].get("characteristic_length_m", np.nan)) for t in curves}
            marks = _resonance_marks(n0, lengths, res.speeds_kmh)
            second = _resonance_marks(n2, lengths, res.speeds_kmh) if len(n2) else []
            for v, t, i in marks:
                ax.axvline(v, color=self.colours[t], ls=":", lw=1.2, alpha=0.9)
            for v, t, i in second:
                ax.axvline(v, color=self.colours[t], ls=(0, (6, 3)), lw=0.9, alpha=0.7)
            self._speed_axis(ax)
            ax.set_ylabel("peak deck acceleration [m/s²]")
            ax.set_title(f"Peak deck acceleration (n₀ = {', '.join(significant_text(f) for f in n0)} Hz"
                         + (f"; n₂ = {', '.join(significant_text(f) for f in n2)} Hz" if len(n2) else "") + ")")
            _resonance_labels(ax, sorted([(v, t, f"{i}") for v, t, i in marks]
                                         + [(v, t, f"{i} (n₂)") for v, t, i in second]), self.colours)
            _legend(ax)
            return _png(fig)

    def marked_frequencies(self):
        """``(n₀, n₂)`` [Hz] whose resonances the acceleration chart marks: each deck's n₀, and the
        n₂ of each continuous deck (of several spans), whose second mode is a bending mode of
        its own near n₀ (a simply supported deck's n₂ = 4 n₀ puts its resonances far above the
        swept speeds). EN 1991-2 6.4.6.2 names n₀; vtsi's EN series also resolves n₂ and n₃."""
        table, decks = deck_frequencies_table(self.bridge), span_decks(self.bridge)
        n2 = [float(table[d, 1]) for d in range(len(table)) if np.sum(decks == d) > 1 and np.isfinite(table[d, 1])]
        return np.unique(table[:, 0]), np.unique(n2)       # each deck's n₀: its own resonances

    def acceleration_caption(self, name):
        """The acceleration chart's caption: its curves and which resonances it marks."""
        n0, n2 = self.marked_frequencies()
        return (f"Peak deck acceleration ({name}, the largest over its nodes on the deck, spans and overhangs"
                f"{' and rail samples' if len(self.results.seeds) > 1 else ''}) against speed. Dashed red: the "
                "check's limit. Dotted verticals: the resonance speeds v = n₀ D / i (i = "
                f"{', '.join(str(i) for i in RESONANCE_ORDERS)}) of each train, n₀ each deck's first vertical "
                "frequency, labelled 'train D/i'"
                + ("; dashed verticals, labelled 'train D/i (n₂)': the same for n₂, the second vertical frequency of "
                   "each continuous deck" if len(n2) else "")
                + " (n₃'s are not marked). Star: the governing case.")

    def deflection_curves(self, name):
        """``(checked, dynamic)`` of output ``name`` against speed, ``{train: (speeds, [mm])}`` each,
        the largest over the spans' nodes and rail samples: ``checked`` what the deflection row
        holds to L/600, max |y_dyn| + φ''/2 |y_stat,train| (:func:`~vtsi.check.node_deflections`,
        the check's stored settings), ``dynamic`` max |y_dyn| alone; ``checked`` None (and
        ``dynamic`` the output's whole envelope) when the sweep kept no static values or no
        node of a span."""
        nodes = node_deflections(self.results, name, self.bridge, self.checked.settings)
        spans = [n for n in nodes or () if n.criterion == "deflection"]
        if not spans:
            curves = self._per_train(self.results.envelope(f"{name}_min"), np.nanmin)
            return None, {t: (v, -1e3 * y) for t, (v, y) in curves.items()}
        largest = [np.fmax.reduce(np.stack([getattr(n, kind) for n in spans], axis=-1), axis=-1)
                   for kind in ("checked", "dynamic")]                    # NaN only where every node is
        return tuple({t: (v, 1e3 * y) for t, (v, y) in self._per_train(values, np.nanmax).items()}
                     for values in largest)

    def share_text(self):
        """φ''/2 (careful maintenance) or φ'' (standard): the share of φ'' the check counts."""
        return "φ''/2" if self.checked.settings.maintenance == "careful" else "φ''"

    def deflection_caption(self, name, checked, dynamic):
        """The deflection chart's caption: what its curves are (``checked``, ``dynamic``:
        :meth:`deflection_curves` of output ``name``; ``checked`` None: the raw deflection) and
        what else it draws (:meth:`deflection_png`)."""
        if checked is None:
            return (f"Largest downward deflection of the deck ({name}) against speed (the sweep kept no static "
                    f"deflections: the check's max |y_dyn| + {self.share_text()} |y_stat| cannot be drawn).")
        row = self.row("deflection")
        text = (f"Largest downward deflection of the spans ({name}) against speed, as the deflection row reads it: "
                f"max |y_dyn| + {self.share_text()} |y_stat,train| (EN 1991-2 6.4.6.5(3), y_stat the static "
                "deflection under the same train), the largest over the spans' nodes. Red: L/600.")
        if row is not None and row.train in self.results.trains:
            gap = self.static_share(checked, dynamic)
            text += (" Dotted, in the governing train's colour: its max |y_dyn| alone." if gap is None else
                     f" The governing train's max |y_dyn| alone lies {gap} mm under its curve ({self.share_text()} "
                     f"|y_stat| adds that, as its legend says), less than {100 * DISTINCT_SHARE:g} % of the axis: "
                     "too close to draw apart, so not drawn.")
            text += " Star: the governing case."
        elif row is not None and row.train in STATIC_LOAD_MODELS:
            text += f" Dotted grey: Φ α × {row.train}'s static deflection, which governs."
        return text

    def deflection_png(self, checked, dynamic):
        """The deflection chart: ``checked`` (None: ``dynamic`` instead) and, dotted, the governing
        train's ``dynamic`` (:meth:`deflection_curves`)."""
        row = self.row("deflection")
        with _figure((11, 4.6)) as (fig, ax):
            self._lines(ax, dynamic if checked is None else checked)
            governing = row is not None and row.train in (checked or {})
            gap = self.static_share(checked, dynamic) if governing else None
            if governing and gap is None:
                v, y = dynamic[row.train]
                ax.plot(v, y, ":", color=self.colours[row.train], lw=1.4,
                        label=f"{row.train}: max |y_dyn| alone")
            elif governing:                         # the dotted line would hide under the curve: said instead
                line = next(line for line in ax.get_lines() if line.get_label() == row.train)
                line.set_label(f"{row.train} ({self.share_text()} |y_stat| adds {gap} mm)")
            if row is not None and not math.isnan(row.limit):      # the check's L/600, one line per span length
                spans = sorted({round(float(L), 6) for L in self.bridge["span_lengths_m"]})
                for k, L in enumerate(spans):
                    limit = 1e3 * L / DEFLECTION_SPAN_RATIO
                    label = f"limit L/600 = {_num(limit)} mm" + (f" ({_num(L)} m spans)" if len(spans) > 1 else "")
                    ax.axhline(limit, color=LIMIT_COLOUR, ls=("--", "-.", ":")[k % 3], lw=2, label=label)
                if row.train in STATIC_LOAD_MODELS:      # the row's value is LM71's or SW/0's, which no curve shows
                    ax.axhline(1e3 * row.value, color="0.35", ls=":", lw=1.5,
                               label=f"Φ α × {row.train}: {_num(1e3 * row.value)} mm (governs)")
            if governing:
                self._governing_star(ax, row, 1e3 * row.value, f"{_num(1e3 * row.value)} mm")
            ax.set_ylim(0, self.deflection_top(checked, dynamic))
            self._speed_axis(ax)
            ax.set_ylabel("largest downward deflection [mm]" if checked is None else
                          f"max |y_dyn| + {self.share_text()} |y_stat| [mm]")
            ax.set_title("Largest deck deflection" if checked is None else
                         "Largest span deflection, as the check reads it")
            _legend(ax)
            return _png(fig)

    def deflection_top(self, checked, dynamic):
        """The top [mm] of the deflection chart's axis (its bottom is 0): 1.05 × the largest value
        it draws (the curves, the limits L/600, Φ α × LM71 where it governs, the star)."""
        curves = dynamic if checked is None else checked
        values = [float(np.nanmax(y)) for _, y in curves.values()] + [0.0]
        if checked is not None:
            values += [float(np.nanmax(y)) for _, y in dynamic.values()]
        row = self.row("deflection")
        if row is not None and not math.isnan(row.limit):
            values += [1e3 * float(L) / DEFLECTION_SPAN_RATIO for L in self.bridge["span_lengths_m"]]
            values.append(1e3 * float(row.value))
        top = 1.05 * max(values)
        return top if top > 0 else 1.0

    def static_share(self, checked, dynamic):
        """How much φ''/2 |y_stat| (or φ'') adds to the governing train's max |y_dyn| [mm], as text
        ('0.12' or '0.11–0.12'), when the most it adds is less than DISTINCT_SHARE of the
        deflection chart's axis (:meth:`deflection_top`): the dotted max |y_dyn| would lie under
        the curve; None when it is drawn apart (or there is no such curve)."""
        row = self.row("deflection")
        if checked is None or row is None or row.train not in checked or row.train not in dynamic:
            return None
        (v, total), (w, alone) = checked[row.train], dynamic[row.train]
        both, i, j = np.intersect1d(v, w, return_indices=True)
        added = total[i] - alone[j]
        added = added[np.isfinite(added)]
        if not both.size or not added.size or added.max() >= DISTINCT_SHARE * self.deflection_top(checked, dynamic):
            return None
        return "–".join(dict.fromkeys((_num(added.min(), 2), _num(added.max(), 2))))

    def daf_png(self, name):
        ratios = mid_span_ratios(self.results, name, MIN, self.bridge)
        if ratios is None:
            return None
        curves = self._per_train(ratios[0], np.nanmax)
        row = self.row("dynamic_increment")
        with _figure((11, 4.6)) as (fig, ax):
            self._lines(ax, curves)
            ax.axhline(1.0, color="black", lw=0.8)
            if row is not None:
                self._governing_star(ax, row, row.value + 1.0)
            ax.set_ylim(top=1.06 * max([np.nanmax(y) for _, y in curves.values()] + [1.0]))
            self._speed_axis(ax)
            ax.set_ylabel("DAF = y_dyn / y_stat [-]")
            ax.set_title("Dynamic amplification of the mid-span deflection")
            _legend(ax)
            return _png(fig)

    def _governed(self, train, speed, seed):
        """``{criterion: node}``: the rows this case governs at a node (their place 'node …')."""
        return {r.criterion: int(r.where.split()[1]) for r in self.rows
                if (r.train, r.speed_kmh, r.seed) == (train, speed, seed) and r.where.startswith("node ")}

    def _history_nodes(self, kind, train, speed, seed):
        """The nodes drawn in a history panel: ``[(node, label, governing)]``, each span's middle
        and each node at which this case governs a criterion of that panel's quantity (the
        acceleration: deck acceleration; the deflection: the dynamic increment of the mid-span
        deflection and the deflection rows), those nodes (``governing``) in the train's colour;
        none is when the case governs no such row."""
        criteria = HISTORY_CRITERIA[kind]
        nodes = {}
        for criterion, node in self._governed(train, speed, seed).items():
            if criterion in criteria:
                nodes.setdefault(node, []).append(_label(criterion))
        mid = [int(n) for n in self.bridge["midspan_nodes"]]
        out = []
        for j, n in enumerate(mid):
            label = f"span {j + 1} middle, node {n}" if len(mid) > 1 else f"mid-span, node {n}"
            out.append((n, label + (f"\ngoverns {', '.join(nodes[n])}" if n in nodes else ""), n in nodes))
        for n, governs in nodes.items():
            if n not in mid:
                out.append((n, f"node {n}\ngoverns {', '.join(governs)}", True))
        return out

    def history_panels(self, train, speed, seed):
        """The panels of a case's history chart: ``{response: history name}`` in the order accel,
        disp, contact_force, car_body_accel, each response with a recorded history holding values."""
        h = self.results.history(train, speed, seed)
        responses = {o.name: o.response for o in HISTORY_OUTPUTS}
        responses.update({n: o["response"] for n, o in self.outputs.items()})
        kinds = {}
        for name in h:
            if name != "attrs" and responses.get(name) in HISTORY_PANELS and np.size(h[name][1]):
                kinds.setdefault(responses[name], name)
        return {k: kinds[k] for k in HISTORY_PANELS if k in kinds}

    def history_marks(self, train, speed, seed, panels):
        """The wheel and the car body drawn in black in a case's history chart: ``{response:
        (column, label)}`` for 'contact_force' (the wheel with the lowest force on the bridge)
        and 'car_body_accel' (the car with the largest acceleration on the bridge), as the
        check reads them from the sweep's envelopes (:meth:`vtsi.passage.PassageRunner.counted`;
        on an irregular rail the run's extremes may lie on the ground beside the bridge); from
        the history itself where the sweep kept no such output. Labels count from 1."""
        h = self.results.history(train, speed, seed)
        case = None
        data = self.trains[train]
        out = {}
        for kind, row, pick in (("contact_force", MIN, np.nanargmin), ("car_body_accel", ABSMAX, np.nanargmax)):
            if kind not in panels:
                continue
            _, values, columns = h[panels[kind]]
            name = self.output(kind)
            envelope = None
            if name is not None:
                case = self.results.case(train, speed, seed) if case is None else case
                if name in case and np.any(np.isfinite(case[name]["envelope"][row])):
                    envelope = case[name]["envelope"][row]
            if envelope is None:        # the history's own extreme
                envelope = np.nanmin(values, axis=0) if kind == "contact_force" else np.nanmax(np.abs(values), axis=0)
            column = int(pick(envelope)) if np.size(envelope) else 0
            k = int(np.asarray(columns)[column]) if column < len(columns) else column
            out[kind] = (column, wheel_label(k, data) if kind == "contact_force" else car_label(k, int(data["n_cars"])))
        return out

    def history_caption(self, text, panels, marked=None, case=None):
        """The caption of a history chart: what its panels draw, and nothing else; with ``case``
        (train, speed, seed), the nodes drawn in the train's colour (where the case governs a row of
        a drawn quantity) and the rows it governs whose quantity no panel draws (a bending moment,
        an end rotation)."""
        marked = marked or {}
        n_spans = len(self.bridge["midspan_nodes"])
        where = "at each span's middle" if n_spans > 1 else "at mid-span"
        governed = self._governed(*case) if case is not None else {}
        drawn = {c for k in ("accel", "disp") if k in panels for c in HISTORY_CRITERIA[k]}
        coloured = [f"{_label(c)} at {self.row(c).where}" for c in governed if c in drawn]
        elsewhere = [f"{_label(c)} at {self.row(c).where}" for c in governed if c not in drawn]
        shown = []
        if "accel" in panels:
            row = self.row("deck_acceleration")
            limit = row is not None and not math.isnan(row.limit)
            shown.append("the deck acceleration [m/s²]" + (" (dashed red: ± the check's limit)" if limit else ""))
        if "disp" in panels:
            shown.append("the deflection [mm]")
        parts = []
        if shown:
            style = ["one line style per span"] if n_spans > 1 else []
            if coloured:
                style.append(f"in the train's colour: where this case governs {'; '.join(coloured)}")
            parts.append(" and ".join(shown) + f" {where}" + (f" ({'; '.join(style)})" if style else ""))
        if "contact_force" in panels:
            parts.append("the contact force [kN] of every wheel (its 10 ms mean, as the check reads it; black: "
                         f"{marked['contact_force'][1] if 'contact_force' in marked else 'the wheel'}, the lowest "
                         "on the bridge; dotted: while it counts, on a deck)")
        if "car_body_accel" in panels:
            row = self.row("car_body_acceleration")
            limit = row is not None and not math.isnan(row.limit)
            parts.append("the car bodies' vertical acceleration [m/s²] (each at its centre or over either bogie, as "
                         "the check reads it; black: "
                         f"{marked['car_body_accel'][1] if 'car_body_accel' in marked else 'the car'}, the largest on "
                         "the bridge; dotted: while it counts, a wheel of it on a deck and the run-out after"
                         + ("; dashed red: ± the comfort limit" if limit else "") + ")")
        missing = (f" This case {'also ' if coloured else ''}governs {'; '.join(elsewhere)}: the histories do not hold that quantity "
                   "(bending moments and rotations are not recorded as histories)." if elsewhere else "")
        if not parts:
            return f"{text}: no acceleration, deflection, contact force or car body history recorded." + missing
        return f"{text}: " + "; ".join(parts) + ", against time; shaded: while an axle is on a deck." + missing

    def _counted(self, kind, train, speed, x_head0, column):
        """``(t_first, t_last)`` [s] while the marked wheel's contact force (``kind``
        'contact_force', contact wheel ``column``) or car body ('car_body_accel', car ``column``)
        counts in the check (:meth:`vtsi.passage.PassageRunner.counted`): from its first wheel
        reaching the decks' first end to its last wheel leaving their last, widened by the 10 ms
        mean's reach (a wheel) or followed by the train's run-out (a car body, the stored
        body_runout_s); over several decks the stretches between them are inside."""
        data = self.trains[train]
        offsets = np.asarray(data["axle_offsets_m"], dtype=float)
        V = speed / 3.6
        if kind == "contact_force":
            offsets = offsets[[int(np.asarray(data["contact_wheels"])[column])]]
            before = after = contact_force_reach(float(self.settings["dt"]))
        else:
            offsets = offsets[np.asarray(data["wheel_car"]) == column]
            runout = float(data.get("body_runout_s", 0.0))
            before, after = 0.0, runout if np.isfinite(runout) else 0.0
        ends = np.asarray(deck_ranges(self.bridge), dtype=float)
        if not len(offsets) or not len(ends):
            return ()
        return (ends.min() - x_head0 + offsets.min()) / V - before, (ends.max() - x_head0 + offsets.max()) / V + after

    @staticmethod
    def _one_among_many(ax, time, values, one, colour, label, counted):
        """Columns of ``values`` faint, column ``one`` in black with ``label``, and the dotted
        times ``counted`` between which it counts in the check, those within the data's times
        only: the end of a window that goes on past the run (a car body's, in histories of a
        sweep without a car-body output or of an older vtsi, whose runs were not extended to hold
        it, :meth:`vtsi.passage.PassageRunner.n_steps`) is not drawn, and the legend says so."""
        for j in range(values.shape[1]):
            if j != one:
                ax.plot(time, values[:, j], color=colour, lw=0.5, alpha=0.35)
        if values.size:
            ax.plot(time, values[:, one], color="black", lw=1.2, label=label)
            end = float(time[-1]) + 1e-9 * max(1.0, abs(float(time[-1])))
            inside = [t for t in counted if t <= end]
            text = "while it counts" + ("" if len(inside) == len(counted) else " (past the run's end)")
            for k, t in enumerate(inside):
                ax.axvline(t, color="black", ls=":", lw=1.0, label=text if k == 0 else None)

    def _limit_lines(self, ax, criterion):
        """± the limit [m/s²] of the check's row ``criterion``, dashed, when it has one."""
        row = self.row(criterion)
        if row is not None and not math.isnan(row.limit):
            for sign in (1, -1):
                ax.axhline(sign * row.limit, color=LIMIT_COLOUR, ls="--", lw=1.5,
                           label=f"±limit {_num(row.limit)} m/s²" if sign > 0 else None)

    def history_png(self, train, speed, seed, kinds, marked=None):
        h = self.results.history(train, speed, seed)
        marked = marked if marked is not None else self.history_marks(train, speed, seed, kinds)
        panels = list(kinds)
        colour = self.colours[train]
        data = self.trains[train]
        x0 = float(h["attrs"].get("x_head0", 0.0))
        on = _axles_on_decks(deck_ranges(self.bridge), data["axle_offsets_m"], x0, speed / 3.6)
        with _figure((11, 2.9 * max(len(panels), 1) + 0.6), n_rows=max(len(panels), 1)) as (fig, axes):
            axes = np.atleast_1d(axes)
            for ax, kind in zip(axes, panels):
                time, values, columns = h[kinds[kind]]
                for stretch in on:
                    ax.axvspan(*stretch, color="#f2f2f2", zorder=0)
                if kind in ("accel", "disp"):
                    scale = 1.0 if kind == "accel" else 1e3
                    for j, (node, label, governing) in enumerate(self._history_nodes(kind, train, speed, seed)):
                        c = np.flatnonzero(np.asarray(columns) == node)
                        if c.size:
                            other, ls = SPAN_STYLES[j % len(SPAN_STYLES)]
                            ax.plot(time, scale * values[:, c[0]], color=colour if governing else other,
                                    lw=1.3 if governing else 1.2, ls="-" if governing else ls, label=label,
                                    zorder=3 if governing else 2)
                    if kind == "accel":
                        self._limit_lines(ax, "deck_acceleration")
                        ax.set_ylabel("acceleration [m/s²]")
                    else:
                        ax.set_ylabel("deflection [mm]\n(positive up)")
                elif kind == "contact_force":
                    forces = values / 1e3
                    worst, label = marked.get(kind, (0, "wheel 1"))
                    self._one_among_many(ax, time, forces, worst, colour, f"{label}\n(lowest on the bridge)",
                                         self._counted(kind, train, speed, x0, int(np.asarray(columns)[worst])))
                    if forces.size and np.nanmin(forces) < 0.5 * np.nanmedian(forces):
                        ax.axhline(0.0, color=LIMIT_COLOUR, lw=1, ls="--", label="lift-off (0 kN)")
                    ax.set_ylabel("contact force [kN]\n(compression +)")
                else:
                    worst, label = marked.get(kind, (0, "car 1"))
                    self._one_among_many(ax, time, values, worst, colour, f"{label}\n(largest on the bridge)",
                                         self._counted(kind, train, speed, x0, int(np.asarray(columns)[worst])))
                    self._limit_lines(ax, "car_body_acceleration")
                    ax.set_ylabel("car body\nacceleration [m/s²]")
                _legend(ax)
            axes[-1].set_xlabel("time [s]")
            axes[0].set_title(self.case_text(train, speed, seed))
            if not panels:
                axes[0].text(0.5, 0.5, "no acceleration, deflection, contact force or car body history",
                             transform=axes[0].transAxes, ha="center")
            return _png(fig)


def _axles_on_decks(deck_ends, offsets, x_head0, speed):
    """The stretches of time [s] while an axle is on a deck, ``[(t_on, t_off), ...]`` in time
    order, overlapping ones merged: axle k at ``offsets[k]`` [m] behind the head, the head at
    ``x_head0`` [m] at t = 0 running at ``speed`` [m/s] along +x, is on the deck from x = a to b
    (a row of ``deck_ends``, :func:`~vtsi.sweep_results.deck_ranges`) from (a - x_head0 +
    offsets[k]) / speed to (b - x_head0 + offsets[k]) / speed; on the approaches and on a rail
    joint between decks no axle is on a deck."""
    offsets = np.asarray(offsets, dtype=float)
    stretches = sorted(((a - x_head0 + o) / speed, (b - x_head0 + o) / speed)
                       for a, b in np.asarray(deck_ends, dtype=float) for o in offsets)
    merged = []
    for t_on, t_off in stretches:
        if merged and t_on <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], t_off))
        else:
            merged.append((t_on, t_off))
    return merged


def _drawn_mode_shape(x, phi, decks, points=400):
    """A mode shape as drawn: ``(nodal values, xs, curve)`` [-], ``x`` [m] the nodes (x order),
    ``phi`` their values, ``decks`` each deck's node indices (:func:`~vtsi.scene3d.nodes_by_deck`).
    On each deck the curve is the deck's line through its own nodes
    (:func:`~vtsi.scene3d.deck_spline`: a cubic spline, as the 3-D scene draws it), at about
    ``points`` x over the whole length; between consecutive nodes not on one deck (an approach, a
    joint) a straight line; a NaN between pieces. Both are scaled so that the curve's largest
    absolute value (at ``xs`` and the nodes) is +1: the nodes stay within ±1."""
    x, phi = np.asarray(x, dtype=float), np.asarray(phi, dtype=float)
    length = max(float(x[-1] - x[0]), 1e-300)
    pieces = []
    for mine in (m for m in decks if len(m)):
        a, b = float(x[mine].min()), float(x[mine].max())
        at = np.unique(np.concatenate([np.linspace(a, b, max(24, int(round(points * (b - a) / length)))), x[mine]]))
        pieces.append((at, deck_spline(x[mine], phi[mine])(at)))
    pieces += [(x[i: i + 2], phi[i: i + 2]) for i in _off_deck_steps(x, decks)]
    pieces.sort(key=lambda piece: piece[0][0])
    xs = np.concatenate([np.append(at, np.nan) for at, _ in pieces])[:-1]
    curve = np.concatenate([np.append(y, np.nan) for _, y in pieces])[:-1]
    drawn = np.concatenate([curve[np.isfinite(curve)], phi])
    peak = drawn[np.argmax(np.abs(drawn))]
    return (phi / peak, xs, curve / peak) if peak else (phi, xs, curve)


def _off_deck_steps(x, decks):
    """The indices i of the nodes ``x`` [m] (x order) from which a drawn mode shape runs straight
    to node i + 1: the two not on one deck (``decks``: each deck's node indices; an approach, a
    joint) and apart in x."""
    deck_of = np.full(len(x), -1)
    for d, mine in enumerate(decks):
        deck_of[mine] = d
    return [i for i in range(len(x) - 1) if (deck_of[i] < 0 or deck_of[i] != deck_of[i + 1]) and x[i + 1] > x[i]]


def _mode_shapes_png(bridge):
    x = np.asarray(bridge["deck_x_m"], dtype=float)
    shapes = np.asarray(bridge["mode_shapes_uy"], dtype=float)
    freqs = np.asarray(bridge["frequencies_hz"], dtype=float)
    order = np.argsort(x, kind="stable")            # nodes at one x keep the track's order
    x, shapes = x[order], shapes[order]
    decks = nodes_by_deck(x, deck_ranges(bridge), x_tolerance(bridge))
    supports = np.unique(bridge["span_ends_m"])
    with _figure((11, 3.8)) as (fig, ax):
        for k in range(min(MODES_SHOWN, shapes.shape[1])):
            phi, xs, curve = _drawn_mode_shape(x, shapes[:, k], decks)
            colour = ("#1f3b73", "#c0392b", "#27ae60")[k % 3]
            ax.plot(xs, curve, color=colour, lw=1.8,
                    label=f"mode {k + 1}: {significant_text(freqs[k])} Hz" if k < len(freqs) else f"mode {k + 1}")
            ax.plot(x, phi, "o", color=colour, ms=3)
        ax.axhline(0, color="black", lw=0.8)
        ax.plot(supports, np.zeros_like(supports), "^", color="black", ms=11, clip_on=False, label="supports")
        ax.set_ylim(-1.25, 1.25)
        ax.set_xlabel("x along the deck [m]")
        ax.set_ylabel("vertical mode shape [-]")
        ax.set_title("First vertical mode shapes")
        _legend(ax)
        return _png(fig)


def _resonance_marks(n0, lengths, speeds_kmh):
    """The resonance speeds v = n₀ D / i [km/h] (i in RESONANCE_ORDERS) within the swept speeds:
    ``[(v, train, i)]`` sorted by v, for ``lengths`` ``{train: D [m]}`` (NaN: none) and ``n0``
    [Hz] one frequency or each deck's (a 15 m and a 30 m deck resonate at their own speeds). A speed up to
    RESONANCE_RANGE_TOLERANCE of the range beyond either end counts as in the range (and is
    inside the chart's padding): the stored n₀ = 5.0000337 Hz puts D = 20 m at 360.0024 km/h,
    the resonance of a sweep to 360 km/h."""
    lo, hi = float(np.min(speeds_kmh)), float(np.max(speeds_kmh))
    tol = RESONANCE_RANGE_TOLERANCE * (hi - lo if hi > lo else hi)
    marks = []
    for f in np.unique(np.atleast_1d(np.asarray(n0, dtype=float))):
        for t, D in lengths.items():
            for i in RESONANCE_ORDERS if np.isfinite(D) else ():
                speed = float(resonance_speeds([f], [D], orders=(i,))[0])
                if lo - tol <= speed <= hi + tol:
                    marks.append((speed, t, i))
    return sorted(marks)


def _resonance_labels(ax, marks, colours):
    """Label each resonance line 'train D/i' at the top of ``ax``, rotated: a label that would
    overlap one placed before goes down below it; one that would reach below the upper
    RESONANCE_LABEL_BAND of the axes is left out (its line stays, in the train's colour). The
    axes' limits must be final. Returns the labels drawn (Text)."""
    renderer = ax.figure.canvas.get_renderer()
    to_axes = ax.transAxes.inverted()
    gap = 2.0                                                       # [px] between labels
    placed, drawn = [], []
    for v, t, i in marks:
        text = ax.text(v, 1.0, f"{t} D/{i}", transform=ax.get_xaxis_transform(), rotation=90, ha="center",
                       va="top", fontsize=7.5, color=colours[t],
                       bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 0.6})
        for _ in range(len(placed) + 1):         # each move goes below a placed label: at most all of them
            box = text.get_window_extent(renderer).padded(gap / 2)
            hits = [b for b in placed if b.overlaps(box)]       # (touching counts as overlapping)
            if not hits:
                break
            top = min(b.y0 for b in hits) - gap              # the padded box's top gap / 2 below theirs
            text.set_y(to_axes.transform((0.0, top))[1])
        if hits or to_axes.transform((0.0, box.y0))[1] < 1.0 - RESONANCE_LABEL_BAND:
            text.remove()
            continue
        placed.append(box)
        drawn.append(text)
    return drawn


# -- matplotlib ------------------------------------------------------------------------------------
class _figure:
    """A matplotlib Figure (object API, Agg) under the report's style: ``with _figure(size) as
    (fig, ax)``. The axes keep fixed margins in inches (the legends go in the right margin), so
    that the speed axes of the charts line up on the page."""

    MARGINS = {"left": 1.0, "right": 2.55, "bottom": 0.65, "top": 0.45, "gap": 0.35}      # [in]

    def __init__(self, size, n_rows=1):
        try:
            import matplotlib
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from matplotlib.figure import Figure
        except ImportError as exc:
            raise ImportError("report: the charts need matplotlib (pip install vtsi[plot])") from exc
        self._context = matplotlib.rc_context(CHART_STYLE)
        self._figure, self._canvas, self.size, self.n_rows = Figure, FigureCanvasAgg, size, n_rows

    def __enter__(self):
        self._context.__enter__()
        (w, h), m = self.size, self.MARGINS
        fig = self._figure(figsize=(w, h))
        self._canvas(fig)                      # Agg: a renderer to measure text with (legends, labels)
        panel = (h - m["bottom"] - m["top"] - (self.n_rows - 1) * m["gap"]) / self.n_rows
        fig.subplots_adjust(left=m["left"] / w, right=1 - m["right"] / w, bottom=m["bottom"] / h, top=1 - m["top"] / h,
                            hspace=m["gap"] / panel)
        axes = fig.subplots(self.n_rows, 1, sharex=True, squeeze=True)
        return fig, axes

    def __exit__(self, *exc):
        return self._context.__exit__(*exc)


def _png(fig):
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()


def _legend(ax):
    """The legend of ``ax`` in the figure's right margin, its labels wrapped (at spaces) until it
    fits inside the figure. Returns the Legend."""
    handles, labels = ax.get_legend_handles_labels()
    renderer, right = ax.figure.canvas.get_renderer(), ax.figure.bbox.x1
    width = max((len(line) for label in labels for line in label.split("\n")), default=0)
    while True:
        legend = ax.legend(handles, [_wrap(label, width) for label in labels], loc="upper left",
                           bbox_to_anchor=(1.01, 1.0), frameon=False, borderaxespad=0.0)
        if legend.get_window_extent(renderer).x1 <= right - 2 or width <= 8:
            return legend
        width -= 2


def _wrap(label, width):
    """``label`` with each of its lines wrapped at spaces to ``width`` characters (a longer word
    is broken)."""
    return "\n".join("\n".join(textwrap.wrap(line, width, break_on_hyphens=False) or [""])
                     for line in label.split("\n"))


# -- text ------------------------------------------------------------------------------------------
def _num(value, digits=4):
    """A number with ``digits`` significant digits ('—' for NaN)."""
    value = float(value)
    return "—" if math.isnan(value) else f"{value:.{digits}g}"


def _length(value):
    """A length [m] to the millimetre, trailing zeros dropped: 24.775, 18, 193.3 ('—' for NaN)."""
    value = float(value)
    return "—" if math.isnan(value) else (f"{value:.3f}".rstrip("0").rstrip(".") or "0")


def _fmt_speed(value):
    return "—" if math.isnan(float(value)) else f"{float(value):g}"


def _units(units):
    return UNIT_TEXT.get(units, units)


def _label(criterion):
    return criterion.replace("_", " ").replace("lm71", "LM71")


def _plural(n, word, words=None):
    return f"{n} {word if n == 1 else words or word + 's'}"


def _damping_text(settings):
    zeta, modal = settings.get("damping"), settings.get("bridge", "fe") != "fe"
    if zeta is None:
        return "the bridge as built (its own damping, on its modes)" if modal else \
            "the bridge as built (no Rayleigh damping added)"
    if modal:
        return f"ζ = {100 * zeta:.3g} % on every mode (modal damping)"
    pair = settings.get("damping_hz")
    where = (f"{significant_text(pair[0])} and {significant_text(pair[1])} Hz" if pair else "n₀ and the EN cut-off")
    return f"ζ = {100 * zeta:.3g} % (Rayleigh, through {where})"


KEY_UNITS = (("_kg_m", "kg/m"), ("_Pa", "Pa"), ("_m4", "m⁴"), ("_m2", "m²"), ("_m", "m"), ("_hz", "Hz"),
             ("_Hz", "Hz"))
# Bridge-file inputs whose name alone would be misread next to the model's own values:
# {key: (label, what follows the value)}.
DESCRIPTION_TEXT = {"f1_Hz": ("f1 of the bridge file [Hz]", "(of the first span taken as simply supported: it sets I)")}


def _key_text(key):
    for suffix, units in KEY_UNITS:
        if key.endswith(suffix):
            return f"{key[: -len(suffix)].replace('_', ' ')} [{units}]"
    return key.replace("_", " ")


def _value_text(value):
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, (int, float)):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(_value_text(v) for v in value)
    return str(value)


def _charts(sections):
    return [b for s in sections for b in s.blocks if isinstance(b, Chart)]


# -- HTML ------------------------------------------------------------------------------------------
CSS = """
:root { --ink: #1d2330; --muted: #5b6475; --line: #d9dde5; --pass: #1e7b34; --fail: #b3261e; --info: #3b5b92; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.5 "DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif; color: var(--ink);
       background: #f4f5f8; }
header { background: #1f2a44; color: #fff; padding: 22px 36px 14px; }
header h1 { margin: 0 0 4px; font-size: 24px; font-weight: 600; }
header .meta { margin: 0 0 10px; color: #c9d1e3; font-size: 13px; word-break: break-all; }
nav a { color: #fff; margin-right: 16px; font-size: 14px; text-decoration: none; border-bottom: 1px dotted #9fb0d6; }
main { max-width: 1280px; margin: 0 auto; padding: 8px 28px 40px; }
section { background: #fff; border: 1px solid var(--line); border-radius: 6px; padding: 14px 24px 18px;
          margin: 18px 0; }
h2 { margin: 4px 0 12px; font-size: 20px; border-bottom: 2px solid var(--line); padding-bottom: 4px; }
h3 { margin: 14px 0 6px; font-size: 16px; }
table { border-collapse: collapse; width: 100%; font-size: 14px; margin: 6px 0 10px; }
th, td { border-bottom: 1px solid var(--line); padding: 5px 8px; text-align: left; vertical-align: top; }
th { background: #eef1f6; font-weight: 600; white-space: nowrap; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
th.num { text-align: right; }
table.properties { width: auto; min-width: 50%; }
table.properties td:first-child { color: var(--muted); white-space: nowrap; padding-right: 24px; }
td.swatch { width: 18px; padding: 0; border: 3px solid #fff; }
td.status { font-weight: 700; text-align: center; }
td.status.pass { color: var(--pass); } td.status.fail { color: #fff; background: var(--fail); }
td.status.info { color: var(--info); }
tr[data-status="fail"] td { background: #fdf0ef; } tr[data-status="fail"] td.status { background: var(--fail); }
p.verdict { font-size: 19px; font-weight: 700; padding: 8px 14px; border-radius: 4px; margin: 4px 0 10px; }
p.verdict.pass { background: #e5f4e8; color: var(--pass); border-left: 6px solid var(--pass); }
p.verdict.fail { background: #fbe9e7; color: var(--fail); border-left: 6px solid var(--fail); }
p.verdict.none { background: #eeeeee; color: #333333; border-left: 6px solid #777777; }
p.warning { background: #fff6db; border-left: 6px solid #d9a400; padding: 6px 12px; }
ul { margin: 4px 0 10px; padding-left: 22px; } ul.governing li, ul.notes li { margin: 2px 0; }
ul.notes { color: var(--muted); font-size: 14px; }
figure { margin: 12px 0 18px; } figure img { max-width: 100%; height: auto; display: block; }
figcaption { color: var(--muted); font-size: 13.5px; margin-top: 4px; }
@media print { body { background: #fff; } section { break-inside: avoid; border: none; }
               header { color: #000; background: none; } }
"""


def _numeric_columns(table):
    """The columns of ``table`` whose every cell is a number (class 'num'): their headings are
    aligned as their numbers, right."""
    return {j for j in range(len(table.head)) if table.rows and all(
        isinstance(row[j], Cell) and "num" in row[j].cls.split() for row in table.rows)}


def _attrs(attrs):
    return "".join(f' {k}="{html.escape(str(v), quote=True)}"' for k, v in (attrs or {}).items())


def _html_block(block):
    if isinstance(block, Paragraph):
        return f"<p{_attrs({'class': block.cls} if block.cls else None)}>{html.escape(block.text)}</p>"
    if isinstance(block, Heading):
        return f"<h3>{html.escape(block.text)}</h3>"
    if isinstance(block, Items):
        items = "".join(f"<li>{html.escape(i)}</li>" for i in block.items)
        return f"<ul{_attrs({'class': block.cls} if block.cls else None)}>{items}</ul>"
    if isinstance(block, Chart):
        data = base64.b64encode(block.png).decode("ascii")
        return (f'<figure><img src="data:image/png;base64,{data}" alt="{html.escape(block.alt)}" '
                f'data-chart="{html.escape(block.name)}">'
                f"<figcaption>{html.escape(block.caption)}</figcaption></figure>")
    if isinstance(block, Table):
        attrs = {}
        if block.table_id:
            attrs["id"] = block.table_id
        if block.cls:
            attrs["class"] = block.cls
        numeric = _numeric_columns(block)
        head = "".join(f"<th{_attrs({'class': 'num'} if j in numeric else None)}>{html.escape(h)}</th>"
                       for j, h in enumerate(block.head))
        body = []
        for i, row in enumerate(block.rows):
            cells = []
            for cell in row:
                cell = cell if isinstance(cell, Cell) else Cell(str(cell))
                a = dict(cell.attrs)
                if cell.cls:
                    a["class"] = cell.cls
                cells.append(f"<td{_attrs(a)}>{html.escape(cell.text)}</td>")
            body.append(f"<tr{_attrs(block.row_attrs[i] if block.row_attrs else None)}>{''.join(cells)}</tr>")
        return f"<table{_attrs(attrs)}><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"
    raise TypeError(f"report: unknown block {type(block).__name__}")


def _html(title, meta, sections):
    nav = " ".join(f'<a href="#{s.id}">{html.escape(s.title)}</a>' for s in sections)
    body = "\n".join(f'<section id="{s.id}">\n<h2>{html.escape(s.title)}</h2>\n'
                     + "\n".join(_html_block(b) for b in s.blocks) + "\n</section>" for s in sections)
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            f"<title>{html.escape(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
            f'<header><h1>{html.escape(title)}</h1><p class="meta">{html.escape(meta)}</p><nav>{nav}</nav></header>\n'
            f"<main>\n{body}\n</main>\n</body>\n</html>\n")


# -- Markdown --------------------------------------------------------------------------------------
def _md_escape(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def _md_block(block):
    if isinstance(block, Paragraph):
        return f"**{block.text}**" if "verdict" in block.cls else (f"> {block.text}" if block.cls == "warning"
                                                                   else block.text)
    if isinstance(block, Heading):
        return f"### {block.text}"
    if isinstance(block, Items):
        return "\n".join(f"- {i}" for i in block.items)
    if isinstance(block, Chart):
        return f"![{block.alt}](img/{block.name}.png)\n\n*{block.caption}*"
    if isinstance(block, Table):
        keep = [j for j, h in enumerate(block.head) if h or not all(
            (c.text if isinstance(c, Cell) else str(c)) == "" for c in (row[j] for row in block.rows))]
        head = [block.head[j] for j in keep]
        numeric = _numeric_columns(block)
        lines = ["| " + " | ".join(_md_escape(h) for h in head) + " |",
                 "|" + "".join("---:|" if j in numeric else "---|" for j in keep)]
        for row in block.rows:
            cells = [row[j].text if isinstance(row[j], Cell) else str(row[j]) for j in keep]
            lines.append("| " + " | ".join(_md_escape(c) for c in cells) + " |")
        return "\n".join(lines)
    raise TypeError(f"report: unknown block {type(block).__name__}")


def _markdown(title, meta, sections):
    parts = [f"# {title}", meta, " · ".join(f"[{s.title}](#{s.id})" for s in sections)]
    for s in sections:
        parts.append(f'<a id="{s.id}"></a>\n\n## {s.title}')
        parts.extend(_md_block(b) for b in s.blocks)
    return "\n\n".join(parts) + "\n"
