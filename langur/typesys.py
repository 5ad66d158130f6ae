"""The type system of Langur: paper Fig. 6 (terms) and Fig. 11 (programs), LANGUAGE.md §2.

The judgement is ``Δ; Γ ⊢ t : real`` with ``Δ`` the variables of integration and ``Γ`` the
parameters, disjoint.  Typing happens in two places, with the same rules and codes:

* during elaboration (``langur.syntax.desugar``), on the surface AST, where names are resolved and
  the sugar is expanded: the desugarer reports each rejection through the ``reject_*`` helpers
  below, located at the offending source text;
* on the resulting pure core term (:func:`type_term`, :func:`type_program`): one function per
  judgement, one ``match`` case per rule of Fig. 6 / Fig. 11 in the figure's order.  On the
  desugarer's output these never fire (they certify it); they also type core terms built by
  other means (tests, fuzzers).

Every rejection is a :class:`~langur.diagnostics.Diagnostic` whose message names the rule; its
code (T201–T233) is one of the catalogue :mod:`langur.codes` (``docs/CODES.md`` explains each).
"""

from __future__ import annotations

import functools
import inspect
import sys
import threading
from fractions import Fraction

from . import lazy, observe
from .codes import CODES
from .core import (
    Add,
    Call,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Term,
    Var,
    all_small,
    diffeo_variables,
    free_vars,
    keep_typed,
    shared,
    subterms,
)
from .diagnostics import Diagnostic, Span
from .memo import remember
from .primitives import ALL_PRIMITIVES

#: 30-digit arithmetic for the range check of constants (T231), imported only when a constant is
#: not a small rational (``langur.lazy``: start-up of the Monte Carlo path).
mpmath = lazy.module("mpmath")


def diag(span: Span | None, code: str, message: str, related: tuple[Span, ...] = ()) -> Diagnostic:
    """An error diagnostic with a code from :data:`CODES`."""
    assert code in CODES, code
    return Diagnostic(span, "error", code, message, related)


# ----------------------------------------------------------------------------------------------
# Rejections raised while elaborating the surface AST (one helper per rule; the desugarer calls
# them at the point where the rule applies).


def reject_unbound(span, name: str, where: str = "") -> Diagnostic:
    return diag(span, "T201", f"unbound name `{name}`{where}: not a variable of the enclosing int, a declared "
                "param, a let-bound name or an argument of the enclosing def (Fig. 6, variable/parameter)")


def reject_undeclared_param(span, name: str, position: str) -> Diagnostic:
    return diag(span, "T210", f"undeclared parameter `{name}` in {position}: only declared params, let-bound "
                "names and param arguments may occur here (Fig. 6, parameter: z:real ∈ Γ)")


def reject_unknown_function(span, name: str, detail: str = "") -> Diagnostic:
    return diag(span, "T202", f"unknown function `{name}`{detail}")


def reject_arity(span, what: str, expected: int, got: int) -> Diagnostic:
    return diag(span, "T203", f"{what} takes {expected} argument(s), got {got}")


def reject_var_arg_without_variables(span, fname: str, arg: str) -> Diagnostic:
    return diag(span, "T204", f"argument `{arg}` of `{fname}` is a var argument: it needs a term over variables, "
                "got a variable-free term (a param where a var is required)")


def reject_param_arg_with_variables(span, fname: str, arg: str, names) -> Diagnostic:
    return diag(span, "T205", f"argument `{arg}` of `{fname}` is a parameter: it must be variable-free, but "
                f"mentions {', '.join(sorted(names))} (a var where a param is required; Fig. 6: ·;Γ ⊢ t)")


def reject_let_with_variables(span, name: str, names) -> Diagnostic:
    return diag(span, "T206", f"the term bound to `{name}` mentions the variable(s) {', '.join(sorted(names))} "
                "(Fig. 6, let: ·;Γ ⊢ t : real, the bound term must be variable-free)")


