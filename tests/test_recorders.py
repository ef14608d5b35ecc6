"""Recorders: responses (node, reaction, element), sinks (memory, HDF5, text), envelopes.

Cross-code checks run OpenSeesPy (skipped when it is not installed) on the same small beams
and compare the text files byte for byte where the numbers are not round-off noise.
"""
import re
import subprocess
import sys

import h5py
import numpy as np
import pytest

import vtsi
from vtsi.errors import DivergenceError, ModelError
from vtsi.recorders import (ElementRecorder, Envelope, HDF5Sink, MemorySink, NodeRecorder, ReactionRecorder,
                            TextSink)
from vtsi.recorders import number_text
from vtsi.recorders.sinks import format_envelope, format_rows

DT = 0.01
PATH = [0.0, 1.0, 1.0, 0.5, -0.3, 0.2, 1.0, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
E, A, I, RHO = 3e10, 0.5, 0.04, 1000.0


def beam(n_el=4, length=10.0, cmass=1, rayleigh=(0.0, 0.0), series="path", load=-1e5, support_load=0.0):
    """Simply supported beam on nodes 1..n_el+1 (pin at 1, roller at the end), vertical load at
    the middle node (and optionally on the pinned support)."""
    m = vtsi.Model()
    for i in range(n_el + 1):
        m.node(i + 1, i * length / n_el, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(n_el + 1, 0, 1, 0)
    for e in range(1, n_el + 1):
        m.element("elasticBeamColumn", e, (e, e + 1), A=A, E=E, I=I, rho=RHO, cmass=cmass)
    if any(rayleigh):
        m.rayleigh(rayleigh[0], 0.0, 0.0, rayleigh[1])
    if series == "path":
        m.add_time_series(vtsi.Path(PATH, dt=DT, tag=1))
    elif series == "long":
        m.add_time_series(vtsi.Path(np.sin(np.arange(400) * 0.07) + 0.3, dt=DT, tag=1))
    else:
        m.add_time_series(vtsi.Constant(tag=1))
    p = m.pattern(1, 1)
    p.load(n_el // 2 + 1, 0.0, load, 0.0)
    if support_load:
        p.load(1, 0.0, support_load, 0.0)
    return m


def transient(model, recorders, n=12, chunk_steps=2000, **kw):
    return vtsi.TransientAnalysis(model, "Newmark", DT, recorders=recorders, chunk_steps=chunk_steps, **kw).run(n)


# -- memory, HDF5 and text hold the same numbers -----------------------------------------------
def test_memory_hdf5_text_hold_the_same_numbers(tmp_path):
    h5, txt = tmp_path / "disp.h5", tmp_path / "disp.out"
    recs = [NodeRecorder([2, 3], [1, 2, 3]),
            NodeRecorder([2, 3], [1, 2, 3], sink=HDF5Sink(h5)),
            NodeRecorder([2, 3], [1, 2, 3], sink=TextSink(txt, time=True, precision=17))]
    transient(beam(series="long"), recs, n=150, chunk_steps=40)
    mem = recs[0]
    assert mem.values.shape == (150, 6) and mem.time.shape == (150,)
    np.testing.assert_allclose(mem.time, DT * np.arange(1, 151), rtol=1e-12)
    with h5py.File(h5, "r") as f:
        np.testing.assert_array_equal(f["time"][...], mem.time)
        np.testing.assert_array_equal(f["values"][...], mem.values)
    np.testing.assert_array_equal(recs[1].values, mem.values)     # read back through the sink
    text = np.loadtxt(txt)
    np.testing.assert_array_equal(text[:, 0], mem.time)          # %.17g round-trips exactly
    np.testing.assert_array_equal(text[:, 1:], mem.values)


def test_node_recorder_columns_are_node_major_and_fixed_dofs_read_zero():
    rec = NodeRecorder([1, 3], [2, 3])
    state = transient(beam(), [rec])
    np.testing.assert_array_equal(rec.values[:, 0], 0.0)          # node 1 uy is fixed
    asm = beam().build()
    np.testing.assert_array_equal(rec.values[-1], [state.u[asm.full_dof(n, d)] for n in (1, 3) for d in (2, 3)])


def test_velocity_and_acceleration_match_the_state():
    model = beam()
    vel, acc = NodeRecorder([3], [2], "vel"), NodeRecorder([3], [2], "accel")
    state = transient(model, [vel, acc])
    j = model.build().full_dof(3, 2)
    assert vel.values[-1, 0] == state.v[j] and acc.values[-1, 0] == state.a[j]
    assert vel.sink.layout["units"] == ["m/s"] and acc.sink.layout["units"] == ["m/s^2"]


# -- chunks and decimation ----------------------------------------------------------------------
def _all_kinds(dt=None):
    return [NodeRecorder([2, 3], [1, 2, 3], dt=dt, envelope=True),
            ElementRecorder([1, 3, 2], "force", dt=dt, envelope=True),
            ElementRecorder([4], "localForce", dt=dt),
            ReactionRecorder([1, 5], [1, 2], dt=dt),
            ReactionRecorder([1, 5], [2], include_inertia=True, dt=dt)]


@pytest.mark.parametrize("dt", [None, 0.025])
def test_chunk_boundaries_change_nothing(dt):
    small, large = _all_kinds(dt), _all_kinds(dt)
    transient(beam(series="long", rayleigh=(0.3, 1e-4)), small, n=200, chunk_steps=7)
    transient(beam(series="long", rayleigh=(0.3, 1e-4)), large, n=200, chunk_steps=1000)
    for a, b in zip(small, large):
        np.testing.assert_allclose(a.time, b.time, rtol=1e-12)
        scale = np.abs(b.values).max()
        np.testing.assert_allclose(a.values, b.values, rtol=1e-9, atol=1e-12 * scale)
        if a.envelope is not None:
            for name in ("min", "max", "absmax"):
                np.testing.assert_allclose(getattr(a.envelope, name), getattr(b.envelope, name),
                                           rtol=1e-9, atol=1e-12 * scale)
                signal = np.abs(getattr(b.envelope, name)) > 1e-6 * scale   # not round-off noise
                np.testing.assert_allclose(getattr(a.envelope, "time_of_" + name)[signal],
                                           getattr(b.envelope, "time_of_" + name)[signal], rtol=1e-12)


def test_dT_decimation_follows_opensees_rule():
    every, dec = NodeRecorder([3], [2]), NodeRecorder([3], [2], dt=0.025)
    transient(beam(), [every, dec], n=12, chunk_steps=5)
    # OpenSees (measured, docs/opensees_conventions.md g): dT 0.025, dt 0.01 -> 0.01 0.04 0.07 0.10
    np.testing.assert_allclose(dec.time, [0.01, 0.04, 0.07, 0.10], rtol=1e-12)
    np.testing.assert_array_equal(dec.values[:, 0], every.values[[0, 3, 6, 9], 0])


def test_dT_state_persists_across_runs_and_records_continue():
    once, split = NodeRecorder([3], [2], dt=0.025), NodeRecorder([3], [2], dt=0.025)
    transient(beam(), [once], n=12)
    model = beam()
    analysis = vtsi.TransientAnalysis(model, "Newmark", DT, recorders=[split])
    for _ in range(12):
        analysis.run(1)         # OpenSees's analyze(1) in a loop
    np.testing.assert_allclose(split.time, once.time, rtol=1e-12)
    np.testing.assert_allclose(split.values, once.values, rtol=1e-12)


# -- element forces ------------------------------------------------------------------------------
def _beam_stiffness(L):
    """2-D Euler-Bernoulli beam stiffness in local axes (Przemieniecki 1968, eq. 5.50)."""
    ea, ei = E * A / L, E * I
    k = np.zeros((6, 6))
    k[np.ix_([0, 3], [0, 3])] = ea * np.array([[1, -1], [-1, 1]])
    b = ei / L ** 3 * np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L * L, -6 * L, 2 * L * L],
                                [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L * L, -6 * L, 4 * L * L]])
    k[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = b
    return k


def test_element_force_equals_K_u_by_hand():
    model = beam()
    disp = NodeRecorder([2, 3], [1, 2, 3])
    force = ElementRecorder([2], "force")
    transient(model, [disp, force], n=12, chunk_steps=5)
    k = _beam_stiffness(2.5)
    step = 7
    expected = k @ disp.values[step]        # element 2 joins nodes 2 and 3, horizontal
    np.testing.assert_allclose(force.values[step], expected, rtol=1e-10, atol=1e-9 * np.abs(expected).max())
    assert list(force.sink.layout["columns"]["component_name"]) == ["Px_1", "Py_1", "Mz_1", "Px_2", "Py_2", "Mz_2"]
    assert force.sink.layout["units"] == ["N", "N", "N m", "N", "N", "N m"]


def test_local_force_of_an_inclined_element_is_the_rotated_global_force():
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 3.0, 4.0)
    m.fix(1, 1, 1, 1)
    m.element("elasticBeamColumn", 7, (1, 2), A=A, E=E, I=I, rho=RHO)
    m.add_time_series(vtsi.Constant(tag=1))
    m.pattern(1, 1).load(2, 1e4, -2e4, 3e3)
    glob, loc = ElementRecorder([7], "globalForce"), ElementRecorder([7], "localForce")
    vtsi.StaticAnalysis(m, recorders=[glob, loc]).run(1)
    c, s = 0.6, 0.8
    g = glob.values[0]
    rot = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    np.testing.assert_allclose(loc.values[0], np.concatenate([rot @ g[:3], rot @ g[3:]]), rtol=1e-12, atol=1e-6)
    np.testing.assert_allclose(g[3:], [1e4, -2e4, 3e3], rtol=1e-9)   # node 2 carries the load


