"""The element-type contract and registry.

vtsi batches elements by type: one :class:`ElementType` object holds every element of its
type as arrays, and numba kernels compute all local matrices at once. Assembly scatters them
into CSR through a precomputed position map (:mod:`vtsi.assembly`), so no Python runs per
element once the model is built.

Contract of an element type
---------------------------
1. Class attributes:
   ``name`` (str, the command-layer name, e.g. ``'elasticBeamColumn'``);
   ``n_nodes`` (int, nodes per element);
   ``node_dofs`` (tuple of int, which of a node's dofs the element connects, 0 = ux, 1 = uy,
   2 = rz; the element dof vector is node 1's dofs then node 2's, so ``ndof = n_nodes * len(node_dofs)``);
   ``param_names`` (tuple of str, the columns of ``params``);
   ``positive`` (names that must be > 0), ``non_negative`` (names that must be >= 0),
   ``flags`` (names of switches that must be 0 or 1, e.g. ``cmass``);
   ``defaults`` (dict of default parameter values).
2. ``stiffness(coords, params)``, ``mass(coords, params)``: given ``coords (n_el, n_nodes, 2)``
   float64 [m] and ``params (n_el, n_par)`` float64, return numpy arrays ``(n_el, ndof, ndof)``
   float64 of symmetric matrices in **global** axes [N/m, N, N·m; kg, kg·m²]: stiffness with no
   negative diagonal entry, mass positive semi-definite. Override ``damping`` when the element
   has its own dashpots [N·s/m], positive semi-definite; the default is zero. Other real dtypes
   (float32, integers) are converted to float64; complex, bool or object arrays, lists and arrays
   of another shape are refused. Rayleigh damping is added by the model, not by the element; an
   element to be left out of it (OpenSees ``-doRayleigh 0``) defines ``rayleigh_weights(params)``,
   ``(n_el,)`` finite factors >= 0 (0 or 1 for the shipped types) on its stiffness in the βK term
   and on its mass in the αM term.
3. ``check_geometry(coords, tags, node_tags)`` raises :class:`~vtsi.errors.ModelError` for
   geometry the element cannot take (zero length...). Line elements inherit the check.
4. ``response(kind, coords, params, u_e, v_e)`` returns element forces ``(n_el, n_values)`` for
   ``kind`` in ``response_kinds`` (default: ``'force'``/``'globalForce'``: the global resisting
   force ``K u + C_el v`` at the element's dofs [N, N·m]). The element recorder computes
   ``'force'``/``'globalForce'`` from the matrices of the build without calling ``response``,
   and so any kind that ``end_force_response`` takes, as ``end_force_response(kind, coords,
   K u + C_el v)``: ``response`` must agree with both (the contract tests check it). On an
   element with element loads (``eleLoad``) the force kinds are corrected by the loads'
   fixed-end forces through ``end_force_response``, which refuses the kinds it cannot correct;
   the kinds in ``unloaded_responses`` (deformations, axes, stiffness: what element loads do not
   change) are read as ``response`` gives them.
5. Register with the :func:`register` decorator; ``Model.element(name, ...)`` then knows it.
   Kernels are pure functions of arrays (numba ``@njit(cache=True)``), float64 values and
   int64 indices. The kernels are called once per element type and per build (``Model.build``),
   on all its elements at once.
6. Optional, the OpenSees-style ``element`` command (:mod:`vtsi.opensees`, Tcl files):
   ``command_args`` (tuple of parameter names read in order after the ``n_nodes`` node tags;
   None: the type has no command) and ``command_options`` (dict: an option word -> the parameter
   that the number after it sets, or -> ``(parameter, value)`` for a flag). Responses
   (``eleResponse``, ``recorder Element``) are ``response_kinds`` with the columns of
   ``response``; ``command_layouts`` (dict: kind -> ``(source kind, [(column or -1, coefficient
   on the value, coefficient on its rate)], uses rates)``) rearranges them as OpenSees would.

What is checked where
---------------------
- :func:`register`, when the class is defined: the class attributes of item 1 exist and name
  known parameters, ``node_dofs`` among 0, 1, 2, ``command_args``/``command_options`` (item 6),
  ``stiffness`` and ``mass`` overridden, the name not taken by another class (TypeError).
- :meth:`ElementType.add`, per element: the node count, parameter names, numbers (a text is
  refused, :func:`vtsi.errors.as_number`, and a bool but for a flag, True as 1), finite,
  ``positive``/``non_negative``/``flags`` (ModelError naming the element).
- Each build (:class:`vtsi.assembly.Assembly`, :func:`element_matrices`), once per type: its
  ``check_geometry``; what its kernels return (item 2): a numpy array of real numbers of shape
  ``(n_el, ndof, ndof)``, finite, symmetric, no negative diagonal entry, mass and damping positive
  semi-definite, within :data:`MATRIX_RTOL` of each element's largest entry; ``rayleigh_weights``
  shape and values. A ModelError names the type, the element and what was expected and got. The
  cost is one numba pass per matrix, and a factorisation of each coupled mass or damping
  matrix: the build of 2000 beams takes 7.4 → 8.0 ms (+4 % lumped, +7.5 % consistent mass).
  A stiffness is not checked for semi-definiteness as a whole: the static and eigen analyses
  refuse a structure whose K is not positive definite when they factor it (AnalysisError naming
  the dof); a negative *diagonal* entry, though, is refused at the build: a linear elastic element
  stores energy ½ uᵀ K u >= 0, and a spring that pushes its own dof away is a sign error (a
  destabilising geometric stiffness, a P-Δ leaning column, belongs in the element whose stiffness
  it reduces, so that their sum has a non-negative diagonal).
- ``tests/test_element_contract.py``, for vtsi's own types and the registered types it has a
  sample of (``SAMPLES``): the properties no build can check cheaply: each element's matrices
  depend on its own row only, rigid-body modes in the null space of K and C, total mass,
  stiffness positive semi-definite, responses (item 4), parameter checks. A user's type without
  a sample there is skipped, so registering one does not break vtsi's tests; copy the tests
  (or add a sample) to check it.

A track (:class:`vtsi.track.Track`, the wheels of a train) takes any 2-node type with the dofs
(ux, uy, rz) on horizontal elements, and its wheel rows are the Euler-Bernoulli cubic Hermite
shape functions of the element's end dofs whatever the element is: exact for
``elasticBeamColumn``; for a shear-flexible beam (Timoshenko) or a beam on a foundation the
deflection under a wheel between the nodes is the Hermite interpolation of the end values, not
the element's own field (refine the mesh under the track).
"""
from typing import NamedTuple

