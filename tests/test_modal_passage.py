"""Exact moving-force passages over a modal bridge (vtsi.modal_passage): against Frýba's series,
against the time-stepped FE bridge, the modal damping by free decay, and as a sweep setting."""
import numpy as np
import pytest

import vtsi
from vtsi.modal_bridge import ModalBridge
from vtsi.modal_passage import peaks
from vtsi.models.bridges import simply_supported_beam
from vtsi.passage import Output, PassageSettings
from vtsi.reference.fryba import moving_force_midspan
from vtsi.sweep import Sweep, beam_bridge
from vtsi.track import Track

L, F1, MU, P = 20.0, 5.0, 15000.0, 170e3
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
V = 200 / 3.6


def bridge(n=40, f_max=45.5, zeta=0.0):
    model = vtsi.Model()
    beam = simply_supported_beam(model, L, n, EI, 1.0, MU)
    modal = ModalBridge(model, Track(model, beam.elements), f_max, zeta)
    return model, beam, modal


def test_one_force_is_frybas_series_in_the_same_modes():
    """Modes 1-3 (5, 20, 45 Hz; the beam's axial mode is left out: no wheel loads it) of a
    40-element beam: the mid-span deflection equals Frýba's series with 3 modes to 2e-6 of its
    peak (the FE modes' own error), the acceleration to 5e-4 (the reference's second
    difference, h = 10 µs), over the crossing and as long again of free vibration."""
    model, beam, modal = bridge()
    assert modal.n_modes == 3 and modal.frequencies == pytest.approx([5.0, 20.0, 45.0], rel=1e-5)
    n, dt = 1440, 5e-4
    q, _, qdd = modal.coordinates([0.0], [P], V, 0.0, n, dt)
    t = dt * np.arange(1, n + 1)
    mid = model.build().full_dof(beam.midspan_nodes[0], 2)
    w = lambda tt: moving_force_midspan(P, V, L, EI, MU, tt, n_modes=3)
    exact = -w(t)
    assert np.max(np.abs(q @ modal.shapes[mid] - exact)) < 2e-6 * np.max(np.abs(exact))
    h = 1e-5
    a = -(w(t + h) - 2 * w(t) + w(t - h)) / h ** 2
    assert np.max(np.abs(qdd @ modal.shapes[mid] - a)) < 5e-4 * np.max(np.abs(a))


def test_modal_damping_by_free_decay():
    """After the force has left, every mode decays with its own ratio exactly (ζ = 1, 2, 3 %)."""
    model, beam, modal = bridge(n=10, zeta=[0.01, 0.02, 0.03])
    dt = 2e-4
    n = int(round((L / V + 2.0) / dt))
    q, qd, _ = modal.coordinates([0.0], [P], V, 0.0, n, dt)
    t = dt * np.arange(1, n + 1)
    free = t > L / V + 1e-9
    for j, zeta in enumerate((0.01, 0.02, 0.03)):
        w = modal.omega[j]
        wd = w * np.sqrt(1 - zeta ** 2)
        # the amplitude of the damped free vibration: sqrt(q² + ((q̇ + ζωq)/ω_d)²) ∝ e^(−ζωt)
        amp = np.sqrt(q[free, j] ** 2 + ((qd[free, j] + zeta * w * q[free, j]) / wd) ** 2)
        measured = -np.polyfit(t[free], np.log(amp), 1)[0] / w
        assert measured == pytest.approx(zeta, rel=1e-6)


def test_modal_sweep_converges_to_the_time_stepped_fe_bridge():
    """HSLM-A4 near its resonance: the FE bridge's EN-filtered mid-span acceleration (Newmark,
    Δt = 0.25 ms, Rayleigh damping equal to the modal ratio on modes 1 and 3, the modes that move
    the mid-span) and the exact modal passage agree within 0.3 %."""
    beam = beam_bridge([L], EI, 1.0, MU, elements_per_span=10)
    out = [Output("acceleration", "accel", nodes="midspan", cutoff="en")]
    fe = Sweep(beam, ["HSLM-A4"], "380", PassageSettings(dt=2.5e-4, damping=0.013, damping_hz=(5.0, 45.024)), out)
    modal = Sweep(beam, ["HSLM-A4"], "380", PassageSettings(dt=2.5e-4, damping=0.013, bridge="modal"), out)
    a_fe = fe.run(None, workers=1, progress=False).envelope("acceleration_absmax")[0, 0, 0]
    a_modal = modal.run(None, workers=1, progress=False).envelope("acceleration_absmax")[0, 0, 0]
    assert a_modal == pytest.approx(a_fe, rel=3e-3)


