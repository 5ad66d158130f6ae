"""Langur: a workbench for differentiating integrals with parametric discontinuities.

The executable companion to Michel et al., "Distributions for Compositionally Differentiating
Parametric Discontinuities" (OOPSLA 2024).  The core language is in :mod:`langur.core`; the front
end (parse, desugar, type-check) in :mod:`langur.frontend`; the exact semantics in
:mod:`langur.denote` and :mod:`langur.ddenote`; the Monte Carlo engine in :mod:`langur.operational`.
"""

__version__ = "0.1.0"
