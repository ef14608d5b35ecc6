"""Scene S1: a constant force crossing a simply supported beam, against Frýba's series.

Reference: Frýba, L. (1972) Vibration of Solids and Structures under Moving Loads, ch. 1;
mid-span DAF table computed for this project from Frýba's series (undamped, 101 modes, free
vibration after the exit included; the table below), reproduced here by
:func:`vtsi.reference.daf`.

The FE model is the one an OpenSees user writes: elasticBeamColumn elements with consistent
mass, Newmark average acceleration, and the moving force applied as nodal loads, one ``Path``
time series and one pattern per node, the force shared between the two nodes of its element
by the linear hat functions (``benchmarks/peers/opensees_s1.py: nodal_force_histories``).

Measured (80 elements, 2000 steps per crossing, one period of the first mode after exit),
FE DAF / table − 1: α = 0.1: −1.3e-4, 0.5: −1.1e-4, 0.615: −1.5e-4, 1.2: −1.2e-4
(FE / :func:`daf` − 1: −0.9e-4, −1.3e-4, −1.3e-4, −1.3e-4); tolerance 5e-3. The error is the
spatial one of the hat-function loading, O(h²): at α = 0.615 (1.2) it is −1.95e-3 (−2.19e-3),
−5.2e-4 (−5.4e-4), −1.5e-4 (−1.3e-4) with 20, 40, 80 elements; halving dt changes it by
< 3e-5 (α ≥ 0.5) and by about ±2e-4 at α = 0.1, where the hat loading's element-crossing kinks
excite high modes that average acceleration does not damp. Run time: about 1 s (+ numba
compilation on a cold cache, about 5 s).
"""
import importlib.util
import math
import pathlib

import numpy as np
import pytest

import vtsi
from vtsi.errors import ModelError
from vtsi.recorders import NodeRecorder
from vtsi.reference import daf, first_frequency, moving_force_midspan, speed_of_alpha, static_midspan

ROOT = pathlib.Path(__file__).resolve().parents[1]
# The mid-span DAF = max_t w(L/2, t) / (P L³ / 48 EI) of Frýba's series (ch. 1), computed for
# this project with 101 modes, undamped, the free vibration after the exit included.
ALPHA = [0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.615, 0.7, 0.8, 0.9, 0.99, 1.01, 1.2, 1.5]
TABLE = [1.0482, 1.0965, 1.0653, 1.4105, 1.6129, 1.7054, 1.7311, 1.7317, 1.7204, 1.6787, 1.6127,
         1.5547, 1.5414, 1.3993, 1.1671]

# Scene S1 (docs/scenes.md)
L, E, I, MU, P = 25.0, 2.943e10, 3.81, 36000.0, 1.0e5
EI = E * I


