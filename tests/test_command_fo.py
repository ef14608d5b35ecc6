"""Four differences of the command layer from OpenSees, each checked against OpenSeesPy 3.7.1
run in the test (the oracle), and the cost of moving a load the OpenSees way:

1. ``load(node, *values, '-pattern', tag)``: OpenSees reads every argument after the node tag as
   a load value (OpenSeesPy's ``OPS_NodalLoad``: ``ndf = remaining arguments - 1``; Tcl's
   ``TclCommand_addNodalLoad``, SRC/modelbuilder/tcl/TclModelBuilder.cpp of 3.7.1: ``ndf = argc -
   2``), so both fail on ``-pattern`` and ``-const``; vtsi accepted ``-pattern``, now it refuses
   it in Python and Tcl, naming the word, and the load is not added, as in OpenSeesPy.
2. ``printModel`` named an inline series (``pattern Plain 2 "Linear -factor 2"``) by an internal
   tag (``series Linear -1``); now ``series Linear (inline)``, and under every Plain pattern its
   series as OpenSees prints it (``LinearSeries::Print``...), the text OpenSeesPy prints.
3. ``recorder Element -ele 1 <response>`` of an element without the response was refused;
   OpenSees records no columns: the file holds the times only with ``-time``, else nothing
   (an envelope: nothing); vtsi now writes OpenSeesPy's file, and warns naming the element,
   the response and the file.
4. A moving load the OpenSees way (a new pattern at every step): a pattern of nodal loads goes
   straight into the free dofs (``Assembly.load_vectors``: the numbers of the full-vector path
   to the bit), and the loads kept as last applied copy only the patterns that changed.
"""
import logging
import re

import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.errors import CommandError  # noqa: E402
from vtsi.loads import LoadPattern  # noqa: E402

pytestmark = pytest.mark.usefixtures("fresh_session")


def cantilever(o):
    """A 2 m cantilever (node 1 clamped, node 2 free), a Linear series 1 and Plain pattern 1 of it."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    o.node(1, 0.0, 0.0)
    o.node(2, 2.0, 0.0)
    o.fix(1, 1, 1, 1)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 0.01, 2e11, 1e-4, 1)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)


def static_tip_deflection(o):
    """The tip's y displacement after one static LoadControl step of 1 (λ = 1)."""
    o.system("BandGeneral")
    o.numberer("Plain")
    o.constraints("Plain")
    o.integrator("LoadControl", 1.0)
    o.algorithm("Linear")
    o.analysis("Static")
    o.analyze(1)
    return o.nodeDisp(2, 2)


# -- 1. load -pattern / -const ---------------------------------------------------------------------
@pytest.mark.parametrize("option", [("-pattern", 1), ("-const",)])
def test_load_refuses_the_options_openseespy_refuses_and_adds_nothing(option, one_line):
    """OpenSeesPy fails (``invalid load vector``) and adds no load: the tip stays at 0 under the
    pattern's other load of 0; vtsi refuses naming the word and what OpenSees reads, and the
    tip's deflection under a load given after equals OpenSeesPy's."""
    cantilever(oracle)
    with pytest.raises(oracle.OpenSeesError):
        oracle.load(2, 0.0, -1000.0, 0.0, *option)
    oracle.load(2, 0.0, -10.0, 0.0)
    reference = static_tip_deflection(oracle)
    cantilever(vops)
    with pytest.raises(CommandError) as exc:
        vops.load(2, 0.0, -1000.0, 0.0, *option)
    assert one_line(exc) == (f"load on node 2: a load value must be a number, got '{option[0]}'; OpenSees reads every "
                             f"argument after the node tag as a load value, so it takes no {option[0]} option: a load "
                             "goes to the last pattern defined (pattern('Plain', tag, tsTag))")
    assert vops.session.domain.patterns[1].nodal == {}
    vops.load(2, 0.0, -10.0, 0.0)
    value = static_tip_deflection(vops)
    assert reference == pytest.approx(-10.0 * 2.0 ** 3 / (3 * 2e11 * 1e-4), rel=1e-12)     # P L³ / 3EI
    assert value == pytest.approx(reference, rel=1e-12)


