"""Envelopes with concurrent values (``envelope="concurrent"``): at the step where a column
reaches its min / max / absmax, every column of the recorder, read back against the recorder's
own history (the first step of each extreme, as the envelope's tie rule takes it)."""
import h5py
import numpy as np
import pytest

import vtsi
from vtsi.errors import ModelError
from vtsi.recorders import ElementRecorder, Envelope, HDF5Sink, NodeRecorder, TextSink

DT, N_EL = 0.01, 6


def loaded_beam():
    """A simply supported beam (6 elements, 12 m, 2 % Rayleigh-ish damping) under two vertical
    loads of different histories, so that the columns reach their extremes at different steps."""
    m = vtsi.Model()
    for i in range(N_EL + 1):
        m.node(i + 1, 2.0 * i, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(N_EL + 1, 0, 1, 0)
    for e in range(1, N_EL + 1):
        m.element("elasticBeamColumn", e, (e, e + 1), A=0.5, E=3e10, I=0.04, rho=1000.0)
    m.rayleigh(0.3, 0.0, 0.0, 1e-4)
    k = np.arange(400)
    m.add_time_series(vtsi.Path(np.sin(0.07 * k) + 0.3, dt=DT, tag=1))
    m.add_time_series(vtsi.Path(np.cos(0.031 * k) * np.exp(-0.004 * k), dt=DT, tag=2))
    m.pattern(1, 1).load(3, 0.0, -1e5, 0.0)
    m.pattern(2, 2).load(6, 2e4, -6e4, 0.0)
    return m


def expected_concurrent(time, values):
    """{statistic: (n, n) rows of ``values`` at each column's first extreme} from a history."""
    out = {}
    for name, index in (("min", np.argmin(values, axis=0)), ("max", np.argmax(values, axis=0)),
                        ("absmax", np.argmax(np.abs(values), axis=0))):
        out[name] = values[index]
        out["time_of_" + name] = time[index]
    return out


@pytest.mark.parametrize("chunk_steps", [7, 1000])
def test_concurrent_rows_are_the_history_rows_at_each_extreme(chunk_steps):
    recs = [ElementRecorder([2, 5], "localForce", envelope="concurrent"),
            NodeRecorder([2, 3, 4, 6], [1, 2, 3], "accel", envelope="concurrent")]
    vtsi.TransientAnalysis(loaded_beam(), "Newmark", DT, recorders=recs, chunk_steps=chunk_steps).run(300)
    for rec in recs:
        env, want = rec.envelope, expected_concurrent(rec.time, rec.values)
        n = rec.values.shape[1]
        assert len(set(np.argmax(rec.values, axis=0))) > n // 2      # the extremes fall at different steps
        for name in ("min", "max", "absmax"):
            got = getattr(env, "concurrent_" + name)
            assert got.shape == (n, n)
            np.testing.assert_array_equal(got, want[name])
            np.testing.assert_array_equal(getattr(env, "time_of_" + name), want["time_of_" + name])
        np.testing.assert_array_equal(np.diag(env.concurrent_max), env.max)
        np.testing.assert_array_equal(np.diag(env.concurrent_min), env.min)
        np.testing.assert_array_equal(np.abs(np.diag(env.concurrent_absmax)), env.absmax)


def test_an_envelope_only_recorder_keeps_the_same_concurrent_values_in_hdf5(tmp_path):
    """history=False (OpenSees's EnvelopeElement) keeps the same concurrent values, and the
    HDF5 file holds them as /envelope/concurrent_* (n_columns, n_columns)."""
    path = tmp_path / "env.h5"
    full = ElementRecorder([1, 4], "localForce", envelope="concurrent")
    only = ElementRecorder([1, 4], "localForce", envelope="concurrent", history=False, sink=HDF5Sink(path))
    vtsi.TransientAnalysis(loaded_beam(), "Newmark", DT, recorders=[full, only], chunk_steps=11).run(250)
    with h5py.File(path, "r") as f:
        assert "values" not in f
        for name in Envelope.CONCURRENT:
            np.testing.assert_array_equal(getattr(only.envelope, name), getattr(full.envelope, name))
            np.testing.assert_array_equal(f["envelope"][name][...], getattr(full.envelope, name))
        np.testing.assert_array_equal(f["envelope/max"][...], full.envelope.max)


def test_ties_keep_the_first_step_and_a_plain_envelope_keeps_no_concurrent_values():
    env = Envelope(2, concurrent=True)
    env.update(np.array([0.1, 0.2]), np.array([[1.0, 5.0], [1.0, -5.0]]))
    env.update(np.array([0.3]), np.array([[1.0, 2.0]]))
    np.testing.assert_array_equal(env.concurrent_max, [[1.0, 5.0], [1.0, 5.0]])     # column 0: tie, first step
    np.testing.assert_array_equal(env.concurrent_min, [[1.0, 5.0], [1.0, -5.0]])
    np.testing.assert_array_equal(env.concurrent_absmax, [[1.0, 5.0], [1.0, 5.0]])   # |5| = |-5|: first step
    plain = Envelope(2)
    assert plain.fields == Envelope.FIELDS and not hasattr(plain, "concurrent_max")
    assert set(env.as_dict()) == set(Envelope.FIELDS + Envelope.CONCURRENT)


@pytest.mark.parametrize("envelope, message", [
    ("yes", "node recorder: envelope must be True, False or 'concurrent', got 'yes'"),
    (1, "node recorder: envelope must be True, False or 'concurrent', got 1"),
])
def test_a_bad_envelope_option_is_named(envelope, message):
    with pytest.raises(ModelError, match=f"^{message}$"):
        NodeRecorder([2], [2], envelope=envelope)


def test_a_text_file_refuses_concurrent_values(tmp_path):
    with pytest.raises(ModelError, match="concurrent"):
        NodeRecorder([2], [2], envelope="concurrent", history=False, sink=TextSink(tmp_path / "e.out"))
