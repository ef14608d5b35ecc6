"""Query commands: ``nodeDisp``, ``nodeVel``, ``nodeAccel``, ``nodeReaction`` after
``reactions``, ``eleForce``, ``eleResponse``, ``getTime``, ``setTime``, ``loadConst``,
``getLoadFactor``, ``nodeMass``, ``nodeBounds``, ``nodeCoord``, ``nodeEigenvector``,
``nodeResponse``, ``getNodeTags``, ``getEleTags``, with OpenSees's return values."""
import logging
import math

import numpy as np

from vtsi.analysis import domain_state
from vtsi.errors import CommandError, ModelError, is_int, is_number
from vtsi.recorders.element import FORCE_KINDS, element_response
from vtsi.recorders.moment import element_end_forces
from vtsi.recorders.node import AppliedLoads, element_ground_loads, subtract_coupled_loads

from .args import Args, dof_value
from .base import Placeholder, SessionBase
from .model_text import model_text
from .responses import ELEMENT_RESPONSE_ALIASES, accepted_responses, apply_layout, element_answers, opensees_layout

QUERY_COMMANDS = ("printModel", "nodeDisp", "nodeVel", "nodeAccel", "nodeReaction", "reactions", "eleForce", "eleResponse",
                  "getTime", "setTime", "loadConst", "nodeCoord", "nodeEigenvector", "nodeResponse", "getNodeTags",
                  "getEleTags", "getLoadFactor", "nodeMass", "nodeBounds")
NODE_RESPONSE_IDS = {1: "disp", 2: "vel", 3: "accel", 6: "reaction", 7: "unbalance"}

log = logging.getLogger(__name__)


class LoadsLastApplied:
    """The loads as the domain last applied them (OpenSees's ``Domain::applyLoad``: an analysis
    step, ``reactions``), kept as they were then, as OpenSees's nodes (unbalanced load) and
    elements (load vector) keep them until the next application: a load added to or removed
    from a pattern, a pattern added or removed, a nodal mass changed since count from the next.

    ``time`` [s] the load time; ``patterns``: ``{id(pattern): (pattern, kept, equivalents)}`` of
    every pattern in the model then, ``kept`` a copy of it (its factor, freezing, series and nodal
    loads as they were), ``equivalents`` its element loads' global nodal loads at factor 1
    (``{element tag: (ndof,)}``, :meth:`vtsi.assembly.Assembly.element_equivalent_loads`);
    ``nodal_mass`` the nodal masses then (a ground acceleration's load on them). ``previous``: the
    last application, whose copies are reused while the model and its assembly (the masses) are
    unchanged: all of them while its patterns are (``Model.load_version``), so that a script's
    ``analyze(1, dt)`` loop copies nothing, else those of the patterns whose own loads, factor and
    freezing are (``LoadPattern.version``): a script that adds a pattern at every step copies
    that one only."""

    def __init__(self, model, time, previous=None):
        asm = model.build()
        self.time = float(time)
        self.model, self.assembly, self.version = model, asm, model.load_version
        same = previous is not None and previous.model is model and previous.assembly is asm
        if same and previous.version == model.load_version:
            self.patterns, self.nodal_mass = previous.patterns, previous.nodal_mass
            return
        before = previous.patterns if same else {}
        self.patterns = {}
        for p in model.patterns.values():
            entry = before.get(id(p))
            if entry is None or entry[0] is not p or entry[1].version != p.version:
                entry = (p, p.snapshot(), asm.element_equivalent_loads(p) if p.element_loads else {})
            self.patterns[id(p)] = entry
        self.nodal_mass = previous.nodal_mass if same else dict(model.nodal_mass)

    def factor(self, pattern):
        """The load factor the model's ``pattern`` was applied with (OpenSees's
        ``LoadPattern::getLoadFactor``): its factor × its series' at :attr:`time` (frozen by
        ``loadConst``), 0 for a pattern not in the model then."""
        if not self.applied(pattern):
            return 0.0
        return float(self.patterns[id(pattern)][1].factors(np.array([self.time]))[0])

    def applied(self, pattern):
        """Whether the model's ``pattern`` was in the model at the last application."""
        entry = self.patterns.get(id(pattern))
        return entry is not None and entry[0] is pattern

    def terms(self):
        """``[(kept, factor, equivalents)]`` of every pattern applied (one removed since included)."""
        return [(kept, float(kept.factors(np.array([self.time]))[0]), equivalents)
                for _, kept, equivalents in self.patterns.values()]


