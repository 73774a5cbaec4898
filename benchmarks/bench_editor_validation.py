"""Speed of validation and regularization in the editor window, per structure.

Run with ``python benchmarks/bench_editor_validation.py`` (under ``xvfb-run`` without a
display). Drag steps go through the VTK interactor as in ``bench_editor.py`` (render
excluded), now with the live validation (a local check of the moved residues folded into
the last report, run between mouse events and timed apart as "check"), the validation
markers and the dock: without regularization, then with
"regularize while dragging". Also timed: the full check when a file opens, the local check
alone, and the release of a drag with "regularize on release" (the regularization and the
updates of the one undo step).
"""

from __future__ import annotations

import sys
import time

import numpy as np
from bench_editor import MOVES, STRUCTURES, Clock, display, open_window
from PySide6.QtWidgets import QApplication

from app.editor.main_window import MainWindow


def drag(window: MainWindow, level: float, *, while_dragging: bool) -> tuple[Clock, list[float], float]:
    """Drag the middle shown control point at ``level`` in MOVES steps, releasing with
    regularization on; returns the step clock, the local-check times and the release time (ms)."""
    document = window.document
    document.set_level(level)
    document.set_regularization(on_release=True, while_dragging=while_dragging)
    window.plotter.render()
    shown = window.scene.shown_control_points()
    start = display(window, document.level_curve().control_points[shown[len(shown) // 2]])
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    clock, checks = Clock(window), []
    for k in range(1, MOVES + 1):
        interactor.SetEventInformation(start[0] + 3 * k, start[1] + 2 * k)
        clock.step(lambda: interactor.InvokeEvent("MouseMoveEvent"))
        window.validation.check_now()  # the check the event loop runs between mouse events
        checks.append(window.validation.elapsed_ms)
    window.plotter.render = lambda: None
    begin = time.perf_counter()
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    release = 1e3 * (time.perf_counter() - begin)
    del window.plotter.render
    assert document.undo_stack.count() == 1
    document.undo_stack.undo()
    return clock, checks, release


def main() -> None:
    app = QApplication.instance() or QApplication(sys.argv[:1])
    print(f"Editor steps with validation in ms (median and worst of {MOVES} steps; render excluded)")
    print(f"  {'':<44}{'update':>9}{'worst':>9}{'check':>9}{'release':>9}")
    for name, label in STRUCTURES:
        window = open_window(app, name)
        document = window.document
        begin = time.perf_counter()
        window.validation._check_all()
        print(f"{name} ({label}); full check {1e3 * (time.perf_counter() - begin):.1f} ms "
              f"({sum(window.validation.report.counts.values())} flags as read)")
        top = document.max_level
        for level in (top, np.floor(top) - 3.0, top - 2.5):
            for while_dragging in (False, True):
                clock, checks, release = drag(window, level, while_dragging=while_dragging)
                what = f"level {level:.2f}, " + ("regularized steps" if while_dragging else "plain steps")
                update = np.array(clock.updates)
                print(f"  {what:<44}{np.median(update):>9.2f}{update.max():>9.2f}{np.median(checks):>9.2f}"
                      f"{release:>9.1f}")
        document.undo_stack.setClean()
        window.close()


if __name__ == "__main__":
    main()
