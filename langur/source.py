"""A program's bytes read from a file or a stream, bounded (E108): what the front end reads — FILE,
standard input, and every module a program imports — never fills memory, whatever the file is
(``/dev/zero``, an endless pipe, a link to a huge file), and a named file is never waited for
without a bound: opening a named pipe that no program writes to does not block, and its reader
waits for bytes at most as long as it was told (:func:`read_file`)."""

from __future__ import annotations

import errno
import os
import stat
import time

from . import lazy
from .diagnostics import Span, error

# Waiting for a pipe's bytes, imported when a file that is not a regular file is read (3 ms of every
# process's start-up otherwise: issue 15's one-shot target).
select = lazy.module("select")

#: Most bytes a source may have: a program has at most a million characters outside comments and
#: white space (E108, ``langur.syntax.parser``), so this leaves room for comments; past it the
#: source is refused, E108.
MAX_SOURCE_BYTES = 64 * 2**20


def read_source(fh, path: str) -> bytes:
    """All of ``fh`` (opened in binary mode, or standard input's buffer) as bytes; a LangurError
    E108 at ``path:1:1`` past :data:`MAX_SOURCE_BYTES` (a regular file is judged by its size before
    it is read, anything else after that many bytes)."""
    try:
        st = os.fstat(fh.fileno())
    except (OSError, ValueError):  # no file descriptor (an io.BytesIO)
        st = None
    if st is not None and stat.S_ISREG(st.st_mode):
        if st.st_size <= MAX_SOURCE_BYTES:
            return fh.read()
    else:
        chunks, size = [], 0
        while size <= MAX_SOURCE_BYTES:
            chunk = fh.read(1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)
            size += len(chunk)
    raise error(Span(path, 1, 1, 1, 1), "E108", f"source too large: more than {MAX_SOURCE_BYTES:,} bytes (a program "
                "has at most 1,000,000 characters outside comments and white space)")


def read_file(path: str, wait: float | None = None) -> bytes:
    """The bytes of the file ``path`` (:func:`read_source`); OSError as ``open`` raises it.

    The file is opened without blocking (``O_NONBLOCK``): a plain ``open`` of a named pipe waits,
    uninterruptibly by a CPU-time limit, until some program opens it for writing — forever if none
    does (``langur check`` of a program importing such a "module" sat there for its 605 s
    backstop, bench/history/2026-11-29.md#hostile32.  A regular file is then read as before; anything else
    (a pipe, a device) is read as its bytes arrive, and when ``wait`` (seconds of wall clock) is
    given, :class:`TimeoutError` (an OSError, ETIMEDOUT) says that it was not all there by then.
    Without ``wait`` the caller's own time limit bounds the read."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(fd, "rb", buffering=0) as fh:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):  # (``open`` refuses a directory; ``os.open`` does not)
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), path)
        if stat.S_ISREG(st.st_mode):
            os.set_blocking(fd, True)
            return read_source(fh, path)
        return read_source(_Arriving(fd, wait), path)


class LinkedAway(OSError):
    """A module file that is a symbolic link to a regular file not named ``*.lgr``: not read."""


def linked_away(path: str) -> LinkedAway | None:
    """Why the ``.lgr`` file ``path`` that nobody named (an import found beside its importer, a file
    ``langur check DIR`` found) is not read as a program: it leads, through symbolic links, to a
    regular file whose name does not end in ``.lgr`` — a link ``m.lgr -> /proc/self/environ`` or
    ``-> ~/.git-credentials`` in a pull request made ``langur check`` in CI print that file's first
    word in its syntax error (E102 quotes the unexpected name), bench/history/2026-11-29.md#hostile33.  A
    link to another ``.lgr`` file, to a pipe or a device (read bounded, as above) is read; a file
    named on the command line (FILE, ``--module NAME=PATH``) is read wherever it leads: the user
    chose it.  (Checked before the open: a link changed in between is not caught — a checkout
    does not change under the command.)"""
    real = os.path.realpath(path)
    if real.endswith(".lgr") or not os.path.isfile(real):
        return None
    return LinkedAway(errno.EPERM, f"it is a symbolic link to {real}, which is not a .lgr file: a module or "
                      "program found by its name is read only from a .lgr file", path)


class _Arriving:
    """A non-blocking descriptor read as a blocking file would be (``read(n)``: up to n bytes, b""
    at the end), each read waiting (``poll``) for bytes until ``wait`` seconds after the first."""

    def __init__(self, fd: int, wait: float | None):
        self.fd = fd
        self.wait = wait
        self.end = None if wait is None else time.monotonic() + wait

    def fileno(self) -> int:
        return self.fd

    def read(self, n: int) -> bytes:
        poller = select.poll()
        poller.register(self.fd, select.POLLIN)
        while True:
            left = None if self.end is None else self.end - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(errno.ETIMEDOUT, f"nothing to read after {self.wait:g} s (a named pipe no "
                                   "program writes to?)")
            if poller.poll(None if left is None else max(1, round(left * 1000))):
                try:
                    return os.read(self.fd, n)
                except BlockingIOError:  # (woken, but another reader was first)
                    continue
