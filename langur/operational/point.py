"""What a separately compiled unit reads when it runs (§9): the evaluation :class:`Point` (ρ, ρ', γ,
γ', the mode, the delta sites), its :class:`Linking` (where the unit sits in a linked program),
and the compiled :class:`Unit` itself.

The modes say what the derivative part ``d`` of a unit's dual number means
(:mod:`langur.operational.compile`): ``VALUE`` ⟦t⟧ only (Fig. 7), ``TANGENT`` forward-mode tangents
with every delta dropped (standard AD, the paper's Dˢ), ``DELTA`` the coefficients G_k of the
deltas of ⦇t⦈ (Fig. 8).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field

import numpy as np

from ..records import FACTORY, frozen, record

VALUE, TANGENT, DELTA = 0, 1, 2
NAN = float("nan")
#: How the frozen, slotted records below set their fields (as dataclass's generated ``__init__`` does).
_set = object.__setattr__


@frozen(slots=True)
class Linking:
    """Where a unit sits in a linked program (§9, linking): the global id of its first site
    (``base``), its slot → site offset table (``offsets``; None: slot = offset) and the linked
    defs its calls go to (``units``: (module, def) → (fn, offsets, argument names))."""

    base: int = 0
    offsets: list | None = None
    units: dict | None = None

    def __init__(self, base=0, offsets=None, units=None):  # (records: a slotted record writes its own)
        _set(self, "base", base)
        _set(self, "offsets", offsets)
        _set(self, "units", units)


#: A unit run on its own: no calls to resolve, its sites numbered by its own slots.
UNLINKED = Linking()


@frozen(slots=True)
class Point:
    """The evaluation point (§9: what a separately compiled unit reads when run): ρ (``vars``), a
    direction in the variables ρ' (``dvars``), γ (``params``), γ' (``dparams``), the mode, in
    DELTA mode the site owning each point (``site``, with the ids present in ``sites``), and the
    program's own (γ, γ') (``root``) that a def's body reads for its module's declared params
    (None at the program's top level, where they are ``params``, ``dparams``)."""

    vars: dict
    params: dict
    dvars: dict = field(default_factory=dict)
    dparams: dict = field(default_factory=dict)
    mode: int = VALUE
    site: np.ndarray | None = None
    sites: frozenset = frozenset()
    root: tuple | None = None
    #: values of the shared subterms already evaluated at this point (see :func:`evaluated_once`)
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    def __init__(self, vars, params, dvars=FACTORY, dparams=FACTORY, mode=VALUE, site=None,  # noqa: A002
                 sites=frozenset(), root=None, memo=FACTORY):  # noqa: B008 (immutable)
        _set(self, "vars", vars)
        _set(self, "params", params)
        _set(self, "dvars", {} if dvars is FACTORY else dvars)
        _set(self, "dparams", {} if dparams is FACTORY else dparams)
        _set(self, "mode", mode)
        _set(self, "site", site)
        _set(self, "sites", sites)
        _set(self, "root", root)
        _set(self, "memo", {} if memo is FACTORY else memo)

    def values(self) -> Point:
        """The same point and parameters without any derivative (conditions are values only)."""
        if self.mode == VALUE:
            return self
        found = self.memo.get(_VALUES)  # made once per point (every condition reads it)
        if found is None:
            found = self.memo[_VALUES] = Point(self.vars, self.params, root=self.root and (self.root[0], {}))
        return found

    def bind(self, name: str, v, d) -> Point:
        """``γ[z ↦ v]``, ``γ'[z ↦ d]`` (Fig. 8, let)."""
        dp = self.dparams
        if d is not None or name in dp:
            dp = dict(dp)
            if d is None:
                del dp[name]
            else:
                dp[name] = d
        return Point(self.vars, {**self.params, name: v}, self.dvars, dp, self.mode, self.site, self.sites,
                     self.root or (self.params, self.dparams))


#: The key of :meth:`Point.values`'s point in :attr:`Point.memo` (the shared subterms' keys are ints).
_VALUES = "values"

Fn = Callable[[Point, Linking], tuple]


@record
class Unit:
    """A compiled term: ``fn`` and its slots in pre-order: ``("site", None, ())`` or
    ``("call", (module, def), which arguments are plain variables)``."""

    fn: Fn
    slots: list


def full(v, n: int) -> np.ndarray:
    """``v`` (a scalar, None for 0, or an array of n values) as an array of n floats."""
    if type(v) is np.ndarray:
        return v if v.shape == (n,) else np.full(n, v, dtype=float)
    out = np.empty(n)  # (np.full's own work without its Python frame: a number converted as it does)
    out.fill(0.0 if v is None else v)
    return out
