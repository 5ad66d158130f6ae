"""Independent adaptive quadrature of pieces at the evaluation point (cross-check and fallback;
paper §8.2's ⟦p⟧ at a point, §7.3's delta pieces, Theorem 8.1's finite differences).

Nothing here uses the closed-form machinery of :mod:`langur.symbolic.regions`: every integrand is
evaluated numerically (``lambdify`` at the parameter values) and integrated with nested
``scipy.integrate.quad``.  At each level the range of the current variable is split at the
breakpoints of the conditions that depend only on it and on outer variables:

* the roots given by a condition's Psi when it is solved for that variable (inverse branches at
  ``u0 = 0``, guards checked), and
* numerically found roots: sign changes of the condition on a grid refined with ``brentq``, and
  boundaries of the set where the condition is defined (NaN, e.g. ``sqrt`` of a negative number)
  refined by bisection.

On each sub-interval the conditions are constant (tested at the midpoint), so ``quad`` only ever
sees smooth integrands.  Delta pieces (LANGUAGE.md §4) are integrated over ``u'`` after the change
of variables; the Jacobian used here is ``1/|det DΨ̂(x)|`` at ``x = Ψ̂_b⁻¹(0, u')`` (the forward
map's derivative), independent of the inverse-map Jacobian used by the closed form.

The modules, each importing only those above it in this list:

* :mod:`.tolerance` — tolerances, thresholds, the outermost level's loosening;
* :mod:`.compiling` — sympy expressions to cached ``math``/``mpmath``/numpy functions;
* :mod:`.gausskronrod` — QUADPACK's 21-point panel, vectorized;
* :mod:`.roots` — a condition's roots in one variable (polynomial, grid + ``brentq``, hidden pairs);
* :mod:`.problem` — :class:`NumCond`, :class:`NumProblem`, :class:`UndefinedIntegral`;
* :mod:`.adaptive` — one level's ``quad``, made safe and honest;
* :mod:`.kinks` — breakpoints and kinks of a level (critical points, crossings), and which kinks
  are tangency points (integrated after a substitution by :mod:`.nested`);
* :mod:`.fold` — integration next to a delta's fold (substitution, allowances, time limit);
* :mod:`.foldcurve` — where the fold curve turns (outer kinks, guards through turning points);
* :mod:`.brackets` — what an implicit root's bracket implies;
* :mod:`.rounding` — how far a breakpoint's float may be from the true boundary (the error bound's
  share for the breakpoints' rounding, whatever the program's scale);
* :mod:`.wide` — breakpoints where the mass may hide on a range wide for its weight (> 10⁴ of its scale);
* :mod:`.enclosed` — a piece's integral enclosed by interval arithmetic: a proof, which backs a
  quadrature's error bound or finds the mass it missed (it imports none of the modules here);
* :mod:`.nested` — the nested integral of one problem;
* :mod:`.pieceproblems`, :mod:`.deltaproblems` — the pieces' and delta pieces' fronts.

Here: what the rest of langur imports.
"""

from langur.symbolic.quadrature.compiling import printable
from langur.symbolic.quadrature.deltaproblems import quad_delta_pieces
from langur.symbolic.quadrature.pieceproblems import quad_pieces
from langur.symbolic.quadrature.problem import BeyondRange, NumProblem, UndefinedIntegral
from langur.symbolic.quadrature.tolerance import looseness, outer_tolerance
from langur.symbolic.quadrature.wide import ESTIMATE

__all__ = ["ESTIMATE", "BeyondRange", "NumProblem", "UndefinedIntegral", "looseness", "outer_tolerance", "printable", "quad_delta_pieces",
           "quad_pieces"]
