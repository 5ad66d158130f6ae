"""Work kept on the nodes across loads (issue 15): typing, the range check of constants, the depth
of an inlined program, the inliner leaving call-free subterms alone.

The reference for typing is the derivation recorded by an observer (``observe.observing``), which
takes the rules' own path with nothing remembered (the ``show --typing`` path): every program here
is typed both ways, several times over, and must give the same diagnostics as a fresh copy of it
(``pickle`` drops whatever a node keeps)."""

import pickle
from fractions import Fraction

import pytest

from langur import frontend, observe
from langur import typesys as ty
from langur.core import Add, Call, Const, IfDiffeo, Mul, Param, Pow, Program, Var, tree_size
from langur.syntax.inline import inline

SCENE = ("from shader import shade\nparam c = -1\n"
         "int ([0, 1], [0, 1]) sum i in 1..6: [x + y + c + i/10 >= 0] * shade(x, y, c + i) d(x, y)\n")
SHADER = "def shade(x: var, y: var, c: param) = c * x + {k}\n"


def _codes(found):
    return [(d.code, d.message) for d in found]


def _observed(p, gamma):
    with observe.observing():
        return ty.type_program(p, gamma)


def _fresh(p):
    return pickle.loads(pickle.dumps(p))


def _program(body, variables=("x",)):
    box = tuple((Const(Fraction(0)), Const(Fraction(1))) for _ in variables)
    return Program(integrand=body, variables=tuple(variables), box=box)


@pytest.fixture(autouse=True)
def _empty_cache():
    frontend.clear_load_cache()
    yield
    frontend.clear_load_cache()


def test_a_subterm_well_typed_in_one_program_is_checked_again_in_another_context():
    shared = Add(Var("x"), Param("a"))  # well typed where a is a parameter, not where it is unknown
    good = _program(Mul(shared, shared))
    assert ty.type_program(good, frozenset({"a"})) == []
    bad = _program(Add(shared, Const(Fraction(1))))
    found = ty.type_program(bad, frozenset())
    assert _codes(found) == _codes(_observed(_fresh(bad), frozenset())) != []
    assert ty.type_program(good, frozenset({"a"})) == []  # and again, from what it kept


def test_an_ill_typed_program_keeps_nothing_and_reports_the_same_every_time():
    inner = Add(Var("x"), Param("z"))  # z undeclared: T2xx at each load, once per shared node
    p = _program(Mul(inner, Mul(inner, Var("y"))))
    expected = _codes(_observed(_fresh(p), frozenset()))
    assert expected
    for _ in range(3):
        assert _codes(ty.type_program(p, frozenset())) == expected


def test_constants_out_of_range_are_reported_on_every_load():
    big = Pow(Const(Fraction(10)), Fraction(200))
    p = _program(Add(Var("x"), Mul(big, big)))
    for _ in range(2):
        assert [d.code for d in ty.type_program(p, frozenset())] == ["T231"]
    small = _program(Add(Var("x"), big))  # 1e200 is in range; the same node, kept from above
    assert ty.type_program(small, frozenset()) == []


@pytest.mark.parametrize("name", ["fig1", "fig9", "risk", "renderer", "densities", "triangle", "window"])
def test_examples_type_the_same_with_and_without_what_is_kept(name):
    import os
    path = os.path.join(os.path.dirname(__file__), "..", "examples", f"{name}.lgr")
    if not os.path.exists(path):
        pytest.skip(f"no example {name}")
    loaded = frontend.load(path)
    if loaded.program is None:
        pytest.skip(f"{name} declares no program")
    gamma = frozenset(loaded.params)
    assert _observed(_fresh(loaded.program), gamma) == []
    for _ in range(2):
        assert ty.type_program(loaded.program, gamma) == []


