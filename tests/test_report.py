"""The report (vtsi.report): every section and chart present in the HTML, the checks table equal to
the check stored in the results file, the Markdown's images on disk, a file without a check
refused."""
import base64
import math
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import vtsi.report
from vtsi.check import check, stored_check
from vtsi.errors import SweepError
from vtsi.passage import PassageSettings
from vtsi.bridge_file import load_bridge
from vtsi.report import (PALETTE, PNG_MAGIC, SECTIONS, SPAN_STYLES, _drawn_mode_shape, _figure,
                         _legend, _resonance_labels, _resonance_marks, write_report)
from vtsi.sweep import Sweep, beam_bridge
from vtsi.workflow import design_check

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
CHARTS = ["mode_shapes", "acceleration", "deflection", "daf", "history_1"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A small sweep's results file at three stages: without a check, with a check but no
    histories, and with the governing cases' histories recorded (sweep.h5); and a sweep of a
    train of cars (cars.h5: the interaction rows, contact forces in the histories)."""
    root = tmp_path_factory.mktemp("report")
    path = root / "sweep.h5"
    sweep = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=4), ["HSLM-A1", "HSLM-A4"], "250,330,350",
                  PassageSettings(dt=5e-3, damping=0.013))
    results = sweep.run(path, workers=1, progress=False)
    shutil.copyfile(path, root / "unchecked.h5")
    result = check(results)
    result.store(path)
    shutil.copyfile(path, root / "no_histories.h5")
    governing = sorted({(r.train, r.speed_kmh, r.seed) for r in result.rows
                        if r.train in results.trains and not math.isnan(r.speed_kmh)})
    sweep.record_histories(path, governing)
    cars = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=4), ["ICE3"], "300",
                 PassageSettings(dt=5e-3, damping=0.01, cars="full", interpolation="bspline"))
    check(cars.run(root / "cars.h5", workers=1, progress=False)).store(root / "cars.h5")
    cars.record_histories(root / "cars.h5", [("ICE3", 300.0, -1)])
    return root


class _Page(HTMLParser):
    """What the test reads from report.html: section ids, images, the checks table, any
    external resource."""

    def __init__(self, text):
        super().__init__()
        self.sections, self.images, self.rows, self.external, self.scripts = [], [], [], [], 0
        self._in_table = self._in_verdict = False
        self.verdict = ""
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "section":
            self.sections.append(a.get("id"))
        elif tag == "img":
            self.images.append(a)
        elif tag == "script":
            self.scripts += 1
        elif tag == "table" and a.get("id") == "check-table":
            self._in_table = True
        elif tag == "tr" and self._in_table and "data-criterion" in a:
            self.rows.append({"criterion": a["data-criterion"], "status": a["data-status"]})
        elif tag == "td" and self._in_table and self.rows and "data-value" in a:
            self.rows[-1][a["data-field"]] = a["data-value"]
        elif tag == "p" and "verdict" in a.get("class", ""):
            self._in_verdict = True
        for name in ("src", "href"):
            value = a.get(name) or ""
            if value and not value.startswith(("data:", "#")):
                self.external.append(value)
        if tag == "link":
            self.external.append(a.get("href"))

    def handle_endtag(self, tag):
        if tag == "table":
            self._in_table = False
        elif tag == "p":
            self._in_verdict = False

    def handle_data(self, data):
        if self._in_verdict:
            self.verdict += data


def _same(text, value):
    """A data-value (repr) equals a stored float exactly (NaN equals NaN)."""
    parsed = float(text)
    return (math.isnan(parsed) and math.isnan(value)) or parsed == value


@pytest.mark.parametrize("name", ["sweep", "cars"])
def test_html_has_every_section_chart_and_the_stored_check(files, tmp_path, name):
    path = files / f"{name}.h5"
    out = write_report(path, tmp_path / "report")
    page = _Page(out["html"].read_text(encoding="utf-8"))
    assert page.sections == [s for s in SECTIONS if s != "scene"]
    assert not page.external and page.scripts == 0
    charts = [img.get("data-chart") for img in page.images]
    assert charts == CHARTS
    for img in page.images:
        prefix = "data:image/png;base64,"
        assert img["src"].startswith(prefix)
        assert base64.b64decode(img["src"][len(prefix):], validate=True)[:8] == PNG_MAGIC

    stored = stored_check(path)
    if name == "cars":
        assert {"car_body_acceleration", "wheel_unloading", "contact_loss"} <= {r.criterion for r in stored.rows}
    assert page.verdict.startswith("PASS" if stored.passed else "FAIL")
    assert [r["criterion"] for r in page.rows] == [r.criterion for r in stored.rows]
    for shown, row in zip(page.rows, stored.rows):
        assert shown["status"] == row.status
        # an info row's limit is a reference ('ref.', data-field reference) unless it is a limit the
        # check could not hold the value to; an info row has no utilisation
        info_reference = row.status == "info" and not math.isnan(row.limit) and row.criterion not in stored.unchecked
        names = ["value", "reference" if info_reference else "limit", "speed_kmh"]
        if row.status != "info":
            names.append("utilisation")
        else:
            assert "utilisation" not in shown, row.criterion
        for name in names:
            stored_name = "limit" if name == "reference" else name
            assert _same(shown[name], getattr(row, stored_name)), (row.criterion, name, shown[name],
                                                                  getattr(row, stored_name))


def test_markdown_references_the_written_pngs(files, tmp_path):
    out = write_report(files / "sweep.h5", tmp_path / "report", title="Bridge 7")
    text = out["markdown"].read_text(encoding="utf-8")
    assert text.startswith("# Bridge 7")
    for section in ("Summary", "Checks", "Bridge", "Trains", "Settings", "Envelopes", "Time histories"):
        assert f"\n## {section}\n" in text
    linked = re.findall(r"!\[[^\]]*\]\((img/[^)]+\.png)\)", text)
    assert sorted(linked) == sorted(f"img/{c}.png" for c in CHARTS)
    for link in linked:
        assert (out["markdown"].parent / link).read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in out["images"]) == sorted(f"{c}.png" for c in CHARTS)
    for row in stored_check(files / "sweep.h5").rows:
        assert f"| {row.criterion.replace('_', ' ')} |" in text.lower()


def test_the_settings_name_the_bridge_model(files, tmp_path):
    """The reader must know which bridge model the envelopes come from: FE, or modal with the
    frequency of its basis (default 1.1 × the EN cut-off, 49.53 Hz here), and how it is damped
    (Rayleigh on the FE bridge, the ratio on every mode of the modal one)."""
    fe = write_report(files / "sweep.h5", tmp_path / "fe")["markdown"].read_text(encoding="utf-8")
    assert "| bridge model | FE model, time-stepped |" in fe
    assert "| damping | ζ = 1.3 % (Rayleigh, through n₀ and the EN cut-off) |" in fe
    path = tmp_path / "modal.h5"
    modal = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=10), ["HSLM-A1"], "300",
                  PassageSettings(dt=1e-3, damping=0.013, bridge="modal"))
    check(modal.run(path, workers=1, progress=False)).store(path)
    text = write_report(path, tmp_path / "modal")["markdown"].read_text(encoding="utf-8")
    assert ("| bridge model | modal: 3 modes up to 49.53 Hz (1.1 × the EN cut-off 45.02 Hz, the default; the highest "
            "at 45.02 Hz), exact passages of moving forces, cars time-stepped |") in text
    assert "| damping | ζ = 1.3 % on every mode (modal damping) |" in text


def test_scene_section_and_a_file_without_histories(files, tmp_path):
    first = write_report(files / "sweep.h5", tmp_path / "a")
    scene = first["images"][0]
    out = write_report(files / "no_histories.h5", tmp_path / "b", scene_png=scene)
    page = _Page(out["html"].read_text(encoding="utf-8"))
    assert page.sections == list(SECTIONS)
    assert [img.get("data-chart") for img in page.images] == CHARTS[:-1] + ["scene"]
    assert "no time histories" in out["markdown"].read_text(encoding="utf-8").lower()
    with pytest.raises(SweepError, match="not a PNG"):
        write_report(files / "sweep.h5", tmp_path / "c", scene_png=files / "sweep.h5")


def test_the_sections_are_in_the_documented_order():
    """SECTIONS orders the report's sections (the report builds them from it): the order the
    module docstring and docs/report.md give."""
    docs = (Path(__file__).parents[1] / "docs" / "report.md").read_text(encoding="utf-8")
    assert tuple(re.findall(r"^\| `(\w+)` \|", docs, flags=re.M)) == SECTIONS
    assert tuple(re.findall(r"^(\w+) {2,}", vtsi.report.__doc__.split("Sections, in this order")[1],
                            flags=re.M)) == SECTIONS


def _markdown_rows(text):
    """``{first cell: the rest}`` of the Markdown table rows of ``text`` (the rest is the second cell
    of a two-column row, e.g. of the settings or bridge tables)."""
    return dict(re.findall(r"^\| ([^|]+?) \| (.*?) \|$", text, flags=re.M))


def test_info_rows_show_a_reference_without_a_utilisation_and_the_verdict_counts_the_limits(files, tmp_path):
    """dynamic vs LM71 (info: > 1 means the dynamic analysis governs) reads 'ref. 1' with no
    utilisation, so that it does not read as an exceedance; the verdict's 'n criteria held to a
    limit' is the number of rows with a utilisation in the table."""
    out = write_report(files / "sweep.h5", tmp_path / "r")
    text = out["markdown"].read_text(encoding="utf-8")
    rows = {r.criterion: r for r in stored_check(files / "sweep.h5").rows}
    assert rows["dynamic_vs_lm71"].status == "info" and rows["dynamic_vs_lm71"].limit == 1.0
    assert "| dynamic vs LM71 | " + f"{rows['dynamic_vs_lm71'].value:.4g} | ref. 1 | — | INFO |" in text
    assert "dynamic vs LM71: " + f"{rows['dynamic_vs_lm71'].value:.4g} (reference 1) —" in text
    html = out["html"].read_text(encoding="utf-8")
    with_utilisation = len(re.findall(r'data-field="utilisation" data-value=', html))
    assert with_utilisation == sum(r.status != "info" for r in rows.values())
    verdict = _Page(html).verdict
    if verdict.startswith("FAIL"):
        assert re.match(rf"FAIL: \d+ of {with_utilisation} criteri(on|a) held to a limit", verdict), verdict


def test_a_sweep_of_moving_forces_shows_only_what_applies(files, tmp_path):
    """No cars ran: the settings list no car outputs and no contact model, the check's settings
    no comfort level or wheel unloading limit; a sweep of cars shows them. ICE3's D = 24.775 m
    in full; the history caption names only what is drawn (no contact forces without cars, no
    moment or end rotation ever)."""
    forces = write_report(files / "sweep.h5", tmp_path / "f")["markdown"].read_text(encoding="utf-8")
    cars = write_report(files / "cars.h5", tmp_path / "c")["markdown"].read_text(encoding="utf-8")
    settings = _markdown_rows(forces)
    assert "contact_force" not in settings["outputs"] and "car_body" not in settings["outputs"]
    assert settings["contact"] == "not used (no cars in the sweep)"
    assert "comfort level" not in forces and "wheel unloading limit" not in forces
    assert "contact_force (contact_force)" in _markdown_rows(cars)["outputs"]
    assert "comfort level 'good'" in cars and "wheel unloading limit ΔQ/Q = 0.6" in cars
    assert re.search(r"^\| ICE3 \| \d+ \| [\d.]+ \| [\d.]+ \| 24\.775 \|", cars, flags=re.M)

    def captions(text):
        return re.findall(r"!\[time histories of [^\]]*\]\(img/history_\d+\.png\)\n\n\*([^*]+)\*", text)
    assert captions(forces) and captions(cars)
    for caption in captions(forces):
        assert "acceleration" in caption and "deflection" in caption and "contact force" not in caption
    for caption in captions(cars):
        assert "contact force" in caption
    for caption in captions(forces) + captions(cars):       # a moment or rotation row governed: not drawn, so said
        drawn, _, rest = caption.partition(" This case")
        assert "moment" not in drawn and "rotation" not in drawn
        assert not rest or "the histories do not hold that quantity" in rest


def test_a_continuous_deck_from_a_bridge_file(tmp_path, beam_toml):
    """A three-span deck from a bridge file with f1_Hz: the table says that f1 is the file's input
    (the first span as simply supported), next to the model's frequencies; the history caption
    says each span has its own line style."""
    bridge = beam_toml(tmp_path / "cont.toml", {"spans_m": [20.0, 25.0, 20.0], "f1_Hz": 4.5, "mu_kg_m": 20000.0})
    path = tmp_path / "cont.h5"
    sweep = Sweep(load_bridge(bridge), ["HSLM-A1"], "300", PassageSettings(dt=5e-3, damping=0.02))
    result = check(sweep.run(path, workers=1, progress=False))
    result.store(path)
    sweep.record_histories(path, [("HSLM-A1", 300.0, -1)])
    text = write_report(path, tmp_path / "r")["markdown"].read_text(encoding="utf-8")
    table = _markdown_rows(text)
    assert table["f1 of the bridge file [Hz]"] == "4.5 (of the first span taken as simply supported: it sets I)"
    assert "f1 Hz" not in table
    assert "at each span's middle (one line style per span" in text
    assert len({style for style in SPAN_STYLES}) == len(SPAN_STYLES)
    assert not {colour for colour, _ in SPAN_STYLES} & set(PALETTE)


def test_a_resonance_at_the_end_of_the_speed_range_is_marked():
    """The stored n₀ = 5.0000337 Hz puts HSLM-A3 (D = 20 m) D/1 at 360.0024 km/h: marked on a
    sweep to 360 km/h; a resonance well past the range is not."""
    speeds = np.arange(140.0, 361.0, 10.0)
    marks = _resonance_marks(5.0000337, {"HSLM-A3": 20.0, "HSLM-A7": 24.0, "none": float("nan")}, speeds)
    # A3 D/3 = 120 km/h and A7 D/1 = 432 km/h are outside 140-360 km/h
    assert [(t, i) for _, t, i in marks] == [("HSLM-A7", 3), ("HSLM-A3", 2), ("HSLM-A7", 2), ("HSLM-A3", 1)]
    assert marks[-1][0] == pytest.approx(360.0024, abs=1e-4)
    assert _resonance_marks(5.0, {"HSLM-A3": 20.0}, np.array([140.0, 358.0]))[-1][2] == 2   # 360: 0.9 % past


def test_resonance_labels_and_legends_do_not_collide_or_leave_the_figure():
    """The example's eleven trains at n₀ = 5 Hz (HSLM-A1 D/2 and HSLM-A10 D/3 both at 162 km/h):
    every label drawn, no two overlapping, all inside the axes; a legend with a long label stays
    inside the figure."""
    lengths = {f"HSLM-A{i}": 17.0 + i for i in range(1, 11)} | {"ICE3": 24.775}
    colours = {t: PALETTE[i] for i, t in enumerate(lengths)}
    marks = _resonance_marks(5.0, lengths, [140.0, 360.0])
    with _figure((11, 5.6)) as (fig, ax):
        ax.set_xlim(136.7, 363.3)
        ax.set_ylim(0, 37)
        labels = _resonance_labels(ax, marks, colours)
        renderer = fig.canvas.get_renderer()
        boxes = [label.get_window_extent(renderer) for label in labels]
        assert len(labels) == len(marks) == 19
        for a in range(len(boxes)):
            assert ax.bbox.y0 <= boxes[a].y0 and boxes[a].y1 <= ax.bbox.y1 + 1
            for b in range(a):
                assert not boxes[a].overlaps(boxes[b]), (labels[a].get_text(), labels[b].get_text())
        ax.plot([0], [0], label="governing: a train with a long name, 280.8 km/h")
        ax.plot([0], [0], label="span 3 middle, node 26\ngoverns dynamic increment moment")
        legend = _legend(ax)
        assert legend.get_window_extent(renderer).x1 <= fig.bbox.x1
        assert "\n" in legend.get_texts()[0].get_text()              # wrapped, not cut


def test_the_mode_shapes_drawn_reach_one():
    """A coarse mesh (4 elements): the spline through the nodes is scaled to a largest value of 1,
    not the nodes (the caption says so)."""
    x = np.linspace(0.0, 20.0, 5)
    fine = np.linspace(0.0, 20.0, 400)
    for k in (1, 2, 3):
        nodes, curve = _drawn_mode_shape(x, -7.0 * np.sin(k * np.pi * x / 20.0), fine)
        assert np.max(np.abs(curve)) == pytest.approx(1.0, abs=1e-3)
        assert curve[np.argmax(np.abs(curve))] > 0 and np.max(np.abs(curve)) <= 1.0 + 1e-12
        assert np.max(np.abs(nodes)) <= 1.0 + 1e-12


def test_a_file_without_a_check_is_refused(files, tmp_path):
    with pytest.raises(SweepError, match="holds no check; run the check first"):
        write_report(files / "unchecked.h5", tmp_path / "report")
    with pytest.raises(SweepError, match="not found"):
        write_report(files / "missing.h5", tmp_path / "report")
    (tmp_path / "text.h5").write_text("not HDF5")
    with pytest.raises(SweepError, match="not a readable HDF5 file"):
        write_report(tmp_path / "text.h5", tmp_path / "report")
    assert not (tmp_path / "report").exists()


def test_bad_report_and_design_check_arguments_are_named_before_anything_runs(files, tmp_path):
    """A report directory that is a file, arguments of the wrong kind, and a design check whose
    settings or report directory are wrong: named before the sweep runs (no results file)."""
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(SweepError, match=r"report: .*notes.txt is a file, not a directory for the report"):
        write_report(files / "sweep.h5", tmp_path / "notes.txt")
    for kwargs, message in (({"title": 5}, "the title must be text, got 5"),
                            ({"scene_png": 5}, "the scene image must be a path, got 5")):
        with pytest.raises(SweepError, match=message):
            write_report(files / "sweep.h5", tmp_path / "r", **kwargs)
    with pytest.raises(SweepError, match="the report directory must be a path, got None"):
        write_report(files / "sweep.h5", None)
    sweep = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=4), ["HSLM-A1"], "300", PassageSettings(dt=5e-3))
    for args, kwargs, message in (((sweep, tmp_path / "w.h5", "ballasted"), {}, "settings must be CheckSettings, got str"),
                                  ((sweep, tmp_path / "w.h5"), {"report_dir": tmp_path / "notes.txt"}, "is a file"),
                                  (("sweep", tmp_path / "w.h5"), {}, "sweep must be a vtsi.sweep.Sweep, got str"),
                                  ((sweep, None), {}, "the results file must be a path, got None")):
        with pytest.raises(SweepError, match=message):
            design_check(*args, **kwargs)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