def test_element_columns_are_element_major_in_the_given_order():
    model = beam()
    both, one = ElementRecorder([3, 1], "force"), ElementRecorder([1], "force")
    transient(model, [both, one])
    np.testing.assert_array_equal(both.values[:, 6:], one.values)
    assert list(both.sink.layout["columns"]["element"]) == [3] * 6 + [1] * 6


# -- reactions -----------------------------------------------------------------------------------
def test_static_reactions_balance_the_applied_load():
    model = beam(series="constant", load=-7e4, support_load=-1e4)
    rec = ReactionRecorder([1, 5], [1, 2, 3])
    vtsi.StaticAnalysis(model, recorders=[rec]).run(2)
    r = rec.values
    assert r.shape == (2, 6)
    np.testing.assert_allclose(r[:, 1] + r[:, 4], 8e4, rtol=1e-10)          # = -(applied vertical)
    np.testing.assert_allclose(r[:, 4], 3.5e4, rtol=1e-10)                  # symmetric span
    np.testing.assert_allclose(r[:, 1], 3.5e4 + 1e4, rtol=1e-10)            # the support's own load
    np.testing.assert_allclose(r[:, [2, 5]], 0.0, atol=1e-6)                # free rotations: equilibrium


def test_reaction_with_inertia_is_K_u_plus_C_v_plus_M_a_minus_P():
    model = beam(rayleigh=(0.5, 2e-4), support_load=-2e4)
    nodes = list(model.nodes)
    u, v, a = (NodeRecorder(nodes, [1, 2, 3], q) for q in ("disp", "vel", "accel"))
    stat, dyn = ReactionRecorder([1, 5], [1, 2]), ReactionRecorder([1, 5], [1, 2], include_inertia=True)
    free = ReactionRecorder([3], [2], include_inertia=True)       # a free dof: dynamic equilibrium
    transient(model, [u, v, a, stat, dyn, free], n=12)
    asm = model.build()
    rows = [asm.full_dof(n, d) for n in (1, 5) for d in (1, 2)]
    order = [asm.full_dof(n, d) for n in nodes for d in (1, 2, 3)]
    U, V, Acc = (np.zeros((12, asm.n_full)) for _ in range(3))
    U[:, order], V[:, order], Acc[:, order] = u.values, v.values, a.values
    factors = np.interp(u.time, DT * np.arange(len(PATH)), PATH)
    P = np.zeros((12, 4))
    P[:, 1] = -2e4 * factors
    k_part = (asm.K_full[rows] @ U.T).T
    np.testing.assert_allclose(stat.values, k_part - P, rtol=1e-9, atol=1e-6)
    expected = k_part + (asm.C_full[rows] @ V.T).T + (asm.M_full[rows] @ Acc.T).T - P
    np.testing.assert_allclose(dyn.values, expected, rtol=1e-9, atol=1e-6)
    assert np.abs(free.values).max() < 1e-7 * np.abs(dyn.values).max()


