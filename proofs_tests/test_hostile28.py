"""Hostile files cost bounded time and memory: long sums of *distinct* conditions (hostile28).

``langur check`` on ``[x - 0/n >= 0]·x + [x - 1/n >= 0]·x + … + [x - n/n >= 0]·x`` compiled a
function per term three times over (the coincidence check's spot values of each condition against
the domain's bounds, the integrability analysis's regions of each piece, a sympy ``solve`` per pair
when the conditions move with a parameter): ≈ 5 CPU ms per term.  Each of these questions has an
exact answer read off the term (a nonzero polynomial written as distinct monomials is not zero, a
bounded integrand has nothing to blow up, a pole base without a root on the box has no pole there,
one parameter's affine equation has one solution), which is what the tests below check against the
definitions, and the checks run in subprocesses bounded in CPU time (``RLIMIT_CPU``) and address
space (``RLIMIT_AS``).  An analysis that stops at its limit says so (X312), and the exact engine's
closed-form search honours the one budget of its call.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp

from langur import frontend
from langur.denote import denote_program
from langur.lint import algebra, doubleroot, singular
from langur.symbolic import integrability as blowup
from langur.symbolic.pieces import Method
from langur.transversality import check_loaded

ROOT = Path(__file__).resolve().parents[1]


def _terms(n: int, term: str, last: int | None = None) -> str:
    """``term`` for k = 0 … last (default n), joined by +."""
    return " + ".join(term.format(k=k, n=n) for k in range((n if last is None else last) + 1))


def _dist(n: int) -> str:  # n + 1 distinct fixed conditions, the first and last on the domain's ends
    return f"int ([0, 1]) {_terms(n, '[x - {k}/{n} >= 0] * x')} d(x)\n"


def _col(text: str, fragment: str) -> int:
    """The column of ``fragment`` on its line of ``text``."""
    line = next(ln for ln in text.splitlines() if fragment in ln)
    return line.index(fragment) + 1


# ------------------------------------------------------------------------------------------------
# Findings on small sums, by hand (main's findings: the same, checked on main's tree 2026-11-29)

def _findings(tmp_path: Path, text: str, name: str = "small") -> list[tuple[str, str, int, int]]:
    path = tmp_path / f"{name}.lgr"
    path.write_text(text, encoding="utf-8")
    loaded = frontend.load_text(text, str(path))
    return sorted((f.code, f.severity, f.span.line, f.span.col) for f in check_loaded(loaded, sources={str(path): text}))


def test_distinct_fixed_conditions_by_hand(tmp_path):
    # [x - k/4 >= 0] for k = 0 … 4 on [0, 1]: each multiplies only the domain's bounds (x alone is
    # no condition).  Zero sets x = k/4: k = 0 is the lower bound's x = 0, k = 4 the upper bound's
    # x = 1, neither moves (no parameter): X308, twice; k = 1, 2, 3 meet nothing.  The integrand
    # is bounded (conditions times x): no X311/X312; no primitive: no X307.
    text = _dist(4)
    assert _findings(tmp_path, text) == [("X308", "warning", 1, _col(text, "[x - 0/4")),
                                         ("X308", "warning", 1, _col(text, "[x - 4/4"))]


def test_distinct_conditions_with_a_pole_off_the_domain_by_hand(tmp_path):
    # 1/(x + 1) has its pole at x = -1, outside [0, 1]: every piece is integrable (no X311, X312);
    # the conditions x >= k/4 are those above (X308 at k = 0 and k = 4).
    text = f"int ([0, 1]) {_terms(4, '[x >= {k}/{n}] / (x + 1)')} d(x)\n"
    assert _findings(tmp_path, text) == [("X308", "warning", 1, _col(text, "[x >= 0/4")),
                                         ("X308", "warning", 1, _col(text, "[x >= 4/4"))]


def test_distinct_conditions_with_a_pole_inside_still_diverge(tmp_path):
    # 1/(x - 1/3) on [k/4, 1]: the pieces k = 0, 1 contain x = 1/3, where ∫ dx/|x - 1/3| diverges:
    # ⟦p⟧ does not exist, X311 (one finding for the integral), whatever the other pieces do.
    text = f"int ([0, 1]) {_terms(4, '[x >= {k}/{n}] / (x - 1/3)')} d(x)\n"
    codes = [(c, s) for c, s, _, _ in _findings(tmp_path, text)]
    assert codes.count(("X311", "error")) == 1 and codes.count(("X308", "warning")) == 2


def test_moving_conditions_by_hand(tmp_path):
    # [x - a·k/4 >= 0] at a = 1/4: k = 0 is x = 0 (X308 with the lower bound); k ≥ 1 moves with a
    # and meets the bound x = 0 only at a = 0, not the value in force: no finding at a = 1/4.
    text = f"param a = 0.25\nint ([0, 1]) {_terms(4, '[x - a * {k}/{n} >= 0] * x')} d(x)\n"
    assert _findings(tmp_path, text) == [("X308", "warning", 2, _col(text, "[x - a * 0/4"))]


# ------------------------------------------------------------------------------------------------
# The exact answers that replace compiled spot values, against their definitions

def test_a_polynomial_written_as_distinct_monomials_does_not_vanish():
    a, b, x = sp.symbols("a b x")
    nonzero = [sp.Rational(-3, 10), -a * sp.Rational(3, 10), x**2 - 2 * a + 1, a * b - b, sp.Rational(1, 10**12) * a]
    for e in nonzero:
        assert algebra._distinct_monomials(e)
        assert algebra.vanishes(e, (a, b, x)) is False
        # independently: some rational point where it is not 0
        assert any(e.subs({a: p, b: p + 1, x: p + 2}) != 0 for p in range(1, 6))
    # identically zero, or not visibly polynomial: no claim from the written form, the full check
    # decides (and finds the zeros)
    zero = (a + 1) ** 2 - a**2 - 2 * a - 1
    assert not algebra._distinct_monomials(zero) and algebra.vanishes(zero, (a,)) is True
    for e in (sp.sin(a), a * (b + 1), 1 / a, sp.sqrt(a), sp.Float(0.5) * a, sp.I * a):
        assert not algebra._distinct_monomials(e)


def test_one_parameters_affine_equation_is_solved_as_sympy_does():
    a, x = sp.symbols("a x")
    for e in (-a * sp.Rational(3, 10), a - sp.Rational(1, 7), 3 * a + 2, -a * sp.Rational(5, 4) - sp.Rational(1, 3)):
        e = sp.sympify(e)
        assert algebra.bad_parameters(e, (), (a,)) == sp.solve([e], [a], dict=True)


def test_finite_on_box_is_a_proof():
    x = sp.Symbol("x")
    box = ((sp.Integer(0), sp.Integer(1)),)
    # no zero of the pole base on [0, 1] (by hand): finite there
    for w in (x, 1 / (x + 1), sp.exp(x) / (x**2 + 1), sp.pi * x / (2 - x)):
        assert blowup.finite_on_box(w, (x,), box), w
    # a zero in [0, 1] or at an end (the box is closed), or a primitive defined on part of ℝ: no claim
    for w in (1 / x, 1 / (x - 1), 1 / (x - sp.Rational(1, 3)), 1 / (x**2 - sp.Rational(1, 2)), sp.sqrt(x),
              sp.log(x + 2), sp.tan(x), sp.zoo * x):
        assert not blowup.finite_on_box(w, (x,), box), w
    # where it claims nothing blows up, the full analysis finds nothing on regions inside the box
    for w in (1 / (x + 1), sp.exp(x) / (x**2 + 1)):
        for lo in (0, sp.Rational(1, 3), sp.Rational(9, 10)):
            assert blowup.blowups(w, blowup.Region((x,), [(lo, 1)], [])) == []


# ------------------------------------------------------------------------------------------------
# An analysis that stops says so; the exact engine's one budget


def test_an_integrability_analysis_stopped_by_its_limit_says_so(tmp_path, monkeypatch):
    # 1/(x + 1) is integrable: the analysis, given no time, decides nothing and must say that
    # (X312 at the program), where it used to report nothing at all.
    text = f"int ([0, 1]) {_terms(4, '[x >= {k}/{n}] / (x + 1)')} d(x)\n"
    monkeypatch.setattr(singular, "TIME_LIMIT", 0.0)
    found = [f for f in check_loaded(frontend.load_text(text, "p.lgr"), sources={"p.lgr": text}) if f.code == "X312"]
    assert len(found) == 1 and "unchecked" in found[0].message and "⟦p⟧" in found[0].message, found


@pytest.mark.parametrize("limit, total, says", [(0.0, 15.0, "sympy took longer than 0 CPU s on 6 condition(s), the first at 1:1"),
                                                 (2.0, 0.0, "stopped after 0 CPU s with 6 condition(s) left")])
def test_a_per_condition_analysis_says_what_it_did_not_decide(monkeypatch, limit, total, says):
    # The double-root check (X315) of 5 distinct conditions and the domain's 2 bounds (conditions of
    # the inlined integrand, located at the program, 1:1), given no time per condition or in all:
    # nothing decided, and one X310 says so, where it used to pass over them in silence.
    # 6 conditions, not 7: k = 0's x - 0/4 and the lower bound's x - 0 are one condition, x (the
    # same zero set x = 0); before fold31 they were written x + (-1)·(0·4^-1) and x + (-1)·0, two
    # terms, and the check counted the one condition twice.  Since fold31 both fold to x.
    monkeypatch.setattr(doubleroot, "TIME_LIMIT", limit)
    monkeypatch.setattr(doubleroot, "TOTAL", total)
    text = _dist(4)
    found = doubleroot.double_root_findings(frontend.load_text(text, "p.lgr").program)
    assert [(f.code, f.severity) for f in found] == [("X310", "warning")] and says in found[0].message, found


def test_the_exact_engines_closed_forms_stop_at_the_calls_budget():
    # Σ_{k=0}^{n-1} ∫_{k/n}^1 x dx = n/2 − (n − 1)(2n − 1)/(12n) (by hand); 3,000 pieces take seconds of
    # closed forms, far more than a 0.05 s budget: past it the pieces left are integrated by
    # quadrature (the value stands, with its error bound) instead of the search going on.
    n = 3000
    text = "int ([0, 1]) " + _terms(n, "[x - {k}/{n} >= 0] * x", last=n - 1) + " d(x)\n"
    r = denote_program(frontend.load_text(text, "p.lgr").program, {}, timeout=0.05)
    exact = Fraction(n, 2) - Fraction((n - 1) * (2 * n - 1), 12 * n)
    assert r.method == Method.QUADRATURE and any("time limit" in note for note in r.notes), r.notes[:3]
    assert abs(r.value - float(exact)) <= max(r.error, 1e-9 * float(exact))


# ------------------------------------------------------------------------------------------------
# Bounded in CPU time and address space, in a subprocess

#: Measured 2026-11-29 (``/proc/self/status``, ``resource``): 10,000 distinct conditions take
#: 12.4 CPU s and 475 MB of address space at the peak (main: 37 CPU s).  The limits are about 4×
#: the CPU and 1.5× the address space.
CPU = 50
MEMORY_MB = 720


def _check(path: Path):
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_MB << 20, MEMORY_MB << 20))
        resource.setrlimit(resource.RLIMIT_CPU, (CPU, CPU + 5))

    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    # --timeout (wall clock) far above what CPU allows: a loaded machine must not stop it (X399)
    return subprocess.run([sys.executable, "-P", "-m", "langur", "check", "--format", "json", "--timeout", "3000",
                           str(path)], preexec_fn=limit, capture_output=True, text=True, env=env, timeout=3060)


@pytest.mark.parametrize("n", [9_999])
def test_ten_thousand_distinct_conditions_within_cpu_and_memory(tmp_path, n):
    path = tmp_path / "long.lgr"
    text = _dist(n)
    path.write_text(text, encoding="utf-8")
    r = _check(path)
    stopped = " (stopped: RLIMIT_CPU)" if r.returncode in (-signal.SIGXCPU, -signal.SIGKILL) else ""
    assert r.returncode == 0 and "Traceback" not in r.stderr, f"exit {r.returncode}{stopped}\n{r.stderr[-2000:]}"
    found = sorted((d["code"], d["severity"], d["line"], d["col"]) for d in json.loads(r.stdout)["diagnostics"])
    # as for 5 conditions, except that only the first 4,000 products are analysed (collect.MAX_PRODUCTS),
    # which X310 says: the last condition, x = 1 on the upper bound, is among those left unchecked
    assert found == [("X308", "warning", 1, _col(text, "[x - 0/")), ("X310", "warning", 1, 1)]


def test_pairs_made_one_at_a_time_are_those_listed():
    # A product of many conditions has its pairs made as the checks reach them (LISTED_PAIRS): the
    # same checks in the same order, so the same findings, as when they are listed up front.
    from langur.lint import classify

    programs = [f"int ([0, 1]) {' * '.join(f'[x - {k}/6 >= 0]' for k in range(7))} * x d(x)\n",
                "param a = 0.5\nint ([0, 1], [0, 1]) [x - a >= 0] * [x + y - 1 >= 0] * [y - a >= 0] * [x - y >= 0] d(x, y)\n",
                (ROOT / "examples" / "degenerate" / "three_lines.lgr").read_text(encoding="utf-8")]
    for text in programs:
        loaded = frontend.load_text(text, "p.lgr")
        listed = check_loaded(loaded, sources={"p.lgr": text})
        old = classify.LISTED_PAIRS
        try:
            classify.LISTED_PAIRS = 0
            made = check_loaded(loaded, sources={"p.lgr": text})
        finally:
            classify.LISTED_PAIRS = old
        assert made == listed and listed, text


PRODUCT = """
import sys
from langur.lint import classify
classify.BUDGET = 2.0  # (the checker's 30 CPU s, shortened: what is measured is what comes before it)
from langur.cli import main
sys.exit(main(["check", "--format", "json", "--timeout", "3000", sys.argv[1]]))
"""


def test_a_product_of_3000_distinct_conditions_within_memory(tmp_path):
    # 3000 conditions multiplied: 4.5 million pairs.  Listed up front they took 1.8 GB (main, before
    # its budget's clock even started); made one at a time, 209 MB (measured).  Under 720 MB of
    # address space the check ends, says that its budget stopped it (X310), and still finds the
    # first condition's coincidence with the domain's bound (X308: the pairs come in order).
    n = 3000
    path = tmp_path / "product.lgr"
    text = f"int ([0, 1]) {' * '.join(f'[x - {k}/{n} >= 0]' for k in range(n))} * x d(x)\n"
    path.write_text(text, encoding="utf-8")

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_MB << 20, MEMORY_MB << 20))
        resource.setrlimit(resource.RLIMIT_CPU, (CPU, CPU + 5))

    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    r = subprocess.run([sys.executable, "-P", "-c", PRODUCT, str(path)], preexec_fn=limit, capture_output=True,
                       text=True, env=env, timeout=3060)
    assert r.returncode == 0 and "Traceback" not in r.stderr, f"exit {r.returncode}\n{r.stderr[-2000:]}"
    found = json.loads(r.stdout)["diagnostics"]
    assert [(d["code"], d["line"], d["col"]) for d in found] == [("X310", 1, 1), ("X308", 1, _col(text, "[x - 0/"))]
    assert "stopped after 2 CPU s (its budget)" in found[0]["message"], found[0]["message"]
