import pytest

from paths import EXAMPLES


def pytest_configure(config):
    if not EXAMPLES.is_dir():
        raise pytest.UsageError(f"the shared examples are not at {EXAMPLES}: set LANGUR_SHARED")
