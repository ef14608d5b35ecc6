"""Coupled-analysis defects a review found: NaN/inf divergence, massless wheels in the train's
stability check, dt or integrator changed between runs, HHT's λ_n after a new dead-load start,
reactions on a modal bridge that keeps every mode moving the track, divergence messages."""
import numpy as np
import pytest
import scipy.linalg

import vtsi
import vtsi.coupled
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, DivergenceError
from vtsi.integrators import HHT, Newmark
from vtsi.modal_bridge import ModalBridge
from vtsi.models import Train, sprung_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders import NodeRecorder, ReactionRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain
from vtsi.vehicle import moving_force

L, N_EL, E, I, MU = 20.0, 20, 3.5e10, 3.0, 2.0e4
NEWMARK_LIMIT = np.sqrt(12.0)      # Newmark(1/2, 1/6): Ω_max = 1/sqrt(γ/2 - β)


def _span():
    model = vtsi.Model()
    deck = simply_supported_beam(model, L, N_EL, E, I, MU)
    return model, deck, Track(model, deck.elements)


def _stiff_car_case(m_w=0.0, **kw):
    """A 1e5 kg body on a spring at 0.95 × Newmark(1/2, 1/6)'s limit (wheel held) over a one-mode bridge."""
    m_s, dt = 1e5, 1e-3
    k_s = m_s * (0.95 * NEWMARK_LIMIT / dt) ** 2
    model, deck, track = _span()
    con = MovingLoadConstraint(track, TrainSubdomain(Train([sprung_mass(m_s, k_s, m_w=m_w)], [0.0], 1.0),
                                                      x_head0=10.0))
    bridge = ModalBridge(model, track, n_modes=1)
    return CoupledAnalysis(model, con, Newmark(0.5, 1 / 6), dt, bridge=bridge, **kw), m_s, k_s, dt


def test_massless_wheel_takes_the_rails_mass():
    """The body on k_s over the modal mass μL/2 (mode 1 is 1 at mid-span): ω_max Δt = 4.03 > √12."""
    a, m_s, k_s, dt = _stiff_car_case()
    m_q, w_q = MU * L / 2, np.pi ** 2 / L ** 2 * np.sqrt(E * I / MU)
    K = np.array([[k_s, -k_s], [-k_s, k_s + m_q * w_q ** 2]])
    omega = np.sqrt(scipy.linalg.eigh(K, np.diag([m_s, m_q]), eigvals_only=True)[-1])
    assert omega * dt > NEWMARK_LIMIT > np.sqrt(k_s / m_s) * dt
    with pytest.raises(AnalysisError, match="stability limit") as err:
        a.static()
    given = float(str(err.value).split("omega_max = ")[1].split(" rad/s")[0])
    assert given == pytest.approx(np.sqrt(k_s * (1 / m_s + 1 / m_q)), rel=1e-5)   # body on the rail's mass
    assert given == pytest.approx(omega, rel=1e-4)                                 # K_q << k_s
    b, *_ = _stiff_car_case(m_w=1.0)         # a 1 kg wheel: its own ω = sqrt(k_s / 1 kg)
    with pytest.raises(AnalysisError, match="stability limit"):
        b.static()


def test_nan_and_inf_diverge_in_any_entry(monkeypatch):
    """The stiff car's check bypassed (only here) and no bound on |u|: the run blows up to inf,
    then NaN, which must stop it at the first step whose state is not finite."""
    monkeypatch.setattr(vtsi.coupled, "check_train_stability", lambda *args: None)
    a, *_ = _stiff_car_case(divergence_limit=np.inf)
    a.static()
    a.run(20)
    with pytest.raises(DivergenceError, match=r"of this run, t = .* \(NaN or inf\)") as err:
        a.run(2000)
    assert err.value.step > 1
    assert err.value.time == pytest.approx(0.02 + err.value.step * a.dt, rel=1e-12)
    assert np.all(np.isfinite(a.contact_force))          # every recorded step before it is finite
    assert len(a.time) == 20 + err.value.step - 1


