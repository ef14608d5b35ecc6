"""Recorders whose files cannot grow (a full disk: a file size limit, RLIMIT_FSIZE with SIGXFSZ
ignored, whose writes fail with EFBIG as a full disk's with ENOSPC; or /dev/full, every write of
which fails with ENOSPC). HDF5 writing the file itself lost the error where h5py released a
dataset, raised HDF5's multi-line RuntimeErrors, and left a file whose header claimed bytes it
never wrote (unreadable: 'truncated file'), or crashed the process at close. Now the run stops
with one RecorderError naming the recorder, the file, the OS's reason and what the file holds,
and the file holds exactly that. The runs that write to a failing disk run in a subprocess (a
crash must not take pytest down); each file is compared with the same run recorded in memory.
The command layer's Contact and Train recorders' message for a file option without its name is
tested at the end."""
import errno
import os
import re
import subprocess
import sys
import textwrap

import h5py
import numpy as np
import pytest

import vtsi
import vtsi.opensees as ops
from vtsi.errors import CommandError, RecorderError, VtsiError
from vtsi.recorders import HDF5Sink, NodeRecorder, TextSink

DT, N_STEPS, CHUNK = 1e-3, 4000, 50
NODES, DOFS = list(range(1, 51)), [1, 2]          # 100 columns

BEAM = """
import os, resource, signal, sys
import vtsi


def beam():
    '''A simply supported 10 m beam of 49 elements, a constant load at node 26.'''
    m = vtsi.Model()
    for i in range(50):
        m.node(i + 1, 10.0 * i / 49, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(50, 0, 1, 0)
    for e in range(1, 50):
        m.element("elasticBeamColumn", e, (e, e + 1), A=0.5, E=2e11, I=0.01, rho=1e3)
    m.add_time_series(vtsi.Constant(tag=1))
    m.pattern(1, 1).load(26, 0.0, -1e5, 0.0)
    return m


def limit_after(cls, chunks, path, extra=0):
    '''From the chunk after ``chunks`` on, no file of this process may grow past ``path``'s size
    then (+ ``extra`` bytes): its writes fail as on a full disk.'''
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    write, seen = cls.write, []

    def limited(self, times, values, envelope):
        seen.append(len(times))
        if len(seen) == chunks + 1:
            limit = os.path.getsize(path) + extra
            print("limit", limit)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))
        write(self, times, values, envelope)
    cls.write = limited
"""

API = BEAM + """
from vtsi.errors import VtsiError
from vtsi.recorders import HDF5Sink, NodeRecorder, TextSink

kind, path, flush_every = sys.argv[1], sys.argv[2], int(sys.argv[3]) or None
if kind == "h5":
    rec = NodeRecorder(list(range(1, 51)), [1, 2], sink=HDF5Sink(path, flush_every=flush_every), envelope=True)
else:
    rec = NodeRecorder(list(range(1, 51)), [1, 2], sink=TextSink(path, time=True, precision=17))
limit_after(type(rec.sink), 3, path, extra=0 if kind == "h5" else 1000)     # text: a line is cut by the limit
analysis = vtsi.TransientAnalysis(beam(), "Newmark", 1e-3, recorders=[rec], chunk_steps=50)
for attempt in range(2 if kind == "h5" else 1):                               # h5: a second run after the failure
    try:
        analysis.run(4000)
    except VtsiError as exc:
        print(f"{type(exc).__name__}: {exc}")
if kind == "h5":
    print("read", rec.values.shape[0])                                        # read back: the file's rows
"""

COMMANDS = BEAM + """
import vtsi.opensees as ops
from vtsi.errors import VtsiError
from vtsi.recorders import HDF5Sink

ops.model("basic", "-ndm", 2, "-ndf", 3)
for i in range(50):
    ops.node(i + 1, 10.0 * i / 49, 0.0)
ops.fix(1, 1, 1, 0)
ops.fix(50, 0, 1, 0)
ops.geomTransf("Linear", 1)
for e in range(1, 50):
    ops.element("elasticBeamColumn", e, e, e + 1, 0.5, 2e11, 0.01, 1, "-mass", 500.0)
ops.timeSeries("Constant", 1)
ops.pattern("Plain", 1, 1)
ops.load(26, 0.0, -1e5, 0.0)
ops.integrator("Newmark", 0.5, 0.25)
ops.analysis("Transient")
ops.recorder("Node", "-h5", sys.argv[1], "-time", "-nodeRange", 1, 50, "-dof", 1, 2, "disp")
limit_after(HDF5Sink, 3, sys.argv[1])
for again in range(2):                  # analyze 50 steps at a time until it stops, then once more
    try:
        while True:
            ops.analyze(50, 1e-3)
    except VtsiError as exc:
        print(f"{type(exc).__name__}: {exc}")
ops.remove("recorder", 0)
print("removed")
"""


