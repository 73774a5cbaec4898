"""A globe surface built on the command line's path and in a real editor window, side by side,
and the time to quit while a build runs.

Usage: ``xvfb-run -a python benchmarks/bench_surface_editor.py [--runs N] [STRUCTURE ...]``
(default 1UBQ and 4YVS from tests/data). For each structure: ``build_surface('globe', atoms)``
called once in a fresh process, as ``ribbonwave surface`` does; in the editor, the time from ticking
"Show surface" (the Surface tab in front) to the globe built (received from the build's
process) and drawn (the frame that shows it), with the window idle and while the view turns
(the left button held in an empty corner, the pointer moving every 20 ms), with the frames
per second drawn meanwhile. Then the window is closed (File >
Quit) while a globe of the last structure is being built, once its molecular surface is under
way. Medians over the runs, s.

Each build's process runs this script again as its main module (multiprocessing's rule), so
the script imports Qt and the editor only where it uses them, not at its top.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from app.editor.main_window import MainWindow

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
DEFAULT = ("1UBQ.pdb.gz", "4YVS.cif.gz")
TURN_MS = 20
CLI_CHILD = """
import sys, time
from core.protein.reading import read_atoms
from core.surfaces.levelled import build_surface
atoms = read_atoms(sys.argv[1])
start = time.perf_counter()
build_surface("globe", atoms)
print(len(atoms), time.perf_counter() - start)
"""


def cli_build(path: Path) -> tuple[int, float]:
    """The atoms of ``path`` and the seconds of its globe's build in a fresh process."""
    result = subprocess.run([sys.executable, "-c", CLI_CHILD, str(path)], capture_output=True, text=True, check=True)
    atoms, seconds = result.stdout.split()
    return int(atoms), float(seconds)


def _until(condition: Callable[[], bool]) -> None:
    """Run the event loop (sleeping while it has nothing to do) until ``condition()``."""
    from PySide6.QtCore import QEventLoop, QTimer

    loop = QEventLoop()
    timer = QTimer(interval=10)
    timer.timeout.connect(lambda: condition() and loop.quit())
    timer.start()
    loop.exec()


def _window(path: Path) -> MainWindow:
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QDockWidget

    from app.editor.document import Document
    from app.editor.main_window import MainWindow
    from app.editor.surfaces.layer import KIND_NAMES

    document = Document()
    document.open(path)
    window = MainWindow(document)
    window.resize(1400, 900)
    window.show()
    QTest.qWaitForWindowExposed(window)
    _until(lambda: window.plotter.frames > 0)
    window.findChild(QDockWidget, "Surface").raise_()  # its tab, as the user clicks it
    window.surface_panel.kind.setCurrentIndex(list(KIND_NAMES).index("globe"))
    return window


def editor_build(path: Path, turning: bool) -> tuple[float, float, float]:
    """Seconds from ticking "Show surface" to the globe received from its build and to the frame
    that shows it, and the frames per second meanwhile."""
    from PySide6.QtCore import QPoint, Qt, QTimer
    from PySide6.QtTest import QTest

    window = _window(path)
    view, layer = window.plotter, window.surface_layer
    corner = QPoint(12, view.height() - 12)  # nothing there: a drag turns the camera
    steps = iter(range(1, 1_000_000))
    turner = QTimer(interval=TURN_MS)
    turner.timeout.connect(lambda: QTest.mouseMove(view, corner + QPoint(0, -30) + QPoint(next(steps) % 60, 0)))
    if turning:
        QTest.mousePress(view, Qt.MouseButton.LeftButton, pos=corner)
        turner.start()
    built: list[tuple[int, float]] = []  # the frame count and time when the surface came: the next frame shows it
    layer.updated.connect(lambda: layer.built is None or built or built.append((view.frames, time.perf_counter())))
    frames, start = view.frames, time.perf_counter()
    window.surface_panel.show_box.setChecked(True)
    _until(lambda: bool(built) and view.frames > built[0][0])
    drawn = time.perf_counter() - start
    turner.stop()
    if turning:
        QTest.mouseRelease(view, Qt.MouseButton.LeftButton, pos=corner)
    window.quit_unattended(discard=True)
    return built[0][1] - start, drawn, (view.frames - frames) / drawn


def quit_while_building(path: Path) -> float:
    """Seconds File > Quit takes while the globe's molecular surface is being computed."""
    window = _window(path)
    layer = window.surface_layer
    window.surface_panel.show_box.setChecked(True)
    _until(lambda: layer.stage.startswith("molecular surface"))
    start = time.perf_counter()
    window.files.quit_action.trigger()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="*", default=list(DEFAULT))
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    QApplication.instance() or QApplication(sys.argv[:1])
    from app.editor.surfaces.build import start_server

    QSettings.setPath(QSettings.Format.NativeFormat, QSettings.Scope.UserScope, tempfile.mkdtemp())  # not the user's
    start_server()  # as the window does: it is ready when the command line's builds are timed
    print(f"globe surface, medians of {args.runs} runs (s); the editor's window idle, then turning")
    print(f"{'structure':<10} {'atoms':>6} {'CLI build':>10} {'built':>7} {'drawn':>7} {'turning: built':>15} "
          f"{'drawn':>7} {'fps':>5}")
    for name in args.structures:
        path = Path(name) if Path(name).exists() else DATA / name
        cli = np.array([cli_build(path) for _ in range(args.runs)])
        idle = np.median([editor_build(path, turning=False) for _ in range(args.runs)], axis=0)
        turning = np.median([editor_build(path, turning=True) for _ in range(args.runs)], axis=0)
        print(f"{path.name.split('.')[0]:<10} {int(cli[0, 0]):>6} {np.median(cli[:, 1]):>10.2f} {idle[0]:>7.2f} "
              f"{idle[1]:>7.2f} {turning[0]:>15.2f} {turning[1]:>7.2f} {turning[2]:>5.1f}")
    quits = [quit_while_building(path) for _ in range(args.runs)]
    print(f"quit while a globe of {path.name.split('.')[0]} builds: {np.median(quits):.3f} (worst {max(quits):.3f})")


if __name__ == "__main__":
    main()
