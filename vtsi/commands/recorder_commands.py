"""Recorder commands: ``recorder Node|EnvelopeNode|Element|EnvelopeElement`` (``Contact`` and
``Train`` in :mod:`.train_commands`), kept open across ``analyze`` calls as in OpenSees, their
sinks (``-file`` OpenSees text, ``-h5``/``-hdf5``) and OpenSees's element-response columns."""
import logging
import os

import numpy as np

from vtsi import recorders as rec
from vtsi.errors import CommandError
from vtsi.recorders import ElementRecorder, Recorder
from vtsi.recorders.element import DESCRIPTION
from vtsi.units import Units

from .args import Args, is_option
from .base import SessionBase
from .responses import (ELEMENT_RESPONSE_ALIASES, PART_WORDS, accepted_responses, apply_layout, element_answers,
                        opensees_layout)

RECORDER_COMMANDS = ("recorder",)
NODE_RESPONSES = ("disp", "vel", "accel", "reaction", "reactionIncInertia")
RECORDER_TYPES = ("Node", "EnvelopeNode", "Element", "EnvelopeElement", "Contact", "Train")
# the options that take values: none of them is a file name (a flag, -time, is: as OpenSeesPy)
VALUE_OPTIONS = ("-file", "-h5", "-hdf5", "-precision", "-dT", "-node", "-nodeRange", "-dof", "-ele", "-eleRange", "-wheel")
# the options that shape a text file only: refused with -h5 (vtsi's own option, so no OpenSees script has both)
TEXT_ONLY = {"-precision": "it sets the digits of a text file (an HDF5 file stores every value as a float64)",
             "-closeOnWrite": "it reopens a text file for every write (an HDF5 file is flushed after every chunk "
                              "of steps)"}

log = logging.getLogger(__name__)


class KeptOpen:
    """One command-layer recorder across many ``analyze`` calls, as in OpenSees: its record is
    opened once (again only when the model, its load patterns or the analysis' description
    ``info`` change: an HDF5 file then describes the new run) and closed by
    ``remove('recorder', tag)``, ``wipe()`` or the end of the process, not at the end of every
    ``analyze`` (scripts often call ``analyze(1, dt)`` in a loop). Follows the recorder
    contract of :mod:`vtsi.recorders.base` and delegates to the wrapped ``recorder``."""

    def __init__(self, recorder):
        self.recorder = recorder
        self._requests = None     # (assembly, requests)
        self._started = None      # (assembly, model.load_version, [(tag, pattern, n_loads)], info)

    def __repr__(self):
        return repr(self.recorder)

    @property
    def dt(self):
        return self.recorder.dt

    @property
    def sink(self):
        """The wrapped recorder's sink (an analysis refuses two recorders writing one file)."""
        return getattr(self.recorder, "sink", None)

    def requests(self, assembly):
        if self._requests is None or self._requests[0] is not assembly:
            self._requests = (assembly, self.recorder.requests(assembly))
        return self._requests[1]

    def start(self, assembly, model, info=None):
        info = dict(info or {})
        if self._started is not None and self._started[0] is assembly and self._started[1] == model.load_version \
                and self._started[3] == info:
            return        # nothing changed since the last analyze (a per-step loop)
        patterns = [(tag, p, len(p.nodal)) for tag, p in model.patterns.items()]
        if self._started is not None:
            asm, _, old, old_info = self._started
            same = asm is assembly and old_info == info and len(old) == len(patterns) and all(
                a[0] == b[0] and a[1] is b[1] and a[2] == b[2] for a, b in zip(old, patterns))
            if same:
                self._started = (assembly, model.load_version, patterns, info)
                return
            self.recorder.close()
        self.recorder.start(assembly, model, info)
        self._started = (assembly, model.load_version, patterns, info)

    def write(self, times, columns, assembly):
        self.recorder.write(times, columns, assembly)

    @property
    def load_lag(self):
        return self.recorder.load_lag

    @load_lag.setter
    def load_lag(self, value):
        self.recorder.load_lag = value

    def close(self):
        """End of one analysis run: nothing to do (the sinks flush every chunk)."""

    def finish(self):
        """Close the record for good (OpenSees: the recorder is destroyed)."""
        if self._started is not None:
            self._started = None
            self.recorder.close()