def test_peaks_are_refined_between_samples():
    t = 0.011 * np.arange(1, 91)                       # the samples peaks() assumes: t = dt, 2 dt, …
    y = (np.cos(2 * np.pi * 3.0 * (t - 0.5)) * np.exp(-((t - 0.5) / 0.3) ** 2))[:, None]
    env = peaks(y, 0.011)
    assert env[1, 0] == pytest.approx(1.0, abs=2e-4) and env[4, 0] == pytest.approx(0.5, abs=2e-4)
    assert np.max(y) < 1.0 - 1e-3                     # the samples alone miss the peak


def test_the_static_correction_restores_the_truncated_modes_moment():
    """HSLM-A4 at 250 km/h, bending moment and deflection at mid-span, against the FE bridge
    (every mode, Newmark, Δt = 0.25 ms, Rayleigh equal to the modal ratio on modes 1 and 3). The
    modal bridge keeps 3 modes (up to 1.1 × 30 Hz): without the static correction the largest
    moment misses 0.9 % (measured 8.6e-3), with it 2.7e-4; the deflection 5.0e-4 and 1.7e-5. The
    time-stepped modal passage ('modal-stepped', the same Δt) gets the same correction: 2.9e-4
    and 8e-6 with it, 8.8e-3 and 4.9e-4 without (the moments with the axles' fixed-end share,
    vtsi.recorders.moment, which moved the FE peak: 7.3e-3 and 2.5e-4 before)."""
    beam = beam_bridge([L], EI, 1.0, MU, elements_per_span=10)
    out = [Output("deflection", "disp", nodes="midspan"), Output("moment", "moment", nodes="midspan")]
    fe = Sweep(beam, ["HSLM-A4"], "250", PassageSettings(dt=2.5e-4, damping=0.013, damping_hz=(5.0, 45.024)),
               out).runner.run("HSLM-A4", 250.0)
    for kind in ("modal", "modal-stepped"):
        modal = {sc: Sweep(beam, ["HSLM-A4"], "250", PassageSettings(dt=2.5e-4, damping=0.013, bridge=kind,
                                                                      static_correction=sc), out).runner.run("HSLM-A4", 250.0)
                 for sc in (True, False)}
        err = {sc: (abs(r.envelopes["moment"][1, 0] / fe.envelopes["moment"][1, 0] - 1.0),
                    abs(r.envelopes["deflection"][0, 0] / fe.envelopes["deflection"][0, 0] - 1.0))
               for sc, r in modal.items()}
        assert err[True][0] < 1e-3 and err[True][1] < 1e-4, kind
        assert err[False][0] > 3e-3 and err[False][0] > 10 * err[True][0], kind


def test_a_modal_sweep_of_cars_with_every_mode_equals_the_fe_sweep():
    """ICE3 of 10-dof cars, LCP contact, the deck's self weight, no damping: with every mode that
    moves the track kept (modal_hz far above the FE model's highest frequency) the modal bridge
    steps the FE bridge's equations, so every envelope of the passage agrees to rounding."""
    beam = beam_bridge([L], EI, 1.0, MU, elements_per_span=6)
    common = dict(dt=2e-3, cars="full", contact="lcp", bridge_self_weight=True)
    fe = Sweep(beam, ["ICE3"], "300", PassageSettings(**common)).runner.run("ICE3", 300.0)
    modal = Sweep(beam, ["ICE3"], "300", PassageSettings(bridge="modal", modal_hz=1e7, **common)).runner.run("ICE3", 300.0)
    assert set(fe.envelopes) == set(modal.envelopes) and len(fe.envelopes) >= 3
    for name, env in fe.envelopes.items():
        scale = np.max(np.abs(env[:3]))
        assert np.max(np.abs(modal.envelopes[name][:3] - env[:3])) <= 1e-9 * scale, name


