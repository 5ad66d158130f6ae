"""``langur fuzz``: differential testing of the exact and Monte Carlo engines (CLI.md).

Random well-typed, transverse programs (:mod:`langur.fuzz`), each evaluated by both engines:
value, derivative in each parameter, its regular and boundary parts, standard AD, and the
Theorem 8.1 check.  Exit status 0 when every comparison agrees, 1 when a discrepancy was found
(the minimal failing program, shrunk by hypothesis, is printed as ``.lgr`` text).
"""

from __future__ import annotations

import math
import os
import statistics
import sys

from .. import engines, fuzz
from ..cli import MAX_SAMPLES, UsageError, count, samples, seed
from . import _common as c

#: Most programs one run generates, and the longest time limit per program (a day).
MAX_EXAMPLES = 1_000_000
MAX_TIMEOUT = 86400.0


def add_arguments(p):
    p.add_argument("--examples", type=count(1, MAX_EXAMPLES, "the number of programs"), default=50, metavar="N",
                   help=f"number of distinct random programs, 1 to {MAX_EXAMPLES:,} (default 50)")
    p.add_argument("--seed", type=seed, default=0, metavar="S",
                   help="random seed, a non-negative integer: same seed, same programs and numbers")
    p.add_argument("--samples", type=samples(), default=20000, metavar="N",
                   help=f"Monte Carlo samples per estimate, 2 to {MAX_SAMPLES:,} (default 20000)")
    p.add_argument("--timeout", type=float, default=20.0, metavar="SECONDS",
                   help="time limit per program (the exact engine; the whole unit is killed when it has used "
                        f"{fuzz.pool.GRACE:g} CPU seconds more); slower programs are counted apart as timeouts, "
                        "never as verdicts (default 20)")
    p.add_argument("--workers", type=count(0, 1024, "the number of workers"), default=None, metavar="N",
                   help="long-lived worker processes, each running one program (both engines) at a time and "
                        "keeping its caches; one whose program reaches its time limit is killed and replaced; "
                        "0 runs in this process (default: the core count)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the units on the Dask distributed cluster at ADDRESS (e.g. tcp://host:8786) "
                        "instead of local workers (needs the cluster extra: pip install -e '.[cluster]')")
    p.add_argument("--hypothesis-dir", metavar="DIR",
                   help="hypothesis's storage folder (default $HYPOTHESIS_STORAGE_DIRECTORY, else "
                        "~/.cache/langur/hypothesis; never the current folder unless asked)")
    p.add_argument("--no-shrink", action="store_true",
                   help="report the first failing program as found (no hypothesis shrinking; the files of --out are "
                        "still shrunk, at most 40 candidates each)")
    p.add_argument("--method", choices=["uniform", "stratified", "qmc"], default="uniform",
                   help="Monte Carlo sampling (default uniform; stratified and qmc estimate their standard "
                        "error from 32 independent, randomly shifted replicates, widened for their 31 "
                        "degrees of freedom; any comparison outside 5 standard errors is estimated again "
                        "with 10 times the samples)")
    p.add_argument("--no-lint", action="store_true",
                   help="do not run the transversality linter (no program is discarded)")
    p.add_argument("--out", "--keep", dest="out", metavar="DIR",
                   help="write each failing program to DIR as a shrunk .lgr file whose comment header holds "
                   "both engines' numbers (created if missing; files already there are never overwritten; "
                   "--keep is the old name)")
    p.add_argument("--engine", metavar="NAME",
                   help="compare this engine with the exact engine instead of the Monte Carlo engine: "
                   "standard-ad, module:function, cmd:PROGRAM or an installed plug-in (docs/engines.md)")
    p.add_argument("--kinks", action="store_true",
                   help="also draw conditions with abs, min or max inside (split at their kinks)")
    p.add_argument("--turning", action="store_true",
                   help="also draw conditions in one variable with no closed-form inverse "
                        "(x^3 - x, exp(x) + x: implicit roots between turning points)")
    p.add_argument("--wide", action="store_true",
                   help="also draw what the default draw never makes (langur.strategies.wide, .variants): "
                        "sum/prod loops (nested too), &/|/not, a let inside a factor, partial primitives under a "
                        "guard, atan2's cut, erf/asin/acos/atanh/tan (erf also in conditions), ifge0 on any "
                        "condition, strict chains with pi, vectors (dot, cross, .z), negative exponents, a diffeo "
                        "with a parametric Jacobian, boxes with both ends moving, programs without a domain, "
                        "negative parameter defaults, programs without parameters, a def called with other "
                        "parameter terms (and a def's let at other parameter terms), modules (a def imported, "
                        "renamed, through a second module; diffeos from a module), comments, CRLF, tabs, "
                        "numbers as .5 or 37e-2, ≤/≥, extra parentheses; the same seed draws other programs "
                        "than without --wide")
    p.add_argument("--poles", action="store_true",
                   help="also draw conditions with a moving pole ([(x - a)/(y + b) >= 0], [1/(x - b) >= 1]), "
                        "products of moving factors ([(x - a)*(y - b) >= 0], a factor squared or cubed), such "
                        "conditions as an if's inside another, and terms spelled with neutral elements "
                        "(x*1, t - 0, 0*(1/(x - a))) (langur.strategies.poles)")
    p.add_argument("--huge", action="store_true",
                   help="draw a third of the programs over a huge box (up to [-1e10, 1e10]) with decaying "
                        "weights: narrow or far-off Gaussians, 1/(1 + x^2)")
    p.add_argument("--deep", action="store_true",
                   help="also draw products of moving lines over two variables ([(x + y - a)*(x - 2*y - b) "
                        ">= 0], one cubed, over a moving pole), split conditions nested three deep, and "
                        "such a condition in a def called at two parameter terms (langur.strategies.deep; "
                        "up to 7 zero sets per program instead of 4)")
    p.add_argument("--profile", action="store_true",
                   help="print where the programs' time went: front end, linter, the exact engine's "
                        "symbolic search, its quadratures and the rest of it, the Monte Carlo engine")
    p.add_argument("--json", action="store_true", help="one JSON object on standard output")
    p.add_argument("-v", "--verbose", action="store_true", help="print each program's status as it runs")


