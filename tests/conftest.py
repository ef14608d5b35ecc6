"""Shared test setup.

The user-defined element type of ``examples/custom_element.py`` (``timoshenkoBeam``) is imported
once per session, as a user's script would import it, before the test modules are collected: the
contract tests (tests/test_element_contract.py) are parametrised over the registry and so check
it like the shipped types; tests/test_custom_element.py gets the module from the
``custom_element`` fixture.
"""
import importlib.util
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
