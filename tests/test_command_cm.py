"""Five findings of the command layer, each checked against OpenSeesPy 3.7.1 run in the test
(the oracle), OpenSees's source where no Tcl OpenSees runs here, or a second run:

1. ``irregularity 1 german low 0 100`` without ``-seed`` drew a new profile at every run
   (``np.random.default_rng(None)``); the seed is now 0, a sweep's default seed too
   (docs/sweeps.md, ``seeds``; docs/cli.md, ``--seeds``).
2. ``deadLoad -dt abc`` said ``-dt needs a value (...), got 0 ('abc' follows)``; it now says that
   ``-dt`` needs a number and names ``'abc'``. ``deadLoad -dt 1e-3 -dt 2e-3`` took the last
   silently; an option given twice is now refused, as ``timeSeries Path`` refuses it.
3. ``eleResponse`` of a response the element has not raised; OpenSeesPy returns ``[]`` (and
   OpenSees's Tcl ``eleResponse`` an empty result, ``SRC/tcl/commands.cpp``: nothing appended
   when ``Domain::getElementResponse`` returns none), so vtsi returns ``[]`` with a warning
   naming the element and what it answers, as its Element recorder does; a response OpenSees
   answers with values that vtsi does not compute is refused.
4. ``recorder Element -ele 1 section 1 force`` on a beam was refused ("vtsi's elements are
   elastic, with no sections"); OpenSeesPy records no columns (the times with ``-time``,
   nothing without), and so does vtsi now, byte for byte, with the warning.
5. An inline series with a tag, Tcl ``pattern Plain 1 "Linear 5 -factor 2" {...}``, was refused
   at the 5; OpenSees's ``TclSeriesCommand`` hands the words to the type's reader
   (``OPS_LinearSeries``, ``OPS_TrigSeries``, ... of SRC/domain/pattern, 3.7.1), which takes a
   tag where the count of words says there is one, and adds the series to no table of series.
   OpenSeesPy's ``timeSeries`` calls the same readers, so it is the oracle of the tag rule.
"""
import logging

import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.commands.args import tcl_words  # noqa: E402
from vtsi.commands.session import Session  # noqa: E402
from vtsi.errors import CommandError  # noqa: E402
from vtsi.tcl import Interpreter, run_file  # noqa: E402

pytestmark = pytest.mark.usefixtures("fresh_session")


# -- 1. a random rail profile without -seed ----------------------------------------------------

def test_an_irregularity_without_seed_is_the_seed_0_profile_in_every_session():
    """Two sessions (a new run each) without ``-seed``, in Python and in Tcl, give the profile of
    ``-seed 0``, to the bit; ``-seed 1`` gives another (the profile is random)."""
    pytest.importorskip("tkinter")
    x = np.linspace(0.0, 100.0, 401)

    def profile(*seed, in_tcl=False):
        session = Session()
        if in_tcl:
            Interpreter(session).eval(" ".join(["irregularity 1 german low 0 100", *map(str, seed)]))
        else:
            session.irregularity(1, "german", "low", 0.0, 100.0, *seed)
        return session._irregularities[1](x)

    seed_0 = profile("-seed", 0)
    for run in (profile(), profile(), profile(in_tcl=True), profile(in_tcl=True)):
        np.testing.assert_array_equal(run, seed_0)
    assert np.abs(profile("-seed", 1) - seed_0).max() > 0.1 * np.abs(seed_0).max()


# -- 2. deadLoad's options ---------------------------------------------------------------------

@pytest.mark.parametrize("words, message", [
    ("deadLoad -dt abc", "deadLoad: -dt needs a number (the run's time step [s]), got 'abc'"),
    ("deadLoad -selfWeight -dt 1e-3x", "deadLoad: -dt needs a number (the run's time step [s]), got '1e-3x'"),
    ("deadLoad -dt 1e-3 -dt 2e-3", "deadLoad: option -dt given twice"),
    ("deadLoad -selfWeight -dt 1e-3 -selfWeight", "deadLoad: option -selfWeight given twice"),
])
def test_dead_load_names_a_word_for_a_number_and_refuses_an_option_twice(words, message, tcl, one_line):
    """In Tcl and in Python (the words as Python arguments, numbers as numbers)."""
    with pytest.raises(CommandError) as exc:
        tcl.eval(words)
    assert one_line(exc) == message
    with pytest.raises(CommandError) as exc:
        vops.deadLoad(*tcl_words(words)[1:])
    assert one_line(exc) == message


