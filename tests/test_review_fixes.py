"""Small defects found by the reviews of 2026-11-27, each checked here: a results file of another
run length is not blamed on car bodies alone; a CSV train's file written before its D came from
its signature names D; 'vtsi check -h' states every exit status; a failed passage's line has no
class name; a bridge script's track error has one prefix; a train in a model's units keeps its
signature's peak; the report's history charts shade while an axle is on a deck, not on the
approaches."""
import json
import re
import textwrap

import h5py
import numpy as np
import pytest

import vtsi.__main__ as cli
from vtsi import report as report_module
from vtsi.bridge_file import script_bridge
from vtsi.check import check, stored_check
from vtsi.errors import BridgeModelError, DivergenceError, PassageError, SweepError
from vtsi.models.catalogue import catalogue_train
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.report import _axles_on_decks, _Report
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import SweepResults, train_fingerprint
from vtsi.units import Units
from vtsi.vehicle import Train

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2          # f1 = (pi/L)^2 sqrt(EI/mu) / 2pi = 5 Hz
FAST = PassageSettings(dt=5e-3, damping=0.0125)
COACH_M = 18.0                                              # [m] the coach length of _coach_table


def _bridge():
    return beam_bridge([L], EI, 1.0, MU, elements_per_span=4)


def _coach_table(path, load_kn=170):
    """An axle table of ten 18 m coaches, each with axles at 0, 2.5, 12.5 and 15 m from its front
    (``load_kn`` each): its regular spacing, the coach length, is D = 18 m."""
    positions = np.concatenate([c * COACH_M + np.array([0.0, 2.5, 12.5, 15.0]) for c in range(10)])
    path.write_text("position_m,load_kN\n" + "".join(f"{p:g},{load_kn}\n" for p in positions))
    return path


# -- 1. a file of another run length ---------------------------------------------------------------
def test_another_run_length_is_not_blamed_on_car_bodies(tmp_path):
    """A sweep of moving forces reads no car body; a file whose case ran another number of steps
    is refused naming the case and both lengths, saying the passages ran another length, the car
    bodies' rule only as an example."""
    path = tmp_path / "r.h5"
    Sweep(_bridge(), ["HSLM-A1"], "200", FAST).run(path, workers=1, progress=False)
    with h5py.File(path, "a") as f:
        written = int(f["cases/n_steps"][0])          # what this vtsi ran
        f["cases/n_steps"][0] = written + 7
    with pytest.raises(SweepError) as info:
        Sweep(_bridge(), ["HSLM-A1"], "200", FAST).run(path, workers=1, progress=False, resume=True)
    text = str(info.value)
    assert text.startswith(f"results file {path}: its passage of HSLM-A1 at 200 km/h ran {written + 7} steps, this "
                           f"vtsi runs {written}: the file was written by a vtsi whose passages ran another length "
                           "(since 2026-11-27 a sweep reading car bodies runs until the last car body stops "
                           "counting; since 2026-11-28 cars on an irregular rail start far enough")
    assert "use another file, or overwrite=True (--overwrite)" in text


# -- 2. a CSV train's D --------------------------------------------------------------------------
def test_a_csv_file_run_before_its_d_came_from_its_signature_names_d(tmp_path, monkeypatch):
    """Before 2026-11-27 an axle table had no D, hashed as 0 in its fingerprint; now its D comes
    from its signature (18 m, the coach length), so the fingerprints differ: the refusal names D,
    not 'its axles, loads or cars'."""
    monkeypatch.chdir(tmp_path)
    csv, path = _coach_table(tmp_path / "t.csv"), tmp_path / "csv.h5"
    assert catalogue_train("t.csv", 1.0).characteristic_length == COACH_M
    Sweep(_bridge(), ["t.csv"], "200", FAST).run(path, workers=1, progress=False)
    old = Train.from_csv(csv, 1.0, characteristic_length=None)      # the table as a vtsi before then read it
    with h5py.File(path, "a") as f:
        identity = json.loads(f.attrs["identity"])
        identity["train_fingerprints"]["t.csv"] = train_fingerprint(old)
        f.attrs["identity"] = json.dumps(identity, sort_keys=True)
    with pytest.raises(SweepError, match=re.escape(
            "csv.h5 holds a different sweep (train t.csv differs from the one it ran with in its characteristic "
            "length D only (none in the file, 18 m here: from its dynamic signature, which vtsi reads from an axle "
            "table since 2026-11-27)); use another file, or overwrite=True (--overwrite)")):
        Sweep(_bridge(), ["t.csv"], "200", FAST).run(path, workers=1, progress=False, resume=True)
    lighter = Train.from_csv(_coach_table(tmp_path / "u.csv", 150), 1.0, characteristic_length=None)
    with h5py.File(path, "a") as f:                  # other loads and no D: not D alone
        identity["train_fingerprints"]["t.csv"] = train_fingerprint(lighter)
        f.attrs["identity"] = json.dumps(identity, sort_keys=True)
    with pytest.raises(SweepError, match=r"train t.csv differs from the one it ran with in its axles, loads, cars or "
                                         r"characteristic length D: an edited axle table"):
        Sweep(_bridge(), ["t.csv"], "200", FAST).run(path, workers=1, progress=False, resume=True)


