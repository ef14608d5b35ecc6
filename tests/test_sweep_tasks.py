"""How a sweep's cases reach its workers, from a review's findings: tasks sized by each case's own
time histories (a task of slow cases held 311 MB against a 128 MB budget, sized from the mean
case), a speed step too fine for a float to count its speeds refused in one line, and a bridge
whose classes or settings the pool's workers cannot receive: a bridge script's element type
under a fork server or spawn (run in this process, with a warning), a lambda (refused)."""
import logging
import multiprocessing
import re
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import vtsi.sweep as sweep_module
from vtsi.__main__ import main
from vtsi.bridge_file import load_bridge
from vtsi.errors import SweepError
from vtsi.passage import Output, PassageSettings
from vtsi.sweep import TASK_HISTORY_BYTES, Sweep, beam_bridge, speeds
from vtsi.sweep_results import ResultsWriter

MODAL = PassageSettings(damping=0.01, bridge="modal")
ACCELERATIONS = [Output("acceleration", "accel", cutoff="en", history=True)]
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "bridge_20m.toml"


# -- 1. a task's time histories, counted case by case --------------------------------------------
def test_no_task_holds_more_than_the_history_budget():
    """The reviewer's sweep: HSLM-A1 and A7 at 40 to 400 km/h over 10 x 30 m keeping the deck
    accelerations. From the mean case (13.7 MB) its tasks held 9 cases each, the first (HSLM-A1,
    40-80 km/h) 311 MB; each case's own size now closes a task before the budget, and the tasks
    are the cases in order."""
    sweep = Sweep(beam_bridge([30.0] * 10, 3.5e10, 1.9, 15000.0), ["HSLM-A1", "HSLM-A7"], "40:400:5", MODAL,
                  outputs=ACCELERATIONS)
    todo = sweep.cases
    each = dict(zip(todo, sweep.history_bytes(todo)))
    assert each[todo[0]] > 9 * each[todo[72]] > 9 * 2 ** 20           # 40 km/h against 400 km/h
    assert sum(each[c] for c in todo[:9]) > 2 * TASK_HISTORY_BYTES      # the 9 cases of the mean's first task
    for workers in (1, 8):
        size = sweep.task_size(len(todo), sweep.case_cost(todo), workers)
        tasks = sweep.tasks(todo, workers)
        held = [sum(each[c] for c in task) for task in tasks]
        assert [c for task in tasks for c in task] == todo
        assert max(held) <= TASK_HISTORY_BYTES and max(map(len, tasks)) <= size and len(tasks) >= workers
        assert all(h + each[after[0]] > TASK_HISTORY_BYTES or len(task) == size      # closed only when it had to be
                   for task, h, after in zip(tasks, held, tasks[1:]))
        assert [len(t) for t in tasks[:3]] == [2, 3, 4]                 # 40-45, 50-60, 65-80 km/h


def test_a_case_above_the_budget_alone_is_a_task_of_its_own(monkeypatch):
    sweep = Sweep(beam_bridge([20.0, 20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], [100.0, 150.0, 200.0, 300.0], MODAL,
                  outputs=ACCELERATIONS)
    each = sweep.history_bytes(sweep.cases)
    assert np.all(np.diff(each) < 0)
    monkeypatch.setattr(sweep_module, "TASK_HISTORY_BYTES", each[1] + each[3])   # below the 100 km/h case's
    assert [len(t) for t in sweep.tasks(sweep.cases, 1)] == [1, 1, 2]


def test_history_bytes_are_each_case_s_own():
    """A case's estimate is the float64 time and values its history holds, measured on a run at
    two speeds (each seed of a speed alike); 0 without a history."""
    sweep = Sweep(beam_bridge([20.0, 20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], [150.0, 300.0], MODAL,
                  outputs=ACCELERATIONS)
    sweep.prepare()
    kept = [sum(a.nbytes for a in sweep.runner.run("HSLM-A1", v).histories["acceleration"]) for v in (150.0, 300.0)]
    assert sweep.history_bytes(sweep.cases).tolist() == kept and kept[0] > 1.5 * kept[1]
    plain = Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], [150.0, 300.0], MODAL)
    assert plain.history_bytes(plain.cases).tolist() == [0.0, 0.0]
    assert [len(t) for t in plain.tasks(plain.cases * 5, 2)] == [5, 5]        # without histories: as before


