"""Words a user understands (branch words30).

* Notes and diagnostics never quote sympy's exception names or messages: every site that reports a
  caught failure asks the one catalogue, ``langur.failures.why``.  The end-to-end cases are programs
  whose output named ``NotImplementedError`` or quoted sympy's "No algorithms are implemented to solve
  equation …" before (X310 of ``langur check``; the exact engine's note on examples/turning2d.lgr).
* The core printer prints a comparison with 0 as it was written — ``[t >= 0]``, ``if t >= 0 then s
  else r`` — instead of ``ifge0 t - 0 then …``, and the printed text still desugars to the same term.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp

from langur import failures
from langur.core import TooManyRoots
from langur.failures import OTHERWISE, WORDS, why

ROOT = Path(__file__).resolve().parent.parent
#: What a user must never read: an exception's class name, or sympy's own failure text.
JARGON = re.compile(r"\b\w*(Error|Failed|Needed|TooManyRoots)\b|No algorithms are implemented|generators")
X = sp.Symbol("x")


def langur(*args: str, cwd: Path) -> str:
    done = subprocess.run([sys.executable, "-P", "-m", "langur", *args], capture_output=True, text=True, cwd=cwd,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}, timeout=600)
    return done.stdout + done.stderr


# ---------------------------------------------------------------------------------------------
# The catalogue, on failures raised for real.


def _raised(fn) -> BaseException:
    try:
        fn()
    except Exception as e:  # noqa: BLE001 - the failure is the point
        return e
    raise AssertionError("no failure")


def test_sympy_polynomial_errors_are_one_entry_in_words():
    for e in (_raised(lambda: sp.Poly(1 / X, X)), _raised(lambda: sp.degree(sp.sin(X) + X, X))):
        assert isinstance(e, sp.PolynomialError) and "generators" in str(e)  # sympy's words …
        assert why(e) == WORDS["BasePolynomialError"]  # … are not passed on
        assert not JARGON.search(why(e))
    e = _raised(lambda: sp.Poly(X, X).exquo(sp.Poly(X + 1, X)))  # another of its polynomial errors, one entry
    assert isinstance(e, sp.polys.polyerrors.BasePolynomialError), type(e)
    assert why(e) == WORDS["BasePolynomialError"]
    assert not JARGON.search(why(e))


def test_sympy_has_no_algorithm_in_words():
    e = _raised(lambda: sp.solve(sp.exp(X) + sp.erf(X) - X**3 - sp.Rational(1, 3), X))
    assert isinstance(e, NotImplementedError) and "No algorithms" in str(e)  # sympy's own words …
    assert why(e) == WORDS["NotImplementedError"]  # … are not passed on
    assert not JARGON.search(why(e))


def test_other_sympy_failures_and_a_builtin_raised_inside_sympy():
    e = _raised(lambda: bool(sp.Symbol("a") < 1))  # TypeError raised inside sympy
    assert isinstance(e, TypeError)
    assert why(e) == OTHERWISE


def test_langurs_own_words_are_kept():
    e = TooManyRoots("cannot certify the turning points near x in [0, 1]")
    assert why(e) == "cannot certify the turning points near x in [0, 1]"
    from langur.sympy_bridge import from_sympy

    e = _raised(lambda: from_sympy(sp.gamma(X), ("x",), ()))  # a ValueError Langur raises, its message
    assert isinstance(e, ValueError) and "gamma" in str(e)
    assert why(e) == str(e).splitlines()[0]


def test_no_site_prints_an_exception_class_name():
    """The sites reworded here stay so: no `type(e).__name__` in a message outside the CLI's
    internal-error line (a bug report), the fuzz tester's own output (compare, cluster, pool) and
    reading a file (an OSError's strerror, its name only when it has none: frontend, check, _common)."""
    allowed = {"cli.py", "compare.py", "cluster.py", "pool.py", "frontend.py", "check.py", "_common.py"}
    found = []
    for path in (ROOT / "langur").rglob("*.py"):
        if path.name in allowed:
            continue
        for n, line in enumerate(path.read_text().splitlines(), 1):
            if "__name__}" in line and re.search(r"type\((e|exc|err)\)\.__name__", line):
                found.append(f"{path.relative_to(ROOT)}:{n}")
    assert found == []
    assert failures.why.__module__ == "langur.failures"


# ---------------------------------------------------------------------------------------------
# Programs whose output quoted sympy before.


def test_check_says_why_transversality_is_undecided_in_words(tmp_path):
    # main: "X310 could not decide the transversality of … (sympy failed: NotImplementedError)"
    (tmp_path / "erf.lgr").write_text("param a = 0.3\nint ([-1, 1], [-1, 1]) [erf(x) + y >= a] * [x * y >= a] d(x, y)\n")
    (tmp_path / "asin.lgr").write_text("param a = 0.3\nint ([-1, 1], [-1, 1]) [asin(x*y) >= a] * [atanh(x/2) + y >= a] "
                                       "d(x, y)\n")
    out = langur("check", "erf.lgr", "asin.lgr", "--timeout", "300", cwd=tmp_path)
    lines = [ln for ln in out.splitlines() if " X310 " in ln]
    assert len(lines) >= 2, out
    assert not JARGON.search(out), out
    assert all(f"({WORDS['NotImplementedError']})" in ln or "CPU s" in ln for ln in lines), lines


def test_the_exact_engine_note_on_turning2d_in_words():
    # main: "note: delta piece 0: cannot solve root(…) + 1 = 0 for u1: No algorithms are implemented to
    # solve equation root(…) + 1"
    from langur.exact import exact_deriv
    from langur.frontend import load

    loaded = load(str(ROOT / "examples" / "turning2d.lgr"))
    r = exact_deriv(loaded.program, loaded.param_values(), {"a": 1})
    notes = [n for n in r.notes if "cannot solve" in n]
    assert len(notes) == 1, r.notes
    assert notes[0].endswith(f"= 0 for u1: {WORDS['NotImplementedError']}")
    assert not any(JARGON.search(n) for n in r.notes), r.notes
    assert r.value == pytest.approx(-5.254463785, abs=1e-8)  # the value as before (quadrature)


# ---------------------------------------------------------------------------------------------
# The core printer: no `- 0` (since fold31 the desugarer builds none: a comparison with 0 is the term
# itself, syntax/folding.py; a bracket prints as a bracket, other conditionals as ifge0).


@pytest.mark.parametrize("body, printed", [
    ("[x^3 - x - a >= 0] * exp(x / 2)", "[x ^ 3 - x - a >= 0] * exp(x / 2)"),
    ("(if x - a >= 0 then 2 else 1)", "ifge0 x - a then 2 else 1"),
    ("[0 <= x - a] * [a < 0.5]", "[x - a >= 0] * [0.5 - a >= 0]"),
    ("(if a - 0.5 >= 0 then x else 1)", "ifge0 a - 0.5 then x else 1"),  # a variable-free condition
])
def test_a_comparison_with_zero_prints_as_written(body, printed):
    from langur.frontend import load_text
    from langur.syntax.printer import print_program

    text = f"param a = 0.25\nint ([-2, 2]) {body} d(x)\n"
    loaded = load_text(text, "cmp.lgr")
    out = print_program(loaded.program, loaded.params)
    assert out.splitlines()[-1] == f"int ([-2, 2]) {printed} d(x)"
    assert "- 0 " not in out
    again = load_text(out, "again.lgr")  # the printer's round trip (test_printer) holds for these forms
    assert again.program.body == loaded.program.body


def test_show_core_of_the_examples_has_no_minus_zero(tmp_path):
    out = langur("show", str(ROOT / "examples" / "turning.lgr"), "--core", cwd=tmp_path)
    assert "[x ^ 3 - x - a >= 0] * exp(x / 2)" in out, out
    out = langur("show", str(ROOT / "examples" / "fig1.lgr"), "--wrt", "theta", "--steps", cwd=tmp_path)
    assert "on  [x >= 0] * [1 - x >= 0]" in out, out
    assert not re.search(r" - 0 then", out), out
