"""What follows a fit, whatever its target: regularization as after a drag, keeping the
finest level whose regularized model has no more bad peptide junctions than the input."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from core.fitting.coarse_to_fine import LevelFit
from core.geometry.regularize import LOOSE_TO_TIGHT, TIGHT, regularized
from core.geometry.validation import validate
from core.protein.model import Edit, EditableModel, per_segment
from core.protein.structure import Structure


@dataclass(frozen=True, eq=False)
class FitResult:
    """A fit settled by :func:`settle`.

    Attributes
    ----------
    levels : the fit of each level kept, coarse first (their edits applied to the model).
    regularization : the regularizing edit of each segment, after the levels.
    dropped : levels fitted but undone: the regularized model of each left clearly more bad
        peptide junctions and Ramachandran outliers than the input had (finer levels bent
        the backbone to a shape its residues cannot take, as when the target is another
        protein).
    refinement : what followed, one edit per segment (for a map: the side chains turned into
        it and the finest level fitted again, :func:`core.fitting.density.refine`).
    """

    levels: list[LevelFit]
    regularization: list[Edit]
    dropped: list[int]
    refinement: list[Edit] = field(default_factory=list)


BACKBONE = ("peptide_bond", "ca_ca", "ramachandran")
"""The flags a regularized fit may not clearly add (:data:`MARGIN`): bad peptide junctions
and Ramachandran outliers, where the backbone cannot take the fitted shape."""
MARGIN = 0.02
"""Such flags a regularized fit may add, per fitted residue (at least :data:`MIN_MARGIN`),
before its finest level is undone. A homologue's finest level adds many (3PTB onto 3SGB:
14 or more); a fit that reaches its target none to three, depending on the last bits of
floating point where the regularization has many minima. Undoing the finest level for one
junction more put adenylate kinase 2.9 Å from its target in a 10 Å map cut sharply in
Fourier space, where keeping it ends 1.4–1.5 Å from it from every start."""
MIN_MARGIN = 2
SCHEDULES = (LOOSE_TO_TIGHT, TIGHT)
"""How a fit is regularized (:func:`core.geometry.regularize.relax`): loose to tight, and
tight at once where that leaves clearly more :data:`BACKBONE` flags than the input, before a
level is undone."""
FIT_ITERATIONS = 60
"""Levenberg–Marquardt steps at most when regularizing a fit: a whole chain moved onto
another conformation, every side chain checked for clashes, takes 40–45 to settle, where
a drag takes 4–14 (:data:`core.geometry.least_squares.MAX_ITERATIONS`)."""


def settle(model: EditableModel, fits: list[LevelFit], *, regularize: bool = True,
           cancelled: Callable[[], bool] = lambda: False,
           undo: Callable[[LevelFit], None] | None = None) -> FitResult:
    """With ``regularize``, regularize what ``fits`` (applied to ``model``) moved (each of
    :data:`SCHEDULES` in turn); while the regularized model has clearly more bad peptide
    junctions and Ramachandran outliers than the input (:data:`BACKBONE`, by more than
    :data:`MARGIN` of the fitted residues), undo the finest level kept (with ``undo``,
    where its edits are undo steps; else by reverting them) and try again, while more than
    one level moved something."""
    fits = list(fits)
    if not regularize:
        return FitResult(fits, [], [])
    fitted = sum(len(edit.residues) for edit in per_segment(edit for fit in fits for edit in fit.edits))
    allowed = (_backbone_flags(model.structure, model.structure.coords)
               + max(MIN_MARGIN, round(MARGIN * fitted)))
    dropped: list[int] = []
    while True:
        for schedule in SCHEDULES:
            edits = regularize_fit(model, fits, schedule)
            if sum(1 for fit in fits if fit.edits) <= 1 or _backbone_flags(model.structure, model.coords) <= allowed or cancelled():
                return FitResult(fits, edits, dropped)
            for edit in reversed(edits):
                model.revert(edit)
        if undo is None:
            for edit in reversed(fits[-1].edits):
                model.revert(edit)
        else:
            undo(fits[-1])
        dropped.insert(0, fits.pop().level)


def _backbone_flags(structure: Structure, coords: np.ndarray) -> int:
    counts = validate(structure, coords).counts
    return sum(counts[kind] for kind in BACKBONE)


def regularize_fit(model: EditableModel, fits: Sequence[LevelFit], schedule: Sequence[float] = LOOSE_TO_TIGHT
                   ) -> list[Edit]:
    """Regularize (and apply) what ``fits`` moved, one edit per segment: ideal peptide
    junctions, on the fitted curve, without new clashes (:func:`core.geometry.regularize.regularized`,
    through ``schedule``)."""
    edits = []
    for edit in per_segment(edit for fit in fits for edit in fit.edits):
        if len(edit.residues):
            fixed = regularized(model, edit, max_iterations=FIT_ITERATIONS, schedule=schedule)
            step = Edit(edit.segment, edit.new_points, edit.new_points, fixed.residues, fixed.rows,
                        model.coords[fixed.rows], fixed.new_coords)  # from the fitted state
            model.apply(step)
            edits.append(step)
    return edits
