"""The model: nodes, fixities, masses, elements, time series, load patterns and damping.

Built through this object API or through the OpenSees-style commands of :mod:`vtsi.opensees`;
every call validates its input and raises :class:`~vtsi.errors.ModelError` naming the object
and the value at fault. :meth:`Model.build` numbers the dofs and assembles the matrices
(cached until the model changes).
"""
import numpy as np

from vtsi.assembly import Assembly
from vtsi.elements import element_type  # the package: importing it registers the element library
from vtsi.errors import ModelError, as_flag, as_number, is_int, number_array
from vtsi.loads import LoadPattern, UniformExcitation
from vtsi.timeseries import TimeSeries


class Model:
    """A 2-D structural model (``ndm = 2``, ``ndf = 3``: ux, uy, rz; SI units).

    Examples
    --------
    >>> m = Model()
    >>> m.node(1, 0.0, 0.0); m.node(2, 10.0, 0.0)
    >>> m.fix(1, 1, 1, 0); m.fix(2, 0, 1, 0)
    >>> m.element("elasticBeamColumn", 1, (1, 2), A=1.0, E=3e10, I=2.0, rho=1e4, cmass=1)
    """

    def __init__(self, ndm=2, ndf=3):
        if ndm != 2 or ndf not in (2, 3):
            raise ModelError(f"model: only ndm 2 with ndf 2 or 3 is supported, got ndm {ndm} ndf {ndf}")
        self.ndm, self.ndf = ndm, ndf
        self.nodes = {}
        self.fixities = {}
        self.mp_constraints = {}    # (constrained node, dof 0-based) -> [(retained node, dof, coefficient)]
        self.nodal_mass = {}
        self.element_types = {}
        self._element_owner = {}
        self.time_series = {}
        self.patterns = {}
        self.load_version = 0       # counts the changes of the patterns (their loads, factors, freezing)
        self.rayleigh_factors = (0.0, 0.0)
        self.rayleigh_every_element = False     # Rayleigh on the elements with do_rayleigh 0 too (rayleigh)
        self._assembly = None

    def __repr__(self):
        types = ", ".join(f"{len(et)} {name}" for name, et in self.element_types.items() if len(et))
        return (f"Model(ndm={self.ndm}, ndf={self.ndf}: {len(self.nodes)} nodes, {len(self._element_owner)} elements"
                f"{f' ({types})' if types else ''}, {sum(map(any, self.fixities.values()))} fixed nodes, "
                f"{len(self.mp_constraints)} constrained dofs, {len(self.time_series)} time series, "
                f"{len(self.patterns)} load patterns)")

    # -- definition -----------------------------------------------------------------------
    def _changed(self):
        self._assembly = None

    def _loads_changed(self):
        self.load_version += 1

    def _add_pattern(self, pattern):
        self.patterns[pattern.tag] = pattern
        pattern.on_change, pattern.ndf = self._loads_changed, self.ndf
        self._loads_changed()
        return pattern

    def node(self, tag, *coords, mass=None):
        """Add node ``tag`` at ``coords = (x, y)`` [m] (x along the bridge, y up); ``mass``
        optionally its nodal masses, one per dof, as :meth:`mass` takes them.

        Raises ModelError if ``tag`` is not an integer in OpenSees's int range or already
        exists, or if the coordinates are not ``ndm`` finite numbers, or the masses are invalid
        (then the node is not added)."""
        tag = _tag("node", tag)
        if tag in self.nodes:
            raise ModelError(f"node {tag} already exists")
        if len(coords) != self.ndm:
            raise ModelError(f"node {tag}: needs {self.ndm} coordinates, got {len(coords)}")
        xy = number_array(coords)
        if xy is None:              # a text ('0.0'), a bool: a value not converted
            raise ModelError(f"node {tag}: coordinates must be numbers, got {list(coords)!r}")
        if not np.all(np.isfinite(xy)):
            raise ModelError(f"node {tag}: coordinates must be finite, got {xy.tolist()}")
        if mass is not None:
            mass = _nodal_mass(tag, mass, self.ndf)   # checked before the node is added
        self.nodes[tag] = xy
        if mass is not None:
            self.nodal_mass[tag] = mass
        self._changed()

    def _node(self, tag, what):
        return _existing(self.nodes, "node", tag, what)

    def fix(self, tag, *flags):
        """Fix dofs of node ``tag`` (OpenSees ``fix``): one flag per dof (ux, uy[, rz]), 1 fixed,
        0 free. Fixities add up over calls (a later 0 does not free a dof fixed before), each dof
        fixed once: ``fix(1, 1, 0, 0); fix(1, 0, 1, 0)`` fixes ux and uy.

        Raises ModelError if the node does not exist, the flags are not ``ndf`` values of 0 or
        1 (not bools), or a dof to fix is already fixed (as OpenSees, whose ``Domain::addSP_Constraint``
        refuses a second constraint on a dof), constrained by equalDOF/rigidLink or prescribed
        (``sp``); the node's fixity is then left as it was."""
        self._node(tag, "fix")
        if len(flags) != self.ndf or any(isinstance(f, (bool, np.bool_)) or f not in (0, 1) for f in flags):
            raise ModelError(f"fix node {tag}: needs {self.ndf} flags of 0 or 1, got {list(flags)}")
        old = self.fixities.get(tag, (0,) * self.ndf)
        for d, f in enumerate(flags):
            if f and old[d]:
                raise ModelError(f"fix node {tag}: dof {d + 1} is already fixed (a second fix of a dof is refused, "
                                 "as OpenSees); fix each dof once, with 0 for the dofs fixed before")
            if f and (tag, d) in self.mp_constraints:
                raise ModelError(f"fix node {tag}: dof {d + 1} is constrained (equalDOF/rigidLink); it cannot also be fixed")
            prescribed = [p.tag for p in self.patterns.values() if (tag, d) in p.prescribed]
            if f and prescribed:
                raise ModelError(f"fix node {tag}: dof {d + 1} has a prescribed displacement (sp in pattern "
                                 f"{prescribed[0]}); it cannot also be fixed")
        self.fixities[tag] = tuple(int(a or b) for a, b in zip(old, flags))
        self._changed()

    def equal_dof(self, retained, constrained, *dofs):
        """``u(constrained, d) = u(retained, d)`` for each 1-based dof ``d`` (OpenSees ``equalDOF``)."""
        self._node(retained, "equalDOF")
        self._node(constrained, "equalDOF")
        if retained == constrained:
            raise ModelError(f"equalDOF: retained and constrained node are both {retained}")
        if not dofs or any(not is_int(d) or d not in range(1, self.ndf + 1) for d in dofs):
            raise ModelError(f"equalDOF {retained} {constrained}: dofs must be among 1..{self.ndf}, got {list(dofs)}")
        self._constrain(constrained, {d - 1: [(retained, d - 1, 1.0)] for d in dofs}, f"equalDOF {retained} {constrained}")

    def rigid_link(self, kind, master, slave):
        """A rigid link from ``master`` to ``slave`` (OpenSees ``rigidLink``): ``'bar'`` equal
        translations; ``'beam'`` (ndf 3) a rigid body, ``u_s = u_m − (y_s − y_m) θ_m``,
        ``v_s = v_m + (x_s − x_m) θ_m``, ``θ_s = θ_m``."""
        what = f"rigidLink {kind} {master} {slave}"
        self._node(master, "rigidLink")
        self._node(slave, "rigidLink")
        if master == slave:
            raise ModelError(f"{what}: master and slave are the same node")
        if kind == "bar":
            rows = {0: [(master, 0, 1.0)], 1: [(master, 1, 1.0)]}
        elif kind == "beam":
            if self.ndf != 3:
                raise ModelError(f"{what}: a beam link needs 3 dofs per node (the model has {self.ndf})")
            dx, dy = self.nodes[slave] - self.nodes[master]
            rows = {0: [(master, 0, 1.0), (master, 2, -dy)], 1: [(master, 1, 1.0), (master, 2, dx)],
                    2: [(master, 2, 1.0)]}
        else:
            raise ModelError(f"rigidLink: type {kind!r} is not supported; supported: bar, beam")
        self._constrain(slave, rows, what)

    def _constrain(self, node, rows, what):
        for d in rows:
            if (node, d) in self.mp_constraints:
                raise ModelError(f"{what}: node {node} dof {d + 1} is already constrained")
            if self.fixities.get(node, (0,) * self.ndf)[d]:
                raise ModelError(f"{what}: node {node} dof {d + 1} is fixed; it cannot also be constrained")
        for d, row in rows.items():
            self.mp_constraints[(node, d)] = [(int(n), int(k), float(c)) for n, k, c in row]
        self._changed()

    def mass(self, tag, *values):
        """Lumped nodal mass of node ``tag`` (OpenSees ``mass``): one value per dof, ``(m_x, m_y[,
        I_z])`` [kg, kg, kg·m²], finite and >= 0. Replaces the node's earlier nodal mass (it does
        not add to it, nor to the element masses, which are assembled separately).

        Raises ModelError if the node does not exist or the values are not ``ndf`` finite
        numbers >= 0."""
        self._node(tag, "mass")
        self.nodal_mass[tag] = _nodal_mass(tag, values, self.ndf)
        self._changed()

    def element(self, type_name, tag, nodes, **params):
        """Add element ``tag`` (an integer not yet taken) of the registered type ``type_name`` on
        ``nodes`` (a sequence of existing node tags, as many as the type takes), with the type's
        parameters by name in SI units (its class docstring lists them, e.g.
        ``'elasticBeamColumn'``: ``A`` [m²], ``E`` [Pa], ``I`` [m⁴], ``rho`` mass per length
        [kg/m], ``cmass`` 0 lumped or 1 consistent; the types: ``'elasticBeamColumn'``,
        ``'ElasticTimoshenkoBeam'``, ``'truss'``, ``'zeroLength'``, ``'pointMass'`` and any a user
        registers, :mod:`vtsi.elements.base`). Parameters are checked here, the geometry when
        the model is built.

        Raises ModelError if the tag is taken or not an integer, the type is unknown (the message
        lists the known ones), ``nodes`` is not a sequence or names a missing node, the type
        needs a dof the model lacks (``ndf``), or a parameter is unknown, missing, not finite or
        out of its range."""
        tag = _tag("element", tag)
        if tag in self._element_owner:
            raise ModelError(f"element {tag} already exists")
        cls = element_type(type_name)
        if isinstance(nodes, (int, np.integer)) or not hasattr(nodes, "__len__"):
            raise ModelError(f"element {tag} ({type_name}): nodes must be a sequence of node tags, got {nodes!r}")
        if max(cls.node_dofs) >= self.ndf:
            raise ModelError(f"element {tag} ({type_name}): needs node dofs {[d + 1 for d in cls.node_dofs]}, "
                             f"but the model has ndf {self.ndf}")
        for n in nodes:
            _existing(self.nodes, "node", n, f"element {tag} ({type_name})")
        etype = self.element_types.setdefault(type_name, cls())
        etype.add(tag, nodes, **params)
        self._element_owner[tag] = etype
        self._changed()

    def remove_element(self, tag):
        """Remove element ``tag`` (OpenSees ``remove element``); its nodes stay. An element load
        on it left in a pattern is refused when the model is next built (ModelError).

        Raises ModelError if the element does not exist."""
        self._element_owner.pop(_existing(self._element_owner, "element", tag, "remove element")).remove(tag)
        self._changed()

    def add_time_series(self, series):
        """Register ``series`` (a :class:`~vtsi.timeseries.TimeSeries` with an integer ``tag``)
        so that patterns can name it by its tag; returns ``series``.

        Raises ModelError if ``series`` is not a TimeSeries, its tag is not an integer (e.g.
        None) or a series with that tag already exists."""
        if not isinstance(series, TimeSeries):
            raise ModelError(f"timeSeries: expected a TimeSeries, got {series!r}")
        _tag("timeSeries", series.required_tag())   # None: a message saying how to give the tag
        if series.tag in self.time_series:
            raise ModelError(f"timeSeries {series.tag} already exists")
        self.time_series[series.tag] = series
        return series

    def pattern(self, tag, series, factor=1.0):
        """Create and return load pattern ``tag`` (an integer not yet taken; OpenSees ``pattern Plain``),
        a :class:`~vtsi.loads.LoadPattern` whose loads (:meth:`load`, :meth:`beam_load`,
        :meth:`sp`) act times ``factor × series(t)`` [–]; ``series`` a
        :class:`~vtsi.timeseries.TimeSeries` or the tag of one added with
        :meth:`add_time_series`; ``factor`` finite.

        Raises ModelError if the tag is taken or not an integer, the series tag is unknown, or
        ``factor`` is not finite."""
        tag, series = self._new_pattern(tag, series)
        return self._add_pattern(LoadPattern(tag, series, factor))

    def uniform_excitation(self, tag, direction, series, factor=1.0):
        """Create and return a :class:`~vtsi.loads.UniformExcitation` (ground acceleration
        ``factor * series(t)`` [m/s²] along dof ``direction``)."""
        tag, series = self._new_pattern(tag, series)
        return self._add_pattern(UniformExcitation(tag, direction, series, factor))

    def _new_pattern(self, tag, series):
        """A new pattern's tag (checked free) and its series (a TimeSeries, or resolved from its tag)."""
        tag = _tag("pattern", tag)
        if tag in self.patterns:
            raise ModelError(f"pattern {tag} already exists")
        if not isinstance(series, TimeSeries):
            series = self.time_series[_existing(self.time_series, "time series", series, f"pattern {tag}")]
        return tag, series

    def load(self, pattern_tag, node, *values):
        """Nodal load ``(F_x, F_y[, M_z])`` [N, N, N·m] on ``node`` in pattern ``pattern_tag``
        (OpenSees ``load``), scaled by the pattern's ``factor × series(t)``; positive along +x,
        +y (up) and counter-clockwise. Loads on the same node in the same pattern add up.

        Raises ModelError if the pattern or node does not exist, the values are not ``ndf``
        finite numbers, or the pattern takes no nodal loads (a UniformExcitation)."""
        _existing(self.patterns, "pattern", pattern_tag, "load")
        self._node(node, f"load in pattern {pattern_tag}")
        if len(values) != self.ndf:
            raise ModelError(f"load on node {node}: needs {self.ndf} values, got {len(values)}")
        self.patterns[pattern_tag].load(node, *values)

    def beam_load(self, pattern_tag, element, kind, *values):
        """An element load on beam ``element`` in pattern ``pattern_tag``: ``'uniform'`` ``(w_y[,
        w_x])`` [N/m] or ``'point'`` ``(P_y, x/L[, P_x])`` [N], in element axes, the axial part 0
        when not given (:meth:`vtsi.loads.LoadPattern.beam_load`; OpenSees ``eleLoad``)."""
        _existing(self.patterns, "pattern", pattern_tag, "beam_load")
        _existing(self._element_owner, "element", element, f"beam_load in pattern {pattern_tag}")
        self.patterns[pattern_tag].beam_load(element, kind, *values)

    def sp(self, pattern_tag, node, dof, value):
        """A prescribed displacement ``value × factor(t)`` [m, rad] of ``node``'s 1-based ``dof``
        in pattern ``pattern_tag`` (OpenSees ``sp``): the dof is then constrained like a fixed
        one, and its motion loads the free dofs through the stiffness (``−K_fc u_c``), as
        OpenSees's Transformation handler does (the moving support's velocity and acceleration
        stay 0, so no damping or inertia coupling: for a support motion with inertia, use
        ``uniform_excitation``)."""
        _existing(self.patterns, "pattern", pattern_tag, "sp")
        self._node(node, f"sp in pattern {pattern_tag}")
        if not (is_int(dof) and 1 <= dof <= self.ndf):
            raise ModelError(f"sp node {node}: dof must be 1..{self.ndf}, got {dof!r}")
        value = as_number(value, f"sp node {node} dof {dof}", "value")
        if not np.isfinite(value):
            raise ModelError(f"sp node {node} dof {dof}: value must be finite, got {value}")
        if self.fixities.get(node, (0,) * self.ndf)[dof - 1] or (node, dof - 1) in self.mp_constraints:
            raise ModelError(f"sp node {node} dof {dof}: the dof is already fixed or constrained")
        if any((node, dof - 1) in p.prescribed for p in self.patterns.values()):
            raise ModelError(f"sp node {node} dof {dof}: the dof already has a prescribed displacement")
        self.patterns[pattern_tag].prescribed[(node, dof - 1)] = value
        self._loads_changed()
        self._changed()

    def remove_node(self, tag):
        """Remove node ``tag`` with its fixity and mass; refused while an element, a constraint
        or a load uses it."""
        self._node(tag, "remove node")
        users = [f"element {e}" for et in self.element_types.values() for e, nodes in zip(et.tags, et.nodes)
                 if tag in nodes]
        users += [f"a constraint on node {n}" for (n, _), row in self.mp_constraints.items()
                  if n == tag or any(r == tag for r, _, _ in row)]
        users += [f"pattern {p.tag}" for p in self.patterns.values() if tag in p.nodal or
                  any(n == tag for n, _ in p.prescribed)]
        if users:
            raise ModelError(f"remove node {tag}: used by {users[0]}; remove that first")
        del self.nodes[tag]
        self.fixities.pop(tag, None)
        self.nodal_mass.pop(tag, None)
        self._changed()

    def remove_time_series(self, tag):
        """Forget series ``tag`` (the patterns made with it keep it, as in OpenSees)."""
        del self.time_series[_existing(self.time_series, "series", tag, "remove timeSeries")]

    def remove_sp(self, node, dof, pattern_tag=None):
        """Free ``node``'s 1-based ``dof``: without ``pattern_tag`` its ``fix`` if it is fixed
        (OpenSees's ``remove sp``: the domain's single-point constraint; a later ``fix`` may fix
        it again), else its prescribed displacement (in ``pattern_tag``, or in whichever pattern
        holds it)."""
        flags = self.fixities.get(node)
        if pattern_tag is None and flags is not None and 1 <= dof <= len(flags) and flags[dof - 1]:
            self.fixities[node] = tuple(0 if d == dof - 1 else f for d, f in enumerate(flags))
            self._changed()
            return
        holders = [p for p in self.patterns.values() if (node, dof - 1) in p.prescribed
                   and (pattern_tag is None or p.tag == pattern_tag)]
        if not holders:
            raise ModelError(f"remove sp: node {node} dof {dof} has no prescribed displacement"
                             + (f" in pattern {pattern_tag}" if pattern_tag is not None else ""))
        del holders[0].prescribed[(node, dof - 1)]
        self._loads_changed()
        self._changed()

    def remove_mp(self, node):
        """Remove the equalDOF / rigidLink constraints of constrained node ``node``."""
        keys = [k for k in self.mp_constraints if k[0] == node]
        if not keys:
            raise ModelError(f"remove mp: node {node} has no equalDOF/rigidLink constraint")
        for k in keys:
            del self.mp_constraints[k]
        self._changed()

    def remove_pattern(self, tag):
        """Remove load pattern ``tag`` with its loads and prescribed displacements (OpenSees
        ``remove loadPattern``); its time series stays registered.

        Raises ModelError if the pattern does not exist."""
        pattern = self.patterns.pop(_existing(self.patterns, "pattern", tag, "remove loadPattern"))
        pattern.on_change = None
        self._loads_changed()
        if pattern.prescribed:      # its sp dofs were constrained: number the dofs again
            self._changed()

    def rayleigh(self, alpha_m, beta_k, beta_k_init=0.0, beta_k_comm=0.0, *, every_element=False):
        """Rayleigh damping ``C = alpha_m M + (beta_k + beta_k_init + beta_k_comm) K`` (OpenSees
        ``rayleigh αM βK βKinit βKcomm``; a linear model: current, initial and committed
        stiffness coincide, so the three β add up): ``alpha_m`` αM [1/s], the ``beta_*`` βK [s],
        all finite and >= 0 (ModelError otherwise). The damping ratio at circular frequency ω
        [rad/s] is ζ(ω) = αM/(2ω) + βK ω/2 (:func:`vtsi.damping.rayleigh_coefficients` gives the
        pair for a ratio at two frequencies). Replaces earlier factors. The nodal masses are in
        the αM term; elements with ``do_rayleigh=0`` (the default of ``truss`` and
        ``zeroLength``) are in neither term, their own dashpots kept, as in OpenSees; with
        ``every_element`` every element is in both (C = αM M + βK K of the whole model, each mode
        damped at exactly ζ(ω): :func:`vtsi.damping.rayleigh_damping`)."""
        given = {"alpha_m": alpha_m, "beta_k": beta_k, "beta_k_init": beta_k_init, "beta_k_comm": beta_k_comm}
        values = np.array([as_number(value, "rayleigh", name) for name, value in given.items()])
        if not np.all(np.isfinite(values)) or np.any(values < 0):
            raise ModelError(f"rayleigh: factors must be finite and >= 0, got {values.tolist()}")
        self.rayleigh_factors = (values[0], values[1] + values[2] + values[3])
        self.rayleigh_every_element = as_flag(every_element, "rayleigh", "every_element")
        self._changed()

    # -- assembly -------------------------------------------------------------------------
    def build(self):
        """Number the dofs and assemble K, M, C (cached until the model changes)."""
        if self._assembly is None:
            self._assembly = Assembly(self)
        return self._assembly

    def element_tags(self):
        """The tags of the model's elements, of every type, in ascending order (a new list)."""
        return sorted(self._element_owner)


