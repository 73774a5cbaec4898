"""Fold search: the local alignment of 3Di states and amino acids and its E-values, the hits aligned
by structure; the descriptors of the low-level curves (invariant to position and orientation, near
for one fold and far for others); the index file round trip and what it refuses."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.analysis.fold_alignment import align_folds
from core.analysis.fold_index import (
    DESCRIPTOR_SIZE,
    FileArray,
    FoldIndex,
    curve_descriptor,
    descriptor_distances,
    index_path,
    merge,
    profile_similarities,
)
from core.analysis.fold_search import chains_scored, evalues, length_fair, search, sensitivity
from core.analysis.local_alignment import LANES, local_pairs, local_scores
from core.curves.wavelets import smooth

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def index() -> FoldIndex:
    return merge([index_path(DATA / name) for name in ("1UBQ.pdb.gz", "2K39_CA-only.pdb.gz", "3PTB.pdb.gz",
                                                         "1BMA.pdb.gz", "1TIM.pdb.gz")])


def test_the_descriptor_is_the_distance_profile_of_the_coarse_control_points(index) -> None:
    ca, _ = index.chain(0)
    descriptor = curve_descriptor(ca)
    assert descriptor.shape == (DESCRIPTOR_SIZE,) == (21 + 55 + 171,)
    points = np.stack([np.interp(np.linspace(0, len(ca) - 1, 67), np.arange(len(ca)), ca[:, k]) for k in range(3)], 1)
    level_2 = smooth(points, 2)  # 7 control points: their 21 distances come first
    assert np.allclose(descriptor[:21], [np.linalg.norm(level_2[i] - level_2[j]) for i in range(7)
                                         for j in range(i + 1, 7)], atol=1e-4)
    moved = ca @ Rotation.from_euler("xyz", [30, 70, -20], degrees=True).as_matrix().T + [40.0, -3.0, 12.0]
    assert np.allclose(curve_descriptor(moved), descriptor, atol=1e-3)


def test_one_fold_is_near_and_others_far(index) -> None:
    rows = {entry: k for k, entry in reversed(list(enumerate(index.entries.tolist())))}
    distance = descriptor_distances(index.descriptors, index.descriptors[rows["1UBQ"]])
    assert distance[rows["1UBQ"]] < 0.05 and distance[rows["2K39_CA-only"]] < 5.0  # its NMR model: loose tail
    assert distance[rows["3PTB"]] > 15.0 and distance[rows["1TIM"]] > 15.0
    distance = descriptor_distances(index.descriptors, index.descriptors[rows["3PTB"]])
    assert distance[rows["1BMA"]] < min(distance[rows["1UBQ"]], distance[rows["1TIM"]])  # elastase, a protease


def test_search_ranks_the_proteases_by_their_alignment_and_fold_score(index) -> None:
    """Elastase finds itself, then trypsin (a serine protease of another sequence), with
    E-values far below ubiquitin's and the TIM barrel's; the aligned hits come by fold score,
    and trypsin's TM-score is within 0.03 of TM-align's full search."""
    row = int(np.flatnonzero(index.entries == "1BMA")[0])
    ca, codes = index.chain(row)
    hits = search(index, ca, codes.tobytes().decode(), top=len(index), max_evalue=np.inf)
    assert [h.entry for h in hits[:2]] == ["1BMA", "3PTB"] and len(hits) == len(index)
    assert hits[0].match.tm_score_a == pytest.approx(1.0) and hits[0].evalue < 1e-40
    by_entry = {h.entry: h for h in hits}
    assert by_entry["3PTB"].evalue < 1e-10 < min(by_entry[e].evalue for e in ("1UBQ", "1TIM"))
    trypsin = index.chain(by_entry["3PTB"].row)[0]
    assert by_entry["3PTB"].match.tm_score_a == pytest.approx(align_folds(ca, trypsin).tm_score, abs=0.03)
    folds = [h.fold_score for h in hits if h.fold_score is not None]
    assert folds == sorted(folds, reverse=True) and len(folds) == len(index)  # every chain aligned here
    assert [h.entry for h in search(index, ca, codes.tobytes().decode(), top=3, aligned=2)][:2] == ["1BMA", "3PTB"]


def test_the_chains_nearest_by_pair_profile_are_aligned_whatever_their_score(index, monkeypatch) -> None:
    from core.analysis import fold_search

    ca, codes = index.chain(int(np.flatnonzero(index.entries == "1BMA")[0]))
    hits = search(index, ca, codes.tobytes().decode(), top=len(index), aligned=1, max_evalue=np.inf)
    assert all(h.match is not None for h in hits)  # 1 by score, the 5 others by profile
    monkeypatch.setattr(fold_search, "PROFILED", 0)
    hits = search(index, ca, codes.tobytes().decode(), top=len(index), aligned=1, max_evalue=np.inf)
    assert [h.match is not None for h in hits] == [True] + [False] * (len(index) - 1)


def test_search_leaves_out_what_is_neither_significant_nor_of_the_fold(index) -> None:
    """In an index of 6 chains any unrelated chain scores as well as 2 or more others would (an
    E-value of 2 to 4); ubiquitin's NMR model (Cα only) is significant at 1e-11."""
    ca, codes = index.chain(int(np.flatnonzero(index.entries == "1UBQ")[0]))
    hits = search(index, ca, codes.tobytes().decode(), max_evalue=1e-3)
    assert [h.entry for h in hits] == ["1UBQ", "2K39_CA-only"] and hits[1].evalue < 1e-8
    others = search(index, ca, codes.tobytes().decode())[2:]
    assert len(others) == 4 and all(1 < h.evalue <= 10 and h.match.tm_score_a < 0.4 for h in others)
    assert len(search(index, ca, codes.tobytes().decode(), top=1)) == 1


