"""A sweep stopped from outside: Ctrl-C to the whole process group (every case a worker
finished is written, the workers end the case they run), a worker killed as the sweep stops
(the process ends), and a results file that cannot grow (a full disk, a file size limit:
nothing half-written is committed, and the process is not crashed). The kill of a sweep
(SIGKILL, with a pool) is tested in test_sweep.py."""
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.bridge_file import load_bridge
from vtsi.errors import DivergenceError, PassageError
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.sweep import Sweep
from vtsi.sweep_results import ResultsWriter, SweepResults, case_key

CASES = 2 * 29                                     # HSLM-A1 and A2 at 140:420:10
SWEEP = ["--trains", "HSLM-A1,HSLM-A2", "--speeds", "140:420:10", "--quiet"]

LOGGED = """
import sys, time
import vtsi.passage
from vtsi.__main__ import main
run = vtsi.passage.PassageRunner.run


def logged(self, train, speed_kmh, seed=-1, *args, **kwargs):
    result = run(self, train, speed_kmh, seed, *args, **kwargs)
    time.sleep(0.4)                                   # a task of many cases, each long enough to be cut
    with open(sys.argv[1], "a") as log:               # the case is finished: its worker says so
        log.write(f"{train} {float(speed_kmh):.10g} {seed}\\n")
    return result


vtsi.passage.PassageRunner.run = logged               # forked into the pool's workers
sys.exit(main(sys.argv[2:]))
"""


def _cases(path):
    """The cases in the results file ``path``: {(train, speed [km/h], seed)}."""
    r = SweepResults(path)
    there = ~np.isnan(r.start_positions())
    return {(r.trains[i], float(r.speeds_kmh[j]), r.seeds[k]) for i, j, k in zip(*np.nonzero(there))}


def _same_results(a, b):
    """The two results files hold the same cases with the same envelopes, bit for bit."""
    ra, rb = SweepResults(a), SweepResults(b)
    assert ra.n_done == rb.n_done == ra.n_cases
    for q in ra.quantities:
        np.testing.assert_array_equal(ra.envelope(q), rb.envelope(q))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups and fork")
def test_ctrl_c_writes_every_case_the_workers_finished(tmp_path, beam_toml):
    """Ctrl-C reached the workers too: their running tasks were waited for, or cut, and none
    of their cases written (a cars sweep waited 14.5 s after a Ctrl-C, then threw 2 tasks away).
    Now the workers ignore it, end the case they run when the sweep tells them, and the sweep
    writes every case they finished before it exits 130 with its one line; a resume equals an
    uninterrupted run."""
    import psutil    # a dependency of dask.distributed, a test extra: its absence fails the test
    bridge = beam_toml(tmp_path / "bridge.toml", damping=0.0125, dt_s=0.01)
    out, log = tmp_path / "out.h5", tmp_path / "finished.txt"
    script = tmp_path / "logged.py"
    script.write_text(textwrap.dedent(LOGGED))
    proc = subprocess.Popen([sys.executable, str(script), str(log), "sweep", str(bridge), *SWEEP, "--workers", "2",
                             "--out", str(out)], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)      # its own process group, as a terminal's job
    try:
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None and \
                (not log.exists() or len(log.read_text().splitlines()) < 4):
            time.sleep(0.02)
        assert proc.poll() is None, "the sweep ended before it could be interrupted"
        workers = psutil.Process(proc.pid).children()
        assert len(workers) == 2
        os.killpg(proc.pid, signal.SIGINT)                   # Ctrl-C: the sweep and its workers
        at_signal = len(log.read_text().splitlines())
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    _, alive = psutil.wait_procs(workers, timeout=10)
    assert not alive
    finished = {(t, float(v), int(s)) for t, v, s in (line.split() for line in log.read_text().splitlines())}
    done = len(finished)
    assert proc.returncode == 130 and stdout == ""
    assert stderr.splitlines() == [f"vtsi sweep: interrupted ({done} of {CASES} cases are in {out}; --resume runs "
                                   "the rest)"]
    assert _cases(out) == finished                          # every finished case written, none lost
    assert done <= at_signal + 2 < CASES                    # each worker ended the case it ran
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bridge.toml", "finished.txt", "logged.py", "out.h5"]
    assert main(["sweep", str(bridge), *SWEEP, "--workers", "1", "--out", str(out), "--resume"]) == 0
    assert main(["sweep", str(bridge), *SWEEP, "--workers", "1", "--out", str(tmp_path / "whole.h5")]) == 0
    _same_results(out, tmp_path / "whole.h5")


