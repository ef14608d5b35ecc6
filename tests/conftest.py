"""Shared test setup.

The user-defined element type of ``examples/custom_element.py`` (``timoshenkoBeam``) is imported
once per session, as a user's script would import it, before the test modules are collected: the
contract tests (tests/test_element_contract.py) are parametrised over the registry and so check
it like the shipped types; tests/test_custom_element.py gets the module from the
``custom_element`` fixture. ``moving_load_beam`` gives the builders of the moving-force script
that several tests run through OpenSeesPy and vtsi. The other fixtures are the test data and
setup that several test files share (bridge files and scripts, a fresh command session, the
comparisons with OpenSeesPy): each is defined here once.
"""
import importlib.util
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import vtsi
import vtsi.opensees as vops
from vtsi.tcl import Interpreter
from vtsi.vehicle import GRAVITY

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "custom_element.py"
MODULE = "vtsi_example_custom_element"


def _load_custom_element_example():
    if MODULE not in sys.modules:
        spec = importlib.util.spec_from_file_location(MODULE, EXAMPLE)
        module = importlib.util.module_from_spec(spec)
        sys.modules[MODULE] = module
        spec.loader.exec_module(module)
    return sys.modules[MODULE]


_load_custom_element_example()


@pytest.fixture(scope="session")
def custom_element():
    """The imported ``examples/custom_element.py`` module."""
    return _load_custom_element_example()


@pytest.fixture(scope="session")
def cantilever():
    """``cantilever(o)``: with the command module or Session ``o``, a fresh 2-D model of a 5-length
    cantilever (node 1 clamped, node 2 free) with nodal mass on the translations only (its rotation
    is a free dof with stiffness and no mass), a Linear series and a load of 100 down at node 2."""
    def build(o):
        o.wipe()
        o.model("basic", "-ndm", 2, "-ndf", 3)
        o.node(1, 0.0, 0.0)
        o.node(2, 5.0, 0.0)
        o.fix(1, 1, 1, 1)
        o.mass(2, 10.0, 10.0, 0.0)
        o.geomTransf("Linear", 1)
        o.element("elasticBeamColumn", 1, 1, 2, 0.5, 3e10, 0.05, 1)
        o.timeSeries("Linear", 1)
        o.pattern("Plain", 1, 1)
        o.load(2, 0.0, -100.0, 0.0)
    return build


@pytest.fixture(scope="session")
def truss_spring():
    """``truss_spring(o, series, stiffness=1.0, element="truss")``: with the command module or
    Session ``o``, a fresh 2-D model (ndf 2) of one truss ``element`` of A = 1 from node 1 (fixed)
    to node 2 (x = 1, free along x only), its Elastic material of modulus ``stiffness`` (so EA/L =
    ``stiffness``), under a load of 1 along x at node 2 in Plain pattern 1 of the timeSeries
    ``series`` (its arguments: type, tag, options)."""
    def build(o, series, stiffness=1.0, element="truss"):
        o.wipe()
        o.model("basic", "-ndm", 2, "-ndf", 2)
        o.node(1, 0.0, 0.0)
        o.node(2, 1.0, 0.0)
        o.fix(1, 1, 1)
        o.fix(2, 0, 1)
        o.uniaxialMaterial("Elastic", 1, stiffness)
        o.element(element, 1, 1, 2, 1.0, 1)
        o.timeSeries(*series)
        o.pattern("Plain", 1, series[1])
        o.load(2, 1.0, 0.0)
    return build


@pytest.fixture(scope="session")
def deck_script():
    """``deck_script(I, tail)``: the text of an OpenSeesPy bridge script (``import vtsi.opensees
    as ops``) of a 20 m simply supported deck: nodes 1-11 every 2 m, ten elasticBeamColumn
    elements (A = 5 m², E = 35 GPa, ``I`` [m⁴], 15 t/m consistent mass), track 1 on elements
    1-10, then the lines ``tail``."""
    head = """import vtsi.opensees as ops
ops.wipe()
ops.model('basic', '-ndm', 2, '-ndf', 3)
for i in range(11):
    ops.node(i + 1, 2.0 * i, 0.0)
ops.fix(1, 1, 1, 0)
ops.fix(11, 0, 1, 0)
ops.geomTransf('Linear', 1)
for i in range(1, 11):
    ops.element('elasticBeamColumn', i, i, i + 1, 5.0, 3.5e10, I, 1, '-mass', 15000.0, '-cMass')
ops.track(1, '-eleRange', 1, 10)
"""
    return lambda I, tail="": head.replace(", I, 1,", f", {I!r}, 1,") + tail


