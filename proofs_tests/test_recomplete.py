"""A completion that degenerates at the parameter values, replaced by one that does not
(``langur/lint/recomplete.py``; paper §5.2, Def. 3.4, Theorem 8.1).

A triangle's edge function ``(cx − bx)·(y − by) − (cy − by)·(x − bx)`` is completed by isolating
``y``, which divides by ``cx − bx``: at ``bx = cx`` that completion is not a diffeomorphism, but the
edge is the vertical line ``x = bx`` and the covered area is a smooth function of the vertices.
Before, ``deriv`` at ``bx = cx`` said "the derivative does not exist" (X305) and the Monte Carlo
engine lost the edge's delta (−0.079 instead of ≈ 0.129 on examples/stylize/linear.lgr).  The
values below are the triangle's area and its partial derivatives by hand:
``f = ((bx − ax)(cy − ay) − (by − ay)(cx − ax)) / 2``.
"""

import json
from fractions import Fraction

import pytest

from langur.cli import main
from langur.core import IfDiffeo, subterms
from langur.frontend import load
from langur.lint import recomplete
from langur.syntax.completion import complete
from langur.syntax.printer import print_core

A = (Fraction(1, 5), Fraction(1, 10))
B = (Fraction(7, 10), Fraction(1, 5))
C = (Fraction(7, 10), Fraction(4, 5))  # bx = cx: the edge bc is vertical

TRIANGLE = """\
param ax = 0.2, ay = 0.1, bx = 0.7, by = 0.2, cx = 0.7, cy = 0.8
int ([0, 1], [0, 1])
  [(bx - ax) * (y - ay) - (by - ay) * (x - ax) >= 0]
  * [(cx - bx) * (y - by) - (cy - by) * (x - bx) >= 0]
  * [(ax - cx) * (y - cy) - (ay - cy) * (x - cx) >= 0]
d(x, y)
"""

# the triangle lies inside the unit square: f is its area, and its partials are polynomials
AREA = ((B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0])) / 2
D_BX = (C[1] - A[1]) / 2
D_BY = -(C[0] - A[0]) / 2


@pytest.fixture
def triangle(tmp_path):
    path = tmp_path / "triangle.lgr"
    path.write_text(TRIANGLE)
    return str(path)


def run(capsys, *argv):
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out, out.err


def edges(program):
    return [t.psi for t in subterms(program.integrand) if isinstance(t, IfDiffeo) and t.psi.nonzero]


def test_completion_avoiding_a_variable(triangle, tmp_path):
    # the sympy path (a parameter coefficient): isolate x instead of y
    bc = edges(load(triangle).program)[1]
    assert bc.solved_for == "y" and [print_core(n) for n in bc.nonzero] == ["cx - bx"]
    alt = complete(bc.condition, ("x", "y"), avoid=frozenset({"y"}))
    assert alt.solved_for == "x" and len(alt.nonzero) == 1
    assert set(print_core(alt.nonzero[0]).replace("(", "").replace(")", "").split()) >= {"cy", "by"}
    # the direct path (rational coefficients)
    line = tmp_path / "line.lgr"
    line.write_text("int ([0, 1], [0, 1]) [x + 2 * y - 1 >= 0] d(x, y)\n")
    (psi,) = [t.psi for t in subterms(load(str(line)).program.integrand) if isinstance(t, IfDiffeo)]
    assert psi.solved_for == "y"
    assert complete(psi.condition, ("x", "y"), avoid=frozenset({"y"})).solved_for == "x"


def test_check_reports_only_where_every_completion_degenerates(triangle, capsys):
    status, out, err = run(capsys, "check", triangle)
    assert status == 0, out + err
    x306 = [line for line in out.splitlines() if " X306 " in line]
    # each edge degenerates only where its two vertices coincide (the triangle collapses)
    assert len(x306) == 3
    assert "when bx = cx and by = cy" in x306[1]
    assert not any("default values" in line for line in x306)  # bx = cx alone is not in the set
    # the defaults have the edge vertical (bx = cx): no error above; where b = c: X305
    status, out, _ = run(capsys, "check", triangle, "--at", "by=0.8")
    assert status == 1 and " error X305 " in out and "not a diffeomorphism" in out


def test_at_values_replaces_the_vertical_edge_only(triangle):
    program = load(triangle).program
    values = {"ax": "0.2", "ay": "0.1", "bx": "0.7", "by": "0.2", "cx": "0.7", "cy": "0.8"}
    changed, done = recomplete.at_values(program, values)
    assert [(r.was, r.now) for r in done] == [("y", "x")]
    assert "cx - bx" in done[0].vanishing.replace("-bx + cx", "cx - bx")
    after = edges(changed)
    assert [psi.solved_for for psi in after] == ["y", "x", "y"]
    # away from the degenerate values nothing changes
    assert recomplete.at_values(program, {**values, "cx": "0.6"}) == (program, ())


@pytest.mark.parametrize("wrt, hand, theorem", [("bx", D_BX, True), ("by", D_BY, False)])
def test_deriv_at_the_vertical_edge_is_the_hand_value(triangle, capsys, wrt, hand, theorem):
    status, out, err = run(capsys, "deriv", triangle, "--wrt", wrt, "--json", "--samples", "20000",
                           *(() if theorem else ("--no-theorem",)))
    assert status == 0, err
    r = json.loads(out)
    assert r["undefined"] is None and r["recompleted"]
    assert r["exact"]["value"] == pytest.approx(float(hand), abs=1e-12)
    mc = r["mc"]
    assert abs(mc["value"] - float(hand)) <= 5 * mc["stderr"] + 1e-9
    if theorem:
        assert r["theorem_8_1"]["holds"] is True


def test_eval_at_the_vertical_edge(triangle, capsys):
    status, out, err = run(capsys, "eval", triangle, "--json")
    assert status == 0, err
    r = json.loads(out)
    assert r["exact"]["value"] == pytest.approx(float(AREA), abs=1e-12)
    assert abs(r["mc"]["value"] - float(AREA)) <= 5 * r["mc"]["stderr"] + 1e-9


def test_a_condition_degenerate_in_every_completion_stays_undefined(tmp_path, capsys):
    # [t·(x − ½) + t·(y − ½) ≥ 0]: at t = 0 it is 0 ≥ 0 everywhere; the integral is ½ for t ≠ 0
    # and 1 at t = 0, so it has no derivative there, and no completion can help
    path = tmp_path / "flat.lgr"
    path.write_text("param t = 0\nint ([0, 1], [0, 1]) [t * (x - 0.5) + t * (y - 0.5) >= 0] d(x, y)\n")
    status, out, err = run(capsys, "deriv", str(path), "--wrt", "t", "--json", "--engine", "exact")
    r = json.loads(out)
    assert status == 1 and r["undefined"] and r["exact"] is None and r["recompleted"] == []
    assert "X305" in [d["code"] for d in r["diagnostics"]]