def test_an_option_twice_is_refused_as_time_series_path_refuses_it(tcl, one_line):
    """The message of ``deadLoad`` is that of ``timeSeries Path``, and a word among several
    numbers (``node -mass``) is named with its place."""
    tcl.eval("model basic -ndm 2 -ndf 3")
    with pytest.raises(CommandError) as exc:
        tcl.eval("timeSeries Path 1 -dt 0.1 -dt 0.2 -values {0 1}")
    assert one_line(exc) == "timeSeries Path 1: option -dt given twice"
    with pytest.raises(CommandError) as exc:
        tcl.eval("node 9 1 1 -mass 1.0 abc 1.0")
    assert one_line(exc) == "node 9: -mass needs 3 numbers (one per dof); value 2 is 'abc'"


# -- 3. eleResponse of a response the element has not -----------------------------------------

def four_elements(o, recorders=()):
    """A beam, a Timoshenko beam and a two-material zeroLength from node 2, a truss to it, under
    a static load in two LoadControl steps, recording ``recorders`` (argument tuples)."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in ((1, 0.0, 0.0), (2, 5.0, 0.0), (3, 5.0, 0.0), (4, 0.0, 3.0)):
        o.node(tag, x, y)
    for tag in (1, 3, 4):
        o.fix(tag, 1, 1, 1)
    o.geomTransf("Linear", 1)
    o.element("elasticBeamColumn", 1, 1, 2, 1.0, 200e9, 1e-4, 1)
    o.element("ElasticTimoshenkoBeam", 2, 1, 2, 200e9, 80e9, 1.0, 1e-4, 0.8, 1)
    o.uniaxialMaterial("Elastic", 1, 1e6)
    o.element("truss", 3, 4, 2, 1.0, 1)
    o.element("zeroLength", 4, 2, 3, "-mat", 1, 1, "-dir", 1, 2)
    o.timeSeries("Linear", 1)
    o.pattern("Plain", 1, 1)
    o.load(2, 100.0, -1000.0, 0.0)
    for args in recorders:
        o.recorder(*args)
    o.system("BandGeneral")
    o.numberer("Plain")
    o.constraints("Plain")
    o.algorithm("Linear")
    o.integrator("LoadControl", 1.0)
    o.analysis("Static")
    o.analyze(2)


SOURCE_NAMES = (   # the names the four types' setResponse (OpenSees 3.7.1) compares, and three others
    "force", "forces", "globalForce", "globalForces", "globalforces", "localForce", "localForces", "basicForce",
    "basicForces", "axialForce", "axialForces", "basicStiffness", "basicDeformation", "basicDeformations",
    "deformatons", "deformation", "deformations", "defo", "basicDefo", "chordRotation", "chordDeformation",
    "xaxis", "yaxis", "zaxis", "energy", "RayleighForces", "rayleighForces", "dampingForces", "defoANDforce",
    "deformationANDforces", "deformationsANDforces", "materials", "directions", "globalDampingForce",
    "stresses", "stress", "foo")
PARTS = (("section", 1, "force"), ("section", "force"), ("section", 1, "deformation"), ("material", 1, "stress"),
         ("material", "stress"), ("material", 1, "strain"), ("material", 2, "tangent"), ("-material", 1, "stress"),
         ("material",))
VTSI_ONLY = {(4, "globalForce"), (4, "basicDeformations"), (3, "axialForces")}
"""Names vtsi answers and OpenSeesPy returns [] for (docs/commands.md, eleResponse)."""


def ele_response(e, words, caplog):
    """vtsi's ``eleResponse(e, *words)``: its list and the warnings it logged, or its refusal."""
    caplog.clear()
    try:
        with caplog.at_level(logging.WARNING, logger="vtsi.commands.query_commands"):
            values = vops.eleResponse(e, *words)
    except CommandError as exc:
        return "refused", str(exc)
    return values, [r.getMessage() for r in caplog.records]


