"""Reactions against OpenSeesPy where the loads and the moving dofs are not just nodal loads on
free dofs: prescribed (``sp``) supports, ``equalDOF``/``rigidLink`` neighbours, element loads
(static, Newmark, HHT) and ground accelerations (``UniformExcitation``) on the mass of supports.

Each model runs through ``openseespy.opensees`` and ``vtsi.opensees`` with the same commands; the
``reaction`` and ``reactionIncInertia`` Node recorders (vtsi: text ``-file``, ``-h5`` and in
memory) and ``reactions()``/``reactions('-dynamic')`` after every step must equal OpenSeesPy's
to 1e-7 of each history's largest magnitude. Rayleigh damping here is stiffness-proportional
only: with αM and nodal mass OpenSees adds αM·M·v to the static reaction of a node (a missing
``else``, docs/commands.md "What differs"), which is not the subject here.
"""
import h5py
import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402

RTOL = 1e-7
FLAGS = ("reaction", "reactionIncInertia")


def assert_histories_close(reference, value, what):
    """``|value - reference| <= RTOL ·`` the largest magnitude of each column (history) of
    ``reference``; columns that are zero up to round-off (below 1e-6 of the array's largest
    magnitude: a moment at a pin, 1e-14 of the loads) are compared to that floor."""
    reference, value = np.asarray(reference, dtype=float), np.asarray(value, dtype=float)
    assert reference.shape == value.shape, what
    assert np.abs(reference).max() > 0.0, what
    scale = np.maximum(np.abs(reference).max(axis=0), 1e-6 * np.abs(reference).max())
    worst = np.max(np.abs(value - reference) / scale)
    assert worst < RTOL, f"{what}: {worst:.2e} of the history's magnitude"


def run(ops, outdir, build, analysis, n_steps=6, dt=0.01):
    """Build the model (``build(ops, transient)`` -> nodes, dofs), record both reaction responses,
    run ``n_steps`` of ``analysis`` (``'static'``, ``'Newmark'`` or ``('HHT', α)``) one at a time
    with ``reactions()`` and ``reactions('-dynamic')`` after each; return the recorder files
    (time column dropped), the commands' reactions and, for vtsi, the HDF5 and memory records."""
    transient = analysis != "static"
    nodes, dofs = build(ops, transient)
    where = ["-node", *nodes, "-dof", *dofs]
    memory = {}
    for flag in FLAGS:
        ops.recorder("Node", "-file", str(outdir / f"{flag}.out"), "-time", "-precision", 15, *where, flag)
        if ops is vops:
            ops.recorder("Node", "-h5", str(outdir / f"{flag}.h5"), *where, flag)
            memory[flag] = ops.recorder("Node", *where, flag)
    ops.algorithm("Linear")
    if transient:
        ops.integrator(*(("Newmark", 0.5, 0.25) if analysis == "Newmark" else analysis))
        ops.analysis("Transient")
    else:
        ops.integrator("LoadControl", 1.0 / n_steps)
        ops.analysis("Static")
    commands = {flag: [] for flag in FLAGS}
    for _ in range(n_steps):
        assert (ops.analyze(1, dt) if transient else ops.analyze(1)) == 0
        for flag, option in zip(FLAGS, ((), ("-dynamic",))):
            ops.reactions(*option)
            commands[flag].append([ops.nodeReaction(n, d) for n in nodes for d in dofs])
    out = {f"{flag} command": np.array(commands[flag]) for flag in FLAGS}
    for flag, tag in memory.items():
        out[f"{flag} memory"] = np.array(vops.session.recorders[tag].values)
    ops.wipe()
    for flag in FLAGS:
        out[f"{flag} file"] = np.loadtxt(outdir / f"{flag}.out", ndmin=2)[:, 1:]
        if ops is vops:
            with h5py.File(outdir / f"{flag}.h5", "r") as f:
                out[f"{flag} h5"] = f["values"][:]
    return out


