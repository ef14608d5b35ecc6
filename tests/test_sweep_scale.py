"""Sweeps at scale, from a probe's findings: the static envelopes' memory bounded by a block
budget (vtsi.influence.BLOCK_BYTES) whatever the number of responses × axles, a task's time
histories bounded (vtsi.sweep.TASK_HISTORY_BYTES), a lock file that cannot be created refused
as a bad input (status 2), speed ranges that are not finite or far too fine refused in one line,
record_histories' own remedy for a file of another sweep, and an axle table named by another
path (a sweep resumed from another folder) continuing its file, and the static envelopes computed
once per output."""
import os
import re
import tracemalloc
import warnings

import numpy as np
import pytest

import vtsi
import vtsi.influence as influence
import vtsi.sweep as sweep_module
from vtsi.__main__ import main
from vtsi.bridge_file import load_bridge
from vtsi.errors import ModelError, SweepError
from vtsi.influence import InfluenceLines
from vtsi.models import hslm_a
from vtsi.models.bridges import continuous_beam
from vtsi.passage import Output, PassageRunner, PassageSettings
from vtsi.sweep import MAX_SPEEDS, Sweep, beam_bridge, speeds
from vtsi.sweep_results import ResultsFileRefused, ResultsWriter, SweepResults
from vtsi.track import Track, row_width
from vtsi.vehicle import MAX_TRAIN_SPEED
from vtsi.workflow import refuse_before_sweep

MODAL = PassageSettings(damping=0.01, bridge="modal")
AXLES = "position_m,load_kN\n0,170\n3.0,170\n14.0,170\n17.0,170\n21.0,170\n24.0,170\n"


def three_spans():
    """The deflection influence lines of every node of a continuous beam of 3 × 20 m (10
    elements a span: 31 responses) and HSLM-A1 (50 axles)."""
    model = vtsi.Model()
    beam = continuous_beam(model, [20.0, 20.0, 20.0], 10, 3.5e10, 1.9, 15000.0)
    track = Track(model, beam.elements)
    return InfluenceLines(model, track, [(n, 2) for n in beam.nodes]), hslm_a(1, 1.0)


def peak_bytes(call):
    """The peak of Python's allocations (numpy's arrays included) while ``call()`` runs [B]."""
    tracemalloc.start()
    try:
        call()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


