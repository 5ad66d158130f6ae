"""Text and LaTeX of the exact engine's objects: Iverson products, Ψ̂ with its inverse branches,
delta terms, ⦇t⦈ in the normal form of Theorem 7.1 (Eq. 9), derivative results.

Pure formatting (sympy's ``sstr`` and ``latex``): what ``langur show`` prints is assembled from
these by :mod:`langur.exact`.
"""

from __future__ import annotations

import builtins
import inspect
import itertools
import keyword
import linecache
import re
import weakref
from collections.abc import Sequence

import sympy as sp
from sympy.printing.latex import LatexPrinter
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import MpmathPrinter, PythonCodePrinter
from sympy.printing.str import StrPrinter

from ..memo import remember
from .cse import evaluated_once
from .pieces import Condition, DeltaPiece, Method, Piece, Psi, accuracy_of
from .walks import any_node, atoms_of


class _Shared:
    """A sympy printer mixin printing each subtree object once: a closed form built by substitution
    (the local closed forms of :mod:`langur.symbolic.local`: vertices substituted at every point of
    a lattice rule) is a tree of ~10⁵ nodes over a few thousand distinct objects.  The text is the
    printer's own, character for character: a subtree's text does not depend on where it occurs
    (parentheses are added by the parent; only the root is printed at the top level)."""

    def __init__(self, settings=None):
        super().__init__(settings)
        self._memo: dict = {}

    def _print(self, expr, **kwargs) -> str:
        if kwargs or not isinstance(expr, sp.Basic) or not expr.args:
            return super()._print(expr, **kwargs)
        hit = self._memo.get(id(expr))
        if hit is not None:
            return hit[1]
        out = super()._print(expr)
        self._memo[id(expr)] = (expr, out)  # the object is kept: its id is not reused meanwhile
        return out

    def _handle_UnevaluatedExpr(self, expr):
        # (a code printer's first step rewrites every ``re(…)`` node: a walk of the tree with its
        # repeats, a fifth of lambdify's time on a large integrand; with none there is nothing
        # to rewrite and sympy's walk would return ``expr`` itself)
        if isinstance(expr, sp.Basic) and not any_node(expr, lambda node: isinstance(node, sp.re)):
            return expr
        return super()._handle_UnevaluatedExpr(expr)


class _SharedPrinter(_Shared, StrPrinter):
    pass


#: Subtrees' code by code printer class, for :func:`shared_lambdify`'s printers (always the same
#: settings): the engine compiles integrand after integrand, probe after probe, sharing subtrees (a
#: polygon's vertices, root formulas, Jacobians), and each printer printed them again.  Keyed by the
#: subtree (sympy's structural equality: equal trees print the same text; Floats of different
#: precisions are not equal); only subtrees whose printing declared nothing to the printer
#: (``_not_supported``, ``_number_symbols``) are kept.  Cleared when it holds :data:`CODE_TEXTS`.
_CODE_TEXTS: dict = {}
CODE_TEXTS = 50_000
#: The modules' names any printer of a class has imported (``module_imports``): a new printer starts
#: with them, so that a subtree's code taken from :data:`_CODE_TEXTS` finds its names (lambdify
#: imports each name the function's namespace lacks; the names are the module's own).
_CODE_IMPORTS: dict = {}


class _SharedCode(_Shared):
    """A code printer of :func:`shared_lambdify`: subtrees' code shared across printers (above)."""

    def __init__(self, settings=None):
        super().__init__(settings)
        for mod, names in _CODE_IMPORTS.get(type(self), {}).items():
            self.module_imports[mod].update(names)

    def _declared(self) -> tuple[int, int]:
        return len(getattr(self, "_not_supported", ())), len(getattr(self, "_number_symbols", ()))

    def _print(self, expr, **kwargs) -> str:
        if kwargs or not isinstance(expr, sp.Basic) or not expr.args:
            return super()._print(expr, **kwargs)
        texts = _CODE_TEXTS.setdefault(type(self), {})
        out = texts.get(expr)
        if out is not None:
            return out
        declared = self._declared()
        out = super()._print(expr)
        if declared == self._declared():
            remember(texts, expr, out, CODE_TEXTS, at_once=True)
            known = _CODE_IMPORTS.setdefault(type(self), {})
            for mod, names in self.module_imports.items():
                if not names <= known.get(mod, set()):
                    known.setdefault(mod, set()).update(names)
        return out


class _SharedPython(_SharedCode, PythonCodePrinter):
    pass


class _SharedMpmath(_SharedCode, MpmathPrinter):
    pass


