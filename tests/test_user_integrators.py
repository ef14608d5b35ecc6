"""User integrators and user recorders through their contracts (integrators/base.py,
vtsi/recorders/base.py): a scheme or recorder that breaks its contract is refused once, when an
analysis prepares it, with an error naming it and the rule it breaks, instead of crashing the
compiled loop, running to a wrong answer or failing deep in a sink; one that keeps it (a
Wilson-θ written by a user) runs from the Python API and from the ``integrator`` command.

The broken schemes are the ones a probe wrote (one of each mistake). None is registered at import
time: tests/test_integrator_contract.py is parametrised over the registry when it is collected,
and the registrations made here are undone by the fixtures.
"""
import re
import subprocess
import sys
import textwrap

import h5py
import numpy as np
import pytest

import vtsi
from vtsi.analysis import StaticAnalysis, domain_state
from vtsi.errors import AnalysisError, CommandError, ModelError
from vtsi.integrators import INTEGRATORS, Bathe, Integrator, Newmark, Stage, make_integrator, register
from vtsi.recorders import HDF5Sink, NodeRecorder
from vtsi.recorders.base import Recorder
from vtsi.timeseries import Constant

K, MASS, P = 4.0e6, 1000.0, -1000.0        # oscillator [N/m], [kg], step load [N]
U_STATIC = P / K


def oscillator(series=None):
    """A one-dof oscillator: node 2 on a vertical zeroLength spring K with mass MASS, loaded by P
    (a Constant series unless given) at uy."""
    model = vtsi.Model()
    model.node(1, 0.0, 0.0)
    model.node(2, 0.0, 0.0)
    model.fix(1, 1, 1, 1)
    model.fix(2, 1, 0, 1)
    model.element("zeroLength", 1, (1, 2), ky=K)
    model.mass(2, MASS, MASS, 0.0)
    model.pattern(1, series or Constant(1.0))
    model.load(1, 2, 0.0, P, 0.0)
    return model


def run(integrator, n=50, dt=1e-3, **kwargs):
    rec = NodeRecorder([2], [2])
    vtsi.TransientAnalysis(oscillator(), integrator, dt, recorders=[rec], **kwargs).run(n)
    return rec


class _Trapezoid(Integrator):
    """Newmark's trapezoidal rule written out (a base for the broken variants)."""
    n_stages = 1

    def _update(self, dt):
        du = self.coefficients(u_n=1.0, v_n=dt, a_n=dt * dt / 4, a=dt * dt / 4)
        dv = self.coefficients(v_n=1.0, a_n=dt / 2, a=dt / 2)
        return du, dv

    def stages(self, dt):
        du, dv = self._update(dt)
        return [Stage(du=du, dv=dv, ku=du, kv=dv)]


class BrokenNStages(_Trapezoid):
    """Declares two stages, returns one (ran the compiled loop past its bank: SIGSEGV)."""
    name, n_stages = "BrokenNStages", 2

    def stages(self, dt):
        return _Trapezoid.stages(self, dt)


class BrokenLoadWeights(_Trapezoid):
    """Load weights summing to 2 with mass weight 1 (ran; every response doubled)."""
    name = "BrokenLoadWeights"

    def stages(self, dt):
        (st,) = super().stages(dt)
        st.load = [(1.0, 2.0)]
        return [st]


class BrokenFutureSlot(Integrator):
    """Stage 1 of 2 reads slot 6, stage 2's u, written later (ran silently)."""
    name, n_stages = "BrokenFutureSlot", 2

    def stages(self, dt):
        du, dv = _Trapezoid._update(self, dt)
        bad = du.copy()
        bad[6] = 0.3
        du2, dv2 = self.coefficients(slot3=1.0, a=1e-12), self.coefficients(slot4=1.0, a=1e-12)
        return [Stage(du=du, dv=dv, ku=bad, kv=dv), Stage(du=du2, dv=dv2, ku=du2, kv=dv2)]


