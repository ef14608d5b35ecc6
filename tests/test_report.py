"""The report (vtsi.report): every section and chart present in the HTML, the checks table equal to
the check stored in the results file, the Markdown's images on disk, a file without a check
refused."""
import base64
import math
import re
import shutil
from html.parser import HTMLParser

import numpy as np
import pytest

from vtsi.check import check, stored_check
from vtsi.errors import SweepError
from vtsi.passage import PassageSettings
from vtsi.report import PNG_MAGIC, SECTIONS, write_report
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
        for name in ("value", "limit", "utilisation", "speed_kmh"):
            assert _same(shown[name], getattr(row, name)), (row.criterion, name, shown[name], getattr(row, name))


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
    assert "| bridge model | modal: its modes up to 49.53 Hz, exact passages of moving forces, cars time-stepped |" in text
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
