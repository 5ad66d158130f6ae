"""An engine in another process, in any language: ``cmd:PROGRAM`` (``docs/engines.md``).

PROGRAM is started once (split as a shell would, never run through a shell) and kept running.
For each question the workbench writes one JSON request on a line of its standard input::

    {"id": 3, "request": "value" | "derivative", "program": <langur-core JSON>,
     "params": {"a": 0.5}, "direction": {"a": 1}}

and reads one JSON answer on a line of its standard output::

    {"id": 3, "kind": "exact" | "bounded" | "stochastic", "value": 0.5, "error": 0.0}
    {"id": 3, "declined": "why"}

A process that exits, an answer later than the budget, a line that is not such an answer (or
answers another id) is an :class:`~.protocol.EngineFailure` naming what went wrong; the process
is then killed and started afresh for the next question.
"""

from __future__ import annotations

import json
import math
import os
import select
import shlex
import subprocess
import time
from collections.abc import Mapping

from .. import core_json
from ..core import Program
from .protocol import Answer, Declined, EngineFailure, Kind

#: Longest answer line read (bytes): a longer one is malformed.
MAX_LINE = 1 << 20


class ExternalEngine:
    """The engine behind ``cmd:PROGRAM``; ``timeout``: seconds per answer."""

    def __init__(self, command: str, timeout: float = 60.0):
        self.argv = shlex.split(command)
        if not self.argv:
            raise ValueError("cmd: needs a program to run")
        self.name = f"cmd:{command}"
        self.timeout = timeout
        self.kind = Kind.STOCHASTIC  # until the first answer says otherwise
        self.proc: subprocess.Popen | None = None
        self.count = 0
        self.buffer = b""

    def value(self, program: Program, params: Mapping[str, float]) -> Answer | Declined:
        return self._ask("value", program, params, None)

    def derivative(self, program: Program, params, direction) -> Answer | Declined:
        return self._ask("derivative", program, params, direction)

    def close(self) -> None:
        if self.proc is not None:
            try:
                self.proc.kill()
            except OSError:
                pass
            self.proc.wait()
            for stream in (self.proc.stdin, self.proc.stdout, self.proc.stderr):
                if stream is not None:
                    stream.close()
        self.proc, self.buffer = None, b""

    def __del__(self):
        self.close()

    def _start(self) -> subprocess.Popen:
        if self.proc is None or self.proc.poll() is not None:
            self.close()
            try:
                self.proc = subprocess.Popen(self.argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                             stderr=subprocess.PIPE)
            except OSError as e:
                raise EngineFailure(f"{self.name}: cannot start {self.argv[0]!r}: {e.strerror or e}") from None
        return self.proc

    def _fail(self, why: str):
        err = b""
        if self.proc is not None and self.proc.stderr is not None:
            self.proc.kill()
            try:
                err = self.proc.stderr.read(4000) or b""
            except (OSError, ValueError):
                pass
        self.close()
        tail = err.decode("utf-8", "replace").strip().splitlines()[-1:] if err else []
        raise EngineFailure(f"{self.name}: {why}" + (f" (its last words: {tail[0][:300]})" if tail else ""))

    def _ask(self, request: str, program: Program, params, direction) -> Answer | Declined:
        proc = self._start()
        self.count += 1
        ask = {"id": self.count, "request": request, "program": core_json.to_json(program),
               "params": {k: float(v) for k, v in params.items()}}
        if direction is not None:
            ask["direction"] = {k: float(v) for k, v in direction.items()}
        try:
            proc.stdin.write((json.dumps(ask) + "\n").encode())
            proc.stdin.flush()
        except (BrokenPipeError, OSError):
            self._fail(f"exited (status {proc.poll()}) before reading the question")
        line = self._line(proc)
        return self._parse(line)

    def _line(self, proc) -> bytes:
        deadline = time.monotonic() + self.timeout
        fd = proc.stdout.fileno()
        while b"\n" not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                self._fail(f"no answer within {self.timeout:g} s")
            ready, _, _ = select.select([fd], [], [], left)
            if not ready:
                continue
            chunk = os.read(fd, 65536)
            if not chunk:
                self._fail(f"exited (status {proc.wait()}) without answering")
            self.buffer += chunk
            if len(self.buffer) > MAX_LINE:
                self._fail(f"answered a line longer than {MAX_LINE:,} bytes")
        line, _, self.buffer = self.buffer.partition(b"\n")
        return line

    def _parse(self, line: bytes) -> Answer | Declined:
        try:
            a = json.loads(line)
        except ValueError:
            self._fail(f"answered something that is not JSON: {line[:200]!r}")
        if not isinstance(a, dict) or a.get("id") != self.count:
            self._fail(f"answered {line[:200]!r}, not an answer to question {self.count}")
        if "declined" in a:
            return Declined(str(a["declined"])[:1000])
        try:
            kind = Kind(a.get("kind"))
            value = a["value"]
            value = float(value) if not isinstance(value, str) else float({"nan": "nan", "inf": "inf",
                                                                             "-inf": "-inf"}[value])
            error = float(a.get("error", 0.0))
        except (KeyError, ValueError, TypeError):
            self._fail(f"answered {line[:200]!r}: an answer needs \"kind\" (exact, bounded or stochastic), "
                       "\"value\" and, unless exact, \"error\"")
        if not (error >= 0 and not math.isnan(error)):
            self._fail(f"answered an error of {error!r} (it must be a non-negative number)")
        self.kind = kind
        return Answer(value, error)