def test_local_alignment_scores_and_pairs_agree_and_evalues_fall_with_score() -> None:
    """The linear-memory scores, chains side by side in lanes, are the best of each chain's full
    table, whatever the chains beside it (several groups of lanes, lengths from 1, any order);
    the pairs the traceback gives sum, with their gaps, to that score; a higher score is less
    expected."""
    rng = np.random.default_rng(5)
    profile = rng.normal(-1.0, 3.0, size=(40, 420)).astype(np.float32)
    lengths = np.concatenate([[1, 7, 40, 93], rng.integers(1, 120, size=2 * LANES + 5)])
    chains = [rng.integers(0, 420, size=n).astype(np.int16) for n in lengths]
    codes = np.concatenate(chains)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    scores = local_scores(profile, codes, starts, lengths, 10.0, 1.0)
    shuffled = rng.permutation(len(chains))
    assert np.array_equal(local_scores(profile, codes, starts[shuffled], lengths[shuffled], 10.0, 1.0),
                          scores[shuffled])
    assert np.array_equal(local_scores(profile, codes, starts[:1], lengths[:1], 10.0, 1.0), scores[:1])
    for chain, score in zip(chains, scores):
        pairs_a, pairs_b, best = local_pairs(profile, chain, 10.0, 1.0)
        assert best == pytest.approx(score, rel=1e-6)
        total = profile[pairs_a, chain[pairs_b]].sum()
        for gaps in (np.diff(pairs_a) - 1, np.diff(pairs_b) - 1):
            total -= np.sum(np.where(gaps > 0, 10.0 + (gaps - 1) * 1.0, 0.0))
        assert total == pytest.approx(best, rel=1e-5) and (np.diff(pairs_a) > 0).all() and (np.diff(pairs_b) > 0).all()
    low, high = evalues(np.array([50.0, 150.0]), 100, np.array([120, 120]), 1000)
    assert 0 < high < low <= 1000


def test_chains_rank_by_their_length_fair_score_as_by_their_evalue() -> None:
    """A chain as long as the query keeps its score; a longer one, whose score an unrelated chain
    reaches more easily by chance, ranks behind a shorter one of the same score, and the order
    is the E-values', also where they are too small to tell apart."""
    rng = np.random.default_rng(11)
    scores = np.concatenate([rng.uniform(0.0, 400.0, 2000), rng.uniform(15_000.0, 20_000.0, 50)])  # (large chains' self-matches)
    lengths = rng.integers(5, 3000, len(scores))
    fair = length_fair(scores, 150, lengths)
    assert length_fair(np.array([80.0]), 150, np.array([150]))[0] == 80.0
    assert np.all(np.diff(fair[np.argsort(-scores)][lengths[np.argsort(-scores)] == 150]) <= 0)
    longer, shorter = length_fair(np.array([120.0, 120.0]), 150, np.array([600, 75]))
    assert longer < 120.0 < shorter
    expected = evalues(scores, 150, lengths, 1_000_000)
    ranked = expected[np.argsort(-fair, kind="stable")]
    assert np.all(np.diff(ranked) >= 0) and np.sum(expected == 0.0) > 10  # E-values of 0 tie; fair scores do not
    assert len(np.unique(fair[expected == 0.0])) == np.sum(expected == 0.0)


