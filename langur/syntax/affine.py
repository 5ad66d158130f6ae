"""Completing affine conditions without sympy: the direct path of condition completion (§4, §5.2).

A condition ``t`` over variables is completed to ``Ψ̂ = (t, the other variables)`` by solving
``t = u₀`` for one variable (``langur.syntax.diffeo.complete``, LANGUAGE.md §6).  When ``t`` is
*affine with rational coefficients* in the variables and parameters (``x - θ``, ``x + 2*y - 3*a + 1``,
``x/2 - 1/3``), every variable has a constant coefficient (rank 0 of ``diffeo``'s ranking), the last
one in order is chosen, and its inverse is a linear form: exact rational arithmetic
(``fractions.Fraction``) solves it in time linear in the size of ``t``, with no sympy.

The result is the *same* :class:`~langur.core.Diffeo` as the sympy path's, term for term: sympy
writes ``(u₀ − rest)/c`` as an expanded sum, the number first, then the terms in the order of
``sympy.Basic.compare`` (a bare symbol before ``c·symbol``; ``c·symbol`` by the class of ``c`` —
``1/2``, ``-1``, other integers, other rationals — then by ``c``'s numerator and denominator, then
by name), and ``langur.sympy_bridge.from_sympy`` folds it from the left.  :func:`_ordered` copies
that order; ``proofs_tests/test_affine.py`` checks it against sympy on random conditions.

Anything else (a parametric coefficient, a graph ``y - x^2``, a primitive, π) returns ``None``:
the sympy path decides (``langur.syntax.diffeo``).  This module never imports sympy, so a program
whose conditions are affine loads without it (the Monte Carlo path's start-up).

Also here, because both paths need them: :func:`fresh_inputs` (the names ``u0 …`` of Ψ̂⁻¹'s inputs)
and :func:`rational_value` (a variable-free term's exact value, when it is rational).
"""

from __future__ import annotations

import functools
from fractions import Fraction

from ..core import (
    Add,
    Const,
    Diffeo,
    InverseBranch,
    Mul,
    Param,
    Pow,
    Term,
    Var,
    free_params,
    free_vars,
    keep_solved,
    kept_solved,
    like_binary,
    shape_with_span,
    small_value,
    tree_size,
)
from ..memo import make_room

#: Largest |exponent| folded exactly (``2^k`` with a constant base): beyond it, the sympy path.
MAX_EXPONENT = 64

#: A linear form: coefficients by ``("v", name)`` (a variable) or ``("p", name)`` (a parameter),
#: and the constant term.
Linear = tuple[dict[tuple[str, str], Fraction], Fraction]


#: The prefixes of :func:`fresh_inputs`, in the order they are tried, each with its first names.
_PREFIXES = tuple((prefix, tuple(f"{prefix}{i}" for i in range(8))) for prefix in ("u", "u_", "w", "w_", "v_", "_u"))


def fresh_inputs(n: int, taken: set[str]) -> tuple[str, ...]:
    """``u0 … u{n-1}``, or with the first prefix among ``u, u_, w, w_, …`` that clashes with nothing.
    (Up to 8 names read off a table: every completion of a new shape asks, issue 15.)"""
    for prefix, first in _PREFIXES:
        names = first[:n] if n <= 8 else tuple(f"{prefix}{i}" for i in range(n))
        if taken.isdisjoint(names):
            return names
    k = 0
    while any(f"_u{k}_{i}" in taken for i in range(n)):
        k += 1
    return tuple(f"_u{k}_{i}" for i in range(n))


def linear(t: Term) -> Linear | None:
    """``t`` as an affine form with rational coefficients, or ``None`` if it is not one.  A term
    shared after inlining (a DAG: ``let v = v + v`` forty times) is read once per distinct node
    (a small term, under 64 nodes written out, is read as a tree)."""
    if tree_size(t) < 64:
        return _tree_linear(t)
    memo: dict[int, Linear | None] = {}

    def go(u: Term) -> Linear | None:
        key = id(u)
        if key not in memo:
            memo[key] = _linear(u, go)
        return memo[key]

    return go(t)


def _tree_linear(t: Term) -> Linear | None:
    return _linear(t, _tree_linear)


_ZERO, _ONE = Fraction(0), Fraction(1)