def test_a_sweep_writes_the_tasks_it_built_and_the_same_results(tmp_path, monkeypatch):
    """Tasks only regroup cases: the envelopes are those of one task of all cases, bit for bit."""
    sweep = Sweep(beam_bridge([20.0, 20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], "120:320:40", MODAL,
                  outputs=ACCELERATIONS)
    each = sweep.history_bytes(sweep.cases)
    monkeypatch.setattr(sweep_module, "TASK_HISTORY_BYTES", each[0] + each[1])
    expected = [len(t) for t in sweep.tasks(sweep.cases, 1)]
    batches = []
    write = ResultsWriter.write
    monkeypatch.setattr(ResultsWriter, "write",
                        lambda self, results: batches.append(len(results)) or write(self, results))
    split = sweep.run(tmp_path / "split.h5", workers=1, progress=False)
    assert batches == expected == [2, 3, 1]
    whole = sweep.run(tmp_path / "whole.h5", workers=1, progress=False, cases_per_task=6)
    assert batches[3:] == [6]
    for quantity in split.quantities:
        np.testing.assert_array_equal(split.envelope(quantity), whole.envelope(quantity))
    for case in sweep.cases:
        a, b = split.history(*case)["acceleration"], whole.history(*case)["acceleration"]
        np.testing.assert_array_equal(a[1], b[1])


# -- 2. a step too fine for a float to count its speeds -----------------------------------------
@pytest.mark.parametrize("spec, step, count", [("1:400:1e-310", "1e-310", "3.99e+312"),
                                               ("5e-324:1:1e-320", "9.99989e-321", "1.00001e+320"),
                                               ("300:400:1e-300", "1e-300", "1e+302")])
def test_a_step_below_a_float_s_range_of_counts_is_refused_in_one_line(spec, step, count):
    """(stop - start) / step overflowed to inf and math.floor raised a bare OverflowError."""
    with pytest.raises(SweepError, match=re.escape(f"speeds {spec!r}: a step of {step} km/h makes {count} speeds, "
                                                   f"more than {sweep_module.MAX_SPEEDS}")):
        speeds(spec)


def test_the_command_line_exits_2_on_it(capsys):
    status = main(["sweep", str(EXAMPLE), "--trains", "HSLM-A1", "--speeds", "1:400:1e-310", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err and "makes 3.99e+312 speeds, more than 10000" in err


# -- 3. what the pool's workers cannot receive --------------------------------------------------
def _spawned(monkeypatch, method):
    """The sweep's pool forced to start its workers by ``method``, as when another thread runs."""
    monkeypatch.setattr(sweep_module, "_pool_context", lambda: multiprocessing.get_context(method))


@pytest.fixture(scope="module")
def script_sweep(tmp_path_factory, own_element_script):
    """A sweep over a bridge script's deck of its own element type (loaded once: its element
    type's name is registered)."""
    path = tmp_path_factory.mktemp("script") / "bridge.py"
    path.write_text(own_element_script("TaskBeam", "taskBeam"))
    return Sweep(load_bridge(str(path)), ["HSLM-A1"], "250:300:25", MODAL)


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_a_script_s_element_type_runs_in_this_process_when_the_pool_cannot_import_it(script_sweep, monkeypatch,
                                                                                       caplog, method):
    """A bridge script's class lives in a module only this process has (sys.modules): a forked
    worker inherits it, a spawned one failed with a worker's traceback. The sweep now runs in
    this process, saying so, with the results of workers=1."""
    if method not in multiprocessing.get_all_start_methods():
        pytest.skip(f"no {method} here")
    sweep = script_sweep
    etype = sweep.runner.model.build().blocks[0][0]
    module = (etype if isinstance(etype, type) else type(etype)).__module__
    assert module.startswith("vtsi_bridge_script_") and sys.modules[module].__spec__ is None
    serial = sweep.run(None, workers=1, progress=False)
    _spawned(monkeypatch, method)
    monkeypatch.setattr(sweep_module, "ProcessPoolExecutor", None)          # no pool may start
    with caplog.at_level(logging.WARNING, logger="vtsi.sweep"):
        pooled = sweep.run(None, workers=2, progress=False)
    [record] = caplog.records
    assert record.getMessage() == (
        f"sweep: TaskBeam is defined in module {module}, which the pool's {method} workers (another thread runs "
        "in this process) cannot import: the sweep runs in this process, on one core; define it in an importable "
        "module to run it on 2")
    for quantity in serial.quantities:
        np.testing.assert_array_equal(pooled.envelope(quantity), serial.envelope(quantity))


def test_only_a_module_made_at_run_time_is_out_of_the_workers_reach(monkeypatch):
    """A class whose module is in sys.modules but has no file or finder a new process has: out of
    reach of spawned workers, not of forked ones; a catalogue bridge is in reach of both."""
    sweep = Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], "300", MODAL)
    assert sweep_module._unimportable(sweep.runner, "spawn") is None
    module = types.ModuleType("vtsi_tasks_test_made_here")
    monkeypatch.setitem(sys.modules, module.__name__, module)

    class Marker:
        pass

    Marker.__module__, Marker.__qualname__ = module.__name__, "Marker"
    module.Marker = Marker
    sweep.runner.model.marker = Marker
    assert sweep_module._unimportable(sweep.runner, "spawn") is Marker
    assert sweep_module._unimportable(sweep.runner, "forkserver") is Marker
    assert sweep_module._unimportable(sweep.runner, "fork") is None


def test_large_arrays_pickle_for_the_workers():
    """Arrays of more than 64 kB reach the pickler's file as a pickle.PickleBuffer (protocol 5),
    which has no len(): every bridge of realistic size was refused as one that cannot be pickled."""
    assert sweep_module._pickle_error({"factor": np.zeros((3000, 300)), "rows": np.ones(10_000)})[0] is None


def test_what_cannot_be_pickled_is_named_before_anything_runs(monkeypatch):
    """A lambda in the bridge's model raised PicklingError from the pool's feeder thread."""
    sweep = Sweep(beam_bridge([20.0], 3.5e10, 1.9, 15000.0), ["HSLM-A1"], "250:300:25", MODAL)
    sweep.runner.model.hook = lambda x: x
    monkeypatch.setattr(sweep_module, "ProcessPoolExecutor", None)          # no pool may start
    with pytest.raises(SweepError, match=re.escape("sweep: the sweep's model cannot be pickled for the pool's workers "
                                                   "(")) as caught:
        sweep.run(None, workers=2, progress=False)
    assert "<lambda>" in str(caught.value) and "\n" not in str(caught.value)
    assert str(caught.value).endswith("run in this process with workers=1 (--workers 1)")