def compare(tmp_path, build, analysis, n_steps=6, dt=0.01):
    (tmp_path / "ref").mkdir()
    (tmp_path / "val").mkdir()
    ref = run(oracle, tmp_path / "ref", build, analysis, n_steps, dt)
    val = run(vops, tmp_path / "val", build, analysis, n_steps, dt)
    for flag in FLAGS:
        if analysis == "static" and flag == "reactionIncInertia":
            continue                          # equal to 'reaction' when nothing moves in time
        for sink in ("file", "h5", "memory", "command"):
            reference = ref[f"{flag} command"] if sink == "command" else ref[f"{flag} file"]
            assert_histories_close(reference, val[f"{flag} {sink}"], f"{flag} {sink}")
        assert_histories_close(ref[f"{flag} command"], ref[f"{flag} file"], f"OpenSeesPy's {flag} file")
    return ref, val


# -- prescribed displacements (sp) ---------------------------------------------------------------
def settling_end(ops, transient):
    """A three-element beam clamped at node 1 whose far end 4 (x fixed) settles by a prescribed
    uy (sp: ramped, or a Trig pulse), a load at node 3, element and nodal mass (Transformation
    handler). The prescribed dof's K·u loads its neighbours and its own reaction."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(4):
        ops.node(1 + i, 4.0 * i, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.fix(4, 1, 0, 0)
    ops.geomTransf("Linear", 1)
    for e in range(3):
        ops.element("elasticBeamColumn", 1 + e, 1 + e, 2 + e, 0.01, 2e11, 1e-4, 1, "-mass", 40.0)
    ops.mass(2, 100.0, 100.0, 1.0)
    if transient:
        ops.timeSeries("Trig", 1, 0.0, 1.0, 0.05)
        ops.rayleigh(0.0, 1e-4, 0.0, 0.0)
    else:
        ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.sp(4, 2, -0.01)
    ops.load(3, 0.0, -2e3, 0.0)
    ops.constraints("Transformation")
    return (1, 2, 3, 4), (1, 2, 3)


@pytest.mark.parametrize("analysis", ["static", "Newmark", ("HHT", 0.85)], ids=["static", "Newmark", "HHT"])
def test_prescribed_support(tmp_path, analysis):
    """The recorders read 36328 at the settling end where OpenSeesPy reads −1171.9 (static): the
    K·u of the prescribed dof was left out."""
    ref, val = compare(tmp_path, settling_end, analysis)
    assert np.abs(ref["reaction file"][:, 10]).max() > 100.0      # the settling end's uy carries load


# -- equalDOF and rigidLink ----------------------------------------------------------------------
def tied_frame(ops, transient):
    """A beam 1-2 clamped at 1 carries beam 3-4 through equalDOF (ux, uy of 3 follow 2); node 5
    hangs on node 4 by a rigidLink beam and stands on a column 5-6 clamped at 6. Loads at the
    constrained nodes 3 and 5, element and nodal mass (Transformation handler)."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0.0, 0.0), (2, 5.0, 0.0), (3, 5.0, 0.0), (4, 10.0, 1.0), (5, 12.0, 1.0), (6, 12.0, -3.0)):
        ops.node(tag, x, y)
    ops.fix(1, 1, 1, 1)
    ops.fix(6, 1, 1, 1)
    ops.geomTransf("Linear", 1)
    ops.element("elasticBeamColumn", 1, 1, 2, 0.1, 2e10, 1e-3, 1, "-mass", 100.0)
    ops.element("elasticBeamColumn", 2, 3, 4, 0.1, 2e10, 1e-3, 1, "-mass", 100.0, "-cMass")
    ops.element("elasticBeamColumn", 3, 5, 6, 0.1, 2e10, 1e-3, 1, "-mass", 60.0)
    ops.equalDOF(2, 3, 1, 2)
    ops.rigidLink("beam", 4, 5)
    ops.mass(3, 50.0, 50.0, 5.0)
    ops.timeSeries("Linear", 1, "-factor", 20.0 if transient else 1.0)
    ops.pattern("Plain", 1, 1)
    ops.load(5, 1e3, -1e4, 0.0)
    ops.load(3, 1e3, 0.0, 2e3)
    if transient:
        ops.rayleigh(0.0, 2e-4, 0.0, 0.0)
    ops.constraints("Transformation")
    return (1, 2, 3, 4, 5, 6), (1, 2, 3)