def run(args) -> int:
    if not (math.isfinite(args.timeout) and 0 < args.timeout <= MAX_TIMEOUT):
        raise UsageError(f"--timeout must be a positive number of seconds, at most {MAX_TIMEOUT:g}")
    if args.out is not None and os.path.exists(args.out) and not os.path.isdir(args.out):
        raise UsageError(f"--out {args.out}: exists and is not a directory (it is never overwritten)")
    if args.out is not None:
        try:  # before the run, so that a long run never ends unable to keep its programs
            os.makedirs(args.out, exist_ok=True)
        except OSError as e:
            raise UsageError(f"--out {args.out}: cannot create the directory ({e.strerror})") from None

    def progress(res):
        if args.verbose:
            print(f"  {verbose_times(res)}  {res.text.splitlines()[-2].strip()[:90]}", file=sys.stderr)
            if res.failed:
                print("".join(f"    | {line}\n" for line in res.text.splitlines()), end="", file=sys.stderr)
                for r in res.rows:
                    if not r.ok:
                        print(f"    ! {r.quantity}{' wrt ' + r.wrt if r.wrt else ''}: exact {r.exact!r} "
                              f"(error {r.error:.3g}), {r.engine} {r.mc!r} ± {r.stderr:.3g}", file=sys.stderr)

    workers = fuzz.pool.default_workers() if args.workers is None else args.workers
    bar = None if (args.json or args.verbose or not sys.stderr.isatty()) else _progress_bar.make(args.examples)

    def shown(res):
        progress(res)
        if bar is not None:
            bar.advance(res)

    engine = None
    if args.engine is not None:
        try:
            engine = engines.resolve(args.engine, samples=args.samples, seed=args.seed, method=args.method,
                                     timeout=args.timeout)
        except engines.UnknownEngine as e:
            raise UsageError(str(e)) from None
    try:
        with bar if bar is not None else _nothing():
            summary = fuzz.run_fuzz(args.examples, args.seed, args.samples, args.timeout, keep=args.out,
                                    lint=not args.no_lint, progress=shown, method=args.method, engine=engine,
                                    workers=workers, shrink=not args.no_shrink,
                                    storage=args.hypothesis_dir, scheduler=args.scheduler,
                                    planned=bar.plan if bar is not None else None,
                                    kinks=args.kinks, turning=args.turning, wide=args.wide,
                                    poles=args.poles, huge=args.huge, deep=args.deep)
    except (fuzz.MissingHypothesis, fuzz.cluster.MissingCluster) as e:
        print(f"langur fuzz: error: {e}", file=sys.stderr)
        return 2
    status = 1 if summary.failed else 0
    if args.json:
        c.dump_json(summary.to_json())
        if args.profile:
            print(profile_text(summary), file=sys.stderr)
        return status
    counts = summary.counts()
    print(f"langur fuzz: {len(summary.results)} programs (seed {args.seed}, {args.samples} samples), "
          f"{summary.comparisons} comparisons, {summary.seconds:.1f} s with {workers or 'no'} worker"
          f"{'s' if workers != 1 else ''} ({60 * len(summary.results) / max(summary.seconds, 1e-9):.1f} programs/minute)")
    print(f"  {'status':<20}{'programs':>9}")
    for k, v in counts.items():
        print(f"  {k:<20}{v:>9}")
    th = summary.theorem_counts()
    if any(th.values()):
        print(f"  Theorem 8.1 on the partial derivatives: {th['checked']} checked, {th['undecided']} undecided, "
              f"{th['budget']} left out (its CPU budget spent), {th['not_computed']} not computed")
    worst = max((r for res in summary.results for r in res.rows if r.quantity != "theorem_8_1"
                 and r.stderr > 0), key=lambda r: r.z, default=None)
    label = engine.name if engine is not None else "mc"
    if worst is not None:
        print(f"  largest |{label} - exact| / error: {worst.z:.2f} ({worst.quantity}"
              f"{' wrt ' + worst.wrt if worst.wrt else ''})")
    if summary.minimal is not None:
        m = summary.minimal
        print(f"\nminimal failing program ({m.status}{': ' + m.reason if m.reason else ''}):")
        print(m.text, end="")
        for r in m.rows:
            if not r.ok:
                print(f"  {r.quantity}{' wrt ' + r.wrt if r.wrt else ''}: exact {c.fmt(r.exact)}"
                      f" (error {c.fmt(r.error, 3)}), {r.engine} {c.fmt(r.mc)} ± {c.fmt(r.stderr, 3)}")
    if workers or args.scheduler:
        rows = summary.coverage()
        print(f"  rule coverage ({sum(1 for *_, n in rows if n)}/{len(rows)} rules fired):")
        for fig, rule, n in rows:
            print(f"    {fig:<14}{rule:<44}{n:>9}{'   NEVER' if not n else ''}")
    if args.profile:
        print(profile_text(summary))
    for path in summary.kept:
        print(f"  wrote {path}")
    print("all comparisons agree" if not status else "DISCREPANCY found")
    return status