class QueryCommands(SessionBase):
    """What a script reads back from the domain."""

    _applied = None     # the LoadsLastApplied of the last load time, None before the first
    _coupled_state = None   # (CoupledLoads, DomainState): the coupled analysis that computed the domain's state

    def _clear_queries(self):
        self._reactions = None

    @property
    def _load_time(self):
        """The time [s] at which the domain last applied its loads (OpenSees's
        ``Domain::applyLoad``: an analysis step, ``reactions``), None before the first. Setting it
        (the analyses do, after a step) also keeps the loads applied then (:class:`LoadsLastApplied`)."""
        return None if self._applied is None else self._applied.time

    @_load_time.setter
    def _load_time(self, t):
        model = self.domain
        self._applied = None if t is None or model is None else LoadsLastApplied(model, t, self._applied)

    def _applied_factor(self, pattern):
        """The load factor of ``pattern`` as the domain last applied it (:meth:`LoadsLastApplied.factor`):
        0 before the first application and for a pattern added since, until the next analysis
        step applies it (``setTime`` applies nothing)."""
        return 0.0 if self._applied is None else self._applied.factor(pattern)

    def nodeDisp(self, node, dof=-1):
        """Displacement of ``node`` [m, rad]: a list over its dofs, or one 1-based ``dof``."""
        return dof_value(self._node_values("nodeDisp", node, "u"), dof, f"nodeDisp {node}")

    def nodeVel(self, node, dof=-1):
        """Velocity of ``node`` [m/s, rad/s]."""
        return dof_value(self._node_values("nodeVel", node, "v"), dof, f"nodeVel {node}")

    def nodeAccel(self, node, dof=-1):
        """Acceleration of ``node`` [m/s², rad/s²]."""
        return dof_value(self._node_values("nodeAccel", node, "a"), dof, f"nodeAccel {node}")

    def nodeCoord(self, node, dim=-1):
        """Coordinates ``[x, y]`` of ``node`` [m], or one 1-based coordinate."""
        tag = self._node("nodeCoord", node)
        return dof_value(list(self.domain.nodes[tag]), dim, f"nodeCoord {node}")

    def nodeReaction(self, node, dof=-1):
        """Reaction at ``node`` as last computed by :meth:`reactions` (zeros before) [N, N·m]."""
        asm, _ = self._state("nodeReaction")
        if self._reactions is None or self._reactions.shape[0] != asm.n_full:
            values = np.zeros(asm.ndf)
            self._node("nodeReaction", node)
        else:
            values = self._node_values("nodeReaction", node, self._reactions)
        return dof_value(values, dof, f"nodeReaction {node}")

    def nodeEigenvector(self, node, mode, dof=-1):
        """Mode ``mode`` (1-based) of the last ``eigen`` at ``node``: list over the dofs or one dof."""
        tag = self._node("nodeEigenvector", node)
        if self._eigen is None:
            raise CommandError(f"nodeEigenvector: no eigenvectors; {self._command_hint(('eigen', Placeholder('n')))} first")
        asm, _, shapes = self._eigen
        if not is_int(mode) or not 1 <= mode <= shapes.shape[1]:
            raise CommandError(f"nodeEigenvector: mode must be 1..{shapes.shape[1]} (eigen computed "
                               f"{shapes.shape[1]}), got {mode!r}")
        if tag not in asm.node_index:
            raise CommandError(f"nodeEigenvector: node {tag} was added after the last eigen")
        i = asm.node_index[tag] * asm.ndf
        return dof_value(shapes[i: i + asm.ndf, int(mode) - 1], dof, f"nodeEigenvector {node} {mode}")

    def nodeResponse(self, node, dof, response_id):
        """``nodeResponse(node, dof, id)``: id 1 disp, 2 vel, 3 accel, 6 reaction (as last
        computed), 7 applied nodal load."""
        if not is_int(response_id) or int(response_id) not in NODE_RESPONSE_IDS:
            raise CommandError(f"nodeResponse: response id {response_id!r} is not supported; supported: "
                               + ", ".join(f"{k} ({v})" for k, v in NODE_RESPONSE_IDS.items()))
        kind = NODE_RESPONSE_IDS[int(response_id)]
        self._node("nodeResponse", node)
        if kind == "unbalance":
            asm, _ = self._state("nodeResponse")
            values = self._node_values("nodeResponse", node, self._applied_loads(asm))
            return dof_value(values, dof, f"nodeResponse {node}")
        method = {"disp": self.nodeDisp, "vel": self.nodeVel, "accel": self.nodeAccel,
                  "reaction": self.nodeReaction}[kind]
        return method(node, dof)

    def getTime(self):
        """The current (committed) domain time [s]."""
        if self.domain is None or not self.domain.nodes:
            return 0.0
        return float(domain_state(self.domain).time)

    def setTime(self, t):
        """Set the domain time [s]; the next step goes to ``t + Δt``. The loads are not applied
        (``getLoadFactor`` reads what the last step applied, as OpenSees)."""
        _, state = self._state("setTime")
        if not is_number(t) or not math.isfinite(t):
            raise CommandError(f"setTime: time must be a finite number, got {t!r}")
        state.time = float(t)

    def loadConst(self, *args):
        """``loadConst(['-time', t])``: freeze every existing pattern at the factor the domain
        last applied it with (OpenSees's ``LoadPattern::setLoadConstant`` keeps ``loadFactor``), its
        factor at the last load time; then set the time. A pattern never applied (defined before
        any analysis step, or after the last) is frozen at 0, as in OpenSees: its ``factor`` is
        set to 0, its loads never act, and a warning (logged, on stderr by default) names it."""
        model = self._model("loadConst")
        a = Args("loadConst", args)
        new_time = None
        while a.more():
            a.option(("-time",))
            new_time = a.option_floats("-time", 1, "the new time [s]")[0]
        at = self._load_time if self._load_time is not None else self.getTime()
        never = []
        for tag, p in model.patterns.items():
            if p.constant_time is None:
                if self._applied is None or not self._applied.applied(p):
                    p.factor = 0.0
                    never.append(tag)
                p.constant_time = at
        if never:
            one = len(never) == 1
            log.warning("loadConst: pattern%s %s frozen at load factor 0: no analysis step applied %s since %s "
                        "defined, so %s loads never act (as in OpenSees)", "" if one else "s",
                        ", ".join(map(str, never)), "it" if one else "them", "it was" if one else "they were",
                        "its" if one else "their")
        if new_time is not None:
            _, state = self._state("loadConst")
            state.time = new_time

    def getLoadFactor(self, tag):
        """The load factor of pattern ``tag`` as OpenSees returns it: its factor × its series' at
        the time the domain last applied its loads (an analysis step, ``reactions``); 0 before
        the first step and for a pattern defined since, until the next step (:meth:`_applied_factor`)."""
        model = self._model("getLoadFactor")
        if not is_int(tag) or tag not in model.patterns:
            raise CommandError(f"getLoadFactor: pattern {tag!r} does not exist")
        return self._applied_factor(model.patterns[tag])

    def nodeMass(self, node, dof=-1):
        """The nodal mass of ``node`` (``mass`` command or ``node -mass``; element mass not
        included, as OpenSees) [M, M·L²]: a list over its dofs, or one 1-based ``dof``."""
        tag = self._node("nodeMass", node)
        values = self.domain.nodal_mass.get(tag, np.zeros(self.domain.ndf))
        return dof_value(list(map(float, values)), dof, f"nodeMass {node}")

    def nodeBounds(self):
        """``[x_min, y_min, 0, x_max, y_max, 0]`` of the nodes (OpenSees's 6 values in 2-D)."""
        model = self._model("nodeBounds")
        if not model.nodes:
            raise CommandError("nodeBounds: the model has no nodes")
        xy = np.array(list(model.nodes.values()), dtype=float)
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        return [float(lo[0]), float(lo[1]), 0.0, float(hi[0]), float(hi[1]), 0.0]

    def getNodeTags(self, *args):
        """Node tags, ascending (OpenSees's ``'-mesh', tag`` is refused: vtsi has no meshes)."""
        self._no_mesh("getNodeTags", args)
        return sorted(self.domain.nodes) if self.domain is not None else []

    def getEleTags(self, *args):
        """Element tags, ascending (OpenSees's ``'-mesh', tag`` is refused: vtsi has no meshes)."""
        self._no_mesh("getEleTags", args)
        return self.domain.element_tags() if self.domain is not None else []

    @staticmethod
    def _no_mesh(command, args):
        a = Args(command, args)
        if a.more():
            if a.option(("-mesh",)) == "-mesh":
                raise CommandError(f"{command}: option '-mesh' is not supported (vtsi has no mesh command); "
                                   "call it without options for every tag")

    def printModel(self, *args):
        """``printModel(['-node', *tags], ['-ele', *tags], ['-file', name])``: a readable dump of the
        model (its units, nodes with fixities, masses and committed response, elements with their
        type, nodes and parameters, patterns with their series and loads, damping, time) to
        stdout or appended to a file. Without ``-node``/``-ele`` everything is printed; with them,
        just those nodes and elements (as OpenSees). OpenSees's ``-JSON`` is refused (its schema
        is OpenSees's own)."""
        model = self._model("printModel")
        a = Args("printModel", args)
        nodes, elements, path = None, None, None
        while a.more():
            opt = a.option(("-node", "-ele", "-file", "-JSON"))
            if opt == "-JSON":
                raise CommandError("printModel: option '-JSON' is not supported (OpenSees's own JSON schema); "
                                   "use the text form, or vtsi.Model and its assembly from Python")
            if opt == "-file":
                path = a.word("-file name")
            else:
                tags = a.ints(f"{opt} tag")
                for t in tags:
                    if opt == "-node":
                        self._node("printModel", t)
                    elif t not in model._element_owner:
                        raise CommandError(f"printModel: element {t} does not exist")
                if opt == "-node":
                    nodes = tags
                else:
                    elements = tags
        text = model_text(model, domain_state(model) if model.nodes else None, nodes, elements)
        if nodes is None and elements is None:
            text = f"Units: {self._units}\n{text}"
        if path is None:
            print(text)
        else:
            try:
                with open(path, "a") as fh:
                    fh.write(text + "\n")
            except OSError as exc:
                raise CommandError(f"printModel: cannot write {path}: {exc.strerror}") from None

    # -- forces ------------------------------------------------------------------------------------
    def _applied_terms(self):
        """:meth:`LoadsLastApplied.terms` of the last application ([] before the first)."""
        return [] if self._applied is None else self._applied.terms()

    def _applied_loads(self, asm):
        """Full-dof nodal load vector (in ``asm``'s numbering) the domain last applied (OpenSees's
        unbalanced load of the nodes: their nodal loads and, under a ground acceleration, −m r a_g
        of their nodal mass, ``Node::addInertiaLoadToUnbalance``; element loads and element mass
        load the elements), the loads and masses as they were then (:class:`LoadsLastApplied`)."""
        p = np.zeros(asm.n_full)
        ndf = asm.ndf
        for pattern, f, _ in self._applied_terms():
            if f == 0.0:
                continue
            if pattern.ground_direction is not None:
                d = pattern.ground_direction - 1
                for tag, mass in self._applied.nodal_mass.items():
                    if tag in asm.node_index:
                        p[asm.node_index[tag] * ndf + d] -= f * float(mass[d])
            for tag, values in pattern.nodal.items():
                if tag in asm.node_index:
                    i = asm.node_index[tag] * ndf
                    p[i: i + ndf] += f * np.asarray(values)[:ndf]
        return p

    def _coupled_now(self, command):
        """The :class:`~vtsi.coupled.CoupledLoads` of the coupled analysis that computed the
        domain's committed state (``deadLoad``, or ``analyze`` with a moving-load constraint),
        which holds what it applied besides the patterns at that state (the train's forces and
        contact forces, the bridge's own weight with ``deadLoad -selfWeight``), or None (no such
        analysis, or the state made anew since: a node added or removed). A CommandError naming
        ``command`` when the domain's time is no longer that state's (``setTime``, ``loadConst
        -time``, a run that diverged): the train's loads are known at the analysis's steps only."""
        if self._coupled_state is None:
            return None
        coupled, state = self._coupled_state
        if state is not domain_state(self.domain) or coupled.time is None:
            return None
        if coupled.time != state.time:
            raise CommandError(f"{command}: the domain's time is t = {state.time:.9g} s, and the train's loads are "
                               f"known at the coupled analysis's last step, t = {coupled.time:.9g} s (setTime or "
                               f"loadConst -time changed it since, or the run diverged); "
                               f"{self._command_hint(('setTime', coupled.time))} first, or query before")
        return coupled

    def _element_load_now(self, tag):
        """The ``(ndof,)`` global nodal loads equivalent to element ``tag``'s element loads as the
        domain last applied them (the fixed-end forces, negated, that OpenSees counts in element
        forces; :class:`LoadsLastApplied`), or None when it has none."""
        out = None
        for _, f, equivalents in self._applied_terms():
            eq = equivalents.get(tag)
            if eq is not None:
                out = (0.0 if out is None else out) + f * eq
        return out

    def _ground_accelerations_now(self):
        """``[(direction, a_g)]`` of the ground accelerations (UniformExcitation) as the domain last
        applied them [m/s²] (:class:`LoadsLastApplied`)."""
        return [(p.ground_direction, f) for p, f, _ in self._applied_terms() if p.ground_direction is not None]

    def _element_response(self, command, tag, kind, u, v):
        """One element's response (the element ``tag`` exists) as OpenSees returns it (:func:`~.responses.opensees_layout`), its
        element loads' fixed-end forces included (after a coupled analysis also those of the
        wheel loads inside it at the state's time, :meth:`_coupled_now`: the train's moving forces
        and contact forces λ_{n+1}, spread as the constraint's rows spread them), and in the global
        end forces (``force``, ``globalForce``) the ground's load on its own mass, ``+M_e r a_g``,
        as OpenSees's ``getResistingForce`` subtracts the element's load vector."""
        asm = self.domain.build()
        kind = ELEMENT_RESPONSE_ALIASES.get(kind, kind)
        b, i = asm.element_location[tag]
        etype, _, coords, _params, dofs = asm.blocks[b]
        layout = opensees_layout(etype, kind, asm.ndf, self._zero_length.get(tag))
        source = layout[0] if layout is not None else kind
        if source not in etype.response_kinds:
            valid = accepted_responses(etype, asm.ndf, self._zero_length.get(tag))
            raise CommandError(f"{command}: element {tag} ({etype.name}) has no response {kind!r}; valid: "
                               f"{', '.join(valid)}")
        d = dofs[i]
        rows, u_e, v_e = slice(i, i + 1), u[d][None, :], v[d][None, :]
        values = element_response(asm, b, rows, source, u_e, v_e)
        loaded = None if source in etype.unloaded_responses else self._element_load_now(tag)
        coupled = None if source in etype.unloaded_responses else self._coupled_now(command)
        if coupled is not None and tag in coupled.constraint.track.elements:
            table = element_end_forces(asm, coupled.constraint.track, [tag])
            wheels = coupled.add(table, np.array([coupled.time]), np.zeros((1, table.n_columns)))[0]   # −f_eq
            if wheels.any():
                loaded = -wheels if loaded is None else loaded - wheels
        if loaded is not None:
            try:
                values = values - np.asarray(etype.end_force_response(source, coords[rows], loaded[None, :]),
                                             dtype=float)
            except ModelError as exc:
                raise CommandError(f"{command}: element {tag}: {exc}") from None
        if source in FORCE_KINDS:
            for direction, a_g in self._ground_accelerations_now():
                values = values - a_g * element_ground_loads(asm, b, rows, direction)
        if layout is None:
            return values[0]
        rates = element_response(asm, b, rows, source, v_e, v_e) if layout[2] else None
        return apply_layout(layout, values, rates)[0]

    def eleForce(self, tag, dof=-1):
        """Resisting force of element ``tag`` in global axes (``K u`` plus the element's own
        dashpots; no Rayleigh damping, no inertia), the force the nodes exert on the element, less
        the loads applied on the element as OpenSees's ``getResistingForce``: the fixed-end forces
        of its element loads and, under a ground acceleration, ``−M_e r a_g`` on its own mass.
        A missing element gives None (Tcl: an empty result) and a warning (logged) naming it, as
        OpenSeesPy returns None (its ``Domain::getElementResponse`` finds no element)."""
        _, state = self._state("eleForce")
        if not is_int(tag):
            raise CommandError(f"eleForce: element tag must be an integer, got {tag!r}")
        if int(tag) not in self.domain.build().element_location:
            log.warning("eleForce %d: element %d does not exist and gives None, as in OpenSees", tag, tag)
            return None
        values = self._element_response("eleForce", int(tag), "force", state.u, state.v)
        return dof_value(values, dof, f"eleForce {tag}")

    def eleResponse(self, tag, *args):
        """``eleResponse(tag, 'force'|'globalForce'|'localForce'|'basicForce'|...)`` as a list. A
        response the element has not, in vtsi as in OpenSees (``stresses``, ``section 1 force``),
        gives ``[]``, as OpenSeesPy (Tcl: an empty result), and a warning (logged: on stderr by
        default) naming the element and the responses it answers; one OpenSees answers and vtsi
        does not is refused (:func:`~.responses.element_answers`). A missing element gives ``[]``
        and a warning naming it, as OpenSeesPy gives ``[]``."""
        _, state = self._state("eleResponse")
        a = Args(f"eleResponse {tag}", args)
        a.word("response")      # a name first: a missing one or a number is named
        if not is_int(tag):
            raise CommandError(f"eleResponse: element tag must be an integer, got {tag!r}")
        tag = int(tag)
        asm = self.domain.build()
        asked = " ".join(map(str, a.items))
        if tag not in asm.element_location:
            log.warning("%s %s: element %d does not exist and gives [], as in OpenSees", a.command, asked, tag)
            return []
        etype = asm.blocks[asm.element_location[tag][0]][0]
        valid = accepted_responses(etype, asm.ndf, self._zero_length.get(tag))
        if not element_answers(a.command, tag, etype, a.items, valid):
            log.warning("%s %s: element %d (%s) has no response %r and gives [], as in OpenSees (it answers "
                        "%s)", a.command, asked, tag, etype.name, asked, ", ".join(valid))
            return []
        return [float(x) for x in self._element_response("eleResponse", tag, a.items[0], state.u, state.v)]

    def reactions(self, *args):
        """Compute the nodal reactions (read them with :meth:`nodeReaction`): ``R = F_resisting - P``
        with the elements' static resisting forces (default), ``'-dynamic'``: ``K u + C v + M a - P``
        (inertia and Rayleigh damping included), ``'-rayleigh'``: the Rayleigh damping forces
        ``αM M v + βK K v`` of every element (also of one that takes no Rayleigh damping in the
        analysis, as OpenSees's ``Element::getRayleighDampingForces``) and nodal mass.
        As OpenSees (``Domain::calculateNodalReactions``), the loads are first applied again at the
        committed time, which then is the load time of the queries after (``getLoadFactor``, the
        element loads in ``eleForce``; HHT and GeneralizedAlpha applied them at ``t_n + αΔt``).
        ``P`` (:class:`~vtsi.recorders.node.AppliedLoads`, as the reaction recorders): nodal loads,
        the element loads' equivalent nodal loads, and under a ground acceleration −M r a_g at every
        dof, the supports' included (a support's reaction accelerates its own mass); after a
        coupled analysis (``deadLoad``, ``analyze`` with a moving-load constraint) also what it
        applied at the state's time (:meth:`_coupled_now`, as the reaction recorders take it:
        :func:`~vtsi.recorders.node.subtract_coupled_loads`): the train's moving forces and
        contact forces, the share of a wheel in an end element on the support's own dof included,
        and the bridge's own weight with ``deadLoad -selfWeight``."""
        asm, state = self._state("reactions")
        a = Args("reactions", args)
        flag = "-static"
        while a.more():
            flag = a.option(("-dynamic", "-rayleigh"))
        coupled = None if flag == "-rayleigh" else self._coupled_now("reactions")
        self._load_time = state.time     # OpenSees applies the loads again at the committed time first
        loads = AppliedLoads(asm, self.domain.patterns.values()).at([state.time])[0]
        if coupled is not None:
            rows = np.arange(asm.n_full)
            minus_p = subtract_coupled_loads(coupled, coupled.shares(asm, rows), rows, np.array([coupled.time]),
                                             np.zeros((1, asm.n_full)))
            loads = loads - minus_p[0]
        if flag == "-rayleigh":
            # OpenSees (flag 2): Element::getRayleighDampingForces of *every* element, whether it
            # takes Rayleigh damping in the analysis or not (zeroLength, truss without -doRayleigh),
            # plus alphaM M v of the nodal masses (Node::resetReactionForce)
            alpha_m, beta_k = self.domain.rayleigh_factors
            r = alpha_m * (asm.M_full @ state.v) + beta_k * (asm.K_full @ state.v)
        elif flag == "-dynamic":
            r = asm.K_full @ state.u + asm.C_full @ state.v + asm.M_full @ state.a - loads
        else:
            own = np.zeros(asm.n_full)   # elements' resisting forces K u + C_el v
            for etype, _tags, coords, params, dofs in asm.blocks:
                f = np.asarray(etype.response("force", coords, params, state.u[dofs], state.v[dofs]))
                np.add.at(own, dofs, f)
            r = own - loads
        self._reactions = r

