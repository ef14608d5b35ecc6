"""OpenSeesPy peer of benchmark scene S1 (moving constant force on a simply supported beam).

Scene S1
--------
* simply supported beam, span L = 25 m, E = 2.943e10 Pa, Iz = 3.81 m^4,
  A = 1.0 m^2 (only enters the axial stiffness; irrelevant for the vertical response),
  mass mu = 36000 kg/m, consistent mass (``elasticBeamColumn ... '-mass', mu, '-cMass'``);
* n_el equal elements (20 or 200), nodes along x at y = 0, node 1 pinned (fix 1 1 0),
  node n_el+1 roller (fix 0 1 0), geomTransf Linear, no damping;
* one downward force P = 100 kN crossing at V = 100 km/h from x = 0 to x = L;
* Newmark average acceleration (gamma = 0.5, beta = 0.25), dt = 1e-3 s,
  n_steps = ceil((L/V)/dt) + 500 (= 1400 at 25 m).

Load driving (as OpenSees users do it)
--------------------------------------
The moving force is distributed to the two nodes of the element it is on with the
linear hat functions; ``nodal_force_histories`` returns these nodal forces (N, positive
downward) sampled at the analysis times t_k = k*dt, k = 0..n_steps.  Each interior node
gets its own ``timeSeries('Path', tag, '-dt', dt, '-values', *F_k)`` (the force magnitude
is carried in the Path values) and its own ``pattern('Plain', tag, tag)`` with
``load(node, 0.0, -1.0, 0.0)`` (reference load: unit downward).  The two support nodes are
skipped: their vertical dof is fixed, so a load there only goes into the reaction.
The Path covers t = 0 .. n_steps*dt (n_steps+1 samples); beyond its last sample OpenSees
returns 0, which is also the physical value once the force has left the span.

Analysis: constraints Plain, numberer Plain (nodes are numbered along the beam, so the
band is already minimal), system BandSPD, algorithm Linear '-factorOnce' (the effective
stiffness K + 4/dt^2 M is constant), integrator Newmark 0.5 0.25, analysis Transient.
Newmark in OpenSees starts from the committed acceleration (zero), it does not solve
M a0 = P(0) - K u0; here P(0) = 0 on the free dofs anyway (the force is on the support).

Two driving styles:
* ``'step'``: ``analyze(1, dt)`` n_steps times, reading ``nodeDisp(mid, 2)`` after each step;
* ``'bulk'``: a text Node recorder of the midspan node (``-precision 16``) to a temp file,
  one ``analyze(n_steps, dt)``, then the file is read (reading is outside the timing).

``nodal_force_histories`` is pure numpy (no openseespy import) so that it can drive vtsi
with exactly the same nodal loads.
"""

from __future__ import annotations

import importlib
import math
import os
import tempfile
import time as _time

import numpy as np

# ---- scene S1 constants -------------------------------------------------------------
L = 25.0            # span [m]
E = 2.943e10        # Young's modulus [Pa]
IZ = 3.81           # second moment of area [m^4]
AREA = 1.0          # cross-section area [m^2] (axial only; does not affect the result)
MU = 36000.0        # mass per unit length [kg/m]
P = 1.0e5           # moving force [N], acts downward
V = 100.0 / 3.6     # speed [m/s] = 27.777... m/s


def default_n_steps(dt: float = 1e-3, span: float = L, speed: float = V) -> int:
    """ceil((L/V)/dt) + 500 (1400 for the S1 values and dt = 1e-3)."""
    return int(math.ceil((span / speed) / dt - 1e-9)) + 500


def nodal_force_histories(node_x, P, V, times):
    """Hat-function nodal forces of a single moving force.

    Parameters
    ----------
    node_x : (n_nodes,) array of increasing node abscissae (the beam nodes, in order).
    P : force magnitude (returned with the sign of P; S1 uses P > 0 = downward).
    V : speed [m/s]; the force is at x = V*t.
    times : (n_times,) array of times.

    Returns
    -------
    F : (n_nodes, n_times) array.  At time t with x = V*t inside [x_0, x_last], the
        force on element e = [x_e, x_{e+1}] (x_e <= x <= x_{e+1}) gives
        F[e] = P*(1 - xi), F[e+1] = P*xi with xi = (x - x_e)/(x_{e+1} - x_e);
        at x exactly on a node the whole force is on that node.  Outside the beam
        (x < x_0 or x > x_last) all nodal forces are zero.
    """
    node_x = np.asarray(node_x, dtype=float)
    times = np.asarray(times, dtype=float)
    n_nodes = node_x.size
    F = np.zeros((n_nodes, times.size))
    x = V * times
    on = (x >= node_x[0]) & (x <= node_x[-1])
    if not np.any(on):
        return F
    cols = np.nonzero(on)[0]
    xs = x[on]
    # element index e with node_x[e] <= x < node_x[e+1]; x == x_last -> last element
    e = np.searchsorted(node_x, xs, side="right") - 1
    e = np.clip(e, 0, n_nodes - 2)
    xi = (xs - node_x[e]) / (node_x[e + 1] - node_x[e])
    F[e, cols] += P * (1.0 - xi)
    F[e + 1, cols] += P * xi
    return F