# -- 3. vtsi check -h ---------------------------------------------------------------------------
def test_check_help_states_every_exit_status_as_the_module_docstring(capsys):
    """'vtsi check -h' said '1 a criterion fails' without no verdict, and nothing of 143."""
    with pytest.raises(SystemExit):
        cli.main(["check", "-h"])
    text = " ".join(capsys.readouterr().out.split())
    docstring = " ".join(cli.__doc__.split())
    verdicts = ("0 every criterion passes (PASS); 1 a criterion fails (FAIL), or no verdict (NO VERDICT: an "
                "incomplete sweep, a criterion with a limit left not checked, or none held to a limit)")
    assert verdicts in text and verdicts.removesuffix(")") in docstring
    assert (f"{cli.EXIT_INTERRUPTED} interrupted (Ctrl-C), {cli.EXIT_TERMINATED} terminated (SIGTERM)" in text
            and "130 interrupted (Ctrl-C) and 143 terminated (SIGTERM" in docstring)
    assert "3 a passage failed" in text and "3 a passage failed" in docstring
    assert "or a results file another run is writing" in text


# -- 4. a failed passage's line -------------------------------------------------------------------
def test_a_failed_passage_says_vtsis_message_without_its_class(monkeypatch):
    """vtsi's messages name the object and the value; the class name before them
    ('DivergenceError: ') told a user nothing more."""
    message = "coupled analysis diverged at step 3, t = 0.015 s (|u| > 1000 m or NaN)"

    def diverging(self, train, speed_kmh, seed=-1):
        raise DivergenceError(message, 3, 0.015)

    monkeypatch.setattr(PassageRunner, "run", diverging)
    with pytest.raises(PassageError) as info:
        Sweep(_bridge(), ["HSLM-A1"], "200", FAST).run(None, workers=1, progress=False)
    assert str(info.value) == f"case HSLM-A1/200kmh/smooth: {message}"


# -- 5. a bridge script's track error -------------------------------------------------------------
def test_a_track_error_of_a_bridge_script_has_one_prefix(tmp_path, deck_script):
    """The Track's message began 'track: ' after the script's 'track 2: ': one prefix, with the
    tag. Elements 2 (x = 2 to 4 m) and 4 (x = 6 to 8 m) of the deck leave a gap from 4 to 6 m."""
    path = tmp_path / "gap.py"
    path.write_text(deck_script(0.6948, "ops.track(2, '-ele', 1, 2, 4)\n"))
    with pytest.raises(BridgeModelError) as info:
        script_bridge(path, 2)
    assert str(info.value) == (f"bridge script {path}: track 2: elements 2 and 4 leave a gap or overlap between "
                               "x = 4 and 6")


