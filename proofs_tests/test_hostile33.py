"""Hostile input, seventh round (hostile33): a program or module read twice (a named pipe, a file that
changes in between), definitions inlined into millions of nodes by a three-line file, a module that is
a symbolic link to a secret, a render grid whose ends are ±1e308, an output file the system refuses —
each failing on main at 3851775 (a hang, an internal error, minutes of CPU and gigabytes, a leaked
word) and passing here.

Every command runs in a subprocess bounded in memory (``RLIMIT_AS``), CPU time (``RLIMIT_CPU``) and
wall clock; the contract (CLI.md): exit 0, 1 or 2, a located diagnostic or one usage line, never a
traceback or an internal error.  bench/history/2026-11-29.md#hostile33.
"""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest

# (the subprocess under RLIMIT_AS / RLIMIT_CPU / a wall clock, asserting the CLI contract, and a file)
from test_hostile32 import _file, _langur

from langur import frontend
from langur.diagnostics import LangurError
from langur.lint import fix as fixmod
from langur.syntax.inline import MAX_INLINED_NODES

SECRET = "ghp_TOKEN_hostile33_not_to_be_printed"


def _write_once(pipe: Path, text: str) -> threading.Thread:
    """A writer that puts ``text`` into the named pipe once (blocking until a reader opens it)."""

    def write():
        with open(pipe, "w", encoding="utf-8") as fh:
            fh.write(text)

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    return writer


# --- a program's files are read once per run ---------------------------------------------------------


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_check_fix_of_a_program_importing_a_named_pipe(tmp_path):
    """hostile32's leftover.  The module comes from a FIFO written once; the main program counts the
    jump [x ≥ a] twice (X301), so ``--fix`` writes the rewrite — and loaded it back to compare, which
    read the module again: a wait for a writer that never comes, until check's wall-clock backstop
    (main: X399 after 55 s at --timeout 5, no rewrite written).  The rewrite by hand (§7.3.2: the
    product of the two equal jumps is one jump, the body f(x) = x inlined where it holds):
    ``(ifge0 x - a then x else 0)``."""
    os.mkfifo(tmp_path / "pipe.lgr")
    _file(tmp_path, "main.lgr", "from pipe import f\nparam a = 0.5\nint ([0, 1]) f(x) * [x >= a] * [x >= a] d(x)\n")
    writer = _write_once(tmp_path / "pipe.lgr", "def f(x: var) = x\n")
    start = time.monotonic()
    r, said = _langur(tmp_path, "check", "main.lgr", "--fix", "--timeout", "5", wall=90)
    writer.join(5)
    assert time.monotonic() - start < 45, said
    assert "X399" not in r.stdout and r.returncode == 0, said
    assert "written to main.fixed.lgr" in r.stdout + r.stderr, said
    assert (tmp_path / "main.fixed.lgr").read_text(encoding="utf-8") == \
        "from pipe import f\nparam a = 0.5\nint ([0, 1]) (ifge0 x - a then x else 0) d(x)\n"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
@pytest.mark.parametrize("command, text, says", [
    (("eval", "--samples", "100"), "int ([0, 1]) 1/x d(x)\n",
     "p.lgr:1:14: error X311 `1/x` is not integrable on the domain"),
    (("deriv", "--wrt", "a", "--samples", "100"), "param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n",
     "error X301"),
])
def test_eval_and_deriv_of_a_program_from_a_named_pipe(tmp_path, command, text, says):
    """FILE is a FIFO written once.  ``eval`` (X311: ∫₀¹ dx/x diverges, by hand) and ``deriv`` (X301:
    the same jump twice) opened FILE a second time, with a blocking ``open``, to quote it: main
    waited for a writer until the command's 600 s --timeout (killed here after 90 s).  Now the text
    the load read is quoted, and the answer comes at once."""
    pipe = tmp_path / "p.lgr"
    os.mkfifo(pipe)
    writer = _write_once(pipe, text)
    r, said = _langur(tmp_path, command[0], "p.lgr", *command[1:], wall=90)
    writer.join(5)
    assert r.returncode == 1 and says in r.stderr, said


