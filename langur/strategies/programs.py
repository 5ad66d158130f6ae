"""Whole programs: factors, summands, boxes, ``let``, ``def`` and modules (LANGUAGE.md §6), drawn
type-directed (:mod:`langur.strategies.conditions`) and kept generic (:func:`~.terms.generic`).
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from fractions import Fraction as F

from hypothesis import assume
from hypothesis import strategies as st

from ..frontend import load, load_text
from ..modules import Loaded
from ..syntax import surface as S
from ..syntax.printer import decimal, print_module_surface, print_term
from . import conditions as C
from . import deep as D
from . import lexical as L
from . import poles as P
from . import terms as T
from . import variants as V
from . import wide as W
from .terms import call, mul, name, num

#: Parameter names, and their defaults: irregular decimals drawn without replacement (no two
#: parameters equal, none a round number a zero set could meet by accident).
PARAMS = ("a", "b", "c")
GENERIC = tuple(F(d) for d in ("0.37", "0.61", "0.23", "0.83", "0.47", "0.71", "0.29", "0.53", "0.67",
                                 "0.41", "0.79", "0.31"))
VARIABLES = ("x", "y", "z")
#: The name a ``let`` binds, and the library module of :func:`programs` (``modules=True``).
LET_NAME, LIBRARY = "s", "lib"


@dataclass(frozen=True)
class Generated:
    """A drawn program: its main module (surface AST), the modules it imports (name → surface
    AST), its parameters' defaults and how its text is spelled (:mod:`.lexical`; None: as
    :func:`render` prints it)."""

    module: S.ModuleS
    params: tuple[tuple[str, F], ...]
    libraries: tuple[tuple[str, S.ModuleS], ...] = ()
    spelling: L.Spelling | None = None

    @property
    def text(self) -> str:
        """The main module as `.lgr` text (:func:`render`, spelled as :attr:`spelling` says)."""
        return self._spelled(render(self.module))

    def _spelled(self, text: str) -> str:
        return text if self.spelling is None else L.spell(text, self.spelling)

    @property
    def defaults(self) -> tuple[tuple[str, str], ...]:
        """The parameters' defaults as decimal text (``("a", "0.37")``, ``("b", "-0.61")``, …)."""
        return tuple((p, ("-" if d < 0 else "") + (decimal(abs(d)) or str(abs(d)))) for p, d in self.params)

    def files(self) -> dict[str, str]:
        """Every module's text by file name (``main.lgr`` and one ``NAME.lgr`` per import)."""
        return {"main.lgr": self.text, **{f"{n}.lgr": self._spelled(render(m)) for n, m in self.libraries}}

    def load(self, directory: str | None = None) -> Loaded:
        """Through the front end (parse, elaborate, inline, type-check): the core program.  With
        imports the modules are written to ``directory`` (a fresh temporary folder when None)."""
        if not self.libraries:
            return load_text(self.text, path="main.lgr")
        if directory is None:
            with tempfile.TemporaryDirectory(prefix="langur-strategies-") as d:
                return self.load(d)
        for file, text in self.files().items():
            with open(os.path.join(directory, file), "w", encoding="utf-8", newline="") as fh:
                fh.write(text)
        return load(os.path.join(directory, "main.lgr"))


def render(m: S.ModuleS) -> str:
    """`.lgr` text of a module: the printer's items, then the program on three lines
    (``int (box)``, the body, ``d(vars)``); parsing it gives ``m`` back."""
    head = print_module_surface(S.ModuleS(m.path, m.items, None))
    p = m.program
    if p is None:
        return head
    dom = "" if p.domain is None else \
        " (" + ", ".join(f"[{print_term(i.lo)}, {print_term(i.hi)}]" for i in p.domain) + ")"
    return f"{head}int{dom}\n  {print_term(p.body)}\nd({', '.join(v.name for v in p.variables)})\n"


# ---------------------------------------------------------------------------------------------
# Factors and boxes
# ---------------------------------------------------------------------------------------------

