"""Diagnostics that tell the truth (session 2026-11-29, diag32; bench/RESULTS.md, diag32).

1. The engines remember what they compiled by equal core terms, whose spans do not count (the
   Monte Carlo engine's units, samplers and linked programs, the exact engine's Ψ̂ and results).
   A refusal raised from such a memo (X316, an implicit root beyond its split) named the place of
   the equal program loaded FIRST in the process — another file, or another line.  A refusal now
   carries its node, and each engine's public entry names the program's own equal node
   (``core.refusals_located``).
"""

from __future__ import annotations

import pytest
from test_cli_contract import run  # (status, stdout, stderr) of ``langur ARGV`` in this process

from langur import frontend, operational
from langur.core import ImplicitRoot, TooManyRoots, own_root, subterms
from langur.ddenote import ddenote_program
from langur.denote import denote_program

# ---------------------------------------------------------------- 1. a refusal names its own program

# sin(7x) turns 8 times on [-2, 2] (x = (π/2 + kπ)/7, k = −4 … 3), more than the 7 pieces the condition is
# split for (syntax/turning.py): both engines refuse, X316, at the condition `sin(a * x) - 0.5` (col 16)
SINE7 = "param a = 7\nint ([-2, 2]) [sin(a * x) - 0.5 >= 0] * (1 + x) d(x)\n"
# the same core program, two lines lower and indented: the condition at line 4, col 18
SINE7_LOWER = "# the same program\nparam a = 7\n\nint ([-2, 2])   [sin(a * x) - 0.5 >= 0] * (1 + x) d(x)\n"


def _x316(err: str) -> list[str]:
    return [ln.split(" X316 ", 1)[0] + " X316 " + ln.split(" X316 ", 1)[1].split(":", 1)[0]
            for ln in err.splitlines() if " X316 " in ln]


def _files(tmp_path):
    first, second, lower = tmp_path / "one" / "sine7.lgr", tmp_path / "two" / "sine7.lgr", tmp_path / "lower.lgr"
    for f, text in ((first, SINE7), (second, SINE7), (lower, SINE7_LOWER)):
        f.parent.mkdir(exist_ok=True)
        f.write_text(text)
    return first, second, lower


def test_the_second_of_two_equal_programs_is_named_in_its_own_file_and_line(capsys, tmp_path):
    first, second, lower = _files(tmp_path)
    assert frontend.load(str(first)).program == frontend.load(str(lower)).program  # equal core terms
    for f, where in ((first, "2:16"), (second, "2:16"), (lower, "4:18"), (first, "2:16")):
        status, out, err = run(capsys, "deriv", f, "--wrt", "a", "--no-theorem", "--samples", "200")
        assert status == 1
        assert _x316(err) == [f"{f}:{where}: error X316 no exact value",
                              f"{f}:{where}: error X316 no Monte Carlo value"], (f, err)
        status, out, err = run(capsys, "eval", f, "--samples", "200")
        assert _x316(err) == [f"{f}:{where}: error X316 no exact value"], (f, err)


def _roots(program) -> list:
    """The program's implicit roots (in the completed conditions' inverse branches)."""
    found, stack = [], [program.body]
    while stack:
        for u in subterms(stack.pop()):
            if isinstance(u, ImplicitRoot):
                found.append(u)
            if hasattr(u, "psi"):
                stack += [*u.psi.forward, *(c for b in u.psi.branches for c in (*b.components, *b.guards))]
    return found


@pytest.mark.parametrize("engine", ["mc derivative", "exact value", "exact derivative"])
def test_a_library_refusal_carries_the_programs_own_node(tmp_path, engine):
    first, _, lower = _files(tmp_path)
    calls = {
        "mc derivative": lambda ld: operational.estimate_derivative(ld, {"a": 7.0}, {"a": 1.0}, samples=200),
        "exact value": lambda ld: denote_program(ld.program, {"a": 7}),
        "exact derivative": lambda ld: ddenote_program(ld.program, {"a": 7}, {"a": 1}),
    }
    for f, line, col in ((first, 2, 16), (lower, 4, 18), (first, 2, 16)):
        loaded = frontend.load(str(f))
        with pytest.raises(TooManyRoots) as caught:
            calls[engine](loaded)
        e = caught.value
        assert (e.span.path, e.span.line, e.span.col) == (str(f), line, col)
        assert any(e.root is r for r in _roots(loaded.program)) and e.span is e.root.span


def test_own_root_finds_the_equal_node_or_none(tmp_path):
    first, _, lower = _files(tmp_path)
    a, b = frontend.load(str(first)).program, frontend.load(str(lower)).program
    roots_a = _roots(a)
    assert len(roots_a) >= 7  # the split's indexed roots, at least one per turning point it allows
    for r in roots_a:
        mine = own_root(b, r)
        assert mine == r and mine is not r and (r.span is None) == (mine.span is None)
        assert r.span is None or (r.span.path, mine.span.path) == (str(first), str(lower))
    assert own_root(frontend.load_text("int ([0, 1]) x d(x)\n").program, roots_a[0]) is None
