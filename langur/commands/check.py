"""``langur check FILE…``: parse, type-check and lint for transversality (CLI.md, Diagnostics).

Each FILE (``-`` is standard input, a directory means every ``*.lgr`` below it) is loaded by the
front end; its E1xx/T2xx errors are reported as they are, otherwise the transversality analysis
(``langur.transversality``, paper Def. 7.2) runs on the inlined program.  Findings pass through
the configuration (``[tool.langur]`` in the nearest pyproject.toml, ``--select``/``--ignore``;
``langur.lint.config``) and ``# noqa`` comments (``langur.lint.noqa``), and are printed in the
chosen format (``langur.lint.formats``).  With ``--prove`` each finding also carries the
Theorem 8.1 check at the parameter values in force (``langur.commands._prove``).

Exit status: 0 when nothing at error severity was reported (or ``--exit-zero``), 1 when
something was (including front-end errors), 2 for usage errors (unknown option, a FILE that is
missing, a malformed ``[tool.langur]``, a ``--select``/``--ignore``/configured code prefix that
matches no code, an ``--at`` name no FILE declares).  A FILE that exists but cannot be read (also
one found in a directory) is reported where it is, ``PATH:1:1: error E109 …`` with the operating
system's reason, every other file is still checked, and the status is then 2, the worst.
"""

from __future__ import annotations

import errno
import os
import sys
import time
from pathlib import Path

from .. import __version__, frontend
from ..cli import (
    UsageError,
    add_common,
    add_timeout,
    parse_assignments,
    parse_modules,
    refuse_unimported_modules,
)
from ..diagnostics import Diagnostic, LangurError, Span
from ..lint import config as cfgmod
from ..lint import fix as fixmod
from ..lint.formats import Report, distinct, known_codes, render
from ..lint.noqa import suppressed
from ..source import linked_away, read_file, read_source
from ..timebox import Clock, by_backstop, run_with_timeout, stopped_by
from ..transversality import check_library, check_loaded, point_of
from ._prove import Prover

FORMATS = ("text", "json", "sarif", "github")
STDIN_NAME = "<stdin>"


def add_arguments(p):
    p.add_argument(
        "files", nargs="+", metavar="FILE", help=".lgr files or directories to check (- reads standard input)"
    )
    add_common(p, params=True)
    add_timeout(p, "check", "for each FILE, in CPU seconds (and at most 10 × SECONDS + 5 of wall clock)")
    p.add_argument(
        "--format",
        choices=FORMATS,
        default=None,
        help="output format: text (default), json (same as --json), sarif (SARIF 2.1.0), "
        "github (GitHub Actions annotations)",
    )
    p.add_argument(
        "--exit-zero", action="store_true", help="exit with status 0 even when errors are reported"
    )
    p.add_argument(
        "--prove",
        action="store_true",
        help="for each finding, also check Theorem 8.1 at the parameter values in force "
        "(is the derivative actually wrong there?)",
    )
    p.add_argument(
        "--select",
        action="append",
        metavar="CODES",
        help="report only these code prefixes (comma-separated; replaces [tool.langur] select)",
    )
    p.add_argument(
        "--ignore",
        action="append",
        metavar="CODES",
        help="never report these code prefixes (comma-separated; added to [tool.langur] ignore)",
    )
    p.add_argument("--isolated", action="store_true", help="ignore every pyproject.toml configuration")
    p.add_argument(
        "--fix",
        action="store_true",
        help="write the transverse rewrite (paper §7.3.2) of each FILE with X301 findings to "
        "NAME.fixed.lgr (never over an existing file) and report what remains",
    )
    p.add_argument("--in-place", action="store_true", help="with --fix: rewrite FILE itself, keeping FILE.bak")
    p.add_argument("--diff", action="store_true", help="print the rewrite of --fix as a unified diff; write nothing")
    p.add_argument(
        "--stdin-filename", metavar="PATH", help="the name standard input is reported (and configured) as"
    )


def _codes(values) -> list[str] | None:
    if not values:
        return None
    out = [c.strip() for v in values for c in v.split(",") if c.strip()]
    return out or None


def _expand(files: list[str]) -> tuple[list[str], set[str]]:
    """The FILEs to check, a directory replaced by its ``*.lgr`` files; and those found that way
    (nobody named them: ``source.linked_away`` is asked before one is read)."""
    out: list[str] = []
    found_in_dirs: set[str] = set()
    stdin_seen = False
    for f in files:
        if f == "-":
            if stdin_seen:
                raise UsageError("standard input (-) can be checked only once")
            stdin_seen = True
            out.append(f)
        elif os.path.isdir(f):
            # every *.lgr entry that is not a directory: one that cannot be read (a broken link,
            # no permission) is reported as E109 with the others, not skipped
            found = sorted(str(p) for p in Path(f).rglob("*.lgr") if not p.is_dir())
            if not found:
                raise UsageError(f"{f}: no .lgr files in this directory")
            out.extend(found)
            found_in_dirs.update(found)
        elif not os.path.lexists(f):
            raise UsageError(f"{f}: no such file")
        else:
            out.append(f)
    return out, found_in_dirs


