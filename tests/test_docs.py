"""Docs that can be checked mechanically say what the code has."""
import builtins
import inspect
import re
from pathlib import Path

import vtsi.errors
from vtsi.recorders import ContactRecorder, NodeRecorder, ReactionRecorder, TrainRecorder
from vtsi.recorders.modal import ModalNodeRecorder
from vtsi.recorders.moment import BendingMomentRecorder

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_every_exception_class_in_bad_inputs_exists_and_every_vtsi_error_is_listed():
    text = (DOCS / "bad_inputs.md").read_text()
    named = set(re.findall(r"`?\b([A-Z][A-Za-z]*Error|UnknownCommand)\b", text))
    ours = {name for name, obj in inspect.getmembers(vtsi.errors, inspect.isclass)
            if issubclass(obj, vtsi.errors.VtsiError)} | {"UnknownCommand"}
    for name in named:
        assert name in ours or isinstance(getattr(builtins, name, None), type), name
    table = text.split("| class | base classes | raised for |")[1].split("\n\n")[0]
    for name in ours - {"VtsiError"}:
        assert f"| `{name}` |" in table, f"{name} missing from the class table of docs/bad_inputs.md"


def test_every_recorder_class_is_documented():
    text = (DOCS / "recorders.md").read_text()
    for cls in (NodeRecorder, ReactionRecorder, ModalNodeRecorder, BendingMomentRecorder, TrainRecorder,
                ContactRecorder):
        assert f"### `{cls.__name__}(" in text, cls.__name__


def test_every_train_command_is_documented_with_its_units():
    from vtsi.commands.train_commands import TRAIN_COMMANDS
    text = (DOCS / "commands.md").read_text()
    for command in TRAIN_COMMANDS:
        assert f"| `{command}` |" in text, command
    assert "**Units.**" in text


NUMPY_2_ONLY = ("np.trapezoid(", "np.cumulative_sum(", "np.unstack(", "np.vecdot(", "np.matrix_transpose(",
                "np.isdtype(", "np.concat(", "np.bitwise_count(", "np.permute_dims(")


def test_the_code_and_tests_stay_within_the_numpy_setup_cfg_allows():
    """setup.cfg allows numpy >= 1.24; nothing in the package, its tests, benchmarks or examples
    calls a function that numpy 1.x lacks (np.trapezoid was one, in a test: now scipy's)."""
    root = DOCS.parent
    bound = re.search(r"numpy>=([0-9.]+)", (root / "setup.cfg").read_text()).group(1)
    assert tuple(map(int, bound.split("."))) < (2, 0)
    for folder in ("vtsi", "elements", "integrators", "models", "tests", "benchmarks", "examples"):
        for path in (root / folder).rglob("*.py"):
            if path.name == "test_docs.py":
                continue
            text = path.read_text()
            for name in NUMPY_2_ONLY:
                assert name not in text, f"{path.relative_to(root)} calls {name} (numpy >= 2) but setup.cfg allows {bound}"
