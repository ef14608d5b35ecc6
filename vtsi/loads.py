"""Load patterns: nodal loads scaled by a time series (OpenSees ``pattern Plain``)."""
import math

import numpy as np

from vtsi.errors import ModelError, as_number, number_array
from vtsi.timeseries import TimeSeries

ELEMENT_LOADS = {"uniform": ("w_y", "w_x"), "point": ("P_y", "x/L", "P_x")}
"""The values of each kind of element load, in order (OpenSees ``eleLoad -beamUniform Wy [Wx]``,
``-beamPoint Py xL [Px]``); the last, axial, is optional: 0 when not given
(:func:`element_load_values`)."""


class LoadPattern:
    """Nodal loads ``[Fx, Fy, Mz]`` [N, N·m] times ``factor * series(t)``.

    Loads on the same node add up (as in OpenSees). ``ground_direction`` (None here): see
    :class:`UniformExcitation`.
    """

    ground_direction = None

    def __init__(self, tag, series, factor=1.0):
        if not isinstance(series, TimeSeries):
            raise ModelError(f"pattern {tag}: time series must be a TimeSeries, got {series!r}")
        self.tag, self.series, self._factor = tag, series, _finite(tag, "factor", factor)
        self.nodal = {}
        self.element_loads = []     # (element tag, 'uniform' (w_y, w_x) | 'point' (P_y, x/L, P_x))
        self.prescribed = {}        # (node, dof 0-based) -> displacement [m, rad] at factor 1 (OpenSees sp)
        self.version = 0            # counts the changes of the loads, factor and freezing (analyses cache them)
        self._constant_time = None
        self.on_change = None       # set by the owning model: called after every change
        self.ndf = None             # set by the owning model: values per nodal load

    def _changed(self):
        self.version += 1
        if self.on_change is not None:
            self.on_change()

    @property
    def factor(self):
        """The pattern's scale on its series [-]."""
        return self._factor

    @factor.setter
    def factor(self, value):
        self._factor = _finite(self.tag, "factor", value)
        self._changed()

    @property
    def constant_time(self):
        """None, or the time [s] at which ``loadConst`` froze the factor."""
        return self._constant_time

    @constant_time.setter
    def constant_time(self, value):
        self._constant_time = None if value is None else _finite(self.tag, "constant_time", value)
        self._changed()

    def snapshot(self):
        """A detached copy of the pattern as it is now: its factor, freezing and series, and its
        own copies of its loads, owned by no model (later changes of this pattern leave it as it
        was). A shallow copy by hand: ``copy.copy`` costs four times as much."""
        kept = object.__new__(type(self))
        kept.__dict__.update(self.__dict__)
        kept.nodal, kept.element_loads, kept.prescribed = dict(self.nodal), list(self.element_loads), dict(self.prescribed)
        kept.on_change = None
        return kept

    def load(self, node, *values):
        """Nodal load ``(Fx, Fy[, Mz])`` [N, N·m] on ``node``: one value per dof of the model."""
        given, values = values, number_array(values)
        if values is None:          # a text ('-1e3'), a bool: a value not converted
            raise ModelError(f"pattern {self.tag}: load on node {node} must be numbers, got {list(given)!r}")
        if self.ndf is not None and values.shape != (self.ndf,):
            raise ModelError(f"pattern {self.tag}: load on node {node}: needs {self.ndf} values, got {len(values)}")
        if not all(map(math.isfinite, values.ravel().tolist())):     # (numpy's isfinite costs more on ndf values)
            raise ModelError(f"pattern {self.tag}: load on node {node} has NaN or inf: {values.tolist()}")
        old = self.nodal.get(node)
        self.nodal[node] = values + 0.0 if old is None else old + values     # (+ 0.0: a -0.0 load is 0.0)
        self._changed()

    def beam_load(self, element, kind, *values):
        """A load on beam ``element`` (OpenSees ``eleLoad``), in element axes: ``'uniform'``
        ``(w_y[, w_x])`` [N/m] (transverse, axial from node i to j) or ``'point'`` ``(P_y, x/L[,
        P_x])`` [N] at the fraction ``x/L`` of the length from node i; the axial part is 0 when
        not given, as OpenSees's. Loads on the same element add up."""
        if isinstance(element, (bool, np.bool_)) or not isinstance(element, (int, np.integer)):
            raise ModelError(f"pattern {self.tag}: element tag must be an integer, got {element!r}")
        if kind not in ("uniform", "point"):
            raise ModelError(f"pattern {self.tag}: element load kind {kind!r} on element {element}; valid: "
                             "'uniform', 'point'")
        array = number_array(values)
        if array is None or array.ndim != 1:    # a text ('-1e3'), a bool: a value not converted
            raise ModelError(f"pattern {self.tag}: load on element {element} must be numbers, got {values!r}")
        values = tuple(array.tolist())
        names = ELEMENT_LOADS[kind]
        if not len(names) - 1 <= len(values) <= len(names) or not np.all(np.isfinite(values)):
            raise ModelError(f"pattern {self.tag}: {kind} load on element {element} needs "
                             f"({', '.join(names[:-1])}[, {names[-1]}]) finite ({names[-1]} 0 if not given), "
                             f"got {list(values)}")
        values = element_load_values(kind, values)
        if kind == "point" and not 0.0 <= values[1] <= 1.0:
            raise ModelError(f"pattern {self.tag}: point load on element {element} at x/L = {values[1]:g}, "
                             "outside [0, 1]")
        self.element_loads.append((int(element), kind, values))
        self._changed()

    def factors(self, t):
        """Load factor at the times ``t`` (array); a NaN or inf factor raises a ModelError naming
        the pattern, its series and the first such time (never a silent NaN load)."""
        if self.constant_time is not None:
            out = np.full(np.shape(t), self.factor * float(self.series(np.array([self.constant_time]))[0]))
        else:
            out = self.factor * np.asarray(self.series(t), dtype=float)
        if not np.all(np.isfinite(out)):
            bad = np.flatnonzero(~np.isfinite(out).ravel())[0]
            when = self.constant_time if self.constant_time is not None else np.asarray(t, dtype=float).ravel()[bad]
            kind, tag = type(self.series).__name__, self.series.tag
            series = f"time series {tag} ({kind})" if tag is not None else f"its {kind} series (inline)"
            raise ModelError(f"pattern {self.tag}: {series} gives load factor {out.ravel()[bad]} at t = {when:g} s")
        return out


