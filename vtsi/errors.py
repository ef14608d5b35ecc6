"""Exceptions raised by vtsi. Every message names the object and the value at fault.

The classes, by what is at fault::

    VtsiError
    ├── ModelError (ValueError)          a definition: tag, parameter, node, series, track ...
    │   └── BridgeModelError             ... of the bridge itself (also a BridgeError)
    ├── AnalysisError (RuntimeError)     an analysis that cannot run as set up
    │   └── DivergenceError              a run that diverged (.step, .time)
    ├── CommandError (ValueError)        a command of the OpenSees-style layer
    ├── RecorderError (OSError)          a recorder's file that cannot be written (a full disk)
    ├── SweepError (ValueError)          a sweep that cannot run as asked
    │   ├── SettingError                 a setting that does not suit the bridge or trains (.setting)
    │   ├── PassageError                 a passage that failed while the sweep ran
    │   └── BridgeSweepError             a bridge the sweep refuses (also a BridgeError)
    └── BridgeError                      the bridge is at fault (never raised alone)

:class:`BridgeError` marks what is wrong with the bridge itself (its model, the track on it, or
the file that describes them) as opposed to the trains, speeds or settings of an analysis: the
command line names the bridge file of such an error (``vtsi sweep: bridge file b.tcl: track:
...``), whatever its message says. It is a mixin, raised as :class:`BridgeModelError` where the
bridge is built or read (a :class:`ModelError`, like every other definition) and as
:class:`BridgeSweepError` where a :class:`~vtsi.sweep.Sweep` refuses it (a :class:`SweepError`,
like every other refusal of a sweep): ``except ModelError`` and ``except SweepError`` catch what
they caught before the class existed, and ``except BridgeError`` catches both.
"""
import math
import numbers
import reprlib
from decimal import Decimal

import numpy as np


class VtsiError(Exception):
    """Base class of every error vtsi raises on purpose."""


class ModelError(VtsiError, ValueError):
    """A model definition is invalid (bad tag, bad parameter, unknown type...)."""


class AnalysisError(VtsiError, RuntimeError):
    """An analysis cannot run as set up (mechanism, bad step size, unstable integrator...)."""


class DivergenceError(AnalysisError):
    """A time integration produced non-finite or unbounded response.

    Attributes
    ----------
    step : int
        1-based index of the first step whose response diverged.
    time : float
        Time of that step [s].
    """

    def __init__(self, message, step, time):
        super().__init__(message)
        self.step = step
        self.time = time


class CommandError(VtsiError, ValueError):
    """A command of the OpenSees-style layer is unknown, unsupported or malformed."""


class RecorderError(VtsiError, OSError):
    """A recorder's file could not be written (a full disk, a file size limit, a lost drive):
    the message names the recorder, its file, the OS's reason and what the file holds
    (:meth:`vtsi.recorders.sinks.Sink.failure`). An OSError too, as any file that cannot be
    written (``vtsi run`` exits 1 on it)."""


class SweepError(VtsiError, ValueError):
    """A sweep cannot run as asked: a bad input, a results file of another sweep or one that
    cannot be written, or a case that failed (the message names the case)."""


class BridgeError(VtsiError):
    """The bridge itself is at fault: its model, the track on it, or the file that describes them
    (a mixin, see the module docstring: raised as :class:`BridgeModelError` or
    :class:`BridgeSweepError`). Its message names the bridge or its track, and not always the file
    they came from (a script's model has no other name): ``vtsi sweep`` and ``vtsi check`` add it."""


class BridgeModelError(BridgeError, ModelError):
    """A :class:`BridgeError` found where the bridge is built or read: its track (:class:`~vtsi.track.Track`,
    the deck layout), its modes and frequencies, its bridge file."""


class BridgeSweepError(BridgeError, SweepError):
    """A :class:`BridgeError` found when a :class:`~vtsi.sweep.Sweep` is built (a
    :class:`BridgeModelError` of its passages' bridge, re-raised as the sweep's: ``sweep: ...``)."""


class SettingError(SweepError):
    """A setting of a sweep's passages does not suit its bridge or trains (a time step that does
    not resolve the bridge's first mode, or the passage of a train at a speed). ``setting``: the
    :class:`~vtsi.passage.PassageSettings` field at fault ('dt'), so that a caller that read the
    value from a file names the file and its key (``vtsi sweep``: 'bridge file b.toml: [analysis]
    dt_s = 1: ...')."""

    def __init__(self, message, setting):
        super().__init__(message)
        self.setting = setting


class PassageError(SweepError):
    """A passage of a sweep failed while the sweep ran (e.g. it diverged): the message names
    the case (train, speed, seed); the cases finished before it are kept in the results file
    (``.finished``: those of its task, which the sweep writes)."""


class _Short(reprlib.Repr):
    """The value of a refusal on one line of at most a few dozen characters (an array's items
    as a list's: numpy's own repr breaks lines)."""

    def repr_ndarray(self, x, level):
        return f"array({self.repr1(x.tolist(), level)})"


_SHORT = _Short()
_SHORT.maxlist = _SHORT.maxtuple = 8
_SHORT.maxstring = _SHORT.maxother = 80