import numpy as np
from numba import njit

from vtsi.errors import ModelError, as_number

from .kernels import matrix_defects, semidefinite_defects

ELEMENT_TYPES = {}

#: Tolerance of the build-time checks of element matrices (:func:`element_matrices`), relative to
#: each element's largest entry, on the asymmetry max|a − aᵀ|, on a negative diagonal entry and on
#: the distance from positive semi-definite. Kernels that write symmetric formulas out, or rotate
#: them (``rotate_to_global``), are symmetric to a few ulps (~1e-15); matrices a user computes by
#: quadrature or by inverting a flexibility matrix of condition number up to ~1e6 carry ~1e-10;
#: a defect below 1e-9 of the largest entry changes the response by that order, far below any
#: engineering meaning, while real mistakes (a sign, a transposed index, a typo) are 1e-3..1.
MATRIX_RTOL = 1e-9
DOF_NAMES = ("ux", "uy", "rz")


def register(cls):
    """Class decorator: validate the contract of an element type and make it known by name.

    A name belongs to one class; the same class defined again (a script or notebook cell run
    twice) replaces the old definition."""
    for attribute in ("name", "n_nodes", "node_dofs", "param_names"):
        if not hasattr(cls, attribute):
            raise TypeError(f"element type {cls.__name__}: missing class attribute {attribute!r}")
    for attribute in ("param_names", "positive", "non_negative", "flags"):
        names = getattr(cls, attribute)
        if isinstance(names, str) or not all(isinstance(n, str) for n in names):
            raise TypeError(f"element type {cls.__name__}: {attribute} must be a tuple of str, got {names!r}")
    unknown = (set(cls.positive) | set(cls.non_negative) | set(cls.flags) | set(cls.defaults)) - set(cls.param_names)
    if unknown:
        raise TypeError(f"element type {cls.__name__}: {sorted(unknown)} are not in param_names")
    if not isinstance(cls.name, str) or not cls.name:
        raise TypeError(f"element type {cls.__name__}: name must be a non-empty str, got {cls.name!r}")
    if any(d not in (0, 1, 2) for d in cls.node_dofs):
        raise TypeError(f"element type {cls.__name__}: node_dofs {cls.node_dofs} must be among 0, 1, 2")
    if cls.command_args is not None:
        named = list(cls.command_args) + [t[0] if isinstance(t, tuple) else t for t in cls.command_options.values()]
        if set(named) - set(cls.param_names):
            raise TypeError(f"element type {cls.__name__}: command_args/command_options name "
                            f"{sorted(set(named) - set(cls.param_names))}, which are not in param_names")
        if any(not (isinstance(o, str) and o.startswith("-")) for o in cls.command_options):
            raise TypeError(f"element type {cls.__name__}: command_options keys must be options like '-mass'")
    for method in ("stiffness", "mass"):
        if getattr(cls, method) is getattr(ElementType, method):
            raise TypeError(f"element type {cls.__name__}: must override {method}()")
    known = ELEMENT_TYPES.get(cls.name)
    redefined = known is not None and (known.__module__, known.__qualname__) == (cls.__module__, cls.__qualname__)
    if known is not None and known is not cls and not redefined:   # re-running a script redefines its class
        raise TypeError(f"element type name {cls.name!r} is already registered by {known.__module__}.{known.__qualname__}")
    ELEMENT_TYPES[cls.name] = cls
    return cls


