"""What a probe of the recorders found, each fix checked against OpenSeesPy 3.7.1 (the oracle) or
an independent computation: an HDF5 file fed by several analyses describes each run (``/runs``),
a recorder that raises leaves the others every completed step, ``-precision 0`` writes as
OpenSeesPy, options that shape a text file are refused with ``-h5``, tags given as text or
floats are refused (OpenSeesPy does not read them as tags), and ``-file`` without its name says so."""
import h5py
import numpy as np
import pytest

import vtsi
import vtsi.opensees as vops
from vtsi.errors import CommandError
from vtsi.recorders import HDF5Sink, NodeRecorder, Recorder, TextSink
from vtsi.tcl import Interpreter

pytestmark = pytest.mark.usefixtures("fresh_session")
DT = 0.01
D_LAMBDA = 0.25


@pytest.fixture
def oracle():
    return pytest.importorskip("openseespy.opensees")


def model():
    """A 20 m simply supported beam of 4 elements with mass, a Linear pattern of 1 MN down at midspan."""
    m = vtsi.Model()
    for i in range(5):
        m.node(i + 1, 5.0 * i, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(5, 0, 1, 0)
    for i in range(4):
        m.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=5.0, E=3.5e10, I=2.5, rho=15000.0)
    m.pattern(1, vtsi.Linear())
    m.load(1, 3, 0.0, -1e6, 0.0)
    return m


def beam(o):
    """The same beam as OpenSees commands (module or session ``o``), the load in Linear pattern 1."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(5):
        o.node(i + 1, 5.0 * i, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(5, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for i in range(4):
        o.element("elasticBeamColumn", i + 1, i + 1, i + 2, 5.0, 3.5e10, 2.5, 1, "-mass", 15000.0 * 5.0)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e6, 0.0)


def solver(o):
    o.constraints("Plain")
    o.numberer("RCM")
    o.system("BandGeneral")
    o.test("NormDispIncr", 1e-10, 10)
    o.algorithm("Linear")


def strings(dataset):
    return [x.decode() for x in dataset[...]]


# -- 1. an HDF5 file of several runs describes each ----------------------------------------------
def test_hdf5_of_a_static_then_a_transient_run_describes_each_run(tmp_path):
    """4 static steps (dλ = 0.25), then 3 transient ones (Δt = 0.01) into one history file and one
    envelope-only file: /runs gives each run's rows, analysis, integrator, dt and time units; the
    root keeps only what both runs share (loads); the times' units, differing, are removed."""
    memory = NodeRecorder([3], [2])
    history = NodeRecorder([3], [2], sink=HDF5Sink(tmp_path / "h.h5"))
    peaks = NodeRecorder([3], [2], envelope=True, history=False, sink=HDF5Sink(tmp_path / "e.h5"))
    m = model()
    vtsi.StaticAnalysis(m, D_LAMBDA, recorders=[memory, history, peaks]).run(4)
    vtsi.TransientAnalysis(m, "Newmark", DT, recorders=[memory, history, peaks]).run(3)
    expected_time = np.r_[D_LAMBDA * np.arange(1, 5), 1.0 + DT * np.arange(1, 4)]
    with h5py.File(tmp_path / "h.h5", "r") as f:
        np.testing.assert_allclose(f["time"][...], expected_time, rtol=1e-14)
        np.testing.assert_array_equal(f["values"][...], memory.values)
        runs = f["runs"]
        np.testing.assert_array_equal(runs["first_row"][...], [0, 4])
        np.testing.assert_array_equal(runs["rows"][...], [4, 3])
        assert strings(runs["analysis"]) == ["static", "transient"]
        assert strings(runs["integrator"]) == ["LoadControl", "Newmark(gamma=0.5, beta=0.25)"]
        np.testing.assert_array_equal(runs["dt"][...], [D_LAMBDA, DT])
        assert strings(runs["time_units"]) == ["", "s"]
        assert strings(runs["loads"]) == ["the load patterns"] * 2
        assert not {"analysis", "integrator", "dt"} & set(f.attrs) and f.attrs["loads"] == "the load patterns"
        assert "units" not in f["time"].attrs
    with h5py.File(tmp_path / "e.h5", "r") as f:
        assert "time" not in f and f["envelope"].attrs["n_records"] == 7
        np.testing.assert_array_equal(f["runs/first_row"][...], [0, 4])
        np.testing.assert_array_equal(f["runs/rows"][...], [4, 3])
        assert "units" not in f["envelope/time_of_absmax"].attrs


