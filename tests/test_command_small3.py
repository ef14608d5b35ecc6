"""Three small defects of the command layer and the coupled preparation: an option given twice
to a train command (the last one was taken silently), the queries of a missing element (vtsi
raised where OpenSeesPy, the oracle, answers None or []), and the train's stability check cached
per bridge, not per track (a second analysis on the same bridge with another track reused the
first one's verdict)."""
import logging

import pytest

import vtsi
import vtsi.opensees as vops
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis, TrainStages
from vtsi.errors import AnalysisError, CommandError
from vtsi.integrators import Newmark
from vtsi.models import Train, sprung_mass
from vtsi.models.bridges import simply_supported_beam
from vtsi.subdomain import BridgeStageCache, max_frequency
from vtsi.track import Track
from vtsi.train import TrainSubdomain

pytestmark = pytest.mark.usefixtures("fresh_session")


@pytest.fixture
def oracle():
    """OpenSeesPy (with VTSI_REQUIRE_ORACLES=1 or in CI a missing one fails: tests/conftest.py)."""
    return pytest.importorskip("openseespy.opensees")


# -- 1. an option given twice ----------------------------------------------------------------------
def _deck_with_train_parts():
    """A 20 m deck of ten beams (the vtsi session), track 1, a sprung car 1, train 1, and two
    irregularities 1 and 2."""
    vops.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(11):
        vops.node(i + 1, 2.0 * i, 0.0)
    vops.fix(1, 1, 1, 0)
    vops.fix(11, 0, 1, 0)
    vops.geomTransf("Linear", 1)
    for i in range(1, 11):
        vops.element("elasticBeamColumn", i, i, i + 1, 5.0, 3.5e10, 0.6948, 1, "-mass", 15000.0, "-cMass")
    vops.track(1, "-eleRange", 1, 10)
    vops.car(1, "sprungMass", 4e4, 2e6)
    vops.train(1, 30.0, "-cars", 1, 0.0)
    vops.irregularity(1, "profile", "-x", 0.0, 20.0, "-r", 0.0, 1e-3)
    vops.irregularity(2, "profile", "-x", 0.0, 20.0, "-r", 1e-3, 0.0)


@pytest.mark.parametrize("command, args, message", [
    ("movingLoadConstraint", (5, 1, 1, 0.0, "-irregularity", 1, "-irregularity", 2),
     "movingLoadConstraint 5: option -irregularity given twice"),
    ("movingLoadConstraint", (5, 1, 1, 0.0, "-bspline", "-exactEvents", "-bspline"),
     "movingLoadConstraint 5: option -bspline given twice"),
    ("track", (2, "-ele", 1, 2, "-ele", 3), "track 2: option -ele given twice"),
    ("track", (2, "-eleRange", 1, 3, "-eleRange", 4, 5), "track 2: option -eleRange given twice"),
    ("car", (2, "sprungMass", 4e4, 2e6, "-c", 1e3, "-c", 2e3), "car 2 sprungMass: option -c given twice"),
    ("car", (2, "sprungMass", 4e4, 2e6, "-wheelMass", 1e3, "-c", 5.0, "-wheelMass", 2e3),
     "car 2 sprungMass: option -wheelMass given twice"),
    ("train", (2, 30.0, "-cars", 1, 0.0, "-cars", 1, 20.0), "train 2: option -cars given twice"),
    ("train", (2, 30.0, "-ICE3", 2, "-ICE3", 3), "train 2: option -ICE3 given twice"),
    ("irregularity", (3, "profile", "-x", 0.0, 1.0, "-x", 2.0, 3.0), "irregularity 3: option -x given twice"),
    ("irregularity", (3, "profile", "-x", 0.0, 1.0, "-r", 0.0, 0.0, "-r", 1e-3, 0.0),
     "irregularity 3: option -r given twice"),
    ("irregularity", (3, "german", "low", 0.0, 10.0, "-seed", 1, "-seed", 2), "irregularity 3: option -seed given twice"),
    ("irregularity", (3, "fra", 5, 0.0, 10.0, "-seed", 1, "-seed", 1), "irregularity 3: option -seed given twice"),
    ("deadLoad", ("-selfWeight", "-dt", 0.01, "-selfWeight"), "deadLoad: option -selfWeight given twice"),
])
def test_an_option_given_twice_is_refused(command, args, message, one_line):
    _deck_with_train_parts()
    with pytest.raises(CommandError) as err:
        getattr(vops, command)(*args)
    assert one_line(err) == message