def test_tcl_load_refuses_pattern_too(tcl, one_line):
    """OpenSees's Tcl ``load`` reads every word after the node tag as a force (``ndf = argc - 2``
    in TclModelBuilder.cpp of 3.7.1), so it fails on ``-pattern`` as OpenSeesPy does: vtsi's Tcl
    layer refuses it with the Python layer's message (in Tcl's words), inside a pattern's braces
    too, and the load is not added."""
    tcl.eval("model basic -ndm 2 -ndf 3; node 1 0 0; node 2 2 0; fix 1 1 1 1; timeSeries Linear 1")
    with pytest.raises(CommandError) as exc:
        tcl.eval("pattern Plain 1 1 { load 2 0 -1000 0 -pattern 1 }")
    assert one_line(exc) == ("load on node 2: a load value must be a number, got '-pattern'; OpenSees reads every "
                             "argument after the node tag as a load value, so it takes no -pattern option: a load goes "
                             'to the last pattern defined ("pattern Plain tag tsTag")')
    assert vops.session.domain.patterns[1].nodal == {}


def test_a_value_that_is_not_finite_is_named_as_before(one_line):
    """The values are read in one pass (Args.floats): a NaN is named as Args.float names it."""
    cantilever(vops)
    with pytest.raises(CommandError) as exc:
        vops.load(2, 0.0, float("nan"), 0.0)
    assert one_line(exc) == "load: load on node 2 must be finite, got nan"


# -- 2. printModel of an inline series -------------------------------------------------------------
SERIES = [   # (OpenSees's timeSeries arguments after the tag, the inline form)
    ("Constant", ("-factor", 2.5), "Constant -factor 2.5"),
    ("Linear", ("-factor", 2.0), "Linear -factor 2"),
    ("Trig", (0.0, 1.0, 0.5, "-factor", 2.0, "-shift", 0.1, "-zeroShift", 0.5),
     "Trig 0 1 0.5 -factor 2 -shift 0.1 -zeroShift 0.5"),
    ("Triangle", (0.0, 1.0, 0.5, "-factor", 2.0, "-shift", 0.1, "-zeroShift", 0.5),
     "Triangle 0 1 0.5 -factor 2 -shift 0.1 -zeroShift 0.5"),
    ("Rectangular", (0.25, 1.5, "-factor", 2.0), "Rectangular 0.25 1.5 -factor 2"),
    ("Pulse", (0.0, 1.0, 0.5, "-width", 0.3, "-factor", 2.0, "-shift", 0.1, "-zeroShift", 0.5),
     "Pulse 0 1 0.5 -width 0.3 -factor 2 -shift 0.1 -zeroShift 0.5"),
    ("Path", ("-dt", 0.1, "-values", 0.0, 1.0, 0.0, "-factor", 3.0), "Path -dt 0.1 -values {0 1 0} -factor 3"),
    ("Path", ("-time", 0.0, 0.1, 0.2, "-values", 0.0, 1.0, 0.0, "-factor", 3.0),
     "Path -time {0 0.1 0.2} -values {0 1 0} -factor 3"),
]


def opensees_series_text(path):
    """What OpenSees's printModel wrote of pattern 1's series: between its scale factor line and
    ``  Nodal Loads:`` (LoadPattern::Print), its last newline left out."""
    text = path.read_text()
    return re.search(r"Load Pattern: 1\n  Scale Factor: [^\n]*\n(.*?)  Nodal Loads:", text, re.S).group(1).rstrip("\n")


def vtsi_pattern_lines(path, tag):
    """vtsi's printModel lines of pattern ``tag``: its line, and the lines under it (indented by 4)."""
    lines = path.read_text().splitlines()
    first = next(k for k, line in enumerate(lines) if line.startswith(f"  pattern {tag}: "))
    under = []
    for line in lines[first + 1:]:
        if not line.startswith("    "):
            break
        under.append(line[4:])
    return lines[first], "\n".join(under)


@pytest.mark.parametrize("kind, args, inline", SERIES, ids=[f"{s[0]}{'-time' * ('-time' in s[1])}" for s in SERIES])
def test_print_model_names_an_inline_series_and_prints_it_as_opensees(tmp_path, kind, args, inline):
    """OpenSeesPy takes no inline series (its ``pattern`` reads an integer tag: OPS_LoadPattern),
    and OpenSees prints no tag of a series in any case: the series of a tagged OpenSeesPy pattern
    prints as the inline one does in vtsi, where the pattern's line names it ``(inline)``."""
    for o in (oracle, vops):
        o.wipe()
        o.model("basic", "-ndm", 2, "-ndf", 3)
        o.node(1, 0.0, 0.0)
        o.node(2, 1.0, 0.0)
    oracle.timeSeries(kind, 1, *args)
    oracle.pattern("Plain", 1, 1)
    oracle.load(2, 0.0, -10.0, 0.0)
    oracle.printModel("-file", str(tmp_path / "ops.txt"))
    vops.pattern("Plain", 1, inline)
    vops.load(2, 0.0, -10.0, 0.0)
    vops.timeSeries(kind, 7, *args)
    vops.pattern("Plain", 2, 7)
    vops.printModel("-file", str(tmp_path / "vtsi.txt"))
    reference = opensees_series_text(tmp_path / "ops.txt")
    line, under = vtsi_pattern_lines(tmp_path / "vtsi.txt", 1)
    assert line == f"  pattern 1: series {kind} (inline), factor 1, node 2: 0 -10 0"
    assert under == reference
    tagged = vtsi_pattern_lines(tmp_path / "vtsi.txt", 2)
    assert tagged == (f"  pattern 2: series {kind} 7, factor 1, no loads", reference)


