"""Type-directed pieces of a program: parameter terms, conditions over the variables, smooth
factors and declared diffeomorphisms, as surface ASTs (:mod:`langur.strategies.terms`).

Each builder takes a :class:`Scope` (the typing environment, LANGUAGE.md §4 and Fig. 11: the
variables, the parameter-kind names with their default values, the diffeos declared so far) and
draws its choices through ``scope.draw``; the simplest choice is always the first (index 0), so
hypothesis shrinks a program towards affine conditions and polynomial factors.  A condition
registers its zero sets in the scope (:func:`Scope.register`), from which the program's
genericity is checked.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction as F

from hypothesis import strategies as st

from ..syntax import surface as S
from . import terms as T
from .terms import call, mul, name, num, offset, power, sub

#: Literal offsets ``k`` in ``P + k`` (irregular, so that zero sets rarely meet by accident).
OFFSETS = (F(0), F(3, 10), F(-1, 5), F(3, 20), F(-9, 20), F(11, 20))
#: Coefficients of a variable in an affine condition.
COEFFICIENTS = (F(1), F(2), F(-1), F(1, 2))
CMPS = ("<=", ">=", "<", ">")


@dataclass
class Scope:
    """The typing environment while a program is drawn, and what it has registered so far."""

    draw: object
    variables: tuple[str, ...]
    env: dict[str, float]                  # parameter-kind names (parameters, let names) -> value
    names: list[str]                       # parameter-kind names usable in terms
    light: bool = False
    kinks: bool = False
    turning: bool = False
    #: constructs the default draw never makes (:mod:`~.wide`)
    wide: bool = False
    #: moving poles, products of moving factors, folding edge cases (:mod:`~.poles`)
    poles: bool = False
    #: split conditions over two variables, nested three deep, in defs called twice (:mod:`~.deep`)
    deep: bool = False
    #: the variables whose domain bounds are constants (an implicit root needs a fixed bracket)
    fixed: tuple[str, ...] = ()
    #: the conditions drawn by :func:`turning_condition` (they stay in the program: in a ``def``
    #: the variables' domain, which their implicit roots need, is unknown)
    implicit: list = field(default_factory=list)
    zero_sets: list[T.ZeroSet] = field(default_factory=list)
    diffeos: dict[str, S.DiffeoDecl] = field(default_factory=dict)
    #: each factor of the program with the zero sets it registered (a def called with other
    #: parameter terms registers them again at those terms)
    made: list[tuple[S.STerm, tuple[T.ZeroSet, ...]]] = field(default_factory=list)
    #: the bound of each ``let`` drawn inside a factor (:func:`~.wide.let_level`), by its name: a
    #: def whose body binds it, called with other parameter terms, binds it to other values
    lets: dict[str, S.STerm] = field(default_factory=dict)
    #: the factors drawn by :func:`~.deep.factor` (a def is preferably made of one of them)
    split: list = field(default_factory=list)

    def pick(self, seq):
        return self.draw(st.sampled_from(tuple(seq)))

    def index(self, n: int) -> int:
        return self.draw(st.integers(0, n - 1))

    def var(self) -> str:
        return self.pick(self.variables)

    def two_vars(self) -> tuple[str, str]:
        v = self.var()
        return v, self.pick(w for w in self.variables if w != v)

    def param(self) -> S.Name:
        return name(self.pick(self.names))

    def positive(self, p: S.Name) -> S.STerm:
        """``p``, or ``-p`` when its value is negative (``wide`` draws negative defaults): a
        parameter term with a positive value, where a primitive's domain needs one."""
        return p if self.env[p.name] >= 0 else S.Neg(p)

    def register(self, term: S.STerm, key=None) -> None:
        """The zero sets of the condition ``term ≥ 0`` (or of a kink): every smooth piece of
        ``term`` (``abs``, ``min``, ``max`` are conditionals, split by the front end) and every
        kink inside it."""
        found: list[T.ZeroSet] = []
        for piece in _pieces(term):
            found.append(T.zero_set(piece, self.variables, self.env, key=key if piece is term else None))
        for k in _kinks(term):
            found.append(T.zero_set(k, self.variables, self.env))
        # one zero set met twice inside one term is one set; met again in another term it is a
        # coincidence, which :func:`~.terms.generic` rejects
        self.zero_sets += list({z.key: z for z in found}.values())


