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
from vtsi.errors import ModelError, SweepError
from vtsi.passage import PassageSettings
from vtsi.bridge_file import load_bridge
from vtsi.report import (PALETTE, PNG_MAGIC, RESONANCE_ORDERS, SECTIONS, SPAN_STYLES, _drawn_mode_shape, _figure,
                         _legend, _Report, _resonance_labels, _resonance_marks, write_report)
from vtsi.scene3d import RenderedAnimation, nodes_by_deck, render_case
from vtsi.signature import HARMONICS
from vtsi.sweep_results import SweepResults
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
    frequency of its basis (by default, with the sweep's bending moments, 1.1 × twice the
    frequency at which HSLM-A1's bogie axles, 2 m apart, pass at 300 km/h: 1.1 × 2 × 41.67 =
    91.67 Hz, above 1.1 × the EN cut-off 45.02 Hz; the span's modes 5.01 × j²: 4 of them, the
    highest 80.13 Hz), and how it is damped (Rayleigh on the FE bridge, the ratio on every mode
    of the modal one)."""
    fe = write_report(files / "sweep.h5", tmp_path / "fe")["markdown"].read_text(encoding="utf-8")
    assert "| bridge model | FE model, time-stepped |" in fe
    assert "| damping | ζ = 1.3 % (Rayleigh, through n₀ and the EN cut-off) |" in fe
    path = tmp_path / "modal.h5"
    modal = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=10), ["HSLM-A1"], "300",
                  PassageSettings(dt=1e-3, damping=0.013, bridge="modal"))
    check(modal.run(path, workers=1, progress=False)).store(path)
    text = write_report(path, tmp_path / "modal")["markdown"].read_text(encoding="utf-8")
    assert ("| bridge model | modal: 4 modes up to 91.67 Hz (2.04 × the EN cut-off 45.02 Hz, the default for the "
            "moments: 1.1 × twice the 41.67 Hz at which the trains' closest axles pass at 300 km/h; the highest at "
            "80.13 Hz), exact passages of moving forces, cars time-stepped |") in text
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
    no wheel unloading limit and the comfort level as not checked (it was left out, and nothing
    said that neither route of EN 1990 A2.4.4.3 was checked); a sweep of cars shows them, the
    comfort read from the car bodies. ICE3's D = 24.775 m
    in full; the history caption names only what is drawn (no contact forces without cars, no
    moment or end rotation ever)."""
    forces = write_report(files / "sweep.h5", tmp_path / "f")["markdown"].read_text(encoding="utf-8")
    cars = write_report(files / "cars.h5", tmp_path / "c")["markdown"].read_text(encoding="utf-8")
    settings = _markdown_rows(forces)
    assert "contact_force" not in settings["outputs"] and "car_body" not in settings["outputs"]
    assert settings["contact"] == "not used (no cars in the sweep)"
    assert "wheel unloading limit" not in forces
    assert ("comfort level 'good' (not checked: the sweep kept no car body (moving forces have none) for Table "
            "A2.9's b_v; the deflection limits of EN 1990 A2.4.4.3.2, Figure A2.3, are not checked)") in forces
    assert "contact_force (contact_force)" in _markdown_rows(cars)["outputs"]
    assert "comfort level 'good' (the car bodies' b_v, Table A2.9;" in cars and "wheel unloading limit ΔQ/Q = 0.6" in cars
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
    for k in (1, 2, 3):
        nodes, _, curve = _drawn_mode_shape(x, -7.0 * np.sin(k * np.pi * x / 20.0), [np.arange(5)])
        assert np.nanmax(np.abs(curve)) == pytest.approx(1.0, abs=1e-3)
        assert curve[np.nanargmax(np.abs(curve))] > 0 and np.nanmax(np.abs(curve)) <= 1.0 + 1e-12
        assert np.max(np.abs(nodes)) <= 1.0 + 1e-12


def _two_decks(x_joint=15.0, lengths=(15.0, 20.0), n=10):
    """Two simply supported decks of ``n`` elements each, ending on one pier at x = 15 m with a
    node each there (the ending deck's first, as the track runs), as a results file's /bridge:
    deck_x_m, deck_ends_m, span_ends_m; and the x of every node."""
    first = np.linspace(0.0, lengths[0], n + 1)
    second = np.linspace(x_joint, x_joint + lengths[1], n + 1)
    ends = np.array([[0.0, lengths[0]], [x_joint, x_joint + lengths[1]]])
    return {"deck_x_m": np.concatenate([first, second]), "deck_ends_m": ends, "span_ends_m": ends}