def reject_condition(span, reason: str) -> Diagnostic:
    return diag(span, "T207", "the condition mentions variables, so it must be a diffeomorphism "
                f"(Fig. 6, diffeomorphic conditional), but it cannot be completed to one: {reason}")


def reject_not_compact(span, unbounded) -> Diagnostic:
    return diag(span, "T209", "integrand is not compactly supported (§8.3, Prop. 8.1): nothing bounds "
                f"{', '.join(unbounded)}; give a domain `int ([lo, hi], …) …` or bounding indicator "
                "factors such as `[0 <= x <= 1] * …`")


def reject_duplicate(span, what: str, name: str, first: Span | None = None) -> Diagnostic:
    where = f" (first at {first})" if first is not None else ""
    return diag(span, "T211", f"duplicate {what} `{name}`{where}", (first,) if first is not None else ())


def reject_var_param_clash(span, name: str, detail: str) -> Diagnostic:
    return diag(span, "T212", f"`{name}` is both a variable and a parameter ({detail}; Vars ∩ Params = ∅, §4)")


def reject_nested_int(span) -> Diagnostic:
    return diag(span, "T208", "no nested integration: `int … d(…)` is a program, not a term, and a program "
                "integrates a term that contains no `int` (Fig. 11); integrate over all the variables at "
                "once, `int ([a, b], [c, d]) t d(x, y)`")


def reject_exponent(span) -> Diagnostic:
    return diag(span, "T213", "non-constant exponent: `t ^ k` needs a constant rational k (LANGUAGE.md §1; "
                "use exp(k * log(t)) for a variable exponent)")


def reject_diffeo_args(span, name: str, detail: str) -> Diagnostic:
    return diag(span, "T217", f"diffeo `{name}` must be applied to distinct variables of integration "
                f"(Fig. 6, diffeomorphic conditional): {detail}")


def reject_recursive(span, cycle) -> Diagnostic:
    return diag(span, "T221", "recursive def: " + " -> ".join(cycle) + " (defs are inlined; Langur is first-order)")


def reject_too_large(span, detail: str) -> Diagnostic:
    return diag(span, "T230", f"program too large: {detail}")


def reject_loop_bound(span, why: str) -> Diagnostic:
    return diag(span, "T224", f"loop bound is not an integer constant: {why} (§9: the loop is unrolled before "
                "anything is evaluated, so its bounds are number literals or arithmetic of them and of the indices "
                "of enclosing loops, and their values are integers)")


def reject_loop_too_large(span, detail: str) -> Diagnostic:
    return diag(span, "T225", f"loops too large once unrolled: {detail}")


def reject_vector(span, size: int, detail: str = "") -> Diagnostic:
    return diag(span, "T226", f"a vector of {size} components where a real is expected{detail} (vectors live only "
                "inside terms and are desugared to their components: an integrand, a condition, a bound, an "
                "argument or body of a def, a loop's body are reals; take dot(u, v), cross(u, v).z or u.x)")


def reject_real(span, detail: str) -> Diagnostic:
    return diag(span, "T227", f"a real where a vector is expected: {detail}")


def reject_sizes(span, detail: str) -> Diagnostic:
    return diag(span, "T228", f"vector sizes differ: {detail}")


def reject_cross(span, sizes) -> Diagnostic:
    return diag(span, "T229", f"cross(u, v) takes two 3-vectors, got vectors of {' and '.join(map(str, sizes))} "
                "components")


def reject_component(span, name: str, size: int, names) -> Diagnostic:
    return diag(span, "T232", f"no component `.{name}` in a vector of {size} components (its components are "
                f"{', '.join('.' + n for n in names)})")


def reject_vector_capture(span, name: str, vector: str) -> Diagnostic:
    return diag(span, "T233", f"`{vector}` is used here, inside a let that rebinds `{name}`, which the components of "
                f"`{vector}` mention: a let-bound vector is substituted where it is used, so it would now mean "
                f"the inner `{name}`; rename one of them")


