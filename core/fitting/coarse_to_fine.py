"""Fit a model onto target Cα positions coarse to fine, with the wavelet levels as unknowns.

At level j the unknowns are the level-j control points of each fitted segment. A change
``ΔC^j`` reaches the finest control points as ``M_j ΔC^j`` with ``M_j = P^J ⋯ P^{j+1}``
(every finer detail kept, Carson eq. 5) and moves residue point ``C^r_i = Φ(u_i) C`` by
``Φ(u_i) M_j ΔC^j``; the residues follow as rigid bodies, turning with the curve around
them, exactly as when a control point is dragged (:meth:`~core.protein.model.EditableModel.plan`).

Against paired target Cα the step at a level is linear least squares: with each residue's
Cα held at its offset from its curve point (the residues' turn left out), find the
``ΔC^j`` that brings the paired Cα closest to the target, then remap exactly and superpose
the target again. A few such Gauss–Newton steps settle a level; the next level starts from
there. A little Tikhonov damping keeps control points that few paired residues see (or
none) where they are.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import sparse

from core.analysis.superpose import superpose
from core.curves.filters import level_filters
from core.curves.splines import spline_space
from core.protein.model import Edit, EditableModel, per_segment
from core.protein.ribbon import Ribbon

STEPS_PER_LEVEL = 4
"""Most Gauss–Newton steps at one level."""
SETTLED = 0.005
"""A level is settled when a step improves the rmsd by less than this fraction."""
DAMPING = 0.01
"""Tikhonov damping of a step, relative to the size of its design matrix."""
UNPAIRED_HOLD = 1.0
"""Weight, against 1 for a paired residue, of keeping each residue without a partner in the
target where it is in a step. Without it the control points that carry a homologue's
unpaired tail swung with the paired residues next to it: trypsin's (3PTB) first twelve
residues moved up to 118 Å, their Cα 14 Å apart, in levels 0-5 onto 3SGB."""


@dataclass(frozen=True)
class Pairs:
    """Residues of one segment of the model and the target Cα they are paired with.

    Attributes
    ----------
    segment : index of the segment in the model.
    residues : (k,) indices of residues within the segment.
    target : (k, 3) Cα of the paired target residues, Å (in the target's own frame).
    """

    segment: int
    residues: np.ndarray
    target: np.ndarray


@dataclass(frozen=True, eq=False)
class LevelFit:
    """The result of fitting at one level.

    Attributes
    ----------
    level : the integer level fitted.
    control_points : unknown control points at that level, over all fitted segments.
    score : after the level, the Cα rmsd of the paired residues to the superposed target
        (Å), or for a map the correlation of the model's density with it as the level saw
        the map (see ``resolution``).
    seconds : time the level took.
    edits : one edit per fitted segment (already applied to the model), from the state
        before this level to the state after it.
    resolution : for a map, the resolution the level saw it at (Å); None for a structure.
    motion : for the rigid-domain stage before the levels (``level`` -1,
        :data:`core.fitting.domains.DOMAINS`), what moved, for people; None where nothing did.
    """

    level: int
    control_points: int
    score: float
    seconds: float
    edits: tuple[Edit, ...]
    resolution: float | None = None
    motion: str | None = None

    @property
    def name(self) -> str:
        """``'level 3'``, or ``'domains'`` for the rigid-domain stage (level -1)."""
        return "domains" if self.level < 0 else f"level {self.level}"


@lru_cache(maxsize=64)
def pushed_to_finest(level: int, finest: int) -> sparse.csr_array:
    """``M = P^finest ⋯ P^(level+1)``: level-``level`` control-point changes to the finest level."""
    matrix = sparse.identity(spline_space(level).n_points, format="csr")
    for j in range(level + 1, finest + 1):
        matrix = sparse.csr_array(level_filters(j).P @ matrix)
    return matrix


def fit_levels(
    model: EditableModel,
    pairs: Sequence[Pairs],
    levels: Sequence[int],
    ca_rows: np.ndarray,
    *,
    cancelled: Callable[[], bool] = lambda: False,
) -> Iterator[LevelFit]:
    """Fit ``model``'s paired Cα onto the target at each of ``levels`` in turn (coarse first),
    applying each level's edits to ``model`` and yielding them.

    Parameters
    ----------
    model : the model; its coordinates and ribbons change.
    pairs : the paired residues of each fitted segment.
    levels : integer levels, each at most the segment's finest (higher ones are clipped).
    ca_rows : (n_residues,) row of the Cα of every residue of the structure.
    cancelled : asked between steps; the fit stops after the step under way when it says so.
    """
    if not pairs or sum(len(p.residues) for p in pairs) < 3:
        raise ValueError("the fit needs at least 3 paired residues")
    rows = np.concatenate([ca_rows[model.segments[p.segment].residue_index[p.residues]] for p in pairs])
    target = np.concatenate([p.target for p in pairs])
    for level in levels:
        if cancelled():
            return
        start = time.perf_counter()
        steps: list[Edit] = []
        fit = superpose(model.coords[rows], target)
        n_points = 0
        for _ in range(STEPS_PER_LEVEL):
            placed = fit.apply(target)
            offset = 0
            for p in pairs:
                k = len(p.residues)
                edit = _step(model, p, level, placed[offset:offset + k], model.coords[rows[offset:offset + k]])
                offset += k
                model.apply(edit)
                steps.append(edit)
            new = superpose(model.coords[rows], target)
            settled = new.rmsd > (1.0 - SETTLED) * fit.rmsd
            fit = new
            if settled or cancelled():
                break
        for p in pairs:
            n_points += spline_space(min(level, model.ribbons[p.segment].level)).n_points
        yield LevelFit(level, n_points, fit.rmsd, time.perf_counter() - start, tuple(per_segment(steps)))


def _step(model: EditableModel, pairs: Pairs, level: int, target: np.ndarray, ca: np.ndarray) -> Edit:
    """One Gauss–Newton step at ``level`` for one segment: the planned edit (not applied)."""
    ribbon = model.ribbons[pairs.segment]
    level = min(level, ribbon.level)
    push = pushed_to_finest(level, ribbon.level)
    unpaired = np.setdiff1d(np.arange(len(ribbon.residue_u)), pairs.residues)
    change = damped_change(ribbon, pairs.residues, push, target - ca, unpaired)
    return model.plan(pairs.segment, ribbon.points + push @ change)


def damped_change(ribbon: Ribbon, residues: np.ndarray, push: sparse.csr_array, wanted: np.ndarray,
                  held: np.ndarray | None = None) -> np.ndarray:
    """The change of a level's control points (pushed to the finest by ``push``) that moves
    the curve points of ``residues`` closest to ``wanted`` (k, 3) and those of ``held`` little
    (:data:`UNPAIRED_HOLD`), damped a little."""
    design = (ribbon.space.design_matrix(ribbon.residue_u[residues]) @ push).toarray()
    damping = DAMPING * np.sqrt(np.mean(design**2) * len(design))  # keeps points that few residues see in place
    rows = [design, damping * np.eye(design.shape[1])]
    if held is not None and len(held):
        rows.append(UNPAIRED_HOLD * (ribbon.space.design_matrix(ribbon.residue_u[held]) @ push).toarray())
    system = np.vstack(rows)
    change, *_ = np.linalg.lstsq(system, np.vstack([wanted, np.zeros((len(system) - len(wanted), 3))]), rcond=None)
    return change
