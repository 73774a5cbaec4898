"""Speed of the editor window: a slider step and a drag step, then the render, per structure.

Run with ``python benchmarks/bench_editor.py`` (under ``xvfb-run`` without a display).
A slider step is one change of the level: the document's new level curves, the in-place
update of the level-curve and control-point meshes, the dock panel and the status bar. A
drag step is one mouse move during a drag, through the VTK interactor as a mouse sends it:
the edit planned from the drag start, the rigid-body remap of the residues it moves, and
the in-place update of the tube, level curve, control points, Cα trace and atoms. Renders
are timed apart (software OpenGL under Xvfb here, so they say little about a GPU).
Targets, render excluded: slider and drag steps under 10 ms at 400 residues, under 30 ms
for 4YVS (3,405 residues in 20 segments).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from PySide6.QtWidgets import QApplication

from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.scene.scene import Layer

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
STRUCTURES = (("1UBQ.pdb.gz", "ubiquitin, 76 residues"), ("1AYE.pdb.gz", "procarboxypeptidase, 401 residues"),
              ("4YVS.cif.gz", "EV71 capsid protomers, 3,405 residues"))
MOVES = 30


class Clock:
    """Times updates with the plotter's render switched off, and the renders on their own."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window
        self.updates: list[float] = []
        self.renders: list[float] = []

    def step(self, action) -> None:
        plotter = self.window.plotter
        plotter.render = lambda: None  # the scene's render calls become no-ops
        start = time.perf_counter()
        action()
        middle = time.perf_counter()
        del plotter.render
        plotter.render()
        end = time.perf_counter()
        self.updates.append(1e3 * (middle - start))
        self.renders.append(1e3 * (end - middle))

    def row(self, label: str) -> str:
        update, render = np.array(self.updates), np.array(self.renders)
        return (f"  {label:<34}{np.median(update):>9.2f}{update.max():>9.2f}"
                f"{np.median(render):>11.2f}{render.max():>9.2f}")


def display(window: MainWindow, point: np.ndarray) -> tuple[int, int]:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return round(x), round(y)


def drag(window: MainWindow, level: float) -> Clock:
    """Drag the middle shown control point of the current segment at ``level`` in MOVES steps."""
    document = window.document
    document.set_level(level)
    window.plotter.render()
    shown = window.scene.shown_control_points()
    start = display(window, document.level_curve().control_points[shown[len(shown) // 2]])
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    clock = Clock(window)
    for k in range(1, MOVES + 1):
        interactor.SetEventInformation(start[0] + 3 * k, start[1] + 2 * k)
        clock.step(lambda: interactor.InvokeEvent("MouseMoveEvent"))
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    assert document.undo_stack.count() == 1
    document.undo_stack.undo()
    return clock


def open_window(app: QApplication, name: str) -> MainWindow:
    """A shown window on test entry ``name``, every layer that follows an edit switched on,
    with its longest segment chosen."""
    document = Document()
    document.open(DATA / name)
    window = MainWindow(document)
    for layer in (Layer.CA_TRACE, Layer.ATOMS):
        window.scene.set_layer(layer, True)
    window.show()
    app.processEvents()
    document.set_segment(max(range(len(document.paths)), key=lambda g: len(document.structure.segments[g])))
    return window


def main() -> None:
    app = QApplication.instance() or QApplication(sys.argv[:1])
    print(f"Editor steps in ms (median and worst of {MOVES} steps; render = one software-OpenGL frame)")
    print(f"  {'':<34}{'update':>9}{'worst':>9}{'render':>11}{'worst':>9}")
    for name, label in STRUCTURES:
        window = open_window(app, name)
        document = window.document
        residues = document.structure.n_residues
        segment = document.segment
        print(f"{name} ({label}); edited segment of {len(document.structure.segments[segment])} residues, "
              f"{residues} residues in all, tube of {window.scene.meshes['tube'].n_points} vertices")
        top = document.max_level
        first_pass = Clock(window)  # the first visit of each level builds its filters and design matrices
        for level in np.append(np.arange(0.0, top, 0.5), top):
            first_pass.step(lambda level=level: document.set_level(level))
        print(first_pass.row("slider, first pass over all levels"))
        slider = Clock(window)
        for level in np.linspace(1.0, top, MOVES):
            slider.step(lambda level=level: document.set_level(level))
        print(slider.row("slider step (fractional levels)"))
        print(drag(window, top).row("drag step at full resolution"))
        print(drag(window, np.floor(top) - 3.0).row(f"drag step at level {np.floor(top) - 3:.0f}"))
        print(drag(window, top - 2.5).row(f"drag step at level {top - 2.5:.2f}"))
        document.undo_stack.setClean()
        window.close()


if __name__ == "__main__":
    main()
