"""A 20 m span (nodes 5 to 15) with a 4 m overhang (nodes 1 to 5) carrying the track from its tip
(x = -4 m): tests/test_influence.py, tests/test_influence_speed.py."""
import vtsi.opensees as ops
ops.wipe()
ops.model('basic', '-ndm', 2, '-ndf', 3)
xs = [-4.0 + 1.0*i for i in range(4)] + [0.0 + 2.0*i for i in range(11)]
for k, x in enumerate(xs, start=1):
    ops.node(k, x, 0.0)
ops.fix(5, 1, 1, 0)
ops.fix(15, 0, 1, 0)
ops.geomTransf('Linear', 1)
for k in range(1, len(xs)):
    ops.element('elasticBeamColumn', k, k, k+1, 5.0, 3.5e10, 1.9, 1, '-mass', 15000.0, '-cMass')
ops.track(1, '-eleRange', 1, len(xs)-1)
