"""``langur show --latex`` (issue 14): one complete LaTeX document, ASCII only, braces and
environments balanced, one notation (no ``**``); compiled with pdflatex where one is installed."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest
from paths import EXAMPLES

from langur.cli import main

CASES = [
    (EXAMPLES / "fig1.lgr", ["--wrt", "theta"]),
    (EXAMPLES / "fig9.lgr", ["--wrt", "theta"]),
    (EXAMPLES / "risk.lgr", ["--wrt", "a"]),
    (EXAMPLES / "densities.lgr", []),
]


def _show(capsys, path, extra, flag="--latex"):
    status = main(["show", str(path), *extra, flag])
    out = capsys.readouterr().out
    assert status == 0
    return out


def well_formed(tex: str) -> list[str]:
    """Problems that would stop pdflatex: unbalanced braces (escaped ones aside), environments or
    \\left/\\right, non-ASCII characters, display math left open."""
    problems = []
    body = re.sub(r"\\begin\{verbatim\}.*?\\end\{verbatim\}", "", tex, flags=re.S)
    bare = re.sub(r"\\[{}]", "", body)
    depth = 0
    for ch in bare:
        depth += {"{": 1, "}": -1}.get(ch, 0)
        if depth < 0:
            problems.append("a } closes nothing")
            break
    if depth > 0:
        problems.append(f"{depth} unclosed {{")
    stack = []
    for kind, env in re.findall(r"\\(begin|end)\{([^}]*)\}", tex):
        if kind == "begin":
            stack.append(env)
        elif not stack or stack.pop() != env:
            problems.append(f"\\end{{{env}}} does not match")
    if stack:
        problems.append(f"unclosed environments {stack}")
    if len(re.findall(r"\\left\b", body)) != len(re.findall(r"\\right\b", body)):
        problems.append("\\left without \\right")
    if any(ord(ch) > 127 for ch in tex):
        problems.append("non-ASCII characters: " + "".join(sorted({ch for ch in tex if ord(ch) > 127})))
    if "**" in body:
        problems.append("** beside LaTeX powers")
    if body.count("$") % 2:
        problems.append("odd number of $")
    return problems


def test_the_checker_catches_what_breaks_latex():
    good = "\\documentclass{article}\\begin{document}$\\left(x^{2}\\right)$\\end{document}"
    assert well_formed(good) == []
    for bad in (good.replace("x^{2}", "x^{2"), good.replace("\\right", ""), good + "⟦", good + "x**2",
                good.replace("\\end{document}", "")):
        assert well_formed(bad), bad


@pytest.mark.parametrize("path, extra", CASES, ids=lambda c: getattr(c, "name", ""))
def test_latex_is_one_well_formed_document(capsys, path, extra):
    tex = _show(capsys, path, extra)
    assert tex.startswith("\\documentclass{article}") and tex.rstrip().endswith("\\end{document}")
    assert tex.count("\\begin{document}") == 1
    assert well_formed(tex) == []
    fragment = _show(capsys, path, extra, "--latex-fragment")
    assert "\\documentclass" not in fragment and fragment in tex and well_formed(fragment) == []


def test_latex_shows_the_readable_cases(capsys):
    tex = _show(capsys, EXAMPLES / "fig9.lgr", ["--wrt", "theta"])
    assert "\\begin{cases} 0 & \\theta \\leq -2" in tex and "4 \\theta + 4 & \\theta > 2" in tex


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="pdflatex is not installed on this machine")
@pytest.mark.parametrize("path, extra", CASES[:3], ids=lambda c: getattr(c, "name", ""))
def test_latex_compiles_with_pdflatex(capsys, tmp_path, path, extra):
    (tmp_path / "show.tex").write_text(_show(capsys, path, extra))
    r = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "show.tex"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout[-2000:]
    assert (tmp_path / "show.pdf").exists()


def test_indicators_print_as_brackets_and_other_piecewise_as_sympy():
    import sympy as sp

    from langur.symbolic.text import expr_text

    x = sp.Symbol("x", real=True)
    ind = sp.Piecewise((1, x >= 0), (0, True))
    other = sp.Piecewise((x**2, x >= 0), (-x, True))
    assert expr_text(2 * ind) == "2*[x >= 0]" and expr_text(other) == "Piecewise((x^2, x >= 0), (-x, True))"
    assert expr_text(x * ind, latex=True) == "x \\left[x \\geq 0\\right]"
    assert "\\begin{cases}" in expr_text(other, latex=True)