class BrokenShort(Integrator):
    """Coefficient arrays n_slots long instead of n_slots + 1 (IndexError in subdomain.py)."""
    name, n_stages = "BrokenShort", 1

    def stages(self, dt):
        du, dv = np.array([1.0, dt, dt * dt / 4]), np.array([0.0, 1.0, dt / 2])
        return [Stage(du=du, dv=dv, ku=du, kv=dv)]


class BrokenForceWeight(_Trapezoid):
    """force_weight = 0 (a coupled analysis divided by it: bare ZeroDivisionError)."""
    name = "BrokenForceWeight"

    def stages(self, dt):
        (st,) = super().stages(dt)
        st.force_weight = 0.0
        return [st]


class BatheThetaLeftAtOne(Bathe):
    """Bathe with the first stage's end time left at its default 1 (it ends at γΔt)."""
    name = "BatheThetaLeftAtOne"

    def stages(self, dt):
        first, second = super().stages(dt)
        first.theta = 1.0
        return [first, second]


class NewmarkWithoutVelocity(_Trapezoid):
    """The displacement update forgets Δt v_n: not consistent (a moving body stops)."""
    name = "NewmarkWithoutVelocity"

    def stages(self, dt):
        (st,) = super().stages(dt)
        st.du[1] = 0.0
        st.ku = st.du.copy()
        return [st]


FORCE_WEIGHT_ZERO = r"BrokenForceWeight\(\): stage 1 of 1: force_weight = 0.0; it must be finite and > 0"
BROKEN = {   # integrator -> what the error says
    BrokenLoadWeights(): r"BrokenLoadWeights\(\): stage 1 of 1: its load weights sum to 2, its mass weight "
                         r"1 \+ sum\(km\) is 1; they must be equal",
    BrokenFutureSlot(): r"BrokenFutureSlot\(\): stage 1 of 2: ku reads slot 6 \(u of stage 2\), not written yet",
    BrokenShort(): r"BrokenShort\(\): stage 1 of 1: du has shape \(3,\); it needs \(7,\)",
    BrokenForceWeight(): FORCE_WEIGHT_ZERO,
    BatheThetaLeftAtOne(): r"BatheThetaLeftAtOne\(gamma=0.5\): stage 1 of 2 does not keep the constant-velocity "
                           r"motion .* its u is .* at the stage's end time theta = 1",
    NewmarkWithoutVelocity(): r"NewmarkWithoutVelocity\(\): stage 1 of 1 does not keep the constant-velocity motion",
}


# -- 1. stages that break the contract are refused when the analysis prepares them --------------------
@pytest.mark.parametrize("integrator", list(BROKEN), ids=lambda i: type(i).__name__)
def test_a_broken_integrator_is_refused_naming_it(integrator):
    """Each broken scheme: an AnalysisError naming it (its repr) and the rule, when the analysis
    prepares its stages (before: a wrong answer, an IndexError, nothing at all)."""
    with pytest.raises(AnalysisError, match=BROKEN[integrator]):
        run(integrator)
    with pytest.raises(AnalysisError, match=BROKEN[integrator]):
        integrator.checked_stages(1e-3)


def test_a_stage_count_other_than_n_stages_is_refused_not_a_crash():
    """n_stages = 2 with one stage returned crashed the process (SIGSEGV in the compiled loop):
    run in a child process, so that a regression fails this test instead of killing the suite."""
    script = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {str(__import__('pathlib').Path(__file__).parent)!r})
        from test_user_integrators import BrokenNStages, run
        from vtsi.errors import AnalysisError
        try:
            run(BrokenNStages())
        except AnalysisError as exc:
            print(exc)
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "integrator BrokenNStages(): declares n_stages = 2 but stages(dt=0.001) returned 1 stage(s)" in out.stdout


