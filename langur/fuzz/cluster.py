"""Campaign units on a Dask distributed cluster (``langur fuzz --scheduler ADDRESS``; the
``cluster`` extra: ``pip install -e '.[cluster]'`` in the clone).

The same units as :mod:`langur.fuzz.pool` — one program, both engines, a verdict — submitted to
an existing distributed engine instead of a home-made one: each task runs its unit in a forked
child of the Dask worker (:func:`langur.fuzz.pool.run_units` with one worker), so a unit past its
time limit is killed there and reported as a timeout, and verdicts, coverage counts and
counterexamples are gathered as they arrive (the results come back in the programs' order).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from . import pool


class MissingCluster(RuntimeError):
    """``dask.distributed`` (the ``cluster`` extra) is not installed."""


def _distributed():
    try:
        import distributed
    except ImportError:  # pragma: no cover - depends on the environment
        raise MissingCluster("--scheduler needs dask.distributed: pip install -e '.[cluster]' in the clone "
                             "(or pip install 'dask[distributed]')") from None
    return distributed


def _task(text: str, work, limit: float, on_time_limit, on_error):
    """One unit on a Dask worker: ``work(text)`` in a forked child killed at the time limit."""
    return pool.run_units([text], work, workers=1, limit=limit, on_time_limit=on_time_limit,
                          on_error=on_error)[0]


def run_units(texts: Sequence[str], work: Callable[[str], object], *, scheduler, limit: float,
              on_time_limit, on_error, progress=None) -> list:
    """:func:`langur.fuzz.pool.run_units` on the Dask cluster at ``scheduler`` (an address such as
    ``tcp://host:8786``, or a ``distributed.Client``)."""
    distributed = _distributed()
    client = scheduler if isinstance(scheduler, distributed.Client) else distributed.Client(scheduler)
    try:
        futures = [client.submit(_task, t, work, limit, on_time_limit, on_error, pure=False) for t in texts]
        where = {f.key: i for i, f in enumerate(futures)}
        results: list = [None] * len(texts)
        for fut in distributed.as_completed(futures):
            i = where[fut.key]
            try:
                results[i] = fut.result()
            except Exception as e:  # noqa: BLE001 - a task lost by the cluster is the unit's failure
                results[i] = on_error(texts[i], f"dask task failed: {type(e).__name__}: {e}")
            if progress is not None:
                progress(results[i])
        return results
    finally:
        if client is not scheduler:
            client.close()