def test_print_model_in_tcl_prints_the_inline_series_as_python(tmp_path, tcl):
    """Tcl's ``pattern Plain 1 {Linear -factor 2} {...}`` prints the text of the Python inline form."""
    tcl.eval(f"""model basic -ndm 2 -ndf 3; node 1 0 0; node 2 1 0
pattern Plain 1 {{Linear -factor 2}} {{ load 2 0 -10 0 }}
printModel -file {tmp_path / 'tcl.txt'}""")
    vops.wipe()
    vops.model("basic", "-ndm", 2, "-ndf", 3)
    vops.node(1, 0.0, 0.0)
    vops.node(2, 1.0, 0.0)
    vops.pattern("Plain", 1, "Linear -factor 2")
    vops.load(2, 0.0, -10.0, 0.0)
    vops.printModel("-file", str(tmp_path / "python.txt"))
    assert (tmp_path / "tcl.txt").read_text() == (tmp_path / "python.txt").read_text()
    assert vtsi_pattern_lines(tmp_path / "tcl.txt", 1) == (
        "  pattern 1: series Linear (inline), factor 1, node 2: 0 -10 0", "Linear Series: constant factor: 2")


def test_an_inline_series_has_no_tag_in_its_messages(one_line):
    """A load factor that overflows names the inline series by its type, not by a made-up tag."""
    cantilever(vops)
    vops.pattern("Plain", 2, "Constant -factor 1e300", "-fact", 1e300)
    with pytest.raises(vops.ModelError) as exc, np.errstate(over="ignore"):
        vops.session.domain.patterns[2].factors(np.array([0.5]))
    assert one_line(exc) == "pattern 2: its Constant series (inline) gives load factor inf at t = 0.5 s"
    assert vops.session.domain.patterns[2].series.tag is None


