"""Hypothesis strategies for the concrete syntax of `.lgr` files (LANGUAGE.md §6).

* :func:`surface_terms` – random surface ASTs exactly as the parser builds them (non-negative
  terminating literals, ``Neg`` for minus, ``DiffeoApp`` only as an ``ifge0`` condition, names
  never keywords except the soft keyword ``d``).
* :func:`surface_modules` – random whole modules (items, then maybe a program).
* :func:`relayout` – re-spaces a text at random between its tokens (spaces, tabs, newlines,
  comments), keeping its meaning: ``parse(relayout(print(ast))) == ast``.
* :func:`term_texts`, :func:`module_texts` – grammar-valid source texts with random layout.
* :func:`tokenize` – split a source into tokens (for mutation fuzzing).

The strategy factories are cached: building a recursive strategy is costly, and hypothesis
generates much faster from one strategy object reused than from a fresh one per draw.

Other helpers may import this module (from ``proofs_tests``).
"""

from __future__ import annotations

import re
from fractions import Fraction
from functools import cache

from hypothesis import strategies as st

from langur.syntax import surface as S
from langur.syntax.printer import print_module_surface, print_term

NAMES = ("x", "y", "z", "a", "b", "c", "theta", "mu", "u0", "x_1", "_t", "d", "pi", "inx", "iff", "dd")
FUNCS = ("exp", "log", "sin", "cos", "tan", "sqrt", "tanh", "atan", "abs", "min", "max", "f", "shade", "d")
CMPS = ("<=", ">=", "<", ">")
COMPONENTS = ("x", "y", "z", "w", "d", "q")  # any name parses after `.`; the desugarer knows x y z w

names = st.sampled_from(NAMES)
numbers = st.builds(
    lambda m, k: Fraction(m, 10**k),
    st.one_of(st.integers(0, 20), st.integers(0, 10**12)),
    st.integers(0, 6),
)


@st.composite
def iverson(draw, children) -> S.Iverson:
    """``[t0 op0 t1 …]`` with one to three comparisons."""
    ops = tuple(draw(st.lists(st.sampled_from(CMPS), min_size=1, max_size=3)))
    return S.Iverson(tuple(draw(children) for _ in range(len(ops) + 1)), ops)


@cache
def surface_terms(max_leaves: int = 16) -> st.SearchStrategy:
    """Random surface terms as the parser produces them (spans left out: they never compare)."""
    leaves = st.one_of(st.builds(S.Num, numbers), st.builds(S.Name, names))

    def extend(children):
        tuples = st.lists(children, min_size=1, max_size=3).map(tuple)
        # loop bounds: mostly small (a loop of 10⁴ copies is legal but slow to fuzz), or a name (T224),
        # or any term that is not a literal (the printer's parentheses around a bound)
        bounds = st.one_of(st.integers(0, 3).map(lambda k: S.Num(Fraction(k))), st.builds(S.Name, names),
                           children.filter(lambda t: not isinstance(t, S.Num)))
        diffeo_app = st.builds(S.DiffeoApp, names, tuples, st.lists(children, max_size=2).map(tuple))
        return st.one_of(
            st.builds(S.BinOp, st.sampled_from("+-*/^"), children, children),
            st.builds(S.Neg, children),
            st.builds(S.Apply, st.sampled_from(FUNCS), st.lists(children, max_size=3).map(tuple)),
            iverson(children),
            st.builds(S.LetIn, names, children, children),
            st.builds(S.IfGe0S, st.one_of(children, diffeo_app), children, children),
            st.builds(S.IfCmp, children, st.sampled_from(CMPS), children, children, children),
            st.builds(S.Loop, st.sampled_from(("sum", "prod")), names, bounds, bounds, children),
            st.builds(S.Vector, st.lists(children, min_size=2, max_size=4).map(tuple)),
            st.builds(S.Component, children, st.sampled_from(COMPONENTS)),
        )

    return st.recursive(leaves, extend, max_leaves=max_leaves)


def _idents(n_min=1, n_max=3):
    return st.lists(st.builds(S.Ident, names), min_size=n_min, max_size=n_max).map(tuple)


