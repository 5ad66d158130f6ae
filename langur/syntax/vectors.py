"""Small fixed-size vectors, helpers of the desugarer (``langur.syntax.desugar``, the one desugaring
place): geometry written like the math (issue 12), desugared to reals.

A vector is a tuple of core terms, :class:`Vec`; it exists only while the desugarer works, and
never reaches the core language (§4: every term is real).  The sugar:

* ``(t1, …, tn)``, n ≥ 2, is the vector of the ``ti``;
* ``u + v``, ``u - v`` component-wise (same sizes, T228); ``s * u``, ``u * s``, ``u / s`` and ``-u``
  scale each component by the real ``s``, written in the order given (``s * u`` is
  ``(s * u1, …)``, ``u / s`` is ``(u1 / s, …)``);
* ``dot(u, v)`` is ``u1 * v1 + … + un * vn`` (left-nested, as written out);
* ``cross(u, v)`` of 3-vectors (T229) is ``(u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z,
  u.x * v.y - u.y * v.x)``;
* ``u.x``, ``u.y``, ``u.z``, ``u.w`` are the first to fourth components (T232 past the size);
* written out with the identities folded (``x·1`` is ``x``, ``y·0`` is ``0``, a sum drops its 0s:
  :mod:`langur.syntax.folding`), so ``dot((x, y, 0), (a, 1, 0))`` is ``x·a + y``;
* ``let o = (…) in t``: ``o`` names the vector, whose components are substituted where ``o`` is
  used (a let-bound vector is a name for its components, like an inlined def's body, so unlike a
  real ``let`` its components may mention variables; T233 when an inner ``let`` rebinds a name
  its components mention).

A vector anywhere a real is expected (an integrand, a condition, a loop body, an argument or the
body of a def, the base of ``^``, …) is T226; a real where a vector is expected is T227.  Each
function here returns the result or raises :class:`VectorError` with the diagnostic.
"""

from __future__ import annotations

from .. import typesys as ty
from ..core import Term, free_params
from ..diagnostics import Diagnostic, Span
from ..records import frozen
from .folding import divided, minus, negated, plus, times
from .loops import balanced

#: Component names, in order: ``u.x`` is the first component, ``u.w`` the fourth.
COMPONENTS = ("x", "y", "z", "w")


@frozen
class Vec:
    """A vector value during desugaring: its components, core terms."""

    parts: tuple[Term, ...]

    def __init__(self, parts):
        self.__dict__["parts"] = parts


#: The value of a vector expression whose error has been reported: every use of it is silent.
POISON = Vec(())


@frozen
class VecName:
    """A let-bound vector: its value, the parameters its components mention, and the name of an
    inner ``let`` that rebinds one of them (then the vector may no longer be used: T233)."""

    vec: Vec
    params: frozenset[str]
    shadowed_by: str | None = None

    def __init__(self, vec, params, shadowed_by=None):
        d = self.__dict__
        d["vec"], d["params"], d["shadowed_by"] = vec, params, shadowed_by

    @staticmethod
    def of(vec: Vec) -> VecName:
        return VecName(vec, frozenset().union(*(free_params(p) for p in vec.parts)))


class VectorError(Exception):
    def __init__(self, diagnostic: Diagnostic):
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


def _sizes(u: Vec, v: Vec, span: Span | None, what: str) -> None:
    if len(u.parts) != len(v.parts):
        raise VectorError(ty.reject_sizes(span, f"{what} of a vector of {len(u.parts)} and a vector of "
                                          f"{len(v.parts)} components"))


def binop(op: str, left: Term | Vec, right: Term | Vec, span: Span | None, spans) -> Vec:
    """``left op right`` with at least one vector operand (``op`` one of ``+ - * /``);
    ``spans`` are the operands' own spans (to point at the misplaced one)."""
    if op in "+-":
        if not isinstance(left, Vec) or not isinstance(right, Vec):
            where = spans[0] if not isinstance(left, Vec) else spans[1]
            raise VectorError(ty.reject_real(where, f"`{op}` adds or subtracts vectors of one size, component-wise; "
                                             "this operand is a real"))
        _sizes(left, right, span, "`+`" if op == "+" else "`-`")
        make = (lambda a, b: plus(a, b, span)) if op == "+" else minus
        return Vec(tuple(make(a, b) for a, b in zip(left.parts, right.parts)))
    if op == "*":
        if isinstance(left, Vec) and isinstance(right, Vec):
            raise VectorError(ty.reject_vector(spans[1], len(right.parts), ": `*` scales a vector by a real; "
                                               "vectors multiply by dot(u, v) or cross(u, v)"))
        if isinstance(left, Vec):
            return Vec(tuple(times(a, right, span) for a in left.parts))
        return Vec(tuple(times(left, b, span) for b in right.parts))
    if op == "/":
        if isinstance(right, Vec):
            raise VectorError(ty.reject_vector(spans[1], len(right.parts), ": a vector is divided by a real, "
                                               "never by a vector"))
        return Vec(tuple(divided(a, right, span) for a in left.parts))
    raise ValueError(f"not a vector operator: {op}")


def negate(u: Vec) -> Vec:
    """``-u``: each component times −1 (as unary minus on a real)."""
    return Vec(tuple(negated(a) for a in u.parts))


def _vectors(args: list[Term | Vec], spans, fname: str) -> list[Vec]:
    for a, sp in zip(args, spans):
        if not isinstance(a, Vec):
            raise VectorError(ty.reject_real(sp, f"the arguments of `{fname}` are vectors; this one is a real"))
    return args  # type: ignore[return-value]


def dot(args: list[Term | Vec], span: Span | None, spans) -> Term:
    """``dot(u, v)``: the sum of the component-wise products."""
    u, v = _vectors(args, spans, "dot")
    _sizes(u, v, span, "dot")
    return balanced([times(a, b, span) for a, b in zip(u.parts, v.parts)], "sum", span)


def cross(args: list[Term | Vec], span: Span | None, spans) -> Vec:
    """``cross(u, v)`` of two 3-vectors."""
    u, v = _vectors(args, spans, "cross")
    if len(u.parts) != 3 or len(v.parts) != 3:
        raise VectorError(ty.reject_cross(span, (len(u.parts), len(v.parts))))
    (ux, uy, uz), (vx, vy, vz) = u.parts, v.parts
    return Vec((minus(times(uy, vz), times(uz, vy)), minus(times(uz, vx), times(ux, vz)),
                minus(times(ux, vy), times(uy, vx))))


def component(u: Term | Vec, name: str, span: Span | None, base_span: Span | None, name_span: Span | None) -> Term:
    """``u.name``: the component ``name`` (``x y z w``) of the vector ``u``."""
    if not isinstance(u, Vec):
        raise VectorError(ty.reject_real(base_span, f"`.{name}` takes a component of a vector; this is a real"))
    names = COMPONENTS[: len(u.parts)]
    if name not in names:
        raise VectorError(ty.reject_component(name_span or span, name, len(u.parts), names or COMPONENTS))
    return u.parts[COMPONENTS.index(name)]