@pytest.mark.parametrize("analysis", ["static", "Newmark"])
def test_equal_dof_and_rigid_link_neighbours(tmp_path, analysis):
    """The column's support 6 under the rigidLink node read 0 in the recorders: the constrained
    dofs' K·u was left out."""
    ref, _ = compare(tmp_path, tied_frame, analysis)
    assert np.abs(ref["reaction file"][:, 15:18]).max() > 100.0     # node 6


# -- element loads ----------------------------------------------------------------------------------
def loaded_beam(ops, transient):
    """Two spans on pins 1 and 3 and an inclined overhang 3-4: uniform loads (with an axial part)
    on the spans, a point load with an axial part on the overhang, a nodal load at node 2;
    element mass."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0.0, 0.0), (2, 5.0, 0.0), (3, 10.0, 0.0), (4, 13.0, 2.0)):
        ops.node(tag, x, y)
    ops.fix(1, 1, 1, 0)
    ops.fix(3, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    for e, (i, j) in enumerate(((1, 2), (2, 3), (3, 4)), start=1):
        ops.element("elasticBeamColumn", e, i, j, 0.02, 2e11, 2e-4, 1, "-mass", 80.0)
    if transient:
        ops.timeSeries("Path", 1, "-dt", 0.02, "-values", 0.0, 1.0, 0.3, 0.8, 0.5)
        ops.rayleigh(0.0, 1e-4, 0.0, 0.0)
    else:
        ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.eleLoad("-ele", 1, 2, "-type", "-beamUniform", -2e3, 300.0)
    ops.eleLoad("-ele", 3, "-type", "-beamPoint", -5e3, 0.3, 400.0)
    ops.load(2, 0.0, -1e3, 0.0)
    return (1, 2, 3, 4), (1, 2, 3)


@pytest.mark.parametrize("analysis", ["static", "Newmark", ("HHT", 0.8)], ids=["static", "Newmark", "HHT"])
def test_element_loads(tmp_path, analysis):
    """The recorders read 4166.67 where OpenSeesPy reads 5000 (a uniformly loaded simply
    supported beam): the element loads' fixed-end forces were left out. With HHT the analysis
    applies the loads at t_n + αΔt; the reactions (command and recorders) apply them again at
    t_{n+1}, as OpenSees's Domain::calculateNodalReactions."""
    compare(tmp_path, loaded_beam, analysis)