def _else(scope: C.Scope, *choices) -> S.STerm:
    """An ``else`` branch: a literal of ``choices`` or a smooth factor (the last choice)."""
    i = scope.index(len(choices) + 1)
    return num(choices[i]) if i < len(choices) else C.smooth(scope)


def _if(scope: C.Scope, then: S.STerm | None = None) -> S.IfCmp:
    lhs, cmp, rhs = C.condition(scope)
    return S.IfCmp(lhs, cmp, rhs, then if then is not None else C.smooth(scope), _else(scope, 0, 1, F(1, 2)))


def factor(scope: C.Scope) -> S.STerm:
    """One factor of a summand, by kind (the first, a smooth factor, is what shrinking aims at):
    smooth, ``[cond]``, ``if cond then … else …``, nested conditionals, a window, ``min``/``max``
    of two affine terms, a conditional on parameters only, a declared diffeo's ``ifge0``, and with
    ``scope.kinks`` a condition with ``abs``/``min``/``max`` inside, with ``scope.turning`` one
    with no closed-form inverse (implicit roots), with ``scope.wide`` a construct of :mod:`.wide`
    (loops, ``&``/``|``/``not``, a ``let`` in a factor, guarded partial primitives, …), with
    ``scope.poles`` one of :mod:`.poles` (moving poles, products of moving factors, folding edge cases),
    with ``scope.deep`` one of :mod:`.deep` (products of moving lines, splits nested three deep)."""
    if scope.kinks and scope.index(4) == 3:
        return C.kink_condition(scope)
    if scope.turning and scope.index(4) == 3:
        return C.turning_condition(scope)
    if scope.wide and scope.index(3) == 2:
        return W.factor(scope)
    if scope.poles and scope.index(3) == 2:
        return P.factor(scope)
    if scope.deep and scope.index(2) == 1:
        return D.factor(scope)
    kind = scope.index(11)
    if kind <= 1:
        return C.smooth(scope)
    if kind <= 3:
        lhs, cmp, rhs = C.condition(scope)
        return S.Iverson((lhs, rhs), (cmp,))
    if kind == 4:
        return _if(scope)
    if kind == 5:  # min/max(lhs, rhs) of an affine condition: a kink on its zero set
        lhs, _, rhs = C.affine(scope)
        scope.register(T.sub(lhs, rhs), key=(lhs, rhs))
        return call(scope.pick(("min", "max")), lhs, rhs)
    if kind == 6:  # nested conditionals: a conditional in a branch (their zero sets multiply)
        inner = _if(scope)
        lhs, cmp, rhs = C.condition(scope)
        return S.IfCmp(lhs, cmp, rhs, inner, _else(scope, 1))
    if kind == 7:
        return C.window(scope)
    if kind == 8 or len(scope.variables) == 1:  # a conditional on parameters only
        p = scope.param()
        q = scope.pick([n for n in scope.names if n != p.name] + ["0.5"])
        rhs = num(F(1, 2)) if q == "0.5" else name(q)
        scope.register(T.sub(p, rhs), key=(p, rhs))
        return S.IfCmp(p, ">=", rhs, C.smooth(scope), _else(scope, 0))
    return S.IfGe0S(C.declared(scope), C.smooth(scope), _else(scope, 0, 1))


#: Box kinds: constant, or a parametric bound (``[0, P + 1]``, ``[P - 1, 1]``; ``wide``: also both
#: ends moving, ``[P - 1, Q + 1]`` and ``[-P, 2 * Q]``); all in [-1, 2]: ``params`` are the positive
#: parameters (without any, a constant box).
@st.composite
def _interval(draw, params: tuple[str, ...], wide: bool = False) -> S.Interval:
    kind = draw(st.integers(0, 6 if wide else 4))
    if kind < 3 or not params:
        lo, hi = ((0, 1), (-1, 1), (0, 2))[kind % 3]
        return S.Interval(num(lo), num(hi))
    p = name(draw(st.sampled_from(params)))
    if kind == 3:
        return S.Interval(num(0), T.offset(p, 1))
    if kind == 4:
        return S.Interval(T.offset(p, -1), num(1))
    q = name(draw(st.sampled_from(params)))
    return S.Interval(T.offset(p, -1), T.offset(q, 1)) if kind == 5 else S.Interval(S.Neg(p), mul(num(2), q))