def test_hdf5_of_one_analysis_keeps_its_attributes_and_has_one_run_row(tmp_path):
    """A transient analysis run twice (5 + 7 steps) is one row of /runs and the root attributes it
    always had; a static-only file says its times are the (dimensionless) pseudo-time."""
    rec = NodeRecorder([3], [2], sink=HDF5Sink(tmp_path / "t.h5"))
    analysis = vtsi.TransientAnalysis(model(), "Newmark", DT, recorders=[rec])
    analysis.run(5)
    analysis.run(7)
    with h5py.File(tmp_path / "t.h5", "r") as f:
        assert (f.attrs["analysis"], f.attrs["integrator"], f.attrs["dt"]) == \
            ("transient", "Newmark(gamma=0.5, beta=0.25)", DT)
        assert f["time"].attrs["units"] == "s"
        np.testing.assert_array_equal(f["runs/first_row"][...], [0])
        np.testing.assert_array_equal(f["runs/rows"][...], [12])
        np.testing.assert_allclose(f["time"][...], DT * np.arange(1, 13), rtol=1e-13)
    static = NodeRecorder([3], [2], sink=HDF5Sink(tmp_path / "s.h5"))
    vtsi.StaticAnalysis(model(), D_LAMBDA, recorders=[static]).run(4)
    with h5py.File(tmp_path / "s.h5", "r") as f:
        assert (f.attrs["analysis"], f.attrs["integrator"], f.attrs["dt"]) == ("static", "LoadControl", D_LAMBDA)
        assert f["time"].attrs["units"] == "" and strings(f["runs/time_units"]) == [""]


def test_command_h5_tells_a_static_analyze_from_the_transient_one_after_it(tmp_path, oracle):
    """A script's static analyze (4 steps), loadConst -time 0, then transient analyze (3 steps):
    the -h5 file's times and values are OpenSeesPy's text file's, its /runs splits them 4 + 3; the
    text and envelope files (the recorders reopened when the analysis changed) are OpenSeesPy's."""
    def script(o, d):
        beam(o)
        o.recorder("Node", "-file", str(d / "n.out"), "-time", "-precision", 12, "-node", 3, "-dof", 2, "disp")
        o.recorder("EnvelopeNode", "-file", str(d / "env.out"), "-precision", 12, "-node", 3, "-dof", 2, "disp")
        if o is vops:
            o.recorder("Node", "-h5", str(d / "n.h5"), "-node", 3, "-dof", 2, "disp")
        solver(o)
        o.integrator("LoadControl", D_LAMBDA)
        o.analysis("Static")
        o.analyze(4)
        o.loadConst("-time", 0.0)
        o.wipeAnalysis()
        solver(o)
        o.integrator("Newmark", 0.5, 0.25)
        o.analysis("Transient")
        o.analyze(3, DT)
        o.wipe()

    (tmp_path / "ops").mkdir()
    (tmp_path / "vtsi").mkdir()
    script(oracle, tmp_path / "ops")
    script(vops, tmp_path / "vtsi")
    ref = np.loadtxt(tmp_path / "ops" / "n.out")
    np.testing.assert_allclose(np.loadtxt(tmp_path / "vtsi" / "n.out"), ref, rtol=1e-9)
    np.testing.assert_allclose(np.loadtxt(tmp_path / "vtsi" / "env.out"), np.loadtxt(tmp_path / "ops" / "env.out"),
                               rtol=1e-9)
    with h5py.File(tmp_path / "vtsi" / "n.h5", "r") as f:
        np.testing.assert_allclose(f["time"][...], ref[:, 0], rtol=1e-12)
        np.testing.assert_allclose(f["values"][:, 0], ref[:, 1], rtol=1e-9)
        np.testing.assert_array_equal(f["runs/first_row"][...], [0, 4])
        np.testing.assert_array_equal(f["runs/rows"][...], [4, 3])
        assert strings(f["runs/analysis"]) == ["static", "transient"]
        np.testing.assert_array_equal(f["runs/dt"][...], [D_LAMBDA, DT])
        assert "analysis" not in f.attrs


