"""Fold descriptors of the low-level curves: invariant to position and orientation, near for one
fold and far for others; the screen of the candidates against the full alignment; the index
file round trip and what it refuses."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.analysis.fold_alignment import align_folds
from core.analysis.fold_search import (
    DESCRIPTOR_SIZE,
    FoldIndex,
    curve_descriptor,
    descriptor_distances,
    index_path,
    merge,
    search,
    sensitivity,
)
from core.analysis.tm_align import screen
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


def test_search_orders_the_candidates_by_tm_score(index) -> None:
    """Every chain screened by the alignment of every 4th Cα, the best 3 aligned in full: the
    screen keeps elastase's own chain and trypsin."""
    ca, codes = index.chain(int(np.flatnonzero(index.entries == "1BMA")[0]))
    hits = search(index, ca, codes.tobytes().decode(), top=3, candidates=len(index), aligned=3)
    assert [h.entry for h in hits[:2]] == ["1BMA", "3PTB"] and hits[0].match.tm_score_a == pytest.approx(1.0)
    assert hits[0].match.tm_score_a >= hits[1].match.tm_score_a >= hits[2].match.tm_score_a


def test_the_screen_scores_as_the_alignment_does(index) -> None:
    """On every Cα, the screen's TM-score is the full alignment's (to its quicker final search);
    on every 4th, trypsin and elastase still rank first for elastase, ubiquitin last."""
    ca, _ = index.chain(int(np.flatnonzero(index.entries == "1BMA")[0]))
    full = np.array([align_folds(ca, index.chain(k)[0]).tm_score for k in range(len(index))])
    assert screen(ca, index.coordinates, index.starts, index.lengths, 1) == pytest.approx(full, abs=0.01)
    quick = screen(ca, index.coordinates, index.starts, index.lengths, 4)
    order = index.entries[np.argsort(-quick)].tolist()
    assert order[:2] == ["1BMA", "3PTB"] and set(order[-2:]) == {"1UBQ", "2K39_CA-only"}


def test_the_index_file_round_trip_and_refusals(index, tmp_path) -> None:
    path = tmp_path / "folds.npz"
    path.write_bytes(index.to_bytes())
    again = FoldIndex.read(path)
    for name in ("entries", "chains", "lengths", "descriptors", "coordinates", "sequences"):
        assert np.array_equal(getattr(again, name), getattr(index, name))
    assert isinstance(again.coordinates, np.memmap) and isinstance(again.sequences, np.memmap)  # read per chain
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
