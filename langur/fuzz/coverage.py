"""Rule coverage of a campaign (after PLT Redex's ``covered-cases``; issue 13).

How often each rule of the paper's figures fires while a campaign runs: Fig. 6 (typing of terms,
:func:`langur.typesys.type_term`), Fig. 7 (⟦t⟧ as simply decomposable pieces,
:func:`langur.symbolic.decompose.decompose`, whose smooth pieces are
:func:`langur.sympy_bridge.denote`), Fig. 8 (⦇t⦈
in the exact engine, :func:`langur.ddenote.ddenote_subterm`, and in the Monte Carlo engine's compiler,
:func:`langur.operational.compile.compile_subterm`), Fig. 11 (typing of programs,
:func:`langur.typesys.type_program`), Fig. 12 (⟦p⟧, :func:`langur.denote.denote_program`), and
each kind of diffeomorphism completion met by Fig. 8's diffeomorphic conditional.

Nothing in the semantics knows about coverage: while :func:`recording` is active, each of those
functions is wrapped (its module's global, through which its ``match`` recurses) by a wrapper
that calls :func:`fired` with the rule its ``match`` case is about to apply — the rule is the
case's term constructor — and calls the function; and the rules are marked as watched
(:func:`langur.observe.counted`), so that no memo skips an application.  A call made through a
name imported into another module before the wrapping is not seen (the first call of a tree; its
recursion is).
"""

from __future__ import annotations

import contextlib
from collections import Counter

from .. import ddenote, denote, exact, observe, sympy_bridge, theorem, typesys
from ..core import Add, Call, Const, IfDiffeo, IfGe0, Let, Mul, Param, Pow, Prim, Var
from ..operational import compile as mc_compile
from ..symbolic import decompose

#: The rules of each figure, in the figure's order (LANGUAGE.md, the paper's Fig. 6, 7, 8, 11, 12).
TERM_RULES = {Const: "constant", Var: "variable", Param: "parameter", Add: "sum", Mul: "product",
              Prim: "primitive", Pow: "power", IfGe0: "conditional", IfDiffeo: "diffeomorphic conditional",
              Let: "let", Call: "call"}
#: The completion kinds of a diffeomorphic conditional (LANGUAGE.md §6).
COMPLETIONS = ("declared", "completed, one inverse branch", "completed, several inverse branches",
               "completed, parameter coefficient (nonzero)")
_CORE = tuple(r for r in TERM_RULES.values() if r != "call")
#: The rules counted: a call is met only by the Monte Carlo engine, which compiles defs separately
#: (§9); the front end inlines them for the exact engine and the type system.
FIGURES = {
    "Fig. 6": _CORE,
    "Fig. 7": _CORE,
    "Fig. 8 exact": _CORE,
    "Fig. 8 mc": tuple(TERM_RULES.values()),
    "Fig. 11": ("program",),
    "Fig. 12": ("program",),
    "completion": COMPLETIONS,
}

_counts: Counter = Counter()


def fired(figure: str, rule: str) -> None:
    """Count one application of ``rule`` of ``figure``."""
    _counts[(figure, rule)] += 1


def counts() -> Counter:
    """The counts so far: (figure, rule) → applications."""
    return Counter(_counts)


def reset() -> None:
    _counts.clear()


def completion_kind(psi) -> str:
    """The kind of ``psi``: declared (``diffeo``), or completed (LANGUAGE.md §6) with a parameter
    coefficient that must not vanish, with several (guarded) inverse branches, or with one."""
    if psi.name is not None:
        return COMPLETIONS[0]
    if psi.nonzero:
        return COMPLETIONS[3]
    return COMPLETIONS[1] if len(psi.branches) == 1 else COMPLETIONS[2]


def _by_term(figure: str, fn, index: int):
    def wrapper(*args, **kwargs):
        t = args[index]
        rule = TERM_RULES.get(type(t))
        if rule is not None:
            fired(figure, rule)
            if figure == "Fig. 8 exact" and isinstance(t, IfDiffeo):
                fired("completion", completion_kind(t.psi))
        return fn(*args, **kwargs)
    return wrapper


def _whole(figure: str, fn):
    def wrapper(*args, **kwargs):
        fired(figure, "program")
        return fn(*args, **kwargs)
    return wrapper


def _hooks():
    return [
        (typesys, "type_term", lambda f: _by_term("Fig. 6", f, 2)),
        (decompose, "decompose", lambda f: _by_term("Fig. 7", f, 0)),  # conditionals: pieces
        (sympy_bridge, "denote", lambda f: _by_term("Fig. 7", f, 0)),  # smooth terms: one expression
        (ddenote, "ddenote_subterm", lambda f: _by_term("Fig. 8 exact", f, 0)),
        (mc_compile, "compile_subterm", lambda f: _by_term("Fig. 8 mc", f, 0)),
        (typesys, "type_program", lambda f: _whole("Fig. 11", f)),
        *[(m, "denote_program", lambda f: _whole("Fig. 12", f)) for m in (denote, exact, theorem)
          if "denote_program" in vars(m)],
    ]


@contextlib.contextmanager
def recording():
    """Count rule applications (:func:`fired`) while the block runs; the functions are unwrapped after."""
    saved = []
    try:
        for module, name, wrap in _hooks():
            original = getattr(module, name)
            saved.append((module, name, original))
            setattr(module, name, wrap(original))
        with observe.counted():  # (the passes that would skip applications stand aside)
            yield
    finally:
        for module, name, original in reversed(saved):
            setattr(module, name, original)


def table(c: Counter) -> list[tuple[str, str, int]]:
    """Every rule of :data:`FIGURES` with its count (0 included), in the figures' order."""
    return [(fig, rule, c.get((fig, rule), 0)) for fig, rules in FIGURES.items() for rule in rules]
