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


def beam4():
    model = vtsi.Model()
    simply_supported_beam(model, L, 4, E, I, MU)
    return model


BAD_DAMPING = [
    ("text frequencies", lambda: rayleigh_damping(beam4(), 0.02, ("a", "b")),
     r"^damping: a frequency \[Hz\] must be a number, got 'a'$"),
    ("one frequency", lambda: rayleigh_damping(beam4(), 0.02, (5,)), r"^damping: give two frequencies \(f_a, f_b\) \[Hz\], got \(5,\)$"),
    ("three frequencies", lambda: rayleigh_damping(beam4(), 0.02, (5, 30, 60)),
     r"^damping: give two frequencies \(f_a, f_b\) \[Hz\], got \(5, 30, 60\)$"),
    ("a number, not a pair", lambda: rayleigh_damping(beam4(), 0.02, 5), r"^damping: give two frequencies \(f_a, f_b\) \[Hz\], got 5$"),
    ("negative frequency", lambda: rayleigh_damping(beam4(), 0.02, (-5, 30)),
     r"^damping: frequencies must be > 0 and finite \[Hz\], got \(-5, 30\)$"),
    ("zero frequency", lambda: rayleigh_damping(beam4(), 0.02, (0, 30)),
     r"^damping: frequencies must be > 0 and finite \[Hz\], got \(0, 30\)$"),
    ("equal frequencies", lambda: rayleigh_coefficients(0.02, 5, 5), r"^damping: the two frequencies must differ, got \(5, 5\)$"),
    ("opposite frequencies", lambda: rayleigh_coefficients(0.02, 5, -5),
     r"^damping: frequencies must be > 0 and finite \[Hz\], got \(5, -5\)$"),
    ("text ratio", lambda: rayleigh_coefficients("x", 5, 30), r"^damping: the ratio must be a number, got 'x'$"),
    ("negative ratio", lambda: rayleigh_coefficients(-0.02, 5, 30), r"^damping: the ratio must be in \[0, 1\) \(0.01 for 1 %\), got -0.02$"),
    ("ratio at 0 Hz", lambda: rayleigh_ratio(0, 1.0, 1e-3), r"^rayleigh ratio: frequencies must be > 0 and finite \[Hz\], got 0.0$"),
    ("ratio at -5 Hz", lambda: rayleigh_ratio([-5, 3], 1.0, 1e-3),
     r"^rayleigh ratio: frequencies must be > 0 and finite \[Hz\], got \[-5.0, 3.0\]$"),
    ("ratio at a text frequency", lambda: rayleigh_ratio("x", 1.0, 1e-3), r"^rayleigh ratio: frequencies must be numbers \[Hz\], got 'x'$"),
    ("no vertical frequency", lambda: vertical_frequencies(beam4(), 0),
     r"^vertical frequencies: the count must be an integer >= 1, got 0$"),
    ("negative count", lambda: vertical_frequencies(beam4(), -1), r"^vertical frequencies: the count must be an integer >= 1, got -1$"),
    ("text count", lambda: vertical_frequencies(beam4(), "x"), r"^vertical frequencies: the count must be an integer >= 1, got 'x'$"),
    ("fractional count", lambda: vertical_frequencies(beam4(), 2.5), r"^vertical frequencies: the count must be an integer >= 1, got 2.5$"),
    ("damping of no model", lambda: rayleigh_damping(None, 0.02), r"^damping: model must be a vtsi.Model, got None$"),
    ("frequencies of no model", lambda: vertical_frequencies(None), r"^vertical frequencies: model must be a vtsi.Model, got None$"),
    ("more than the model has", lambda: vertical_frequencies(beam4(), 100),
     r"^vertical frequencies: 100 asked, the model has 8 vertical modes$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in BAD_DAMPING], ids=[c[0] for c in BAD_DAMPING])
def test_bad_damping_input_is_named(bad, match):
    with pytest.raises(vtsi.ModelError, match=match):
        bad()


def test_a_refused_fit_leaves_the_model_undamped():
    model = beam4()
    with pytest.raises(vtsi.ModelError):
        rayleigh_damping(model, 0.02, (0, 30))
    assert model.rayleigh_factors == (0.0, 0.0)
    assert len(vertical_frequencies(model, 8)[0]) == 8       # every vertical mode of the model, when asked
