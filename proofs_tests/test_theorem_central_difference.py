"""Theorem 8.1's central difference of ⟦p⟧'s closed form (langur.theorem._central_difference) on a
form whose 30-digit values carry imaginary noise: √ of a radicand that is identically 0 (a random
program of the seeded campaign, `langur fuzz --seed 1`, no. 437, gave such a form; its check was
"not computed: 'Cannot convert complex to float'")."""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy as sp

from langur import theorem

b = sp.Symbol("b", real=True)
ROOT = sp.sqrt(30) / 10
# −4b² + 8b(b − √30/10) − 4(b − √30/10)² + 6/5 = −4·(√30/10)² + 6/5 = 0 for every b
ZERO_RADICAND = -4 * b**2 + 8 * b * (b - ROOT) - 4 * (b - ROOT) ** 2 + sp.Rational(6, 5)


def test_the_radicand_is_zero_and_sympy_evaluates_the_difference_with_imaginary_noise():
    assert sp.expand(ZERO_RADICAND) == 0
    e, h, p = b**3 + sp.sqrt(ZERO_RADICAND), sp.Rational(1, 10**8), sp.Rational(71, 100)
    z = complex(sp.N((e.xreplace({b: p + h}) - e.xreplace({b: p - h})) / (2 * h), 30))
    assert z.imag != 0.0 and abs(z.imag) < 1e-40  # the noise this test is about


def test_a_real_form_with_imaginary_noise_has_its_real_central_difference():
    expr = b**3 + sp.sqrt(ZERO_RADICAND)
    got = theorem._central_difference(expr, {"b": Fraction(71, 100)}, {"b": 1})
    assert got == pytest.approx(3 * 0.71**2, rel=1e-12)  # d/db b³ (the root is 0 for every b)


def test_a_form_off_the_reals_is_an_error_that_says_so():
    with pytest.raises(ValueError, match="not real"):
        theorem._central_difference(b + sp.sqrt(b - 2), {"b": Fraction(71, 100)}, {"b": 1})