class _SharedNumPy(_SharedCode, NumPyPrinter):
    pass


def shared_sstr(expr, **settings) -> str:
    """``sympy.sstr(expr, **settings)``, the same text, each shared subtree printed once."""
    return _SharedPrinter(settings).doprint(expr)


def shared_sstrs(exprs, **settings) -> list[str]:
    """``[sympy.sstr(e, **settings) for e in exprs]``, the same texts, each subtree they share printed
    once (by one printer: a subtree's text does not depend on where it occurs)."""
    printer = _SharedPrinter(settings)
    return [printer.doprint(e) for e in exprs]


#: lambdify without its docstring: it holds ``str(expr)``, printed with its terms sorted (a second
#: of a raytrace partial derivative's ~100 compilations); the generated code is the same.
_NO_DOC = {"docstring_limit": 0} if "docstring_limit" in inspect.signature(sp.lambdify).parameters else {}


def _implemented(expr) -> bool:
    """Whether ``expr`` holds a function with its own numeric implementation (``_imp_``, as
    :class:`langur.implicit.ImplicitRootFn`), each distinct subtree looked at once."""
    if not isinstance(expr, sp.Basic):
        return True  # (a list or matrix of expressions: lambdify looks itself)
    return any_node(expr, lambda node: hasattr(node, "_imp_"))


def lambdify(args, expr, **kwargs):
    """``sympy.lambdify(args, expr, **kwargs)``: the same function, without the docstring, and
    without lambdify's search for implemented functions when there are none (it walks the tree
    with its repeats: half a second for a stylize partial derivative's integrands)."""
    if "use_imps" not in kwargs and not _implemented(expr):
        kwargs["use_imps"] = False
    return sp.lambdify(args, expr, **kwargs, **_NO_DOC)


def shared_lambdify(args, expr, module: str):
    """``sympy.lambdify(args, expr, modules=[module])`` for ``module`` "math", "mpmath" or "numpy": the same
    generated code (sympy's printer for that module, with lambdify's settings), each shared subtree
    printed once; for plain arguments and an expression (or a list of them: a function returning the
    list of their values) with nothing lambdify rewrites, generated without lambdify's walks of the
    tree with its repeats (:func:`_generated`)."""
    plain = (isinstance(expr, sp.Basic) or _basic_list(expr)) and _plain_arguments(args)
    key = _Key((tuple(args), "list", tuple(expr), module) if isinstance(expr, list) else (tuple(args), expr, module)) \
        if plain else None
    func = _FUNCTIONS.get(key) if plain else None
    if func is not None:
        return func
    cls = {"math": _SharedPython, "mpmath": _SharedMpmath, "numpy": _SharedNumPy}[module]
    printer = cls({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                   "user_functions": {}})
    if plain and not any(any_node(e, _rewritten) for e in (expr if isinstance(expr, list) else [expr])):
        func = _FUNCTIONS[key] = _generated(list(args), expr, printer, module)
        return func
    return lambdify(args, expr, modules=[module], printer=printer)


class _Key(tuple):
    """A key of :data:`_FUNCTIONS`: a tuple whose hash is computed once, when it is made.  A weak
    dictionary hashes a key again when its value goes, which may be at interpreter shutdown; a bare
    sympy ``Float``'s hash is recomputed at each call (through mpmath), and there it failed
    ("Exception ignored … sys.meta_path is None" from pytest's workers, for a list of coefficients
    holding Floats)."""

    def __new__(cls, items):
        key = super().__new__(cls, items)
        key.hash = tuple.__hash__(key)
        return key

    def __hash__(self):
        return self.hash


#: The functions :func:`_generated` made, by (arguments, expression, module), while they are in use
#: (weak references: one goes, with its source in ``linecache``, when its callers drop it): the same
#: code is asked for again by other callers (the quadrature's compilations, its retry after a probe's
#: domain error, the sign probes of solving.py).  sympy's equality tells Floats of other precisions
#: apart, and such a function is a pure function of its arguments.
_FUNCTIONS: weakref.WeakValueDictionary = weakref.WeakValueDictionary()


def _basic_list(expr) -> bool:
    """Whether ``expr`` is a list of sympy expressions (lambdify returns the list of their values)."""
    return isinstance(expr, list) and all(isinstance(e, sp.Basic) for e in expr)


def _plain_arguments(args) -> bool:
    """Whether lambdify would name every argument by its own name (symbols, not a ``Dummy`` nor of a
    subclass, whose names are Python identifiers: then it substitutes nothing in the expression)."""
    return isinstance(args, (list, tuple)) and all(
        type(a) is sp.Symbol and a.name.isidentifier() and not keyword.iskeyword(a.name) for a in args)