def _linear(t: Term, linear) -> Linear | None:
    """One node of :func:`linear` (``linear`` reads the children).  (By the node's class, the most
    frequent first, rather than a ``match``, whose class patterns test each class in turn and read
    the fields by name: every node of every condition comes here, issue 15.)"""
    v = t.small  # (core.small_value, read in place: every node of every condition comes here)
    if v is not None and v is not False:
        return {}, v  # a constant whose exact value the node keeps: the same rational, no walk
    tt = type(t)
    if tt is Add:
        la, lb = linear(t.left), linear(t.right)
        if la is None or lb is None:
            return None
        ca, cb = la[1], lb[1]
        constant = cb if not ca else (ca if not cb else ca + cb)
        if not lb[0] or not la[0]:  # (forms are never changed once built: they may be shared)
            return (la[0] or lb[0]), constant
        coeffs = dict(la[0])
        for k, c in lb[0].items():
            if k not in coeffs:
                coeffs[k] = c
                continue
            s = coeffs[k] + c
            if s:
                coeffs[k] = s
            else:
                del coeffs[k]
        return coeffs, constant
    if tt is Var:
        return {("v", t.name): _ONE}, _ZERO
    if tt is Param:
        return {("p", t.name): _ONE}, _ZERO
    if tt is Mul:
        la = linear(t.left)
        lb = linear(t.right) if la is not None else None
        if la is None or lb is None:
            return None
        if la[0] and lb[0]:
            return None  # a product of two non-constant forms is not affine
        c, form = (la[1], lb) if not la[0] else (lb[1], la)
        if not c:
            return {}, _ZERO
        if c == 1:
            return form
        return {k: c * v for k, v in form[0].items()}, c * form[1]
    if tt is Pow:
        k = t.exponent
        lb = linear(t.base)
        if lb is None:
            return None
        if k == 1:
            return lb
        if lb[0] or k.denominator != 1 or abs(k) > MAX_EXPONENT or (k < 0 and lb[1] == 0):
            return None
        return {}, lb[1] ** int(k)
    if tt is Const:
        value = t.value
        if type(value) is Fraction or isinstance(value, Fraction):
            return {}, value
    return None


def rational_value(t: Term) -> Fraction | None:
    """The exact value of a variable- and parameter-free ``t`` when it is rational, else ``None``."""
    form = linear(t)
    if form is None or form[0]:
        return None
    return form[1]


def complete(cond: Term, variables: tuple[str, ...], avoid: frozenset[str] = frozenset()) -> Diffeo | None:
    """The completion of ``cond`` over ``variables`` (as ``diffeo.complete`` gives it), isolating none
    of the variables in ``avoid``, or ``None`` when ``cond`` is not affine with rational coefficients
    (then the sympy path decides).

    Conditions of one shape — the same variables, parameters and coefficients, whatever their
    constant term (a loop's copies: ``x + 1/i + a - 1`` for i = 10 … 58) — are solved once
    (:func:`_solve`); each then costs its linear form, the constant ``−c₀/a`` and the Diffeo."""
    found = solve(cond, variables, avoid)
    if found is None:
        return None
    solved, c0 = found  # (completed and solved_at written out: every completion of a new shape)
    constant = -c0 if solved[1] == 1 else -c0 / solved[1]
    psi = _solved_at(cond, variables, solved, (constant.numerator, constant.denominator), constant)
    if not avoid:  # (kept for a loop's template, which completes this shape again: `solved_by`)
        keep_solved(psi, found)
    return psi


def solved_by(psi: Diffeo, cond: Term, variables: tuple[str, ...]) -> tuple[tuple, Fraction] | None:
    """``solve(cond, variables)``, read off ``psi`` when :func:`complete` made it from that ``cond``
    (the same object) over those ``variables`` (isolating any): no second walk (a loop's template,
    issue 15)."""
    found = kept_solved(psi)
    if found is not None and psi.forward[0] is cond and psi.variables == tuple(variables):
        return found
    return solve(cond, tuple(variables))


def solve(cond: Term, variables: tuple[str, ...], avoid: frozenset[str] = frozenset()) -> tuple[tuple, Fraction] | None:
    """What :func:`complete` finds of ``cond``: its shape solved (:func:`_solve`, shared by every
    condition of that shape) and its constant term ``c₀``; ``None`` when :func:`complete` gives None."""
    form = linear(cond)
    if form is None:
        return None
    coeffs, c0 = form
    occurring = free_vars(cond)
    if not occurring:
        return None
    solved = _solve(tuple(variables), tuple(coeffs.items()), occurring, free_params(cond), frozenset(avoid))
    return None if solved is None else (solved, c0)


def completed(cond: Term, variables: tuple[str, ...], solved: tuple, c0: Fraction) -> Diffeo:
    """The completion of ``cond``, whose shape :func:`solve` solved (``solved``) and whose constant
    term is ``c0`` (:func:`complete` is ``completed(cond, variables, *solve(cond, variables))``)."""
    a = solved[1]
    return solved_at(cond, variables, solved, -c0 if a == 1 else -c0 / a)