def test_a_swap_keeps_the_scene_and_reuses_its_typing(tmp_path):
    (tmp_path / "scene.lgr").write_text(SCENE)
    paths = []
    for k in range(3):
        (tmp_path / f"s{k}.lgr").write_text(SHADER.format(k=k))
        paths.append(str(tmp_path / f"s{k}.lgr"))
    loads = [frontend.load(str(tmp_path / "scene.lgr"), {"shader": p}) for p in paths]
    brackets = [[u for u in _walk(L.program.body) if isinstance(u, IfDiffeo)] for L in loads]
    # the conditions (call-free) are the scene's own nodes in every swap, not copies
    assert len(brackets[0]) == 6 + 4  # the conditions and the domain's indicators
    assert all(a is b for k in (1, 2) for a, b in zip(brackets[0], brackets[k]))
    for k, L in enumerate(loads):  # each swap is what a load from an empty cache gives
        frontend.clear_load_cache()
        fresh = frontend.load(str(tmp_path / "scene.lgr"), {"shader": paths[k]})
        assert L.program == fresh.program
        assert tree_size(L.program.body) == tree_size(_fresh(fresh.program).body)
        assert ty.type_program(L.program, frozenset(L.params)) == []


def test_inlining_a_program_without_calls_returns_it_and_depth_is_checked_every_time(monkeypatch):
    from langur.diagnostics import LangurError
    from langur.modules import CoreDef, ElaboratedModule
    from langur.syntax import inline as inline_module

    monkeypatch.setattr(inline_module, "MAX_INLINED_DEPTH", 100)
    t = Var("x")
    for _ in range(60):  # depth 61: under the limit
        t = Add(t, Const(Fraction(1)))
    p = _program(t)
    assert inline(p, {}) is p and inline(p, {}) is p  # the second time, t's depth is kept on it
    body = Var("x")
    for _ in range(60):
        body = Mul(body, Var("x"))
    m = ElaboratedModule(name="m", path="m.lgr", source=b"h", params={}, diffeos={},
                         defs={"f": CoreDef("m", "f", (("x", "var"),), body)}, imports={}, program=None)
    # f(t) is t substituted 61 levels down: 61 + 61 > 100, whatever t kept from before
    deep = _program(Add(t, Call("m", "f", (t,))))
    for _ in range(2):
        with pytest.raises(LangurError) as e:
            inline(deep, {"m": m})
        assert [d.code for d in e.value.diagnostics] == ["T230"]
    shallow = _program(Add(t, Call("m", "f", (Var("x"),))))
    assert not inline_module.has_calls(inline(shallow, {"m": m}).integrand)


def _walk(t):
    from langur.core import subterms
    return list(subterms(t))


def test_loading_restores_the_cyclic_collector_as_it_found_it(tmp_path):
    import gc

    from langur.diagnostics import LangurError

    (tmp_path / "ok.lgr").write_text("param a = 1\nint ([0, 1]) [x - a/2 >= 0] d(x)\n")
    (tmp_path / "bad.lgr").write_text("int ([0, 1]) [x - nope >= 0] d(x)\n")
    was = gc.isenabled()
    try:
        for enabled in (True, False):
            (gc.enable if enabled else gc.disable)()
            frontend.load(str(tmp_path / "ok.lgr"))
            assert gc.isenabled() is enabled
            with pytest.raises(LangurError):
                frontend.load(str(tmp_path / "bad.lgr"))
            assert gc.isenabled() is enabled
    finally:
        (gc.enable if was else gc.disable)()


@pytest.mark.parametrize("name", ["fig1", "fig9", "risk", "triangle", "window", "scene"])
def test_the_depth_of_a_program_without_calls_is_the_measures_own(name):
    import os

    from langur.syntax import inline as inline_module

    path = os.path.join(os.path.dirname(__file__), "..", "examples", f"{name}.lgr")
    loaded = frontend.load(path)
    body = loaded.program.body
    # the depth kept on the nodes (computed bottom-up when they were built, and again when
    # unpickled), against a measure written out here: a leaf is 1, a completed condition a child
    from langur.core import IfDiffeo, children, depth

    def measured(t):
        below = [measured(c) for c in children(t)]
        if isinstance(t, IfDiffeo):
            below.append(measured(t.psi.forward[0]) if t.psi.name is None else 1)
        return 1 + max(below, default=0)

    own = _fresh(body)
    assert not inline_module.has_calls(own)
    assert depth(own) == depth(body) == inline_module._Depth(lambda m, n: None).of(own, {}) == measured(body) > 3
