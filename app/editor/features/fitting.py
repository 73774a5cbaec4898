"""Edit ▸ Fit to Map and Fit to Compared Structure: the edited chain (every segment of it)
moved onto a target at the level shown or coarse to fine (:mod:`core.fitting`), as
``ribbonwave fit`` moves it, each level one undo step.

The fit runs on the GUI thread, level by level. Between its steps it lets the event loop
run, so the window repaints and the progress dialog's Cancel is heard, while that dialog,
window-modal, keeps other edits away. Each level's edits (one per segment) become one undo
step as soon as the level is done, so the view follows the fit. After coarse to fine the
fit settles as on the command line (:func:`core.fitting.settle.settle`): the residues that
moved are regularized as after a drag, one more step, and where that leaves more bad
peptide junctions than the file had, the finest level's step is undone and the rest
regularized again. A map fit is then refined (:func:`core.fitting.density.refine`: every
residue moved into the map on its own, its side chains turning), one more step. The progress
dialog covers every stage. Cancel never leaves broken geometry: during the levels, whose
steps are not yet regularized, it undoes the whole fit; during the regularization it keeps
the pass done, regularized; during the refinement, the residues refined so far, regularized.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication, QProgressDialog, QWidget

from app.editor.document import Document
from app.editor.scene.overlay import Compared, chain_segments
from core.fitting.coarse_to_fine import LevelFit, fit_levels
from core.fitting.conformation import SAME_FOLD, fold_similarity, pair_segments
from core.fitting.density import fit_map_levels, refine, resolved_levels
from core.fitting.domains import DOMAINS
from core.fitting.map_target import MapTarget, heavy_atoms
from core.fitting.settle import settle
from core.protein.model import Edit
from core.surfaces.volume import DensityMap

Fits = Callable[[Sequence[int], Callable[[], bool]], Iterator[LevelFit]]
"""Fits the edited chain at the given levels, asking the callable whether to stop."""
Refines = Callable[[Callable[[], bool]], list[Edit]]
"""Refines a settled fit: the edits, applied."""


@dataclass(frozen=True)
class FitTarget:
    """What the edited chain is fitted to, and how to say how well it fits."""

    name: str
    """As the undo steps name it: ``'map'``, ``'4AKE A'``."""
    fits: Fits
    score: Callable[[LevelFit], str]
    """A level's score for people: ``'CC 0.953 at 13 Å'`` (the map as that level sees it), ``'Cα rmsd 1.21 Å'``."""
    refine: Refines | None = None
    """For a map: every residue moved into it on its own, its side chains turning."""
    domains: bool = False
    """For a map: coarse to fine, the chain's smaller dynamic domain is first moved as a rigid
    body (:mod:`core.fitting.domains`), a stage of its own."""
    resolved: Callable[[list[int]], list[int]] = list
    """The levels asked for that the target can hold (a map: not those finer than it resolves,
    :func:`core.fitting.density.resolved_levels`)."""


def edited_chain(document: Document) -> list[int]:
    """The segments of the edited segment's chain, in order: those a fit moves."""
    segments = document.structure.segments
    chain = segments[document.segment].chain
    return [k for k, segment in enumerate(segments) if segment.chain == chain]


def map_target(document: Document, density: DensityMap, resolution: float) -> FitTarget:
    """The map as target, the model's density blurred to ``resolution`` Å (raises
    :class:`core.surfaces.volume.MapError` where the map does not overlap the model)."""
    model, segments = document.model, edited_chain(document)
    target = MapTarget(density, resolution, model.coords[heavy_atoms(model)])
    return FitTarget("map", lambda levels, cancelled: fit_map_levels(model, segments, target, levels,
                                                                       cancelled=cancelled),
                     lambda fit: f"CC {fit.score:.3f} at {fit.resolution:.3g} Å",
                     lambda cancelled: refine(model, segments, target, cancelled=cancelled), domains=True,
                     resolved=lambda levels: resolved_levels(model, segments, levels, resolution))


def compared_target(document: Document, compared: Compared) -> FitTarget:
    """A compared structure's chain as target, its residues paired as Compare pairs them
    (raises ValueError for too few pairs or another fold)."""
    model = document.model
    pairs, used = pair_segments(model, edited_chain(document), chain_segments(compared.structure, compared.chain))
    count = sum(len(p.residues) for p in pairs)
    if count < 3:
        raise ValueError(f"only {count} residue pair(s) between the edited chain and {compared.name}: nothing to fit")
    similarity = fold_similarity(model, pairs)
    if similarity < SAME_FOLD:
        raise ValueError(f"{compared.name} is another fold (TM-score {similarity:.2f} < {SAME_FOLD} over {count} "
                         f"{used}-paired residues): nothing to fit onto")
    return FitTarget(compared.name.strip(), lambda levels, cancelled: fit_levels(model, pairs, levels, document.ca_rows,
                                                                         cancelled=cancelled),
                     lambda fit: f"Cα rmsd {fit.score:.2f} Å")