def reject_not_smooth(span, name: str, detail: str) -> Diagnostic:
    return diag(span, "T222", f"diffeo `{name}`: components must be smooth terms over its variables and "
                f"parameters: {detail}")


# ----------------------------------------------------------------------------------------------
# Fig. 6 and Fig. 11 on the core language.


#: While :func:`type_program` runs: its judgements checked so far, by the identities of
#: ``(t, Δ, Γ, out)`` (the objects kept alive with them, so that an identity stays theirs).
_CHECKING = threading.local()
# A node keeps the contexts (Δ, Γ) it was found well typed in as ``t.typed`` (``core.keep_typed``).
_LEAVES = (Const, Var, Param)


#: One object per distinct set of contexts (or of variable lists) kept on nodes: thousands of
#: nodes keep the same one, and the cyclic collector has fewer objects to traverse.
_INTERNED: dict[frozenset, frozenset] = {}


def _interned(s: frozenset) -> frozenset:
    known = _INTERNED.get(s)
    return known if known is not None else remember(_INTERNED, s, s, 4096, at_once=True)


_KNOWN_PRIMITIVES = frozenset(ALL_PRIMITIVES)


def well_typed(delta: frozenset[str], gamma: frozenset[str], t: Term) -> bool:
    """Whether ``Δ; Γ ⊢ t`` holds, read off the attributes ``t`` keeps (``langur.core``, "per-node
    attributes"): the premises of Fig. 6's rules that do not depend on the context hold everywhere
    in ``t`` (``_scoped``), its free variables — with those of its diffeomorphic conditions — are
    in Δ (variable, diffeomorphic conditional), its parameters — with its diffeos' — in Γ
    (parameter), no ``let`` binds a variable of Δ (let) and every primitive is known.  A
    sufficient condition, checked in constant time: when it fails, :func:`type_term` applies the
    rules one by one and reports what they find (it finds nothing when this holds:
    ``proofs_tests/test_typing_attributes.py`` compares the two)."""
    try:
        fv, fp, _, _, _, _, _, scoped, ops, binders, dfp = t.shape  # (core.attributes FV … DFP, in order: one read)
    except (AttributeError, TypeError, ValueError):  # not a core term (no ``shape``, or an array's): the rules say why
        return False
    return (scoped and fv <= delta and fp <= gamma and dfp <= gamma and ops <= _KNOWN_PRIMITIVES
            and binders.isdisjoint(delta))


def _remembered(fn):
    """While :func:`type_program` runs (and no observer records the derivation: ``show --typing``
    sees every rule), ``Δ; Γ ⊢ t`` is checked once per distinct node and context, as
    :func:`~langur.core.shared` would, by the rules themselves without the other layers; and it is
    skipped when a program found well typed (no diagnostic at all) already contained ``t`` in the
    same ``Δ; Γ`` — the judgement is a function of ``(Δ, Γ, t)`` and terms are immutable, so it
    holds again.  Loading a scene again after a shader swap re-types the inlined calls only, not
    the scene's conditions (issue 15)."""
    rules = inspect.unwrap(fn)

    @functools.wraps(fn)
    def wrapper(delta, gamma, t, out):
        # (not while the rules are watched one by one, :func:`langur.observe.watched`: recorded for
        # ``show --typing``, or counted by the campaigns' rule coverage, which wraps type_term)
        if not observe.watched() and well_typed(delta, gamma, t):
            return None  # every rule's premises hold: the rules would add no diagnostic
        visited = getattr(_CHECKING, "visited", None)
        if visited is None:
            return fn(delta, gamma, t, out)
        key = (id(t), id(delta), id(gamma))
        if key in visited:
            return None
        known = t.typed
        if known is not None and (delta, gamma) in known:
            return None
        visited[key] = (t, delta, gamma)
        return rules(delta, gamma, t, out)

    return wrapper