def command_element_types():
    """``{name: class}`` of the registered types that declare an ``element`` command."""
    return {name: cls for name, cls in ELEMENT_TYPES.items() if cls.command_args is not None}


def element_type(name):
    """The registered element class called ``name``; the error lists the valid names."""
    try:
        return ELEMENT_TYPES[name]
    except KeyError:
        raise ModelError(f"unknown element type {name!r}; known types: {', '.join(sorted(ELEMENT_TYPES))}") from None


class ElementType:
    """Base class of a batch of elements of one type (see the module docstring for the contract)."""

    name = None
    n_nodes = 2
    node_dofs = (0, 1, 2)
    param_names = ()
    positive = ()
    non_negative = ()
    flags = ()
    defaults = {}
    response_kinds = ("force", "globalForce")
    unloaded_responses = ()
    command_args = None
    command_options = {}
    command_layouts = {}

    def __init__(self):
        self.tags = []
        self.nodes = []
        self._params = []

    @property
    def ndof(self):
        return self.n_nodes * len(self.node_dofs)

    def __len__(self):
        return len(self.tags)

    def add(self, tag, nodes, **params):
        """Append one element; parameters are checked here, geometry when the model is built."""
        if len(nodes) != self.n_nodes:
            raise ModelError(f"element {tag} ({self.name}): needs {self.n_nodes} nodes, got {len(nodes)}")
        unknown = set(params) - set(self.param_names)
        if unknown:
            raise ModelError(f"element {tag} ({self.name}): unknown parameter(s) {sorted(unknown)}; "
                             f"valid: {', '.join(self.param_names)}")
        values = []
        for pname in self.param_names:
            if pname in params:
                value = params[pname]
            elif pname in self.defaults:
                value = self.defaults[pname]
            else:
                raise ModelError(f"element {tag} ({self.name}): parameter {pname!r} is required")
            if pname in self.flags and isinstance(value, (bool, np.bool_)):
                value = float(value)                  # a flag: True or False as 1 or 0
            value = as_number(value, f"element {tag} ({self.name})", pname)   # not a text ('3e10'), nor a bool
            if not np.isfinite(value):
                raise ModelError(f"element {tag} ({self.name}): {pname} must be finite, got {value}")
            if pname in self.positive and value <= 0.0:
                raise ModelError(f"element {tag} ({self.name}): {pname} must be > 0, got {value:g}")
            if pname in self.non_negative and value < 0.0:
                raise ModelError(f"element {tag} ({self.name}): {pname} must be >= 0, got {value:g}")
            if pname in self.flags and value not in (0.0, 1.0):
                raise ModelError(f"element {tag} ({self.name}): {pname} must be 0 or 1, got {value:g}")
            values.append(value)
        self.tags.append(int(tag))
        self.nodes.append(tuple(int(n) for n in nodes))
        self._params.append(values)

    def remove(self, tag):
        i = self.tags.index(tag)
        for seq in (self.tags, self.nodes, self._params):
            del seq[i]

    @property
    def params(self):
        """``(n_el, n_par)`` float64 parameter table."""
        return np.array(self._params, dtype=np.float64).reshape(len(self.tags), len(self.param_names))

    def param(self, name):
        return self.params[:, self.param_names.index(name)]

    # -- kernels (override) ---------------------------------------------------------------
    def stiffness(self, coords, params):
        raise NotImplementedError

    def mass(self, coords, params):
        raise NotImplementedError

    def damping(self, coords, params):
        return np.zeros((len(params), self.ndof, self.ndof))

    def check_geometry(self, coords, tags, node_tags):
        """Line elements: nodes must not coincide (override for zero-length types)."""
        if self.n_nodes == 2:
            short = lengths_2d(coords) <= 1e-12 * max(1.0, abs(coords).max())
            if short.any():
                i = short.argmax()
                raise ModelError(f"element {tags[i]} ({self.name}): zero length between nodes "
                                 f"{node_tags[i][0]} and {node_tags[i][1]}")

    def response(self, kind, coords, params, u_e, v_e):
        """Element forces for a recorder or ``eleForce``; ``u_e, v_e`` are ``(n_el, ndof)``."""
        if kind in ("force", "globalForce"):
            return (np.einsum("eij,ej->ei", self.stiffness(coords, params), u_e)
                    + np.einsum("eij,ej->ei", self.damping(coords, params), v_e))
        raise ModelError(f"element type {self.name}: unknown response {kind!r}; "
                         f"valid: {', '.join(self.response_kinds)}")

    def equivalent_loads(self, coords, params, kind, values):
        """Optional (beams): the global nodal loads ``(ndof,)`` [N, N·m] equivalent to an element
        load (:meth:`vtsi.loads.LoadPattern.beam_load`) on one element (``coords (n_nodes, 2)``,
        ``params (n_par,)``); the element's end forces then lack these (fixed-end forces)."""
        raise ModelError(f"element type {self.name} takes no element loads (eleLoad): load its nodes instead")

    def end_force_response(self, kind, coords, forces):
        """The columns of response ``kind`` of global end forces ``forces (n_el, ndof)``, to
        correct a response by the fixed-end forces of element loads; default: 'force' and
        'globalForce' are the forces themselves."""
        if kind in ("force", "globalForce"):
            return forces
        raise ModelError(f"element type {self.name}: response {kind!r} of an element with element loads is not "
                         "available; record 'force' or 'globalForce'")