@st.composite
def diffeo_decls(draw, terms) -> S.DiffeoDecl:
    n = draw(st.integers(1, 3))
    return S.DiffeoDecl(
        S.Ident(draw(names)),
        draw(_idents(1, 3)),
        draw(_idents(0, 2)),
        tuple(draw(terms) for _ in range(n)),
        draw(_idents(n, n)),
        tuple(draw(terms) for _ in range(n)),
    )


@cache
def surface_items() -> st.SearchStrategy:
    terms = surface_terms(6)
    defaults = st.one_of(st.none(), numbers, numbers.map(lambda v: -v))
    param_item = st.builds(
        S.ParamItem,
        st.lists(st.builds(S.ParamDecl, st.builds(S.Ident, names), defaults), min_size=1, max_size=3).map(
            tuple
        ),
    )
    diffeo = diffeo_decls(terms)
    defn = st.builds(
        S.DefDecl,
        st.builds(S.Ident, names),
        st.lists(
            st.builds(S.DefArg, st.builds(S.Ident, names), st.sampled_from(("var", "param"))), max_size=3
        ).map(tuple),
        terms,
    )
    imp = st.builds(
        S.ImportItem,
        st.builds(S.Ident, names),
        st.lists(
            st.builds(
                S.ImportName, st.builds(S.Ident, names), st.one_of(st.none(), st.builds(S.Ident, names))
            ),
            min_size=1,
            max_size=3,
        ).map(tuple),
    )
    return st.one_of(param_item, diffeo, defn, imp)


@cache
def surface_programs() -> st.SearchStrategy:
    terms = surface_terms(10)
    domain = st.one_of(
        st.none(), st.lists(st.builds(S.Interval, terms, terms), min_size=1, max_size=3).map(tuple)
    )
    return st.builds(S.ProgramS, domain, terms, _idents(1, 3))


@cache
def surface_modules() -> st.SearchStrategy:
    return st.builds(
        lambda items, program: S.ModuleS("<string>", tuple(items), program),
        st.lists(surface_items(), max_size=3),
        st.one_of(st.none(), surface_programs()),
    )


# ----------------------------------------------------------------------------------------------
# Layout.

TOKEN = re.compile(
    r"[A-Za-z_][A-Za-z0-9_]*|(?:[0-9]+(?:\.(?!\.)[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|\.\.|<=|>=|#[^\n]*|\S"
)
_WORDISH = re.compile(r"[A-Za-z0-9_.]")


def tokenize(text: str) -> list[str]:
    """The tokens of a source text, comments dropped (a rough lexer, for mutations)."""
    return [t for t in TOKEN.findall(text) if not t.startswith("#")]


SEPARATORS = ("", "", " ", " ", "  ", "\n", "\t", " # a comment\n", "\n\n  ", "#\n")


def _join(tokens: list[str], seps: list[str]) -> str:
    out = [tokens[0]] if tokens else []
    for prev, tok, sep in zip(tokens, tokens[1:], seps):
        if sep == "" and _WORDISH.match(prev[-1]) and _WORDISH.match(tok[0]):
            sep = " "
        if sep == "" and prev[-1] in "<>" and tok[0] == "=":
            sep = " "
        out.append(sep)
        out.append(tok)
    return "".join(out)


@st.composite
def relayout(draw, text: str) -> str:
    """``text`` with random white space and comments between its tokens."""
    tokens = tokenize(text)
    seps = draw(st.lists(st.sampled_from(SEPARATORS), min_size=len(tokens), max_size=len(tokens)))
    lead = draw(st.sampled_from(("", "", "\n", "# header\n", "\ufeff")))
    trail = draw(st.sampled_from(("", "\n", "  # end", "\n\n")))
    return lead + _join(tokens, seps) + trail


@st.composite
def term_texts(draw) -> tuple[S.STerm, str]:
    """A random surface term and a random layout of its text."""
    t = draw(surface_terms())
    return t, draw(relayout(print_term(t)))


@st.composite
def module_texts(draw) -> tuple[S.ModuleS, str]:
    """A random surface module and a random layout of its text."""
    m = draw(surface_modules())
    return m, draw(relayout(print_module_surface(m)))
