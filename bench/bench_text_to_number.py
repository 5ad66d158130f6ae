"""From text to number (issue 15): the front end, compile and evaluate of the §10.3 microbenchmarks,
one-shot processes and the Monte Carlo path's import time (not a test).

Run:  python bench/bench_text_to_number.py [--plot OUT.png] [--reps K]

* **Microbenchmark 1** at n = 1, 10, 25, 49, 100 (the program of ``bench_peers.langur_text``):
  ``load`` (text → elaborated, inlined, typed core; the front end's caches emptied first), ``link``
  (compile, §9) and ``eval`` (the derivative, 10 samples), CPU medians; text to number is their sum.
* **Microbenchmark 2**: the 90-jump scene with 50 shader swaps (``bench_peers.langur_mb2``: every swap
  a new module file, loaded, linked and evaluated), total CPU with the incremental front end
  (``frontend.CACHE``) and with every load from scratch (the cache cleared before each load).
* **One-shot**: wall and CPU time of ``python -m langur eval examples/fig1.lgr --engine mc`` (medians
  of K processes; on a loaded machine the CPU time is the fair number), and the CPU time of
  importing ``langur.frontend`` + ``langur.operational`` beyond numpy's; each with Python's
  compiled modules kept (as an installed package has them) and with every module compiled from
  source at start (``PYTHONDONTWRITEBYTECODE=1`` without a ``__pycache__``); and ``python -X
  importtime``'s cumulative time of those two imports (in-process wall time of the imports alone).

numpy's BLAS runs on one thread here (``OPENBLAS_NUM_THREADS=1``, ``OMP_NUM_THREADS=1``, in this
process and in the subprocesses, unless ``--blas-threads`` or the variables are already set): with
its default thread pool, idle BLAS threads spinning on the other core were counted in the process's
CPU time (user time above wall time in every one-shot run), which inflated the one-shot and import
numbers of earlier runs (before 2026-11-26, branch ``loadonce``).  Nothing measured here uses BLAS.

``--sizes 49,100`` measures those n only; ``--mb1-only`` skips microbenchmark 2 and the processes.

``--against ROOT``: side by side with another source tree (a checkout of main): microbenchmark 1
and the one-shot, each tree in processes of its own (``python -P``, ``PYTHONPATH=tree``), alternated
``--rounds`` times; microbenchmark 1 as the minimum over calls and processes (on a shared machine the
minimum separates ±10 % where medians do not), the one-shot as medians of process CPU.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

if "--blas-threads" not in sys.argv:  # before numpy is imported (see the docstring)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from bench_peers import SCENE, langur_text  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIZES = (1, 10, 25, 49, 100)
CLOCK = time.process_time


def _times(f, reps: int, setup=None) -> tuple[list[float], object]:
    """The CPU times of ``reps`` calls of ``f()``, and its last result; the previous call's result
    is dropped and ``setup()`` called before the clock starts (freeing a whole loaded program is
    not the next load's work)."""
    ts, out = [], None
    for _ in range(reps):
        out = None
        if setup is not None:
            setup()
        t0 = CLOCK()
        out = f()
        ts.append(CLOCK() - t0)
    return ts, out


def _median(f, reps: int, setup=None):
    """Median CPU time of ``f()`` over ``reps`` calls (:func:`_times`), and its last result."""
    ts, out = _times(f, reps, setup)
    return statistics.median(ts), out


_MEMOS: list = [0, ()]  # (len(sys.modules) when last looked, the caches found)


def cold() -> None:
    """What a user's first load of new text finds: no module parsed or elaborated
    (``frontend.CACHE``) and no memo of the front end's: every ``functools`` cache of a loaded
    ``langur.syntax`` module emptied (the completions by condition shape of ``affine`` and
    ``diffeo``), so that loading the same text again and again costs what loading it once does.
    The same on any tree (``--against`` runs this definition in both); the interning tables of
    ``core`` and ``typesys`` (a few frozensets of names) are kept."""
    import functools

    from langur import frontend

    frontend.CACHE.clear()
    if _MEMOS[0] != len(sys.modules):  # (looked for again when a module was imported)
        _MEMOS[:] = [len(sys.modules), tuple(
            value for name, module in list(sys.modules.items())
            if name.startswith("langur.syntax.") and module is not None
            for value in list(vars(module).values()) if isinstance(value, functools._lru_cache_wrapper))]
    for memo in _MEMOS[1]:
        memo.cache_clear()


def mb1(n: int, reps: int) -> dict:
    from langur import frontend
    from langur.operational import clear_cache, estimate_derivative, link

    text = langur_text(n)

    # (cold() before the clock: emptying the caches frees the previous load's parsed and
    # elaborated module, 0.03 ms at n = 1 to 0.4 ms at n = 100, which is not this load's work)
    t_load, loaded = _median(lambda: frontend.load_text(text), reps, setup=cold)

    def compile_():
        clear_cache()
        return link(loaded)

    t_link, _ = _median(compile_, reps)
    t_eval, est = _median(lambda: estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=10, seed=0), reps)
    return {"n": n, "load": t_load, "link": t_link, "eval": t_eval, "total": t_load + t_link + t_eval,
            "value": est.value}


