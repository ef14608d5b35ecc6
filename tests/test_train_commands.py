"""vtsi's train commands (vtsi.train_commands) through vtsi.opensees and Tcl."""
import subprocess
import sys

import numpy as np
import pytest

import vtsi
from vtsi.integrators import GeneralizedAlpha
import vtsi.opensees as ops
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import CommandError, ModelError
from vtsi.models.scenes import S2, s2_model
from vtsi.recorders import ContactRecorder, NodeRecorder, TrainRecorder
from vtsi.track import Track
from vtsi.train import TrainSubdomain

NE, DT, STEPS = 20, 1e-3, 900


def _bridge(session, *mass_options):
    """The S2 span as NE elastic beam-columns, pinned-roller, ``-mass`` plus ``mass_options``."""
    session.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(NE + 1):
        session.node(i + 1, S2["L"] * i / NE, 0.0)
    session.fix(1, 1, 1, 0)
    session.fix(NE + 1, 0, 1, 0)
    session.geomTransf("Linear", 1)
    for e in range(NE):
        session.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0, S2["E"], S2["I"], 1, "-mass", S2["mu"],
                        *mass_options)


def s2_commands(session, interpolation=()):
    session.wipe()
    _bridge(session, "-cMass")
    session.track(1, "-eleRange", 1, NE)
    session.car(1, "sprungMass", S2["m_s"], S2["k_s"])
    session.train(1, S2["V"], "-cars", 1, 0.0)
    session.movingLoadConstraint(1, 1, 1, 0.0, *interpolation)
    session.integrator("Newmark", 0.5, 0.25)
    session.analysis("Transient")


def test_commands_equal_the_object_api():
    session = ops.Session()
    s2_commands(session)
    mid = session.recorder("Node", "-node", NE // 2 + 1, "-dof", 2, "disp")
    force = session.recorder("Contact", "force")
    acc = session.recorder("Train", "-dof", "car0.body_y", "accel")
    session.analyze(STEPS, DT)

    model = vtsi.Model()
    bridge, train = s2_model(model, NE)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train))
    recs = [NodeRecorder([bridge.midspan_nodes[0]], [2]), ContactRecorder(constraint),
            TrainRecorder(constraint.train, ["car0.body_y"], "accel")]
    analysis = CoupledAnalysis(model, constraint, "Newmark", DT, recorders=recs)
    analysis.static()
    analysis.run(STEPS)
    for tag, ref in zip((mid, force, acc), recs):
        np.testing.assert_allclose(session.recorders[tag].values, ref.values, rtol=1e-12, atol=1e-15)
    # the S2 reference (Yang & Yau 1997): 2.4073 mm; 20 elements, 1 ms: within 0.2 %
    assert abs(-session.recorders[mid].values.min() / S2["max_midspan_deflection"] - 1.0) < 2e-3


def test_exact_events_option_equals_the_object_api():
    """``-exactEvents`` is ``CoupledAnalysis(exact_events=True)``: S2's sprung mass (massless
    wheel) leaves the span at t = L/V = 0.9 s, where its wheel's velocity jumps onto the ground."""
    n = int(round(1.0 / DT))
    session = ops.Session()
    s2_commands(session, ("-exactEvents",))
    force = session.recorder("Contact", "force")
    session.analyze(n, DT)
    model = vtsi.Model()
    bridge, train = s2_model(model, NE)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train))
    runs = []
    for exact in (True, False):
        rec = ContactRecorder(constraint)
        analysis = CoupledAnalysis(model, constraint, "Newmark", DT, recorders=[rec], exact_events=exact)
        analysis.static()
        analysis.run(n)
        runs.append(rec.values)
        assert len(analysis._events(0.0, n)) == (1 if exact else 0)
    np.testing.assert_allclose(session.recorders[force].values, runs[0], rtol=1e-12, atol=1e-9)
    assert np.abs(runs[0] - runs[1]).max() > 1.0


def test_contact_recorder_text_and_bspline_option(tmp_path):
    session = ops.Session()
    s2_commands(session, ("-bspline",))
    session.contact("lcp")
    with pytest.raises(vtsi.AnalysisError, match="contact='lcp' needs a dissipative integrator"):
        session.analyze(1, DT)                       # s2_commands' integrator Newmark 0.5 0.25
    session.integrator("HHT", 0.9)
    path = tmp_path / "contact.out"
    session.recorder("Contact", "-file", str(path), "-time", "inContact")
    session.analyze(100, DT)
    session.wipe()
    data = np.loadtxt(path)
    assert data.shape == (100, 2) and np.all(data[:, 1] == 1.0)     # the sprung mass never lifts off


