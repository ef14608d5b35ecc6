"""Numbers given as text, NaN, inf and bools in the model's object API: nodes, masses, fixities,
loads, element parameters, Rayleigh factors, time series and a car's own fields.

Each entry point refuses each bad value with a ModelError naming the object and the value
(before the fix a text such as '0.0' ran as its number, True as 1, ``wheel_dofs=['1']`` was parsed,
``[nan]`` raised numpy's ValueError); numpy's numbers stay numbers. The Tcl layer reads its words
as numbers before it calls the objects (the last test, and tests/test_tcl.py).
"""
import math
import re

import numpy as np
import pytest

import vtsi
from vtsi.errors import ModelError, number_array
from vtsi.models.cars import sprung_mass
from vtsi.timeseries import Constant, Linear, Path, Pulse, Rectangular, Trig
from vtsi.vehicle import Car

BAD = {"text": "1.0", "nan": float("nan"), "inf": float("inf"), "bool": True}
SHOWN = {"text": "'1.0'", "nan": "nan", "inf": "inf", "bool": "True"}     # how a message shows the value


def model():
    """Nodes 1-3 on a line, element 1 (a beam 1-2), series 1 and pattern 1."""
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 10.0, 0.0)
    m.node(3, 5.0, 0.0)
    m.fix(1, 1, 1, 0)
    m.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=3e10, I=2.0, rho=1e4, cmass=1)
    m.add_time_series(Constant(tag=1))
    m.pattern(1, 1)
    return m


def beam(**change):
    params = dict(A=1.0, E=3e10, I=2.0, rho=1e4, cmass=1)
    params.update(change)
    model().element("elasticBeamColumn", 2, (2, 3), **params)


def car(**change):
    fields = dict(name="c", kind="user", M=np.eye(2), C=np.zeros((2, 2)), K=np.array([[1e6, -1e6], [-1e6, 1e6]]),
                  gravity_load=[-9.81, -9.81], wheel_dofs=[1], wheel_offsets=[0.0], dof_names=("body_y", "wheel1_y"))
    fields.update(change)
    return Car(**fields)


ENTRIES = {   # name: (call with the bad value v, the object the message must name)
    "node coordinate": (lambda v: model().node(7, v, 0.0), r"^node 7: "),
    "node mass": (lambda v: model().node(7, 1.0, 0.0, mass=(v, 1.0, 0.0)), r"^mass node 7: "),
    "mass": (lambda v: model().mass(3, 0.0, v, 0.0), r"^mass node 3: "),
    "fix flag": (lambda v: model().fix(3, 0, v, 0), r"^fix node 3: "),
    "equalDOF dof": (lambda v: model().equal_dof(2, 3, v), r"^equalDOF 2 3: "),
    "rayleigh alpha_m": (lambda v: model().rayleigh(v, 0.0), r"^rayleigh: "),
    "rayleigh beta_k_comm": (lambda v: model().rayleigh(0.0, 1e-3, 0.0, v), r"^rayleigh: "),
    "nodal load": (lambda v: model().load(1, 3, 0.0, v, 0.0), r"^pattern 1: load on node 3"),
    "element load": (lambda v: model().beam_load(1, 1, "uniform", v), r"^pattern 1: (uniform )?load on element 1"),
    "element point load x/L": (lambda v: model().beam_load(1, 1, "point", -1e3, v),
                               r"^pattern 1: (point )?load on element 1"),
    "sp value": (lambda v: model().sp(1, 3, 2, v), r"^sp node 3 dof 2: "),
    "sp dof": (lambda v: model().sp(1, 3, v, 0.01), r"^sp node 3: "),
    "pattern factor": (lambda v: model().pattern(2, 1, factor=v), r"^pattern 2: "),
    "ground motion factor": (lambda v: model().uniform_excitation(2, 2, 1, factor=v), r"^pattern 2: "),
    "beam E": (lambda v: beam(E=v), r"^element 2 \(elasticBeamColumn\): E "),
    "beam cmass": (lambda v: beam(cmass=v), r"^element 2 \(elasticBeamColumn\): cmass "),
    "Timoshenko G": (lambda v: model().element("ElasticTimoshenkoBeam", 2, (2, 3), A=1.0, E=3e10, G=v, I=2.0,
                                               Avy=0.8), r"^element 2 \(ElasticTimoshenkoBeam\): G "),
    "truss A": (lambda v: model().element("truss", 2, (2, 3), A=v, E=2e11), r"^element 2 \(truss\): A "),
    "zeroLength kx": (lambda v: model().element("zeroLength", 2, (2, 3), kx=v), r"^element 2 \(zeroLength\): kx "),
    "pointMass m": (lambda v: model().element("pointMass", 2, (3,), m=v), r"^element 2 \(pointMass\): m "),
    "Constant factor": (lambda v: Constant(v, tag=1), r"^timeSeries Constant 1: factor "),
    "Linear factor": (lambda v: Linear(v), r"^timeSeries Linear: factor "),
    "Rectangular tStart": (lambda v: Rectangular(v, 2.0), r"^timeSeries Rectangular: tStart "),
    "Trig period": (lambda v: Trig(0.0, 1.0, v, tag=3), r"^timeSeries Trig 3: period "),
    "Pulse width": (lambda v: Pulse(0.0, 1.0, 0.5, width=v), r"^timeSeries Pulse: width "),
    "Path values": (lambda v: Path([0.0, v], dt=0.1, tag=2), r"^timeSeries Path 2: value"),
    "Path time": (lambda v: Path([0.0, 1.0], time=[0.0, v]), r"^timeSeries Path: time"),
    "Path dt": (lambda v: Path([0.0, 1.0], dt=v), r"^timeSeries Path: dt "),
    "Path factor": (lambda v: Path([0.0, 1.0], dt=0.1, factor=v), r"^timeSeries Path: factor "),
    "Path start_time": (lambda v: Path([0.0, 1.0], dt=0.1, start_time=v), r"^timeSeries Path: start_time "),
    "car wheel_dofs": (lambda v: car(wheel_dofs=[v]), r"^car 'c': wheel_dofs "),
    "car M": (lambda v: car(M=[[v, 0.0], [0.0, 1.0]]), r"^car 'c': M "),
    "car wheel_offsets": (lambda v: car(wheel_offsets=[v]), r"^car 'c': wheel_offsets "),
    "force car static loads": (lambda v: car(M=np.zeros((0, 0)), C=np.zeros((0, 0)), K=np.zeros((0, 0)),
                                             gravity_load=[], wheel_dofs=[], dof_names=(), static_wheel_loads=[v]),
                               r"^car 'c': static[ _]wheel[ _]loads "),
    "sprung mass damping": (lambda v: sprung_mass(5750.0, 1.6e6, c_s=v), r"^sprung_mass: c_s "),
}