def test_force_weight_zero_in_a_coupled_analysis_is_named():
    """A coupled analysis divides each stage's constraint force by its force_weight: 0 gave a bare
    ZeroDivisionError from the compiled loop."""
    from vtsi.constraint import MovingLoadConstraint
    from vtsi.coupled import CoupledAnalysis
    from vtsi.models import Train, four_dof_car
    from vtsi.models.bridges import simply_supported_beam
    from vtsi.track import Track
    from vtsi.train import TrainSubdomain

    model = vtsi.Model()
    beam = simply_supported_beam(model, L=30.0, n_elements=10, E=3.5e10, I=7.0, mu=3.0e4)
    car = four_dof_car(m_c=47800, J_c=1.96e6, m_w=7100, k_s=1.4e6, c_s=8e4, l_c=17.375)
    train = TrainSubdomain(Train([car], [0.0], speed=300 / 3.6), x_head0=-5.0)
    tie = MovingLoadConstraint(Track(model, beam.elements), train, interpolation="bspline")
    analysis = CoupledAnalysis(model, tie, BrokenForceWeight(), dt=1e-3)
    with pytest.raises(AnalysisError, match=FORCE_WEIGHT_ZERO):
        analysis.static()
        analysis.run(20)


class WilsonTheta(Integrator):
    """Wilson-θ (Bathe & Wilson 1973) in the stage form: unknown a_{n+1}, equilibrium at t + θΔt with
    a_θ = (1 − θ) a_n + θ a_{n+1}, the equation divided by θ (so km = (1 − θ)/θ, load (θ, 1/θ)).
    Its constraint forces extrapolate: force_weight 1 > mass weight 1/θ, and its load point lies
    beyond the step (θ > 1); both within the contract."""
    name, n_stages = "WilsonTheta", 1

    def __init__(self, theta=1.4):
        self.theta = float(theta)
        if not 1.37 <= self.theta <= 3.0:
            raise AnalysisError(f"integrator {self.name}: theta = {self.theta:g} is outside [1.37, 3]")

    def stages(self, dt):
        th = self.theta
        h = th * dt
        du = self.coefficients(u_n=1.0, v_n=dt, a_n=dt * dt / 3.0, a=dt * dt / 6.0)
        dv = self.coefficients(v_n=1.0, a_n=dt / 2.0, a=dt / 2.0)
        ku = self.coefficients(u_n=1.0, v_n=h, a_n=h * h / 6.0 * (3.0 - th), a=h * h / 6.0 * th) / th
        kv = self.coefficients(v_n=1.0, a_n=h / 2.0 * (2.0 - th), a=h / 2.0 * th) / th
        km = self.coefficients(a_n=(1.0 - th) / th)
        return [Stage(du=du, dv=dv, ku=ku, kv=kv, km=km, load=[(th, 1.0 / th)], force_weight=1.0)]


class BackwardEuler(Integrator):
    """First order, not exact for a constant acceleration: the consistency check must not refuse it."""
    name, n_stages = "BackwardEuler", 1

    def stages(self, dt):
        du = self.coefficients(u_n=1.0, v_n=dt, a=dt * dt)
        dv = self.coefficients(v_n=1.0, a=dt)
        return [Stage(du=du, dv=dv, ku=du, kv=dv)]


class HHTLoadAtEnd(Newmark):
    """HHT(0.9)'s stiffness at t_n + αΔt with the load at t_{n+1}: first order (a wrong load time is
    an accuracy matter that tests/test_integrators.py measures, not a contract violation)."""
    name = "HHTLoadAtEnd"

    def stages(self, dt):
        from vtsi.integrators import HHT
        (st,) = HHT(0.9).stages(dt)
        st.load = [(1.0, 1.0)]
        return [st]


def reference_run(integrator, dt, n):
    """The stage equations of integrators/base.py, literally, on the oscillator (a₀ = 0)."""
    stages, n_slots = integrator.stages(dt), integrator.n_slots
    bank, out = np.zeros(n_slots), []
    for _ in range(n):
        for s, st in enumerate(stages):
            rhs = sum(w * P for _, w in st.load)
            rhs -= MASS * (st.km[:n_slots] @ bank) + K * (st.ku[:n_slots] @ bank)
            a = rhs / (MASS + K * st.ku[n_slots])
            bank[3 + 3 * s] = st.du[:n_slots] @ bank + st.du[n_slots] * a
            bank[4 + 3 * s] = st.dv[:n_slots] @ bank + st.dv[n_slots] * a
            bank[5 + 3 * s] = a
        bank[:3] = bank[n_slots - 3:]
        out.append(bank[0])
    return np.array(out)


