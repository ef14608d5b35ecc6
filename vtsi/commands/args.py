"""Arguments of OpenSees-style commands: a cursor that names the command and the argument in
every error, the Tcl word rules (OpenSees reads an integer word as an int, a number as a float)
and small readers shared by the command modules."""
import math
import re

import numpy as np

from vtsi.errors import CommandError, is_int, is_number


class UnknownCommand(CommandError, AttributeError):
    """A command (or module attribute) that this layer does not offer."""


def is_list(x):
    """Whether the argument ``x`` is a list: a Python list, tuple or array of 1 or more dimensions
    (a Tcl word holding several numbers, ``{4.0 1.0}``, ``$props``, arrives as a list:
    :func:`convert_word`)."""
    return isinstance(x, (list, tuple)) or (isinstance(x, np.ndarray) and x.ndim > 0)


def list_values(x):
    """The items of the list ``x`` (:func:`is_list`; an array's flattened)."""
    return list(np.ravel(x)) if isinstance(x, np.ndarray) else list(x)


class Args:
    """A cursor over one command's arguments; every error names the command and the argument.

    An argument is one value, as OpenSees reads it: a list (:func:`is_list`) is spread only
    where OpenSees takes a list as one word (:meth:`number_list`: ``-values {0 1 2}``); where
    one number is expected it is refused naming the argument and the list, as OpenSees's Tcl
    fails on ``node 3 {4.0 1.0}`` and OpenSeesPy on ``node(3, [4.0, 1.0])``."""

    def __init__(self, command, args):
        self.command = command
        self.items = tuple(args)    # (a command's own tuple is not copied)
        self.pos = 0
        self.once = set()           # the options read with option(..., once=True)

    def more(self):
        return self.pos < len(self.items)

    def peek(self):
        return self.items[self.pos] if self.more() else None

    def next_is_number(self):
        return self.more() and is_number(self.peek())

    def numbers_ahead(self):
        """How many numbers follow the cursor before the next word or the end."""
        k = self.pos
        while k < len(self.items) and is_number(self.items[k]):
            k += 1
        return k - self.pos

    def take(self, what):
        if not self.more():
            raise CommandError(f"{self.command}: missing {what}")
        x = self.items[self.pos]
        self.pos += 1
        return x

    def int(self, what):
        x = self.take(what)
        if type(x) is int:
            return x
        if not is_int(x):
            raise self._refused(what, x, "an integer")
        return int(x)

    def float(self, what):
        x = self.take(what)
        if not is_number(x):
            raise self._refused(what, x, "a number")
        x = float(x)
        if not math.isfinite(x):
            raise CommandError(f"{self.command}: {what} must be finite, got {x}")
        return x

    def word(self, what, choices=None):
        x = self.take(what)
        if not isinstance(x, str):
            raise CommandError(f"{self.command}: {what} must be a name, got {x!r}")
        if choices is not None and x not in choices:
            raise CommandError(f"{self.command}: {what} {x!r} is not supported; supported: {', '.join(choices)}")
        return x

    def option_floats(self, option, count=1, what="value"):
        """The ``count`` numbers after ``option`` (just read); a missing one raises ``'<command>:
        -mass needs 3 values (one per dof), got 1'`` (an option in its place is named: ``got 0
        ('-cMass' follows)``), another word in its place names it: ``'deadLoad: -dt needs a number
        (the run's time step [s]), got 'abc''``, ``'node 9: -mass needs 3 numbers (one per dof);
        value 2 is 'abc''``."""
        got = 0
        while got < count and self.next_is_number():
            got += 1
            self.pos += 1
        if got < count:
            if self.more() and is_list(self.peek()):
                raise self._refused(f"{option} ({what})", self.peek(), "a number")
            if self.more() and not is_option(self.peek()):
                word = self.peek()
                raise CommandError(f"{self.command}: {option} needs a number ({what}), got {word!r}" if count == 1 else
                                   f"{self.command}: {option} needs {count} numbers ({what}); value {got + 1} is "
                                   f"{word!r}")
            plural = f"{count} values" if count > 1 else "a value"
            found = f"{got} ({self.peek()!r} follows)" if self.more() else str(got) if got else "none"
            raise CommandError(f"{self.command}: {option} needs {plural} ({what}), got {found}")
        self.pos -= count
        return [self.float(f"{option} {what}") for _ in range(count)]

    def floats(self, what):
        """The numbers that follow, up to the next word, as floats (a NaN or ±inf one, or a list
        there, is refused naming ``what``, as :meth:`float` refuses it). One pass over the items:
        a script's ``load`` in a per-step loop reads its values here."""
        items, end = self.items, self.pos
        while end < len(items) and is_number(items[end]):
            end += 1
        out = [float(x) for x in items[self.pos: end]]
        if not all(map(math.isfinite, out)):
            bad = next(x for x in out if not math.isfinite(x))
            raise CommandError(f"{self.command}: {what} must be finite, got {bad}")
        self.pos = end
        if end < len(items) and is_list(items[end]):
            raise self._refused(what, items[end], "a number")
        return out

    def number_list(self, option):
        """The numbers after ``option`` (just read), up to the next option or the end, as floats:
        numbers, lists of them (:func:`is_list`: ``{0 1 2}``, ``$values``, a Python list or
        array), and Tcl list words (:func:`convert_word` leaves one holding a non-number a str),
        spread out. An item that is not a number raises naming ``option`` and the item's
        1-based position (``'timeSeries Path 1: -values item 3 is 'abc', not a number'``), a
        NaN or ±inf one likewise (``-values item 3 must be finite, got nan``), and so does a
        number given as a Python str (``'2'``: a Tcl word arrives converted), also in a list;
        none at all raises ``the -values list is empty``."""
        out = []
        while self.more() and not is_option(self.peek()):
            word = self.take(option)
            if isinstance(word, str) and convert_word(word) is word:     # a Tcl word: its items as Tcl reads them
                items = [(item, _list_item(item)) for item in split_list(word)]
            else:                                                       # a number, or a list of numbers
                items = [(value, value) for value in (list_values(word) if is_list(word) else [word])]
            for item, value in items:
                if not is_number(value):
                    raise CommandError(f"{self.command}: {option} item {len(out) + 1} is {item!r}, not a number")
                if not math.isfinite(value):
                    raise CommandError(f"{self.command}: {option} item {len(out) + 1} must be finite, got {value}")
                out.append(float(value))
        if not out:
            raise CommandError(f"{self.command}: the {option} list is empty; give its numbers after {option}")
        return out

    def ints(self, what):
        """The integers that follow, up to the next word (a list there is refused naming ``what``)."""
        out = []
        while self.next_is_number():
            out.append(self.int(what))
        if self.more() and is_list(self.peek()):
            raise self._refused(what, self.peek(), "an integer")
        return out

    def option(self, valid, once=False):
        """The next option name (a str); an unknown one raises naming it and the valid ones. With
        ``once``, an option given before (read with ``once``) raises ``'<command>: option -seed
        given twice'``, also where another option is expected and at :meth:`done`."""
        x = self.take(f"option {' or '.join(valid)}")
        if not isinstance(x, str):
            raise CommandError(f"{self.command}: unexpected argument {x!r} (expected an option: {', '.join(valid)})")
        self._refuse_repeat(x)
        if x not in valid:
            raise CommandError(f"{self.command}: option {x!r} is not supported; supported: {', '.join(valid)}")
        if once:
            self.once.add(x)
        return x

    def done(self):
        if self.more():
            self._refuse_repeat(self.peek())
            raise CommandError(f"{self.command}: unexpected argument {self.peek()!r}")

    def _refuse_repeat(self, x):
        if isinstance(x, str) and x in self.once:
            raise CommandError(f"{self.command}: option {x} given twice")

    def _refused(self, what, x, kind):
        """The CommandError of ``x`` read as ``what``, which must be ``kind`` ('a number', 'an
        integer'); a list (:func:`is_list`) is named as one, with its items."""
        if is_list(x):
            items = list_values(x)
            return CommandError(f"{self.command}: {what} must be {kind}, got a list of {len(items)} "
                                f"({' '.join(map(str, items))}); give each value as its own argument")
        return CommandError(f"{self.command}: {what} must be {kind}, got {x!r}")


