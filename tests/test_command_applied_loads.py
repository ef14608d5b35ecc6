"""What the domain last applied, as OpenSees keeps it, checked against OpenSeesPy 3.7.1 (the
oracle) and closed forms: ``loadConst`` freezes a pattern never applied at 0 (with a warning);
a load added to or removed from a pattern after a step counts in ``nodeResponse`` id 7,
``eleForce`` and ``getLoadFactor`` only from the next application (an analysis step,
``reactions``), a nodal mass under a ground acceleration likewise; ``analyze(0)`` applies
nothing; after a coupled HHT or GeneralizedAlpha step the load time is ``t_n + αΔt``, as after
the transient one (OpenSees's ``HHT::newStep``); a time series names itself in its messages by
the label it is given."""
import subprocess
import sys

import numpy as np
import pytest

oracle = pytest.importorskip("openseespy.opensees")
import vtsi.opensees as vops  # noqa: E402
from vtsi.errors import ModelError  # noqa: E402
from vtsi.timeseries import Constant, Linear, Path, Pulse, Rectangular, Triangle, Trig  # noqa: E402

pytestmark = pytest.mark.usefixtures("fresh_session")
RTOL, ATOL = 1e-9, 1e-9      # forces up to 1e4 N, displacements 1e-2 m: both compared to 1e-9
DT = 0.01


def beam(o, n_el=4, length=8.0):
    """A simply supported beam of ``n_el`` elasticBeamColumn elements with nodal masses at the
    inner nodes (OpenSees commands on module or session ``o``)."""
    o.wipe()
    o.model("basic", "-ndm", 2, "-ndf", 3)
    for i in range(n_el + 1):
        o.node(i + 1, length * i / n_el, 0.0)
        if 0 < i < n_el:
            o.mass(i + 1, 1000.0, 1000.0, 0.0)
    o.fix(1, 1, 1, 0)
    o.fix(n_el + 1, 0, 1, 0)
    o.geomTransf("Linear", 1)
    for i in range(n_el):
        o.element("elasticBeamColumn", i + 1, i + 1, i + 2, 0.01, 2e11, 1e-5, 1)


def solver(o, integrator):
    o.constraints("Plain")
    o.numberer("Plain")
    o.system("BandGeneral")
    o.test("NormDispIncr", 1e-12, 10)
    o.algorithm("Linear")
    o.integrator(*integrator)
    o.analysis("Static" if integrator[0] == "LoadControl" else "Transient")


def step_args(integrator):
    return () if integrator[0] == "LoadControl" else (DT,)


# -- 1. loadConst on a pattern never applied ------------------------------------------------------
def frozen_before_applied(o, integrator, second=True):
    """Pattern 1 (Constant 2) applied by a step; pattern 2 (Constant 1, ``second``) defined after
    it; ``loadConst -time 0``; a step. Then pattern 3 defined before any step of a fresh model,
    ``loadConst``, a step. getLoadFactor, the displacement and the applied loads."""
    beam(o)
    o.timeSeries("Constant", 1, "-factor", 2.0)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e3, 0.0)
    solver(o, integrator)
    o.analyze(1, *step_args(integrator))
    if second:
        o.timeSeries("Constant", 2)
        o.pattern("Plain", 2, 2)
        o.load(2, 0.0, -5e2, 0.0)
    o.loadConst("-time", 0.0)
    o.analyze(1, *step_args(integrator))
    out = [o.getLoadFactor(1), o.nodeDisp(3, 2), o.nodeResponse(3, 2, 7), o.nodeResponse(2, 2, 7)]
    if second:
        out += [o.getLoadFactor(2)]
        o.reactions()
        out += [o.getLoadFactor(2), o.nodeResponse(2, 2, 7)]
    beam(o)
    o.timeSeries("Constant", 3)
    o.pattern("Plain", 3, 3)
    o.load(3, 0.0, -1e3, 0.0)
    o.loadConst("-time", 0.0)
    solver(o, integrator)
    o.analyze(1, *step_args(integrator))
    return out + [o.getLoadFactor(3), o.nodeDisp(3, 2), o.nodeResponse(3, 2, 7)]


