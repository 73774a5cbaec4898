"""Structural alignment of two chains: residues paired by where their Cα lie in space.

A sequence alignment pairs the wrong residues of distant homologues (below about 30%
identity, e.g. *S. griseus* proteinase B and trypsin), and those of unrelated folds
arbitrarily. :func:`align_folds` does what TM-align does (Zhang & Skolnick 2005), in numpy:

1. Starts, as superpositions of chain b on chain a: the best gapless threading of one chain
   along the other, the TM-score superpositions of the pairings of secondary-structure states
   (alone, and with the TM-score terms under that threading), of a given pairing (the
   sequence alignment, say), and of fragment pairs (20 and 100 residues, at 8 places along
   each chain: TM-align's local superpositions).
2. Rounds: the chains superposed are paired by dynamic programming over the TM-score terms
   ``1 / (1 + (d / d0)²)`` of every residue pair (:func:`monotone_pairs`), and the pairs
   superposed for their highest TM-score (TM-score's search, :func:`tm_superpose`), until
   the TM-score stops rising. As in TM-align the search takes the shorter chain's d0 plus
   0.8 Å and counts only the pairs within :func:`tm_d8` of it.
3. Every start runs one quick round on every other residue (every fourth for long chains);
   the best :data:`SCREEN_KEEP` run their rounds on every other residue of chains of
   :data:`COARSE_FROM` residues or more, and the best :data:`FINE_STARTS` of those their
   last rounds on all residues, without gap penalty and with TM-align's 0.6 per gap.

The alignment of highest TM-score is kept; its pairs closer than :func:`tm_d8` after its
superposition are the aligned ones, and its TM-score (normalised by chain a, with chain a's
d0) that of TM-score's search on them. The starts and the rounds go through numpy together:
hundreds of superpositions at once (:func:`core.analysis.superpose.fit_subsets`), one numpy
pass per row of the dynamic programme for all starts at once. Against TM-align (tmtools) on
pairs of the shared set, within 0.02 of its TM-score for about 85% of the pairs, never
0.04 lower, at 1–2 times its time (``python benchmarks/bench_fold_alignment.py FOLDER``).
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
ROUNDS = 3
"""Superposition and pairing rounds at most from each start; a start stops as soon as a
round does not raise its TM-score."""
STATE_GAP = 1.0
"""Score lost per gap when secondary-structure states are paired (TM-align's)."""
SEARCH_ROUNDS = 20
"""Refinements of each start of the TM-score search."""
QUICK_STEP = 40
"""Pairs between the fragments that start the quick TM-score searches of the starts
(TM-align's ``simplify_step``); the final search starts from every half-overlapping fragment."""
FRAGMENT_PLACES = 8
"""Places along each chain of the fragments whose superpositions start an alignment."""
SCREEN_KEEP = 6
"""Starts kept after one round of all of them (a quick one: :data:`SCREEN_SEARCH_ROUNDS`)."""
SCREEN_COARSE_FROM = 60
"""Residues from which that round runs on every other residue of the chains it is given."""
SCREEN_SEARCH_ROUNDS = 3
"""Refinements of the TM-score search in that round (TM-align's quick score takes three)."""
COARSE_FROM = 150
"""Residues of the shorter chain from which the search runs on every other residue first."""
FINE_STARTS = 2
"""Starts refined on all residues after the search on every other residue."""
FINE_ROUNDS = 2
"""Rounds of the search on all residues."""
GAPS = (0.6, 0.0)
"""Score lost per gap in the pairings of the rounds on all residues (TM-align's two passes);
each start runs with each."""
SEARCH_D0 = 0.8
"""Å added to d0 of the shorter chain while searching (TM-align's: it finds better alignments);
the final TM-score takes chain a's own d0."""
SCORE_BLOCK = 4_000_000
"""Score-matrix entries of the starts paired at once (8 bytes each, a few tables of them)."""


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
    given = []
    if pairs_a is not None and pairs_b is not None:
        given = [(np.asarray(pairs_a, dtype=np.int64), np.asarray(pairs_b, dtype=np.int64))]
        if len(given[0][0]) != len(given[0][1]) or len(given[0][0]) < MIN_PAIRS:
            raise ValueError(f"the start needs at least {MIN_PAIRS} pairs of equal length; got {len(given[0][0])} "
                             f"and {len(given[0][1])}")
    shorter = min(len(ca_a), len(ca_b))
    d0 = (0.168 if shorter <= 19 else 1.24 * float(np.cbrt(shorter - 15)) - 1.8) + SEARCH_D0  # TM-align's
    limit = tm_d8(shorter)
    pairs, rotation, translation = _search(ca_a, ca_b, given, d0, limit)
    close = np.linalg.norm(ca_a[pairs[0]] - ca_b[pairs[1]] @ rotation.T - translation, axis=1) < limit
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
    return align_folds(ca_a, ca_b, pairs_a, pairs_b).within(ca_a, ca_b, PAIR_CUTOFF)


def monotone_pairs(score: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The order-keeping pairing of rows with columns of ``score`` (n, m; >= 0) that
    maximises the sum of the paired scores less ``gap`` per gap: per run of rows, and per
    run of columns, left unpaired between two pairs, whatever its length (TM-align's gap
    opening without extension). Rows and columns before the first pair and after the last
    are free.

    Returns increasing (row, column) index arrays.
    """
    score = np.asarray(score, dtype=np.float64)[:, None]
    return _free_pairings(score)[0] if gap == 0.0 else _pairings(score, np.array([gap]))[0]


# ---------------------------------------------------------------------- the starts and the rounds


Motions = tuple[np.ndarray, np.ndarray]
"""(k, 3, 3) rotations and (k, 3) translations moving chain b onto chain a."""


def _search(ca_a: np.ndarray, ca_b: np.ndarray, given: list[tuple[np.ndarray, np.ndarray]], d0: float,
            limit: float) -> tuple[tuple[np.ndarray, np.ndarray], np.ndarray, np.ndarray]:
    """The pairing of highest TM-score and its superposition: every start refined (each with
    each of :data:`GAPS`) on every other residue of each chain when both have at least
    :data:`COARSE_FROM` residues (on all of them otherwise), then the best :data:`FINE_STARTS`
    of them on all residues."""
    step = 2 if min(len(ca_a), len(ca_b)) >= COARSE_FROM else 1
    coarse_a, coarse_b = ca_a[::step], ca_b[::step]
    rotation, translation = _starts(coarse_a, coarse_b, d0, limit)
    if given:
        _, given_rotation, given_translation, _ = _tm_fits([ca_a[p[0]] for p in given], [ca_b[p[1]] for p in given],
                                                           d0, QUICK_STEP, limit)
        rotation = np.concatenate([given_rotation, rotation])
        translation = np.concatenate([given_translation, translation])
    screen = 2 if len(coarse_a) >= SCREEN_COARSE_FROM and len(coarse_b) >= SCREEN_COARSE_FROM else 1
    _, score, rotation, translation = _refine(coarse_a[::screen], coarse_b[::screen], rotation, translation, d0, limit,
                                              1, SCREEN_SEARCH_ROUNDS)
    chosen = np.argsort(score)[::-1][:SCREEN_KEEP]
    _, score, rotation, translation = _refine(coarse_a, coarse_b, rotation[chosen], translation[chosen], d0, limit,
                                              ROUNDS)
    chosen = np.repeat(np.argsort(score)[::-1][:FINE_STARTS], len(GAPS))
    gaps = np.tile(GAPS, len(chosen) // len(GAPS))
    pairs, score, rotation, translation = _refine(ca_a, ca_b, rotation[chosen], translation[chosen], d0, limit,
                                                  FINE_ROUNDS, gaps=gaps)
    best = int(np.argmax(score))
    return pairs[best], rotation[best], translation[best]


def _starts(ca_a: np.ndarray, ca_b: np.ndarray, d0: float, limit: float) -> Motions:
    """TM-align's initial alignments, as superpositions: the best gapless threading, the
    best superpositions of fragment pairs, and the TM-score superpositions of the pairings of
    secondary-structure states alone and with the TM-score terms under that threading."""
    threading = _threading(ca_a, ca_b, d0)
    states_a, states_b = _ca_states(ca_a), _ca_states(ca_b)
    same = (states_a[:, None] == states_b[None, :]).astype(np.float64)
    near = _terms(ca_a, ca_b @ threading[0][0].T + threading[1][0], d0)
    pairings = _pairings(np.stack([same, near + 0.5 * same], axis=1), np.full(2, STATE_GAP))
    pairings = [p for p in pairings if len(p[0]) >= MIN_PAIRS]
    _, rotation, translation, _ = _tm_fits([ca_a[p[0]] for p in pairings], [ca_b[p[1]] for p in pairings], d0,
                                           QUICK_STEP, limit)
    fragments = _fragment_motions(ca_a, ca_b)
    return (np.concatenate([threading[0], fragments[0], rotation]),
            np.concatenate([threading[1], fragments[1], translation]))


def _refine(ca_a: np.ndarray, ca_b: np.ndarray, rotation: np.ndarray, translation: np.ndarray, d0: float,
            limit: float, rounds: int, search_rounds: int = SEARCH_ROUNDS, gaps: np.ndarray | None = None
            ) -> tuple[list, np.ndarray, np.ndarray, np.ndarray]:
    """From every start (a superposition) at once, alternate the pairing of the superposed
    chains by dynamic programming on the TM-score terms (without gap penalty, or with the
    start's of ``gaps``), and the TM-score
    superposition of the pairs (searched from the pairs the last superposition brought close,
    ``search_rounds`` refinements), until a round no longer raises the TM-score (pairs within
    ``limit`` counted) or ``rounds`` are done.

    Returns, per start, its best pairing, TM-score sum, rotation and translation.
    """
    rotation, translation = rotation.copy(), translation.copy()
    best_pairs, best_score = [None] * len(rotation), np.full(len(rotation), -np.inf)
    active = np.arange(len(rotation))
    for _ in range(rounds):
        found = []
        block = max(SCORE_BLOCK // (len(ca_a) * len(ca_b)), 1)  # starts at once: bounded memory
        for part in (active[first:first + block] for first in range(0, len(active), block)):
            moved = ca_b @ np.swapaxes(rotation[part], 1, 2) + translation[part][:, None]
            found += _gapped_pairings(_terms(ca_a, moved, d0), np.zeros(len(part)) if gaps is None else gaps[part])
        keep = [k for k, pairs in enumerate(found) if len(pairs[0]) >= MIN_PAIRS]
        if not keep:
            break
        jobs = active[keep]
        score, fitted_rotation, fitted_translation, _ = _tm_fits(
            [ca_a[found[k][0]] for k in keep], [ca_b[found[k][1]] for k in keep], d0, None, limit,
            (rotation[jobs], translation[jobs]), search_rounds)
        better = score > best_score[jobs] + 1e-9
        for index in np.flatnonzero(better):
            best_pairs[jobs[index]] = found[keep[index]]
        best_score[jobs[better]] = score[better]
        rotation[jobs[better]], translation[jobs[better]] = fitted_rotation[better], fitted_translation[better]
        active = jobs[better]
        if not len(active):
            break
    return best_pairs, best_score, rotation, translation


def _threading(ca_a: np.ndarray, ca_b: np.ndarray, d0: float) -> Motions:
    """The superposition (as (1, 3, 3) and (1, 3) arrays) of the gapless pairing
    ``(i, i - shift)`` of highest TM-score after a short search, among the shifts that
    overlap half the shorter chain (at least 3 residues)."""
    n_a, n_b = len(ca_a), len(ca_b)
    overlap = max(min(n_a, n_b) // 2, MIN_PAIRS)
    shifts = np.arange(overlap - n_b, n_a - overlap + 1)
    partner = np.arange(n_a)[None, :] - shifts[:, None]  # (shifts, n_a): residue of b paired with i
    valid = (partner >= 0) & (partner < n_b)
    score, rotation, translation, _ = _tm_search(ca_a, ca_b[np.clip(partner, 0, n_b - 1)], valid, valid, d0, rounds=3)
    k = int(np.argmax(score))
    return rotation[k:k + 1], translation[k:k + 1]


def _fragment_motions(ca_a: np.ndarray, ca_b: np.ndarray) -> Motions:
    """The superpositions of a fragment of chain a on one of chain b (20 and 100 residues, at
    most a third and half of the shorter chain, at :data:`FRAGMENT_PLACES` places along each
    chain): TM-align's local superpositions."""
    n_a, n_b = len(ca_a), len(ca_b)
    shorter = min(n_a, n_b)
    rotations, translations = [np.zeros((0, 3, 3))], [np.zeros((0, 3))]
    for size in sorted({min(20, shorter // 3), min(100, shorter // 2)}):
        if size < MIN_PAIRS:
            continue
        first_a, first_b = (np.unique(np.linspace(0, n - size, FRAGMENT_PLACES).round().astype(np.int64))
                            for n in (n_a, n_b))
        i, j = (places.ravel() for places in np.meshgrid(first_a, first_b, indexing="ij"))
        window = np.arange(size)
        rotation, translation = fit_subsets(ca_a[i[:, None] + window], ca_b[j[:, None] + window],
                                            np.ones((len(i), size), dtype=bool))
        rotations.append(rotation)
        translations.append(translation)
    return np.concatenate(rotations), np.concatenate(translations)


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


def _tm_fits(fixed: Sequence[np.ndarray], moving: Sequence[np.ndarray], d0: float, step: int | None,
             limit: float = np.inf, motions: Motions | None = None, rounds: int = SEARCH_ROUNDS
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The TM-score search of several sets of paired points at once, started from fragments
    ``step`` pairs apart (see :func:`tm_superpose`; None: none) and, given ``motions`` (one
    per set), from all pairs and from the pairs each motion brings within the search cutoff.
    For each set: its best TM-score sum (of the pairs closer than ``limit``), rotation,
    translation, and the (padded) pairs that fit was computed on."""
    if not fixed:
        return np.zeros(0), np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros((0, 0), dtype=bool)
    length = max(len(points) for points in fixed)
    padded_fixed, padded_moving = np.zeros((len(fixed), length, 3)), np.zeros((len(fixed), length, 3))
    valid = np.zeros((len(fixed), length), dtype=bool)
    for k, (a, b) in enumerate(zip(fixed, moving)):
        padded_fixed[k, :len(a)], padded_moving[k, :len(b)], valid[k, :len(a)] = a, b, True
    seeds, owner = [], []
    if step is not None:
        for k, a in enumerate(fixed):
            fragments = _fragments(len(a), step)
            seeds.append(np.pad(fragments, ((0, 0), (0, length - len(a)))))
            owner += [k] * len(fragments)
    if motions is not None:
        moved = padded_moving @ np.swapaxes(motions[0], 1, 2) + motions[1][:, None]
        near = valid & (np.sum((padded_fixed - moved) ** 2, axis=2) < _search_cutoff(d0) ** 2)
        near[near.sum(axis=1) < MIN_PAIRS] = valid[near.sum(axis=1) < MIN_PAIRS]
        seeds += [valid, near]
        owner += 2 * list(range(len(fixed)))
    owner = np.array(owner)
    score, rotation, translation, used = _tm_search(padded_fixed[owner], padded_moving[owner], valid[owner],
                                                    np.concatenate(seeds), d0, rounds, limit)
    order = np.lexsort((-score, owner))  # each set's seeds, best first
    best = order[np.searchsorted(owner[order], np.arange(len(fixed)))]
    return score[best], rotation[best], translation[best], used[best]


def _search_cutoff(d0: float) -> float:
    """Å: the TM-score search refits on the pairs closer than this (TM-align's ``d0_search``)."""
    return float(np.clip(d0, 4.5, 8.0))


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
               rounds: int = SEARCH_ROUNDS, limit: float = np.inf
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """TM-score search from many starts at once.

    ``fixed`` and ``moving`` (n, 3) or (k, n, 3); ``valid`` (n,) or (k, n) bool, the pairs
    that exist; ``seeds`` (k, n) bool, the pairs of each start. Each start is fitted, then
    refitted on the valid pairs within the search cutoff until they settle (``rounds`` at most).
    Returns, for each start, the best TM-score sum (unnormalised; of the pairs closer than
    ``limit``), its rotation and translation, and the pairs that fit was computed on.
    """
    cutoff = _search_cutoff(d0)
    valid = np.broadcast_to(valid, seeds.shape)
    best = np.full(len(seeds), -np.inf)
    best_rotation, best_translation, best_used = np.zeros((len(seeds), 3, 3)), np.zeros((len(seeds), 3)), seeds.copy()
    active, used = np.arange(len(seeds)), seeds
    for _ in range(rounds):
        a, b = (points[active] if points.ndim == 3 else points for points in (fixed, moving))
        rotation, translation = fit_subsets(a, b, used)
        squared = np.sum((a - b @ np.swapaxes(rotation, 1, 2) - translation[:, None]) ** 2, axis=2)
        exists = valid[active]
        score = np.sum((exists & (squared < limit**2)) / (1.0 + squared / d0**2), axis=1)
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


def _gapped_pairings(score: np.ndarray, gaps: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`_pairings`, by :func:`_free_pairings` for the matrices without gap penalty."""
    free = gaps == 0.0
    found = dict(zip(np.flatnonzero(free), _free_pairings(score[:, free]) if free.any() else []))
    found |= dict(zip(np.flatnonzero(~free), _pairings(score[:, ~free], gaps[~free]) if (~free).any() else []))
    return [found[k] for k in range(len(gaps))]


def _pairings(score: np.ndarray, gaps: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The pairings of :func:`monotone_pairs` of k score matrices given as (n, k, m), each
    with its own gap (k,), all at once: one numpy pass per row along the shorter side, which
    keeps with each best sum where the pair before it lies, then one pass per pair back."""
    if score.shape[0] > score.shape[2]:
        return [(rows, columns) for columns, rows in _pairings(np.transpose(score, (2, 1, 0)), gaps)]
    n, k, m = score.shape
    gap = np.asarray(gaps, dtype=np.float64)[:, None]
    columns = np.arange(m)
    offsets = (np.arange(k) * m)[:, None]
    total = np.empty((n, k, m))  # the best sum whose last pair is (i, j)
    back = np.full((n, k, m), -1, dtype=np.int32)  # where the pair before it lies (i * m + j), -1: none
    above, above_row = np.full((k, m), -np.inf), np.full((k, m), -1)  # best sum per column over the rows < i - 1
    last = np.full((k, m), -np.inf)  # row i - 1 of total
    reach, run, value = np.empty((k, m)), np.empty((k, m)), np.zeros((k, m))
    pointer, run_column = np.empty((k, m), dtype=np.int64), np.empty((k, m), dtype=np.int64)
    for i in range(n):
        # reach: the best sum ending in each column that a pair of row i may follow in the next
        # column (row i - 1, or an earlier row with a gap); run: the same with columns skipped
        np.subtract(above, gap, out=reach)
        reach_row = np.where(last >= reach, i - 1, above_row)
        np.maximum(reach, last, out=reach)
        np.maximum.accumulate(reach, axis=1, out=run)
        np.multiply(reach == run, columns, out=run_column)
        np.maximum.accumulate(run_column, axis=1, out=run_column)
        value[:, 1:] = reach[:, :-1]
        np.multiply(reach_row[:, :-1], m, out=pointer[:, 1:])
        pointer[:, 1:] += columns[:-1]
        run -= gap
        take = run[:, :-2] > value[:, 2:]
        np.copyto(value[:, 2:], run[:, :-2], where=take)
        skipped = reach_row.ravel()[run_column[:, :-2] + offsets] * m + run_column[:, :-2]
        np.copyto(pointer[:, 2:], skipped, where=take)
        follows = value > 0.0  # else a first pair
        np.add(score[i], np.maximum(value, 0.0), out=total[i])
        np.copyto(back[i], pointer, where=follows)
        better = last > above
        np.copyto(above, last, where=better)
        np.copyto(above_row, i - 1, where=better)
        last = total[i]
    return _trace(total, back)


def _free_pairings(score: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`_pairings` without gap penalty, where a pair follows the best sum ending in any
    earlier row and column: fewer passes per row."""
    if score.shape[0] > score.shape[2]:
        return [(rows, columns) for columns, rows in _free_pairings(np.transpose(score, (2, 1, 0)))]
    n, k, m = score.shape
    columns = np.arange(m)
    offsets = (np.arange(k) * m)[:, None]
    total = np.empty((n, k, m))
    back = np.full((n, k, m), -1, dtype=np.int32)
    best, best_row = np.zeros((k, m)), np.full((k, m), -1)  # best sum per column over the rows < i (0: none)
    run, run_column = np.empty((k, m)), np.empty((k, m), dtype=np.int64)
    for i in range(n):
        np.maximum.accumulate(best, axis=1, out=run)
        np.multiply(best == run, columns, out=run_column)
        np.maximum.accumulate(run_column, axis=1, out=run_column)
        total[i, :, 0] = score[i, :, 0]
        np.add(score[i, :, 1:], run[:, :-1], out=total[i, :, 1:])
        before = best_row.ravel()[run_column[:, :-1] + offsets]
        np.copyto(back[i, :, 1:], before * m + run_column[:, :-1], where=before >= 0)
        better = total[i] > best
        np.copyto(best, total[i], where=better)
        np.copyto(best_row, i, where=better)
    return _trace(total, back)


def _trace(total: np.ndarray, back: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The pairing of highest sum of each of k tables (n, k, m), followed back pair by pair
    (``back``: where the pair before lies, ``i * m + j``; -1: none), all at once."""
    n, k, m = total.shape
    flat_total, flat_back = (np.swapaxes(table, 0, 1).reshape(k, -1) for table in (total, back))
    current, path = np.argmax(flat_total, axis=1), []
    jobs = np.arange(k)
    while (current >= 0).any():
        path.append(current)
        current = np.where(current >= 0, flat_back[jobs, np.maximum(current, 0)], -1)
    path = np.array(path)
    found = []
    for job in range(k):
        steps = path[:, job][::-1]
        steps = steps[steps >= 0].astype(np.int64)
        found.append((steps // m, steps % m))
    return found
