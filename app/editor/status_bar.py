"""The window's status bar: the file, the edited chain, the level, the picked point (or the
selection, or what a drag in the current mode does), the map's correlation, the name of
what is under the pointer and, where reading the file skipped or ignored something, a button
that says so."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QMessageBox, QStatusBar, QStyle, QToolButton

from app import PROG
from app.editor.interaction.drag import Mode
from core.protein.lookup import Selected

if TYPE_CHECKING:
    from app.editor.document import Document
    from app.editor.interaction.drag import DragController
    from app.editor.map_correlation import LiveCorrelation

LABELS = ("file", "segment", "level", "pick", "map", "hover")
NOTES_LISTED = 30
"""Notes on reading listed in the dialog (and 10 in the tooltip); the rest are counted."""


class StatusBar:
    """The labels of ``bar`` that follow ``document``, the drag mode of ``controller`` and
    ``correlation``; the hover's name is set from outside (:attr:`labels` ``["hover"]``)."""

    def __init__(self, bar: QStatusBar, document: Document, controller: DragController,
                 correlation: LiveCorrelation) -> None:
        self.document = document
        self.controller = controller
        self.correlation = correlation
        self.labels = {key: QLabel() for key in LABELS}
        for key, label in self.labels.items():
            bar.addWidget(label, 1 if key == "pick" else 0)
        self.notes = QToolButton()
        self.notes.setAutoRaise(True)
        self.notes.setIcon(bar.style().standardIcon(QStyle.StandardPixmap.SP_MessageBoxWarning))
        self.notes.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        self.notes.clicked.connect(self.show_notes)
        bar.addPermanentWidget(self.notes)
        document.fileChanged.connect(self._update_notes)
        self._update_notes()
        for signal in (document.fileChanged, document.loaded, document.levelChanged, document.segmentChanged,
                       document.picked, document.selectionChanged):
            signal.connect(self.update)
        correlation.updated.connect(self._update_correlation)
        self.update()

    def update(self) -> None:
        """Say what the document and the drag mode are now."""
        document = self.document
        labels = self.labels
        if document.model is None:
            labels["file"].setText("no structure")
            return
        structure = document.structure
        labels["file"].setText(f"{document.path.name if document.path else ''}  ({structure.entry_id})")
        if not document.editable:  # only viewed: say why instead of the segment, level and pick
            labels["segment"].clear()
            labels["level"].clear()
            labels["pick"].setText(document.read_only_reason)
            return
        labels["segment"].setText(f"chain {document.structure.segments[document.segment].summary}")
        labels["level"].setText(f"level {document.shown_level():.2f} / {document.max_level:.2f}")
        pick = document.pick
        if (len(document.selection) or len(document.selected_groups)) and pick is None:
            labels["pick"].setText(f"selected {selection_text(document)}; Esc clears")
            return
        idle = ("Click a control point to pick it; drag it to edit." if self.controller.mode is Mode.POINT
                else "Drag the curve to tug it.")
        labels["pick"].setText(
            f"{idle} Drag elsewhere to turn the view." if pick is None
            else f"point {pick.index} moves {len(pick.residues)} residues: {document.residue_range(pick.residues)}"
        )

    def show_notes(self) -> None:
        """A dialog listing what reading the file skipped or ignored (the button's click)."""
        QMessageBox.information(self.notes.window(), PROG, f"Reading {self.document.path.name}:\n\n"
                                + _listed(self.document.structure.warnings, NOTES_LISTED))

    def _update_notes(self) -> None:
        notes = self.document.structure.warnings if self.document.model is not None else ()
        self.notes.setVisible(bool(notes))
        self.notes.setText(f"{len(notes)} note{'' if len(notes) == 1 else 's'} on reading")
        self.notes.setToolTip(_listed(notes, 10) + "\n\nClick for the list." if notes else "")

    def _update_correlation(self) -> None:
        value = self.correlation.value
        self.labels["map"].setText("" if value is None else f"map CC {value:.3f}")


def selection_text(document: Document, named: int = 4) -> str:
    """The selection in a few words: a run of residues as ``A:LYS40–A:TYR42 (3 residues)``,
    others as ``13 residues: A:ASP189, A:SER190, A:CYS191 … A:TYR228`` (the first ``named``
    and the last), then groups by name, ``A:BEN1``, or by number, ``56 groups: A:HOH143 … A:HOH198``."""
    rows = document.selection
    label = document.structure.residue_label
    segments = document.structure.residue_place(rows)[0]
    if not len(rows):
        residues = ""
    elif np.all(np.diff(rows) == 1) and len(set(segments.tolist())) == 1:  # one run
        first, last = label(int(rows[0])), label(int(rows[-1]))
        residues = first if first == last else f"{first}–{last} ({len(rows)} residues)"
    else:
        shown = ", ".join(label(int(row)) for row in rows[:named])
        residues = f"{len(rows)} residues: {shown}" + (f" … {label(int(rows[-1]))}" if len(rows) > named else "")
    groups = Selected(rows[:0], document.selected_groups).labels(document.structure)
    groups = f"{len(groups)} groups: {groups[0]} … {groups[-1]}" if len(groups) > 2 else ", ".join(groups)
    return " and ".join(part for part in (residues, groups) if part)


def _listed(notes: tuple[str, ...], most: int) -> str:
    """The first ``most`` of ``notes``, a line each, and how many more there are."""
    shown = "\n".join(f"• {note}" for note in notes[:most])
    return shown + (f"\n… and {len(notes) - most} more" if len(notes) > most else "")