# -- 7. a recorder that raises ------------------------------------------------------------------
class Failing(Recorder):
    """Node 3's vertical displacement, raising once a chunk reaches ``fail_at`` [s]."""
    name = "failing recorder"

    def __init__(self, fail_at, **kw):
        self.fail_at = fail_at
        super().__init__(**kw)

    def requests(self, assembly):
        return [("u", assembly.full_dof(3, 2))]

    def prepare(self, assembly, model):
        return {"units": ["m"], "columns": {}, "quantity": "displacement"}

    def compute(self, times, columns, assembly):
        if times[-1] >= self.fail_at:
            raise RuntimeError(f"failed at t = {times[-1]:.3f}")
        return columns


def test_a_raising_recorder_leaves_the_others_every_completed_step(tmp_path):
    """Chunks of 4 steps; the middle one of three recorders raises on the third chunk (t = 0.009 to
    0.012): the first and the last hold the 12 steps a run without it records, the raising one the
    8 before; its error propagates with a note naming it. Alone, its error is unchanged."""
    alone = NodeRecorder([3], [2])
    vtsi.TransientAnalysis(model(), "Newmark", 0.001, recorders=[alone], chunk_steps=4).run(12)
    first, failing = NodeRecorder([3], [2], sink=HDF5Sink(tmp_path / "first.h5")), Failing(0.0095)
    last = NodeRecorder([3], [2], sink=TextSink(tmp_path / "last.out", time=True, precision=17))
    analysis = vtsi.TransientAnalysis(model(), "Newmark", 0.001, recorders=[first, failing, last], chunk_steps=4)
    with pytest.raises(RuntimeError) as exc:
        analysis.run(20)
    assert str(exc.value) == "failed at t = 0.012"
    assert exc.value.__notes__ == [f"raised by recorders[1] {failing!r} on the steps of t = 0.009 to 0.012; "
                                   "the other recorders hold these steps"]
    np.testing.assert_array_equal(first.time, alone.time)
    np.testing.assert_array_equal(first.values, alone.values)
    np.testing.assert_array_equal(np.loadtxt(tmp_path / "last.out"), np.column_stack([alone.time, alone.values]))
    np.testing.assert_array_equal(failing.values, alone.values[:8])
    assert failing.last_time == alone.time[7]
    single = Failing(0.0095)
    with pytest.raises(RuntimeError) as exc:
        vtsi.TransientAnalysis(model(), "Newmark", 0.001, recorders=[single], chunk_steps=4).run(20)
    assert str(exc.value) == "failed at t = 0.012" and not getattr(exc.value, "__notes__", None)


# -- 4. -precision 0 ------------------------------------------------------------------------------
def test_precision_zero_writes_what_opensees_writes(tmp_path, oracle):
    """-precision 0 (C's %.0g, as %.1g) in a Node and an EnvelopeNode file: OpenSeesPy's bytes."""
    def script(o, d):
        beam(o)
        o.recorder("Node", "-file", str(d / "p0.out"), "-time", "-precision", 0, "-node", 2, 4, "-dof", 2, 3, "disp")
        o.recorder("EnvelopeNode", "-file", str(d / "e0.out"), "-time", "-precision", 0, "-node", 3, "-dof", 2,
                   "disp")
        solver(o)
        o.integrator("LoadControl", 0.1)
        o.analysis("Static")
        o.analyze(3)
        o.wipe()

    (tmp_path / "ops").mkdir()
    (tmp_path / "vtsi").mkdir()
    script(oracle, tmp_path / "ops")
    script(vops, tmp_path / "vtsi")
    for name in ("p0.out", "e0.out"):
        ref = (tmp_path / "ops" / name).read_bytes()
        assert len(ref.splitlines()) == 3 and (tmp_path / "vtsi" / name).read_bytes() == ref, name
    beam(vops)
    with pytest.raises(CommandError, match=r"^recorder Node: -precision must be an integer >= 0, got -1$"):
        vops.recorder("Node", "-file", str(tmp_path / "n.out"), "-precision", -1, "-node", 3, "-dof", 2, "disp")


