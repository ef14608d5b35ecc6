"""Damping by a ratio (vtsi.damping): the Rayleigh fit, what it gives the other modes, the bridge
builders' damping argument, and a free-decay measurement of the ratio."""
import numpy as np
import pytest

import vtsi
from vtsi.damping import rayleigh_coefficients, rayleigh_damping, rayleigh_ratio, vertical_frequencies
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders import NodeRecorder

L, E, I, MU = 20.0, 3.5e10, 0.6948, 15000.0


def test_rayleigh_fit_and_the_modes_between_and_above():
    zeta, fa, fb = 0.013, 5.0, 45.0
    a, b = rayleigh_coefficients(zeta, fa, fb)
    assert rayleigh_ratio([fa, fb], a, b) == pytest.approx([zeta, zeta], rel=1e-12)
    mid = np.sqrt(fa * fb)
    assert rayleigh_ratio(mid, a, b) == pytest.approx(2 * zeta * mid / (fa + fb), rel=1e-12)   # the minimum
    f = np.linspace(fa, fb, 50)
    assert np.all(rayleigh_ratio(f, a, b) <= zeta * (1 + 1e-12))
    assert rayleigh_ratio(100.0, a, b) > zeta and rayleigh_ratio(2.0, a, b) > zeta


def test_builder_damping_is_rayleigh_through_n0_and_the_cutoff():
    model = vtsi.Model()
    simply_supported_beam(model, L, 10, E, I, MU, damping=0.013)
    f = vertical_frequencies(model, 3)[0]
    a, b = model.rayleigh_factors
    assert rayleigh_ratio(f[[0, 2]], a, b) == pytest.approx([0.013, 0.013], rel=1e-10)   # cut-off = n3 = 45 Hz here
    with pytest.raises(vtsi.ModelError, match="ratio"):
        rayleigh_damping(vtsi.Model(), 1.3)


def test_free_decay_measures_the_ratio_of_the_first_mode():
    """The beam released from its first mode shape: the logarithmic decrement of the midspan over
    10 periods gives ζ within 1 % of 1.3 % (Newmark's numerical damping is zero)."""
    model = vtsi.Model()
    beam = simply_supported_beam(model, L, 10, E, I, MU, damping=0.013)
    f, shapes = vertical_frequencies(model, 1)
    state = vtsi.domain_state(model)
    state.u[:] = 0.01 * shapes[:, 0] / np.max(np.abs(shapes[:, 0]))
    rec = NodeRecorder([beam.midspan_nodes[0]], [2], "disp")
    dt = 1.0 / f[0] / 400
    vtsi.TransientAnalysis(model, "Newmark", dt, recorders=[rec]).run(4000)
    u = np.asarray(rec.values)[:, 0]
    peaks = [abs(u[i]) for i in range(1, len(u) - 1) if abs(u[i]) >= abs(u[i - 1]) and abs(u[i]) > abs(u[i + 1])]
    n = (len(peaks) - 1) / 2                          # |u| peaks twice per period
    zeta = np.log(peaks[0] / peaks[-1]) / (2 * np.pi * n)
    assert zeta == pytest.approx(0.013, rel=0.01)