def _pieces(t: S.STerm) -> list[S.STerm]:
    """The smooth alternatives of a term with ``abs``/``min``/``max`` (each kink's branches)."""
    match t:
        case S.Apply("abs", (u,)):
            return [p for q in _pieces(u) for p in (q, S.Neg(q))]
        case S.Apply("min" | "max", (a, b)):
            return _pieces(a) + _pieces(b)
        case S.BinOp(op, a, b) if op in "+-":
            return [S.BinOp(op, p, q) for p in _pieces(a) for q in _pieces(b)]
    return [t]


def _kinks(t) -> list[S.STerm]:
    """The terms whose zero sets are kinks of ``t``: ``u`` of ``abs(u)``, ``a - b`` of ``min(a, b)``."""
    out = []
    stack = [t]
    while stack:
        u = stack.pop()
        if isinstance(u, S.Apply):
            if u.name == "abs":
                out.append(u.args[0])
            elif u.name in ("min", "max"):
                out.append(sub(*u.args))
            stack.extend(u.args)
        elif isinstance(u, (S.BinOp,)):
            stack.extend((u.left, u.right))
        elif isinstance(u, S.Neg):
            stack.append(u.arg)
    return out


# ---------------------------------------------------------------------------------------------
# Parameter terms (type param: no variable inside)
# ---------------------------------------------------------------------------------------------

def shifted_param(scope: Scope, offsets=OFFSETS) -> S.STerm:
    """``P + k``: a parameter-kind name moved by a literal."""
    return offset(scope.param(), scope.pick(offsets))


def positive_param_term(scope: Scope, params: list[str]) -> S.STerm:
    """A positive term over parameters, for ``let s = … in …``: ``2*p``, ``p + 0.5*q``, ``p*q + 0.1``."""
    p, q = params[0], params[-1]
    forms = (lambda: mul(num(2), name(p)),
             lambda: T.add(name(p), mul(num(F(1, 2)), name(q))),
             lambda: T.add(mul(name(p), name(q)), num(F(1, 10))))
    return forms[scope.index(len(forms))]()


# ---------------------------------------------------------------------------------------------
# Conditions: (lhs, op, rhs), ``lhs − rhs`` a diffeomorphism's first component after completion
# ---------------------------------------------------------------------------------------------

Cond = tuple[S.STerm, str, S.STerm]


def affine(scope: Scope) -> Cond:
    """``Σ c_v·v CMP P + k`` with literal coefficients over a nonempty set of the variables."""
    first = scope.var()
    coefs = {}
    for v in scope.variables:
        if v == first or scope.draw(st.integers(0, 2)) == 2:
            coefs[v] = scope.pick(COEFFICIENTS)
    return T.linear(coefs), scope.pick(CMPS), shifted_param(scope)


def parametric_coefficient(scope: Scope) -> Cond:
    """``P*v CMP k`` (the completion divides by P: ``Diffeo.nonzero``) or ``P*v + c*w CMP Q + k``."""
    v = scope.var()
    p = scope.param()
    if len(scope.variables) == 1 or scope.draw(st.booleans()) is False:
        return mul(p, name(v)), scope.pick(("<=", ">=")), num(scope.pick((F(3, 10), F(3, 20), F(-1, 5), F(11, 20))))
    w = scope.pick(u for u in scope.variables if u != v)
    return T.linear({v: p, w: scope.pick(COEFFICIENTS)}), scope.pick(CMPS), shifted_param(scope)


def quadratic(scope: Scope) -> Cond:
    """Two roots: ``v^2 CMP P + k``, ``(v - P)^2 CMP k`` or ``v^2 - P*v CMP Q``."""
    v = name(scope.var())
    form = scope.index(3)
    cmp = scope.pick(("<=", ">="))
    if form == 0:
        return power(v, 2), cmp, shifted_param(scope, (F(0), F(3, 10), F(11, 20), F(-1, 5)))
    if form == 1:
        return power(sub(v, scope.param()), 2), cmp, num(scope.pick((F(1, 10), F(1, 4))))
    return sub(power(v, 2), mul(scope.param(), v)), cmp, scope.param()


