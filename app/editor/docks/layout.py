"""Where the docks go, and the window's layout kept between runs: its size and place (kept on
the screen) and the arrangement of its docks and tool bar."""

from __future__ import annotations

from PySide6.QtCore import QMargins, QPoint, QRect, QSettings, QSize, Qt
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QMainWindow,
    QScrollArea,
    QTabBar,
    QWidget,
)

GEOMETRY_KEY = "windowGeometry"
FRAME_ALLOWANCE = QMargins(0, 32, 0, 0)
"""Room left for the window manager's title bar before the window is shown and its frame known."""
LAYOUT_KEY = "windowLayout"


def new_dock(window: QMainWindow, title: str, widget: QWidget) -> QDockWidget:
    """``widget`` in a new dock of ``window`` titled ``title`` (its name in the saved layout too),
    to be placed with ``addDockWidget``."""
    dock = QDockWidget(title, window)
    dock.setObjectName(title)
    dock.setWidget(widget)
    return dock


class Pending(QWidget):
    """An empty panel of about the size of the one that will replace it (the window lays its docks
    out by their panels' sizes)."""

    def __init__(self, hint: QSize) -> None:
        super().__init__()
        self.hint = hint

    def sizeHint(self) -> QSize:  # noqa: N802 (Qt's name)
        """About the size the panel to come will ask for."""
        return self.hint


def scrolled(widget: QWidget) -> QScrollArea:
    """``widget`` in a scroll area: a tall panel does not make the window taller."""
    area = QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    return area


def fitted(size: QSize, frame: QMargins = FRAME_ALLOWANCE) -> QSize:
    """``size`` shrunk so that the window, with ``frame`` around it (the window manager's title
    bar and borders), fits the available area of the screen (a 1366 x 768 laptop shows it all,
    status bar included)."""
    screen = QApplication.primaryScreen()
    if screen is None:
        return size
    room = screen.availableGeometry().marginsRemoved(frame)
    return QSize(min(size.width(), room.width()), min(size.height(), room.height()))


def fit_frame(window: QMainWindow) -> None:
    """Once ``window`` is shown and its frame known: shrink and move it so that the whole frame
    lies in the screen's available area (a window manager may decorate it more than
    :data:`FRAME_ALLOWANCE`)."""
    outer, inner = window.frameGeometry(), window.geometry()
    frame = QMargins(inner.left() - outer.left(), inner.top() - outer.top(),
                     outer.right() - inner.right(), outer.bottom() - inner.bottom())
    screen = QApplication.primaryScreen()
    if screen is None or frame.isNull():  # no frame (or not known yet): the allowance stands
        return
    window.resize(fitted(window.size(), frame))
    room, outer = screen.availableGeometry(), window.frameGeometry()
    left = max(room.left(), min(outer.left(), room.right() - outer.width() + 1))
    top = max(room.top(), min(outer.top(), room.bottom() - outer.height() + 1))
    if (left, top) != (outer.left(), outer.top()):
        window.setGeometry(QRect(QPoint(left + frame.left(), top + frame.top()), window.size()))


def tidy_tab_bars(window: QMainWindow) -> None:
    """Dock tabs show their whole titles (scroll buttons when they do not fit). Qt (6.11)
    also leaves the tab bar of a two-dock group visible, under the docks, once a third
    dock joins the group; a bottom dock uncovers it: hide every tab bar whose tabs another
    one shows too."""
    bars = [bar for bar in window.findChildren(QTabBar) if bar.parent() is window]
    tabs = {bar: {bar.tabText(k) for k in range(bar.count())} for bar in bars}
    for bar in bars:
        bar.setElideMode(Qt.TextElideMode.ElideNone)
        bar.setUsesScrollButtons(True)
        if any(other is not bar and tabs[bar] < tabs[other] for other in bars):
            bar.hide()


def restore_layout(window: QMainWindow, settings: QSettings) -> None:
    """The size, place and dock layout ``window`` had when it last closed (kept on screen)."""
    geometry, layout = settings.value(GEOMETRY_KEY), settings.value(LAYOUT_KEY)
    if geometry is not None:
        window.restoreGeometry(geometry)
        window.resize(fitted(window.size()))
    if layout is not None:
        window.restoreState(layout)
        tidy_tab_bars(window)


def save_layout(window: QMainWindow, settings: QSettings) -> None:
    """Keep ``window``'s size, place and dock layout for the next run."""
    settings.setValue(GEOMETRY_KEY, window.saveGeometry())
    settings.setValue(LAYOUT_KEY, window.saveState())
