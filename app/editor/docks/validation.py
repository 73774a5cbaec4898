"""The validation dock: problem counts, the worst offenders and the regularization switches.

It shows the :class:`~app.editor.live_validation.LiveValidation` report, refreshed after every
change (during a drag too: the report is updated locally, see that module), and sets the
document's regularization options through its mutator.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.editor.live_validation import LiveValidation
from core.geometry.validation import KINDS

KIND_NAMES = {
    "peptide_bond": "Peptide bonds C–N",
    "ca_ca": "Cα–Cα distances",
    "angle_ca_c_n": "Angles Cα–C–N",
    "angle_c_n_ca": "Angles C–N–Cα",
    "omega": "Peptide planarity ω",
    "ramachandran": "Ramachandran outliers",
    "clash": "Clashes",
}
CHECKED_NAMES = {"ramachandran": "residues", "clash": "atoms"}
"""What the 'checked' figure counts (junctions otherwise)."""
WORST = 15
"""Offenders listed."""


class ValidationPanel(QWidget):
    """Counts per kind, the worst flags, and 'regularize on release / while dragging'."""

    def __init__(self, validation: LiveValidation, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.validation = validation
        document = validation.document
        self.count_labels: dict[str, QLabel] = {}
        counts = QGroupBox("Problems")
        form = QFormLayout(counts)
        for kind in KINDS:
            label = QLabel()
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            form.addRow(KIND_NAMES[kind], label)
            self.count_labels[kind] = label
        self.timing = QLabel()
        form.addRow(self.timing)
        self.worst = QTreeWidget()
        self.worst.setColumnCount(3)
        self.worst.setHeaderLabels(["Severity", "Where", "Problem"])
        self.worst.setRootIsDecorated(False)
        self.worst.setToolTip("Severity: deviation / tolerance (above 1 is flagged)")
        offenders = QGroupBox("Worst offenders")
        QVBoxLayout(offenders).addWidget(self.worst)
        self.on_release = QCheckBox("Regularize on release")
        self.on_release.setToolTip("Each drag's undo step ends with ideal peptide junctions and no new clashes")
        self.while_dragging = QCheckBox("Regularize while dragging")
        self.while_dragging.setToolTip("Regularize every step of a drag (slower: tens of ms a step)")
        self.on_release.setChecked(document.regularize_on_release)
        self.while_dragging.setChecked(document.regularize_while_dragging)
        switches = QGroupBox("Regularization")
        switch_box = QVBoxLayout(switches)
        switch_box.addWidget(self.on_release)
        switch_box.addWidget(self.while_dragging)
        layout = QVBoxLayout(self)
        layout.addWidget(counts)
        layout.addWidget(offenders, 1)
        layout.addWidget(switches)
        self.on_release.toggled.connect(lambda on: document.set_regularization(on_release=on))
        self.while_dragging.toggled.connect(lambda on: document.set_regularization(while_dragging=on))
        validation.updated.connect(self.refresh)
        self.refresh()

    def refresh(self) -> None:
        """Show the current report."""
        report = self.validation.report
        if report is None:
            for label in self.count_labels.values():
                label.setText("")
            self.timing.setText(self.validation.document.read_only_reason)
            self.worst.clear()
            return
        counts = report.counts
        for kind, label in self.count_labels.items():
            label.setText(f"{counts[kind]} of {report.checked[kind]} {CHECKED_NAMES.get(kind, 'junctions')}")
        self.timing.setText(f"{'local' if self.validation.local else 'full'} check: "
                            f"{self.validation.elapsed_ms:.1f} ms")
        self.worst.clear()
        self.worst.addTopLevelItems([
            QTreeWidgetItem([f"{flag.severity:.1f}", flag.where, f"{KIND_NAMES[flag.kind]}: {flag.detail}"])
            for flag in report.worst(WORST)
        ])
