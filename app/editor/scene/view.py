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
that renders. A screenshot renders at once, so it never reads a stale frame. What the two
widgets share is :class:`~app.editor.scene.view_base.View`, in a module of its own.
"""

from __future__ import annotations

import os

import pyvista
from PySide6.QtCore import QCoreApplication, Qt, Signal
from PySide6.QtGui import QGuiApplication, QPaintEvent
from PySide6.QtWidgets import QWidget
from pyvista.plotting.plotter import BasePlotter
from pyvista.plotting.render_window_interactor import RenderWindowInteractor
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor

from app.editor.scene.view_base import View

NATIVE_PLATFORMS = ("xcb", "windows", "cocoa")
"""Qt platforms whose native child windows VTK can draw into."""


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