@pytest.fixture(scope="session")
def own_element_script():
    """``own_element_script(cls, name)``: the text of an OpenSeesPy bridge script that defines and
    registers its own element type, class ``cls`` named ``name`` (the elastic beam-column under the
    script's names: ``element name tag i j A E I -mass rho``), and a function ``deck_mass(span)``
    [kg/m], then builds a 20 m simply supported deck of ten such elements (lumped mass), track 1."""
    text = """import vtsi.opensees as ops
from vtsi.elements import register
from vtsi.elements.beam_column import ElasticBeamColumn2d


@register
class CLASS(ElasticBeamColumn2d):
    name = "NAME"
    command_args = ("A", "E", "I")
    command_options = {"-mass": "rho"}


def deck_mass(span):
    return 15000.0


ops.model("basic", "-ndm", 2, "-ndf", 3)
for i in range(11):
    ops.node(i + 1, 2.0 * i, 0.0)
ops.fix(1, 1, 1, 0)
ops.fix(11, 0, 1, 0)
for i in range(10):
    ops.element("NAME", i + 1, i + 1, i + 2, 5.0, 3.5e10, 1.9, "-mass", deck_mass(20.0))
ops.track(1, "-eleRange", 1, 10)
"""
    return lambda cls, name: text.replace("CLASS", cls).replace("NAME", name)


@pytest.fixture(scope="session")
def deck_tcl():
    """``deck_tcl(tail)``: the deck of :func:`deck_script` with I = 0.6948 m⁴ (f1 = 5 Hz) as a Tcl
    bridge script, then the lines ``tail``."""
    head = """model basic -ndm 2 -ndf 3
for {set i 0} {$i <= 10} {incr i} { node [expr $i + 1] [expr 2.0 * $i] 0.0 }
fix 1 1 1 0
fix 11 0 1 0
geomTransf Linear 1
for {set i 1} {$i <= 10} {incr i} { element elasticBeamColumn $i $i [expr $i + 1] 5.0 3.5e10 0.6948 1 -mass 15000.0 -cMass }
track 1 -eleRange 1 10
"""
    return lambda tail="": head + tail


@pytest.fixture(scope="session")
def approaches_tcl():
    """A Tcl bridge script: 5 m approaches of rail on ground springs (nodes 1-5 and 27-31, 1 m
    apart; 1e8 N/m along x and y to fixed nodes 101-105 and 127-131) either side of a 20 m simply
    supported deck (5 m², 35 GPa, 1.9 m⁴, 15 t/m) between node 6 (x = 5 m, pinned) and node 26
    (x = 25 m, on rollers); track 1 on elements 1-30."""
    return """
model basic -ndm 2 -ndf 3
for {set i 0} {$i <= 30} {incr i} { node [expr {$i + 1}] [expr {$i * 1.0}] 0.0 }
geomTransf Linear 1
uniaxialMaterial Elastic 1 1.0e8
for {set i 1} {$i <= 30} {incr i} {
  if {$i <= 5 || $i > 25} {
    element elasticBeamColumn $i $i [expr {$i + 1}] 0.0154 2.1e11 6.1e-5 1 -mass 2000.0 -cMass
  } else {
    element elasticBeamColumn $i $i [expr {$i + 1}] 5.0 3.5e10 1.9 1 -mass 15000.0 -cMass
  }
}
foreach n {1 2 3 4 5 27 28 29 30 31} {
  node [expr {$n + 100}] [expr {($n - 1) * 1.0}] 0.0
  fix [expr {$n + 100}] 1 1 1
  element zeroLength [expr {$n + 100}] [expr {$n + 100}] $n -mat 1 1 -dir 1 2
}
fix 6 1 1 0
fix 26 0 1 0
track 1 -eleRange 1 30
"""


@pytest.fixture(scope="session")
def beam_toml():
    """``beam_toml(path, bridge=None, **analysis)``: writes ``path``, a bridge file of a 20 m
    simply supported beam (``kind = "beam"``, E = 35 GPa, f1 = 5 Hz, μ = 15 t/m, 4 elements per
    span), its ``[bridge]`` keys updated by the dict ``bridge`` (a key given None is left out),
    its ``[analysis]`` table ``analysis`` (e.g. ``dt_s=0.005``); returns ``path``."""
    def write(path, bridge=None, **analysis):
        keys = {"kind": "beam", "spans_m": [20.0], "E_Pa": 3.5e10, "f1_Hz": 5.0, "mu_kg_m": 15000.0,
                "elements_per_span": 4, **(bridge or {})}
        lines = ["[bridge]", *(f"{key} = {json.dumps(value)}" for key, value in keys.items() if value is not None),
                 "[analysis]", *(f"{key} = {json.dumps(value)}" for key, value in analysis.items())]
        path.write_text("\n".join(lines) + "\n")
        return path
    return write


@pytest.fixture
def fresh_session():
    """The test on its own default vtsi.opensees session, wiped after it, and OpenSeesPy (the
    oracle) wiped too where a test module imported it. A module comparing with OpenSeesPy gives
    it to every test: ``pytestmark = pytest.mark.usefixtures("fresh_session")``."""
    old = vops.set_session(vops.Session())
    yield
    vops.session.wipe()
    vops.set_session(old)
    oracle = sys.modules.get("openseespy.opensees")
    if oracle is not None:
        oracle.wipe()


@pytest.fixture
def tcl(fresh_session):
    """A Tcl interpreter on the test's own vtsi session (tkinter: the standard library's Tcl)."""
    pytest.importorskip("tkinter")
    return Interpreter(vops.session)


