"""Fig. 1 of the paper in Potto, as one process computes it (not a test): ∫₀¹ [x ≤ θ] dx and its
derivative in θ at θ = 0.5 — the program of ``examples/fig1.lgr``, written as Potto's README writes
it (its illustrative example), evaluated with Potto's default number of samples.

Run:  PYTHONPATH=DIR python bench/peer_programs/potto_fig1.py

DIR is a checkout of github.com/divicomp/potto: this program imports Potto from there; none of
Potto's code is in this project.  ``bench/bench_issue15.py`` times this process beside
``langur eval examples/fig1.lgr --engine mc`` (issue 15's one-shot target).
"""

from potto import BoundedLebesgue, Const, FlipShift, IfElse, Int, TegVar, Var, VarVal, deriv, evaluate

x, theta, dtheta = TegVar("x"), Var("theta"), Var("dtheta")
integral = Int(IfElse(FlipShift((theta,), (x,)), Const(1), Const(0)), BoundedLebesgue(0, 1, x))
at = VarVal({theta.name: 0.5, dtheta.name: 1})
print("value", evaluate(integral, at))
print("d/dtheta", evaluate(deriv(integral, {theta.name: dtheta.name}), at))
