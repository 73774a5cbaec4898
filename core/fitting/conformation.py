"""Fit a model onto another conformation (or a close homologue): pair the residues as
``compare`` does, fit level by level (:mod:`core.fitting.coarse_to_fine`), then regularize as
after a drag, keeping the finest level whose regularized model has no new bad junctions."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from core.analysis.compare import pair_residues
from core.analysis.fold_alignment import tm_superpose
from core.fitting.coarse_to_fine import LevelFit, Pairs, fit_levels
from core.geometry.regularize import regularized
from core.geometry.validation import validate
from core.protein.model import Edit, EditableModel
from core.protein.structure import BackboneSegment, Structure, ca_rows


def pair_segments(
    model: EditableModel, segments: Sequence[int], target: Sequence[BackboneSegment], pairing: str = "auto"
) -> tuple[list[Pairs], str]:
    """Pair the residues of the model's ``segments`` (one chain, in order) with the target
    chain's (see :func:`core.analysis.compare.pair_residues`); returns the pairs of each
    segment that has any, and the pairing used."""
    chain = [model.segments[s] for s in segments]
    pairs_a, pairs_b, used = pair_residues(chain, target, pairing)
    target_ca = np.concatenate([s.ca for s in target])[pairs_b]
    starts = np.cumsum([0] + [len(s) for s in chain])
    pairs = []
    for k, segment in enumerate(segments):
        inside = (pairs_a >= starts[k]) & (pairs_a < starts[k + 1])
        if inside.any():
            pairs.append(Pairs(segment, pairs_a[inside] - starts[k], target_ca[inside]))
    return pairs, used


SAME_FOLD = 0.5
"""TM-score from which two chains have the same fold (below it there is nothing to fit onto)."""


def fold_similarity(model: EditableModel, pairs: Sequence[Pairs]) -> float:
    """TM-score of the paired Cα, normalised by the residues of the paired segments."""
    ca = np.concatenate([model.coords[ca_rows(model.structure)[model.segments[p.segment].residue_index[p.residues]]]
                         for p in pairs])
    length = sum(len(model.segments[p.segment]) for p in pairs)
    return tm_superpose(ca, np.concatenate([p.target for p in pairs]), length)[1]


@dataclass(frozen=True, eq=False)
class ConformationFit:
    """The result of :func:`fit_conformation`.

    Attributes
    ----------
    levels : the fit of each level kept, coarse first (their edits applied to the model).
    regularization : the regularizing edit of each segment, after the levels.
    dropped : levels fitted but undone: the regularized model of each left more bad
        peptide junctions than the input had (finer levels bent the backbone to a shape
        its residues cannot take, as when the target is another protein).
    """

    levels: list[LevelFit]
    regularization: list[Edit]
    dropped: list[int]


BACKBONE = ("peptide_bond", "ca_ca")
"""The flags a regularized fit may not add."""


def fit_conformation(
    model: EditableModel,
    pairs: Sequence[Pairs],
    levels: Sequence[int],
    *,
    regularize: bool = True,
    cancelled: Callable[[], bool] = lambda: False,
) -> ConformationFit:
    """Fit ``model`` onto the paired target Cα at ``levels`` (coarse first) and, with
    ``regularize``, regularize the residues that moved; every edit kept is applied to
    ``model``. A finest level whose regularized model has more bad peptide junctions than
    the input is undone (and so on down)."""
    fits = list(fit_levels(model, pairs, levels, ca_rows(model.structure), cancelled=cancelled))
    if not regularize:
        return ConformationFit(fits, [], [])
    allowed = _bad_junctions(model.structure, model.structure.coords)
    dropped: list[int] = []
    while True:
        edits = regularize_fit(model, fits)
        if len(fits) <= 1 or _bad_junctions(model.structure, model.coords) <= allowed or cancelled():
            return ConformationFit(fits, edits, dropped)
        for edit in reversed(edits):
            model.revert(edit)
        for edit in reversed(fits[-1].edits):
            model.revert(edit)
        dropped.insert(0, fits.pop().level)


def _bad_junctions(structure: Structure, coords: np.ndarray) -> int:
    counts = validate(structure, coords).counts
    return sum(counts[kind] for kind in BACKBONE)


def regularize_fit(model: EditableModel, fits: Sequence[LevelFit]) -> list[Edit]:
    """Regularize (and apply) what ``fits`` moved, one edit per segment: ideal peptide
    junctions, on the fitted curve, without new clashes (:func:`core.geometry.regularize.regularized`)."""
    total: dict[int, Edit] = {}
    for fit in fits:
        for edit in fit.edits:
            total[edit.segment] = total[edit.segment].then(edit) if edit.segment in total else edit
    edits = []
    for edit in total.values():
        if len(edit.residues):
            fixed = regularized(model, edit)
            step = Edit(edit.segment, edit.new_points, edit.new_points, fixed.residues, fixed.rows,
                        model.coords[fixed.rows], fixed.new_coords)  # from the fitted state
            model.apply(step)
            edits.append(step)
    return edits
