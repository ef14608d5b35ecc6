"""A 3-span continuous beam (3 x 20 m) crossed by a moving force, as OpenSees users model it:
one Path time series per node (the force shared between the two nodes of the element under it),
Newmark average acceleration, lumped mass, Rayleigh damping of 2 % on modes 1 and 3, text
recorders, and a step-by-step loop reading nodeDisp / nodeAccel / eleForce.

A plain OpenSeesPy script: ``run(ops, outdir)`` builds and runs it with the command module
``ops`` (``openseespy.opensees`` or ``vtsi.opensees``) and returns the results.
"""
import math
import os

import numpy as np

import openseespy.opensees as ops  # noqa: F401  (the script's own backend when run directly)

SPAN, N_PER_SPAN, N_SPANS = 20.0, 10, 3
E, A, IZ, RHO = 3.5e10, 5.0, 2.5, 15000.0      # Pa, m2, m4, kg/m
FORCE, SPEED = -2.0e5, 40.0                      # N, m/s
DT, N_STEPS = 0.002, 900


def run(ops, outdir):
    ops.wipe()
    ops.model('basic', '-ndm', 2, '-ndf', 3)
    n_el = N_SPANS * N_PER_SPAN
    h = SPAN / N_PER_SPAN
    for i in range(n_el + 1):
        ops.node(i + 1, i * h, 0.0)
    ops.fix(1, 1, 1, 0)
    for s in range(1, N_SPANS + 1):
        ops.fix(s * N_PER_SPAN + 1, 0, 1, 0)
    ops.geomTransf('Linear', 1)
    for e in range(n_el):
        ops.element('elasticBeamColumn', e + 1, e + 1, e + 2, A, E, IZ, 1, '-mass', RHO)

    omega2 = ops.eigen(3)
    w1, w3 = math.sqrt(omega2[0]), math.sqrt(omega2[2])
    zeta = 0.02
    ops.rayleigh(2 * zeta * w1 * w3 / (w1 + w3), 2 * zeta / (w1 + w3), 0.0, 0.0)

    # one Path series per node: hat function of the force position x = V t
    length = n_el * h
    t_end = length / SPEED
    n_path = int(round(t_end / DT)) + 1
    t_path = np.arange(n_path + 1) * DT
    for i in range(n_el + 1):
        xi = i * h
        if i % 2 == 0:   # -dt form, sampled every step
            x = SPEED * t_path
            values = np.clip(1.0 - np.abs(x - xi) / h, 0.0, None)
            values[x > length] = 0.0
            ops.timeSeries('Path', i + 1, '-dt', DT, '-values', *values.tolist())
        else:            # -time form, only the three points of the hat
            times = [max(xi - h, 0.0) / SPEED, xi / SPEED, min(xi + h, length) / SPEED]
            ops.timeSeries('Path', i + 1, '-time', *times, '-values', 0.0, 1.0, 0.0)
        ops.pattern('Plain', i + 1, i + 1)
        ops.load(i + 1, 0.0, FORCE, 0.0)

    mid = [N_PER_SPAN // 2 + 1 + s * N_PER_SPAN for s in range(N_SPANS)]
    ops.recorder('Node', '-file', os.path.join(outdir, 'disp.out'), '-time', '-node', *mid, '-dof', 2, 'disp')
    ops.recorder('Node', '-file', os.path.join(outdir, 'accel.out'), '-time', '-dT', 0.005, '-node', mid[1],
                 '-dof', 1, 2, 3, 'accel')
    ops.recorder('Element', '-file', os.path.join(outdir, 'force.out'), '-time', '-precision', 8, '-ele', 1, 15,
                 'force')
    ops.recorder('Element', '-file', os.path.join(outdir, 'local.out'), '-ele', 16, 'localForce')
    ops.recorder('Node', '-file', os.path.join(outdir, 'reaction.out'), '-time', '-node', 1, 11, '-dof', 1, 2,
                 'reaction')
    ops.recorder('EnvelopeNode', '-file', os.path.join(outdir, 'env.out'), '-time', '-nodeRange', 4, 7,
                 '-dof', 2, 'disp')

    ops.constraints('Plain')
    ops.numberer('RCM')
    ops.system('BandGeneral')
    ops.test('NormDispIncr', 1e-8, 10)
    ops.algorithm('Linear')
    ops.integrator('Newmark', 0.5, 0.25)
    ops.analysis('Transient')

    history = []
    for _ in range(N_STEPS):
        ops.analyze(1, DT)
        history.append([ops.getTime(), ops.nodeDisp(mid[0], 2), ops.nodeDisp(mid[1], 2), ops.nodeVel(mid[1], 2),
                        ops.nodeAccel(mid[1], 2)] + ops.eleForce(15) + ops.eleResponse(16, 'localForce'))
    ops.reactions()
    reactions = [ops.nodeReaction(s * N_PER_SPAN + 1) for s in range(N_SPANS + 1)]
    ops.wipe()
    return {'eigen': np.array(omega2), 'history': np.array(history), 'reactions': np.array(reactions)}


if __name__ == '__main__':
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        res = run(ops, tmp)
    print({k: np.shape(v) for k, v in res.items()})