def test_tcl_runs_train_commands(tmp_path):
    out = tmp_path / "mid.out"
    script = tmp_path / "s2.tcl"
    script.write_text(f"""model basic -ndm 2 -ndf 3
for {{set i 0}} {{$i <= {NE}}} {{incr i}} {{ node [expr $i+1] [expr {S2['L']}*$i/{NE}] 0.0 }}
fix 1 1 1 0
fix {NE + 1} 0 1 0
geomTransf Linear 1
for {{set e 1}} {{$e <= {NE}}} {{incr e}} {{ element elasticBeamColumn $e $e [expr $e+1] 1.0 {S2['E']} {S2['I']} 1 -mass {S2['mu']} -cMass }}
track 1 -eleRange 1 {NE}
car 1 sprungMass {S2['m_s']} {S2['k_s']}
train 1 {S2['V']} -cars 1 0.0
movingLoadConstraint 1 1 1 0.0
integrator Newmark 0.5 0.25
analysis Transient
recorder Node -file {out} -time -node {NE // 2 + 1} -dof 2 disp
analyze {STEPS} {DT}
""")
    subprocess.run([sys.executable, "-m", "vtsi", str(script)], check=True, capture_output=True, timeout=120)
    session = ops.Session()
    s2_commands(session)
    mid = session.recorder("Node", "-node", NE // 2 + 1, "-dof", 2, "disp")
    session.analyze(STEPS, DT)
    np.testing.assert_allclose(np.loadtxt(out)[:, 1], session.recorders[mid].values[:, 0], rtol=1e-5, atol=1e-11)


@pytest.mark.parametrize("command, args, message", [
    ("car", (1, "bogie", 1.0), r"car type 'bogie' is not supported; supported: movingForce"),
    ("car", (1, "catalogue", "TGV"), r"car 1: .*TGV"),
    ("car", (1, "sprungMass", -5.0, 1e6), r"car 1: .*-5"),
    ("train", (1, 80.0, "-cars", 9, 0.0), r"train 1: car 9 does not exist"),
    ("track", (1, "-ele", 99), None),
    ("movingLoadConstraint", (1, 7, 1, 0.0), r"train 7 does not exist"),
    ("contact", ("penalty",), r"contact strategy 'penalty' is not supported; supported: bilateral, lcp"),
])
def test_bad_train_commands_name_the_object(command, args, message):
    session = ops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    if message is None:    # an unknown track element is reported where the train meets the model
        session.track(*args)
        session.car(1, "movingForce", 1e5)
        session.train(1, 80.0, "-cars", 1, 0.0)
        with pytest.raises(CommandError, match=r"movingLoadConstraint 1: track 1: (.*element 99 does not exist|"
                                               r".*model has no nodes)"):
            session.movingLoadConstraint(1, 1, 1, 0.0)
        return
    with pytest.raises(CommandError, match=message):
        getattr(session, command)(*args)


def test_generalized_alpha_in_a_coupled_script_equals_the_object_api():
    """``integrator GeneralizedAlpha`` runs the coupled analysis of a script as the object API's."""
    session = ops.Session()
    s2_commands(session)
    session.integrator("GeneralizedAlpha", 0.9, 0.75)
    force = session.recorder("Contact", "force")
    session.analyze(STEPS, DT)
    model = vtsi.Model()
    bridge, train = s2_model(model, NE)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train))
    rec = ContactRecorder(constraint)
    analysis = CoupledAnalysis(model, constraint, GeneralizedAlpha(0.9, 0.75), DT, recorders=[rec])
    analysis.static()
    analysis.run(STEPS)
    np.testing.assert_allclose(session.recorders[force].values, rec.values, rtol=1e-12, atol=1e-9)


def test_coupled_analysis_refuses_explicit_integrators():
    session = ops.Session()
    s2_commands(session)
    session.integrator("CentralDifference")
    with pytest.raises(CommandError, match="CentralDifference is not available for a coupled analysis"):
        session.analyze(1, DT)


