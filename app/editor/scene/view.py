"""The 3D view widget: a PyVista plotter in a Qt widget that draws one frame per event.

Two widgets can hold the plotter, and :func:`new_view` picks one for the platform:

- :class:`NativeView` (X11, Windows, macOS): VTK's ``QVTKRenderWindowInteractor``, a widget
  with a native window of its own that VTK draws into and shows directly. The rest of the
  window is painted by Qt without OpenGL.
- :class:`~app.editor.scene.widget_view.WidgetView` (Wayland and other platforms without such windows): pyvistaqt's
  ``QtInteractor``, a ``QOpenGLWidget``. Qt composes the whole window through OpenGL
  whenever any widget in it repaints, 13–17 ms per event with software OpenGL at 1400 × 900,
  which the native window does not pay.

``RIBBONWAVE_VIEW=native`` or ``widget`` overrides the choice. In both, ``render()`` only asks
Qt for a paint (``update()``, which Qt coalesces: one paint per event-loop turn however many
views ask), and the renders the interactor asks for (the camera style while it turns or
zooms) go the same way through the interactor's ``RenderEvent``. The paint is the one place
that renders. A screenshot renders at once, so it never reads a stale frame.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import pyvista
from PySide6.QtCore import QCoreApplication, Qt, Signal
from PySide6.QtGui import QGuiApplication, QPaintEvent
from PySide6.QtWidgets import QWidget
from pyvista.plotting.plotter import BasePlotter
from pyvista.plotting.render_window_interactor import RenderWindowInteractor
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor

NATIVE_PLATFORMS = ("xcb", "windows", "cocoa")
"""Qt platforms whose native child windows VTK can draw into."""


class View(BasePlotter if TYPE_CHECKING else object):
    """What both views share: a plotter whose renders become paints, and whose paint renders once
    (a mixin before the widget class, which calls :meth:`_paint_per_render` once set up)."""

    frames = 0
    """Frames rendered (for tests and benchmarks)."""
    _immediate = True  # while the plotter sets itself up
    _painting = False

    def _paint_per_render(self) -> None:
        """Turn the interactor's renders into paints and count the frames (once set up)."""
        self._immediate = False
        interactor = self.iren.interactor
        interactor.EnableRenderOff()  # its renders become paints
        interactor.AddObserver("RenderEvent", lambda *_: None if self._painting else self.update())
        self.ren_win.AddObserver("StartEvent", lambda *_: self._count())

    def render(self) -> None:
        """Ask for a frame: one paint, however many views ask, when the event loop next turns
        (drawn at once while a screenshot is taken)."""
        if getattr(self, "_closed", False):
            return
        self._rendered = True  # pyvista's "has been shown" flag
        if self._immediate:
            BasePlotter.render(self)
        else:
            self.update()

    def _render_in_paint(self, draw: Callable[[], None]) -> None:
        """Run the paint's ``draw``, the only place where the interactor may render."""
        interactor = self.iren.interactor
        self._painting = True
        interactor.EnableRenderOn()
        try:
            draw()
        finally:
            interactor.EnableRenderOff()
            self._painting = False

    def screenshot(self, *args: Any, **kwargs: Any) -> Any:  # noqa: ANN401 (pyvista's)
        """pyvista's screenshot of what the document shows now: its renders are drawn at once."""
        self.capturing.emit()
        self._immediate = True
        try:
            self.render()
            return BasePlotter.screenshot(self, *args, **kwargs)
        finally:
            self._immediate = False

    def _count(self) -> None:
        self.frames += 1


class NativeView(View, QVTKRenderWindowInteractor, BasePlotter):
    """A plotter in VTK's native-window widget, rendering once per paint."""

    capturing = Signal()
    """A screenshot is about to be rendered (views draw their full detail)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        # Only this widget gets a native window: its siblings (the docks) stay painted by Qt.
        QCoreApplication.setAttribute(Qt.ApplicationAttribute.AA_DontCreateNativeWidgetSiblings)
        QVTKRenderWindowInteractor.__init__(self, parent)
        if not vars(self).get("_initialized"):  # PySide's QWidget.__init__ goes on to BasePlotter's
            BasePlotter.__init__(self)
        self.ren_win = self.GetRenderWindow()
        self.ren_win.SetMultiSamples(0)  # the editor smooths edges with FXAA
        for renderer in self.renderers:
            renderer.view_isometric()
            self.ren_win.AddRenderer(renderer)
        self.background_color = pyvista.global_theme.background
        self._off_screen = False
        self.iren = RenderWindowInteractor(self, interactor=self.ren_win.GetInteractor())
        self.iren.interactor.RemoveObservers("MouseMoveEvent")  # the widget sends the moves
        self.iren.initialize()
        self.enable_trackball_style()
        self._first_time = False
        self._paint_per_render()

    def paintEvent(self, event: QPaintEvent) -> None:  # noqa: N802 (Qt's name)
        """Render and show the scene (the interactor may render only here; not once closed)."""
        if not getattr(self, "_closed", False):
            self._render_in_paint(self._Iren.Render)

    def close(self) -> bool:
        """Close the widget and the plotter (once), releasing VTK's window."""
        if not getattr(self, "_closed", False):
            BasePlotter.close(self)
            self.Finalize()
        return QWidget.close(self)


def view_kind() -> str:
    """``native`` or ``widget``: ``RIBBONWAVE_VIEW`` if set, else by the Qt platform."""
    chosen = os.environ.get("RIBBONWAVE_VIEW", "").strip().lower()
    if chosen in ("native", "widget"):
        return chosen
    return "native" if QGuiApplication.platformName() in NATIVE_PLATFORMS else "widget"


def new_view(parent: QWidget | None = None) -> View:
    """The 3D view for this platform (see the module's text)."""
    if view_kind() == "native":
        return NativeView(parent)
    from app.editor.scene.widget_view import WidgetView  # pyvistaqt, only where it is used

    return WidgetView(parent)
