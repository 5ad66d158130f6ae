"""Implicit roots in the exact engine (paper §7.2: a point of an inverse branch Ψ̂⁻¹ of a
diffeomorphism with no closed form, in ⟦p⟧'s and ⦇p⦈'s closed forms and the delta's change of
variables; issue 18): :class:`langur.core.ImplicitRoot` as a sympy function.  The Monte Carlo
engine has its own vectorized solver (no sympy there: :mod:`langur.operational.roots`).

The modules, each importing only those above it in this list:

* :mod:`.solvers` — one root of a function monotone on a bracket: to any precision (false
  position) and in doubles (Brent's method); no sympy;
* :mod:`.equations` — what is known of a root's equation beside its sympy term: its source place
  and leniency, its form up to its bound variable, its exact polynomial coefficients, and the
  refusal of more sign changes than the split (X316);
* :mod:`.evalf` — a root to the precision sympy's ``evalf`` asks, on brackets certified by
  interval enclosures or a Sturm sequence;
* :mod:`.lambdified` — a root in ``lambdify``'s compiled code, in doubles: indexed roots named by
  keys, certified once per box of the other symbols' values, remembered by their arguments;
* :mod:`.function` — :class:`ImplicitRootFn` (its derivative by the implicit function theorem,
  its printing) and :func:`implicit_root`, which builds one.

Here: what the rest of langur imports (``from langur.implicit import ImplicitRootFn``).
"""

from langur.implicit.function import ImplicitRootFn, implicit_root

__all__ = ["ImplicitRootFn", "implicit_root"]