def test_each_element_response_is_answered_as_opensees_answers_it_or_refused(caplog):
    """Over every name the types' ``setResponse`` compares and responses of their parts, for a
    beam, a Timoshenko beam, a truss and a zeroLength: where OpenSeesPy returns values, vtsi
    returns the same or refuses (never ``[]``: it would hide them), naming the response as one
    it does not compute; where OpenSeesPy returns ``[]``, vtsi returns ``[]`` with one warning
    line naming the element and the names it answers, except the names only vtsi answers, and
    the responses of a truss's or a zeroLength's material, refused whatever follows."""
    four_elements(oracle)
    words = [(name,) for name in SOURCE_NAMES] + list(PARTS)
    expected = {(e, w): oracle.eleResponse(e, *w) for e in (1, 2, 3, 4) for w in words}
    four_elements(vops)
    types = {1: "elasticBeamColumn", 2: "ElasticTimoshenkoBeam", 3: "truss", 4: "zeroLength"}
    counts = {"values": 0, "refused": 0, "empty": 0}
    for (e, w), ref in expected.items():
        asked = " ".join(map(str, w))
        got, said = ele_response(e, w, caplog)
        if got == "refused":
            counts["refused"] += 1
            assert said.startswith(f"eleResponse {e}: response {asked!r} of element {e} ({types[e]}) is not supported: "
                                   "OpenSees answers it with values vtsi does not compute; supported: force, "), said
            assert ref or (w[0] in ("material", "-material") and e in (3, 4)), (e, w, said)
        elif ref and got:
            counts["values"] += 1
            np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max(), err_msg=f"{e} {asked}")
        elif got:
            assert (e, asked) in VTSI_ONLY, (e, w)
        else:
            counts["empty"] += 1
            assert ref == [] and got == [], (e, w, ref)
            assert len(said) == 1 and said[0].startswith(
                f"eleResponse {e} {asked}: element {e} ({types[e]}) has no response {asked!r} and gives [], as in "
                "OpenSees (it answers force, globalForce, "), said
    assert min(counts.values()) >= 10, counts


def test_tcl_ele_response_of_a_section_is_an_empty_result(tcl, caplog):
    """OpenSees's Tcl ``eleResponse`` appends nothing to the result when the element has not the
    response (read in SRC/tcl/commands.cpp); OpenSeesPy returns []."""
    four_elements(oracle)
    assert oracle.eleResponse(1, "section", 1, "force") == []
    four_elements(vops)
    with caplog.at_level(logging.WARNING, logger="vtsi.commands.query_commands"):
        assert tcl.eval("eleResponse 1 section 1 force") == ""
    assert [r.getMessage().split(" (it answers")[0] for r in caplog.records] == [
        "eleResponse 1 section 1 force: element 1 (elasticBeamColumn) has no response 'section 1 force' and gives "
        "[], as in OpenSees"]
    assert tcl.eval("llength [eleResponse 1 localForce]") == "6"


def test_a_name_followed_by_more_words_is_refused(one_line):
    """OpenSees compares the first word only (``force extra`` is ``force``); vtsi names the
    extra words rather than drop them."""
    four_elements(oracle)
    assert oracle.eleResponse(1, "force", "extra") == oracle.eleResponse(1, "force")
    four_elements(vops)
    with pytest.raises(CommandError) as exc:
        vops.eleResponse(1, "force", "extra")
    assert one_line(exc) == ("eleResponse 1: response 'force extra' of element 1 (elasticBeamColumn): force takes no "
                             "more words, got 'extra' (OpenSees ignores them)")


# -- 4. recorder Element of a section ----------------------------------------------------------

SECTION_RECORDERS = [   # (file, recorder arguments after the file)
    ("a.out", ("Element", "-time", "-ele", 1, "section", 1, "force")),
    ("b.out", ("Element", "-ele", 1, "section", 1, "force")),
    ("c.out", ("Element", "-time", "-ele", 1, 2, "section", "force")),
    ("d.out", ("Element", "-time", "-ele", 1, 3, "section", 1, "force")),
    ("e.out", ("EnvelopeElement", "-time", "-ele", 1, "section", 1, "force")),
    ("f.out", ("Element", "-time", "-ele", 1, "material", 1, "stress")),
]


def with_file(path, args):
    return (args[0], "-file", str(path), *args[1:])


