"""Edit ▸ Fit to Map and Fit to Compared Structure: the edited segment moved onto a target at
the level shown or coarse to fine (:mod:`core.fitting`), each level one undo step.

The fit runs on the GUI thread, level by level. Between its steps it lets the event loop
run, so the window repaints and the progress dialog's Cancel is heard, while that dialog,
window-modal, keeps other edits away. Each level's edit becomes an undo step as soon as the
level is done, so the view follows the fit; after coarse to fine the residues that moved are
regularized as after a drag (:func:`core.fitting.conformation.regularize_fit`), one more
step. Cancel undoes the level under way and keeps the levels done.
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
from core.fitting.density import MapTarget, fit_map_levels, heavy_atoms
from core.fitting.settle import regularize_fit
from core.surfaces.volume import DensityMap

Fits = Callable[[Sequence[int], Callable[[], bool]], Iterator[LevelFit]]
"""Fits the edited segment at the given levels, asking the callable whether to stop."""


@dataclass(frozen=True)
class FitTarget:
    """What the edited segment is fitted to, and how to say how well it fits."""

    name: str
    """As the undo steps name it: ``'map'``, ``'4AKE A'``."""
    fits: Fits
    score: Callable[[float], str]
    """A level's score for people: ``'CC 0.953'``, ``'Cα rmsd 1.21 Å'``."""


def map_target(document: Document, density: DensityMap, resolution: float) -> FitTarget:
    """The map as target, the model's density blurred to ``resolution`` Å (raises
    :class:`core.surfaces.volume.MapError` where the map does not overlap the model)."""
    model, segment = document.model, document.segment
    target = MapTarget(density, resolution, model.coords[heavy_atoms(model)])
    return FitTarget("map", lambda levels, cancelled: fit_map_levels(model, [segment], target, levels,
                                                                       cancelled=cancelled),
                     lambda cc: f"CC {cc:.3f}")


def compared_target(document: Document, compared: Compared) -> FitTarget:
    """A compared structure's chain as target, its residues paired as Compare pairs them
    (raises ValueError for too few pairs or another fold)."""
    model = document.model
    pairs, used = pair_segments(model, [document.segment], chain_segments(compared.structure, compared.chain))
    count = sum(len(p.residues) for p in pairs)
    if count < 3:
        raise ValueError(f"only {count} residue pair(s) between the edited segment and {compared.name}: nothing to fit")
    similarity = fold_similarity(model, pairs)
    if similarity < SAME_FOLD:
        raise ValueError(f"{compared.name} is another fold (TM-score {similarity:.2f} < {SAME_FOLD} over {count} "
                         f"{used}-paired residues): nothing to fit onto")
    return FitTarget(compared.name.strip(), lambda levels, cancelled: fit_levels(model, pairs, levels, document.ca_rows,
                                                                         cancelled=cancelled),
                     lambda rmsd: f"Cα rmsd {rmsd:.2f} Å")


def levels_to_fit(document: Document, coarse_to_fine: bool) -> list[int]:
    """The integer level at or below the one shown, or every level from 0 up to it."""
    level = math.floor(document.shown_level())
    return list(range(level + 1)) if coarse_to_fine else [level]


def run_fit(document: Document, target: FitTarget, levels: Sequence[int], parent: QWidget) -> list[LevelFit]:
    """Fit the edited segment to ``target`` at ``levels`` in turn (coarse first), each level
    one undo step; after more than one level (not cancelled), regularize as one more step.
    Shows a window-modal progress dialog with Cancel. Returns the levels kept."""
    progress = QProgressDialog(f"Fitting to the {target.name} at level {levels[0]}…", "Cancel", 0, len(levels),
                               parent)
    progress.setWindowTitle(f"Fit to {target.name}")
    progress.setWindowModality(Qt.WindowModality.WindowModal)
    progress.setMinimumDuration(0)
    progress.setValue(0)

    def cancelled() -> bool:
        QApplication.processEvents()
        return progress.wasCanceled()

    kept: list[LevelFit] = []
    try:
        for fit in target.fits(levels, cancelled):
            if progress.wasCanceled():  # cut short: undone
                for edit in reversed(fit.edits):
                    document.model.revert(edit)
                break
            for edit in fit.edits:
                document.push_applied(edit, f"Fit to {target.name} at level {fit.level} ({target.score(fit.score)})")
            kept.append(fit)
            progress.setValue(len(kept))
            if len(kept) < len(levels):
                progress.setLabelText(f"Level {fit.level}: {target.score(fit.score)}. Fitting at level "
                                      f"{levels[len(kept)]}…")
        if len(levels) > 1 and kept and not progress.wasCanceled():
            progress.setLabelText("Regularizing…")
            QApplication.processEvents()
            for edit in regularize_fit(document.model, kept):
                document.push_applied(edit, f"Regularize the fit to {target.name}")
    finally:
        progress.close()
        progress.deleteLater()
    return kept
