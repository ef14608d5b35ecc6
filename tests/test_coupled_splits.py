"""A coupled analysis split into runs of any length gives one run's numbers to the bit
(CoupledAnalysis.run; docs/theory/coupled_step.md §5, "Runs split anywhere").

- A run that starts where the last one ended continues its count of steps: the same chunks,
  stage times and rows, so runs of 17, 33, 250, ... steps, splits at a chunk boundary and across
  one, give one run's records, recorder values and states exactly: FE bridge with Newmark, HHT
  and Bathe, bilateral and LCP contact (wheels in flight over a dip), Hermite and B-spline rows,
  kink crossings taken at their own time (``exact_events``), an irregular rail and the deck's
  self-weight sag.
- The smoothed irregularity of B-spline rows at a position does not depend on the range it was
  tabulated over, and it is the convolution it stands for (closed form on a sine).
- A modal bridge goes on from the modal coordinates it committed, and from a state changed
  between two runs as the FE bridge does.
- Changing the recorders between two runs changes nothing; a run after a change of the
  patterns counts its steps from its own start.
- A negative car offset and a time step that does not resolve the passage are refused.
"""
import numpy as np
import pytest

import vtsi
from vtsi.analysis import domain_state
from vtsi.constraint import MovingLoadConstraint, SmoothedProfile
from vtsi.coupled import STEPS_ON_TRACK, CoupledAnalysis
from vtsi.damping import rayleigh_damping
from vtsi.errors import AnalysisError, ModelError
from vtsi.integrators import HHT, Newmark
from vtsi.modal_bridge import ModalBridge
from vtsi.models import Irregularity, Train, four_dof_car
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders import ContactRecorder, NodeRecorder, TrainRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain

DT, SPAN, SPEED = 1e-3, 20.0, 40.0     # [s], [m] (10 elements), [m/s]
CHUNK, STEPS = 300, 850                # chunk_steps, steps of each run
SPLITS = {"17-33-250-300-250": [17, 33, 250, 300, 250],     # 300 and 600: splits at the chunk boundaries
          "290-20-1-539": [290, 20, 1, 539],                # 290 -> 310 across the first boundary
          "7-123-299-1-420": [7, 123, 299, 1, 420]}         # 130 -> 429, 430 -> 850 across both


def dip_rail():
    """A sampled rail with a 2 cm, 1 m cosine dip from x = 6 m: LCP wheels fly over it."""
    x = np.linspace(-40.0, 80.0, 4801)
    inside = (x >= 6.0) & (x <= 7.0)
    return Irregularity(x, np.where(inside, -0.01 * (1.0 - np.cos(2.0 * np.pi * (x - 6.0))), 0.0))


def passage(contact="bilateral", interpolation="hermite", integrator="Newmark", exact_events=False,
            self_weight=False, modal=None, dt=DT):
    """A 20 m span of 2 % Rayleigh damping (its ends kinks of the rail), two four-dof cars entering
    from the ground over the dip, the bridge's, train's and contact recorders; at its dead-load
    state. ``modal``: None (the FE bridge) or the modes of a ModalBridge ('all': with every mode,
    the FE bridge's equations)."""
    model = vtsi.Model()
    bridge = simply_supported_beam(model, SPAN, 10, 3.0e10, 0.6, 1.2e4)
    rayleigh_damping(model, 0.02)
    car = four_dof_car(3.0e4, 1.5e6, 1.5e3, 1.0e6, 2.0e4, 8.0)
    sub = TrainSubdomain(Train([car, car], [0.0, 12.0], SPEED), -1.0)
    track = Track(model, bridge.elements)
    con = MovingLoadConstraint(track, sub, dip_rail(), interpolation)
    recorders = [NodeRecorder(bridge.midspan_nodes, [2], "disp"), NodeRecorder(bridge.midspan_nodes, [2], "accel"),
                 TrainRecorder(sub, ["car0.body_y", "car1.wheel2_y"], "accel"),
                 ContactRecorder(con, None, "force"), ContactRecorder(con, None, "gap")]
    analysis = CoupledAnalysis(model, con, integrator, dt, contact=contact, recorders=recorders,
                               exact_events=exact_events, chunk_steps=CHUNK, bridge_self_weight=self_weight,
                               bridge=None if modal is None else ModalBridge(model, track, n_modes=modal))
    analysis.static()
    return analysis, recorders


def outcome(analysis, recorders, sizes):
    """Everything the runs of ``sizes`` steps leave: records, recorder values and times, states."""
    for n in sizes:
        analysis.run(n)
    state, train = domain_state(analysis.model), analysis.train
    out = {"time": analysis.time, "force": analysis.contact_force, "end": analysis.contact_force_end,
           "gap": analysis.gap, "u": state.u, "v": state.v, "a": state.a, "t": np.array([state.time]),
           "train": np.concatenate([train.u, train.v, train.a])}
    for k, rec in enumerate(recorders):
        out[f"recorder {k}"], out[f"recorder {k} time"] = rec.values, rec.time
    return out


