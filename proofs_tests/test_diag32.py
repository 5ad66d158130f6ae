"""Diagnostics that tell the truth (session 2026-11-29, diag32; bench/history/2026-11-29.md#diag32.

1. The engines remember what they compiled by equal core terms, whose spans do not count (the
   Monte Carlo engine's units, samplers and linked programs, the exact engine's Ψ̂ and results).
   A refusal raised from such a memo (X316, an implicit root beyond its split) named the place of
   the equal program loaded FIRST in the process — another file, or another line.  A refusal now
   carries its node, and each engine's public entry names the program's own equal node
   (``core.refusals_located``).
2. pole31 splits a condition with a moving pole into conditionals on its factors' signs; the linter's
   findings about one factor quoted the written condition only.  They name the part as well: "the
   part `f >= 0` of `[written]`" (``lint/classify.py``, ``split_parts``).
3. ``syntax/folding.defined_everywhere`` walks with ``core.subterms`` (and π₀Ψ̂ on its own).
4. fold31's leftovers in core terms: ``x - -1``, ``t - -s``, ``-1 * -1 * a`` (a loop's ``-i * a`` at
   i = −1) and turning2d's guard ``u1 * 1`` fold, by exact rules: −(−s) = s, t − (−s) = t + s.
"""

from __future__ import annotations

from fractions import Fraction

import pytest
from test_cli_contract import run  # (status, stdout, stderr) of ``langur ARGV`` in this process

from langur import frontend, operational
from langur.core import Add, Const, IfDiffeo, ImplicitRoot, Mul, Param, TooManyRoots, Var, own_root, subterms
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.syntax import folding, template
from langur.syntax.folding import defined_everywhere
from langur.syntax.printer import print_core

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


# ---------------------------------------------------------------- 2. a split condition's findings name the part

# [zth − k/d ≥ 0] with d = x + n·y (its pole d = 0 crosses the box and moves with n): split into the signs
# of its factors, zth·d − k and d (zth − k/d = (zth·d − k)/d, by hand); the strict [k/d − zth > 0] into
# those of −k + zth·d and −d ((k − zth·d)/d has the sign of (−k + zth·d)·(−d))
SIX = "param k = 1\nparam zth = 2.6\nparam n = 0.3\nint ([-1, 1], [-1, 1]) [zth - k / (x + n * y) >= 0] d(x, y)\n"
SEVEN = "param k = 1\nparam zth = 2.6\nparam n = 0.3\nint ([-1, 1], [-1, 1]) [k / (x + n * y) - zth > 0] d(x, y)\n"


def _check_lines(capsys, tmp_path, name, text, *more):
    f = tmp_path / name
    f.write_text(text)
    _, out, err = run(capsys, "check", f, *more)
    return f, [ln for ln in (out + err).splitlines() if ln.startswith(str(f))]


def test_a_factors_finding_names_the_factor(capsys, tmp_path):
    f, lines = _check_lines(capsys, tmp_path, "seven.lgr", SEVEN)
    written = "`[k / (x + n * y) - zth > 0]`"
    # at k = 0 the factors −k + zth·d and −d have the same zero set d = 0 (X304); −k + zth·d's completion
    # divides by n·zth (X306 when zth = 0; n = 0 has the other completion, by x)
    assert lines == [
        f"{f}:4:24: warning X304 the part `-k + x * zth + n * y * zth >= 0` of {written} and the part "
        f"`-x + -n * y >= 0` of {written} at 4:24 have coincident zero sets when k = 0: there the derivative counts "
        "the jump twice (Def. 7.2 fails; paper §7.3.1)",
        f"{f}:4:24: warning X306 the part `-k + x * zth + n * y * zth >= 0` of {written} stops being a "
        "diffeomorphism when zth = 0 (its completion divides by n*zth, and every completion by another variable "
        "degenerates there too): there the derivative is not defined"]


def test_the_k_0_case_of_the_non_strict_condition_is_found_at_the_point(capsys, tmp_path):
    # [zth − k/d ≥ 0] at k = 0: the factors zth·d and d are ≥ 0 on the same side of d = 0 and their signs' parity
    # is constant — no jump — while for k ≠ 0 the slab between d = 0 and d = k/zth is cut out: the integral is
    # A − c·|k|, a kink in k at 0 (by hand), which the linter reports at the point (a jump lying on another)
    f, lines = _check_lines(capsys, tmp_path, "six.lgr", SIX)
    assert [ln.split(" ")[2] for ln in lines] == ["X306"]  # no parametric warning: kinks are reported at a point
    f, lines = _check_lines(capsys, tmp_path, "six.lgr", SIX, "--at", "k=0")
    x305 = [ln for ln in lines if " X305 " in ln]
    assert len(x305) == 1 and "at k = 0, zth = 2.6, n = 0.3 the jump of the part `x + n * y >= 0` of " \
        "`[zth - k / (x + n * y) >= 0]` lies on the part `-k + x * zth + n * y * zth >= 0`" in x305[0]