class CommandElementRecorder(Recorder):
    """OpenSees's ``recorder Element``: ``response`` of ``elements`` in OpenSees's columns,
    element after element, whatever their types (a beam's 6 global forces, then a truss's 6).

    ``layouts``: per element, how its columns are built from a vtsi response
    (:func:`~vtsi.commands.responses.opensees_layout`; None: that response's own columns). The
    elements that need the same vtsi response (``deformation`` for a zeroLength's basic
    quantities, also on the velocities) are recorded by one
    :class:`~vtsi.recorders.ElementRecorder`, whose columns are then rearranged. With no
    ``elements`` (none has the response: OpenSees records no columns) it records none."""

    name = "element recorder"

    def __init__(self, elements, response, layouts, sink=None, dt=None, envelope=False, history=True, tag=None):
        self.elements, self.response, self._layouts = list(elements), response, list(layouts)
        by_source = {}
        for k, layout in enumerate(self._layouts):
            by_source.setdefault(response if layout is None else layout[0], []).append(k)
        # (the recorder of one vtsi response, the places of its elements in self.elements, whether a layout
        # of theirs needs the response's rate)
        self._parts = [(ElementRecorder([self.elements[k] for k in places], source), places,
                        any(self._layouts[k] is not None and self._layouts[k][2] for k in places))
                       for source, places in by_source.items()]
        super().__init__(sink=sink, dt=dt, envelope=envelope, history=history, tag=tag)
        self._load_lag = Recorder.load_lag
        self._columns = None      # per part: its request columns, and the same with u replaced by v
        self._blocks = None       # per element: (part, first column in its values, width, layout)
        self._slices = None       # the output in slices of successive elements (see requests)

    @property
    def load_lag(self):
        return self._load_lag

    @load_lag.setter
    def load_lag(self, value):
        self._load_lag = value
        for part, _places, _rates in self._parts:
            part.load_lag = value

    def requests(self, assembly):
        keys, requests, self._columns = {}, [], []
        self._blocks = [None] * len(self.elements)
        for p, (part, places, _rates) in enumerate(self._parts):
            own = part.requests(assembly)
            for key in own:
                if key not in keys:
                    keys[key] = len(requests)
                    requests.append(key)
            self._columns.append((np.array([keys[key] for key in own], dtype=np.int64),
                                  np.array([keys[("v", full) if q == "u" else (q, full)] for q, full in own],
                                           dtype=np.int64)))
            start = 0
            for k, width in zip(places, part.widths):
                self._blocks[k] = (p, start, int(width), self._layouts[k])
                start += int(width)
        # the output in slices (part, start, width, count, layout) of successive elements whose columns follow
        # each other in one part: recorded as they are (one slice of count 1), or all with one layout (count
        # elements of that width, rearranged together)
        self._slices = []
        for p, start, width, layout in self._blocks:
            last = self._slices[-1] if self._slices else None
            if last is not None and last[0] == p and last[1] + last[2] * last[3] == start and last[4] == layout:
                if layout is None:
                    self._slices[-1] = (p, last[1], last[2] + width, 1, None)
                    continue
                if last[2] == width:
                    self._slices[-1] = (p, last[1], width, last[3] + 1, layout)
                    continue
            self._slices.append((p, start, width, 1, layout))
        return requests

    def start(self, assembly, model, info=None):
        """Start the record; each part takes the wheel loads of a coupled analysis into its track
        elements' end forces (:meth:`~vtsi.recorders.element.ElementRecorder.take_coupled_loads`)."""
        for part, _places, _rates in self._parts:
            part.take_coupled_loads(assembly, (info or {}).get("coupled_loads"))
        super().start(assembly, model, info)

    def prepare(self, assembly, model):
        described = [part.prepare(assembly, model) for part, _places, _rates in self._parts]
        units, element, component, names = [], [], [], []
        for tag, (p, start, width, layout) in zip(self.elements, self._blocks):
            part_units = described[p]["units"]
            if layout is None:
                units += part_units[start: start + width]
                names += list(described[p]["columns"]["component_name"][start: start + width])
            else:
                units += [part_units[start + max(src, 0)] for src, _cu, _cv in layout[1]]
                width = len(layout[1])
                names += [f"{self.response}_{j + 1}" for j in range(width)]
            element += [tag] * width
            component += range(1, width + 1)
        return {"response": self.response, "quantity": DESCRIPTION.get(self.response, f"element {self.response}"),
                "units": units, "columns": {"element": np.array(element, dtype=np.int64),
                                            "component": np.array(component, dtype=np.int64),
                                            "component_name": np.array(names)}}

    def compute(self, times, columns, assembly):
        values, rates = [], []
        for (part, _places, uses_rates), (cols, rate_cols) in zip(self._parts, self._columns):
            values.append(part.compute(times, columns[:, cols], assembly))
            rates.append(part.compute(times, columns[:, rate_cols], assembly) if uses_rates else None)
        n, blocks = len(times), []
        for p, start, width, count, layout in self._slices:
            block = values[p][:, start: start + width * count]
            if layout is not None:          # one element a row
                rate = None if rates[p] is None else rates[p][:, start: start + width * count].reshape(n * count, width)
                block = apply_layout(layout, block.reshape(n * count, width), rate).reshape(n, -1)
            blocks.append(block)
        if len(blocks) == 1:
            return blocks[0]
        return np.hstack(blocks) if blocks else np.empty((n, 0))      # no elements: no columns