def dof_value(values, dof, what):
    """``values`` (list) or its 1-based component ``dof`` (-1: all), as OpenSeesPy returns them."""
    if type(dof) is int and 1 <= dof <= len(values):
        return float(values[dof - 1])
    if dof == -1:
        return [float(v) for v in values]
    if not is_int(dof) or not 1 <= dof <= len(values):
        raise CommandError(f"{what}: dof must be -1 (all) or 1..{len(values)}, got {dof!r}")
    return float(values[int(dof) - 1])


# ---------------------------------------------------------------------------------------------
# time series with OpenSees's exact rules

def read_numbers(command, path):
    """The numbers of the text file ``path`` (whitespace-separated), or a CommandError."""
    try:
        with open(path) as fh:
            words = fh.read().split()
    except OSError as exc:
        raise CommandError(f"{command}: cannot read {path}: {exc.strerror}") from None
    try:
        return np.array([float(w) for w in words])
    except ValueError as exc:
        raise CommandError(f"{command}: {path} holds a word that is not a number ({exc})") from None



_INT = re.compile(r"^[+-]?\d+$")
_PREFIXED_INT = re.compile(r"^[+-]?0([xX][0-9a-fA-F]+|[oO][0-7]+|[bB][01]+)$")
_FLOAT = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_NONFINITE = re.compile(r"^[+-]?(inf(inity)?|nan)$", re.IGNORECASE)
"""The words Tcl's ``Tcl_GetDouble`` reads as ±inf (and ``NaN``, which it refuses): a number list
names them as not finite rather than as not numbers."""


