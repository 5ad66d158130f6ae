"""Fig. 1 of the paper in Teg, as one process computes it (not a test): ∫₀¹ [x < θ] dx and its
derivative in θ at θ = 0.5 — the program of ``examples/fig1.lgr``, written as Teg's README writes
it (its illustrative example), evaluated by its numpy backend with its default number of samples.

Run:  PYTHONPATH=DIR python bench/peer_programs/teg_fig1.py

DIR is a checkout of github.com/ChezJrk/Teg: this program imports Teg from there; none of Teg's
code is in this project.  ``bench/bench_issue15.py`` times this process beside
``langur eval examples/fig1.lgr --engine mc`` (issue 15's one-shot target).
"""

from teg import IfElse, Teg, TegVar, Var
from teg.derivs import FwdDeriv
from teg.eval.numpy_eval import evaluate

x, theta = TegVar("x"), Var("theta", 0.5)
integral = Teg(0, 1, IfElse(x < theta, 1, 0), x)
print("value", evaluate(integral))
print("d/dtheta", evaluate(FwdDeriv(integral, [(theta, 1)])))
