"""What every command module of a session reads: the model under construction and its state,
found by tag with errors that name the command and the tag."""
from vtsi.analysis import domain_state
from vtsi.errors import CommandError, is_int


class SessionBase:
    """The helpers the command mixins share (:class:`vtsi.commands.session.Session` combines
    them); ``domain`` is the :class:`vtsi.Model` being built, None before ``model(...)``."""

    domain = None

    def _model(self, command):
        if self.domain is None:
            raise CommandError(f"{command}: no model; call model('basic', '-ndm', 2, '-ndf', 3) first")
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