def is_option(x):
    """Whether ``x`` is an option word (``-factor``), not a number (``-inf``) or a Tcl list
    (``-1 2``, ``-Inf 0``)."""
    return (isinstance(x, str) and len(x) > 1 and x[0] == "-" and x[1].isalpha() and not _NONFINITE.match(x)
            and not any(c.isspace() for c in x))


def _list_item(item):
    """An item of a number list as Tcl's ``Tcl_GetDouble`` reads it (``Inf`` too, and ``NaN``,
    for the list to name them as not finite); a non-number stays as it is."""
    if isinstance(item, str) and _NONFINITE.match(item.strip()):
        return float(item)
    return convert_word(item)


def convert_word(word):
    """A Tcl word as OpenSees reads it: ``int``, ``float``, a list of numbers (a word holding
    several numbers) or the ``str`` itself. Integers as ``Tcl_GetInt`` reads them: decimal,
    ``0x1f``, ``0o17``, ``0b101``; a leading zero is decimal (``010`` is 10, as in Tcl 9; Tcl
    8.6 reads it as octal 8)."""
    if not isinstance(word, str):
        return word
    w = word.strip()
    if _INT.match(w):
        return int(w)
    if _PREFIXED_INT.match(w):
        return int(w, 0)
    if _FLOAT.match(w):
        return float(w)
    if w and any(c.isspace() for c in w):
        items = split_list(w)
        if items and all(_INT.match(x) or _FLOAT.match(x) for x in items):
            return [convert_word(x) for x in items]
    return word


def split_list(text):
    """Split a Tcl list (whitespace-separated words; ``{...}`` and ``"..."`` group, braces nest)."""
    words, i, n = [], 0, len(text)
    while i < n:
        while i < n and text[i].isspace():
            i += 1
        if i >= n:
            break
        if text[i] == "{":
            depth, j = 1, i + 1
            while j < n and depth:
                if text[j] == "\\":
                    j += 2
                    continue
                depth += {"{": 1, "}": -1}.get(text[j], 0)
                j += 1
            if depth:
                raise CommandError(f"Tcl list {text!r}: unmatched open brace")
            words.append(text[i + 1: j - 1])
            i = j
        elif text[i] == '"':
            j = text.find('"', i + 1)
            if j < 0:
                raise CommandError(f"Tcl list {text!r}: unmatched quote")
            words.append(text[i + 1: j])
            i = j + 1
        else:
            j = i
            while j < n and not text[j].isspace():
                j += 1
            words.append(text[i:j])
            i = j
    return words


def tcl_words(text):
    """A Tcl-like word list (``'Path -dt 0.1 -values {1 2 3}'``) as typed words."""
    return [convert_word(w) for w in split_list(text)]