def monotone(scope: Scope) -> Cond:
    """A monotone primitive of one variable, its argument inside the primitive's domain on every
    box (boxes lie in [-1, 2]): ``exp(v)``, ``sqrt(v + 2)``, ``log(v + 2)``, ``atan(2*v)``,
    ``tanh(v - P)`` against a parameter term."""
    v = name(scope.var())
    cmp = scope.pick(("<=", ">="))
    forms = (
        lambda: (call("exp", v), offset(scope.param(), 1)),
        lambda: (call("sqrt", offset(v, 2)), offset(scope.param(), 1)),
        lambda: (call("log", offset(v, 2)), shifted_param(scope)),
        lambda: (call("atan", mul(num(2), v)), offset(scope.param(), F(-1, 2))),
        lambda: (call("tanh", sub(v, scope.param())), num(scope.pick((F(1, 10), F(-3, 10))))),
    )
    lhs, rhs = forms[scope.index(2 if scope.light else len(forms))]()
    return lhs, cmp, rhs


def graph(scope: Scope) -> Cond:
    """The region above or below a graph, ``w CMP g(v) + P + k`` (two variables at least)."""
    v, w = scope.two_vars()
    forms = (
        lambda: T.add(power(name(v), 2), shifted_param(scope)),
        lambda: sub(mul(scope.param(), power(name(v), 2)), num(F(1, 5))),
        lambda: T.add(call("sin", name(v)), scope.param()),
        lambda: sub(call("exp", name(v)), offset(scope.param(), 1)),
    )
    g = forms[scope.index(2 if scope.light else len(forms))]()
    return name(w), scope.pick((">=", "<=")), g


def circle(scope: Scope) -> Cond:
    """A disk ``v^2 + w^2 <= P + k``, an off-centre disk ``(v - P)^2 + w^2 <= k``, or in three
    variables a ball."""
    v, w = scope.two_vars()
    form = scope.index(3 if len(scope.variables) == 3 else 2)
    cmp = scope.pick(("<=", ">="))
    if form == 0:
        return T.add(power(name(v), 2), power(name(w), 2)), cmp, shifted_param(scope, (F(0), F(3, 10), F(11, 20)))
    if form == 1:
        return T.add(power(sub(name(v), scope.param()), 2), power(name(w), 2)), cmp, num(scope.pick((F(3, 10), F(1, 5))))
    x, y, z = (name(u) for u in scope.variables)
    return T.add(T.add(power(x, 2), power(y, 2)), power(z, 2)), cmp, shifted_param(scope, (F(3, 10), F(11, 20)))


#: Condition kinds by weight (the first is what shrinking aims at); graphs and circles need two
#: variables and fall back to an affine condition in one.
CONDITIONS = (affine, affine, parametric_coefficient, quadratic, monotone, monotone, graph, graph, circle, circle)


def condition(scope: Scope) -> Cond:
    """A condition over the variables (one of :data:`CONDITIONS`), its zero sets registered."""
    kind = CONDITIONS[scope.index(len(CONDITIONS))]
    if kind in (graph, circle) and len(scope.variables) == 1:
        kind = affine
    lhs, cmp, rhs = kind(scope)
    scope.register(sub(lhs, rhs), key=(lhs, rhs))
    return lhs, cmp, rhs


def kink_condition(scope: Scope) -> S.Iverson:
    """A condition with a kink inside, split at the kink by the front end (issue 18): the window
    ``[abs(v - P) <= k]``, ``[max(v, c) >= P]`` or, in two variables or more, ``[min(v, w) >= P]``."""
    v = name(scope.var())
    shape = scope.index(3 if len(scope.variables) > 1 else 2)
    if shape == 0:
        lhs, cmp, rhs = call("abs", sub(v, scope.param())), "<=", num(scope.pick((F(1, 5), F(7, 20))))
    elif shape == 1:
        lhs, cmp, rhs = call("max", v, num(scope.pick((F(9, 20), F(13, 20))))), ">=", scope.param()
    else:
        a, b = scope.two_vars()
        lhs, cmp, rhs = call("min", name(a), name(b)), ">=", scope.param()
    scope.register(sub(lhs, rhs), key=(lhs, rhs))
    return S.Iverson((lhs, rhs), (cmp,))


