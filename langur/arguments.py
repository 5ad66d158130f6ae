"""A command's arguments declared once, read without argparse when the command line is plain
(issue 15, start-up).

``argparse`` costs a one-shot ``langur eval FILE --engine mc`` about 16 M instructions, 3 % of the
process: its import with ``gettext``'s (7.7 M), ``locale``'s (3.6 M, imported by ``gettext``'s first
search for a translation, which every parser makes for its help's titles), and the parsers built and
run (4.4 M), though such a command line is only names and values.  Each command still declares its
arguments through ``add_arguments(p)`` alone; :class:`Arguments` is given to it first and records
the calls.  When the command is the command line's first word and every word after it is plain —
the command's positionals, and its long options spelt out in full, each with its value as the next
word or after ``=`` — :meth:`Arguments.parse` reads them as argparse would (the same types,
choices, defaults and order of attributes).  Anything else (``--help``, a short or abbreviated
option, ``--``, a value that starts with ``-``, a type or choice refused, a missing or extra
positional, an option argparse would find ambiguous, a feature the reading does not cover) returns
``None``, and the command line goes to argparse, which answers as it always did: help, errors and
exit statuses come from it alone.  ``proofs_tests/test_oneshot23.py`` checks both readings against
each other on random command lines.
"""

from __future__ import annotations

from types import SimpleNamespace

#: ``add_argument``'s keywords the direct reading covers (any other: argparse reads the command line).
_KEYWORDS = frozenset({"action", "type", "default", "choices", "metavar", "help"})
#: The actions it covers (argparse's names).
_ACTIONS = frozenset({"store", "store_true", "append"})


class _Action:
    __slots__ = ("dest", "kind", "type", "default", "choices")

    def __init__(self, dest: str, kind: str, options: dict):
        self.dest, self.kind = dest, kind
        self.type = options.get("type")
        self.default = options.get("default", False if kind == "store_true" else None)
        self.choices = options.get("choices")


class Arguments:
    """Stands for an ``argparse`` parser while a command declares its arguments (``add_argument``,
    ``set_defaults``), and reads a plain command line with them (:meth:`parse`)."""

    def __init__(self):
        self.positionals: list[_Action] = []
        self.options: dict[str, _Action] = {}
        self.order: list[_Action] = []  # (argparse's order of the attributes: the declarations')
        self.defaults: dict[str, object] = {}
        self.plain = True  # every declaration is one the direct reading covers

    def add_argument(self, *flags: str, **options) -> None:
        kind = options.get("action", "store")
        if self.defaults:
            self.plain = False  # (argparse's default may then come from set_defaults: left to it)
            return
        if not flags or not _KEYWORDS.issuperset(options) or kind not in _ACTIONS:
            self.plain = False
            return
        if not flags[0].startswith("-"):
            if len(flags) > 1 or kind != "store":
                self.plain = False
                return
            action = _Action(flags[0], kind, options)
            self.positionals.append(action)
        else:
            long = [f for f in flags if f.startswith("--")]
            if not long:
                self.plain = False
                return
            action = _Action(long[0][2:].replace("-", "_"), kind, options)
            for flag in long:  # (a short flag is left to argparse: the reading declines it)
                self.options[flag] = action
        self.order.append(action)

    def set_defaults(self, **defaults) -> None:
        if any(action.dest in defaults for action in self.order):
            self.plain = False  # (argparse then changes the argument's default: left to it)
        self.defaults.update(defaults)

    def parse(self, words: list[str], before: dict, reserved: tuple[str, ...] = ()) -> SimpleNamespace | None:
        """The attributes argparse gives ``words`` (the command line after the command's name), after
        ``before`` (the attributes the command line's parser sets first: the command's name), or
        None when the words are not plain (see above).  ``reserved``: the options of the parser
        above the command's (``--help``, ``--version``), which argparse also matches ``words``
        against."""
        if not self.plain:
            return None
        given: dict[str, object] = {}
        positionals: list[str] = []
        i = 0
        while i < len(words):
            word = words[i]
            i += 1
            if not word.startswith("-"):
                positionals.append(word)
                continue
            name, eq, value = word.partition("=")
            action = self.options.get(name)
            if action is None or any(r.startswith(name) for r in reserved):
                return None  # (-h, --help, -, --, a short or abbreviated option, an unknown one)
            if action.kind == "store_true":
                if eq:
                    return None  # (argparse: "ignored explicit argument")
                given[action.dest] = True
                continue
            if not eq:
                if i == len(words) or words[i].startswith("-"):
                    return None
                value = words[i]
                i += 1
            value = _converted(action, value)
            if value is _REFUSED:
                return None
            if action.kind == "append":
                given[action.dest] = [*(given.get(action.dest) or ()), value]
            else:
                given[action.dest] = value
        if len(positionals) != len(self.positionals):
            return None
        for action, word in zip(self.positionals, positionals):
            value = _converted(action, word)
            if value is _REFUSED:
                return None
            given[action.dest] = value
        out = dict(before)
        for action in self.order:
            if action.dest in given:
                out[action.dest] = given[action.dest]
            elif isinstance(action.default, str) and action.type is not None:  # (argparse converts it)
                value = _converted(action, action.default)
                if value is _REFUSED:
                    return None
                out[action.dest] = value
            else:
                out[action.dest] = action.default
        for name, value in self.defaults.items():
            out.setdefault(name, value)
        return SimpleNamespace(**out)


_REFUSED = object()


def _converted(action: _Action, word: str):
    """``word`` through the action's type and choices, or ``_REFUSED`` (argparse reports why)."""
    if action.type is not None:
        try:
            value = action.type(word)
        except Exception:  # (argparse turns the type's refusal into its usage error)
            return _REFUSED
    else:
        value = word
    if action.choices is not None and value not in action.choices:
        return _REFUSED
    return value