def assert_splits_equal_one_run(**kwargs):
    """Each of SPLITS gives one run of STEPS steps' outcome, every array to the bit."""
    one = outcome(*passage(**kwargs), [STEPS])
    assert one["time"].shape == (STEPS,)
    for name, sizes in SPLITS.items():
        assert sum(sizes) == STEPS
        split = outcome(*passage(**kwargs), sizes)
        assert split.keys() == one.keys()
        for key in one:
            assert np.array_equal(split[key], one[key]), (name, key)
    return one


CASES = [(contact, interpolation, integrator, events)
         for contact, integrators in (("bilateral", ("Newmark", "HHT", "Bathe")), ("lcp", ("Newmark", "HHT", "Bathe")))
         for integrator in integrators
         for interpolation, events in (("hermite", False), ("hermite", True), ("bspline", False))]
SCHEMES = {("bilateral", "Newmark"): "Newmark", ("lcp", "Newmark"): Newmark(0.6, 0.3025),     # LCP: dissipative
           ("bilateral", "HHT"): HHT(0.9), ("lcp", "HHT"): HHT(0.9), ("bilateral", "Bathe"): "Bathe",
           ("lcp", "Bathe"): "Bathe"}


@pytest.mark.parametrize("contact, interpolation, integrator, exact_events", CASES,
                         ids=[f"{c}-{i}-{g}{'-events' if e else ''}" for c, i, g, e in CASES])
def test_runs_split_anywhere_equal_one_run(contact, interpolation, integrator, exact_events):
    one = assert_splits_equal_one_run(contact=contact, interpolation=interpolation,
                                      integrator=SCHEMES[contact, integrator], exact_events=exact_events)
    if contact == "lcp":
        assert np.any(one["gap"] > 0.0)            # the dip made wheels fly


def test_runs_split_anywhere_equal_one_run_with_the_self_weight_sag():
    """The rail measured from the deck's self-weight deflection (its sag in every row)."""
    assert_splits_equal_one_run(interpolation="bspline", self_weight=True)


def test_a_recorder_added_between_two_runs_changes_nothing():
    """The runs 290 + 560 with a recorder of the midspan deflection added between them give one
    run's records and states, and the new recorder holds that run's deflection of its steps."""
    one, recorders = passage()
    one.run(STEPS)
    split, _ = passage()
    split.run(290)
    added = NodeRecorder(recorders[0].nodes, [2], "disp")
    split.recorders = split.recorders + [added]
    split.run(STEPS - 290)
    for name in ("time", "contact_force", "contact_force_end", "gap"):
        assert np.array_equal(getattr(split, name), getattr(one, name)), name
    assert np.array_equal(domain_state(split.model).u, domain_state(one.model).u)
    assert np.array_equal(added.values, recorders[0].values[290:])


@pytest.mark.parametrize("contact", ["bilateral", "lcp"])
def test_a_modal_bridge_split_anywhere_equals_one_run(contact):
    """Its runs go on from the modal coordinates q the last one committed (reloading them as
    Φᵀ M u from the state it wrote gives them back to round-off only)."""
    assert_splits_equal_one_run(contact=contact, integrator=HHT(0.9), modal=6)


def test_a_modal_bridge_reads_a_state_changed_between_two_runs():
    """The deck's velocity set to 0 between two runs: the modal bridge of every mode goes on from
    that state as the FE bridge does (whose equations it steps, to round-off), not from the
    modal coordinates it committed."""
    deflections = []
    for modal, change in ((None, True), ("all", True), ("all", False)):
        analysis, (deck, *_) = passage(modal=modal)
        analysis.run(200)
        if change:
            domain_state(analysis.model).v[:] = 0.0
        analysis.run(100)
        deflections.append(deck.values[:, 0])
    fe, modal, unchanged = deflections
    scale = np.abs(fe).max()
    assert np.abs(modal - unchanged).max() > 1e-2 * scale          # the change shows
    assert np.abs(modal - fe).max() < 1e-9 * scale


def test_a_run_counts_on_from_the_last_and_afresh_after_a_change():
    """The steps' end times: a run that starts where the last ended continues its count (chunks
    of CHUNK steps from t = 0: t = k Δt, then 300 Δt + k Δt); after a change of the load
    patterns a run counts from its own start t_137: t_137 + k Δt (k <= CHUNK)."""
    analysis, _ = passage()
    analysis.run(137)
    analysis.run(400)
    k = np.arange(1, 538)
    expected = np.where(k <= CHUNK, DT * k, CHUNK * DT + DT * (k - CHUNK))
    assert np.array_equal(analysis.time, expected)
    analysis, _ = passage()
    analysis.run(137)
    start = domain_state(analysis.model).time
    analysis.model.add_time_series(vtsi.Constant(1.0, tag=90))
    analysis.model.pattern(90, 90)
    analysis.model.load(90, 4, 0.0, -5e4, 0.0)
    analysis.run(250)
    assert np.array_equal(analysis.time[137:], start + DT * np.arange(1, 251))


