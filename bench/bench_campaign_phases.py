"""CPU seconds per phase of campaign units (issue 13, camp8): where a program's time goes.

    python bench/bench_campaign_phases.py LIST.json 178,268,333 OUT.jsonl [--limit 45]

``LIST.json``: a JSON list of program texts (e.g. ``langur.fuzz.compare.generated(1000, 1)`` saved
once); the positions to run; ``OUT.jsonl`` gets one line per phase and program, appended.  Each
program runs in a child forked from this warm process (``langur.fuzz.campaign._warm_up``), killed when it has
used ``--limit`` CPU seconds; the phases, timed with ``time.process_time`` in the child: the front
end, the linter (``check_loaded``, only the analyses that can discard the program where the tree
has ``only``, as a unit), ⟦p⟧ (``exact_eval``), each partial derivative
(``exact_deriv``, split into ``ddenote_program`` and the Theorem 8.1 check, and within that the
CPU of ``theorem._finite_difference``), and the Monte Carlo estimates (20,000 samples) — the
linter within ``LINT_SHARE · 20`` CPU s, the exact engine inside the campaign's closed-form budget
(``SYMBOLIC_SHARE · 20`` s) and Theorem 8.1's checks within ``CHECK_SHARE · 20`` s, as a unit runs
them, the quadratures' outermost level at the campaign's looseness (``OUTER_LOOSENESS``, camp9;
1 in trees that predate it).  A phase that raises is recorded with its CPU and the error.
"""

from __future__ import annotations

import argparse
import inspect
import json
import os
import signal
import time

from langur import exact as api
from langur import operational, theorem
from langur.frontend import load_text
from langur.fuzz import campaign, compare, pool
from langur.symbolic import integrate, quadrature
from langur.timebox import budget
from langur.transversality import check_loaded

#: The campaign's time limit per program (``langur fuzz --timeout``): the linter's, the closed-form
#: search's and Theorem 8.1's shares of it are the campaign's (``compare.LINT_SHARE`` …).
TIMEOUT = 20.0


def _timed(owner, name: str, acc: dict):
    real = getattr(owner, name)

    def wrapper(*args, **kwargs):
        c0 = time.process_time()
        try:
            return real(*args, **kwargs)
        finally:
            acc["cpu"] += time.process_time() - c0

    setattr(owner, name, wrapper)


def _unit(text: str, i: int, w: int) -> None:
    def emit(**k):
        os.write(w, (json.dumps(dict(i=i, **k)) + "\n").encode())

    T = time.process_time
    c = T()
    loaded = load_text(text, path="<fuzz>.lgr")
    emit(phase="front_end", cpu=T() - c)
    params = loaded.param_values({})
    c = T()
    # as a unit lints (camp10: only the analyses that can discard it; older trees: all of them)
    only = {"only": frozenset(compare.LINT_DISCARD)} if "only" in inspect.signature(check_loaded).parameters else {}
    found = check_loaded(loaded, at={k: float(v) for k, v in params.items()}, sources={"<fuzz>.lgr": text},
                         budget=compare.LINT_SHARE * TIMEOUT, **only)
    emit(phase="lint", cpu=T() - c)
    if any(f.code in compare.LINT_DISCARD for f in found):
        emit(phase="discarded", cpu=0.0)
        return
    fd, dd = {"cpu": 0.0}, {"cpu": 0.0}
    _timed(theorem, "_finite_difference", fd)
    _timed(api, "ddenote_program", dd)
    with (budget(compare.SYMBOLIC_SHARE * TIMEOUT), integrate.untidied(),
          quadrature.outer_tolerance(getattr(compare, "OUTER_LOOSENESS", 1.0))):
        c = T()
        try:
            ex = api.exact_eval(loaded.program, params)
        except BaseException as e:
            emit(phase="value_error", cpu=T() - c, err=repr(e)[:150])
            raise
        emit(phase="value", cpu=T() - c, method=str(ex.method), v=ex.value, e=ex.error)
        checks_end = T() + compare.CHECK_SHARE * TIMEOUT
        for p in params:
            fd["cpu"] = dd["cpu"] = 0.0
            c = T()
            try:
                r = api.exact_deriv(loaded.program, params, {q: (1 if q == p else 0) for q in params},
                                    check_seconds=max(0.0, checks_end - T()))
            except BaseException as e:
                emit(phase="deriv_error", p=p, cpu=T() - c, ddenote=dd["cpu"], fd=fd["cpu"], err=repr(e)[:150])
                raise
            tot, th = T() - c, r.theorem_8_1
            emit(phase="deriv", p=p, cpu=tot, ddenote=dd["cpu"], theorem=tot - dd["cpu"], fd=fd["cpu"],
                 method=str(r.method), v=r.value, e=r.error,
                 th=None if th is None else [th.holds, str(th.how), th.d_denotation, th.error])
    c = T()
    floats = {k: float(v) for k, v in params.items()}
    operational.estimate_value(loaded, floats, samples=20000, seed=1)
    for j, p in enumerate(params):
        operational.estimate_derivative(loaded, floats, {q: (1.0 if q == p else 0.0) for q in params},
                                        samples=20000, seed=2 + j)
    emit(phase="mc", cpu=T() - c)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("programs")
    ap.add_argument("positions", help="comma-separated positions in the list")
    ap.add_argument("out")
    ap.add_argument("--limit", type=float, default=45.0, help="CPU seconds before a program is killed")
    a = ap.parse_args()
    texts = json.load(open(a.programs, encoding="utf-8"))
    campaign._warm_up(True)
    with open(a.out, "a", encoding="utf-8") as fo:
        for i in (int(k) for k in a.positions.split(",")):
            r, w = os.pipe()
            pid = os.fork()
            if pid == 0:  # the child: one program, its phases through the pipe
                os.close(r)
                try:
                    _unit(texts[i], i, w)
                except BaseException as e:  # noqa: BLE001 - recorded
                    os.write(w, (json.dumps(dict(i=i, phase="error", err=repr(e)[:200])) + "\n").encode())
                os._exit(0)
            os.close(w)
            os.set_blocking(r, False)
            buf, t0, killed = b"", time.monotonic(), False
            while True:
                try:
                    chunk = os.read(r, 65536)
                    if not chunk:
                        break
                    buf += chunk
                except BlockingIOError:
                    time.sleep(0.2)
                cpu = pool.cpu_seconds(pid)
                if not killed and cpu is not None and cpu > a.limit:
                    os.kill(pid, signal.SIGKILL)
                    killed = True
            os.waitpid(pid, 0)
            os.close(r)
            fo.write(buf.decode())
            fo.write(json.dumps(dict(i=i, phase="end", killed=killed, wall=time.monotonic() - t0)) + "\n")
            fo.flush()
            print(i, "killed" if killed else "done", round(time.monotonic() - t0, 1), flush=True)


if __name__ == "__main__":
    main()
