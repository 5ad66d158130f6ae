"""Issue 15 (exact15q): the quadrature cross-check's critical points of a condition of degree at
most 1 in its variable are found from the tree's degree bound, without sympy's ``Poly``.

An affine condition ``k·v + c`` (``k``, ``c`` free of ``v``) has ∂/∂v = k free of ``v``: no point
where a region in ``v`` appears or vanishes.  The reference is computed independently: sympy's
``solve`` of the derivative for ``v`` (no solution for a derivative free of ``v``), and the
polynomial answer (the vertex −b/2a) for quadratics.
"""

from __future__ import annotations

import random

import sympy as sp

import langur.symbolic.quadrature.kinks as kinks

ax, ay, bx, by, cx, cy, px, py, h, x, y = sp.symbols("ax ay bx by cx cy px py h x y")

#: The stylization kernel's half-planes and box sides (examples/stylize/quadratic.lgr), in y.
STYLIZE = [(-bx + cx) * (-by + y) - (-bx + x) * (-by + cy), (ax - cx) * (-cy + y) - (ay - cy) * (-cx + x),
           (-ax + bx) * (-ay + y) - (-ax + x) * (-ay + by), -py + y, h + py - y]


def _random_affine(rng: random.Random) -> sp.Expr:
    """A random expression of degree ≤ 1 in y as a tree (products of sums, powers of y-free parts,
    a y-free function), not expanded."""
    others = [ax, bx, x, sp.sqrt(ax), sp.sin(bx), sp.Float("0.1")]

    def free():
        return sum(sp.Rational(rng.randint(-4, 4), rng.randint(1, 3)) * rng.choice(others) ** rng.randint(0, 2)
                   for _ in range(rng.randint(1, 3)))
    term = free() * (y - free()) if rng.random() < 0.7 else free() * y
    return term + free() * free()


def _reference(e: sp.Expr, v: sp.Symbol) -> list:
    """The critical points from scratch: sympy's solve of ∂e/∂v = 0 for v, real and free of v."""
    sols = sp.solve(sp.numer(sp.together(sp.diff(e, v))), v)
    return [r for r in sols if v not in r.free_symbols and not r.has(sp.I)]


def _forbid_poly(monkeypatch):
    def no_poly(*args, **kwargs):
        raise AssertionError("sympy Poly built for a condition of degree <= 1")
    monkeypatch.setattr(kinks.sp, "Poly", no_poly)


def test_stylize_half_planes_have_no_critical_point_without_poly(monkeypatch):
    for e in STYLIZE:
        assert _reference(e, y) == []
    _forbid_poly(monkeypatch)
    for e in STYLIZE:
        assert kinks._solve_critical(e, y) == ([], True)
        assert kinks._solve_critical(e, x) == ([], True)  # also affine in x


def test_random_affine_trees_match_sympy(monkeypatch):
    rng = random.Random(15)
    cases = [_random_affine(rng) for _ in range(40)] + [sp.Integer(3), ax * bx, sp.sin(x) + ax]
    refs = [_reference(e, y) for e in cases]
    assert all(r == [] for r in refs)
    _forbid_poly(monkeypatch)
    for e in cases:
        assert kinks._solve_critical(e, y) == ([], True)


def test_higher_degree_still_asks_sympy():
    # a quadratic's vertex (−b/2a), and a cubic's critical points by solve, as before
    e2 = (y - ax) ** 2 - bx
    assert kinks._solve_critical(e2, y) == ([ax], True)
    e3 = x ** 3 - x * y + y ** 3 - ax
    pts, final = kinks._solve_critical(e3, y)
    assert final and sorted(pts, key=str) == sorted(_reference(e3, y), key=str)
    assert {sp.simplify(p ** 2 - x / 3) for p in pts} == {0}
    # y inside a function: not a polynomial, solve decides (tanh has no critical point)
    assert kinks._solve_critical(sp.tanh(y - ax), y) == ([], True)


def test_degree_bound_is_not_fooled_by_powers(monkeypatch):
    # a tree of degree 2 in y goes to Poly as before: (y + 1)² − ax·y² has its vertex at 1/(ax − 1)
    calls = []
    real = sp.Poly

    def counting(*args, **kwargs):
        calls.append(args[0])
        return real(*args, **kwargs)
    monkeypatch.setattr(kinks.sp, "Poly", counting)
    (pt,), final = kinks._solve_critical((y + 1) ** 2 - y ** 2 * ax, y)
    assert final and sp.simplify(pt - 1 / (ax - 1)) == 0
    assert calls
    # (y + 1)² − y² is affine once expanded: Poly (degree 1) and the bound agree, no critical point
    assert kinks._solve_critical((y + 1) ** 2 - y ** 2, y) == ([], True)


def _poly_check(e: sp.Expr, v: sp.Symbol) -> bool:
    """The eligibility for a crossing, from scratch: a polynomial of degree 1 to 4 in v with
    coefficients free of v."""
    try:
        poly = sp.Poly(e, v)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return False
    return 1 <= poly.degree() <= 4 and not any(v in k.free_symbols for k in poly.all_coeffs())


def test_crossing_eligibility_remembered_and_equal_to_poly(monkeypatch):
    rng = random.Random(7)
    cases = STYLIZE + [_random_affine(rng) for _ in range(10)] + [
        (y - ax) ** 2 - bx, y ** 5 - x, y ** 4 - x * y, sp.sin(y) + x, sp.sqrt(y) - x, 1 / y - x, x + ax, sp.Integer(2),
        (y + 1) ** 2 - y ** 2 - 1 - 2 * y]  # the last is 0 once expanded: not a crossing
    refs = [(_poly_check(e, y), _poly_check(e, x)) for e in cases]
    kinks._CROSSES.clear()
    assert [(kinks._crosses(e, y), kinks._crosses(e, x)) for e in cases] == refs
    _forbid_poly(monkeypatch)  # asked again: remembered, no Poly
    assert [(kinks._crosses(e, y), kinks._crosses(e, x)) for e in cases] == refs
    assert refs[-1] == (False, False) and refs[len(STYLIZE) + 10 + 1][0] is False  # 0; degree 5: too high
