"""Interval enclosures on arrays of boxes (langur/operational/interval.py, the samplers' boxes of
§9) and the batch's reuse of a zero set's work (issue 12, Fig. 14): an enclosure contains every
value the term takes in its box (checked against the term written out in numpy by hand), equal
subterms are enclosed once, a point stays a point, and an image asked again for another channel
or shader reuses the zero sets' work without changing a number."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from paths import EXAMPLES

from langur.core import Add, Const, IfGe0, Let, Mul, Param, Pow, Prim, Var
from langur.frontend import load
from langur.operational import batch
from langur.operational.batch import estimate_batch
from langur.operational.interval import _tape, enclose, enclose_all, tape_of
from langur.operational.sample import SiteSampler


def _xy():  # a fresh x·y + 1 each time: equal terms that are not one shared node
    return Add(Mul(Var("x"), Var("y")), Const(Fraction(1)))


def _term():
    """let z = a·a in ifge0 (a − 1/2) then (x·y + 1)² + (x·y + 1)²·(x + 2)⁻¹ + z else exp(x·y + 1)·z,
    the two copies of x·y + 1 written out separately."""
    sq = Pow(_xy(), Fraction(2))
    then = Add(Add(sq, Mul(Pow(_xy(), Fraction(2)), Pow(Add(Var("x"), Const(Fraction(2))), Fraction(-1)))), Param("z"))
    orelse = Mul(Prim("exp", _xy()), Param("z"))
    return Let("z", Mul(Param("a"), Param("a")),
               IfGe0(Add(Param("a"), Const(Fraction(-1, 2))), then, orelse))


def _by_hand(x, y, a):
    z = a * a
    s = x * y + 1
    return np.where(a - 0.5 >= 0, s ** 2 + s ** 2 / (x + 2) + z, np.exp(s) * z)


def _inside(f, lo, hi):
    # the enclosure's ends are computed in floating point, in the term's order of operations (a
    # quotient as a product with an inverse): a value at a box's corner may differ in the last bits
    slack = 1e-12 * (1 + np.abs(f))
    assert np.all(lo <= f + slack) and np.all(f - slack <= hi)


def test_enclosures_contain_the_values_on_every_box():
    rng = np.random.default_rng(3)
    lo = rng.uniform(-1.5, 1.0, size=(7, 5, 2))
    hi = lo + rng.uniform(0.0, 0.8, size=(7, 5, 2))
    a = np.array([0.1, 0.4, 0.5, 0.6, 0.9, 1.3, -0.7])[:, None]  # one per row, broadcast over the boxes
    elo, ehi = enclose(_term(), {"x": (lo[..., 0], hi[..., 0]), "y": (lo[..., 1], hi[..., 1])}, {"a": a})
    assert elo.shape == ehi.shape == (7, 5)
    for s in rng.random((200, 2)):
        x, y = lo[..., 0] + s[0] * (hi[..., 0] - lo[..., 0]), lo[..., 1] + s[1] * (hi[..., 1] - lo[..., 1])
        _inside(_by_hand(x, y, a), elo, ehi)
    # at the corners too (where a product's bounds are reached)
    for cx in (0, 1):
        for cy in (0, 1):
            _inside(_by_hand((lo, hi)[cx][..., 0], (lo, hi)[cy][..., 1], a), elo, ehi)


def test_a_box_where_the_term_is_undefined_is_unbounded():
    # (x + 2)^-1 over a box around x = -2: no finite interval contains it
    t = Pow(Add(Var("x"), Const(Fraction(2))), Fraction(-1))
    lo, hi = enclose(t, {"x": (np.array([-2.5, 0.0]), np.array([-1.5, 1.0]))}, {})
    assert (lo[0], hi[0]) == (-np.inf, np.inf)
    assert (lo[1], hi[1]) == (1 / 3, 1 / 2)


def test_equal_subterms_are_one_step_and_a_point_stays_a_point():
    t = _term()
    body = t.body.then
    # (x·y + 1)² twice, written out separately: x, y, x·y, 1, x·y + 1, its square, 2, x + 2, its
    # inverse, the product, the sum, z, the sum: 13 steps (the copies add none)
    assert len(_tape(body).steps) == 13
    assert _tape(t) is _tape(t)  # built once
    p = Add(Mul(Param("a"), Param("a")), Pow(Param("a"), Fraction(3)))
    a = np.array([[0.5], [-2.0]])
    lo, hi = enclose(p, {}, {"a": a})
    assert lo is hi and np.array_equal(lo, a * a + np.power(a, 3.0))


def _raytrace(shader: str):
    module = {"depth": "shader.lgr", "lambert": "lambert.lgr"}[shader]
    return load(str(EXAMPLES / "raytrace" / "scene.lgr"), modules={"shader": str(EXAMPLES / "raytrace" / module)})


def test_another_channel_reuses_the_zero_sets_without_changing_a_number(monkeypatch):
    loaded = _raytrace("depth")
    xs = -0.3 + np.arange(6) * 0.1
    px, py = (a.ravel() for a in np.meshgrid(xs, xs))
    grid = {"px": px, "py": py, "h": 0.1, "t": 0.0}
    fields = ("value", "stderr", "regular", "regular_stderr", "boundary", "boundary_stderr")

    def image(ch):
        b = estimate_batch(loaded, {**grid, "ch": float(ch)}, direction={"t": 1.0}, samples=32, seed=5)
        return [getattr(b, f) for f in fields]

    monkeypatch.setattr(batch, "GEOMETRY_BYTES", -1)  # nothing kept: every zero set computed afresh
    batch._GEOMETRY.clear()
    fresh = [image(ch) for ch in range(3)]
    assert not batch._GEOMETRY
    monkeypatch.setattr(batch, "GEOMETRY_BYTES", 96 * 2 ** 20)
    image(0)
    kept = len(batch._GEOMETRY)
    assert kept >= 4  # the triangle's three edges and the depth threshold move with t
    calls = []
    for name in ("shrink_many", "points_many"):
        monkeypatch.setattr(SiteSampler, name, _counting(calls, name))
    for ch in range(3):
        got = image(ch)
        for f, a, b in zip(fields, got, fresh[ch]):
            assert np.array_equal(a, b, equal_nan=True), (ch, f)
    assert calls == []  # the channels read the same zero sets: nothing recomputed
    assert len(batch._GEOMETRY) == kept
    # a parameter the zero sets read (t) is a new key: computed afresh
    estimate_batch(loaded, {**grid, "ch": 0.0, "t": 0.05}, direction={"t": 1.0}, samples=32, seed=5)
    assert "shrink_many" in calls



def _counting(calls, name):
    orig = getattr(SiteSampler, name)

    def wrapped(self, *args, **kwargs):
        calls.append(name)
        return orig(self, *args, **kwargs)

    return wrapped


def test_one_tape_for_several_terms_gives_each_terms_enclosure():
    terms = [_term(), Pow(_xy(), Fraction(2)), Mul(Prim("exp", _xy()), Var("x"))]
    tape = tape_of(terms)
    # the let's a, a·a and itself (its body is a tape of its own: another scope); x, y, x·y, 1,
    # x·y + 1, its square; exp of it and the product with x — x·y + 1 once for the last two terms
    assert [len(_tape(t).steps) for t in terms] == [3, 6, 7]
    assert len(tape.steps) == 3 + 6 + 2
    rng = np.random.default_rng(4)
    lo = rng.uniform(-1.0, 1.0, size=(3, 4, 2))
    hi = lo + rng.uniform(0.0, 0.5, size=(3, 4, 2))
    box = {"x": (lo[..., 0], hi[..., 0]), "y": (lo[..., 1], hi[..., 1])}
    params = {"a": np.array([[0.2], [0.7], [1.1]])}
    for (elo, ehi), t in zip(enclose_all(tape, box, params), terms):
        alo, ahi = enclose(t, box, params)
        assert np.array_equal(elo, alo) and np.array_equal(ehi, ahi)
