"""The undo history within a memory budget.

Every step holds the coordinates before and after of each atom it moved (a move at a coarse
level moves them all), so a day of editing would hold a day of coordinates. Past
:attr:`History.budget` bytes the oldest steps are dropped, down to half the budget and never
the last :data:`MIN_UNDO_STEPS`; what they did becomes the history's :class:`Base`, which the
journal and sessions record, so that the document is still rebuilt bit for bit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from PySide6.QtCore import QObject, QSignalBlocker, Signal
from PySide6.QtGui import QUndoStack

from app.editor.commands import EditCommand, Edited
from core.protein.model import Edit, EditableModel


class Documented(Edited, Protocol):
    """What a history keeps the steps of: the :class:`~app.editor.document.Document` (a QObject),
    its undo stack and its model."""

    undo_stack: QUndoStack
    model: EditableModel | None

UNDO_BUDGET = 200 * 2**20
"""Bytes of edits the undo history holds at most (its oldest steps dropped past it)."""
MIN_UNDO_STEPS = 100
"""Steps the history keeps whatever their size."""


@dataclass(frozen=True)
class Base:
    """The document where its undo history starts, once older steps were dropped."""

    coords: np.ndarray
    """(n_atoms, 3): the coordinates."""
    points: list[np.ndarray]
    """Each segment's finest control points."""


class History(QObject):
    """The undo steps of ``document`` (its ``undo_stack``) within :attr:`budget` bytes."""

    trimmed = Signal(int)
    """Steps were dropped from the bottom of the history (their number): :attr:`base` moved."""

    def __init__(self, document: Documented) -> None:
        super().__init__(document)
        self.document = document
        self.budget = UNDO_BUDGET
        self.nbytes = 0
        """Bytes of the edits of the steps in the history."""
        self.base: Base | None = None
        """Where the history starts: None for the structure as read."""

    def reset(self, base: Base | None = None) -> None:
        """An empty history (a new structure, or one replayed) starting at ``base``."""
        self.document.undo_stack.clear()
        self.nbytes, self.base = 0, base

    def push(self, edits: Edit | Sequence[Edit], text: str, *, applied: bool = False) -> None:
        """A new step of ``edits`` named ``text`` (``applied``: the model already shows them),
        replacing the steps undone; the oldest steps go if the history outgrows its budget."""
        stack = self.document.undo_stack
        replaced = sum(stack.command(k).nbytes for k in range(stack.index(), stack.count()))
        command = EditCommand(self.document, edits, text, applied=applied)
        stack.push(command)
        self.nbytes += command.nbytes - replaced
        if self.nbytes > self.budget and stack.count() > MIN_UNDO_STEPS:
            self._drop_oldest()

    def _drop_oldest(self) -> None:
        """Drop the oldest steps down to half the budget (the stack is at its top, just pushed):
        the model stays as it is; the commands kept are pushed anew as already applied."""
        stack, model = self.document.undo_stack, self.document.model
        commands = [stack.command(k) for k in range(stack.count())]
        sizes = np.array([command.nbytes for command in commands])
        after = np.cumsum(sizes[::-1])[::-1]  # bytes of step k and all after it
        drop = min(int(np.argmax(after <= self.budget / 2)) if after[-1] <= self.budget / 2 else len(sizes) - 1,
                   len(sizes) - MIN_UNDO_STEPS)
        if drop <= 0:
            return
        coords, points = model.coords.copy(), [ribbon.points for ribbon in model.ribbons]
        for command in reversed(commands[drop:]):  # back to the state before the first step kept
            for edit in reversed(command.edits):
                coords[edit.rows] = edit.old_coords
                points[edit.segment] = edit.old_points
        clean = stack.cleanIndex()
        kept = [(command.edits, command.text()) for command in commands[drop:]]
        del commands
        with QSignalBlocker(stack):
            stack.clear()
            for edits, text in kept:
                stack.push(EditCommand(self.document, edits, text, applied=True))
            if clean >= drop:  # the saved state is still in the history: mark it there
                with QSignalBlocker(self.document):
                    stack.setIndex(clean - drop)
                    stack.setClean()
                    stack.setIndex(stack.count())
            else:
                stack.resetClean()
        self.base = Base(coords, points)
        self.nbytes = int(sizes[drop:].sum())
        self.trimmed.emit(drop)
        stack.indexChanged.emit(stack.index())  # (views of the stack: the steps below moved)
