"""The one catalogue of diagnostic codes (CLI.md, Diagnostics; ``docs/CODES.md`` has the long form).

``E1xx``: syntax (``langur.syntax.parser``); ``T2xx``: typing and elaboration (Fig. 6, 11;
``langur.typesys``); ``X3xx``: transversality and integrability (``langur check``, Def. 7.2,
``langur.lint``).  Every :class:`~langur.diagnostics.Diagnostic` carries a code of this catalogue;
``proofs_tests/test_check_cli.py`` checks that each is emitted somewhere and
``docs/CODES.md`` documents each.  A code's message built in more than one place is declared here
too, once (X316's, below).
"""

from __future__ import annotations

from .records import frozen


@frozen
class Code:
    """A diagnostic code: ``summary`` is its one-line meaning; ``name`` and ``severity`` the
    linter's rule name and default level (SARIF), for the X3xx codes the linter may grade."""

    code: str
    summary: str
    severity: str = "error"
    name: str | None = None


def _catalogue(*codes: Code) -> dict[str, Code]:
    return {c.code: c for c in codes}


CODES: dict[str, Code] = _catalogue(
    # E1xx: syntax
    Code("E101", "the file is not UTF-8"),
    Code("E102", "unexpected token"),
    Code("E103", "unexpected end of input"),
    Code("E104", "a character that starts no token"),
    Code("E105", "nesting too deep"),
    Code("E106", "number literal out of range"),
    Code("E107", "text after the program"),
    Code("E108", "source too large"),
    Code("E109", "file unreadable"),
    # T2xx: typing and elaboration
    Code("T201", "unbound name"),
    Code("T202", "unknown function"),
    Code("T203", "wrong arity"),
    Code("T204", "variable-free term for a var argument"),
    Code("T205", "term with variables for a param argument"),
    Code("T206", "let-bound term with a variable"),
    Code("T207", "condition over variables cannot be completed to a diffeomorphism"),
    Code("T208", "nested int"),
    Code("T209", "integrand not compactly supported"),
    Code("T210", "undeclared parameter"),
    Code("T211", "duplicate declaration"),
    Code("T212", "name both variable and parameter"),
    Code("T213", "non-constant exponent"),
    Code("T214", "diffeo arity"),
    Code("T215", "diffeo inverse does not invert"),
    Code("T216", "diffeo Jacobian singular"),
    Code("T217", "diffeo variable arguments not distinct variables"),
    Code("T218", "module not found"),
    Code("T219", "import cycle"),
    Code("T220", "imported name not found"),
    Code("T221", "recursive def"),
    Code("T222", "diffeo component not smooth"),
    Code("T223", "module unreadable"),
    Code("T224", "loop bound not an integer constant"),
    Code("T225", "loops too large once unrolled"),
    Code("T226", "vector where a real is expected"),
    Code("T227", "real where a vector is expected"),
    Code("T228", "vector sizes differ"),
    Code("T229", "cross of vectors that are not 3-vectors"),
    Code("T230", "too large once inlined"),
    Code("T231", "constant beyond the range of doubles"),
    Code("T232", "vector component out of range"),
    Code("T233", "let shadows a name that a let-bound vector uses"),
    Code("T234", "power too large to compute exactly"),
    # X3xx: transversality and integrability (langur check)
    Code("X301", "Two multiplying conditions (or one multiplied by itself through a power or primitive) have the "
         "same zero set for every parameter value: the derivative counts the jump twice (Def. 7.2).",
         "error", "coincident-zero-sets"),
    Code("X302", "Two multiplying zero sets are tangent at a point (normals linearly dependent): Def. 7.2 fails on "
         "a null set; Theorem 8.1 no longer applies, the derivative is still likely right.",
         "warning", "tangent-zero-sets"),
    Code("X303", "More than n multiplying zero sets pass through one point of R^n: Def. 7.2 fails on a null set.",
         "warning", "too-many-zero-sets-through-a-point"),
    Code("X304", "Multiplying zero sets coincide for some parameter values (the set is printed).",
         "warning", "degenerate-for-some-parameters"),
    Code("X305", "At the parameter values given with --at the zero sets coincide or a condition is not a "
         "diffeomorphism: the derivative is not defined there.",
         "error", "degenerate-at-given-parameters"),
    Code("X306", "A parameter coefficient of a condition vanishes for some parameter values: there the condition "
         "is not a diffeomorphism.",
         "warning", "not-a-diffeomorphism-for-some-parameters"),
    Code("X307", "A primitive (log, sqrt, division, tan, ...) is applied outside its domain on the domain of "
         "integration at the parameter values in force.",
         "warning", "primitive-outside-domain"),
    Code("X308", "Multiplying conditions with the same zero set that does not move with the parameters: the deltas "
         "have zero weight, the derivative is unaffected (the product is redundant).",
         "warning", "redundant-static-coincidence"),
    Code("X310", "The checker could not decide transversality here (a sympy computation timed out or failed).",
         "warning", "undecided"),
    Code("X311", "The integrand is not integrable on the domain at the parameter values in force (a pole whose "
         "order reaches the codimension of the set it sits on): the integral does not exist.",
         "error", "not-integrable"),
    Code("X312", "The integrand blows up on the domain, or the analysis stopped (its time limit), and it cannot "
         "decide whether it is integrable there; the engines' answers rely on their own diagnostics.",
         "warning", "integrability-undecided"),
    Code("X313", "The derivative denotation in a parameter is not an integral (its regular part is not integrable, "
         "or a delta term's weight is infinite or undefined on its zero set), although the value exists.",
         "error", "derivative-not-integrable"),
    Code("X314", "An interval of the domain is empty at the parameter values in force (lower end above upper end): "
         "the integrand is 0 there, so the value is 0, not minus the integral as in calculus.",
         "warning", "empty-domain"),
    Code("X316",
         "A condition split at turning points that move with the parameters cannot be evaluated at these parameter "
         "values: it has more turning points on the domain than it was split for, or they cannot be certified "
         "(a degenerate turning point).",
         "error", "turning-points-beyond-the-split"),
    Code("X315",
         "A condition's zero set is a double root for every parameter value (its derivative in the solved "
         "variable vanishes on it): it is not a diffeomorphism anywhere and the derivative is not defined.",
         "error", "double-root-condition"),
    Code("X399", "The check of this file did not finish within its time budget (--timeout, default 60 CPU s): what was "
         "not reported is unchecked.",
         "error", "time-limit"),
)