def _rewritten(node) -> bool:
    """A node lambdify treats apart: a function with its own numeric implementation (``_imp_``: it
    goes into the function's namespace) or an unevaluated substitution (``Subs``: made an assignment)."""
    return hasattr(node, "_imp_") or isinstance(node, sp.Subs)


#: lambdify's namespace by module (its module's names, ``builtins`` and ``range``): copied for
#: each function :func:`_generated` makes.
_NAMESPACES: dict = {}
_GENERATED = itertools.count()


def _namespace(module: str) -> dict:
    ns = _NAMESPACES.get(module)
    if ns is None:
        ns = dict(sp.lambdify([], sp.Integer(0), modules=[module], use_imps=False, **_NO_DOC).__globals__)
        _NAMESPACES[module] = ns
    return dict(ns)


#: Source text (characters) from which :func:`_generated`'s code evaluates each repeated
#: subexpression once (shorter code has little to share, and parsing it costs more than it saves).
SHARED_CODE = 1000


def _generated(args: list, expr, printer, module: str):
    """What ``sympy.lambdify(args, expr, modules=[module], printer=printer, use_imps=False)`` makes for
    plain ``args`` (:func:`_plain_arguments`) and an ``expr`` without :func:`_rewritten` nodes: the same
    source text, namespace and values (for ``math`` and ``numpy`` the function evaluates each repeated
    subexpression once: :func:`langur.symbolic.cse.evaluated_once`, the same values and exceptions).  Its two walks of the tree with its repeats are not made:
    ``atoms(Symbol)`` for the namespace (here each distinct subtree once: :func:`atoms_of`) and the
    replacement of ``Subs`` nodes (there are none) — two thirds of lambdify's time on a stylize
    partial derivative's integrands, each ~10⁴ nodes over a few hundred distinct ones."""
    namespace = _namespace(module)
    if isinstance(expr, list):  # (lambdify prints each, in brackets; it adds no symbol to the namespace)
        text = "[" + ", ".join(printer.doprint(e) for e in expr) + "]"
    else:
        for sym in atoms_of(expr, (sp.Symbol,)):
            namespace[sym.name if type(sym) is sp.Symbol else str(sym)] = sym  # (str(Symbol) is its name)
        text = printer.doprint(expr)
    if "\n" in text:
        text = f"({text})"
    source = f"def _lambdifygenerated({', '.join(a.name for a in args)}):\n    return {text}\n"
    for mod, names in (getattr(printer, "module_imports", None) or {}).items():
        for name in names:
            if name not in namespace:
                exec(f"from {mod} import {name}", {}, namespace)  # (as lambdify: the module's own name)
    namespace.update({"builtins": builtins, "range": range})
    filename = f"<lambdifygenerated-langur-{next(_GENERATED)}>"
    local: dict = {}
    # (math and numpy: each repeated subexpression evaluated once, the same values and exceptions;
    # the text kept for tracebacks is lambdify's, whose line the rewritten code keeps)
    tree = evaluated_once(source, [a.name for a in args]) \
        if module in ("math", "numpy") and len(source) >= SHARED_CODE else None
    code = None
    if tree is not None:
        try:
            code = compile(tree, filename, "exec")
        except (RecursionError, SyntaxError, ValueError):
            code = None  # (lambdify's own text, compiled as before)
    exec(code or compile(source, filename, "exec"), namespace, local)
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    func = local["_lambdifygenerated"]
    weakref.finalize(func, linecache.cache.pop, filename, None)
    return func


def math_lambdify(args, expr):
    """``sympy.lambdify(args, expr, modules=["math"])``: the same function, each shared subtree
    printed once (:func:`shared_lambdify`) unless a function of ``expr`` has its own numeric
    implementation (lambdify then prints it with settings of its own)."""
    if _implemented(expr):
        return lambdify(args, expr, modules=["math"])
    return shared_lambdify(list(args), expr, "math")


def _iverson(e):
    """``Piecewise((1, c), (0, True))`` → ``[c]`` (the Iverson bracket of the paper) for display."""
    if isinstance(e, sp.Piecewise) and len(e.args) == 2 and e.args[0].expr == 1 and e.args[1].expr == 0 \
            and e.args[1].cond == sp.true:
        return True
    return False


class _TextPrinter(StrPrinter):
    def _print_Piecewise(self, e):
        if _iverson(e):
            return f"[{self._print(e.args[0].cond)}]"
        return self._print_Basic(e)