# -- envelopes -----------------------------------------------------------------------------------
def test_envelope_equals_the_extremes_of_the_history(tmp_path):
    rec = NodeRecorder([2, 3, 4], [2, 3], envelope=True, sink=HDF5Sink(tmp_path / "env.h5"))
    transient(beam(series="long"), [rec], n=300, chunk_steps=64)
    values, time, env = rec.values, rec.time, rec.envelope
    np.testing.assert_array_equal(env.max, values.max(axis=0))
    np.testing.assert_array_equal(env.min, values.min(axis=0))
    np.testing.assert_array_equal(env.absmax, np.abs(values).max(axis=0))
    np.testing.assert_array_equal(env.time_of_max, time[values.argmax(axis=0)])
    np.testing.assert_array_equal(env.time_of_min, time[values.argmin(axis=0)])
    np.testing.assert_array_equal(env.time_of_absmax, time[np.abs(values).argmax(axis=0)])
    assert env.n_records == 300
    with h5py.File(tmp_path / "env.h5", "r") as f:
        for name in Envelope.FIELDS:
            np.testing.assert_array_equal(f["envelope"][name][...], getattr(env, name))
        assert f["envelope"].attrs["n_records"] == 300


def test_envelope_only_recorder_keeps_no_history_and_ties_keep_the_first_time():
    env = Envelope(2)
    env.update(np.array([1.0, 2.0]), np.array([[1.0, -3.0], [1.0, 3.0]]))
    env.update(np.array([3.0]), np.array([[-1.0, 3.0]]))
    np.testing.assert_array_equal(env.max, [1.0, 3.0])
    np.testing.assert_array_equal(env.time_of_max, [1.0, 2.0])
    np.testing.assert_array_equal(env.time_of_absmax, [1.0, 1.0])
    np.testing.assert_array_equal(env.time_of_min, [3.0, 1.0])
    rec = NodeRecorder([3], [2], envelope=True, history=False)
    transient(beam(), [rec])
    assert rec.values.shape == (0, 1) and rec.envelope.n_records == 12


