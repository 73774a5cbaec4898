"""Structural alignment of two chains: residues paired by where their Cα lie in space.

A sequence alignment pairs the wrong residues of distant homologues (below about 30%
identity, e.g. *S. griseus* proteinase B and trypsin), and those of unrelated folds
arbitrarily. :func:`align_folds` runs TM-align's search (Zhang & Skolnick 2005; compiled
kernels in :mod:`core.analysis.tm_align`): its initial alignments (gapless threading,
secondary-structure states, local superpositions of fragments, states plus the best
superposition so far, threading of the longest fragments, and a given pairing, the sequence
alignment say), each refined by rounds of dynamic programming on the TM-score terms of the
superposed chains and TM-score's search for the superposition of the pairs, and keeps the
alignment of highest TM-score. As in TM-align the search takes the shorter chain's d0 plus
0.8 Å and counts only the pairs within :func:`tm_d8` of it; the final TM-score is that of
chain a's d0 over the pairs within :func:`tm_d8` after the search's superposition.
Against TM-align (tmtools) on pairs of the shared set: ``python benchmarks/bench_fold_alignment.py FOLDER``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core import _validate
from core.analysis import tm_align
from core.analysis.superpose import MIN_PAIRS, Superposition

PAIR_CUTOFF = 5.0
"""Å: pairs farther apart after the final superposition are not structurally equivalent
(:func:`align_structures`)."""
STATE_GAP = 1.0
"""Score lost per gap when secondary-structure states are paired (TM-align's)."""


def tm_d0(length: int) -> float:
    """TM-score's distance scale (Å) for ``length`` residues, at least 0.5 Å as in TM-align."""
    return max(1.24 * float(np.cbrt(length - 15)) - 1.8, 0.5)


def tm_d8(length: int) -> float:
    """TM-align's cutoff (Å) of the aligned pairs, ``1.5 L^0.3 + 3.5``, for ``length``
    residues (the shorter chain's): pairs farther apart after the superposition are not aligned."""
    return 1.5 * float(length) ** 0.3 + 3.5


@dataclass(frozen=True, eq=False)
class FoldAlignment:
    """Result of :func:`align_folds`.

    Attributes
    ----------
    pairs_a, pairs_b : (k,) increasing int64 indices into each chain: the aligned pairs.
    motion : the superposition of chain b on chain a that maximises their TM-score.
    tm_score : TM-score of the aligned pairs after ``motion``, normalised by chain a's length.
    """

    pairs_a: np.ndarray
    pairs_b: np.ndarray
    motion: Superposition
    tm_score: float

    def within(self, ca_a: np.ndarray, ca_b: np.ndarray, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
        """The aligned pairs closer than ``cutoff`` (Å) after ``motion`` (indices into each chain)."""
        a, b = self.pairs_a, self.pairs_b
        close = np.linalg.norm(np.asarray(ca_a)[a] - self.motion.apply(np.asarray(ca_b)[b]), axis=1) < cutoff
        return a[close], b[close]


def tm_superpose(fixed: np.ndarray, moving: np.ndarray, length: int, step: int = 1) -> tuple[Superposition, float]:
    """The superposition of paired points that maximises their TM-score (TM-score's search,
    :func:`core.analysis.tm_align.tm_search`).

    Fits start from fragments of the pairs (all of them, halves, quarters, … down to 4
    pairs, ``step`` pairs apart) and are refitted on the pairs they bring within
    ``d0 + 1`` (d0 at least 4.5 Å, at most 8 Å) until that set settles; the best is kept.

    Parameters
    ----------
    fixed, moving : (n, 3) paired points, n >= 3, finite, Å.
    length : residues the TM-score is normalised by (its ``d0`` is :func:`tm_d0` of it).

    Returns
    -------
    (the superposition, whose rmsd is that of the pairs it was fitted on; the TM-score)
    """
    fixed, moving = np.asarray(fixed, dtype=np.float64), np.asarray(moving, dtype=np.float64)
    if fixed.shape != moving.shape or fixed.shape[1:] != (3,) or len(fixed) < MIN_PAIRS:
        raise ValueError(f"fixed and moving must have one shape (n >= {MIN_PAIRS}, 3); got {fixed.shape} and "
                         f"{moving.shape}")
    d0 = tm_d0(length)
    score, rotation, translation, used = tm_align.tm_search(
        np.ascontiguousarray(moving), np.ascontiguousarray(fixed), max(int(step), 1), d0, min(max(d0, 4.5), 8.0),
        np.inf, float(length))
    moved = moving @ rotation.T + translation
    rmsd = float(np.sqrt(np.mean(np.sum((fixed - moved)[used] ** 2, axis=1))))
    return Superposition(rotation, translation, rmsd), float(score)


def align_folds(
    ca_a: np.ndarray, ca_b: np.ndarray, pairs_a: np.ndarray | None = None, pairs_b: np.ndarray | None = None
) -> FoldAlignment:
    """The structural alignment of two chains' Cα of highest TM-score (normalised by chain a).

    Parameters
    ----------
    ca_a, ca_b : (n_a, 3) and (n_b, 3) Cα positions of the two chains, finite, Å; 3 or more each.
    pairs_a, pairs_b : (k,) increasing indices into each chain, k >= 3: one more start (e.g.
        a sequence alignment); None: none.
    """
    ca_a, ca_b = _validate.finite_array("ca_a", ca_a, ndim=(2,)), _validate.finite_array("ca_b", ca_b, ndim=(2,))
    if ca_a.shape[1:] != (3,) or ca_b.shape[1:] != (3,) or min(len(ca_a), len(ca_b)) < MIN_PAIRS:
        raise ValueError(f"ca_a and ca_b must be (n >= {MIN_PAIRS}, 3) each; got {ca_a.shape} and {ca_b.shape}")
    given = np.full(len(ca_b), -1, dtype=np.int64)
    if pairs_a is not None and pairs_b is not None:
        pairs_a, pairs_b = np.asarray(pairs_a, dtype=np.int64), np.asarray(pairs_b, dtype=np.int64)
        if len(pairs_a) != len(pairs_b) or len(pairs_a) < MIN_PAIRS:
            raise ValueError(f"the start needs at least {MIN_PAIRS} pairs of equal length; got {len(pairs_a)} "
                             f"and {len(pairs_b)}")
        given[pairs_b] = pairs_a
    invmap, _, rotation, translation = tm_align.align(np.ascontiguousarray(ca_a), np.ascontiguousarray(ca_b), given)
    pairs_b = np.flatnonzero(invmap >= 0)
    pairs_a = invmap[pairs_b]
    close = np.linalg.norm(ca_a[pairs_a] @ rotation.T + translation - ca_b[pairs_b], axis=1) <= tm_d8(
        min(len(ca_a), len(ca_b)))
    if close.sum() >= MIN_PAIRS:
        pairs_a, pairs_b = pairs_a[close], pairs_b[close]
    motion, score = tm_superpose(ca_a[pairs_a], ca_b[pairs_b], len(ca_a))
    return FoldAlignment(pairs_a, pairs_b, motion, score)


def refine_pairs(ca_a: np.ndarray, ca_b: np.ndarray, pairs_a: np.ndarray, pairs_b: np.ndarray, rounds: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """TM-align's refinement of one alignment of two chains' Cα (k >= 3 pairs, increasing
    indices into each): the superposition of its pairs, then ``rounds`` rounds of dynamic
    programming on the TM-score terms and the superposition again
    (:func:`core.analysis.tm_align.refine`), a small part of :func:`align_folds`' work.
    Returns the increasing pairs of the best alignment found."""
    given = np.full(len(ca_b), -1, dtype=np.int64)
    given[np.asarray(pairs_b, dtype=np.int64)] = np.asarray(pairs_a, dtype=np.int64)
    invmap, _ = tm_align.refine(np.ascontiguousarray(ca_a, dtype=np.float64),
                                np.ascontiguousarray(ca_b, dtype=np.float64), given, int(rounds))
    pairs_b = np.flatnonzero(invmap >= 0)
    return invmap[pairs_b], pairs_b


def align_structures(
    ca_a: np.ndarray, ca_b: np.ndarray, pairs_a: np.ndarray | None = None, pairs_b: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The structurally equivalent pairs of two chains' Cα: those of :func:`align_folds`
    (started also from ``pairs_a``, ``pairs_b`` where given) closer than :data:`PAIR_CUTOFF`
    after its superposition.

    Returns
    -------
    (indices into chain a, indices into chain b), both increasing int64 arrays.
    """
    return align_folds(ca_a, ca_b, pairs_a, pairs_b).within(ca_a, ca_b, PAIR_CUTOFF)


def monotone_pairs(score: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """TM-align's order-keeping pairing of rows with columns of ``score`` (n, m; >= 0): the
    highest sum of the paired scores by dynamic programming, less ``gap`` where a run of rows
    or columns left unpaired follows a pair (TM-align's gap opening without extension, as its
    recursion charges it: exact for ``gap`` 0). Rows and columns before the first pair and
    after the last are free.

    Returns increasing (row, column) index arrays.
    """
    score = np.ascontiguousarray(score, dtype=np.float64)
    invmap = np.empty(score.shape[1], dtype=np.int64)
    tm_align.pairing(score, -float(gap), invmap)
    columns = np.flatnonzero(invmap >= 0)
    return invmap[columns], columns
