"""A simply supported beam under a force crossing it, written as OpenSees scripts write it: one
Path series and one pattern per interior node (the force shared by the hat functions). Shared
by the tests that run it through ``openseespy.opensees`` and ``vtsi.opensees``."""
import numpy as np


def build(ops, n_el, span, I, dt, n_steps, speed, force=1e5, rayleigh=(0.1, 1e-4)):
    """Nodes, supports, ``n_el`` consistent-mass elasticBeamColumn elements (E = 3e10 Pa, A = 1,
    inertia ``I`` [m⁴], 2e4 kg/m), the Path patterns of ``force`` [N] crossing at ``speed`` [m/s]
    sampled every ``dt`` [s] for ``n_steps``, Rayleigh ``(alphaM, betaKcomm)``."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    x = np.linspace(0.0, span, n_el + 1)
    for i, xi in enumerate(x):
        ops.node(i + 1, float(xi), 0.0)
    ops.fix(1, 1, 1, 0)
    ops.fix(n_el + 1, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    for e in range(n_el):
        ops.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0, 3.0e10, I, 1, "-mass", 2.0e4, "-cMass")
    t = dt * np.arange(n_steps + 1)
    h = span / n_el
    for i in range(1, n_el):
        share = np.clip(1.0 - np.abs(speed * t - x[i]) / h, 0.0, None) * force
        ops.timeSeries("Path", i + 1, "-dt", dt, "-values", *share.tolist())
        ops.pattern("Plain", i + 1, i + 1)
        ops.load(i + 1, 0.0, -1.0, 0.0)
    ops.rayleigh(rayleigh[0], 0.0, 0.0, rayleigh[1])


def transient(ops, integrator=("Newmark", 0.5, 0.25)):
    """The linear transient analysis settings of the scripts."""
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear")
    ops.integrator(*integrator)
    ops.analysis("Transient")
