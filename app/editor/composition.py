"""One composition of the window per event.

With a ``QOpenGLWidget`` in it (the 3D view where it is pyvistaqt's widget, see
:mod:`app.editor.scene.view`), every event-loop turn that repaints a widget composes the whole
window again: 15–20 ms with software OpenGL for a 1400 × 900 window. Beside VTK's native
window a turn only repaints the widgets that changed, but each still costs. Two habits of
Qt's own give an event turns of their own after the frame's:

- A layout request climbs the widget tree one level per turn. A label's new text lays out its
  panel, and the next turns lay out the dock's scroll area, the dock and the main window,
  which repaints. :class:`LayoutsFirst` lets the requests settle before the window paints.
- After each such layout the main window animates its docks into place, with animations of
  no length where nothing moves. They end in a turn of their own and repaint the window.
  :class:`StillWidgets`, the style of the widgets it lays out (not of their contents: a
  style's hint asked of Python costs), has no widget animations.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject
from PySide6.QtWidgets import QApplication, QMainWindow, QProxyStyle, QStyle, QStyleHintReturn, QStyleOption, QWidget

LAYOUT_LEVELS = 8
"""Passes over the layout requests before a paint: each lays out one more level of widgets."""


class StillWidgets(QProxyStyle):
    """The application's style without widget animations (docks, tool boxes, tab bars)."""

    def styleHint(self, hint: QStyle.StyleHint, option: QStyleOption | None = None,  # noqa: N802 (Qt's name)
                  widget: QWidget | None = None, returned: QStyleHintReturn | None = None) -> int:
        """No animation lasts; every other hint as the style it wraps says."""
        if hint == QStyle.StyleHint.SH_Widget_Animation_Duration:
            return 0
        return super().styleHint(hint, option, widget, returned)


class LayoutsFirst(QObject):
    """An event filter for a main window: before it paints, the pending layouts are done; the
    widgets it lays out (docks, tool bars, tab bars, the central widget) have a still style."""

    def __init__(self, window: QMainWindow) -> None:
        super().__init__(window)
        self.style = StillWidgets(QApplication.style().name())
        for child in window.children():
            self._still(child)
        window.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:  # noqa: N802 (Qt's name)
        """On the window's update request, lay out what waits to be laid out (then it paints);
        a widget the window gains (a tab bar for docks put together) is still too."""
        if event.type() == QEvent.Type.UpdateRequest:
            for _ in range(LAYOUT_LEVELS):
                QApplication.sendPostedEvents(None, QEvent.Type.LayoutRequest)
        elif event.type() == QEvent.Type.ChildPolished:
            self._still(event.child())
        return False

    def _still(self, child: QObject) -> None:
        if isinstance(child, QWidget) and not isinstance(child.style(), StillWidgets):
            child.setStyle(self.style)


def compose_once(window: QMainWindow) -> None:
    """Make an event that changes ``window`` compose it once (see the module's text)."""
    LayoutsFirst(window)