# -- 1. the static envelopes' memory -------------------------------------------------------------
def test_blocks_split_the_budget():
    """A scan takes BLOCK_BYTES // (bytes per position) positions a block, whatever their number
    (the axle sums need no blocks: a compiled kernel adds each axle's row in place)."""
    lines, train = three_spans()
    n = lines.n_responses
    heads = influence._blocks(10 ** 6, 8 * train.wheel_offsets.size * n)
    assert {s.stop - s.start for s in heads[:-1]} == {influence.BLOCK_BYTES // (8 * train.wheel_offsets.size * n)}
    assert heads[-1].stop >= 10 ** 6 and influence._blocks(3, 10 ** 12) == [slice(0, 1), slice(1, 2), slice(2, 3)]


def test_static_envelopes_peak_within_the_budget():
    """HSLM-A1 over 3 × 20 m, 31 deflections: a fixed block of 2048 heads gathered (2048 × 50
    axles, 4, 31) float64, 101 MB, twice over (230 MB peak, measured); now each of the train's,
    LM71's and SW/0's envelopes peaks within 3 × BLOCK_BYTES (the scan's own arrays here ~1 MB)."""
    lines, train = three_spans()
    old_block = 2048 * train.wheel_offsets.size * row_width(lines.track.length.min(), 0.0) * lines.n_responses * 8
    assert old_block > 100e6
    for call in (lambda: lines.train_envelope(train.wheel_offsets, train.static_wheel_loads),
                 lines.lm71_envelope, lines.sw0_envelope):
        assert peak_bytes(call) < 3 * influence.BLOCK_BYTES < old_block / 8


def test_blocks_give_the_same_numbers_to_the_bit(monkeypatch):
    """Blocks of one position and the default blocks give the same train and SW/0 envelopes and
    LM71 envelope, bit for bit (each row is summed alone, in one order, whatever its block); and
    LM71's point loads, now summed as a train's axles, equal P × Σ IL(centre + offset), LM71's
    old sum, to round-off."""
    lines, train = three_spans()
    default = (lines.train_envelope(train.wheel_offsets, train.static_wheel_loads), lines.lm71_envelope(),
               lines.sw0_envelope(), lines(np.linspace(-3.0, 63.0, 661)))
    width, n = row_width(lines.track.length.min(), 0.0), lines.n_responses
    monkeypatch.setattr(influence, "BLOCK_BYTES", 8 * (width + 1) * n * 7)    # 7 positions, 1 head a block
    single = (lines.train_envelope(train.wheel_offsets, train.static_wheel_loads), lines.lm71_envelope(),
              lines.sw0_envelope(), lines(np.linspace(-3.0, 63.0, 661)))
    for a, b in zip(default, single):
        np.testing.assert_array_equal(a, b)
    offsets = influence.LM71_SPACING * np.array([-1.5, -0.5, 0.5, 1.5])
    centres = np.linspace(-2.4, 62.4, 651)
    summed = influence.LM71_AXLE * lines((centres[:, None] + offsets).ravel()).reshape(len(centres), 4, -1).sum(axis=1)
    point = lines._train_response(centres, -offsets, np.full(4, influence.LM71_AXLE))
    np.testing.assert_allclose(point, summed, rtol=1e-14, atol=1e-14 * np.abs(summed).max())


# -- 2. a task's time histories ----------------------------------------------------------------
def history_sweep(n_speeds=6):
    outputs = [Output("deflection", "disp"), Output("acceleration", "accel", cutoff="en", history=True)]
    return Sweep(beam_bridge([20.0, 20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], 200.0 + 10.0 * np.arange(n_speeds),
                 MODAL, outputs=outputs)


def test_history_bytes_are_what_a_passage_keeps():
    """A case's estimate is the float64 time and values its history holds, measured on a run."""
    sweep = history_sweep(1)
    sweep.prepare()
    time, values = sweep.runner.run("HSLM-A1", 200.0).histories["acceleration"]
    assert sweep.history_bytes(sweep.cases) == time.nbytes + values.nbytes
    no_history = Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], "200", MODAL)
    assert no_history.history_bytes(no_history.cases) == 0.0


def test_a_task_holds_at_most_the_history_budget(tmp_path, monkeypatch):
    """An exact modal case counts 0.02 of a time step a sample: 60 such cases of 14.5 MB of
    histories each were one task (870 MB held until one write). A task now holds at most
    TASK_HISTORY_BYTES of them (counted case by case: tests/test_sweep_tasks.py); without
    histories the split is as before."""
    assert Sweep.task_size(60, 356.0, 1) == 60
    sweep = history_sweep()
    each = sweep.history_bytes(sweep.cases)
    monkeypatch.setattr(sweep_module, "TASK_HISTORY_BYTES", 2.5 * each.max())
    batches = []
    write = ResultsWriter.write
    monkeypatch.setattr(ResultsWriter, "write", lambda self, results: batches.append(len(results)) or write(self, results))
    results = sweep.run(tmp_path / "h.h5", workers=1, progress=False)
    assert batches == [2, 2, 2] and results.n_done == 6 and len(results.histories()) == 6


