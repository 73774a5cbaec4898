"""``python -m app``: the same as the ``ribbonwave`` command."""

import sys

from app.main import main

sys.exit(main())
