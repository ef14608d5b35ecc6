"""The public API keeps what its docstrings say: CoupledAnalysis refuses recorders as the other
analyses do, a sweep's settings and outputs raise the ModelError their docstrings and
docs/bad_inputs.md name, a Train's matrices are read-only, the main objects have one-line reprs
that say what they hold, ``vtsi.__all__`` holds the errors users catch, and a Track takes its
elements in any order."""
import numpy as np
import pytest

import vtsi
import vtsi.errors
import vtsi.models as Mo
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, ModelError, SweepError
from vtsi.modal_bridge import ModalBridge
from vtsi.models.bridges import first_frequency, simply_supported_beam
from vtsi.passage import Output, PassageSettings
from vtsi.recorders import NodeRecorder
from vtsi.sweep import Sweep, beam_bridge
from vtsi.track import Track
from vtsi.train import TrainSubdomain

CAR = dict(m_c=47800, J_c=1.96e6, m_w=7100, k_s=1.4e6, c_s=8e4, l_c=17.375)


def setup(irregularity=None):
    """A 30 m simply supported beam of 20 elements with one four-dof car at 300 km/h."""
    model = vtsi.Model()
    bridge = simply_supported_beam(model, L=30.0, n_elements=20, E=3.5e10, I=7.0, mu=3.0e4)
    train = TrainSubdomain(Mo.Train([Mo.four_dof_car(**CAR)], [0.0], speed=300 / 3.6), x_head0=-5.0)
    tie = MovingLoadConstraint(Track(model, bridge.elements), train, irregularity=irregularity)
    return model, bridge, tie


# -- 1. CoupledAnalysis refuses recorders as StaticAnalysis and TransientAnalysis do -------------
@pytest.mark.parametrize("recorders, message", [
    (NodeRecorder([2], [2]), r"^CoupledAnalysis: recorders must be a list of recorders, got NodeRecorder\(nodes=\[2\]"),
    ([5, "hello"], r"^CoupledAnalysis: recorders\[0\] is not a recorder \(NodeRecorder, ElementRecorder\.\.\.\), got 5$"),
    ("abc", r"^CoupledAnalysis: recorders must be a list of recorders, got 'abc'$"),
])
def test_coupled_analysis_refuses_what_is_not_a_list_of_recorders_when_built(recorders, message):
    model, _, tie = setup()
    with pytest.raises(AnalysisError, match=message):
        CoupledAnalysis(model, tie, dt=1e-3, recorders=recorders)


def test_coupled_analysis_takes_a_tuple_of_recorders_and_feeds_them():
    model, bridge, tie = setup()
    mid = NodeRecorder([bridge.midspan_nodes[0]], [2])
    analysis = CoupledAnalysis(model, tie, dt=1e-3, recorders=(mid,))
    analysis.static()
    analysis.run(5)
    assert analysis.recorders == [mid] and mid.values.shape == (5, 1) and np.all(np.isfinite(mid.values))


# -- 2. a sweep's settings and outputs are definitions: ModelError when made ----------------------
@pytest.mark.parametrize("make, message", [
    (lambda: PassageSettings(contact="x"), r"^sweep settings: unknown contact 'x'; valid: bilateral, lcp$"),
    (lambda: PassageSettings(dt=-1), r"^sweep settings: dt must be > 0 and finite, got -1$"),
    (lambda: PassageSettings(damping=1.3), r"^sweep settings: damping 1\.3 is 130 % of critical, above the 20 %"),
    (lambda: PassageSettings(irregularity="german-low"),
     r"^sweep settings: an irregular rail \(german-low\) acts through the wheels of cars; moving forces"),
    (lambda: Output("x", "strain"), r"^output 'x': unknown response 'strain'; valid: disp, vel, accel,"),
    (lambda: Output("x", "disp", nodes="middle"),
     r"^output 'x': nodes must be 'deck', 'track', 'midspan', 'supports', 'piers' or node tags, got 'middle'$"),
])
def test_sweep_settings_and_outputs_raise_a_model_error_when_made(make, message):
    with pytest.raises(ModelError, match=message) as caught:
        make()
    assert not isinstance(caught.value, SweepError)


