"""Structural alignment of two chains: residues paired by where their Cα lie in space.

A sequence alignment pairs the wrong residues of distant homologues (below about 30%
identity, e.g. *S. griseus* proteinase B and trypsin), and those of unrelated folds
arbitrarily. :func:`align_folds` does what TM-align does (Zhang & Skolnick 2005): from
several starts (a given pairing, the best gapless threading of one chain along the other,
pairings of secondary-structure states, and the pairing under the best superposition of
two fragments) it alternates a superposition that maximises the TM-score of the pairs
(:func:`tm_superpose`, TM-score's search) with a pairing of the superposed chains by
dynamic programming over the TM-score terms ``1 / (1 + (d / d0)²)`` of every residue pair
(:func:`monotone_pairs`), and keeps the pairing of highest TM-score. The pairs closer than
:func:`tm_d8` after the final superposition are the aligned ones.

The starts and the rounds are computed together in numpy (:func:`core.analysis.superpose.fit_subsets`
fits hundreds of subsets at once): 0.1–0.35 s for chains of 200–400 residues on a 2-core machine.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.spatial.distance import cdist

from core import _validate
from core.analysis.superpose import MIN_PAIRS, Superposition, fit_subsets

PAIR_CUTOFF = 5.0
"""Å: pairs farther apart after the final superposition are not structurally equivalent
(:func:`align_structures`)."""
ROUNDS = 5
"""Superposition and pairing rounds at most from each start; a start stops as soon as a
round does not raise its TM-score."""
STATE_GAP = 1.0
"""Score lost per gap when secondary-structure states are paired (TM-align's). The rounds
pair TM-score terms without a gap penalty (TM-align's second pass; its first, with 0.6 per
gap, gave lower TM-scores on the test chains)."""
SEARCH_ROUNDS = 20
"""Refinements of each start of the TM-score search."""
QUICK_STEP = 40
"""Pairs between the fragments that start the quick TM-score searches of the rounds
(TM-align's ``simplify_step``); the final search starts from every half-overlapping fragment."""
FRAGMENT_PLACES = 8
"""Places along each chain of the fragments whose superpositions start an alignment."""
SCORE_BLOCK = 4_000_000
"""Score-matrix entries computed at once (8 bytes each)."""


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


def tm_superpose(fixed: np.ndarray, moving: np.ndarray, length: int, step: int = 0) -> tuple[Superposition, float]:
    """The superposition of paired points that maximises their TM-score (TM-score's search).

    Fits start from fragments of the pairs (all of them, halves, quarters, … down to 4
    pairs, ``step`` pairs apart; 0: half a fragment apart) and are refitted on the pairs
    they bring within ``d0`` (at least 4.5 Å, at most 8 Å) until that set settles; the best is kept.

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
    score, rotation, translation, used = _tm_fits([fixed], [moving], tm_d0(length), step)
    moved = moving @ rotation[0].T + translation[0]
    rmsd = float(np.sqrt(np.mean(np.sum((fixed - moved)[used[0]] ** 2, axis=1))))
    return Superposition(rotation[0], translation[0], rmsd), float(score[0]) / length


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
    starts = []
    if pairs_a is not None and pairs_b is not None:
        given = np.asarray(pairs_a, dtype=np.int64), np.asarray(pairs_b, dtype=np.int64)
        if len(given[0]) != len(given[1]) or len(given[0]) < MIN_PAIRS:
            raise ValueError(f"the start needs at least {MIN_PAIRS} pairs of equal length; got {len(given[0])} and "
                             f"{len(given[1])}")
        starts.append(given)
    d0 = tm_d0(len(ca_a))
    starts += [pairs for pairs in _starts(ca_a, ca_b, d0) if len(pairs[0]) >= MIN_PAIRS]
    pairs = _iterate(ca_a, ca_b, starts, d0)
    motion, _ = tm_superpose(ca_a[pairs[0]], ca_b[pairs[1]], len(ca_a), QUICK_STEP)
    close = np.linalg.norm(ca_a[pairs[0]] - motion.apply(ca_b[pairs[1]]), axis=1) < tm_d8(min(len(ca_a), len(ca_b)))
    if close.sum() >= MIN_PAIRS:
        pairs = pairs[0][close], pairs[1][close]
    motion, score = tm_superpose(ca_a[pairs[0]], ca_b[pairs[1]], len(ca_a))
    return FoldAlignment(pairs[0], pairs[1], motion, score)


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
    alignment = align_folds(ca_a, ca_b, pairs_a, pairs_b)
    a, b = alignment.pairs_a, alignment.pairs_b
    close = np.linalg.norm(np.asarray(ca_a)[a] - alignment.motion.apply(np.asarray(ca_b)[b]), axis=1) < PAIR_CUTOFF
    return a[close], b[close]


def monotone_pairs(score: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The order-keeping pairing of rows with columns of ``score`` (n, m; >= 0) that
    maximises the sum of the paired scores less ``gap`` per gap: per run of rows, and per
    run of columns, left unpaired between two pairs, whatever its length (TM-align's gap
    opening without extension). Rows and columns before the first pair and after the last
    are free.

    Returns increasing (row, column) index arrays.
    """
    score = np.asarray(score, dtype=np.float64)
    total, before = _pairing_tables(score[:, None], gap)
    return _traceback(total[:, 0], before[:, 0], gap)


# ---------------------------------------------------------------------- the starts and the rounds


def _starts(ca_a: np.ndarray, ca_b: np.ndarray, d0: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """TM-align's initial alignments: the best gapless threading, the pairing of
    secondary-structure states alone and with the TM-score terms under that threading's
    superposition, and the pairing under the best superposition of two fragments."""
    threading, motion = _threading(ca_a, ca_b, d0)
    states_a, states_b = _ca_states(ca_a), _ca_states(ca_b)
    same = (states_a[:, None] == states_b[None, :]).astype(np.float64)
    near = _terms(ca_a, ca_b @ motion[0].T + motion[1], d0)
    return [threading, monotone_pairs(same, STATE_GAP), monotone_pairs(near + 0.5 * same, STATE_GAP),
            _fragment_start(ca_a, ca_b, d0)]


def _iterate(ca_a: np.ndarray, ca_b: np.ndarray, starts: Sequence[tuple[np.ndarray, np.ndarray]],
             d0: float) -> tuple[np.ndarray, np.ndarray]:
    """From every start at once, alternate the quick TM-score superposition of the pairs
    and their pairing by dynamic programming; the pairing of highest TM-score."""
    best_pairs, best_score = list(starts), np.full(len(starts), -np.inf)
    current, active = list(starts), np.arange(len(starts))
    for _ in range(ROUNDS):
        _, rotation, translation, _ = _tm_fits([ca_a[current[k][0]] for k in active],
                                               [ca_b[current[k][1]] for k in active], d0, QUICK_STEP)
        terms = _terms(ca_a, ca_b @ np.swapaxes(rotation, 1, 2) + translation[:, None], d0)
        going = []
        for index, k in enumerate(active):
            value = terms[:, index][current[k]].sum()
            if value > best_score[k]:
                best_pairs[k], best_score[k] = current[k], value
                going.append(index)
        if not going:
            break
        total, before = _pairing_tables(terms[:, going], 0.0)
        active_next = []
        for row, index in enumerate(going):
            k = active[index]
            found = _traceback(total[:, row], before[:, row], 0.0)
            if len(found[0]) >= MIN_PAIRS and not all(np.array_equal(p, q) for p, q in zip(found, current[k])):
                current[k] = found
                active_next.append(k)
        if not active_next:
            break
        active = np.array(active_next)
    return best_pairs[int(np.argmax(best_score))]


def _threading(ca_a: np.ndarray, ca_b: np.ndarray,
               d0: float) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """The gapless pairing ``(i, i - shift)`` of highest TM-score after a short search,
    among the shifts that overlap half the shorter chain (at least 3 residues), and its
    superposition (rotation, translation)."""
    n_a, n_b = len(ca_a), len(ca_b)
    overlap = max(min(n_a, n_b) // 2, MIN_PAIRS)
    shifts = np.arange(overlap - n_b, n_a - overlap + 1)
    partner = np.arange(n_a)[None, :] - shifts[:, None]  # (shifts, n_a): residue of b paired with i
    valid = (partner >= 0) & (partner < n_b)
    score, rotation, translation, _ = _tm_search(ca_a, ca_b[np.clip(partner, 0, n_b - 1)], valid, valid, d0, rounds=3)
    k = int(np.argmax(score))
    return (np.flatnonzero(valid[k]), partner[k][valid[k]]), (rotation[k], translation[k])


def _fragment_start(ca_a: np.ndarray, ca_b: np.ndarray, d0: float) -> tuple[np.ndarray, np.ndarray]:
    """The pairing, by dynamic programming without gap penalty on TM-score terms (d0 + 1.5 Å),
    under the superposition of a fragment of chain a on one of chain b (20 and 100
    residues, at most a third and half of the shorter chain, at :data:`FRAGMENT_PLACES`
    places along each chain) whose pairing scores best (TM-align's local superpositions).
    The superpositions are ranked on every other residue of each chain."""
    n_a, n_b = len(ca_a), len(ca_b)
    shorter = min(n_a, n_b)
    moved = []
    for size in sorted({min(20, shorter // 3), min(100, shorter // 2)}):
        if size < MIN_PAIRS:
            continue
        first_a, first_b = (np.unique(np.linspace(0, n - size, FRAGMENT_PLACES).round().astype(np.int64))
                            for n in (n_a, n_b))
        i, j = (places.ravel() for places in np.meshgrid(first_a, first_b, indexing="ij"))
        window = np.arange(size)
        rotation, translation = fit_subsets(ca_a[i[:, None] + window], ca_b[j[:, None] + window],
                                            np.ones((len(i), size), dtype=bool))
        moved.append(ca_b @ np.swapaxes(rotation, 1, 2) + translation[:, None])  # (k, n_b, 3)
    if not moved:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    moved = np.concatenate(moved)
    coarse_a, coarse_b = ca_a[::2], moved[:, ::2]
    block = max(SCORE_BLOCK // (len(coarse_a) * coarse_b.shape[1]), 1)
    values = np.concatenate([_best_sums(_terms(coarse_a, coarse_b[first:first + block], d0 + 1.5))
                             for first in range(0, len(moved), block)])
    return monotone_pairs(_terms(ca_a, moved[int(np.argmax(values))], d0 + 1.5), 0.0)


def _terms(ca_a: np.ndarray, moved_b: np.ndarray, d0: float) -> np.ndarray:
    """TM-score terms ``1 / (1 + (d / d0)²)`` of every pair of Cα: (n_a, n_b) for moved_b
    (n_b, 3), (n_a, k, n_b) for (k, n_b, 3)."""
    terms = cdist(ca_a, moved_b.reshape(-1, 3), "sqeuclidean").reshape(len(ca_a), *moved_b.shape[:-1])
    terms *= 1.0 / d0**2  # in place: these are the large arrays
    terms += 1.0
    return np.reciprocal(terms, out=terms)


def _ca_states(ca: np.ndarray) -> np.ndarray:
    """(n,) int8 secondary structure of each residue from the distances of the Cα one to
    four apart around it, as TM-align assigns it: 1 helix, 2 strand, 3 turn, 0 coil (and
    the two residues at each end)."""
    n = len(ca)
    states = np.zeros(n, dtype=np.int8)
    if n < 5:
        return states
    d2, d3, d4 = (np.linalg.norm(ca[k:] - ca[:-k], axis=1) for k in (2, 3, 4))
    d13, d24, d35, d14, d25, d15 = d2[:-2], d2[1:-1], d2[2:], d3[:-1], d3[1:], d4  # residues c-2 .. c+2 are 1 .. 5
    helix = np.all([np.abs(d - ref) < 2.1 for d, ref in ((d13, 5.45), (d24, 5.45), (d35, 5.45), (d14, 5.18),
                                                          (d25, 5.18), (d15, 6.37))], axis=0)
    strand = np.all([np.abs(d - ref) < 1.42 for d, ref in ((d13, 6.1), (d24, 6.1), (d35, 6.1), (d14, 10.4),
                                                           (d25, 10.4), (d15, 13.0))], axis=0)
    states[2:-2] = np.select([helix, strand, d15 < 8.0], [1, 2, 3], 0)
    return states


# ---------------------------------------------------------------------- the TM-score search


def _tm_fits(fixed: Sequence[np.ndarray], moving: Sequence[np.ndarray], d0: float,
             step: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The TM-score search (fragments ``step`` pairs apart, see :func:`tm_superpose`) of
    several sets of paired points at once: for each set, its best TM-score sum, rotation,
    translation, and the (padded) pairs that fit was computed on."""
    length = max(len(points) for points in fixed)
    padded_fixed, padded_moving = np.zeros((len(fixed), length, 3)), np.zeros((len(fixed), length, 3))
    valid = np.zeros((len(fixed), length), dtype=bool)
    seeds, owner = [], []
    for k, (a, b) in enumerate(zip(fixed, moving)):
        padded_fixed[k, :len(a)], padded_moving[k, :len(b)], valid[k, :len(a)] = a, b, True
        fragments = _fragments(len(a), step)
        seeds.append(np.pad(fragments, ((0, 0), (0, length - len(a)))))
        owner += [k] * len(fragments)
    owner = np.array(owner)
    score, rotation, translation, used = _tm_search(padded_fixed[owner], padded_moving[owner], valid[owner],
                                                    np.concatenate(seeds), d0)
    best = np.array([np.flatnonzero(owner == k)[np.argmax(score[owner == k])] for k in range(len(fixed))])
    return score[best], rotation[best], translation[best], used[best]


def _fragments(n: int, step: int) -> np.ndarray:
    """(k, n) bool: fragments of n pairs, n, n/2, n/4, … long (at least 4, or n when fewer),
    starting ``step`` pairs apart (0: half a fragment apart)."""
    seeds, size = [], n
    while True:
        stride = step or max(size // 2, 1)
        for first in range(0, n - size + 1, stride):
            seed = np.zeros(n, dtype=bool)
            seed[first:first + size] = True
            seeds.append(seed)
        if size // 2 < 4:
            return np.array(seeds)
        size //= 2


def _tm_search(fixed: np.ndarray, moving: np.ndarray, valid: np.ndarray, seeds: np.ndarray, d0: float,
               rounds: int = SEARCH_ROUNDS) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """TM-score search from many starts at once.

    ``fixed`` and ``moving`` (n, 3) or (k, n, 3); ``valid`` (n,) or (k, n) bool, the pairs
    that exist; ``seeds`` (k, n) bool, the pairs of each start. Each start is fitted, then
    refitted on the valid pairs within the search cutoff until they settle (``rounds`` at most).
    Returns, for each start, the best TM-score sum (unnormalised), its rotation and
    translation, and the pairs that fit was computed on.
    """
    cutoff = float(np.clip(d0, 4.5, 8.0))
    valid = np.broadcast_to(valid, seeds.shape)
    best = np.full(len(seeds), -np.inf)
    best_rotation, best_translation, best_used = np.zeros((len(seeds), 3, 3)), np.zeros((len(seeds), 3)), seeds.copy()
    active, used = np.arange(len(seeds)), seeds
    for _ in range(rounds):
        a, b = (points[active] if points.ndim == 3 else points for points in (fixed, moving))
        rotation, translation = fit_subsets(a, b, used)
        squared = np.sum((a - b @ np.swapaxes(rotation, 1, 2) - translation[:, None]) ** 2, axis=2)
        exists = valid[active]
        score = np.sum(exists / (1.0 + squared / d0**2), axis=1)
        better = score > best[active]
        improved = active[better]
        best[improved], best_used[improved] = score[better], used[better]
        best_rotation[improved], best_translation[improved] = rotation[better], translation[better]
        within = exists & (squared < cutoff**2)
        too_few = within.sum(axis=1) < MIN_PAIRS
        within[too_few] = used[too_few]
        changed = np.any(within != used, axis=1)
        if not changed.any():
            break
        active, used = active[changed], within[changed]
    return best, best_rotation, best_translation, best_used


# ---------------------------------------------------------------------- the pairing by dynamic programming


def _pairing_tables(score: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The dynamic programme of :func:`monotone_pairs` for k score matrices at once, given
    as (n, k, m), one numpy pass per row: ``total`` (n, k, m), the best sum whose last pair
    is (i, j), and ``before``, its part before that pair (0: none)."""
    n, k, m = score.shape
    total, before = np.empty((n, k, m)), np.empty((n, k, m))
    above = np.full((k, m), -np.inf)  # best sum ending in each column, over the rows < i - 1
    last = np.full((k, m), -np.inf)  # row i - 1 of total
    for i in range(n):
        row = before[i]
        row[:] = 0.0  # a first pair
        np.maximum(row[:, 1:], last[:, :-1], out=row[:, 1:])  # after (i - 1, j - 1)
        if gap == 0.0:  # every earlier pair costs the same: one running maximum does
            np.maximum(row[:, 1:], np.maximum.accumulate(np.maximum(above, last), axis=1)[:, :-1], out=row[:, 1:])
        else:
            np.maximum(row[:, 2:], np.maximum.accumulate(last, axis=1)[:, :-2] - gap, out=row[:, 2:])  # columns skipped
            np.maximum(row[:, 1:], above[:, :-1] - gap, out=row[:, 1:])  # rows skipped
            np.maximum(row[:, 2:], np.maximum.accumulate(above, axis=1)[:, :-2] - 2.0 * gap, out=row[:, 2:])  # both
        np.add(score[i], row, out=total[i])
        np.maximum(above, last, out=above)
        last = total[i]
    return total, before


def _best_sums(score: np.ndarray) -> np.ndarray:
    """(k,) the best sums of :func:`monotone_pairs` without gap penalty of k score matrices
    given as (n, k, m), without the tables to trace them back."""
    n, k, m = score.shape
    above = np.zeros((k, m))  # best sum ending in each column, over the rows done (0: none)
    for i in range(n):
        reach = score[i].copy()
        reach[:, 1:] += np.maximum.accumulate(above, axis=1)[:, :-1]
        np.maximum(above, reach, out=above)
    return above.max(axis=1)


def _traceback(total: np.ndarray, before: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The pairing of highest sum of one matrix's tables (n, m) from :func:`_pairing_tables`."""
    i, j = (int(k) for k in np.unravel_index(np.argmax(total), total.shape))
    rows, columns = [i], [j]
    while i > 0 and j > 0 and before[i, j] > 0.0:
        value = before[i, j]
        if total[i - 1, j - 1] == value:
            i, j = i - 1, j - 1
        elif gap == 0.0:
            block = total[:i, :j]
            i, j = (int(k) for k in np.unravel_index(np.argmax(block), block.shape))
        elif j > 1 and total[i - 1, :j - 1].max() - gap == value:
            i, j = i - 1, int(np.argmax(total[i - 1, :j - 1]))
        elif i > 1 and total[:i - 1, j - 1].max() - gap == value:
            i, j = int(np.argmax(total[:i - 1, j - 1])), j - 1
        else:
            block = total[:i - 1, :j - 1]
            i, j = (int(k) for k in np.unravel_index(np.argmax(block), block.shape))
        rows.append(i)
        columns.append(j)
    return np.array(rows[::-1], dtype=np.int64), np.array(columns[::-1], dtype=np.int64)
