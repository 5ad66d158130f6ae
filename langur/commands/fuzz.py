"""``langur fuzz``: differential testing of the exact and Monte Carlo engines (CLI.md).

Random well-typed, transverse programs (:mod:`langur.fuzz`), each evaluated by both engines:
value, derivative in each parameter, its regular and boundary parts, standard AD, and the
Theorem 8.1 check.  Exit status 0 when every comparison agrees, 1 when a discrepancy was found
(the minimal failing program, shrunk by hypothesis, is printed as ``.lgr`` text).
"""

from __future__ import annotations

import sys

from ..cli import UsageError
from . import _common as c


def add_arguments(p):
    p.add_argument("--examples", type=int, default=50, metavar="N",
                   help="number of random programs (default 50)")
    p.add_argument("--seed", type=int, default=0, help="random seed: same seed, same programs and numbers")
    p.add_argument("--samples", type=int, default=20000, metavar="N",
                   help="Monte Carlo samples per estimate (default 20000)")
    p.add_argument("--timeout", type=float, default=20.0, metavar="SECONDS",
                   help="time limit of the exact engine per program; slower programs count as timeouts (default 20)")
    p.add_argument("--method", choices=["uniform", "stratified", "qmc"], default="uniform",
                   help="Monte Carlo sampling (default uniform; the 5-sigma rule assumes i.i.d. "
                        "points: stratified/qmc standard errors can be 0 on a jump, so they false-alarm)")
    p.add_argument("--no-lint", action="store_true",
                   help="do not run the transversality linter (no program is discarded)")
    p.add_argument("--keep", metavar="DIR", help="write each failing program to DIR as a .lgr file")
    p.add_argument("--json", action="store_true", help="one JSON object on standard output")
    p.add_argument("-v", "--verbose", action="store_true", help="print each program's status as it runs")


def run(args) -> int:
    from .. import fuzz

    if args.examples < 1:
        raise UsageError("--examples must be at least 1")
    if args.samples < 2:
        raise UsageError("--samples must be at least 2")
    if args.timeout <= 0:
        raise UsageError("--timeout must be positive")

    def progress(res):
        if args.verbose:
            print(f"  {res.status:<18} {res.exact_seconds:6.1f}s  "
                  f"{res.text.splitlines()[-2].strip()[:90]}", file=sys.stderr)
            if res.failed:
                print("".join(f"    | {line}\n" for line in res.text.splitlines()), end="", file=sys.stderr)
                for r in res.rows:
                    if not r.ok:
                        print(f"    ! {r.quantity}{' wrt ' + r.wrt if r.wrt else ''}: exact {r.exact!r} "
                              f"(error {r.error:.3g}), mc {r.mc!r} ± {r.stderr:.3g}", file=sys.stderr)

    try:
        summary = fuzz.run_fuzz(args.examples, args.seed, args.samples, args.timeout, keep=args.keep,
                                lint=not args.no_lint, progress=progress, method=args.method)
    except fuzz.MissingHypothesis as e:
        print(f"langur fuzz: error: {e}", file=sys.stderr)
        return 2
    status = 1 if summary.failed else 0
    if args.json:
        c.dump_json(summary.to_json())
        return status
    counts = summary.counts()
    print(f"langur fuzz: {len(summary.results)} programs (seed {args.seed}, {args.samples} samples), "
          f"{summary.comparisons} comparisons")
    print(f"  {'status':<20}{'programs':>9}")
    for k, v in counts.items():
        print(f"  {k:<20}{v:>9}")
    worst = max((r for res in summary.results for r in res.rows if r.quantity != "theorem_8_1"
                 and r.stderr > 0), key=lambda r: r.z, default=None)
    if worst is not None:
        print(f"  largest |mc - exact| / stderr: {worst.z:.2f} ({worst.quantity}"
              f"{' wrt ' + worst.wrt if worst.wrt else ''})")
    if summary.minimal is not None:
        m = summary.minimal
        print(f"\nminimal failing program ({m.status}{': ' + m.reason if m.reason else ''}):")
        print(m.text, end="")
        for r in m.rows:
            if not r.ok:
                print(f"  {r.quantity}{' wrt ' + r.wrt if r.wrt else ''}: exact {c.fmt(r.exact)}"
                      f" (error {c.fmt(r.error, 3)}), mc {c.fmt(r.mc)} ± {c.fmt(r.stderr, 3)}")
    for path in summary.kept:
        print(f"  wrote {path}")
    print("all comparisons agree" if not status else "DISCREPANCY found")
    return status
