"""Issue 15's one-shot process, this tree beside another (a checkout of main) and the peers (not a test).

Run:  python bench/oneshot_against.py OTHER_TREE [--teg DIR] [--potto DIR] [--rounds K]

Round by round (each round runs every process once, in turn, so that a change of the machine's load
falls on all of them alike): ``python -P -m langur eval examples/fig1.lgr --engine mc`` in each tree
(``PYTHONPATH`` and the working directory that tree, its compiled modules kept in a folder of its
own: ``PYTHONPYCACHEPREFIX``, written by one run before the rounds), each peer's
``bench/peer_programs/NAME_fig1.py`` with ``PYTHONPATH=DIR`` (as ``bench_issue15.py`` runs them), and
``python -c "import numpy"``, the floor under all of them.  Medians and minima of wall and CPU
(user + system) seconds, and the load average before and after; numpy's BLAS on one thread
(``bench_text_to_number``'s setting).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_text_to_number as ttn  # noqa: E402  (first: it sets numpy's BLAS threads)

ROOT = ttn.ROOT
PROGRAMS = os.path.join(ROOT, "bench", "peer_programs")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("other", help="another source tree (a checkout of main)")
    ap.add_argument("--teg", metavar="DIR")
    ap.add_argument("--potto", metavar="DIR")
    ap.add_argument("--rounds", type=int, default=15)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        commands = {}
        for name, tree in (("langur eval --engine mc (this tree)", ROOT),
                           ("langur eval --engine mc (other tree)", os.path.abspath(args.other))):
            env = {**ttn._env(os.path.join(cache, str(len(commands)))), "PYTHONPATH": tree}
            commands[name] = (["-P", *ttn.ONE_SHOT], env, tree)
        for peer, path in (("teg", args.teg), ("potto", args.potto)):
            if path:
                env = {**ttn._env(os.path.join(cache, peer)), "PYTHONPATH": os.path.abspath(path)}
                commands[peer] = ([os.path.join(PROGRAMS, f"{peer}_fig1.py")], env, ROOT)
        commands["python -c 'import numpy'"] = (["-c", "import numpy"], ttn._env(os.path.join(cache, "numpy")), ROOT)
        for argv, env, cwd in commands.values():  # (writes the compiled modules)
            subprocess.run([sys.executable, *argv], cwd=cwd, env=env, check=True, capture_output=True)
        loads = [os.getloadavg()[0]]
        times: dict = {name: [] for name in commands}
        for _ in range(args.rounds):
            for name, (argv, env, cwd) in commands.items():
                times[name].append(ttn.process(argv, env, cwd))
        loads.append(os.getloadavg()[0])
    print(f"load average {loads[0]:.1f} before, {loads[1]:.1f} after; {args.rounds} rounds; "
          f"this tree {ROOT}, other tree {os.path.abspath(args.other)}")
    floor = statistics.median(w for w, _ in times["python -c 'import numpy'"])
    print("| process | wall median | wall min | CPU median | CPU min | wall beyond numpy's |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, ts in times.items():
        walls, cpus = [w for w, _ in ts], [c for _, c in ts]
        print(f"| {name} | {statistics.median(walls):.3f} | {min(walls):.3f} | {statistics.median(cpus):.3f} | "
              f"{min(cpus):.3f} | {statistics.median(walls) - floor:+.3f} |")


if __name__ == "__main__":
    main()
