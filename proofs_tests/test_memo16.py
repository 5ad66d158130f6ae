"""The bounded in-process memo, declared once (``langur.memo``), and the point-free memos standing
aside while the rules are observed (``langur.observe.watched``; issue 15, branch memo16).

The memo's bound and its two ways of making room are checked on plain dicts against what they
promise (first in, first out; all at once), and at sites that use it with their own sizes.  The
observer: a campaign's rule coverage (``langur.fuzz.coverage``) counts each application of Fig. 7's
and Fig. 8's rules by wrapping the semantic functions; the memos of a point-free program's pieces
(``denote._decomposed``) and of its ⦇p⦈ normal form (``ddenote.normal_form``) must not skip any
of them, so the counts with the memos filled beforehand are those with the memos empty.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from langur import ddenote as ddenote_module
from langur import denote as denote_module
from langur import observe
from langur import typesys as ty
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load
from langur.fuzz import coverage
from langur.memo import make_room, remember
from langur.symbolic import decompose as decompose_module
from langur.symbolic.quadrature import compiling, kinks
from langur.sympy_bridge import symbol

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
DISK = EXAMPLES / "adapters" / "programs" / "disk.lgr"  # ∫∫ [r² − x² − y² ≥ 0]: πr², d/dr 2πr


# --- the memo -------------------------------------------------------------------------------------

def test_remember_keeps_at_most_size_entries_dropping_the_oldest_first():
    memo: dict = {}
    for i in range(5):
        assert remember(memo, i, i * i, 3) == i * i
        assert len(memo) == min(i + 1, 3)
    assert list(memo.items()) == [(2, 4), (3, 9), (4, 16)]  # 0 and 1, the oldest, dropped in turn
    remember(memo, 5, 25, 3)
    assert list(memo) == [3, 4, 5]


def test_remember_at_once_forgets_every_entry_when_full():
    memo: dict = {}
    for i in range(3):
        remember(memo, i, -i, 3, at_once=True)
    assert list(memo) == [0, 1, 2]
    remember(memo, 3, -3, 3, at_once=True)
    assert memo == {3: -3}  # a fresh start, then the new entry
    remember(memo, 4, -4, 3, at_once=True)
    assert memo == {3: -3, 4: -4}


def test_make_room_drops_only_when_full_and_clears_the_companions():
    memo, companion, held = {1: "a", 2: "b"}, {"x": 1}, ["kept alive"]
    make_room(memo, 3, at_once=True, also=(companion, held))
    assert memo == {1: "a", 2: "b"} and companion and held  # room left: nothing dropped
    memo[3] = "c"
    make_room(memo, 3, at_once=True, also=(companion, held))
    assert memo == {} and companion == {} and held == []
    memo.update({1: "a", 2: "b", 3: "c"})
    make_room(memo, 3)
    assert memo == {2: "b", 3: "c"}


def test_the_default_size_is_the_exact_engines_2048():
    memo: dict = {}
    for i in range(2049):
        remember(memo, i, None)
    assert len(memo) == 2048 and 0 not in memo and 2048 in memo


def test_sites_keep_their_own_sizes(monkeypatch):
    """Two of the memos that used to cap themselves by hand: kinks' crossings (``COMPILED``
    entries, the oldest dropped) and a compiled integrand's point floats (64 entries)."""
    v = symbol("x")
    filler = {("filler", i): False for i in range(compiling.COMPILED)}
    monkeypatch.setattr(kinks, "_CROSSES", dict(filler))
    assert kinks._crosses(v ** 2 - 3, v) is True  # by hand: degree 2 in x, coefficients free of x
    assert len(kinks._CROSSES) == compiling.COMPILED
    assert ("filler", 0) not in kinks._CROSSES and ("filler", 1) in kinks._CROSSES
    assert kinks._CROSSES[(v ** 2 - 3, v)] == (1, 0, -3)  # its coefficients in x, kept for the crossings
    monkeypatch.setattr(compiling, "_FLOATS", {})
    for i in range(70):
        compiling._floats({v: i})
    assert len(compiling._FLOATS) == 64 and ((v, 69),) in compiling._FLOATS and ((v, 5),) not in compiling._FLOATS


# --- the observer's flag --------------------------------------------------------------------------

