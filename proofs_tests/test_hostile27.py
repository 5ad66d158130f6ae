"""Hostile files cost bounded memory: `langur check` on a long sum (hostile27).

X307's sampling check (``langur/lint/domains.py``) kept the 4096 samples of every node of the
integrand (32 kB each) until it finished: 35 kB per term, 3.5 GB for a sum of 10⁵ terms, which the
parser accepts.  It now keeps only the values of nodes used more than once, until their last use.
Each check runs in a subprocess whose address space is limited (``RLIMIT_AS``) below what the old
analysis needed (it died there with "out of memory") and far above what the check needs now; its
findings must be those of the same sum with three terms (the analyses see the same conditions and
primitives whatever the number of copies).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


#: CPU seconds a check may use (``RLIMIT_CPU``; the 30,000-term sum takes 2.2, 2026-11-29), and its own
#: ``--timeout`` (wall clock) far above it: a loaded machine slows the check down without it using
#: more CPU, and must not stop it (X399) — the bound here is CPU time.
CPU = 120
TIMEOUT = 1200


def _check(path: Path, limit_mb: int | None):
    def limit():
        if limit_mb is not None:
            resource.setrlimit(resource.RLIMIT_AS, (limit_mb << 20, limit_mb << 20))
        resource.setrlimit(resource.RLIMIT_CPU, (CPU, CPU + 5))

    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run(
        [sys.executable, "-P", "-m", "langur", "check", "--format", "json", str(path), "--timeout", str(TIMEOUT)],
        preexec_fn=limit, capture_output=True, text=True, env=env, timeout=TIMEOUT + 60,
    )


def _codes(out: str) -> list[tuple[str, str]]:
    return sorted((d["code"], d["severity"]) for d in json.loads(out)["diagnostics"])


def _sum(tmp_path: Path, name: str, head: str, term: str, n: int) -> Path:
    p = tmp_path / f"{name}.lgr"
    p.write_text("int ([0, 1]) " + " + ".join([head] + [term] * (n - 1)) + " d(x)\n")
    return p


def _same_findings_within(tmp_path: Path, head: str, term: str, n: int, limit_mb: int):
    big = _check(_sum(tmp_path, "big", head, term, n), limit_mb)
    assert "Traceback" not in big.stderr and "out of memory" not in big.stderr, big.stderr[-2000:]
    small = _check(_sum(tmp_path, "small", head, term, 3), None)
    assert big.returncode == small.returncode, (big.stderr[-2000:], small.stderr[-2000:])
    assert _codes(big.stdout) == _codes(small.stdout)
    return _codes(big.stdout)


def test_long_sum_with_a_primitive_outside_its_domain(tmp_path):
    # 30 000 terms: the old analysis held ~1.1 GB and died under 768 MB; now ~180 MB.  log(x - 0.5)
    # is negative on half of [0, 1], so X307 must still be reported (once), whatever the sum's length.
    codes = _same_findings_within(tmp_path, "log(x - 0.5)", "x", 30_000, 768)
    assert codes.count(("X307", "warning")) == 1


def test_long_sum_of_one_shared_condition(tmp_path):
    # 2 000 copies of one condition times x (the same node after hash-consing): the old analysis
    # held ~0.7 GB and died under 600 MB.  A fixed condition summed with itself: nothing to report.
    assert _same_findings_within(tmp_path, "[x >= 0.5] * x", "[x >= 0.5] * x", 2_000, 600) == []
