"""What the mouse and the keys do in the 3D view: each pointer event goes to the drag
controller, to the camera, or to a hover, click or double click that names, selects or
centres on what is under the pointer.

A press that grabs a control point or the curve starts a drag; any other press turns the
camera, and its release, when the pointer moved less than a click's pixels, is a click.
The scene draws less while the camera or a drag moves and in full once they rest. VTK's
one-letter camera-style keys never reach the view.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtGui import QCursor
from PySide6.QtWidgets import QApplication, QToolTip

from app.editor.interaction.drag import CLICK_PIXELS, Mode, PointerEvent
from app.editor.interaction.identify import Hit, describe, identify
from app.editor.interaction.picking import PRIORITY, PointerAdapter
from app.editor.scene.scene import Layer
from core.protein.lookup import groups_of

if TYPE_CHECKING:
    from app.editor.document import Document
    from app.editor.interaction.drag import DragController
    from app.editor.scene.scene import Scene
    from app.editor.scene.view import View


class Gestures:
    """Routes ``plotter``'s pointer events to ``controller`` and the camera; a click goes to
    ``measure`` (what is under it; True when a measuring tool took it) or selects (``select``,
    residue-table rows, and the coordinate rows of a group: a ligand, ion, water or nucleotide),
    and the hover is named (``name``, '' for nothing)."""

    def __init__(self, document: Document, plotter: View, scene: Scene, controller: DragController, *,
                 select: Callable[[Sequence[int], Sequence[int]], None], name: Callable[[str], None],
                 measure: Callable[[Hit | None], bool] = lambda hit: False) -> None:
        self.document = document
        self.plotter = plotter
        self.scene = scene
        self.controller = controller
        self.select = select
        self.name = name
        self.measure = measure
        self.pointer = PointerAdapter(plotter, self._on_pointer)
        self._press_at: tuple[int, int] | None = None  # where a press the camera took began (display pixels)
        self._hovered: tuple | None = None  # what the hover names now
        interactor = plotter.iren.interactor
        tag = interactor.AddObserver("CharEvent", lambda caller, _: caller.GetCommand(tag).SetAbortFlag(1), PRIORITY)
        style = interactor.GetInteractorStyle()
        for event in ("StartInteractionEvent", "InteractionEvent"):
            style.AddObserver(event, lambda *_: self.scene.moved())
        style.AddObserver("EndInteractionEvent", lambda *_: self._end_interaction())

    def close(self) -> None:
        """Stop listening to the view (before it closes)."""
        self.pointer.close()

    def _on_pointer(self, event: PointerEvent) -> bool:
        if event.kind == "press" and event.double:
            self._centre_on_pointer(event)
            return True
        if event.kind == "move" and not self.controller.dragging:
            if self._press_at is None:
                self._hover(event)
            return False
        grabs = Layer.CONTROL_POINTS if self.controller.mode is Mode.POINT else Layer.CURVE
        if event.kind == "press" and grabs not in self.scene.layers:
            used = False  # what is hidden cannot be grabbed: the press turns the camera
        elif event.kind == "release" and self.controller.dragging:
            with busy():  # the release regularizes: a hard edit takes a few tenths of a second
                used = self.controller.handle(event)
            self.scene.moved()  # full detail a moment after the release
            return used
        else:
            self.controller.point_radius = self.scene.point_radius  # as drawn
            used = self.controller.handle(event)
            if used:
                self.scene.moved()
        if event.kind == "press":
            # a press the camera takes: its release ends the camera's interaction (the camera
            # style holds the interactor's focus until then, so no release comes here)
            self._press_at = None if used else self.plotter.iren.interactor.GetEventPosition()
        return used

    def _end_interaction(self) -> None:
        """The camera's gesture ended; one that moved less than a click's pixels was a click."""
        x, y = self.plotter.iren.interactor.GetEventPosition()
        press, self._press_at = self._press_at, None
        if press is not None and max(abs(x - press[0]), abs(y - press[1])) < CLICK_PIXELS:
            self._click(self.pointer.event_at("release", x, y))
        self.plotter.render()

    def _hit(self, event: PointerEvent) -> Hit | None:
        """What is drawn under the pointer of ``event``."""
        return identify(self.document, event, points=Layer.CONTROL_POINTS in self.scene.layers,
                        point_radius=self.scene.point_radius, atoms=self.scene.shown_atoms())

    def _hover(self, event: PointerEvent) -> None:
        """Name what is under the pointer in a tooltip and the status bar (when it changes)."""
        hit = self._hit(event) if self.document.model is not None else None
        key = None if hit is None else (hit.kind, hit.index, hit.row, self.document.shown_level())
        if key == self._hovered:  # the same thing: no new name (a point's costs an edit plan)
            return
        self._hovered = key
        text = "" if hit is None else describe(self.document, hit)
        self.name(text)
        if hit is None:
            QToolTip.hideText()
        else:
            QToolTip.showText(QCursor.pos(), text, self.plotter)

    def _click(self, event: PointerEvent) -> None:
        """A click that no drag took: an atom for the measuring tool in use, else select the
        residue under the pointer."""
        hit = self._hit(event)
        if not self.measure(hit):
            self._select(hit)

    def _select(self, hit: Hit | None) -> None:
        """Select the residue of ``hit``, or the group of an atom outside the backbone segments."""
        if hit is None or hit.kind == "point":
            return
        if hit.row >= 0:
            self.select([hit.row], [])
        elif hit.kind == "atom":
            self.select([], groups_of(self.document.structure, np.array([hit.index])))

    def _centre_on_pointer(self, event: PointerEvent) -> None:
        """Double click: turn the view about what is under the pointer (and select its residue or group)."""
        hit = self._hit(event)
        if hit is None:
            return
        self._select(hit)
        self.scene.centre_on(hit.position)
        self.plotter.render()


@contextmanager
def busy() -> Iterator[None]:
    """A wait cursor while the window works without returning to the event loop."""
    QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
    try:
        yield
    finally:
        QApplication.restoreOverrideCursor()