def test_options_given_once_are_taken():
    """The same commands with each option once define what they say."""
    _deck_with_train_parts()
    vops.car(2, "sprungMass", 4e4, 2e6, "-wheelMass", 1e3, "-c", 5e3)
    vops.train(2, 30.0, "-cars", 1, 0.0, 2, 20.0)
    vops.irregularity(3, "german", "low", 0.0, 10.0, "-seed", 4)
    vops.movingLoadConstraint(5, 1, 1, 0.0, "-irregularity", 2, "-bspline", "-exactEvents")
    spec = vops.session._constraint
    assert spec["irregularity"] is vops.session._irregularities[2]
    assert (spec["interpolation"], spec["exact_events"]) == ("bspline", True)
    car = vops.session._cars[2]
    assert car.M.diagonal().tolist() == [4e4, 1e3]                  # body, wheel [kg]
    assert car.C[0, 0] == 5e3
    assert len(vops.session._trains[2].cars) == 2


# -- 2. queries of a missing element, node or pattern, against OpenSeesPy ---------------------------
QUERIES = [("eleForce", (99,)), ("eleForce", (99, 2)), ("eleResponse", (99, "force")),
           ("eleResponse", (99, "localForce")), ("nodeDisp", (99,)), ("nodeDisp", (99, 1)), ("nodeVel", (99,)),
           ("nodeAccel", (99,)), ("nodeCoord", (99,)), ("nodeCoord", (99, 1)), ("nodeReaction", (99,)),
           ("nodeMass", (99,)), ("nodeEigenvector", (99, 1)), ("nodeResponse", (99, 1, 1)), ("getLoadFactor", (99,))]


def _static_cantilever(o, cantilever):
    cantilever(o)
    o.constraints("Plain")
    o.numberer("Plain")
    o.system("BandGeneral")
    o.test("NormDispIncr", 1e-12, 10)
    o.algorithm("Linear")
    o.integrator("LoadControl", 1.0)
    o.analysis("Static")
    o.analyze(1)


@pytest.mark.parametrize("command, args", QUERIES, ids=[f"{c}{a}" for c, a in QUERIES])
def test_a_missing_tag_answers_as_openseespy(command, args, oracle, cantilever, caplog):
    """OpenSeesPy 3.7.1 returns None for ``eleForce`` and [] for ``eleResponse`` of a missing
    element (``Domain::getElementResponse`` finds none and nothing is output), and raises for a
    missing node or pattern: vtsi does the same, and warns (logged) naming the element."""
    _static_cantilever(oracle, cantilever)
    _static_cantilever(vops, cantilever)
    try:
        expected = getattr(oracle, command)(*args)
    except oracle.OpenSeesError:
        with pytest.raises(CommandError, match=r"(node|pattern) 99 does not exist"):
            getattr(vops, command)(*args)
        return
    with caplog.at_level(logging.WARNING, logger="vtsi"):
        assert getattr(vops, command)(*args) == expected
    assert f"{command} 99" in caplog.text and "element 99 does not exist" in caplog.text