def test_a_recorder_of_a_section_writes_opensees_file(tmp_path, caplog):
    """OpenSeesPy writes the times only with ``-time`` (steps 1 and 2), nothing without and
    nothing in an envelope; vtsi writes the same bytes and warns once per recorder."""
    for label, o in (("ops", oracle), ("vtsi", vops)):
        (tmp_path / label).mkdir()
        with caplog.at_level(logging.WARNING, logger="vtsi.commands.recorder_commands"):
            four_elements(o, [with_file(tmp_path / label / name, args) for name, args in SECTION_RECORDERS])
        o.wipe()                    # closes the files
    for name, _args in SECTION_RECORDERS:
        assert (tmp_path / "vtsi" / name).read_bytes() == (tmp_path / "ops" / name).read_bytes(), name
    assert (tmp_path / "ops" / "a.out").read_text() == "1\n2\n"
    assert [(tmp_path / "ops" / name).stat().st_size for name in ("b.out", "e.out")] == [0, 0]
    warnings = [r.getMessage() for r in caplog.records]
    assert len(warnings) == len(SECTION_RECORDERS) and all("\n" not in w for w in warnings)
    assert warnings[0].startswith(
        f"recorder Element section 1 force: element 1 (elasticBeamColumn) has no response 'section 1 force' and gets "
        f"no columns, as in OpenSees: {tmp_path / 'vtsi' / 'a.out'} holds no values (element 1 answers force, ")
    assert warnings[3].startswith("recorder Element section 1 force: elements 1 (elasticBeamColumn), 3 (truss) have no "
                                  "response 'section 1 force' and get no columns")


def test_a_tcl_script_recording_a_section_writes_opensees_file(tmp_path):
    """``vtsi run``'s reader (:func:`vtsi.tcl.run_file`) of a script with the recorder, against
    OpenSeesPy given the same commands."""
    pytest.importorskip("tkinter")
    four_elements(oracle, [with_file(tmp_path / "ops.out", SECTION_RECORDERS[0][1])])
    oracle.wipe()
    script = tmp_path / "model.tcl"
    script.write_text(f"""model basic -ndm 2 -ndf 3
node 1 0 0; node 2 5 0; node 3 5 0; node 4 0 3
fix 1 1 1 1; fix 3 1 1 1; fix 4 1 1 1
geomTransf Linear 1
element elasticBeamColumn 1 1 2 1.0 200e9 1e-4 1
element ElasticTimoshenkoBeam 2 1 2 200e9 80e9 1.0 1e-4 0.8 1
uniaxialMaterial Elastic 1 1e6
element truss 3 4 2 1.0 1
element zeroLength 4 2 3 -mat 1 1 -dir 1 2
pattern Plain 1 Linear {{ load 2 100.0 -1000.0 0.0 }}
recorder Element -file {tmp_path / 'vtsi.out'} -time -ele 1 section 1 force
system BandGeneral; numberer Plain; constraints Plain; algorithm Linear
integrator LoadControl 1.0; analysis Static; analyze 2
wipe
""")
    run_file(script, session=vops.session)
    assert (tmp_path / "vtsi.out").read_bytes() == (tmp_path / "ops.out").read_bytes() == b"1\n2\n"


def test_a_recorder_of_a_truss_material_is_refused_and_creates_no_file(tmp_path, one_line):
    """OpenSeesPy records the truss's material stress (its axial force / A); vtsi does not compute
    it, and says so before it creates the file."""
    four_elements(oracle, [with_file(tmp_path / "ops.out", ("Element", "-time", "-ele", 3, "material", 1, "stress"))])
    oracle.wipe()
    stress = np.loadtxt(tmp_path / "ops.out")
    four_elements(vops)
    axial = vops.eleResponse(3, "axialForce")[0]      # at step 2 (λ = 2); A = 1
    np.testing.assert_allclose(stress[:, 1], [axial / 2.0, axial], rtol=1e-5)     # OpenSees's 6 digits
    with pytest.raises(CommandError) as exc:
        vops.recorder(*with_file(tmp_path / "vtsi.out", ("Element", "-ele", 1, 3, "material", 1, "stress")))
    assert one_line(exc).startswith("recorder Element: response 'material 1 stress' of element 3 (truss) is not "
                                    "supported: OpenSees answers it with values vtsi does not compute; supported: ")
    assert not (tmp_path / "vtsi.out").exists()


# -- 5. an inline series with a tag ------------------------------------------------------------

