"""Undo commands: every change of the document's structure is one of these."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtGui import QUndoCommand

from core.protein.model import Edit

if TYPE_CHECKING:
    from app.editor.document import Document


class EditCommand(QUndoCommand):
    """One edit of one segment (a whole drag): redo applies it, undo restores it exactly."""

    def __init__(self, document: Document, edit: Edit, text: str) -> None:
        super().__init__(text)
        self.document = document
        self.edit = edit

    def redo(self) -> None:
        self.document.apply_edit(self.edit)

    def undo(self) -> None:
        self.document.revert_edit(self.edit)
