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
