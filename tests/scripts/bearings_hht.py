"""A 24 m simply supported beam on elastomeric bearings (zeroLength springs and dashpots) with
a propping truss: gravity by a static analysis, ``loadConst('-time', 0.0)``, eigenvalues,
Rayleigh damping from modes 1 and 2, then a transient analysis under Path loads (``-time`` and
``-dt`` forms with ``-factor``, ``-prependZero``, ``-startTime``, ``-useLast``) with HHT,
continued after removing a pattern. Text recorders of every kind; queries at the end.

A plain OpenSeesPy script: ``run(ops, outdir)`` builds and runs it with the command module
``ops`` (``openseespy.opensees`` or ``vtsi.opensees``) and returns the results.
"""
import math
import os

import numpy as np

import openseespy.opensees as ops  # noqa: F401  (the script's own backend when run directly)

L, N_EL = 24.0, 12
E, A, IZ, RHO, G = 3.5e10, 4.0, 0.8, 12000.0, 9.81
DT = 0.004


def run(ops, outdir, integrator=('HHT', 0.9)):
    out = lambda name: os.path.join(outdir, name)
    ops.wipe()
    ops.model('basic', '-ndm', 2, '-ndf', 3)
    h = L / N_EL
    for i in range(N_EL + 1):
        ops.node(i + 1, i * h, 0.0)
    mid = N_EL // 2 + 1
    ops.node(101, 0.0, 0.0)
    ops.node(102, L, 0.0)
    ops.node(103, L / 2, -8.0)
    for n in (101, 102, 103):
        ops.fix(n, 1, 1, 1)
    ops.mass(mid, 5000.0, 5000.0, 0.0)

    ops.geomTransf('Linear', 1)
    for e in range(N_EL):
        ops.element('elasticBeamColumn', e + 1, e + 1, e + 2, A, E, IZ, 1, '-mass', RHO, '-cMass')

    ops.uniaxialMaterial('Elastic', 1, 5.0e9)            # vertical bearing stiffness [N/m]
    ops.uniaxialMaterial('Viscous', 2, 2.0e6, 1.0)       # bearing dashpot [N s/m]
    ops.uniaxialMaterial('Elastic', 3, 1.0e9)            # horizontal restraint
    ops.uniaxialMaterial('Elastic', 4, 4.0e9, 1.5e6)     # vertical spring with damping (eta)
    ops.uniaxialMaterial('Elastic', 5, 2.0e11)           # steel prop
    ops.element('zeroLength', 201, 101, 1, '-mat', 1, 2, 3, '-dir', 2, 2, 1)
    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    ops.element('zeroLength', 202, 102, N_EL + 1, '-mat', 3, 4, '-dir', 1, 2,
                '-orient', c, s, 0.0, -s, c, 0.0)
    ops.element('truss', 301, 103, mid, 0.002, 5, '-rho', 16.0, '-cMass', 1, '-doRayleigh', 1)

    # gravity, static, in 10 load steps; one recorder sees the static steps too
    ops.recorder('Node', '-file', out('static.out'), '-time', '-node', mid, '-dof', 2, 'disp')
    ops.timeSeries('Linear', 1)
    ops.pattern('Plain', 1, 1)
    for i in range(N_EL + 1):
        w = RHO * G * h * (0.5 if i in (0, N_EL) else 1.0)
        ops.load(i + 1, 0.0, -w, 0.0)
    ops.load(mid, 0.0, -5000.0 * G, 0.0)
    ops.constraints('Transformation')
    ops.numberer('RCM')
    ops.system('BandSPD')
    ops.test('NormDispIncr', 1.0e-10, 6)
    ops.algorithm('Newton')
    ops.integrator('LoadControl', 0.1)
    ops.analysis('Static')
    ops.analyze(10)
    static_disp = ops.nodeDisp(mid)
    ops.reactions()
    static_reactions = [ops.nodeReaction(n) for n in (101, 102, 103)]
    static_time = ops.getTime()
    ops.loadConst('-time', 0.0)

    omega2 = ops.eigen('-genBandArpack', 4)
    shapes = []
    for mode in (1, 2, 3):
        phi = np.array([ops.nodeEigenvector(n, mode) for n in (3, mid, 10)]).ravel()
        shapes.append(phi * np.sign(phi[np.argmax(np.abs(phi))]))
    w1, w2 = math.sqrt(omega2[0]), math.sqrt(omega2[1])
    zeta = 0.03
    ops.rayleigh(2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2), 0.0, 0.0)

    # transient loads
    ops.timeSeries('Path', 2, '-time', 0.0, 0.01, 0.03, 0.05, '-values', 0.0, 1.0, 1.0, 0.0)
    ops.pattern('Plain', 2, 2)
    ops.load(5, 0.0, -3.0e5, 0.0)
    values = [0.0, 0.5, 1.0, 0.2, -0.4, 0.3, 0.8]
    ops.timeSeries('Path', 3, '-dt', 0.012, '-values', *values, '-factor', 2.0, '-prependZero', '-startTime', 0.02,
                   '-useLast')
    ops.pattern('Plain', 3, 3, '-fact', 0.5)
    ops.load(9, 1.0e4, -1.0e5, 0.0)

    ops.recorder('Node', '-file', out('disp.out'), '-time', '-precision', 10, '-node', 4, mid, 10,
                 '-dof', 1, 2, 3, 'disp')
    ops.recorder('Node', '-file', out('vel.out'), '-node', mid, '-dof', 2, 'vel')
    ops.recorder('Node', '-file', out('accel.out'), '-time', '-dT', 0.01, '-node', mid, '-dof', 2, 'accel')
    ops.recorder('Node', '-file', out('reaction.out'), '-time', '-node', 101, 102, 103, '-dof', 1, 2, 3,
                 'reaction')
    ops.recorder('Element', '-file', out('bearing_basic.out'), '-time', '-ele', 201, 202, 'basicForce')
    ops.recorder('Element', '-file', out('bearing_force.out'), '-ele', 202, 'force')
    ops.recorder('Element', '-file', out('prop.out'), '-time', '-ele', 301, 'axialForce')
    ops.recorder('Element', '-file', out('prop_force.out'), '-ele', 301, 'globalForce')
    ops.recorder('EnvelopeElement', '-file', out('beam_env.out'), '-time', '-ele', 6, 7, 'localForce')
    ops.recorder('EnvelopeNode', '-file', out('disp_env.out'), '-node', mid, '-dof', 2, 'disp')

    ops.wipeAnalysis()
    ops.constraints('Plain')
    ops.numberer('RCM')
    ops.system('BandGeneral')
    ops.test('EnergyIncr', 1.0e-12, 20)
    ops.algorithm('Newton')
    ops.integrator(*integrator)
    ops.analysis('Transient')

    ops.analyze(40, DT)
    ops.remove('loadPattern', 2)
    ops.analyze(35, DT)
    final_time = ops.getTime()
    ops.reactions('-dynamic')
    dynamic_reactions = [ops.nodeReaction(n) for n in (101, 102, 103)]
    ops.reactions()
    final_reactions = [ops.nodeReaction(n) for n in (101, 102, 103)]
    final = {
        'disp': [ops.nodeDisp(n) for n in (1, mid, N_EL + 1)],
        'vel': [ops.nodeVel(mid, 2), ops.nodeAccel(mid, 2)],
        'bearing': ops.eleForce(201) + ops.eleForce(202) + ops.eleResponse(201, 'basicForce')
        + ops.eleResponse(202, 'localForce') + ops.eleResponse(202, 'deformation'),
        'prop': ops.eleForce(301) + ops.eleResponse(301, 'axialForce'),
        'beam': ops.eleForce(6) + ops.eleResponse(7, 'localForce'),
    }
    ops.wipe()   # closes the recorder files

    files = {}
    for name in sorted(os.listdir(outdir)):
        with open(os.path.join(outdir, name)) as fh:
            files[name] = np.array([[float(x) for x in line.split()] for line in fh if line.strip()])
    results = {'static_disp': np.array(static_disp), 'static_reactions': np.array(static_reactions),
               'static_time': np.array([static_time, final_time]), 'eigen': np.array(omega2),
               'shapes': np.array(shapes), 'dynamic_reactions': np.array(dynamic_reactions),
               'final_reactions': np.array(final_reactions)}
    results.update({k: np.array(v, dtype=float) for k, v in final.items()})
    results.update({'file ' + k: v for k, v in files.items()})
    return results


if __name__ == '__main__':
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        res = run(ops, tmp)
    print({k: np.shape(v) for k, v in res.items()})