@pytest.fixture(scope="session")
def difference():
    """``difference(reference, value)``: the largest difference of two histories (arrays of shape
    (steps, columns)), relative to each column's largest magnitude in ``reference``."""
    def largest(reference, value):
        reference, value = np.asarray(reference), np.asarray(value)
        return float((np.abs(value - reference).max(axis=0) / np.abs(reference).max(axis=0)).max())
    return largest


@pytest.fixture(scope="session")
def one_line():
    """``one_line(excinfo)``: the message of a ``pytest.raises`` exception, asserted to be one line
    without a traceback."""
    def text(excinfo):
        message = str(excinfo.value)
        assert "\n" not in message and "Traceback" not in message, message
        return message
    return text


@pytest.fixture(scope="session")
def required_args():
    """``required_args(name)``: the arguments a registered integrator needs by name, those of its
    parameters without a default (OpenSees's ``integrator HHT`` needs α)."""
    required = {"HHT": (0.9,)}
    return lambda name: required.get(name, ())


@pytest.fixture(scope="session")
def moving_load_beam():
    """``tests/scripts/moving_load_beam.py``: the Path-per-node moving force script's builders."""
    spec = importlib.util.spec_from_file_location("vtsi_test_moving_load_beam",
                                                  Path(__file__).parent / "scripts" / "moving_load_beam.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _step_load_beam():
    """A 10 m simply supported beam of 4 elements (nodes 1..5, 2.5 m apart), a 100 kN step load at
    midspan (node 3, pattern 1 on a Constant series)."""
    m = vtsi.Model()
    for i in range(5):
        m.node(i + 1, 2.5 * i, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(5, 0, 1, 0)
    for e in range(1, 5):
        m.element("elasticBeamColumn", e, (e, e + 1), A=0.5, E=3e10, I=0.04, rho=1000.0)
    m.pattern(1, vtsi.Constant())
    m.load(1, 3, 0.0, -1e5, 0.0)
    return m


@pytest.fixture(scope="session")
def step_load_beam():
    """``step_load_beam()``: a new model of :func:`_step_load_beam` at every call."""
    return _step_load_beam


def _mass_beam(o, n_el=10, length=20.0):
    """A simply supported beam of ``n_el`` elasticBeamColumn elements with mass (15 t/m; OpenSees
    commands on module or session ``o``: OpenSeesPy's or vtsi's), nodes 1..n_el + 1, pinned at 1,
    roller at the last, transformation 1."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(n_el + 1):
        o.node(i + 1, length * i / n_el, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(n_el + 1, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for i in range(n_el):
        o.element("elasticBeamColumn", i + 1, i + 1, i + 2, 5.0, 3.5e10, 0.7, 1, "-mass", 15000.0)


@pytest.fixture(scope="session")
def mass_beam():
    """``mass_beam(o, n_el=10, length=20.0)``: :func:`_mass_beam`."""
    return _mass_beam


SPAN_20M = {"L": 20.0, "n_el": 20, "E": 3.5e10, "I": 3.0, "mu": 2.0e4, "P": 98100.0}   # 1 m elements, f1 9.0 Hz


def _span_20m_commands(session):
    """By commands on ``session``: the 20 m simply supported span of :data:`SPAN_20M` (20
    ``elasticBeamColumn`` of 1 m, consistent mass, nodes 1..21, pinned at 1, roller at 21), its
    track (elements 1..20) and two cars, 1 a moving force P (a 10 t axle) and 2 a 10 t moving mass."""
    d = SPAN_20M
    session.wipe()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(d["n_el"] + 1):
        session.node(i + 1, d["L"] * i / d["n_el"], 0.0)
    session.fix(1, 1, 1, 0)
    session.fix(d["n_el"] + 1, 0, 1, 0)
    session.geomTransf("Linear", 1)
    for e in range(d["n_el"]):
        session.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0, d["E"], d["I"], 1, "-mass", d["mu"], "-cMass")
    session.track(1, "-eleRange", 1, d["n_el"])
    session.car(1, "movingForce", d["P"])
    session.car(2, "movingMass", d["P"] / GRAVITY)


@pytest.fixture(scope="session")
def span_20m_commands():
    """``span_20m_commands(session)``: :func:`_span_20m_commands` (the constants: SPAN_20M)."""
    return _span_20m_commands


# In CI (CI=true, as .ci/run sets it) or with VTSI_REQUIRE_ORACLES=1, a test that skips because a
# module could not be imported (an oracle such as openseespy or scikit-sundae, tkinter, pyvista)
# fails instead: CI installs them all, so a skip there hides a broken install.
REQUIRE_ORACLES = os.environ.get("CI") == "true" or os.environ.get("VTSI_REQUIRE_ORACLES") == "1"


def _import_skip(excinfo):
    return excinfo is not None and excinfo.errisinstance(pytest.skip.Exception) and "could not import" in str(excinfo.value)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_ORACLES and report.skipped and _import_skip(call.excinfo):
        report.outcome = "failed"
        report.longrepr = f"required module missing (CI=true / VTSI_REQUIRE_ORACLES=1): {call.excinfo.value}"


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_ORACLES and report.skipped and "could not import" in str(report.longrepr):
        report.outcome = "failed"