def test_dead_load_says_what_it_contains_and_adds_the_self_weight_on_request(tmp_path):
    """deadLoad alone: the response to the train (the sprung mass at x = 0, over the support,
    leaves the deck straight); deadLoad -selfWeight adds the deck's weight: mid-span deflection
    5 μ g L⁴ / (384 EI) (consistent-mass Hermite beam, exact for a uniform load at the nodes to
    1e-9). Each HDF5 record and the static state say which in ``loads``."""
    import h5py
    deflection = {}
    for flag in ((), ("-selfWeight",)):
        session = ops.Session()
        s2_commands(session)
        path = tmp_path / f"mid{len(flag)}.h5"
        session.recorder("Node", "-h5", str(path), "-node", NE // 2 + 1, "-dof", 2, "disp")
        session.deadLoad(*flag)
        deflection[flag] = session.nodeDisp(NE // 2 + 1, 2)
        loads = session._coupled.static_state["loads"]
        session.integrator("Newmark", 0.5, 0.25)
        session.analyze(2, DT)
        session.wipe()
        with h5py.File(path, "r") as f:
            assert f.attrs["loads"] == loads
        assert ("self weight (totals)" in loads) == bool(flag)
    exact = 5 * S2["mu"] * vtsi.models.GRAVITY * S2["L"] ** 4 / (384 * S2["E"] * S2["I"])
    assert abs(deflection[()]) < 1e-12
    assert deflection[("-selfWeight",)] == pytest.approx(-exact, rel=1e-9)
    with pytest.raises(CommandError, match="option '-gravity' is not supported; supported: -selfWeight"):
        session = ops.Session()
        s2_commands(session)
        session.deadLoad("-gravity")


def _ice3_over_s2_bridge(force_unit, length_unit, declare=True, speed="250km/h"):
    """Two ICE3 cars (10-dof, from the SI catalogue) over the S2 span written in the given units;
    mid-span deflection [model length] and contact forces [model force] of 300 steps."""
    f_F = {"N": 1.0, "kN": 1e-3}[force_unit]
    f_L = {"m": 1.0, "mm": 1e3}[length_unit]
    f_M = f_F / f_L
    session = ops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    if declare:
        session.units(force_unit, length_unit)
    for i in range(NE + 1):
        session.node(i + 1, S2["L"] * i / NE * f_L, 0.0)
    session.fix(1, 1, 1, 0)
    session.fix(NE + 1, 0, 1, 0)
    session.geomTransf("Linear", 1)
    for e in range(NE):
        session.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0 * f_L ** 2, S2["E"] * f_F / f_L ** 2,
                        S2["I"] * f_L ** 4, 1, "-mass", S2["mu"] * f_M / f_L, "-cMass")
    session.track(1, "-eleRange", 1, NE)
    session.train(1, speed, "-ICE3", 2)
    session.movingLoadConstraint(1, 1, 1, -1.0 * f_L)
    session.integrator("Newmark", 0.5, 0.25)
    session.analysis("Transient")
    mid = session.recorder("Node", "-node", NE // 2 + 1, "-dof", 2, "disp")
    force = session.recorder("Contact", "force")
    session.analyze(300, DT)
    values = np.array(session.recorders[mid].values)[:, 0], np.array(session.recorders[force].values)
    session.wipe()
    return values


@pytest.mark.parametrize("force_unit, length_unit", [("kN", "m"), ("N", "mm")])
def test_units_a_script_in_other_units_gives_the_same_physics(force_unit, length_unit):
    """The same bridge in kN-t-m (or N-t-mm) with SI catalogue trains, ``units`` declared: every
    deflection is the SI one × f_L and every contact force × f_F, to rounding (measured 1e-13 and
    5e-12);
    a speed given as '250km/h' is 69.44 m/s (= 69444 mm/s)."""
    w_si, lam_si = _ice3_over_s2_bridge("N", "m")
    w, lam = _ice3_over_s2_bridge(force_unit, length_unit)
    f_F, f_L = {"N": 1.0, "kN": 1e-3}[force_unit], {"m": 1.0, "mm": 1e3}[length_unit]
    assert np.abs(w - f_L * w_si).max() <= 1e-9 * np.abs(f_L * w_si).max()
    assert np.abs(lam - f_F * lam_si).max() <= 1e-9 * np.abs(f_F * lam_si).max()
    w_ms, _ = _ice3_over_s2_bridge("N", "m", speed=250.0 / 3.6)
    assert np.array_equal(w_ms, w_si)


def test_units_undeclared_on_a_kn_t_m_model_are_refused():
    """A kN-t-m bridge with SI trains and no ``units``: its deck reads 2.3 kg/m, refused where the
    train meets the model, naming the fix; units after a train, or unknown ones, are refused too."""
    with pytest.raises(CommandError, match=r"movingLoadConstraint 1: the deck weighs 2\.303 kg/m.*units\('kN', 'm'\)"):
        _ice3_over_s2_bridge("kN", "m", declare=False)
    with pytest.raises(CommandError, match=r"deck weighs 0\.002303 kg/m .* in N, mm, t .*it would weigh 2303 kg/m: "
                                           r"declare them first \(Tcl: units N mm; Python: units\('N', 'mm'\)\)"):
        _ice3_over_s2_bridge("N", "mm", declare=False)               # it said "units('kN', 'm')" whatever the units
    from vtsi.units import Units
    with pytest.raises(ModelError, match=r"the deck weighs 2\.303e\+06 kg/m .*above 1e\+06 kg/m \(no railway deck is "
                                         r"that heavy\).* units kN m;"):
        Units("N", "mm").check_deck_mass(2.303, "track 1")            # a kN-m deck declared N, mm: it ran
    session = ops.Session()
    session.model("basic", "-ndm", 2, "-ndf", 3)
    session.car(1, "movingForce", 1e5)
    with pytest.raises(CommandError, match="units: declare the units before any car"):
        session.units("kN", "m")
    with pytest.raises(CommandError, match="force unit 'lbf' is not supported; supported: N, kN, MN"):
        ops.Session().units("lbf", "m")
    with pytest.raises(CommandError, match=r"train 1: speed: '300 mph' is not a speed"):
        s = ops.Session()
        s.model("basic", "-ndm", 2, "-ndf", 3)
        s.train(1, "300 mph", "-HSLM", "A1")


def test_sprung_mass_options_take_effect():
    session = ops.Session()
    session.car(1, "sprungMass", 5750.0, 1e6)
    session.car(2, "sprungMass", 5750.0, 1e6, "-c", 1e4, "-wheelMass", 500.0)
    plain, damped = session._cars[1], session._cars[2]
    assert plain.C[0, 0] == 0.0 and plain.M[1, 1] == 0.0
    assert damped.C[0, 0] == 1e4 and damped.C[0, 1] == -1e4 and damped.M[1, 1] == 500.0
    with pytest.raises(CommandError, match=r"^car 3 sprungMass: -c must be a number, got 'x'$"):
        session.car(3, "sprungMass", 5750.0, 1e6, "-c", "x")


def _zero_length_track(session):
    _bridge(session)
    session.uniaxialMaterial("Elastic", 1, 1e6)
    session.node(50, S2["L"], 0.0)
    session.element("zeroLength", 50, NE + 1, 50, "-mat", 1, "-dir", 1)
    session.track(2, "-ele", 50)
    session.car(1, "movingForce", 1e5)
    session.train(1, 20.0, "-cars", 1, 0.0)


def _missing_element_track(session):
    _bridge(session)
    session.track(2, "-ele", 1, 99)
    session.car(1, "movingForce", 1e5)
    session.train(1, 20.0, "-cars", 1, 0.0)


def _s2(session):
    s2_commands(session)


BAD_TRAIN_INPUTS = [   # (setup, command, args, message)
    (_bridge, "train", (2, True, "-cars", 1, 0.0), r"train 2: speed: True is not a speed"),
    (_bridge, "train", (2, float("nan"), "-cars", 1, 0.0), r"train 2: speed: must be finite, got nan"),
    (_bridge, "train", (2, 300, "-cars", 1, 0.0), r"train 2: speed: 300 m/s \(1080 km/h\) is faster than any train "
                                                  r"\(at most 200 m/s\); a speed in km/h is written '300km/h'$"),
    (_bridge, "train", (2, "800km/h", "-cars", 1, 0.0), r"train 2: speed: 222\.222 m/s \(800 km/h\) is faster than "
                                                        r"any train \(at most 200 m/s\)$"),
    (_bridge, "recorder", ("Train", "-dof", 1.5, "disp"), r"recorder Train: -dof must be a train dof name or an "
                                                           r"integer index, got 1.5"),
    (_bridge, "recorder", ("Train", "-dof", None, "disp"), r"recorder Train: -dof .* got None"),
    (_bridge, "recorder", ("Contact", "force", "gap"), r"recorder Contact: give one response, got 'force' and 'gap'"),
    (_bridge, "recorder", ("Contact", "-file", "a.out", "-file", "b.out", "force"),
     r"recorder Contact: give one output file"),
    (_bridge, "recorder", ("Contact", "-wheel", "a", "force"), r"recorder Contact: -wheel index must be an integer, "
                                                                r"got 'a'"),
    (_bridge, "recorder", ("Contact", "-file", "-wheel", 1, "force"),      # once a file named '-wheel'
     r"^recorder Contact: -file needs a file name, got none \('-wheel' follows\)$"),
    (_bridge, "recorder", ("Train", "-h5", "t.h5", "-precision", 3, "disp"),     # once silently ignored
     r"^recorder Train: -precision does nothing with -h5: it sets the digits of a text file"),
    (_zero_length_track, "movingLoadConstraint", (1, 1, 2, 0.0),
     r"movingLoadConstraint 1: track 2: elements \[50\] have no length along x"),
    (_missing_element_track, "movingLoadConstraint", (1, 1, 2, 0.0),      # once 'track 2: track: element 99 ...'
     r"^movingLoadConstraint 1: track 2: element 99 does not exist$"),
    (_bridge, "irregularity", (1, "file", "/nonexistent.txt"),
     r"^irregularity 1: cannot read /nonexistent.txt: no such file$"),
    (_bridge, "irregularity", (1, "file", "/"), r"^irregularity 1: cannot read /: Is a directory$"),
    (_bridge, "irregularity", (1, "german", "low", 0.0, 1e12),
     r"^irregularity 1: x_first \.\. x_last = 0 \.\. 1e\+12 needs 2e\+13 samples at 0.05 m steps, more than 200000"),
    (_bridge, "irregularity", (1, "german", "low", 0.0, 100.0, "-seed", -1),
     r"^irregularity 1: -seed must be a non-negative integer, got -1"),
    (_bridge, "irregularity", (1, "profile", "-x", 0.0, 1.0), r"^irregularity 1: missing option -r$"),
    (_bridge, "irregularity", (1, "profile", "-x", "0 1 abc", "-r", 0.0, 0.0, 0.0),     # Tcl's -x {0 1 abc}
     r"^irregularity 1: -x item 3 is 'abc', not a number$"),
    (_s2, "analyze", (1,), r"analyze: a Static analysis would ignore the train .* deadLoad\(\)"),
]


@pytest.mark.parametrize("setup, command, args, message", BAD_TRAIN_INPUTS,
                         ids=[f"{c[1]}{c[2]!r}" for c in BAD_TRAIN_INPUTS])
def test_bad_train_inputs_name_the_object_and_value(setup, command, args, message):
    session = ops.Session()
    setup(session)
    if command == "analyze":
        session.analysis("Static")
    with pytest.raises(CommandError, match=message):
        getattr(session, command)(*args)


def test_a_train_of_cars_in_a_model_s_own_units():
    """With units('N', 'mm') a train's speed is in mm/s: 'train -cars' at 300 km/h (83 333 mm/s)
    ran, then was refused as faster than any train (200 m/s read as 200 mm/s); a speed above
    200 m/s in the model's units still is."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.units("N", "mm")
    ops.car(1, "movingForce", 170e3)
    ops.train(1, "300km/h", "-cars", 1, 0.0)
    ops.train(2, "300km/h", "-HSLM", "A1")
    with pytest.raises(CommandError, match=r"train 3: speed: 250000 mm/s \(900 km/h\) is faster than any train"):
        ops.train(3, 250e3, "-cars", 1, 0.0)
    ops.wipe()


def test_hdf5_recorders_label_the_model_s_units(tmp_path, cantilever):
    """A script in kN and mm records mm, kN and kN mm: its HDF5 files said m, N and N m (the text
    files and nodeDisp were already in the model's units; only the labels were SI)."""
    import h5py
    cantilever(ops)
    ops.units("kN", "mm")
    ops.recorder("Node", "-h5", str(tmp_path / "u.h5"), "-node", 2, "-dof", 2, 3, "disp")
    ops.recorder("Element", "-h5", str(tmp_path / "f.h5"), "-ele", 1, "localForce")
    ops.integrator("LoadControl", 1.0)
    ops.analysis("Static")
    ops.analyze(1)
    ops.wipe()
    with h5py.File(tmp_path / "u.h5") as f:
        assert [u.decode() if isinstance(u, bytes) else u for u in f["values"].attrs["units"]] == ["mm", "rad"]
    with h5py.File(tmp_path / "f.h5") as f:
        assert {u.decode() if isinstance(u, bytes) else u for u in f["values"].attrs["units"]} == {"kN", "kN mm"}


def test_a_rail_profile_in_other_units_is_refused():
    """A profile of 2 (mm meant) in an m model read as 2 m and gave a deck acceleration of
    117 m/s²: deeper than 100 mm it is refused, naming the model's length unit; in an mm model
    the same numbers are 2 mm and run."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    with pytest.raises(CommandError, match=r"^irregularity 1: a rail profile of 2 m \(2000 mm\), more than any "
                                           r"track's 100 mm: is it in other units than the model's \(m\)\?$"):
        ops.irregularity(1, "profile", "-x", 0.0, 10.0, 20.0, "-r", 0.0, 2.0, 0.0)
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.units("N", "mm")
    ops.irregularity(1, "profile", "-x", 0.0, 1e4, 2e4, "-r", 0.0, 2.0, 0.0)
    with pytest.raises(CommandError, match=r"a bare number is in mm/s: write km/h as text, e.g. '300km/h'"):
        ops.train(1, 1.08e6, "-HSLM", "A1")
    ops.wipe()


def test_get_load_factor_after_a_coupled_analyze():
    """getLoadFactor reads the factor the domain last applied (0 before any step, as OpenSees):
    a coupled script applies its patterns in deadLoad (at t = 0) and at every step, the last at
    the step's end time (Newmark): a Constant series of factor 2 reads 2 from deadLoad on, a Linear
    one of factor 3 reads 3 t after the steps."""
    session = ops.Session()
    s2_commands(session)
    session.timeSeries("Linear", 7, "-factor", 3.0)
    session.pattern("Plain", 7, 7)
    session.load(NE // 2 + 1, 0.0, -1e3, 0.0)
    session.timeSeries("Constant", 8, "-factor", 2.0)
    session.pattern("Plain", 8, 8)
    session.load(NE // 2, 0.0, -1e3, 0.0)
    assert session.getLoadFactor(7) == session.getLoadFactor(8) == 0.0
    session.deadLoad()
    assert session.getLoadFactor(7) == 0.0 and session.getLoadFactor(8) == 2.0
    session.analyze(5, DT)
    assert session.getTime() == pytest.approx(5 * DT) and session.getLoadFactor(7) == pytest.approx(3.0 * 5 * DT)
    assert session.getLoadFactor(8) == 2.0


def test_dead_load_of_b_spline_rows_takes_the_run_s_dt():
    """B-spline rows spread a moving wheel over 2 V Δt, so the dead load depends on the run's Δt:
    ``deadLoad`` without it solved them for Δt = 1 s (the S2 car at mid-span, V = 27.8 m/s: a
    56 m knot on a 25 m span, the mid-span deflection 0.41 mm for 2.21) and ``analyze`` started from that
    state. Now ``deadLoad`` needs ``-dt`` before the first ``analyze`` and gives the object API's
    ``static()`` at that Δt; an ``analyze`` at another Δt right after it is refused; after an
    ``analyze`` it takes the run's Δt."""
    def commands(session):
        session.wipe()
        _bridge(session, "-cMass")
        session.track(1, "-eleRange", 1, NE)
        session.car(1, "sprungMass", S2["m_s"], S2["k_s"])
        session.train(1, S2["V"], "-cars", 1, 0.0)
        session.movingLoadConstraint(1, 1, 1, S2["L"] / 2, "-bspline")
        session.integrator("Newmark", 0.5, 0.25)
        session.analysis("Transient")

    model = vtsi.Model()
    bridge, train = s2_model(model, NE)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x_head0=S2["L"] / 2),
                                      interpolation="bspline")
    CoupledAnalysis(model, constraint, "Newmark", DT).static()
    reference = vtsi.analysis.domain_state(model).u[3 * (NE // 2) + 1]     # mid-span uy
    session = ops.Session()
    commands(session)
    with pytest.raises(CommandError, match=r"^deadLoad: the train's B-spline rows .* give it, deadLoad -dt <dt>"):
        session.deadLoad()
    session.deadLoad("-dt", DT)
    assert session.nodeDisp(NE // 2 + 1, 2) == pytest.approx(reference, rel=1e-12)
    with pytest.raises(CommandError, match=r"^analyze: dt = 0.002 s, but deadLoad solved .* for dt = 0.001 s; "
                                           r"give deadLoad -dt 0.002$"):
        session.analyze(1, 2 * DT)
    session.analyze(2, DT)
    commands(session)
    session.analyze(1, DT)          # the automatic dead load at the run's dt; then deadLoad takes it
    session.deadLoad()
    moved = session.nodeDisp(NE // 2 + 1, 2)
    session.deadLoad("-dt", DT)
    assert session.nodeDisp(NE // 2 + 1, 2) == moved and moved == pytest.approx(reference, rel=1e-3)