class _LatexPrinter(LatexPrinter):
    def _print_Piecewise(self, e):
        if _iverson(e):
            return f"\\left[{self._print(e.args[0].cond)}\\right]"
        return super()._print_Piecewise(e)


def expr_text(e: sp.Expr, latex: bool = False) -> str:
    """sympy's LaTeX, or its text with powers written ``^`` as in Langur's own syntax (one notation
    beside the core term; the JSON output keeps sympy's ``**``, which ``sympify`` reads); an
    indicator ``Piecewise((1, c), (0, True))`` is written as the Iverson bracket ``[c]``."""
    if latex:  # sympy parenthesizes a Piecewise factor; a bracket needs none
        return re.sub(r"\\left\(\\left\[(.*?)\\right\]\\right\)", r"\\left[\1\\right]", _LatexPrinter().doprint(e))
    return _TextPrinter().doprint(e).replace("**", "^")


def condition_text(c: Condition, latex: bool = False) -> str:
    """``[Φ >= 0]``, or ``[Φ > 0]`` for a strict condition (the complement of a non-strict one)."""
    relation = (">" if c.strict else "\\geq") if latex else (">" if c.strict else ">=")
    return f"[{expr_text(c.expr, latex)} {relation} 0]"


def _factor(weight: sp.Expr, latex: bool) -> str:
    s = expr_text(weight, latex)
    if isinstance(weight, sp.Add):
        return f"\\left({s}\\right)" if latex else f"({s})"
    return s


def product_text(conditions: Sequence[Condition], weight: sp.Expr, latex: bool = False,
                 lead: str = "") -> str:
    """``c·lead·[Φ1 >= 0]·[Φ2 >= 0]·(g)`` with the rational coefficient c of the weight in front."""
    dot = " \\cdot " if latex else "·"
    coeff, rest = sp.sympify(weight).as_coeff_Mul()
    parts = ([lead] if lead else []) + [condition_text(c, latex) for c in conditions]
    if rest != 1 or not parts:
        parts.append(_factor(rest, latex))
    text = dot.join(parts)
    if coeff == 1:
        return text
    if coeff == -1:
        return "-" + text
    return expr_text(coeff, latex) + dot + text


def pieces_text(pieces: Sequence[Piece], latex: bool = False) -> str:
    if not pieces:
        return "0"
    return " + ".join(product_text(p.conditions, p.weight, latex) for p in pieces)


def psi_text(psi: Psi, latex: bool = False) -> list[str]:
    """Ψ̂ and its inverse branches, e.g. ``Ψ̂(x) = (theta - x); x = theta - u0``."""
    ins = ", ".join(expr_text(u, latex) for u in psi.inputs)
    vs = ", ".join(expr_text(v, latex) for v in psi.variables)
    fwd = ", ".join(expr_text(f, latex) for f in psi.forward)
    head = (f"\\hat\\Psi({vs}) = ({fwd})" if latex else f"Psi({vs}) = ({fwd})")
    lines = [head]
    for i, b in enumerate(psi.branches):
        inv = ", ".join(f"{expr_text(v, latex)} = {expr_text(e, latex)}" for v, e in b.inverse)
        guard = ""
        if b.guards:
            sep = " \\wedge " if latex else " and "
            ge = " \\geq 0" if latex else " >= 0"
            guard = (" \\text{ where } " if latex else " where ") + sep.join(expr_text(g, latex) + ge for g in b.guards)
        label = f"\\text{{branch {i + 1} in }} ({ins})" if latex else f"inverse branch {i + 1} in ({ins})"
        lines.append(f"{label}: {inv}{guard}")
    return lines


def delta_text(d: DeltaPiece, latex: bool = False) -> str:
    phi = expr_text(d.psi.forward[0], latex)
    lead = f"\\delta\\left({phi}\\right)" if latex else f"δ({phi})"
    return product_text(d.conditions, d.weight, latex, lead=lead)


def normal_form_text(nf, latex: bool = False) -> str:
    """⦇t⦈ = f + Σ δ(Φ)·h on one line."""
    parts = [pieces_text(nf.regular, latex)] if nf.regular else []
    parts += [delta_text(d, latex) for d in nf.deltas]
    return " + ".join(parts) if parts else "0"


def derivative_result_text(res, latex: bool = False) -> str:
    value = f"{res.value:.12g}" + (("" if res.method == Method.CLOSED_FORM else f" ± {res.error:.2g}") if latex
                                   else accuracy_of(res))
    if res.expr is not None:
        body = expr_text(res.expr, latex)
        return f"{body} = {value}" if not latex else f"{body} \\approx {value}"
    return value
