"""The records of exact region integration (paper §6.3, Def. 6.1–6.2; LANGUAGE.md §3–§4): a
condition ``[expr ≥ 0]`` (:class:`Cond`, Def. 6.1's simple discontinuity, with its diffeomorphism
``Psi`` when known), a weight made only when needed (:class:`Deferred`), and the evaluation point
with the decisions taken there (:class:`Context`: every comparison of parameter-only quantities is
decided at the point and recorded in its ``cell``, where the closed form is valid), and
:class:`Unsupported`, which sends a piece to quadrature.

Used by :mod:`langur.symbolic.solving` (one condition solved for one variable) and
:mod:`langur.symbolic.regions` (the iterated integration).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from langur.memo import remember
from langur.symbolic import local, rational, walks
from langur.symbolic.pieces import Psi
from langur.timebox import Deadline


class Unsupported(Exception):
    """No closed form by this method; the caller falls back to quadrature."""


@dataclass(frozen=True)
class Cond:
    """``expr ≥ 0`` (``expr > 0`` when ``strict``; strictness only matters for parameter-only
    comparisons, where it breaks ties between case splits)."""

    expr: sp.Expr
    strict: bool = False
    psi: Psi | None = None


#: The point's values as 40-digit Floats, by point (:meth:`Context.value` substitutes them in
#: every expression it evaluates: building them again each time was a third of its time).
_FLOATS40: dict = {}


def _floats40(at: dict) -> dict:
    key = tuple(at.items())
    out = _FLOATS40.get(key)
    if out is None:
        out = {k: sp.Float(float(v), 40) for k, v in at.items()}
        remember(_FLOATS40, key, out, 64)
    return out


#: :meth:`Context.value`'s results by (expression, point): the same roots, bounds and relations are
#: evaluated again for ⟦p⟧, ⦇p⦈'s pieces and the check (a third of raytrace ∂/∂t's evaluations are
#: repeats).  sympy's equality tells Floats of different precisions apart, so a key is exact.
_VALUES: dict = {}
VALUES = 4096


#: :func:`_canonical`'s answers by (kind, expression): the same coefficients' signs are recorded
#: for each case of a decomposition and again for other partial derivatives.
_CANONICAL: dict = {}


def _canonical(rel_kind: str, expr) -> tuple:
    """``(p, p ⋈ 0)``: ``expr`` expanded, its positive content divided out (remembered)."""
    key = (rel_kind, sp.sympify(expr))
    out = _CANONICAL.get(key)
    if out is None:
        _, p = sp.expand(expr).as_content_primitive()
        out = (p, {">": sp.StrictGreaterThan, ">=": sp.GreaterThan, "=": sp.Eq}[rel_kind](p, 0))
        remember(_CANONICAL, key, out)
    return out


class Deferred:
    """A weight made only when the integration needs it (``make()``, called once): a delta piece's
    weight holds sympy's determinant and simplification of det DΨ̂⁻¹ (a fifth of a second for the
    ray tracer's), which a region found empty at the evaluation point never uses.  The maker of one
    promises that the weight is not 0 (so ``weight == 0`` is rightly false for it); it stays
    unmade only in one variable where the conditions alone are large (:func:`_outermost`): the
    weight's size, which else chooses the method, does not matter there, and :func:`_generic_1d`
    asks for it only to integrate a non-empty interval.  Everywhere else it is made at once."""

    __slots__ = ("_make", "_made")

    def __init__(self, make):
        self._make, self._made = make, None

    def made(self) -> sp.Expr:
        if self._made is None:
            self._made = sp.sympify(self._make())
        return self._made


def _made(weight):
    """``weight``, a :class:`Deferred` one made."""
    return weight.made() if isinstance(weight, Deferred) else weight


@dataclass
class Context:
    """Evaluation point, time budget and the decisions taken at the evaluation point."""

    at: dict
    deadline: Deadline
    params: frozenset = frozenset()
    cell: list = field(default_factory=list)
    generic: bool = False  # the generic 1-D path was used (cell also fixes the set of real roots)
    notes: list = field(default_factory=list)
    inconsistent: list = field(default_factory=list)  # closed forms that failed the cross-check
    estimated: bool = False  # a quadrature sampled a range wider than 1e4 (quadrature.ESTIMATE)

    def value(self, expr) -> complex:
        """``expr`` at the point with 30 digits (40-digit floats substituted), as a complex;
        remembered per (expression, point) (:data:`_VALUES`)."""
        return self.value_with(expr, {})

    def value_with(self, expr, numbers: dict) -> complex:
        """:meth:`value` of ``expr.xreplace(numbers)`` (``numbers``: symbols → sympy Floats), in
        one substitution: the tree is rebuilt once, from numbers only, instead of once with the
        floats ``numbers`` among the parameters' symbols (sympy's products and sums of symbolic
        terms, their assumptions) and again with the point's floats; remembered likewise."""
        expr = sp.sympify(expr)
        key = (expr, tuple(numbers.items()), tuple(self.at.items()))
        z = _VALUES.get(key)
        if z is None:
            rule = {**_floats40(self.at), **numbers}
            # each distinct subtree rebuilt once (sympy's xreplace rebuilds a subtree wherever it occurs:
            # a condition's root formulas repeat their parts); the same tree, except that equal Floats of
            # other precisions in ``expr`` would be taken for one another: then sympy's own
            e = expr.xreplace(rule) if walks.has_any(expr, (sp.Float,)) else walks.shared_xreplace(expr, rule, False)
            try:
                z = complex(e.evalf(30))
            except TypeError:
                raise ValueError(f"no value for {sorted(map(str, e.free_symbols))} in {expr}") from None
            remember(_VALUES, key, z, VALUES)
        return z

    def exact_value(self, expr) -> complex:
        """:meth:`value` with the point's rational values substituted exactly (then evaluated to 30
        digits): a closed form's value at the point.  With 40-digit floats substituted, a closed
        form that is exactly 0 there came out as cancellation noise (Fig. 14's pixel at the
        origin: −2⁻¹²⁶ ≈ −1.17549435082e-38)."""
        exact = {k: v for k, v in self.at.items() if isinstance(v, sp.Rational)}
        expr = sp.sympify(expr)
        if exact and walks.size(expr, local.LARGE_OPS) >= local.LARGE_OPS:
            q = rational.float_value(expr, exact)  # a large rational form: its exact value's double
            if q is not None:
                return complex(q)
        return self.value(expr.xreplace(exact) if exact else expr)

    def record(self, rel_kind: str, expr) -> None:
        """Add ``expr > 0`` / ``expr >= 0`` / ``expr = 0`` to the cell, canonically (positive
        content divided out, so ``4*a + 4 > 0`` and ``-a - 1 < 0`` are one entry)."""
        p, rel = _canonical(rel_kind, expr)
        if rel_kind == "=" and sp.Eq(-p, 0) in self.cell:
            return
        if rel not in (sp.true, sp.false) and rel not in self.cell:
            self.cell.append(rel)

    def record_relation(self, rel) -> None:
        if isinstance(rel, sp.Rel) and rel.rel_op in (">", "<", ">=", "<="):
            d = rel.lhs - rel.rhs if rel.rel_op[0] == ">" else rel.rhs - rel.lhs
            self.record(">" if len(rel.rel_op) == 1 else ">=", d)
        elif isinstance(rel, sp.Not) and isinstance(rel.args[0], sp.Rel):
            self.record_relation(rel.args[0].negated)
        elif rel not in self.cell:
            self.cell.append(rel)

    def decide(self, expr, strict: bool = False) -> bool:
        """``expr ≥ 0`` (``> 0``) for a parameter-only ``expr``, at the evaluation point; recorded."""
        expr = sp.sympify(expr)
        if expr.is_number:
            return self._decide_number(expr, strict)
        v = self.value(expr)
        if abs(v.imag) > 1e-20 * max(1.0, abs(v.real)):
            raise Unsupported(f"complex value of {expr} at the evaluation point")
        x = v.real
        if abs(x) < 1e-25:
            self.record("=", expr)
            return not strict
        self.record(">", expr if x > 0 else -expr)
        return x > 0

    def _decide_number(self, expr, strict: bool) -> bool:
        if expr.is_zero:
            return not strict
        if expr.is_extended_real is False:
            raise Unsupported(f"complex number {expr}")
        pos = expr.is_positive
        if pos is None:
            v = complex(expr.evalf(40))
            if abs(v.imag) > 1e-30:
                raise Unsupported(f"complex number {expr}")
            return v.real > 0 or (v.real == 0 and not strict)
        return bool(pos)

    def sign(self, expr) -> int:
        """Sign of a parameter-only expression at the evaluation point (recorded)."""
        if self.decide(expr, strict=True):
            return 1
        if self.decide(-expr, strict=True):
            return -1
        raise Unsupported(f"{expr} vanishes at the evaluation point")


#: A 30-digit value whose imaginary part is at most this, relative to max(1, |real part|), is real:
#: evaluation noise (√ of a radicand that is identically 0 gave ±1e-59·i), not a value off the reals.
IMAGINARY_NOISE = 1e-12


def nearly_real(z: complex) -> bool:
    """Whether the 30-digit value ``z`` is real up to :data:`IMAGINARY_NOISE`."""
    return abs(z.imag) <= IMAGINARY_NOISE * max(1.0, abs(z.real))

