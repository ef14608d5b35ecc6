"""vtsi's imports run one way: no module of vtsi imports, directly or through others, a module
that imports it back, counting the imports inside functions too (which would hide a circle);
the core imports no catalogue of ``vtsi.models``; the command layer imports nothing inside a function; every module of ``vtsi.commands`` imports
alone in a fresh interpreter."""
import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = {"vtsi": "vtsi", "vtsi.elements": "elements", "vtsi.integrators": "integrators", "vtsi.models": "models"}
COMMAND_LAYER = ("vtsi.commands", "vtsi.opensees", "vtsi.tcl")


def modules():
    """``{dotted name: file}`` of every module of the installed packages (setup.cfg's package_dir)."""
    found = {}
    for package, folder in PACKAGES.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            name = ".".join((package,) + path.relative_to(ROOT / folder).with_suffix("").parts)
            found[name.removesuffix(".__init__")] = path
    return found


def imports(name, path, known):
    """``{imported vtsi module: True if some import of it sits inside a function or class}``."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = {}
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base for alias in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target and target != name:
                out[target] = out.get(target, False) or node.col_offset > 0
    return out


def graph():
    known = modules()
    return {name: imports(name, path, known) for name, path in known.items()}


def cycles(edges):
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in edges:
        if v not in index:
            visit(v)
    return found


def test_the_import_graph_has_no_circle():
    edges = graph()
    assert len(edges) > 60 and "vtsi.commands.session" in edges
    assert cycles(edges) == []


def test_the_cycle_finder_finds_a_hidden_circle():
    """The check itself: a circle closed by an import inside a function is found."""
    edges = graph()
    edges["vtsi.errors"] = dict(edges["vtsi.errors"], **{"vtsi.opensees": True})
    assert any("vtsi.errors" in c and "vtsi.opensees" in c for c in cycles(edges))


CATALOGUE_USERS = ("vtsi.__main__", "vtsi.bridge_file", "vtsi.commands", "vtsi.passage", "vtsi.sweep")


def test_only_the_workflow_and_command_layers_import_the_catalogues():
    """STYLE 14: core types (a car, a train, gravity) live in the core (``vtsi.vehicle``);
    ``vtsi.models`` holds catalogues built from them, which only the layers that pick a train or
    a bridge by name (sweeps, passages, bridge files, commands, the command line) import."""
    users = sorted(name for name, out in graph().items() if not name.startswith("vtsi.models")
                   and any(target.startswith("vtsi.models") for target in out))
    assert users and all(name.startswith(CATALOGUE_USERS) for name in users), users


def test_the_command_layer_imports_at_module_level():
    inner = [(name, target) for name, out in graph().items() if name.startswith(COMMAND_LAYER)
             for target, hidden in out.items() if hidden]
    assert inner == []


COMMAND_MODULES = sorted(name for name in modules() if name.startswith(COMMAND_LAYER))


def test_each_command_module_imports_alone_in_a_fresh_interpreter():
    assert len(COMMAND_MODULES) >= 10
    runs = {name: subprocess.Popen([sys.executable, "-c", f"import {name}"], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True, cwd=ROOT)
            for name in COMMAND_MODULES}
    failed = {}
    for name, run in runs.items():
        _, err = run.communicate(timeout=300)
        if run.returncode:
            failed[name] = err.strip().splitlines()[-1:]
    assert failed == {}


@pytest.mark.parametrize("name", ["vtsi.opensees", "vtsi.tcl"])
def test_the_public_command_modules_keep_their_names(name):
    module = __import__(name, fromlist=["_"])
    for attribute in ("Session", "COMMANDS", "UnknownCommand") if name == "vtsi.opensees" else ("Interpreter",
                                                                                                  "run_file"):
        assert hasattr(module, attribute)
