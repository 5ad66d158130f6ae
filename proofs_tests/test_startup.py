"""Start-up without sympy or scipy on the Monte Carlo path of an affine program (issue 15).

The command runs in a fresh interpreter (sympy must not be imported by anything, including the
CLI's other commands or the integrability analysis, which ``langur.lint.bounded`` makes
unnecessary for a bounded integrand); its number is checked against the exact value.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = """
import json, sys
from langur.cli import main
status = main(["eval", sys.argv[1], "--engine", "mc", "--json"])
print(json.dumps({"status": status, "sympy": "sympy" in sys.modules, "scipy": "scipy" in sys.modules}))
"""


def _run(path: str) -> tuple[dict, dict]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", SCRIPT, path], capture_output=True, text=True, env=env,
                         cwd=ROOT, timeout=120, check=True).stdout.strip().splitlines()
    return json.loads(out[0]), json.loads(out[1])


def test_fig1_monte_carlo_path_imports_neither_sympy_nor_scipy():
    result, seen = _run("examples/fig1.lgr")
    assert seen == {"status": 0, "sympy": False, "scipy": False}
    mc = result["mc"]
    assert abs(mc["value"] - 0.5) <= 5 * mc["stderr"] + 1e-9  # ∫₀¹ [x ≤ 1/2] dx = 1/2


def test_a_nonlinear_condition_still_loads_sympy(tmp_path):
    src = tmp_path / "disk.lgr"
    src.write_text("param r = 0.5\nint ([0, 1], [0, 1]) [x^2 + y^2 <= r^2] d(x, y)\n")
    result, seen = _run(str(src))
    assert seen["sympy"] and seen["status"] == 0
    mc = result["mc"]
    assert abs(mc["value"] - 3.141592653589793 / 16) <= 5 * mc["stderr"] + 1e-9  # a quarter disk of radius 1/2


DERIV = """
import json, sys
from langur.cli import main
status = main(["deriv", sys.argv[1], "--engine", "mc", "--json"])
print(json.dumps({"status": status, "scipy": "scipy" in sys.modules, "scipy.optimize": "scipy.optimize" in sys.modules}))
"""


def test_deriv_by_monte_carlo_of_fig1_does_not_import_scipy():
    # its analyses (transversality, integrability) need sympy, but neither solves an implicit root
    # nor splits a case with a linear program: scipy.optimize's import is left to those who do
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", DERIV, "examples/fig1.lgr"], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=120, check=True).stdout.strip().splitlines()
    result, seen = json.loads(out[0]), json.loads(out[1])
    assert seen == {"status": 0, "scipy": False, "scipy.optimize": False}
    mc = result["mc"]
    assert abs(mc["value"] - 1.0) <= 5 * mc["stderr"] + 1e-9  # d/dθ ∫₀¹ [x ≤ θ] dx = 1 (by hand)


def test_the_parser_of_one_command_and_the_list_of_all():
    """``langur eval …`` makes the parser of ``eval`` alone (start-up); wherever the list of commands
    can be asked for (no command first, or ``--help`` before it) every command is in it."""
    from langur import cli

    alone = cli.build_parser(["eval", "x.lgr"])
    (sub,) = [a for a in alone._actions if a.dest == "command"]
    assert list(sub.choices) == ["eval"]
    for argv in (["--help", "eval"], ["--version"], []):
        every = cli.build_parser(argv)
        (sub,) = [a for a in every._actions if a.dest == "command"]
        assert list(sub.choices) == list(cli.COMMANDS), argv
    r = subprocess.run([sys.executable, "-m", "langur", "--help", "eval"], capture_output=True, text=True,
                       cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=120)
    assert r.returncode == 0 and all(name in r.stdout for name in cli.COMMANDS)
