"""Issue 15, exact14s: the stylization kernel's first partial derivative without computing again what
⟦p⟧'s check and the other parts already computed — two conditions' crossings (resultant and
square-free part) remembered per pair in either order (``quadrature.kinks._crossing``), a polygon's
lines, vertices and cell relations remembered (``local._affine``, ``_vertex``, ``_relation``), and a
cell's relations printed by one shared printer (``integrate._relation_texts``).  Each gives the same
expressions and text as the computation it replaces; checked here against sympy's own ``resultant``,
``sqf_part`` and ``sstr`` computed afresh, the crossings of lines and the moments of the clipped
polygon by hand (exact rationals), and the stylize kernel's closed forms."""

from __future__ import annotations

import random
from fractions import Fraction

import sympy as sp
from test_stylize import clip, defaults

from langur.symbolic import integrate, local
from langur.symbolic.context import Cond, Context
from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature import kinks
from langur.symbolic.quadrature.pieceproblems import piece_problem
from langur.symbolic.text import shared_sstr, shared_sstrs
from langur.sympy_bridge import symbol
from langur.timebox import Deadline

X, Y, A, B, C = (symbol(n) for n in ("x14", "y14", "a14", "b14", "c14"))


def _clear(module, *names) -> None:
    """Empty the module's memos ``names`` (those it has)."""
    for name in names:
        getattr(module, name, {}).clear()


def _sympy_crossing(e1, e2, v, w):
    """What ``_crossings`` computed for the ordered pair before the memo: sympy's resultant in ``v``,
    then its square-free part in ``w`` when that still has ``w`` (else the resultant itself)."""
    r = sp.sympify(sp.resultant(e1, e2, v))
    try:
        out = sp.sympify(sp.sqf_part(r, w))
    except Exception:  # noqa: BLE001 - as kinks.py: the resultant is kept
        return r
    return out if w in out.free_symbols else r


def _random_condition(rng: random.Random):
    """A polynomial with rational coefficients in X, Y and the parameters, of degree 1 or 2 in Y."""
    def coeff():
        return sum((sp.Rational(rng.randint(-3, 3), rng.randint(1, 2)) * s for s in (A, B, C, X, sp.Integer(1))
                    if rng.random() < 0.5), sp.Integer(0)) or sp.Integer(1)
    e = coeff() * Y + coeff()
    if rng.random() < 0.3:
        e += sp.Rational(rng.randint(1, 3)) * Y ** 2
    return e


def test_a_pair_in_either_order_gives_sympys_own_crossing():
    rng = random.Random(14)
    checked = swapped = 0
    for _ in range(40):
        e1, e2 = _random_condition(rng), _random_condition(rng)
        if Y not in e1.free_symbols or Y not in e2.free_symbols:
            continue
        kinks._PAIRS.clear()
        kinks._SQUARE_FREE.clear()
        first = kinks._crossing(e1, e2, Y, X)
        again = kinks._crossing(e2, e1, Y, X)  # (from the memo when the answer is the same either way)
        want1, want2 = _sympy_crossing(e1, e2, Y, X), _sympy_crossing(e2, e1, Y, X)
        assert sp.srepr(first) == sp.srepr(want1)
        assert sp.srepr(again) == sp.srepr(want2)
        checked += 1
        swapped += kinks._PAIRS[(e1, e2, Y, X)][1]
    assert checked >= 30 and swapped >= 20


def test_a_float_pair_in_the_other_order_is_computed_again(monkeypatch):
    e1, e2 = sp.Float(0.3, 30) * Y - X + A, Y + sp.Float(0.7, 30) * X - B
    kinks._PAIRS.clear()
    kinks._SQUARE_FREE.clear()
    kinks._crossing(e1, e2, Y, X)
    assert kinks._PAIRS[(e1, e2, Y, X)][1] is False  # (not an exact coefficient domain)
    calls = []
    real = sp.resultant
    monkeypatch.setattr(sp, "resultant", lambda *a, **k: calls.append(a) or real(*a, **k))
    kinks._crossing(e2, e1, Y, X)
    assert len(calls) == 1


def _triangle_piece(order):
    """The stylize kernel's triangle in its pixel with a cubic weight, its conditions in ``order``
    (the box's own conditions among them, as ⟦p⟧'s piece lists them)."""
    ax, ay, bx, by, cx, cy, px, py, h, x, y = (symbol(n) for n in ("ax", "ay", "bx", "by", "cx", "cy", "px", "py",
                                                                   "h", "x", "y"))
    conds = [(cx - bx) * (y - by) - (cy - by) * (x - bx), (ax - cx) * (y - cy) - (ay - cy) * (x - cx),
             (bx - ax) * (y - ay) - (by - ay) * (x - ax), y - py, py + h - y]
    return [conds[i] for i in order], (x, y), {x: (px, px + h), y: (py, py + h)}


