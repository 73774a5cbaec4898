"""Fit a model onto another conformation (or a close homologue): pair the residues as
``compare`` does, fit level by level (:mod:`core.fitting.coarse_to_fine`), then regularize as
after a drag, keeping the finest level whose regularized model has no new bad junctions."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from core.analysis.compare import pair_residues
from core.analysis.fold_alignment import tm_superpose
from core.fitting.coarse_to_fine import Pairs, fit_levels
from core.fitting.settle import FitResult, settle
from core.protein.model import EditableModel
from core.protein.structure import BackboneSegment, ca_rows


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


def fit_conformation(
    model: EditableModel,
    pairs: Sequence[Pairs],
    levels: Sequence[int],
    *,
    regularize: bool = True,
    cancelled: Callable[[], bool] = lambda: False,
) -> FitResult:
    """Fit ``model`` onto the paired target Cα at ``levels`` (coarse first), then
    :func:`~core.fitting.settle.settle` it; every edit kept is applied to ``model``."""
    fits = list(fit_levels(model, pairs, levels, ca_rows(model.structure), cancelled=cancelled))
    return settle(model, fits, regularize=regularize, cancelled=cancelled)
