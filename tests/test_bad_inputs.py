"""Bad inputs: every one raises a vtsi error (or FileExistsError for a recorder file) whose
message names the object and the offending value, never a numpy traceback, a silent NaN or a
dead process; and nothing already defined or computed is lost (the model still analyses as
before, recorders keep every completed step). ``docs/bad_inputs.md`` lists the same cases.
"""
import math
import os
import re

import h5py
import numpy as np
import pytest

import vtsi
import vtsi.opensees as ops
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import AnalysisError, CommandError, DivergenceError, ModelError, RecorderError, VtsiError
from vtsi.integrators import HHT, Bathe, Newmark
from vtsi.models import Irregularity, Train, car_from_catalogue, four_dof_car, ice3, moving_force, sprung_mass, ten_dof_car
from vtsi.models.cars import TEN_DOF_PARAMETERS
from vtsi.models.bridges import simply_supported_beam
from vtsi.analysis import modes_up_to
from vtsi.recorders import (ContactRecorder, ElementRecorder, HDF5Sink, MemorySink, ModalNodeRecorder, NodeRecorder,
                             ReactionRecorder, TextSink, TrainRecorder)
from vtsi.timeseries import Rectangular, TimeSeries, Trig
from vtsi.track import Track
from vtsi.train import TrainSubdomain

NAN, INF = float("nan"), float("inf")
L, E, I, P = 10.0, 3e10, 0.1, 1e5