def test_crossings_of_the_triangle_are_its_vertices_in_either_order(monkeypatch):
    # the kinks of the outer level x from the pairs of conditions on y: the triangle's vertices'
    # x and where an edge meets y = py or y = py + h, whichever order the piece lists them in
    loaded, prm = defaults("linear")
    q = {k: Fraction(v).limit_denominator(1000) for k, v in prm.items()}
    at = {symbol(k): sp.Rational(v.numerator, v.denominator) for k, v in q.items()}
    want = {q["ax"], q["bx"], q["cx"]}
    for (x1, y1), (x2, y2) in (((q["ax"], q["ay"]), (q["bx"], q["by"])), ((q["bx"], q["by"]), (q["cx"], q["cy"])),
                               ((q["cx"], q["cy"]), (q["ax"], q["ay"]))):
        for level in (q["py"], q["py"] + q["h"]):
            want.add(x1 + (level - y1) * (x2 - x1) / (y2 - y1))
    found = []
    calls = []
    real = sp.resultant
    monkeypatch.setattr(sp, "resultant", lambda *a, **k: calls.append(a) or real(*a, **k))
    _clear(kinks, "_PAIRS", "_SQUARE_FREE", "_KINKS")
    for order in ((0, 1, 2, 3, 4), (3, 4, 0, 1, 2)):
        conds, (x, y), box = _triangle_piece(order)
        piece = Piece(tuple(Condition(c) for c in conds), x * y)
        prob = piece_problem(piece, [x, y], [box[x], box[y]], at)
        exprs = kinks._crossings(prob, 0, parametric=True)
        roots = set()
        for e in exprs:
            for r in sp.Poly(e.xreplace(at), x).real_roots():
                roots.add(Fraction(int(sp.fraction(r)[0]), int(sp.fraction(r)[1])))
        assert roots == want
        found.append(sorted(sp.srepr(e) for e in exprs))
        if order[0] == 3:
            assert not calls  # every pair known from the first order (the same answers: below)
        calls.clear()
    assert found[0] == found[1]


def _moment(poly, a: int, b: int) -> Fraction:
    """∫∫ xᵃ yᵇ over the convex polygon ``poly`` (counter-clockwise) for a + b ≤ 2, exactly: a fan of
    triangles from its first vertex, each by the edge-midpoint rule (weights 1/3, exact for degree
    ≤ 2) times its area."""
    total = Fraction(0)
    p0 = poly[0]
    for p1, p2 in zip(poly[1:], poly[2:]):
        area = ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1])) / 2
        mids = [((u[0] + v[0]) / 2, (u[1] + v[1]) / 2) for u, v in ((p0, p1), (p1, p2), (p2, p0))]
        total += area * sum(m[0] ** a * m[1] ** b for m in mids) / 3
    return total


def test_polygon_geometry_remembered_gives_the_same_closed_form_and_moments(monkeypatch):
    loaded, prm = defaults("linear")
    q = {k: Fraction(v).limit_denominator(1000) for k, v in prm.items()}
    at = {symbol(k): sp.Rational(v.numerator, v.denominator) for k, v in q.items()}
    poly = clip([(q["ax"], q["ay"]), (q["bx"], q["by"]), (q["cx"], q["cy"])], (q["px"], q["py"]),
                (q["px"] + q["h"], q["py"] + q["h"]))
    for order, weight in (((0, 1, 2, 3, 4), "xy"), ((3, 4, 0, 1, 2), "xy"), ((2, 0, 1), "yy")):
        conds, (x, y), box = _triangle_piece(order)
        w = x * y if weight == "xy" else y ** 2 + 3 * x
        fresh = []
        for cleared in (True, False):
            if cleared:
                _clear(local, "_LINES", "_VERTICES", "_RELATIONS")
            made = []
            real = sp.StrictGreaterThan
            monkeypatch.setattr(sp, "StrictGreaterThan",
                                lambda *a, made=made, real=real, **k: made.append(a) or real(*a, **k))
            ctx = Context(at, Deadline(20.0), frozenset(at))
            val = local.polygon_integral([Cond(c) for c in conds], w, x, y, box, ctx)
            monkeypatch.setattr(sp, "StrictGreaterThan", real)
            fresh.append((val, ctx.cell, made))
        (v1, cell1, made1), (v2, cell2, made2) = fresh
        assert sp.srepr(v1) == sp.srepr(v2) and [sp.srepr(r) for r in cell1] == [sp.srepr(r) for r in cell2]
        assert made1 and not made2  # the second time every relation came from the memo
        want = _moment(poly, 1, 1) if weight == "xy" else _moment(poly, 0, 2) + 3 * _moment(poly, 1, 0)
        assert v2.xreplace(at) == sp.Rational(want.numerator, want.denominator)
        assert all(rel.lhs.xreplace(at) > 0 for rel in cell2)  # the point is inside its cell


def test_relations_printed_by_one_printer_are_sympys_texts():
    rng = random.Random(7)
    vertex = (A * B - C) / (A - 2 * B + 3)
    other = (C ** 2 - A) / (B + 5)
    rels = []
    for _ in range(12):
        a, b, c = (sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) * s for s in (A, B, C))
        rels.append(sp.StrictGreaterThan(a * vertex + b * other + c, 0, evaluate=False))
    assert shared_sstrs(rels) == [sp.sstr(r) for r in rels]
    integrate._RELATION_TEXTS.clear()
    texts = integrate._relation_texts(rels[:5] + rels[:3] + rels[5:])
    assert texts == [sp.sstr(r) for r in rels[:5] + rels[:3] + rels[5:]]
    assert all(integrate._RELATION_TEXTS[r] == shared_sstr(r) for r in rels)
