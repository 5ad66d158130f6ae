"""Values of a rational closed form modulo a prime (issue 15).  Equal expressions have equal
values, so equal residues; values that differ differ modulo a large prime but for a coincidence
(``local._near_form`` tells sympy's terms apart by them, and counts a coincidence against itself;
:func:`langur.symbolic.rational.residue`).
"""

from __future__ import annotations

from functools import lru_cache

from langur.symbolic.arithmetic import Arithmetic


class NoResidue(Exception):
    """No residue: the prime divides a denominator, a power below 1 of 0, or |·|."""


@lru_cache(maxsize=None)
def residues(prime: int) -> Arithmetic:
    """The arithmetic modulo ``prime`` (a point's values given as residues)."""
    def const(n, d):
        q = d % prime
        if q == 0:
            raise NoResidue()
        return n * pow(q, -1, prime) % prime

    def total(xs):
        out = 0
        for v in xs:
            out = (out + v) % prime
        return out

    def product(xs):
        out = 1
        for v in xs:
            out = out * v % prime
        return out

    def inverse(v):
        if v == 0:
            raise NoResidue()
        return pow(v, -1, prime)

    def sign(v):
        raise NoResidue()  # (no order modulo a prime: no |·|)

    return Arithmetic(
        f"residues mod {prime}", const=const, read=lambda z: z, total=total, product=product,
        add=lambda u, v: (u + v) % prime, mul=lambda u, v: u * v % prime,
        raise_=lambda v, k: pow(v, k, prime), inverse=inverse, sign=sign, neg=lambda v: -v % prime,
        failure=NoResidue)


__all__ = ["NoResidue", "residues"]