def _check_prefixes(cfg, known, where: str | None = None) -> None:
    """A code prefix that matches no code is a usage error (it would select or ignore nothing)."""
    bad = cfg.unknown_prefixes(known)
    if bad:
        key, prefix = bad[0]
        raise UsageError(f"{where or key}: {prefix!r} matches no diagnostic code (codes: E1xx, T2xx, X3xx; "
                         "docs/CODES.md lists them)")


def unreadable(path: str, err: OSError) -> Diagnostic:
    """E109: the file exists but cannot be read (located at its start, with the OS's reason)."""
    return Diagnostic(Span(path, 1, 1, 1, 1), "error", "E109",
                      f"cannot read this file: {err.strerror or type(err).__name__}")


def timed_out(path: str, seconds: float, clock: Clock | None, used: float) -> Diagnostic:
    """X399: the check of ``path`` was stopped, saying by which limit (``clock``, None: the CPU budget)
    after ``used`` CPU seconds, and how to raise it (``--timeout`` sets both: CPU, and wall clock
    through :func:`~langur.timebox.backstop`)."""
    if clock is Clock.BACKSTOP:
        why = (f"was stopped {by_backstop(seconds, used)} (--timeout {seconds:g}: a larger one raises both "
               "limits; or check it again when the machine is less loaded)")
    else:
        why = (f"did not finish within {seconds:g} CPU s, its CPU budget (--timeout {seconds:g}; a larger "
               f"--timeout raises it)")
    return Diagnostic(Span(path, 1, 1, 1, 1), "error", "X399",
                      f"the check {why}: what was not reported is unchecked")


def here_at(at: dict, loaded) -> dict:
    return {k: v for k, v in at.items() if k in loaded.params}


def _fix(fixmod, text, name, loaded, modules, at, sources):
    """The rewrite of a file with X301 findings (None: nothing to rewrite)."""

    if not any(fd.code == "X301" for fd in check_loaded(loaded, at=at, sources=sources)):
        return None
    try:
        return fixmod.fix(text, name, loaded, modules)
    except fixmod.FixError as e:
        raise UsageError(str(e)) from None


def _check_one(args, name, data, cfg, modules, at, used_at: set, fixes: list, reports: list,
               loaded_files: list) -> None:
    """Check one FILE's contents (under its --timeout), appending to ``reports``, ``used_at``,
    ``fixes`` and ``loaded_files`` (its name and :class:`~langur.modules.Loaded`, once loaded)."""

    text = data.decode("utf-8", errors="replace")
    sources = {name: text}
    try:
        loaded = frontend.load_bytes(data, name, modules=modules, wait=args.timeout)
    except LangurError as e:
        reports.extend(Report(d) for d in e.diagnostics)
        return
    loaded_files.append((name, loaded))  # (as given: a rewrite below may inline what it imports)
    if (args.fix or args.diff) and loaded.program is not None:
        fixed = _fix(fixmod, text, name, loaded, modules, here_at(at, loaded), sources)
        if fixed is not None:
            fixes.append(fixed)
            if args.fix and not args.diff:  # report what remains in the rewritten file
                name = STDIN_NAME if name == STDIN_NAME else fixmod.target(name, args.in_place)
                text, sources = fixed.after, {name: fixed.after}
                # (its imports as the first load read them: a named pipe is not read twice)
                loaded = frontend.load_text(text, name, modules=modules, wait=args.timeout, files=loaded.files())
    here = {k: v for k, v in at.items() if k in loaded.params}
    used_at |= set(here)
    if loaded.program is None:  # a library module: each def on its own
        findings = check_library(loaded, sources=sources)
    else:
        findings = None
    for m in loaded.modules.values():  # imported modules: quoted in messages, their # noqa honoured
        if m.path not in sources:  # (the bytes the load read: a named pipe cannot be read again)
            sources[m.path] = m.source.decode("utf-8", errors="replace")
    if findings is None:
        findings = check_loaded(loaded, at=here, sources=sources)
    prover = (
        Prover(loaded.program, point_of(loaded.params, here))
        if args.prove and loaded.program is not None
        else None
    )
    for fd in findings:
        d: Diagnostic = fd.diagnostic()
        if not cfg.enabled(d.code, name) or suppressed(d, sources):
            continue
        reports.append(Report(d, prover.prove(fd.params) if prover is not None else None))


