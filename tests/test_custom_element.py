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
    assert [line.split()[0] for line in done.stdout.splitlines()[2:]] == ["slender", "deep"]