def _peer():
    spec = importlib.util.spec_from_file_location("opensees_s1", ROOT / "benchmarks" / "peers" / "opensees_s1.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


nodal_force_histories = _peer().nodal_force_histories


@pytest.mark.parametrize("alpha, expected", list(zip(ALPHA, TABLE)))
def test_reference_daf_reproduces_table(alpha, expected):
    assert daf(alpha) == pytest.approx(expected, rel=2e-4)   # the table has 4 decimals


def test_reference_series_is_frybas_closed_form():
    """While the force is on the span, the modal solution is Frýba's series (README S1)."""
    V = speed_of_alpha(0.615, L, EI, MU)
    t = np.linspace(0.0, L / V, 501)
    omega1 = (math.pi / L) ** 2 * math.sqrt(EI / MU)
    alpha, w0 = 0.615, 2.0 * P * L ** 3 / (math.pi ** 4 * EI)
    series = sum(w0 / (j * j * (j * j - alpha ** 2)) * (np.sin(j * math.pi * V / L * t)
                                                       - alpha / j * np.sin(j * j * omega1 * t)) * math.sin(j * math.pi / 2)
                 for j in range(1, 102))
    assert np.allclose(moving_force_midspan(P, V, L, EI, MU, t), series, rtol=0, atol=1e-12 * np.abs(series).max())


def test_reference_resonance():
    """Exactly at resonance (α = 1) the undamped solution is finite and continuous in α;
    vanishing damping changes nothing."""
    assert daf(1.0) == pytest.approx(0.5 * (daf(1.0 - 1e-6) + daf(1.0 + 1e-6)), rel=1e-6)
    assert daf(0.615, zeta=1e-9) == pytest.approx(daf(0.615), rel=1e-7)


def test_reference_refuses_bad_input():
    """Bad input is a ModelError naming the value."""
    with pytest.raises(ModelError, match=r"daf: alpha must be > 0, got -0\.5"):
        daf(-0.5)
    with pytest.raises(ModelError, match=r"daf: alpha must be a number, got 'fast'"):
        daf("fast")
    with pytest.raises(ModelError, match=r"damping ratio must be in \[0, 1\), got 1\.5"):
        moving_force_midspan(P, 10.0, L, EI, MU, [0.1], zeta=1.5)
    with pytest.raises(ModelError, match=r"V, L, EI, mu must be > 0, got 10\.0, -1\.0"):
        moving_force_midspan(P, 10.0, -1.0, EI, MU, [0.1])


@pytest.mark.parametrize("zeta", [0.0, 0.02])
def test_reference_modes_match_ode_integration(zeta):
    """Per-mode exact solution (forced, then free) vs solve_ivp of the modal equations
    q̈_j + 2ζω_j q̇_j + ω_j² q_j = (2P/(μL)) sin(jπVt/L) on the span, 0 after (5 modes)."""
    from scipy.integrate import solve_ivp

    V, n_modes = speed_of_alpha(1.2, L, EI, MU), 5
    crossing = L / V
    modes = np.arange(1, n_modes + 1, 2)
    omega = (modes * np.pi / L) ** 2 * math.sqrt(EI / MU)

    def rhs(t, y):
        q, qd = y[: len(modes)], y[len(modes):]
        force = 2.0 * P / (MU * L) * np.sin(modes * np.pi * V * t / L) if t <= crossing else 0.0
        return np.r_[qd, force - 2.0 * zeta * omega * qd - omega ** 2 * q]

    t = np.linspace(0.0, crossing + 0.5, 400)
    sol = solve_ivp(rhs, (0.0, t[-1]), np.zeros(2 * len(modes)), t_eval=t, method="DOP853",
                    rtol=1e-11, atol=1e-16, max_step=crossing / 200)
    w = np.sin(modes * np.pi / 2) @ sol.y[: len(modes)]
    w_ref = moving_force_midspan(P, V, L, EI, MU, t, n_modes=n_modes, zeta=zeta)
    assert np.max(np.abs(w_ref - w)) < 1e-8 * np.max(np.abs(w))


def _s1_model(n_elements, V, dt, n_steps):
    """S1 in vtsi with the moving force as hat-function nodal loads (one Path per node)."""
    model = vtsi.Model()
    node_x = np.linspace(0.0, L, n_elements + 1)
    for i, x in enumerate(node_x):
        model.node(i + 1, float(x), 0.0)
    model.fix(1, 1, 1, 0)
    model.fix(n_elements + 1, 0, 1, 0)
    for e in range(n_elements):
        model.element("elasticBeamColumn", e + 1, (e + 1, e + 2), A=1.0, E=E, I=I, rho=MU, cmass=1)
    forces = nodal_force_histories(node_x, P, V, dt * np.arange(n_steps + 1))
    for i in range(1, n_elements):
        model.pattern(i + 1, vtsi.Path(forces[i], dt=dt))
        model.load(i + 1, i + 1, 0.0, -1.0, 0.0)
    return model


def fe_daf(alpha, n_elements=80, steps_per_crossing=2000):
    """Max midspan deflection / (PL³/48EI) over the crossing and one period of mode 1 after it."""
    V = speed_of_alpha(alpha, L, EI, MU)
    crossing = L / V
    dt = crossing / steps_per_crossing
    n_steps = int(math.ceil((crossing + 1.0 / first_frequency(L, EI, MU)) / dt)) + 1
    model = _s1_model(n_elements, V, dt, n_steps)
    rec = NodeRecorder([n_elements // 2 + 1], [2], "disp")
    vtsi.TransientAnalysis(model, vtsi.integrators.Newmark(0.5, 0.25), dt=dt, recorders=[rec]).run(n_steps)
    return float(np.max(-rec.values[:, 0])) / static_midspan(P, L, EI)


@pytest.mark.parametrize("alpha", [0.1, 0.5, 0.615, 1.2])
def test_s1_fe_daf_matches_fryba(alpha):
    value = fe_daf(alpha)
    assert value == pytest.approx(TABLE[ALPHA.index(alpha)], rel=5e-3)
    assert value == pytest.approx(daf(alpha), rel=1e-3)   # measured ≤ 1.5e-4


@pytest.mark.parametrize("alpha", [0.615, 1.2])
def test_s1_fe_converges_in_space(alpha):
    """Hat-function loading on Hermite beams: the DAF error falls as h² (ratio ≈ 4 per halving)."""
    ref = daf(alpha)
    errors = [abs(fe_daf(alpha, n, 1000) / ref - 1.0) for n in (20, 40, 80)]
    assert errors[0] / errors[1] > 3.0 and errors[1] / errors[2] > 3.0, errors