def levels_to_fit(document: Document, target: FitTarget, coarse_to_fine: bool) -> list[int]:
    """The integer level at or below the one shown, or every level from 0 up to it (after
    the domains, :data:`~core.fitting.domains.DOMAINS`, where ``target`` moves them first),
    less those ``target`` cannot hold (:attr:`FitTarget.resolved`)."""
    level = math.floor(document.shown_level())
    if not coarse_to_fine:
        return [level]
    return target.resolved([DOMAINS] * target.domains + list(range(level + 1)))


def _stage(level: int) -> str:
    """A stage of a fit for people: ``'level 3'``, ``'the domains'``."""
    return "the domains" if level == DOMAINS else f"level {level}"


def run_fit(document: Document, target: FitTarget, levels: Sequence[int], parent: QWidget) -> list[LevelFit]:
    """Fit the edited chain to ``target`` at ``levels`` in turn (coarse first), each level
    one undo step; after more than one level (not cancelled), settle and refine as the
    module says, a step each. Shows a window-modal progress dialog with Cancel. Returns the
    levels kept."""
    settles = len(levels) > 1
    stages = len(levels) + (1 + (target.refine is not None) if settles else 0)
    progress = QProgressDialog(f"Fitting {_stage(levels[0])} to the {target.name}…", "Cancel", 0, stages, parent)
    progress.setWindowTitle(f"Fit to {target.name}")
    progress.setWindowModality(Qt.WindowModality.WindowModal)
    progress.setMinimumDuration(0)
    progress.setValue(0)

    def cancelled() -> bool:
        QApplication.processEvents()
        return progress.wasCanceled()

    def undo(fit: LevelFit) -> None:  # a level the regularization cannot keep
        if fit.edits:
            document.undo_stack.undo()

    kept: list[LevelFit] = []
    before = document.undo_stack.index()
    try:
        for fit in target.fits(levels, cancelled):
            if progress.wasCanceled():  # cut short: undone
                for edit in reversed(fit.edits):
                    document.model.revert(edit)
                break
            if fit.edits:
                moved = f"; {fit.motion}" if fit.motion else ""
                where = ": the domains" if fit.level == DOMAINS else f" at level {fit.level}"
                document.push_applied(fit.edits, f"Fit to {target.name}{where} ({target.score(fit)}{moved})")
            kept.append(fit)
            progress.setValue(len(kept))
            if len(kept) < len(levels):
                progress.setLabelText(f"{_stage(fit.level).capitalize()}: {target.score(fit)}. Fitting "
                                      f"{_stage(levels[len(kept)])}…")
        if progress.wasCanceled():  # the levels kept are not regularized: the fit is undone
            document.undo_stack.setIndex(before)
            return []
        if settles and kept:
            kept = _settle(document, target, kept, progress, cancelled, undo)
    finally:
        progress.close()
        progress.deleteLater()
    return kept


def _settle(document: Document, target: FitTarget, fits: list[LevelFit], progress: QProgressDialog,
            cancelled: Callable[[], bool], undo: Callable[[LevelFit], None]) -> list[LevelFit]:
    """Regularize (dropping the finest levels that leave bad junctions) and refine, a step each."""
    progress.setLabelText("Regularizing…")
    QApplication.processEvents()
    result = settle(document.model, fits, cancelled=cancelled, undo=undo)
    undone = f" (level {', '.join(map(str, result.dropped))} undone: bad junctions, Ramachandran outliers)" if result.dropped else ""
    if result.regularization:
        document.push_applied(result.regularization, f"Regularize the fit to {target.name}{undone}")
    progress.setValue(progress.value() + 1)
    if target.refine is not None and result.levels and not progress.wasCanceled():
        progress.setLabelText(f"Refining each residue into the {target.name} (Cancel keeps the residues refined so "
                              "far, regularized)…")
        QApplication.processEvents()
        refined = target.refine(cancelled)  # (regularized, also when cancelled)
        if refined:
            document.push_applied(refined, f"Refine the fit to {target.name} (each residue, side chains)")
        progress.setValue(progress.value() + 1)
    return result.levels
