"""The "Compared structures" dock: add, list, choose chains, show or hide, remove.

One row per compared structure: a visibility check box with its colour and file name, its
chain, the TM-score of its superposition on the edited chain, the aligned pairs, their
rms, and a remove button. Below a TM-score of 0.5 the folds differ: the row says so
rather than let a small rms on a few pairs pass for a good fit. The columns fit their
content and the Structure column takes the rest, never narrower than its names. The panel
changes the :class:`~app.editor.scene.overlay.Comparison` only through its mutators.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QMessageBox,
    QPushButton,
    QStyle,
    QTableWidget,
    QTableWidgetItem,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.editor.scene.overlay import CORE_CUTOFF, SAME_FOLD, Compared, Comparison, chains
from core.protein.input_files import StructureError

STRUCTURE_FILTER = "Structures (*.pdb *.ent *.cif *.mmcif *.gz);;All files (*)"
COLUMNS = ("Structure", "Chain", "TM-score", "Aligned", "rms (Å)", "")
STRUCTURE, CHAIN, TM_SCORE, ALIGNED, RMS, REMOVE = range(len(COLUMNS))
HEADER_TIPS = {
    TM_SCORE: "TM-score of the superposition shown, normalised by the edited chain's length (TM-align's d0): "
              "1 for identical chains, 0.5 or more for the same fold, below 0.5 mostly different folds",
    ALIGNED: "Residue pairs within TM-align's distance cutoff after the superposition, of the edited chain's residues",
    RMS: "rms Cα distance over the aligned pairs after the superposition shown",
}
WARNING_COLOUR = QColor(190, 70, 0)
"""The TM-score of chains of different folds."""
PAIRED_BY = {"numbering": "residue numbering", "alignment": "sequence alignment",
             "structure": "structural alignment (TM-align's way)"}


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
        for column, tip in HEADER_TIPS.items():
            self.table.horizontalHeaderItem(column).setToolTip(tip)
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(STRUCTURE, QHeaderView.ResizeMode.Stretch)
        header.setStretchLastSection(False)
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
            visible = QCheckBox(_label(item))
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
            remove = QToolButton()
            remove.setIcon(self.style().standardIcon(QStyle.StandardPixmap.SP_TitleBarCloseButton))
            remove.setAutoRaise(True)
            remove.setToolTip(f"Remove {item.name} from the comparison")
            remove.clicked.connect(lambda _=False, row=row: self.comparison.remove(row))
            for column, widget in ((STRUCTURE, visible), (CHAIN, chain), (REMOVE, remove)):
                self.table.setCellWidget(row, column, widget)
            for column, cell in zip((TM_SCORE, ALIGNED, RMS), self._fit_cells(item)):
                self.table.setItem(row, column, cell)
        self.table.resizeRowsToContents()
        self.table.updateGeometries()  # place the new widgets in their cells now, not at the next event
        self.table.setMinimumWidth(self._content_width())
        self._update_level()

    def _fit_cells(self, item: Compared) -> tuple[QTableWidgetItem, QTableWidgetItem, QTableWidgetItem]:
        """The TM-score, aligned pairs and rms cells of ``item``: a warning below :data:`SAME_FOLD`."""
        fit = item.fit
        to = f"the edited chain {item.fitted_to} ({fit.length} residues)"
        tm = QTableWidgetItem(f"{fit.tm_score:.2f}")
        tm.setToolTip(f"TM-score {fit.tm_score:.3f} of the superposition shown, normalised by {to}: "
                      f"{SAME_FOLD:g} or more, the same fold.")
        if not fit.same_fold:
            tm.setText(f"{fit.tm_score:.2f} — different folds")
            tm.setIcon(self.style().standardIcon(QStyle.StandardPixmap.SP_MessageBoxWarning))
            tm.setForeground(WARNING_COLOUR)
            tm.setToolTip(f"TM-score {fit.tm_score:.3f}, normalised by {to}. A TM-score below {SAME_FOLD:g} means "
                          f"the folds differ: the superposition is a guess, and an rms on the few pairs that "
                          f"happen to lie close is not meaningful.")
        aligned = QTableWidgetItem(f"{fit.n_aligned} of {fit.length}")
        aligned.setToolTip(f"{fit.n_aligned} Cα pairs closer than {fit.cutoff:.1f} Å after the superposition, of the "
                           f"{fit.length} residues of {to}; residues paired by {PAIRED_BY[fit.pairing]}")
        rms = QTableWidgetItem(f"{fit.rms_aligned:.2f}" if fit.n_aligned else "—")
        fitted = (f"superposed on the pairs within {CORE_CUTOFF:g} Å" if fit.pairing != "structure"
                  else "superposition of highest TM-score")
        rms.setToolTip(f"rms Cα distance over the {fit.n_aligned} aligned pairs ({fitted})")
        for cell in (tm, aligned, rms):
            cell.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        return tm, aligned, rms

    def _content_width(self) -> int:
        """Width the table needs to show every column at its content's width (the Structure
        column is stretched, so it is never narrower than its names when the table is this wide)."""
        header = self.table.horizontalHeader()
        columns = sum(max(header.sectionSizeHint(c), self.table.sizeHintForColumn(c)) for c in range(len(COLUMNS)))
        return columns + 2 * self.table.frameWidth() + self.table.verticalScrollBar().sizeHint().width()

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


def _label(item: Compared) -> str:
    """The file name, and the entry's code where the name does not hold it."""
    name = item.path.name
    return name if item.structure.entry_id.lower() in name.lower() else f"{name} ({item.structure.entry_id})"