def test_a_rewrite_is_loaded_with_the_modules_the_program_was_loaded_with(tmp_path):
    """A module that changes while the command works: ``fix`` loads its rewrite back to compare it
    with the rewritten program, and read the imported module again — now a file that does not parse
    (main: the patch "did not load back", so the whole program was printed instead, defs inlined and
    the import gone; with another valid module it would have compared against another program).  Now
    the bytes the first load read: the file is patched in place."""
    lib = _file(tmp_path, "lib.lgr", "def f(x: var) = x\n")
    main = _file(tmp_path, "main.lgr", "from lib import f\nparam a = 0.5\nint ([0, 1]) f(x) * [x >= a] * [x >= a] d(x)\n")
    text = main.read_text(encoding="utf-8")
    loaded = frontend.load_text(text, str(main))
    lib.write_text("this is not a module\n", encoding="utf-8")  # changed after the load read it
    fixed = fixmod.fix(text, str(main), loaded)
    assert fixed is not None and not fixed.whole
    assert loaded.files() == {str(lib): b"def f(x: var) = x\n"}
    assert fixed.after.endswith("int ([0, 1]) (ifge0 x - a then x else 0) d(x)\n")
    with pytest.raises(LangurError):  # (the file on disk itself no longer loads)
        frontend.load_text(text, str(main))


# --- inlining: copies of definitions' bodies are bounded -------------------------------------------


def _copies(k: int, n: int) -> str:
    return (f"param a = 0.5\ndef f(y: var) = sum j in 1..{k}: y*j\n"
            f"int ([0, 1]) (sum i in 1..{n}: f(x + i)) * [x <= a] d(x)\n")


def test_inlining_a_loop_of_calls_at_distinct_arguments_is_bounded(tmp_path):
    """Three lines: a def whose body is a 1000-term loop, called at 1000 distinct arguments.  Each
    call with new arguments is a copy of the body (~3,000 nodes): ~3·10⁶ nodes in all.  Main built
    them all (17 CPU s and 500 MB for the front end alone; 2000 × 2000: 65 s and 1.9 GB; 5000 × 5000
    went past check's budget at 1.6 GB), and SECURITY.md said size needed no bound.  Now T230 at the
    call that passes 500,000 copied nodes — what loops may write out (T225) — well within 20 CPU s."""
    _file(tmp_path, "copies.lgr", _copies(1000, 1000))
    r, said = _langur(tmp_path, "check", "copies.lgr", cpu=20, wall=90)
    assert r.returncode == 1, said
    assert f"copies.lgr:3:33: error T230 program too large: `f(…)` here makes the copies of definitions' " \
           f"bodies more than {MAX_INLINED_NODES:,} nodes in all" in r.stdout, said


def test_a_loop_of_calls_within_the_bound_is_computed(tmp_path):
    """The same shape, 10 × 100: by hand ∫₀^a Σᵢ Σⱼ j·(x + i) dx = 55·(100·a²/2 + 5050·a), at a = ½
    55 · 2537.5 = 139562.5; and it is below the bound (about 100 copies of a 30-node body)."""
    _file(tmp_path, "few.lgr", _copies(10, 100))
    r, said = _langur(tmp_path, "eval", "few.lgr", "--engine", "exact", cpu=40)
    assert r.returncode == 0 and "exact : 139562.5" in r.stdout, said


# --- links out of the project --------------------------------------------------------------------