def loaded_beam(n_el=4, cmass=0, fixed=True):
    """Simply supported beam on nodes 1..5 (x = 0, 2.5 ... 10 m), elements 1..4, time series 1
    (Constant), pattern 1 with ``-P`` on the middle node 3."""
    m = vtsi.Model()
    for i in range(n_el + 1):
        m.node(i + 1, L * i / n_el, 0.0)
    if fixed:
        m.fix(1, 1, 1, 0)
        m.fix(n_el + 1, 0, 1, 0)
    for e in range(1, n_el + 1):
        m.element("elasticBeamColumn", e, (e, e + 1), A=0.5, E=E, I=I, rho=1e3, cmass=cmass)
    m.add_time_series(vtsi.Constant(tag=1))
    m.pattern(1, 1)
    m.load(1, n_el // 2 + 1, 0.0, -P, 0.0)
    return m


def midspan_deflection(model):
    state = vtsi.StaticAnalysis(model).run(1)
    return state.u[model.build().full_dof(3, 2)]


DEFLECTION = -P * L ** 3 / (48.0 * E * I)      # closed form, point load at midspan


def snapshot(m):
    """Everything a definition call could have changed."""
    return (sorted(m.nodes), {t: m.nodes[t].tolist() for t in m.nodes}, m.element_tags(), dict(m.fixities),
            {t: v.tolist() for t, v in m.nodal_mass.items()}, sorted(m.time_series),
            {t: {n: np.asarray(v).tolist() for n, v in p.nodal.items()} for t, p in m.patterns.items()},
            m.rayleigh_factors)


def _assert_message(excinfo, match):
    """The message is one clear line of ours, not a numpy/scipy traceback text."""
    text = str(excinfo.value)
    assert "could not convert" not in text and "ufunc" not in text and "invalid literal" not in text
    return text


class NaNSeries(TimeSeries):
    """A user series that returns NaN from ``t_bad`` on (a broken user function)."""

    def __init__(self, t_bad, tag=9):
        self.t_bad, self.tag = t_bad, tag

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        return np.where(t >= self.t_bad - 1e-12, np.nan, 1.0)


# =============================================================================================
# 1. model definition: rejected, and the model is unchanged and analyses as before
# =============================================================================================
BEAM = dict(A=0.5, E=E, I=I)
MODEL_CASES = [
    ("duplicate node", lambda m: m.node(3, 1.0, 1.0), r"^node 3 already exists$"),
    ("duplicate element", lambda m: m.element("truss", 2, (1, 3), A=1.0, E=1.0), r"^element 2 already exists$"),
    ("duplicate time series", lambda m: m.add_time_series(vtsi.Constant(tag=1)), r"^timeSeries 1 already exists$"),
    ("duplicate pattern", lambda m: m.pattern(1, 1), r"^pattern 1 already exists$"),
    ("element on unknown node", lambda m: m.element("truss", 7, (3, 42), A=1.0, E=1.0),
     r"^element 7 \(truss\): node 42 does not exist$"),
    ("fix unknown node", lambda m: m.fix(42, 1, 1, 1), r"^fix: node 42 does not exist$"),
    ("mass on unknown node", lambda m: m.mass(42, 1.0, 1.0, 0.0), r"^mass: node 42 does not exist$"),
    ("load on unknown node", lambda m: m.load(1, 42, 0.0, -1.0, 0.0), r"^load in pattern 1: node 42 does not exist$"),
    ("load in unknown pattern", lambda m: m.load(9, 3, 0.0, -1.0, 0.0), r"^load: pattern 9 does not exist$"),
    ("pattern on unknown series", lambda m: m.pattern(2, 9), r"^pattern 2: time series 9 does not exist$"),
    ("unknown element type lists the valid ones", lambda m: m.element("elasticBeam", 7, (1, 3), **BEAM),
     r"^unknown element type 'elasticBeam'; known types: (.*, )?elasticBeamColumn, (.*, )?pointMass, (.*, )?truss, (.*, )?zeroLength"),
    ("three nodes for a beam", lambda m: m.element("elasticBeamColumn", 7, (1, 2, 3), **BEAM),
     r"^element 7 \(elasticBeamColumn\): needs 2 nodes, got 3$"),
    ("two nodes for a point mass", lambda m: m.element("pointMass", 7, (1, 2), m=1.0),
     r"^element 7 \(pointMass\): needs 1 nodes, got 2$"),
    ("nodes not a sequence", lambda m: m.element("truss", 7, 3, A=1.0, E=1.0),
     r"^element 7 \(truss\): nodes must be a sequence of node tags, got 3$"),
    ("E = 0", lambda m: m.element("elasticBeamColumn", 7, (1, 3), A=0.5, E=0.0, I=I),
     r"^element 7 \(elasticBeamColumn\): E must be > 0, got 0$"),
    ("A < 0", lambda m: m.element("elasticBeamColumn", 7, (1, 3), A=-1.0, E=E, I=I),
     r"^element 7 \(elasticBeamColumn\): A must be > 0, got -1$"),
    ("I = NaN", lambda m: m.element("elasticBeamColumn", 7, (1, 3), A=0.5, E=E, I=NAN),
     r"^element 7 \(elasticBeamColumn\): I must be finite, got nan$"),
    ("E = inf", lambda m: m.element("truss", 7, (1, 3), A=0.5, E=INF),
     r"^element 7 \(truss\): E must be finite, got inf$"),
    ("rho < 0", lambda m: m.element("elasticBeamColumn", 7, (1, 3), rho=-5.0, **BEAM),
     r"^element 7 \(elasticBeamColumn\): rho must be >= 0, got -5$"),
    ("E not a number", lambda m: m.element("elasticBeamColumn", 7, (1, 3), A=0.5, E="stiff", I=I),
     r"^element 7 \(elasticBeamColumn\): E must be a number, got 'stiff'$"),
    ("cmass flag 2", lambda m: m.element("elasticBeamColumn", 7, (1, 3), cmass=2, **BEAM),
     r"^element 7 \(elasticBeamColumn\): cmass must be 0 or 1, got 2$"),
    ("unknown element parameter", lambda m: m.element("elasticBeamColumn", 7, (1, 3), A=0.5, E=E, Iz=I),
     r"^element 7 \(elasticBeamColumn\): unknown parameter\(s\) \['Iz'\]; valid: A, E, I"),
    ("missing element parameter", lambda m: m.element("truss", 7, (1, 3), A=0.5),
     r"^element 7 \(truss\): parameter 'E' is required$"),
    ("point mass m = 0", lambda m: m.element("pointMass", 7, (3,), m=0.0),
     r"^element 7 \(pointMass\): m must be > 0, got 0$"),
    ("negative nodal mass", lambda m: m.mass(3, -1.0, 0.0, 0.0),
     r"^mass node 3: needs 3 finite values >= 0, got \[-1.0, 0.0, 0.0\]$"),
    ("NaN nodal mass", lambda m: m.mass(3, NAN, NAN, 0.0), r"^mass node 3: needs 3 finite values >= 0, got \[nan, nan, 0.0\]$"),
    ("two nodal masses for ndf 3", lambda m: m.mass(3, 1.0, 1.0), r"^mass node 3: needs 3 finite values >= 0, got \[1.0, 1.0\]$"),
    ("NaN coordinate", lambda m: m.node(7, NAN, 0.0), r"^node 7: coordinates must be finite, got \[nan, 0.0\]$"),
    ("inf coordinate", lambda m: m.node(7, 0.0, INF), r"^node 7: coordinates must be finite, got \[0.0, inf\]$"),
    ("text coordinate", lambda m: m.node(7, "x", 0.0), r"^node 7: coordinates must be numbers, got \['x', 0.0\]$"),
    ("one coordinate", lambda m: m.node(7, 1.0), r"^node 7: needs 2 coordinates, got 1$"),
    ("node with NaN mass is not added", lambda m: m.node(7, 1.0, 1.0, mass=(NAN, 1.0, 0.0)),
     r"^mass node 7: needs 3 finite values >= 0, got \[nan, 1.0, 0.0\]$"),
    ("NaN load", lambda m: m.load(1, 3, 0.0, NAN, 0.0), r"^pattern 1: load on node 3 has NaN or inf: \[0.0, nan, 0.0\]$"),
    ("inf load", lambda m: m.load(1, 3, INF, 0.0, 0.0), r"^pattern 1: load on node 3 has NaN or inf: \[inf, 0.0, 0.0\]$"),
    ("two load values for ndf 3", lambda m: m.load(1, 3, 0.0, -1.0), r"^load on node 3: needs 3 values, got 2$"),
    ("NaN pattern factor", lambda m: m.pattern(2, 1, factor=NAN), r"^pattern 2: factor must be finite, got nan$"),
    ("text pattern factor", lambda m: m.pattern(2, 1, factor="big"), r"^pattern 2: factor must be a number, got 'big'$"),
    ("fractional node tag", lambda m: m.node(1.5, 0.0, 1.0), r"^node tag must be an integer, got 1.5$"),
    ("bool node tag", lambda m: m.node(True, 0.0, 1.0), r"^node tag must be an integer, got True$"),
    ("text element tag", lambda m: m.element("truss", "7", (1, 3), A=1.0, E=1.0), r"^element tag must be an integer, got '7'$"),
    ("text pattern tag", lambda m: m.pattern("dead", 1), r"^pattern tag must be an integer, got 'dead'$"),
    ("series without tag", lambda m: m.add_time_series(vtsi.Constant()),
     r"^timeSeries Constant\(factor=1\.0\) has no tag: give it as tag=\.\.\., e\.g\. Constant\(factor=1\.0, tag=1\); "
     r"Constant's first argument is factor, not the tag as in OpenSees's 'timeSeries Constant <tag> \.\.\.'$"),
    ("not a time series", lambda m: m.add_time_series(math.sin), r"^timeSeries: expected a TimeSeries, got <built-in"),
    ("fix flag 2", lambda m: m.fix(3, 2, 0, 0), r"^fix node 3: needs 3 flags of 0 or 1, got \[2, 0, 0\]$"),
    ("fix flag 0.5", lambda m: m.fix(3, 0.5, 0, 0), r"^fix node 3: needs 3 flags of 0 or 1, got \[0.5, 0, 0\]$"),
    ("two fix flags for ndf 3", lambda m: m.fix(3, 1, 1), r"^fix node 3: needs 3 flags of 0 or 1, got \[1, 1\]$"),
    ("negative Rayleigh factor", lambda m: m.rayleigh(-0.1, 0.0),
     r"^rayleigh: factors must be finite and >= 0, got \[-0.1, 0.0, 0.0, 0.0\]$"),
    ("remove unknown element", lambda m: m.remove_element(42), r"^remove element: element 42 does not exist$"),
    ("pattern factor set to text", lambda m: setattr(m.patterns[1], "factor", "x"),
     r"^pattern 1: factor must be a number, got 'x'$"),
    ("pattern factor set to NaN", lambda m: setattr(m.patterns[1], "factor", NAN), r"^pattern 1: factor must be finite, got nan$"),
    ("pattern frozen at NaN", lambda m: setattr(m.patterns[1], "constant_time", NAN),
     r"^pattern 1: constant_time must be finite, got nan$"),
    ("pattern frozen at text", lambda m: setattr(m.patterns[1], "constant_time", "x"),
     r"^pattern 1: constant_time must be a number, got 'x'$"),
    ("two load values for ndf 3, through the pattern", lambda m: m.patterns[1].load(3, 0.0, -1.0),
     r"^pattern 1: load on node 3: needs 3 values, got 2$"),
    ("beam load on a fractional element tag", lambda m: m.patterns[1].beam_load(1.7, "uniform", -1.0, 0.0),
     r"^pattern 1: element tag must be an integer, got 1.7$"),
    ("beam load on a text element tag", lambda m: m.patterns[1].beam_load("x", "uniform", -1.0, 0.0),
     r"^pattern 1: element tag must be an integer, got 'x'$"),
    ("a beam of 1e10 elements a span (E slipped into its place: it tried to allocate 75 GB)",
     lambda m: simply_supported_beam(m, 20.0, 1e10, 1.0, 1e4, 15e3, first_node=100, first_element=100),
     r"^continuous_beam: elements_per_span must be an even integer from 2 to 1000, got 10000000000.0$"),
    ("an infinite span", lambda m: simply_supported_beam(m, math.inf, 4, 3e10, 1.0, 1e4, first_node=100),
     r"^continuous_beam: spans must be positive and finite, got \[inf\]$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in MODEL_CASES], ids=[c[0] for c in MODEL_CASES])
def test_model_definition_is_rejected_and_the_model_is_unchanged(bad, match):
    m = loaded_beam()
    before = snapshot(m)
    with pytest.raises(ModelError, match=match) as info:
        bad(m)
    _assert_message(info, match)
    assert snapshot(m) == before
    assert midspan_deflection(m) == pytest.approx(DEFLECTION, rel=1e-9)


def test_ndf_and_ndm_mismatch():
    m = vtsi.Model(ndf=2)
    m.node(1, 0.0, 0.0)
    m.node(2, 1.0, 0.0)
    with pytest.raises(ModelError, match=r"^element 1 \(elasticBeamColumn\): needs node dofs \[1, 2, 3\], "
                                         r"but the model has ndf 2$"):
        m.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=1.0, I=1.0)
    with pytest.raises(ModelError, match=r"^fix node 1: needs 2 flags of 0 or 1, got \[1, 1, 1\]$"):
        m.fix(1, 1, 1, 1)
    with pytest.raises(ModelError, match=r"^model: only ndm 2 with ndf 2 or 3 is supported, got ndm 3 ndf 6$"):
        vtsi.Model(ndm=3, ndf=6)
    m.element("truss", 1, (1, 2), A=1.0, E=1.0)            # the 2-dof truss is fine
    assert m.element_tags() == [1]


def test_zero_length_element_is_named_at_build_and_removing_it_restores_the_model():
    m = loaded_beam()
    m.node(6, 10.0, 0.0)                                     # on top of node 5
    m.fix(6, 1, 1, 1)
    m.element("elasticBeamColumn", 7, (5, 6), **BEAM)
    with pytest.raises(ModelError, match=r"^element 7 \(elasticBeamColumn\): zero length between nodes 5 and 6$"):
        m.build()
    with pytest.raises(ModelError, match=r"element 7 .*zero length between nodes 5 and 6"):
        vtsi.StaticAnalysis(m).run(1)
    m.remove_element(7)
    assert midspan_deflection(m) == pytest.approx(DEFLECTION, rel=1e-9)


# =============================================================================================
# 2. assembly and analysis
# =============================================================================================
def truss_apex(ndf=3):
    """Two bars meeting at node 3: with ndf 3 its rotation has neither stiffness nor mass."""
    m = vtsi.Model(ndf=ndf)
    m.node(1, 0.0, 0.0)
    m.node(2, 2.0, 0.0)
    m.node(3, 1.0, 1.0)
    m.fix(1, *([1] * ndf))
    m.fix(2, *([1] * ndf))
    m.element("truss", 1, (1, 3), A=1e-3, E=2e11, rho=10.0)
    m.element("truss", 2, (2, 3), A=1e-3, E=2e11, rho=10.0)
    m.add_time_series(vtsi.Constant(tag=1))
    m.pattern(1, 1)
    m.load(1, 3, *([0.0, -1e3, 0.0][:ndf]))
    return m


def bar_chain(n=4):
    """Axial bar chain (ndf 2) with mass on every free dof: omega_max is finite."""
    m = vtsi.Model(ndf=2)
    for i in range(n + 1):
        m.node(i + 1, float(i), 0.0)
        m.fix(i + 1, 1 if i == 0 else 0, 1)
    for i in range(n):
        m.element("truss", i + 1, (i + 1, i + 2), A=1e-4, E=2e11, rho=1.0)
    return m


def omega_max(model):
    from vtsi.subdomain import max_frequency
    return max_frequency(model.build())


MECHANISM = r"is singular or not positive definite at node (\d+) dof (\d) \((ux|uy|rz)\): the structure is a mechanism"
ANALYSIS_CASES = [
    ("beam without supports, static", lambda: vtsi.StaticAnalysis(loaded_beam(fixed=False)).run(1),
     AnalysisError, r"^stiffness matrix K " + MECHANISM),
    ("beam without supports, eigen", lambda: vtsi.eigen(loaded_beam(fixed=False), 2),
     AnalysisError, r"^stiffness matrix K " + MECHANISM),
    ("truss node rotation, static", lambda: vtsi.StaticAnalysis(truss_apex()).run(1),
     AnalysisError, r"^stiffness matrix K .* at node 3 dof 3 \(rz\): the structure is a mechanism or that dof has "
                    r"neither stiffness nor mass"),
    ("truss node rotation, transient", lambda: vtsi.TransientAnalysis(truss_apex(), "Newmark", 1e-3).run(1),
     AnalysisError, r"^effective matrix of Newmark stage 1 \(M \+ .* K\) is singular .* at node 3 dof 3 \(rz\)"),
    ("massless rotation, explicit", lambda: vtsi.TransientAnalysis(loaded_beam(cmass=0), "CentralDifference", 1e-6).run(1),
     AnalysisError, r"effective matrix of CentralDifference stage 1 .* at node \d dof 3 \(rz\): CentralDifference is "
                    r"explicit, so every free dof needs mass"),
    ("dt = 0", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 0.0),
     AnalysisError, r"^transient analysis: dt must be > 0 and finite, got 0.0$"),
    ("dt < 0", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", -1e-3),
     AnalysisError, r"^transient analysis: dt must be > 0 and finite, got -0.001$"),
    ("dt = NaN", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", NAN),
     AnalysisError, r"^transient analysis: dt must be > 0 and finite, got nan$"),
    ("dt = inf", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", INF),
     AnalysisError, r"^transient analysis: dt must be > 0 and finite, got inf$"),
    ("dt text", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", "1ms"),
     AnalysisError, r"^transient analysis: dt must be a number, got '1ms'$"),
    ("no dt", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark").run(1),
     AnalysisError, r"^transient analysis: no time step set$"),
    ("negative step count", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3).run(-1),
     AnalysisError, r"^transient analysis: number of steps must be an integer >= 0, got -1$"),
    ("fractional step count", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3).run(2.5),
     AnalysisError, r"^transient analysis: number of steps must be an integer >= 0, got 2.5$"),
    ("text step count, static", lambda: vtsi.StaticAnalysis(loaded_beam()).run("ten"),
     AnalysisError, r"^static analysis: number of steps must be an integer >= 0, got 'ten'$"),
    ("chunk_steps = 0", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3, chunk_steps=0),
     AnalysisError, r"^transient analysis: chunk_steps must be an integer >= 1, got 0$"),
    ("divergence_limit = 0", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3, divergence_limit=0.0),
     AnalysisError, r"^transient analysis: divergence_limit \(inf: no bound\) must be > 0, got 0.0$"),
    ("LoadControl NaN", lambda: vtsi.StaticAnalysis(loaded_beam(), NAN),
     AnalysisError, r"^LoadControl: increment must be finite, got nan$"),
    ("LoadControl text", lambda: vtsi.StaticAnalysis(loaded_beam(), "tenth"),
     AnalysisError, r"^LoadControl: increment must be a number, got 'tenth'$"),
    ("Newmark gamma < 1/2", lambda: Newmark(0.4, 0.25),
     AnalysisError, r"^integrator Newmark: gamma = 0.4 is outside \[0.5, 1\]"),
    ("Newmark beta < 0", lambda: Newmark(0.5, -0.1), AnalysisError, r"^integrator Newmark: beta = -0.1 is outside \[0, 1\]$"),
    ("Newmark gamma NaN", lambda: Newmark(NAN, 0.25), AnalysisError, r"^integrator Newmark: gamma = nan is outside"),
    ("HHT alpha < 2/3", lambda: HHT(0.5), AnalysisError, r"^integrator HHT: alpha = 0.5 is outside \[0.666667, 1\]"),
    ("HHT alpha > 1", lambda: HHT(1.2), AnalysisError, r"^integrator HHT: alpha = 1.2 is outside \[0.666667, 1\]"),
    ("HHT gamma < 3/2 - alpha", lambda: HHT(0.8, 0.5, 0.3),
     AnalysisError, r"^integrator HHT: gamma = 0.5 is below 3/2 - alpha = 0.7"),
    ("Bathe gamma = 1", lambda: Bathe(1.0), AnalysisError,
     r"^integrator Bathe: gamma = 1 is outside \[0.001, 0.999\] \(below it round-off grows like 1e-16/gamma"),
    ("unknown integrator lists the valid ones", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmrk", 1e-3),
     AnalysisError, r"^unknown integrator 'Newmrk'; known: Bathe, CentralDifference, GeneralizedAlpha, HHT, Newmark, "
                    r"TRBDF2 \(parameters as 'HHT\(0.9\)'\)$"),
    ("eigen: more modes than dofs", lambda: vtsi.eigen(loaded_beam(), 100),
     AnalysisError, r"^eigen: number of modes must be between 1 and 12 \(the free dofs\), got 100$"),
    ("eigen: zero modes", lambda: vtsi.eigen(loaded_beam(), 0),
     AnalysisError, r"^eigen: number of modes must be between 1 and 12 \(the free dofs\), got 0$"),
    ("eigen: fractional modes", lambda: vtsi.eigen(loaded_beam(), 2.5),
     AnalysisError, r"^eigen: number of modes must be an integer, got 2.5$"),
    ("eigen: more modes than massive dofs", lambda: vtsi.eigen(loaded_beam(cmass=0), 10),
     AnalysisError, r"^eigen: only 7 dofs carry mass, 10 modes requested$"),
    ("model without nodes", lambda: vtsi.StaticAnalysis(vtsi.Model()).run(1), ModelError, r"^model has no nodes$"),
    ("recorders not a list", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3, recorders=5),
     AnalysisError, r"^transient analysis: recorders must be a list of recorders, got 5$"),
    ("recorders not a list, static", lambda: vtsi.StaticAnalysis(loaded_beam(), recorders=5),
     AnalysisError, r"^static analysis: recorders must be a list of recorders, got 5$"),
    ("a recorder that is a text", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3, recorders=["x"]),
     AnalysisError, r"^transient analysis: recorders\[0\] is not a recorder \(NodeRecorder, ElementRecorder\.\.\.\), got 'x'$"),
    ("a recorder that is None, static", lambda: vtsi.StaticAnalysis(loaded_beam(), recorders=[NodeRecorder([3], [2]), None]),
     AnalysisError, r"^static analysis: recorders\[1\] is not a recorder .*, got None$"),
    ("a recorder that is a number, static", lambda: vtsi.StaticAnalysis(loaded_beam(), recorders=[5]),
     AnalysisError, r"^static analysis: recorders\[0\] is not a recorder .*, got 5$"),
    ("integrator name in a list", lambda: vtsi.TransientAnalysis(loaded_beam(), ["Newmark"], 1e-3),
     AnalysisError, r"^unknown integrator \['Newmark'\]; known: Bathe, CentralDifference"),
    ("transient analysis of no model", lambda: vtsi.TransientAnalysis(None, "Newmark", 1e-3),
     AnalysisError, r"^transient analysis: model must be a vtsi.Model, got None$"),
    ("static analysis of no model", lambda: vtsi.StaticAnalysis("beam"),
     AnalysisError, r"^static analysis: model must be a vtsi.Model, got 'beam'$"),
    ("eigen of no model", lambda: vtsi.eigen(None, 2), AnalysisError, r"^eigen: model must be a vtsi.Model, got None$"),
    ("modes_up_to: text f_max", lambda: modes_up_to(loaded_beam(), "x"),
     AnalysisError, r"^modes_up_to: f_max \[Hz\] must be a number, got 'x'$"),
    ("modes_up_to: no f_max", lambda: modes_up_to(loaded_beam(), None),
     AnalysisError, r"^modes_up_to: f_max \[Hz\] must be a number, got None$"),
    ("modes_up_to: two f_max", lambda: modes_up_to(loaded_beam(), [10, 20]),
     AnalysisError, r"^modes_up_to: f_max \[Hz\] must be a number, got \[10, 20\]$"),
    ("modes_up_to: NaN f_max", lambda: modes_up_to(loaded_beam(), NAN),
     AnalysisError, r"^modes_up_to: f_max must be > 0 and finite \[Hz\], got nan$"),
    ("modes_up_to: negative f_max", lambda: modes_up_to(loaded_beam(), -5),
     AnalysisError, r"^modes_up_to: f_max must be > 0 and finite \[Hz\], got -5.0$"),
    ("modes_up_to: f_max = 0", lambda: modes_up_to(loaded_beam(), 0),
     AnalysisError, r"^modes_up_to: f_max must be > 0 and finite \[Hz\], got 0.0$"),
    ("modes_up_to: f_max = inf", lambda: modes_up_to(loaded_beam(), INF),
     AnalysisError, r"^modes_up_to: f_max must be > 0 and finite \[Hz\], got inf$"),
    ("active dofs before a run", lambda: vtsi.TransientAnalysis(loaded_beam(), "Newmark", 1e-3).active,
     AnalysisError, r"^transient analysis: active \(the dofs that can move\) is known once a run has started; "
                    r"call run\(\) first$"),
]


