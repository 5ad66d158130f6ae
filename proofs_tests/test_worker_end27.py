"""The end of a test session leaves pytest's clean-up nothing heavy to do (``conftest.py``).

Under pytest-xdist a worker is shut down once it reports its session finished, and execnet sends
it a SIGINT when it has not ended 5 s later.  What a worker still did then was pytest's clean-up:
five full garbage collections, each over the whole heap the suite built — on a loaded machine more
than 5 s, so the SIGINT arrived inside one of them and hypothesis's ``gc.callbacks`` timer printed
"Exception ignored in: <function gc_callback ...>" with a ``KeyboardInterrupt`` (seen at the end of
whole-suite runs).  The conftest's ``pytest_sessionfinish`` now collects once and freezes what
survives (``gc.freeze``), before the worker reports: pytest's later collections traverse only what
is made after.

The test runs a short session of this suite in a fresh process with a probe plugin that counts, as
pytest's clean-up starts, the objects its collections would traverse and those frozen.
"""

import json
import os
import subprocess
import sys
import textwrap

from paths import REPO

PROBE = textwrap.dedent('''
    import gc, json, os
    import pytest

    @pytest.hookimpl(trylast=True)
    def pytest_unconfigure(config):
        # (pytest's clean-up, with its full collections, runs right after the last unconfigure)
        with open(os.environ["ENDPROBE_OUT"], "w") as f:
            json.dump({"traversed": len(gc.get_objects()), "frozen": gc.get_freeze_count(),
                       "collector_on": gc.isenabled()}, f)
''')


def test_pytests_end_of_session_collections_traverse_only_what_is_made_after_the_session(tmp_path):
    (tmp_path / "endprobe.py").write_text(PROBE)
    out = tmp_path / "end.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(REPO)]), "ENDPROBE_OUT": str(out)}
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-o", "addopts=", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
         "-p", "endprobe", "proofs_tests/test_timebox_gap.py::test_limits_still_work_after_the_gap_tests"],
        capture_output=True, text=True, env=env, cwd=REPO, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    end = json.loads(out.read_text())
    # the session's heap (pytest, hypothesis, langur: tens of thousands of objects) is frozen ...
    assert end["frozen"] > 20_000, end
    # ... and what pytest's collections still traverse is what was made after it, a small fraction
    # (on main, before the fix: the whole heap, nothing frozen)
    assert end["traversed"] < end["frozen"] / 10, end
    assert end["collector_on"], end  # frozen, not switched off