@_remembered
@shared
@observe.nested
def type_term(delta: frozenset[str], gamma: frozenset[str], t: Term, out: list[Diagnostic]) -> None:
    """``Δ; Γ ⊢ t : real`` (Fig. 6, extended by primitives and constant powers, LANGUAGE.md §1).

    Appends one diagnostic per violated rule to ``out``.  ``Call`` (elaborated modules only) is
    typed by its arguments: the callee's own body was typed where it was declared.
    """
    match t:
        case Const():
            # Fig. 6, constant: Δ;Γ ⊢ c : real
            observe.rule("Fig. 6, constant: Δ;Γ ⊢ c : real", t, delta=delta, gamma=gamma)
            return
        case Var(x):
            # Fig. 6, variable: x:real ∈ Δ
            observe.rule("Fig. 6, variable: x:real ∈ Δ ⟹ Δ;Γ ⊢ x : real", t, delta=delta, gamma=gamma)
            if x not in delta:
                if x in gamma:
                    out.append(reject_var_param_clash(t.span, x, "used as a variable but bound as a parameter"))
                else:
                    out.append(reject_unbound(t.span, x, " (not a variable of Δ)"))
        case Param(z):
            # Fig. 6, parameter: z:real ∈ Γ
            observe.rule("Fig. 6, parameter: z:real ∈ Γ ⟹ Δ;Γ ⊢ z : real", t, delta=delta, gamma=gamma)
            if z not in gamma:
                out.append(reject_undeclared_param(t.span, z, "this term"))
        case Add(a, b) | Mul(a, b):
            # Fig. 6, sum / product
            observe.rule("Fig. 6, sum / product: Δ;Γ ⊢ t, Δ;Γ ⊢ s ⟹ Δ;Γ ⊢ t ∘ s", t, delta=delta, gamma=gamma)
            type_term(delta, gamma, a, out)
            type_term(delta, gamma, b, out)
        case Prim(op, a):
            # LANGUAGE.md §1, smooth primitive f(t)
            observe.rule("LANGUAGE.md §1, smooth primitive: Δ;Γ ⊢ t ⟹ Δ;Γ ⊢ f(t)", t, delta=delta, gamma=gamma)
            if op not in ALL_PRIMITIVES:
                out.append(reject_unknown_function(t.span, op))
            type_term(delta, gamma, a, out)
        case Pow(a, k):
            # LANGUAGE.md §1, constant power t ^ k
            observe.rule("LANGUAGE.md §1, constant power: Δ;Γ ⊢ t, k constant ⟹ Δ;Γ ⊢ t ^ k", t, delta=delta, gamma=gamma)
            if not isinstance(k, Fraction):
                out.append(reject_exponent(t.span))
            type_term(delta, gamma, a, out)
        case IfGe0(c, a, b):
            # Fig. 6, conditional: ·;Γ ⊢ t, Δ;Γ ⊢ s, Δ;Γ ⊢ r
            observe.rule("Fig. 6, conditional: ·;Γ ⊢ t, Δ;Γ ⊢ s, Δ;Γ ⊢ r ⟹ Δ;Γ ⊢ ifge0 t then s else r", t, delta=delta, gamma=gamma)
            used = free_vars(c)
            if used:
                out.append(reject_condition(t.span, "a plain ifge0 condition must be variable-free, but it "
                                            f"mentions {', '.join(sorted(used))}"))
            type_term(delta if used else frozenset(), gamma, c, out)  # one report per fault
            type_term(delta, gamma, a, out)
            type_term(delta, gamma, b, out)
        case IfDiffeo(psi, a, b):
            # Fig. 6, diffeomorphic conditional: Ψ over variables of Δ and params of Γ
            observe.rule("Fig. 6, diffeomorphic conditional: Ψ̂ a diffeomorphism over Δ, Γ; Δ;Γ ⊢ s, r", t, delta=delta, gamma=gamma)
            type_diffeo(delta, gamma, psi, out, t.span)
            type_term(delta, gamma, a, out)
            type_term(delta, gamma, b, out)
        case Let(z, bound, body):
            # Fig. 6, let: ·;Γ ⊢ t and Δ; Γ, z ⊢ s
            observe.rule("Fig. 6, let: ·;Γ ⊢ t, Δ;Γ,z ⊢ s ⟹ Δ;Γ ⊢ let z = t in s", t, delta=delta, gamma=gamma)
            used = free_vars(bound)
            if used:
                out.append(reject_let_with_variables(t.span, z, used))
            if z in delta:
                out.append(reject_var_param_clash(t.span, z, "let binds the name of a variable"))
            type_term(delta if used else frozenset(), gamma, bound, out)
            type_term(delta, gamma | {z}, body, out)
        case Call(_, _, args):
            # elaborated modules only: the arguments are terms of the caller's context
            observe.rule("call (elaborated modules): the arguments typed in the caller's context", t, delta=delta, gamma=gamma)
            for a in args:
                type_term(delta, gamma, a, out)
        case ImplicitRoot(eq, x, target, lo, hi):
            # issue 18, an inverse branch's implicit root: x, Δ ⊢ eq smooth (Δ: Ψ̂⁻¹'s inputs, the
            # other variables of a condition in several), target and bracket over Δ (a bracket's end
            # is a turning point that moves with the other variables when split along x)
            observe.rule("LANGUAGE.md §1 (issue 18), implicit root: x,Δ;Γ ⊢ f, Δ;Γ ⊢ target, lo, hi ⟹ Δ;Γ ⊢ root", t, delta=delta, gamma=gamma)
            type_term(delta | {x}, gamma, eq, out)
            type_term(delta, gamma, target, out)
            type_term(delta, gamma, lo, out)
            type_term(delta, gamma, hi, out)
        case _:
            raise TypeError(f"not a core term: {t!r}")


