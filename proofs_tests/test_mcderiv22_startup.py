"""``langur deriv FILE --engine mc`` without sympy on affine programs (issue 15).

In a fresh interpreter: Fig. 1, microbenchmark 1 (§10.3.2) and two 2-D affine programs run
without importing sympy (``langur.lint.affineclear`` decides that the transversality and
integrability analyses would find nothing), and the command's output — JSON, standard error and
exit status — is the same as with those analyses run in full (the pre-check switched off in the
same interpreter).  A program the pre-check does not decide (a jump on the domain's end at the
values: X305) still runs the analyses, with the same output.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from proofs_tests.test_mcderiv22_affineclear import FIG9, TWO_LINES, mb1

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = """
import io, json, sys, contextlib
from langur.cli import main
if sys.argv[1] == "full":  # the analyses in full: the pre-check answers "not decided"
    from langur.lint import affineclear
    affineclear.nothing_to_find = lambda *a, **k: False
    affineclear.derivative_bounded = lambda *a, **k: False
out, err = io.StringIO(), io.StringIO()
with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
    status = main(["deriv", *sys.argv[2:], "--engine", "mc", "--json"])
print(json.dumps({"status": status, "stdout": out.getvalue(), "stderr": err.getvalue(),
                  "sympy": "sympy" in sys.modules}))
"""


def _run(mode: str, *args: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", SCRIPT, mode, *args], capture_output=True, text=True, env=env,
                         cwd=ROOT, timeout=300, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def _file(tmp_path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("case", ["fig1", "mb1", "fig9", "two lines"])
def test_affine_deriv_by_monte_carlo_without_sympy(case, tmp_path):
    args = {"fig1": ["examples/fig1.lgr"],
            "mb1": [_file(tmp_path, "mb1.lgr", mb1(49))],
            "fig9": ["examples/fig9.lgr", "--at", "theta=0.25"],
            "two lines": [_file(tmp_path, "lines.lgr", TWO_LINES), "--wrt", "t"]}[case]
    fast, full = _run("fast", *args), _run("full", *args)
    assert not fast["sympy"] and full["sympy"]
    assert (fast["status"], fast["stdout"], fast["stderr"]) == (full["status"], full["stdout"], full["stderr"])
    result = json.loads(fast["stdout"])
    assert fast["status"] == 0 and result["undefined"] is None and result["diagnostics"] == []
    if case == "fig1":
        mc = result["mc"]
        assert abs(mc["value"] - 1.0) <= 5 * mc["stderr"] + 1e-9  # d/dθ ∫₀¹ [x ≤ θ] dx = 1 (by hand)
    assert FIG9  # (imported for the 2-D case)


def test_an_undecided_program_still_runs_the_analyses():
    fast = _run("fast", "examples/fig1.lgr", "--at", "theta=0")
    full = _run("full", "examples/fig1.lgr", "--at", "theta=0")
    assert fast["sympy"]
    assert fast == full
    result = json.loads(fast["stdout"])
    assert fast["status"] == 1 and [d["code"] for d in result["diagnostics"]] == ["X305"]
