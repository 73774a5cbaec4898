"""Structural alignment: the compiled kernels against references (the pairing dynamic
programme against every pairing of small matrices and a transcription of TM-align's, the
superposition against gemmi's), the TM-score search, real serine proteases paired by
structure where their sequences mislead, and TM-scores as TM-align finds them (recorded, and
run side by side through tmtools) for close, remote and unrelated folds."""

from itertools import combinations
from pathlib import Path

import numpy as np
import pytest
import tmtools
from scipy.spatial.transform import Rotation

from core.analysis.compare import pair_residues, tm_score
from core.analysis.fold_alignment import STATE_GAP, align_folds, align_structures, monotone_pairs, tm_d0, tm_superpose
from core.analysis.superpose import superpose
from core.analysis.tm_align import kabsch
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def _value(score: np.ndarray, rows: np.ndarray, columns: np.ndarray, gap: float) -> float:
    """Paired scores less ``gap`` per run of rows and per run of columns skipped between two pairs."""
    gaps = np.count_nonzero(np.diff(rows) > 1) + np.count_nonzero(np.diff(columns) > 1)
    return float(score[rows, columns].sum() - gap * gaps)


def _best_by_enumeration(score: np.ndarray, gap: float) -> float:
    n, m = score.shape
    best = 0.0
    for k in range(1, min(n, m) + 1):
        for rows in combinations(range(n), k):
            for columns in combinations(range(m), k):
                best = max(best, _value(score, np.array(rows), np.array(columns), gap))
    return best


