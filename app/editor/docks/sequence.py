"""The sequence bar: the edited segment's one-letter codes along the view.

Each residue is a cell coloured by secondary structure, numbered every ten residues; the
residues the picked control point moves are underlined in the pick's colour and the
selected ones framed in the selection's colour. With a map open, a thin bar over each cell
gives the residue's correlation with the map (red 0.3 or less, through yellow, to green 0.8
or more; grey where it has none). A click (or a drag across cells) asks for
those residues to be selected and centred (:attr:`SequenceBar.residuesActivated`, which the
window connects); Shift extends the selection. Hovering names the residue. After them come
the letters of the entry's DNA and RNA strands (a modified base in lower case, N where it
has no known parent), each on its base's colour and headed by its chain (drawn, not edited);
a click on one selects that nucleotide and centres on it (:attr:`SequenceStrip.groupsActivated`),
framed as selected residues are.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, QRect, QSize, Qt, Signal
from PySide6.QtGui import QColor, QFont, QFontDatabase, QMouseEvent, QPainter, QPaintEvent
from PySide6.QtWidgets import QScrollArea, QToolTip, QWidget

from app.editor.document import Document
from app.editor.scene.layers.control_points import PICKED_COLOUR
from app.editor.scene.layers.selection import SELECTION_COLOUR
from app.editor.scene.molecule import SS_COLOURS, SS_NAMES
from app.editor.scene.nucleic import nucleotides
from core.protein.lookup import group_label, groups_of
from core.protein.structure import nucleotide_letter

NUMBER_EVERY = 10
STRAND_GAP = 2
"""Empty cells before each DNA or RNA strand."""


class SequenceStrip(QWidget):
    """The painted row of residue cells of the document's current segment."""

    residuesActivated = Signal(object)
    """Residue-table rows (an array) to select and centre on."""
    groupsActivated = Signal(object)
    """The coordinate rows of a nucleotide (an array) to select and centre on."""

    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.document = document
        font = QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
        font.setPointSize(max(font.pointSize(), 9))
        font.setWeight(QFont.Weight.DemiBold)
        self.setFont(font)
        metrics = self.fontMetrics()
        self.cell = metrics.horizontalAdvance("W") + 4
        self.row_height = metrics.height() + 4
        self.setMouseTracking(True)
        self._anchor: int | None = None
        self._strands: list[tuple[str, str, np.ndarray]] = []
        """Each nucleic-acid strand's chain, letters and colours."""
        self._anchors: dict[int, int] = {}
        """The strands' cells, counted from the segment's last: each one's nucleotide, by an atom
        row of it (its P or C4')."""
        self.scores: np.ndarray | None = None
        """Each residue's correlation with the map (NaN where none), or None without a map."""
        for signal in (document.segmentChanged, document.picked, document.selectionChanged):
            signal.connect(self._refresh)
        document.loaded.connect(self._loaded)
        self._loaded()

    def sizeHint(self) -> QSize:
        strands = sum(len(letters) + STRAND_GAP for _, letters, _ in self._strands)
        return QSize((self._count() + strands) * self.cell + 8, 2 * self.row_height + 6)

    def minimumSizeHint(self) -> QSize:
        return self.sizeHint()

    def cell_rect(self, residue: int) -> QRect:
        """Where residue ``residue`` (index within the segment) is drawn."""
        return QRect(4 + residue * self.cell, self.row_height + 2, self.cell - 1, self.row_height)

    def residue_at(self, x: int) -> int | None:
        """The residue (index within the segment) at ``x`` pixels, or None."""
        k = (x - 4) // self.cell
        return int(k) if 0 <= k < self._count() and x >= 4 else None

    def set_scores(self, scores: np.ndarray | None) -> None:
        """Show each residue's correlation with the map (``None``: no map)."""
        self.scores = None if scores is None else np.asarray(scores, dtype=np.float64)
        self.update()

    def _count(self) -> int:
        document = self.document
        return len(document.structure.segments[document.segment]) if document.editable else 0

    def _loaded(self) -> None:
        atoms = self.document.structure.atoms if self.document.model is not None else None
        found = nucleotides(atoms) if atoms is not None else None
        self._strands = [] if found is None else [
            (str(found.chain[a]), "".join(nucleotide_letter(str(atoms.resname[row]), atoms.parents)
                                          for row in found.backbone[a:b]), found.colours[a:b])
            for a, b in zip(found.strand_start[:-1], found.strand_start[1:])]
        self._anchors, k = {}, 0
        if found is not None:
            for a, b in zip(found.strand_start[:-1].tolist(), found.strand_start[1:].tolist()):
                k += STRAND_GAP
                self._anchors |= {k + n: int(row) for n, row in enumerate(found.backbone[a:b].tolist())}
                k += b - a
        self._refresh()

    def _refresh(self) -> None:
        self.setMinimumSize(self.sizeHint())
        self.resize(self.sizeHint())
        self.update()

    def paintEvent(self, event: QPaintEvent) -> None:
        self._paint_strands()
        document = self.document
        if not document.editable:
            return
        segment = document.structure.segments[document.segment]
        start = int(segment.residue_index[0])
        selected = np.zeros(len(segment), dtype=bool)
        rows = document.selection[(document.selection >= start) & (document.selection < start + len(segment))]
        selected[rows - start] = True
        moved = np.zeros(len(segment), dtype=bool)
        if document.pick is not None:
            moved[document.pick.residues] = True
        painter = QPainter(self)
        first = max(0, self.residue_at(event.rect().left()) or 0)
        last = min(len(segment), (event.rect().right() - 4) // self.cell + 2)
        text = self.palette().windowText().color()
        for k in range(first, last):
            cell = self.cell_rect(k)
            painter.fillRect(cell, QColor(*_light(SS_COLOURS[segment.ss[k]])))
            if self.scores is not None and k < len(self.scores):
                painter.fillRect(QRect(cell.left(), cell.top(), cell.width(), 3), _score_colour(self.scores[k]))
            if moved[k]:
                painter.fillRect(QRect(cell.left(), cell.bottom() - 2, cell.width(), 3), QColor(*PICKED_COLOUR))
            if selected[k]:
                painter.setPen(QColor(*SELECTION_COLOUR).darker(120))
                painter.drawRect(cell.adjusted(0, 0, -1, -1))
            painter.setPen(text)
            painter.drawText(cell, Qt.AlignmentFlag.AlignCenter, segment.sequence[k])
            number = int(segment.resseq[k])
            if number % NUMBER_EVERY == 0 or k == 0 and not np.any(segment.resseq[:3] % NUMBER_EVERY == 0):
                painter.drawText(QPoint(cell.left(), self.row_height - 2), f"{number}{segment.icode[k]}")
        painter.end()

    def nucleotide_at(self, x: int) -> np.ndarray | None:
        """The coordinate rows of the nucleotide whose letter is at ``x`` pixels, or None."""
        anchor = self._anchors.get((x - 4) // self.cell - self._count()) if x >= 4 else None
        return None if anchor is None else groups_of(self.document.structure, np.array([anchor]))

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() != Qt.MouseButton.LeftButton:
            return
        residue = self.residue_at(int(event.position().x()))
        if residue is None:
            nucleotide = self.nucleotide_at(int(event.position().x()))
            if nucleotide is not None:
                self.groupsActivated.emit(nucleotide)
            return
        shift = bool(event.modifiers() & Qt.KeyboardModifier.ShiftModifier)
        if not shift or self._anchor is None:
            self._anchor = residue
        self._activate(self._anchor, residue)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        residue = self.residue_at(int(event.position().x()))
        if residue is None:
            nucleotide = self.nucleotide_at(int(event.position().x()))
            if nucleotide is not None:
                label = group_label(self.document.structure, int(nucleotide[0]))
                QToolTip.showText(event.globalPosition().toPoint(), f"{label} · nucleic acid", self)
            return
        if event.buttons() & Qt.MouseButton.LeftButton and self._anchor is not None:
            self._activate(self._anchor, residue)
            return
        segment = self.document.structure.segments[self.document.segment]
        text = f"{segment.labels[residue]} · {SS_NAMES[segment.ss[residue]]}"
        if self.scores is not None and residue < len(self.scores) and np.isfinite(self.scores[residue]):
            text += f" · map CC {self.scores[residue]:.2f}"
        QToolTip.showText(event.globalPosition().toPoint(), text, self)

    def _activate(self, a: int, b: int) -> None:
        start = int(self.document.structure.segments[self.document.segment].residue_index[0])
        low, high = sorted((a, b))
        self.residuesActivated.emit(np.arange(start + low, start + high + 1))


    def _paint_strands(self) -> None:
        """The DNA and RNA strands' letters after the segment's, each headed by its chain."""
        if not self._strands:
            return
        painter = QPainter(self)
        text = self.palette().windowText().color()
        k = self._count()
        selected = set(self.document.selected_groups.tolist())
        for chain, letters, colours in self._strands:
            k += STRAND_GAP
            painter.setPen(text)
            painter.drawText(QPoint(self.cell_rect(k).left(), self.row_height - 2), f"{chain} (nucleic acid)")
            for letter, colour in zip(letters, colours):
                cell = self.cell_rect(k)
                painter.fillRect(cell, QColor(*_light(tuple(int(c) for c in colour))))
                if self._anchors[k - self._count()] in selected:
                    painter.setPen(QColor(*SELECTION_COLOUR).darker(120))
                    painter.drawRect(cell.adjusted(0, 0, -1, -1))
                    painter.setPen(text)
                painter.drawText(cell, Qt.AlignmentFlag.AlignCenter, letter)
                k += 1
        painter.end()


class SequenceBar(QScrollArea):
    """The :class:`SequenceStrip` in a horizontal scroll area that keeps the selection in sight."""

    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.strip = SequenceStrip(document)
        self.setWidget(self.strip)
        self.setWidgetResizable(False)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setFixedHeight(self.strip.sizeHint().height() + self.horizontalScrollBar().sizeHint().height() + 4)
        document.selectionChanged.connect(self._follow)
        document.picked.connect(self._follow)

    def _follow(self) -> None:
        """Scroll so the first selected (or picked) residue of the segment is visible."""
        document = self.strip.document
        if not document.editable:
            return
        segment = document.structure.segments[document.segment]
        start = int(segment.residue_index[0])
        rows = document.selection[(document.selection >= start) & (document.selection < start + len(segment))] - start
        if not len(rows) and document.pick is not None:
            rows = document.pick.residues
        if len(rows):
            cell = self.strip.cell_rect(int(rows[0]))
            self.ensureVisible(cell.center().x(), cell.center().y(), 3 * self.strip.cell, 0)


def _score_colour(cc: float) -> QColor:
    """Red at CC 0.3 or less, yellow at 0.55, green at 0.8 or more; grey for NaN."""
    if not np.isfinite(cc):
        return QColor(160, 160, 160)
    return QColor.fromHsvF(float(np.clip((cc - 0.3) / 0.5, 0.0, 1.0)) / 3.0, 0.85, 0.9)


def _light(rgb: tuple[int, int, int]) -> tuple[int, int, int]:
    """``rgb`` halfway to white: a cell background that black letters read on."""
    return tuple(int(c + (255 - c) * 0.55) for c in rgb)  # type: ignore[return-value]
