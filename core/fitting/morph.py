"""A morph from one conformation to another, level by level: the coarse motion first.

The fit of A onto B (:func:`core.fitting.conformation.fit_conformation`) moves A's control
points level by level. The frames of the morph pass along that path: within each level
the control points go linearly from where the level started to where it ended, and each
frame is A remapped onto those control points (residues as rigid bodies along the curve
frames) and regularized, so every frame has ideal peptide junctions and no new clashes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from core.fitting.coarse_to_fine import LevelFit
from core.fitting.settle import FIT_ITERATIONS
from core.geometry.regularize import regularized
from core.protein.model import EditableModel


def frame_counts(fits: Sequence[LevelFit], frames: int) -> list[int]:
    """Frames given to each level: in proportion to how far its control points moved, at
    least one for a level that moved anything, ``frames`` in all (or one per moving level)."""
    moves = np.array([sum(float(np.linalg.norm(e.new_points - e.old_points)) for e in fit.edits) for fit in fits])
    moving = moves > 1e-9
    counts = np.where(moving, 1, 0)
    spare = frames - int(counts.sum())
    if spare > 0 and moving.any():
        share = moves / moves.sum() * spare
        counts += np.floor(share).astype(int)
        left = frames - int(counts.sum())
        counts[np.argsort(np.floor(share) - share)[:left]] += 1  # the largest remainders
    return counts.tolist()


def morph_frames(
    start: EditableModel,
    fits: Sequence[LevelFit],
    frames: int,
    *,
    regularize: bool = True,
    cancelled: Callable[[], bool] = lambda: False,
    done: Callable[[], object] = lambda: None,
) -> list[np.ndarray]:
    """Coordinates of every frame from ``start`` (its state before ``fits``, unchanged here)
    along the levels of ``fits``: the first frame is ``start`` itself. ``done`` is called as
    each frame after it is made (a progress bar)."""
    result = [start.coords.copy()]
    for fit, count in zip(fits, frame_counts(fits, frames)):
        for k in range(1, count + 1):
            if cancelled():
                return result
            coords = start.coords.copy()
            for edit in fit.edits:
                now = edit.old_points + (edit.new_points - edit.old_points) * (k / count)
                planned = start.plan(edit.segment, now)
                if regularize and len(planned.residues):
                    planned = regularized(start, planned, max_iterations=FIT_ITERATIONS)
                coords[planned.rows] = planned.new_coords
            result.append(coords)
            done()
    return result
