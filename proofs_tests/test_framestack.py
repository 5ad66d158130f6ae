"""langur.framestack: a computation whose call depth crosses a frame-stack chunk's edge over and
over maps and unmaps memory each time (CPython 3.11); run inside :func:`framestack.run` it does not.

Counted in minor page faults (``resource.getrusage``), not time: each chunk mapped anew is touched,
so a recursion that crosses an edge 100 times costs at least 100 faults without the large
frame, and almost none with it.  The check runs in a fresh process so that nothing else in the test
session (a deeper caller, another test's chunks) moves the edges.
"""

import subprocess
import sys
import textwrap

import pytest

from langur import framestack

SCRIPT = textwrap.dedent("""
    import resource, sys
    from langur import framestack

    def down(n):
        return 0 if n == 0 else 1 + down(n - 1)

    def work():
        faults = []
        for depth in range(20, 900, 40):  # some depth crosses a 16 KiB chunk's edge
            before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            for _ in range(100):
                down(depth)
            faults.append(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
        return max(faults)

    work()  # warm up: every page the interpreter and the allocator need is touched once
    print(work() if sys.argv[1] == "plain" else framestack.run(work))
""")


def _faults(mode: str) -> int:
    out = subprocess.run([sys.executable, "-c", SCRIPT, mode], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return int(out.stdout)


def test_the_result_and_the_exception_are_the_function_s():
    assert framestack.run(lambda a, b=0: a * 10 + b, 4, b=2) == 42

    def boom():
        raise KeyError("x")

    with pytest.raises(KeyError, match="x"):
        framestack.run(boom)


@pytest.mark.skipif(sys.implementation.name != "cpython" or sys.version_info[:2] != (3, 11),
                    reason="the 16 KiB frame-stack chunks are CPython 3.11's")
def test_crossing_a_chunk_edge_maps_memory_only_without_the_large_frame():
    plain, large = _faults("plain"), _faults("large")
    assert plain >= 100, plain  # 100 recursions across an edge: at least one fault each
    assert large < 20, large