# -- 3. recorder Element of an element without the response ---------------------------------------
def recorded(o, folder, recorders):
    """A beam element (1) and a truss (2) in line, node 3 on a roller, a Linear load along x at
    node 3; ``recorders`` (argument tuples of ``recorder``, ``{f}`` in a word: ``folder``) over
    two static steps of 0.5 then two Newmark steps of 0.1 s; the files closed by ``wipe``."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x in ((1, 0.0), (2, 1.0), (3, 2.0)):
        o.node(tag, x, 0.0)
    o.fix(1, 1, 1, 1)
    o.fix(3, 0, 1, 1)
    o.mass(2, 1.0, 1.0, 0.0)
    o.mass(3, 1.0, 0.0, 0.0)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 1.0, 100.0, 1.0, 1)
    o.uniaxialMaterial("Elastic", 1, 100.0)
    o.element("truss", 2, 2, 3, 1.0, 1)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.load(3, 1.0, 0.0, 0.0)
    for args in recorders:
        o.recorder(*[a.format(f=folder) if isinstance(a, str) else a for a in args])
    o.system("BandGeneral")
    o.numberer("Plain")
    o.constraints("Plain")
    o.algorithm("Linear")
    o.integrator("LoadControl", 0.5)
    o.analysis("Static")
    o.analyze(2)
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")
    o.analyze(2, 0.1)
    o.wipe()


LACKING = [   # recorder arguments: elements of which none has the response
    ("Element", "-file", "{f}/a.out", "-time", "-ele", 1, "axialForce"),
    ("Element", "-file", "{f}/b.out", "-ele", 1, "axialForce"),
    ("Element", "-file", "{f}/c.out", "-time", "-ele", 1, "stresses"),
    ("Element", "-file", "{f}/d.out", "-time", "-dT", 0.6, "-ele", 1, "axialForce"),
    ("Element", "-file", "{f}/e.out", "-time", "-closeOnWrite", "-ele", 1, "stresses"),
    ("EnvelopeElement", "-file", "{f}/f.out", "-time", "-ele", 1, "axialForce"),
    ("EnvelopeElement", "-file", "{f}/g.out", "-ele", 1, "axialForce"),
]


def test_a_recorder_of_an_element_without_the_response_writes_opensees_file(tmp_path, caplog):
    """OpenSeesPy records no columns: the times only with ``-time`` (every step, or every ``-dT``),
    nothing without, nothing in an envelope; vtsi's files are the same bytes, and a warning
    names the element, the response and the file. With the element that has it (the truss's
    ``axialForce``) the record is the truss's, as before."""
    (tmp_path / "ops").mkdir()
    (tmp_path / "vtsi").mkdir()
    both = LACKING + [("Element", "-file", "{f}/h.out", "-time", "-ele", 1, 2, "axialForce")]
    recorded(oracle, tmp_path / "ops", both)
    with caplog.at_level(logging.WARNING, logger="vtsi.commands.recorder_commands"):
        recorded(vops, tmp_path / "vtsi", both)
    for name in "abcdefgh":
        assert (tmp_path / "vtsi" / f"{name}.out").read_bytes() == (tmp_path / "ops" / f"{name}.out").read_bytes(), name
    assert (tmp_path / "ops" / "a.out").read_text().split() == ["0.5", "1", "1.1", "1.2"]   # the times
    assert [(tmp_path / "ops" / f"{n}.out").stat().st_size for n in "bfg"] == [0, 0, 0]
    assert len(np.loadtxt(tmp_path / "ops" / "h.out")) == 4
    warnings = [r.getMessage() for r in caplog.records]
    assert (f"recorder Element axialForce: element 1 (elasticBeamColumn) has no response 'axialForce' and gets no "
            f"columns, as in OpenSees: {tmp_path / 'vtsi' / 'a.out'} holds no values (element 1 answers force, "
            "globalForce, localForce") in warnings[0]
    assert len(warnings) == len(both) and all("\n" not in w for w in warnings)
    assert f"{tmp_path / 'vtsi' / 'c.out'} holds no values" in warnings[2] and "'stresses'" in warnings[2]
    assert warnings[-1] == ("recorder Element axialForce: element 1 (elasticBeamColumn) has no response "
                            "'axialForce' and gets no columns, as in OpenSees; the record holds those of element 2")


def test_an_hdf5_recorder_of_no_columns_keeps_the_times(tmp_path):
    """An HDF5 record of no columns holds the step times (the static pseudo-times, then the
    transient ones), values of shape (steps, 0), and an envelope of no columns."""
    h5py = pytest.importorskip("h5py")
    recorded(vops, tmp_path, [("Element", "-h5", "{f}/x.h5", "-ele", 1, "axialForce"),
                              ("EnvelopeElement", "-h5", "{f}/y.h5", "-ele", 1, "axialForce")])
    with h5py.File(tmp_path / "x.h5") as f:
        np.testing.assert_allclose(f["time"][:], [0.5, 1.0, 1.1, 1.2])
        assert f["values"].shape == (4, 0) and f["columns/element"].shape == (0,)
    with h5py.File(tmp_path / "y.h5") as f:
        assert f["envelope/max"].shape == (0,) and f["envelope"].attrs["n_records"] == 4


def test_a_memory_recorder_of_no_columns():
    """In memory: the times, values (steps, 0), an envelope of no columns over every step."""
    cantilever(vops)
    vops.load(2, 0.0, -10.0, 0.0)
    history = vops.session.recorders[vops.recorder("Element", "-ele", 1, "axialForce")]
    envelope = vops.session.recorders[vops.recorder("EnvelopeElement", "-ele", 1, "axialForce")]
    static_tip_deflection(vops)
    vops.analyze(2)
    np.testing.assert_array_equal(history.time, [1.0, 2.0, 3.0])
    assert history.values.shape == (3, 0)
    assert envelope.envelope.min.shape == (0,) and envelope.envelope.n_records == 3


def test_tcl_recorder_of_an_element_without_the_response(tmp_path, tcl):
    """The Tcl command writes the Python command's file: the times (OpenSeesPy's, test above)."""
    tcl.eval(f"""model basic -ndm 2 -ndf 3; node 1 0 0; node 2 2 0; fix 1 1 1 1; geomTransf Linear 1
element elasticBeamColumn 1 1 2 0.01 2e11 1e-4 1
timeSeries Linear 1; pattern Plain 1 1 {{ load 2 0 -10 0 }}
recorder Element -file {tmp_path / 't.out'} -time -ele 1 axialForce
integrator LoadControl 0.5; analysis Static; analyze 3; wipe""")
    assert (tmp_path / "t.out").read_text() == "0.5\n1\n1.5\n"


