"""Undo commands: every change of the document's structure is one of these."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from PySide6.QtGui import QUndoCommand

from core.protein.model import Edit


class Edited(Protocol):
    """What an undo command changes: the :class:`~app.editor.document.Document`, which carries
    out an edit and undoes it exactly."""

    def apply_edit(self, edit: Edit) -> None:
        """Carry out ``edit``."""

    def revert_edit(self, edit: Edit) -> None:
        """Undo ``edit`` exactly."""


class EditCommand(QUndoCommand):
    """One step: the edit of one segment (a whole drag), or of several at once (a level of a
    fit of a chain); redo applies them in turn, undo restores them exactly. ``applied``: the
    document already shows them, so the first redo (QUndoStack.push's) does nothing."""

    def __init__(self, document: Edited, edits: Edit | Sequence[Edit], text: str, *, applied: bool = False) -> None:
        super().__init__(text)
        self.document = document
        self.edits = (edits,) if isinstance(edits, Edit) else tuple(edits)
        self.nbytes = sum(getattr(edit, name).nbytes for edit in self.edits for name in
                          ("old_points", "new_points", "residues", "rows", "old_coords", "new_coords"))
        """Bytes its edits hold."""
        self._applied = applied

    def redo(self) -> None:
        if self._applied:
            self._applied = False
            return
        for edit in self.edits:
            self.document.apply_edit(edit)

    def undo(self) -> None:
        for edit in reversed(self.edits):
            self.document.revert_edit(edit)