def solved_at(cond: Term, variables: tuple[str, ...], solved: tuple, constant: Fraction) -> Diffeo:
    """The completion of ``cond``, whose shape :func:`solve` solved (``solved``), where the solved
    variable's solution has the constant term ``constant`` (``−c₀/a``)."""
    return _solved_at(cond, variables, solved, (constant.numerator, constant.denominator), constant)


def solved_at_ratio(cond: Term, variables: tuple[str, ...], solved: tuple, num: int, den: int) -> Diffeo:
    """:func:`solved_at` with the constant given in lowest terms, ``num / den`` (``den > 0``): its
    ``Fraction`` is made only when its branches are new (a loop's copies add up their constants in
    integers, issue 15)."""
    return _solved_at(cond, variables, solved, (num, den), None)


def solved_at_ratios(conds: list, variables: tuple[str, ...], solved: tuple, keys: list) -> list:
    """``[solved_at_ratio(cond, variables, solved, *key) for cond, key in zip(conds, keys)]`` in one
    loop, None where a key is None (a loop's copies whose conditions have one solved shape and
    differ in their constants, issue 15)."""
    v, a, inputs, others, parts, renamed, known = solved
    variables = tuple(variables)
    out = []
    append = out.append
    for cond, key in zip(conds, keys):
        if key is None:
            append(None)
            continue
        branches = known.get(key)
        if branches is None:
            make_room(known, 4096, at_once=True)
            branches = known[key] = _branches(Fraction(*key), parts, renamed, known)
        append(Diffeo(variables, (cond,) + others, inputs, branches, v, None, (), getattr(cond, "span", None)))
    return out


def _solved_at(cond: Term, variables: tuple[str, ...], solved: tuple, key: tuple[int, int],
               constant: Fraction | None) -> Diffeo:
    """:func:`solved_at` with the constant's numerator and denominator ``key`` (and the constant
    itself, or None)."""
    v, a, inputs, others, parts, renamed, known = solved
    branches = known.get(key)  # (two ints hash in C; a Fraction in Python)
    if branches is None:
        make_room(known, 4096, at_once=True)
        branches = known[key] = _branches(Fraction(*key) if constant is None else constant, parts, renamed, known)
    # (positional: a keyword call costs a loop's copy more than the record's own init)
    return Diffeo(tuple(variables), (cond,) + others, inputs, branches, v, None, (), getattr(cond, "span", None))


def summands(cond: Term, moving) -> list[tuple[Term, Fraction]] | None:
    """The subterms of ``cond`` that ``moving`` picks (a loop's copies rebuild them), each with the
    factor it is multiplied by in ``cond``, when each is a constant with a small value reached from
    ``cond``'s root through sums and products by constants ``moving`` does not pick, and ``moving``
    picks no other subterm of ``cond`` (it is asked of a subterm before its children); else
    ``None``.  Then every condition that differs from ``cond`` only in those constants' values
    (each still small) has :func:`linear`'s coefficients of ``cond`` and the constant term ``c₀ +
    Σ factor·(new − old)``: the same shape, solved once (a loop's copies, issue 15)."""
    out: list[tuple[Term, Fraction]] = []
    stack: list[tuple[Term, Fraction]] = [(cond, _ONE)]
    while stack:
        u, factor = stack.pop()
        if not moving(u):
            continue
        v = small_value(u)
        if v is not None and v is not False:  # (a small value: no variable, no parameter)
            out.append((u, factor))
            continue
        tu = type(u)
        if tu is Add:
            stack += ((u.right, factor), (u.left, factor))
            continue
        if tu is Mul:
            for c, t in ((u.left, u.right), (u.right, u.left)):
                k = small_value(c)
                if k is not None and k is not False and not moving(c):
                    stack.append((t, factor * k))
                    break
            else:
                return None
            continue
        return None
    return out


def _branches(constant: Fraction, parts: tuple, renamed: tuple, known: dict) -> tuple[InverseBranch, ...]:
    """Ψ̂⁻¹ of a completed affine condition: its one branch, the solution ``constant + Σ c·atom``
    (``parts``: :func:`_atoms`) in place of the solved variable.  Built once per shape and constant
    (:func:`solved_at`, by the constant's numerator and denominator): equal conditions (a loop
    written twice, a def's condition inlined at every call) share the same branch objects, so that
    comparing their Diffeos (the Monte Carlo engine's sampler lookup) stops there (issue 15).  (No
    memo of its own: its key hashed Fractions, about 5 µs of each of a loop's copies.)  The sums
    above a nonzero constant have the same shape whatever the constant: built by ``core.like_binary``
    from the first's, kept in ``known`` (the shape's table) under :data:`_SUMS`."""
    solution = _ordered(constant, parts, known)
    return (InverseBranch(tuple(solution if x is None else x for x in renamed), ()),)