def test_two_decks_count_their_own_nodes_and_draw_a_spline_each():
    """Two 10-element decks on one pier, a node of each at x = 15 m: the Bridge table counted both
    end nodes for each deck (12 + 12 of 22); now 11 each, summing to the track's. Their mode
    shapes were drawn straight between the nodes (two nodes at one x); now each deck's own
    spline: deck 2's second mode, sin(2π (x − 15) / 20), drawn within 1 % of the closed form,
    its peak 1 at x = 20 m between the nodes at 19 and 21 m (sin 72° = 0.951 there), where a
    straight line would stop at the nodes."""
    bridge = _two_decks()
    x = bridge["deck_x_m"]
    decks = nodes_by_deck(x, bridge["deck_ends_m"], 1e-9)
    assert [d.tolist() for d in decks] == [list(range(11)), list(range(11, 22))]
    assert sum(len(d) for d in decks) == len(x)
    on_two = np.where(x < 15.0, 0.0, np.sin(2 * np.pi * (x - 15.0) / 20.0))
    on_two[10] = 0.0                                     # deck 1's end node: deck 1 at rest in this mode
    nodes, xs, curve = _drawn_mode_shape(x, -3.0 * on_two, decks)
    assert np.max(np.abs(nodes)) == pytest.approx(np.sin(0.4 * np.pi), rel=2e-3)     # 0.951, scaled by the curve's 1
    second = np.isfinite(xs) & (xs > 15.0)
    sign = np.sign(curve[np.flatnonzero(np.isclose(xs, 20.0))[0]])     # the peaks at 20 and 30 m tie: either is +1
    exact = sign * np.sin(2 * np.pi * (xs[second] - 15.0) / 20.0)
    assert np.max(np.abs(curve[second] - exact)) < 0.01
    assert np.nanmax(curve) == 1.0 and np.nanmin(curve) == pytest.approx(-1.0, abs=1e-3)
    assert abs(curve[np.flatnonzero(np.isclose(xs, 20.0))[0]]) == pytest.approx(1.0, abs=2e-3)
    assert np.all(curve[np.isfinite(xs) & (xs < 15.0)] == 0.0)


def test_the_bridge_table_counts_each_decks_own_nodes(files, tmp_path, monkeypatch):
    """The Bridge table of a results file of two decks meeting on one pier (its bridge record
    replaced): 11 nodes per deck and 22 on the track."""
    report = _Report(SweepResults(str(files / "sweep.h5")), stored_check(files / "sweep.h5"), files / "sweep.h5")
    two = _two_decks()
    report.bridge = dict(report.bridge, **two, deck_nodes=np.arange(1, 23),
                         span_lengths_m=np.array([15.0, 20.0]), midspan_nodes=np.array([6, 17]),
                         deck_frequencies_hz=np.array([[13.06, 52.25, 117.6], [9.485, 37.94, 85.41]]),
                         mode_shapes_uy=np.zeros((22, 3)))
    monkeypatch.setattr(vtsi.report, "_png", lambda fig: b"")
    rows = dict(report.bridge_section().blocks[0].rows)
    counts = [int(re.search(r"(\d+) nodes", rows[f"deck {d}"]).group(1)) for d in (1, 2)]
    assert counts == [11, 11]
    assert sum(counts) == int(re.search(r"(\d+) nodes", rows["track nodes"]).group(1)) == 22


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


# -- from a visual review: what the report draws and says --------------------------------------------
def _governing_recorded(path):
    """(train, speed, seed) of the stored deck acceleration row (its histories are recorded) and
    the times of its recorded deck displacement."""
    row = stored_check(path).row("deck_acceleration")
    times = SweepResults(str(path)).history(row.train, row.speed_kmh, row.seed)["deck_displacement"][0]
    return (row.train, row.speed_kmh, row.seed), times