INLINE = [   # (the words of the inline series, the tag OpenSees reads: 0 when none)
    ("Linear 5 -factor 2", 5), ("Linear 5", 5), ("Linear -factor 2", 0), ("Constant 3 -factor 4", 3),
    ("Trig 0 10 1", 0), ("Trig 7 0 10 1", 7), ("Trig 7 0 10 1 -factor 2 -shift 0.1", 7),
    ("Triangle 6 0 10 2", 6), ("Triangle 0 10 2 -factor 3", 0), ("Rectangular 0 10", 0),
    ("Rectangular 9 0 10 -factor 3", 9), ("Pulse 4 0 10 1 -width 0.2", 4), ("Pulse 0 10 1 -width 0.2", 0),
]


def load_factors(o, pattern):
    """Load factors of Plain pattern 1, made by ``pattern()``, after each of 18 LoadControl
    steps of 0.7 (a truss spring under a unit load)."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 2)
    o.node(1, 0.0, 0.0)
    o.node(2, 1.0, 0.0)
    o.fix(1, 1, 1)
    o.fix(2, 0, 1)
    o.uniaxialMaterial("Elastic", 1, 1.0)
    o.element("truss", 1, 1, 2, 1.0, 1)
    pattern()
    o.system("BandGeneral")
    o.numberer("Plain")
    o.constraints("Plain")
    o.algorithm("Linear")
    o.integrator("LoadControl", 0.7)
    o.analysis("Static")
    out = []
    for _ in range(18):
        o.analyze(1)
        out.append(o.getLoadFactor(1))
    return out


@pytest.mark.parametrize("spec, tag", INLINE, ids=[s for s, _ in INLINE])
def test_an_inline_series_takes_its_tag_as_opensees(spec, tag, tcl, one_line):
    """OpenSeesPy's ``timeSeries`` given the same words makes the series of the tag listed (the
    pattern of that tag finds it); vtsi's Tcl inline series gives the same load factors, to the
    bit, and keeps it in no table of series (``pattern Plain 2 <tag>`` does not find it)."""
    words = tcl_words(spec)

    def oracle_pattern():
        oracle.timeSeries(*words)
        oracle.pattern("Plain", 1, tag)
        oracle.load(2, 1.0, 0.0)

    expected = load_factors(oracle, oracle_pattern)
    got = load_factors(vops, lambda: tcl.eval(f'pattern Plain 1 "{spec}" {{ load 2 1.0 0.0 }}'))
    assert got == expected
    assert len(set(expected)) > 1 or spec.startswith("Constant")
    with pytest.raises(CommandError) as exc:
        tcl.eval(f"pattern Plain 2 {tag} {{}}")
    assert one_line(exc) == f"pattern Plain 2: time series {tag} does not exist"


def test_an_inline_path_takes_a_leading_integer_for_its_tag(tcl):
    """OpenSees 3.7.1's ``TclSeriesCommand`` reads a Path's first word as its tag when
    ``Tcl_GetInt`` reads it (read in the source): the series is that of the words without it."""
    results = []
    for spec in ("Path -dt 0.5 -values {0 1 3 2}", "Path 5 -dt 0.5 -values {0 1 3 2}"):
        results.append(load_factors(vops, lambda: tcl.eval(f'pattern Plain 1 "{spec}" {{ load 2 1.0 0.0 }}')))
    times = 0.7 * np.arange(1, 19)
    np.testing.assert_allclose(results[1], np.interp(times, [0.0, 0.5, 1.0, 1.5], [0.0, 1.0, 3.0, 2.0], right=0.0),
                               rtol=1e-12)
    assert results[0] == results[1]


def test_an_inline_series_tag_that_is_not_an_integer_is_refused(tcl, one_line):
    """OpenSees fails on it (``OPS_GetIntInput``: ``WARNING invalid series tag in LinearSeries``)."""
    tcl.eval("model basic -ndm 2 -ndf 2")
    for spec, message in (("Linear 5.5 -factor 2", "pattern Plain 1: series Linear: tag must be an integer, got 5.5"),
                          ("Trig 1.5 0 10 1", "pattern Plain 1: series Trig: tag must be an integer, got 1.5")):
        with pytest.raises(CommandError) as exc:
            tcl.eval(f'pattern Plain 1 "{spec}" {{}}')
        assert one_line(exc) == message
