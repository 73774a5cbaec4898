"""ribbonwave application: the Qt editor window and the command-line interface."""

import os
from pathlib import Path

# pyvistaqt reaches Qt through qtpy; pin qtpy to PySide6 before any app module imports it.
os.environ.setdefault("QT_API", "pyside6")

PROG = "ribbonwave"
"""The name of the command."""

EXAMPLES_DIR = Path(__file__).resolve().parent.parent / "resources" / "examples"
"""Bundled example structures (resources/ sits beside this package; install editable)."""

DEFAULT_STRUCTURE = EXAMPLES_DIR / "1UBQ.pdb"
"""The structure opened when no file is given: ubiquitin, PDB entry 1UBQ."""