def _nodal_mass(tag, values, ndf):
    """``values`` as ``ndf`` finite masses >= 0 [kg, kg m^2], or a ModelError naming node ``tag``."""
    given, values = values, number_array(values)
    if values is None:          # a text ('1000'), a bool: a value not converted
        raise ModelError(f"mass node {tag}: masses must be numbers, got {given!r}")
    values = values.ravel()
    if len(values) != ndf or not np.all(np.isfinite(values)) or np.any(values < 0):
        raise ModelError(f"mass node {tag}: needs {ndf} finite values >= 0, got {values.tolist()}")
    return values


def _existing(table, kind, tag, what):
    """``tag`` if it is a key of ``table`` (the model's nodes, elements, series or patterns),
    else a ModelError ``'{what}: {kind} {tag} does not exist'``; a bool or a text is no tag
    (True would be found as 1, '3' would be named as 3)."""
    if not is_int(tag):
        raise ModelError(f"{what}: {kind} tag must be an integer, got {tag!r}")
    if tag not in table:
        raise ModelError(f"{what}: {kind} {tag} does not exist")
    return tag


def _tag(kind, tag):
    """A tag as an int: an integer of OpenSees's (C int) range."""
    if isinstance(tag, (bool, np.bool_)) or not isinstance(tag, (int, np.integer)):
        raise ModelError(f"{kind} tag must be an integer, got {tag!r}")
    if not -2 ** 31 <= tag < 2 ** 31:
        raise ModelError(f"{kind} tag must be an integer from -2147483648 to 2147483647 (OpenSees's int), got {tag}")
    return int(tag)
