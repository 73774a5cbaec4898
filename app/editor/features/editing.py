"""Editing: Edit ▸ Undo, Redo, Cancel Drag / Deselect, the drag modes (move a control point,
tug the curve; also in the tool bar), Regularize Region and Carry Bound Ligands."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Qt, Signal
from PySide6.QtGui import QActionGroup, QKeySequence
from PySide6.QtWidgets import QMainWindow, QStyle

from app.editor.interaction.drag import Mode
from app.editor.interaction.gestures import busy

if TYPE_CHECKING:
    from app.editor.document import Document
    from app.editor.features.menus import Menus
    from app.editor.interaction.drag import DragController


class Editing(QObject):
    """The edit actions of ``window`` on ``document``, whose drags ``controller`` makes."""

    modeChanged = Signal()
    """The drag mode (the controller's) changed."""

    def __init__(self, window: QMainWindow, document: Document, controller: DragController, menus: Menus) -> None:
        super().__init__(window)
        self.document = document
        self.controller = controller
        icon, pixmap = window.style().standardIcon, QStyle.StandardPixmap
        self.undo_action = document.undo_stack.createUndoAction(window, "&Undo")
        self.undo_action.setShortcut(QKeySequence.StandardKey.Undo)
        self.undo_action.setIcon(icon(pixmap.SP_ArrowBack))
        self.undo_action.setIconText("Undo")  # the toolbar keeps a short label; the menu names the edit
        self.redo_action = document.undo_stack.createRedoAction(window, "&Redo")
        # each key once: QKeySequence.StandardKey.Redo is Ctrl+Shift+Z on Linux, and a key bound
        # twice is an "ambiguous shortcut" that does nothing
        self.redo_action.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
        self.redo_action.setIcon(icon(pixmap.SP_ArrowForward))
        self.redo_action.setIconText("Redo")
        self.cancel_action = menus.action("Cancel Drag / Deselect", QKeySequence(Qt.Key.Key_Escape), self._cancel)
        self.regularize_action = menus.action("Re&gularize Region", QKeySequence("Ctrl+G"), self._regularize_region)
        self.regularize_action.setToolTip("Ideal peptide junctions and no new clashes for the residues of the picked "
                                          "point and three on each side (one undo step)")
        self.regularize_action.setEnabled(False)
        self.carry_action = menus.action("Carry &Bound Ligands", QKeySequence(), document.set_carry_ligands)
        self.carry_action.setCheckable(True)
        self.carry_action.setChecked(document.carry_ligands)
        self.carry_action.setToolTip("A ligand or ion within 4 Å of a residue moves with the nearest such residue, "
                                     "as a rigid body (untick: edits leave them where they are)")
        self.mode_actions = QActionGroup(window)
        for mode, key in ((Mode.POINT, "M"), (Mode.CURVE, "T")):
            action = menus.action(mode.value[0].upper() + mode.value[1:], QKeySequence(key),
                                  lambda _=False, mode=mode: self._set_mode(mode))
            action.setCheckable(True)
            action.setChecked(mode is controller.mode)
            self.mode_actions.addAction(action)
        menus.add("undo", self.undo_action, self.redo_action, self.cancel_action)
        menus.add("mode", *self.mode_actions.actions())
        menus.add("region", self.regularize_action, self.carry_action)
        menus.add_tools("undo", self.undo_action, self.redo_action)
        menus.add_tools("mode", *self.mode_actions.actions())
        document.picked.connect(self._update_regularize_action)
        document.loaded.connect(self._update_modes)
        self._update_modes()

    def _set_mode(self, mode: Mode) -> None:
        self.controller.mode = mode
        self.modeChanged.emit()

    def _cancel(self) -> None:
        if self.controller.dragging:
            self.controller.cancel()
        elif self.document.model is not None:
            self.document.pick_point(None)
            self.document.select([])

    def _regularize_region(self) -> None:
        if self.document.pick is not None:
            with busy():
                self.document.regularize_region(self.document.pick.residues)

    def _update_regularize_action(self) -> None:
        self.regularize_action.setEnabled(self.document.pick is not None)

    def _update_modes(self) -> None:
        """Drags need a structure that can be edited: the modes are disabled for one only viewed."""
        if self.document.model is not None:
            self.mode_actions.setEnabled(self.document.editable)