def turning_condition(scope: Scope) -> S.Iverson:
    """A condition in one variable with no closed-form inverse, completed on its monotone pieces by
    implicit roots (issue 18, :mod:`langur.syntax.turning`): the cubic ``v^3 - v`` (two turning
    points, up to three roots), ``exp(v) + v`` and ``v^5 + v`` (monotone, no inverse in closed
    form), ``sin(3*v)`` (turning points inside the box), and turning points that move with a
    parameter ``P`` (``sin(3*P*v)``, ``v^3 - P*v``: counted certified by the engines) or, with two
    variables of constant bounds, with the other variable (``v^3 - v*w + w^3``: split along one of
    them at turning points that move with the other), against a
    parameter term; ``v`` a variable with constant bounds, or one whose bound moves with the
    parameters (the implicit root's bracket follows it; the cubics' pieces end at the certified
    sign changes of their derivative on the moving interval)."""
    moving = tuple(v for v in scope.variables if v not in scope.fixed)
    if not scope.fixed and not moving:
        lhs, cmp, rhs = condition(scope)
        return S.Iverson((lhs, rhs), (cmp,))
    monotone = (
        lambda v: T.add(call("exp", v), v),
        lambda v: T.add(power(v, 5), v),
    )
    if scope.fixed and (not moving or scope.index(3) != 0):
        v = name(scope.pick(scope.fixed))
        forms = monotone + (
            lambda v: sub(power(v, 3), v),
            lambda v: call("sin", mul(num(3), v)),
            lambda v: call("sin", mul(num(3), mul(scope.param(), v))),
            lambda v: sub(power(v, 3), mul(scope.param(), v)),
        )
        others = tuple(w for w in scope.fixed if w != v.name) if isinstance(v, S.Name) else ()
        if others:  # two variables: split along one at turning points that move with the other
            w = name(others[0])
            forms += (lambda v: T.add(sub(power(v, 3), mul(v, w)), power(w, 3)),)
    else:  # a bound that moves: monotone on the whole line, or turning points (fixed or moving) split
        v = name(scope.pick(moving))  # at their certified sign changes on the moving interval
        forms = monotone + (
            lambda v: sub(power(v, 3), v),
            lambda v: sub(power(v, 3), mul(scope.param(), v)),
        )
    lhs = forms[scope.index(len(forms))](v)
    cmp = scope.pick(("<=", ">="))
    rhs = shifted_param(scope, (F(0), F(-1, 5), F(3, 20), F(-9, 20)))
    scope.register(sub(lhs, rhs), key=(lhs, rhs))
    out = S.Iverson((lhs, rhs), (cmp,))
    scope.implicit.append(out)
    return out


def window(scope: Scope) -> S.Iverson:
    """``[P + k <= affine <= P + k + w]``: a chained bracket, two parallel jumps."""
    lhs, _, lo = affine(scope)
    hi = offset(lo, scope.pick((F(7, 20), F(3, 5))))
    scope.register(sub(lhs, lo), key=(lhs, lo))
    scope.register(sub(lhs, hi), key=(lhs, hi))
    return S.Iverson((lo, lhs, hi), ("<=", "<="))


# ---------------------------------------------------------------------------------------------
# Smooth factors
# ---------------------------------------------------------------------------------------------

