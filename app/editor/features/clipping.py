"""The clipping slab: *View ▸ Clip Slab* (Ctrl+K) clips the view to a slab :data:`DEFAULT` Å
either side of its centre, or stops clipping. As in PyMOL, a drag with the right button and
Shift moves the planes: up and down the near one, left and right the far one; Ctrl+Alt+Up
and Ctrl+Alt+Down make the slab thicker and thinner. The slab turns with the view about its
centre and is kept in sessions (:attr:`app.editor.scene.scene.Scene.slab`)."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import QMainWindow

from app.editor.features.menus import Menus
from app.editor.interaction.picking import PRIORITY
from app.editor.scene.scene import Scene
from app.editor.scene.view_base import View

DEFAULT = 10.0
"""Å, each plane's distance from the centre when the slab is switched on."""
STEP = 1.0
"""Å a key moves each plane."""
PIXELS_PER_ANGSTROM = 4.0
"""How far the pointer moves to move a plane 1 Å."""


class Clipping:
    """The slab's menu entries, keys and drag."""

    def __init__(self, window: QMainWindow, scene: Scene, plotter: View, menus: Menus) -> None:
        self.window = window
        self.scene = scene
        self.toggle_action = menus.action("Clip &Slab", QKeySequence("Ctrl+K"), self._toggle)
        self.toggle_action.setCheckable(True)
        thicker = menus.action("Thicker Slab", QKeySequence("Ctrl+Alt+Up"), lambda: self.widen(STEP, STEP))
        thinner = menus.action("Thinner Slab", QKeySequence("Ctrl+Alt+Down"), lambda: self.widen(-STEP, -STEP))
        menus.add("camera", self.toggle_action, thicker, thinner)
        scene.document.loaded.connect(lambda: self.toggle_action.setChecked(scene.slab is not None))  # (after the scene)
        self._drag: tuple[int, int, tuple[float, float]] | None = None  # where it began, and the slab then
        self._tags: dict[str, int] = {}
        interactor = plotter.iren.interactor
        for name, slot in (("RightButtonPressEvent", self._press), ("MouseMoveEvent", self._move),
                           ("RightButtonReleaseEvent", self._release)):
            self._tags[name] = interactor.AddObserver(name, self._observer(name, slot), PRIORITY)

    def _observer(self, name: str, slot: Callable[[object], bool]) -> Callable[[object, str], None]:
        """Calls ``slot`` with the interactor; what it used, the camera does not see."""
        def observe(interactor: object, _event: str) -> None:
            if slot(interactor):
                interactor.GetCommand(self._tags[name]).SetAbortFlag(1)  # type: ignore[attr-defined]
        return observe

    def set(self, slab: tuple[float, float] | None) -> None:
        """Clip to ``slab`` (Å in front of and behind the centre), or (None) not."""
        self.scene.set_slab(slab)
        self.toggle_action.setChecked(self.scene.slab is not None)
        slab = self.scene.slab
        self.window.statusBar().showMessage("" if slab is None else
                                            f"Slab: {slab[0]:.1f} Å in front of the centre, {slab[1]:.1f} Å behind",
                                            5000)

    def widen(self, front: float, back: float) -> None:
        """Move the near plane ``front`` Å and the far one ``back`` Å further out (a slab is on)."""
        slab = self.scene.slab or (DEFAULT, DEFAULT)
        self.set((slab[0] + front, slab[1] + back))

    def _toggle(self, on: bool) -> None:
        self.set((DEFAULT, DEFAULT) if on else None)

    def _press(self, interactor: object) -> bool:
        if not interactor.GetShiftKey():  # type: ignore[attr-defined]
            return False
        x, y = interactor.GetEventPosition()  # type: ignore[attr-defined]
        self._drag = (x, y, self.scene.slab or (DEFAULT, DEFAULT))
        return True

    def _move(self, interactor: object) -> bool:
        if self._drag is None:
            return False
        x, y = interactor.GetEventPosition()  # type: ignore[attr-defined]
        x0, y0, (front, back) = self._drag
        self.set((front + (y - y0) / PIXELS_PER_ANGSTROM, back + (x - x0) / PIXELS_PER_ANGSTROM))
        return True

    def _release(self, _interactor: object) -> bool:
        dragged, self._drag = self._drag is not None, None
        return dragged