@pytest.mark.parametrize("integrator", [("LoadControl", 1.0), ("Newmark", 0.5, 0.25)])
def test_load_const_freezes_a_pattern_never_applied_at_zero(integrator, caplog):
    """OpenSees's LoadPattern::setLoadConstant keeps loadFactor, which only applyLoad sets (0
    from the constructor): a pattern defined after the last step, or before any, frozen by
    loadConst never loads (its factor 0, also after reactions); vtsi froze it at its factor."""
    reference = frozen_before_applied(oracle, integrator)
    with caplog.at_level("WARNING", logger="vtsi.commands.query_commands"):
        value = frozen_before_applied(vops, integrator)
    assert [r.getMessage() for r in caplog.records] == [
        f"loadConst: pattern {tag} frozen at load factor 0: no analysis step applied it since it was defined, so its "
        "loads never act (as in OpenSees)" for tag in (2, 3)]
    np.testing.assert_allclose(value, reference, rtol=RTOL, atol=ATOL)
    assert reference[3:7] == [0.0] * 4 and reference[7:] == [0.0] * 3
    # pattern 2 loads nothing: the same displacement as without it (vtsi, independently)
    assert value[1] == pytest.approx(frozen_before_applied(vops, integrator, second=False)[1], rel=1e-12)


def test_load_const_warns_once_on_stderr_naming_the_patterns():
    """The warning is one line on stderr with Python's default logging (no handler configured),
    both patterns in it; the pattern a step applied is not named, and nothing else is written."""
    script = """
import vtsi.opensees as o
o.model('basic', '-ndm', 2, '-ndf', 3)
o.node(1, 0.0, 0.0); o.node(2, 5.0, 0.0); o.fix(1, 1, 1, 1); o.mass(2, 10.0, 10.0, 0.0)
o.geomTransf('Linear', 1); o.element('elasticBeamColumn', 1, 1, 2, 0.5, 3e10, 0.05, 1)
o.timeSeries('Constant', 1); o.pattern('Plain', 1, 1); o.load(2, 0.0, -100.0, 0.0)
o.analysis('Static'); o.analyze(1)
for tag in (2, 3):
    o.pattern('Plain', tag, 1); o.load(2, 0.0, -100.0, 0.0)
o.loadConst('-time', 0.0)
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout == ""
    assert done.stderr == ("loadConst: patterns 2, 3 frozen at load factor 0: no analysis step applied them since "
                           "they were defined, so their loads never act (as in OpenSees)\n")


# -- 2. loads changed after a step count from the next application --------------------------------
def loads_between_steps(o, integrator):
    """A Linear pattern applied by two steps; a nodal load and a uniform element load added to
    it; a step; a new Constant pattern with a point element load and a nodal load; a step; the
    first pattern removed; reactions; a step. After each: getLoadFactor, nodeResponse 7 at nodes
    3 and 2, eleForce of elements 2 and 3."""
    def read(first=True):
        factor = [o.getLoadFactor(1)] if first else []
        return factor + [o.nodeResponse(3, 2, 7), o.nodeResponse(2, 2, 7), *o.eleForce(2), o.eleForce(3, 2)]

    beam(o)
    o.timeSeries("Linear", 1, "-factor", 10.0)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e3, 0.0)
    solver(o, integrator)
    o.analyze(2, DT)
    rows = [read()]
    o.load(2, 0.0, -5e2, 0.0)
    o.eleLoad("-ele", 2, "-type", "-beamUniform", -1e3)
    rows.append(read())
    o.analyze(1, DT)
    rows.append(read())
    o.timeSeries("Constant", 2)
    o.pattern("Plain", 2, 2)
    o.eleLoad("-ele", 3, "-type", "-beamPoint", -2e3, 0.25)
    o.load(3, 0.0, -7e2, 0.0)
    rows.append(read() + [o.getLoadFactor(2)])
    o.analyze(1, DT)
    rows.append(read() + [o.getLoadFactor(2)])
    o.remove("loadPattern", 1)
    rows.append(read(first=False))
    o.reactions()
    rows.append(read(first=False))
    o.analyze(1, DT)
    rows.append(read(first=False))
    return rows


@pytest.mark.parametrize("integrator", [("Newmark", 0.5, 0.25), ("HHT", 0.8)])
def test_loads_changed_after_a_step_count_from_the_next_application(integrator):
    """OpenSees's nodes and elements hold the loads of the last Domain::applyLoad (each analysis
    step, reactions): a load added to an applied pattern, a new pattern's loads and a removed
    pattern's loads change nodeResponse 7 and eleForce only from then on. vtsi counted an added
    load and a removal at once."""
    reference, value = loads_between_steps(oracle, integrator), loads_between_steps(vops, integrator)
    assert [len(r) for r in value] == [len(r) for r in reference]
    for ref, val in zip(reference, value):
        np.testing.assert_allclose(val, ref, rtol=RTOL, atol=ATOL)
    assert reference[1] == reference[0]                  # added to the pattern: not counted yet
    assert reference[3][:-1] == reference[2] and reference[3][-1] == 0.0      # a new pattern: likewise
    assert reference[5] == reference[4][1:-1]            # the pattern removed: still counted
    assert reference[6][0] == -7e2 and reference[6][1] == 0.0          # reactions applied the loads again


def ground_mass_changed(o):
    """A UniformExcitation (Linear ground acceleration, factor 10) applied by two steps, the nodal
    mass of node 3 tripled, a step: getLoadFactor and nodeResponse 7 (−m a_g) at nodes 3 and 2."""
    beam(o)
    o.timeSeries("Linear", 1, "-factor", 10.0)
    o.pattern("UniformExcitation", 1, 2, "-accel", 1)
    solver(o, ("Newmark", 0.5, 0.25))
    o.analyze(2, DT)
    out = [o.getLoadFactor(1), o.nodeResponse(3, 2, 7), o.nodeResponse(2, 2, 7)]
    o.mass(3, 3000.0, 3000.0, 0.0)
    out += [o.getLoadFactor(1), o.nodeResponse(3, 2, 7), o.nodeResponse(2, 2, 7)]
    o.analyze(1, DT)
    return out + [o.getLoadFactor(1), o.nodeResponse(3, 2, 7), o.nodeResponse(2, 2, 7), o.nodeDisp(3, 2)]


def test_a_nodal_mass_changed_after_a_step_loads_from_the_next():
    """−m a_g of a node is its mass at the last application (Node::addInertiaLoadToUnbalance):
    a_g = 10 t, so −1000 × 0.2 before and after the mass changes, −3000 × 0.3 after a step."""
    reference, value = ground_mass_changed(oracle), ground_mass_changed(vops)
    np.testing.assert_allclose(value, reference, rtol=RTOL, atol=ATOL)
    np.testing.assert_allclose(value[:8], [0.2, -1000 * 0.2, -1000 * 0.2] * 2 + [0.3, -3000 * 0.3], rtol=1e-12)


def zero_steps(o, integrator):
    beam(o)
    o.timeSeries("Linear", 1, "-factor", 10.0)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e3, 0.0)
    solver(o, integrator)
    o.analyze(2, *step_args(integrator))
    o.timeSeries("Constant", 2)
    o.pattern("Plain", 2, 2)
    o.load(3, 0.0, -7e2, 0.0)
    o.analyze(0, *step_args(integrator))
    return [o.getLoadFactor(1), o.getLoadFactor(2), o.nodeResponse(3, 2, 7)]


@pytest.mark.parametrize("integrator", [("LoadControl", 0.1), ("Newmark", 0.5, 0.25), ("TRBDF2",)])
def test_analyze_zero_steps_applies_nothing(integrator):
    """analyze(0) takes no step, so OpenSees applies no loads: the pattern defined before it reads
    0 (vtsi's static and TRBDF2 analyses took it as applied)."""
    reference, value = zero_steps(oracle, integrator), zero_steps(vops, integrator)
    np.testing.assert_allclose(value, reference, rtol=RTOL, atol=ATOL)
    assert reference[1] == 0.0


# -- 3. the load time after a coupled HHT step ------------------------------------------------------
def hht_factor(o, integrator, steps):
    """getLoadFactor of a Linear pattern (factor 3) after ``steps`` steps of DT from t = 0."""
    beam(o)
    o.timeSeries("Linear", 1, "-factor", 3.0)
    o.pattern("Plain", 1, 1)
    o.load(3, 0.0, -1e3, 0.0)
    solver(o, integrator)
    o.analyze(steps, DT)
    return o.getLoadFactor(1)


@pytest.mark.parametrize("integrator, alpha", [(("HHT", 0.8), 0.8), (("GeneralizedAlpha", 1.0, 0.8), 0.8)])
def test_transient_alpha_schemes_apply_the_loads_at_the_alpha_point(integrator, alpha):
    """OpenSees's HHT::newStep applies the loads at t_n + αΔt and commit only moves the time
    (GeneralizedAlpha: αF): getLoadFactor after 5 steps is 3 (4 + α) Δt, in OpenSeesPy and vtsi."""
    reference, value = hht_factor(oracle, integrator, 5), hht_factor(vops, integrator, 5)
    assert reference == pytest.approx(3.0 * (4 + alpha) * DT, rel=1e-12)
    assert value == pytest.approx(reference, rel=1e-12)


def coupled_bridge(mass_beam, session, integrator, n_el=10, length=20.0):
    """A 20 m simply supported deck of 10 elements (15 t/m; conftest's ``mass_beam``) under a moving force of 100 kN at
    20 m/s, ``integrator``, and a Linear pattern 7 (factor 3) with a load at midspan."""
    mass_beam(session, n_el, length)
    session.timeSeries("Linear", 7, "-factor", 3.0)
    session.pattern("Plain", 7, 7)
    session.load(n_el // 2 + 1, 0.0, -1e3, 0.0)
    session.track(1, "-eleRange", 1, n_el)
    session.car(1, "movingForce", 1e5)
    session.train(1, 20.0, "-cars", 1, 0.0)
    session.movingLoadConstraint(1, 1, 1, 0.0)
    session.integrator(*integrator)
    session.analysis("Transient")


@pytest.mark.parametrize("integrator, alpha", [(("HHT", 0.8), 0.8), (("GeneralizedAlpha", 1.0, 0.8), 0.8),
                                               (("Newmark", 0.5, 0.25), 1.0), (("Bathe",), 1.0)])
def test_a_coupled_step_applies_the_loads_where_the_transient_one_does(integrator, alpha, mass_beam):
    """The coupled analysis (no OpenSees counterpart) applies its patterns at its stage load
    points, HHT and GeneralizedAlpha t_n + αΔt, and getLoadFactor reads them there, as after the
    transient step (above): 3 (4 + α) Δt after 5 steps, 3 (5 + α) Δt after one more (its start
    the time before the run), 3 (7 + α) Δt after 2 more; vtsi read the step's end (3 × 5 Δt)."""
    session = vops.Session()
    coupled_bridge(mass_beam, session, integrator)
    session.analyze(5, DT)
    assert session.getLoadFactor(7) == pytest.approx(3.0 * (4 + alpha) * DT, rel=1e-12)
    session.analyze(1, DT)
    assert session.getLoadFactor(7) == pytest.approx(3.0 * (5 + alpha) * DT, rel=1e-12)
    session.analyze(2, DT)
    assert session.getLoadFactor(7) == pytest.approx(3.0 * (7 + alpha) * DT, rel=1e-12)
    assert session.getTime() == pytest.approx(8 * DT, rel=1e-12)


# -- 4. a time series' label -------------------------------------------------------------------------
@pytest.mark.parametrize("cls, args, message", [
    (Constant, (float("nan"),), "factor must be finite, got nan"),
    (Linear, ("x",), "factor must be a number, got 'x'"),
    (Trig, (0.0, 1.0, 0.0), "period must be > 0, got 0.0"),
    (Triangle, (0.0, 1.0, 0.0), "period must be > 0 and factor not 0, got 0.0, 1.0"),
    (Rectangular, (2.5, 1.0), "tEnd = 1 is before tStart = 2.5 (the series would be 0 always)"),
    (Pulse, (0.0, 1.0, 1.0, 1.5), "period must be > 0 and width in (0, 1), got 1.0, 1.5"),
    (Path, ([0.0, 1.0], None, -0.1), "dt must be > 0, got -0.1"),
])
def test_a_series_names_itself_by_its_label(cls, args, message, one_line):
    """Every series' message begins with its label: the one given (the command layer's, e.g. an
    inline series' 'pattern Plain 7: series Trig'), else 'timeSeries <type> <tag>', without a tag
    'timeSeries <type>' (a Trig, Triangle or Pulse without a tag said 'timeSeries Trig None')."""
    kind = cls.__name__
    for kw, label in [({"tag": 4, "label": "pattern Plain 7: series X"}, "pattern Plain 7: series X"),
                      ({"tag": 4}, f"timeSeries {kind} 4"), ({}, f"timeSeries {kind}")]:
        with pytest.raises(ModelError) as exc:
            cls(*args, **kw)
        assert one_line(exc) == f"{label}: {message}"


def test_a_label_is_not_a_parameter_in_the_repr():
    series = Linear(2.0, tag=1, label="timeSeries LinearSeries 1")
    assert series.label == "timeSeries LinearSeries 1" and repr(series) == "Linear(factor=2.0, tag=1)"
    assert Linear(2.0, tag=1).label == "timeSeries Linear 1" and Linear(2.0).label == "timeSeries Linear"
