"""Fold search: every protein chain of a database as the string of its residues' 3Di states
and amino acids, scored against the query's by local alignment, the best aligned by structure.

:func:`search` works as Foldseek does (van Kempen et al. 2024), from Cα alone:

1. Each chain is read as two strings (:mod:`core.analysis.structural_alphabet`): the 3Di state
   of each residue (its backbone's geometry and that of its nearest residue in space) and its
   amino acid. The Smith–Waterman score of the query against every chain
   (:func:`alignment_scores`, :mod:`core.analysis.local_alignment`: 3Di substitution scores
   plus :data:`AMINO_ACID_WEIGHT` times BLOSUM62, affine gaps) ranks the database, about
   1,150 million cells a CPU second, and gives each chain an E-value (:func:`evalues`). The
   chains rank by their score made fair to length (:func:`length_fair`), as by E-value: an
   unrelated long chain scores higher by chance.
2. The :data:`ALIGNED` best, and the :data:`PROFILED` others nearest the query's profile of
   3Di state pairs, are aligned by structure: their local alignment, refined by two
   rounds of TM-align's dynamic programming on the superposed chains (:func:`refine_pairs`),
   gives the TM-score, rms and identity of each (:class:`~core.analysis.compare.FoldMatch`).
   They come first, by their fold score, the TM-score plus :data:`SCORE_SHARE` times the
   length-fair score relative to the query's with itself; the others follow by that score.

On both halves of SCOP40 (Foldseek's benchmark, ``benchmarks/bench_fold_search.py``) this
finds more superfamilies and folds than exhaustive TM-align, at less than 1/150 of its CPU:
the cost of a query grows with the database only by its first step. Whole PDB chains added
to the index as decoys take more of its superfamily matches than of TM-align's on the
benchmark's held-out half (the README's table).

A query against a large index (the PDB has 800,000 chains) may spend :data:`SCORED_CELLS` cells
of local alignment, about a CPU second (:func:`chains_scored`): the chains it scores are the
nearest to it, half by each of the index's two summaries of a chain
(:mod:`core.analysis.fold_index`: Carson's coarse curves and the profile of consecutive 3Di
state pairs). For a query of 200 residues among 800,000 chains of 200 on average, that is the
12,500 nearest by each; on SCOP40's two halves they keep 75–86% of the family matches, 60% of
the superfamily and 36–52% of the fold matches at that scale; neither summary knows domains.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.analysis.compare import SAME_FOLD, FoldMatch, fold_match
from core.analysis.fold_alignment import refine_pairs
from core.analysis.fold_index import (
    FoldIndex,
    curve_descriptor,
    descriptor_distances,
    pair_profile,
    profile_similarities,
)
from core.analysis.local_alignment import local_pairs, local_scores
from core.analysis.structural_alphabet import AMINO_ACID_SCORES, STATE_SCORES, amino_acid_codes, states
from core.analysis.superpose import MIN_PAIRS

AMINO_ACID_WEIGHT = 0.6
"""Weight of the amino acids' BLOSUM62 score beside the 3Di states' in the local alignment."""
GAP_OPEN, GAP_EXTEND = 10.0, 1.0
"""Cost of a gap's first residue and of each further one in the local alignment, half bits."""
SCORE_SLOPE, SCORE_LOCATION, SCORE_SCALE = 15.2322, -113.9755, 18.8031
"""The local alignment scores of unrelated chains of m and n residues: ``SCORE_SLOPE ln(m n)``
plus a Gumbel variable of this location and scale (``scripts/train_fold_scores.py``)."""
SCORED_CELLS = 1_000_000_000
"""Cells of local alignment (query residues × chain residues) a query may spend, about a CPU
second: against an index of more, only the chains nearest the query are scored (:func:`chains_scored`)."""
ALIGNED = 30
"""Chains of best local alignment score that :func:`search` aligns by structure."""
PROFILED = 10
"""Chains nearest the query's pair profile that :func:`search` aligns by structure as well,
whatever their alignment score (remote matches whose 3Di strings align poorly)."""
REFINE_ROUNDS = 2
"""Rounds of TM-align's refinement of their local alignment (:func:`refine_pairs`)."""
MATCH_STEP = 8
"""The TM-score searches of the hits' matches start from fragments at every 8th pair (their
TM-scores within 0.004 of every 4th pair's on SCOP40's development half, at less cost)."""
SCORE_SHARE = 1.0
"""Weight of the alignment score (:func:`length_fair`, relative to the query's with itself)
beside the TM-score in the fold score that orders the chains aligned by structure."""
TOP, MAX_EVALUE = 100, 10.0
"""Hits :func:`search` lists at most, and the E-value above which it leaves a hit out."""