@pytest.mark.parametrize("bad, exc, match", [c[1:] for c in ANALYSIS_CASES], ids=[c[0] for c in ANALYSIS_CASES])
def test_analysis_input_is_rejected(bad, exc, match):
    with pytest.raises(exc, match=match) as info:
        bad()
    _assert_message(info, match)


def test_mechanism_names_a_dof_of_the_unsupported_beam_and_fixing_it_restores_the_analysis():
    m = loaded_beam(fixed=False)
    with pytest.raises(AnalysisError, match=MECHANISM) as info:
        vtsi.StaticAnalysis(m).run(1)
    node, dof = (int(g) for g in re.search(MECHANISM, str(info.value)).groups()[:2])
    assert node in m.nodes and 1 <= dof <= 3
    m.fix(1, 1, 1, 0)
    m.fix(5, 0, 1, 0)
    assert midspan_deflection(m) == pytest.approx(DEFLECTION, rel=1e-9)


def test_a_mechanism_whose_zero_pivot_round_off_made_positive_is_named():
    """A deck on rollers only (nothing holds it along x), 32 elements, EA = 2.6e11 N, 24 t/m: the
    axial rigid-body mode's pivot comes out of the Cholesky sweep as round-off (~1e-18 of its
    diagonal, positive), which eigen took as a stiffness ('only 1 dofs carry mass'). Every
    analysis must name the mechanism instead; holding one node along x restores eigen."""
    m = vtsi.Model()
    for i in range(33):
        m.node(i + 1, 2.5 * i, 0.0)
    for e in range(1, 33):
        m.element("elasticBeamColumn", e, (e, e + 1), A=7.2, E=3.6e10, I=5.8, rho=24000.0)
    for n in (1, 11, 23, 33):
        m.fix(n, 0, 1, 0)
    for run in (lambda: vtsi.eigen(m, 12), lambda: vtsi.StaticAnalysis(m).run(1)):
        with pytest.raises(AnalysisError, match=r"^stiffness matrix K " + MECHANISM):
            run()
    m.fix(1, 1, 0, 0)
    omega2, _ = vtsi.eigen(m, 2)
    # the first span (25 m of 80 m on rollers at 0, 25, 55, 80 m) sets the first bending mode: a
    # continuous three-span beam's first frequency lies between the simply supported 25 m and 30 m spans'
    f1 = math.sqrt(omega2[0]) / (2 * math.pi)
    fss = [math.pi / (2 * L ** 2) * math.sqrt(3.6e10 * 5.8 / 24000.0) for L in (30.0, 25.0)]
    assert fss[0] < f1 < fss[1]


