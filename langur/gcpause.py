"""Pausing Python's cyclic garbage collector while the front end builds terms (issue 15).

Parsing and loading allocate many small objects (tokens, surface nodes, core terms and the values
kept on them) and create no reference cycles, but every few hundred allocations the cyclic
collector runs and traverses the young objects again (and, now and then, every older object):
a fifth to a third of a load of microbenchmark 1 at n = 100.  :func:`paused` switches it off for
the duration of a block and back on after (if it was on); reference counting frees everything as
usual meanwhile, and a cycle made in the block (an exception's traceback) is collected once the
collector runs again.  Nested uses leave it off until the outermost block ends.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def paused() -> Iterator[None]:
    """The cyclic collector off inside the ``with`` block (restored after)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
