"""The validation dock: the flags to look at, their filter, the counts and the regularization switches.

It shows the :class:`~app.editor.live_validation.LiveValidation` report, refreshed after every
change (during a drag too: the report is updated locally, see that module). At the top, the
list of the flags that the triage filter shows, worst first (new and worse ones in bold);
clicking a row emits :attr:`ValidationPanel.flagActivated`. Under it the filter (scope,
minimum severity, a box per kind beside its counts), then the regularization options. The
panel sets the filter and the options through the mutators of the live validation and of
the document.
"""

from __future__ import annotations

from dataclasses import replace

from PySide6.QtCore import QSignalBlocker, Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QStyle,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.editor.live_validation import LiveValidation
from core.geometry.triage import AS_READ, EDITED, EDITED_OR_SEVERE, EVERYTHING, SEVERE
from core.geometry.validation import KINDS, Flag

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
SCOPE_NAMES = {EDITED_OR_SEVERE: "edits and severe", EDITED: "edits only", EVERYTHING: "everything"}
SEVERITIES = {"all flagged": 0.0, "severity > 2": 2.0, "severity > 4": 4.0}
"""Choices of the minimum severity."""
LISTED = 200
"""Rows of the list at most (a last row says how many more are shown on the model)."""
COLUMNS = ("Severity", "Status", "Where", "Problem")
LIST_LINES = 6
"""Height of the list at its smallest, in lines of text: it fits a 1366 × 768 screen's dock."""


