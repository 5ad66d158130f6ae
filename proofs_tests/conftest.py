import gc
import os

import pytest
from hypothesis import settings
from paths import EXAMPLES

# Property tests draw the same examples on every run (no flaky suite; CI uses fixed seeds) and keep
# no example database in the checkout.  LANGUR_HYPOTHESIS_PROFILE=explore draws fresh examples
# each run, for hunting bugs locally.
settings.register_profile("fixed", derandomize=True, database=None)
settings.register_profile("explore", database=None)
settings.load_profile(os.environ.get("LANGUR_HYPOTHESIS_PROFILE", "fixed"))


def pytest_configure(config):
    if not (EXAMPLES / "fig1.lgr").is_file():
        raise pytest.UsageError(f"the repository's example programs are missing from {EXAMPLES}")


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session):
    """The session's heap frozen once its tests and fixtures are done.

    Under pytest-xdist a worker reports "finished" when this hook returns; the controller then
    shuts the worker down and execnet gives it 5 s to end, after which it sends the worker a
    SIGINT.  What the worker still does by then is pytest's own clean-up: five full garbage
    collections (looking for objects whose finalizers raise), each traversing the whole heap the
    suite built (sympy, the engines, their caches) — seconds of CPU, many more seconds of wall
    clock on a loaded machine.  The SIGINT then landed in hypothesis's ``gc.callbacks`` timer and
    was printed as "Exception ignored in: <function gc_callback ...>: KeyboardInterrupt", or, the
    worker still busy 10 s after, the controller killed it (a whole-suite run with ``-n 2`` on the
    loaded machine: ~850 000 objects, 3.2–4.0 s a collection, 18 s of clean-up after "finished").
    So the full collection is done here, once, while pytest still reports what it finds, and
    what survives it (alive until the process ends) is moved to the permanent generation
    (``gc.freeze``), which pytest's later collections do not traverse."""
    gc.collect()
    gc.freeze()
