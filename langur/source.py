"""A program's bytes read from a file or a stream, bounded (E108): what the front end reads — FILE,
standard input, and every module a program imports — never fills memory, whatever the file is
(``/dev/zero``, an endless pipe, a link to a huge file)."""

from __future__ import annotations

import os
import stat

from .diagnostics import Span, error

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


def read_file(path: str) -> bytes:
    """The bytes of the file ``path`` (:func:`read_source`); OSError as ``open`` raises it."""
    with open(path, "rb") as fh:
        return read_source(fh, path)