# X316's texts (docs/CODES.md), declared here once for both engines: the exact engine's implicit
# roots (:mod:`langur.implicit.equations`) and the Monte Carlo engine's (:mod:`langur.operational.roots`,
# :mod:`langur.operational.naive`).  True of ``langur eval`` as of ``langur deriv``: a value needs
# the ends of the condition's monotone pieces as much as a derivative does.

def turning_points_beyond_split(count: int, of: int, where: str, at_least: bool = False) -> str:
    """X316: ``count`` turning points ``where`` (``on [-2, 2]``, ``on the domain``) at the parameter
    values in force, more than the ``of`` the condition was split for; ``at_least``: the count
    stopped there (the first ones found, from the left end)."""
    return (f"{'at least ' if at_least else ''}{count} turning points {where} at these parameter values, more than "
            f"the {of} the condition "
            "was split for: this engine cannot find the ends of the condition's monotone pieces here; split "
            "the variable's domain (a sum of integrals over sub-intervals, each with at most that many "
            "turning points)")


#: X316: a condition split at turning points that move with the parameters, whose implicit root
#: comes without the enclosure of its slope that certifies them.
NO_SLOPE_TO_CERTIFY = ("a turning point that moves with the parameters has no ∂²/∂x² to certify that none is "
                       "missed (an implicit root without its slope): this engine cannot find the ends of the "
                       "condition's monotone pieces")


def turning_points_uncertified(what: str, near: str, a: float, b: float) -> str:
    """X316: the sign changes of ``what`` (∂f/∂x) near ``near`` in [a, b] not certified: there it
    and its derivative both vanish, or their enclosures stay too wide."""
    return (f"cannot certify the turning points (sign changes of {what}) near {near} in [{float(a):.12g}, "
            f"{float(b):.12g}] at these parameter values: there {what} and its derivative both vanish (a "
            "degenerate turning point) or their interval enclosures stay too wide; Langur refuses rather "
            "than miss one")