BROKEN = """
import multiprocessing, os, signal, sys, threading
from vtsi.bridge_file import load_bridge
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep
from vtsi.sweep_results import ResultsWriter

write, batches = ResultsWriter.write, []


def kill(pid):
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:                    # it had ended
        pass


def interrupted(self, results):                   # the first task written, Ctrl-C, and a worker dies in its case
    write(self, results)
    batches.append(len(results))
    if len(batches) == 1:
        threading.Timer(0.05, kill, (multiprocessing.active_children()[0].pid,)).start()
        raise KeyboardInterrupt


ResultsWriter.write = interrupted
sweep = Sweep(load_bridge(sys.argv[1]), ["HSLM-A1", "HSLM-A2"], "140:420:2", PassageSettings(dt=2e-4, damping=0.0125))
try:
    sweep.run(sys.argv[2], workers=2, progress=False, cases_per_task=3)      # ~0.3 s a case
except KeyboardInterrupt:
    print("interrupted")
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork")
def test_a_pool_that_breaks_while_the_sweep_stops_does_not_hang_it(tmp_path, beam_toml):
    """A Ctrl-C, then a worker killed (as a SIGTERM to the whole process group kills them): the
    sweep cancelled its tasks while the pool's thread failed the futures of the broken pool,
    which killed that thread (Python 3.11, InvalidStateError) and hung the process at exit (2
    of 6 SIGTERMs to the process group of a sweep of HSLM-A and ICE3; 2 of 4 runs of this
    test). The sweep stops, and the process ends."""
    bridge = beam_toml(tmp_path / "bridge.toml")
    path = tmp_path / "out.h5"
    script = tmp_path / "broken.py"
    script.write_text(textwrap.dedent(BROKEN))
    done = subprocess.run([sys.executable, str(script), str(bridge), str(path)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0 and done.stdout == "interrupted\n", done.stderr[-2000:]
    assert "InvalidStateError" not in done.stderr
    assert SweepResults(path).n_done >= 3 and sorted(p.name for p in tmp_path.iterdir()) == [
        "bridge.toml", "broken.py", "out.h5"]


LIMITED = """
import os, resource, signal, sys
from vtsi.bridge_file import load_bridge
from vtsi.errors import SweepError
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep
from vtsi.sweep_results import ResultsWriter

path = sys.argv[2]
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)     # a write past the limit fails (EFBIG), as on a full disk
write, batches = ResultsWriter.write, []


def limited(self, results):
    write(self, results)
    batches.append(len(results))
    if len(batches) == 2:                         # from now on, no file of this process may grow past this one
        resource.setrlimit(resource.RLIMIT_FSIZE, (os.path.getsize(path), resource.RLIM_INFINITY))


ResultsWriter.write = limited
sweep = Sweep(load_bridge(sys.argv[1]), ["HSLM-A1"], "140:420:10", PassageSettings(dt=0.01, damping=0.0125))
try:
    sweep.run(path, workers=1, progress=False, cases_per_task=1)
except SweepError as exc:
    print(exc)