@pytest.mark.parametrize("integrator", [WilsonTheta(1.4), WilsonTheta(2.0), BackwardEuler(), HHTLoadAtEnd()],
                         ids=lambda i: repr(i))
def test_a_scheme_within_the_contract_runs_as_its_stages_say(integrator):
    """Schemes the checks must not refuse — Wilson-θ (load point beyond the step, force weight
    above the mass weight), backward Euler (first order), a load at the wrong time (first order) —
    run, and give what the stage equations give literally (to roundoff)."""
    integrator.checked_stages(2e-3)
    rec = run(integrator, n=300, dt=2e-3)
    ref = reference_run(integrator, 2e-3, 300)
    assert np.abs(rec.values[:, 0] - ref).max() <= 1e-10 * np.abs(ref).max()


def test_stages_are_checked_once_per_preparation_not_per_step(monkeypatch):
    """The check runs when the analysis prepares Δt (the compiled loop runs unchanged): a run of
    several chunks, and a second run, check once."""
    calls = []
    original = Integrator.checked_stages

    def counting(self, dt):
        calls.append(dt)
        return original(self, dt)

    monkeypatch.setattr(Integrator, "checked_stages", counting)
    analysis = vtsi.TransientAnalysis(oscillator(), Newmark(), 1e-3, chunk_steps=7)
    analysis.run(50)
    analysis.run(50)
    assert calls == [1e-3]


# -- 2. a name is registered once ----------------------------------------------------------------------
@pytest.fixture
def registry():
    """INTEGRATORS as it was after the test (registrations undone)."""
    before = dict(INTEGRATORS)
    yield INTEGRATORS
    INTEGRATORS.clear()
    INTEGRATORS.update(before)


def test_a_builtin_name_cannot_be_registered_again(registry):
    """A copy of Newmark not renamed replaced make_integrator('Newmark') for the Python API, sweeps
    and coupled analyses (not for Tcl): refused, naming both classes."""
    with pytest.raises(TypeError, match=r"integrator name 'Newmark' of .*MyNewmark is already registered by "
                                        r"vtsi.integrators.newmark.Newmark"):
        @register
        class MyNewmark(Newmark):
            name = "Newmark"

            def __init__(self, gamma=0.6, beta=0.3025):
                super().__init__(gamma, beta)
    assert type(make_integrator("Newmark")) is Newmark and make_integrator("Newmark").gamma == 0.5


@pytest.mark.parametrize("n_stages", [0, -1, True, 1.0])
def test_n_stages_must_be_a_positive_int(registry, n_stages):
    with pytest.raises(TypeError, match="n_stages must be an int >= 1"):
        register(type("Zero", (_Trapezoid,), {"name": "Zero-test", "n_stages": n_stages}))
    assert "Zero-test" not in registry


def test_the_same_class_defined_again_replaces_itself(registry):
    """A script or notebook cell run twice defines its class again (same module and qualified
    name): that is not a collision."""
    def define():
        class Again(_Trapezoid):
            name = "Again-test"
        return register(Again)

    first, second = define(), define()
    assert first is not second and registry["Again-test"] is second


# -- 3. the integrator command builds any registered integrator --------------------------------------
@pytest.fixture
def wilson(registry):
    register(WilsonTheta)
    return WilsonTheta


