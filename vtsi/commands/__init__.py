"""The OpenSees-style command layer behind :mod:`vtsi.opensees` and :mod:`vtsi.tcl`.

Imports run one way, each module importing only those above it:

- :mod:`.args`: the argument cursor, Tcl word rules, :class:`~.args.UnknownCommand`;
- :mod:`.base`: the helpers every command module shares (the model, a node by tag);
- :mod:`.responses`: OpenSees's layouts of element responses;
- :mod:`.model_commands`, :mod:`.analysis_commands`, :mod:`.query_commands`,
  :mod:`.recorder_commands`, :mod:`.train_commands`: the commands, one mixin per concern;
- :mod:`.session`: :class:`~.session.Session`, the commands combined, and ``COMMANDS``;
- :mod:`.tcl`: the Tcl interpreter that hands a script's words to a session.
"""