def verbose_times(res) -> str:
    """A program's status and times for ``-v``: the exact engine's seconds, then the CPU seconds
    its whole unit used in its worker (a unit killed at its time limit: what it had used when it
    was killed, its exact engine's share unknown: ``-``; outside a worker pool: no CPU column)."""
    killed = res.status == "timeout" and res.exact_seconds == 0.0
    exact = f"{'-':>6} " if killed else f"{res.exact_seconds:6.1f}s"
    cpu = f" {res.cpu_seconds:6.1f} CPU s" if res.cpu_seconds > 0 else ""
    return f"{res.status:<18} {exact}{cpu}"


def profile_text(summary) -> str:
    """Where the per-program budget went (``--profile``): each phase's total, share, median and
    largest time per program, then the slowest programs with their split."""
    phases = fuzz.compare.PHASES
    results = summary.results
    total = summary.timing()
    whole = sum(total.values()) or 1e-9
    lines = [f"  time per phase over {len(results)} programs (wall seconds; a unit killed at its time limit counts the "
             "phases it finished):",
             f"    {'phase':<18}{'total':>9}{'share':>8}{'median':>9}{'max':>9}"]
    for k in phases:
        per = sorted(r.timing.get(k, 0.0) for r in results) or [0.0]
        lines.append(f"    {k:<18}{total[k]:>9.1f}{100 * total[k] / whole:>7.0f}%{statistics.median(per):>9.3f}"
                     f"{per[-1]:>9.2f}")
    killed = [r for r in results if r.status == "timeout"]
    if killed:
        where = {}
        for r in killed:
            where[r.killed_in or "unknown"] = where.get(r.killed_in or "unknown", 0) + 1
        lines.append(f"    killed at the time limit: {len(killed)} ("
                     + ", ".join(f"{n} in {k}" for k, n in sorted(where.items(), key=lambda kv: -kv[1])) + ")")
    cpu = sorted(r.cpu_seconds for r in results if r.cpu_seconds > 0)
    if cpu:
        lines.append(f"    CPU seconds per program (in its worker; the machine may be shared): median "
                     f"{statistics.median(cpu):.3f}, mean {sum(cpu) / len(cpu):.3f}, total {sum(cpu):.1f} "
                     f"over {len(cpu)} programs, of which {sum(r.cpu_seconds for r in killed):.1f} in the "
                     f"{len(killed)} killed at their time limit")
    exact = sorted(r.exact_seconds for r in results) or [0.0]
    lines.append(f"    exact engine per program: median {statistics.median(exact):.3f} s, "
                 f"{sum(e > 1.0 for e in exact)} of {len(results)} over 1 s")
    slow = sorted(results, key=lambda r: -r.seconds)[:5]
    if slow:
        lines.append("  slowest programs:")
    for r in slow:
        split = ", ".join(f"{k} {r.timing.get(k, 0.0):.2f}" for k in phases if r.timing.get(k, 0.0) >= 0.01)
        body = r.text.strip().splitlines()
        lines.append(f"    {r.seconds:6.2f} s {r.status:<10} {split or '(killed: no split)'}")
        lines.append(f"             {(body[-2] if len(body) > 1 else body[-1]).strip()[:100]}")
    return "\n".join(lines)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


class _progress_bar:
    """A rich progress bar on standard error with live counts (only on a terminal; none without rich)."""

    @classmethod
    def make(cls, total: int):
        try:
            return cls(total)
        except ImportError:  # rich is optional: the summary still comes at the end
            return None

    def __init__(self, total: int):
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        self.counts: dict[str, int] = {}
        self.progress = Progress(TextColumn("langur fuzz"), BarColumn(), MofNCompleteColumn(),
                                 TimeElapsedColumn(), TextColumn("{task.description}"),
                                 console=Console(stderr=True), transient=True)
        self.task = self.progress.add_task("", total=total)

    def plan(self, n: int):
        """The campaign has ``n`` distinct programs (hypothesis may repeat one)."""
        self.progress.update(self.task, total=n)

    def advance(self, res):
        self.counts[res.status] = self.counts.get(res.status, 0) + 1
        self.progress.update(self.task, advance=1,
                             description=" ".join(f"{k} {v}" for k, v in sorted(self.counts.items())))

    def __enter__(self):
        self.progress.__enter__()
        return self

    def __exit__(self, *exc):
        return self.progress.__exit__(*exc)