def mb2(swaps: int, incremental: bool) -> tuple[float, dict]:
    """CPU seconds of ``swaps`` shader swaps (module doc), and the counts: modules elaborated and
    reused, and ``load``, the CPU seconds of the loads alone (the front end)."""
    from langur import frontend
    from langur.operational import clear_cache, estimate_derivative

    with tempfile.TemporaryDirectory() as folder:
        scene = os.path.join(folder, "scene.lgr")
        with open(scene, "w") as fh:
            fh.write(SCENE)
        paths = []
        for k in range(swaps + 1):
            path = os.path.join(folder, f"shader_{k}.lgr")
            with open(path, "w") as fh:
                fh.write(f"def shade(x: var, a: param) = a {'+' if k < swaps else '-'} x + {k} * 0\n")
            paths.append(path)
        clear_cache()
        frontend.clear_load_cache()
        elaborated = reused = 0
        front = 0.0  # the CPU of the loads alone (the front end); the rest is link + evaluate
        t0 = CLOCK()
        for path in paths:
            if not incremental:
                frontend.clear_load_cache()
            t1 = CLOCK()
            loaded = frontend.load(scene, modules={"shader": path})
            front += CLOCK() - t1
            stats = frontend.load_stats()
            elaborated, reused = elaborated + len(stats["elaborated"]), reused + stats["reused"]
            frontend.reset_load_stats()
            estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=10, seed=0)
        return CLOCK() - t0, {"elaborated": elaborated, "reused": reused, "load": front}


def _env(bytecode: str | None) -> dict:
    """The subprocesses' environment: with ``bytecode`` a folder, Python's compiled modules are
    kept there (``PYTHONPYCACHEPREFIX``), as an installed package has them (pip compiles them at
    install); with ``None``, every module is compiled from source at each start, as in a process
    run with ``PYTHONDONTWRITEBYTECODE=1`` on a tree that has no ``__pycache__``."""
    env = {**os.environ, "PYTHONPATH": ROOT}  # (with the BLAS thread variables set above)
    if bytecode is None:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        env.pop("PYTHONPYCACHEPREFIX", None)
    else:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = bytecode
    return env


#: The one-shot process of issue 15's target.
ONE_SHOT = ("-m", "langur", "eval", "examples/fig1.lgr", "--engine", "mc")


