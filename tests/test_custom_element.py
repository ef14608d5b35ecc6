"""``examples/custom_element.py``: a Timoshenko beam added without touching the core.

The contract tests (``tests/test_element_contract.py``) check the new type like the shipped
ones; here it meets its closed forms and the example's printed comparison.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from vtsi.elements import ELEMENT_TYPES

import vtsi
import vtsi.opensees
from vtsi.tcl import run_file


def test_registered_without_touching_the_core(custom_element):
    assert ELEMENT_TYPES["timoshenkoBeam"] is custom_element.TimoshenkoBeam2d
    assert custom_element.TimoshenkoBeam2d.__module__ == "vtsi_example_custom_element"


@pytest.mark.parametrize("n_el", [1, 3])
@pytest.mark.parametrize("depth", [0.1, 1.5])
def test_cantilever_tip_deflection_with_shear(custom_element, n_el, depth):
    """Tip load P: δ = PL³/3EI + PL/κGA (bending + shear), θ = PL²/2EI; the two-node
    Timoshenko stiffness is exact for end loads (Przemieniecki 1968, §5.6)."""
    L, P = 4.0, 2e5
    s = custom_element.rectangular_steel_section(depth)
    m = vtsi.Model()
    for i in range(n_el + 1):
        m.node(i + 1, L * i / n_el, 0.0)
    m.fix(1, 1, 1, 1)
    for i in range(n_el):
        m.element("timoshenkoBeam", i + 1, (i + 1, i + 2), **s)
    m.pattern(1, m.add_time_series(vtsi.Constant(tag=1))).load(n_el + 1, 0.0, -P, 0.0)
    vtsi.StaticAnalysis(m).run(1)
    asm = m.build()
    ei, shear = s["E"] * s["I"], s["kappa"] * s["G"] * s["A"]
    assert m.state.u[asm.full_dof(n_el + 1, 2)] == pytest.approx(-(P * L ** 3 / (3 * ei) + P * L / shear), rel=1e-10)
    assert m.state.u[asm.full_dof(n_el + 1, 3)] == pytest.approx(-P * L ** 2 / (2 * ei), rel=1e-10)


def test_main_compares_the_beams(custom_element, capsys):
    """Slender: Timoshenko and Euler-Bernoulli within 1 %; deep: Timoshenko clearly lower.
    Each FE value matches its closed form within 0.1 % (40 lumped-mass elements)."""
    results = custom_element.main()
    printed = capsys.readouterr().out
    slender, deep = results["slender"], results["deep"]
    assert slender["timoshenko"] == pytest.approx(slender["euler_bernoulli"], rel=1e-2)
    assert deep["timoshenko"] < 0.95 * deep["euler_bernoulli"]
    for row in (slender, deep):
        assert row["timoshenko"] < row["euler_bernoulli"]
        assert row["euler_bernoulli"] == pytest.approx(row["euler_bernoulli_exact"], rel=1e-3)
        assert row["timoshenko"] == pytest.approx(row["timoshenko_exact"], rel=1e-3)
    for label, row in results.items():
        line = next(text for text in printed.splitlines() if text.strip().startswith(label))
        numbers = [float(x) for x in line.split()[2:]]
        np.testing.assert_allclose(numbers, [row["euler_bernoulli"], row["timoshenko"],
                                             row["timoshenko"] / row["euler_bernoulli"],
                                             row["euler_bernoulli_exact"], row["timoshenko_exact"]], atol=1e-4)


def test_runs_as_a_script(custom_element):
    script = Path(custom_element.__file__)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300,
                          cwd=script.parent)
    assert done.returncode == 0, done.stderr
    assert "Euler-Bernoulli" in done.stdout and "Timoshenko" in done.stdout
    assert [line.split()[0] for line in done.stdout.splitlines()[2:4]] == ["slender", "deep"]
    assert done.stdout.splitlines()[4].startswith("Tcl script, 'element timoshenkoBeam'")


TCL_FILE = """
model basic -ndm 2 -ndf 3
for {set i 0} {$i <= 3} {incr i} { node [expr {$i + 1}] [expr {$i * 4.0 / 3}] 0.0 }
fix 1 1 1 1
for {set e 1} {$e <= 3} {incr e} { element timoshenkoBeam $e $e [expr {$e + 1}] %(A)r %(E)r %(I)r %(G)r %(kappa)r }
timeSeries Constant 1
pattern Plain 1 1 { load 4 0.0 -2e5 0.0 }
analysis Static
analyze 1
set tip [nodeDisp 4 2]
set force [eleResponse 3 force]
"""


def test_the_new_type_is_reached_from_a_tcl_file(custom_element, tmp_path):
    """A Tcl file uses the type's ``element`` command (declared by ``command_args``) with no
    change to vtsi: three elements of a cantilever give the closed-form tip deflection, and the
    element's end forces (its ``response``) balance the tip load."""
    s = custom_element.rectangular_steel_section(1.5)
    path = tmp_path / "cantilever.tcl"
    path.write_text(TCL_FILE % s)
    tcl = run_file(path)
    L, P = 4.0, 2e5
    exact = -(P * L ** 3 / (3 * s["E"] * s["I"]) + P * L / (s["kappa"] * s["G"] * s["A"]))
    assert float(tcl.tcl.getvar("tip")) == pytest.approx(exact, rel=1e-10)
    force = [float(x) for x in tcl.tcl.eval("set force").split()]
    assert force[4] == pytest.approx(-P, rel=1e-10)          # the tip node's load on the element, y
    assert tcl.session.domain.element_types["timoshenkoBeam"].tags == [1, 2, 3]


def test_the_new_type_command_through_vtsi_opensees(custom_element):
    """The same command from Python: ``-mass`` sets ``rho``; a missing or unknown argument names
    the element and the argument."""
    ops = vtsi.opensees.Session()
    s = custom_element.rectangular_steel_section(0.5)
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 2.0, 0.0)
    ops.element("timoshenkoBeam", 1, 1, 2, s["A"], s["E"], s["I"], s["G"], s["kappa"], "-mass", s["rho"])
    etype = ops.domain.element_types["timoshenkoBeam"]
    assert etype.params[0].tolist() == [s["A"], s["E"], s["I"], s["G"], s["kappa"], s["rho"]]
    with pytest.raises(vtsi.CommandError, match=r"^element timoshenkoBeam 2: missing kappa$"):
        ops.element("timoshenkoBeam", 2, 1, 2, 1.0, 2.0, 3.0, 4.0)
    with pytest.raises(vtsi.CommandError, match=r"^element timoshenkoBeam 2: option '-rho' is not supported; "
                                                r"supported: -mass$"):
        ops.element("timoshenkoBeam", 2, 1, 2, 1.0, 2.0, 3.0, 4.0, 0.8, "-rho", 5.0)
    with pytest.raises(vtsi.ModelError, match=r"^element 2 \(timoshenkoBeam\): G must be > 0, got 0$"):
        ops.element("timoshenkoBeam", 2, 1, 2, 1.0, 2.0, 3.0, 0.0, 0.8)
    with pytest.raises(vtsi.CommandError, match="supported: elasticBeamColumn, ElasticTimoshenkoBeam, truss, "
                                                "zeroLength, .*timoshenkoBeam"):
        ops.element("noSuchBeam", 2, 1, 2)