def smooth(scope: Scope) -> S.STerm:
    """A smooth factor: polynomials, ``exp``, ``sin``, ``cos``, ``sqrt``, … of affine or quadratic
    terms, each argument inside its primitive's domain on every box (boxes lie in [-1, 2],
    parameters are positive); ``light`` keeps to the first ten (sympy integrates ``atan``, ``log``
    and fractional powers over regions slowly).  ``min``, ``max`` and ``abs`` are conditionals:
    their kinks are registered; where a form needs a positive parameter, a negative one enters as
    ``-P`` (:meth:`Scope.positive`)."""
    v, w = name(scope.var()), name(scope.var())
    p = scope.param()
    k = num(scope.pick((F(1, 2), F(3, 2), F(2), F(1, 4))))
    forms = (
        lambda: T.add(v, k),
        lambda: T.add(mul(p, v), k),
        lambda: power(v, 2),
        lambda: sub(mul(v, w), p),
        lambda: call("exp", sub(mul(k, v), p)),
        lambda: call("sin", T.add(v, mul(p, w))),
        lambda: call("cos", sub(mul(p, v), k)),
        lambda: call("sqrt", offset(v, F(3, 2))),
        lambda: call("sqrt", T.add(mul(v, v), scope.positive(p))),
        lambda: p,
        lambda: call("log", offset(v, 2)),
        lambda: call("atan", T.add(mul(v, w), p)),
        lambda: call("tanh", mul(p, v)),
        lambda: T.div(num(1), offset(T.add(v, scope.positive(p)), F(3, 2))),
        lambda: power(T.add(v, p), 3),
        lambda: power(offset(w, F(3, 2)), F(3, 2)),
        lambda: call("exp", call("min", v, p)),
        lambda: call("sqrt", offset(call("max", v, p), F(3, 2))),
        lambda: call("abs", sub(v, p)),
    )
    term = forms[scope.index(10 if scope.light else len(forms))]()
    scope.zero_sets += [T.zero_set(kink, scope.variables, scope.env) for kink in _kinks(term)]
    return term


# ---------------------------------------------------------------------------------------------
# Declared diffeomorphisms (LANGUAGE.md §6): shear, rotation, cubic graph
# ---------------------------------------------------------------------------------------------

def _decl(n: str, forward, inverse) -> S.DiffeoDecl:
    return S.DiffeoDecl(S.Ident(n), (S.Ident("x"), S.Ident("y")), (S.Ident("c"),), tuple(forward),
                        (S.Ident("u"), S.Ident("v")), tuple(inverse))


def _declarations() -> dict[str, S.DiffeoDecl]:
    x, y, u, v, c = (name(n) for n in "xyuvc")
    three, four = num(F(3, 5)), num(F(4, 5))
    return {
        # (x, y) ↦ (x + y − c, y): a shear
        "sh": _decl("sh", (sub(T.add(x, y), c), y), (T.add(sub(u, v), c), v)),
        # (x, y) ↦ R(x, y) − (c, 0), R the rotation with cos = 3/5, sin = 4/5: inverse Rᵀ(u + c, v)
        "rot": _decl("rot", (sub(sub(mul(three, x), mul(four, y)), c), T.add(mul(four, x), mul(three, y))),
                     (T.add(mul(three, T.add(u, c)), mul(four, v)), sub(mul(three, v), mul(four, T.add(u, c))))),
        # (x, y) ↦ (y − x³ − c, x): the region above a cubic graph
        "cub": _decl("cub", (sub(sub(y, power(x, 3)), c), x), (v, T.add(T.add(u, power(v, 3)), c))),
    }


DIFFEOS = _declarations()


def _scaled() -> S.DiffeoDecl:
    """``(x, y) ↦ (x − c·y − c, (1 + c)·y)``, inverse ``(u, v) ↦ (u + c·v/(1 + c) + c, v/(1 + c))``:
    its inverse and |det DΨ̂⁻¹| = 1/(1 + c) depend on the parameter."""
    x, y, u, v, c = (name(n) for n in "xyuvc")
    one_c = T.add(num(1), c)
    return _decl("scl", (sub(sub(x, mul(c, y)), c), mul(one_c, y)),
                 (T.add(T.add(u, T.div(mul(c, v), one_c)), c), T.div(v, one_c)))


#: Declared diffeomorphisms drawn only by wide programs (``Scope.wide``).
WIDE_DIFFEOS = {"scl": _scaled()}


def declared(scope: Scope) -> S.DiffeoApp:
    """``NAME(v, w; P)`` for a declared diffeo (two variables at least), declared in the scope."""
    known = {**DIFFEOS, **WIDE_DIFFEOS} if scope.wide else DIFFEOS
    n = scope.pick(known)
    decl = known[n]
    scope.diffeos[n] = decl
    v, w = scope.two_vars() if scope.draw(st.integers(0, 3)) == 3 else scope.variables[:2]
    p = scope.param()
    first = T.rename(decl.forward[0], {"x": v, "y": w, "c": p.name})
    scope.register(first, key=("diffeo", n, v, w, p.name))
    return S.DiffeoApp(n, (name(v), name(w)), (p,))
