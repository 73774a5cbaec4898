"""PySide's check of every module imported after Qt keeps its answers and no longer keeps the
source it read."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
IMPORTS = """
import json, linecache, sys
from PySide6.QtWidgets import QApplication
import app.editor.main_window
import app.editor.window_parts
feature = sys.modules["shibokensupport.feature"].pyside_feature_dict
print(json.dumps({"cached": sorted(linecache.cache), "document": feature.get("app.editor.document"),
                  "plotter": feature.get("pyvista.plotting.plotter"), "modules": len(sys.modules)}))
"""


def test_the_editor_imports_leave_no_source_in_the_line_cache() -> None:
    """A fresh process that imports the editor (over a thousand modules, numpy, scipy, VTK,
    pyvista and matplotlib among them) caches none of their lines (855 files before), and PySide
    still knows which of them use it: the editor's document does, pyvista's plotter does not."""
    result = subprocess.run([sys.executable, "-c", IMPORTS], cwd=ROOT, capture_output=True, text=True, timeout=120,
                            check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    seen = json.loads(result.stdout.strip().splitlines()[-1])
    assert seen["modules"] > 1000 and len(seen["cached"]) < 60  # (those imported before the window's module)
    heavy = ("numpy", "scipy", "vtkmodules", "pyvista", "matplotlib", "window_parts", "document")
    assert not [name for name in seen["cached"] if any(part in name for part in heavy)]
    assert seen["document"] == 0 and seen["plotter"] == -1
