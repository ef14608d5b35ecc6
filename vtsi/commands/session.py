"""The OpenSees-style interpreter state: a :class:`Session` combines the command modules (model,
analysis, queries, recorders, trains) into one object whose methods are the commands."""
import atexit
import functools
import inspect
import weakref

from vtsi.errors import CommandError

from .analysis_commands import ANALYSIS_COMMANDS, AnalysisCommands
from .args import Args, UnknownCommand
from .model_commands import MODEL_COMMANDS, ModelCommands
from .query_commands import QUERY_COMMANDS, QueryCommands
from .recorder_commands import RECORDER_COMMANDS, RecorderCommands
from .train_commands import TRAIN_COMMANDS, TrainCommands

COMMANDS = MODEL_COMMANDS + ANALYSIS_COMMANDS + QUERY_COMMANDS + RECORDER_COMMANDS + ("remove", "wipe") + TRAIN_COMMANDS
"""Every command this layer knows; anything else raises :class:`~vtsi.commands.args.UnknownCommand`."""

_SESSIONS = weakref.WeakSet()


@atexit.register
def _close_recorders_at_exit():
    for s in list(_SESSIONS):
        for r in list(s._kept.values()):
            r.finish()


def _counted(name, method):
    """``method`` refusing a wrong number of positional arguments with a CommandError that names
    the command and what it takes (commands reading ``*args`` check their own)."""
    params = list(inspect.signature(method).parameters.values())[1:]
    if any(p.kind is p.VAR_POSITIONAL for p in params):
        return method
    least = sum(p.default is p.empty for p in params)
    most = len(params)
    usage = " ".join(p.name if p.default is p.empty else f"[{p.name}]" for p in params)
    count = str(least) if least == most else f"{least} to {most}"
    takes = f"{usage} ({count} argument{'s' if most > 1 else ''})" if most else "no arguments"

    @functools.wraps(method)
    def command(self, *args, **kwargs):
        if not kwargs and not least <= len(args) <= most:
            raise CommandError(f"{name}: takes {takes}, got {len(args)}: {list(args)!r}")
        return method(self, *args, **kwargs)

    return command


def _argument_counts(cls):
    """Class decorator: every command of :data:`COMMANDS` on ``cls`` checks its argument count."""
    for name in COMMANDS:
        setattr(cls, name, _counted(name, getattr(cls, name)))
    return cls


@_argument_counts
class Session(ModelCommands, AnalysisCommands, QueryCommands, RecorderCommands, TrainCommands):
    """One OpenSees-style interpreter state: a model under construction, materials, transforms,
    the analysis settings, recorders and the results of the last queries.

    Every command of :data:`COMMANDS` is a method with OpenSeesPy's name and argument order.
    ``domain`` is the :class:`vtsi.Model` being built (None before ``model(...)``), for mixing
    commands with the object API; ``recorders`` maps recorder tags to the recorder objects.
    """

    def __init__(self):
        self._recorder_count = 0   # OpenSees: a process-wide counter that wipe() does not reset
        self.recorders = {}        # tag -> vtsi recorder (memory sinks hold .time and .values)
        self._kept = {}            # tag -> KeptOpen adapter handed to the analyses
        self._clear()
        _SESSIONS.add(self)

    def _clear(self):
        self._clear_model()
        self._clear_results()
        self._clear_queries()
        self._clear_analysis()
        self._clear_train()

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        raise UnknownCommand(f"Session has no command {name!r}; supported commands: {', '.join(COMMANDS)}")

    def remove(self, *args):
        """``remove('recorders')`` (every recorder, files closed), ``remove('recorder', tag)``,
        ``remove('loadPattern', tag)``, ``remove('element', tag)``, ``remove('node', tag)``,
        ``remove('timeSeries', tag)``, ``remove('sp', node, dof, [patternTag])`` or
        ``remove('mp', node)`` (the constraints of a constrained node)."""
        a = Args("remove", args)
        what = a.word("object type", ("recorders", "recorder", "loadPattern", "element", "node", "timeSeries", "sp",
                                      "mp"))
        if what in ("node", "timeSeries", "sp", "mp"):
            model = self._model("remove")
            tag = a.int("node tag" if what != "timeSeries" else "series tag")
            if what == "sp":
                dof = a.int("dof")
                pattern = a.int("pattern tag") if a.more() else None
                a.done()
                return model.remove_sp(tag, dof, pattern)
            a.done()
            return {"node": model.remove_node, "timeSeries": model.remove_time_series, "mp": model.remove_mp}[what](tag)
        if what == "recorders":
            a.done()
            for tag in list(self.recorders):
                del self.recorders[tag]
                self._kept.pop(tag).finish()
            return
        tag = a.int(f"{what} tag")
        a.done()
        if what == "recorder":
            if tag not in self.recorders:
                raise CommandError(f"remove recorder: recorder {tag} does not exist")
            del self.recorders[tag]
            self._kept.pop(tag).finish()
            return
        model = self._model("remove")
        if what == "loadPattern":
            if tag not in model.patterns:
                raise CommandError(f"remove loadPattern: pattern {tag} does not exist")
            model.remove_pattern(tag)
            if self._current_pattern == tag:
                self._current_pattern = None
        else:
            if tag not in model._element_owner:
                raise CommandError(f"remove element: element {tag} does not exist")
            model.remove_element(tag)
            self._zero_length.pop(tag, None)

    def wipe(self):
        """Delete everything: model, materials, series, patterns, analysis and recorders (their
        files are closed). Recorder tags keep counting up, as in OpenSees."""
        kept, self._kept, self.recorders = list(self._kept.values()), {}, {}
        try:
            for r in kept:
                r.finish()
        finally:
            self._clear()
