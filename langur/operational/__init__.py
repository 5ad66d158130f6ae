"""The operational semantics of Langur as a Monte Carlo engine (paper §9, Appendix D/E).

The second, independent implementation of ⟦p⟧ and ⦇p⦈ (the symbolic engine is the reference).
It shares only the core layer (:mod:`langur.core`, :mod:`langur.primitives`, :mod:`langur.modules`,
:mod:`langur.diagnostics`) with the rest of the workbench and never uses sympy
(``proofs_tests/test_layers.py`` checks both).

API::

    estimate_value(program_or_loaded, params, *, samples=10000, seed=0, method="uniform",
                   sites="inlined", cache=CACHE) -> ValueEstimate (value, stderr, samples, seed, …)
    estimate_derivative(program_or_loaded, params, direction, *, samples=10000, seed=0,
                        method="uniform", sites="inlined", cache=CACHE)
        -> DerivativeEstimate (… and regular, boundary, standard_ad: Estimate(value, stderr))
    cache_stats() -> {"compiled": [(kind, module, name), …], "hits", "units", "last_link"} (of CACHE)
    reset_cache_stats(), clear_cache(), link(loaded, sites="inlined", cache), compile_program(program, cache)

``program_or_loaded`` is a core :class:`~langur.core.Program` (evaluated as is: the *inlined*
program) or a :class:`~langur.modules.Loaded` (then *linked* from separately compiled modules,
§9; see :mod:`.link`; ``sites`` chooses where its zero-set samplers come from).  ``params``
may omit parameters with defaults (for a Loaded); ``direction`` (γ') names parameters, the
others move by 0; a parameter with no value, a non-finite value or a direction naming a parameter
without a value raises :class:`~langur.values.ParameterError` (a ``KeyError``), as the exact engine does.  ``method`` is ``"uniform"``, ``"stratified"`` or ``"qmc"``.  ``seed``
makes the output bit-identical (one ``np.random.default_rng(seed)``, never global state).
``cache``: the :class:`CompileCache` of compiled units and linked programs (§9), CACHE or the caller's.

The estimator
-------------
Value.  With B = Program.box (evaluated at γ; the integrand vanishes outside it), V = vol(B)
and points ρ₁…ρ_N of a design in B (i.i.d. uniform; or R = 32 independent replicates of a jittered
grid or of a scrambled Sobol' net, each randomly shifted and tent-transformed: :mod:`.replicates`),

    ⟦int t d(x⃗)⟧(γ) ≈ V · (1/N) Σᵢ ⟦t⟧(ρᵢ, γ).

Derivative.  By Theorem 7.1, ⦇t⦈ = f·T₁ + Σ_k E_k·δ(π₀Ψ̂_k), one delta per *site* k (a syntactic
diffeomorphic conditional; inside a def, each call is its own site), so

    ⦇int t d(x⃗)⦈(γ,γ') = ∫_B f + Σ_k ∫ E_k δ(π₀Ψ̂_k).

* Regular part ∫_B f: f is the forward-mode tangent with every delta dropped (standard AD, the
  paper's Dˢ), sampled on the same design as the value.  Reported as ``regular`` and
  ``standard_ad``.
* Delta part (``boundary``).  E_k obeys Fig. 8 with E_k(c) = E_k(x) = 0: sums add, products
  E_k(t)·⟦s⟧ + E_k(s)·⟦t⟧, primitives f'(⟦t⟧)·E_k(t), conditionals select, and site k itself adds
  (D_γ π₀Ψ̂_k·γ')·(⟦s⟧ − ⟦r⟧).  With the change of variables u = Ψ̂_k(x) (LANGUAGE.md §4),

      ∫ E_k δ(π₀Ψ̂_k) dx = Σ_b ∫_{U'} [guards_b ≥ 0] · E_k(Ψ̂_b⁻¹(0,u')) · |det DΨ̂_b⁻¹(0,u')| du',

  summed over every inverse branch b (x² − a has two).  U' is a box containing every u' whose
  preimage lies in B: for a completed condition the other variables' own intervals; for a
  declared Ψ̂ whose other components are not variables, an interval enclosure of Ψ̂[1:] over B.
  The engine draws a design of N points u'ⱼ in U' and estimates the site by
  vol(U') · (1/N) Σⱼ Σ_b [guards ≥ 0]·E_k(x_bj)·|det DΨ̂_b⁻¹(0,u'ⱼ)|, with x_bj = Ψ̂_b⁻¹(0, u'ⱼ).
  The Jacobian is computed by the engine's own forward mode through the compiled inverse branch
  (one pass per input).  In one variable U' is a point: each root is evaluated once, exactly
  (standard error 0, the sifting property).  Sites whose condition reads no parameter that γ'
  moves (such as a fixed domain bound) have D_γ π₀Ψ̂·γ' ≡ 0 and are skipped.

Why unbiased: each design point is uniform on its box (uniform: i.i.d.; stratified and qmc:
marginally, through each replicate's random shift), so each term's expectation is the integral it
estimates.  Nothing
relies on a particular variable order, on Ψ̂'s other coordinates being the original variables, on
a single root, or on fixed bounds: the domain's indicators [x ≥ l(γ)] are sites like any other
(Leibniz rule), and points outside B score 0 through those indicators, evaluated at the point
(``≥ 0`` holds at exactly 0, the paper's convention).

Folds: where an inverse branch folds (a guard vanishes, e.g. a circle x² + y² ≤ r² solved for
y = ±√(r² − x²)), |det DΨ̂_b⁻¹| grows like 1/√(distance to the fold): integrable but not
square-integrable.  With a 1-dimensional u' (two variables) the design is mapped through an exact
change of variables that vanishes quadratically at the guards' roots (``SiteSampler.fold_map``),
which makes the variance finite (still unbiased: it is a change of variables, whatever the roots
found).  With u' of dimension ≥ 2 (three or more variables) folds are not treated: the estimator
stays unbiased but its variance is (logarithmically) infinite and the standard error unreliable.

Limits: if no finite box encloses a zero set's
coordinates u' (Ψ̂'s other components have a pole over the domain), the boundary estimate is NaN
rather than biased.  A ``var`` argument that is not
a plain variable makes the program evaluate inlined (see :mod:`.link`).

Standard errors and variance sources: the sample standard deviation over i.i.d. points / √N;
for stratified and qmc designs the spread of the R = 32 independent replicates' means / √R,
widened by Student's t for their R − 1 degrees of freedom (:mod:`.replicates`, :mod:`.student`;
shifting each replicate keeps a jump from making them all err alike, finding F0).  The regular
part, the value and each site use independent draws, so variances add.  Variance comes from the
integrand's variation over B, from E_k's variation along each zero set (none in one variable),
and from the Jacobian weights; a site whose enclosure U' is much larger than its zero set's image
wastes samples (more variance, no bias).

Separate compilation: :mod:`.link`.  The naive per-sample pure-Python evaluator used as the
benchmark baseline and as a cross-check: :mod:`.naive`.
"""

from .estimate import MAX_TREE_NODES, TooLarge, estimate_derivative, estimate_value
from .link import CACHE, CompileCache, cache_stats, clear_cache, compile_program, link, reset_cache_stats

__all__ = [
           "CACHE",
           "MAX_TREE_NODES",
           "CompileCache",
           "TooLarge",
           "cache_stats",
           "clear_cache",
           "compile_program",
           "estimate_derivative",
           "estimate_value",
           "link",
           "reset_cache_stats",
]