# -- 6. a train in a model's units ----------------------------------------------------------------
def test_a_train_in_a_models_units_keeps_its_signature_peak(tmp_path):
    """Units.train rebuilt the train with D scaled, and its signature_peak became None, which the
    Train docstring says only of a D that was given. In kN and mm the peak's lengths are 1000
    times the SI ones and its G 1/1000 of it; D is the peak's D, 18 m = 18000 mm."""
    si = Train.from_csv(_coach_table(tmp_path / "t.csv"), 1.0)
    mm = Units("kN", "mm").train(si, 1000.0)
    peak, si_peak = mm.signature_peak, si.signature_peak
    assert mm.characteristic_length == pytest.approx(1000 * COACH_M, rel=1e-15)
    assert peak.length_m == mm.characteristic_length
    assert peak.wavelength_m == pytest.approx(1000 * si_peak.wavelength_m, rel=1e-15)
    assert peak.wavelength_range_m == pytest.approx(tuple(1000 * x for x in si_peak.wavelength_range_m), rel=1e-15)
    assert peak.signature == pytest.approx(si_peak.signature / 1000, rel=1e-15)
    assert (peak.repeats, peak.share, peak.below_m) == (si_peak.repeats, si_peak.share, None)
    given = Units("kN", "mm").train(catalogue_train("HSLM-A1", 1.0), 1000.0)     # D given: no peak
    assert given.signature_peak is None and given.characteristic_length == pytest.approx(18000.0, rel=1e-15)


# -- 7. the history charts' shading ---------------------------------------------------------------
def test_axles_on_decks_in_closed_form():
    """Axle k at offset o_k behind the head (at x0 when t = 0, speed V) is on the deck a..b from
    (a - x0 + o_k)/V to (b - x0 + o_k)/V; the stretches of all axles and decks merged."""
    np.testing.assert_allclose(_axles_on_decks([[5.0, 25.0]], [0.0, 3.0], -2.0, 10.0), [(0.7, 3.0)], rtol=1e-12)
    # two decks 10 m apart, axles 3 m apart: each deck its own stretch
    np.testing.assert_allclose(_axles_on_decks([[0.0, 10.0], [20.0, 30.0]], [0.0, 3.0], 0.0, 10.0),
                               [(0.0, 1.3), (2.0, 3.3)], rtol=1e-12)
    # axles 15 m apart: none on a deck from 1.0 to 1.5 s (between them over deck 1) and from
    # 3.0 to 3.5 s (between them over deck 2); the second axle on deck 1 while the first is on deck 2
    np.testing.assert_allclose(_axles_on_decks([[0.0, 10.0], [20.0, 30.0]], [0.0, 15.0], 0.0, 10.0),
                               [(0.0, 1.0), (1.5, 3.0), (3.5, 4.5)], rtol=1e-12)


def test_the_history_chart_shades_the_deck_not_the_approaches(tmp_path, monkeypatch, approaches_tcl):
    """A 20 m deck (x = 5 to 25 m) with 5 m approaches: HSLM-A1 (its axles at most 16 m apart,
    less than the deck) at 300 km/h has an axle on the deck from its head reaching x = 5 m to
    its last axle leaving x = 25 m, one stretch; before, the shading began when the head reached
    the approach at x = 0."""
    script = tmp_path / "approaches.tcl"
    script.write_text(textwrap.dedent(approaches_tcl))
    path = tmp_path / "a.h5"
    sweep = Sweep(script_bridge(script), ["HSLM-A1"], "300", PassageSettings(dt=2e-3, damping=0.01))
    check(sweep.run(path, workers=1, progress=False)).store(path)
    sweep.record_histories(path, [("HSLM-A1", 300.0, -1)])
    drawn = []
    monkeypatch.setattr(report_module, "_png", lambda fig: drawn.append(fig) or b"")
    _Report(SweepResults(path), stored_check(path), path).history_png("HSLM-A1", 300.0, -1, {"disp": "deck_displacement"})
    shaded = [p for p in drawn[0].axes[0].patches if p.get_facecolor()[:3] == pytest.approx((0.949, 0.949, 0.949),
                                                                                             abs=1e-3)]
    offsets = catalogue_train("HSLM-A1", 1.0).wheel_offsets
    assert np.all(np.diff(offsets) < 20.0)
    V, x0 = 300 / 3.6, float(offsets[0])          # the default approach, 0 m: the head at the track's start, x = 0
    np.testing.assert_allclose([(p.get_x(), p.get_x() + p.get_width()) for p in shaded],
                               [((5.0 - x0) / V, (25.0 - x0 + offsets.max()) / V)], rtol=1e-12)