# -- HDF5 ----------------------------------------------------------------------------------------
def test_hdf5_metadata_units_and_dimension_scales(tmp_path):
    path = tmp_path / "meta.h5"
    rec = NodeRecorder([2, 3], [2, 3], sink=HDF5Sink(path))
    forces = ElementRecorder([1, 2], "force", sink=HDF5Sink(tmp_path / "forces.h5"))
    transient(beam(), [rec, forces], n=12, chunk_steps=5)
    with h5py.File(path, "r") as f:
        attrs = dict(f.attrs)
        assert attrs["recorder"] == "NodeRecorder" and attrs["response"] == "disp"
        assert attrs["quantity"] == "displacement" and attrs["vtsi_version"] == vtsi.__version__
        assert attrs["n_nodes"] == 5 and attrs["n_elements"] == 4 and attrs["ndf"] == 3
        assert "created" in attrs and attrs["record_dt"] == 0.0
        values, time = f["values"], f["time"]
        assert values.maxshape == (None, 4) and time.maxshape == (None,) and values.chunks is not None
        assert time.is_scale and time.attrs["units"] == "s"
        assert values.dims[0].label == "time" and values.dims[0][0] == time
        assert list(values.attrs["units"]) == ["m", "rad", "m", "rad"]
        np.testing.assert_array_equal(f["columns/node"][...], [2, 2, 3, 3])
        np.testing.assert_array_equal(f["columns/dof"][...], [2, 3, 2, 3])
        assert [s.decode() for s in f["columns/dof_name"][...]] == ["uy", "rz", "uy", "rz"]
        assert values.dims[1]["node"] == f["columns/node"]
    with h5py.File(tmp_path / "forces.h5", "r") as f:
        assert list(f["values"].attrs["units"]) == ["N", "N", "N m"] * 4
        np.testing.assert_array_equal(f["columns/element"][...], [1] * 6 + [2] * 6)
        assert f.attrs["quantity"].startswith("element resisting force")


def test_hdf5_stores_the_analysis_description_given_to_start(tmp_path):
    """The contract's optional ``info`` (integrator, dt) ends up in the root attributes."""
    model = beam()
    asm = model.build()
    rec = NodeRecorder([3], [2], sink=HDF5Sink(tmp_path / "info.h5"))
    feed_columns = rec.requests(asm)
    rec.start(asm, model, {"analysis": "transient", "integrator": "Newmark", "dt": DT})
    rec.write(np.array([DT, 2 * DT]), np.array([[1.0], [2.0]]), asm)
    rec.close()
    assert len(feed_columns) == 1
    with h5py.File(tmp_path / "info.h5", "r") as f:
        assert f.attrs["integrator"] == "Newmark" and f.attrs["dt"] == DT and f.attrs["analysis"] == "transient"
        np.testing.assert_array_equal(f["values"][:, 0], [1.0, 2.0])


def test_hdf5_refuses_an_existing_file_before_any_work(tmp_path):
    path = tmp_path / "exists.h5"
    path.write_bytes(b"precious")
    with pytest.raises(FileExistsError, match=str(path)):
        HDF5Sink(path)
    assert path.read_bytes() == b"precious"
    rec = NodeRecorder([3], [2], sink=HDF5Sink(path, overwrite=True))
    transient(beam(), [rec])
    with h5py.File(path, "r") as f:
        assert f["values"].shape == (12, 1)