class ValidationPanel(QWidget):
    """The flags shown (a list to click), the triage filter with the counts per kind, and
    'regularize on release / while dragging'."""

    flagActivated = Signal(object)
    """A row of the list was clicked (or activated with the keyboard): its :class:`~core.geometry.validation.Flag`."""

    def __init__(self, validation: LiveValidation, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.validation = validation
        document = validation.document
        self.listed: tuple[Flag, ...] = ()
        """The flags of the list's rows, in order."""

        self.scope = QComboBox()
        for scope, name in SCOPE_NAMES.items():
            self.scope.addItem(name, scope)
        self.scope.setToolTip(f"Edits and severe: the problems the edits made or worsened, and any over {SEVERE:g} × "
                              "its tolerance. Edits only: the former. Everything: the file's own problems too.")
        self.severity = QComboBox()
        for name, value in SEVERITIES.items():
            self.severity.addItem(name, value)
        self.severity.setToolTip("Severity: deviation / tolerance (above 1 is flagged)")
        self.shown = QLabel()
        filters = QHBoxLayout()
        filters.addWidget(QLabel("Show"))
        filters.addWidget(self.scope)
        filters.addWidget(self.severity)
        filters.addStretch(1)
        filters.addWidget(self.shown)

        self.offenders = QTreeWidget()
        self.offenders.setColumnCount(len(COLUMNS))
        self.offenders.setHeaderLabels(COLUMNS)
        self.offenders.setRootIsDecorated(False)
        self.offenders.setUniformRowHeights(True)
        self.offenders.header().setStretchLastSection(False)
        self.offenders.headerItem().setToolTip(0, self.severity.toolTip())
        self.offenders.headerItem().setToolTip(1, "new: not in the structure as read; worse: more severe than there")
        self.offenders.setMinimumHeight(LIST_LINES * self.fontMetrics().lineSpacing())
        self.offenders.setToolTip("Click a problem to centre the view on it")
        self.offenders.itemActivated.connect(self._activate)  # Enter, a double click, or a click where the style says
        if not self.offenders.style().styleHint(QStyle.StyleHint.SH_ItemView_ActivateItemOnSingleClick,
                                                None, self.offenders):
            self.offenders.itemClicked.connect(self._activate)

        self.kind_boxes: dict[str, QCheckBox] = {}
        self.count_labels: dict[str, QLabel] = {}
        counts = QGroupBox("Problems")
        grid = QGridLayout(counts)
        grid.setVerticalSpacing(0)
        for row, kind in enumerate(KINDS):
            box = QCheckBox(KIND_NAMES[kind])
            box.setChecked(True)
            box.toggled.connect(self._set_kinds)
            label = QLabel()
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            grid.addWidget(box, row, 0)
            grid.addWidget(label, row, 1)
            self.kind_boxes[kind], self.count_labels[kind] = box, label
        self.timing = QLabel()
        grid.addWidget(self.timing, len(KINDS), 0, 1, 2)

        self.on_release = QCheckBox("Regularize on release")
        self.on_release.setToolTip("Each drag's undo step ends with ideal peptide junctions and no new clashes")
        self.while_dragging = QCheckBox("Regularize while dragging")
        self.while_dragging.setToolTip("Regularize every step of a drag (slower: tens of ms a step)")
        self.on_release.setChecked(document.regularize_on_release)
        self.while_dragging.setChecked(document.regularize_while_dragging)
        switches = QHBoxLayout()
        switches.addWidget(self.on_release)
        switches.addWidget(self.while_dragging)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(filters)
        layout.addWidget(self.offenders, 1)
        layout.addWidget(counts)
        layout.addLayout(switches)
        self.scope.currentIndexChanged.connect(
            lambda: validation.set_triage(replace(validation.triage_filter, scope=self.scope.currentData())))
        self.severity.currentIndexChanged.connect(
            lambda: validation.set_triage(replace(validation.triage_filter, min_severity=self.severity.currentData())))
        self.on_release.toggled.connect(lambda on: document.set_regularization(on_release=on))
        self.while_dragging.toggled.connect(lambda on: document.set_regularization(while_dragging=on))
        validation.updated.connect(self.refresh)
        validation.triageChanged.connect(self._show_triage)
        self._show_triage()

    def refresh(self) -> None:
        """Show the current report."""
        report, triaged = self.validation.report, self.validation.triaged
        if report is None:
            for label in self.count_labels.values():
                label.setText("")
            self.timing.setText(self.validation.document.read_only_reason)
            self.offenders.clear()
            self.listed = ()
            self.shown.setText("")
            return
        counts = report.counts
        for kind, label in self.count_labels.items():
            changes = [f"{n} {what}" for n, what in ((triaged.new[kind], "new"), (triaged.worse[kind], "worse")) if n]
            label.setText(", ".join(changes + [f"{counts[kind]} of {report.checked[kind]} "
                                               f"{CHECKED_NAMES.get(kind, 'junctions')}"]))
        self.timing.setText(f"{'local' if self.validation.local else 'full'} check: "
                            f"{self.validation.elapsed_ms:.1f} ms")
        self._fill_list()

    def _show_triage(self) -> None:
        """The filter's widgets as the live validation's filter says, and the list it lets through."""
        triage_filter = self.validation.triage_filter
        with QSignalBlocker(self.scope):
            self.scope.setCurrentIndex(self.scope.findData(triage_filter.scope))
        with QSignalBlocker(self.severity):
            if self.severity.findData(triage_filter.min_severity) < 0:  # set by a script
                self.severity.addItem(f"severity > {triage_filter.min_severity:g}", triage_filter.min_severity)
            self.severity.setCurrentIndex(self.severity.findData(triage_filter.min_severity))
        for kind, box in self.kind_boxes.items():
            with QSignalBlocker(box):
                box.setChecked(kind in triage_filter.kinds)
        self.refresh()

    def _fill_list(self) -> None:
        """Fill the list; where its rows are as many as before (as in most drag steps), only the
        texts that changed change. The columns only widen, where a text needs it: a column
        resized repaints in an event-loop turn of its own, after the frame's, and each turn
        composes the whole window again."""
        triaged = self.validation.triaged
        if triaged is None:
            return
        self.listed = triaged.flags[:LISTED]
        rows = [([f"{flag.severity:.1f}", "" if novelty == AS_READ else novelty, flag.where, _problem(flag)],
                 novelty != AS_READ) for flag, novelty in zip(self.listed, triaged.novelty)]
        more = len(triaged.flags) - len(self.listed)
        if more:
            rows.append((["", "", f"… and {more} more", ""], False))
        self.shown.setText(f"{len(triaged.flags)} of {len(self.validation.report.flags)} shown")
        tree = self.offenders
        if tree.topLevelItemCount() != len(rows):
            tree.clear()
            tree.addTopLevelItems([QTreeWidgetItem(len(COLUMNS)) for _ in rows])
            tree.doItemsLayout()
        for k, (texts, bold) in enumerate(rows):
            item = tree.topLevelItem(k)
            font = item.font(0)
            font.setBold(bold)
            for column, text in enumerate(texts):
                item.setText(column, text)  # no change where the text is the same
                item.setFont(column, font)
            item.setTextAlignment(0, Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        for column in range(len(COLUMNS)):
            if tree.sizeHintForColumn(column) > tree.columnWidth(column):
                tree.resizeColumnToContents(column)

    def _set_kinds(self) -> None:
        kinds = frozenset(kind for kind, box in self.kind_boxes.items() if box.isChecked())
        self.validation.set_triage(replace(self.validation.triage_filter, kinds=kinds))

    def _activate(self, item: QTreeWidgetItem) -> None:
        row = self.offenders.indexOfTopLevelItem(item)
        if 0 <= row < len(self.listed):
            self.flagActivated.emit(self.listed[row])


def _problem(flag: Flag) -> str:
    """The flag's detail line, named where it does not say what it is about."""
    return f"clash: {flag.detail}" if flag.kind == "clash" else flag.detail
