"""What follows a fit, whatever its target: regularization as after a drag, keeping the
finest level whose regularized model has no more bad peptide junctions than the input."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from core.fitting.coarse_to_fine import LevelFit
from core.geometry.regularize import regularized
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
        peptide junctions than the input had (finer levels bent the backbone to a shape
        its residues cannot take, as when the target is another protein).
    refinement : what followed, one edit per segment (for a map: the side chains turned into
        it and the finest level fitted again, :func:`core.fitting.density.refine`).
    """

    levels: list[LevelFit]
    regularization: list[Edit]
    dropped: list[int]
    refinement: list[Edit] = field(default_factory=list)


BACKBONE = ("peptide_bond", "ca_ca")
"""The flags a regularized fit may not clearly add (:data:`JUNCTION_MARGIN`)."""
JUNCTION_MARGIN = 0.02
"""Bad peptide junctions a regularized fit may add, per fitted residue (at least
:data:`MIN_JUNCTION_MARGIN`) before its finest level is undone. A homologue's finest level
leaves many (3PTB onto 3SGB: 22 more than the input); a fit that reaches its target leaves
none or one or two, depending on the last bits of floating point (the regularization of a
whole chain has many minima). Undoing the finest level for one junction more put adenylate
kinase 2.9 Å from its target in a 10 Å map cut sharply in Fourier space, where keeping
the level ends 1.4–1.5 Å from it from every start."""
MIN_JUNCTION_MARGIN = 2
FIT_ITERATIONS = 60
"""Levenberg–Marquardt steps at most when regularizing a fit: a whole chain moved onto
another conformation, every side chain checked for clashes, takes 40–45 to settle, where
a drag takes 4–14 (:data:`core.geometry.least_squares.MAX_ITERATIONS`)."""


def settle(model: EditableModel, fits: list[LevelFit], *, regularize: bool = True,
           cancelled: Callable[[], bool] = lambda: False,
           undo: Callable[[LevelFit], None] | None = None) -> FitResult:
    """With ``regularize``, regularize what ``fits`` (applied to ``model``) moved; while
    the regularized model has clearly more bad peptide junctions than the input (by more
    than :data:`JUNCTION_MARGIN` of the fitted residues), undo the finest level kept (with
    ``undo``, where its edits are undo steps; else by reverting them) and try again."""
    fits = list(fits)
    if not regularize:
        return FitResult(fits, [], [])
    fitted = sum(len(edit.residues) for edit in per_segment(edit for fit in fits for edit in fit.edits))
    allowed = (_bad_junctions(model.structure, model.structure.coords)
               + max(MIN_JUNCTION_MARGIN, round(JUNCTION_MARGIN * fitted)))
    dropped: list[int] = []
    while True:
        edits = regularize_fit(model, fits)
        if len(fits) <= 1 or _bad_junctions(model.structure, model.coords) <= allowed or cancelled():
            return FitResult(fits, edits, dropped)
        for edit in reversed(edits):
            model.revert(edit)
        if undo is None:
            for edit in reversed(fits[-1].edits):
                model.revert(edit)
        else:
            undo(fits[-1])
        dropped.insert(0, fits.pop().level)


def _bad_junctions(structure: Structure, coords: np.ndarray) -> int:
    counts = validate(structure, coords).counts
    return sum(counts[kind] for kind in BACKBONE)


def regularize_fit(model: EditableModel, fits: Sequence[LevelFit]) -> list[Edit]:
    """Regularize (and apply) what ``fits`` moved, one edit per segment: ideal peptide
    junctions, on the fitted curve, without new clashes (:func:`core.geometry.regularize.regularized`)."""
    edits = []
    for edit in per_segment(edit for fit in fits for edit in fit.edits):
        if len(edit.residues):
            fixed = regularized(model, edit, max_iterations=FIT_ITERATIONS)
            step = Edit(edit.segment, edit.new_points, edit.new_points, fixed.residues, fixed.rows,
                        model.coords[fixed.rows], fixed.new_coords)  # from the fitted state
            model.apply(step)
            edits.append(step)
    return edits
