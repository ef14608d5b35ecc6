"""OpenSeesPy peer of benchmark scene S4: one passage of a train of moving axle forces over a
simply supported beam, with Path load series, as an OpenSees user would run an HSLM sweep.

The beam is :func:`peers.opensees_s1.build_beam` (elasticBeamColumn, consistent mass ``-cMass``,
node 1 pinned, the last node a roller) with Rayleigh damping ``rayleigh alpha_m beta_k 0 0``,
analysed by :func:`peers.opensees_s1.linear_newmark_analysis` (BandSPD, ``Linear -factorOnce``,
Newmark average acceleration).

Loads: the moving axle forces are turned into the consistent nodal loads of the element under
each axle, through the cubic Hermite functions of that element (:func:`hermite_nodal_loads`):
a downward force P at ξ = (x − x_e)/h on element e loads its nodes with the vertical forces
−P H1(ξ), −P H3(ξ) [N] and the moments −P h H2(ξ), −P h H4(ξ) [N·m] (y up, rz counterclockwise).
These are the loads vtsi's MovingLoadConstraint puts on the bridge (the Hermite row of each
force wheel). Each loaded dof — uy of every interior node, rz of every node — gets its own
``timeSeries Path -dt dt -values ...`` (its load history sampled at t_k = k dt, k = 0..n) and
its own ``pattern Plain`` with a unit reference load on that dof. OpenSees's ``Path -dt``
returns 0 at its last sample; a passage ends after the last axle has left the span, so the last
sample is 0 anyway.

Output: an ``EnvelopeNode`` recorder of the midspan node's vertical acceleration (``accel``,
dof 2, ``-precision 16``): min, max and max |a| over the steps, written when the recorder is
removed (no per-step file output).

``hermite_nodal_loads`` is pure numpy (no openseespy import).
"""
from __future__ import annotations

import os
import tempfile
import time as _time

import numpy as np

from peers.opensees_s1 import build_beam, linear_newmark_analysis


def hermite_nodal_loads(node_x, axle_x0, axle_loads, speed, times):
    """Consistent nodal loads of axle forces moving along a beam.

    Parameters
    ----------
    node_x : (n_nodes,) increasing node abscissae [m] (the beam's nodes, in order).
    axle_x0 : (n_axles,) axle positions at t = 0 [m]; axle i is at ``axle_x0[i] + speed t``.
    axle_loads : (n_axles,) axle forces [N], positive downward.
    speed : [m/s].
    times : (n_times,) [s].

    Returns
    -------
    F : (n_nodes, 2, n_times): ``F[:, 0]`` vertical nodal forces [N, positive up] and ``F[:, 1]``
        nodal moments [N·m, counterclockwise]. An axle outside [x_0, x_last] loads nothing; an
        axle on a node between two elements is on the element to its right (the shape functions
        agree there).
    """
    node_x = np.asarray(node_x, dtype=float)
    x = np.asarray(axle_x0, dtype=float)[:, None] + speed * np.asarray(times, dtype=float)[None, :]
    P = np.broadcast_to(np.asarray(axle_loads, dtype=float)[:, None], x.shape)
    n_nodes = node_x.size
    F = np.zeros((n_nodes, 2, x.shape[1]))
    on = (x >= node_x[0]) & (x <= node_x[-1])
    if not np.any(on):
        return F
    axle, col = np.nonzero(on)
    xs, Ps = x[axle, col], P[axle, col]
    e = np.clip(np.searchsorted(node_x, xs, side="right") - 1, 0, n_nodes - 2)
    h = node_x[e + 1] - node_x[e]
    xi = (xs - node_x[e]) / h
    x2, x3 = xi * xi, xi * xi * xi
    np.add.at(F, (e, 0, col), -Ps * (1.0 - 3.0 * x2 + 2.0 * x3))
    np.add.at(F, (e, 1, col), -Ps * h * (xi - 2.0 * x2 + x3))
    np.add.at(F, (e + 1, 0, col), -Ps * (3.0 * x2 - 2.0 * x3))
    np.add.at(F, (e + 1, 1, col), -Ps * h * (x3 - x2))
    return F


def run_passage(node_x, E, Iz, mu, rayleigh, axle_x0, axle_loads, speed, dt, n_steps, area=1.0):
    """One passage in OpenSeesPy, from rest; everything a user pays per passage is timed.

    Parameters
    ----------
    node_x : (n_nodes,) node abscissae [m] of the simply supported beam (n_nodes odd: a node at
        midspan).
    E [Pa], Iz [m⁴], mu [kg/m], area [m²]; rayleigh : (alpha_m [1/s], beta_k [s]).
    axle_x0, axle_loads, speed : the train (see :func:`hermite_nodal_loads`).
    dt [s], n_steps : the analysis (``analyze(n_steps, dt)``).

    Returns
    -------
    dict with ``absmax`` (max over steps 1..n of |midspan vertical acceleration| [m/s²]),
    ``min``, ``max`` [m/s²], ``seconds`` (wall time: load histories, model, Path series and
    patterns, analysis, ``analyze``, reading the envelope), ``analyze_s`` (``analyze`` alone),
    ``n_steps``, ``n_series`` (Path series built).
    """
    import openseespy.opensees as ops

    node_x = np.asarray(node_x, dtype=float)
    n_nodes = node_x.size
    if n_nodes % 2 == 0:
        raise ValueError(f"S4 peer: need an odd number of nodes (a node at midspan), got {n_nodes}")
    mid = n_nodes // 2 + 1                         # node tags are 1..n_nodes
    fd, path = tempfile.mkstemp(prefix="opensees_s4_", suffix=".out")
    os.close(fd)
    try:
        t0 = _time.perf_counter()
        F = hermite_nodal_loads(node_x, axle_x0, axle_loads, speed, dt * np.arange(n_steps + 1))
        build_beam(ops, node_x, E, Iz, mu, area, rayleigh)
        tag = 0
        for i in range(n_nodes):
            for dof, ref in ((0, (0.0, 1.0, 0.0)), (1, (0.0, 0.0, 1.0))):
                if dof == 0 and i in (0, n_nodes - 1):
                    continue                       # uy fixed at the supports: only a reaction
                tag += 1
                ops.timeSeries("Path", tag, "-dt", dt, "-values", *F[i, dof].tolist())
                ops.pattern("Plain", tag, tag)
                ops.load(i + 1, *ref)
        rec = ops.recorder("EnvelopeNode", "-file", path, "-precision", 16, "-node", mid, "-dof", 2, "accel")
        linear_newmark_analysis(ops)
        t1 = _time.perf_counter()
        rc = ops.analyze(n_steps, dt)
        t2 = _time.perf_counter()
        if rc != 0:
            raise RuntimeError(f"OpenSees analyze failed (code {rc})")
        ops.remove("recorder", rec)                # writes the envelope and closes the file
        env = np.loadtxt(path, ndmin=2)            # rows: min, max, absmax
        ops.wipe()
        seconds = _time.perf_counter() - t0
    finally:
        os.remove(path)
    return dict(absmax=float(env[2, 0]), min=float(env[0, 0]), max=float(env[1, 0]), seconds=seconds,
                analyze_s=t2 - t1, n_steps=int(n_steps), n_series=tag)
