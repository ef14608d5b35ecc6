"""The modal bridge as a bridge subdomain (vtsi.modal_bridge, vtsi.subdomain).

- With every mode kept and classical (Rayleigh) damping, the modal coordinates obey the same
  equations as the FE dofs, so the same integrator and Δt give the same numbers up to rounding:
  S1 (moving force as nodal Path loads, TransientAnalysis) and S5 (the 8-car ICE3 of 10-dof cars
  over the 3 × 30 m viaduct, CoupledAnalysis, bilateral and LCP contact, both remedies).
- Stepping a truncated modal bridge converges to the exact modal passage (vtsi.modal_passage,
  no time-step error) at the integrator's order.
- A ratio per mode: the free decay of each mode gives back its ζ.
"""
import math

import numpy as np
import pytest

import vtsi
from vtsi.analysis import modes_up_to
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.damping import rayleigh_damping
from vtsi.errors import AnalysisError, ModelError
from vtsi.integrators import HHT, GeneralizedAlpha
from vtsi.modal_bridge import ModalBridge
from vtsi.models.bridges import simply_supported_beam
from vtsi.models.catalogue import catalogue_train
from vtsi.models.scenes import S1, s5_viaduct
from vtsi.recorders import NodeRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain

L, E, I, MU, P = S1["L"], S1["E"], S1["I"], S1["mu"], S1["P"]


def s1_path_model(n_elements, V, dt, n_steps):
    """S1 as an OpenSees user writes it: one Path pattern per node, hat-function sharing."""
    model = vtsi.Model()
    x = np.linspace(0.0, L, n_elements + 1)
    for i, xi in enumerate(x):
        model.node(i + 1, float(xi), 0.0)
    model.fix(1, 1, 1, 0)
    model.fix(n_elements + 1, 0, 1, 0)
    for e in range(n_elements):
        model.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=1.0, E=E, I=I, rho=MU, cmass=1)
    t = dt * np.arange(n_steps + 1)
    pos = V * t
    h = L / n_elements
    for i in range(1, n_elements):
        share = np.clip(1.0 - np.abs(pos - x[i]) / h, 0.0, None) * (pos <= L)
        model.pattern(i + 1, vtsi.Path(P * share, dt=dt))
        model.load(i + 1, i + 1, 0.0, -1.0, 0.0)
    return model


