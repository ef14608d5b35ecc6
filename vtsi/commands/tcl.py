"""Run OpenSees Tcl scripts with vtsi: every command of :mod:`vtsi.opensees` in a Tcl interpreter.

The interpreter is Python's own ``tkinter.Tcl()`` (the standard library's Tcl, no Tk window),
so Tcl's ``set``, ``expr``, ``puts``, ``proc``, ``for``/``foreach``/``while``, ``source``... work
natively. Each vtsi command is a Tcl procedure that hands its words to the session, converted as
OpenSees's Tcl interpreter reads them: an integer word becomes an ``int``, a number a ``float``,
anything else stays a ``str``; a braced or quoted list of numbers (``-values {0 1 2}``) becomes a
list, which only an option that takes a list reads: where one number is expected it is refused,
as OpenSees's Tcl refuses ``node 3 {4.0 1.0}`` (:class:`~vtsi.commands.args.Args`). Results
come back as Tcl values (``eigen 3`` returns the list of ω², ``nodeDisp 2 2`` a number,
``recorder ...`` its tag).

Tcl-specific forms, as in OpenSees:

* ``pattern Plain 1 1 { load 2 0 -1 0 }``: the braced body is evaluated (in the caller's scope)
  after the pattern is created, so its ``load`` commands go to that pattern; an inline series
  (``pattern Plain 1 Linear {...}``, ``pattern Plain 2 "Path -dt 0.1 -values {0 1 0}" {...}``)
  is accepted too, as is ``-accel "Path -dt 0.1 -values {0 1 0}"`` of a UniformExcitation
  (OpenSees reads ``-accel``'s word as a tag or an inline series).
* ``timeSeries Path 1 -dt 0.01 -values {0 1 2}`` (or ``-values $list``).
* ``exit [code]`` ends the script (not the Python process).

Errors: a command that fails raises a Tcl error carrying vtsi's message (``catch`` works); when
the script stops on it, :meth:`Interpreter.eval` re-raises the original Python exception (a
:class:`~vtsi.errors.VtsiError`), with the Tcl location added as a note. An unknown command
raises :class:`~vtsi.commands.args.UnknownCommand` naming it.

Example
-------
>>> from vtsi.tcl import Interpreter
>>> tcl = Interpreter()
>>> tcl.eval("model basic -ndm 2 -ndf 3; node 1 0 0; nodeCoord 1")
'0.0 0.0'
"""
import os
import re

from vtsi.errors import CommandError

from .args import UnknownCommand, convert_word
from .session import COMMANDS, Session

_EXIT = "__vtsi_exit__"
TRACEBACK_NOTE = "Tcl traceback:"   # heads the note :meth:`Interpreter.eval` adds to a script's error


def script_line(exc, path):
    """The line of the Tcl file ``path`` where the error ``exc`` raised by :meth:`Interpreter.eval`
    stopped the script (the innermost frame in that file), or None."""
    notes = [n for n in getattr(exc, "__notes__", ()) if n.startswith(TRACEBACK_NOTE)]
    path = os.path.abspath(path)
    lines = [int(m.group(2)) for note in notes for m in re.finditer(r'\(file "([^"]*)" line (\d+)\)', note)
             if os.path.abspath(m.group(1)) == path]
    return lines[0] if lines else None

_WRAPPER = r"""
proc ::%(name)s args {
    set r [::vtsi::call %(name)s {*}$args]
    switch -- [lindex $r 0] {
        0 { return [lindex $r 1] }
        2 { uplevel 1 [lindex $r 1]; return "" }
        default { return -code error [lindex $r 1] }
    }
}
"""

_UNKNOWN = r"""
proc ::unknown args {
    if {[auto_load [lindex $args 0]]} { return [uplevel 1 $args] }
    return -code error [lindex [::vtsi::call unknown {*}$args] 1]
}
"""


