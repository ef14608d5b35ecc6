"""A free rail end (vtsi.track_ends, docs/sweeps.md "Ground"): a track end node not fixed in uy
sags under a wheel, and the cars' wheels meet that sag as a step from the rigid ground beyond
the track. A 25 m deck with 6 m approaches of rail on springs, free at their ends, read a false
wheel-unloading FAIL under ICE3 cars. A sweep of cars now says so (``Sweep.free_end_note``,
``vtsi sweep``'s summary), naming each end node, its x and its sag under the trains' heaviest
static wheel load, and the check's wheel unloading and contact loss rows carry it (so the
report does); fixed ends, a stiff bearing and moving forces are not told."""
import numpy as np
import pytest

import vtsi
from vtsi.__main__ import main
from vtsi.check import check
from vtsi.passage import PassageSettings
from vtsi.report import write_report
from vtsi.sweep import Sweep, SweepBridge
from vtsi.track_ends import FREE_END_SAG

# the documented case: a 25 m simply supported deck (15 t/m, n0 = 5 Hz) with 6 m approaches of
# rail (2 x UIC60) on 5e7 N/m springs a metre apart, its elements 1 m long
L, MU, E, F1 = 25.0, 15000.0, 3.5e10, 5.0
I_DECK = MU * (2 * L ** 2 * F1 / np.pi) ** 2 / E         # f1 = (π / 2L²) √(EI/μ)
APPROACH, SPRING = 6.0, 5e7
E_RAIL, I_RAIL, A_RAIL, MU_RAIL = 2.1e11, 6.1e-5, 0.0154, 120.0
ICE3_WHEEL = 152055.0                                     # [N] each ICE3 wheel (axle) at rest: 15.5 t
FIRST, LAST = 1, 38                                       # the track's end nodes, x = -6 and 31 m
CARS = PassageSettings(cars="full", damping=0.01)


def approach_bridge(ends=None):
    """The documented bridge: the end nodes on their springs (``ends`` None), fixed in uy
    ('fixed'), or on springs of ``ends`` [N/m] in place of theirs."""
    model = vtsi.Model()
    xs = np.arange(-APPROACH, L + APPROACH + 0.5)
    for i, x in enumerate(xs):
        node = i + 1
        model.node(node, float(x), 0.0)
        if x in (0.0, L):
            model.fix(node, int(x == 0.0), 1, 0)
        elif node in (FIRST, LAST) and ends == "fixed":
            model.fix(node, 1, 1, 0)
        elif x < 0.0 or x > L:
            model.node(1000 + node, float(x), 0.0)
            model.fix(1000 + node, 1, 1, 1)
            ky = ends if node in (FIRST, LAST) and ends is not None else SPRING
            model.element("zeroLength", 1000 + node, (node, 1000 + node), kx=1e8, ky=ky)
    for e in range(1, len(xs)):
        on_deck = 0.0 < 0.5 * (xs[e - 1] + xs[e]) < L
        model.element("elasticBeamColumn", e, (e, e + 1), A=5.0 if on_deck else A_RAIL,
                      E=E if on_deck else E_RAIL, I=I_DECK if on_deck else I_RAIL, rho=MU if on_deck else MU_RAIL)
    return SweepBridge(model, list(range(1, len(xs))), {"kind": "script"})