@pytest.mark.parametrize("entry, kind", [(e, k) for e in ENTRIES for k in BAD
                                          if (e, k) != ("beam cmass", "bool")])    # test_a_flag_takes_a_bool
def test_text_nan_inf_and_bool_are_refused_naming_the_object_and_the_value(entry, kind):
    call, names = ENTRIES[entry]
    with pytest.raises(ModelError) as info:
        call(BAD[kind])
    message = str(info.value)
    assert re.search(names, message), message
    assert SHOWN[kind] in message and "\n" not in message, message


def test_a_flag_takes_a_bool():
    """An element's flag (``cmass``) takes True and False as 1 and 0, Python's or numpy's."""
    masses = []
    for flag in (True, 1, np.True_, False, 0):
        m = model()
        m.element("elasticBeamColumn", 2, (2, 3), A=1.0, E=3e10, I=2.0, rho=1e4, cmass=flag)
        masses.append(m.build().M.toarray())
    assert all(np.array_equal(masses[0], M) for M in masses[1:3]) and np.array_equal(masses[3], masses[4])
    assert not np.array_equal(masses[0], masses[3])


def test_a_refused_call_leaves_the_model_as_it_was():
    m = model()
    for call in (lambda: m.node(7, "1.0", 0.0), lambda: m.mass(3, "500", 500.0, 0.0), lambda: m.fix(3, True, 0, 0),
                 lambda: m.rayleigh("0.1", 0.0), lambda: m.load(1, 3, 0.0, "-1e3", 0.0),
                 lambda: m.element("truss", 2, (2, 3), A="1", E=2e11)):
        with pytest.raises(ModelError):
            call()
    assert sorted(m.nodes) == [1, 2, 3] and m.nodal_mass == {} and m.fixities == {1: (1, 1, 0)}
    assert m.rayleigh_factors == (0.0, 0.0) and m.patterns[1].nodal == {} and m.element_tags() == [1]


@pytest.mark.parametrize("tag", [True, "3", 3.0])
def test_a_node_pattern_or_element_named_by_a_bool_or_a_text_is_no_tag(tag):
    """``True`` was found as node 1 (``True in {1: ...}``), ``'3'`` named as node 3 in 'does not exist'."""
    m = model()
    for call, message in ((lambda: m.fix(tag, 0, 1, 0), "fix: node tag must be an integer"),
                          (lambda: m.mass(tag, 1.0, 1.0, 0.0), "mass: node tag must be an integer"),
                          (lambda: m.element("truss", 2, (2, tag), A=1.0, E=1.0),
                           r"element 2 \(truss\): node tag must be an integer"),
                          (lambda: m.load(tag, 3, 0.0, 1.0, 0.0), "load: pattern tag must be an integer"),
                          (lambda: m.beam_load(1, tag, "uniform", 1.0),
                           "beam_load in pattern 1: element tag must be an integer"),
                          (lambda: m.pattern(2, tag), "pattern 2: time series tag must be an integer"),
                          (lambda: m.remove_element(tag), "remove element: element tag must be an integer")):
        with pytest.raises(ModelError, match=f"^{message}, got {re.escape(repr(tag))}$"):
            call()
    assert m.fixities == {1: (1, 1, 0)} and m.element_tags() == [1] and m.nodal_mass == {}


