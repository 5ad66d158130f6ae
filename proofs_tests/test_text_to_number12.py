"""Fixed per-load work cut (issue 15, branch front12), against independent references.

* ``syntax/parser.py``: a parse pauses the cyclic collector (``gcpause.paused``) only when it is
  on; inside a load, which has paused it already, no second context manager is entered.  The
  collector's state after a parse is the one before, the collector is off during the parse either
  way, and the trees (spans included) and syntax errors are the same.
* ``syntax/inline.py``: a program without calls is returned as it is before the inliner and the
  numeric box it would use are built (the numeric box is not computed again for nothing); a program
  with calls still gets them, and the T230 depth check still runs first.
"""

from __future__ import annotations

import contextlib
import gc

import pytest
from paths import REPO

from langur import frontend, gcpause
from langur.diagnostics import LangurError
from langur.syntax import inline, parser

FILES = sorted(p for p in REPO.rglob("*.lgr") if ".venv" not in p.parts)


@contextlib.contextmanager
def _collector(on: bool):
    before = gc.isenabled()
    (gc.enable if on else gc.disable)()
    try:
        yield
    finally:
        (gc.enable if before else gc.disable)()


@pytest.fixture
def pauses(monkeypatch):
    """How many times ``gcpause.paused`` (or ``kept``) is entered (the real one, counted, whoever calls it: the
    module attribute is replaced), and whether the collector was on inside each driver call."""
    seen = {"paused": 0, "inside": []}
    real, real_kept = gcpause.paused, gcpause.kept

    @contextlib.contextmanager
    def counted():
        seen["paused"] += 1
        with real():
            yield

    @contextlib.contextmanager
    def counted_kept():  # (a load's pause, whose objects are kept: test_load25)
        seen["paused"] += 1
        with real_kept():
            yield

    monkeypatch.setattr(parser.gcpause, "paused", counted)
    monkeypatch.setattr(parser.gcpause, "kept", counted_kept)
    with parser._LOCK:
        parser._parser()  # (built on first use: the driver exists from here on)
    driver = parser._DRIVER
    if driver is not None:
        def watched(text, start):
            seen["inside"].append(gc.isenabled())
            return driver(text, start)
        monkeypatch.setattr(parser, "_DRIVER", watched)
    return seen


def _tree(m) -> str:
    return repr(m)  # (the surface dataclasses' repr: every field, spans included)


TEXTS = [
    "param a = 1\nint ([-1, 1]) (sum i in 10..12: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x)) d(x)\n",
    "def f(x: var, a: param) = a * x ^ 2\nint ([0, 1]) f(x, 2) d(x)\n",
    "int ([0, 1], [0, 2]) [x + y <= 1] * (x - y) d(x, y)\n",
]


@pytest.mark.parametrize("text", TEXTS)
def test_a_parse_under_a_paused_collector_enters_no_second_pause(pauses, text):
    with _collector(on=True):
        on = parser.parse_module(text)
        assert gc.isenabled()  # restored
    assert pauses["paused"] == 1
    with _collector(on=False):
        off = parser.parse_module(text)
        assert not gc.isenabled()  # left off
    assert pauses["paused"] == 1  # (not entered again: the collector was off already)
    if parser._DRIVER is not None:
        assert pauses["inside"] == [False, False]  # off during both parses
    assert _tree(on) == _tree(off)


def test_a_load_pauses_the_collector_once(pauses):
    with _collector(on=True):
        frontend.clear_load_cache()
        frontend.load_text(TEXTS[0])
        assert gc.isenabled()
    assert pauses["paused"] == 1  # the load's own pause only (``gcpause.paused`` is counted for every
    # caller): the parse inside it enters none
    if parser._DRIVER is not None:
        assert pauses["inside"] == [False]


@pytest.mark.parametrize("bad", ["int ([0, 1]) x + d(x)\n", "param a = \n", "int ([0, 1]) x $ 2 d(x)\n",
                                 "int ([0, 1]) (x d(x)\n"])
def test_syntax_errors_are_the_same_with_the_collector_on_or_off(bad):
    messages = []
    for on in (True, False):
        with _collector(on=on):
            with pytest.raises(LangurError) as e:
                parser.parse_module(bad, "bad.lgr")
            assert gc.isenabled() is on
        messages.append([d.format() for d in e.value.diagnostics])
    assert messages[0] == messages[1] and messages[0][0].startswith("bad.lgr:")


@pytest.mark.parametrize("path", FILES[:40], ids=lambda p: p.name)
def test_every_file_parses_to_the_same_tree_with_the_collector_on_or_off(path):
    data = path.read_bytes()
    out = []
    for on in (True, False):
        with _collector(on=on):
            try:
                out.append(_tree(parser.parse_bytes(data, str(path))))
            except LangurError as e:
                out.append([d.format() for d in e.diagnostics])
    assert out[0] == out[1]


def test_a_call_free_program_is_not_given_a_numeric_box_by_the_inliner(monkeypatch):
    calls = []
    real = inline.numeric_box

    def counted(variables, box):
        calls.append(variables)
        return real(variables, box)

    monkeypatch.setattr(inline, "numeric_box", counted)
    frontend.clear_load_cache()
    loaded = frontend.load_text(TEXTS[2])
    assert calls == []
    # nothing to inline: the program is the elaborated module's own object
    assert loaded.program is loaded.main.program
    frontend.clear_load_cache()
    with_calls = frontend.load_text(TEXTS[1])
    assert calls == [("x",)]  # a program with calls: the inliner's box, as before
    assert with_calls.program is not with_calls.main.program


def test_the_depth_check_still_runs_before_the_early_return(monkeypatch):
    # (T230 is decided before the call test: a call-free program deeper than the bound is refused)
    monkeypatch.setattr(inline, "MAX_INLINED_DEPTH", 3)
    frontend.clear_load_cache()
    with pytest.raises(LangurError) as e:
        frontend.load_text("int ([0, 1]) x * (x + (x * (x + 1))) d(x)\n")
    assert [d.code for d in e.value.diagnostics] == ["T230"]


# ---- records built once per load, their __init__ written out (as Span's and BinOp's) ----------

def _written_out():
    from langur import core
    from langur.syntax import surface
    return [surface.ParamDecl, surface.ParamItem, surface.Interval, surface.ProgramS, surface.ModuleS,
            core.Interval, core.Program]


@pytest.mark.parametrize("cls", _written_out(), ids=lambda c: f"{c.__module__}.{c.__name__}")
def test_written_out_inits_behave_as_the_generic_one(cls):
    import dataclasses

    fields = [f for f in dataclasses.fields(cls) if f.init]
    assert cls.__init__.__qualname__ == f"{cls.__qualname__}.__init__"  # its own
    values = {f.name: object() for f in fields}
    by_name = cls(**values)
    by_position = cls(*values.values())
    for obj in (by_name, by_position):
        assert {k: obj.__dict__[k] for k in values} == values
        assert set(obj.__dict__) == set(values)  # nothing else written
    assert by_name == by_position and hash(by_name) == hash(by_position)
    # the defaults of the fields that have one (dataclasses' own field list as the reference)
    required = [f.name for f in fields if f.default is dataclasses.MISSING]
    partial = cls(*(values[n] for n in required))
    for f in fields:
        if f.default is not dataclasses.MISSING:
            assert partial.__dict__[f.name] == f.default
    with pytest.raises(TypeError):
        cls(*values.values(), object())  # one argument too many
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(by_name, fields[0].name, 1)
    other = object()
    replaced = dataclasses.replace(by_name, **{fields[0].name: other})
    assert replaced.__dict__[fields[0].name] is other
