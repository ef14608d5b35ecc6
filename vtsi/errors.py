"""Exceptions raised by vtsi. Every message names the object and the value at fault."""
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


class SweepError(VtsiError, ValueError):
    """A sweep cannot run as asked: a bad input, a results file of another sweep or one that
    cannot be written, or a case that failed (the message names the case)."""


class PassageError(SweepError):
    """A passage of a sweep failed while the sweep ran (e.g. it diverged): the message names
    the case (train, speed, seed); the cases finished before it are kept in the results file."""


def as_number(value, where, name, error=ModelError):
    """``value`` as a float, or ``error`` naming ``where``, ``name`` and the value given (a bool
    is not taken for 1 or 0)."""
    try:
        if isinstance(value, (bool, np.bool_)):
            raise TypeError
        return float(value)
    except (TypeError, ValueError):
        raise error(f"{where}: {name} must be a number, got {value!r}") from None


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
    """Whether ``value`` is a whole number >= ``least``: an int, or a float without a fraction
    (``3.0``), not a bool."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_)) \
        and bool(np.isfinite(value)) and int(value) == value and value >= least