AXIS_RESPONSES = ("xaxis", "yaxis", "zaxis")


def axis_vectors(kind, c, s):
    """Response ``kind`` in :data:`AXIS_RESPONSES` of elements whose local x axis has the
    direction cosines ``c, s`` ``(n_el,)``: that local axis's unit vector ``(n_el, 3)`` in global
    axes (OpenSees's ``xaxis``, ``yaxis``, ``zaxis``; y is x turned 90° anticlockwise)."""
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack({"xaxis": (c, s, zero), "yaxis": (-s, c, zero), "zaxis": (zero, zero, one)}[kind], axis=1)


@njit(cache=True)
def lengths_2d(coords):
    """Lengths ``(n_el,)`` [m] of 2-node line elements (``coords (n_el, 2, 2)``)."""
    length = np.empty(coords.shape[0])
    for e in range(coords.shape[0]):
        length[e] = np.hypot(coords[e, 1, 0] - coords[e, 0, 0], coords[e, 1, 1] - coords[e, 0, 1])
    return length


@njit(cache=True)
def rotation_2d(coords):
    """Direction cosines and lengths of 2-node line elements: ``(c, s, L)`` each ``(n_el,)``
    (of nonzero length: :meth:`ElementType.check_geometry`)."""
    length = lengths_2d(coords)
    c, s = np.empty(coords.shape[0]), np.empty(coords.shape[0])
    for e in range(coords.shape[0]):
        c[e] = (coords[e, 1, 0] - coords[e, 0, 0]) / length[e]
        s[e] = (coords[e, 1, 1] - coords[e, 0, 1]) / length[e]
    return c, s, length


