"""Programs of the core language Langur (paper §4.2, Fig. 11; LANGUAGE.md §6): ``int t d(x1, …, xn)``
with its domain.
"""

from __future__ import annotations

from dataclasses import replace

from ..diagnostics import Span
from ..records import frozen
from .sharing import _sharing
from .structural import product
from .terms import Mul, Term, _span


class _computed_once:
    """``functools.cached_property`` without its lock (Python 3.11 takes an ``RLock`` on every first
    read; 3.12 dropped it): the value computed on first read and kept in the instance's ``__dict__``,
    where later reads find it (a program's body is read once per load, issue 15)."""

    def __init__(self, func):
        self.func, self.name, self.__doc__ = func, func.__name__, func.__doc__

    def __get__(self, instance, owner=None):
        if instance is None:
            return self
        value = instance.__dict__[self.name] = self.func(instance)
        return value


@frozen
class Interval:
    """One interval ``[lo, hi]`` of a program's domain ``int ([l1, u1], …) t d(x⃗)`` (LANGUAGE.md §6).

    ``lo`` and ``hi`` are variable-free terms (parameters allowed); ``lower`` and ``upper`` are the
    indicators ``[x − lo ≥ 0]`` and ``[hi − x ≥ 0]`` as the front end completed them (a diffeomorphic
    conditional; a conditional on the parameters around two of them when a bound is one), which
    multiply the integrand (§6 sugar, §8.3); ``span`` is the interval's text.
    """

    variable: str
    lo: "Term"
    hi: "Term"
    lower: "Term"
    upper: "Term"
    span: Span | None = _span()

    def __init__(self, variable, lo, hi, lower, upper, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["variable"], d["lo"], d["hi"], d["lower"], d["upper"], d["span"] = variable, lo, hi, lower, upper, span


@frozen
class Program:
    """``int domain? integrand d(variables)`` (Fig. 11).

    ``domain``: the declared intervals, one per variable in order, or ``()`` when the program has
    none (then ``integrand`` bounds itself with indicator factors, Prop. 8.1).  ``box`` is a
    bounding box outside of which the integrand vanishes: one ``(lo, hi)`` pair of variable-free
    terms per variable (the domain, or read off the bounding indicators); it is what makes the
    integrand compactly supported (Prop. 8.1) and where samplers sample.  ``body`` is the term the
    semantics integrate: the domain's indicators times the integrand (§6 sugar).
    """

    integrand: "Term"
    variables: tuple[str, ...]
    box: tuple[tuple["Term", "Term"], ...]
    domain: tuple[Interval, ...] = ()
    span: Span | None = _span()

    def __init__(self, integrand, variables, box, domain=(), span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["integrand"], d["variables"], d["box"], d["domain"], d["span"] = integrand, variables, box, domain, span

    @_computed_once
    def body(self) -> "Term":
        """``[x1 ≥ l1]·[u1 ≥ x1]·…·integrand`` (the domain's indicators first, in order)."""
        if not self.domain:
            return self.integrand
        return product([ind for iv in self.domain for ind in (iv.lower, iv.upper)] + [self.integrand], self.span)

    def with_body(self, body: "Term") -> "Program":
        """This program integrating ``body`` instead (a rewrite of :attr:`body`): the domain stays when
        ``body`` is still its indicators times an integrand, else it is dropped (the box stays)."""
        if self.domain and isinstance(body, Mul) and body.left == self.body.left:
            return replace(self, integrand=body.right)
        return replace(self, integrand=body, domain=())


for _cls in (Interval, Program):
    _sharing(_cls)
