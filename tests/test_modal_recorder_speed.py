"""The recorder feed hands each recorder its columns as a view of the chunk's table where it can,
and the modal recorder projects through the modal coordinates, (x M Φ) Φ_dᵀ: both are exact.
The modal recorder against the formed projection Φ_d Φᵀ M x of every dof's response; every
recorder of overlapping, reordered, fixed, prescribed and equalDOF requests against one that
records every dof; what the sinks keep owned by each recorder (no view of the analysis's table).
Nothing here is timed."""
import numpy as np
import pytest

import vtsi
from vtsi.modal_bridge import ModalBridge
from vtsi.recorders import NodeRecorder
from vtsi.recorders.base import Recorder
from vtsi.recorders.modal import ModalNodeRecorder

NODES = tuple(range(1, 12))


def beam_on_bearings():
    """A 20 m beam in 10 elements (nodes 1-11) on zeroLength bearings to fixed nodes 100, 101,
    lumped mass; two point loads under a Path series."""
    model = vtsi.Model()
    for i in range(11):
        model.node(i + 1, 2.0 * i, 0.0)
    model.node(100, 0.0, 0.0)
    model.node(101, 20.0, 0.0)
    model.fix(100, 1, 1, 1)
    model.fix(101, 1, 1, 1)
    for e in range(10):
        model.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=1.0, E=3e10, I=0.5, rho=5000.0)
    model.element("zeroLength", 200, (100, 1), kx=1e10, ky=5e9)
    model.element("zeroLength", 201, (101, 11), ky=5e9)
    model.pattern(1, vtsi.Path(dt=0.01, values=[0.0, 1.0, 0.3, 0.8, 0.5, 0.0]))
    model.load(1, 5, 2e4, -1e5, 0.0)
    model.load(1, 8, 0.0, -5e4, 0.0)
    return model