def test_an_unsplit_condition_is_quoted_as_written(capsys, tmp_path):
    f, lines = _check_lines(capsys, tmp_path, "kink.lgr", "param a = 0.5\nparam b = 0.2\n"
                            "int ([-1, 1], [-1, 1]) [abs(x - b) + abs(y) <= a] * [y - x + b >= 0] d(x, y)\n")
    assert lines == [f"{f}:3:53: warning X304 `[y - x + b >= 0]` and `[abs(x - b) + abs(y) <= a]` at 3:24 have "
                     "coincident zero sets when a = 0: there the derivative counts the jump twice (Def. 7.2 fails; "
                     "paper §7.3.1)"]


# ---------------------------------------------------------------- 3. defined_everywhere


@pytest.mark.parametrize("text, defined", [
    ("x * a + exp(y)", True),
    ("x ^ 2 + y / 4", True),
    ("1 / x", False),
    ("sqrt(x)", False),
    ("x ^ 0.5", False),
    ("[x - a >= 0] * y", True),
    ("[log(x) - a >= 0] * y", False),  # the condition is evaluated: undefined for x ≤ 0
    ("[x - 1 / a >= 0] * y", False),  # a parameter's reciprocal: undefined at a = 0
])
def test_defined_everywhere_reads_conditions_too(text, defined):
    box = tuple((Const(-1), Const(1)) for _ in "xy")
    t = frontend.core_term_from_text(text, variables=("x", "y"), params=("a",), box=box)
    assert defined_everywhere(t) is defined
    if "[" in text:
        assert any(isinstance(u, IfDiffeo) for u in subterms(t))


# ---------------------------------------------------------------- 4. the leftovers fold


def _core(text: str) -> str:
    return print_core(frontend.load_text(text).program.body)


def test_the_new_folds_are_the_identities_they_claim():
    x, a = Var("x"), Param("a")
    minus_one, one, two = Const(Fraction(-1)), Const(Fraction(1)), Const(Fraction(2))
    assert folding.negated(folding.negated(x)) is x and folding.negated(minus_one) == one
    assert folding.minus(a, folding.negated(x)) == Add(a, x) and folding.minus(a, minus_one) == Add(a, one)
    assert folding.times(minus_one, folding.negated(x)) is x and folding.times(minus_one, minus_one) == one
    # what is not a negation stays: t − 2, 2·(−x), (−1)·x, and −2 written as a constant is no negation of 2
    assert folding.minus(a, two) == Add(a, Mul(minus_one, two))
    assert folding.times(two, folding.negated(x)) == Mul(two, Mul(minus_one, x))
    assert folding.times(minus_one, x) == Mul(minus_one, x)
    assert folding.negated(Const(Fraction(-2))) == Mul(minus_one, Const(Fraction(-2)))


def test_double_negations_fold():
    assert _core("int ([-1, 1]) [x >= 0] d(x)") == "[x + 1 >= 0] * [1 - x >= 0] * [x >= 0]"
    assert _core("param a = 1\nint ([0, 1]) [a - -x >= 0] + -(-x) - -1 d(x)").endswith("([a + x >= 0] + x + 1)")
    assert _core("param a = 1\nint ([0, 1]) -(-(-x)) * a d(x)").endswith("(-x * a)")
    # −(−s) stays undefined where s is: sqrt(x) on [−1, 0)
    assert _core("int ([-1, 1]) -(-sqrt(x)) d(x)").endswith("sqrt(x)")


def test_the_guard_of_a_split_along_y_has_no_times_one():
    ld = frontend.load("examples/turning2d.lgr")
    guards = [g for u in subterms(ld.program.body) if isinstance(u, IfDiffeo)
              for b in u.psi.branches for g in b.guards]
    assert guards and not any(isinstance(v, Mul) and isinstance(v.right, Const) and v.right.value == 1
                              for g in guards for v in subterms(g))


LOOP = "param a = 0.5\nint ([-1, 1]) (sum i in {lo}..{hi}: [x - i >= a * 0.1] + -i * a - -i) d(x)\n"


@pytest.mark.parametrize("lo, hi", [(-4, 3), (-3, -1), (-1, 2), (-6, -2), (2, 5)])
def test_a_loops_copies_from_the_template_are_the_copies_desugared_one_by_one(monkeypatch, lo, hi):
    text = LOOP.format(lo=lo, hi=hi)
    with_template = frontend.load_text(text).program
    frontend.clear_load_cache()
    monkeypatch.setattr(template, "ENABLED", False)
    one_by_one = frontend.load_text(text).program
    assert with_template == one_by_one and print_core(with_template.body) == print_core(one_by_one.body)
    printed = print_core(with_template.body)
    if lo <= -1 <= hi:  # the copy at i = −1 (desugared on its own): x − (−1), −(−1)·a and − −(−1) folded
        assert "[x + 1 - a * 0.1 >= 0] + a - 1" in printed and "x - -1" not in printed
    if lo <= -2:  # the other copies keep the first copy's shape: no constant arithmetic on the index
        assert "[x - -2 - a * 0.1 >= 0] + -1 * -2 * a + -2" in printed