class UniformExcitation(LoadPattern):
    """A ground acceleration a_g(t) = ``factor * series(t)`` [m/s²] along dof ``direction``
    (1 = x, 2 = y) of every node (OpenSees ``pattern UniformExcitation dir -accel``): the
    effective load −M r a_g with r the unit rigid-body translation along ``direction``; the
    responses are relative to the ground, as OpenSees's."""

    def __init__(self, tag, direction, series, factor=1.0):
        super().__init__(tag, series, factor)
        if isinstance(direction, (bool, np.bool_)) or direction not in (1, 2):
            raise ModelError(f"pattern UniformExcitation {tag}: direction must be 1 (x) or 2 (y), got {direction!r}")
        self.ground_direction = int(direction)

    def load(self, node, *values):
        raise ModelError(f"pattern UniformExcitation {self.tag}: takes no nodal loads (its load is −M r a_g)")

    def beam_load(self, element, kind, *values):
        raise ModelError(f"pattern UniformExcitation {self.tag}: takes no element loads (its load is −M r a_g)")


def element_load_values(kind, values):
    """The values of an element load of ``kind`` ('uniform' or 'point', :data:`ELEMENT_LOADS`)
    with the optional axial part 0 when not given: ``(w_y,)`` -> ``(w_y, 0.0)``, ``(P_y, x/L)``
    -> ``(P_y, x/L, 0.0)``; a full tuple as given. The one place these defaults are set (the
    ``eleLoad`` command and :meth:`LoadPattern.beam_load` both read it)."""
    values = tuple(values)
    return values + (0.0,) if len(values) == len(ELEMENT_LOADS[kind]) - 1 else values


def _finite(tag, name, value):
    """``value`` as a finite float, or a ModelError naming pattern ``tag``, ``name`` and the value."""
    if type(value) is not float:
        value = as_number(value, f"pattern {tag}", name)
    if not math.isfinite(value):
        raise ModelError(f"pattern {tag}: {name} must be finite, got {value}")
    return value
