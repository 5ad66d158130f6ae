"""``python -m langur``: the same command as the ``langur`` console script."""

import sys

from .cli import main

sys.exit(main())