def _forget() -> None:
    """Empty the memos that would hand a later call an earlier call's pieces or results."""
    for memo in (denote_module._remembered, denote_module._DECOMPOSED, ddenote_module._NORMAL_FORMS):
        memo.clear()


def test_counted_marks_the_rules_watched_and_nests():
    assert not observe.watched()
    with observe.counted():
        assert observe.watched() and not observe.active()  # counted, not recorded
        with observe.counted():
            assert observe.watched()
        assert observe.watched()
    assert not observe.watched()
    with observe.observing():
        assert observe.watched() and observe.active()
    with coverage.recording():  # the campaigns' rule coverage says so itself
        assert observe.watched()
    assert not observe.watched()


@pytest.fixture
def disk():
    loaded = load(str(DISK))
    assert denote_module.point_free(loaded.program)
    _forget()
    yield loaded.program
    _forget()


def test_the_point_free_decomposition_memo_stands_aside_while_counted(disk, monkeypatch):
    """The memo is on without an observer (one decomposition for three points) and off while the
    rules are counted (one per point) — nothing but the flag tells them apart: both names of
    ``decompose`` are the same spy throughout."""
    calls = []
    real = denote_module.decompose

    def spy(t, *rest):
        if t is disk.body:
            calls.append(1)
        return real(t, *rest)

    monkeypatch.setattr(denote_module, "decompose", spy)
    monkeypatch.setattr(decompose_module, "decompose", spy)
    points = [{"r": q} for q in (0.3, 0.45, 0.6)]
    values = [denote_program(disk, q, symbolic=False) for q in points]
    assert len(calls) == 1
    _forget()
    with observe.counted():
        counted = [denote_program(disk, q, symbolic=False) for q in points]
    assert len(calls) == 1 + 3
    for q, a, b in zip(points, values, counted):
        assert abs(a.value - math.pi * q["r"] ** 2) < 1e-9  # πr² by hand
        assert (a.value, a.error) == (b.value, b.error)


def test_the_point_free_normal_form_memo_stands_aside_while_counted(disk, monkeypatch):
    calls = []
    real = ddenote_module.ddenote

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(ddenote_module, "ddenote", spy)
    points = [{"r": q} for q in (0.3, 0.45, 0.6)]
    derivs = [ddenote_program(disk, q, {"r": 1}, symbolic=False) for q in points]
    assert len(calls) == 1  # one normal form for every point
    with observe.counted():
        counted = [ddenote_program(disk, q, {"r": 1}, symbolic=False) for q in points]
    assert len(calls) == 1 + 3
    for q, a, b in zip(points, derivs, counted):
        assert abs(a.value - 2 * math.pi * q["r"]) < 1e-7  # 2πr by hand
        assert (a.value, a.error) == (b.value, b.error)


def test_rule_counts_do_not_depend_on_what_the_memos_hold(disk):
    """A campaign's rule coverage counts the same applications whether or not the point-free
    memos were filled by an earlier, unobserved call at another point."""
    at, other = {"r": 0.45}, {"r": 0.3}

    def counted():
        coverage.reset()
        with coverage.recording():
            denote_program(disk, at, symbolic=False)
            ddenote_program(disk, at, {"r": 1}, symbolic=False)
        return coverage.counts()

    fresh = counted()
    _forget()
    denote_program(disk, other, symbolic=False)  # fills _DECOMPOSED and _NORMAL_FORMS
    ddenote_program(disk, other, {"r": 1}, symbolic=False)
    assert denote_module._DECOMPOSED and ddenote_module._NORMAL_FORMS
    primed = counted()
    coverage.reset()
    assert fresh[("Fig. 7", "diffeomorphic conditional")] > 0 and fresh[("Fig. 8 exact", "diffeomorphic conditional")] > 0
    assert primed == fresh


def test_typing_reads_no_kept_attributes_while_counted(monkeypatch):
    """Typing's shortcut (a term found well typed before) stands aside while the rules are
    counted, as while they are recorded: every node's rule is applied."""
    program = load(str(DISK)).program
    asked = []
    real = ty.well_typed
    monkeypatch.setattr(ty, "well_typed", lambda *args: asked.append(1) or real(*args))
    assert ty.type_program(program, frozenset({"r"})) == []
    assert asked  # the shortcut consulted without an observer
    asked.clear()
    with observe.counted():
        assert ty.type_program(program, frozenset({"r"})) == []
    assert not asked