@pytest.mark.parametrize("k", [1e15, 1e20])
def test_a_rigid_spring_whose_pivot_round_off_lost_is_named_as_such(k):
    """A deck node tied to a 10 m column's head (EI = 3e8 N m², 9e5 N/m sideways) by a zeroLength
    spring: k = 1e15 solves to the closed form (column + spring); k = 1e20, some 1e14 times the
    column's stiffness, leaves the pivot 9e-15 of its diagonal, below LOST_PIVOT (OpenSees's
    BandSPD solves it 1.3 % off): refused, naming the stiff spring as a cause beside a mechanism."""
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 0.0, 10.0)
    m.node(3, 0.0, 10.0)
    m.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=3e10, I=0.01)
    m.element("zeroLength", 2, (2, 3), kx=k, ky=k, krz=k)
    m.fix(1, 1, 1, 1)
    m.add_time_series(vtsi.Constant(tag=1))
    m.pattern(1, 1)
    m.load(1, 3, -1e3, 0.0, 0.0)
    if k < 1e18:
        ux = vtsi.StaticAnalysis(m).run(1).u[m.build().full_dof(3, 1)]
        # a stiffness ratio of 1e9 costs some 9 of double precision's 16 digits (measured 2e-8)
        assert ux == pytest.approx(-1e3 * (10.0 ** 3 / (3 * 3e10 * 0.01) + 1 / k), rel=1e-7)
        return
    with pytest.raises(AnalysisError, match=r"^stiffness matrix K " + MECHANISM + r", or a stiffness there is some "
                                            r"1e\+13 times its neighbours' or more .*'rigid' spring"):
        vtsi.StaticAnalysis(m).run(1)


def test_unconnected_node_is_named():
    m = loaded_beam()
    m.node(6, 20.0, 0.0)
    with pytest.raises(AnalysisError, match=r"at node 6 dof \d \((ux|uy|rz)\): the structure is a mechanism or that "
                                            r"dof has neither stiffness nor mass \(fix it or connect it\)$"):
        vtsi.StaticAnalysis(m).run(1)
    m.fix(6, 1, 1, 1)
    assert midspan_deflection(m) == pytest.approx(DEFLECTION, rel=1e-9)


@pytest.mark.parametrize("integrator, limit, ratio", [("CentralDifference", 2.0, 1.25),
                                                       (Newmark(0.5, 1.0 / 6.0), math.sqrt(12.0), 1.1)],
                         ids=["central difference beyond 2/omega_max", "linear acceleration beyond sqrt(12)/omega_max"])
def test_conditionally_stable_integrator_beyond_its_limit(integrator, limit, ratio):
    m = bar_chain()
    w = omega_max(m)
    dt = ratio * limit / w
    with pytest.raises(AnalysisError) as info:
        vtsi.TransientAnalysis(m, integrator, dt).run(1)
    name = integrator if isinstance(integrator, str) else integrator.name
    assert str(info.value).startswith(f"integrator {name}: dt = {dt:g} s exceeds its stability limit {limit / w:.6g} s")
    assert not isinstance(info.value, DivergenceError)
    assert vtsi.domain_state(m).time == 0.0                   # nothing ran
    vtsi.TransientAnalysis(m, integrator, 0.99 * limit / w).run(5)  # below the limit it runs
    assert vtsi.domain_state(m).time == pytest.approx(5 * 0.99 * limit / w)


def test_transient_of_an_unsupported_beam_is_allowed():
    """A free body with mass is a well-posed dynamic problem (rigid-body motion): no error, finite
    response; the static and eigen analyses of the same model name the mechanism (above)."""
    m = loaded_beam(cmass=1, fixed=False)
    rec = NodeRecorder([3], [2])
    vtsi.TransientAnalysis(m, "Newmark", 1e-3, recorders=[rec]).run(5)
    assert np.all(np.isfinite(rec.values)) and rec.values[-1, 0] < 0.0


def test_diverging_run_names_step_and_time_and_the_hdf5_file_keeps_every_step_before(tmp_path):
    """A midspan load ramping up (factor 100 t) crosses divergence_limit: DivergenceError with the
    step and the time; the HDF5 recorder file holds every step before it (across chunks of 7
    steps), equal to a memory recorder's; the model state stays finite."""
    m = loaded_beam(cmass=1)
    m.remove_pattern(1)
    m.add_time_series(vtsi.Linear(1e2, tag=2))
    m.pattern(2, 2)
    m.load(2, 3, 0.0, -P, 0.0)
    limit, dt = 1e-3, 1e-3
    path = tmp_path / "midspan.h5"
    disk, memory = NodeRecorder([3], [2], sink=HDF5Sink(path)), NodeRecorder([3], [2])
    analysis = vtsi.TransientAnalysis(m, "Newmark", dt, recorders=[disk, memory], divergence_limit=limit, chunk_steps=7)
    with pytest.raises(DivergenceError) as info:
        analysis.run(1000)
    step, t = info.value.step, info.value.time
    assert step > 7 and t == pytest.approx(step * dt, rel=1e-12)
    assert str(info.value).startswith(f"transient analysis diverged at step {step} of this run, t = {t:.6g} s (|u| > 0.001 or NaN)")
    with h5py.File(path, "r") as f:                          # closed by the analysis, readable
        values, times = f["values"][:, 0], f["time"][...]
    assert len(values) == step - 1
    np.testing.assert_array_equal(values, memory.values[:, 0])
    np.testing.assert_allclose(times, dt * np.arange(1, step), rtol=1e-12)
    assert np.all(np.abs(values) <= limit) and np.all(np.isfinite(values))
    state = vtsi.domain_state(m)
    assert np.all(np.isfinite(state.u)) and state.time <= (step - 1) * dt + 1e-12


