"""``python -m app``: the same as the ``ribbonwave`` command."""

import sys

from app.cli import main

sys.exit(main())
