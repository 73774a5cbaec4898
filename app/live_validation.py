"""Validation that follows the document: one full check per structure, local checks per edit.

:class:`LiveValidation` validates the whole structure when it is loaded; after that each
:class:`~app.document.Change` (a drag preview, an undo, a regularization) re-checks only
the residues that moved, with what they touch, and folds that local report into the
current one (:meth:`core.validation.ValidationReport.updated`); a change that moves more
than half of the residues is checked in full. Every atom outside a change is where it was
when the report described it, so the folded report is the report of the current
coordinates. Views follow :attr:`LiveValidation.updated`.
"""

from __future__ import annotations

import time

from PySide6.QtCore import QObject, Signal

from app.document import Change, Document
from core.validation import ValidationReport, validate

LOCAL_FRACTION = 0.5
"""A change of more than this fraction of the residues is checked in full (as fast, and exact)."""


class LiveValidation(QObject):
    """The validation report of a :class:`Document`'s current coordinates."""

    updated = Signal()
    """:attr:`report` describes new coordinates (or a new structure)."""

    def __init__(self, document: Document) -> None:
        super().__init__(document)
        self.document = document
        self.report: ValidationReport | None = None
        self.elapsed_ms = 0.0
        """Time of the last check, ms (a full one after loading, a local one after a change)."""
        self.local = False
        """Whether the last check was a local one."""
        document.loaded.connect(self._check_all)
        document.changed.connect(self._check_change)
        if document.model is not None:
            self._check_all()

    def _check_all(self) -> None:
        start = time.perf_counter()
        self.report = validate(self.document.structure, self.document.model.coords)
        self._done(start, local=False)

    def _check_change(self, change: Change) -> None:
        structure = self.document.structure
        residues = structure.segments[change.segment].residue_index[change.residues]
        if len(residues) > LOCAL_FRACTION * structure.n_residues:
            self._check_all()
            return
        start = time.perf_counter()
        self.report = self.report.updated(validate(structure, self.document.model.coords, residues=residues))
        self._done(start, local=True)

    def _done(self, start: float, local: bool) -> None:
        self.elapsed_ms = 1e3 * (time.perf_counter() - start)
        self.local = local
        self.updated.emit()