def test_the_smoothed_rail_at_a_position_does_not_depend_on_the_range_asked():
    """r̃ and its rate under the wheels at the stage times of steps 160..209 (the head over the
    dip), asked in a block of 512 steps, in those 50 steps and step by step, each by an analysis
    of its own (its table over the range it asked), are the same to the bit."""
    t = DT * np.arange(160, 210, dtype=float)
    asked = {"block": lambda con, nu: con.irregularity_at(DT * np.arange(0, 512, dtype=float), DT, nu)[160:210],
             "run": lambda con, nu: con.irregularity_at(t, DT, nu),
             "steps": lambda con, nu: np.concatenate([con.irregularity_at(t[k: k + 1], DT, nu) for k in range(50)])}
    for nu in (0, 1):
        values = {name: ask(passage(interpolation="bspline")[0].constraint, nu) for name, ask in asked.items()}
        assert np.abs(values["run"]).max() > 1e-3 * SPEED ** nu          # wheels in the dip
        assert np.array_equal(values["block"], values["run"]) and np.array_equal(values["steps"], values["run"])


def test_the_smoothed_rail_is_the_convolution_it_stands_for():
    """On a 3 m sine r = A sin Ωx (the shortest wave of vtsi's sample profiles) the convolution
    with B₃(ξ/κ)/κ is sinc⁴(Ωκ/2) r (the kernel's Fourier transform, docs/theory/constraints.md
    §4): the table gives r̃ and dr̃/dx to 2e-8 and 2e-7 of their amplitudes (measured 5.8e-9 and
    7.2e-8 at κ = 0.08 m; the quasi-interpolant's error at a node is (Ωκ/8)⁴/36 = 5.3e-9); two
    tables over different ranges give the same values to the bit."""
    amplitude, omega = 0.005, 2.0 * np.pi / 3.0
    rail = Irregularity.from_function(lambda x: amplitude * np.sin(omega * x),
                                      lambda x: amplitude * omega * np.cos(omega * x))
    knot = 2.0 * SPEED * DT
    wide = SmoothedProfile(rail, knot, 0.0, -10.0, 30.0)
    narrow = SmoothedProfile(rail, knot, 0.0, 4.0, 6.0)
    at = np.random.default_rng(7).uniform(4.0, 6.0, 200)
    gain = (np.sin(0.5 * omega * knot) / (0.5 * omega * knot)) ** 4
    for nu, exact, bound in ((0, amplitude * gain * np.sin(omega * at), 2e-8),
                             (1, amplitude * omega * gain * np.cos(omega * at), 2e-7)):
        assert np.abs(wide(at, nu) - exact).max() < bound * np.abs(exact).max()
        assert np.array_equal(wide(at, nu), narrow(at, nu))


def test_a_negative_car_offset_is_refused(one_line):
    model = vtsi.Model()
    bridge = simply_supported_beam(model, SPAN, 10, 3.0e10, 0.6, 1.2e4)
    car = four_dof_car(3.0e4, 1.5e6, 1.5e3, 1.0e6, 2.0e4, 8.0)
    sub = TrainSubdomain(Train([car, car], [-12.5, 0.0], SPEED), -1.0)
    with pytest.raises(ModelError) as excinfo:
        CoupledAnalysis(model, MovingLoadConstraint(Track(model, bridge.elements), sub), dt=DT)
    assert one_line(excinfo) == ("CoupledAnalysis: car 0 of train 'train' has the offset -12.5 m; car offsets are "
                                 "measured behind the train's head and must be >= 0")


@pytest.mark.parametrize("dt", [0.0505, 0.5, 2.0])
def test_a_time_step_that_does_not_resolve_the_passage_is_refused(one_line, dt):
    """The sweep's rule: an axle crosses the track in at least STEPS_ON_TRACK steps; here the
    train crosses the 20 m span in 0.5 s, so dt <= 0.05 s (a dt as long as the passage, 0.5 s,
    and longer, refused)."""
    analysis, _ = passage(dt=dt)
    with pytest.raises(AnalysisError) as excinfo:
        analysis.run(1)
    assert one_line(excinfo) == (f"CoupledAnalysis: dt = {dt:g} s does not resolve the passage: the train at "
                                 f"40 m/s crosses the 20 m track in 0.5 s, fewer than {STEPS_ON_TRACK} steps of dt; "
                                 "take dt <= 0.05 s")


def test_the_longest_time_step_that_resolves_the_passage_runs():
    analysis, _ = passage(dt=0.5 / STEPS_ON_TRACK)
    analysis.run(2)
    assert analysis.time.shape == (2,)