def test_a_modal_sweep_keeps_the_bridge_models_own_damping():
    """A bridge model with its own Rayleigh damping (ζ = 1.3 % through n₀ and the cut-off) swept
    on the modal bridge without a damping setting: its modes get that damping (the modal sweep
    gave them none: 60.6 m/s² for HSLM-A4 at its resonance against the FE bridge's 30.8), and the
    peak agrees with the FE bridge's. Non-classical damping (a dashpot to the ground) is refused
    with the sweep's remedy."""
    beam = beam_bridge([L], EI, 1.0, MU, elements_per_span=10, damping=0.013)
    out = [Output("a", "accel", nodes="midspan", cutoff="en")]
    runs = {kind: Sweep(beam, ["HSLM-A4"], "380", PassageSettings(dt=2.5e-4, bridge=kind), out).runner
            for kind in ("fe", "modal")}
    assert runs["modal"].modal.zeta[[0, -1]] == pytest.approx([0.013, 0.013], rel=1e-6)
    assert np.all(runs["modal"].modal.zeta <= 0.013 + 1e-9)
    peak = {kind: r.run("HSLM-A4", 380.0).envelopes["a"][2, 0] for kind, r in runs.items()}
    assert peak["modal"] == pytest.approx(peak["fe"], rel=3e-3)
    node = beam.model.nodes
    mid = max(node, key=lambda n: -abs(node[n][0] - 0.5 * L))
    beam.model.node(999, *node[mid])
    beam.model.fix(999, 1, 1, 1)
    beam.model.element("zeroLength", 999, (mid, 999), cy=1e5)
    refused = (r"^sweep: modal bridge: the model.s damping is not classical .*; give the damping ratios: zeta=\.\.\. "
               r"\(a sweep: its damping ratio, PassageSettings\(damping=\.\.\.\), --damping\)$")
    with pytest.raises(vtsi.VtsiError, match=refused):
        Sweep(beam, ["HSLM-A4"], "380", PassageSettings(dt=2.5e-4, bridge="modal"), out)


def test_an_exact_modal_output_reads_the_modes_up_to_its_cut_off():
    """An acceleration output with a 10 Hz cut-off keeps mode 1 only, whatever the modal basis:
    exact passages read every mode of the basis (2.23 m/s² for HSLM-A4 at 250 km/h instead of
    1.31), and a modal_hz of 200 Hz made the 'en' output count modes above the EN cut-off too."""
    beam = beam_bridge([L], EI, 1.0, MU, elements_per_span=10)
    outputs = [Output("en", "accel", cutoff="en"), Output("ten", "accel", cutoff=10.0)]

    def peak(name, **settings):
        sweep = Sweep(beam, ["HSLM-A4"], "250", PassageSettings(dt=2.5e-4, damping=0.015, **settings), outputs)
        return sweep.runner.run("HSLM-A4", 250.0).envelopes[name][2].max()       # over the deck

    stepped = peak("ten", bridge="modal-stepped")
    assert stepped < 0.7 * peak("en", bridge="modal-stepped")
    for modal_hz in (None, 200.0):
        assert peak("ten", bridge="modal", modal_hz=modal_hz) == pytest.approx(stepped, rel=2e-3)
    assert peak("en", bridge="modal", modal_hz=200.0) == pytest.approx(peak("en", bridge="modal"), rel=1e-12)


def test_modal_bridge_settings():
    with pytest.raises(vtsi.ModelError, match="unknown bridge"):
        PassageSettings(bridge="shell")
    with pytest.raises(vtsi.ModelError, match="damping ratios"):
        bridge(n=10, zeta=[0.01, 0.02, 0.03, 0.04])


def test_one_pass_gives_every_column_as_its_own_pass():
    """The kernel sums weights on q, q̇ and q̈ per column (displacement, velocity and
    acceleration columns of two nodes in one call): each column equals the modal coordinates
    of the same passage times its weights, across breakpoints and the free vibration's long
    pieces (more samples than one block of the power table)."""
    model, beam, modal = bridge(n=10, zeta=[0.01, 0.02, 0.03])
    offsets, loads = [0.0, 2.5, 5.0, 17.5], [170e3, 150e3, 170e3, 120e3]
    n, dt = 2000, 7e-4
    q = modal.coordinates(offsets, loads, V, 0.0, n, dt)
    rng = np.random.default_rng(3)
    rows = rng.normal(size=(3, modal.n_modes, 5))
    rows[:, :, 0] *= [[1.0], [0.0], [0.0]]          # a pure displacement, velocity and acceleration column
    rows[:, :, 1] *= [[0.0], [1.0], [0.0]]
    rows[:, :, 2] *= [[0.0], [0.0], [1.0]]
    out = modal.passage(offsets, loads, V, 0.0, n, dt, rows)
    expected = sum(q[order] @ rows[order] for order in range(3))
    assert np.max(np.abs(out - expected)) <= 1e-12 * np.max(np.abs(expected))
    with pytest.raises(vtsi.ModelError, match=r"passage rows must be \(3, 3, n_columns\)"):
        modal.passage(offsets, loads, V, 0.0, n, dt, rows[:2])