# -- 3. options that do nothing --------------------------------------------------------------------
@pytest.mark.parametrize("option, args, reason", [
    ("-precision", ("-precision", 3), r"it sets the digits of a text file \(an HDF5 file stores every value as a "
                                      r"float64\)"),
    ("-closeOnWrite", ("-closeOnWrite",), r"it reopens a text file for every write \(an HDF5 file is flushed after "
                                         r"every chunk of steps\)")])
@pytest.mark.parametrize("kind, where", [("Node", ("-node", 3, "-dof", 2, "disp")),
                                         ("EnvelopeElement", ("-ele", 1, "force"))])
def test_text_options_with_h5_are_refused(tmp_path, option, args, reason, kind, where):
    beam(vops)
    for h5 in ("-h5", "-hdf5"):
        with pytest.raises(CommandError, match=rf"^recorder {kind}: {option} does nothing with {h5}: {reason}$"):
            vops.recorder(kind, h5, str(tmp_path / "r.h5"), *args, *where)
    assert not (tmp_path / "r.h5").exists()


def test_opensees_takes_screen_options_and_ignores_h5(tmp_path, oracle, monkeypatch):
    """Without a file OpenSeesPy takes -time, -precision and -closeOnWrite (for its screen output),
    so vtsi's memory recorder takes them (and holds its float64 values as without them); OpenSeesPy
    skips -h5 and its file name (no file), so no OpenSees script combines -h5 with them."""
    monkeypatch.chdir(tmp_path)
    opts = ("-time", "-precision", 3, "-closeOnWrite")
    beam(oracle)
    assert isinstance(oracle.recorder("Node", *opts, "-node", 3, "-dof", 2, "disp"), int)
    assert isinstance(oracle.recorder("Node", "-h5", "o.h5", "-node", 3, "-dof", 2, "disp"), int)
    solver(oracle)
    oracle.integrator("LoadControl", 0.5)
    oracle.analysis("Static")
    oracle.analyze(2)
    oracle.wipe()
    assert not (tmp_path / "o.h5").exists()
    beam(vops)
    with_opts = vops.recorder("Node", *opts, "-node", 3, "-dof", 2, "disp")
    plain = vops.recorder("Node", "-node", 3, "-dof", 2, "disp")
    solver(vops)
    vops.integrator("LoadControl", 0.5)
    vops.analysis("Static")
    vops.analyze(2)
    rec, ref = vops.session.recorders[with_opts], vops.session.recorders[plain]
    np.testing.assert_array_equal(rec.time, [0.5, 1.0])
    np.testing.assert_array_equal(rec.values, ref.values)


# -- 5. tags as text or floats -----------------------------------------------------------------
def test_opensees_does_not_read_text_or_float_tags_as_tags(tmp_path, oracle, monkeypatch):
    """OpenSeesPy 3.7.1 takes `-node '3'` and `-node 3.0` but records every node (5 columns, not
    node 3's one), `-node 3 4.0` node 3 only, `-dof '2'` and `-ele '2'` nothing; it refuses
    `-nodeRange '3' '4'`. So reading them as tags would not do what OpenSeesPy does."""
    monkeypatch.chdir(tmp_path)
    beam(oracle)
    for name, args in [("s", ("-node", "3", "-dof", 2)), ("f", ("-node", 3.0, "-dof", 2)),
                       ("mix", ("-node", 3, 4.0, "-dof", 2)), ("dof", ("-node", 3, "-dof", "2"))]:
        oracle.recorder("Node", "-file", f"{name}.out", *args, "disp")
    oracle.recorder("Element", "-file", "ele.out", "-ele", "2", "localForce")
    with pytest.raises(oracle.OpenSeesError):
        oracle.recorder("Node", "-file", "r.out", "-nodeRange", "3", "4", "-dof", 2, "disp")
    solver(oracle)
    oracle.integrator("LoadControl", 0.5)
    oracle.analysis("Static")
    oracle.analyze(2)
    oracle.wipe()
    assert np.loadtxt("s.out").shape == np.loadtxt("f.out").shape == (2, 5)
    assert np.loadtxt("mix.out").shape == (2,)
    assert (tmp_path / "dof.out").read_text() == (tmp_path / "ele.out").read_text() == ""