class ElementMatrices(NamedTuple):
    """The checked matrices of one block of elements, ``(n_el, ndof, ndof)`` float64
    C-contiguous each, in global axes: ``stiffness`` [N/m, N, N·m], ``mass`` [kg, kg·m²],
    ``damping`` (the element's own dashpots, not Rayleigh) [N·s/m]."""
    stiffness: np.ndarray
    mass: np.ndarray
    damping: np.ndarray


def _where(etype, tags, e):
    return f"element type {etype.name} (element {int(tags[e])})"


def _dof_label(etype, i):
    """``'uy of node 2'`` for row ``i`` of an element matrix of ``etype``."""
    per_node = len(etype.node_dofs)
    return f"{DOF_NAMES[etype.node_dofs[i % per_node]]} of node {i // per_node + 1}"


def checked_matrix(etype, what, value, tags, params=None):
    """``value``, what ``etype``'s kernel ``what`` ('stiffness', 'mass', 'damping') returned for
    the elements ``tags``, as a C-contiguous float64 ``(n_el, ndof, ndof)`` array, or a
    :class:`ModelError` naming the type and the first element at fault.

    Checked: a numpy array of real numbers (float of any width and integers are converted to
    float64; complex, bool and object arrays, lists and scalars are refused), of shape
    ``(n_el, ndof, ndof)``, finite, symmetric, no negative diagonal entry (all within
    :data:`MATRIX_RTOL` of each element's largest entry); mass and damping positive
    semi-definite. One compiled call per block, :func:`_defective` (20 beams: ~3 µs; 2000 beams:
    ~0.07 ms, a consistent mass ~0.2 ms); the message is built only for a block that fails."""
    n_el, nd = len(tags), etype.ndof
    if not (isinstance(value, np.ndarray) and value.dtype.kind in "fiu" and value.shape == (n_el, nd, nd)):
        expected = f"(n_el, {nd}, {nd}) = ({n_el}, {nd}, {nd}) float64"
        if not isinstance(value, np.ndarray):
            raise ModelError(f"{_where(etype, tags, 0)}: {what} must be {expected} (a numpy array), "
                             f"got {type(value).__name__}")
        real = "" if value.dtype.kind in "fiu" else " (real numbers)"
        raise ModelError(f"{_where(etype, tags, 0)}: {what} must be {expected}{real}, got {value.shape} {value.dtype}")
    value = np.ascontiguousarray(value, dtype=np.float64)
    if _defective(value, MATRIX_RTOL, what != "stiffness"):
        _refuse_defect(etype, what, value, tags, params)
    return value


@njit(cache=True)
def _defective(matrices, rtol, semidefinite):
    """Whether an element matrix of ``matrices (n_el, nd, nd)`` fails a check of
    :func:`checked_matrix` (:func:`_refuse_defect` names which), in one compiled call:
    :func:`~vtsi.elements.kernels.matrix_defects`, then
    :func:`~vtsi.elements.kernels.semidefinite_defects` when ``semidefinite`` (mass, damping) and
    every matrix passed the first."""
    nonfinite, scale, asymmetry, min_diagonal, _ = matrix_defects(matrices)
    for e in range(matrices.shape[0]):
        tol = rtol * scale[e]
        if nonfinite[e] >= 0 or asymmetry[e] > tol or min_diagonal[e] < -tol:
            return True
    return semidefinite and np.any(semidefinite_defects(matrices, rtol) > 0.0)


