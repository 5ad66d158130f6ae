"""deriv23b (issue 15): Theorem 8.1's check (paper §8.3, :mod:`langur.theorem`) on turning2d ∂a —
37 % of the partial's instructions — re-evaluates ⟦p⟧ by quadrature at the four shifted points of
its finite differences.  What does not depend on the point is done once per process and shared
with the shifted points: the program's decomposition (``denote._decomposed``), the compiled
integrands and conditions (``compiling._COMPILED``), the kinks' sympy work (critical points,
crossings: ``kinks._KINKS``, ``kinks._CRITICAL``).  Counted here: at the shifted points none of
that sympy work is done again (a guard — these memos are what makes the shifted points cost only
their quadratures), and the check's value is reproduced from an independent evaluation of the
four shifted values in a fresh process (no memo shared with the derivative or with ⟦p⟧ at the
point), bit for bit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from langur import denote, theorem
from langur.ddenote import ddenote_program
from langur.frontend import load
from langur.symbolic.quadrature import compiling, kinks

REPO = Path(__file__).resolve().parent.parent
TURNING2D = REPO / "examples" / "turning2d.lgr"


def _counted(monkeypatch, module, name: str, calls: list) -> None:
    f = getattr(module, name)

    def counting(*args, **kwargs):
        calls.append(name)
        return f(*args, **kwargs)

    monkeypatch.setattr(module, name, counting)


#: A fresh process: ⟦p⟧ at the four shifted points (the finite differences' first step, at its
#: loosened outer tolerance) and at the parameters, ⦇p⦈ at the parameters, each value's repr.
_INDEPENDENT = """
import json, sys
from langur.frontend import load
from langur.denote import denote_program
from langur.ddenote import ddenote_program
from langur.symbolic import quadrature
from langur.theorem import LOOSE_OUTER
loaded = load(sys.argv[1])
at = loaded.param_values()
points = json.loads(sys.argv[2])
with quadrature.outer_tolerance(LOOSE_OUTER):
    shifted = [denote_program(loaded.program, q, timeout=1.0, symbolic=False).value for q in points]
den = denote_program(loaded.program, at, near=True)
der = ddenote_program(loaded.program, at, {"a": 1})
print(json.dumps({"shifted": [repr(v) for v in shifted], "den": repr(den.value), "der": repr(der.value)}))
"""


def test_turning2d_check_shares_the_point_free_work(monkeypatch):
    """The check after ⦇p⦈ and ⟦p⟧ at the parameters: four shifted ⟦p⟧, with no decomposition, no
    compilation (sympy's lambdify) and no kink computation (sympy's solve, resultants) of their own;
    its D⟦p⟧·γ' is the Richardson estimate of those four values, which a fresh process computes
    alike."""
    loaded = load(str(TURNING2D))
    at = loaded.param_values()
    direction = {"a": 1}
    der = ddenote_program(loaded.program, dict(at), direction)
    den = denote.denote_program(loaded.program, dict(at), near=True)
    assert str(den.method) == "quadrature"  # (the finite-difference path is what is checked here)

    calls: list = []
    _counted(monkeypatch, denote, "decompose", calls)
    _counted(monkeypatch, compiling, "shared_lambdify", calls)
    _counted(monkeypatch, kinks, "_solve_critical", calls)
    _counted(monkeypatch, kinks, "_crossings", calls)
    shifted: list = []
    real = theorem.denote_program

    def recording(program, q, **kwargs):
        out = real(program, q, **kwargs)
        shifted.append((dict(q), out.value))
        return out

    monkeypatch.setattr(theorem, "denote_program", recording)
    compiled = len(compiling._COMPILED)
    th = theorem.check_theorem_8_1(loaded.program, dict(at), direction, denotation=den, derivative=der)
    monkeypatch.undo()

    assert th.how == theorem.How.FINITE_DIFFERENCE and th.holds is True
    assert any("outermost quadrature at 30× its usual tolerance" in n for n in th.notes)  # the first step
    assert len(shifted) == 4
    assert calls == []  # nothing point-free done again at the shifted points
    assert len(compiling._COMPILED) == compiled

    # the shifted points are a ± h, a ± 2h (the first step, h = 10⁻³ times the parameters' scale)
    a = float(at["a"])
    h = 1e-3 * max(1.0, abs(a))
    assert [q["a"] for q, _ in shifted] == [a + h, a - h, a + 2 * h, a - 2 * h]

    # an independent evaluation of each shifted value (a fresh process, no memo shared)
    out = subprocess.run([sys.executable, "-P", "-c", _INDEPENDENT, str(TURNING2D),
                          json.dumps([q for q, _ in shifted])],
                         capture_output=True, text=True, timeout=600, cwd=str(REPO),
                         env={**os.environ, "PYTHONPATH": str(REPO)})
    assert out.returncode == 0, out.stderr
    fresh = json.loads(out.stdout.strip().splitlines()[-1])
    values = [float(v) for v in fresh["shifted"]]
    assert values == [v for _, v in shifted]
    assert float(fresh["den"]) == den.value and float(fresh["der"]) == der.value
    p1, m1, p2, m2 = values
    fd1, fd2 = (p1 - m1) / (2 * h), (p2 - m2) / (4 * h)
    assert th.d_denotation == (4 * fd1 - fd2) / 3
    assert th.derivative_denotation == der.value