def process(argv, env: dict, cwd: str = ROOT) -> tuple[float, float]:
    """Wall time and CPU time (user + system) of one process ``python ARGV`` run to its end."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, *argv], cwd=cwd, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def one_shot(reps: int, bytecode: str | None = None) -> tuple[float, float]:
    """Median wall time and median CPU time (user + system) of the whole process."""
    env = _env(bytecode)
    if bytecode is not None:  # one run first, which writes the compiled modules
        process(ONE_SHOT, env)
    walls, cpus = zip(*(process(ONE_SHOT, env) for _ in range(reps)))
    return statistics.median(walls), statistics.median(cpus)


def import_time(reps: int, bytecode: str | None = None) -> tuple[float, float]:
    code = ("import time; t0 = time.process_time(); import numpy; t1 = time.process_time(); "
            "import langur.frontend, langur.operational; t2 = time.process_time(); print(t1 - t0, t2 - t1)")
    env = _env(bytecode)
    if bytecode is not None:
        subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, check=True, capture_output=True)
    runs = [tuple(map(float, subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, check=True,
                                            capture_output=True, text=True).stdout.split())) for _ in range(reps)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def import_tree(reps: int, bytecode: str | None = None) -> float:
    """Median over ``reps`` processes of ``python -X importtime``'s cumulative time (s) of importing
    ``langur.frontend`` and ``langur.operational`` after numpy (the modules numpy already brought in
    are not counted again)."""
    env = _env(bytecode)
    out = []
    for _ in range(reps + (bytecode is not None)):
        err = subprocess.run([sys.executable, "-X", "importtime", "-c",
                              "import numpy; import langur.frontend, langur.operational"],
                             env=env, cwd=ROOT, check=True, capture_output=True, text=True).stderr
        total = 0
        for line in err.splitlines():
            parts = line.split("|")
            if len(parts) == 3 and parts[2].strip() in ("langur.frontend", "langur.operational") \
                    and parts[2].startswith(" langur"):  # top level: no indentation
                total += int(parts[1])
        out.append(total / 1e6)
    return statistics.median(out[1:] if bytecode is not None else out)


_SIDE = r"""
import json, os, sys, time
sys.path.insert(0, os.path.join(os.environ["LANGUR_TREE"], "bench"))
import bench_text_to_number as b
def least(f, reps, setup=None):
    ts, out = [], None
    for _ in range(reps):
        out = None
        if setup is not None:
            setup()
        t0 = time.process_time(); out = f(); ts.append(time.process_time() - t0)
    return min(ts), out
