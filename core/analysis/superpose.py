"""Least-squares superposition and sequence alignment, on plain arrays (a gemmi adapter).

gemmi does the work (``gemmi.superpose_positions``, ``gemmi.align_string_sequences``);
only numpy arrays, strings and the small :class:`Superposition` leave this module (the
structural alignment's own fits, thousands a pair, are compiled: :func:`core.analysis.tm_align.kabsch`).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import gemmi
import numpy as np

from core import _validate

MIN_PAIRS = 3
"""Fewest point pairs a superposition is computed from."""


@dataclass(frozen=True)
class Superposition:
    """A rigid motion ``x -> rotation @ x + translation`` and the rmsd of the fitted points (Å)."""

    rotation: np.ndarray
    translation: np.ndarray
    rmsd: float

    def apply(self, points: np.ndarray) -> np.ndarray:
        """The moved points, (n, 3) -> (n, 3), Å."""
        return np.asarray(points, dtype=np.float64) @ self.rotation.T + self.translation


def superpose(fixed: np.ndarray, moving: np.ndarray) -> Superposition:
    """The rigid motion that best fits ``moving`` onto ``fixed`` in the least-squares sense.

    Parameters
    ----------
    fixed, moving : (n, 3) paired points, n >= 3, Å.
    """
    fixed = _validate.finite_array("fixed", fixed, ndim=(2,))
    moving = _validate.finite_array("moving", moving, ndim=(2,))
    if fixed.shape != moving.shape or fixed.shape[1:] != (3,) or len(fixed) < MIN_PAIRS:
        raise ValueError(f"fixed and moving must have one shape (n >= {MIN_PAIRS}, 3); got {fixed.shape} and {moving.shape}")
    result = gemmi.superpose_positions(_positions(fixed), _positions(moving))
    rotation = np.array(result.transform.mat.tolist())
    translation = np.array(result.transform.vec.tolist())
    return Superposition(rotation, translation, float(result.rmsd))


def fit_closest(
    fixed: np.ndarray, moving: np.ndarray, cutoff: float, start: Superposition | None = None, rounds: int = 20
) -> tuple[Superposition, np.ndarray]:
    """A superposition refined on the pairs it brings closer than ``cutoff`` (Å).

    From ``start`` (default: the fit on all pairs), fit again on the pairs closer than
    ``cutoff`` until that set settles (at most ``rounds`` times), stopping before a set of
    fewer than 3 pairs. Returns the last fit and the (n,) bool set it was fitted on (all
    pairs for the fit on all).
    """
    motion = superpose(fixed, moving) if start is None else start
    used = np.ones(len(fixed), dtype=bool)
    for _ in range(rounds):
        close = np.linalg.norm(fixed - motion.apply(moving), axis=1) < cutoff
        if close.sum() < MIN_PAIRS or np.array_equal(close, used):
            break
        motion, used = superpose(fixed[close], moving[close]), close
    return motion, used


def align_sequences(names_a: Sequence[str], names_b: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Residues paired by a global alignment of two sequences of residue names.

    The alignment is gemmi's Needleman–Wunsch with BLOSUM62 scores (gap opening −10,
    extension −1); aligned positions are paired whether or not the names agree.

    Returns
    -------
    (k,) and (k,) int64: indices into ``names_a`` and ``names_b``, increasing.
    """
    result = gemmi.align_string_sequences(list(names_a), list(names_b), [], gemmi.AlignmentScoring("b"))
    a, b, pairs_a, pairs_b = 0, 0, [], []
    for count, op in re.findall(r"(\d+)([MID])", result.cigar_str()):
        count = int(count)
        if op == "M":
            pairs_a.extend(range(a, a + count))
            pairs_b.extend(range(b, b + count))
        a += count if op in "MI" else 0
        b += count if op in "MD" else 0
    return np.array(pairs_a, dtype=np.int64), np.array(pairs_b, dtype=np.int64)


def _positions(points: np.ndarray) -> list[gemmi.Position]:
    return [gemmi.Position(*p) for p in points.tolist()]
