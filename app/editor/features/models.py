"""Playing the models of an ensemble: *View ▸ Play Models* (Ctrl+Shift+Y) shows model after
model of a multi-model entry (an NMR ensemble), :data:`PLAY_MS` apart, in the same view,
until chosen again. The models change only while there are no edits to undo; it says so."""

from __future__ import annotations

from PySide6.QtCore import QTimer
from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import QMainWindow

from app.editor.document import Document
from app.editor.features.menus import Menus

PLAY_MS = 300
"""Milliseconds between two models."""


class Models:
    """The *Play Models* entry and its timer."""

    def __init__(self, window: QMainWindow, document: Document, menus: Menus) -> None:
        self.window = window
        self.document = document
        self.play_action = menus.action("&Play Models", QKeySequence("Ctrl+Shift+Y"), self.play)
        self.play_action.setCheckable(True)
        menus.add("camera", self.play_action)
        self.timer = QTimer(window, interval=PLAY_MS)
        self.timer.timeout.connect(self._next)
        document.loaded.connect(self._loaded)
        self._loaded()

    def play(self, on: bool) -> None:
        """Start or stop showing the models in turn."""
        if on and self.document.undo_stack.index() > 0:
            on = False
            self.window.statusBar().showMessage("the models can be played only while there are no edits to undo",
                                                8000)
        self.play_action.setChecked(on)
        if on:
            self.timer.start()
        else:
            self.timer.stop()

    def _next(self) -> None:
        structure = self.document.structure
        try:
            self.document.set_model_number(structure.model_number % structure.n_models + 1)
        except ValueError as error:  # an edit since the start
            self.play(False)
            self.window.statusBar().showMessage(str(error), 8000)

    def _loaded(self) -> None:
        several = self.document.model is not None and self.document.structure.n_models > 1
        self.play_action.setEnabled(several)
        if not several and self.timer.isActive():
            self.play(False)