def _refuse_defect(etype, what, value, tags, params):
    """Raise the ModelError for the first defect :func:`_defective` found in ``value`` (float64
    ``(n_el, ndof, ndof)``): a non-finite entry, asymmetry, a negative diagonal entry, then a
    mass or damping not positive semi-definite, naming the type and the element."""
    nd = etype.ndof
    nonfinite, scale, asymmetry, min_diagonal, min_at = matrix_defects(value)
    bad = np.flatnonzero(nonfinite >= 0)
    if len(bad):
        e = bad[0]
        i, j = divmod(int(nonfinite[e]), nd)
        named = "" if params is None else f" (its parameters {dict(zip(etype.param_names, params[e].tolist()))})"
        raise ModelError(f"{_where(etype, tags, e)}: {what} has a non-finite entry {value[e, i, j]} at row {i}, "
                         f"column {j}{named}: the element's kernel returned it (an overflow or a division by zero)")
    tol = MATRIX_RTOL * scale
    bad = np.flatnonzero(asymmetry > tol)
    if len(bad):
        e = bad[0]
        raise ModelError(f"{_where(etype, tags, e)}: {what} is not symmetric: max |A - Aᵀ| = {asymmetry[e]:.6g} "
                         f"is {asymmetry[e] / scale[e]:.3g} of max |A| = {scale[e]:.6g} (tolerance {MATRIX_RTOL:g}); "
                         "the solvers take symmetric matrices and would use one triangle")
    bad = np.flatnonzero(min_diagonal < -tol)
    if len(bad):
        e = bad[0]
        row = int(min_at[e])
        raise ModelError(f"{_where(etype, tags, e)}: {what} has a negative diagonal entry {min_diagonal[e]:.6g} "
                         f"(row {row}, {_dof_label(etype, row)}): a physical {what} matrix has no negative diagonal "
                         "entry (a sign error in the kernel?)")
    e = np.flatnonzero(semidefinite_defects(value, MATRIX_RTOL) > 0.0)[0]
    eig = np.linalg.eigvalsh(value[e])
    raise ModelError(f"{_where(etype, tags, e)}: {what} is not positive semi-definite: eigenvalues "
                     f"{eig.min():.6g} to {eig.max():.6g} (tolerance {MATRIX_RTOL:g} of max |A|)")


def element_matrices(etype, coords, params, tags):
    """The :class:`ElementMatrices` of a block: ``etype``'s kernels called once each on all its
    elements (``coords (n_el, n_nodes, 2)``, ``params (n_el, n_par)``, element ``tags``) and
    checked (:func:`checked_matrix`). :class:`vtsi.assembly.Assembly` calls it once per block and
    per build and keeps the result (``Assembly.element_matrices``)."""
    return ElementMatrices(*(checked_matrix(etype, what, getattr(etype, what)(coords, params), tags, params)
                             for what in ElementMatrices._fields))


def element_rayleigh_weights(etype, params, tags):
    """``etype.rayleigh_weights(params)`` checked: ``(n_el,)`` real, finite, >= 0 (float64, a
    list or an integer array converted), else a :class:`ModelError` naming the type and element;
    ones when the type defines no ``rayleigh_weights``."""
    n_el = len(tags)
    if not hasattr(etype, "rayleigh_weights"):
        return np.ones(n_el)
    value = etype.rayleigh_weights(params)
    expected = f"(n_el,) = ({n_el},) float64 factors >= 0, one per element"
    try:
        array = np.asarray(value) if isinstance(value, (np.ndarray, list, tuple)) else None
    except ValueError:                          # a ragged list
        array = None
    if array is None or array.dtype.kind not in "fiu" or array.shape != (n_el,):
        got = f"{array.shape} {array.dtype}" if array is not None else type(value).__name__
        raise ModelError(f"{_where(etype, tags, 0)}: rayleigh_weights must be {expected}, got {got}")
    array = np.ascontiguousarray(array, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(array) | (array < 0.0))
    if len(bad):
        raise ModelError(f"{_where(etype, tags, bad[0])}: rayleigh_weights must be finite and >= 0, "
                         f"got {array[bad[0]]}")
    return array