def test_a_scene_case_the_sweep_does_not_have_is_refused_in_render_cases_words(files, tmp_path, one_line):
    """write_report(scene_case=...) printed any dict in the caption ('TGV at 999 km/h, rail sample
    7 at t = -3 s', '× -5', '× nan'); now each value is checked before anything is written, by
    render_case's own checks: one line each, the same type and words as render_case for the same
    mistake. A scene image that does not exist is 'not found', not 'not a PNG file'."""
    path = files / "sweep.h5"
    png = write_report(path, tmp_path / "a")["images"][0]
    (train, speed, seed), times = _governing_recorded(path)
    other = "HSLM-A4" if train == "HSLM-A1" else "HSLM-A1"           # a case without histories: its n_steps Δt
    record = SweepResults(str(path)).case(other, 250.0, -1)["attrs"]["n_steps"] * 5e-3
    case = {"train": train, "speed_kmh": speed}
    refused = [
        ({"train": "TGV", "speed_kmh": 250}, SweepError,
         f"scene: train 'TGV' is not in the sweep of {path} (trains: HSLM-A1, HSLM-A4)"),
        ({"speed_kmh": 300}, SweepError,
         "scene: speed_kmh = 300 km/h without a train: name the train too (or neither, for the governing case)"),
        ({"train": train}, SweepError, f"scene: a case of train '{train}' needs its speed_kmh"),
        ({**case, "speed_kmh": 999}, SweepError, "sweep results: 999 km/h is not one of the sweep's 3 speeds (250 to "
                                                 "350 km/h: 250, 330, 350)"),
        ({**case, "speed_kmh": "fast"}, SweepError, "sweep results: speed [km/h] must be a number, got 'fast'"),
        ({**case, "seed": 7}, SweepError, "sweep results: seed 7 is not one of the sweep's: -1 (a smooth rail)"),
        ({**case, "seed": "x"}, SweepError,
         "sweep results: a case's seed must be an integer (-1: smooth rail), got 'x'"),
        ({**case, "time_s": -3.0}, ModelError, f"report: the scene's case: time -3 s is outside the recorded passage "
                                               f"({times[0]:g} to {times[-1]:g} s)"),
        ({**case, "time_s": float("nan")}, ModelError, f"report: the scene's case: time nan s is outside the recorded "
                                                       f"passage ({times[0]:g} to {times[-1]:g} s)"),
        ({**case, "time_s": "noon"}, ModelError, "report: the scene's case: time [s] must be a number, got 'noon'"),
        ({"train": other, "speed_kmh": 250, "time_s": 99.0}, ModelError,
         f"report: the scene's case: time 99 s is outside the recorded passage (0.005 to {record:g} s)"),
        ({"time_s": 1.0}, SweepError, "report: the scene's case: time_s = 1.0 without its case: name its train and "
                                      "speed_kmh too"),
        ({"scale": 0}, ModelError, "report: the scene's case: scale: expected a positive number, got 0"),
        ({"scale": -5}, ModelError, "report: the scene's case: scale: expected a positive number, got -5"),
        ({"scale": float("nan")}, ModelError, "report: the scene's case: scale: expected a positive number, got nan"),
        ({"speeed_kmh": 300}, SweepError,
         "report: the scene's case: unknown key 'speeed_kmh'; valid: train, speed_kmh, seed, time_s, scale"),
    ]
    for scene_case, error, message in refused:
        with pytest.raises(error) as info:
            write_report(path, tmp_path / "r", scene_png=png, scene_case=scene_case)
        assert one_line(info) == message, scene_case
    words = {repr(scene_case): (error, message) for scene_case, error, message in refused}
    for kwargs, scene_case in (({"train": "TGV", "speed_kmh": 250},) * 2, ({"speed_kmh": 300},) * 2,
                               ({**case, "seed": 7},) * 2, ({**case, "time": -3.0}, {**case, "time_s": -3.0})):
        error, message = words[repr(scene_case)]
        with pytest.raises(error) as info:             # render_case: the same type and words (its own prefix)
            render_case(path, tmp_path / "t.png", **kwargs)
        assert str(info.value).replace("render_case:", "report: the scene's case:") == message
    with pytest.raises(SweepError) as info:
        write_report(path, tmp_path / "r", scene_png=tmp_path / "missing.png")
    assert one_line(info) == f"report: scene image {tmp_path / 'missing.png'} not found"
    assert not (tmp_path / "r").exists() and not (tmp_path / "t.png").exists()
    text = write_report(path, tmp_path / "r", scene_png=png, scene_case={"train": other, "speed_kmh": 250,
                                                                        "time_s": record, "scale": 40})["markdown"]
    assert (f"The passage of {other} at 250 km/h, smooth rail at t = {record:.4g} s as a 3-D scene (mode_shapes.png): "
            "the deck's vertical displacements, drawn through a cubic spline between its nodes, exaggerated × 40; the "
            "axles where they are at that time.*") in text.read_text(encoding="utf-8")


