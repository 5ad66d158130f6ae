"""Surface syntax of `.lgr` files (LANGUAGE.md §6): what the parser builds, before desugaring.

Every node carries the ``span`` of its source text.  Spans do not take part in equality.
The desugarer (``langur.syntax.desugar``) is the only consumer; it maps these nodes to the core
language of ``langur.core`` exactly as LANGUAGE.md §6's table says.
"""

from __future__ import annotations

from dataclasses import field
from fractions import Fraction
from typing import Union

from ..diagnostics import Span
from ..records import frozen


def _span() -> Span | None:
    return field(default=None, compare=False, repr=False)  # type: ignore[return-value]


# --- terms ------------------------------------------------------------------------------------


@frozen
class Num:
    """A decimal literal, read exactly (``0.5`` is ``Fraction(1, 2)``)."""

    value: Fraction
    span: Span | None = _span()

    def __init__(self, value, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["value"], d["span"] = value, span


@frozen
class Name:
    """A name in a term: variable, parameter, let-bound name, def argument, or ``pi``."""

    name: str
    span: Span | None = _span()

    def __init__(self, name, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["name"], d["span"] = name, span


@frozen
class BinOp:
    """``left op right`` with ``op`` one of ``+ - * / ^``."""

    op: str
    left: "STerm"
    right: "STerm"
    span: Span | None = _span()

    def __init__(self, op, left, right, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["op"], d["left"], d["right"], d["span"] = op, left, right, span


@frozen
class Neg:
    """Unary minus ``-arg``."""

    arg: "STerm"
    span: Span | None = _span()

    def __init__(self, arg, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["arg"], d["span"] = arg, span


@frozen
class Apply:
    """``name(args…)``: a primitive (``exp``, …, ``abs``, ``min``, ``max``) or a def call."""

    name: str
    args: tuple["STerm", ...]
    span: Span | None = _span()
    name_span: Span | None = _span()

    def __init__(self, name, args, span=None, name_span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["name"], d["args"], d["span"], d["name_span"] = name, args, span, name_span


@frozen
class Iverson:
    """``[t0 op0 t1 op1 t2 …]``: a chain of comparisons, ``ops[i]`` between ``terms[i]`` and ``terms[i+1]``."""

    terms: tuple["STerm", ...]
    ops: tuple[str, ...]  # each one of "<=", ">=", "<", ">"
    span: Span | None = _span()

    def __init__(self, terms, ops, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["terms"], d["ops"], d["span"] = terms, ops, span


@frozen
class Logic:
    """``[A & B & …]``, ``[A | B | …]`` or ``[not A]`` over comparison chains ``parts``."""

    op: str  # "and", "or" or "not"
    parts: tuple[Iverson, ...]
    span: Span | None = _span()


@frozen
class IfLogic:
    """``if A & B & … then s else r`` (also ``|``, and ``if not A``) over comparison chains."""

    cond: Logic
    then: "STerm"
    orelse: "STerm"
    span: Span | None = _span()


@frozen
class LetIn:
    """``let name = bound in body``."""

    name: str
    bound: "STerm"
    body: "STerm"
    span: Span | None = _span()
    name_span: Span | None = _span()


@frozen
class DiffeoApp:
    """``NAME(terms ; terms)`` in the condition of ``ifge0``: a declared diffeo applied (⌊Ψ⌋)."""

    name: str
    variables: tuple["STerm", ...]
    params: tuple["STerm", ...]
    span: Span | None = _span()
    name_span: Span | None = _span()


@frozen
class IfGe0S:
    """``ifge0 cond then then else orelse``; ``cond`` a term or a :class:`DiffeoApp`."""

    cond: Union["STerm", DiffeoApp]
    then: "STerm"
    orelse: "STerm"
    span: Span | None = _span()


@frozen
class IfCmp:
    """``if left op right then then else orelse``."""

    left: "STerm"
    op: str
    right: "STerm"
    then: "STerm"
    orelse: "STerm"
    span: Span | None = _span()


@frozen
class NestedInt:
    """``int (domain)? body d(variables)`` where a term is expected.  Parsed only so that the type
    system can reject it at its text with its own code (T208, Fig. 11: a term contains no ``int``)."""

    domain: tuple["Interval", ...] | None
    body: "STerm"
    variables: tuple["Ident", ...]
    span: Span | None = _span()


@frozen
class Loop:
    """``sum i in lo..hi: body`` or ``prod i in lo..hi: body``: the finite loop of §9 ("a finite
    looping construct that is syntactic sugar and is unrolled"); ``index`` is an integer constant
    in ``body``."""

    op: str  # "sum" or "prod"
    index: str
    lo: "STerm"
    hi: "STerm"
    body: "STerm"
    span: Span | None = _span()
    name_span: Span | None = _span()

    def __init__(self, op, index, lo, hi, body, span=None, name_span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["op"], d["index"], d["lo"], d["hi"], d["body"], d["span"], d["name_span"] = op, index, lo, hi, body, span, name_span


@frozen
class Vector:
    """``(t1, t2, …)``: a small fixed-size vector of at least two terms (desugared to its
    components: vectors never reach the core language)."""

    parts: tuple["STerm", ...]
    span: Span | None = _span()


@frozen
class Component:
    """``v.x``, ``v.y``, ``v.z``, ``v.w``: a component of a vector."""

    vector: "STerm"
    name: str
    span: Span | None = _span()
    name_span: Span | None = _span()


class Fields:
    """A node's fields, writable: the parser fills one and makes it the node it builds most —
    :class:`Num`, :class:`Name`, :class:`BinOp` — by assigning its class, without a call of the
    node's ``__init__`` (issue 15, parse25: ≈ 1.7–1.9 k instructions a node instead of 2.7–3.7 k)::

        n = Fields()
        n.value = value  # the fields in the order of the class's __init__ (the same __dict__)
        n.span = span
        n.__class__ = Num

    Never kept as it is; a record with a ``__dict__`` and no slots of its own (any of this
    module's), so that Python allows the assignment."""


STerm = Union[Num, Name, BinOp, Neg, Apply, Iverson, Logic, LetIn, IfGe0S, IfCmp, IfLogic, NestedInt, Loop, Vector,
              Component]


# --- declarations and modules -----------------------------------------------------------------


@frozen
class Ident:
    """A name being declared or bound, with where it was written."""

    name: str
    span: Span | None = _span()

    def __init__(self, name, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["name"], d["span"] = name, span


@frozen
class ParamDecl:
    """One ``pdecl`` of a ``param`` item: a name with an optional numeric default."""

    name: Ident
    default: Fraction | None
    span: Span | None = _span()

    def __init__(self, name, default, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["name"], d["default"], d["span"] = name, default, span


@frozen
class ParamItem:
    """``param a = 1, b``: one declaration line of parameters."""

    decls: tuple[ParamDecl, ...]
    span: Span | None = _span()

    def __init__(self, decls, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["decls"], d["span"] = decls, span


@frozen
class DiffeoDecl:
    """``diffeo name(variables; params) = (forward…) inverse (inputs) = (inverse…)``."""

    name: Ident
    variables: tuple[Ident, ...]
    params: tuple[Ident, ...]
    forward: tuple[STerm, ...]
    inputs: tuple[Ident, ...]
    inverse: tuple[STerm, ...]
    span: Span | None = _span()


@frozen
class DefArg:
    """An argument of a ``def``: its name and kind (``var`` or ``param``)."""

    name: Ident
    kind: str  # "var" | "param"
    span: Span | None = _span()


@frozen
class DefDecl:
    """``def name(args) = body``."""

    name: Ident
    args: tuple[DefArg, ...]
    body: STerm
    span: Span | None = _span()


@frozen
class ImportName:
    """``name [as alias]`` in an import."""

    name: Ident
    alias: Ident | None
    span: Span | None = _span()


@frozen
class ImportItem:
    """``from module import name [as alias], …``."""

    module: Ident
    names: tuple[ImportName, ...]
    span: Span | None = _span()


Item = Union[ParamItem, DiffeoDecl, DefDecl, ImportItem]


@frozen
class Interval:
    """``[lo, hi]``: one interval of a program's domain."""

    lo: STerm
    hi: STerm
    span: Span | None = _span()

    def __init__(self, lo, hi, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["lo"], d["hi"], d["span"] = lo, hi, span


@frozen
class ProgramS:
    """``int (domain)? body d(variables)``; ``domain`` is ``None`` when absent."""

    domain: tuple[Interval, ...] | None
    body: STerm
    variables: tuple[Ident, ...]
    span: Span | None = _span()

    def __init__(self, domain, body, variables, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["domain"], d["body"], d["variables"], d["span"] = domain, body, variables, span


@frozen
class ModuleS:
    """A parsed `.lgr` file: its items in order, then at most one program."""

    path: str
    items: tuple[Item, ...]
    program: ProgramS | None
    span: Span | None = _span()

    def __init__(self, path, items, program, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["path"], d["items"], d["program"], d["span"] = path, items, program, span
