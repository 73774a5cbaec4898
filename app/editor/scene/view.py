"""The 3D view widget: a pyvistaqt ``QtInteractor`` that draws one frame per event.

pyvistaqt's widget is a ``QOpenGLWidget`` whose ``paintGL`` renders the scene and shows it,
and every VTK render schedules such a paint: each render drew the scene twice, and each
view that changed something rendered on its own. Here ``render()`` only asks Qt for a paint
(``update()``, which Qt coalesces: one paint per event-loop turn however many views ask), and
the renders the interactor asks for (the camera style while it turns or zooms) go the same
way through the interactor's ``RenderEvent``. ``paintGL`` is the one place that renders. A
screenshot renders at once, so it never reads a stale frame.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Signal
from pyvista.plotting.plotter import BasePlotter
from pyvistaqt import QtInteractor


class View(QtInteractor):
    """A ``QtInteractor`` that renders once per paint and paints once per event-loop turn."""

    capturing = Signal()
    """A screenshot is about to be rendered (views draw their full detail)."""
    frames = 0
    """Frames rendered (for tests and benchmarks)."""
    _immediate = True  # while QtInteractor sets itself up
    _painting = False

    def __init__(self, *args: Any, **kwargs: Any) -> None:  # noqa: ANN401 (QtInteractor's)
        super().__init__(*args, **kwargs)
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

    def paintGL(self) -> None:  # noqa: N802 (Qt's name)
        """Render and show the scene (the interactor may render only here)."""
        interactor = self.iren.interactor
        self._painting = True
        interactor.EnableRenderOn()
        try:
            super().paintGL()
        finally:
            interactor.EnableRenderOff()
            self._painting = False

    def screenshot(self, *args: Any, **kwargs: Any) -> Any:  # noqa: ANN401 (pyvista's)
        """pyvista's screenshot of what the document shows now: its renders are drawn at once."""
        self.capturing.emit()
        self._immediate = True
        try:
            self.render()
            return super().screenshot(*args, **kwargs)
        finally:
            self._immediate = False

    def _count(self) -> None:
        self.frames += 1
