"""What a recorder that raises leaves (docs/recorders.md, "A recorder that raises"): the other
recorders hold the chunk it failed on, and the analysis is at that chunk's last step, so that a
new run goes on from there. Before, the model's displacements had advanced while its time had
not (a transient analysis) or the chunk was not committed (a coupled one): the next run
recorded the same times again (t = 0.01 ... 0.05 twice in a text file of the command layer)."""
import h5py
import numpy as np
import pytest

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.models.scenes import s2_model
from vtsi.recorders import HDF5Sink, MemorySink, NodeRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain

CHUNK = 5


class FailsOnSecondChunk(MemorySink):
    """A sink whose second write fails as a full disk does."""

    def __init__(self):
        super().__init__()
        self.writes = 0

    def write(self, times, values, envelope):
        self.writes += 1
        if self.writes == 2:
            raise OSError(28, "No space left on device")
        super().write(times, values, envelope)


class FailsToClose(MemorySink):
    """A sink whose close fails (a text envelope written at the end on a full disk)."""

    def close(self, envelope):
        raise OSError(28, "No space left on device")


def coupled():
    """Scene S2 (a sprung mass over a 25 m beam, 10 elements), its analysis and a recorder."""
    model = vtsi.Model()
    bridge, train = s2_model(model, 10)
    con = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, 0.0))
    return model, CoupledAnalysis(model, con, "Newmark", 1e-3, chunk_steps=CHUNK), bridge.midspan_nodes


def test_a_transient_analysis_is_left_at_the_chunk_the_recorders_hold(step_load_beam):
    reference = NodeRecorder([3], [2, 3], "accel")
    vtsi.TransientAnalysis(step_load_beam(), "Newmark", 0.01, recorders=[reference], chunk_steps=CHUNK).run(20)
    model = step_load_beam()
    kept, failing = NodeRecorder([3], [2, 3], "accel"), NodeRecorder([2], [2], sink=FailsOnSecondChunk())
    analysis = vtsi.TransientAnalysis(model, "Newmark", 0.01, recorders=[kept, failing], chunk_steps=CHUNK)
    with pytest.raises(OSError, match="No space left on device"):
        analysis.run(20)
    assert len(kept.time) == 2 * CHUNK and vtsi.domain_state(model).time == kept.time[-1]
    vtsi.TransientAnalysis(model, "Newmark", 0.01, recorders=[kept], chunk_steps=CHUNK).run(20 - 2 * CHUNK)
    np.testing.assert_allclose(kept.time, reference.time, rtol=1e-14)
    np.testing.assert_allclose(kept.values, reference.values, rtol=1e-12, atol=1e-12 * np.abs(reference.values).max())


def test_a_coupled_analysis_is_left_at_the_chunk_the_recorders_hold():
    _, whole, mid = coupled()
    reference = NodeRecorder(mid, [2])
    whole.recorders = [reference]
    whole.run(30)
    model, analysis, mid = coupled()
    kept, failing = NodeRecorder(mid, [2]), NodeRecorder(mid, [2], sink=FailsOnSecondChunk())
    analysis.recorders = [kept, failing]
    with pytest.raises(OSError, match="No space left on device"):
        analysis.run(30)
    assert len(kept.time) == 2 * CHUNK and vtsi.domain_state(model).time == pytest.approx(kept.time[-1], rel=1e-14)
    analysis.recorders = [kept]
    analysis.run(30 - 2 * CHUNK)
    np.testing.assert_allclose(kept.time, reference.time, rtol=1e-14)
    np.testing.assert_allclose(kept.values, reference.values, rtol=1e-12, atol=1e-12 * np.abs(reference.values).max())


def test_a_recorder_that_fails_to_close_leaves_no_other_open(tmp_path, step_load_beam):
    """The first recorder's close raises: the HDF5 recorder after it is still closed (its file
    complete and unlocked: another reader opens it) and the error names the one that raised.
    Before, the others stayed open, and their files locked, until garbage collection."""
    path = tmp_path / "kept.h5"
    failing, kept = NodeRecorder([3], [2], sink=FailsToClose()), NodeRecorder([3], [2], sink=HDF5Sink(path))
    with pytest.raises(OSError, match="No space left on device") as info:
        vtsi.TransientAnalysis(step_load_beam(), "Newmark", 0.01, recorders=[failing, kept]).run(10)
    assert info.value.__notes__ == [f"raised by recorders[0] {failing!r} when closed; the other recorders are closed"]
    with h5py.File(path, "r") as f:                           # HDF5's own lock: refused while the sink holds it
        np.testing.assert_array_equal(f["time"][...], failing.time)
        assert f["values"].shape == (10, 1)