def test_numpy_numbers_stay_numbers():
    """np.float64, np.float32, np.int64 and 0-d arrays build the model the floats build."""
    def build(f):
        m = vtsi.Model()
        m.node(1, f(0.0), f(0.0))
        m.node(2, f(10.0), f(0.0), mass=(f(5.0), f(5.0), f(0.0)))
        m.fix(1, 1, 1, 0)
        m.fix(2, 0, 1, 0)
        m.element("elasticBeamColumn", 1, (1, 2), A=f(1.0), E=f(3e10), I=f(2.0), rho=f(1e4), cmass=np.int64(1))
        m.rayleigh(f(0.1), f(1e-3))
        m.add_time_series(Path([f(0.0), f(1.0), f(1.0)], time=[f(0.0), f(0.5), f(1.0)], factor=f(2.0), tag=1))
        m.pattern(1, 1, factor=f(1.5))
        m.load(1, 2, f(0.0), f(-1e3), f(0.0))
        m.beam_load(1, 1, "point", f(-1e3), f(0.25))
        m.sp(1, 2, np.int64(1), f(0.0))
        return m

    want = build(float)
    whole_as_int64 = lambda x: np.int64(x) if x == int(x) else x            # noqa: E731
    for f in (np.float64, np.float32, whole_as_int64, np.asarray):
        m = build(f)
        params = m.element_types["elasticBeamColumn"].params
        for got, expected in ((m.nodes[2], want.nodes[2]), (m.nodal_mass[2], [5.0, 5.0, 0.0]),
                              (m.rayleigh_factors, want.rayleigh_factors),
                              (params, want.element_types["elasticBeamColumn"].params),
                              (m.patterns[1].nodal[2], [0.0, -1e3, 0.0]),
                              (m.patterns[1].element_loads[0][2], (-1e3, 0.25, 0.0)),
                              (m.patterns[1].factors(np.array([0.25, 0.75])), [1.5, 3.0])):   # 1.5 * 2 * (0.5, 1)
            assert np.allclose(got, expected, rtol=1e-7, atol=0.0), (f, got, expected)   # (float32: 0.1 is 1.5e-8 off)
    assert car(wheel_dofs=np.array([1], dtype=np.int32)).wheel_dofs.tolist() == [1]


def test_bools_inside_number_lists_are_refused():
    """numpy reads ``[True, 2.0]`` as ``[1.0, 2.0]``: number_array looks at the items of lists."""
    for value in ([True, 2.0], [[1.0, 2.0], (3.0, np.bool_(False))], (np.array([True]), 1.0), [1, True]):
        assert number_array(value) is None
    assert number_array([1, 2.5, np.float32(3.0), np.int64(4), np.asarray(5.0)]).tolist() == [1.0, 2.5, 3.0, 4.0, 5.0]
    assert number_array(np.array([1, 2])).dtype == np.float64


def test_a_series_is_evaluated_at_numbers_only():
    series = Linear(2.0, tag=1)
    assert series([0.5, 1]).tolist() == [1.0, 2.0]
    assert series(np.float32(0.25)).tolist() == 0.5
    with pytest.raises(ModelError, match=r"^timeSeries Linear 1: times must be numbers \[s\], got \['0.5'\]$"):
        series(["0.5"])
    with pytest.raises(ModelError, match=r"^timeSeries Linear 1: times must be numbers \[s\], got True$"):
        series(True)


def test_the_tcl_layer_converts_its_words_before_the_objects(tcl):
    """A Tcl model's words reach the object API as numbers: the model equals the Python one."""
    tcl.eval("""
        model basic -ndm 2 -ndf 3
        node 1 0.0 0.0; node 2 10.0 0.0 -mass 5.0 5.0 0.0; node 3 20.0 0.0
        fix 1 1 1 0; fix 3 0 1 0
        geomTransf Linear 1
        element elasticBeamColumn 1 1 2 0.8 3e10 0.05 1 -mass 2000.0 -cMass
        element elasticBeamColumn 2 2 3 0.8 3e10 0.05 1 -mass 2000.0
        mass 2 500.0 500.0 0.0
        rayleigh 0.1 1e-3 0.0 0.0
        timeSeries Path 1 -time {0.0 0.5 1.0} -values {0.0 1.0 1.0} -factor 2.0
        pattern Plain 1 1 -fact 1.5 { load 2 0.0 -1000.0 0.0; eleLoad -ele 1 -type -beamUniform -10.0 }
    """)
    m = tcl.session.domain
    assert m.nodes[2].tolist() == [10.0, 0.0] and m.nodal_mass[2].tolist() == [500.0, 500.0, 0.0]
    assert m.element_types["elasticBeamColumn"].params.tolist() == [[0.8, 3e10, 0.05, 2000.0, 1.0],
                                                                     [0.8, 3e10, 0.05, 2000.0, 0.0]]
    assert m.rayleigh_factors == (0.1, 1e-3)
    assert m.patterns[1].nodal[2].tolist() == [0.0, -1000.0, 0.0]
    assert m.patterns[1].element_loads == [(1, "uniform", (-10.0, 0.0))]
    assert math.isclose(float(m.patterns[1].factors(np.array([0.25]))[0]), 1.5)
