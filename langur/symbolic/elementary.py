"""Deciding early that sympy will not find an antiderivative (issue 15, the exact engine's time).

The exact engine asks sympy for antiderivatives of smooth weights in one variable
(:func:`langur.symbolic.antiderivatives.antiderivative`).  When there is none in elementary terms, sympy's
algorithms (heuristic Risch, full Risch, Meijer G) do not say so quickly: they run until their
time limit, seconds per weight, and the piece then falls back to quadrature anyway.
:func:`hopeless` recognises the commonest shapes of such weights from their structure alone, so
that the engine goes straight to its rigorous quadrature (regions and delta sites still come from
the denotational side, so the answer stays independent of the Monte Carlo engine).

The weight is expanded into terms (sympy integrates term by term); each term is a product of
factors, classified in the variable ``v``:

* *polynomial*: a polynomial in ``v`` (a constant included);
* *exponential*: ``exp``, ``sin``, ``cos``, ``sinh``, ``cosh`` of an affine function of ``v`` (and
  ``exp`` of a quadratic: a Gaussian, integrated by completing the square);
* *other*: anything else (powers of non-polynomials, ``1/q(v)``, ``log``, ``atan``, compositions).

A term is integrable in elementary terms in the classical cases: polynomial × products of
exponentials (repeated integration by parts); polynomial × one *other* factor that is itself
elementary to integrate against a polynomial — ``log``/``atan``/``asin``/``acos`` of a polynomial
or rational function, a power of a polynomial of degree at most two (``√(a + x²)``,
``(x + 1)^(3/2)``), a rational function.  Everything else — an exponential times an algebraic or
rational factor (``√x·eˣ`` is erf, ``eˣ/x`` is Ei), two *other* factors (``√(1 + x²)·atan(x²)``,
``atan(x)/x`` is a dilogarithm), a transcendental function of a non-affine argument
(``sin(x²)`` is Fresnel, ``exp(x³)``), a root of a polynomial of degree three or more (elliptic) —
is reported hopeless, with the reason.  The test is conservative about what it calls hopeless
(only these shapes; a factor it does not classify leaves the term to sympy), never about closed
forms: a weight it lets through is still verified by differentiation
(:func:`~langur.symbolic.antiderivatives._derivative_matches`).

Four classical shapes are integrated here without sympy's ``integrate`` (milliseconds, and
within no time budget): a polynomial times ``exp``/``sin``/``cos``/``sinh``/``cosh`` of an affine
argument (:func:`exponential_antiderivative`, by parts), a polynomial times a rational power of an
affine function (:func:`affine_power_antiderivative`, substitution), the same times powers of its
logarithm (:func:`power_log_antiderivative`, substitution and parts), and a polynomial times a
normal density (:func:`gaussian_antiderivative`, completing the square: ``erf``).

One shape is rewritten first (:func:`sign_split`): atan2's angle ``acos(c/√(c² + y²))`` of an affine
``y`` and the square roots of its derivative hide ``|y|``; written ``P + sign(y)·Q`` with ``P``, ``Q``
smooth, each is integrated as any weight (:func:`langur.symbolic.antiderivatives.antiderivative`).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from langur.symbolic.walks import any_node

#: Functions that are exponentials of an affine argument for this purpose (their products with
#: polynomials integrate by parts in elementary terms).
EXPONENTIAL = (sp.exp, sp.sin, sp.cos, sp.sinh, sp.cosh)
#: Functions whose product with a polynomial of the variable integrates in elementary terms when
#: their argument is a polynomial or rational function of it (integration by parts leaves a
#: rational or algebraic integrand).
BY_PARTS = (sp.log, sp.atan, sp.asin, sp.acos, sp.asinh, sp.acosh, sp.atanh)
#: Weights larger than this (operations) are not classified (the expansion itself would cost).
MAX_OPS = 400


def _degree(e, v) -> int | None:
    """The degree of ``e`` as a polynomial in ``v`` (None when it is not one)."""
    if v not in e.free_symbols:
        return 0
    try:
        p = sp.Poly(e, v)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if any(v in c.free_symbols for c in p.all_coeffs()):
        return None
    return p.degree()


def _rational(e, v) -> bool:
    n, d = sp.fraction(sp.together(e))
    return _degree(n, v) is not None and _degree(d, v) is not None


def _kind(f, v) -> tuple[str, str]:
    """``(kind, reason)`` of one factor: polynomial, exponential, gaussian, alone (an *other*
    factor that integrates against a polynomial), elliptic (a root of a square-free polynomial of
    degree ≥ 3), hopeless, or unknown (a shape not classified: sympy is asked)."""
    if v not in f.free_symbols:
        return "polynomial", ""
    if _degree(f, v) is not None:
        return "polynomial", ""
    if isinstance(f, EXPONENTIAL):
        d = _degree(f.args[0], v)
        if d is not None and d <= 1:
            return "exponential", ""
        if isinstance(f, sp.exp) and d == 2:
            return "gaussian", ""
        if d is not None:
            return "hopeless", f"{f.func.__name__} of a polynomial of degree {d}"
        return "unknown", ""
    if isinstance(f, BY_PARTS):
        return ("alone", "") if _rational(f.args[0], v) else ("unknown", "")
    if isinstance(f, sp.Pow):
        base, ex = f.args
        if v in ex.free_symbols or not ex.is_Rational:
            return "unknown", ""
        d = _degree(base, v)
        if d is not None and (ex.is_Integer or d <= 2):
            return "alone", ""  # 1/q(v)^k: partial fractions; (a + b·x + c·x²)^(p/q): Euler
        if d is not None and sp.degree(sp.sqf_part(base, v), v) >= 3:
            return "elliptic", f"a root of a polynomial of degree {d}"
        if d is None and ex.is_Integer and _rational(base, v):
            return "alone", ""
    return "unknown", ""


def _term(t, v) -> str:
    """Why the term ``t`` has no elementary antiderivative in ``v`` that sympy will find (empty:
    it may have one)."""
    factors = [f for f in sp.Mul.make_args(t) if v in f.free_symbols]
    kinds = [_kind(f, v) for f in factors]
    for k, why in kinds:
        if k == "hopeless":
            return why
    names = [k for k, _ in kinds]
    if "unknown" in names:
        return ""
    if names == ["elliptic"]:
        return kinds[0][1] + " (an elliptic integral)"
    if "elliptic" in names:
        return ""  # x²·√(x³ + 1) is elementary (substitution): let sympy look
    others = names.count("alone")
    transcendental = names.count("exponential") + names.count("gaussian")
    if others and transcendental:
        return "an exponential or trigonometric factor times an algebraic, rational or logarithmic one"
    if others > 1:
        rest = sp.Mul(*[f for f, k in zip(factors, names) if k == "alone"])
        if _rational(rest, v):
            return ""  # a rational function after all (partial fractions)
        return "a product of two non-polynomial factors"
    return ""


def hopeless(w, v) -> str:
    """Why sympy will not find an elementary antiderivative of the smooth weight ``w`` in ``v``
    (one of the shapes of the module docstring), or the empty string when it may."""
    w = sp.sympify(w)
    if v not in w.free_symbols or sp.count_ops(w) > MAX_OPS:
        return ""
    try:
        terms = sp.Add.make_args(sp.expand(sp.powsimp(w), power_exp=False, log=False, multinomial=False))
    except Exception:  # noqa: BLE001 - classification is an optimisation: let sympy try
        return ""
    for t in terms:
        why = _term(t, v)
        if why:
            return f"no elementary antiderivative expected in {v} ({why}: {t})"
    return ""


def polynomial_antiderivative(w, v):
    """The antiderivative of ``w`` in ``v`` when ``w`` is a polynomial in ``v`` (coefficients in
    the parameters and outer variables), by the power rule; None otherwise."""
    if not w.is_polynomial(v):
        return None
    total = sp.Integer(0)
    for t in sp.Add.make_args(sp.expand(w)):
        c, e = t.as_coeff_exponent(v)
        if v in c.free_symbols or not (e.is_Integer and e >= 0):
            return None
        total += c * v ** (e + 1) / (e + 1)
    return total


def _affine(e, v):
    """``(k, c)`` with ``e = k·v + c`` and ``k`` free of ``v`` and non-zero, else None."""
    try:
        p = sp.Poly(e, v)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if p.degree() != 1 or any(v in c.free_symbols for c in p.all_coeffs()):
        return None
    k, c = p.all_coeffs()
    return k, c


#: The n-th iterated antiderivative of f(k·v + c) for the functions whose iterates cycle.
_CYCLE = {sp.sin: (lambda a: -sp.cos(a), lambda a: -sp.sin(a), sp.cos, sp.sin),
          sp.cos: (sp.sin, lambda a: -sp.cos(a), lambda a: -sp.sin(a), sp.cos),
          sp.sinh: (sp.cosh, sp.sinh), sp.cosh: (sp.sinh, sp.cosh), sp.exp: (sp.exp,)}


def exponential_antiderivative(w, v, divisors: list | None = None):
    """The antiderivative of ``w`` in ``v`` when every term of ``w`` is a polynomial in ``v`` times
    at most one of ``exp``, ``sin``, ``cos``, ``sinh``, ``cosh`` of an affine function ``k·v + c``
    (repeated integration by parts: ∫P·f = Σⱼ (−1)ʲ P⁽ʲ⁾ F₍ⱼ₊₁₎ with F₍ₙ₎ the n-th iterate of f,
    F₍ₙ₎ = f₍ₙ₎(k·v + c)/kⁿ); None otherwise.  The form is the generic one (``k ≠ 0``), like
    sympy's with ``conds="none"``: each ``k`` is appended to ``divisors`` for callers to check at
    the evaluation point."""
    if v not in w.free_symbols or sp.count_ops(w) > MAX_OPS:
        return None
    total = sp.Integer(0)
    for t in sp.Add.make_args(sp.expand(w, power_exp=False, log=False)):
        fs = [f for f in sp.Mul.make_args(t) if v in f.free_symbols]
        special = [f for f in fs if isinstance(f, tuple(_CYCLE))]
        if not special:
            plain = polynomial_antiderivative(t, v)
            if plain is None:
                return None
            total += plain
            continue
        if len(special) != 1:
            return None
        f = special[0]
        kc = _affine(f.args[0], v)
        if kc is None:
            return None
        k, _ = kc
        rest = sp.Mul(*[g for g in sp.Mul.make_args(t) if g is not f])
        try:
            p = sp.Poly(rest, v)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            return None
        if any(v in c.free_symbols for c in p.all_coeffs()):
            return None
        if divisors is not None:
            divisors.append(k)
        cycle = _CYCLE[type(f)]
        derivative = p.as_expr()
        for j in range(p.degree() + 1):
            iterate = cycle[j % len(cycle)](f.args[0]) / k ** (j + 1)
            total += (-1) ** j * derivative * iterate
            derivative = sp.diff(derivative, v)
    return total


def _in_u(rest, v, u, k, c):
    """``rest`` (a factor of a term) as a polynomial in ``u = k·v + c`` (``v = (u − c)/k``), or None
    when it is not one."""
    try:
        p = sp.Poly(sp.expand(rest.xreplace({v: (u - c) / k})), u)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if any(u in coeff.free_symbols or v in coeff.free_symbols for coeff in p.all_coeffs()):
        return None
    return p


def affine_power_antiderivative(w, v, divisors: list | None = None):
    """The antiderivative of ``w`` in ``v`` when every term of ``w`` is a polynomial in ``v`` times
    at most one power ``(k·v + c)^r`` (``r`` rational, not an integer): with ``u = k·v + c`` the
    term is a sum of powers of ``u`` (``v = (u − c)/k``), integrated by the power rule (the powers
    are never −1: ``r`` is not an integer); None for other shapes.  Each ``k`` is appended to
    ``divisors`` (the form needs ``k ≠ 0``)."""
    if v not in w.free_symbols or sp.count_ops(w) > MAX_OPS:
        return None
    u = sp.Dummy("u")
    total = sp.Integer(0)
    for t in sp.Add.make_args(sp.expand(w, power_exp=False, log=False)):
        powers = [f for f in sp.Mul.make_args(t) if isinstance(f, sp.Pow) and v in f.free_symbols
                  and f.exp.is_Rational and not f.exp.is_Integer]
        if not powers:
            plain = polynomial_antiderivative(t, v)
            if plain is None:
                return None
            total += plain
            continue
        if len(powers) != 1:
            return None
        f = powers[0]
        kc = _affine(f.base, v)
        if kc is None:
            return None
        k, c = kc
        if divisors is not None:
            divisors.append(k)
        p = _in_u(sp.Mul(*[g for g in sp.Mul.make_args(t) if g is not f]), v, u, k, c)
        if p is None:
            return None
        for (n,), coeff in p.terms():
            e = f.exp + n + 1
            total += coeff * f.base ** e / (e * k)
    return total


def power_log_antiderivative(w, v, divisors=None):
    """The antiderivative of ``w`` in ``v`` when every term of ``w`` is a polynomial in ``v`` times
    powers and logarithms of one affine function ``u = k·v + c``: ``u^r·log(u)^m`` (``r``
    rational, ``m`` a non-negative integer; ``√x·log x``, ``log(x)/x``, ``x²·log(x − a)²``, which
    :func:`hopeless` would call a product of two non-polynomial factors); None for other shapes.
    With ``v = (u − c)/k`` the term is a sum of ``u^s·log(u)^m``, each integrated by parts:
    ``∫ u^s log^m u du = u^(s+1) Σⱼ (−1)ʲ m!/(m − j)! log^(m−j)(u) / (s + 1)^(j+1)`` for ``s ≠ −1``,
    ``log^(m+1)(u)/(m + 1)`` for ``s = −1``.  Each ``k`` is appended to ``divisors`` (the form needs
    ``k ≠ 0``)."""
    if v not in w.free_symbols or not any_node(w, lambda node: isinstance(node, sp.log)) or sp.count_ops(w) > MAX_OPS:
        return None  # (without a logarithm: affine_power_antiderivative's, or sympy's)
    u = sp.Dummy("u", positive=True)
    total = sp.Integer(0)
    for t in sp.Add.make_args(sp.expand(w, power_exp=False, log=False, multinomial=False)):
        factors = [f for f in sp.Mul.make_args(t) if v in f.free_symbols]
        logs = [f for f in factors if isinstance(f, sp.log) or (isinstance(f, sp.Pow) and isinstance(f.base, sp.log)
                                                               and f.exp.is_Integer and f.exp > 0)]
        powers = [f for f in factors if isinstance(f, sp.Pow) and not isinstance(f.base, sp.log)
                  and f.exp.is_Rational and not (f.exp.is_Integer and f.exp >= 0)]
        if not logs and not powers:
            plain = polynomial_antiderivative(t, v)
            if plain is None:
                return None
            total += plain
            continue
        inner = {(f.args[0] if isinstance(f, sp.log) else f.base.args[0]) for f in logs} | {f.base for f in powers}
        if len(inner) != 1 or len(logs) > 1 or len(powers) > 1:
            return None
        base = inner.pop()
        kc = _affine(base, v)
        if kc is None:
            return None
        k, c = kc
        m = 0 if not logs else (1 if isinstance(logs[0], sp.log) else int(logs[0].exp))
        r = powers[0].exp if powers else sp.Integer(0)
        p = _in_u(sp.Mul(*[g for g in sp.Mul.make_args(t) if g not in logs and g not in powers]), v, u, k, c)
        if p is None:
            return None
        if divisors is not None:
            divisors.append(k)
        L = sp.log(base)
        for (n,), coeff in p.terms():
            s = r + n
            if s == -1:
                total += coeff * L ** (m + 1) / ((m + 1) * k)
            else:
                acc = sum((-1) ** j * sp.factorial(m) / sp.factorial(m - j) * L ** (m - j) / (s + 1) ** (j + 1)
                          for j in range(m + 1))
                total += coeff * base ** (s + 1) * acc / k
    return total


def gaussian_antiderivative(w, v):
    """The antiderivative of ``w`` in ``v`` when every term of ``w`` is a polynomial in ``v`` times
    ``exp`` of a quadratic ``A·v² + B·v + C`` whose ``A`` is a negative number (a normal density:
    ``A`` free of the parameters, so the form holds for all of them), else None.  With
    ``s = v + B/(2A)`` and ``α = −A``: ``∫ P·e^q = e^(C − B²/4A) Σ cₙ Jₙ(s)`` where
    ``P = Σ cₙ sⁿ``, ``J₀ = √π/(2√α)·erf(√α s)``, ``J₁ = −e^(−α s²)/(2α)`` and
    ``Jₙ = −s^(n−1) e^(−α s²)/(2α) + (n − 1)/(2α)·Jₙ₋₂`` (integration by parts)."""
    if v not in w.free_symbols or sp.count_ops(w) > MAX_OPS:
        return None
    total = sp.Integer(0)
    for t in sp.Add.make_args(sp.expand(sp.powsimp(sp.expand(w), combine="exp"), power_exp=False, log=False)):
        t = sp.powsimp(t, combine="exp")
        exps = [f for f in sp.Mul.make_args(t) if isinstance(f, sp.exp) and v in f.free_symbols]
        if not exps:
            plain = polynomial_antiderivative(t, v)
            if plain is None:
                return None
            total += plain
            continue
        if len(exps) != 1:
            return None
        try:
            q = sp.Poly(sp.expand(exps[0].args[0]), v)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            return None
        if q.degree() != 2 or any(v in c.free_symbols for c in q.all_coeffs()):
            return None
        A, B, C = q.all_coeffs()
        if not (A.is_number and A.is_negative):
            return None
        rest = sp.Mul(*[f for f in sp.Mul.make_args(t) if f is not exps[0]])
        s = sp.Dummy("s")
        shift = B / (2 * A)
        try:
            p = sp.Poly(sp.expand(rest.xreplace({v: s - shift})), s)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            return None
        if any(v in c.free_symbols or s in c.free_symbols for c in p.all_coeffs()):
            return None
        alpha = -A
        g = sp.exp(-alpha * s**2)
        J = [sp.sqrt(sp.pi) / (2 * sp.sqrt(alpha)) * sp.erf(sp.sqrt(alpha) * s), -g / (2 * alpha)]
        for n in range(2, p.degree() + 1):
            J.append(-s ** (n - 1) * g / (2 * alpha) + (n - 1) / (2 * alpha) * J[n - 2])
        inner = sp.Add(*[coeff * J[n] for (n,), coeff in p.terms()])
        total += sp.exp(C - B**2 / (4 * A)) * inner.xreplace({s: v + shift})
    return total


@dataclass(frozen=True)
class SignSplit:
    """``w = P + sign(s)·Q`` wherever ``s ≠ 0`` (:func:`sign_split`): ``s`` affine in the variable,
    ``P`` and ``Q`` free of ``|s|``; ``divisors``: what the identities divide by (non-zero needed)."""

    s: sp.Expr
    P: sp.Expr
    Q: sp.Expr
    divisors: tuple


def _square_of_affine(e, v):
    """``(A, s)`` with ``e = A·s²``, ``s = v + d`` (``A``, ``d`` free of ``v``, ``A`` a positive
    number), else None."""
    try:
        p = sp.Poly(sp.expand(e), v)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if p.degree() != 2 or any(v in c.free_symbols for c in p.all_coeffs()):
        return None
    A, B, C = p.all_coeffs()
    if not (A.is_number and A.is_positive) or sp.expand(B**2 - 4 * A * C) != 0:
        return None
    return A, v + sp.cancel(B / (2 * A))


def _is_half_odd(e) -> bool:
    return e.is_Rational and not e.is_Integer and (2 * e).is_Integer


def sign_split(w, v) -> SignSplit | None:
    """``w`` as ``P + sign(s)·Q`` when the only non-smooth-looking parts of it are the absolute
    values hidden in atan2's desugaring (LANGUAGE.md §1: ``atan2(y, x)`` is ``acos(x/√(x² + y²))``
    under ``[y ≥ 0]``) with ``y = s`` affine in ``v`` and ``x = c`` free of it: ``acos(c/√(c² + A·s²))``
    (an even function of s) and the square roots ``√(A·s²/D)^(n/2)`` of its derivative
    (``√(1 − c²/(c² + s²))`` = |s|/√(c² + s²), which the chain rule writes so:
    :func:`langur.sympy_bridge.derivative_function`), or ``|A'·s|`` itself.  With |s| = sign(s)·s:

    * ``acos(c/√(c² + U²)) = (π/2)(1 − sign c) + sign(s)·atan(U/c)``, U = √A·s (c ≠ 0);
      ``asin = π/2 − acos``;
    * ``(A·s²/D)^e = sign(s)·s^(2e)·(A/D)^e`` for 2e odd (sign(s)^(2e) = sign(s) where s ≠ 0).

    Then ``P``, ``Q`` are the even and odd parts in sign(s) = ±1.  sympy's own antiderivatives of
    such weights hold on one side of s = 0 only (``t·acos(−1/√(t² + 1)) − log(1/√(t² + 1))``), fail
    the check by differentiation, and take it seconds to find or time out (``atan2(x − a, −1)``:
    36 CPU s for its derivative).  None when ``w`` has no such part, or more than one ``s``."""
    if v not in w.free_symbols or sp.count_ops(w) > MAX_OPS or not any_node(
            w, lambda e: isinstance(e, (sp.acos, sp.asin, sp.Abs))
            or (isinstance(e, sp.Pow) and _is_half_odd(e.exp))):
        return None
    found: dict = {}  # s → True (one s only)
    divisors: list = []

    def angle(f):
        g = f.args[0]
        if v not in g.free_symbols:
            return None
        c = sp.Mul(*[x for x in sp.Mul.make_args(g) if v not in x.free_symbols])
        rest = [x for x in sp.Mul.make_args(g) if v in x.free_symbols]
        if len(rest) != 1 or not (isinstance(rest[0], sp.Pow) and rest[0].exp == -sp.S.Half):
            return None
        sq = _square_of_affine(rest[0].base - c**2, v)
        if sq is None:
            return None
        A, s = sq
        found[s] = True
        divisors.append(c)
        out = sp.pi / 2 * (1 - sp.sign(c)) + sp.sign(s) * sp.atan(sp.sqrt(A) * s / c)
        return out if isinstance(f, sp.acos) else sp.pi / 2 - out

    def root(f):
        if v not in f.base.free_symbols:
            return None
        n, d = sp.fraction(sp.together(f.base))
        sq = _square_of_affine(n, v)
        if sq is None:
            return None
        A, s = sq
        found[s] = True
        return sp.sign(s) * s ** (2 * f.exp) * (A / d) ** f.exp

    def absolute(f):
        sq = _square_of_affine(f.args[0] ** 2, v)
        if sq is None:
            return None
        A, s = sq
        found[s] = True
        return sp.sqrt(A) * sp.sign(s) * s

    def rewrite(e):
        if isinstance(e, (sp.acos, sp.asin)):
            return angle(e)
        if isinstance(e, sp.Abs):
            return absolute(e)
        if isinstance(e, sp.Pow) and _is_half_odd(e.exp):
            return root(e)
        return None

    memo: dict = {}

    def walk(e):
        if e in memo:
            return memo[e]
        if not e.args or v not in e.free_symbols:
            out = e
        else:
            out = rewrite(e)
            if out is None:
                out = e.func(*[walk(a) for a in e.args])
        memo[e] = out
        return out

    try:
        rewritten = walk(w)
    except (TypeError, ValueError):  # (not this shape)
        return None
    if len(found) != 1:
        return None
    s = next(iter(found))
    sigma = sp.Dummy("sigma")
    plain = rewritten.xreplace({sp.sign(s): sigma})
    if plain.has(sp.sign) or plain.has(sp.Abs):
        return None
    up, down = plain.xreplace({sigma: sp.Integer(1)}), plain.xreplace({sigma: sp.Integer(-1)})
    P, Q = sp.cancel((up + down) / 2), sp.cancel((up - down) / 2)
    return SignSplit(s, P, Q, tuple(divisors))