# -- ground acceleration (UniformExcitation) ---------------------------------------------------------
def shaken_truss(ops, transient, cmass=False):
    """Two trusses with their own mass (-rho, lumped or -cMass) from the supports 1 and 2 to the
    apex 3 (nodal mass), nodal mass on the support 1 too, under a ground acceleration in y (a Path)
    (ndf 2)."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 2)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 4.0, 0.0)
    ops.node(3, 2.0, 1.5)
    ops.fix(1, 1, 1)
    ops.fix(2, 1, 1)
    ops.uniaxialMaterial("Elastic", 1, 2e11)
    extra = ("-cMass", 1) if cmass else ()
    ops.element("truss", 1, 1, 3, 1e-4, 1, "-rho", 20.0, *extra)
    ops.element("truss", 2, 2, 3, 1e-4, 1, "-rho", 20.0, *extra)
    ops.mass(3, 100.0, 100.0)
    ops.mass(1, 50.0, 70.0)
    ops.timeSeries("Path", 1, "-dt", 0.002, "-values", 0.0, 1.0, 0.2, -0.7, 0.4, 0.1, "-factor", 9.81)
    ops.pattern("UniformExcitation", 1, 2, "-accel", 1)
    return (1, 2, 3), (1, 2)


@pytest.mark.parametrize("cmass", [False, True], ids=["lumped", "consistent"])
@pytest.mark.parametrize("analysis", ["Newmark", ("HHT", 0.8)], ids=["Newmark", "HHT"])
def test_ground_acceleration_on_the_mass_of_supports(tmp_path, analysis, cmass):
    """Under UniformExcitation a support's reaction also accelerates the mass it carries (its
    nodal mass, the truss's share): OpenSees puts −m a_g in every node's unbalance, a fixed one's
    too, and the truss subtracts its load vector −M_e r a_g in getResistingForce. R1y read 87.77
    where OpenSeesPy reads 774.47 (nodal mass 70 × 9.81)."""
    ref, _ = compare(tmp_path, lambda ops, transient: shaken_truss(ops, transient, cmass), analysis, 5, 0.002)
    assert np.abs(ref["reaction file"][:, 1]).max() > 100.0


def truss_forces(ops, cmass, outdir):
    shaken_truss(ops, True, cmass)
    ops.recorder("Element", "-file", str(outdir / "force.out"), "-precision", 15, "-ele", 1, 2, "force")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    rows = []
    for _ in range(5):
        ops.analyze(1, 0.002)
        rows.append(ops.eleForce(1) + ops.eleForce(2) + ops.eleResponse(1, "axialForce")
                    + ops.eleResponse(2, "localForce") + ops.nodeDisp(3)
                    + [ops.nodeResponse(n, 2, 7) for n in (1, 3)])
    ops.wipe()
    return np.array(rows), np.loadtxt(outdir / "force.out", ndmin=2)


@pytest.mark.parametrize("cmass", [False, True], ids=["lumped", "consistent"])
def test_truss_force_under_ground_acceleration(tmp_path, cmass):
    """A truss's eleForce (OpenSees's getResistingForce) and its Element recorder's ``force`` are
    K·u − (−M_e r a_g); its axialForce and localForce are its material's force alone, as
    OpenSees's. A node's unbalanced load (nodeResponse id 7) holds −m a_g of its nodal mass, a
    fixed node's too, not the truss's share."""
    (tmp_path / "ref").mkdir()
    (tmp_path / "val").mkdir()
    (ref, ref_file), (val, val_file) = truss_forces(oracle, cmass, tmp_path / "ref"), truss_forces(vops, cmass,
                                                                                                 tmp_path / "val")
    assert_histories_close(ref, val, "truss forces")
    assert_histories_close(ref_file, val_file, "Element recorder force")
    np.testing.assert_allclose(val_file[:, :4], val[:, :4], rtol=1e-12, atol=1e-9)    # = eleForce(1)


def shaken_beam(ops, cmass):
    """A horizontal two-element beam (clamped at 1, on a roller at 3) with its own mass under a
    ground acceleration in y: ``eleForce − localForce`` of each element (equal axes), which is the
    element's ground load subtracted in getResistingForce, +M_e r a_g, whatever the response."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(3):
        ops.node(1 + i, 4.0 * i, 0.0)
    ops.fix(1, 1, 1, 1)
    ops.fix(3, 0, 1, 0)
    ops.geomTransf("Linear", 1)
    extra = ("-cMass",) if cmass else ()
    for e in (1, 2):
        ops.element("elasticBeamColumn", e, e, e + 1, 0.01, 2e11, 1e-4, 1, "-mass", 50.0, *extra)
    ops.timeSeries("Path", 1, "-dt", 0.01, "-values", 0.0, 1.0, -0.5, 0.25, "-factor", 9.81)
    ops.pattern("UniformExcitation", 1, 2, "-accel", 1)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    rows = []
    for _ in range(3):
        ops.analyze(1, 0.01)
        rows.append([f - g for e in (1, 2) for f, g in zip(ops.eleForce(e), ops.eleResponse(e, "localForce"))])
    ops.wipe()
    return np.array(rows)


@pytest.mark.parametrize("cmass", [False, True], ids=["lumped", "consistent"])
def test_beam_force_includes_its_ground_load(cmass):
    """elasticBeamColumn with -mass: OpenSeesPy's response to the ground is twice vtsi's (docs,
    What differs), but the part of eleForce that is the element's own ground load, +M_e r a_g,
    is the same in both."""
    ref, val = shaken_beam(oracle, cmass), shaken_beam(vops, cmass)
    assert np.abs(ref).max() > 10.0
    assert_histories_close(ref, val, "eleForce - localForce")
