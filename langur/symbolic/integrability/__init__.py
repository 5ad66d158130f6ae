"""Whether an integrand is integrable on its region: an integral that does not exist (LANGUAGE.md §3).

⟦int t d(x⃗)⟧ = ∫ ⟦t⟧ (Fig. 12) exists only when ⟦t⟧ is integrable on the box (Prop. 7.1, Theorem 7.1
assume it: "if ⟦t⟧ is locally integrable").  A principal value is not an integral: ``1/t − 1/(1 − t)``
on [0, 1] diverges at both ends although its symmetric cancellation is 0, and quadrature can
converge to that 0 without a warning; a closed form evaluated at the ends can too (``x/(x²+y²)²`` on
[−1, 1]², odd in x).  This package decides it, once, for the exact engine (:func:`divergence` and
:func:`delta_divergence`, which ``langur.denote.require_defined`` asks after integrating) and for the
linter's X311–X313 (``langur.lint.singular``, through :func:`piece_blowups`, :func:`delta_blowups` and
:func:`blowups`).

One simply decomposable piece ``Π [c ≥ 0] · w`` (Def. 6.2) at given parameter values is integrable
on its closed region R̄ (the box cut by the conditions) unless ``w`` blows up somewhere on R̄. It
can only blow up on the zero set of a *pole base* ``g``: the base of a negative power (``1/x^2`` is
``x^-2``, ``1/sqrt(x)`` is ``x^(-1/2)``), ``cos`` of the argument of a ``tan``, or ``log(b)`` in a
denominator. Near a set S of codimension c in R̄ on which ``|w| ~ dist(·, S)^-α``,

    ∫ |w| < ∞  ⇔  α < c                                    (polar coordinates around S)

so ``1/x`` on [0, 1] (α = 1 on a point of ℝ¹) diverges, ``1/sqrt(x)`` (α = ½) does not,
``1/(x²+y²)`` at the corner of [0, 1]² (α = 2 at a point of ℝ²) diverges, ``1/sqrt(x²+y²)`` does
not, and ``1/(x+y)`` at that corner (α = 1) does not; ``w²`` (the variance of a uniform Monte

Its modules, one job each (every zero is checked, nothing is assumed):

* :mod:`.region` — R̄, the box cut by a piece's conditions, sampled on a grid;
* :mod:`.zerosets` — where a pole base vanishes on R̄, and the codimension of that set;
* :mod:`.verdicts` — the exponent α along directions into R̄, and the verdict α against c;
* :mod:`.finite` — a weight certainly finite on the whole box (nothing to look for);
* :mod:`.deltas` — ⦇t⦈'s delta terms pulled back to their zero sets (X313's delta half);
* :mod:`.driver` — piece by piece: the weights of ⟦t⟧'s or ⦇t⦈'s pieces, and the exact engine's verdict.
"""

from .deltas import delta_blowups
from .driver import TIME_LIMIT, Divergent, delta_divergence, divergence, piece_blowups
from .finite import ZERO_FREE_DEGREE, finite_on_box
from .region import GRID, Region, Undecidable
from .verdicts import Blowup, Verdict, blowups, blowups_on, decide, growth
from .zerosets import DIRECTIONS, pole_bases, sites

__all__ = ["DIRECTIONS", "GRID", "TIME_LIMIT", "ZERO_FREE_DEGREE", "Blowup", "Divergent", "Region", "Undecidable",
           "Verdict", "blowups", "blowups_on", "decide", "delta_blowups", "delta_divergence", "divergence", "finite_on_box",
           "growth", "piece_blowups", "pole_bases", "sites"]