# -- 4. a moving load the OpenSees way ------------------------------------------------------------
def test_nodal_load_vectors_straight_into_the_free_dofs_equal_the_full_vector_path():
    """A pattern of nodal loads, in a model without constraints, goes straight into the free dofs;
    the general path (the full vector, reduced) gives the same numbers to the bit, a -0.0 load
    as a 0.0, and the rows of the patterns it takes (element loads, sp) keep their places."""
    cantilever(vops)
    vops.node(3, 4.0, 0.0)
    vops.element("elasticBeamColumn", 2, 2, 3, 0.01, 2e11, 1e-4, 1)
    vops.load(2, 0.1, -0.0, 1.0 / 3.0)
    vops.load(3, -7.25, 1e-300, 2.0 ** 0.5)
    vops.pattern("Plain", 2, 1)
    vops.eleLoad("-ele", 2, "-type", "-beamUniform", -3.0)
    vops.pattern("Plain", 3, 1)
    vops.load(3, 1.5, -2.5, 0.5)
    vops.pattern("Plain", 4, 1)
    vops.sp(3, 1, 0.001)
    model = vops.session.domain
    asm = model.build()
    patterns = list(model.patterns.values())
    direct = asm.load_vectors(patterns)
    general = asm.reduce(asm.full_load_vectors(patterns).T).T
    for p, pattern in enumerate(patterns):
        if pattern.prescribed:              # −K g of the sp, on its own
            g = np.zeros(asm.n_full)
            g[asm.full_dof(3, 1)] = 0.001
            general[p] -= asm.reduce(asm.K_full @ g)
    assert direct.tobytes() == general.tobytes()
    zero = direct[0, asm.free_of_full[asm.full_dof(2, 2)]]        # the -0.0 load
    assert zero == 0.0 and not np.signbit(zero) and direct[1].any() and direct[3].any()


def swap_loop(o, n_el, steps, dead_load):
    """The S9 pattern swap on a 20 m beam of ``n_el`` elements: at every step a new Plain pattern of
    a Constant series with 100 kN at the node the force has reached, after removing the last one,
    and ``analyze(1, 1 ms)``; with ``dead_load`` also a pattern of constant loads all along. Returns
    the midspan deflection at every step."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(n_el + 1):
        o.node(i + 1, 20.0 * i / n_el, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(n_el + 1, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for e in range(n_el):
        o.element("elasticBeamColumn", e + 1, e + 1, e + 2, 1.0, 3e10, 3.0, 1, "-mass", 2e4, "-cMass")
    o.timeSeries("Constant", 1)
    if dead_load:
        o.pattern("Plain", 1, 1)
        for i in range(2, n_el + 1):
            o.load(i, 0.0, -1e4, 0.0)
    o.constraints("Plain")
    o.numberer("RCM")
    o.system("BandSPD")
    o.test("NormDispIncr", 1e-8, 10)
    o.algorithm("Linear", "-factorOnce")
    o.integrator("Newmark", 0.5, 0.25)
    o.analysis("Transient")
    o.pattern("Plain", 1000, 1)
    o.load(2, 0.0, -1e5, 0.0)
    o.analyze(1, 1e-3)
    w = []
    for k in range(steps):
        o.remove("loadPattern", 1000 + k)
        o.pattern("Plain", 1001 + k, 1)
        o.load(2 + (k * (n_el - 1)) // steps, 0.0, -1e5, 0.0)
        o.analyze(1, 1e-3)
        w.append(o.nodeDisp(n_el // 2 + 1, 2))
    return np.array(w)


def test_a_new_pattern_at_every_step_copies_that_one_only_and_equals_opensees(monkeypatch):
    """The loads kept as last applied (getLoadFactor, reactions, element forces read them) copy a
    pattern when it is new or changed: one copy per step of the swap loop, the dead-load pattern
    copied once; the midspan history equals OpenSeesPy's (to its round-off: 1e-11 measured 3e-13)."""
    reference = swap_loop(oracle, 10, 40, True)
    copies = []
    original = LoadPattern.snapshot
    monkeypatch.setattr(LoadPattern, "snapshot", lambda self: copies.append(self.tag) or original(self))
    value = swap_loop(vops, 10, 40, True)
    assert copies == [1, 1000] + list(range(1001, 1041))
    assert np.abs(reference).max() > 1e-4
    assert np.abs(value - reference).max() <= 1e-11 * np.abs(reference).max()
    assert vops.getLoadFactor(1) == 1.0 and vops.getLoadFactor(1040) == 1.0