# -- 3. a lock file that cannot be created -------------------------------------------------------
def test_a_lock_file_that_cannot_be_created_is_a_bad_input(tmp_path, beam_toml, capsys, monkeypatch):
    """'results file /sys/a.h5: cannot create its lock file ... (Permission denied)' exited 1 (a
    passage failed) where docs/cli.md lists it under 2: the writer's refusals before any passage
    runs are ResultsFileRefused, status 2 (here the lock's path is a directory: EISDIR)."""
    monkeypatch.chdir(tmp_path)
    bridge = beam_toml(tmp_path / "bridge.toml", damping=0.0125)
    (tmp_path / "r.h5.lock").mkdir()
    status = main(["sweep", str(bridge), "--trains", "A1", "--speeds", "300", "--bridge-model", "modal",
                   "--out", "r.h5", "--workers", "1", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err
    assert err.startswith(f"vtsi sweep: results file {tmp_path / 'r.h5'}: cannot create its lock file "
                          f"{tmp_path / 'r.h5.lock'} ("), err
    assert sorted(os.listdir(tmp_path)) == ["bridge.toml", "r.h5.lock"]
    sweep = Sweep(load_bridge(bridge), ["HSLM-A1"], "300", MODAL)
    with pytest.raises(ResultsFileRefused, match="cannot create its lock file"):
        sweep.run(tmp_path / "r.h5", workers=1, progress=False)


# -- 4. speeds ---------------------------------------------------------------------------------
@pytest.mark.parametrize("spec, words", [
    ("300:400:inf", "the step must be finite, got inf km/h"),
    ("300:400:-inf", "the step must be finite, got -inf km/h"),
    ("nan:400:5", "the start must be finite, got nan km/h"),
    ("300:inf:5", "the stop must be finite, got inf km/h"),
])
def test_a_range_that_is_not_finite_is_named_without_a_warning(spec, words):
    """'300:400:inf' printed numpy's RuntimeWarning, then '... got nan'; 'nan:400:5' and
    '300:inf:5' raised numpy's ValueError and OverflowError."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SweepError, match=re.escape(f"speeds {spec!r}: {words}")):
            speeds(spec)


def test_more_than_max_speeds_is_refused():
    """'200:300:0.001' (100 001 passages) ran 9 minutes. 10 000 speeds span every speed a train
    reaches (up to 720 km/h) 0.072 km/h apart: more is refused, naming the step and the count;
    a range's count is known before any array is made (a step of 1e-300 km/h too)."""
    with pytest.raises(SweepError, match=re.escape("speeds '200:300:0.001': a step of 0.001 km/h makes 100001 speeds, "
                                                   f"more than {MAX_SPEEDS}")):
        speeds("200:300:0.001")
    with pytest.raises(SweepError, match=re.escape("a step of 1e-300 km/h makes 1e+302 speeds")):
        speeds("300:400:1e-300")
    assert MAX_SPEEDS == 10_000 and 3.6 * MAX_TRAIN_SPEED / MAX_SPEEDS == pytest.approx(0.072)
    assert len(speeds(np.linspace(1.0, 720.0, MAX_SPEEDS))) == MAX_SPEEDS
    with pytest.raises(SweepError, match=re.escape(f"speeds: {MAX_SPEEDS + 1} speeds, more than {MAX_SPEEDS}")):
        speeds(np.linspace(1.0, 720.0, MAX_SPEEDS + 1))


# -- 5. record_histories on a file of other settings --------------------------------------------
def test_record_histories_says_to_build_the_sweep_as_the_file_s(tmp_path):
    """It said 'use another file, or overwrite=True (--overwrite)', which record_histories does
    not take: it names the setting that differs and says to build the Sweep with the file's."""
    bridge = beam_bridge([20.0], 3.5e10, 1.9, 15000.0)
    path = tmp_path / "r.h5"
    Sweep(bridge, ["HSLM-A1"], "300", MODAL).run(path, workers=1, progress=False)
    before = path.read_bytes()
    other = Sweep(bridge, ["HSLM-A1"], "300", PassageSettings(damping=0.02, bridge="modal"))
    with pytest.raises(ResultsFileRefused) as excinfo:
        other.record_histories(path, [("HSLM-A1", 300, -1)])
    text = str(excinfo.value)
    assert text == (f"results file {path} holds a different sweep (it differs in settings.damping (0.02 here, 0.01 in "
                    "the file)); record_histories adds to the file of its own sweep: build the Sweep with the file's "
                    "settings.damping")
    assert "overwrite" not in text and path.read_bytes() == before


# -- 6. an axle table by another path; the reader's and the bridge file's messages ----------------
def test_an_axle_table_by_another_path_continues_its_file(tmp_path, monkeypatch):
    """Run from one folder as 't.csv', resumed from a folder below as '../t.csv': refused as
    another sweep ('../t.csv is here, not in the file; t.csv is in the file, not here') although
    the table is the same (its content's hash, which the file holds). The resume continues the
    file; its cases and histories keep the name first given, and equal an uninterrupted run's."""
    (tmp_path / "t.csv").write_text(AXLES)
    (tmp_path / "below").mkdir()
    bridge = beam_bridge([20.0, 20.0], 3.5e10, 1.9, 15000.0)
    outputs = [Output("deflection", "disp", history=True)]
    monkeypatch.chdir(tmp_path)
    whole = Sweep(bridge, ["HSLM-A1", "t.csv"], "250,300", MODAL, outputs=outputs).run(None, workers=1, progress=False)
    run, calls = PassageRunner.run, []

    def stopped(self, *args, **kwargs):         # the sweep interrupted after its first case
        calls.append(args)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return run(self, *args, **kwargs)
    monkeypatch.setattr(PassageRunner, "run", stopped)
    with pytest.raises(KeyboardInterrupt):
        Sweep(bridge, ["HSLM-A1", "t.csv"], "250,300", MODAL, outputs=outputs).run(
            "below/r.h5", workers=1, progress=False, cases_per_task=1)
    monkeypatch.setattr(PassageRunner, "run", run)
    assert SweepResults("below/r.h5").n_done == 1
    monkeypatch.chdir(tmp_path / "below")
    results = Sweep(bridge, ["HSLM-A1", "../t.csv"], "250,300", MODAL, outputs=outputs).run(
        "r.h5", workers=1, progress=False, resume=True)
    assert results.trains == ["HSLM-A1", "t.csv"] and results.n_done == 4
    assert results.histories() == sorted(whole.histories()) and "t.csv/300kmh/smooth" in results.histories()
    for q in whole.quantities:
        np.testing.assert_array_equal(results.envelope(q), whole.envelope(q))
    np.testing.assert_array_equal(results.history("t.csv", 300)["deflection"][1], whole.history("t.csv", 300)["deflection"][1])
    (tmp_path / "below" / "u.csv").write_text(AXLES.replace("170", "180"))      # another table: another sweep
    with pytest.raises(ResultsFileRefused, match=re.escape("it differs in trains (u.csv is here, not in the file; "
                                                           "t.csv is in the file, not here)")):
        Sweep(bridge, ["HSLM-A1", "u.csv"], "250,300", MODAL, outputs=outputs).run(
            "r.h5", workers=1, progress=False, resume=True)


def test_the_reader_says_an_axle_table_keeps_its_case(tmp_path, monkeypatch):
    """SweepResults.train_name('T.CSV') said 'names ignore case', which holds for catalogue
    names only."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.csv").write_text(AXLES)
    results = Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1", "t.csv"], "300", MODAL).run(
        None, workers=1, progress=False)
    assert results.train_name("a1") == "HSLM-A1" and results.train_name("t.csv") == "t.csv"
    with pytest.raises(SweepError) as excinfo:
        results.train_name("T.CSV")
    assert str(excinfo.value) == ("sweep results: train 'T.CSV' is not one of the sweep's: HSLM-A1, t.csv (catalogue "
                                  "names ignore case, 'A1' is 'HSLM-A1'; an axle table is named by its path as the "
                                  "sweep was given it, case included)")


def test_an_infinite_span_must_be_finite(tmp_path):
    """'a span of inf m is not a railway span (1 to 1000 m); is spans_m in mm?'"""
    path = tmp_path / "inf.toml"
    path.write_text('[bridge]\nkind = "beam"\nspans_m = [30.0, inf]\nE_Pa = 3.6e10\nf1_Hz = 4.0\nmu_kg_m = 20000.0\n')
    with pytest.raises(ModelError, match=re.escape("spans_m: every span must be finite [m], got inf")) as excinfo:
        load_bridge(path)
    assert "mm" not in str(excinfo.value)


def test_static_envelopes_are_computed_once_per_output(monkeypatch):
    """A check refuses bad inputs before its sweep by building the results record in memory,
    /static included, and the sweep's file builds it again: the influence-line envelopes
    (quadratic in the mesh: 20 s on 10 × 40 elements) were computed twice per output."""
    sweep = Sweep(beam_bridge([20.0, 20.0], 3.0e11, 1.0, 15000.0, elements_per_span=6), ["HSLM-A1"], "200",
                  MODAL, outputs=[Output("deflection", "disp"), Output("moment", "moment")])
    computed = []
    compute = PassageRunner._static_envelopes
    monkeypatch.setattr(PassageRunner, "_static_envelopes",
                        lambda self, o, trains: computed.append(o.name) or compute(self, o, trains))
    refuse_before_sweep(sweep)
    results = sweep.run(None, workers=1, progress=False)
    assert sorted(computed) == ["deflection", "moment"]
    fresh = compute(sweep.runner, sweep.runner.outputs[0], sweep.trains)
    np.testing.assert_array_equal(results.static("deflection")[1], fresh.lm71)