class Interpreter:
    """A Tcl interpreter whose OpenSees commands act on ``session`` (a new
    :class:`~vtsi.commands.session.Session` by default; pass ``vtsi.opensees.session`` to share the
    module-level one)."""

    def __init__(self, session=None):
        import tkinter   # optional in the standard library (Debian: python3-tk)

        self.session = session if session is not None else Session()
        self.tcl = tkinter.Tcl()
        self._tcl_error = tkinter.TclError
        self._error = None
        self.exit_code = None
        self.tcl.createcommand("::vtsi::call", self._call)
        for name in COMMANDS + ("exit",):
            self.tcl.eval(_WRAPPER % {"name": name})
        self.tcl.eval(_UNKNOWN)

    # -- the bridge -----------------------------------------------------------------------------
    def _call(self, name, *words):
        syntax, self.session.syntax = self.session.syntax, "tcl"   # its messages write commands as Tcl
        try:
            if name == "exit":
                code = convert_word(words[0]) if words else 0
                self.exit_code = code if isinstance(code, int) else 1
                return (1, _EXIT)
            if name == "unknown":
                raise UnknownCommand(f"unknown command {words[0]!r}; vtsi's OpenSees commands: {', '.join(COMMANDS)}")
            if name == "pattern":
                return self._pattern(words)
            result = getattr(self.session, name)(*[convert_word(w) for w in words])
            return (0, _to_tcl(result))
        except Exception as exc:   # handed to Tcl as an error; re-raised by eval() if the script stops
            self._error = exc
            return (1, f"{exc}")
        finally:
            self.session.syntax = syntax

    def _pattern(self, words):
        words = list(words)
        body = None
        if len(words) >= 4:
            last = words[-1]
            previous = words[-2]
            if (not last.lstrip().startswith("-") and convert_word(last) is last
                    and previous not in ("-fact", "-factor", "-accel")):   # -accel takes an inline series
                body = words.pop()
        args = [convert_word(w) if i != 2 else _series_word(w) for i, w in enumerate(words)]
        self.session.pattern(*args)
        if body is not None and body.strip():
            return (2, body)
        return (0, "")

    # -- running scripts ------------------------------------------------------------------------
    def eval(self, script):
        """Evaluate Tcl ``script``; returns its result (str). A failing vtsi command re-raises its
        exception; other Tcl errors raise :class:`~vtsi.errors.CommandError`."""
        self._error = None
        try:
            return self.tcl.eval(script)
        except self._tcl_error as tcl_error:
            message = str(tcl_error)
            if message == _EXIT and self.exit_code is not None:
                return ""
            info = self.tcl.eval("set ::errorInfo")
            exc = self._error
            if exc is None or message != str(exc):
                exc = CommandError(f"Tcl error: {message}")
            where = info[len(message):].lstrip("\n") if info.startswith(message) else info
            exc.__notes__ = [*getattr(exc, "__notes__", ()), f"{TRACEBACK_NOTE}\n{where}"]   # add_note (3.11+)
            raise exc from None

    def source(self, path, argv=()):
        """Run the Tcl file ``path`` (``argv``: the script's ``$argv``); returns the exit code
        given to ``exit`` (0 otherwise)."""
        path = os.fspath(path)
        self.tcl.setvar("argv0", path)
        self.tcl.setvar("argc", len(argv))
        self.tcl.setvar("argv", tuple(str(a) for a in argv))
        self.tcl.setvar("::vtsi::script", path)
        self.exit_code = None
        try:
            self.eval("source $::vtsi::script")
        finally:
            self.tcl.eval("flush stdout")
        return self.exit_code or 0


def run_file(path, session=None, argv=()):
    """Run a Tcl model file with vtsi; returns the :class:`Interpreter` (its ``session`` holds
    the model and results)."""
    interp = Interpreter(session)
    interp.source(path, argv)
    return interp


def _series_word(word):
    """The tsTag word of ``pattern``: an integer tag or an inline series specification (str)."""
    value = convert_word(word)
    return value if isinstance(value, int) else word


def _to_tcl(value):
    """A command's result as a Tcl value: None -> '', list -> Tcl list, numbers as they are."""
    if value is None:
        return ""
    if isinstance(value, (list, tuple)):
        return tuple(_to_tcl(v) for v in value)
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, (int, float, str)):
        return value
    return str(value)
