"""Smith–Waterman local alignment scores of one query against many chains, in numba.

The query is a profile: the score of each of its residues against each residue code of the
chains (a code names a residue's 3Di state and amino acid together,
:func:`core.analysis.fold_search.residue_codes`), so the inner loop is one lookup per cell.
Gaps cost Gotoh's affine penalties. Only the best score of each chain is kept (linear
memory); the chains are shared among the threads, each scored alone, so the scores are the
same on any number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


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
    m = profile.shape[0]
    scores = np.zeros(len(starts), dtype=np.float32)
    opening, extension = np.float32(gap_open), np.float32(gap_extend)
    for k in prange(len(starts)):
        best = np.zeros(m + 1, dtype=np.float32)  # H of the previous column
        down = np.full(m + 1, np.float32(-1e30), dtype=np.float32)  # gaps in the chain, by query row
        top = np.float32(0.0)
        for j in range(starts[k], starts[k] + lengths[k]):
            code = codes[j]
            diagonal, left, across = np.float32(0.0), np.float32(0.0), np.float32(-1e30)
            for i in range(1, m + 1):
                down[i] = max(down[i] - extension, best[i] - opening)
                across = max(across - extension, left - opening)
                value = max(diagonal + profile[i - 1, code], down[i], across, np.float32(0.0))
                diagonal, best[i], left = best[i], value, value
                top = max(top, value)
        scores[k] = top
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
