"""Pausing Python's cyclic garbage collector while the front end builds terms (issue 15).

Parsing and loading allocate many small objects (tokens, surface nodes, core terms and the values
kept on them) and create no reference cycles, but every few hundred allocations the cyclic
collector runs and traverses the young objects again (and, now and then, every older object):
a fifth to a third of a load of microbenchmark 1 at n = 100.  :func:`paused` switches it off for
the duration of a block and back on after (if it was on); reference counting frees everything as
usual meanwhile, and a cycle made in the block (an exception's traceback) is collected once the
collector runs again.  Nested uses leave it off until the outermost block ends.

:func:`kept` is :func:`paused` for a block whose objects outlive it (a load: the typed core, and
the parsed module the front end keeps).  Once such a block has run, the young generation holds
every object it made, above the collector's threshold, and the first allocation after the block
would start a young collection that traverses all of them only to find them alive (a tenth of
microbenchmark 1's load at n = 10, measured with the collector off and on).  So when the block
ends without an exception, every tracked object is moved to the oldest generation as it is
(``gc.freeze()`` then ``gc.unfreeze()``: the documented pair, two list splices, no traversal):
what a young collection would do to survivors, without the traversal.  They are traversed again
at the next full collection, as every long-lived object is.  The objects the caller made just
before are promoted with them (they, too, wait for a full collection); nothing is done when some
code keeps objects frozen (``gc.get_freeze_count()``: its freeze is left alone) or the collector
was off.
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


@contextmanager
def kept() -> Iterator[None]:
    """:func:`paused`, and what the block made (every tracked object) moved to the collector's
    oldest generation when the block ends without an exception (the module docstring)."""
    enabled = gc.isenabled()
    gc.disable()
    done = False
    try:
        yield
        done = True
    finally:
        if enabled:
            if done and not gc.get_freeze_count():
                gc.freeze()
                gc.unfreeze()
            gc.enable()
