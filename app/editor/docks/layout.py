"""Where the docks go, and the window's layout kept between runs: its size and place (kept on
the screen) and the arrangement of its docks and tool bar."""

from __future__ import annotations

from PySide6.QtCore import QSettings, QSize, Qt
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QMainWindow,
    QScrollArea,
    QTabBar,
    QWidget,
)

GEOMETRY_KEY = "windowGeometry"
LAYOUT_KEY = "windowLayout"


def add_dock(window: QMainWindow, title: str, widget: QWidget,
             area: Qt.DockWidgetArea = Qt.DockWidgetArea.RightDockWidgetArea) -> QDockWidget:
    """``widget`` in a new dock of ``window`` titled ``title`` (its name in the saved layout too)."""
    dock = QDockWidget(title, window)
    dock.setObjectName(title)
    dock.setWidget(widget)
    window.addDockWidget(area, dock)
    return dock


def scrolled(widget: QWidget) -> QScrollArea:
    """``widget`` in a scroll area: a tall panel does not make the window taller."""
    area = QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    return area


def fitted(size: QSize) -> QSize:
    """``size`` shrunk to the available area of the screen (a 1366 x 768 laptop shows it all)."""
    screen = QApplication.primaryScreen()
    if screen is None:
        return size
    room = screen.availableGeometry()
    return QSize(min(size.width(), room.width()), min(size.height(), room.height()))


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
