"""OpenSees-style commands: ``import vtsi.opensees as ops`` runs OpenSeesPy bridge scripts.

The module offers OpenSeesPy's command names and argument orders (``model``, ``node``, ``fix``,
``mass``, ``geomTransf``, ``element``, ``uniaxialMaterial``, ``timeSeries``, ``pattern``,
``load``, ``rayleigh``, ``constraints``, ``numberer``, ``system``, ``test``, ``algorithm``,
``integrator``, ``analysis``, ``analyze``, ``eigen``, ``nodeDisp`` ..., ``recorder``, ``wipe``
and the queries around them, see :data:`COMMANDS` and ``docs/commands.md``) as a thin layer
over the object API (:class:`vtsi.Model`, :class:`vtsi.StaticAnalysis`,
:class:`vtsi.TransientAnalysis`, :func:`vtsi.eigen`, :mod:`vtsi.recorders`).

The commands act on a :class:`Session` (:mod:`vtsi.commands`: argument parsing, the model,
analysis, query, recorder and train commands, the Tcl runner; this module is the import users
write). The module functions delegate to the module attribute
``session`` at every call, so ``ops.session = ops.Session()`` (or :func:`set_session`) replaces
the default one; a session's methods are the same commands (``s = Session(); s.node(1, 0, 0)``).
The session is a state machine like OpenSees's interpreter: the analysis is assembled at
``analyze`` from the last ``constraints``/``numberer``/``system``/``integrator``/``analysis``
settings, a change to the model between two ``analyze`` calls is taken into account, and every
analysis continues from the model's committed state (:func:`vtsi.domain_state`), so that "static
gravity analysis, ``loadConst('-time', 0.0)``, transient analysis" works as in OpenSees.

Where vtsi differs from OpenSees (errors are exceptions, every option is either honoured or
refused by name, ``system``/``numberer`` choices map to vtsi's banded Cholesky solver, ...), see
``docs/commands.md``. The conventions reproduced here were measured on OpenSeesPy 3.7.1
(``docs/opensees_conventions.md``).
"""
from vtsi.commands.analysis_commands import ALGORITHMS, INTEGRATORS, NUMBERERS, SYSTEMS, TESTS
from vtsi.commands.args import UnknownCommand
from vtsi.commands.model_commands import ELEMENT_TYPES, MATERIAL_TYPES, SERIES_TYPES
from vtsi.commands.session import COMMANDS, Session
from vtsi.errors import AnalysisError, CommandError, DivergenceError, ModelError

__all__ = ["Session", "set_session", "session", "COMMANDS", "UnknownCommand", "CommandError", "ModelError",
           "AnalysisError", "DivergenceError", "ELEMENT_TYPES", "MATERIAL_TYPES", "SERIES_TYPES", "ALGORITHMS",
           "INTEGRATORS", "NUMBERERS", "SYSTEMS", "TESTS"]


# ---------------------------------------------------------------------------------------------
# module-level commands delegating to the current session
# ---------------------------------------------------------------------------------------------
session = Session()
"""The default session; replace it (``ops.session = ops.Session()``) to start afresh."""


def set_session(new):
    """Make ``new`` (a :class:`Session`) the target of the module-level commands; returns the old one."""
    global session
    if not isinstance(new, Session):
        raise TypeError(f"set_session: expected a Session, got {new!r}")
    old, session = session, new
    return old


def _delegate(name):
    method = getattr(Session, name)

    def command(*args):
        return getattr(session, name)(*args)

    command.__name__ = command.__qualname__ = name
    command.__doc__ = method.__doc__
    return command


for _name in COMMANDS:
    globals()[_name] = _delegate(_name)
del _name


def __getattr__(name):
    if name.startswith("__"):
        raise AttributeError(name)
    raise UnknownCommand(f"vtsi.opensees has no command {name!r}; supported commands: {', '.join(COMMANDS)}")


def __dir__():
    return sorted(list(globals()) + list(COMMANDS))