def _sprung(integrator="Newmark", dt=1e-3):
    model, deck, track = _span()
    con = MovingLoadConstraint(track, TrainSubdomain(Train([sprung_mass(5e4, 2e6, 500.0, m_w=2e3)], [0.0], 30.0),
                                                      x_head0=-1.0))
    rec = NodeRecorder([deck.nodes[N_EL // 2]], [2], "disp")
    return CoupledAnalysis(model, con, integrator, dt, recorders=[rec]), rec


@pytest.mark.parametrize("change", ["dt", "integrator"])
def test_dt_or_integrator_assigned_between_runs(change):
    """The second run equals a new analysis's from the committed state, to the bit (Bathe's first
    recorded mean takes λ_n, which the new analysis has not: its end forces are compared there)."""
    a, _ = _sprung()
    a.static()
    a.run(100)
    integrator, dt = ("Newmark", 2e-3) if change == "dt" else ("Bathe", 1e-3)
    a.integrator, a.dt = integrator, dt
    ref, _ = _sprung()
    ref.static()
    ref.run(100)
    fresh = CoupledAnalysis(ref.model, ref.constraint, integrator, dt)
    a.run(60)
    fresh.run(60)
    assert np.array_equal(a.contact_force_end[-60:], fresh.contact_force_end)
    assert np.array_equal(a.contact_force[-59:], fresh.contact_force[1:])
    assert np.array_equal(a.time[-60:], fresh.time)
    assert repr(a.integrator) == repr(fresh.integrator)


def test_integrator_assigned_after_static_is_used():
    """HHT assigned after static(): the run is a new HHT analysis's, to the bit."""
    a, _ = _sprung()
    a.static()
    a.integrator = HHT(0.7)
    a.run(80)
    b, _ = _sprung(HHT(0.7))
    b.static()
    b.run(80)
    assert np.array_equal(a.contact_force, b.contact_force)


def test_new_dead_load_start_restarts_hht_forces():
    """static() again after a run: HHT's λ_n is the new state's start force (a fresh analysis's)."""
    fresh, _ = _sprung(HHT(0.8), 2e-3)
    fresh.static()
    fresh.run(30)
    again, _ = _sprung(HHT(0.8), 2e-3)
    again.static()
    again.run(100)
    vtsi.analysis.domain_state(again.model).time = 0.0
    again.static()
    again.run(30)
    assert np.array_equal(again.contact_force[-30:], fresh.contact_force)


def test_modal_bridge_of_every_track_mode_records_reactions():
    """n_modes='all' with a track drops the axial modes only: not truncated, reactions are statics."""
    P, x = 98100.0, 7.3
    model, deck, track = _span()
    mb = ModalBridge(model, track, n_modes="all")
    assert mb.off_track.shape[1] > 0 and not mb.truncated
    assert ModalBridge(model, track, n_modes=3).truncated
    con = MovingLoadConstraint(track, TrainSubdomain(Train([moving_force(P)], [0.0], 0.0), x_head0=x))
    rec = ReactionRecorder(deck.supports, [2])
    a = CoupledAnalysis(model, con, "Newmark", 1e-3, recorders=[rec], bridge=mb)
    a.static()
    a.run(3)
    assert rec.values[-1] == pytest.approx([P * (L - x) / L, P * x / L], rel=1e-9)


def test_modal_bridge_refuses_a_load_on_the_dropped_modes():
    """A horizontal nodal load on a straight deck only excites the axial modes dropped with the track."""
    model, deck, track = _span()
    mb = ModalBridge(model, track, n_modes="all")
    model.pattern(1, vtsi.Constant())
    model.load(1, deck.nodes[5], 1e3, 0.0, 0.0)
    with pytest.raises(AnalysisError, match="move no track dof"):
        vtsi.TransientAnalysis(model, "Newmark", 1e-3, bridge=mb).run(1)