def is_number(value):
    """Whether ``value`` is a real number: a Python or numpy int or float, a Fraction or Decimal,
    or a 0-d numpy array of ints or floats (``np.asarray(2.0)``). Not a bool, nor a text ('60':
    a value read from a file and not converted; the command layer and the file readers convert
    their words before they hand them on), nor a complex, nor an array of one item or more."""
    if type(value) in (float, int):         # (the common case first: the command layer asks per word)
        return True
    if isinstance(value, np.ndarray):
        return value.ndim == 0 and value.dtype.kind in "iuf"
    return isinstance(value, (numbers.Real, Decimal)) and not isinstance(value, bool)


def as_number(value, where, name, error=ModelError):
    """``value`` as a float if it is a number (:func:`is_number`: not a bool, not a text), else
    ``error`` naming ``where``, ``name`` and the value given."""
    if not is_number(value):
        raise error(f"{where}: {name} must be a number, got {_SHORT.repr(value)}")
    try:
        return float(value)
    except OverflowError:            # an int or a fraction beyond a float's range (1e308)
        size = (f"an integer of {len(str(abs(value)))} digits" if is_int(value) else
                f"a {type(value).__name__} of about 1e{len(str(abs(int(value)))) - 1}")
        raise error(f"{where}: {name} must be a number within a float's range (1e308), got {size}") from None
    except ValueError:               # Decimal('sNaN'), which float() refuses
        raise error(f"{where}: {name} must be a number, got {_SHORT.repr(value)}") from None


def number_array(value):
    """``value`` (a number, or a sequence or array of them, any shape) as a new C-contiguous
    float64 array if every item is a number as :func:`is_number` has it, else None (a bool or a
    text item, ``['0.02']`` as ``'0.02'``, a ragged nesting, an int beyond a float's range).
    Finiteness and shape are the caller's to check; :func:`as_numbers` words the refusal."""
    if type(value) in (list, tuple) and set(map(type, value)) <= _PLAIN:   # Python floats: the common case
        try:
            return np.array(value, dtype=np.float64)
        except OverflowError:                # an int beyond a float's range (1e308)
            return None
    if isinstance(value, (str, bytes)):
        return None
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):          # a ragged nesting; an object numpy cannot hold
        return None
    if not (array.dtype.kind in "iuf" or (array.dtype.kind == "O" and all(is_number(item) for item in array.flat))):
        return None
    if isinstance(value, (list, tuple)) and array.dtype.kind in "iuf" and _holds_bool(value):
        return None                          # numpy reads [True, 2.0] as [1.0, 2.0]
    try:
        return np.array(array, dtype=np.float64, order="C")
    except (OverflowError, ValueError):      # an int beyond a float's range (1e308); Decimal('sNaN')
        return None


_PLAIN = {float, int}


def _holds_bool(items):
    """Whether ``items``, a nest of lists and tuples, holds a bool (Python's or numpy's) at any depth."""
    kinds = set(map(type, items))                        # (one pass in C: a list of floats holds one kind)
    if kinds <= _PLAIN:
        return False
    if any(issubclass(kind, (bool, np.bool_)) for kind in kinds):
        return True
    nests = tuple(kind for kind in kinds if issubclass(kind, (list, tuple, np.ndarray)))
    return bool(nests) and any(_holds_bool(item) if not isinstance(item, np.ndarray) else item.dtype.kind == "b"
                               for item in items if isinstance(item, nests))


def as_numbers(value, where, name, error=ModelError):
    """:func:`number_array` of ``value``, or ``error`` naming ``where``, ``name`` and the value given
    (a long one shortened with '...': its first items)."""
    array = number_array(value)
    if array is None:
        raise error(f"{where}: {name} must be numbers, got {_SHORT.repr(value)}")
    return array


def as_positive(value, where, name, error=ModelError, *, finite=True, allow_zero=False):
    """``value`` as a float > 0 (>= 0 with ``allow_zero``; finite unless ``finite=False``), or
    ``error`` naming ``where``, ``name`` and the value given."""
    number = as_number(value, where, name, error)
    if not ((number >= 0.0 if allow_zero else number > 0.0) and (not finite or np.isfinite(number))):
        raise error(f"{where}: {name} must be {'>=' if allow_zero else '>'} 0{' and finite' if finite else ''}, "
                    f"got {value!r}")
    return number


def as_flag(value, where, name, error=ModelError):
    """``value`` as a bool if it is one (bool or numpy bool), else ``error`` naming ``where``,
    ``name`` and the value (a text such as ``'no'`` is not taken for True)."""
    if not isinstance(value, (bool, np.bool_)):
        raise error(f"{where}: {name} must be True or False, got {value!r}")
    return bool(value)


def is_int(value):
    """Whether ``value`` is an integer (a Python or numpy int), not a bool."""
    return type(value) is int or (isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)))


def is_count(value, least=0):
    """Whether ``value`` is a whole number >= ``least``: a number as :func:`is_number` has it (an
    int, a float without a fraction (``3.0``), a 0-d array, a Fraction 6/1), not a bool."""
    if not is_number(value):
        return False
    try:
        return math.isfinite(value) and int(value) == value and value >= least
    except ValueError:               # Decimal('sNaN')
        return False
