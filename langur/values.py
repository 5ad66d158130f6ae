"""Parameter values γ (and directions γ') for a program: the check both engines make before they
evaluate (Fig. 11: a program reads the parameters free in its body and its box, ·;Γ ⊢ p)."""

from __future__ import annotations

from .core import Program, free_params


def program_params(program: Program) -> frozenset[str]:
    """The parameters ``program`` reads: free in its body or its box's bounds (Fig. 11: ·;Γ ⊢ p)."""
    out = free_params(program.body)
    for lo, hi in program.box:
        out |= free_params(lo) | free_params(hi)
    return out


class ParameterError(KeyError, ValueError):
    """A program evaluated at parameter values γ that do not fit it (both engines raise it alike):
    a parameter it reads has no value, a value is not a finite number, or the direction γ' names a
    parameter γ gives no value to.  A ``KeyError`` (a missing value) and a ``ValueError``."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


def check_values(program: Program, at, direction=None) -> None:
    """Raise :class:`ParameterError` unless ``at`` (name → number) gives every parameter of
    ``program`` a finite value and ``direction`` (γ', name → number) names only parameters of
    ``at``, with finite components."""
    at = at or {}
    missing = sorted(program_params(program) - set(at))
    if missing:
        raise ParameterError(f"no value for parameter(s) {', '.join(missing)} (the program reads them)")
    unknown = sorted(set(direction or {}) - set(at))
    if unknown:
        raise ParameterError(f"the direction names parameter(s) {', '.join(unknown)} that have no value "
                             f"(parameters: {', '.join(sorted(at)) or 'none'})")
    for what, values in (("parameter", at), ("direction", direction or {})):
        for name, v in values.items():
            try:
                finite = float(v) - float(v) == 0  # False for nan and ±inf
            except (TypeError, ValueError, OverflowError):
                continue  # a symbolic value (a sympy expression): the caller's business
            if not finite:
                raise ParameterError(f"{what} {name} = {v}: not a finite number")
