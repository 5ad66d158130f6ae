"""Running a long computation with CPython's frame stack already grown (issue 13, measured).

CPython 3.11 keeps the frames of Python calls on a per-thread data stack made of 16 KiB chunks: a
call that does not fit in the current chunk maps a new one (``mmap``), and the return that leaves
that chunk empty unmaps it.  A computation whose call depth goes up and down across a chunk's edge
— sympy's recursive walks, nested integrands, compiled closures calling closures — maps, touches
and unmaps memory at every crossing.  In a ``langur fuzz`` worker this was 73 % of all page faults
(``perf record -e page-faults``: ``_PyThreadState_BumpFramePointerSlow``), about 19,000 per program,
and about a tenth of a 10-minute campaign's CPU went to the kernel (124 of 1,185 s).

:func:`run` calls its function from a frame whose code declares a value stack of :data:`SLOTS`
entries (``co_stacksize``; only its size is declared, the interpreter never touches the unused
slots).  That frame does not fit in a 16 KiB chunk, so CPython maps one chunk of 1 MiB for it; the
frames called from it go into the rest of that chunk, which stays mapped as long as the call lasts.
Depths up to about half a MiB of frames no longer map or unmap anything; deeper ones behave as
before.  The result, exceptions and tracebacks are the function's own.  On other Python versions
or implementations the frame is simply larger than needed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

#: The value-stack entries (8 bytes each) declared by :func:`run`'s calling frame: 512 KiB, so
#: CPython gives it a chunk of 1 MiB and about half of that is left for the frames it calls.
SLOTS = 1 << 16


def _call(fn, args, kwargs):
    return fn(*args, **kwargs)


_call.__code__ = _call.__code__.replace(co_stacksize=SLOTS)


def run(fn: Callable[..., T], *args, **kwargs) -> T:
    """``fn(*args, **kwargs)``, called from a frame that keeps a large frame-stack chunk mapped."""
    return _call(fn, args, kwargs)
