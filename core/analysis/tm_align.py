"""TM-align's structural alignment (Zhang & Skolnick 2005, Nucleic Acids Res. 33:2302), in
numba: compiled kernels on plain arrays, which :mod:`core.analysis.fold_alignment` wraps.

As in TM-align, chain x is superposed on chain y and ``invmap[j]`` is the residue of x paired
with residue j of y (-1: none). :func:`align` runs TM-align's search: its five initial
alignments (gapless threading, secondary-structure states, local superpositions of fragments,
states plus the best superposition so far, gapless threading of the longest fragments), each
refined by :func:`_detailed_search` (TM-score's search from fragments of the pairs) and
:func:`_dp_iterations` (dynamic programming on the TM-score terms of the superposed chains,
gap opening 0.6 or none, then the search again), and keeps the alignment of highest TM-score.

The kernels compile on first use and are cached next to this file (``cache=True``), so only
the first run after an install pays for it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

SIMPLIFY_STEP = 40
"""Pairs between the fragments that start the TM-score searches of the alignment (TM-align's)."""
MAX_ITERATIONS = 20
"""Refits of each start of the TM-score search."""
DP_ROUNDS = 30
"""Rounds of dynamic programming and search from the thorough starts (TM-align's)."""
QUICK_DP_ROUNDS = 2
"""Rounds from the local superpositions and the fragment threading (TM-align's)."""
GAP_OPEN = (-0.6, 0.0)
"""TM-align's two gap penalties of the rounds."""
COARSE_FROM = 40
"""Residues of the shorter chain from which the local superpositions are screened on every
other residue (:func:`_local_superpositions`)."""
COARSER_FROM = 160
"""Residues of the shorter chain from which they are screened on every third."""
LOCAL_KEEP = 4
"""Local superpositions kept from that screen."""


@njit(cache=True)
def kabsch(x: np.ndarray, y: np.ndarray, rows: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The rotation (3, 3) and translation (3,) that best fit ``x[rows[:count]]`` onto
    ``y[rows[:count]]`` in the least-squares sense (``x -> rotation @ x + translation``): Horn's
    unit quaternion, the eigenvector of the largest eigenvalue of a symmetric 4 × 4 matrix
    (:func:`_largest_eigenvector`)."""
    cx0 = cx1 = cx2 = cy0 = cy1 = cy2 = 0.0
    s00 = s01 = s02 = s10 = s11 = s12 = s20 = s21 = s22 = 0.0
    for k in range(count):  # one pass: sums, then the centred sums of products from them
        r = rows[k]
        a0, a1, a2, b0, b1, b2 = x[r, 0], x[r, 1], x[r, 2], y[r, 0], y[r, 1], y[r, 2]
        cx0, cx1, cx2, cy0, cy1, cy2 = cx0 + a0, cx1 + a1, cx2 + a2, cy0 + b0, cy1 + b1, cy2 + b2
        s00, s01, s02 = s00 + a0 * b0, s01 + a0 * b1, s02 + a0 * b2
        s10, s11, s12 = s10 + a1 * b0, s11 + a1 * b1, s12 + a1 * b2
        s20, s21, s22 = s20 + a2 * b0, s21 + a2 * b1, s22 + a2 * b2
    cx0, cx1, cx2, cy0, cy1, cy2 = cx0 / count, cx1 / count, cx2 / count, cy0 / count, cy1 / count, cy2 / count
    s00, s01, s02 = s00 - count * cx0 * cy0, s01 - count * cx0 * cy1, s02 - count * cx0 * cy2
    s10, s11, s12 = s10 - count * cx1 * cy0, s11 - count * cx1 * cy1, s12 - count * cx1 * cy2
    s20, s21, s22 = s20 - count * cx2 * cy0, s21 - count * cx2 * cy1, s22 - count * cx2 * cy2
    n = np.empty((4, 4))
    n[0, 0], n[1, 1] = s00 + s11 + s22, s00 - s11 - s22
    n[2, 2], n[3, 3] = -s00 + s11 - s22, -s00 - s11 + s22
    n[0, 1] = n[1, 0] = s12 - s21
    n[0, 2] = n[2, 0] = s20 - s02
    n[0, 3] = n[3, 0] = s01 - s10
    n[1, 2] = n[2, 1] = s01 + s10
    n[1, 3] = n[3, 1] = s20 + s02
    n[2, 3] = n[3, 2] = s12 + s21
    w, p, q, z = _largest_eigenvector(n)
    rotation = np.empty((3, 3))
    rotation[0, 0], rotation[1, 1] = w * w + p * p - q * q - z * z, w * w - p * p + q * q - z * z
    rotation[2, 2] = w * w - p * p - q * q + z * z
    rotation[0, 1], rotation[1, 0] = 2.0 * (p * q - w * z), 2.0 * (p * q + w * z)
    rotation[0, 2], rotation[2, 0] = 2.0 * (p * z + w * q), 2.0 * (p * z - w * q)
    rotation[1, 2], rotation[2, 1] = 2.0 * (q * z - w * p), 2.0 * (q * z + w * p)
    translation = np.empty(3)
    translation[0] = cy0 - rotation[0, 0] * cx0 - rotation[0, 1] * cx1 - rotation[0, 2] * cx2
    translation[1] = cy1 - rotation[1, 0] * cx0 - rotation[1, 1] * cx1 - rotation[1, 2] * cx2
    translation[2] = cy2 - rotation[2, 0] * cx0 - rotation[2, 1] * cx1 - rotation[2, 2] * cx2
    return rotation, translation


@njit(cache=True)
def _largest_eigenvector(a: np.ndarray) -> tuple[float, float, float, float]:
    """The unit eigenvector of the largest eigenvalue of the traceless symmetric 4 × 4 ``a`` (kept):
    the eigenvalue by Newton's method on the characteristic polynomial from above (Theobald's
    QCP), the vector as the largest column of the adjugate of ``a - λ I``; by cyclic Jacobi
    rotations where that eigenvalue is (nearly) repeated."""
    trace2, trace3 = 0.0, 0.0
    for i in range(4):
        for k in range(4):
            trace2 += a[i, k] * a[k, i]
            for j in range(4):
                trace3 += a[i, k] * a[k, j] * a[j, i]
    c0 = 0.0
    for i in range(4):
        c0 += a[0, i] * _cofactor(a, 0, i)
    c2, c1 = -0.5 * trace2, -trace3 / 3.0
    bound = 0.0
    for i in range(4):
        for k in range(4):
            bound += abs(a[i, k])
    if bound == 0.0:
        return 1.0, 0.0, 0.0, 0.0
    value = bound  # above the largest eigenvalue
    for _ in range(50):
        polynomial = ((value * value + c2) * value + c1) * value + c0
        slope = (4.0 * value * value + 2.0 * c2) * value + c1
        if slope == 0.0:
            break
        change = polynomial / slope
        value -= change
        if abs(change) <= 1e-14 * bound:
            break
    for i in range(4):
        a[i, i] -= value
    best, best_norm = 0, 0.0
    for j in range(4):  # column j of the adjugate of a - λ I: the cofactors of row j
        norm = 0.0
        for i in range(4):
            norm += _cofactor(a, j, i) ** 2
        if norm > best_norm:
            best, best_norm = j, norm
    w, p, q, z = _cofactor(a, best, 0), _cofactor(a, best, 1), _cofactor(a, best, 2), _cofactor(a, best, 3)
    for i in range(4):
        a[i, i] += value
    if best_norm <= (1e-8 * bound) ** 6:
        return _jacobi_largest(a)
    scale = 1.0 / np.sqrt(best_norm)
    return w * scale, p * scale, q * scale, z * scale


_OTHERS = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
"""The indices other than each of 0 … 3."""


@njit(cache=True)
def _cofactor(m: np.ndarray, row: int, column: int) -> float:
    """The cofactor of ``m[row, column]`` of a 4 × 4 matrix."""
    r, c = _OTHERS[row], _OTHERS[column]
    minor = (m[r[0], c[0]] * (m[r[1], c[1]] * m[r[2], c[2]] - m[r[1], c[2]] * m[r[2], c[1]])
             - m[r[0], c[1]] * (m[r[1], c[0]] * m[r[2], c[2]] - m[r[1], c[2]] * m[r[2], c[0]])
             + m[r[0], c[2]] * (m[r[1], c[0]] * m[r[2], c[1]] - m[r[1], c[1]] * m[r[2], c[0]]))
    return minor if (row + column) % 2 == 0 else -minor


@njit(cache=True)
def _jacobi_largest(a: np.ndarray) -> tuple[float, float, float, float]:
    """The unit eigenvector of the largest eigenvalue of the symmetric 4 × 4 ``a`` (overwritten),
    by cyclic Jacobi rotations."""
    v = np.eye(4)
    scale = 0.0
    for p in range(4):
        for q in range(4):
            scale += a[p, q] * a[p, q]
    for _ in range(50):
        off = 0.0
        for p in range(3):
            for q in range(p + 1, 4):
                off += a[p, q] * a[p, q]
        if off <= 1e-30 * scale:
            break
        for p in range(3):
            for q in range(p + 1, 4):
                if a[p, q] == 0.0:
                    continue
                theta = (a[q, q] - a[p, p]) / (2.0 * a[p, q])
                t = (1.0 if theta >= 0.0 else -1.0) / (abs(theta) + np.sqrt(theta * theta + 1.0))
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                for k in range(4):
                    akp, akq = a[k, p], a[k, q]
                    a[k, p], a[k, q] = c * akp - s * akq, s * akp + c * akq
                for k in range(4):
                    apk, aqk = a[p, k], a[q, k]
                    a[p, k], a[q, k] = c * apk - s * aqk, s * apk + c * aqk
                for k in range(4):
                    vkp, vkq = v[k, p], v[k, q]
                    v[k, p], v[k, q] = c * vkp - s * vkq, s * vkp + c * vkq
    best = 0
    for k in range(1, 4):
        if a[k, k] > a[best, best]:
            best = k
    return v[0, best], v[1, best], v[2, best], v[3, best]


@njit(cache=True)
def _moved(x: np.ndarray, rotation: np.ndarray, translation: np.ndarray, out: np.ndarray) -> None:
    for i in range(len(x)):
        for c in range(3):
            out[i, c] = (rotation[c, 0] * x[i, 0] + rotation[c, 1] * x[i, 1] + rotation[c, 2] * x[i, 2]
                         + translation[c])


@njit(cache=True)
def _squared(a: np.ndarray, b: np.ndarray, i: int, j: int) -> float:
    return (a[i, 0] - b[j, 0]) ** 2 + (a[i, 1] - b[j, 1]) ** 2 + (a[i, 2] - b[j, 2]) ** 2


# ---------------------------------------------------------------------- the TM-score search


@njit(cache=True, fastmath=True)
def _score_within(x: np.ndarray, y: np.ndarray, rotation: np.ndarray, translation: np.ndarray, d: float, d0: float,
                  cut: float, lnorm: float, chosen: np.ndarray, distance: np.ndarray) -> tuple[float, int]:
    """TM-align's ``score_fun8``: the TM-score (by ``lnorm``) of the pairs x[k] moved, y[k]
    closer than ``cut``, and the pairs closer than ``d`` (in ``chosen``; d grows by 0.5 Å
    until there are 3; all of them for 3 pairs); ``distance`` (n,): room for the squared distances."""
    n = len(x)
    r, t = rotation, translation
    for k in range(n):
        a = r[0, 0] * x[k, 0] + r[0, 1] * x[k, 1] + r[0, 2] * x[k, 2] + t[0] - y[k, 0]
        b = r[1, 0] * x[k, 0] + r[1, 1] * x[k, 1] + r[1, 2] * x[k, 2] + t[1] - y[k, 1]
        c = r[2, 0] * x[k, 0] + r[2, 1] * x[k, 1] + r[2, 2] * x[k, 2] + t[2] - y[k, 2]
        distance[k] = a * a + b * b + c * c
    d02, cut2 = d0 * d0, cut * cut
    score = 0.0
    for k in range(n):
        if distance[k] <= cut2:
            score += 1.0 / (1.0 + distance[k] / d02)
    limit, grow = d * d, 0
    while True:
        found = 0
        for k in range(n):
            if distance[k] < limit:
                chosen[found] = k
                found += 1
        if found >= 3 or n < 3:
            return score / lnorm, found
        if n == 3:  # all three (TM-align would fit none)
            chosen[:3] = np.arange(3)
            return score / lnorm, 3
        grow += 1
        limit = (d + grow * 0.5) ** 2


@njit(cache=True)
def tm_search(x: np.ndarray, y: np.ndarray, step: int, d0: float, d0_search: float, cut: float,
              lnorm: float) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """TM-align's ``TMscore8_search``: the superposition of the paired points ``x`` on ``y``
    (n, 3 each; n >= 3) of highest TM-score. Fits start from fragments of the pairs (all,
    halves, quarters, … down to 4 pairs; ``step`` pairs apart) and are refitted on the pairs
    they bring within ``d0_search + 1`` until that set settles.

    Returns (TM-score of the pairs within ``cut``, by ``lnorm``; rotation; translation; the
    pairs of the best fit, as a bool mask).
    """
    n = len(x)
    rows, chosen, settled = np.arange(n), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    distance = np.empty(n)
    best, best_rotation, best_translation = -1.0, np.eye(3), np.zeros(3)
    best_rows, best_count = np.arange(n), n
    smallest = min(4, n)
    sizes = [max(n // 2**k, smallest) for k in range(5)] + [smallest]  # TM-align's six lengths at most
    seen = np.zeros(_table_size(n, step), dtype=np.uint64)
    for k, size in enumerate(sizes):
        if k > 0 and sizes[k - 1] <= smallest:
            break
        last = n - size
        first = 0
        while True:
            rotation, translation = kabsch(x, y, rows[first:], size)
            score, count = _score_within(x, y, rotation, translation, d0_search - 1.0, d0, cut, lnorm, chosen,
                                         distance)
            if score > best:
                best, best_rotation, best_translation = score, rotation, translation
                best_rows[:size], best_count = rows[first:first + size], size
            for _ in range(MAX_ITERATIONS):
                if not _first_visit(seen, chosen, count):
                    break  # refitted before: the same fits follow
                settled[:count] = chosen[:count]
                fitted = count
                rotation, translation = kabsch(x, y, settled, fitted)
                score, count = _score_within(x, y, rotation, translation, d0_search + 1.0, d0, cut, lnorm,
                                             chosen, distance)
                if score > best:
                    best, best_rotation, best_translation = score, rotation, translation
                    best_rows[:fitted], best_count = settled[:fitted], fitted
                if count == fitted and _same(chosen, settled, count):
                    break
            if first >= last:
                break
            first = min(first + step, last)
    used = np.zeros(n, dtype=np.bool_)
    used[best_rows[:best_count]] = True
    return best, best_rotation, best_translation, used


@njit(cache=True)
def _same(a: np.ndarray, b: np.ndarray, count: int) -> bool:
    """Whether the first ``count`` entries of ``a`` and ``b`` agree."""
    for k in range(count):
        if a[k] != b[k]:
            return False
    return True


@njit(cache=True)
def _table_size(n: int, step: int) -> int:
    """Slots of :func:`tm_search`'s table of the sets of pairs refitted: a power of 2, about 16
    per start."""
    starts = 0
    size = n
    for _ in range(6):
        starts += (n - size) // step + 2
        size = max(size // 2, 1)
    return 1 << min(max(int(np.ceil(np.log2(16 * starts))), 6), 20)


@njit(cache=True)
def _first_visit(table: np.ndarray, rows: np.ndarray, count: int) -> bool:
    """Whether the set ``rows[:count]`` (increasing) is new to ``table`` (open addressing of
    64-bit hashes, 0 empty), which then holds it; True as well when the table is full."""
    key = np.uint64(14695981039346656037)
    for k in range(count):
        key = (key ^ np.uint64(rows[k] + 1)) * np.uint64(1099511628211)
    key = key | np.uint64(1)
    mask = np.uint64(len(table) - 1)
    slot = key & mask
    for _ in range(len(table)):
        if table[slot] == key:
            return False
        if table[slot] == 0:
            table[slot] = key
            return True
        slot = (slot + np.uint64(1)) & mask
    return True


@njit(cache=True)
def _paired(x: np.ndarray, y: np.ndarray, invmap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Cα of the pairs of ``invmap``, in order: (k, 3) of x and of y."""
    count = 0
    for j in range(len(y)):
        if invmap[j] >= 0:
            count += 1
    px, py = np.empty((count, 3)), np.empty((count, 3))
    k = 0
    for j in range(len(y)):
        if invmap[j] >= 0:
            px[k], py[k] = x[invmap[j]], y[j]
            k += 1
    return px, py


@njit(cache=True)
def _detailed_search(x: np.ndarray, y: np.ndarray, invmap: np.ndarray, step: int, d0: float, d0_search: float,
                     cut: float, lnorm: float) -> tuple[float, np.ndarray, np.ndarray]:
    """:func:`tm_search` of the pairs of ``invmap``; (-1, identity, 0) for fewer than 3."""
    px, py = _paired(x, y, invmap)
    if len(px) < 3:
        return -1.0, np.eye(3), np.zeros(3)
    score, rotation, translation, _ = tm_search(px, py, step, d0, d0_search, cut, lnorm)
    return score, rotation, translation


# ---------------------------------------------------------------------- the pairing by dynamic programming


@njit(cache=True)
def pairing(score: np.ndarray, gap_open: float, invmap: np.ndarray) -> None:
    """TM-align's ``NWDP_TM``: the order-keeping pairing of the rows of ``score`` (n, m) with
    its columns of highest sum, less ``gap_open`` (<= 0, added) where a gap follows a pair;
    written to ``invmap`` (m,): the row paired with each column, -1 for none."""
    n, m = score.shape
    value, gap, step = np.zeros((2, m + 1)), np.zeros((2, m + 1)), np.empty((n, m), dtype=np.uint8)
    for i in range(n):
        _pairing_row(score[i], gap_open, i, value, gap, step)
    _trace(step, invmap)


@njit(cache=True)
def _superposed_pairing(x: np.ndarray, y: np.ndarray, rotation: np.ndarray, translation: np.ndarray, d0: float,
                        gap_open: float, invmap: np.ndarray) -> None:
    """:func:`pairing` of the TM-score terms ``1 / (1 + (d / d0)²)`` of x[i] moved and y[j],
    computed a row at a time."""
    moved = np.empty((len(x), 3))
    _moved(x, rotation, translation, moved)
    value, gap, step = np.zeros((2, len(y) + 1)), np.zeros((2, len(y) + 1)), np.empty((len(x), len(y)), dtype=np.uint8)
    terms = np.empty(len(y))
    for i in range(len(x)):
        _row_terms(moved[i], y, d0, terms)
        _pairing_row(terms, gap_open, i, value, gap, step)
    _trace(step, invmap)


@njit(cache=True, fastmath=True)
def _row_terms(point: np.ndarray, y: np.ndarray, d0: float, terms: np.ndarray) -> None:
    """``terms[j]``: the TM-score term ``1 / (1 + (d / d0)²)`` of ``point`` and y[j]."""
    scale = 1.0 / (d0 * d0)
    for j in range(len(y)):
        d = (point[0] - y[j, 0]) ** 2 + (point[1] - y[j, 1]) ** 2 + (point[2] - y[j, 2]) ** 2
        terms[j] = 1.0 / (1.0 + d * scale)


@njit(cache=True)
def _pairing_row(score: np.ndarray, gap_open: float, i: int, value: np.ndarray, gap: np.ndarray, step: np.ndarray
                 ) -> None:
    """Row i of TM-align's recursion from the scores of its cells: ``value`` (2, m + 1), the best
    sums of rows i - 1 and i by parity; ``gap`` (2, m + 1), the gap opening after each of those
    cells where it is a pair (else 0); ``step`` (n, m), the step into each cell (0: the pair
    (i, j); 1: from (i, j - 1); 2: from (i - 1, j))."""
    above, row, gap_above, gap_row = value[1 - i % 2], value[i % 2], gap[1 - i % 2], gap[i % 2]
    left, gap_left = 0.0, 0.0
    for j in range(1, len(score) + 1):
        d = above[j - 1] + score[j - 1]
        h = above[j] + gap_above[j]
        v = left + gap_left
        pair, down = d >= h and d >= v, v >= h
        left = d if pair else v if down else h
        gap_left = gap_open if pair else 0.0
        step[i, j - 1] = 0 if pair else 1 if down else 2
        row[j], gap_row[j] = left, gap_left


@njit(cache=True)
def _trace(step: np.ndarray, invmap: np.ndarray) -> None:
    """The pairing of the dynamic programme, followed back from its last cell."""
    invmap[:] = -1
    i, j = step.shape[0] - 1, step.shape[1] - 1
    while i >= 0 and j >= 0:
        if step[i, j] == 0:
            invmap[j] = i
            i -= 1
            j -= 1
        elif step[i, j] == 1:
            j -= 1
        else:
            i -= 1


@njit(cache=True)
def _terms(x: np.ndarray, y: np.ndarray, rotation: np.ndarray, translation: np.ndarray, d0: float,
           score: np.ndarray) -> None:
    """``score[i, j]``: the TM-score term ``1 / (1 + (d / d0)²)`` of x[i] moved, y[j]."""
    moved = np.empty((len(x), 3))
    _moved(x, rotation, translation, moved)
    d02 = d0 * d0
    for i in range(len(x)):
        for j in range(len(y)):
            score[i, j] = 1.0 / (1.0 + _squared(moved, y, i, j) / d02)


@njit(cache=True)
def _dp_iterations(x: np.ndarray, y: np.ndarray, rotation: np.ndarray, translation: np.ndarray, first_gap: int,
                   rounds: int, d0: float, d0_search: float, cut: float, lnorm: float, best_map: np.ndarray
                   ) -> float:
    """TM-align's ``DP_iter``: from the superposition given, pair the chains by
    :func:`pairing` on the TM-score terms, search their superposition, and again, ``rounds``
    times at most per gap penalty (of :data:`GAP_OPEN` from ``first_gap``); the best pairing
    goes to ``best_map``. Returns its TM-score.

    A round depends only on the pairing before it, so a pairing seen before in the same pass
    repeats the rounds since then: the pass stops there, and the next starts from the
    superposition TM-align would reach after all ``rounds``.
    """
    invmap = np.empty(len(y), dtype=np.int64)
    seen = np.empty((rounds, len(y)), dtype=np.int64)
    rotations, translations = np.empty((rounds, 3, 3)), np.empty((rounds, 3))
    best, gaps = -1.0, np.array(GAP_OPEN)
    for g in range(first_gap, len(gaps)):
        old = 0.0
        for iteration in range(rounds):
            _superposed_pairing(x, y, rotation, translation, d0, gaps[g], invmap)
            cycle = -1
            for earlier in range(iteration):
                if np.all(seen[earlier] == invmap):
                    cycle = earlier
                    break
            if cycle >= 0:  # TM-align's last round is a round of this cycle
                last = cycle + (rounds - 1 - cycle) % (iteration - cycle)
                rotation, translation = rotations[last], translations[last]
                break
            tm, found_rotation, found_translation = _detailed_search(x, y, invmap, SIMPLIFY_STEP, d0, d0_search, cut,
                                                                     lnorm)
            if tm < 0.0:
                break
            rotation, translation = found_rotation, found_translation
            seen[iteration], rotations[iteration], translations[iteration] = invmap, rotation, translation
            if tm > best:
                best = tm
                best_map[:] = invmap
            if iteration > 0 and abs(old - tm) < 1e-6:
                break
            old = tm
    return best


# ---------------------------------------------------------------------- the initial alignments


@njit(cache=True)
def _quick_score(x: np.ndarray, y: np.ndarray, invmap: np.ndarray, d0: float, d0_search: float
                 ) -> tuple[float, np.ndarray, np.ndarray]:
    """TM-align's ``get_score_fast``: the best TM-score sum of three fits of the pairs of
    ``invmap`` (all; those within ``d0_search``; within ``d0_search + 1``), its rotation and
    translation."""
    px, py = _paired(x, y, invmap)
    n = len(px)
    if n < 3:
        return -1.0, np.eye(3), np.zeros(3)
    rows, moved = np.arange(n), np.empty((n, 3))
    d02 = d0 * d0
    rotation, translation = kabsch(px, py, rows, n)
    best, best_rotation, best_translation = -1.0, rotation, translation
    for extra in (0.0, 1.0):
        _moved(px, rotation, translation, moved)
        score = 0.0
        distance = np.empty(n)
        for k in range(n):
            distance[k] = _squared(moved, py, k, k)
            score += 1.0 / (1.0 + distance[k] / d02)
        if score >= best:
            best, best_rotation, best_translation = score, rotation, translation
        limit = d0_search * d0_search + extra
        while True:
            count = 0
            for k in range(n):
                if distance[k] <= limit:
                    rows[count] = k
                    count += 1
            if count >= 3 or n < 3:
                break
            if n == 3:  # all three (TM-align would fit none)
                rows[:3], count = np.arange(3), 3
                break
            limit += 0.5
        if count == n and extra == 0.0:
            return best, best_rotation, best_translation
        rotation, translation = kabsch(px, py, rows, count)
    _moved(px, rotation, translation, moved)
    score = 0.0
    for k in range(n):
        score += 1.0 / (1.0 + _squared(moved, py, k, k) / d02)
    if score >= best:
        best, best_rotation, best_translation = score, rotation, translation
    return best, best_rotation, best_translation


@njit(cache=True)
def _threading(x: np.ndarray, y: np.ndarray, d0: float, d0_search: float, invmap: np.ndarray) -> None:
    """TM-align's ``get_initial``: the gapless pairing of highest quick TM-score among the
    shifts that overlap half the shorter chain (at least 5 residues)."""
    xlen, ylen = len(x), len(y)
    overlap = min(max(min(xlen, ylen) // 2, 5), min(xlen, ylen))
    trial = np.empty(ylen, dtype=np.int64)
    best = -1.0
    for k in range(overlap - ylen, xlen - overlap + 1):
        for j in range(ylen):
            trial[j] = j + k if 0 <= j + k < xlen else -1
        score, _, _ = _quick_score(x, y, trial, d0, d0_search)
        if score >= best:
            best = score
            invmap[:] = trial


@njit(cache=True)
def _local_superpositions(x: np.ndarray, y: np.ndarray, d0: float, d0_search: float, invmap: np.ndarray) -> bool:
    """TM-align's ``get_initial5``: pairings by :func:`pairing` (no gap penalty) of the
    chains superposed on a fragment of each (20 and 100 residues at most, at steps of 15 to
    45 residues along each chain); the best by quick TM-score goes to ``invmap``.

    From :data:`COARSE_FROM` residues on, every superposition is first judged so on every
    other residue of each chain (a quarter of the work; every third from :data:`COARSER_FROM`),
    and the best :data:`LOCAL_KEEP` on all.
    """
    xlen, ylen = len(x), len(y)
    d01 = d0 + 1.5
    shorter = min(xlen, ylen)
    jumps = np.empty(2, dtype=np.int64)
    for k, length in enumerate((xlen, ylen)):
        jump = 45 if length > 250 else 35 if length > 200 else 25 if length > 150 else 15
        jumps[k] = max(min(jump, length // 3), 1)
    sizes = (min(20, shorter // 3), min(100, shorter // 2))
    total = 0
    for size in sizes:
        total += ((xlen - size) // jumps[0] + 1) * ((ylen - size) // jumps[1] + 1)
    rotations, translations, screened = np.empty((total, 3, 3)), np.empty((total, 3)), np.full(total, -1.0)
    coarse = shorter >= COARSE_FROM
    step = 1 if not coarse else 2 if shorter < COARSER_FROM else 3
    cx, cy = np.ascontiguousarray(x[::step]), np.ascontiguousarray(y[::step])
    trial = np.empty(len(cy), dtype=np.int64)
    rows = np.arange(max(xlen, ylen))
    k = 0
    for size in sizes:
        for i in range(0, xlen - size + 1, jumps[0]):
            for j in range(0, ylen - size + 1, jumps[1]):
                if size >= 3:
                    rotations[k], translations[k] = kabsch(x[i:i + size], y[j:j + size], rows, size)
                    _superposed_pairing(cx, cy, rotations[k], translations[k], d01, 0.0, trial)
                    screened[k] = _quick_score(cx, cy, trial, d0, d0_search)[0]
                k += 1
    chosen = np.argsort(-screened)[:LOCAL_KEEP] if coarse else np.arange(total)
    if coarse:
        trial = np.empty(ylen, dtype=np.int64)
    best, found = 0.0, False
    for k in chosen:
        if screened[k] < 0.0:
            continue
        if coarse:
            _superposed_pairing(x, y, rotations[k], translations[k], d01, 0.0, trial)
            tm = _quick_score(x, y, trial, d0, d0_search)[0]
        else:
            tm = screened[k]
        if tm > best:
            best, found = tm, True
            if coarse:
                invmap[:] = trial
            else:
                _superposed_pairing(x, y, rotations[k], translations[k], d01, 0.0, invmap)
    return found


@njit(cache=True)
def _states_plus(x: np.ndarray, y: np.ndarray, states_x: np.ndarray, states_y: np.ndarray, start: np.ndarray,
                 d0: float, invmap: np.ndarray) -> bool:
    """TM-align's ``get_initial_ssplus``: the pairing (gap opening 1) of the TM-score terms
    (``d0 + 1.5``) of the chains superposed on the pairs of ``start`` (3 or more, else False),
    plus 0.5 where the secondary-structure states agree."""
    px, py = _paired(x, y, start)
    if len(px) < 3:
        return False
    rotation, translation = kabsch(px, py, np.arange(len(px)), len(px))
    score = np.empty((len(x), len(y)))
    _terms(x, y, rotation, translation, d0 + 1.5, score)
    for i in range(len(x)):
        for j in range(len(y)):
            if states_x[i] == states_y[j]:
                score[i, j] += 0.5
    pairing(score, -1.0, invmap)
    return True


@njit(cache=True)
def _longest_fragment(ca: np.ndarray) -> tuple[int, int]:
    """TM-align's ``find_max_frag``: the first and last residue of the longest run of Cα
    closer than 4.25 Å in turn (the cutoff grows by 10% until the run has a third of the chain
    or 4 residues)."""
    n = len(ca)
    shortest = min(n // 3, 4)
    cutoff, grow = 4.25, 0
    while True:
        longest, first, last, run, start = 0, 0, 0, 1, 0
        for i in range(1, n):
            if _squared(ca, ca, i - 1, i) < cutoff * cutoff:
                run += 1
                if i == n - 1 and run > longest:
                    longest, first, last = run, start, i
            else:
                if run > longest:
                    longest, first, last = run, start, i - 1
                run, start = 1, i
        if longest >= shortest:
            return first, last
        grow += 1
        cutoff = 1.1**grow * 4.25


@njit(cache=True)
def _fragment_threading(x: np.ndarray, y: np.ndarray, d0: float, d0_search: float, invmap: np.ndarray) -> None:
    """TM-align's ``get_initial_fgt``: the gapless threading of the shorter of the two chains'
    longest fragments (:func:`_longest_fragment`; its middle 80% when it is the whole chain)
    along the other chain."""
    xlen, ylen = len(x), len(y)
    x_first, x_last = _longest_fragment(x)
    y_first, y_last = _longest_fragment(y)
    lx, ly = x_last - x_first + 1, y_last - y_first + 1
    on_x = lx < ly or (lx == ly and xlen <= ylen)
    fragment = np.arange(x_first, x_first + lx) if on_x else np.arange(y_first, y_first + ly)
    length = min(lx, ly)
    fragment = fragment[:length]
    if length == min(xlen, ylen):
        fragment = fragment[int(length * 0.1):int(length * 0.89) + 1]
        length = len(fragment)
    other = ylen if on_x else xlen
    overlap = max(int(min(length, other) / 2.5), 3)
    trial = np.empty(ylen, dtype=np.int64)
    best = -1.0
    for k in range(overlap - (other if on_x else length), (length if on_x else other) - overlap + 1):
        trial[:] = -1
        if on_x:
            for j in range(ylen):
                if 0 <= j + k < length:
                    trial[j] = fragment[j + k]
        else:
            for j in range(length):
                if 0 <= j + k < xlen:
                    trial[fragment[j]] = j + k
        score, _, _ = _quick_score(x, y, trial, d0, d0_search)
        if score >= best:
            best = score
            invmap[:] = trial


@njit(cache=True)
def _states_pairing(states_x: np.ndarray, states_y: np.ndarray, invmap: np.ndarray) -> None:
    """TM-align's ``get_initial_ss``: the pairing (gap opening 1) of equal secondary-structure states."""
    score = np.empty((len(states_x), len(states_y)))
    for i in range(len(states_x)):
        for j in range(len(states_y)):
            score[i, j] = 1.0 if states_x[i] == states_y[j] else 0.0
    pairing(score, -1.0, invmap)


# ---------------------------------------------------------------------- the whole search


@njit(cache=True)
def _search_scales(shorter: int) -> tuple[float, float, float]:
    """TM-align's scales of the search for chains whose shorter has ``shorter`` residues: its
    d0 (the TM-score's, plus 0.8 Å), the d0 of the superposition search and the cutoff of the
    pairs kept (Å)."""
    d0 = (0.168 if shorter <= 19 else 1.24 * (shorter - 15.0) ** (1.0 / 3.0) - 1.8) + 0.8
    return d0, min(max(d0, 4.5), 8.0), 1.5 * shorter**0.3 + 3.5


@njit(cache=True)
def align(x: np.ndarray, y: np.ndarray, given: np.ndarray) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """TM-align's search for the alignment of chains x (n, 3) and y (m, 3), 3 residues or more
    each, with ``given``, a pairing (m,) to start from as well (all -1: none).

    Returns the best pairing (``invmap``, m), its TM-score in the search (by the shorter
    chain, with TM-align's search d0) and the superposition of x on y that TM-score's search
    finds for it with every fragment as a start (rotation, translation).
    """
    xlen, ylen = len(x), len(y)
    states_x, states_y = secondary_states(x), secondary_states(y)
    shorter = min(xlen, ylen)
    d0, d0_search, cut = _search_scales(shorter)
    ddcc = 0.1 if shorter <= 40 else 0.4
    best_map, invmap = np.full(ylen, -1, dtype=np.int64), np.full(ylen, -1, dtype=np.int64)
    best = -1.0
    for start in range(6):
        quick = start == 2 or start == 4
        if start == 0:
            _threading(x, y, d0, d0_search, invmap)
        elif start == 1:
            _states_pairing(states_x, states_y, invmap)
        elif start == 2:
            if not _local_superpositions(x, y, d0, d0_search, invmap):
                continue
        elif start == 3:
            if not _states_plus(x, y, states_x, states_y, best_map, d0, invmap):
                continue
        elif start == 4:
            _fragment_threading(x, y, d0, d0_search, invmap)
        elif np.any(given >= 0):
            invmap[:] = given
        else:
            continue
        tm, rotation, translation = _detailed_search(x, y, invmap, SIMPLIFY_STEP, d0, d0_search, cut, shorter)
        if tm > best:
            best = tm
            best_map[:] = invmap
        if tm > best * (0.0 if start == 0 else 0.2 if start == 1 else ddcc):
            found = np.full(ylen, -1, dtype=np.int64)
            tm = _dp_iterations(x, y, rotation, translation, 1 if start == 4 else 0,
                                QUICK_DP_ROUNDS if quick else DP_ROUNDS, d0, d0_search, cut, shorter, found)
            if tm > best:
                best = tm
                best_map[:] = found
    _, rotation, translation = _detailed_search(x, y, best_map, 1, d0, d0_search, cut, shorter)
    return best_map, best, rotation, translation


@njit(cache=True)
def refine(x: np.ndarray, y: np.ndarray, given: np.ndarray, rounds: int) -> tuple[np.ndarray, float]:
    """TM-align's refinement of one pairing ``given`` (m,) of chains x and y alone (no other
    start): TM-score's search of its pairs, then ``rounds`` rounds of :func:`_dp_iterations`.
    Returns the best pairing (``invmap``) and its TM-score in the search (as :func:`align`)."""
    shorter = min(len(x), len(y))
    d0, d0_search, cut = _search_scales(shorter)
    best_map = given.copy()
    best, rotation, translation = _detailed_search(x, y, given, SIMPLIFY_STEP, d0, d0_search, cut, shorter)
    if best < 0.0:
        return best_map, best
    found = np.full(len(y), -1, dtype=np.int64)
    tm = _dp_iterations(x, y, rotation, translation, 0, rounds, d0, d0_search, cut, shorter, found)
    if tm > best:
        best, best_map = tm, found
    return best_map, best


@njit(cache=True)
def secondary_states(ca: np.ndarray) -> np.ndarray:
    """(n,) int8 secondary structure of each residue from the distances of the Cα one to
    four apart around it, as TM-align assigns it: 1 helix, 2 strand, 3 turn, 0 coil (and
    the two residues at each end)."""
    n = len(ca)
    states = np.zeros(n, dtype=np.int8)
    for c in range(2, n - 2):
        d13, d24, d35 = (np.sqrt(_squared(ca, ca, c - 2, c)), np.sqrt(_squared(ca, ca, c - 1, c + 1)),
                         np.sqrt(_squared(ca, ca, c, c + 2)))
        d14, d25 = np.sqrt(_squared(ca, ca, c - 2, c + 1)), np.sqrt(_squared(ca, ca, c - 1, c + 2))
        d15 = np.sqrt(_squared(ca, ca, c - 2, c + 2))
        if (abs(d15 - 6.37) < 2.1 and abs(d14 - 5.18) < 2.1 and abs(d25 - 5.18) < 2.1 and abs(d13 - 5.45) < 2.1
                and abs(d24 - 5.45) < 2.1 and abs(d35 - 5.45) < 2.1):
            states[c] = 1
        elif (abs(d15 - 13.0) < 1.42 and abs(d14 - 10.4) < 1.42 and abs(d25 - 10.4) < 1.42 and abs(d13 - 6.1) < 1.42
              and abs(d24 - 6.1) < 1.42 and abs(d35 - 6.1) < 1.42):
            states[c] = 2
        elif d15 < 8.0:
            states[c] = 3
    return states