def build_beam(ops, node_x, E, Iz, mu, area=1.0, rayleigh=None):
    """A fresh OpenSees model (``wipe``) of a simply supported beam: nodes 1..n at ``node_x`` (y = 0),
    node 1 pinned (fix 1 1 0), node n roller (fix 0 1 0), geomTransf Linear 1, elasticBeamColumn
    elements 1..n-1 with consistent mass (``-mass mu -cMass``); ``rayleigh = (alpha_m, beta_k)``
    adds ``rayleigh alpha_m beta_k 0 0``. Units SI (Pa, m^4, kg/m, m^2)."""
    n_nodes = len(node_x)
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for i, x in enumerate(node_x):
        ops.node(i + 1, float(x), 0.0)
    ops.fix(1, 1, 1, 0)
    ops.fix(n_nodes, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    for e in range(n_nodes - 1):
        ops.element("elasticBeamColumn", e + 1, e + 1, e + 2, area, E, Iz, 1, "-mass", mu, "-cMass")
    if rayleigh is not None:
        ops.rayleigh(float(rayleigh[0]), float(rayleigh[1]), 0.0, 0.0)


def linear_newmark_analysis(ops, gamma=0.5, beta=0.25):
    """The analysis of a linear model, its fastest in OpenSees: constraints Plain, numberer Plain
    (nodes numbered along the beam: the band is already minimal), system BandSPD, algorithm Linear
    -factorOnce (the effective stiffness is constant), integrator Newmark, analysis Transient."""
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("BandSPD")
    ops.algorithm("Linear", "-factorOnce")
    ops.integrator("Newmark", gamma, beta)
    ops.analysis("Transient")


def run(n_elements, dt=1e-3, style="step", n_steps=None, module="openseespy.opensees"):
    """Run S1 in OpenSeesPy.

    Returns dict(midspan=(n_steps,) vertical displacement of the midspan node after
    steps 1..n_steps [m, negative = downward], time=(n_steps,) the analysis time after
    each step (from getTime() in 'step' style, from the recorder's time column in 'bulk'
    style), seconds=wall time of the time loop only, us_per_step=1e6*seconds/n_steps,
    plus n_elements, n_steps, dt, style). ``module``: the command module the script imports,
    ``'openseespy.opensees'`` or ``'vtsi.opensees'`` (the one line a user changes).
    """
    ops = importlib.import_module(module)

    if style not in ("step", "bulk"):
        raise ValueError("style must be 'step' or 'bulk'")
    if n_elements % 2:
        raise ValueError("n_elements must be even (a node at midspan)")
    if n_steps is None:
        n_steps = default_n_steps(dt)

    n_nodes = n_elements + 1
    node_x = np.linspace(0.0, L, n_nodes)
    mid = n_elements // 2 + 1                      # node tags are 1..n_nodes
    times = dt * np.arange(n_steps + 1)            # samples of the Path series
    F = nodal_force_histories(node_x, P, V, times)

    # ---- model building (not timed) ------------------------------------------------
    build_beam(ops, node_x, E, IZ, MU, AREA)
    for i in range(1, n_nodes - 1):                # interior nodes only
        tag = i + 1
        ops.timeSeries("Path", tag, "-dt", dt, "-values", *F[i].tolist())
        ops.pattern("Plain", tag, tag)
        ops.load(tag, 0.0, -1.0, 0.0)

    rec_path = None
    if style == "bulk":
        fd, rec_path = tempfile.mkstemp(prefix="opensees_s1_", suffix=".out")
        os.close(fd)
        rec_tag = ops.recorder("Node", "-file", rec_path, "-time", "-precision", 16,
                               "-node", mid, "-dof", 2, "disp")

    linear_newmark_analysis(ops)

    # ---- time loop (timed) ---------------------------------------------------------
    if style == "step":
        w = np.empty(n_steps)
        tt = np.empty(n_steps)
        t0 = _time.perf_counter()
        for k in range(n_steps):
            if ops.analyze(1, dt) != 0:
                raise RuntimeError("OpenSees analyze failed at step %d" % (k + 1))
            w[k] = ops.nodeDisp(mid, 2)
            tt[k] = ops.getTime()
        seconds = _time.perf_counter() - t0
    else:
        t0 = _time.perf_counter()
        rc = ops.analyze(n_steps, dt)
        seconds = _time.perf_counter() - t0
        if rc != 0:
            raise RuntimeError("OpenSees analyze failed (code %d)" % rc)
        ops.remove("recorder", rec_tag)            # flushes and closes the file
        data = np.loadtxt(rec_path, ndmin=2)
        os.remove(rec_path)
        tt, w = data[:, 0], data[:, 1]
        if w.size != n_steps:
            raise RuntimeError("recorder wrote %d rows, expected %d" % (w.size, n_steps))
    ops.wipe()

    return dict(midspan=w, time=tt, seconds=seconds, us_per_step=1e6 * seconds / n_steps,
                n_elements=n_elements, n_steps=n_steps, dt=dt, style=style)


# ---- analytical reference (Fryba, modal series of the continuous beam) -----------------
def first_frequency(span=L, EI=E * IZ, mu=MU):
    """f1 = (pi/L)^2 sqrt(EI/mu) / (2 pi)  [Hz]."""
    return (math.pi / span) ** 2 * math.sqrt(EI / mu) / (2.0 * math.pi)


def fryba_midspan(t, span=L, EI=E * IZ, mu=MU, force=P, speed=V, n_modes=60):
    """Midspan deflection (positive downward) of the undamped continuous simply supported
    beam under a constant force crossing at constant speed (Fryba 1972, modal series):
    q_j'' + w_j^2 q_j = (2P/(mu L)) sin(j pi V t / L) for 0 <= t <= L/V, free vibration
    afterwards; w(L/2, t) = sum_j q_j(t) sin(j pi / 2)."""
    t = np.asarray(t, dtype=float)
    T = span / speed
    out = np.zeros_like(t)
    for j in range(1, n_modes + 1):
        s = math.sin(j * math.pi / 2.0)
        if abs(s) < 1e-12:
            continue
        wj = (j * math.pi / span) ** 2 * math.sqrt(EI / mu)
        Om = j * math.pi * speed / span
        a = 2.0 * force / (mu * span) / (wj ** 2 - Om ** 2)

        def q(tt):
            return a * (np.sin(Om * tt) - Om / wj * np.sin(wj * tt))

        def qd(tt):
            return a * (Om * np.cos(Om * tt) - Om * np.cos(wj * tt))

        qT, qdT = q(T), qd(T)
        during = t <= T
        tau = t - T
        qj = np.where(during, q(np.minimum(t, T)),
                      qT * np.cos(wj * tau) + qdT / wj * np.sin(wj * tau))
        out += s * qj
    return out


def static_midspan(span=L, EI=E * IZ, force=P):
    """P L^3 / (48 EI)."""
    return force * span ** 3 / (48.0 * EI)


def daf_check(result):
    """Peak |midspan| of a run compared with delta_st * DAF_Fryba."""
    dt, n = result["dt"], result["n_steps"]
    t_fine = np.linspace(0.0, n * dt, 20 * n + 1)
    daf_fryba = np.max(fryba_midspan(t_fine)) / static_midspan()
    peak = float(np.max(-result["midspan"]))
    return dict(f1=first_frequency(), alpha=V / (2.0 * first_frequency() * L),
                static=static_midspan(), daf_fryba=daf_fryba,
                peak=peak, daf_fe=peak / static_midspan(),
                rel_err=peak / (static_midspan() * daf_fryba) - 1.0)


if __name__ == "__main__":
    for n_el in (20, 200):
        for style in ("step", "bulk"):
            best = None
            for _ in range(3):                      # best of 3
                r = run(n_el, style=style)
                if best is None or r["seconds"] < best["seconds"]:
                    best = r
            c = daf_check(best)
            print("n_el=%3d style=%-4s n_steps=%d  %7.1f us/step  peak=%.6e m  DAF_FE=%.4f"
                  % (n_el, style, best["n_steps"], best["us_per_step"], c["peak"], c["daf_fe"]))
    c = daf_check(run(200, style="bulk"))
    print("f1=%.4f Hz alpha=%.4f static PL^3/48EI=%.6e m  DAF_Fryba=%.4f  "
          "FE(200 el) vs Fryba: %+.3e"
          % (c["f1"], c["alpha"], c["static"], c["daf_fryba"], c["rel_err"]))
