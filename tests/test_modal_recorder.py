"""ModalNodeRecorder: node responses in chosen modes (the EN 1990 A2.4.4.2.1 cut-off by modal
projection). Its error on a closed-form case: a force crossing a simply supported beam, against
Frýba's series truncated to the same modes (vtsi.reference.fryba)."""
import numpy as np
import pytest

import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.models import Train
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders import NodeRecorder
from vtsi.recorders.modal import ModalNodeRecorder
from vtsi.reference.fryba import moving_force_midspan
from vtsi.track import Track
from vtsi.train import TrainSubdomain

L, F1, MU, P = 20.0, 5.0, 15000.0, 170e3
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
V = 200 / 3.6


def crossing(n_elements, dt, cutoff_hz=45.5, n_modes=None):
    """Midspan acceleration of one force crossing (and 1 crossing time of free vibration):
    (times, in the modes up to the cut-off, full FE response, modes kept)."""
    model = vtsi.Model()
    beam = simply_supported_beam(model, L, n_elements, EI, 1.0, MU)
    w2, shapes = vtsi.eigen(model, n_modes or 12)
    keep = shapes[:, np.sqrt(w2) / (2 * np.pi) <= cutoff_hz]
    tie = MovingLoadConstraint(Track(model, beam.elements), TrainSubdomain(Train.from_axle_table([0.0], [P], V), 0.0))
    modal = ModalNodeRecorder([beam.midspan_nodes[0]], 2, "accel", keep, "test modes")
    full = NodeRecorder([beam.midspan_nodes[0]], [2], "accel")
    analysis = CoupledAnalysis(model, tie, "Newmark", dt=dt, recorders=[modal, full])
    analysis.static()
    analysis.run(int(round(2 * L / V / dt)))
    return np.asarray(modal.time), np.asarray(modal.values)[:, 0], np.asarray(full.values)[:, 0], keep.shape[1]


def test_modal_projection_against_the_truncated_series():
    """Cut-off 45.5 Hz keeps bending modes 1-3 (5, 20, 45 Hz; the beam's axial mode at 16 Hz is
    kept but not excited). Frýba's series with modes 1-3, differentiated twice (central
    differences, h = 10 µs), is the exact filtered response: the projection's error is 0.9 %
    of the peak at 20 elements and Δt = 0.2 ms, 0.25 % at 40 elements and 0.1 ms (the FE and
    Newmark errors of mode 3). The full FE response differs by 55-60 % (the modes above the
    cut-off that the force's entry excites): filtering matters."""
    errors = []
    for n_el, dt in ((20, 2e-4), (40, 1e-4)):
        t, filtered, unfiltered, kept = crossing(n_el, dt)
        assert kept == 4
        h = 1e-5
        w = lambda tt: moving_force_midspan(P, V, L, EI, MU, tt, n_modes=3)
        exact = -(w(t + h) - 2 * w(t) + w(t - h)) / h ** 2          # y up, w down
        peak = np.max(np.abs(exact))
        errors.append(np.max(np.abs(filtered - exact)) / peak)
        assert np.max(np.abs(unfiltered - exact)) / peak > 0.3
    assert errors[1] < 0.005 and errors[0] / errors[1] > 3.0, errors


def test_all_modes_give_the_full_response():
    model = vtsi.Model()
    simply_supported_beam(model, L, 6, EI, 1.0, MU)
    n_free = model.build().n_free
    t, modal, full, kept = crossing(6, 1e-3, cutoff_hz=np.inf, n_modes=n_free)
    assert kept == n_free
    np.testing.assert_allclose(modal, full, rtol=0, atol=1e-9 * np.max(np.abs(full)))


def test_bad_shapes_are_refused():
    with pytest.raises(vtsi.ModelError, match="n_modes >= 1"):
        ModalNodeRecorder([1], 2, "accel", np.zeros((9, 0)))
    with pytest.raises(vtsi.ModelError, match="unknown response"):
        ModalNodeRecorder([1], 2, "jerk", np.ones((9, 1)))
