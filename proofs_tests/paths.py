"""Where the shared specification and examples are: ``shared/`` beside the repository.

CI runs in a fresh clone with ``shared/`` beside it, so never hard-code an absolute path.
``LANGUR_SHARED`` overrides the location.
"""

import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("LANGUR_SHARED", REPO.parent / "shared"))
EXAMPLES = SHARED / "examples"
DEGENERATE = EXAMPLES / "degenerate"
