"""Model-building commands: ``model``, ``node``, ``fix``, ``mass``, ``geomTransf``,
``uniaxialMaterial``, ``element``, ``timeSeries``, ``pattern``, ``load``, ``rayleigh``, with
OpenSees's argument orders (docs/commands.md)."""
import math
import os

import numpy as np

from vtsi.elements import command_element_types
from vtsi.errors import CommandError, ModelError, is_int
from vtsi.loads import element_load_values
from vtsi.model import Model
from vtsi.timeseries import Constant, Linear, Path, Pulse, Rectangular, Triangle, Trig

from .args import Args, read_numbers, tcl_words
from .base import Placeholder, SessionBase

MODEL_COMMANDS = ("model", "node", "fix", "equalDOF", "rigidLink", "mass", "geomTransf", "uniaxialMaterial", "element", "timeSeries",
                  "pattern", "load", "sp", "eleLoad", "rayleigh")
ELEMENT_TYPES = ("elasticBeamColumn", "ElasticTimoshenkoBeam", "truss", "zeroLength")
ELEMENT_ALIASES = {"Truss": "truss"}       # OpenSees's other names of the same types
MATERIAL_TYPES = ("Elastic", "Viscous")
SERIES_TYPES = ("Constant", "Linear", "Path", "Trig", "Triangle", "Rectangular", "Pulse")
SERIES_ALIASES = {"ConstantSeries": "Constant", "LinearSeries": "Linear", "Series": "Path", "TrigSeries": "Trig",
                  "Sine": "Trig", "SineSeries": "Trig", "TriangleSeries": "Triangle", "PulseSeries": "Pulse"}
SERIES_LEADING_NUMBERS = {"Constant": 0, "Linear": 0, "Rectangular": 2, "Trig": 3, "Triangle": 3, "Pulse": 3}
"""The numbers an inline series of each type takes before its options, each option taking one
value: OpenSees (``OPS_LinearSeries``, ``OPS_TrigSeries``, ...) reads a tag first when the words
after the type are these plus an odd number (``Linear 5 -factor 2``, ``Trig 1 0 10 1``). A Path
takes a first word that is an integer for its tag (``TclSeriesCommand``, OpenSees 3.7.1)."""


def _missing_runs(lo, hi, present, shown=5):
    """The integers of ``lo..hi`` not in ``present`` (sorted, within the range) as text, in runs
    (``'3, 7-9'``; after ``shown`` runs ``', ... (N in all)'``), and how many they are."""
    runs, start = [], lo
    for t in [*present, hi + 1]:
        if t > start:
            runs.append(f"{start}" if t - 1 == start else f"{start}-{t - 1}")
        start = t + 1
    count = hi - lo + 1 - len(present)
    text = ", ".join(runs[:shown]) + (f", ... ({count} in all)" if len(runs) > shown else "")
    return text, count