def test_a_module_that_links_to_a_file_that_is_not_a_module_is_not_read(tmp_path):
    """A pull request adds ``m.lgr -> SECRET FILE`` beside a program that imports m: ``langur check``
    in CI printed the file's first word (E102 "unexpected name '…'") — /proc/self/environ, a token
    file.  Now T223 at the import, the file unread; a link to another .lgr file is still a module
    (by hand ∫₀¹ x·[x ≤ ½] dx = 1/8)."""
    secret = tmp_path / "outside" / "token.txt"
    secret.parent.mkdir()
    secret.write_text(f"{SECRET} more\n", encoding="utf-8")
    project = tmp_path / "project"
    project.mkdir()
    (project / "m.lgr").symlink_to(secret)
    _file(project, "main.lgr", "from m import f\nint ([0, 1]) f(x) d(x)\n")
    for argv in (("check", "main.lgr"), ("eval", "main.lgr", "--samples", "100"), ("show", "main.lgr")):
        r, said = _langur(project, *argv)
        assert r.returncode == 1 and SECRET not in r.stdout + r.stderr, said
        assert f"main.lgr:1:6: error T223 module `m`: cannot read m.lgr (beside the importing file): it is a " \
               f"symbolic link to {secret.resolve()}, which is not a .lgr file" in r.stdout + r.stderr, said
    _file(tmp_path / "outside", "real.lgr", "def f(x: var) = x\n")
    (project / "lib.lgr").symlink_to(tmp_path / "outside" / "real.lgr")
    _file(project, "good.lgr", "from lib import f\nparam a = 0.5\nint ([0, 1]) f(x) * [x <= a] d(x)\n")
    r, said = _langur(project, "eval", "good.lgr", "--engine", "exact")
    assert r.returncode == 0 and "exact : 0.125" in r.stdout, said


def test_check_of_a_folder_does_not_read_a_link_to_a_secret(tmp_path):
    """``langur check DIR`` reads every *.lgr file it finds: a link ``evil.lgr -> token.txt`` among them
    printed the token (E102).  Now E109 for that entry; the others are checked; a FILE named on the
    command line is read wherever it leads (the user chose it)."""
    secret = tmp_path / "token.txt"
    secret.write_text(f"{SECRET}\n", encoding="utf-8")
    folder = tmp_path / "src"
    folder.mkdir()
    (folder / "evil.lgr").symlink_to(secret)
    _file(folder, "ok.lgr", "param a = 0.5\nint ([0, 1]) x * [x <= a] d(x)\n")
    r, said = _langur(tmp_path, "check", "src")
    assert SECRET not in r.stdout + r.stderr, said
    assert "src/evil.lgr:1:1: error E109 cannot read this file: it is a symbolic link to" in r.stdout, said
    assert "src/ok.lgr" not in r.stdout and r.returncode == 2, said  # (ok.lgr: no finding; 2: a file unread)
    r, said = _langur(tmp_path, "check", "src/evil.lgr")
    assert "E102" in r.stdout, said


# --- render's grid and outputs --------------------------------------------------------------------


def test_a_grid_whose_ends_are_beyond_the_doubles_apart(tmp_path):
    """``--grid b=-1e308:1e308:3``: numpy's linspace steps by (hi − lo)/2 = ∞, its points NaN, and the
    command stopped with an internal error (ParameterError b = nan).  Now the points −1e308, 0, 1e308
    (by hand), and the values those of ⟦p⟧ = min(1, a, b)²/2 clamped at 0 (by hand) within 5 standard
    errors; a picture, whose axes would pass ±1.8e308, is refused before any work."""
    _file(tmp_path, "two.lgr", "param a = 0.5, b = 0.5\nint ([0, 1]) x * [x <= a] * [x <= b] d(x)\n")
    r, said = _langur(tmp_path, "render", "two.lgr", "--grid", "a=0:1e308:3,b=-1e308:1e308:3", "--npz", "g.npz")
    assert r.returncode == 0, said
    g = np.load(tmp_path / "g.npz")
    assert list(g["a"]) == [0.0, 5e307, 1e308] and list(g["b"]) == [-1e308, 0.0, 1e308]
    A, B = np.meshgrid(g["a"], g["b"])
    m = np.clip(np.minimum(A, B), 0, 1)
    assert np.all(np.abs(g["value"] - m * m / 2) <= 5 * g["value_stderr"] + 1e-12), (g["value"], g["value_stderr"])
    r, said = _langur(tmp_path, "render", "two.lgr", "--grid", "a=0:1e308:3,b=-1e308:1e308:3", "-o", "g.png")
    assert r.returncode == 2 and "beyond the largest double" in r.stderr and not (tmp_path / "g.png").exists(), said


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0 or not os.path.isdir("/proc/self"),
                    reason="root, for whom access() calls /proc writable")
