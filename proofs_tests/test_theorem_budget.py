"""Theorem 8.1's check under a CPU budget (``exact_deriv(check_seconds=…)``; issue 13).

In a campaign the checks of one program share ``CHECK_SHARE`` of its time limit: past it a check
is left out with the note ``CHECK_STOPPED`` — the derivative itself is the same as without the
check — the program's comparison of the two engines goes on, and the summary counts the checks
left out apart from those that held.  Values here are by hand: ∫₀¹ [x ≤ θ] dx = θ, so D⟦p⟧ = 1
(Fig. 1), and ∫₀¹ [x ≤ a]·x dx = a²/2, so D⟦p⟧ = a.
"""

from langur import exact as api
from langur import frontend
from langur.fuzz import campaign, compare

FIG1 = "param theta = 0.5\nint ([0, 1]) [x <= theta] d(x)\n"
TWO = "param a = 0.3\nparam b = 0.6\nint ([0, 1]) [x <= a] * x + [x >= b] d(x)\n"


def _program(text):
    return frontend.load_text(text, "t.lgr").program


def test_no_budget_checks_as_before():
    r = api.exact_deriv(_program(FIG1), {"theta": 0.5}, {"theta": 1})
    assert float(r.value) == 1.0
    assert r.theorem_8_1 is not None and r.theorem_8_1.holds is True
    assert api.CHECK_STOPPED not in r.notes


def test_a_spent_budget_leaves_the_check_out_not_the_derivative():
    program = _program(FIG1)
    stopped = api.exact_deriv(program, {"theta": 0.5}, {"theta": 1}, check_seconds=0.0)
    plain = api.exact_deriv(program, {"theta": 0.5}, {"theta": 1}, check=False)
    assert stopped.theorem_8_1 is None
    assert api.CHECK_STOPPED in stopped.notes
    assert (stopped.value, stopped.regular, stopped.boundary) == (plain.value, plain.regular, plain.boundary)
    assert float(stopped.value) == 1.0


def test_a_campaign_counts_checks_left_out_apart(monkeypatch):
    full = compare.compare_text(TWO, samples=4000, isolate=False)
    assert full.status == "agree", full.reason
    monkeypatch.setattr(compare, "CHECK_SHARE", 0.0)
    compare._reference.clear()
    cut = compare.compare_text(TWO, samples=4000, isolate=False)
    compare._reference.clear()
    assert cut.status == "agree", cut.reason
    # the same comparisons of the engines, less the two Theorem 8.1 rows
    assert [r.quantity for r in cut.rows] == [r.quantity for r in full.rows if r.quantity != "theorem_8_1"]
    by = {(r.quantity, r.wrt): r.exact for r in full.rows}
    assert by[("derivative", "a")] == 0.3 and by[("derivative", "b")] == -1.0  # a and −1, by hand
    assert all(r.exact == by[(r.quantity, r.wrt)] for r in cut.rows)
    assert sorted(f for f in cut.findings if "Theorem" in f) == [
        "Theorem 8.1 not checked for a: its CPU budget was spent",
        "Theorem 8.1 not checked for b: its CPU budget was spent"]
    s = campaign.FuzzSummary(2, 0, 4000, results=[full, cut])
    assert s.theorem_counts() == {"checked": 2, "undecided": 0, "budget": 2, "not_computed": 0}