b._median = least
this = {}
exec(os.environ["LANGUR_COLD"], this)
import langur.frontend
b.cold = langur.frontend.clear_load_cache = this["cold"]  # (the same cold start in both trees)
exec(os.environ["LANGUR_MB1"], vars(b))  # (and the same measurement: this tree's mb1)
print(json.dumps({n: b.mb1(int(n), int(sys.argv[2])) for n in sys.argv[1].split(",")}))
"""


def _cold_source() -> str:
    import inspect

    return "import sys\n_MEMOS = [0, ()]\n" + inspect.getsource(cold)


def _mb1_source() -> str:
    import inspect

    return inspect.getsource(mb1)


def against(other: str, sizes: str, reps: int, rounds: int) -> None:
    """Microbenchmark 1 and the one-shot process, this tree and ``other`` side by side."""
    trees = {"other": os.path.abspath(other), "this": ROOT}
    mb: dict = {k: [] for k in trees}
    shots: dict = {k: [] for k in trees}
    envs = {}
    for k, root in trees.items():  # (each tree's compiled modules written once, before measuring)
        envs[k] = {**_env(None), "PYTHONPATH": root, "LANGUR_TREE": root, "LANGUR_COLD": _cold_source(),
                   "LANGUR_MB1": _mb1_source()}
        envs[k].pop("PYTHONDONTWRITEBYTECODE", None)
        subprocess.run([sys.executable, "-P", "-m", "langur", "eval", "examples/fig1.lgr", "--engine", "mc"],
                       cwd=root, env=envs[k], check=True, capture_output=True)
    for _ in range(rounds):
        for k, root in trees.items():
            env = envs[k]
            out = subprocess.run([sys.executable, "-P", "-c", _SIDE, sizes, str(reps)], env=env, cwd=root,
                                 check=True, capture_output=True, text=True).stdout
            mb[k].append(json.loads(out))
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run([sys.executable, "-P", "-m", "langur", "eval", "examples/fig1.lgr", "--engine", "mc"],
                           cwd=root, env=env, check=True, capture_output=True)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            shots[k].append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    print(f"load average {os.getloadavg()[0]:.1f}; {trees['other']} (other) vs {ROOT} (this), ms CPU, "
          f"minimum of {reps} calls x {rounds} processes")
    print("|   n | tree  |  load |  link |  eval | total | load / (link + eval) |")
    for n in sizes.split(","):
        for k in trees:
            r = {key: 1e3 * min(run[n][key] for run in mb[k]) for key in ("load", "link", "eval")}
            total = r["load"] + r["link"] + r["eval"]
            print(f"| {n:>3} | {k:5s} | {r['load']:5.1f} | {r['link']:5.1f} | {r['eval']:5.1f} | {total:5.1f} | "
                  f"{r['load'] / (r['link'] + r['eval']):20.2f} |")
    for k in trees:
        print(f"one-shot langur eval examples/fig1.lgr --engine mc ({k}): {statistics.median(shots[k]):.3f} s CPU "
              f"(median of {rounds}, min {min(shots[k]):.3f})")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--plot", metavar="OUT.png")
    ap.add_argument("--sizes", default=",".join(map(str, SIZES)))
    ap.add_argument("--mb1-only", action="store_true")
    ap.add_argument("--blas-threads", action="store_true", help="leave numpy's BLAS thread pool as it is")
    ap.add_argument("--against", metavar="ROOT", help="side by side with the source tree ROOT (see the docstring)")
    ap.add_argument("--rounds", type=int, default=3, help="alternated processes per tree with --against")
    args = ap.parse_args()
    if args.against:
        against(args.against, args.sizes, max(args.reps, 9), args.rounds)
        return
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; CPU medians of {args.reps}")
    print("\nMicrobenchmark 1: text to number (ms CPU)")
    print("|   n | load (front end) | link (compile) | eval (10 samples) | text to number | load / (link + eval) |")
    print("|----:|-----------------:|---------------:|------------------:|---------------:|---------------------:|")
    rows = []
    for n in map(int, args.sizes.split(",")):
        r = mb1(n, args.reps)
        rows.append(r)
        print(f"| {n:3d} | {1e3 * r['load']:16.1f} | {1e3 * r['link']:14.1f} | {1e3 * r['eval']:17.1f} | "
              f"{1e3 * r['total']:14.1f} | {r['load'] / (r['link'] + r['eval']):20.2f} |")
    if args.mb1_only:
        return
    print("\nMicrobenchmark 2: 90 jumps, 50 shader swaps (s CPU, load + link + evaluate of each)")
    for incremental in (True, False):
        t, stats = mb2(50, incremental)
        how = "incremental front end" if incremental else "every load from scratch"
        print(f"  {how:26s}: {t:.3f} s   (modules elaborated: {stats['elaborated']}, reused: {stats['reused']})")
    print("\nOne-shot process")
    with tempfile.TemporaryDirectory() as cache:
        for bytecode, how in ((cache, "compiled modules kept (as installed)"),
                              (None, "every module compiled from source")):
            wall, cpu = one_shot(args.reps, bytecode)
            print(f"  langur eval examples/fig1.lgr --engine mc, {how}: {wall:.3f} s wall, {cpu:.3f} s CPU "
                  f"(medians of {args.reps})")
            numpy_s, ours = import_time(args.reps, bytecode)
            print(f"  import langur.frontend, langur.operational, {how}: {ours:.3f} s CPU beyond numpy's "
                  f"{numpy_s:.3f} s; -X importtime: {import_tree(args.reps, bytecode):.3f} s")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        ns = [r["n"] for r in rows]
        for key, label in (("load", "load (front end)"), ("link", "link (compile)"), ("eval", "evaluate"),
                           ("total", "text to number")):
            ax.plot(ns, [1e3 * r[key] for r in rows], marker="o", label=label)
        ax.set_xlabel("n (jumps; 2n deltas)")
        ax.set_ylabel("CPU ms (median)")
        ax.set_title("Microbenchmark 1 in Langur, from text to number")
        ax.legend()
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"\nplot: {args.plot}")


if __name__ == "__main__":
    main()