@pytest.mark.parametrize("bridge", ["fe", "modal"])
@pytest.mark.parametrize("response", ["disp", "accel"])
def test_modal_recorder_equals_the_formed_projection(bridge, response):
    """Φ_d Φᵀ M x, x every dof's response (a recorder of all of them), to 1e-12 of the peak, for
    the FE bridge and a modal bridge, 3 of 8 modes kept; chunks of 7 steps."""
    model = beam_on_bearings()
    _, shapes = vtsi.eigen(model, 8)
    kept = shapes[:, [0, 1, 3]]
    everything = NodeRecorder(list(NODES), [1, 2, 3], response)
    filtered = ModalNodeRecorder([3, 6, 11, 1], 2, response, kept, "modes 1, 2, 4")
    modal = None if bridge == "fe" else ModalBridge(model, n_modes=8, zeta=0.02)
    vtsi.TransientAnalysis(model, "Newmark", 0.002, recorders=[everything, filtered], chunk_steps=7,
                           bridge=modal).run(60)
    asm = model.build()
    x = np.zeros((len(everything.time), asm.n_full))
    x[:, [asm.full_dof(n, d) for n in NODES for d in (1, 2, 3)]] = everything.values
    at = [asm.full_dof(n, 2) for n in (3, 6, 11, 1)]
    expected = x @ (asm.M_full @ kept) @ kept[at].T
    assert np.abs(expected).max() > 0.0
    np.testing.assert_allclose(filtered.values, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def tied_frame():
    """A beam 1-2 clamped at 1 carries beam 3-4 through equalDOF (ux, uy of 3 follow 2); node 5
    hangs on node 4 by a rigidLink beam and stands on a column 5-6 clamped at 6; node 7, on a
    beam from 6, settles by a prescribed uy (sp) and slides in ux (fixed)."""
    model = vtsi.Model()
    for tag, x, y in ((1, 0.0, 0.0), (2, 5.0, 0.0), (3, 5.0, 0.0), (4, 10.0, 1.0), (5, 12.0, 1.0),
                      (6, 12.0, -3.0), (7, 16.0, -3.0)):
        model.node(tag, x, y)
    model.fix(1, 1, 1, 1)
    model.fix(6, 1, 1, 1)
    model.fix(7, 1, 0, 0)
    for tag, ends, rho in ((1, (1, 2), 100.0), (2, (3, 4), 100.0), (3, (5, 6), 60.0), (4, (6, 7), 60.0)):
        model.element("elasticBeamColumn", tag, ends, A=0.1, E=2e10, I=1e-3, rho=rho)
    model.equal_dof(2, 3, 1, 2)
    model.rigid_link("beam", 4, 5)
    model.mass(3, 50.0, 50.0, 5.0)
    model.pattern(1, vtsi.Path(dt=0.01, values=[0.0, 1.0, 0.3, 0.8, 0.5, 0.0]))
    model.load(1, 5, 1e3, -1e4, 0.0)
    model.load(1, 3, 1e3, 0.0, 2e3)
    model.sp(1, 7, 2, -0.001)
    return model


@pytest.mark.parametrize("chunk_steps", [1, 7])
def test_every_recorder_gets_its_columns(chunk_steps):
    """Recorders asking for the same columns, part of them, in another order, for fixed,
    prescribed and equalDOF / rigidLink dofs, or for the modal projection of all of them, read
    what one recorder of every dof reads (chunks of one step: the table's row is contiguous, so
    a recorder's columns are a view of it); what each memory sink keeps is its own. The modal
    recorder counts the mass of the tied dofs (it left it out: with every mode, node 2's uy read
    -1.29e-4 m for -2.86e-4 m)."""
    model = tied_frame()
    _, shapes = vtsi.eigen(model, 4)
    nodes = [2, 3, 4, 5, 6, 7]
    every = NodeRecorder(nodes, [1, 2, 3], "disp")
    same = NodeRecorder(nodes, [1, 2, 3], "disp")
    reversed_ = NodeRecorder(nodes[::-1], [2], "disp", envelope=True)
    modal = ModalNodeRecorder(nodes, 2, "disp", shapes)
    alone = NodeRecorder([4], [3], "disp")
    recorders = [every, modal, same, reversed_, alone]
    vtsi.TransientAnalysis(model, "Newmark", 0.0025, recorders=recorders, chunk_steps=chunk_steps).run(30)
    values = every.values                                           # (n, 18): node-major, dofs 1-3
    column = {(n, d): values[:, 3 * i + d - 1] for i, n in enumerate(nodes) for d in (1, 2, 3)}
    t = every.time
    assert np.array_equal(same.values, values)
    assert np.array_equal(reversed_.values, np.column_stack([column[n, 2] for n in nodes[::-1]]))
    assert np.array_equal(reversed_.envelope.min, reversed_.values.min(axis=0))
    assert np.array_equal(alone.values[:, 0], column[4, 3])
    assert np.array_equal(column[3, 1], column[2, 1]) and np.array_equal(column[3, 2], column[2, 2])   # equalDOF
    assert not np.array_equal(column[3, 3], column[2, 3])
    assert np.abs(column[5, 2] - (column[4, 2] + 2.0 * column[4, 3])).max() < 1e-15 + 1e-12 * np.abs(column[5, 2]).max()
    assert not column[6, 1].any() and not column[7, 1].any()                                         # fixed
    settle = vtsi.Path(dt=0.01, values=[0.0, 1.0, 0.3, 0.8, 0.5, 0.0])(t)
    np.testing.assert_allclose(column[7, 2], -0.001 * settle, rtol=0, atol=1e-18)                     # sp
    asm = model.build()
    x = np.zeros((len(t), asm.n_full))
    x[:, [asm.full_dof(n, d) for n in nodes for d in (1, 2, 3)]] = values
    x[:, asm.full_dof(7, 2)] = 0.0          # a prescribed dof is no free dof: not in the modes' projection
    expected = x @ (asm.M_full @ shapes) @ shapes[[asm.full_dof(n, 2) for n in nodes]].T
    np.testing.assert_allclose(modal.values, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    kept = [r.values for r in recorders]
    for i, a in enumerate(kept):
        assert a.flags.writeable
        assert not any(np.shares_memory(a, b) for b in kept[i + 1:])
    same.values[:] = 0.0                    # a user's change of one record leaves the others as they were
    assert np.array_equal(every.values, values) and values.any()


class Millimetres(Recorder):
    """A user's recorder (of another package than vtsi) that scales the columns it is handed in
    place: the uy displacement [mm] of its nodes."""

    def __init__(self, nodes, **kwargs):
        self.nodes = list(nodes)
        super().__init__(**kwargs)

    def requests(self, assembly):
        return [("u", assembly.full_dof(n, 2)) for n in self.nodes]

    def prepare(self, assembly, model):
        return {"units": ["mm"] * len(self.nodes), "columns": {"node": np.array(self.nodes)}, "quantity": "disp"}

    def compute(self, times, columns, assembly):
        columns *= 1e3
        return columns


def test_a_users_recorder_gets_columns_of_its_own():
    """vtsi's own recorders read views of the chunk's table; another package's recorder gets its
    columns as its own, as the contract always gave them: one that scaled them in place raised
    numpy's 'output array is read-only' (with no -dT only), and must not change what vtsi's
    recorder of the same dofs reads."""
    model = tied_frame()
    mine = NodeRecorder([4, 5], [2], "disp")
    theirs = Millimetres([4, 5])
    vtsi.TransientAnalysis(model, "Newmark", 0.0025, recorders=[mine, theirs]).run(30)
    assert np.abs(mine.values).max() > 0
    np.testing.assert_array_equal(theirs.values, 1e3 * mine.values)