def _memory_run():
    """The run of the scripts, recorded in memory: times (N_STEPS,) [s], values (N_STEPS, 100)."""
    namespace = {}
    exec(BEAM, namespace)                                   # the scripts' own beam
    rec = NodeRecorder(NODES, DOFS)
    vtsi.TransientAnalysis(namespace["beam"](), "Newmark", DT, recorders=[rec], chunk_steps=CHUNK).run(N_STEPS)
    return rec.time, rec.values


@pytest.fixture(scope="module")
def memory_run():
    return _memory_run()


def _run(tmp_path, script, *args):
    """Run ``script`` in a subprocess; its stdout lines (it must end normally, without a word on stderr)."""
    path = tmp_path / "script.py"
    path.write_text(textwrap.dedent(script))
    done = subprocess.run([sys.executable, str(path), *map(str, args)], cwd=tmp_path, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0 and done.stderr == "", done.stderr[-3000:]
    return done.stdout.splitlines()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE and SIGXFSZ")
@pytest.mark.parametrize("flush_every, per_flush", [(0, CHUNK), (120, 3 * CHUNK)])
def test_an_hdf5_recorder_on_a_full_disk_stops_the_run_and_keeps_its_last_flush(tmp_path, memory_run, flush_every,
                                                                                per_flush):
    """The file stops growing after the third chunk: the run stops at the first flush that
    needed more of it, with one line naming the recorder, the file, the OS's reason, the records
    lost (those since the last flush: one chunk, or with flush_every=120 the three chunks of a
    flush) and what the file holds; the file holds exactly the rows of its last flush, as the
    run in memory has them, and their envelope; a second run is refused with the same account,
    and the recorder reads its file back."""
    path = tmp_path / "out.h5"
    out = _run(tmp_path, API, "h5", path, flush_every)
    assert out[0].startswith("limit ")
    who = re.escape(f"node recorder (HDF5 file {path})")
    first = re.fullmatch(who + r": cannot write the records of t = (\S+) to (\S+) s \(File too large\); the file "
                               r"holds the (\d+) rows up to t = (\S+) s", out[1][len("RecorderError: "):])
    assert out[1].startswith("RecorderError: ") and first, out[1]
    time, values = memory_run
    with h5py.File(path, "r") as f:
        kept, rows = f["time"][...], f["values"][...]
        np.testing.assert_array_equal(f["runs/rows"][...], [len(kept)])
        envelope = {name: f["envelope"][name][...] for name in ("min", "max", "absmax")}
        n_records = f["envelope"].attrs["n_records"]
    n = len(kept)
    assert int(first[3]) == n and 3 * CHUNK <= n < N_STEPS and n % per_flush == 0
    assert float(first[4]) == pytest.approx(time[n - 1], rel=1e-6)
    assert float(first[1]) == pytest.approx(time[n], rel=1e-6)
    assert float(first[2]) == pytest.approx(time[n + per_flush - 1], rel=1e-6)
    np.testing.assert_array_equal(kept, time[:n])
    np.testing.assert_array_equal(rows, values[:n])
    np.testing.assert_array_equal(envelope["min"], values[:n].min(axis=0))
    np.testing.assert_array_equal(envelope["max"], values[:n].max(axis=0))
    np.testing.assert_array_equal(envelope["absmax"], np.abs(values[:n]).max(axis=0))
    assert n_records == n
    assert out[2] == (f"RecorderError: node recorder (HDF5 file {path}): stopped at a write that failed (File too "
                      f"large); the file holds the {n} rows up to t = {first[4]} s; a new recorder records to a new "
                      "file")
    assert out[3:] == [f"read {n}"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE and SIGXFSZ")
def test_a_text_recorder_on_a_full_disk_keeps_whole_lines(tmp_path, memory_run):
    """The limit lets 1000 bytes of the failing chunk in, part of a line (a line of 100 values at
    17 digits takes some 2.4 kB): the file is cut back to the last whole line, the lines the
    message counts, each as the run in memory has it."""
    path = tmp_path / "out.txt"
    out = _run(tmp_path, API, "text", path, 0)
    limit = int(out[0].split()[1])
    found = re.fullmatch(re.escape(f"RecorderError: node recorder (text file {path})") +
                         r": cannot write the records of t = (\S+) to (\S+) s \(File too large\); the file holds the "
                         r"(\d+) lines up to t = (\S+) s", out[1])
    assert found and len(out) == 2, out
    text = path.read_bytes()
    assert text.endswith(b"\n") and len(text) < limit           # the part of a line written is gone
    table = np.loadtxt(path)
    n = len(table)
    time, values = memory_run
    assert int(found[3]) == n and n >= 3 * CHUNK and float(found[4]) == pytest.approx(time[n - 1], rel=1e-6)
    assert float(found[1]) == pytest.approx(time[n], rel=1e-6)
    np.testing.assert_array_equal(table[:, 0], time[:n])
    np.testing.assert_array_equal(table[:, 1:], values[:n])    # 17 digits: every double as it was


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE and SIGXFSZ")
def test_a_command_layer_hdf5_recorder_on_a_full_disk_names_its_tag(tmp_path):
    """recorder Node -h5: the analyze stops with the recorder's tag, the next one is refused
    with the same account, and removing the recorder raises nothing; the file holds the rows
    of its last flush, the times of the steps."""
    path = tmp_path / "node.h5"
    out = _run(tmp_path, COMMANDS, path)
    found = re.fullmatch(re.escape(f"RecorderError: recorder 0 (node, HDF5 file {path})") +
                         r": cannot write the records of t = (\S+) to (\S+) s \(File too large\); the file holds the "
                         r"(\d+) rows up to t = (\S+) s", out[1])
    assert found, out
    with h5py.File(path, "r") as f:
        kept = f["time"][...]
        assert f["values"].shape == (len(kept), 100)
    n = len(kept)
    assert int(found[3]) == n and n % CHUNK == 0 and n >= 3 * CHUNK
    np.testing.assert_allclose(kept, DT * np.arange(1, n + 1), rtol=1e-12)
    assert out[2:] == [f"RecorderError: recorder 0 (node, HDF5 file {path}): stopped at a write that failed (File too "
                       f"large); the file holds the {n} rows up to t = {found[4]} s; a new recorder records to a new "
                       "file", "removed"]


SCRIPT = """model basic -ndm 2 -ndf 3
node 1 0.0 0.0
node 2 10.0 0.0
fix 1 1 1 0
fix 2 0 1 0
geomTransf Linear 1
element elasticBeamColumn 1 1 2 1.0 2e11 1e-2 1 -mass 1e3
timeSeries Constant 1
pattern Plain 1 1 {{ load 2 0.0 0.0 1e3 }}
integrator Newmark 0.5 0.25
analysis Transient
recorder Node {option} /dev/full -time -node 2 -dof 3 disp
analyze 5 0.01
"""


@pytest.mark.skipif(not os.access("/dev/full", os.W_OK), reason="/dev/full (a device every write to fails: disk full)")
@pytest.mark.parametrize("option, account", [
    ("-h5", "recorder 0 (node, HDF5 file /dev/full): cannot write the new file (No space left on device); the file is "
            "empty"),
    ("-file", "recorder 0 (node, text file /dev/full): cannot write the records of t = 0.01 to 0.05 s (No space left "
              "on device); the file holds no lines")])
def test_vtsi_run_on_a_full_disk_says_so_in_one_line(tmp_path, option, account):
    """A Tcl script whose recorder writes to a full disk: one line, naming the script's line,
    the recorder and its file, and exit status 1 (a file it cannot write, not a usage error)."""
    (tmp_path / "full.tcl").write_text(SCRIPT.format(option=option))
    done = subprocess.run([sys.executable, "-m", "vtsi", "run", "full.tcl"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.splitlines() == [f"vtsi: full.tcl line 13: {account}"]


@pytest.mark.skipif(not os.access("/dev/full", os.W_OK), reason="/dev/full (a device every write to fails: disk full)")
def test_a_text_envelope_that_cannot_be_written_says_where_the_values_are():
    """An envelope-only text recorder writes its three lines at the end of the run: on a full
    disk that write stops the run with the steps the envelope holds, and the recorder's envelope
    holds them (as a recorder in memory has them)."""
    namespace = {}
    exec(BEAM, namespace)
    rec = NodeRecorder([26], [2], envelope=True, history=False, sink=TextSink("/dev/full"))
    memory = NodeRecorder([26], [2])
    analysis = vtsi.TransientAnalysis(namespace["beam"](), "Newmark", DT, recorders=[rec, memory],
                                      chunk_steps=CHUNK)
    with pytest.raises(RecorderError) as info:
        analysis.run(200)
    assert str(info.value) == ("node recorder (text file /dev/full): cannot write the envelope of the 200 steps up to "
                               "t = 0.2 s (No space left on device); the file is empty (the recorder's envelope holds "
                               "the values)")
    assert info.value.__notes__ == [f"raised by recorders[0] {rec!r} when closed; the other recorders are closed"]
    assert issubclass(RecorderError, VtsiError) and issubclass(RecorderError, OSError)
    np.testing.assert_array_equal(rec.envelope.min, memory.values.min(axis=0))
    np.testing.assert_array_equal(rec.envelope.max, memory.values.max(axis=0))


# -- the command layer's Contact and Train recorders: a file option without its name --------------
@pytest.mark.parametrize("line, message", [
    (("Train", "-dof", 2, "-file", "disp"), "recorder Train: no response given: -file took 'disp' for its file name; "
                                            "give the file name after -file, the response last (-file out.txt disp)"),
    (("Contact", "-wheel", 1, "-h5", "force"), "recorder Contact: no response given: -h5 took 'force' for its file "
                                               "name; give the file name after -h5, the response last (-h5 out.h5 "
                                               "force)"),
    (("Train", "-dof", 2, "disp", "-file"), "recorder Train: -file needs a file name, got none"),
    (("Contact", "-file", "-wheel", 1, "gap"),
     "recorder Contact: -file needs a file name, got none ('-wheel' follows)"),
])
def test_contact_and_train_recorders_name_a_file_option_without_its_name(tmp_path, monkeypatch, line, message):
    """``-file disp`` with the file name left out read the response as the file's name and said
    only 'no response given'; it now says so (OpenSeesPy writes a file named 'disp' and records
    nothing it can name: 'dataToStore -file not recognized'). No file is created."""
    monkeypatch.chdir(tmp_path)
    session = ops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    with pytest.raises(CommandError, match=f"^{re.escape(message)}$"):
        session.recorder(*line)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="flock")
def test_a_file_another_process_has_open_is_refused_not_emptied(tmp_path, memory_run):
    """The sink locks its file as HDF5 did: a file another process holds open (here a reader's
    h5py.File, HDF5's shared lock) is refused naming it, and left as it was (HDF5 emptied it for
    overwrite=True, then refused it: 'unable to lock file')."""
    path = tmp_path / "held.h5"
    namespace = {}
    exec(BEAM, namespace)
    first = NodeRecorder(NODES, DOFS, sink=HDF5Sink(path))
    vtsi.TransientAnalysis(namespace["beam"](), "Newmark", DT, recorders=[first], chunk_steps=CHUNK).run(100)
    before = path.read_bytes()
    holder = subprocess.Popen([sys.executable, "-c", "import h5py, sys; f = h5py.File(sys.argv[1], 'r'); print(1, "
                               "flush=True); sys.stdin.read()", str(path)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "1\n"
        second = NodeRecorder(NODES, DOFS, sink=HDF5Sink(path, overwrite=True))
        analysis = vtsi.TransientAnalysis(namespace["beam"](), "Newmark", DT, recorders=[second])
        with pytest.raises(BlockingIOError, match=f"^HDF5 recorder: cannot create {re.escape(str(path))}: another "
                                                  "process has it open \\(locked\\)$"):
            analysis.run(10)
    finally:
        holder.communicate("")
    assert path.read_bytes() == before
    np.testing.assert_array_equal(first.values, memory_run[1][:100])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="flock")
def test_a_file_system_without_locks_is_written_unlocked(tmp_path, monkeypatch, memory_run):
    """flock failing as on a file system without locks (ENOLCK, some NFS mounts): the file is
    written without a lock, as HDF5 writes it there; another failure of flock is raised naming
    the file, and the file it created removed."""
    from vtsi.recorders import sinks

    def no_locks(fd, operation):
        raise OSError(errno.ENOLCK, "No locks available")
    monkeypatch.setattr(sinks.fcntl, "flock", no_locks)
    namespace = {}
    exec(BEAM, namespace)
    rec = NodeRecorder(NODES, DOFS, sink=HDF5Sink(tmp_path / "nolocks.h5"))
    vtsi.TransientAnalysis(namespace["beam"](), "Newmark", DT, recorders=[rec], chunk_steps=CHUNK).run(100)
    with h5py.File(tmp_path / "nolocks.h5", "r") as f:
        np.testing.assert_array_equal(f["values"][...], memory_run[1][:100])

    def broken(fd, operation):
        raise OSError(errno.EIO, "Input/output error")
    monkeypatch.setattr(sinks.fcntl, "flock", broken)
    rec = NodeRecorder(NODES, DOFS, sink=HDF5Sink(tmp_path / "eio.h5"))
    with pytest.raises(OSError, match=f"^HDF5 recorder: cannot create {re.escape(str(tmp_path / 'eio.h5'))}: "
                                      "Input/output error$"):
        vtsi.TransientAnalysis(namespace["beam"](), "Newmark", DT, recorders=[rec]).run(10)
    assert not (tmp_path / "eio.h5").exists()                 # the empty file it made is not left behind