# =============================================================================================
# 3. time series, and no silent NaN
# =============================================================================================
SERIES_CASES = [
    ("unequal time and values", lambda: vtsi.Path([1.0, 2.0, 3.0], time=[0.0, 1.0]),
     r"^timeSeries Path: 2 times but 3 values$"),
    ("time not increasing", lambda: vtsi.Path([1.0, 2.0, 3.0], time=[0.0, 1.0, 1.0], tag=4),
     r"^timeSeries Path 4: times must increase strictly; time\[2\] = 1 follows time\[1\] = 1$"),
    ("NaN value", lambda: vtsi.Path([1.0, NAN, 3.0], dt=0.1, tag=4), r"^timeSeries Path 4: value 1 is nan \(NaN or inf\)$"),
    ("NaN time", lambda: vtsi.Path([1.0, 2.0], time=[0.0, NAN]), r"^timeSeries Path: time\[1\] is nan \(NaN or inf\)$"),
    ("empty", lambda: vtsi.Path([], time=[]), r"^timeSeries Path: no values given$"),
    ("text values", lambda: vtsi.Path(["a", "b"], dt=0.1), r"^timeSeries Path: values must be numbers, got \['a', 'b'\]$"),
    ("neither time nor dt", lambda: vtsi.Path([1.0, 2.0]), r"^timeSeries Path: give the sample times \(time=...\) or the step dt$"),
    ("dt = 0", lambda: vtsi.Path([1.0, 2.0], dt=0.0), r"^timeSeries Path: dt must be > 0, got 0.0$"),
    ("dt NaN", lambda: vtsi.Path([1.0, 2.0], dt=NAN, tag=3), r"^timeSeries Path 3: dt must be finite, got nan$"),
    ("Constant NaN factor", lambda: vtsi.Constant(NAN, tag=3), r"^timeSeries Constant 3: factor must be finite, got nan$"),
    ("Linear text factor", lambda: vtsi.Linear("fast", tag=3), r"^timeSeries Linear 3: factor must be a number, got 'fast'$"),
    ("Trig ending before it starts", lambda: Trig(2.0, 1.0, 0.5, tag=3),
     r"^timeSeries Trig 3: tEnd = 1 is before tStart = 2 \(the series would be 0 always\)$"),
    ("Rectangular ending before it starts", lambda: Rectangular(5.0, 1.0),
     r"^timeSeries Rectangular: tEnd = 1 is before tStart = 5 \(the series would be 0 always\); if 5 was meant as the "
     r"tag, give it as tag=5: Rectangular's first argument is tStart \(OpenSees's 'timeSeries Rectangular <tag> "
     r"<tStart> \.\.\.'\)$"),
    ("Path with 2-D values", lambda: vtsi.Path([[1.0, 2.0], [3.0, 4.0]], dt=0.1),
     r"^timeSeries Path: values must be a 1-D sequence, got shape \(2, 2\)$"),
    ("Path with 2-D times", lambda: vtsi.Path([1.0, 2.0], time=[[0.0, 1.0]]),
     r"^timeSeries Path: time must be a 1-D sequence, got shape \(1, 2\)$"),
    ("Path values as one text", lambda: vtsi.Path("12", dt=0.1), r"^timeSeries Path: values must be numbers, got '12'$"),
    ("Path use_last as text", lambda: vtsi.Path([1.0, 2.0], dt=0.1, use_last="no"),
     r"^timeSeries Path: use_last must be True or False, got 'no'$"),
    ("Path prepend_zero as text", lambda: vtsi.Path([1.0, 2.0], dt=0.1, prepend_zero="no", tag=3),
     r"^timeSeries Path 3: prepend_zero must be True or False, got 'no'$"),
    ("Linear at a text time", lambda: vtsi.Linear(1.0, tag=3)("x"), r"^timeSeries Linear 3: times must be numbers \[s\], got 'x'$"),
    ("Path at a text time", lambda: vtsi.Path([1.0, 2.0], dt=0.1)("x"), r"^timeSeries Path: times must be numbers \[s\], got 'x'$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in SERIES_CASES], ids=[c[0] for c in SERIES_CASES])
def test_time_series_input_is_rejected(bad, match):
    with pytest.raises(ModelError, match=match) as info:
        bad()
    _assert_message(info, match)


def test_nan_load_factor_stops_a_static_run_and_keeps_the_steps_before():
    m = loaded_beam()
    m.pattern(2, NaNSeries(t_bad=3.0)).load(3, 0.0, -1.0, 0.0)
    rec = NodeRecorder([3], [2])
    with pytest.raises(ModelError, match=r"^pattern 2: time series 9 \(NaNSeries\) gives load factor nan at t = 3 s$"):
        vtsi.StaticAnalysis(m, 1.0, recorders=[rec]).run(5)
    np.testing.assert_array_equal(rec.time, [1.0, 2.0])      # steps 1 and 2 kept
    assert np.all(np.isfinite(rec.values))
    state = vtsi.domain_state(m)
    assert state.time == 2.0 and np.all(np.isfinite(state.u))


def test_nan_load_factor_stops_a_transient_run_naming_pattern_and_time():
    m = loaded_beam(cmass=1)
    m.pattern(2, NaNSeries(t_bad=0.005)).load(3, 0.0, -1.0, 0.0)
    rec = NodeRecorder([3], [2])
    with pytest.raises(VtsiError, match=r"pattern 2: time series 9 \(NaNSeries\) gives load factor nan at t = 0.005 s"):
        vtsi.TransientAnalysis(m, "Newmark", 1e-3, recorders=[rec], chunk_steps=2).run(10)
    assert np.all(np.isfinite(rec.values)) and np.all(rec.time < 0.005)
    assert np.all(np.isfinite(vtsi.domain_state(m).u))


# =============================================================================================
# 4. recorders
@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs Linux's /dev/full (every write: no space left)")
def test_a_full_disk_names_the_recorder_its_file_and_the_records_times():
    """A text recorder whose writes fail (a full disk) stops the run with the recorder, its
    file and the times of the records it could not write (the analysis' closing of the
    recorder does not replace that error with a second one)."""
    recorder = NodeRecorder([3], [2], sink=TextSink("/dev/full"))
    analysis = vtsi.TransientAnalysis(loaded_beam(cmass=1), "Newmark", 1e-3, recorders=[recorder], chunk_steps=5)
    with pytest.raises(RecorderError, match=r"^node recorder \(text file /dev/full\): cannot write the records of "
                                            r"t = 0\.001 to 0\.005 s \(No space left on device\); the file holds no "
                                            r"lines$"):
        analysis.run(20)


def test_a_command_recorder_tries_its_file_again_after_a_failed_write(tmp_path):
    """A command-layer recorder stays open from one analyze to the next: after a write that
    failed (its handle dropped, unflushed records reported lost), the next analyze writes to the
    file again, after the lines written before the failure. The failed analyze committed its step,
    as OpenSees commits a step whose recorder fails: the model is at t = 0.03 s, which the error
    named lost from this file, and the next step is t = 0.04 s (before, the model's displacements
    were at 0.03 s and its time at 0.02 s, and the step was recorded again)."""
    session = ops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    session.node(1, 0.0, 0.0)
    session.node(2, 10.0, 0.0)
    session.fix(1, 1, 1, 0)
    session.fix(2, 0, 1, 0)
    session.geomTransf("Linear", 1)
    session.element("elasticBeamColumn", 1, 1, 2, 1.0, 2e11, 1e-2, 1, "-mass", 1e3)
    session.integrator("Newmark", 0.5, 0.25)
    session.analysis("Transient")
    path = tmp_path / "x.out"
    sink = session.recorders[session.recorder("Node", "-file", str(path), "-time", "-node", 2, "-dof", 2, "disp")].sink
    session.analyze(2, 0.01)

    class FullDisk:
        def write(self, data):
            raise OSError(28, "No space left on device")

        def close(self):
            raise OSError(28, "No space left on device")

    sink._handle = FullDisk()
    with pytest.raises(RecorderError, match=r"^recorder 0 \(node, text file .*x\.out\): cannot write the records of "
                                            r"t = 0\.03 to 0\.03 s \(No space left on device\); the file holds the 2 "
                                            r"lines up to t = 0\.02 s$"):
        session.analyze(1, 0.01)
    assert session.getTime() == pytest.approx(0.03)
    session.analyze(1, 0.01)
    session.wipe()
    times = [float(line.split()[0]) for line in path.read_text().splitlines()]
    assert times == pytest.approx([0.01, 0.02, 0.04])


def test_a_failed_hdf5_write_names_the_file_and_keeps_the_chunks_before(tmp_path, monkeypatch):
    """The third chunk's write fails as on a full disk (OSError ENOSPC from h5py): the error names
    the HDF5 recorder, its file and the chunk's times, and the file keeps the two chunks before."""
    write, calls = HDF5Sink._write, []

    def failing_third(sink, times, values, envelope):
        calls.append(len(times))
        if len(calls) == 3:
            raise OSError(28, "No space left on device")
        write(sink, times, values, envelope)

    monkeypatch.setattr(HDF5Sink, "_write", failing_third)
    path = tmp_path / "midspan.h5"
    recorder = NodeRecorder([3], [2], sink=HDF5Sink(path))
    analysis = vtsi.TransientAnalysis(loaded_beam(cmass=1), "Newmark", 1e-3, recorders=[recorder], chunk_steps=5)
    with pytest.raises(RecorderError, match=r"^node recorder \(HDF5 file .*midspan\.h5\): cannot write the records "
                                            r"of t = 0\.011 to 0\.015 s \(No space left on device\); the file holds "
                                            r"the 10 rows up to t = 0\.01 s$"):
        analysis.run(20)
    with h5py.File(path, "r") as f:
        np.testing.assert_allclose(f["time"][...], 1e-3 * np.arange(1, 11), rtol=1e-12)


# =============================================================================================
def test_existing_hdf5_file_is_refused_when_the_sink_is_built(tmp_path):
    path = tmp_path / "results.h5"
    path.write_bytes(b"yesterday's results")
    with pytest.raises(FileExistsError, match=r"^HDF5 recorder: .*results\.h5 already exists; pass overwrite=True"):
        HDF5Sink(path)                                       # before any recorder or analysis
    assert path.read_bytes() == b"yesterday's results"


def test_hdf5_sink_overwrite_must_be_a_bool_and_the_file_is_kept(tmp_path):
    path = tmp_path / "results.h5"
    path.write_bytes(b"yesterday's results")
    with pytest.raises(ModelError, match=r"^HDF5 recorder .*results\.h5: overwrite must be True or False, got 'no'$"):
        HDF5Sink(path, overwrite="no")                       # 'no' is not taken for True
    assert path.read_bytes() == b"yesterday's results"


def test_hdf5_sink_on_a_directory_says_so(tmp_path):
    for overwrite in (False, True):
        with pytest.raises(IsADirectoryError, match=r"^HDF5 recorder: .* is a directory; give a file name$"):
            HDF5Sink(tmp_path, overwrite=overwrite)
    assert tmp_path.is_dir()


def test_unknown_compression_is_refused_when_the_sink_is_built_and_no_file_is_created(tmp_path):
    with pytest.raises(ModelError, match=r"^HDF5 recorder .*f\.h5: compression 'bogus' with options None is not "
                                         r"available: .*bogus"):
        HDF5Sink(tmp_path / "f.h5", compression="bogus")
    with pytest.raises(ModelError, match=r"^HDF5 recorder .*f\.h5: compression 'gzip' with options 99 is not available"):
        HDF5Sink(tmp_path / "f.h5", compression="gzip", compression_opts=99)
    assert list(tmp_path.iterdir()) == []
    rec = NodeRecorder([3], [2], sink=HDF5Sink(tmp_path / "f.h5", compression="gzip", compression_opts=4))
    vtsi.StaticAnalysis(loaded_beam(), recorders=[rec]).run(1)
    with h5py.File(tmp_path / "f.h5", "r") as f:
        assert f["values"].compression == "gzip" and f["values"][0, 0] == pytest.approx(DEFLECTION, rel=1e-9)


SINK_CASES = [
    ("HDF5 path None", lambda d: HDF5Sink(None), r"^HDF5 recorder: path must be a file name \(str or os.PathLike\), got None$"),
    ("text path None", lambda d: TextSink(None), r"^text recorder: path must be a file name \(str or os.PathLike\), got None$"),
    ("flush_every text", lambda d: HDF5Sink(d / "f.h5", flush_every="x"),
     r"^HDF5 recorder .*f\.h5: flush_every must be an integer >= 1, got 'x'$"),
    ("flush_every NaN", lambda d: HDF5Sink(d / "f.h5", flush_every=NAN),
     r"^HDF5 recorder .*f\.h5: flush_every must be an integer >= 1, got nan$"),
    ("flush_every list", lambda d: HDF5Sink(d / "f.h5", flush_every=[1]),
     r"^HDF5 recorder .*f\.h5: flush_every must be an integer >= 1, got \[1\]$"),
    ("precision text", lambda d: TextSink(d / "t.out", precision="x"),
     r"^text recorder .*t\.out: precision must be an integer >= 0, got 'x'$"),
    ("precision NaN", lambda d: TextSink(d / "t.out", precision=NAN),
     r"^text recorder .*t\.out: precision must be an integer >= 0, got nan$"),
    ("precision None", lambda d: TextSink(d / "t.out", precision=None),
     r"^text recorder .*t\.out: precision must be an integer >= 0, got None$"),
    ("empty text file name", lambda d: TextSink(""), r"^text recorder: path must be a non-empty file name, got ''$"),
    ("empty HDF5 file name", lambda d: HDF5Sink(" "), r"^HDF5 recorder: path must be a non-empty file name, got ' '$"),
    ("bytes file name", lambda d: HDF5Sink(b"f.h5"),
     r"^HDF5 recorder: path must be a file name \(str or os\.PathLike\), got b'f\.h5'$"),
    ("text time flag as text", lambda d: TextSink(d / "t.out", time="yes"),
     r"^text recorder .*t\.out: time must be True or False, got 'yes'$"),
]


@pytest.mark.parametrize("make, match", [c[1:] for c in SINK_CASES], ids=[c[0] for c in SINK_CASES])
def test_sink_input_is_rejected_when_built_and_no_file_is_created(tmp_path, make, match):
    with pytest.raises(ModelError, match=match) as info:
        make(tmp_path)
    _assert_message(info, match)
    assert list(tmp_path.iterdir()) == []


def test_hdf5_sink_under_a_file_says_so(tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(NotADirectoryError, match=r"^HDF5 recorder: .*notes\.txt of .*notes\.txt.x\.h5 is a file, not a directory$"):
        HDF5Sink(tmp_path / "notes.txt" / "x.h5")
    assert (tmp_path / "notes.txt").read_text() == "x"


def test_hdf5_sink_in_a_missing_directory(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"^HDF5 recorder: directory .*nowhere of .*nowhere.x\.h5 does not exist$"):
        HDF5Sink(tmp_path / "nowhere" / "x.h5")


RECORDER_BUILD_CASES = [
    ("node: unknown response lists the valid ones", lambda: NodeRecorder([3], [2], "displacement"),
     r"^node recorder: unknown response 'displacement'; valid: disp, vel, accel, reaction, reactionIncInertia$"),
    ("node: dof 0", lambda: NodeRecorder([3], [0]), r"^node recorder: dofs are 1-based \(1 ux, 2 uy, 3 rz\), got \[0\]$"),
    ("node: text node tag", lambda: NodeRecorder(["mid"], [2]), r"^node recorder: nodes must be integers, got \['mid'\]$"),
    ("node: negative dt", lambda: NodeRecorder([3], [2], dt=-0.1), r"^node recorder: dt must be >= 0 and finite, got -0.1$"),
    ("element: response not a name", lambda: ElementRecorder([1], 3), r"^element recorder: response must be a name, got 3$"),
    ("records nothing", lambda: NodeRecorder([3], [2], history=False), r"^node recorder: records nothing"),
    ("envelope as text", lambda: NodeRecorder([3], [2], envelope="no"), r"^node recorder: envelope must be True, False or 'concurrent', got 'no'$"),
    ("history as text", lambda: NodeRecorder([3], [2], history="no"), r"^node recorder: history must be True or False, got 'no'$"),
    ("include_inertia as text", lambda: ReactionRecorder([1], [2], include_inertia="no"),
     r"^reaction recorder: include_inertia must be True or False, got 'no'$"),
    ("modal: dof as text", lambda: ModalNodeRecorder([3], "x", "disp", np.zeros((15, 2))),
     r"^modal node recorder: dof must be an integer >= 1 \(1 ux, 2 uy, 3 rz\), got 'x'$"),
    ("modal: shapes as text", lambda: ModalNodeRecorder([3], 2, "disp", "shapes"),
     r"^modal node recorder: shapes must be an array of numbers \(n_full, n_modes\), got str 'shapes'$"),
    ("modal: NaN in shapes", lambda: ModalNodeRecorder([3], 2, "disp", np.full((15, 2), NAN)),
     r"^modal node recorder: shapes have NaN or inf: row 0, mode 0 is nan$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in RECORDER_BUILD_CASES], ids=[c[0] for c in RECORDER_BUILD_CASES])
def test_recorder_input_is_rejected_when_built(bad, match):
    with pytest.raises(ModelError, match=match) as info:
        bad()
    _assert_message(info, match)


def test_one_sink_for_two_recorders_and_text_file_with_history_and_envelope(tmp_path):
    sink = MemorySink()
    first = NodeRecorder([3], [2], sink=sink)
    with pytest.raises(ModelError, match=r"^MemorySink: this sink already belongs to NodeRecorder"):
        NodeRecorder([2], [2], sink=sink)
    assert sink._owner is first
    with pytest.raises(ModelError, match=r"^text recorder .*both\.out: a text file holds the history"):
        NodeRecorder([3], [2], sink=TextSink(tmp_path / "both.out"), envelope=True)


RECORDER_START_CASES = [
    ("node recorder on unknown node", lambda: NodeRecorder([42], [2]), ModelError,
     r"^node recorder: node 42 does not exist$"),
    ("node recorder on dof 4", lambda: NodeRecorder([3], [4]), ModelError,
     r"^node recorder: node 3: dof 4 out of range 1\.\.3$"),
    ("element recorder on unknown element", lambda: ElementRecorder([42]), ModelError,
     r"^element recorder: element 42 does not exist$"),
    ("element recorder with unknown response", lambda: ElementRecorder([1], "stress"), ModelError,
     r"^element recorder: element 1 \(elasticBeamColumn\) has no response 'stress'; valid: force, globalForce, localForce, "
     r"basicDeformation, chordRotation, chordDeformation, basicStiffness, xaxis, yaxis, zaxis$"),
]


@pytest.mark.parametrize("make, exc, match", [c[1:] for c in RECORDER_START_CASES], ids=[c[0] for c in RECORDER_START_CASES])
def test_recorder_on_unknown_object_fails_before_any_step_and_creates_no_file(tmp_path, make, exc, match):
    m = loaded_beam()
    bad = make()
    path = tmp_path / "good.h5"
    good = NodeRecorder([3], [2], sink=HDF5Sink(path))
    with pytest.raises(exc, match=match):
        vtsi.StaticAnalysis(m, recorders=[good, bad]).run(1)
    assert vtsi.domain_state(m).time == 0.0 and not path.exists()
    vtsi.StaticAnalysis(m, recorders=[good]).run(1)          # the model and the good recorder still work
    assert good.values[0, 0] == pytest.approx(DEFLECTION, rel=1e-9)


# =============================================================================================
# 5. train and track
# =============================================================================================
@pytest.fixture(scope="module")
def bridge():
    m = vtsi.Model()
    b = simply_supported_beam(m, 20.0, 8, 3e10, 1.0, 1e4)   # elements 1..8, 2.5 m each
    return m, b


def sloped_model():
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 5.0, 1.0)
    m.fix(1, 1, 1, 0)
    m.fix(2, 0, 1, 0)
    m.element("elasticBeamColumn", 1, (1, 2), **BEAM)
    return m


def truss_model():
    m = vtsi.Model()
    m.node(1, 0.0, 0.0)
    m.node(2, 1.0, 0.0)
    m.fix(1, 1, 1, 1)
    m.fix(2, 0, 1, 1)
    m.element("truss", 1, (1, 2), A=1.0, E=1.0)
    return m


TRACK_CASES = [
    ("non-horizontal element", lambda b: Track(sloped_model(), [1]), r"^track: element 1 is not horizontal \(y from 0 to 1\)$"),
    ("gap in the chain", lambda b: Track(b[0], [1, 2, 4]),
     r"^track: elements 2 and 4 leave a gap or overlap between x = 5 and 7\.5$"),
    ("unknown element", lambda b: Track(b[0], [1, 42]), r"^track: element 42 does not exist$"),
    ("element listed twice", lambda b: Track(b[0], [1, 2, 2]), r"^track: element 2 is listed twice$"),
    ("no elements", lambda b: Track(b[0], []), r"^track: no elements given$"),
    ("text element tag", lambda b: Track(b[0], [1, "2"]), r"^track: element tags must be integers, got '2'$"),
    ("truss as track", lambda b: Track(truss_model(), [1]),
     r"^track: element 1 \(truss\) is not a 2-node beam with ux, uy, rz dofs$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in TRACK_CASES], ids=[c[0] for c in TRACK_CASES])
def test_track_input_is_rejected(bridge, bad, match):
    with pytest.raises(ModelError, match=match) as info:
        bad(bridge)
    _assert_message(info, match)


CAR = dict(m_s=1000.0, k_s=1e6, m_w=100.0)
CAR_CASES = [
    ("negative sprung mass", lambda: sprung_mass(-1.0, 1e6), r"^sprung_mass: m_s must be > 0, got -1.0$"),
    ("NaN spring", lambda: sprung_mass(1.0, NAN), r"^sprung_mass: k_s must be > 0, got nan$"),
    ("negative damping", lambda: four_dof_car(1e4, 1e5, 1e3, 1e6, -5.0, 10.0), r"^four_dof_car: c_s must be >= 0, got -5.0$"),
    ("zero moving force", lambda: moving_force(0.0), r"^moving_force: P must be > 0, got 0.0$"),
    ("ten-dof car without its parameters", lambda: ten_dof_car({"body_mass": 4e4}),
     r"^ten_dof_car: missing parameters \['axle_spacing', .*\]"),
    ("unknown catalogue car lists the valid names", lambda: car_from_catalogue("ICE4"),
     r"^car_from_catalogue: unknown car 'ICE4'; valid names: \[.*'ICE3_coach'.*\]$"),
    ("negative speed", lambda: Train([sprung_mass(**CAR)], [0.0], -5.0),
     r"^train 'train': speed must be finite and >= 0, got -5.0$"),
    ("two cars on one spot", lambda: Train([sprung_mass(**CAR)] * 2, [0.0, 0.0], 5.0),
     r"^train 'train': wheel offsets must increase from head to tail; wheel 1 \(car 1\) at 0.0 m"),
    ("a parameter that is not a number", lambda: four_dof_car(1e4, 1e5, 1e3, "stiff", 5.0, 10.0),
     r"^four_dof_car: k_s must be a number, got 'stiff'$"),
    ("a ten-dof parameter that is not a number",
     lambda: ten_dof_car({name: 1.0 for name in TEN_DOF_PARAMETERS} | {"body_mass": None}), r"^ten_dof_car: body_mass must be a number, got None$"),
    ("a speed that is not a number", lambda: Train([sprung_mass(**CAR)], [0.0], "fast"),
     r"^train 'train': speed \[m/s\] must be a number, got 'fast'$"),
    ("car offsets that are not numbers", lambda: Train([sprung_mass(**CAR)], ["front"], 5.0),
     r"^train 'train': car_offsets must be numbers \[m\], got \['front'\]$"),
    ("a car count that is not an integer", lambda: ice3("8", speed=50.0), r"^ice3: n_cars must be an integer >= 2, got '8'$"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in CAR_CASES], ids=[c[0] for c in CAR_CASES])
def test_car_and_train_input_is_rejected(bad, match):
    with pytest.raises(ValueError, match=match) as info:
        bad()
    _assert_message(info, match)


@pytest.fixture()
def coupled(bridge):
    m, b = bridge
    train = TrainSubdomain(Train([sprung_mass(**CAR)], [0.0], 20.0), x_head0=0.0)
    return m, Track(m, b.elements), train


COUPLED_CASES = [
    ("train dof name unknown lists the valid ones", lambda m, tr, t, c: TrainRecorder(t, ["car0.bodyy"]),
     ModelError, r"^train recorder: unknown train dof 'car0.bodyy'; valid: car0.body_y, car0.wheel1_y$"),
    ("train dof index out of range", lambda m, tr, t, c: TrainRecorder(t, [7]),
     ModelError, r"^train recorder: train dof 7 out of range 0\.\.1$"),
    ("train recorder response", lambda m, tr, t, c: TrainRecorder(t, None, "force"),
     ModelError, r"^train recorder: unknown response 'force'; valid: disp, vel, accel$"),
    ("contact wheel out of range", lambda m, tr, t, c: ContactRecorder(c, [3]),
     ModelError, r"^contact recorder: wheel 3 out of range 0\.\.0$"),
    ("x_head0 NaN", lambda m, tr, t, c: TrainSubdomain(t.train, NAN),
     ModelError, r"^TrainSubdomain: x_head0 must be finite, got nan$"),
    ("unknown interpolation", lambda m, tr, t, c: MovingLoadConstraint(tr, t, interpolation="spline"),
     ModelError, r"^MovingLoadConstraint: unknown interpolation 'spline'; valid: hermite, bspline$"),
    ("irregularity not callable", lambda m, tr, t, c: MovingLoadConstraint(tr, t, irregularity=1e-3),
     ModelError, r"^MovingLoadConstraint: irregularity must be callable r\(x\)"),
    ("explicit integrator", lambda m, tr, t, c: CoupledAnalysis(m, c, "CentralDifference", 1e-4),
     AnalysisError, r"^CoupledAnalysis: CentralDifference is explicit; a constrained analysis needs an implicit"),
    ("unknown contact strategy", lambda m, tr, t, c: CoupledAnalysis(m, c, "Newmark", 1e-3, contact="hard"),
     AnalysisError, r"^CoupledAnalysis: unknown contact strategy 'hard'; valid: bilateral, lcp$"),
    ("dt = 0", lambda m, tr, t, c: CoupledAnalysis(m, c, "Newmark", 0.0),
     AnalysisError, r"^CoupledAnalysis: dt must be > 0 and finite, got 0.0$"),
    ("NaN irregularity under a wheel",
     lambda m, tr, t, c: MovingLoadConstraint(tr, t, irregularity=lambda x: np.where(x > 1.0, np.nan, 0.0))
     .irregularity_at(np.array([0.0, 0.1]), 1e-3),
     ModelError, r"^MovingLoadConstraint: the irregularity gives nan under contact wheel 0 at x = 2 m$"),
]


def test_a_conditionally_stable_scheme_on_a_massless_dof_is_named_in_both_analyses():
    """A lumped-mass beam has no rotary mass: under Newmark's linear-acceleration rule no dt is
    stable. Both analyses (they build their stages in one place) name the dof; it said 'stability
    limit 0 s (... omega_max = inf rad/s)'."""
    m = vtsi.Model()
    b = simply_supported_beam(m, 20.0, 4, 3e10, 1.0, 1e4, consistent_mass=False)
    message = r"^integrator Newmark is conditionally stable and node \d dof 3 \(rz\) is a free dof without mass"
    with pytest.raises(AnalysisError, match=message):
        vtsi.TransientAnalysis(m, Newmark(0.5, 1 / 6), 1e-3).run(1)
    train = TrainSubdomain(Train([sprung_mass(**CAR)], [0.0], 20.0), x_head0=-1.0)
    with pytest.raises(AnalysisError, match=message):
        CoupledAnalysis(m, MovingLoadConstraint(Track(m, b.elements), train), Newmark(0.5, 1 / 6), 1e-3).static()


@pytest.mark.parametrize("bad, exc, match", [c[1:] for c in COUPLED_CASES], ids=[c[0] for c in COUPLED_CASES])
def test_coupled_input_is_rejected(coupled, bad, exc, match):
    m, track, train = coupled
    con = MovingLoadConstraint(track, train)
    with pytest.raises(exc, match=match) as info:
        bad(m, track, train, con)
    _assert_message(info, match)


def test_irregularity_that_does_not_cover_the_travel_is_refused_before_any_step(coupled):
    m, track, train = coupled
    x = np.linspace(0.0, 5.0, 51)
    rail = Irregularity(x, 1e-3 * np.sin(x))
    analysis = CoupledAnalysis(m, MovingLoadConstraint(track, train, irregularity=rail), "Newmark", 1e-3)
    t0 = vtsi.domain_state(m).time
    with pytest.raises(ModelError, match=r"^MovingLoadConstraint: the irregularity is sampled on \[0, 5\] m but the "
                                         r"wheels travel over \[0, 20\] m in this run"):
        analysis.run(1000)
    assert vtsi.domain_state(m).time == t0 and len(analysis.time) == 0


# =============================================================================================
# 6. commands (vtsi.opensees, vtsi.tcl)
# =============================================================================================
def session():
    s = ops.Session()
    s.model("basic", "-ndm", 2, "-ndf", 3)
    s.node(1, 0.0, 0.0)
    s.node(2, 10.0, 0.0)
    s.fix(1, 1, 1, 1)
    s.geomTransf("Linear", 1)
    return s


COMMAND_CASES = [
    ("unknown element type", lambda s: s.element("elasticBeam", 1, 1, 2, 1.0, 1.0, 1.0, 1),
     r"^element: type 'elasticBeam' is not supported; supported: elasticBeamColumn, ElasticTimoshenkoBeam, truss, zeroLength"),
    ("unknown element option", lambda s: s.element("elasticBeamColumn", 1, 1, 2, 1.0, 1.0, 1.0, 1, "-massDens", 1.0),
     r"option '-massDens' is not supported; supported: -mass, -cMass"),
    ("unknown time series type", lambda s: s.timeSeries("Ramp", 1),
     r"^timeSeries: type 'Ramp' is not supported; supported: Constant, Linear, Path"),
    ("unknown Path option", lambda s: s.timeSeries("Path", 1, "-dt", 0.1, "-values", 1.0, 2.0, "-foo"),
     r"^timeSeries Path 1: option '-foo' is not supported"),
    ("unknown integrator", lambda s: s.integrator("Wilson", 1.4), r"integrator 'Wilson' is not supported; supported: .*Newmark"),
    ("unknown analysis", lambda s: s.analysis("Quasi"), r"analysis type 'Quasi' is not supported; supported: Static, Transient"),
    ("unknown system", lambda s: s.system("Cusp"), r"system 'Cusp' is not supported; supported: BandSPD"),
    ("unknown algorithm option", lambda s: s.algorithm("Newton", "-foo"),
     r"^algorithm Newton: option '-foo' is not supported"),
    ("unknown recorder type", lambda s: s.recorder("Drift", "-file", "x.out"),
     r"recorder type 'Drift' is not supported; supported: Node, EnvelopeNode, Element, EnvelopeElement"),
    ("3-D model", lambda s: s.model("basic", "-ndm", 3), r"^model: vtsi is 2-D, -ndm must be 2, got 3$"),
    ("pattern on unknown series", lambda s: s.pattern("Plain", 1, 9), r"^pattern Plain 1: time series 9 does not exist$"),
    ("analyze before analysis", lambda s: s.analyze(1), r"^analyze: no analysis defined"),
]


@pytest.mark.parametrize("bad, match", [c[1:] for c in COMMAND_CASES], ids=[c[0] for c in COMMAND_CASES])
def test_command_input_is_rejected(bad, match):
    s = session()
    with pytest.raises(CommandError, match=match) as info:
        bad(s)
    _assert_message(info, match)
    assert s.getNodeTags() == [1, 2]                          # the session's model is intact


def test_unknown_command_is_named_with_the_valid_ones():
    with pytest.raises(ops.UnknownCommand, match=r"^vtsi.opensees has no command 'nodeDisplacement'; supported "
                                                 r"commands: model, node, fix, .*nodeDisp") as info:
        ops.nodeDisplacement(1)
    assert isinstance(info.value, CommandError) and isinstance(info.value, AttributeError)


def test_unknown_tcl_command_is_named():
    from vtsi.tcl import Interpreter
    with pytest.raises(ops.UnknownCommand, match=r"unknown command 'nodee'"):
        Interpreter(ops.Session()).eval("model basic -ndm 2 -ndf 3\nnodee 1 0 0")


def test_newmark_with_beta_zero_is_named_as_what_makes_it_explicit(coupled):
    """CoupledAnalysis(..., Newmark(0.5, 0.0)) said 'Newmark is explicit; ... needs an implicit
    integrator (Newmark, HHT, Bathe)', naming Newmark as both the fault and the cure."""
    m, track, train = coupled
    match = (r"^CoupledAnalysis: Newmark with beta = 0 \(central differences\) is explicit; a constrained analysis "
             r"needs an implicit integrator: Newmark with beta > 0 \(e\.g\. Newmark\(0\.5, 0\.25\)\), HHT or Bathe$")
    with pytest.raises(AnalysisError, match=match) as info:
        CoupledAnalysis(m, MovingLoadConstraint(track, train), Newmark(0.5, 0.0), 1e-3)
    _assert_message(info, match)


def test_two_recorders_on_one_file_of_a_coupled_analysis_are_refused_when_it_is_built(coupled, tmp_path):
    m, track, train = coupled
    con = MovingLoadConstraint(track, train)
    first = TrainRecorder(train, None, "disp", sink=TextSink(tmp_path / "same.out"))
    second = ContactRecorder(con, sink=TextSink(tmp_path / "same.out"))
    with pytest.raises(ModelError, match=r"^CoupledAnalysis: recorders\[0\] TrainRecorder.* and recorders\[1\] "
                                         r"ContactRecorder.* both write .*same\.out; give each recorder its own file$"):
        CoupledAnalysis(m, con, "Newmark", 1e-3, recorders=[first, second])


H5_SCRIPT = """model basic -ndm 2 -ndf 3
node 1 0.0 0.0
node 2 5.0 0.0
node 3 10.0 0.0
fix 1 1 1 0
fix 3 0 1 0
geomTransf Linear 1
element elasticBeamColumn 1 1 2 0.5 3e10 0.04 1 -mass 1000.0
element elasticBeamColumn 2 2 3 0.5 3e10 0.04 1 -mass 1000.0
timeSeries Linear 1
pattern Plain 1 1 { load 2 0.0 -1e5 0.0 }
recorder Node -h5 {H5} -time -node 2 -dof 2 disp
recorder Node -file {OUT} -time -node 2 -dof 2 disp
integrator Newmark 0.5 0.25
analysis Transient
analyze {N} 0.01
"""


def test_a_script_run_again_replaces_its_hdf5_recorder_file(tmp_path):
    """`vtsi run beam.tcl` a second time failed: 'HDF5 recorder: mid.h5 already exists; pass
    overwrite=True to replace it', advice a script cannot follow. The command layer's -h5 file
    is replaced, as OpenSees's -file recorders are; the Python API keeps its refusal."""
    from vtsi.tcl import Interpreter
    h5, out = tmp_path / "mid.h5", tmp_path / "mid.out"
    for n in (10, 4):
        script = H5_SCRIPT.replace("{H5}", str(h5)).replace("{OUT}", str(out)).replace("{N}", str(n))
        session = ops.Session()
        Interpreter(session).eval(script)
        session.wipe()
        with h5py.File(h5, "r") as f:
            assert f["values"].shape == (n, 1)
        assert len(out.read_text().splitlines()) == n
    with pytest.raises(FileExistsError, match=r"mid\.h5 already exists; pass overwrite=True"):
        HDF5Sink(h5)


def test_a_second_recorder_command_on_a_recorder_s_file_is_refused(tmp_path):
    """Two `recorder ... -file same.out` of one script interleaved rows of different widths (the
    second truncated the first's file); the second is refused before it touches the file."""
    s = session()
    s.recorder("Node", "-file", str(tmp_path / "same.out"), "-node", 2, "-dof", 2, "disp")
    (tmp_path / "same.out").write_text("kept\n")
    for option in ("-file", "-h5"):
        with pytest.raises(CommandError, match=r"^recorder Node: recorder \d+ already writes .*same\.out; give each "
                                               r"recorder its own file \(or remove recorder \d+ first\)$"):
            s.recorder("Node", option, str(tmp_path / "same.out"), "-node", 1, "-dof", 1, "disp")
    assert (tmp_path / "same.out").read_text() == "kept\n"