def query_profile(chain_states: np.ndarray, sequence: np.ndarray, state_scores: np.ndarray = STATE_SCORES
                  ) -> np.ndarray:
    """(m, 20 × 21) float32: the score of each residue of a chain (its 3Di states and one-letter
    codes) against each residue code (:func:`residue_codes`): its 3Di substitution score plus
    :data:`AMINO_ACID_WEIGHT` times its BLOSUM62 score, half bits."""
    scores = (np.asarray(state_scores, dtype=np.float32)[:, None, :, None]
              + np.float32(AMINO_ACID_WEIGHT) * AMINO_ACID_SCORES.astype(np.float32)[None, :, None, :])
    return np.ascontiguousarray(scores.reshape(420, 420)[residue_codes(chain_states, sequence)])


def residue_codes(chain_states: np.ndarray, sequence: np.ndarray) -> np.ndarray:
    """(n,) int16: each residue's 3Di state and amino acid as one code, ``21 state + amino acid``."""
    return np.asarray(chain_states, dtype=np.int16) * 21 + amino_acid_codes(sequence)


def alignment_scores(index: FoldIndex, profile: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(len(rows),) float32: the local alignment score (half bits; gaps :data:`GAP_OPEN`,
    :data:`GAP_EXTEND`) of the query's ``profile`` (:func:`query_profile`) against chains
    ``rows`` of ``index``. Reads their states and sequences (2 bytes a residue), not their Cα."""
    rows = np.asarray(rows, dtype=np.int64)
    lengths = index.lengths[rows]
    if len(rows) == len(index) and np.array_equal(rows, np.arange(len(index))):
        codes, starts = residue_codes(index.states, index.sequences), index.starts
    else:
        pieces = [slice(int(first), int(first + length)) for first, length in zip(index.starts[rows], lengths)]
        codes = residue_codes(np.concatenate([index.states[piece] for piece in pieces] or [np.zeros(0, np.uint8)]),
                              np.concatenate([index.sequences[piece] for piece in pieces] or [np.zeros(0, "S1")]))
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    return local_scores(profile, codes, starts, lengths, GAP_OPEN, GAP_EXTEND)


def chains_scored(index: FoldIndex, query_length: int) -> int:
    """How many chains of ``index`` :func:`search` scores by local alignment for a query of
    ``query_length`` residues: every chain, or as many chains of the index's mean length as
    :data:`SCORED_CELLS` holds (an even number, at least 2)."""
    residues = int(index.lengths.sum())
    if query_length * residues <= SCORED_CELLS:
        return len(index)
    return max(2, int(SCORED_CELLS * len(index) / (query_length * residues)) // 2 * 2)


def length_fair(scores: np.ndarray, query_length: int, lengths: np.ndarray) -> np.ndarray:
    """Local alignment ``scores`` of chains of ``lengths`` as if each were as long as the query:
    less :data:`SCORE_SLOPE` ``ln(n / m)``, by which the scores of unrelated chains grow with
    length (a long chain scores higher by chance). They rank as the E-values do, without their
    ties where E-values underflow to 0 (a score of about 14,000 half bits: a large chain's own)."""
    return (np.asarray(scores, dtype=np.float64)
            - SCORE_SLOPE * np.log(np.asarray(lengths, dtype=np.float64) / float(query_length)))


def evalues(scores: np.ndarray, query_length: int, lengths: np.ndarray, chains: int) -> np.ndarray:
    """The expected number of chains of unrelated folds, among ``chains``, that align to a
    query of ``query_length`` residues with a score of ``scores`` or more (chains of
    ``lengths``): a Gumbel tail whose location grows with ``ln(m n)`` (:data:`SCORE_SLOPE`,
    :data:`SCORE_LOCATION`, :data:`SCORE_SCALE`, fitted on unrelated chains)."""
    chance = SCORE_SLOPE * 2.0 * np.log(float(query_length)) + SCORE_LOCATION  # (a chain of the query's length)
    shift = (length_fair(scores, query_length, lengths) - chance) / SCORE_SCALE
    return chains * -np.expm1(-np.exp(-shift))


@dataclass(frozen=True)
class Hit:
    """One chain found by :func:`search`: its place in the index, the local alignment score of
    its 3Di states and amino acids with the query's (half bits) and its E-value; for the
    chains aligned by structure, the structural match of the query (chain a) with it (chain b)
    and the fold score that orders them (None for the others)."""

    row: int
    entry: str
    chain: str
    path: str
    length: int
    score: float
    evalue: float
    match: FoldMatch | None
    fold_score: float | None


def search(index: FoldIndex, ca: np.ndarray, sequence: str, top: int = TOP, aligned: int = ALIGNED,
           max_evalue: float = MAX_EVALUE) -> list[Hit]:
    """The chains of ``index`` most like the query, best first: at most ``top``, each with an
    E-value of ``max_evalue`` or less or a TM-score of :data:`~core.analysis.compare.SAME_FOLD`
    or more.

    Every chain (of a large index, the :func:`chains_scored` nearest the query, half by
    descriptor and half by pair profile) is scored by the local alignment
    of its 3Di states and amino acids with the query's. The best ``aligned`` by that score
    made fair to length (:func:`length_fair`), and the :data:`PROFILED` others nearest the
    query's pair profile, are aligned by structure and come first, by their fold score: the
    TM-score (normalised by the query) plus :data:`SCORE_SHARE` times the length-fair score
    relative to the query's with itself. The rest follow by the length-fair score.

    Parameters
    ----------
    ca : (n >= 3, 3) the query's Cα, Å; sequence : its one-letter codes (n).
    """
    ca = np.asarray(ca, dtype=np.float64)
    names = np.frombuffer(sequence.encode("ascii", "replace"), dtype="S1")
    query_states = states(ca)
    profile = query_profile(query_states, names)
    similarity = profile_similarities(index.profiles, pair_profile(query_states))
    scored = chains_scored(index, len(ca))
    if scored < len(index):
        distance = descriptor_distances(index.descriptors, curve_descriptor(ca))
        half = scored // 2
        rows = np.union1d(np.argpartition(distance, half)[:half], np.argpartition(-similarity, half)[:half])
    else:
        rows = np.arange(len(index))
    scores = alignment_scores(index, profile, rows)
    own = float(local_scores(profile, residue_codes(query_states, names), np.zeros(1, np.int64),
                             np.array([len(ca)]), GAP_OPEN, GAP_EXTEND)[0])
    expected = evalues(scores, len(ca), index.lengths[rows], len(index))
    fair = length_fair(scores, len(ca), index.lengths[rows])
    order = np.argsort(-fair, kind="stable")
    chosen = order[:aligned].tolist()
    taken = set(chosen)
    chosen += [k for k in np.argsort(-similarity[rows], kind="stable")[:aligned + PROFILED].tolist()
               if k not in taken][:PROFILED]
    matches, fold_scores = {}, {}
    for k in chosen:
        row = int(rows[k])
        other, other_names = index.chain(row)
        other_states = np.asarray(index.states[index.starts[row]:index.starts[row] + index.lengths[row]])
        pairs_a, pairs_b, _ = local_pairs(profile, residue_codes(other_states, other_names), GAP_OPEN, GAP_EXTEND)
        if len(pairs_a) >= MIN_PAIRS:
            pairs_a, pairs_b = refine_pairs(ca, other, pairs_a, pairs_b, REFINE_ROUNDS)
        if len(pairs_a) >= MIN_PAIRS:
            matches[k] = fold_match(ca, other, pairs_a, pairs_b, names, other_names, MATCH_STEP)
            fold_scores[k] = matches[k].tm_score_a + SCORE_SHARE * float(fair[k]) / max(own, 1.0)
    ranked = sorted(fold_scores, key=lambda k: -fold_scores[k]) + [k for k in order.tolist() if k not in fold_scores]
    hits = []
    for k in ranked:
        match = matches.get(k)
        if expected[k] > max_evalue and (match is None or match.tm_score_a < SAME_FOLD):
            continue
        row = int(rows[k])
        hits.append(Hit(row, str(index.entries[row]), str(index.chains[row]), str(index.paths[row]),
                        int(index.lengths[row]), float(scores[k]), float(expected[k]), match, fold_scores.get(k)))
        if len(hits) == top:
            break
    return hits


def sensitivity(ranked: np.ndarray, family: np.ndarray, superfamily: np.ndarray, fold: np.ndarray,
                query: int) -> np.ndarray | None:
    """Foldseek's measure of one search: per level (same family; same superfamily, other family;
    same fold, other superfamily), the share of the query's true positives that ``ranked``
    (rows, best first; the query itself ignored) lists before the first chain of another fold.
    ``family``, ``superfamily`` and ``fold`` label every row; None when a level has no true positive."""
    kinds = np.select([family == family[query], superfamily == superfamily[query], fold == fold[query]], [0, 1, 2], 3)
    kinds[query] = -1
    totals = np.bincount(kinds[kinds >= 0], minlength=4)[:3]
    if not totals.all():
        return None
    listed = kinds[np.asarray(ranked)[np.asarray(ranked) != query]]
    false = np.flatnonzero(listed == 3)
    before = listed[:false[0]] if len(false) else listed
    return np.bincount(before[before >= 0], minlength=4)[:3] / totals