def approach_sag(load):
    """The free end's static sag [m] under ``load`` [N] on it, solved on its own: the approach's
    six rail elements (Euler-Bernoulli stiffness, exact under nodal loads) on their springs, the
    rail's end at the deck (x = 0) fixed in uy and held in rotation by the simply supported deck
    (M = 3 EI θ / L)."""
    n = int(APPROACH) + 1                    # nodes x = -6 ... 0; dofs (v, θ) of each
    K = np.zeros((2 * n, 2 * n))
    EI, h = E_RAIL * I_RAIL, 1.0
    ke = EI / h ** 3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                 [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
    for e in range(n - 1):
        K[2 * e: 2 * e + 4, 2 * e: 2 * e + 4] += ke
    for k in range(n - 1):
        K[2 * k, 2 * k] += SPRING
    K[2 * n - 1, 2 * n - 1] += 3 * E * I_DECK / L
    keep = np.delete(np.arange(2 * n), 2 * n - 2)      # the last node's v is fixed
    p = np.zeros(2 * n - 1)
    p[0] = -load
    return -np.linalg.solve(K[np.ix_(keep, keep)], p)[0]


def test_the_documented_free_rail_end_is_told_with_its_sag(tmp_path):
    """Free ends on 5e7 N/m springs: 2.62 mm under the ICE3's 152.1 kN wheel (the independent
    solve), both ends named in the sweep's note, in the results file, in the check's wheel
    unloading and contact loss rows and in the report's notes; not in the car body row."""
    sag = approach_sag(ICE3_WHEEL)
    assert sag == pytest.approx(2.623e-3, rel=1e-3) and sag > FREE_END_SAG
    sweep = Sweep(approach_bridge(), ["ICE3"], "280", CARS)
    ends = sweep.runner.track_ends(["ICE3"])
    assert [(e.node, e.x_m) for e in ends] == [(FIRST, -APPROACH), (LAST, L + APPROACH)]
    for end in ends:                         # the two approaches are mirror images
        assert end.sag_m == pytest.approx(sag, rel=1e-9) and end.load_n == pytest.approx(ICE3_WHEEL, rel=1e-6)
    told = (f"track end nodes {FIRST} (x = -6 m) and {LAST} (x = 31 m) are not fixed in uy and sag {1e3 * sag:.3g} "
            f"and {1e3 * sag:.3g} mm under the trains' heaviest static wheel load (152.1 kN), more than 0.25 mm")
    note = sweep.free_end_note()
    assert note.startswith(f"note: {told}") and note.endswith(f"fix nodes {FIRST} and {LAST} in uy, or extend the "
                                                              "approaches")
    path = tmp_path / "free.h5"
    results = sweep.run(path, workers=1, progress=False)
    bridge = results.bridge()
    assert bridge["track_end_nodes"].tolist() == [FIRST, LAST] and bridge["track_end_x_m"].tolist() == [-6.0, 31.0]
    np.testing.assert_allclose(bridge["track_end_sag_m"], [sag, sag], rtol=1e-9)
    result = check(results)
    for criterion in ("wheel_unloading", "contact_loss"):
        assert note.removeprefix("note: ") in result.row(criterion).note
    assert "track end" not in result.row("car_body_acceleration").note
    result.store(path)
    report = write_report(path, tmp_path / "report")["markdown"].read_text(encoding="utf-8")
    assert told in report


def test_free_ends_unload_the_wheels_on_the_deck(tmp_path):
    """What the note warns of (docs/sweeps.md): at 280 km/h the free ends read a wheel unloading
    far above the fixed ends' (0.634 against 0.257, measured), by more than the 0.05 by which
    FREE_END_SAG is drawn."""
    unloading = {}
    for ends in (None, "fixed"):
        results = Sweep(approach_bridge(ends), ["ICE3"], "280", CARS).run(None, workers=1, progress=False)
        unloading[ends] = check(results).row("wheel_unloading").value
    assert unloading[None] > unloading["fixed"] + 0.05


@pytest.mark.parametrize("ends", ["fixed", 1e10])
def test_fixed_ends_and_a_stiff_bearing_are_not_told(tmp_path, ends):
    """Ends fixed in uy sag nothing; on a 1e10 N/m spring (a stiff bearing) 0.015 mm, below
    FREE_END_SAG: no note, no words in the check's rows."""
    sweep = Sweep(approach_bridge(ends), ["ICE3"], "280", CARS)
    sags = [e.sag_m for e in sweep.runner.track_ends(["ICE3"])]
    if ends == "fixed":
        assert sags == [0.0, 0.0]
    else:                                    # the stiff spring in series with what the rail adds: at most P / k
        assert all(0.0 < s < ICE3_WHEEL / ends < FREE_END_SAG for s in sags)
    assert sweep.free_end_note() == ""
    result = check(sweep.run(tmp_path / "ends.h5", workers=1, progress=False))
    assert not any("track end" in row.note for row in result.rows)


def test_moving_forces_are_not_told():
    """Moving forces read no step (docs/sweeps.md: the deck's envelopes moved by 1 % at most):
    the same free ends give no note."""
    sweep = Sweep(approach_bridge(), ["ICE3"], "280", PassageSettings(damping=0.01))
    assert max(e.sag_m for e in sweep.runner.track_ends(["ICE3"])) > FREE_END_SAG
    assert sweep.free_end_note() == ""


SCRIPT = f"""\
import vtsi.opensees as ops
ops.wipe()
ops.model('basic', '-ndm', 2, '-ndf', 3)
ops.geomTransf('Linear', 1)
ops.uniaxialMaterial('Elastic', 1, {SPRING!r})
ops.uniaxialMaterial('Elastic', 2, 1e8)
for i in range(38):
    x = i - 6.0
    ops.node(i + 1, x, 0.0)
    if x in (0.0, 25.0):
        ops.fix(i + 1, int(x == 0.0), 1, 0)
    elif x < 0.0 or x > 25.0:
        ops.node(1001 + i, x, 0.0)
        ops.fix(1001 + i, 1, 1, 1)
        ops.element('zeroLength', 1001 + i, i + 1, 1001 + i, '-mat', 2, 1, '-dir', 1, 2)
for e in range(1, 38):
    if 6 < e <= 31:
        ops.element('elasticBeamColumn', e, e, e + 1, 5.0, {E!r}, {I_DECK!r}, 1, '-mass', {MU!r})
    else:
        ops.element('elasticBeamColumn', e, e, e + 1, {A_RAIL!r}, {E_RAIL!r}, {I_RAIL!r}, 1, '-mass', {MU_RAIL!r})
ops.track(1, '-eleRange', 1, 37)
"""


def test_vtsi_sweep_prints_the_note_under_its_table(tmp_path, capsys):
    """``vtsi sweep`` of cars over the documented bridge as a script: the note's line closes its
    summary (standard output); with moving forces it is not there."""
    script = tmp_path / "approaches.py"
    script.write_text(SCRIPT)
    common = [str(script), "--trains", "ICE3", "--speeds", "280", "--damping", "0.01", "--workers", "1", "--quiet"]
    assert main(["sweep", *common, "--cars", "full", "--out", str(tmp_path / "cars.h5")]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith(f"note: track end nodes {FIRST} (x = -6 m) and {LAST} (x = 31 m) are not fixed in uy and "
                           "sag 2.62 and 2.62 mm")
    assert main(["sweep", *common, "--out", str(tmp_path / "forces.h5")]) == 0
    assert "track end" not in capsys.readouterr().out