def _bounded(domain: tuple[S.Interval, ...], variables: tuple[str, ...], body: S.STerm) -> S.STerm:
    """``[lo1 <= x <= hi1] * … * (body)``: the box as brackets in the body (a program without a
    domain, LANGUAGE.md §6: compactly supported by its own conditions)."""
    out: S.STerm | None = None
    for v, i in zip(variables, domain):
        chain = S.Iverson((i.lo, name(v), i.hi), ("<=", "<="))
        out = chain if out is None else mul(out, chain)
    assert out is not None
    return mul(out, body)


@st.composite
def _factor(draw, scope: C.Scope) -> S.STerm:
    """:func:`factor` as a strategy of its own, so that hypothesis can delete a factor (or a
    summand) of a list wherever it is when shrinking."""
    outer, scope.draw = scope.draw, draw
    start = len(scope.zero_sets)
    try:
        made = factor(scope)
    finally:
        scope.draw = outer
    scope.made.append((made, tuple(scope.zero_sets[start:])))
    return made


# ---------------------------------------------------------------------------------------------
# Defs and modules
# ---------------------------------------------------------------------------------------------

def _extract_def(scope: C.Scope, summands: list[list[S.STerm]], params: list[str]) -> S.DefDecl | None:
    """Move one factor into ``def g(x: var, …, qa: param, …) = …`` and call it there (and maybe once
    more, in a new summand: two call sites of one def, added; ``wide`` or ``deep``: maybe at a third
    site with other parameter terms, :func:`~.variants.call_elsewhere`; ``deep`` prefers a factor of
    :mod:`.deep`), so that elaboration, inlining and
    the Monte Carlo engine's separately compiled defs are exercised.  Factors under a declared
    diffeo stay where they are, and so do conditions completed by implicit roots (they need the
    variables' domain, which a def does not know), and without ``wide`` those reading the
    program's ``let`` name; with ``wide`` that name is passed to the def as a parameter argument,
    and a factor that binds a ``let`` of its own is preferred (fuzz31: its let then takes other
    values at a second site)."""
    terms = [*params, LET_NAME] if scope.wide and LET_NAME in scope.env else params
    cands = [(i, j) for i, fs in enumerate(summands) for j, f in enumerate(fs)
             if (scope.wide or LET_NAME not in T.names_in(f)) and not (T.names_in(f) & set(scope.diffeos))
             and not any(f is c for c in scope.implicit)]
    if scope.wide:
        cands = [(i, j) for i, j in cands if isinstance(summands[i][j], S.LetIn)] or cands
    if scope.deep:  # fuzz33: a split condition in a def, called at two parameter terms
        cands = [(i, j) for i, j in cands if any(summands[i][j] is f for f in scope.split)] or cands
    if not cands:
        return None
    i, j = scope.pick(cands)
    body = original = summands[i][j]
    used = [p for p in terms if p in T.names_in(body)]
    body = T.rename(body, {p: f"q{p}" for p in used})
    args = tuple(S.DefArg(S.Ident(v), "var") for v in scope.variables) + \
        tuple(S.DefArg(S.Ident(f"q{p}"), "param") for p in used)
    use = call("g", *(name(v) for v in (*scope.variables, *used)))
    summands[i][j] = use
    if scope.draw(st.booleans()):
        summands.append([use, C.smooth(scope)])
    if (scope.wide or scope.deep) and scope.draw(st.booleans()):
        elsewhere = V.call_elsewhere(scope, original, used, terms)
        if elsewhere is not None:
            summands.append([elsewhere, C.smooth(scope)])
    return S.DefDecl(S.Ident("g"), args, body)


