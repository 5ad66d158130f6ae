import pytest
from paths import EXAMPLES


def pytest_configure(config):
    if not (EXAMPLES / "fig1.lgr").is_file():
        raise pytest.UsageError(f"the repository's example programs are missing from {EXAMPLES}")
