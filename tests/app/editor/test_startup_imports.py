"""Start-up imports what the first window shows only: the surface code, the comparison of
structures (and numba, which compiles its alignment), matplotlib's Qt canvas and the cluster
code load when first used, and pyvistaqt only where the view cannot be a native window
(``benchmarks/bench_startup.py`` times the start)."""

import json
import os
import subprocess
import sys
from pathlib import Path

DATA = Path(__file__).resolve().parents[2] / "data"
ROOT = Path(__file__).resolve().parents[3]
DEFERRED = (
    "skimage", "pywt", "dask", "distributed", "scipy.ndimage", "core.surfaces.levelled", "core.surfaces.molecular",
    "core.surfaces.volume", "core.surfaces.globe", "core.analysis.compare", "core.analysis.fold_alignment",
    "core.analysis.tm_align", "numba", "core.fitting", "app.editor.features.fitting", "matplotlib.backends.backend_qtagg", "app.cli",
    "pyvistaqt", "qtpy", "app.editor.scene.widget_view",
)  # fmt: skip
"""Modules (and their submodules) that the first window does without."""
FIRST_WINDOW = """
import json, sys, time
from pathlib import Path
from PySide6.QtWidgets import QApplication
app = QApplication([])
from app.editor.main_window import MainWindow
window = MainWindow()  # as `ribbonwave FILE` does: the window, then the file
window.document.open(Path(sys.argv[1]))
window.show()
deadline = time.monotonic() + 60
while window.plotter.frames == 0 and time.monotonic() < deadline:
    app.processEvents()
loaded = sorted({name for name in sys.modules for deferred in sys.argv[2:]
                 if name == deferred or name.startswith(deferred + ".")})
print(json.dumps({"frames": window.plotter.frames, "loaded": loaded}))
window.quit_unattended(discard=True)
"""


def test_the_first_window_on_1ubq_imports_none_of_what_it_does_not_show(tmp_path: Path) -> None:
    env = {**os.environ, "XDG_CONFIG_HOME": str(tmp_path / "config"), "XDG_STATE_HOME": str(tmp_path / "state")}
    result = subprocess.run([sys.executable, "-c", FIRST_WINDOW, str(DATA / "1UBQ.pdb.gz"), *DEFERRED], cwd=ROOT,
                            env=env, capture_output=True, text=True, check=False, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    found = json.loads(result.stdout.splitlines()[-1])
    assert found["frames"] > 0  # the window was drawn
    assert found["loaded"] == []