def _sum(scope: C.Scope, summands: list[list[S.STerm]]) -> S.STerm:
    out: S.STerm | None = None
    for fs in summands:
        term = fs[0]
        for f in fs[1:]:
            term = mul(term, f)
        coef = scope.pick((None, F(7, 10), F(-13, 10), F(2)))
        if coef is not None and out is not None and coef < 0:
            out = T.sub(out, mul(num(-coef), term))
            continue
        if coef is not None:
            term = mul(num(coef), term)
        out = term if out is None else T.add(out, term)
    assert out is not None
    return out


# ---------------------------------------------------------------------------------------------
# The strategy
# ---------------------------------------------------------------------------------------------

def programs(*, min_variables: int = 1, max_variables: int = 3, max_summands: int = 3, max_factors: int = 3,
             max_conds: int = 4, max_params: int = 3, light: bool = False, kinks: bool = True,
             turning: bool = False, lets: bool = True, defs: bool = True, modules: bool = False, generic: bool = True,
             wide: bool = False, poles: bool = False, huge: bool = False, deep: bool = False):
    """A hypothesis strategy of :class:`Generated`: well-typed programs in ``min_variables`` to
    ``max_variables`` (≤ 3) variables, one to ``max_params`` parameters with generic defaults,
    sums of at most ``max_summands`` products of at most ``max_factors`` factors (:func:`factor`),
    over a box with constant or parametric bounds; maybe a ``let`` of a parameter term around the
    body (``lets``), a factor moved into a ``def`` (``defs``), that def in an imported module
    (``modules``: then :meth:`Generated.load` writes the files).  At most ``max_conds`` zero sets;
    ``generic``: transverse at the defaults as far as :func:`~.terms.generic` sees (the rest is the
    linter's to find); ``light``: forms the exact engine integrates quickly; ``kinks``: conditions
    with ``abs``/``min``/``max`` inside; ``turning``: conditions in one variable with no closed-form
    inverse (``v^3 - v``, ``exp(v) + v``: implicit roots, issue 18); ``wide``: the constructs of
    :mod:`.wide` (loops, ``&``/``|``/``not``, a ``let`` inside a factor, guarded partial primitives,
    atan2's cut, erf/asin/acos/atanh/tan, a diffeo with a parametric Jacobian; ``erf`` conditions,
    ``ifge0`` over the variables, nested loops, strict chains with ``pi``, ``cross`` and components,
    negative exponents), boxes with both ends moving, programs without a domain (the box as
    brackets in the body), and the whole-program variants of :mod:`.variants` (negative parameter
    defaults, programs without parameters, a def called with other parameter terms, also a def whose
    ``let`` then takes another value; with ``modules`` the def imported under another name or
    through a second module, the diffeos from a module of their own) and lexical variants of the
    text (:mod:`.lexical`: comments, CRLF, numbers spelled otherwise, ≤/≥, extra parentheses;
    :attr:`Generated.spelling`); ``poles``: the factors of :mod:`.poles` (moving poles, products of
    moving factors, such conditions nested, folding edge cases); ``huge``: a third of the programs
    over a huge box (:func:`.poles.huge`: up to ±10¹⁰, decaying weights); ``deep``: the factors of
    :mod:`.deep` (products of moving lines over two variables, split conditions nested three deep),
    one of them preferably moved into a def called at two parameter terms (they register more zero
    sets: raise ``max_conds`` to 6 or so).  Shrinks towards one variable, one parameter, one smooth
    factor; without ``wide``, ``poles``, ``huge`` and ``deep`` a seed draws what it drew before."""
    if not 1 <= min_variables <= max_variables <= 3:
        raise ValueError("variables: 1 <= min_variables <= max_variables <= 3")

    @st.composite
    def program(draw) -> Generated:
        # lists, not a count then items: hypothesis shrinks a list by deleting any element
        # (the number of variables stays a count: it is drawn uniformly, a list's length is not)
        defaults = draw(st.lists(st.sampled_from(GENERIC), min_size=1, max_size=max_params, unique=True))
        if wide:
            defaults = V.signed(draw, defaults)
        params = list(PARAMS[:len(defaults)])
        positive = [p for p, d in zip(params, defaults) if d > 0]
        if huge and positive and draw(st.integers(0, 2)) == 2:
            domain, body, names = draw(P.huge(tuple(positive)))
            decls = S.ParamItem(tuple(S.ParamDecl(S.Ident(p), d) for p, d in zip(params, defaults)))
            prog = S.ProgramS(domain, body, tuple(S.Ident(v) for v in names))
            return Generated(S.ModuleS("main.lgr", (decls,), prog), tuple(zip(params, defaults)))
        variables = VARIABLES[:draw(st.integers(min_variables, max_variables))]
        domain = tuple(draw(_interval(tuple(positive), wide)) for _ in variables)
        env = {p: float(d) for p, d in zip(params, defaults)}
        scope = C.Scope(draw, variables, env, list(params), light=light, kinks=kinks,
                         turning=turning, wide=wide, poles=poles, deep=deep, fixed=tuple(v for v, i in zip(variables, domain)
                                                      if not T.names_in(i.lo) | T.names_in(i.hi)))
        box = [(T.evaluate(i.lo, env), T.evaluate(i.hi, env)) for i in domain]
        let = None
        if lets and scope.index(4) == 3 and positive:  # let s = <positive parameter term> in …
            let = C.positive_param_term(scope, positive)
            scope.env[LET_NAME] = T.evaluate(let, env)
            scope.names.append(LET_NAME)
        summands = draw(st.lists(st.lists(_factor(scope), min_size=1, max_size=max_factors),
                                 min_size=1, max_size=max_summands))
        items: list[S.Item] = []
        libraries: tuple[tuple[str, S.ModuleS], ...] = ()
        diffeos = tuple(scope.diffeos.values())
        if defs and scope.index(3) == 2:
            d = _extract_def(scope, summands, params)
            if d is not None and modules and draw(st.booleans()):
                if wide:  # the def (and maybe the diffeos) in modules of several shapes
                    libraries, imports, diffeos = V.modular(draw, d, diffeos)
                    items += imports
                else:
                    libraries = ((LIBRARY, S.ModuleS(f"{LIBRARY}.lgr", (d,), None)),)
                    items.append(S.ImportItem(S.Ident(LIBRARY), (S.ImportName(S.Ident("g"), None),)))
            elif d is not None:
                items.append(d)
        assume(len(scope.zero_sets) <= max_conds)
        if generic:
            assume(T.generic(scope.zero_sets, box, variables))
        body = _sum(scope, summands)
        if let is not None:
            body = S.LetIn(LET_NAME, let, body)
        bounded = wide and not scope.implicit and scope.index(4) == 3  # implicit roots need a domain
        if bounded:
            body = _bounded(domain, variables, body)
        decls = S.ParamItem(tuple(S.ParamDecl(S.Ident(p), d) for p, d in zip(params, defaults)))
        items = [decls, *diffeos, *items]
        prog = S.ProgramS(None if bounded else domain, body, tuple(S.Ident(v) for v in variables))
        module = S.ModuleS("main.lgr", tuple(items), prog)
        spelling = draw(L.spellings()) if wide and scope.index(2) == 1 else None
        if wide and V.bare(draw):
            return Generated(V.without_parameters(module, dict(zip(params, defaults))), (), libraries, spelling)
        return Generated(module, tuple(zip(params, defaults)), libraries, spelling)

    return program()


def texts(**shape):
    """A strategy of `.lgr` texts (:func:`programs`' main modules, printed)."""
    return programs(**shape).map(lambda g: g.text)


def cores(**shape):
    """A strategy of loaded programs (:class:`langur.modules.Loaded`: the core program after the
    front end, with its parameters' defaults)."""
    return programs(**shape).map(lambda g: g.load())

