"""Smith–Waterman local alignment scores of one query against many chains, in numba.

The query is a profile: the score of each of its residues against each residue code of the
chains (a code names a residue's 3Di state and amino acid together,
:func:`core.analysis.fold_search.residue_codes`). Gaps cost Gotoh's affine penalties. Only the
best score of each chain is kept (linear memory).

:func:`local_scores` aligns :data:`LANES` chains of similar length at once, side by side (as
SWIPE does, Rognes 2011): each cell of the query's column updates every lane, so the lanes'
updates are independent of each other and keep the CPU's pipelines full, about 3 times the
cells a second of one chain at a time. Each lane does the same arithmetic as one chain alone,
so the scores are the same whatever the lanes, threads or order.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

LANES = 32
"""Chains :func:`local_scores` aligns side by side."""
_PAD = np.float32(-1e4)
"""Score of any query residue against the code that pads a shorter chain to its lanes' length:
low enough that no alignment reaches past its chain's end."""


@njit(cache=True, parallel=True)
def local_scores(profile: np.ndarray, codes: np.ndarray, starts: np.ndarray, lengths: np.ndarray,
                 gap_open: float, gap_extend: float) -> np.ndarray:
    """(k,) float32: the best local alignment score of the query against each chain.

    Parameters
    ----------
    profile : (m, codes) float32: the score of query residue i against each code.
    codes : the residue codes of every chain, one after another; chain k is ``lengths[k]``
        codes from ``starts[k]``.
    gap_open, gap_extend : the cost of a gap's first residue and of each further one (> 0).
    """
    m, alphabet = profile.shape
    table = np.full((alphabet + 1, m), _PAD, dtype=np.float32)  # by code, then query residue
    table[:alphabet] = profile.T
    order = np.argsort(lengths, kind="mergesort")  # lanes of similar length pad little
    scores = np.zeros(len(starts), dtype=np.float32)
    opening, extension = np.float32(gap_open), np.float32(gap_extend)
    for group in prange((len(starts) + LANES - 1) // LANES):
        members = order[group * LANES:(group + 1) * LANES]
        n = lengths[members[-1]]  # the longest: members come by length
        lane_codes = np.full((n, LANES), alphabet, dtype=np.int64)
        for lane in range(len(members)):
            k = members[lane]
            lane_codes[:lengths[k], lane] = codes[starts[k]:starts[k] + lengths[k]]
        column = np.empty((m, LANES), dtype=np.float32)  # the scores of the lanes' residues j
        best = np.zeros((m + 1, LANES), dtype=np.float32)  # H of the previous column
        down = np.full((m + 1, LANES), np.float32(-1e30), dtype=np.float32)  # gaps in the chains, by query row
        diagonal, left = np.zeros(LANES, dtype=np.float32), np.zeros(LANES, dtype=np.float32)
        across, top = np.zeros(LANES, dtype=np.float32), np.zeros(LANES, dtype=np.float32)
        for j in range(n):
            for lane in range(LANES):
                column[:, lane] = table[lane_codes[j, lane]]
                diagonal[lane], left[lane], across[lane] = 0.0, 0.0, -1e30
            for i in range(1, m + 1):
                for lane in range(LANES):
                    gap_down = max(down[i, lane] - extension, best[i, lane] - opening)
                    gap_across = max(across[lane] - extension, left[lane] - opening)
                    value = max(max(diagonal[lane] + column[i - 1, lane], gap_down), max(gap_across, np.float32(0.0)))
                    down[i, lane], across[lane] = gap_down, gap_across
                    diagonal[lane], best[i, lane], left[lane] = best[i, lane], value, value
                    top[lane] = max(top[lane], value)
        for lane in range(len(members)):
            scores[members[lane]] = top[lane]
    return scores


@njit(cache=True)
def local_pairs(profile: np.ndarray, codes: np.ndarray, gap_open: float, gap_extend: float
                ) -> tuple[np.ndarray, np.ndarray, float]:
    """The best local alignment of the query (``profile``, as :func:`local_scores`) with one
    chain (``codes``): increasing indices of the paired residues of each, and the score."""
    m, n = profile.shape[0], len(codes)
    best = np.zeros((m + 1, n + 1), dtype=np.float32)
    down = np.full((m + 1, n + 1), np.float32(-1e30), dtype=np.float32)
    across = np.full((m + 1, n + 1), np.float32(-1e30), dtype=np.float32)
    opening, extension = np.float32(gap_open), np.float32(gap_extend)
    top, top_i, top_j = np.float32(0.0), 0, 0
    for j in range(1, n + 1):
        code = codes[j - 1]
        for i in range(1, m + 1):
            down[i, j] = max(down[i, j - 1] - extension, best[i, j - 1] - opening)
            across[i, j] = max(across[i - 1, j] - extension, best[i - 1, j] - opening)
            value = max(best[i - 1, j - 1] + profile[i - 1, code], down[i, j], across[i, j], np.float32(0.0))
            best[i, j] = value
            if value > top:
                top, top_i, top_j = value, i, j
    pairs_a, pairs_b = np.empty(min(m, n), dtype=np.int64), np.empty(min(m, n), dtype=np.int64)
    count, i, j, state = 0, top_i, top_j, 0  # state 0: in best, 1: in down (a gap in the query), 2: across
    while i > 0 and j > 0:
        if state == 0:
            if best[i, j] <= 0:
                break
            if best[i, j] == best[i - 1, j - 1] + profile[i - 1, codes[j - 1]]:
                pairs_a[count], pairs_b[count] = i - 1, j - 1
                count += 1
                i, j = i - 1, j - 1
            elif best[i, j] == down[i, j]:
                state = 1
            else:
                state = 2
        elif state == 1:
            state = 0 if down[i, j] == best[i, j - 1] - opening else 1
            j -= 1
        else:
            state = 0 if across[i, j] == best[i - 1, j] - opening else 2
            i -= 1
    return pairs_a[:count][::-1].copy(), pairs_b[:count][::-1].copy(), float(top)