"""


def test_a_write_that_fails_commits_nothing_and_the_run_goes_on(tmp_path, beam_toml):
    """HDF5 writing the batch's copy past a file size limit (or on a full disk) lost the error
    where h5py released a dataset, and the process crashed (segmentation fault) when the copy was
    closed; on a full disk the copy, its last batch's envelopes zero, had first been renamed over
    the file. The copy is written by Python now: the write's error stops the run with its
    SweepError, and the file holds the two batches before it, as they were."""
    bridge = beam_toml(tmp_path / "bridge.toml", damping=0.0125, dt_s=0.01)
    path, whole = tmp_path / "limited.h5", tmp_path / "whole.h5"
    script = tmp_path / "limited.py"
    script.write_text(textwrap.dedent(LIMITED))
    done = subprocess.run([sys.executable, str(script), str(bridge), str(path)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.splitlines() == [f"results file {path}: cannot write 1 more cases (File too large); the cases "
                                        "finished before them are in it: resume=True (--resume) continues the sweep"]
    assert SweepResults(path).n_done == 2 and not (tmp_path / "limited.h5.partial").exists()
    assert main(["sweep", str(bridge), "--trains", "HSLM-A1", "--speeds", "140:420:10", "--workers", "1", "--quiet",
                 "--out", str(path), "--resume"]) == 0
    assert main(["sweep", str(bridge), "--trains", "HSLM-A1", "--speeds", "140:420:10", "--workers", "1", "--quiet",
                 "--out", str(whole)]) == 0
    _same_results(path, whole)


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="/dev/full (a device every write to fails: disk full)")
def test_a_full_disk_stops_the_sweep_with_its_line_and_keeps_the_cases_before(tmp_path, beam_toml, monkeypatch,
                                                                              capsys):
    """The copy of the second batch written to a full disk (``<file>.partial`` made a link to
    /dev/full, whose every write fails with ENOSPC): HDF5, writing that copy itself, lost the
    error, renamed a copy with the batch's envelopes zero over the file and crashed the process
    (a full tmpfs, before). The sweep exits 1 with its one line; the file holds the first
    batch's cases, bit for bit the uninterrupted run's, no .partial is left, and a resume
    finishes it."""
    bridge = beam_toml(tmp_path / "bridge.toml", damping=0.0125, dt_s=0.01)
    out, whole = tmp_path / "out.h5", tmp_path / "whole.h5"
    args = ["sweep", str(bridge), *SWEEP, "--workers", "2"]         # two tasks: two batches
    write, batches = ResultsWriter.write, []

    def full_after_first(self, results):
        write(self, results)
        batches.append(len(results))
        if len(batches) == 1:
            os.symlink("/dev/full", str(out) + ".partial")
    monkeypatch.setattr(ResultsWriter, "write", full_after_first)
    assert main([*args, "--out", str(out)]) == 1
    kept = SweepResults(out).n_done
    assert kept == batches[0] < CASES and batches == [kept]          # the second batch's write failed
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.splitlines() == [
        f"vtsi sweep: results file {out}: cannot write {CASES - kept} more cases (No space left on device); the cases "
        f"finished before them are in it: --resume continues the sweep ({kept} of {CASES} cases are in {out})"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bridge.toml", "out.h5"]
    monkeypatch.setattr(ResultsWriter, "write", write)
    assert main([*args, "--out", str(whole)]) == 0
    r, w = SweepResults(out), SweepResults(whole)
    for t, v, s in _cases(out):                            # each kept case as the uninterrupted run has it
        a, b = r.case(t, v, s), w.case(t, v, s)
        assert a.keys() == b.keys()
        for name in set(a) - {"attrs"}:
            np.testing.assert_array_equal(a[name]["envelope"], b[name]["envelope"])
    assert main([*args, "--out", str(out), "--resume"]) == 0
    _same_results(out, whole)


@pytest.mark.parametrize("failure", [KeyboardInterrupt, "diverged"])
def test_a_sweep_in_this_process_writes_the_cases_its_cut_task_finished(tmp_path, beam_toml, monkeypatch, failure):
    """workers=1 ran a whole task before writing it: a Ctrl-C (or a passage that failed) in the
    5th case of a task threw the task's 4 finished cases away. They are written before the
    interrupt (the failure) goes on, as the pool's finished cases are: the file holds the first
    task's 6 cases and the second's 4, in the sweep's order, and a resume equals an
    uninterrupted run envelope for envelope."""
    bridge = load_bridge(beam_toml(tmp_path / "bridge.toml"))
    settings = PassageSettings(dt=0.01, damping=0.0125)
    sweep = Sweep(bridge, ["HSLM-A1"], "140:420:10", settings)
    path, whole = tmp_path / "cut.h5", tmp_path / "whole.h5"
    run, started = PassageRunner.run, []

    def cut(self, train, speed_kmh, seed=-1, *args, **kwargs):
        started.append((train, speed_kmh, seed))
        if len(started) == 6 + 5:                                  # the 5th case of the second task
            if failure is KeyboardInterrupt:
                raise KeyboardInterrupt
            raise DivergenceError(f"{train} at {speed_kmh:g} km/h: {failure}", 1, 0.01)
        return run(self, train, speed_kmh, seed, *args, **kwargs)

    monkeypatch.setattr(PassageRunner, "run", cut)
    with pytest.raises(KeyboardInterrupt if failure is KeyboardInterrupt else PassageError):
        sweep.run(path, workers=1, progress=False, cases_per_task=6)
    assert [case_key(*c) for c in started] == [case_key(*c) for c in sweep.cases[:11]]
    assert _cases(path) == {(t, float(v), s) for t, v, s in sweep.cases[:10]}
    assert not (tmp_path / "cut.h5.partial").exists()
    monkeypatch.setattr(PassageRunner, "run", run)
    Sweep(bridge, ["HSLM-A1"], "140:420:10", settings).run(path, workers=1, progress=False, resume=True)
    Sweep(bridge, ["HSLM-A1"], "140:420:10", settings).run(whole, workers=1, progress=False)
    _same_results(path, whole)


FAILING = """
import sys
from vtsi.bridge_file import load_bridge
from vtsi.errors import DivergenceError, PassageError
from vtsi.passage import PassageRunner, PassageSettings
from vtsi.sweep import Sweep

