"""Why an analysis gave up, in words a reader of the paper understands: the one catalogue.

The exact engine and the checker ask sympy (and mpmath) for roots, antiderivatives, limits and
polynomial algebra (Def. 6.2's decomposition, §6.3's change of variables, Def. 7.2's check).  When a
call fails they fall back — quadrature with an error bound, "undecided", "unchecked" — and a note
says why.  sympy's exception names (``PolynomialError``, ``GeneratorsNeeded``) and messages ("No
algorithms are implemented to solve equation …") say nothing to a user; :func:`why` says what
happened instead.  Every site that reports a caught failure asks it, so each failure is worded once.

* An exception of Langur's own (``TooManyRoots``, ``Undecided``, ``Unsupported``, …) already says
  what happened in the paper's terms: its message is kept.
* A built-in exception raised by Langur's own code keeps its message too (``ValueError("cannot
  express … in the core language")``), except ``NotImplementedError``: Langur raises it only with
  sympy's words (``symbolic/unsolvable.py`` predicts sympy's "no algorithms" failure).
* Any other (sympy's, mpmath's, a built-in raised inside them) is worded by its kind
  (:data:`WORDS`, looked up along the class's bases, so every polynomial-algebra error of sympy
  is one entry), or else by :data:`OTHERWISE`.

Core layer: it imports nothing, not even sympy (classes are matched by name).
"""

from __future__ import annotations

import os

__all__ = ["OTHERWISE", "WORDS", "why"]

#: The kinds of failure, by exception class name (the first match along the class's bases).
WORDS: dict[str, str] = {
    # sympy's polynomial algebra (PolynomialError, GeneratorsNeeded, CoercionFailed, …)
    "BasePolynomialError": "the expression is not a polynomial in the variables, so the polynomial algebra "
                           "(roots, factors, resultants) does not apply",
    "NotImplementedError": "no closed-form method applies",
    "SympifyError": "an expression could not be read as a formula",
    "RecursionError": "the expression is nested too deeply to analyse",
    "ZeroDivisionError": "a division by zero",
    "OverflowError": "a number beyond the range of floating point",
    "MemoryError": "not enough memory",
    "TimeoutError": "it took longer than its time limit",
}

#: Any other failure inside the computer algebra (sympy's ``TypeError``, ``ValueError``, …).
OTHERWISE = "the computer algebra (sympy) failed on this expression"

_HERE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _ours(e: BaseException) -> bool:
    """Was ``e`` raised by Langur's own code (its innermost frame in this package)?"""
    tb = e.__traceback__
    if tb is None:
        return True  # built and not raised: a message Langur wrote
    while tb.tb_next is not None:
        tb = tb.tb_next
    return os.path.abspath(tb.tb_frame.f_code.co_filename).startswith(_HERE)


def why(e: BaseException) -> str:
    """What went wrong, for a note or a diagnostic: ``e``'s own message when Langur wrote it, else
    the words of its kind (:data:`WORDS`, :data:`OTHERWISE`); never an exception's class name."""
    kind = type(e)
    text = " ".join(str(e).strip().split("\n")[0].split())  # its first line
    if text and kind.__module__.split(".")[0] == "langur":
        return text
    if text and kind.__module__ == "builtins" and kind is not NotImplementedError and _ours(e):
        return text
    for base in kind.__mro__:
        words = WORDS.get(base.__name__)
        if words is not None:
            return words
    return OTHERWISE