def test_what_a_sweep_refuses_of_its_outputs_is_a_sweep_error_and_the_docs_say_which():
    bridge = beam_bridge([20.0], E=3.5e10, I=0.6948, mu=15000.0)
    with pytest.raises(SweepError, match=r"^sweep: output 'x': node 999 does not exist$"):
        Sweep(bridge, ["A1"], "200", outputs=[Output("x", "disp", nodes=(999,))])
    table = vtsi.__file__.replace("vtsi/__init__.py", "docs/bad_inputs.md")
    text = open(table).read()
    row = next(line for line in text.splitlines() if line.startswith("| `ModelError` |"))
    assert "`PassageSettings` and `Output`" in row
    assert "`ModelError: output 'x': unknown response 'strain'" in text
    assert "a :class:`~vtsi.errors.ModelError`, as every definition" in " ".join(Sweep.__doc__.split())


# -- 3. a Train's arrays, its sparse matrices' too, are read-only and shared by with_speed ---------
def test_train_matrices_are_read_only_and_shared_unchanged():
    car = Mo.four_dof_car(**CAR)
    train = Mo.Train([car, car], [0.0, 25.0], 10.0)
    copy = train.with_speed(20.0)
    before = {name: getattr(train, name).toarray() for name in "MCK"}
    for name in "MCK":
        matrix = getattr(train, name)
        assert getattr(copy, name) is matrix and matrix.has_canonical_format
        for part in ("data", "indices", "indptr"):
            with pytest.raises(ValueError, match="read-only"):
                getattr(matrix, part)[:1] *= 0
    for name in "MCK":
        np.testing.assert_array_equal(getattr(copy, name).toarray(), before[name])
    np.testing.assert_array_equal(train.K.toarray()[:4, :4], car.K)         # the first car's block
    np.testing.assert_allclose(train.K @ np.ones(8), np.tile(car.K.sum(axis=1), 2), atol=1e-6)   # scipy reads them


# -- 4. vtsi's namespace: the errors users catch, a map of the layers -----------------------------
def test_vtsi_all_holds_every_error_class_and_the_docstring_maps_the_layers():
    errors = {name for name, value in vars(vtsi.errors).items()
              if isinstance(value, type) and issubclass(value, vtsi.errors.VtsiError)}
    assert errors == {"VtsiError", "ModelError", "AnalysisError", "DivergenceError", "CommandError", "RecorderError",
                      "SweepError", "SettingError", "PassageError", "BridgeError", "BridgeModelError",
                      "BridgeSweepError"}
    assert errors <= set(vtsi.__all__)
    assert all(getattr(vtsi, name) is getattr(vtsi.errors, name) for name in errors)
    for name in ("vtsi.coupled.CoupledAnalysis", "vtsi.track.Track", "vtsi.train.TrainSubdomain",
                 "vtsi.constraint.MovingLoadConstraint", "vtsi.modal_bridge.ModalBridge", "vtsi.sweep.Sweep",
                 "vtsi.check.check", "vtsi.workflow.design_check", "vtsi.opensees"):
        assert name in vtsi.__doc__, name