run = PassageRunner.run


def failing(self, train, speed_kmh, seed=-1, *args, **kwargs):
    if speed_kmh == 230.0:                                     # the 4th case of the second task
        raise DivergenceError(f"{train} diverged at {speed_kmh:g} km/h", 1, 0.01)
    result = run(self, train, speed_kmh, seed, *args, **kwargs)
    with open(sys.argv[3], "a") as out:                        # in the worker: the case is finished
        out.write(f"{train} {float(speed_kmh):.10g} {seed}\\n")
    return result


PassageRunner.run = failing                                    # forked into the pool's workers
sweep = Sweep(load_bridge(sys.argv[1]), ["HSLM-A1"], "140:420:10", PassageSettings(dt=0.01, damping=0.0125))
try:
    sweep.run(sys.argv[2], workers=2, progress=False, cases_per_task=6)
except PassageError as exc:
    print(exc)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork: the workers inherit the failing passage")
def test_a_pool_writes_the_cases_a_failed_task_finished(tmp_path, beam_toml):
    """A passage fails in the 4th case of a pool's task: its worker raised the PassageError
    and the task's 3 finished cases were lost (the workers=1 sweep kept them). The error carries
    them (``PassageError.finished``) and the sweep writes them, with every case the other worker
    finished: the file holds exactly the cases the workers finished."""
    bridge = beam_toml(tmp_path / "bridge.toml")
    path, log, script = tmp_path / "failed.h5", tmp_path / "finished.txt", tmp_path / "failing.py"
    script.write_text(textwrap.dedent(FAILING))
    done = subprocess.run([sys.executable, str(script), str(bridge), str(path), str(log)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.startswith("case HSLM-A1/230kmh/smooth: HSLM-A1 diverged at 230 "
                                                           "km/h"), done.stdout + done.stderr[-2000:]
    finished = {(t, float(v), int(s)) for t, v, s in (line.split() for line in log.read_text().splitlines())}
    assert {("HSLM-A1", v, -1) for v in (200.0, 210.0, 220.0)} <= finished
    assert _cases(path) == finished and not (tmp_path / "failed.h5.partial").exists()