def test_integrator_command_builds_a_registered_integrator(wilson, cantilever):
    """``integrator('WilsonTheta', 1.4)`` was 'not supported'; it is ``WilsonTheta(1.4)`` and runs as
    the Python API does."""
    import vtsi.opensees as ops
    from vtsi.commands.analysis_commands import INTEGRATORS as COMMAND_NAMES

    cantilever(ops)
    ops.integrator("WilsonTheta", 1.8)
    ops.analysis("Transient")
    ops.analyze(40, 0.01)
    by_command = ops.nodeDisp(2, 2)
    assert ops.session._transient_integrator[1].theta == 1.8

    cantilever(ops)
    model = ops.session.domain
    rec = NodeRecorder([2], [2])
    vtsi.TransientAnalysis(model, WilsonTheta(1.8), 0.01, recorders=[rec]).run(40)
    assert by_command == pytest.approx(rec.values[-1, 0], rel=1e-12)

    with pytest.raises(AnalysisError, match=r"integrator WilsonTheta: \(1.4, 2.0\) does not fit its parameters"):
        ops.integrator("WilsonTheta", 1.4, 2.0)
    with pytest.raises(AnalysisError, match=r"theta = 5 is outside"):
        ops.integrator("WilsonTheta", 5.0)
    with pytest.raises(CommandError, match=r"integrator WilsonTheta: unexpected argument '-x'"):
        ops.integrator("WilsonTheta", "-x")
    with pytest.raises(CommandError, match=r"'Nope' is not supported; supported: "
                                           + ", ".join(COMMAND_NAMES) + r", .*WilsonTheta"):
        ops.integrator("Nope")
    ops.wipe()


def test_builtin_command_names_keep_opensees_conventions():
    """The OpenSees names stay parsed with OpenSees's argument order, whatever the registry holds:
    GeneralizedAlpha's optional pair is beta then gamma, as OpenSees's parser reads it."""
    import vtsi.opensees as ops
    ops.wipe()
    ops.integrator("GeneralizedAlpha", 1.0, 0.8, 0.4, 0.7)
    integ = ops.session._transient_integrator[1]
    assert (integ.beta, integ.gamma) == (0.4, 0.7)
    ops.wipe()


# -- 4. the recorder contract (b), exactly as documented, works with every sink ---------------------
class Elongation(Recorder):
    """uy(node_b) − uy(node_a) [m], its prepare() returning exactly contract (b)'s required keys
    (no 'response'); ``extra`` more columns from compute() than declared (the bug to catch)."""
    name = "elongation recorder"

    def __init__(self, pairs, extra=0, layout=None, **kwargs):
        self.pairs, self.extra, self.layout = list(pairs), extra, layout
        super().__init__(**kwargs)

    def requests(self, assembly):
        return [("u", assembly.full_dof(node, 2)) for pair in self.pairs for node in pair]

    def prepare(self, assembly, model):
        if self.layout is not None:
            return dict(self.layout)
        return {"units": ["m"] * len(self.pairs), "quantity": "elongation",
                "columns": {"pair": np.arange(len(self.pairs))}}

    def compute(self, times, columns, assembly):
        out = columns[:, 1::2] - columns[:, 0::2]
        return np.hstack([out] * (1 + self.extra))


def test_the_documented_layout_keys_are_enough_for_hdf5(tmp_path):
    """'units', 'columns', 'quantity' (contract (b)) made HDF5Sink fail with KeyError: 'response';
    'response' is optional now (default: the quantity)."""
    path = tmp_path / "elongation.h5"
    rec = Elongation([(1, 2)], sink=HDF5Sink(path))
    node = NodeRecorder([2], [2])
    vtsi.TransientAnalysis(oscillator(), "Newmark", 1e-3, recorders=[rec, node]).run(30)
    with h5py.File(path, "r") as f:
        assert f.attrs["response"] == "elongation" and f.attrs["quantity"] == "elongation"
        np.testing.assert_array_equal(f["values"][:, 0], node.values[:, 0])


@pytest.mark.parametrize("envelope", [False, True])
def test_more_columns_than_declared_are_refused_naming_the_recorder(envelope):
    """compute() giving 2 columns where prepare() declared 1 was stored silently by the memory sink
    and broke envelope=True with a numpy broadcast error."""
    rec = Elongation([(1, 2)], extra=1, envelope=envelope)
    with pytest.raises(ModelError, match=r"Elongation\(sink=MemorySink\): compute\(\) returned values of shape "
                                         r"\(7, 2\) for 7 steps; prepare\(\) declared 1 columns"):
        vtsi.TransientAnalysis(oscillator(), "Newmark", 1e-3, recorders=[rec], chunk_steps=7).run(20)


