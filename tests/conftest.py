"""Shared test setup.

The user-defined element type of ``examples/custom_element.py`` (``timoshenkoBeam``) is imported
once per session, as a user's script would import it, before the test modules are collected: the
contract tests (tests/test_element_contract.py) are parametrised over the registry and so check
it like the shipped types; tests/test_custom_element.py gets the module from the
``custom_element`` fixture. ``moving_load_beam`` gives the builders of the moving-force script
that several tests run through OpenSeesPy and vtsi.
"""
import importlib.util
import os
import sys
from pathlib import Path

import pytest

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