def test_hdf5_failed_run_keeps_every_completed_step(tmp_path):
    path = tmp_path / "failed.h5"
    rec = NodeRecorder([3], [2], sink=HDF5Sink(path))
    with pytest.raises(DivergenceError) as info:
        transient(beam(), [rec], n=12, chunk_steps=3, divergence_limit=2.5e-3)
    done = info.value.step - 1
    with h5py.File(path, "r") as f:                     # closed by the analysis, readable
        assert f["values"].shape == (done, 1)
        assert np.abs(f["values"][...]).max() <= 2.5e-3


def test_hdf5_several_runs_append_to_one_record(tmp_path):
    path = tmp_path / "runs.h5"
    rec, ref = NodeRecorder([3], [2], sink=HDF5Sink(path, flush_every=4)), NodeRecorder([3], [2])
    model = beam()
    analysis = vtsi.TransientAnalysis(model, "Newmark", DT, recorders=[rec, ref])
    analysis.run(5)
    analysis.run(7)
    with h5py.File(path, "r") as f:
        np.testing.assert_array_equal(f["values"][...], ref.values)
        np.testing.assert_array_equal(f["time"][...], ref.time)


KILL_SCRIPT = r"""
import importlib.util, os, sys
spec = importlib.util.spec_from_file_location("recorder_tests", sys.argv[1])
mod = importlib.util.module_from_spec(spec); spec.loader.exec_module(mod)
from vtsi.recorders import HDF5Sink, NodeRecorder

class KillAfter:
    '''Duck-typed recorder (the contract): SIGKILLs the process after its 3rd chunk.'''
    def requests(self, assembly): return []
    def start(self, assembly, model, info=None): self.chunks = 0
    def write(self, times, columns, assembly):
        self.chunks += 1
        if self.chunks == 3:
            os.kill(os.getpid(), 9)
    def close(self): pass

rec = NodeRecorder([2, 3], [2, 3], sink=HDF5Sink(sys.argv[2]))
mod.transient(mod.beam(series="long"), [rec, KillAfter()], n=100, chunk_steps=7)
"""


def test_hdf5_file_survives_sigkill(tmp_path):
    path = tmp_path / "killed.h5"
    proc = subprocess.run([sys.executable, "-c", KILL_SCRIPT, __file__, str(path)], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == -9, proc.stderr
    ref = NodeRecorder([2, 3], [2, 3])
    transient(beam(series="long"), [ref], n=21)
    with h5py.File(path, "r") as f:
        assert f["time"].shape == (21,)
        np.testing.assert_array_equal(f["values"][...], ref.values)
        np.testing.assert_allclose(f["time"][...], ref.time, rtol=1e-12)
        assert f["runs/rows"][...].tolist() == [21]        # written before every flush


# -- text ----------------------------------------------------------------------------------------
def test_format_is_c_printf_g():
    assert format_rows(np.array([0.01]), np.array([[-0.0005195314986, 0.0, -0.0, 123456789.0, 1e-7]])) == \
        "0.01 -0.000519531 0 -0 1.23457e+08 1e-07\n"
    assert format_rows(None, np.array([[np.pi]]), precision=10) == "3.141592654\n"


def _python_g(values, precision):
    """Python's ``'%.{p}g'`` row by row: the reference of :func:`format_rows`."""
    line = " ".join([f"%.{precision}g"] * values.shape[1]) + "\n"
    return "".join(line % tuple(row) for row in values.tolist())


def _python_formatted(values, precision):
    """How many of ``values`` the compiled %g leaves to Python (vtsi.recorders.number_text)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    out = np.empty(values.size * (number_text.SLOT + 1), dtype=np.uint8)
    gaps = np.empty((values.size, 3), dtype=np.int64)
    return number_text._format_rows(np.zeros(0), values, precision, number_text.POW_HI, number_text.POW_LO, out,
                                    gaps)[1]


def test_compiled_format_is_pythons_for_every_kind_of_double():
    """The compiled ``%.{p}g`` (precisions 1..17) writes what Python writes: random bit patterns
    (every exponent, subnormals, nan payloads), log-uniform values, powers of ten and their
    neighbours, exact ties (x.5, dyadic fractions, 17-digit integers), the fixed/exponent switch
    at 1e-4 and 10**p, signed zeros, inf and nan; precisions 0 and 20 (Python's path)."""
    rng = np.random.default_rng(11)
    n = 3000
    bits = rng.integers(0, 2 ** 64, n, dtype=np.uint64).view(np.float64)
    log_uniform = rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-30, 30, n)
    powers = np.array([float(f"1e{k}") for k in range(-310, 309)])
    powers = np.concatenate([powers, np.nextafter(powers, 0.0), np.nextafter(powers, np.inf)])
    ties = np.concatenate([(np.arange(-300, 300) + 0.5) * 10.0 ** rng.integers(-5, 5, 600),
                           np.arange(1, 64) / 64.0, rng.integers(-10 ** 17, 10 ** 17, 600).astype(float),
                           [1234567890123456.5, 0.125, 0.375, 9.5, 99999.5]])
    edges = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, -np.nan, 5e-324, -2.2250738585072014e-308,
                      1.7976931348623157e308, 1e-4, 9.9999999999999995e-5, 0.00010000000000000002, 1e16,
                      9999999999999998.0, 1e17, 99999999999999984.0, 0.30000000000000004, 0.1, 1.0 / 3.0])
    in_range = bits[(np.abs(bits) > 1e-250) & (np.abs(bits) < 1e250)]      # all on the compiled path
    assert _python_formatted(in_range.reshape(-1, 1), 17) == 0
    for values in (bits, in_range, log_uniform, powers, ties, edges):
        block = values.reshape(-1, 1)
        for precision in list(range(0, 18)) + [20]:
            assert format_rows(None, block, precision) == _python_g(block, precision), precision
    typical = np.column_stack([np.cumsum(np.full(500, 1e-3)), rng.normal(0.0, 1e-3, 500)])
    assert _python_formatted(typical, 16) == 0                          # formatted by the compiled path
    assert _python_formatted(np.array([[2.5]]), 1) == 1                 # a tie (2 or 3): Python formats
    assert format_rows(typical[:, 0], typical[:, 1:], 16) == _python_g(typical, 16)