def run(args) -> int:
    fmt = args.format or ("json" if args.json else "text")
    if args.in_place and not args.fix:
        raise UsageError("--in-place goes with --fix")
    if args.json and args.format not in (None, "json"):
        raise UsageError(f"--json and --format {args.format} contradict each other")
    if fmt in ("json", "sarif") and (args.diff or (args.fix and "-" in args.files)):
        # standard output would carry a diff or a program, not the one JSON object (CLI.md)
        what = "--diff prints a diff" if args.diff else "--fix of standard input prints the program"
        raise UsageError(f"{what} on standard output: it does not go with {'--json' if args.json else '--format ' + fmt}")
    at = parse_assignments(args.at, "--at")
    modules = parse_modules(args.module)
    files, found_in_dirs = _expand(args.files)
    select, ignore = _codes(args.select), _codes(args.ignore)
    known = known_codes()
    _check_prefixes(cfgmod.Config(select=tuple(select or ()) or None), known, f"--select {','.join(select or ())}")
    _check_prefixes(cfgmod.Config(ignore=tuple(ignore or ())), known, f"--ignore {','.join(ignore or ())}")

    # Read everything first: a usage problem (bad config) stops before output; a file that cannot
    # be read is reported with the others (E109).
    inputs = []  # (name, data or E108's LangurError, configuration), or (name, None, the E109 diagnostic)
    for f in files:
        stdin = f == "-"
        name, where = (args.stdin_filename or STDIN_NAME, args.stdin_filename or os.getcwd()) if stdin else (f, f)
        try:
            away = linked_away(f) if f in found_in_dirs else None
            if away is not None:
                raise away
            if stdin:
                data = read_source(sys.stdin.buffer, name)
            else:  # within the budget, of wall clock: a named pipe no program writes to has nothing to read
                data = read_file(f, wait=args.timeout)
        except TimeoutError:
            inputs.append((f, None, unreadable(f, TimeoutError(errno.ETIMEDOUT, f"nothing to read after {args.timeout:g} s "
                                                               "(--timeout; a named pipe no program writes to?)"))))
            continue
        except OSError as e:
            inputs.append((f, None, unreadable(f, e)))
            continue
        except LangurError as e:  # too large to read (E108): reported with the others
            data = e
        try:
            cfg = cfgmod.Config() if args.isolated else cfgmod.find_config(where)
        except cfgmod.ConfigError as e:
            raise UsageError(str(e)) from None
        _check_prefixes(cfg, known)
        inputs.append((name, data, cfg.with_cli(select, ignore)))

    reports: list[Report] = []
    used_at: set[str] = set()
    fixes: list = []  # the --fix / --diff rewrites (langur.lint.fix)
    loaded_files: list = []  # (name, Loaded) of each FILE that loaded: what it imports
    unread = [name for name, data, _ in inputs if data is None]
    for name, data, cfg in inputs:
        if data is None:
            reports.append(Report(cfg))
            continue
        if isinstance(data, LangurError):
            reports.extend(Report(d) for d in data.diagnostics)
            continue
        start = time.process_time()
        try:  # CPU seconds, as every limit of the linter: a busy machine does not change the findings
            run_with_timeout(lambda n=name, d=data, c=cfg: _check_one(args, n, d, c, modules, at, used_at, fixes,
                                                                       reports, loaded_files), args.timeout, cpu=True)
        except TimeoutError as e:
            reports.append(Report(timed_out(name, args.timeout, stopped_by(e), time.process_time() - start)))
    reports = distinct(reports)
    unknown = sorted(set(at) - used_at)
    if unknown and not any(r.diagnostic.code[:1] in ("E", "T") for r in reports):
        raise UsageError(f"--at {unknown[0]}: no checked FILE declares this parameter")
    if len(loaded_files) == len(inputs):  # (a FILE that did not load may import any module)
        refuse_unimported_modules(modules, loaded_files)

    if args.diff:
        for f in fixes:
            sys.stdout.write(f.diff(fixmod.target(f.path, args.in_place) if f.path != STDIN_NAME else f.path))
        return 1 if fixes else 0
    if args.fix:
        for f in fixes:
            if f.path != STDIN_NAME:
                try:
                    fixmod.check_writable(f, args.in_place)
                except fixmod.FixError as e:
                    raise UsageError(str(e)) from None
                except OSError as e:  # FILE.bak a directory, …: nothing written, one line
                    raise UsageError(f"{e.filename or f.path}: {e.strerror}: not overwritten") from None
        for f in fixes:
            if f.path == STDIN_NAME:
                sys.stdout.write(f.after)
                continue
            try:
                dest = fixmod.write(f, args.in_place)
            except OSError as e:  # a folder that cannot be written, a full disk
                raise UsageError(f"{e.filename or f.path}: cannot write the rewrite ({e.strerror})") from None
            how = "printed whole, defs inlined" if f.whole else f"{len(f.rewritten.replaced)} subterm(s)"
            print(f"{f.path}: transverse rewrite (paper §7.3.2, {how}) written to {dest}"
                  + (f" (backup {f.path}.bak)" if args.in_place else ""), file=sys.stderr)
    out = render(reports, fmt, __version__)
    if out:  # with --fix of standard input, standard output carries the fixed program
        print(out, file=sys.stderr if args.fix and any(f.path == STDIN_NAME for f in fixes) else sys.stdout)
    errors = sum(1 for r in reports if r.diagnostic.severity == "error")
    warnings = len(reports) - errors
    if fmt == "text":
        n = len(inputs) - len(unread)
        checked = f"{n} file{'s' if n != 1 else ''}"
        if reports:
            print(f"{checked} checked: {errors} error(s), {warnings} warning(s)"
                  + (f", {len(unread)} file(s) could not be read" if unread else ""), file=sys.stderr)
    if unread:
        return 2
    return 0 if args.exit_zero or errors == 0 else 1
