"""What every command module of a session reads: the model under construction and its state,
found by tag with errors that name the command and the tag."""
from vtsi.analysis import domain_state
from vtsi.errors import CommandError, is_int

from .responses import accepted_responses


class Placeholder(str):
    """A word of :meth:`SessionBase._command_text` that stands for a value the user chooses
    (``tag``): written bare in either syntax, where a plain ``str`` word is a literal."""


class SessionBase:
    """The helpers the command mixins share (:class:`vtsi.commands.session.Session` combines
    them); ``domain`` is the :class:`vtsi.Model` being built, None before ``model(...)``.

    ``syntax`` is how the session's messages write a command the user should give: 'python'
    (OpenSeesPy's ``model('basic', '-ndm', 2, '-ndf', 3)``) or 'tcl' (``model basic -ndm 2 -ndf
    3``); :class:`vtsi.commands.tcl.Interpreter` sets 'tcl' while it runs a command."""

    domain = None
    syntax = "python"

    def _command_text(self, name, *words):
        """Command ``name`` with ``words`` as the user writes it in this session's ``syntax``:
        ``model('basic', '-ndm', 2)`` or ``model basic -ndm 2`` (a :class:`Placeholder` word is
        bare in both, a list is ``[0, 1]`` or ``{0 1}``)."""
        if self.syntax == "tcl":
            return " ".join([name] + [_tcl_word(w) for w in words])
        return f"{name}({', '.join(_python_word(w) for w in words)})"

    def _command_hint(self, *commands, verb="call"):
        """What a message asks the user to give: ``commands`` (each ``(name, *words)``,
        :meth:`_command_text`) in the session's syntax, joined by ' or ': "call
        analysis('Static') or analysis('Transient')" (python) or 'give the command "analysis
        Static" or "analysis Transient"' (tcl: each command quoted); ``verb`` '' leaves out the verb."""
        texts = [self._command_text(*command) for command in commands]
        if self.syntax == "tcl":
            return ("give the command " if verb else "") + " or ".join(f'"{t}"' for t in texts)
        return (f"{verb} " if verb else "") + " or ".join(texts)

    def _model(self, command):
        if self.domain is None:
            raise CommandError(f"{command}: no model; {self._command_hint(('model', 'basic', '-ndm', 2, '-ndf', 3))} first")
        return self.domain

    def _assembly(self, command):
        """The built model (:class:`vtsi.assembly.Assembly`); an error naming ``command`` if it has no nodes."""
        model = self._model(command)
        if not model.nodes:
            raise CommandError(f"{command}: the model has no nodes")
        return model.build()

    def _state(self, command):
        return self._assembly(command), domain_state(self.domain)

    def _node(self, command, tag):
        model = self._model(command)
        if type(tag) is int and tag in model.nodes:
            return tag
        if not is_int(tag):
            raise CommandError(f"{command}: node tag must be an integer, got {tag!r}")
        if int(tag) not in model.nodes:
            raise CommandError(f"{command}: node {tag} does not exist")
        return int(tag)

    def _node_values(self, command, tag, vector):
        """The entries of full-dof ``vector`` (an array, or the name of a state vector: 'u', 'v',
        'a') at node ``tag``."""
        asm = self._assembly(command)
        i = asm.node_index.get(tag) if type(tag) is int else None
        if i is None:
            i = asm.node_index[self._node(command, tag)]
        if isinstance(vector, str):
            vector = getattr(domain_state(self.domain), vector)
        i *= asm.ndf
        return vector[i: i + asm.ndf]

    def _element_responses(self, tags):
        """The response names the elements ``tags`` answer (None: every element of the model), for
        a message (:func:`~.responses.accepted_responses`); tags that are not elements are left out."""
        model = self.domain
        tags = model.element_tags() if tags is None else [t for t in tags if is_int(t) and t in model._element_owner]
        names = {}
        for t in tags:
            etype = model._element_owner[t]
            names.update(dict.fromkeys(accepted_responses(etype, model.ndf, self._zero_length.get(t))))
        return tuple(names)


def _python_word(word):
    if isinstance(word, Placeholder):
        return str(word)
    if isinstance(word, (list, tuple)):
        return f"[{', '.join(_python_word(w) for w in word)}]"
    return repr(float(word)) if isinstance(word, float) else repr(word)


def _tcl_word(word):
    if isinstance(word, (list, tuple)):
        return "{" + " ".join(_tcl_word(w) for w in word) + "}"
    text = repr(float(word)) if isinstance(word, float) else str(word)
    return text if text and not any(c.isspace() or c in '{}[]$"\\;' for c in text) else "{" + text + "}"