@pytest.mark.parametrize("call, message", [
    (lambda m: m.passage([0.0, 3.0], [P], V, 0.0, 10, 1e-3, np.zeros((3, m.n_modes, 1))),
     r"as many axle loads as axle offsets .* got \(1,\) loads and \(2,\) offsets"),
    (lambda m: m.passage([0.0, -3.0], [P, P], V, 0.0, 10, 1e-3, np.zeros((3, m.n_modes, 1))),
     r"axle 1: offset -3.0 m is ahead of axle 0's 0.0 m"),
    (lambda m: m.passage([0.0], [np.nan], V, 0.0, 10, 1e-3, np.zeros((3, m.n_modes, 1))),
     r"axle 0: offset 0.0 m and load nan N must be finite"),
    (lambda m: m.passage([0.0], ["heavy"], V, 0.0, 10, 1e-3, np.zeros((3, m.n_modes, 1))),
     r"axle loads must be numbers, got \['heavy'\]"),
    (lambda m: m.coordinates([0.0], [P], 0.0, 0.0, 10, 1e-3), r"passage speed must be > 0 and finite, got 0.0"),
    (lambda m: m.coordinates([0.0], [P], V, 0.0, 10, -1e-3), r"passage dt must be > 0 and finite, got -0.001"),
    (lambda m: m.coordinates([0.0], [P], V, np.inf, 10, 1e-3), r"x_head0 must be a finite position \[m\], got inf"),
    (lambda m: m.coordinates([0.0], [P], V, 0.0, 2.5, 1e-3), r"n_samples must be an integer >= 0, got 2.5"),
    (lambda m: m.passage([0.0], [P], V, 0.0, 10, 1e-3, "rows"), r"passage rows must be numbers, got 'rows'"),
    (lambda m: m.static_correction(np.zeros((3, 1)), [0.0], [P], V, 0.0, 10, 1e-3),
     r"residual flexibility G must be \(n_track = \d+, n_columns\), got \(3, 1\)"),
    (lambda m: m.residual_flexibility(np.ones((3, 2))), r"output map must be \(n_free = \d+, n_columns\), got \(3, 2\)"),
    (lambda m: m.add_ratios("a"), r"added ratios must be numbers, got 'a'"),
    (lambda m: peaks(np.ones(10), 1e-3), r"peaks: values must be \(n_samples, n_columns\), got shape \(10,\)"),
    (lambda m: peaks(np.ones((10, 1)), 0.0), r"peaks: the sampling step dt must be > 0 and finite \[s\], got 0.0"),
], ids=["loads-count", "axle-order", "nan-load", "text-load", "speed", "dt", "x_head0", "n_samples", "rows",
        "G-shape", "output-map", "added-ratios", "peaks-1d", "peaks-dt"])
def test_a_bad_passage_input_is_named(call, message):
    """Every argument of an exact passage is checked before the kernel runs: a wrong count,
    order or value of the axles, a speed, step or sample count out of range, a wrong shape of
    the output rows or the residual flexibility — a ModelError naming it, never a silent
    result from memory past an array's end."""
    _, _, modal = bridge(n=10)
    with pytest.raises(vtsi.ModelError, match=message):
        call(modal)


@pytest.mark.parametrize("zeta, message", [
    ("abc", r"damping ratios must be numbers, got 'abc'"),
    ([0.01, "a", 0.02], r"damping ratios must be numbers"),
    (lambda f: 1.0 / 0.0, r"the damping function failed at 5\.\d+ Hz: ZeroDivisionError"),
    (lambda f: "x", r"the damping function's ratio at 5\.\d+ Hz must be a number, got 'x'"),
], ids=["text", "text-in-list", "function-raises", "function-text"])
def test_bad_damping_ratios_are_named(zeta, message):
    """A ratio that is not a number, or a damping function that fails, is named (with the
    frequency it failed at); and the kept ratios cannot be changed in place, only by add_ratios."""
    with pytest.raises(vtsi.ModelError, match=message):
        bridge(n=10, zeta=zeta)
    _, _, modal = bridge(n=10, zeta=0.02)
    with pytest.raises(ValueError, match="read-only"):
        modal.zeta[0] = 2.0
    modal.add_ratios([0.98])
    assert modal.zeta.tolist() == pytest.approx([1.0, 0.02, 0.02])
    with pytest.raises(vtsi.ModelError, match=r"mode 1 \(5[.0-9]* Hz\) has ζ = 1 >= 1"):
        modal.coordinates([0.0], [P], V, 0.0, 10, 1e-3)