@pytest.mark.parametrize("args, message", [
    (("Node", "-node", "3", "-dof", 2, "disp"), r"-node tag must be an integer, got '3'"),
    (("Node", "-node", 3.0, "-dof", 2, "disp"), r"-node tag must be an integer, got 3\.0"),
    (("Node", "-node", 3.5, "-dof", 2, "disp"), r"-node tag must be an integer, got 3\.5"),
    (("Node", "-node", 3, 4.0, "-dof", 2, "disp"), r"-node tag must be an integer, got 4\.0"),
    (("Node", "-node", 3, "-dof", "2", "disp"), r"-dof must be an integer, got '2'"),
    (("Node", "-node", 3, "-dof", 2.0, "disp"), r"-dof must be an integer, got 2\.0"),
    (("Node", "-nodeRange", "3", "4", "-dof", 2, "disp"), r"-nodeRange start must be an integer, got '3'"),
    (("Element", "-ele", "2", "force"), r"-ele tag must be an integer, got '2'"),
    (("Element", "-ele", 2.0, "force"), r"-ele tag must be an integer, got 2\.0"),
    (("Element", "-eleRange", 2, 3.0, "force"), r"-eleRange end must be an integer, got 3\.0")])
def test_text_and_float_tags_are_refused(args, message):
    beam(vops)
    with pytest.raises(CommandError, match=rf"^recorder {args[0]}: {message}$"):
        vops.recorder(*args)


# -- 6. -file without its name -----------------------------------------------------------------
@pytest.mark.parametrize("args, message", [
    (("Node", "-file", "-node", 2, "-dof", 2, "disp"), r"-file needs a file name, got none \('-node' follows\)"),
    (("Node", "-h5", "-dof", 2, "-node", 2, "disp"), r"-h5 needs a file name, got none \('-dof' follows\)"),
    (("Node", "-hdf5", "-precision", 3, "-node", 2, "-dof", 2, "disp"),
     r"-hdf5 needs a file name, got none \('-precision' follows\)"),
    (("Element", "-file", "-ele", 1, "force"), r"-file needs a file name, got none \('-ele' follows\)"),
    (("Node", "-file", 3, "-node", 2, "-dof", 2, "disp"), r"-file needs a file name, got 3"),
    (("Node", "-node", 2, "-dof", 2, "-file"), r"-file needs a file name, got none")])
def test_a_missing_file_name_is_named(tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    beam(vops)
    with pytest.raises(CommandError, match=rf"^recorder {args[0]}: {message}$"):
        vops.recorder(*args)
    assert list(tmp_path.iterdir()) == []


def test_a_missing_file_name_in_tcl_and_a_flag_taken_as_the_name(tmp_path, oracle, monkeypatch):
    """Tcl `recorder Node -file -node 2 -dof 2 disp` says the name is missing; `-file -time` writes
    the file '-time' without times, as OpenSeesPy does (byte for byte): midspan's P L³/(48 E I)
    at λ = 0.5 and 1."""
    monkeypatch.chdir(tmp_path)
    beam(vops)
    with pytest.raises(CommandError) as exc:
        Interpreter(vops.session).eval("recorder Node -file -node 2 -dof 2 disp")
    assert str(exc.value) == "recorder Node: -file needs a file name, got none ('-node' follows)"
    for o, d in ((oracle, "ops"), (vops, "vtsi")):
        (tmp_path / d).mkdir()
        monkeypatch.chdir(tmp_path / d)
        beam(o)
        o.recorder("Node", "-file", "-time", "-node", 3, "-dof", 2, "disp")
        solver(o)
        o.integrator("LoadControl", 0.5)
        o.analysis("Static")
        o.analyze(2)
        o.wipe()
    ref = (tmp_path / "ops" / "-time").read_bytes()
    assert len(ref.split()) == 2 and (tmp_path / "vtsi" / "-time").read_bytes() == ref
    static = 1e6 * 20.0 ** 3 / (48 * 3.5e10 * 2.5)          # P L³ / (48 E I) at λ = 1, midspan
    np.testing.assert_allclose([float(x) for x in ref.split()], [-0.5 * static, -static], rtol=1e-5)