# -- 5. one-line reprs that say what an object holds ----------------------------------------------
def test_reprs_are_one_line_and_name_counts_and_parameters():
    x = np.linspace(-50.0, 60.0, 221)
    irregularity = Mo.Irregularity(x, 2e-3 * np.sin(x))
    model, bridge, tie = setup(irregularity)
    analysis = CoupledAnalysis(model, tie, dt=1e-3, recorders=[NodeRecorder([bridge.midspan_nodes[0]], [2])])
    analysis.static()
    analysis.run(4)
    modal = ModalBridge(model, tie.track, zeta=0.01, n_modes=3)
    expected = {
        model: "Model(ndm=2, ndf=3: 21 nodes, 20 elements (20 elasticBeamColumn), 2 fixed nodes, 0 constrained "
               "dofs, 0 time series, 0 load patterns)",
        tie.track: "Track(20 elements, x = 0 to 30 m, 40 track dofs)",
        tie.train: "TrainSubdomain(Train('train', 1 cars, 2 wheels, 4 dofs, V = 83.33 m/s), x_head0 = -5 m, "
                   "2 contact wheels, 0 force wheels)",
        irregularity: f"Irregularity(221 samples, x = -50 to 60 m (zero outside), max |r| = "
                      f"{2 * np.abs(np.sin(x)).max():.3g} mm)",
        tie: f"MovingLoadConstraint(train 'train': 2 contact + 0 force wheels on track x = 0 to 30 m, hermite rows, "
             f"rail {irregularity!r})",
        analysis: "CoupledAnalysis(train 'train' on 20 track elements, Newmark(gamma=0.5, beta=0.25), dt = 0.001 s, "
                  "contact='bilateral', 4 steps to t = 0.004 s, 1 recorders)",
        Mo.four_dof_car(**CAR): "Car('four-dof car', four_dof, 4 dofs, 2 wheels, 62 t)",
        Mo.moving_force(1e5): f"Car('moving force', moving_force, 0 dofs, 1 wheels, {1e5 / 9.81e3:.4g} t)",
        Mo.Irregularity.from_function(np.sin): "Irregularity(r(x) = sin)",
    }
    for obj, text in expected.items():
        assert repr(obj) == text
    f = modal.frequencies
    assert repr(modal) == (f"ModalBridge(3 modes, {f[0]:.4g} to {f[2]:.4g} Hz, ζ = 0.01, truncated, "
                           "track x = 0 to 30 m)")
    assert abs(f[0] - np.pi / (2 * 30.0 ** 2) * np.sqrt(3.5e10 * 7.0 / 3.0e4)) < 0.01 * f[0]    # n0 of the beam


def test_sweep_and_results_reprs_name_their_cases():
    bridge = beam_bridge([20.0], E=3.5e10, I=0.6948, mu=15000.0)
    sweep = Sweep(bridge, ["A1", "HSLM-A2", "A3", "A4", "A5"], "200:300:50")
    assert repr(sweep) == ("Sweep(5 trains (HSLM-A1, HSLM-A2, HSLM-A3, ...) x 3 speeds 200 to 300 km/h x a smooth "
                           "rail = 15 cases, bridge beam (10 track elements), cars='force', contact='bilateral', "
                           "bridge='fe', dt = 0.00025 s, 6 outputs)")     # 45 Hz at ζ = 0.5 %: √0.006/(2π 45) s
    results = Sweep(bridge, ["A1"], [250.0]).run(None, workers=1)
    n0 = results.frequencies_hz[0]
    assert repr(results) == ("SweepResults(in memory: 1 of 1 trains (HSLM-A1) x 1 speeds 250 to 250 km/h x a smooth "
                             f"rail = 1 cases done, n0 = {n0:.4g} Hz)")
    assert abs(n0 - first_frequency(20.0, 3.5e10, 0.6948, 15000.0)) < 1e-3 * n0     # the 20 m beam's 5 Hz


# -- 6. a Track takes its elements in any order, and sorts them along +x -------------------------
def test_track_sorts_its_elements_along_x():
    model = vtsi.Model()
    bridge = simply_supported_beam(model, L=30.0, n_elements=4, E=3.5e10, I=7.0, mu=3.0e4)
    track = Track(model, bridge.elements[::-1])
    assert track.elements == list(bridge.elements) and track.x_start.tolist() == [0.0, 7.5, 15.0, 22.5]
    assert "in any order" in " ".join(Track.__doc__.split())
    first, _, third, _ = bridge.elements
    with pytest.raises(ModelError, match=rf"^track: elements {first} and {third} leave a gap or overlap between "
                                         r"x = 7\.5 and 15$"):
        Track(model, [third, first])
