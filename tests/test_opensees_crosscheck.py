"""Cross-check of the command layer against OpenSeesPy: the same bridge scripts (tests/scripts/,
plain OpenSeesPy scripts whose ``run(ops, outdir)`` takes the command module) run through
``openseespy.opensees`` and ``vtsi.opensees``; every history, eigenvalue, reaction, element force
and recorder file must agree to 1e-6 relative (relative to the largest magnitude of each
history), and the recorder files must be written alike (same lines, same columns, the same
text for nearly every line).
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402

SCRIPTS = Path(__file__).parent / "scripts"
RTOL = 1e-6


def load_script(name):
    spec = importlib.util.spec_from_file_location(f"opensees_script_{name}", SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def relative_difference(reference, value):
    """Largest ``|value - reference|`` over each history (column of a 2-D array, the whole array
    otherwise), relative to that history's largest magnitude. Histories that are zero up to
    round-off (below 1e-7 of the array's largest magnitude) are compared to that floor."""
    reference, value = np.asarray(reference, dtype=float), np.asarray(value, dtype=float)
    assert reference.shape == value.shape
    if reference.size == 0:
        return 0.0
    floor = 1e-7 * np.abs(reference).max()
    if reference.ndim == 2:
        scale = np.maximum(np.abs(reference).max(axis=0), floor)
    else:
        scale = max(np.abs(reference).max(), floor)
    if np.all(scale == 0):
        return float(np.abs(value).max())
    return float(np.max(np.abs(value - reference) / np.where(scale > 0, scale, 1.0)))


def compare_files(dir_ref, dir_val, min_identical=0.9):
    """Every recorder file of OpenSeesPy has a twin with the same lines and tokens, numerically
    equal to 1e-6 of each column's magnitude; return the fraction of byte-identical lines."""
    names = sorted(p.name for p in Path(dir_ref).iterdir())
    assert names == sorted(p.name for p in Path(dir_val).iterdir())
    fractions = {}
    for name in names:
        ref = (Path(dir_ref) / name).read_text().splitlines()
        val = (Path(dir_val) / name).read_text().splitlines()
        assert len(ref) == len(val), name
        a = np.array([[float(x) for x in line.split()] for line in ref])
        b = np.array([[float(x) for x in line.split()] for line in val])
        assert a.shape == b.shape, name
        assert relative_difference(a, b) < RTOL, name
        fractions[name] = np.mean([x == y for x, y in zip(ref, val)]) if ref else 1.0
    return fractions


def test_moving_force_three_span_beam(tmp_path):
    """Moving force (a Path per node, -dt and -time forms), Newmark, lumped mass, Rayleigh damping
    from eigen, text recorders (Node, Element, EnvelopeNode, -dT, -precision, reaction)."""
    script = load_script("moving_force_3span")
    ref_dir, val_dir = tmp_path / "openseespy", tmp_path / "vtsi"
    ref_dir.mkdir()
    val_dir.mkdir()
    ref = script.run(oracle, str(ref_dir))
    val = script.run(vops, str(val_dir))
    for key in ("eigen", "history", "reactions"):
        assert relative_difference(ref[key], val[key]) < RTOL, key
    fractions = compare_files(ref_dir, val_dir)
    for name, fraction in fractions.items():
        if name != "force.out":   # its pinned-end moments are round-off (1e-12), printed to 8 digits
            assert fraction > 0.9, name


@pytest.mark.parametrize("integrator", [("HHT", 0.9), ("HHT", 0.95, 0.6, 0.3), ("Newmark", 0.5, 0.25), ("TRBDF2",)],
                         ids=lambda x: "-".join(map(str, x)))
def test_bearings_gravity_then_transient(tmp_path, integrator):
    """zeroLength bearings (springs, Viscous dashpots, Elastic eta, -orient), a truss prop,
    static gravity, loadConst, eigen, Rayleigh, Path loads with every -dt option, a pattern
    removed between two analyze calls, reactions (static and dynamic), element responses."""
    script = load_script("bearings_hht")
    ref_dir, val_dir = tmp_path / "openseespy", tmp_path / "vtsi"
    ref_dir.mkdir()
    val_dir.mkdir()
    ref = script.run(oracle, str(ref_dir), integrator)
    val = script.run(vops, str(val_dir), integrator)
    assert sorted(ref) == sorted(val)
    for key in ref:
        assert relative_difference(ref[key], val[key]) < RTOL, key
    fractions = compare_files(ref_dir, val_dir)
    for name, fraction in fractions.items():
        if name not in ("prop_force.out",):   # OpenSees prints -0 for the vertical prop's zero x force
            assert fraction > 0.9, name


def truss_model(ops, do_rayleigh):
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 2)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 2.0, 0.0)
    ops.node(3, 4.0, 1.0)
    ops.fix(1, 1, 1)
    ops.fix(3, 1, 1)
    ops.uniaxialMaterial("Elastic", 1, 100.0)
    flags = ["-doRayleigh", do_rayleigh]
    ops.element("truss", 1, 1, 2, 1.0, 1, "-rho", 3.0, *flags)
    ops.element("truss", 2, 2, 3, 1.0, 1, "-rho", 3.0, "-cMass", 1, *flags)
    ops.rayleigh(0.5, 0.1, 0.0, 0.0)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(2, 1.0, 2.0)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    ops.analyze(10, 0.05)
    result = ops.nodeDisp(2) + ops.eleForce(2)
    ops.wipe()
    return np.array(result)


@pytest.mark.parametrize("do_rayleigh", [0, 1])
def test_truss_rayleigh(do_rayleigh):
    """OpenSees's truss takes Rayleigh damping (alphaM on its mass and betaK on its stiffness) only
    with -doRayleigh 1; without it, none at all."""
    assert relative_difference(truss_model(oracle, do_rayleigh), truss_model(vops, do_rayleigh)) < RTOL
