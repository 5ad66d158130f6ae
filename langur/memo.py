"""The bounded in-process memo: a plain dict of answers already computed, kept to a fixed number
of entries (issue 15, "each concept declared once").

Both engines, the front end and the linter remember answers already computed, by their keys (a
condition's roots, a compiled integrand, a polygon's vertices, an interned set): the same question
comes back for ⟦p⟧ and each partial derivative, Theorem 8.1's shifted points, a quadrature's
abscissae.  A long process (a fuzz campaign, a render session) must not grow its heap without bound,
so each memo holds at most ``size`` entries and makes room before a new one, in one of two ways:

- the oldest entry dropped (first in, first out: a dict keeps its insertion order), the default;
- ``at_once``: every entry forgotten (and those of the memos ``also`` whose entries depend on the
  dropped ones: keys naming objects only the dropped entries keep alive, ids, …), where dropping
  one by one would cost more than the memo saves or where entries are only valid together.

A memo that forgets the least recently used entry instead pops a hit and remembers it again (it
moves to the end).  Nothing is written to disk; a memo is keyed by everything its answer depends
on, which each user says where it declares its dict.  (The Monte Carlo engine's geometry memo,
``langur.operational.batch``, is bounded by bytes instead, and ``functools.lru_cache`` serves
functions of a few small arguments.)
"""

from __future__ import annotations


def make_room(memo: dict, size: int, *, at_once: bool = False, also: tuple = ()) -> None:
    """Before a new entry: when ``memo`` holds ``size`` entries or more, drop its oldest one, or
    (``at_once``) clear it and each of ``also``."""
    if len(memo) >= size:
        if at_once:
            memo.clear()
            for other in also:
                other.clear()
        else:
            memo.pop(next(iter(memo)))


def remember(memo: dict, key, value, size: int = 2048, *, at_once: bool = False):
    """``memo[key] = value`` (returned), room made first (:func:`make_room`): at most ``size``
    entries, the oldest dropped or (``at_once``) all of them."""
    make_room(memo, size, at_once=at_once)
    memo[key] = value
    return value
