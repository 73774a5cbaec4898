"""Low-resolution comparison of two folds: Carson's factor D experiment (1996; math doc §12.1).

Two protein chains are paired residue by residue (by numbering, by sequence for the same
protein numbered otherwise, or by a structural alignment) and superposed on their paired
Cα. The **core set** is the reference on which every fit is judged: the pairs within a
cutoff after an iterative fit, or a residue list given by the user. Then fits computed on
less data are evaluated on the core set:

* every m-th paired Cα (m = 2, 4, 8, 16), from every starting offset;
* the residue points ``C^r`` of both chains' ribbons at the integer level ``J − k``, on all
  pairs and on every ``2**k``-th pair from every offset (as much data as the level keeps);

each fit's motion is applied to the second chain's Cα and the rms over the core pairs
reported. The TM-score of the superposition on all pairs is normalised by the length of
the first chain. Whatever the pairing, :class:`FoldMatch` sums it up as TM-align does (the
TM-score superposition, normalised by either chain, the aligned pairs, their rms and sequence
identity); chains of different folds have no core set, and then no fits on fewer data either.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.analysis.database import Termini
from core.analysis.deviation import level_residue_points
from core.analysis.fold_alignment import PAIR_CUTOFF, align_folds, tm_d0, tm_d8, tm_superpose
from core.analysis.superpose import MIN_PAIRS, Superposition, align_sequences, fit_closest, superpose
from core.protein.ribbon import RibbonKind, build_ribbon
from core.protein.structure import BackboneSegment

PAIRINGS = ("auto", "numbering", "alignment", "structure")
"""How :func:`pair_residues` may pair residues."""
SAME_PROTEIN = 0.9
"""Sequence identity (of the shorter chain) from which two chains are the same protein,
paired by sequence whatever their conformations."""
SAME_FOLD = 0.5
"""TM-score from which two chains have the same fold (Xu & Zhang 2010)."""


@dataclass(frozen=True)
class FoldMatch:
    """A pairing summed up as TM-align does (:func:`fold_match`).

    Attributes
    ----------
    tm_score_a, tm_score_b : TM-score of the aligned pairs, normalised by chain a's and by
        chain b's length (each with its d0 and its own TM-score superposition).
    n_aligned : pairs closer than :func:`~core.analysis.fold_alignment.tm_d8` of the shorter
        chain after the TM-score superposition (normalised by chain a).
    rms_aligned : their rms distance after that superposition, Å.
    identity : the fraction of them with the same residue name.
    """

    tm_score_a: float
    tm_score_b: float
    n_aligned: int
    rms_aligned: float
    identity: float

    @property
    def same_fold(self) -> bool:
        """Whether either TM-score reaches :data:`SAME_FOLD`."""
        return max(self.tm_score_a, self.tm_score_b) >= SAME_FOLD


@dataclass(frozen=True)
class Fit:
    """One superposition computed on a subset of points, judged on the core set.

    Attributes
    ----------
    points : 'CA' (paired Cα) or 'C^r' (residue points of the curves at level J − depth).
    depth : 0 for Cα, k for the level-(J − k) curves.
    every, start : every ``every``-th pair from pair ``start`` (1-based).
    n_fit : point pairs the fit used.
    rms_core : rms distance of the core pairs after the fit, Å.
    """

    points: str
    depth: int
    every: int
    start: int
    n_fit: int
    rms_core: float


@dataclass(frozen=True, eq=False)
class Comparison:
    """Result of :func:`compare_chains`.

    Attributes
    ----------
    pairing : 'numbering', 'alignment' or 'structure'.
    pairs_a, pairs_b : (n_pairs,) int64, paired residue indices in each chain.
    length_a, length_b : residues of each chain.
    rms_all : rms over all pairs of the fit on all paired Cα, Å.
    tm_score, d0 : TM-score of that fit, normalised by ``length_a``, and its d0 (Å).
    core : (n_pairs,) bool, the core set.
    core_rule : how the core set was chosen.
    rms_core : rms over the core pairs of the fit on the core pairs, Å (NaN without a core set).
    fits : every fit on fewer data, in the order Cα by step, then C^r by depth; none when the
        core set has fewer than 3 pairs.
    match : the pairing summed up as TM-align does.
    """

    pairing: str
    pairs_a: np.ndarray
    pairs_b: np.ndarray
    length_a: int
    length_b: int
    rms_all: float
    tm_score: float
    d0: float
    core: np.ndarray
    core_rule: str
    rms_core: float
    fits: tuple[Fit, ...]
    match: FoldMatch

    @property
    def n_pairs(self) -> int:
        return len(self.pairs_a)

    @property
    def n_core(self) -> int:
        return int(self.core.sum())


def pair_residues(
    chain_a: Sequence[BackboneSegment], chain_b: Sequence[BackboneSegment], pairing: str = "auto"
) -> tuple[np.ndarray, np.ndarray, str]:
    """Pair the residues of two chains (each a sequence of segments, in order).

    ``'numbering'`` pairs equal residue numbers and insertion codes; ``'alignment'`` aligns
    the residue-name sequences (:func:`core.analysis.superpose.align_sequences`); ``'structure'``
    pairs the residues by where the Cα lie (:func:`core.analysis.fold_alignment.align_folds`,
    started also from the sequence alignment; its pairs within
    :data:`~core.analysis.fold_alignment.PAIR_CUTOFF`, or all of them for unrelated folds),
    which homologues need. ``'auto'`` decides as
    :func:`pair_by_sequence` does.

    Returns
    -------
    (indices into chain a, indices into chain b, the pairing used)
    """
    pairs_a, pairs_b, pairing, _ = _pairs_and_alignment(chain_a, chain_b, pairing)
    return pairs_a, pairs_b, pairing


def _pairs_and_alignment(chain_a: Sequence[BackboneSegment], chain_b: Sequence[BackboneSegment], pairing: str
                         ) -> tuple[np.ndarray, np.ndarray, str, tuple[np.ndarray, np.ndarray]]:
    """:func:`pair_residues` and the pairs to sum up as TM-align does: the whole structural
    alignment for ``'structure'``, the same pairs otherwise."""
    pairs_a, pairs_b, pairing = pair_by_sequence(chain_a, chain_b, pairing)
    if pairing != "structure":
        return pairs_a, pairs_b, pairing, (pairs_a, pairs_b)
    ca_a, ca_b = (np.concatenate([s.ca for s in chain]) for chain in (chain_a, chain_b))
    start = (pairs_a, pairs_b) if len(pairs_a) >= MIN_PAIRS else (None, None)
    alignment = align_folds(ca_a, ca_b, *start)
    equivalent = alignment.within(ca_a, ca_b, PAIR_CUTOFF)
    if len(equivalent[0]) < MIN_PAIRS:  # unrelated folds: what the alignment found
        equivalent = alignment.pairs_a, alignment.pairs_b
    return *equivalent, "structure", (alignment.pairs_a, alignment.pairs_b)


def fold_match(ca_a: np.ndarray, ca_b: np.ndarray, pairs_a: np.ndarray, pairs_b: np.ndarray,
               names_a: np.ndarray, names_b: np.ndarray, step: int = 1) -> FoldMatch:
    """TM-align's summary of paired Cα (3 pairs or more): the pairs within ``tm_d8`` of the
    shorter chain after the TM-score superposition, their TM-score normalised by either
    chain, rms and sequence identity (``names_*``: residue names of each chain). ``step``:
    the TM-score searches start from fragments at every ``step``-th pair (1: TM-align's final
    search; larger is quicker)."""
    length_a, length_b = len(ca_a), len(ca_b)
    motion, _ = tm_superpose(ca_a[pairs_a], ca_b[pairs_b], length_a, step)
    distance = np.linalg.norm(ca_a[pairs_a] - motion.apply(ca_b[pairs_b]), axis=1)
    close = distance < tm_d8(min(length_a, length_b))
    if close.sum() < MIN_PAIRS:
        close = np.argsort(distance)[:MIN_PAIRS]
    a, b = pairs_a[close], pairs_b[close]
    motion_a, score_a = tm_superpose(ca_a[a], ca_b[b], length_a, step)
    _, score_b = tm_superpose(ca_a[a], ca_b[b], length_b, step)
    rms = float(np.sqrt(np.mean(np.sum((ca_a[a] - motion_a.apply(ca_b[b])) ** 2, axis=1))))
    return FoldMatch(score_a, score_b, len(a), rms, float(np.mean(names_a[a] == names_b[b])))


def pair_by_sequence(
    chain_a: Sequence[BackboneSegment], chain_b: Sequence[BackboneSegment], pairing: str = "auto"
) -> tuple[np.ndarray, np.ndarray, str]:
    """The pairing of :func:`pair_residues` as far as the sequences decide it.

    ``'auto'`` uses the numbering when the residues it pairs carry the same names and cover
    at least half of the shorter chain, the sequence alignment when it finds the same
    protein (:data:`SAME_PROTEIN`), and otherwise says ``'structure'``: the chains are of
    different proteins and the pairs returned, the sequence alignment's, only a start for
    the structural alignment (as for ``pairing='structure'``).

    Returns
    -------
    (indices into chain a, indices into chain b, 'numbering', 'alignment' or 'structure')
    """
    if pairing not in PAIRINGS:
        raise ValueError(f"pairing must be one of {', '.join(map(repr, PAIRINGS))}; got {pairing!r}")
    labels_a, labels_b = _labels(chain_a), _labels(chain_b)
    where_b = {label: k for k, label in enumerate(labels_b)}
    pairs_a = np.array([k for k, label in enumerate(labels_a) if label in where_b], dtype=np.int64)
    pairs_b = np.array([where_b[labels_a[k]] for k in pairs_a], dtype=np.int64)
    names_a, names_b = _names(chain_a), _names(chain_b)
    agree = len(pairs_a) > 0 and bool(np.all(names_a[pairs_a] == names_b[pairs_b]))
    if pairing == "numbering" or (pairing == "auto" and agree and 2 * len(pairs_a) >= min(len(labels_a), len(labels_b))):
        return pairs_a, pairs_b, "numbering"
    pairs_a, pairs_b = align_sequences(names_a.tolist(), names_b.tolist())
    identity = np.count_nonzero(names_a[pairs_a] == names_b[pairs_b]) / min(len(names_a), len(names_b))
    if pairing == "alignment" or (pairing == "auto" and identity >= SAME_PROTEIN):
        return pairs_a, pairs_b, "alignment"
    return pairs_a, pairs_b, "structure"


def tm_score(distances: np.ndarray, length: int) -> tuple[float, float]:
    """TM-score of paired distances (Å) normalised by ``length`` residues, and its d0.

    ``d0 = 1.24 (L − 15)^(1/3) − 1.8``, at least 0.5 Å (as TM-align does for short chains).
    """
    if length < 1:
        raise ValueError(f"length must be >= 1; got {length}")
    d0 = tm_d0(length)
    return float(np.sum(1.0 / (1.0 + (np.asarray(distances) / d0) ** 2)) / length), d0


def compare_chains(
    chain_a: Sequence[BackboneSegment],
    chain_b: Sequence[BackboneSegment],
    *,
    core_residues: np.ndarray | None = None,
    cutoff: float = 1.0,
    steps: Sequence[int] = (2, 4, 8, 16),
    depths: Sequence[int] = (1, 2, 3, 4),
    ribbon: RibbonKind | str = RibbonKind.PEPTIDE,
    termini: Termini | str = Termini.ATOMS,
    pairing: str = "auto",
) -> Comparison:
    """Superpose chain b on chain a and judge fits on fewer data on the core set.

    Parameters
    ----------
    chain_a, chain_b : the backbone segments of each chain, in order.
    core_residues : (n_a,) bool over chain a's residues: the core set given by the user
        (pairs whose chain-a residue is marked). None: the iterative cutoff rule.
    cutoff : Å; the core set is the pairs closer than this after fitting on the core set
        itself, iterated from all pairs until it no longer changes.
    steps : subsampling steps of the Cα fits.
    depths : k of the C^r fits on the level-(J − k) curves (J of each segment).
    ribbon, termini : the curve construction (see :mod:`core.protein.ribbon`, :class:`Termini`).
    pairing : see :func:`pair_residues`.

    Raises
    ------
    ValueError
        Fewer than 3 pairs, or a core set given by the user of fewer than 3 pairs (a core
        set found by the cutoff rule may have fewer: then there are no fits on fewer data).
    """
    pairs_a, pairs_b, pairing, aligned = _pairs_and_alignment(chain_a, chain_b, pairing)
    if len(pairs_a) < MIN_PAIRS:
        raise ValueError(f"only {len(pairs_a)} residue pair(s) between the chains; at least {MIN_PAIRS} are needed")
    match = fold_match(*(np.concatenate([s.ca for s in chain]) for chain in (chain_a, chain_b)), *aligned,
                       _names(chain_a), _names(chain_b))
    ca_a = np.concatenate([s.ca for s in chain_a])[pairs_a]
    ca_b = np.concatenate([s.ca for s in chain_b])[pairs_b]
    everything = superpose(ca_a, ca_b)
    distances = _distances(ca_a, ca_b, everything)
    length_a = sum(len(s) for s in chain_a)
    tm, d0 = tm_score(distances, length_a)
    if core_residues is None:
        core, rule = _iterative_core(ca_a, ca_b, cutoff), f"pairs within {cutoff:g} Å after an iterative fit"
    else:
        core, rule = np.asarray(core_residues, dtype=bool)[pairs_a], "residues given by the user"
    if core.sum() < MIN_PAIRS and core_residues is not None:
        raise ValueError(f"the core set has {int(core.sum())} pair(s); at least {MIN_PAIRS} are needed")
    fits: list[Fit] = []
    if core.sum() < MIN_PAIRS:  # different folds: nothing to judge fits on
        return Comparison(pairing, pairs_a, pairs_b, length_a, sum(len(s) for s in chain_b), _rms(distances), tm,
                          d0, core, rule, float("nan"), (), match)
    best = superpose(ca_a[core], ca_b[core])

    def judged(points: str, depth: int, every: int, fit_a: np.ndarray, fit_b: np.ndarray) -> list[Fit]:
        found = []
        for start in range(every):
            a, b = fit_a[start::every], fit_b[start::every]
            usable = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
            if usable.sum() >= MIN_PAIRS:
                motion = superpose(a[usable], b[usable])
                rms = _rms(_distances(ca_a[core], ca_b[core], motion))
                found.append(Fit(points, depth, every, start + 1, int(usable.sum()), rms))
        return found

    fits += judged("CA", 0, 1, ca_a, ca_b)
    for every in steps:
        fits += judged("CA", 0, every, ca_a, ca_b)
    kind, termini = RibbonKind(ribbon), Termini(termini)
    for depth in depths:
        cr_a = _curve_points(chain_a, depth, kind, termini)[pairs_a]
        cr_b = _curve_points(chain_b, depth, kind, termini)[pairs_b]
        fits += judged("C^r", depth, 1, cr_a, cr_b)
        fits += judged("C^r", depth, 2**depth, cr_a, cr_b)
    return Comparison(
        pairing=pairing,
        pairs_a=pairs_a,
        pairs_b=pairs_b,
        length_a=length_a,
        length_b=sum(len(s) for s in chain_b),
        rms_all=_rms(distances),
        tm_score=tm,
        d0=d0,
        core=core,
        core_rule=rule,
        rms_core=_rms(_distances(ca_a[core], ca_b[core], best)),
        fits=tuple(fits),
        match=match,
    )


def _iterative_core(ca_a: np.ndarray, ca_b: np.ndarray, cutoff: float) -> np.ndarray:
    """Pairs within ``cutoff`` after fitting on themselves, iterated from all pairs (fewer
    than 3 where the set collapses)."""
    if not (math.isfinite(cutoff) and cutoff > 0):
        raise ValueError(f"cutoff must be > 0 Å; got {cutoff:g}")
    motion, _ = fit_closest(ca_a, ca_b, cutoff, rounds=50)
    return _distances(ca_a, ca_b, motion) < cutoff


def _curve_points(chain: Sequence[BackboneSegment], depth: int, kind: RibbonKind, termini: Termini) -> np.ndarray:
    """(n, 3) residue points of every segment's ribbon at level J − depth (NaN below level 0)."""
    blocks = []
    for segment in chain:
        ends = {"n_start": segment.n[0], "c_end": segment.c[-1]} if termini is Termini.ATOMS else {}
        ribbon = build_ribbon(kind, segment.ca, **ends)
        level = ribbon.level - depth
        blocks.append(level_residue_points(ribbon)[level] if level >= 0 else np.full((len(segment), 3), np.nan))
    return np.concatenate(blocks)


def _labels(chain: Sequence[BackboneSegment]) -> list[tuple[int, str]]:
    return [(number, icode) for s in chain for number, icode in zip(s.resseq.tolist(), s.icode.tolist())]


def _names(chain: Sequence[BackboneSegment]) -> np.ndarray:
    return np.concatenate([s.resname for s in chain])


def _distances(fixed: np.ndarray, moving: np.ndarray, motion: Superposition) -> np.ndarray:
    return np.linalg.norm(fixed - motion.apply(moving), axis=1)


def _rms(distances: np.ndarray) -> float:
    return float(np.sqrt(np.mean(distances**2)))
