"""The 3D view in pyvistaqt's ``QtInteractor`` (a ``QOpenGLWidget``), for platforms where VTK
cannot draw into a native child window (see :mod:`app.editor.scene.view`;
what both views share is :class:`~app.editor.scene.view_base.View`)."""

from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QWidget
from pyvistaqt import QtInteractor

from app.editor.scene.view_base import View


class WidgetView(View, QtInteractor):
    """A plotter in pyvistaqt's ``QOpenGLWidget``, rendering once per paint."""

    capturing = Signal()
    """A screenshot is about to be rendered (views draw their full detail)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent, auto_update=False)
        self._paint_per_render()

    def paintGL(self) -> None:  # noqa: N802 (Qt's name)
        """Render and show the scene (the interactor may render only here)."""
        self._render_in_paint(super().paintGL)