def test_the_index_file_round_trip_and_refusals(index, tmp_path) -> None:
    path = tmp_path / "folds.npz"
    path.write_bytes(index.to_bytes())
    again = FoldIndex.read(path)
    for name in ("entries", "chains", "lengths", "descriptors", "coordinates", "sequences", "states"):
        assert np.array_equal(getattr(again, name), getattr(index, name))
    assert all(isinstance(getattr(again, name), FileArray) for name in ("coordinates", "sequences", "states"))  # read per chain
    ca, codes = index.chain(3)
    assert [(h.row, h.match.tm_score_a) for h in search(again, ca, codes.tobytes().decode(), top=3)] == [
        (h.row, h.match.tm_score_a) for h in search(index, ca, codes.tobytes().decode(), top=3)]
    arrays = dict(np.load(path))
    np.savez_compressed(tmp_path / "old.npz", **(arrays | {"format": np.array(1)}))
    with pytest.raises(ValueError, match="another format version"):
        FoldIndex.read(tmp_path / "old.npz")
    pickled = tmp_path / "pickled.npz"
    np.savez(pickled, entries=np.array([{"not": "an array"}], dtype=object))
    with pytest.raises(ValueError, match="not a ribbonwave fold index"):
        FoldIndex.read(pickled)
    arrays = dict(np.load(path))
    arrays["lengths"] = arrays["lengths"][:-1]
    np.savez(tmp_path / "damaged.npz", **arrays)
    with pytest.raises(ValueError, match="damaged"):
        FoldIndex.read(tmp_path / "damaged.npz")


def test_sensitivity_counts_true_positives_up_to_the_first_other_fold() -> None:
    """Foldseek's measure on a hand-made ranking: the query (row 0) has 2 true positives at each
    level; the first chain of another fold (row 6) stops the count."""
    family = np.array(["a", "a", "a", "b", "c", "d", "x", "e"])
    superfamily = np.array(["A", "A", "A", "A", "B", "C", "X", "A"])
    fold = np.array(["F", "F", "F", "F", "F", "F", "Y", "F"])
    # 7 and 3 are of the superfamily (other families); 4 and 5 of the fold (other superfamilies)
    ranked = np.array([0, 1, 4, 7, 6, 2, 3, 5])  # the query itself first is ignored
    assert np.allclose(sensitivity(ranked, family, superfamily, fold, 0), [1 / 2, 1 / 2, 1 / 2])
    assert np.allclose(sensitivity(np.array([2, 1, 3, 7, 4, 5]), family, superfamily, fold, 0), [1, 1, 1])
    assert np.allclose(sensitivity(np.array([6, 1, 2]), family, superfamily, fold, 0), [0, 0, 0])
    assert np.allclose(sensitivity(np.array([1]), family, superfamily, fold, 0), [1 / 2, 0, 0])  # a short list
    assert sensitivity(ranked, family, superfamily, np.where(fold == "F", "G", fold), 6) is None  # no true positive


def test_a_large_index_scores_only_the_nearest_by_descriptor_and_by_pair_profile(index, monkeypatch) -> None:
    """Past ``SCORED_CELLS`` cells, only the chains nearest the query are scored, half by
    descriptor and half by profile of 3Di state pairs, as many as the cells hold (more for a
    shorter query): elastase still finds itself and trypsin."""
    from core.analysis import fold_search

    ca, codes = index.chain(int(np.flatnonzero(index.entries == "1BMA")[0]))
    assert chains_scored(index, len(ca)) == len(index)
    monkeypatch.setattr(fold_search, "SCORED_CELLS", int(4.5 * len(ca) * index.lengths.mean()))
    assert chains_scored(index, len(ca)) == 4 and chains_scored(index, len(ca) // 2) == len(index)
    assert chains_scored(index, 100 * len(ca)) == 2
    hits = search(index, ca, codes.tobytes().decode(), top=len(index), max_evalue=np.inf)
    assert [h.entry for h in hits[:2]] == ["1BMA", "3PTB"] and 2 <= len(hits) <= 4
    profiles = index.profiles.astype(np.float32)
    assert np.allclose(np.linalg.norm(profiles, axis=1), 1.0, atol=2e-3)  # unit vectors, as float16
    similarity = profile_similarities(index.profiles, profiles[3])
    assert similarity[3] == pytest.approx(1.0, abs=2e-3) and similarity[2] > max(similarity[0], similarity[4])
