"""The "Compared structures" dock: add, list, choose chains, show or hide, remove.

One row per compared structure: a visibility check box with its colour and name, its
chain, the rms of its superposition on the edited chain, and a remove button. The panel
changes the :class:`~app.editor.scene.overlay.Comparison` only through its mutators.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSignalBlocker
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QMessageBox,
    QPushButton,
    QTableWidget,
    QVBoxLayout,
    QWidget,
)

from app.editor.scene.overlay import Comparison, chains
from core.protein.structure import StructureError

STRUCTURE_FILTER = "Structures (*.pdb *.ent *.cif *.mmcif *.gz);;All files (*)"
COLUMNS = ("Structure", "Chain", "rms to edited chain", "")


class ComparisonPanel(QWidget):
    """Lists the structures of a :class:`Comparison` and says at which level they are shown."""

    def __init__(self, comparison: Comparison, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.comparison = comparison
        self.add_button = QPushButton("Add structures…")
        self.add_button.setToolTip("Read structures, superpose their longest chain on the edited chain and show them")
        self.add_button.clicked.connect(self.add_dialog)
        self.level_text = QLabel()
        self.level_text.setToolTip("Every chain has its own top level log₂ N: each compared chain is shown as many "
                                   "levels below its top as the edited segment, so all keep the same fraction of "
                                   "their detail. They are superposed on the edited chain's Cα.")
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.verticalHeader().hide()
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.setMinimumHeight(0)  # the dock shares its place with others: the window stays small
        row = QHBoxLayout()
        row.addWidget(self.add_button)
        row.addStretch(1)
        layout = QVBoxLayout(self)
        layout.addLayout(row)
        layout.addWidget(self.level_text)
        layout.addWidget(self.table, 1)
        comparison.changed.connect(self._fill)
        comparison.document.levelChanged.connect(self._update_level)
        comparison.document.loaded.connect(self._update_level)
        self._fill()

    def add_files(self, paths: list[Path]) -> list[str]:
        """Add each file (its longest chain); returns the messages of those that could not be added."""
        problems = []
        for path in paths:
            try:
                self.comparison.add(path)
            except (StructureError, ValueError) as error:
                problems.append(f"{Path(path).name}: {error}")
        return problems

    def add_dialog(self) -> None:
        """Ask for structure files and add them; problems are reported in one message box."""
        document = self.comparison.document
        if not document.editable:
            return
        folder = str(document.path.parent) if document.path else str(Path.home())
        names, _ = QFileDialog.getOpenFileNames(self, "Add Structures for Comparison", folder, STRUCTURE_FILTER)
        problems = self.add_files([Path(name) for name in names])
        if problems:
            QMessageBox.critical(self, "ribbonwave", "\n".join(problems))

    def _fill(self) -> None:
        items = self.comparison.items
        self.table.setRowCount(0)  # drops the widgets of the old rows
        self.table.setRowCount(len(items))
        for row, item in enumerate(items):
            swatch = QPixmap(14, 14)
            swatch.fill(QColor(*item.colour))
            visible = QCheckBox(f"{item.structure.entry_id}  {item.path.name}")
            visible.setIcon(QIcon(swatch))
            visible.setChecked(item.visible)
            visible.setToolTip(str(item.path))
            visible.toggled.connect(lambda on, row=row: self.comparison.set_visible(row, on))
            chain = QComboBox()
            with QSignalBlocker(chain):
                chain.addItems(chains(item.structure))
                chain.setCurrentText(item.chain)
            chain.setEnabled(chain.count() > 1)
            chain.currentTextChanged.connect(lambda text, row=row: self._chain_chosen(row, text))
            fit = item.fit
            rms = QLabel(f"{fit.rms_core:.2f} Å on {fit.n_core} of {fit.n_pairs} Cα (to {item.fitted_to})")
            rms.setToolTip(f"Cα paired by {fit.pairing}; the fit is refined on the pairs closer than 3 Å. "
                           f"rms over all {fit.n_pairs} pairs: {fit.rms_all:.2f} Å")
            remove = QPushButton("Remove")
            remove.clicked.connect(lambda _=False, row=row: self.comparison.remove(row))
            for column, widget in enumerate((visible, chain, rms, remove)):
                self.table.setCellWidget(row, column, widget)
        self.table.updateGeometries()  # place the new widgets in their cells now, not at the next event
        self._update_level()

    def _chain_chosen(self, row: int, chain: str) -> None:
        try:
            self.comparison.set_chain(row, chain)
        except ValueError as error:
            QMessageBox.critical(self, "ribbonwave", str(error))
            self._fill()

    def _update_level(self) -> None:
        document = self.comparison.document
        self.add_button.setEnabled(document.editable)
        if not document.editable:
            self.level_text.setText(f"{document.read_only_reason}: no chain to compare with."
                                    if document.model is not None else "Open a structure first.")
            return
        depth = self.comparison.depth
        self.level_text.setText(f"Each at {depth:.2f} levels below its own log₂ N (same depth as the edited segment)")