def test_the_scene_caption_says_car_bodies_are_rigid_and_when_the_gif_aliases(files, tmp_path):
    """A train of cars: the caption says the bodies are drawn rigid on their wheels (the file holds
    their accelerations only); moving forces say nothing of bodies. An animation whose frames
    alias the deck's vibration: the caption repeats animate_case's warning; a plain path (no
    frame data) or frames that resolve n₀ add nothing."""
    png = write_report(files / "cars.h5", tmp_path / "a")["images"][0]
    cars = write_report(files / "cars.h5", tmp_path / "c", scene_png=png,
                        scene_case={"train": "ICE3", "speed_kmh": 300})["markdown"].read_text(encoding="utf-8")
    assert ("the axles where they are at that time, the car bodies drawn rigid on their wheels (the results file "
            "holds their accelerations, not their motion).") in cars
    (train, speed, _), times = _governing_recorded(files / "sweep.h5")
    gif = tmp_path / "scene.gif"
    gif.write_bytes(b"GIF89a")
    n0 = float(SweepResults(str(files / "sweep.h5")).bridge()["frequencies_hz"][0])
    needed = math.ceil(4 * n0 * (times[-1] - times[0])) + 1
    spacing = (times[-1] - times[0]) / 6
    aliased = RenderedAnimation(gif, 7, spacing, n0, needed, vtsi.scene3d._aliasing_text(spacing, [n0], n0, needed))
    resolved = RenderedAnimation(gif, needed, 0.25 / n0, n0, needed, "")
    for movie, said in ((aliased, f" In it, frames {spacing:.3g} s apart, more than a quarter period "
                                  f"({0.25 / n0:.3g} s) of the deck's first vertical frequency (n0 = {n0:.4g} Hz); the "
                                  f"deck's vibration is aliased; max_frames >= {needed} resolves it (vtsi check: "
                                  f"--animation-frames {needed})."), (resolved, ""), (gif, "")):
        text = write_report(files / "sweep.h5", tmp_path, scene_png=png, scene_animation=movie,
                            scene_case={"train": train, "speed_kmh": speed})["markdown"].read_text(encoding="utf-8")
        caption = re.search(r"\*(The passage of [^*]*)\*", text).group(1)
        assert "car bodies" not in caption
        assert caption.endswith("The whole passage as an animation: scene.gif (not embedded)." + said)


def _run_row(text):
    return next((label, value) for label, value in _markdown_rows(text).items() if label.startswith("free vibration"))


def test_the_run_after_the_train_is_the_records_whole_length(files, tmp_path):
    """A sweep of cars runs on past the free vibration until its last car body stops counting:
    the row said '0.214 s free vibration' where the record ran 0.62 s past the last axle. Now it
    gives each record's n_steps × Δt past the last axle leaving the track (computed here from the
    stored n_steps, x_head0 and offsets), the free vibration and the run-out with their values;
    that the record runs exactly to the run-out is the closed form of a track ending at the deck
    (the last car's last wheel is the train's last axle: t = n_steps Δt within one Δt)."""
    for name, cars in (("cars.h5", True), ("sweep.h5", False)):
        results = SweepResults(str(files / name))
        dt, f1 = 5e-3, float(results.bridge()["frequencies_hz"][0])
        x_end = float(np.max(results.bridge()["deck_x_m"]))
        after = []
        for train in results.trains:
            data = results.train_data(train)
            for speed in results.speeds_kmh:
                attrs = results.case(train, speed, -1)["attrs"]
                leave = (x_end - attrs["x_head0"] + float(np.max(data["axle_offsets_m"]))) / (speed / 3.6)
                after.append(attrs["n_steps"] * dt - leave)
        label, value = _run_row(write_report(files / name, tmp_path / name)["markdown"].read_text(encoding="utf-8"))
        free = 1.5 / f1
        if cars:
            runout = float(results.train_data("ICE3")["body_runout_s"])
            assert after[0] > free + dt and abs(after[0] - runout) <= dt          # the run-out, not the free vibration
            assert label == "free vibration and car-body run-out"
            assert value == (f"{after[0]:.4g} s after the last axle leaves the track (each record's end, n_steps × "
                             f"Δt): the free vibration, {free:.3g} s (the default, 1.5 periods of the model's first "
                             f"vertical mode, {f1:.4g} Hz), run on until the last car body stops counting, its run-out after "
                             f"the train's last wheel leaves the decks (ICE3 {runout:.3g} s: half a period of the "
                             "car's lowest mode, wheels held, how long the check counts a car body's acceleration "
                             "after it leaves)")
        else:
            assert all(free <= a <= free + dt for a in after)                   # moving forces: the free vibration
            assert (label, value) == ("free vibration", f"{free:.3g} s (the default, 1.5 periods of the model's first "
                                                        f"vertical mode, {f1:.4g} Hz) after the last axle leaves the "
                                                        "track")