def test_text_file_is_truncated_when_built_and_appended_across_runs(tmp_path):
    path = tmp_path / "node.out"
    path.write_text("old content\n")
    sink = TextSink(path, time=True, close_on_write=True)
    assert path.read_text() == ""
    model = beam()
    analysis = vtsi.TransientAnalysis(model, "Newmark", DT, recorders=[NodeRecorder([3], [2], sink=sink)])
    analysis.run(3)
    analysis.run(2)
    assert len(path.read_text().splitlines()) == 5


def test_text_lines_end_as_the_platform_s(tmp_path, monkeypatch):
    """OpenSees's text streams end lines with the platform's line end (CRLF on Windows): a text
    recorder does too (it wrote LF everywhere); numpy reads either."""
    import vtsi.recorders.sinks as sinks
    monkeypatch.setattr(sinks, "LINE_END", b"\r\n")               # as on Windows
    path = tmp_path / "node.out"
    vtsi.TransientAnalysis(beam(), "Newmark", DT, recorders=[NodeRecorder([3], [2], sink=TextSink(path))]).run(3)
    raw = path.read_bytes()
    assert raw.count(b"\r\n") == 3 and raw.count(b"\n") == 3 and np.loadtxt(path).shape == (3,)


def test_text_envelope_format():
    env = Envelope(2)
    env.update(np.array([0.1, 0.2]), np.array([[1.0, -4.0], [-2.0, 3.0]]))
    assert format_envelope(env) == "-2 -4\n1 3\n2 4\n"
    assert format_envelope(env, echo_time=True) == "0.2 -2 0.1 -4\n0.1 1 0.2 3\n0.2 2 0.1 4\n"
    assert format_envelope(Envelope(2)) == ""


def test_recorder_errors_name_the_fault(tmp_path):
    with pytest.raises(ModelError, match="unknown response 'displacement'"):
        NodeRecorder([1], [2], "displacement")
    with pytest.raises(ModelError, match="not both"):
        NodeRecorder([1], [2], envelope=True, sink=TextSink(tmp_path / "x.out"))
    with pytest.raises(ModelError, match="dt must be >= 0"):
        NodeRecorder([1], [2], dt=-1.0)
    with pytest.raises(ModelError, match="1-based"):
        NodeRecorder([1], [0])
    with pytest.raises(ModelError, match="node 99 does not exist"):
        transient(beam(), [NodeRecorder([99], [2])])
    with pytest.raises(ModelError, match="element 42 does not exist"):
        transient(beam(), [ElementRecorder([42])])
    with pytest.raises(ModelError, match=r"element 1 \(elasticBeamColumn\) has no response 'basicForce'"):
        transient(beam(), [ElementRecorder([1], "basicForce")])
    with pytest.raises(FileNotFoundError, match="nowhere"):
        HDF5Sink(tmp_path / "nowhere" / "x.h5")


