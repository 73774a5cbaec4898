"""What both 3D views share (:mod:`app.editor.scene.view`, :mod:`app.editor.scene.widget_view`): a
plotter whose renders become Qt paints, and whose paint renders once."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from pyvista.plotting.plotter import BasePlotter


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
