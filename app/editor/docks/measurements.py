"""The *Measurements* dock: every label and measurement, its atoms and its value as the
model is now (the values change in place as edits move the atoms), and a button that deletes
the selected one."""

from __future__ import annotations

import numpy as np
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.editor.document import Change, Document

COLUMNS = ("What", "Atoms", "Value")


class MeasurementsPanel(QWidget):
    """A table of the document's measurements."""

    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.document = document
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.verticalHeader().hide()
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.Stretch)
        self.delete = QPushButton("Delete")
        self.delete.clicked.connect(self._delete)
        layout = QVBoxLayout(self)
        layout.addWidget(self.table)
        layout.addWidget(self.delete)
        document.measurements.changed.connect(self._list)
        document.changed.connect(self._values)
        self._list()

    def _list(self) -> None:
        items = self.document.measurements.items
        self.table.setRowCount(len(items))
        for row, measurement in enumerate(items):
            for column, text in enumerate((measurement.kind, measurement.names(self.document.structure), "")):
                self.table.setItem(row, column, QTableWidgetItem(text))
        self._values()
        self.delete.setEnabled(bool(items))

    def _values(self, change: Change | None = None) -> None:
        """Each value as the model is now (after an edit that moved their atoms, in place)."""
        items = self.document.measurements.items
        rows = np.array([row for measurement in items for row in measurement.atoms], dtype=np.int64)
        if not len(rows) or (change is not None and not np.isin(rows, change.rows).any()):
            return
        coords = self.document.model.coords
        for row, measurement in enumerate(items):
            value = measurement.value(coords)
            self.table.item(row, 2).setText("" if value is None else measurement.text(self.document.structure, coords))

    def _delete(self) -> None:
        rows = sorted({index.row() for index in self.table.selectedIndexes()}, reverse=True)
        for row in rows or [self.table.rowCount() - 1]:
            self.document.measurements.remove(row)