# -- against OpenSeesPy --------------------------------------------------------------------------
def _opensees_beam(ops, cmass=False):
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(5):
        ops.node(i + 1, i * 2.5, 0.0)
    ops.fix(1, 1, 1, 0)
    ops.fix(5, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    for e in range(1, 5):
        ops.element("elasticBeamColumn", e, e, e + 1, A, E, I, 1, "-mass", RHO, *(["-cMass"] if cmass else []))
    ops.timeSeries("Path", 1, "-dt", DT, "-values", *PATH)
    ops.pattern("Plain", 1, 1)
    ops.load(3, 0.0, -1e5, 0.0)


def _opensees_run(ops, n=12):
    ops.system("BandGeneral")
    ops.numberer("Plain")
    ops.constraints("Plain")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.algorithm("Linear")
    ops.analysis("Transient")
    ops.analyze(n, DT)
    ops.wipe()                 # closes the files; envelopes are written now


def test_text_output_matches_openseespy(tmp_path):
    ops = pytest.importorskip("openseespy.opensees")
    ref, out = tmp_path / "ref", tmp_path / "vtsi"
    ref.mkdir()
    out.mkdir()
    _opensees_beam(ops, cmass=False)
    ops.recorder("Node", "-file", str(ref / "disp.out"), "-time", "-node", 3, "-dof", 2, "disp")
    ops.recorder("Node", "-file", str(ref / "vel.out"), "-time", "-precision", 10, "-node", 3, "-dof", 2, "vel")
    ops.recorder("Node", "-file", str(ref / "dT.out"), "-time", "-dT", 0.025, "-node", 3, "-dof", 2, "accel")
    ops.recorder("Node", "-file", str(ref / "react.out"), "-time", "-node", 1, 5, "-dof", 1, 2, "reaction")
    ops.recorder("EnvelopeNode", "-file", str(ref / "env.out"), "-node", 3, "-dof", 2, "disp")
    ops.recorder("EnvelopeNode", "-file", str(ref / "envt.out"), "-time", "-node", 2, 3, "-dof", 2, "disp")
    ops.recorder("Element", "-file", str(ref / "force.out"), "-time", "-ele", 1, 2, "force")
    ops.recorder("EnvelopeElement", "-file", str(ref / "envf.out"), "-time", "-ele", 2, "localForce")
    _opensees_run(ops)
    recs = [NodeRecorder([3], [2], sink=TextSink(out / "disp.out", time=True)),
            NodeRecorder([3], [2], "vel", sink=TextSink(out / "vel.out", time=True, precision=10)),
            NodeRecorder([3], [2], "accel", dt=0.025, sink=TextSink(out / "dT.out", time=True)),
            ReactionRecorder([1, 5], [1, 2], sink=TextSink(out / "react.out", time=True)),
            NodeRecorder([3], [2], envelope=True, history=False, sink=TextSink(out / "env.out")),
            NodeRecorder([2, 3], [2], envelope=True, history=False, sink=TextSink(out / "envt.out", time=True)),
            ElementRecorder([1, 2], "force", sink=TextSink(out / "force.out", time=True)),
            ElementRecorder([2], "localForce", envelope=True, history=False,
                            sink=TextSink(out / "envf.out", time=True))]
    transient(beam(cmass=0), recs, n=12, chunk_steps=5)
    for name in ("disp.out", "vel.out", "dT.out", "react.out", "env.out", "envt.out"):
        assert (out / name).read_text() == (ref / name).read_text(), name       # byte for byte
    for name in ("force.out", "envf.out"):   # moments at the pin are round-off noise: numbers
        a, b = np.loadtxt(ref / name), np.loadtxt(out / name)
        assert a.shape == b.shape and (ref / name).read_text().count(" ") == (out / name).read_text().count(" ")
        np.testing.assert_allclose(b, a, rtol=1e-5, atol=1e-9 * np.abs(a).max())


def test_reactions_match_openseespy_with_inertia_and_rayleigh(tmp_path):
    ops = pytest.importorskip("openseespy.opensees")
    _opensees_beam(ops, cmass=True)
    ops.rayleigh(0.5, 0.0, 0.0, 2e-4)
    for flag in ("reaction", "reactionIncInertia"):
        ops.recorder("Node", "-file", str(tmp_path / f"{flag}.out"), "-precision", 15, "-node", 1, 5,
                     "-dof", 1, 2, flag)
    _opensees_run(ops)
    stat, dyn = ReactionRecorder([1, 5], [1, 2]), ReactionRecorder([1, 5], [1, 2], include_inertia=True)
    transient(beam(cmass=1, rayleigh=(0.5, 2e-4)), [stat, dyn])
    for rec, flag in ((stat, "reaction"), (dyn, "reactionIncInertia")):
        ref = np.loadtxt(tmp_path / f"{flag}.out")
        np.testing.assert_allclose(rec.values, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    assert np.abs(dyn.values - stat.values).max() > 1e-3 * np.abs(stat.values).max()   # inertia matters


def test_a_sink_serves_one_recorder():
    sink = MemorySink()
    NodeRecorder([1], [2], sink=sink)
    with pytest.raises(ModelError, match="already belongs to NodeRecorder"):
        NodeRecorder([2], [2], sink=sink)


def test_reading_a_memory_recorder_before_its_run_changes_nothing():
    """Reading .values before run() kept a (0, 0) chunk; every read after the run then raised a
    bare numpy ValueError."""
    rec, ref = NodeRecorder([3], [1, 2]), NodeRecorder([3], [1, 2])
    assert rec.values.shape == (0, 0) and rec.time.shape == (0,)
    analysis = vtsi.TransientAnalysis(beam(), "Newmark", DT, recorders=[rec, ref], chunk_steps=4)
    analysis.run(6)
    assert rec.values.shape == (6, 2)                        # read between runs: kept as one array
    analysis.run(6)
    np.testing.assert_array_equal(rec.values, ref.values)
    np.testing.assert_array_equal(rec.time, ref.time)
    assert rec.values.shape == (12, 2) and rec.time.shape == (12,)


@pytest.mark.parametrize("sink", [lambda p: TextSink(p / "same.out"), lambda p: HDF5Sink(p / "same.h5")],
                         ids=["text", "hdf5"])
def test_two_recorders_on_one_file_are_refused_when_the_analysis_is_built(tmp_path, sink):
    """Two text recorders on one path interleaved rows of different widths without a word; two
    HDF5 recorders failed at the analysis start naming no recorder."""
    first, second = NodeRecorder([3], [2], sink=sink(tmp_path)), ElementRecorder([1], "force", sink=sink(tmp_path))
    path = first.sink.path
    with pytest.raises(ModelError, match=re.escape(f"transient analysis: recorders[0] {first!r} and recorders[1] "
                                                   f"{second!r} both write {path}; give each recorder its own file")):
        vtsi.TransientAnalysis(beam(), "Newmark", DT, recorders=[first, second])
    with pytest.raises(ModelError, match=r"^static analysis: recorders\[0\] .* both write"):
        vtsi.StaticAnalysis(beam(series="constant"), recorders=[first, NodeRecorder([2], [2]), second])


READ_LIVE = r"""
import errno, sys, h5py
try:
    h5py.File(sys.argv[1], "r").close()
    print("opened")
except OSError as exc:
    print("locked", exc.errno == errno.EAGAIN)
with h5py.File(sys.argv[1], "r", locking=False) as f:
    print(f["values"].shape[0])
"""


class _ReadWhileRunning:
    """A recorder that, at the chunk ``when``, has another process read ``path`` (the run waits)."""

    def __init__(self, path, when):
        self.path, self.when, self.seen, self.chunk = path, when, None, 0

    def requests(self, assembly):
        return []

    def start(self, assembly, model, info=None):
        pass

    def write(self, times, columns, assembly):
        self.chunk += 1
        if self.chunk == self.when:
            self.seen = subprocess.run([sys.executable, "-c", READ_LIVE, str(self.path)], capture_output=True,
                                       text=True, timeout=60).stdout.split()

    def close(self):
        pass


def test_an_hdf5_recorder_s_file_is_locked_while_a_run_writes_it(tmp_path):
    """docs/recorders.md said the file 'can be opened independently while a run is going': a
    plain h5py.File(path, 'r') of another process fails then (HDF5's file lock, errno 11); the
    docs now say so, and how it is read: between runs (closed at the end of each), or without
    the lock (locking=False), which reads what the last flush wrote."""
    path = tmp_path / "live.h5"
    rec = NodeRecorder([3], [2], sink=HDF5Sink(path))
    probe = _ReadWhileRunning(path, when=2)
    analysis = vtsi.TransientAnalysis(beam(), "Newmark", DT, recorders=[rec, probe], chunk_steps=4)
    analysis.run(12)
    assert probe.seen == ["locked", "True", "8"]            # two chunks of 4 steps flushed
    out = subprocess.run([sys.executable, "-c", READ_LIVE, str(path)], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["opened", "12"]            # between runs: closed, readable