def type_diffeo(delta: frozenset[str], gamma: frozenset[str], psi: Diffeo, out: list[Diagnostic], span=None) -> None:
    """The premise of Fig. 6's diffeomorphic conditional: Ψ̂'s inputs are variables of Δ, its
    components terms over them and Γ; the inverse's branches terms over its inputs and Γ.  That
    ``Ψ̂`` *is* a diffeomorphism is established by ``langur.syntax.diffeo`` (T207, T214–T216)."""
    where = span or psi.span
    if len(set(psi.variables)) != len(psi.variables) or not set(psi.variables) <= delta:
        out.append(reject_diffeo_args(where, psi.name or "(completed)",
                                      f"{', '.join(psi.variables)} are not distinct variables of Δ"))
    if len(psi.forward) != len(psi.variables) or len(psi.inputs) != len(psi.variables):
        out.append(diag(where, "T214", f"Ψ̂ has {len(psi.variables)} variables, {len(psi.forward)} components "
                        f"and {len(psi.inputs)} inverse inputs"))
    for f in psi.forward:
        type_term(frozenset(psi.variables), gamma, f, out)
    for b in psi.branches:
        if len(b.components) != len(psi.variables):
            out.append(diag(where, "T214", "an inverse branch has the wrong number of components"))
        for c in b.components + b.guards:
            type_term(frozenset(psi.inputs), gamma, c, out)
    for z in psi.nonzero:
        type_term(frozenset(), gamma, z, out)


def type_program(p: Program, gamma: frozenset[str]) -> list[Diagnostic]:
    """``·; Γ ⊢ int t d(x1, …, xn) : real`` (Fig. 11) and compact support (§8.3): the program's
    diagnostics (empty when it is well typed)."""
    outer = getattr(_CHECKING, "visited", None)
    _CHECKING.visited = visited = None if observe.active() else {}
    try:
        out = _type_program(p, gamma)
        if not out and visited:
            alone: dict[tuple, frozenset] = {}  # (id Δ, id Γ) -> the interned {(Δ, Γ)}
            for t, delta, gamma_ in visited.values():
                if isinstance(t, _LEAVES):
                    continue
                key = (id(delta), id(gamma_))
                single = alone.get(key)
                if single is None:
                    single = alone[key] = _interned(frozenset({(delta, gamma_)}))
                known = t.typed
                keep_typed(t, single if known is None or known is single else _interned(known | single))
    finally:
        _CHECKING.visited = outer
    return out


