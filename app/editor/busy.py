"""The window while a file is opened: the file's name in its title, "Opening NAME…" and a busy
bar at the right of its status bar, and the wait cursor, painted before the work blocks the
event loop. Qt alone: the window shows it while the rest of the editor is still loading."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from PySide6.QtCore import QEventLoop, Qt
from PySide6.QtWidgets import QApplication, QLabel, QMainWindow, QProgressBar

from app import PROG

BUSY_BAR = "opening"
"""The object name of the busy bar."""


@contextmanager
def opening(window: QMainWindow, path: Path) -> Iterator[None]:
    """``window`` busy opening ``path`` for the time of the ``with`` block; within another such
    block (the editor loading, then the file read), the title only."""
    window.setWindowTitle(f"{path.name} — {PROG}")
    bar = window.statusBar()
    if bar.findChild(QProgressBar, BUSY_BAR) is not None:
        yield
        return
    note, busy = QLabel(f"Opening {path.name}…"), QProgressBar(maximumWidth=120, textVisible=False)
    busy.setObjectName(BUSY_BAR)
    busy.setRange(0, 0)  # (no end known: the bar says only that work goes on)
    for widget in (note, busy):
        bar.addPermanentWidget(widget)
    QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
    QApplication.processEvents(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents)
    try:
        yield
    finally:
        QApplication.restoreOverrideCursor()
        for widget in (note, busy):
            bar.removeWidget(widget)
            widget.deleteLater()