@pytest.mark.parametrize("argv", [("render", "two.lgr", "--grid", "a=0:1:2,b=0:1:2", "--npz", "/proc/x.npz"),
                                  ("render", "two.lgr", "--grid", "a=0:1:2,b=0:1:2", "-o", "/proc/x.png"),
                                  ("plot", "two.lgr", "--wrt", "a", "-o", "/proc/x.png")])
def test_an_output_the_system_refuses_is_a_usage_error(tmp_path, argv):
    """``/proc`` takes no new file, though ``access`` tells root it may write there: the write's
    FileNotFoundError was an internal error (main).  Now one usage line naming the file."""
    _file(tmp_path, "two.lgr", "param a = 0.5, b = 0.5\nint ([0, 1]) x * [x <= a] * [x <= b] d(x)\n")
    r, said = _langur(tmp_path, *argv)
    target = argv[-1]
    assert r.returncode == 2 and f"{argv[-2]} {target}: cannot write this file (No such file or directory)" \
        in r.stderr, said


# --- lines: one definition for the parser, quotes, # noqa and --fix ---------------------------------


def _check(tmp_path, name: str, text: str, *argv: str):
    (tmp_path / name).write_bytes(text.encode("utf-8"))
    return _langur(tmp_path, "check", name, *argv)


def test_a_comment_with_a_unicode_line_separator_moves_no_noqa(tmp_path):
    """A comment may hold U+2028 (or U+0085, a form feed); the parser's lines end at LF only, but quotes,
    ``# noqa`` and ``--fix`` split the text with ``str.splitlines``, which ends a line there too: every
    line after it was one off.  Main: a ``# noqa: X301`` on line 2 silenced the X301 on line 3 (a
    finding hidden by a directive on another line), the one on line 3 itself did not, X301 quoted
    `t ([0, 1` (text of another line), and ``--fix`` could not patch the file (the whole program
    printed instead, its comment lost).  By hand: the finding is at 3:14 in the first file."""
    head = "param a = 0.5 # one\u2028two\n"
    r, said = _check(tmp_path, "other.lgr", head + "int ([0, 1]) [x >= a] * # noqa: X301\n  [x >= a] d(x)\n")
    assert r.returncode == 1 and "other.lgr:3:3: error X301 `[x >= a]` and `[x >= a]` at 2:14" in r.stdout, said
    r, said = _check(tmp_path, "own.lgr", head + "int ([0, 1])\n  [x >= a] * [x >= a] d(x)  # noqa: X301\n")
    assert r.returncode == 0 and "X301" not in r.stdout, said
    r, said = _check(tmp_path, "fix.lgr", head + "int ([0, 1])\n  x * [x >= a] * [x >= a] d(x)\n", "--fix")
    assert r.returncode == 0, said
    assert (tmp_path / "fix.fixed.lgr").read_text(encoding="utf-8") == \
        head + "int ([0, 1])\n  (ifge0 x - a then x else 0) d(x)\n"


def test_carriage_return_line_ends_are_refused_where_they_stand(tmp_path):
    """CR-only line ends (old Mac files), which editors show as lines: the parser read one line, so a
    finding on the third line shown was at 1:55 (main: ``cr.lgr:1:55: error E104 … '$'``), its quote and
    ``# noqa`` taken from the wrong line.  Now E104 at the first lone CR (1:14, by hand); CRLF files
    are read as before (the error at 3:29)."""
    r, said = _check(tmp_path, "cr.lgr", "param a = 0.5\rparam b = 1\rint ([0, 1]) x * [x <= a] * $ d(x)\r")
    assert r.returncode == 1 and "cr.lgr:1:14: error E104 a carriage return (U+000D) not followed by a line " \
        "feed" in r.stdout, said
    r, said = _check(tmp_path, "crlf.lgr", "param a = 0.5\r\nparam b = 1\r\nint ([0, 1]) x * [x <= a] * $ d(x)\r\n")
    assert r.returncode == 1 and "crlf.lgr:3:29: error E104 unexpected character '$'" in r.stdout, said
