"""Structural alignment of two chains: residues paired by where their Cα lie in space.

A sequence alignment pairs the wrong residues of distant homologues (below about 30%
identity, e.g. *S. griseus* proteinase B and trypsin). :func:`align_structures` starts
from a given pairing and alternates, as TM-align does (Zhang & Skolnick 2005), a
superposition that favours the closest pairs with a pairing of the superposed chains by
dynamic programming over the TM-score terms ``1 / (1 + (d / d0)²)`` of every residue pair,
keeping the pairing of highest TM-score. Pairs left farther apart than
:data:`PAIR_CUTOFF` are not structurally equivalent and are dropped.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.distance import cdist

from core.analysis.superpose import MIN_PAIRS, Superposition, fit_closest

GAP = 0.6
"""TM-score terms lost per residue left unpaired inside the alignment (TM-align's gap
opening; the ends are free)."""
PAIR_CUTOFF = 5.0
"""Å: pairs farther apart after the final superposition are not kept."""
ROUNDS = 10
"""Superposition and pairing rounds at most (they usually settle in 2–4)."""


def tm_d0(length: int) -> float:
    """TM-score's distance scale (Å) for ``length`` residues, at least 0.5 Å as in TM-align."""
    return max(1.24 * float(np.cbrt(length - 15)) - 1.8, 0.5)


def align_structures(
    ca_a: np.ndarray, ca_b: np.ndarray, pairs_a: np.ndarray, pairs_b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The structural pairing of two chains' Cα, refined from the pairing ``pairs_a``, ``pairs_b``.

    Parameters
    ----------
    ca_a, ca_b : (n_a, 3) and (n_b, 3) Cα positions of the two chains, Å.
    pairs_a, pairs_b : (k,) increasing indices into each chain, k >= 3: the start (e.g. a
        sequence alignment).

    Returns
    -------
    (indices into chain a, indices into chain b), both increasing int64 arrays: the pairs
    of highest TM-score (normalised by chain a) closer than PAIR_CUTOFF after their fit.
    """
    ca_a, ca_b = np.asarray(ca_a, dtype=np.float64), np.asarray(ca_b, dtype=np.float64)
    pairs = np.asarray(pairs_a, dtype=np.int64), np.asarray(pairs_b, dtype=np.int64)
    if len(pairs[0]) != len(pairs[1]) or len(pairs[0]) < MIN_PAIRS:
        raise ValueError(f"the start needs at least {MIN_PAIRS} pairs of equal length; got {len(pairs[0])} and "
                         f"{len(pairs[1])}")
    d0 = tm_d0(len(ca_a))
    best, best_score = pairs, -np.inf
    for _ in range(ROUNDS):
        motion = _tm_fit(ca_a[pairs[0]], ca_b[pairs[1]], d0)
        score = 1.0 / (1.0 + (cdist(ca_a, motion.apply(ca_b)) / d0) ** 2)
        pairs_score = score[pairs].sum()  # the TM-score of these pairs, times len(ca_a)
        if pairs_score > best_score:
            best, best_score = pairs, pairs_score
        found = monotone_pairs(score, GAP)
        if len(found[0]) < MIN_PAIRS or all(np.array_equal(p, q) for p, q in zip(found, pairs)):
            break
        pairs = found
    motion = _tm_fit(ca_a[best[0]], ca_b[best[1]], d0)
    close = np.linalg.norm(ca_a[best[0]] - motion.apply(ca_b[best[1]]), axis=1) < PAIR_CUTOFF
    return best[0][close], best[1][close]


def _tm_fit(fixed: np.ndarray, moving: np.ndarray, d0: float) -> Superposition:
    """A superposition of paired points that favours the closest pairs (towards the
    TM-score optimum): refined on the pairs within 2 d0, then on those within d0."""
    motion, _ = fit_closest(fixed, moving, 2.0 * d0)
    return fit_closest(fixed, moving, d0, start=motion)[0]


def monotone_pairs(score: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The order-keeping pairing of rows with columns of ``score`` (n, m; positive) that
    maximises the sum of the paired scores less ``gap`` per row or column left unpaired
    between two pairs: rows and columns before the first pair and after the last are free
    (Smith–Waterman, one numpy pass per row).

    Returns increasing (row, column) index arrays.
    """
    n, m = score.shape
    ramp = gap * np.arange(m + 1)
    total = np.zeros((n + 1, m + 1))  # best alignment ending in rows < i and columns < j
    paired = np.zeros((n, m), dtype=bool)  # the cell is reached by pairing row i with column j,
    fresh = np.zeros((n, m), dtype=bool)  # as the first pair,
    across = np.zeros((n, m), dtype=bool)  # or by leaving column j unpaired (else row i)
    for i in range(n):
        fresh[i] = total[i, :-1] <= 0.0
        pair = np.maximum(total[i, :-1], 0.0) + score[i]
        skip_row = total[i, 1:] - gap
        reached = np.concatenate([[0.0], np.maximum(pair, skip_row)]) + ramp
        best = np.maximum.accumulate(reached)  # or skip columns, gap each
        total[i + 1] = best - ramp
        paired[i] = pair >= skip_row
        across[i] = best[1:] > reached[1:]
    i, j = np.unravel_index(np.argmax(total), total.shape)  # the best last pair
    paired_list, fresh_list, across_list = paired.tolist(), fresh.tolist(), across.tolist()
    rows, columns = [], []
    while i > 0 and j > 0:
        if across_list[i - 1][j - 1]:
            j -= 1
        elif paired_list[i - 1][j - 1]:
            rows.append(i - 1)
            columns.append(j - 1)
            if fresh_list[i - 1][j - 1]:
                break
            i, j = i - 1, j - 1
        else:
            i -= 1
    return np.array(rows[::-1], dtype=np.int64), np.array(columns[::-1], dtype=np.int64)