def test_a_present_element_answers_as_before(oracle, cantilever):
    """The cantilever's element 1 answers as OpenSeesPy's (the missing-element path takes no other)."""
    _static_cantilever(oracle, cantilever)
    _static_cantilever(vops, cantilever)
    assert vops.eleForce(1) == pytest.approx(oracle.eleForce(1), abs=1e-9)
    assert vops.eleResponse(1, "localForce") == pytest.approx(oracle.eleResponse(1, "localForce"), abs=1e-9)
    assert vops.eleForce(1, 2) == pytest.approx(100.0)


def test_tcl_missing_element_gives_an_empty_result(tcl, cantilever):
    """In Tcl, as OpenSees's Tcl ``eleForce``/``eleResponse`` of a missing element: ''."""
    _static_cantilever(vops, cantilever)
    assert tcl.eval("eleForce 99") == ""
    assert tcl.eval("eleResponse 99 force") == ""
    assert [float(x) for x in tcl.eval("eleForce 1").split()] == pytest.approx(vops.eleForce(1))


# -- 3. the train's stability check follows the track -------------------------------------------------
SPAN, N_EL, E, I = 10.0, 4, 3.5e10, 0.05
HEAVY, LIGHT = 2e4, 2e3            # [kg/m] span 1, span 2
NEWMARK_16 = Newmark(0.5, 1 / 6)   # conditionally stable: omega dt <= sqrt(12)


def _two_spans():
    """Two simply supported spans of 10 m, the second ten times lighter; dt half the bridge's
    limit for Newmark(1/2, 1/6) (its stiffest element)."""
    model = vtsi.Model()
    first = simply_supported_beam(model, SPAN, N_EL, E, I, HEAVY)
    second = simply_supported_beam(model, SPAN, N_EL, E, I, LIGHT, x0=SPAN, first_node=N_EL + 2,
                                   first_element=N_EL + 1)
    dt = 0.5 * NEWMARK_16.stability_limit(1.0) / max_frequency(model.build())
    return model, first.elements, first.elements + second.elements, dt


def _analysis(model, elements, dt, cache, integrator=NEWMARK_16):
    """A 1000 t body on a 1e12 N/m spring on a massless wheel at x = 2 m: on span 1's rail mass it is
    within the limit, on span 2's (ten times lighter) beyond it."""
    train = TrainSubdomain(Train([sprung_mass(1e6, 1e12)], [0.0], 1.0), x_head0=2.0)
    return CoupledAnalysis(model, MovingLoadConstraint(Track(model, elements), train), integrator, dt,
                           bridge_cache=cache)


def test_the_stability_verdict_follows_the_track():
    """A shared cache gives each track the verdict a fresh cache gives it, in either order: span 1
    alone passes, both spans (the light one's rail mass) fail."""
    model, span1, both, dt = _two_spans()
    _analysis(model, span1, dt, BridgeStageCache()).prepare()
    with pytest.raises(AnalysisError, match="stability limit") as fresh:
        _analysis(model, both, dt, BridgeStageCache()).prepare()
    assert "a wheel without mass on the rail's" in str(fresh.value)
    shared = BridgeStageCache()
    _analysis(model, span1, dt, shared).prepare()
    with pytest.raises(AnalysisError, match="stability limit") as reused:
        _analysis(model, both, dt, shared).prepare()         # it passed on span 1's cached verdict
    assert str(reused.value) == str(fresh.value)
    _analysis(model, span1, dt, shared).prepare()            # and span 1 still passes after it


def test_the_train_factors_are_shared_when_the_check_needs_no_rail():
    """An unconditionally stable integrator (or wheels with mass) reads no rail mass: the two
    tracks share the train's factors (one TrainStages in the cache), with the conditionally
    stable one each track has its own."""
    model, span1, both, dt = _two_spans()
    for integrator, n_train in ((Newmark(0.5, 0.25), 1), (NEWMARK_16, 2)):
        shared = BridgeStageCache()
        _analysis(model, span1, dt, shared, integrator).prepare()
        _analysis(model, span1[:2], dt, shared, integrator).prepare()
        assert sum(isinstance(s, TrainStages) for s in shared.stages()) == n_train