def run_s1(bridge_kind, integrator, n_elements=20, dt=1e-3, n_steps=1500):
    model = s1_path_model(n_elements, S1["V"], dt, n_steps)
    rayleigh_damping(model, 0.02)
    bridge = ModalBridge(model, n_modes=model.build().n_free) if bridge_kind == "modal" else None
    rec = NodeRecorder([n_elements // 2 + 1, n_elements // 4 + 1], [2, 3], "disp")
    acc = NodeRecorder([n_elements // 2 + 1], [2], "accel")
    vtsi.TransientAnalysis(model, integrator, dt=dt, recorders=[rec, acc], bridge=bridge).run(n_steps)
    return rec.values.copy(), acc.values.copy()


@pytest.mark.parametrize("integrator", ["Newmark", HHT(0.9), "Bathe", GeneralizedAlpha(0.9, 0.7)],
                         ids=["Newmark", "HHT", "Bathe", "GeneralizedAlpha"])
def test_all_modes_equal_the_fe_bridge_s1(integrator):
    """Measured: max difference / max value 5e-13 (displacements), 4e-11 (accelerations, which
    the stiff axial and high bending modes carry at Newmark's Δt)."""
    fe_u, fe_a = run_s1("fe", integrator)
    mo_u, mo_a = run_s1("modal", integrator)
    assert np.max(np.abs(mo_u - fe_u)) <= 1e-9 * np.max(np.abs(fe_u))
    assert np.max(np.abs(mo_a - fe_a)) <= 1e-9 * np.max(np.abs(fe_a))


def s5_ice3(bridge_kind, contact, interpolation, integrator="Newmark", n_steps=700, dt=1e-3, n_modes=None):
    """The 8-car ICE3 of 10-dof cars entering the S5 viaduct (10 elements per span) at 300 km/h
    from rigid ground, with the deck's self weight, Rayleigh 2 %; the modal bridge keeps
    ``n_modes`` (default: all)."""
    model = vtsi.Model()
    bridge = s5_viaduct(model, elements_per_span=10)
    rayleigh_damping(model, 0.02)
    track = Track(model, bridge.elements)
    train = catalogue_train("ICE3", 300.0 / 3.6, fidelity="full")
    con = MovingLoadConstraint(track, TrainSubdomain(train, -1.0), interpolation=interpolation)
    n_modes = "all" if n_modes is None else n_modes
    modal = ModalBridge(model, track, n_modes=n_modes) if bridge_kind == "modal" else None
    mid = NodeRecorder([6, 16], [2], "disp")
    an = CoupledAnalysis(model, con, integrator, dt=dt, contact=contact, bridge_self_weight=True,
                         recorders=[mid], bridge=modal)
    an.static()
    an.run(n_steps)
    return an.contact_force.copy(), mid.values.copy(), an.train.u.copy()


@pytest.mark.parametrize("contact, interpolation, integrator", [
    ("bilateral", "hermite", "Newmark"), ("lcp", "bspline", HHT(0.9)), ("bilateral", "hermite", "Bathe"),
    ("lcp", "bspline", GeneralizedAlpha(0.9, 0.7))],
    ids=["bilateral-hermite-Newmark", "lcp-bspline-HHT", "bilateral-hermite-Bathe", "lcp-bspline-GeneralizedAlpha"])
def test_all_modes_equal_the_fe_bridge_s5(contact, interpolation, integrator):
    """Measured: 3e-13 or less relative on the contact forces, the deck and the train
    (generalized-α: 1.3e-13, 7.4e-14, 1e-15)."""
    fe = s5_ice3("fe", contact, interpolation, integrator)
    mo = s5_ice3("modal", contact, interpolation, integrator)
    for a, b in zip(fe, mo):
        assert np.max(np.abs(b - a)) <= 1e-9 * np.max(np.abs(a))


@pytest.mark.parametrize("integrator", [HHT(0.9), "Bathe"], ids=["HHT", "Bathe"])
def test_few_modes_low_rank_contact_solve_equals_the_factored_one(integrator):
    """With 4 modes and up to 20 wheels coupled through the deck, the bilateral contact forces
    come from the Woodbury form of W⁻¹ (vtsi.coupled_loop._solve_low_rank); the LCP builds W from
    the wheels' modal rows and factors it. No wheel lifts off here, so both give the same λ, deck
    and train, with one stage (HHT) and two (Bathe: each stage its own K̂ and inverse car
    blocks). Measured: 4e-15 (HHT) and 1e-15 (Bathe) relative on λ, 2e-16 on the deck, 2e-18 on
    the train."""
    low_rank = s5_ice3("modal", "bilateral", "hermite", integrator, n_modes=4)
    factored = s5_ice3("modal", "lcp", "hermite", integrator, n_modes=4)
    assert np.min(factored[0]) > 0.0                    # in contact throughout: the LCP is the bilateral problem
    for a, b in zip(factored, low_rank):
        assert np.max(np.abs(b - a)) <= 1e-9 * np.max(np.abs(a))


def test_modal_stepping_converges_to_the_exact_passage_at_second_order():
    """A 12-axle train of moving forces over a 20 m span, 4 modes, ζ = 1.5 %: the coupled loop's
    Newmark on the modal bridge against the exact modal passage at the same output times; the
    error of the mid-span displacement falls by 4 per halving of Δt."""
    model = vtsi.Model()
    beam = simply_supported_beam(model, 20.0, 16, 3.0e10, 1.2, 15000.0)
    track = Track(model, beam.elements)
    modal = ModalBridge(model, track, n_modes=8, zeta=0.015)
    train = catalogue_train("HSLM-A1", 250.0 / 3.6)
    t_end = 1.2
    mid_dof = model.build().free_of_full[model.build().full_dof(9, 2)]
    exact_at = {}
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        n = int(round(t_end / dt))
        x_head0 = -0.5
        q, _, _ = modal.coordinates(train.wheel_offsets, train.static_wheel_loads, train.speed, x_head0, n, dt)
        exact_at[dt] = q @ modal.shapes[model.build().full_of_free][mid_dof]
        model.state = None
        con = MovingLoadConstraint(track, TrainSubdomain(train, x_head0))
        rec = NodeRecorder([9], [2], "disp")
        CoupledAnalysis(model, con, "Newmark", dt=dt, recorders=[rec], bridge=modal).run(n)
        errors.append(np.max(np.abs(rec.values[:, 0] - exact_at[dt])) / np.max(np.abs(exact_at[dt])))
    assert errors[-1] < 1e-3
    for coarse, fine in zip(errors, errors[1:]):
        assert 3.2 < coarse / fine < 4.8


def test_a_ratio_per_mode_decays_at_its_rate():
    """Three modes released from q_j = 1 (at rest) with ζ = 1 %, 3 %, 5 %: the logarithmic decrement
    of each mode's recorded free decay over 6 periods (Bathe, 200 steps per period, whose own
    numerical damping is ~1e-7 there) gives its ζ within 1e-4 absolute."""
    model = vtsi.Model()
    simply_supported_beam(model, 20.0, 16, 3.0e10, 1.2, 15000.0, A=100.0)   # axial modes above 170 Hz
    zeta = [0.01, 0.03, 0.05]
    modal = ModalBridge(model, n_modes=3, zeta=zeta)
    asm = model.build()
    state = vtsi.domain_state(model)
    for j in range(3):
        state.u[:] = modal.shapes[:, j]
        state.v[:] = 0.0
        state.a[:] = -modal.omega[j] ** 2 * modal.shapes[:, j]
        state.time = 0.0
        period = 2 * np.pi / modal.omega[j]
        dt = period / 200
        node = 5                                    # quarter span: every one of the three modes moves it
        rec = NodeRecorder([node], [2], "disp")
        vtsi.TransientAnalysis(model, "Bathe", dt=dt, recorders=[rec], bridge=modal).run(200 * 6)
        y = rec.values[:, 0] / modal.shapes[asm.full_dof(node, 2), j]
        peaks = [k for k in range(1, len(y) - 1) if y[k] > y[k - 1] and y[k] >= y[k + 1]]
        ratio = y[peaks[0]] / y[peaks[-1]]
        delta = math.log(ratio) / (len(peaks) - 1)
        measured = delta / math.sqrt(4 * math.pi ** 2 + delta ** 2)
        assert measured == pytest.approx(zeta[j], abs=1e-4)


def test_the_model_damping_must_be_classical_and_the_model_unchanged():
    model = vtsi.Model()
    simply_supported_beam(model, 20.0, 8, 3.0e10, 1.2, 15000.0)
    model.rayleigh(0.1, 1e-4)
    modal = ModalBridge(model, n_modes=4)       # Rayleigh: ζ from ΦᵀCΦ
    omega = modal.omega
    assert modal.zeta == pytest.approx(0.1 / (2 * omega) + 1e-4 * omega / 2, rel=1e-9)
    with pytest.raises(ModelError, match="damping ratios must be finite"):
        ModalBridge(model, n_modes=4, zeta=[0.01, 0.02])
    with pytest.raises(ModelError, match="f_max or n_modes"):
        ModalBridge(model, f_max=30.0, n_modes=4)
    model.node(99, 30.0, 0.0)
    model.fix(99, 1, 1, 1)
    model.element("elasticBeamColumn", 99, (9, 99), A=1.0, E=3.0e10, I=1.2, rho=15000.0)
    with pytest.raises(AnalysisError, match="model changed"):
        vtsi.TransientAnalysis(model, "Newmark", dt=1e-3, bridge=modal).run(1)


def test_every_mode_of_a_lumped_mass_deck():
    """Lumped mass (none on the rotations): 'every mode' (a modal_hz far above the model) is as
    many modes as dofs carry mass, 18 of 30 free dofs here, of which the 9 vertical ones move
    the track; it was refused ('only 18 dofs carry mass, 30 modes requested'). They equal the
    dense generalized eigenproblem's finite eigenvalues. With 15 of 90 (between two doublings
    of the search) too."""
    import scipy.linalg
    model = vtsi.Model()
    deck = simply_supported_beam(model, 20.0, 10, 3.5e10, 1.0, 0.0)       # no element mass
    for node in deck.nodes[1:-1]:
        model.mass(node, 30000.0, 30000.0, 0.0)
    modal = ModalBridge(model, Track(model, deck.elements), 1e7)
    asm = model.build()
    omega2 = 1.0 / np.sort(scipy.linalg.eigh(asm.M.toarray(), asm.K.toarray(), eigvals_only=True))[::-1][:18]
    assert modal.n_modes == 9 and asm.n_free == 30
    assert np.all(np.min(np.abs(modal.omega[:, None] ** 2 / omega2[None, :] - 1.0), axis=1) < 1e-9)
    sparse = vtsi.Model()                 # 15 vertical masses on 90 free dofs: between two doublings
    for node in simply_supported_beam(sparse, 30.0, 30, 3e10, 1.0, 0.0).nodes[1:-1:2]:
        sparse.mass(node, 0.0, 1000.0, 0.0)
    assert len(modes_up_to(sparse, 1e6)[0]) == 15


def test_an_explicit_integrator_is_held_to_the_highest_kept_mode():
    """Central differences on a modal bridge: stable up to Δt = 2/ω_max of the kept modes (far
    above the FE bridge's limit), refused beyond it with a message naming the limit."""
    model = vtsi.Model()
    simply_supported_beam(model, 20.0, 16, 3.0e10, 1.2, 15000.0)
    modal = ModalBridge(model, n_modes=3, zeta=0.0)
    limit = 2.0 / modal.omega.max()
    with pytest.raises(AnalysisError, match="stability limit"):
        vtsi.TransientAnalysis(model, "CentralDifference", dt=1.01 * limit, bridge=modal).run(1)
    vtsi.TransientAnalysis(model, "CentralDifference", dt=0.99 * limit, bridge=modal).run(10)


def test_n_modes_counts_the_modes_that_move_the_track():
    """``n_modes`` keeps the lowest modes that move the track: a 20 m beam's axial mode lies
    between its vertical ones and was counted, then dropped (n_modes = 3 kept 2). Now three
    vertical modes, f_j = j² f₁; asking more than the model has that move the track is refused
    naming both counts."""
    model = vtsi.Model()
    deck = simply_supported_beam(model, 20.0, 10, 3.5e10, 0.6948, 15000.0)
    track = Track(model, deck.elements)
    modal = ModalBridge(model, track, n_modes=3, zeta=0.01)
    assert modal.n_modes == 3
    assert modal.frequencies / modal.frequencies[0] == pytest.approx([1.0, 4.0, 9.0], rel=0.02)
    lumped = vtsi.Model()
    bare = simply_supported_beam(lumped, 20.0, 10, 3.5e10, 0.6948, 0.0)
    for node in bare.nodes[1:-1]:
        lumped.mass(node, 15000.0, 15000.0, 0.0)
    with pytest.raises(ModelError, match=r"^modal bridge: n_modes = 12, but only 9 modes of the model move the track"):
        ModalBridge(lumped, Track(lumped, bare.elements), n_modes=12, zeta=0.01)


def test_a_basis_below_the_first_mode_and_bad_ratios_are_refused():
    """f_max below the first mode kept that mode, and a sweep's modal_hz = 1 Hz ran with a 5 Hz
    mode; ζ = True was taken as 1 (critical)."""
    model = vtsi.Model()
    deck = simply_supported_beam(model, 20.0, 10, 3.5e10, 0.6948, 15000.0)
    track = Track(model, deck.elements)
    with pytest.raises(ModelError, match=r"^modal bridge: f_max = 1 Hz is below the first mode \(5 Hz\)"):
        ModalBridge(model, track, f_max=1.0, zeta=0.01)
    with pytest.raises(ModelError, match=r"^modal bridge: damping ratios must be numbers, got True$"):
        ModalBridge(model, track, zeta=True)


def test_a_modal_sweeps_settings_are_refused_before_anything_runs(tmp_path):
    """A modal_hz below the first mode, the model's Rayleigh damping overdamping a mode of the
    exact passages' basis (it failed at the first case, leaving a file), a flag given as text
    ('no' acted as True) and a modal_hz with the FE bridge (ignored) are refused when the sweep
    is built, naming the setting."""
    from vtsi.errors import SweepError
    from vtsi.passage import PassageSettings
    from vtsi.sweep import Sweep, beam_bridge
    with pytest.raises(SweepError, match=r"^sweep: modal_hz = 1 Hz is below the bridge's first frequency \(5 Hz\)"):
        Sweep(beam_bridge([20.0], 3.5e10, 0.6948, 15000.0), ["HSLM-A1"], "300",
              PassageSettings(bridge="modal", modal_hz=1.0, damping=0.013))
    overdamped = beam_bridge([20.0], 3.5e10, 0.6948, 15000.0, elements_per_span=40, damping=0.013)
    with pytest.raises(SweepError, match=r"^sweep: modal bridge: mode \d+ \(\d+ Hz\) has ζ = 1\.\d+ >= 1"):
        Sweep(overdamped, ["HSLM-A1"], "300", PassageSettings(bridge="modal", modal_hz=20000.0))
    assert not list(tmp_path.iterdir())
    with pytest.raises(ModelError, match=r"^sweep settings: static_correction must be True or False, got 'no'$"):
        PassageSettings(bridge="modal", static_correction="no")
    with pytest.raises(ModelError, match=r"^sweep settings: exact_events must be True or False, got 1$"):
        PassageSettings(exact_events=1)
    with pytest.raises(ModelError, match=r"^sweep settings: modal_hz = 30\.0 is the modal bridge's highest frequency, "
                                         r"and bridge is 'fe'"):
        PassageSettings(bridge="fe", modal_hz=30.0)


def test_a_scripts_modal_damping_reaches_the_modal_bridge_of_a_sweep(tmp_path, deck_script):
    """A bridge script's ``modalDamping`` (ratios of its eigen modes) was dropped by sweeps: the
    passages ran undamped (43.9 m/s² where 2 % gives 16.6). The modal bridge now adds each ratio to
    the kept mode of its frequency (a 20 m beam's eigen(4) holds an axial mode, not kept: its ratio
    goes nowhere); the FE bridge, which steps Rayleigh damping, refuses them; the sweep's own
    damping replaces them, as it replaces the script's rayleigh."""
    from vtsi.bridge_file import script_bridge
    from vtsi.errors import SweepError
    from vtsi.passage import PassageSettings
    from vtsi.sweep import Sweep
    path = tmp_path / "deck.py"
    path.write_text(deck_script(0.6948, "omega2 = ops.eigen(4)\nops.modalDamping(0.02, 0.01, 0.03, 0.04)\n"))
    bridge = script_bridge(path)
    assert [z for _, z in bridge.modal_damping] == [0.02, 0.01, 0.03, 0.04]
    ratio_of = dict(bridge.modal_damping)
    modal = Sweep(bridge, ["HSLM-A1"], "300", PassageSettings(bridge="modal")).runner.modal
    for f, zeta in zip(modal.frequencies, modal.zeta):
        near = [g for g in ratio_of if abs(g - f) <= 1e-6 * f]
        assert zeta == (ratio_of[near[0]] if near else 0.0)
    assert sum(z > 0 for z in modal.zeta) == 3                  # the 4th eigen mode is axial: not kept
    with pytest.raises(SweepError, match=r"^sweep: the bridge's modalDamping \(0\.02, 0\.01, 0\.03, 0\.04\) damps its modes: "
                                         r"the FE bridge steps Rayleigh damping only"):
        Sweep(bridge, ["HSLM-A1"], "300", PassageSettings())
    replaced = Sweep(bridge, ["HSLM-A1"], "300", PassageSettings(bridge="modal", damping=0.015)).runner.modal
    assert np.all(replaced.zeta == 0.015)
