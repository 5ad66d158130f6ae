"""Where the project's example programs are: ``examples/`` in this repository.

Nothing here looks outside the repository: a fresh clone has everything the tests need.
"""

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
DEGENERATE = EXAMPLES / "degenerate"