class _Headings(HTMLParser):
    """Per table id: its headings' classes and, per column, its cells' classes."""

    def __init__(self, text):
        super().__init__()
        self.tables, self._table, self._column = {}, None, 0
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table":
            self._table = self.tables.setdefault(a.get("id") or f"table {len(self.tables)}", {"head": [], "cells": {}})
        elif tag == "tr":
            self._column = 0
        elif tag in ("th", "td") and self._table is not None:
            classes = set((a.get("class") or "").split())
            if tag == "th":
                self._table["head"].append(classes)
            else:
                self._table["cells"].setdefault(self._column, []).append(classes)
                self._column += 1


def test_numeric_headings_sit_over_their_numbers(files, tmp_path):
    """Headings were left-aligned over right-aligned numbers (the trains table's 'total static load
    kN' over the length): a column whose every cell is a number has its heading right-aligned
    (class num, th.num in the style sheet), '---:' in the Markdown; every table of the report."""
    out = write_report(files / "cars.h5", tmp_path / "r")
    html_text, markdown = out["html"].read_text(encoding="utf-8"), out["markdown"].read_text(encoding="utf-8")
    assert re.search(r"th\.num \{ text-align: right; \}", html_text)
    tables = _Headings(html_text).tables
    for name, table in tables.items():
        for j, head in enumerate(table["head"]):
            cells = table["cells"].get(j, [])
            assert ("num" in head) == (bool(cells) and all("num" in c for c in cells)), (name, j)
    numeric = {name: [j for j, head in enumerate(t["head"]) if "num" in head] for name, t in tables.items()}
    assert numeric["train-table"] == [2, 3, 4, 5] and numeric["check-table"] == [1, 2, 3, 6]
    rules = re.findall(r"^\|(?:-{3}:?\|)+$", markdown, flags=re.M)
    assert "|---|---:|---:|---:|---:|---|" in rules                    # trains (the colour swatch not in Markdown)
    assert "|---|---:|---:|---:|---|---|---:|---|---|" in rules          # checks
    assert rules.count("|---|---|") == sum(1 for t in tables.values() if not any("num" in h for h in t["head"]))


def _lab(colour):
    """CIELAB (D65) of an sRGB colour '#rrggbb' (IEC 61966-2-1 and CIE 15)."""
    rgb = np.array([int(colour[i: i + 2], 16) for i in (1, 3, 5)]) / 255.0
    linear = np.where(rgb > 0.04045, ((rgb + 0.055) / 1.055) ** 2.4, rgb / 12.92)
    xyz = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]) @ linear
    t = xyz / np.array([0.95047, 1.0, 1.08883])
    f = np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_the_other_spans_colours_cannot_be_taken_for_a_train():
    """The other spans' gold (#d4a017) was 11.7 ΔE76 from a train's dark goldenrod and near the
    orange of the governing train: every span colour is now at least 27 ΔE76 from every train
    colour and the limit's, 24 from one another, each with its own dashes."""
    spans = [_lab(c) for c, _ in SPAN_STYLES]
    others = [_lab(c) for c in PALETTE + (vtsi.report.LIMIT_COLOUR,)]
    assert min(np.linalg.norm(s - o) for s in spans for o in others) >= 27.0
    assert min(np.linalg.norm(a - b) for i, a in enumerate(spans) for b in spans[:i]) >= 24.0
    assert np.linalg.norm(_lab("#d4a017") - _lab("#b8860b")) < 12.0          # what it was
    assert len({str(style) for _, style in SPAN_STYLES}) == len(SPAN_STYLES) and "-" not in dict(SPAN_STYLES).values()


def test_resonances_are_marked_for_every_order_of_the_en_series(files, tmp_path):
    """The chart marked i = 1, 2, 3 where the EN series refines i = 1 … HARMONICS (4): ICE3's D/4
    at n₀ = 9.485 Hz, 3.6 × 9.485 × 24.775 / 4 = 211.5 km/h, in a 200-250 km/h sweep (two decks'
    check names it as stepped across), is marked; the caption lists the orders."""
    assert RESONANCE_ORDERS == tuple(range(1, HARMONICS + 1)) == (1, 2, 3, 4)
    marks = _resonance_marks(np.array([9.485, 13.06]), {"ICE3": 24.775}, np.array([200.0, 250.0]))
    assert [(t, i) for _, t, i in marks] == [("ICE3", 4)]
    assert marks[0][0] == pytest.approx(3.6 * 9.485 * 24.775 / 4)
    text = write_report(files / "sweep.h5", tmp_path / "r")["markdown"].read_text(encoding="utf-8")
    assert "the resonance speeds v = n₀ D / i (i = 1, 2, 3, 4) of each train" in text