def command_element_recorder(session, elements, response, **kwargs):
    """A :class:`CommandElementRecorder` of ``elements`` whose columns are laid out as OpenSees
    writes them (:func:`~vtsi.commands.responses.opensees_layout`)."""
    asm = session.domain.build()
    layouts = []
    for tag in elements:
        b, _ = asm.element_location[tag]
        layouts.append(opensees_layout(asm.blocks[b][0], response, asm.ndf, session._zero_length.get(tag)))
    return CommandElementRecorder(elements, response, layouts, **kwargs)


class RecorderCommands(SessionBase):
    """``recorder``: the recorders of a session, tagged by a counter that ``wipe`` does not reset."""

    def _recorder_list(self):
        """The recorders handed to an analysis (kept open across ``analyze`` calls)."""
        return list(self._kept.values())

    def recorder(self, *args):
        """``recorder('Node'|'EnvelopeNode'|'Element'|'EnvelopeElement', ...)``; returns its tag.
        Options: ``-file f`` (OpenSees text), vtsi's ``-h5 f``/``-hdf5 f`` (HDF5; an existing file
        is replaced, as ``-file`` replaces its file), ``-time``,
        ``-precision p`` (p >= 0), ``-dT dt``, ``-closeOnWrite``, ``-node``, ``-nodeRange a b``,
        ``-dof``, ``-ele``, ``-eleRange a b``; then the response, last (an option after it is
        refused: OpenSees would take it for the response). ``-precision`` and ``-closeOnWrite``
        with ``-h5`` are refused (they shape a text file); without a file (memory, OpenSees's
        screen) they are accepted and change nothing. A node or element of ``-node`` or ``-ele``
        that does not exist gets no columns and a warning (logged), as OpenSees gives it no
        columns; an Element recorder of none that exists records no values (a text file with
        ``-time`` only the times, as OpenSees's)."""
        if args and args[0] in ("Contact", "Train"):
            return self._vehicle_recorder(*args)
        model = self._model("recorder")
        a = Args("recorder", args)
        kind = a.word("recorder type", RECORDER_TYPES)
        name = f"recorder {kind}"
        a.command = name
        is_node = kind.endswith("Node")
        valid = ["-file", "-h5", "-hdf5", "-time", "-precision", "-dT", "-closeOnWrite"]
        valid += ["-node", "-nodeRange", "-dof"] if is_node else ["-ele", "-eleRange"]
        opts = {"-time": False, "-precision": 6, "-dT": None, "-closeOnWrite": False}
        targets = None            # None: no selection given
        response = []
        after = None              # the list option whose values the response words follow
        last_option = None        # where the last option before the response is in a.items
        given = set()             # the options given
        while a.more():
            x = a.peek()
            if isinstance(x, str) and x.startswith("-") and not response:
                last_option = a.pos
                opt = a.option(valid)
                given.add(opt)
                after = None
                if opt in ("-file", "-h5", "-hdf5"):
                    self._file_option(a, name, opt, opts)
                elif opt in ("-time", "-closeOnWrite"):
                    opts[opt] = True
                elif opt == "-precision":
                    opts[opt] = a.int("-precision")
                elif opt == "-dT":
                    opts[opt] = a.float("-dT")
                elif opt in ("-node", "-ele"):
                    tags = a.ints(f"{opt} tag")
                    if not tags and a.more() and not str(a.peek()).startswith("-"):
                        raise CommandError(f"{name}: {opt} tag must be an integer, got {a.peek()!r}")
                    if not tags:
                        raise CommandError(f"{name}: {opt} names no {'node' if is_node else 'element'}; "
                                           f"give the tags: {opt} 1 2 ...")
                    targets, after = (targets or []) + tags, opt
                elif opt in ("-nodeRange", "-eleRange"):
                    lo, hi = a.int(f"{opt} start"), a.int(f"{opt} end")
                    what = "node" if is_node else "element"
                    if hi < lo:
                        raise CommandError(f"{name}: {opt} {lo} {hi}: the end is before the start")
                    pool = model.nodes if is_node else model.element_tags()
                    tags = [t for t in sorted(pool) if lo <= t <= hi]
                    if not tags:
                        raise CommandError(f"{name}: {opt} {lo} {hi} holds no {what} of the model")
                    targets = (targets or []) + tags
                else:
                    opts["-dof"], after = a.ints("-dof"), "-dof"
            else:
                response.append(a.take("response"))
        if not response:
            raise self._no_response(name, opts, NODE_RESPONSES if is_node else self._element_responses(targets))
        self._refuse_text_options(name, opts, given)
        option_at = next((k for k, w in enumerate(response) if is_option(w)), None)
        if option_at is not None and response[0] in (NODE_RESPONSES if is_node else self._element_responses(targets)):
            raise self._response_not_last(name, a.items, last_option, len(response), option_at, after)
        if after is not None:   # a word that is not a tag among the values of -node, -ele or -dof
            what = {"-node": "-node tag", "-ele": "-ele tag", "-dof": "-dof"}[after]
            rest = response[1:]
            if is_node and (not rest or option_at is not None) and isinstance(response[0], str) \
                    and response[0] not in NODE_RESPONSES:
                raise CommandError(f"{name}: {response[0]!r} is neither a {what} (an integer) nor a response "
                                   f"({', '.join(NODE_RESPONSES)})")
            if not isinstance(response[0], str) or any(isinstance(w, str) and w.startswith("-") for w in rest) or (
                    rest and (response[-1] in NODE_RESPONSES if is_node else len(rest) == 1
                              and response[0] not in PART_WORDS)):
                raise CommandError(f"{name}: {what} must be an integer, got {response[0]!r}")
        if not is_node:
            if not isinstance(response[0], str):
                raise CommandError(f"{name}: response must be a name (one of "
                                   f"{', '.join(self._element_responses(targets))}), got {response[0]!r}")
        elif len(response) > 1 or not isinstance(response[0], str):
            raise CommandError(f"{name}: response {' '.join(map(str, response))!r} is not supported; supported: "
                               + ", ".join(NODE_RESPONSES))
        else:
            response = response[0]
        envelope = kind.startswith("Envelope")
        if is_node:
            if response not in NODE_RESPONSES:
                raise CommandError(f"{name}: response {response!r} is not supported; supported: "
                                   f"{', '.join(NODE_RESPONSES)}")
            nodes = sorted(model.nodes) if targets is None else [n for n in targets if n in model.nodes]
            missing = [] if targets is None else [n for n in targets if n not in model.nodes]
            if missing and not nodes:
                many = len(missing) > 1
                raise CommandError(f"{name}: node{'s' * many} {', '.join(map(str, missing))} do{'' if many else 'es'} "
                                   "not exist (OpenSees writes a file of no values; vtsi's node recorder records at "
                                   "least one node)")
            dofs = opts.get("-dof")
            if not dofs:
                raise CommandError(f"{name}: no dofs (-dof 1 2 ...)")
            for d in dofs:
                if not 1 <= d <= model.ndf:
                    raise CommandError(f"{name}: dof {d} is out of range 1..{model.ndf}")
            if missing:
                self._warn_missing(name, response, "node", missing, nodes)
            make = lambda s: rec.NodeRecorder(nodes, dofs, response, sink=s, dt=opts["-dT"],
                                              envelope=envelope, history=not envelope)
        else:
            words, asked = response, " ".join(map(str, response))
            response = ELEMENT_RESPONSE_ALIASES.get(asked, asked)
            if targets is None:
                raise CommandError(f"{name}: no elements given (-ele 1 2 ... or -eleRange first last), as OpenSees")
            elements = [e for e in targets if e in model._element_owner]
            kept = self._answering(name, elements, words)     # before the sink: a refusal creates no file
            sink = self._recorder_sink(name, opts)      # made before the warnings, which name its file
            path = getattr(sink, "path", None)
            if len(elements) < len(targets):
                self._warn_missing(name, asked, "element", [e for e in targets if e not in model._element_owner],
                                   elements, path)
            if elements:
                self._warn_lacking(name, elements, kept, asked, path)
            return self._register_recorder(command_element_recorder(self, kept, response, sink=sink,
                                                                    dt=opts["-dT"], envelope=envelope,
                                                                    history=not envelope))
        return self._register_recorder(make(self._recorder_sink(name, opts)))

    def _answering(self, name, elements, words):
        """The ``elements`` (tags) that answer the response ``words`` (one name, or several for a
        response of a part of the element: ``section 1 force``), by
        :func:`~.responses.element_answers`, which refuses one OpenSees answers and vtsi does not."""
        asm = self.domain.build()
        kept = []
        for e in elements:
            etype = asm.blocks[asm.element_location[e][0]][0]
            if element_answers(name, e, etype, words, accepted_responses(etype, asm.ndf, self._zero_length.get(e))):
                kept.append(e)
        return kept

    @staticmethod
    def _warn_missing(name, asked, what, missing, recorded, path=None):
        """As in OpenSees, a node or element (``what``) of the recorder's selection that does not
        exist (``missing``, their tags) gets no columns, and a warning (logged: on stderr by
        default; OpenSees says nothing) names it; when no other is in the selection
        (``recorded``), the warning names the file ``path`` (None: in memory), which holds no
        values (a text file only the times with ``-time``, as OpenSees writes it)."""
        many = len(missing) > 1
        head = (f"{name} {asked}: {what}{'s' * many} {', '.join(map(str, missing))} do{'' if many else 'es'} not "
                f"exist and get{'' if many else 's'} no columns, as in OpenSees")
        if recorded:
            log.warning("%s", head)
        else:
            log.warning("%s: %s holds no values", head, path if path is not None else "the record")

    def _warn_lacking(self, name, elements, kept, asked, path):
        """As in OpenSees, an element of ``elements`` not ``kept`` (it has no response ``asked``)
        gets no columns, and a warning (logged: on stderr by default) names it; when none
        answers, as OpenSees, the record has no columns (the file ``path``, None: in memory,
        holds no values: a text file only the times with ``-time``, as OpenSees writes it), and
        the warning names the file and the responses the first element answers."""
        asm = self.domain.build()
        lacking = [e for e in elements if e not in kept]
        if lacking:
            which = ", ".join(f"{e} ({asm.blocks[asm.element_location[e][0]][0].name})" for e in lacking)
            many = len(lacking) > 1
            head = (f"{name} {asked}: element{'s' * many} {which} {'have' if many else 'has'} no response {asked!r} "
                    f"and get{'' if many else 's'} no columns, as in OpenSees")
            if kept:
                log.warning("%s; the record holds those of element%s %s", head, "s" * (len(kept) > 1),
                            ", ".join(map(str, kept)))
            else:
                e = elements[0]
                valid = accepted_responses(asm.blocks[asm.element_location[e][0]][0], asm.ndf,
                                           self._zero_length.get(e))
                log.warning("%s: %s holds no values (element %s answers %s)", head,
                            path if path is not None else "the record", e, ", ".join(valid))

    def _register_recorder(self, recorder):
        """Give ``recorder`` the next tag (OpenSees: a counter wipe() does not reset), keep it open
        across analyze() calls, and return the tag."""
        tag = self._recorder_count
        self._recorder_count += 1
        recorder.tag = tag
        if self._units != Units():                  # its values are in the model's units: so are its labels
            recorder.unit_label = self._units.label
        self.recorders[tag] = recorder
        self._kept[tag] = KeptOpen(recorder)
        return tag

    @staticmethod
    def _file_option(a, name, opt, opts):
        """Take the file name after ``opt`` (-file, -h5 or -hdf5) from the arguments ``a`` into
        ``opts['sink']`` = ``(opt, path)``: one file per recorder, and a name, not an option that
        takes values, must follow (a flag such as ``-time`` is a name, as in OpenSees)."""
        if "sink" in opts:
            raise CommandError(f"{name}: give one output file (-file, -h5 or -hdf5)")
        if not a.more():
            raise CommandError(f"{name}: {opt} needs a file name, got none")
        follows = a.peek()
        if not isinstance(follows, str) or follows in VALUE_OPTIONS:
            got = f"none ({follows!r} follows)" if isinstance(follows, str) else repr(follows)
            raise CommandError(f"{name}: {opt} needs a file name, got {got}")
        opts["sink"] = (opt, a.take(f"{opt} file name"))

    @staticmethod
    def _no_response(name, opts, responses):
        """The CommandError of a recorder given no response (``responses``: the names it takes),
        naming the file option that took one for its file name (``-file disp``: the name left out)."""
        opt, path = opts.get("sink", (None, None))
        if path in responses:
            example = f"{opt} out.{'txt' if opt == '-file' else 'h5'} {path}"
            return CommandError(f"{name}: no response given: {opt} took {path!r} for its file name; give the "
                                f"file name after {opt}, the response last ({example})")
        return CommandError(f"{name}: no response given" + (f" (one of {', '.join(responses)})" if responses else ""))

    @staticmethod
    def _response_not_last(name, items, last_option, n_response, option_at, after):
        """The CommandError of a Node or Element recorder whose response (``n_response`` words at the
        end of ``items``, the command's arguments) is followed by an option at ``option_at``: the
        response comes last, as OpenSees takes every word after it for the response. The example
        moves it there, from the last option before it (at ``last_option``, None: none) on; a file option
        left last without its name is named instead, as :meth:`_file_option` names it."""
        if items[-1] in ("-file", "-h5", "-hdf5"):
            return CommandError(f"{name}: {items[-1]} needs a file name, got none")
        start = len(items) - n_response
        first = 1 if last_option is None else last_option        # items[0] is the recorder type
        words = items[first: start] + items[start + option_at:] + items[start: start + option_at]
        example = ("... " if first > 1 else "") + " ".join(map(str, words))
        prefix = f"{after}: " if after is not None else ""
        return CommandError(f"{name}: {prefix}{items[start]!r} is a response; the response comes last, after every "
                            f"option ({example})")

    @staticmethod
    def _refuse_text_options(name, opts, given):
        """Refuse an option of a text file (:data:`TEXT_ONLY`) among ``given`` with an HDF5 file."""
        clash = sorted(set(given) & set(TEXT_ONLY)) if opts.get("sink", ("-file",))[0] != "-file" else []
        if clash:
            raise CommandError(f"{name}: {clash[0]} does nothing with {opts['sink'][0]}: {TEXT_ONLY[clash[0]]}")

    def _recorder_sink(self, name, opts):
        """The sink of ``opts['sink']`` (``(option, path)``; none: memory). ``-precision`` must be
        >= 0 (0 writes as 1, OpenSees's and C's ``%.0g``; OpenSees takes a negative one as 6)."""
        if opts["-precision"] < 0:
            raise CommandError(f"{name}: -precision must be an integer >= 0, got {opts['-precision']}")
        if "sink" not in opts:
            return rec.MemorySink()
        opt, path = opts["sink"]
        same = os.path.normcase(os.path.realpath(path)) if isinstance(path, str) and path.strip() else None
        for tag, kept in self._kept.items():      # before the file is truncated or replaced
            other = getattr(kept.sink, "path", None)
            if same is not None and isinstance(other, str) and os.path.normcase(os.path.realpath(other)) == same:
                raise CommandError(f"{name}: recorder {tag} already writes {path}; give each recorder its own "
                                   f"file (or remove recorder {tag} first)")
        if opt == "-file":
            return rec.TextSink(path, time=opts["-time"], precision=opts["-precision"],
                                close_on_write=opts["-closeOnWrite"])
        # as OpenSees's file recorders (-file): a re-run script replaces its file (the Python API's
        # HDF5Sink refuses an existing file unless overwrite=True)
        return rec.HDF5Sink(path, overwrite=True)