def _tm_align_pairing(score: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """TM-align's NWDP_TM as its C++ writes it: full tables, the gap opened after a pair."""
    n, m = score.shape
    value, diagonal = np.zeros((n + 1, m + 1)), np.zeros((n + 1, m + 1), dtype=bool)

    def across(i: int, j: int) -> tuple[float, float]:
        return (value[i - 1, j] - gap * diagonal[i - 1, j], value[i, j - 1] - gap * diagonal[i, j - 1])

    for i in range(1, n + 1):
        for j in range(1, m + 1):
            d = value[i - 1, j - 1] + score[i - 1, j - 1]
            h, v = across(i, j)
            diagonal[i, j] = d >= h and d >= v
            value[i, j] = d if diagonal[i, j] else max(h, v)
    rows, columns, i, j = [], [], n, m
    while i > 0 and j > 0:
        if diagonal[i, j]:
            rows.append(i - 1)
            columns.append(j - 1)
            i, j = i - 1, j - 1
        else:
            h, v = across(i, j)
            i, j = (i, j - 1) if v >= h else (i - 1, j)
    return np.array(rows[::-1], dtype=np.int64), np.array(columns[::-1], dtype=np.int64)


@pytest.mark.parametrize("seed", range(24))
def test_the_pairing_is_tm_align_s_and_without_gap_penalty_the_best_of_all(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, m = rng.integers(1, 7, size=2)
    score = rng.random((n, m)) ** 3  # mostly small, a few large: gaps pay off sometimes
    gap = [0.0, 0.1, STATE_GAP][seed % 3]
    rows, columns = monotone_pairs(score, gap)
    assert np.all(np.diff(rows) > 0) and np.all(np.diff(columns) > 0) and len(rows) == len(columns)
    expected = _tm_align_pairing(score, gap)
    assert np.array_equal(rows, expected[0]) and np.array_equal(columns, expected[1])
    best = _best_by_enumeration(score, gap)
    assert _value(score, rows, columns, gap) <= best + 1e-12
    if gap == 0.0:
        assert _value(score, rows, columns, gap) == pytest.approx(best, abs=1e-12)


def test_the_pairing_of_real_chains_is_tm_align_s(trypsin) -> None:
    """On the TM-score terms of trypsin and S. griseus proteinase B superposed by their sequence alignment."""
    chain_a, ca_a = trypsin
    chain_b, ca_b = _longest_chain_ca(DATA / "3SGB.pdb.gz")
    pairs_a, pairs_b, _ = pair_residues(chain_a, chain_b, "alignment")
    moved = superpose(ca_a[pairs_a], ca_b[pairs_b]).apply(ca_b)
    score = 1.0 / (1.0 + np.sum((ca_a[:, None] - moved[None]) ** 2, axis=2) / 4.0**2)
    for gap in (0.0, 0.6):
        rows, columns = monotone_pairs(score, gap)
        expected = _tm_align_pairing(score, gap)
        assert np.array_equal(rows, expected[0]) and np.array_equal(columns, expected[1]) and len(rows) > 100


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_compiled_superposition_is_gemmi_s(seed: int) -> None:
    """Of random subsets of two noisy copies of triosephosphate isomerase, and of a flat and a
    straight set of points (a reflection would fit the noisy subsets better)."""
    rng = np.random.default_rng(seed)
    _, a = _longest_chain_ca(DATA / "1TIM.pdb.gz")
    b = a @ Rotation.random(random_state=seed).as_matrix().T + rng.normal(scale=1.5, size=a.shape)
    flat, line = a.copy(), np.outer(np.arange(10.0), [1.0, 2.0, 0.5])
    flat[:, 2] = 0.0
    cases = [(a, b, np.flatnonzero(rng.random(len(a)) < fraction)) for fraction in (0.02, 0.1, 0.5, 1.0)]
    cases.append((flat, b, np.arange(40)))
    for fixed, moving, rows in cases:
        rotation, translation = kabsch(moving, fixed, rows, len(rows))  # moves moving onto fixed
        direct = superpose(fixed[rows], moving[rows])
        rms = np.sqrt(np.mean(np.sum((fixed[rows] - moving[rows] @ rotation.T - translation) ** 2, axis=1)))
        assert np.linalg.det(rotation) == pytest.approx(1.0) and rms == pytest.approx(direct.rmsd, abs=1e-6)
        if len(rows) > 10:  # a unique best fit
            assert np.allclose(rotation, direct.rotation, atol=1e-6)
            assert np.allclose(translation, direct.translation, atol=1e-5)
    turned = line @ Rotation.random(random_state=seed).as_matrix().T + 3.0  # where gemmi's fit does not converge
    rotation, translation = kabsch(turned, line, np.arange(10), 10)
    assert np.allclose(turned @ rotation.T + translation, line, atol=1e-6)


def _longest_chain_ca(path: Path) -> tuple[list, np.ndarray]:
    structure = read_structure(path)
    chains = {}
    for segment in structure.segments:
        chains.setdefault(segment.chain, []).append(segment)
    chain = max(chains.values(), key=lambda segments: sum(len(s) for s in segments))
    return chain, np.concatenate([s.ca for s in chain])


@pytest.fixture(scope="module")
def trypsin() -> tuple[list, np.ndarray]:
    return _longest_chain_ca(DATA / "3PTB.pdb.gz")


def test_a_shifted_start_is_put_right(trypsin) -> None:
    _, ca = trypsin
    moved = ca @ Rotation.from_euler("xyz", [40, -20, 70], degrees=True).as_matrix().T + [10.0, -5.0, 3.0]
    start = np.arange(len(ca) - 4)
    pairs_a, pairs_b = align_structures(ca, moved, start, start + 4)  # every residue paired with the 4th after it
    assert np.array_equal(pairs_a, np.arange(len(ca))) and np.array_equal(pairs_b, pairs_a)


def _close_pairs(ca_a: np.ndarray, ca_b: np.ndarray, pairs_a: np.ndarray, pairs_b: np.ndarray) -> tuple[int, float]:
    """Pairs closer than 3 Å after fitting on them (from all pairs, until the set settles),
    and the TM-score of that fit over all pairs (normalised by chain a)."""
    a, b = ca_a[pairs_a], ca_b[pairs_b]
    close = np.ones(len(a), dtype=bool)
    for _ in range(20):
        motion = superpose(a[close], b[close])
        distance = np.linalg.norm(a - motion.apply(b), axis=1)
        close, settled = distance < 3.0, np.array_equal(distance < 3.0, close)
        if settled:
            break
    return int(close.sum()), tm_score(distance, len(ca_a))[0]


def test_a_distant_homologue_is_paired_by_structure(trypsin) -> None:
    chain_a, ca_a = trypsin
    chain_b, ca_b = _longest_chain_ca(DATA / "3SGB.pdb.gz")  # S. griseus proteinase B, 26% identical
    by_sequence = pair_residues(chain_a, chain_b, "alignment")
    by_structure = pair_residues(chain_a, chain_b)
    assert by_structure[2] == "structure"
    close_sequence, tm_sequence = _close_pairs(ca_a, ca_b, *by_sequence[:2])
    close_structure, tm_structure = _close_pairs(ca_a, ca_b, *by_structure[:2])
    assert close_sequence < 60 and close_structure > 100 and tm_structure > tm_sequence + 0.1
    pairs_a, pairs_b = by_structure[:2]
    assert np.all(np.diff(pairs_a) > 0) and np.all(np.diff(pairs_b) > 0)
    # the catalytic triad His57, Asp102, Ser195 (chymotrypsin numbering in both entries) is paired
    number_a = np.concatenate([s.resseq for s in chain_a])[pairs_a]
    number_b = np.concatenate([s.resseq for s in chain_b])[pairs_b]
    for triad in (57, 102, 195):
        assert number_b[number_a == triad].tolist() == [triad]


def test_homologues_keep_most_sequence_pairs_and_fit_better(trypsin) -> None:
    chain_a, ca_a = trypsin
    chain_b, ca_b = _longest_chain_ca(DATA / "1BMA.pdb.gz")  # porcine elastase, 41% identical
    by_sequence = pair_residues(chain_a, chain_b, "alignment")
    by_structure = pair_residues(chain_a, chain_b, "structure")
    shared = set(zip(*map(np.ndarray.tolist, by_sequence[:2]))) & set(zip(*map(np.ndarray.tolist, by_structure[:2])))
    assert len(shared) > 0.8 * len(by_sequence[0]) and len(by_structure[0]) > 200
    (close_sequence, tm_sequence), (close_structure, tm_structure) = (
        _close_pairs(ca_a, ca_b, *pairs[:2]) for pairs in (by_sequence, by_structure))
    assert close_structure > close_sequence + 10 and tm_structure > tm_sequence


def test_the_start_must_hold_three_pairs(trypsin) -> None:
    _, ca = trypsin
    with pytest.raises(ValueError, match="at least 3 pairs"):
        align_structures(ca, ca, np.arange(2), np.arange(2))


def test_the_tm_score_search_finds_the_larger_rigid_part(trypsin) -> None:
    """Trypsin with its C-terminal half turned by 40° and shifted: the TM-score search lays the
    N-terminal half back within 1 Å, where a least-squares fit on all pairs splits the
    difference and brings no Cα of it that close."""
    _, ca = trypsin
    half = len(ca) // 2 + 10
    moved = ca.copy()
    centre = ca[half:].mean(axis=0)
    moved[half:] = (ca[half:] - centre) @ Rotation.from_euler("z", 40, degrees=True).as_matrix().T + centre + 6.0
    motion, score = tm_superpose(ca, moved, len(ca))
    least_squares = superpose(ca, moved)
    distance, apart = (np.linalg.norm(ca - fit.apply(moved), axis=1) for fit in (motion, least_squares))
    assert distance[:half].max() < 1.0 and apart[:half].min() > 1.0
    assert score == pytest.approx(tm_score(distance, len(ca))[0], abs=1e-12)
    assert score > half / len(ca) and score > tm_score(apart, len(ca))[0] + 0.1
    copy, identity = tm_superpose(ca, ca, len(ca))
    assert identity == pytest.approx(1.0, abs=1e-12) and np.allclose(copy.rotation, np.eye(3), atol=1e-9)


# TM-align's TM-scores (Zhang & Skolnick 2005, through tmtools 0.3.0), normalised by the
# first chain, on the longest chain's Cα of each entry. The structural alignment need not find
# the same alignment, but one of about the same TM-score, and the same verdict at 0.5.
TM_ALIGN = [("1UBQ", "3PTB", 0.3670), ("1UBQ", "2K39_CA-only", 0.9164), ("3PTB", "3SGB", 0.6017),
            ("3PTB", "1BMA", 0.9554), ("1UBQ", "1L2Y", 0.1697), ("1BPI", "1UBQ", 0.3036), ("1UBQ", "2BEG", 0.1888)]


@pytest.mark.parametrize(("first", "second", "expected"), TM_ALIGN)
def test_tm_scores_agree_with_tm_align(first: str, second: str, expected: float) -> None:
    (_, ca_a), (_, ca_b) = (_longest_chain_ca(next(DATA.glob(f"{name}.*"))) for name in (first, second))
    alignment = align_folds(ca_a, ca_b)
    assert alignment.tm_score == pytest.approx(expected, abs=0.02) and (alignment.tm_score >= 0.5) == (expected >= 0.5)
    pairs_a, pairs_b = alignment.pairs_a, alignment.pairs_b
    assert np.all(np.diff(pairs_a) > 0) and np.all(np.diff(pairs_b) > 0) and len(pairs_a) >= 3
    distance = np.linalg.norm(ca_a[pairs_a] - alignment.motion.apply(ca_b[pairs_b]), axis=1)
    d0 = max(1.24 * (len(ca_a) - 15) ** (1 / 3) - 1.8, 0.5)  # TM-align's d0, by hand
    assert tm_d0(len(ca_a)) == pytest.approx(d0)
    assert alignment.tm_score == pytest.approx(np.sum(1 / (1 + (distance / d0) ** 2)) / len(ca_a), abs=1e-12)


def test_chains_too_short_or_not_finite_are_refused(trypsin) -> None:
    _, ca = trypsin
    with pytest.raises(ValueError, match=r"must be \(n >= 3, 3\) each"):
        align_folds(ca, ca[:2])
    broken = ca.copy()
    broken[5, 1] = np.nan
    with pytest.raises(ValueError, match="ca_b contains 1 non-finite"):
        align_folds(ca, broken)


# Side by side with TM-align on real pairs: close homologues (trypsin and elastase), remote
# ones (trypsin and S. griseus proteinase B; two TIM barrels, triosephosphate isomerase and
# 3-alpha-hydroxysteroid dehydrogenase; T4 and another lysozyme) and unrelated folds.
SIDE_BY_SIDE = [("3PTB", "1BMA", True), ("3PTB", "3SGB", True), ("1TIM", "1AFS", True), ("171L", "1AM7", True),
                ("1FKJ", "1UBQ", False), ("1UBQ", "3PTB", False), ("1AYE", "1TIM", False)]


@pytest.mark.parametrize(("first", "second", "related"), SIDE_BY_SIDE)
def test_tm_scores_side_by_side_with_tm_align(first: str, second: str, related: bool) -> None:
    (chain_a, ca_a), (chain_b, ca_b) = (_longest_chain_ca(next(DATA.glob(f"{name}.*"))) for name in (first, second))
    sequences = ["".join(s.sequence for s in chain) for chain in (chain_a, chain_b)]
    theirs = tmtools.tm_align(ca_a, ca_b, *sequences).tm_norm_chain1
    ours = align_folds(ca_a, ca_b).tm_score
    assert ours == pytest.approx(theirs, abs=0.02 if related else 0.03)
    assert (ours >= 0.5) == (theirs >= 0.5)


def test_the_alignment_beats_every_gapless_threading(trypsin) -> None:
    """Exhaustively: no shift of one chain along the other, superposed for its best TM-score,
    scores above the alignment (3SGB against trypsin, where the best threading is far off)."""
    _, ca_a = trypsin
    _, ca_b = _longest_chain_ca(DATA / "3SGB.pdb.gz")
    alignment = align_folds(ca_a, ca_b)
    best = 0.0
    for shift in range(-len(ca_b) + 3, len(ca_a) - 3):
        rows = np.arange(max(shift, 0), min(len(ca_a), len(ca_b) + shift))
        best = max(best, tm_superpose(ca_a[rows], ca_b[rows - shift], len(ca_a), 40)[1])
    assert alignment.tm_score > best + 0.1