def _type_program(p: Program, gamma: frozenset[str]) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    seen: set[str] = set()
    for x in p.variables:
        if x in seen:
            out.append(reject_duplicate(p.span, "integration variable", x))
        seen.add(x)
        if x in gamma:
            out.append(reject_var_param_clash(p.span, x, "integration variable and declared param"))
    # Fig. 11: x1:real, …, xn:real; Γ ⊢ t : real  (a term contains no int: T208 cannot arise here,
    # since a core Term has no program node)
    observe.rule("Fig. 11, program: x1:real, …, xn:real; Γ ⊢ t ⟹ ·;Γ ⊢ int t d(x1, …, xn)", p,
                 delta=frozenset(p.variables), gamma=gamma)
    type_term(frozenset(p.variables), gamma, p.body, out)
    # after inlining every diffeomorphic condition is over all the program's variables
    for u in _ifdiffeos(p.body) if diffeo_variables(p.body) - {p.variables} else ():
        if u.psi.variables != p.variables:
            out.append(reject_diffeo_args(u.span, u.psi.name or "(completed)",
                                          f"over {u.psi.variables}, not the program's variables {p.variables}"))
    # §8.3: compact support, witnessed by the box
    if len(p.box) != len(p.variables):
        out.append(reject_not_compact(p.span, p.variables[len(p.box):] or p.variables))
    for lo, hi in p.box:
        type_term(frozenset(), gamma, lo, out)
        type_term(frozenset(), gamma, hi, out)
    if not out:
        out += out_of_range(p.body)
    return out


def out_of_range(t: Term) -> list[Diagnostic]:
    """T231 for the first constant subterm (no variable, no parameter) whose exact value lies
    beyond the range of doubles (``10^400``, ``1e200 * 1e200``): the literals themselves are in
    range (E106), but the numeric engines compute in doubles and would see ±∞ there."""
    if all_small(t):
        return []  # no constant near the range of doubles: decided exactly, without mpmath
    limit = mpmath.mpf(sys.float_info.max)
    memo: dict[int, object] = {}
    for u in subterms(t):
        v = _constant(u, memo)
        if v is not None and abs(v) > limit:
            return [diag(u.span, "T231", f"constant beyond the range of doubles: its value is about "
                         f"{mpmath.nstr(v, 3)}, more than {sys.float_info.max:.4g} in magnitude; the numeric "
                         "engines (quadrature, Monte Carlo) compute in doubles and would see an infinity "
                         "(rescale the program)")]
    return []


def _constant(t: Term, memo: dict[int, object]):
    """The value of a variable-free, parameter-free term with mpmath (30 digits), or None."""
    key = id(t)
    if key in memo:
        return memo[key]
    v = None
    try:
        with mpmath.workdps(30):
            match t:
                case Const(value) if value == "pi":
                    v = +mpmath.pi
                case Const(value):
                    v = mpmath.mpf(value.numerator) / value.denominator
                case Add(a, b) | Mul(a, b):
                    x, y = _constant(a, memo), _constant(b, memo)
                    if x is not None and y is not None:
                        v = x + y if isinstance(t, Add) else x * y
                case Pow(a, k):
                    x = _constant(a, memo)
                    if x is not None and (x > 0 or k.denominator == 1) and (x != 0 or k > 0):
                        v = mpmath.power(x, mpmath.mpf(k.numerator) / k.denominator)
                case Prim(op, a):
                    x = _constant(a, memo)
                    f = getattr(mpmath, op, None)
                    if x is not None and f is not None:
                        v = f(x)
                        v = v if isinstance(v, mpmath.mpf) else None
    except (ValueError, ZeroDivisionError, OverflowError):
        v = None
    memo[key] = v
    return v




def _ifdiffeos(t: Term):
    for u in subterms(t):
        if isinstance(u, IfDiffeo):
            yield u