class ModelCommands(SessionBase):
    """The model: nodes, elements and their materials and transformations, loads and damping."""

    def _pattern_hint(self):
        """The command that defines a load pattern, as a message asks for it in the session's syntax."""
        return self._command_hint(("pattern", "Plain", Placeholder("tag"), Placeholder("tsTag")), verb="")

    def _tags_word(self):
        """The element tags of an ``eleLoad -ele`` hint: ``*tags`` (Python) or ``tags...`` (Tcl)."""
        return Placeholder("tags..." if self.syntax == "tcl" else "*tags")

    def _clear_model(self):
        self.domain = None
        self._materials = {}
        self._transforms = {}
        self._zero_length = {}     # element tag -> [(dir, E, eta) per material]
        self._current_pattern = None

    def model(self, *args):
        """``model('basic', '-ndm', 2, '-ndf', 3)`` (``-ndf`` defaults to 3 for ``-ndm 2``)."""
        a = Args("model", args)
        kind = a.word("builder")
        if kind not in ("basic", "Basic", "BasicBuilder"):
            raise CommandError(f"model: builder {kind!r} is not supported; supported: basic")
        ndm, ndf = None, None
        while a.more():
            opt = a.option(("-ndm", "-ndf"))
            if opt == "-ndm":
                ndm = a.int("-ndm")
            else:
                ndf = a.int("-ndf")
        if ndm is None:
            raise CommandError("model: -ndm is required")
        if ndm != 2:
            raise CommandError(f"model: vtsi is 2-D, -ndm must be 2, got {ndm}")
        ndf = 3 if ndf is None else ndf
        if ndf not in (2, 3):
            raise CommandError(f"model: -ndf must be 2 or 3 with -ndm 2, got {ndf}")
        if self.domain is not None and self.domain.nodes:
            if self.domain.ndf != ndf:
                raise CommandError(f"model: the model already has nodes with {self.domain.ndf} dofs; "
                                   f"{self._command_hint(('wipe',))} before changing -ndf to {ndf}")
            return None
        if self.domain is None or self.domain.ndf != ndf:
            self.domain = Model(ndm, ndf)
        return None

    def node(self, *args):
        """``node(tag, x, y, ['-mass', *m])``."""
        model = self._model("node")
        a = Args("node", args)
        tag = a.int("node tag")
        coords = [a.float(f"coordinate {k + 1} of node {tag}") for k in range(model.ndm)]
        a.command = f"node {tag}"
        mass = None
        while a.more():
            a.option(("-mass",))
            mass = a.option_floats("-mass", model.ndf, "one per dof")
            if a.next_is_number():
                raise CommandError(f"node {tag}: -mass takes {model.ndf} values (one per dof, -ndf {model.ndf}), "
                                   f"got more: {a.peek()!r}")
        model.node(tag, *coords)
        if mass is not None:
            model.mass(tag, *mass)

    def fix(self, *args):
        """``fix(node, *flags)`` with one 0/1 flag per dof."""
        model = self._model("fix")
        a = Args("fix", args)
        tag = a.int("node tag")
        flags = a.ints(f"fix flag of node {tag}")
        a.done()
        self._node("fix", tag)
        model.fix(tag, *flags)

    def mass(self, *args):
        """``mass(node, *values)``: nodal mass, one value per dof [kg, kg·m²]."""
        model = self._model("mass")
        a = Args("mass", args)
        tag = a.int("node tag")
        values = a.floats(f"mass of node {tag}")
        a.done()
        self._node("mass", tag)
        model.mass(tag, *values)

    def equalDOF(self, *args):
        """``equalDOF(rNode, cNode, *dofs)``: the constrained node's dofs equal the retained
        node's (1-based dofs; OpenSees's Transformation handler)."""
        model = self._model("equalDOF")
        a = Args("equalDOF", args)
        retained, constrained = a.int("retained node"), a.int("constrained node")
        dofs = a.ints("dof")
        a.done()
        for n in (retained, constrained):
            self._node("equalDOF", n)
        model.equal_dof(retained, constrained, *dofs)

    def rigidLink(self, *args):
        """``rigidLink('bar'|'beam', rNode, cNode)``: equal translations, or a rigid beam (ndf 3)."""
        model = self._model("rigidLink")
        a = Args("rigidLink", args)
        kind = a.word("link type", ("bar", "beam"))
        master, slave = a.int("retained node"), a.int("constrained node")
        a.done()
        for n in (master, slave):
            self._node("rigidLink", n)
        model.rigid_link(kind, master, slave)

    def geomTransf(self, *args):
        """``geomTransf('Linear', tag)`` (vtsi is linear: PDelta and Corotational are refused)."""
        self._model("geomTransf")
        a = Args("geomTransf", args)
        kind = a.word("transformation type")
        if kind != "Linear":
            raise CommandError(f"geomTransf: transformation {kind!r} is not supported (vtsi is linear); "
                               "supported: Linear")
        tag = a.int("transformation tag")
        if tag in self._transforms:
            raise CommandError(f"geomTransf {kind} {tag}: transformation {tag} already exists")
        if a.more():
            raise CommandError(f"geomTransf Linear {tag}: option {a.peek()!r} is not supported "
                               "(joint offsets and 3-D vectors are not)")
        self._transforms[tag] = kind

    def uniaxialMaterial(self, *args):
        """``uniaxialMaterial('Elastic', tag, E, eta=0, Eneg=E)`` or ``('Viscous', tag, C, alpha=1)``."""
        self._model("uniaxialMaterial")
        a = Args("uniaxialMaterial", args)
        kind = a.word("material type")
        if kind not in MATERIAL_TYPES:
            raise CommandError(f"uniaxialMaterial: type {kind!r} is not supported (vtsi is linear); "
                               f"supported: {', '.join(MATERIAL_TYPES)}")
        tag = a.int("material tag")
        if tag in self._materials:
            raise CommandError(f"uniaxialMaterial {kind} {tag}: material {tag} already exists")
        name = f"uniaxialMaterial {kind} {tag}"
        a.command = name
        if kind == "Elastic":
            E = a.float("E")
            eta = a.float("eta") if a.more() else 0.0
            e_neg = a.float("Eneg") if a.more() else E
            a.done()
            if e_neg != E:
                raise CommandError(f"{name}: Eneg = {e_neg:g} differs from E = {E:g}, which makes the material "
                                   "nonlinear (bilinear in tension/compression); vtsi is linear")
            if E < 0 or eta < 0:
                raise CommandError(f"{name}: E and eta must be >= 0, got E = {E:g}, eta = {eta:g}")
            self._materials[tag] = ("Elastic", E, eta)
        else:
            C = a.float("C")
            alpha = a.float("alpha") if a.more() else 1.0
            if a.more():
                a.float("minVel")   # only matters for alpha != 1
            a.done()
            if alpha != 1.0:
                raise CommandError(f"{name}: alpha = {alpha:g} makes the dashpot nonlinear "
                                   "(sigma = C |rate|^alpha); vtsi supports alpha = 1 only")
            if C < 0:
                raise CommandError(f"{name}: C must be >= 0, got {C:g}")
            self._materials[tag] = ("Viscous", 0.0, C)

    def _material(self, command, tag):
        if tag not in self._materials:
            raise CommandError(f"{command}: material {tag} does not exist")
        return self._materials[tag]

    def element(self, *args):
        """``element(type, tag, ...)`` with the argument order of OpenSees for
        ``'elasticBeamColumn'``, ``'truss'`` and ``'zeroLength'`` (see ``docs/commands.md``), and
        ``element(type, tag, *nodes, *command_args, *options)`` for any element type registered in
        :mod:`vtsi.elements` that declares its command (``command_args``, ``command_options``)."""
        model = self._model("element")
        a = Args("element", args)
        kind = a.word("element type")
        kind = ELEMENT_ALIASES.get(kind, kind)
        if kind not in ELEMENT_TYPES and kind not in command_element_types():
            raise CommandError(f"element: type {kind!r} is not supported; supported: "
                               f"{', '.join(ELEMENT_TYPES + tuple(command_element_types()))}")
        tag = a.int("element tag")
        name = f"element {kind} {tag}"
        a.command = name
        if kind not in ELEMENT_TYPES:
            return self._element_registered(model, a, name, tag, command_element_types()[kind])
        i, j = a.int("node i"), a.int("node j")
        for n in (i, j):
            self._node(name, n)
        if i == j:
            raise CommandError(f"{name}: connects node {i} to itself")
        getattr(self, "_element_" + kind)(model, a, name, tag, i, j)

    def _element_registered(self, model, a, name, tag, cls):
        """A registered type's command: its nodes, then ``cls.command_args`` in order, then the
        options of ``cls.command_options`` (an option naming a parameter takes one number, its
        absence named as the shipped types name it: ``-mass needs a value (mu), got none``; one
        mapped to ``(parameter, value)`` is a flag)."""
        a.command = name
        nodes = [a.int(f"node {k + 1}") for k in range(cls.n_nodes)]
        for n in nodes:
            self._node(name, n)
        if len(set(nodes)) < len(nodes):
            raise CommandError(f"{name}: node {next(n for n in nodes if nodes.count(n) > 1)} is given twice")
        params = {p: a.float(p) for p in cls.command_args}
        options = dict(cls.command_options)
        while a.more():
            opt = a.option(tuple(options))
            target = options[opt]
            if isinstance(target, tuple):
                params[target[0]] = target[1]
            else:
                params[target] = a.option_floats(opt, 1, target)[0]
        model.element(cls.name, tag, nodes, **params)

    def _element_elasticBeamColumn(self, model, a, name, tag, i, j):
        if model.ndf != 3:
            raise CommandError(f"{name}: needs -ndf 3 (the model has {model.ndf})")
        if a.numbers_ahead() == 2:
            raise CommandError(f"{name}: OpenSees's section form (secTag transfTag) is not supported (vtsi has no "
                               "sections); give A E Iz transfTag")
        A, E, Iz = a.float("A"), a.float("E"), a.float("Iz")
        if not a.next_is_number():
            words = [Placeholder(w) for w in ("tag", "i", "j", "A", "E", "Iz", "transfTag", "...")]
            usage = self._command_text("element", "elasticBeamColumn", *words)
            raise CommandError(f"{name}: missing transfTag ({usage})")
        transf = a.int("transfTag")
        if a.next_is_number():
            raise CommandError(f"{name}: unexpected number {a.peek()!r} after transfTag {transf}; the 2-D form is "
                               "A E Iz transfTag [-mass m] [-cMass]")
        if transf not in self._transforms:
            raise CommandError(f"{name}: geomTransf {transf} does not exist")
        rho, cmass = 0.0, 0
        while a.more():
            opt = a.option(("-mass", "-cMass"))
            if opt == "-mass":
                rho = a.option_floats("-mass", 1, "mass per unit length")[0]
            else:
                cmass = 1
        model.element("elasticBeamColumn", tag, (i, j), A=A, E=E, I=Iz, rho=rho, cmass=cmass)

    def _element_ElasticTimoshenkoBeam(self, model, a, name, tag, i, j):
        """``element('ElasticTimoshenkoBeam', tag, i, j, E, G, A, Iz, Avy, transfTag, ['-mass', m],
        ['-cMass'])`` (OpenSees's argument order)."""
        if model.ndf != 3:
            raise CommandError(f"{name}: needs -ndf 3 (the model has {model.ndf})")
        E, G, A, Iz, Avy = (a.float(p) for p in ("E", "G", "A", "Iz", "Avy"))
        transf = a.int("transfTag")
        if transf not in self._transforms:
            raise CommandError(f"{name}: geomTransf {transf} does not exist")
        rho, cmass = 0.0, 0
        while a.more():
            if a.option(("-mass", "-cMass")) == "-mass":
                rho = a.option_floats("-mass", 1, "mass per unit length")[0]
            else:
                cmass = 1
        model.element("ElasticTimoshenkoBeam", tag, (i, j), A=A, E=E, G=G, I=Iz, Avy=Avy, rho=rho, cmass=cmass)

    def _element_truss(self, model, a, name, tag, i, j):
        A = a.float("A")
        mat = a.int("matTag")
        kind, E, eta = self._material(name, mat)
        if kind != "Elastic" or eta != 0.0:
            raise CommandError(f"{name}: material {mat} must be Elastic without damping (eta = 0) for a truss "
                               "in vtsi; use a zeroLength dashpot for damping")
        rho, cmass, do_rayleigh = 0.0, 0, 0
        while a.more():
            opt = a.option(("-rho", "-cMass", "-doRayleigh"))
            if opt == "-rho":
                rho = a.option_floats("-rho", 1, "mass per unit length")[0]
            elif opt == "-cMass":
                cmass = a.int("-cMass flag") if a.next_is_number() else 1
            else:
                do_rayleigh = a.int("-doRayleigh flag") if a.next_is_number() else 1
        model.element("truss", tag, (i, j), A=A, E=E, rho=rho, cmass=cmass, do_rayleigh=do_rayleigh)

    def _element_zeroLength(self, model, a, name, tag, i, j):
        if model.ndf != 3:
            raise CommandError(f"{name}: needs -ndf 3 (the model has {model.ndf}); OpenSees also takes -ndf 2, vtsi's "
                               "zeroLength has 3 dofs a node: use -ndf 3 and fix the rotations no element holds")
        mats, dirs, orient, do_rayleigh = [], [], None, 0
        seen = set()
        while a.more():
            opt = a.option(("-mat", "-dir", "-orient", "-doRayleigh"))
            if opt in seen:     # OpenSees fails on a second -mat and ignores a second -dir; takes the last of the others
                raise CommandError(f"{name}: {opt} given twice (give every value after one {opt}, as OpenSees)")
            if opt in ("-mat", "-dir"):
                seen.add(opt)
            if opt == "-mat":
                mats = a.ints("-mat tag")
            elif opt == "-dir":
                dirs = a.ints("-dir")
            elif opt == "-orient":
                orient = a.floats("-orient")
            else:
                do_rayleigh = a.int("-doRayleigh flag") if a.next_is_number() else 1
        if not mats:
            raise CommandError(f"{name}: no materials (-mat tags ...)")
        if len(mats) != len(dirs):
            raise CommandError(f"{name}: {len(mats)} materials (-mat) but {len(dirs)} directions (-dir)")
        angle = 0.0
        if orient is not None:
            # 2-D: local x from the first vector; local y is x turned +90 degrees and rz is the
            # global rotation whatever the side of yp (measured on OpenSeesPy 3.7.1)
            # (OpenSees 3.7.1 reads x only in 2-D, its yp from z x x, and ignores a yp given)
            if len(orient) not in (3, 6):
                raise CommandError(f"{name}: -orient needs 3 numbers (x1 x2 x3) or 6 (x1 x2 x3 yp1 yp2 yp3), "
                                   f"got {len(orient)}")
            x, yp = np.array(orient[:3]), np.array(orient[3:])
            if x[2] != 0.0 or np.hypot(x[0], x[1]) == 0.0:
                raise CommandError(f"{name}: -orient x = {x.tolist()} must lie in the x-y plane (2-D model)")
            if len(yp) and np.linalg.norm(np.cross(x, yp)) <= 1e-12 * np.linalg.norm(x) * np.linalg.norm(yp):
                raise CommandError(f"{name}: -orient yp = {yp.tolist()} is parallel to x = {x.tolist()}")
            angle = math.atan2(x[1], x[0])
        params = dict(kx=0.0, ky=0.0, krz=0.0, cx=0.0, cy=0.0, crz=0.0)
        keys = {1: ("kx", "cx"), 2: ("ky", "cy"), 3: ("krz", "crz"), 6: ("krz", "crz")}
        for mat, d in zip(mats, dirs):
            if d not in keys:
                raise CommandError(f"{name}: -dir {d} is not a 2-D direction; valid: 1 (local x), 2 (local y), "
                                   "3 or 6 (rotation)")
            _, E, eta = self._material(name, mat)
            params[keys[d][0]] += E
            params[keys[d][1]] += eta
        model.element("zeroLength", tag, (i, j), angle=angle, do_rayleigh=do_rayleigh, **params)
        self._zero_length[tag] = [(3 if d == 6 else d, *self._material(name, m)[1:]) for m, d in zip(mats, dirs)]

    def timeSeries(self, *args):
        """``timeSeries('Constant'|'Linear', tag, ['-factor', f])`` or ``timeSeries('Path', tag, ...)``
        with OpenSees's options ``-dt``, ``-values``, ``-time``, ``-filePath``, ``-fileTime``,
        ``-factor``, ``-useLast``, ``-prependZero``, ``-startTime``."""
        model = self._model("timeSeries")
        a = Args("timeSeries", args)
        kind = a.word("series type")
        if kind not in SERIES_TYPES and kind not in SERIES_ALIASES:
            raise CommandError(f"timeSeries: type {kind!r} is not supported; supported: {', '.join(SERIES_TYPES)}")
        tag = a.int("series tag")
        series = self._make_series(kind, tag, a, f"timeSeries {kind} {tag}")
        if tag in model.time_series:
            raise CommandError(f"timeSeries {kind} {tag}: series {tag} already exists")
        model.add_time_series(series)

    def _make_series(self, kind, tag, a, name):
        """The series ``kind`` (a name of :data:`SERIES_TYPES` or :data:`SERIES_ALIASES`) ``tag``
        from the arguments ``a`` after its tag; its errors begin with ``name`` (``timeSeries Path
        1``, or for an inline series ``pattern Plain 7: series Path``), which the series takes as
        its label (:attr:`vtsi.timeseries.TimeSeries.label`) for its own messages."""
        a.command = name
        try:
            return self._series(SERIES_ALIASES.get(kind, kind), tag, a, name)
        except ModelError as exc:      # the series' own message, begun with its label: name
            raise CommandError(str(exc)) from None

    @staticmethod
    def _series(kind, tag, a, name):
        """The series of :meth:`_make_series`, ``kind`` resolved, labelled ``name`` (a ModelError
        from its class)."""
        if kind in ("Constant", "Linear"):
            f = 1.0
            while a.more():     # (a second -factor: OpenSees fails, reading its words by count)
                a.option(("-factor",), once=True)
                f = a.float("-factor")
            return (Constant if kind == "Constant" else Linear)(f, tag=tag, label=name)
        if kind in ("Trig", "Triangle", "Rectangular", "Pulse"):
            t0, t1 = a.float("tStart"), a.float("tEnd")
            period = a.float("period") if kind != "Rectangular" else None
            extra = {"-factor": 1.0, "-shift": 0.0, "-zeroShift": 0.0, "-width": 0.5}
            valid = ("-factor",) if kind == "Rectangular" else tuple(extra) if kind == "Pulse" else tuple(extra)[:3]
            while a.more():
                opt = a.option(valid)
                extra[opt] = a.float(opt)
            if kind == "Rectangular":
                return Rectangular(t0, t1, extra["-factor"], tag=tag, label=name)
            if kind == "Pulse":
                return Pulse(t0, t1, period, extra["-width"], extra["-factor"], extra["-shift"], extra["-zeroShift"],
                             tag=tag, label=name)
            return (Trig if kind == "Trig" else Triangle)(t0, t1, period, extra["-factor"], extra["-shift"],
                                                         extra["-zeroShift"], tag=tag, label=name)
        opts = {}
        valid = ("-dt", "-values", "-time", "-filePath", "-fileTime", "-factor", "-useLast", "-prependZero",
                 "-startTime")
        while a.more():
            opt = a.option(valid, once=True)
            if opt in ("-dt", "-factor", "-startTime"):
                opts[opt] = a.float(opt)
            elif opt in ("-values", "-time"):
                opts[opt] = np.array(a.number_list(opt))
            elif opt in ("-filePath", "-fileTime"):
                opts[opt] = read_numbers(name, os.fspath(a.word(f"{opt} file")))
            else:
                opts[opt] = True
        if ("-values" in opts) == ("-filePath" in opts):
            raise CommandError(f"{name}: give the values with either -values or -filePath")
        if ("-time" in opts) and ("-fileTime" in opts):
            raise CommandError(f"{name}: give the times with either -time or -fileTime")
        values = opts.get("-values", opts.get("-filePath"))
        time = opts.get("-time", opts.get("-fileTime"))
        factor_ = opts.get("-factor", 1.0)
        if "-dt" in opts:
            if time is not None:
                raise CommandError(f"{name}: give either -dt or -time/-fileTime, not both")
            if not opts["-dt"] > 0.0:
                raise CommandError(f"{name}: -dt must be > 0, got {opts['-dt']:g}")
            return Path(values, dt=opts["-dt"], factor=factor_, use_last=opts.get("-useLast", False),
                        prepend_zero=opts.get("-prependZero", False), start_time=opts.get("-startTime", 0.0), tag=tag,
                        label=name)
        if time is None:
            raise CommandError(f"{name}: give the sample times with -dt or -time/-fileTime")
        for opt in ("-prependZero", "-startTime"):
            if opt in opts:
                raise CommandError(f"{name}: option {opt} applies to the -dt form only (OpenSees ignores it "
                                   "with -time); shift or extend the -time list instead")
        return Path(values, time=time, factor=factor_, use_last=opts.get("-useLast", False), tag=tag, label=name)

    def pattern(self, *args):
        """``pattern('Plain', tag, tsTag, ['-fact', f])``; following ``load`` commands go to it.
        ``tsTag`` may also be an inline series as in Tcl (``'Linear'``, ``'Path -dt 0.1 -values {...}'``)."""
        model = self._model("pattern")
        a = Args("pattern", args)
        kind = a.word("pattern type")
        if kind == "UniformExcitation":
            return self._uniform_excitation(model, a)
        if kind != "Plain":
            raise CommandError(f"pattern: type {kind!r} is not supported; supported: Plain, UniformExcitation")
        tag = a.int("pattern tag")
        name = f"pattern Plain {tag}"
        a.command = name
        spec = a.take("time series tag")
        if isinstance(spec, str):
            series = self._inline_series(name, spec, "the time series tag")
        elif is_int(spec):
            series = model.time_series.get(int(spec))
            if series is None:
                raise CommandError(f"{name}: time series {spec} does not exist")
        else:
            raise CommandError(f"{name}: time series tag must be an integer, got {spec!r}")
        fact = 1.0
        while a.more():
            a.option(("-fact", "-factor"))
            fact = a.float("-fact")
        if tag in model.patterns:
            raise CommandError(f"{name}: pattern {tag} already exists")
        model.pattern(tag, series, fact)
        self._current_pattern = tag

    def _uniform_excitation(self, model, a):
        """``pattern('UniformExcitation', tag, dir, '-accel', tsTag, ['-fact', f])``: a ground
        acceleration along dof ``dir`` (1 x, 2 y) [L/s²]; responses relative to the ground."""
        tag = a.int("pattern tag")
        name = f"pattern UniformExcitation {tag}"
        a.command = name
        direction = a.int("direction")
        series, fact = None, 1.0
        while a.more():
            opt = a.option(("-accel", "-fact", "-factor"))
            if opt == "-accel":
                spec = a.take("-accel time series tag")
                if isinstance(spec, str):
                    series = self._inline_series(name, spec, "the -accel time series tag")
                elif is_int(spec) and int(spec) in model.time_series:
                    series = model.time_series[int(spec)]
                else:
                    raise CommandError(f"{name}: -accel time series {spec!r} does not exist")
            else:
                fact = a.float(opt)
        if series is None:
            raise CommandError(f"{name}: give the ground acceleration with -accel tsTag (-disp, -vel: not supported)")
        if direction not in (1, 2):
            raise CommandError(f"{name}: direction must be 1 (x) or 2 (y), got {direction}")
        if tag in model.patterns:
            raise CommandError(f"{name}: pattern {tag} already exists")
        model.uniform_excitation(tag, direction, series, fact)
        self._current_pattern = None

    def _inline_series(self, name, spec, what):
        """The series of the inline specification ``spec`` (``'Path -dt 0.1 -values {0 1 0}'``, as
        Tcl's ``pattern Plain 7 {Path ...}``) of the pattern ``name``; its errors name the pattern
        (``pattern Plain 7: series Path: missing -factor``). A tag given as a str (``'1'``, which
        a Tcl word is not: it arrives as an int) is refused naming ``what``, as OpenSeesPy refuses it.
        The series' own tag, which OpenSees reads where :data:`SERIES_LEADING_NUMBERS` says
        (``Linear 5 -factor 2``), is read, an integer, and dropped: OpenSees's ``TclSeriesCommand``
        adds the series to no table of series (``pattern Plain 2 5`` does not find it), so the
        series has no tag (``printModel`` names it ``inline``)."""
        words = tcl_words(spec)
        if not words:
            raise CommandError(f"{name}: empty time series specification")
        kind = words[0]
        if not isinstance(kind, str):
            raise CommandError(f"{name}: {what} must be an integer, got {spec!r}")
        if kind not in SERIES_TYPES and kind not in SERIES_ALIASES:
            raise CommandError(f"{name}: series type {kind!r} is not supported; supported: {', '.join(SERIES_TYPES)}")
        label = f"{name}: series {kind}"
        a = Args(label, words[1:])
        lead = SERIES_LEADING_NUMBERS.get(SERIES_ALIASES.get(kind, kind))
        if (type(a.peek()) is int if lead is None
                else (len(a.items) - lead) % 2 == 1 and a.next_is_number()):
            a.int("tag")        # OpenSees's tag of a series it keeps in no table
        return self._make_series(kind, None, a, label)

    def load(self, *args):
        """``load(node, *values)``: a nodal load [N, N·m], one value per dof, of the last pattern
        defined (in Tcl also inside its braces). Every argument after the node tag is a load
        value, as OpenSees reads them: OpenSees's ``-pattern`` and ``-const`` options are refused
        naming the word, as OpenSees's Tcl and OpenSeesPy both fail on them
        (docs/opensees_conventions.md, b)."""
        model = self._model("load")
        a = Args("load", args)
        tag = a.int("node tag")
        values = a.floats(f"load on node {tag}")
        if a.more():
            word = a.peek()
            why = (f"; OpenSees reads every argument after the node tag as a load value, so it takes no {word} "
                   f"option: a load goes to the last pattern defined ({self._pattern_hint()})"
                   if word in ("-pattern", "-const") else "")
            raise CommandError(f"load on node {tag}: a load value must be a number, got {word!r}{why}")
        pattern = self._current_pattern
        self._node("load", tag)
        if pattern is None:
            raise CommandError(f"load on node {tag}: no load pattern; define one with {self._pattern_hint()}")
        target = model.patterns.get(pattern)
        if target is None:
            raise CommandError(f"load on node {tag}: pattern {pattern} does not exist")
        target.load(tag, *values)       # (Model.load's other checks, of the node, are the command's own above)

    def sp(self, *args):
        """``sp(node, dof, value)``: a prescribed displacement [m, rad] of the last pattern defined,
        ``value × factor(t)`` (1-based dof); the dof is then constrained (OpenSees's Transformation
        handler: the support's motion loads the structure through the stiffness)."""
        model = self._model("sp")
        a = Args("sp", args)
        node, dof, value = a.int("node tag"), a.int("dof"), a.float("value")
        a.done()
        self._node("sp", node)
        pattern = self._current_pattern
        if pattern is None or pattern not in model.patterns:
            raise CommandError(f"sp node {node}: no load pattern; define one with {self._pattern_hint()}")
        model.sp(pattern, node, dof, value)

    def eleLoad(self, *args):
        """``eleLoad('-ele', *tags | '-range', first, last, '-type', '-beamUniform', Wy, [Wx])`` or
        ``(..., '-type', '-beamPoint', Py, xL, [Px])``: loads in element axes on beams of the
        last pattern defined (Wy, Py transverse, + along local y; Wx, Px axial, from node i to j;
        xL the fraction of the length from node i) [N/m, N]; OpenSees's ``aOverL bOverL`` after
        ``Wx`` only as ``0 1`` (the whole element: :meth:`_whole_span`). Every element of ``-ele`` and of
        ``-range`` must exist (OpenSees warns for a missing one in a range and loads the rest)."""
        model = self._model("eleLoad")
        a = Args("eleLoad", args)
        tags = []
        while a.more() and a.peek() in ("-ele", "-range"):
            if a.option(("-ele", "-range")) == "-ele":
                tags += a.ints("element tag")
            else:
                lo, hi = a.int("-range first"), a.int("-range last")
                if hi < lo:
                    raise CommandError(f"eleLoad -range {lo} {hi}: the last element is before the first")
                found = [t for t in model.element_tags() if lo <= t <= hi]
                if len(found) < hi - lo + 1:     # refused as -ele refuses one (OpenSees warns, loads the rest)
                    runs, count = _missing_runs(lo, hi, found)
                    raise CommandError(f"eleLoad -range {lo} {hi}: element{'s' * (count > 1)} {runs} "
                                       f"do{'es' * (count == 1)} not exist")
                tags += found
        if not tags:
            more = ("-type", Placeholder("..."))
            by_tag = self._command_text("eleLoad", "-ele", self._tags_word(), *more)
            by_range = self._command_text("eleLoad", "-range", Placeholder("first"), Placeholder("last"), *more)
            raise CommandError(f"eleLoad: no elements (give {by_tag} or {by_range})")
        if a.peek() in ("-beamUniform", "-beamPoint"):
            usage = self._command_text("eleLoad", "-ele", self._tags_word(), "-type", a.peek(), Placeholder("..."))
            raise CommandError(f"eleLoad: -type missing before {a.peek()} ({usage})")
        a.option(("-type",))
        kind = a.word("load type", ("-beamUniform", "-beamPoint"))
        if kind == "-beamUniform":
            values = (a.float("Wy"), *([a.float("Wx")] if a.more() else []))
            self._whole_span(a)
        else:
            values = (a.float("Py"), a.float("xL"), *([a.float("Px")] if a.more() else []))
        a.done()
        pattern = self._current_pattern
        if pattern is None or pattern not in model.patterns:
            raise CommandError(f"eleLoad: no load pattern; define one with {self._pattern_hint()}")
        for tag in tags:
            if tag not in model._element_owner:
                raise CommandError(f"eleLoad: element {tag} does not exist")
        build, shape = model.build(), "uniform" if kind == "-beamUniform" else "point"
        values = element_load_values(shape, values)     # Wx, Px: 0 when not given
        for tag in tags:            # each element type says whether it takes the load, before any is added
            b, i = build.element_location[tag]
            etype, _, coords, params, _ = build.blocks[b]
            try:
                etype.equivalent_loads(coords[i], params[i], shape, values)
            except ModelError as exc:
                raise CommandError(f"eleLoad on element {tag}: {exc}") from None
        try:
            for tag in tags:
                model.patterns[pattern].beam_load(tag, shape, *values)
        except ModelError as exc:
            raise CommandError(f"eleLoad: {exc}") from None

    @staticmethod
    def _whole_span(a):
        """Read OpenSees's ``aOverL bOverL [Wyb [Wxb]]`` after ``-beamUniform Wy Wx`` (fractions
        of the length from node i where the load begins and ends, and the load at its end):
        accepted where they give the uniform load on the whole element (``0 1``, or ``0``), as
        OpenSees then builds its ``Beam2dUniformLoad``; a partial or a varying load is refused."""
        extra = a.floats("aOverL, bOverL")
        if not extra:
            return
        a_l, b_l = extra[0], extra[1] if len(extra) > 1 else 1.0
        if len(extra) > 2:
            raise CommandError(f"{a.command}: -beamUniform Wya Wxa aOverL bOverL Wyb Wxb (a load varying from Wya at "
                               "aOverL to Wyb at bOverL) is not supported; split the element where the load "
                               "changes and give each part its own uniform load")
        if (a_l, b_l) != (0.0, 1.0):
            raise CommandError(f"{a.command}: -beamUniform with aOverL = {a_l:g}, bOverL = {b_l:g} is a partial uniform "
                               "load (from a = aOverL L to b = bOverL L from node i), which is not supported; split the "
                               "element at a and b (a node at each) and load the part between them (aOverL 0 and "
                               "bOverL 1, or none, load the whole element)")

    def rayleigh(self, *args):
        """``rayleigh(alphaM, betaK, betaKinit, betaKcomm)``: ``C = αM M + (βK + βK0 + βKc) K``."""
        model = self._model("rayleigh")
        a = Args("rayleigh", args)
        values = [a.float(n) for n in ("alphaM", "betaK", "betaKinit", "betaKcomm")]
        a.done()
        model.rayleigh(*values)

