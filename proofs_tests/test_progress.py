"""The status line of long commands (langur.progress): shown on a terminal, never elsewhere."""

from __future__ import annotations

import os
import select
import subprocess
import sys
import time

from langur import progress

SLOW = ("param a = 0.5\nint ([0, 1], [0, 1]) exp(sin(x * a)^3 + y * log(1 + x^2 + a)) * "
        "[x^2 + y^3 <= x * a + y] * [x <= a^2 + y^2] d(x, y)\n")


def test_a_phase_is_shown_and_cleared(capsys, monkeypatch):
    monkeypatch.setattr(progress, "_DELAY", 0.0)
    monkeypatch.setattr(progress, "_INTERVAL", 0.01)
    progress.enable("eval", on=True)
    try:
        with progress.phase("exact engine"):
            time.sleep(0.2)
    finally:
        progress.enable("eval", on=False)
    err = capsys.readouterr().err
    assert "langur eval: exact engine… 0 s" in err and err.endswith("\r\x1b[2K")


def test_nothing_is_written_off_a_terminal(capsys):
    progress.enable("eval", on=False)
    with progress.phase("exact engine"):
        time.sleep(0.05)
    assert capsys.readouterr().err == ""


def test_the_command_line_shows_its_phase_on_a_terminal(tmp_path):
    path = tmp_path / "slow.lgr"
    path.write_text(SLOW, encoding="utf-8")
    master, slave = os.openpty()
    # (a budget of 15 s: the start-up and the first phases, each shorter than progress._DELAY, take a
    # second or two alone but several on a loaded machine, and the exact engine's phase must still last
    # _DELAY before the budget ends for its line to be shown — with 4 s it sometimes did not, beside CI)
    proc = subprocess.Popen([sys.executable, "-m", "langur", "deriv", str(path), "--wrt", "a", "--timeout", "15"],
                            stdout=subprocess.DEVNULL, stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    seen = b""
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 1.0)
        if ready:
            try:
                chunk = os.read(master, 4096)
            except OSError:
                break
            if not chunk:
                break
            seen += chunk
        elif proc.poll() is not None:
            break
    proc.wait(timeout=60)
    os.close(master)
    text = seen.decode("utf-8", errors="replace")
    assert "langur deriv: " in text and "… " in text and " s" in text, text
    assert "stopped after 15 s" in text  # and the budget still holds