@functools.lru_cache(maxsize=1024)
def _solve(variables: tuple[str, ...], coeffs: tuple, occurring: frozenset, params: frozenset, avoid: frozenset):
    """What :func:`complete` needs of a condition's shape: the variable ``v`` solved for, its
    coefficient ``a``, Ψ̂⁻¹'s inputs, Ψ̂'s other components (``Var`` of the other variables), the
    ``c·atom`` parts of the solution but its constant (:func:`_atoms`), Ψ̂⁻¹'s components (None where
    the solution goes) and the inverse branches built so far by their constant (:func:`solved_at`);
    None when no variable can be isolated (or one is not among ``variables``)."""
    if not occurring <= set(variables):
        return None
    form = dict(coeffs)
    candidates = [x for x in variables if x in occurring and x not in avoid and form.get(("v", x))]
    if not candidates:
        return None  # every variable cancels: the sympy path gives the reason
    v = candidates[-1]  # all have a constant coefficient (rank 0): the last one in order
    inputs = fresh_inputs(len(variables), {*variables, *params, *occurring})
    others = [x for x in variables if x != v]
    renamed = {x: u for x, u in zip(others, inputs[1:])}
    a = form[("v", v)]
    one = a == 1
    over = (lambda c: -c) if one else (lambda c: -c / a)  # −c/a
    terms: list[tuple[str, str, Fraction]] = [(inputs[0], "v", _ONE if one else 1 / a)]
    for (kind, name), c in coeffs:
        if kind == "p":
            terms.append((name, "p", over(c)))
        elif name != v:
            terms.append((renamed[name], "v", over(c)))
    return (v, a, inputs, tuple(Var(x) for x in others), _atoms(tuple(terms)),
            tuple(None if x == v else Var(renamed[x]) for x in variables), {})


# sympy's ordering_of_classes, for the classes a rational coefficient can have
_CLASS_RANK = {"Half": 2, "NegativeOne": 5, "Integer": 7, "Rational": 8}


_HALF = Fraction(1, 2)


def _coefficient_class(c: Fraction) -> str:
    if c == _HALF:
        return "Half"
    if c == -1:
        return "NegativeOne"
    return "Integer" if c.denominator == 1 else "Rational"


def _sort_key(term: tuple[str, str, Fraction]):
    name, _, c = term
    if c == 1:
        return (0, name)  # a Symbol comes before any Mul
    return (1, _CLASS_RANK[_coefficient_class(c)], c.numerator, c.denominator, name)


def _ordered(constant: Fraction, parts: tuple[Term, ...], known: dict | None = None) -> Term:
    """``constant + Σ c·atom`` as ``from_sympy`` would build it from sympy's canonical sum (``parts``:
    the ``c·atom`` in order, :func:`_atoms`); with ``known``, a solved shape's table, the sums above
    a nonzero constant are built from the shapes of the first ones built so (issue 15: a loop's
    copies differ in the constant only, and every ``Const`` of a rational has one shape)."""
    if not constant:
        out = parts[0]
        for p in parts[1:]:
            out = Add(out, p)
        return out
    out = Const(constant)
    shapes = None if known is None else known.get(_SUMS)
    if shapes is not None:
        for p, shape in zip(parts, shapes):
            out = like_binary(Add, shape, out, p)
        return out
    sums = []
    for p in parts:
        out = Add(out, p)
        sums.append(shape_with_span(out))
    if known is not None:
        known[_SUMS] = sums
    return out


#: Where a solved shape's table keeps the shapes of the sums of :func:`_ordered` (``core.shape_of``
#: with the span).
_SUMS = "sums"


@functools.lru_cache(maxsize=1024)
def _atoms(terms: tuple[tuple[str, str, Fraction], ...]) -> tuple[Term, ...]:
    """The ``c·atom`` of :func:`_ordered` in sympy's order: the same for every condition of one
    shape (a loop's copies differ in their constant only), so built once with the shape
    (:func:`_solve`) and shared, also by shapes whose solutions have the same terms (issue 15)."""
    parts: list[Term] = []
    kept = [t for t in terms if t[2]]
    for name, kind, c in (sorted(kept, key=_sort_key) if len(kept) > 1 else kept):
        atom: Term = Var(name) if kind == "v" else Param(name)
        parts.append(atom if c == 1 else Mul(Const(c), atom))
    return tuple(parts)
