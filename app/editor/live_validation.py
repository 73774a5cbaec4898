"""Validation that follows the document: one full check per structure, local checks per edit.

:class:`LiveValidation` validates the whole structure when it is loaded; after that each
:class:`~app.editor.document.Change` (a drag preview, an undo, a regularization) re-checks only
the residues that moved, with what they touch, and folds that local report into the
current one (:meth:`core.geometry.validation.ValidationReport.updated`); a change that moves more
than half of the residues is checked in full. Every atom outside a change is where it was
when the report described it, so the folded report is the report of the current
coordinates. A structure without a backbone (only viewed) has no report. Views follow
:attr:`LiveValidation.updated`.

The first full check of a structure is also its :attr:`~LiveValidation.baseline` (the
structure as read; a replayed session is checked as read once more): each flag of a later
report is new, worse or as read against it, and :attr:`~LiveValidation.triaged` holds the
flags that the :attr:`~LiveValidation.triage_filter` shows (by default those the session's
edits made or worsened, and the severe ones: :mod:`core.geometry.triage`), sorted out after
every check at the cost of a dictionary look-up per flag.

During a drag the report is brought up to date at most every :data:`DRAG_INTERVAL_MS`
(the residues moved meanwhile are checked together): by the first drag step after the
interval, within the step, so its views change with the frame the step draws (each event-loop
turn that changes a widget composes the whole window once more); and, where the drag pauses
for as long, by a timer. Every other change, the end of a drag included, is checked at once.
"""

from __future__ import annotations

import time

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal

from app.editor.document import Change, Document
from core.geometry.triage import Baseline, Triaged, TriageFilter, triage
from core.geometry.validation import ValidationReport, validate

LOCAL_FRACTION = 0.5
"""A change of more than this fraction of the residues is checked in full (as fast, and exact)."""

DRAG_INTERVAL_MS = 100
"""Shortest time between two checks while a drag is previewed."""


class LiveValidation(QObject):
    """The validation report of a :class:`Document`'s current coordinates."""

    updated = Signal()
    """:attr:`report` describes new coordinates (or a new structure)."""
    triageChanged = Signal()
    """:attr:`triage_filter` changed (and with it :attr:`triaged`)."""

    def __init__(self, document: Document) -> None:
        super().__init__(document)
        self.document = document
        self.report: ValidationReport | None = None
        """None until a structure with a backbone is loaded."""
        self.baseline: Baseline | None = None
        """The flags of the structure as read."""
        self.triage_filter = TriageFilter()
        self.triaged: Triaged | None = None
        """:attr:`report` sorted out against :attr:`baseline` by :attr:`triage_filter`."""
        self.elapsed_ms = 0.0
        """Time of the last check, ms (a full one after loading, a local one after a change)."""
        self.local = False
        """Whether the last check was a local one."""
        self.late = False
        """Whether the last check was a drag's deferred one, run after its change was drawn (the drag paused)."""
        self._pending: np.ndarray | None = None  # residues (table rows) moved since the last check
        self._finished = 0.0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(lambda: self._check_pending(late=True))
        document.loaded.connect(self._load)
        document.changed.connect(self._check_change)
        if document.model is not None:
            self._load()

    @property
    def pending(self) -> bool:
        """Whether moved residues wait for their (deferred) check."""
        return self._pending is not None

    def check_now(self) -> None:
        """Run a check that waits for the drag interval at once (if there is one)."""
        self._check_pending()

    def set_triage(self, triage_filter: TriageFilter) -> None:
        """Show the flags that ``triage_filter`` lets through."""
        if triage_filter == self.triage_filter:
            return
        self.triage_filter = triage_filter
        if self.report is not None:
            self.triaged = triage(self.report, self.baseline, triage_filter)
        self.triageChanged.emit()

    def _load(self) -> None:
        self.baseline = None
        self._check_all()

    def _check_all(self, late: bool = False) -> None:
        self._timer.stop()
        self._pending = None
        start = time.perf_counter()
        structure = self.document.structure
        if not self.document.editable:
            self.report = None
        else:
            coords = self.document.model.coords
            self.report = validate(structure, coords)
            if self.baseline is None:  # the first check of this structure
                as_read = np.array_equal(coords, structure.coords)
                self.baseline = Baseline.of(self.report if as_read else validate(structure))
        self._done(start, local=False, late=late)

    def _check_change(self, change: Change) -> None:
        residues = self.document.structure.segments[change.segment].residue_index[change.residues]
        self._pending = residues if self._pending is None else np.union1d(self._pending, residues)
        if self.document.dragging and 1e3 * (time.perf_counter() - self._finished) < DRAG_INTERVAL_MS:
            self._timer.start(DRAG_INTERVAL_MS)  # checked by a later step, or once the drag pauses this long
            return
        self._check_pending()

    def _check_pending(self, late: bool = False) -> None:
        residues = self._pending
        if residues is None:
            return
        if len(residues) > LOCAL_FRACTION * self.document.structure.n_residues:
            self._check_all(late)
            return
        self._timer.stop()
        self._pending = None
        start = time.perf_counter()
        local = validate(self.document.structure, self.document.model.coords, residues=residues)
        self.report = self.report.updated(local)
        self._done(start, local=True, late=late)

    def _done(self, start: float, local: bool, late: bool) -> None:
        self._finished = time.perf_counter()
        self.elapsed_ms = 1e3 * (self._finished - start)
        self.local = local
        self.late = late
        self.triaged = None if self.report is None else triage(self.report, self.baseline, self.triage_filter)
        self.updated.emit()