@pytest.mark.parametrize("layout, message", [
    ({"units": ["m"], "columns": {}}, r"returned no 'quantity'"),
    ({"units": ["m"], "quantity": "q", "columns": {"pair": [0, 1]}}, r"'columns'\['pair'\] has shape \(2,\)"),
    ({"units": "m", "quantity": "q", "columns": {}}, r"'units' must be a list of str"),
])
def test_a_layout_outside_the_contract_is_named(layout, message):
    rec = Elongation([(1, 2)], layout=layout)
    with pytest.raises(ModelError, match=r"Elongation\(sink=MemorySink\): prepare\(\).*" + message):
        vtsi.TransientAnalysis(oscillator(), "Newmark", 1e-3, recorders=[rec]).run(5)


# -- 5. the start of a transient analysis (documented, unchanged) ------------------------------------
def test_a_transient_run_starts_from_the_committed_acceleration_and_static_first_starts_at_rest():
    """As OpenSees: a₀ is the committed acceleration (0 at rest), not M⁻¹(P − K u₀); the
    documented remedy, a static analysis first, starts the oscillator at rest in equilibrium."""
    dt = 1e-3
    rec = run("Newmark", n=1, dt=dt)
    beta_dt2 = 0.25 * dt * dt                 # u1 = βΔt² a1, (M + βΔt² K) a1 = P with a0 = 0
    assert rec.values[0, 0] == pytest.approx(beta_dt2 * P / (MASS + beta_dt2 * K), rel=1e-12)
    model = oscillator()
    StaticAnalysis(model).run(1)
    domain_state(model).time = 0.0
    rec = NodeRecorder([2], [2])
    vtsi.TransientAnalysis(model, "Newmark", dt, recorders=[rec]).run(100)
    assert np.abs(rec.values[:, 0] - U_STATIC).max() <= 1e-12 * abs(U_STATIC)


class WilsonThetaOne(WilsonTheta):
    """Wilson-θ with θ = 1 (the linear acceleration method), which is stable only up to ωΔt = √12:
    it claims unconditional stability (stability_limit None, the base's default)."""
    name = "WilsonThetaOne"

    def __init__(self):
        self.theta = 1.0


class CentralDifferenceNoLimit(Integrator):
    """Central differences (explicit: K̂ holds no stiffness) without their limit ωΔt = 2."""
    name, n_stages, explicit = "CentralDifferenceNoLimit", 1, True

    def stages(self, dt):
        du = self.coefficients(u_n=1.0, v_n=dt, a_n=dt * dt / 2.0)
        dv = self.coefficients(v_n=1.0, a_n=dt / 2.0, a=dt / 2.0)
        return [Stage(du=du, dv=dv, ku=du, kv=dv)]


@pytest.mark.parametrize("integrator, limit", [(WilsonThetaOne(), 12 ** 0.5), (CentralDifferenceNoLimit(), 2.0)],
                         ids=lambda i: type(i).__name__)
def test_a_claim_of_unconditional_stability_is_checked(integrator, limit):
    """A scheme whose stability_limit is None must keep the spectral radius <= 1 at every ωΔt: one
    that does not is refused when the analysis prepares it, naming an ωΔt past its true limit
    (√12 for θ = 1, 2 for central differences) and the radius there; it ran and diverged before."""
    pattern = (rf"^integrator {type(integrator).__name__}\(.*\): stability_limit\(dt\) is None \(unconditionally "
               r"stable\), but its spectral radius at omega dt = ([0-9.e+]+) is ([0-9.e+]+) > 1")
    with pytest.raises(AnalysisError, match=pattern) as info:
        run(integrator)
    omega_dt, radius = map(float, re.match(pattern, str(info.value)).groups())
    assert limit < omega_dt < 1.3 * limit and radius > 1.0      # the first sampled ωΔt where it grows
    for name in ("Newmark", "HHT(0.8)", "Bathe", "TRBDF2", "GeneralizedAlpha(0.8)"):     # the shipped ones pass
        assert make_integrator(name).checked_stages(1e-3)
