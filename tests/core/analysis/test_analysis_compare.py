"""Superposition, residue pairing and the factor D experiment on two copies of triosephosphate isomerase."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.analysis.compare import compare_chains, pair_residues, tm_score
from core.analysis.superpose import align_sequences, fit_closest, superpose
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def chain(structure, name):
    return [s for s in structure.segments if s.chain == name]


@pytest.fixture(scope="module")
def tim():
    return read_structure(DATA / "1TIM.pdb.gz")


@pytest.fixture(scope="module")
def tim8():
    return read_structure(DATA / "8TIM.pdb.gz")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_superpose_recovers_a_rigid_motion(tim, seed):
    ca = tim.segments[0].ca
    rotation = Rotation.random(random_state=seed).as_matrix()
    shift = np.random.default_rng(seed).normal(scale=20, size=3)
    moved = ca @ rotation.T + shift
    fit = superpose(ca, moved)
    assert fit.rmsd < 1e-3
    assert np.allclose(fit.rotation, rotation.T, atol=1e-6) and np.allclose(fit.apply(moved), ca, atol=1e-4)
    assert np.linalg.det(fit.rotation) == pytest.approx(1.0)


def test_superpose_is_least_squares(tim):
    a, b = chain(tim, "A")[0].ca, chain(tim, "B")[0].ca
    fit = superpose(a, b)
    rms = np.sqrt(np.mean(np.sum((a - fit.apply(b)) ** 2, axis=1)))
    assert rms == pytest.approx(fit.rmsd, abs=1e-4)
    for seed in range(5):  # any small change of the motion fits worse
        turn = Rotation.from_rotvec(np.random.default_rng(seed).normal(scale=0.01, size=3)).as_matrix()
        other = np.sqrt(np.mean(np.sum((a - (fit.apply(b) @ turn.T + 0.05)) ** 2, axis=1)))
        assert other > rms
    with pytest.raises(ValueError, match="n >= 3"):
        superpose(a[:2], b[:2])


def test_a_refined_fit_ignores_the_pairs_that_moved(tim):
    ca = tim.segments[0].ca
    rotation = Rotation.from_euler("xyz", [30, -50, 10], degrees=True).as_matrix()
    moved = ca @ rotation.T + [5.0, 0.0, -8.0]
    loop = np.arange(60, 75)
    moved[loop] += [9.0, 4.0, 0.0]  # a loop that differs: it pulls the fit on all pairs
    assert superpose(ca, moved).rmsd > 1.0
    motion, used = fit_closest(ca, moved, 1.0)
    assert np.array_equal(np.flatnonzero(~used), loop)
    np.testing.assert_allclose(motion.rotation, rotation.T, atol=1e-9)
    np.testing.assert_allclose(np.delete(motion.apply(moved), loop, axis=0), np.delete(ca, loop, axis=0), atol=1e-6)


def test_alignment_pairs_the_residues_left_after_deletions(tim):
    names = chain(tim, "A")[0].resname.tolist()
    kept = np.delete(np.arange(len(names)), [0, 1, 50, 51, 52, 120, 246])
    pairs_a, pairs_b = align_sequences(names, [names[k] for k in kept])
    assert np.array_equal(pairs_a, kept) and np.array_equal(pairs_b, np.arange(len(kept)))


def test_pairing_by_numbering_or_by_alignment(tim, tim8):
    a, b = chain(tim, "A"), chain(tim, "B")
    pairs_a, pairs_b, how = pair_residues(a, b)
    assert how == "numbering" and len(pairs_a) == 247 and np.array_equal(pairs_a, pairs_b)
    # 8TIM is numbered from 2, 1TIM from 1 (and skips 3): equal numbers do not always carry equal residues
    c = chain(tim8, "A")
    pairs_a, pairs_c, how = pair_residues(a, c)
    assert how == "alignment" and len(pairs_a) == 247
    assert (a[0].resseq[pairs_a[0]], c[0].resseq[pairs_c[0]]) == (1, 2)  # ALA1 with ALA2
    identity = np.mean(a[0].resname[pairs_a] == c[0].resname[pairs_c])
    by_number = pair_residues(a, c, "numbering")
    assert by_number[2] == "numbering" and len(by_number[0]) == 246
    assert identity > np.mean(a[0].resname[by_number[0]] == c[0].resname[by_number[1]])


def test_tm_score_definition():
    score, d0 = tm_score(np.zeros(247), 247)
    assert score == pytest.approx(1.0) and d0 == pytest.approx(1.24 * 232 ** (1 / 3) - 1.8)
    d0 = tm_score(np.zeros(1), 200)[1]
    score, _ = tm_score(np.full(100, d0), 200)  # every distance equals d0: half weight, half the length
    assert score == pytest.approx(0.25)
    assert tm_score(np.zeros(10), 10)[1] == 0.5  # short chains: d0 floor of TM-align


def test_factor_d_experiment_on_two_tim_chains(tim):
    a, b = chain(tim, "A"), chain(tim, "B")
    result = compare_chains(a, b)
    assert result.pairing == "numbering" and result.n_pairs == 247 and result.length_a == 247
    assert 0.3 < result.rms_all < 2.5 and 0.8 < result.tm_score <= 1.0
    assert 100 < result.n_core < 247 and result.rms_core < result.rms_all
    assert "1 Å" in result.core_rule
    kinds = [(f.points, f.depth, f.every) for f in result.fits]
    expected = [("CA", 0, 1)] + [("CA", 0, m) for m in (2, 4, 8, 16) for _ in range(m)]
    expected += [e for k in (1, 2, 3, 4) for e in [("C^r", k, 1)] + [("C^r", k, 2**k)] * 2**k]
    assert kinds == expected
    for fit in result.fits:  # the fit on the core is the least-squares optimum on the core
        assert fit.rms_core >= result.rms_core - 1e-6
        assert fit.start <= fit.every and fit.n_fit >= (247 // fit.every)
    all_fit = result.fits[0]
    assert all_fit.n_fit == 247 and all_fit.rms_core < result.rms_all


def test_a_chain_against_its_moved_copy_fits_exactly(tim):
    a = chain(tim, "A")
    result = compare_chains(a, a, steps=(4,), depths=(2,))
    assert result.rms_all < 1e-3 and result.tm_score == pytest.approx(1.0) and result.n_core == 247
    assert max(f.rms_core for f in result.fits) < 1e-3


def test_user_core_set_and_errors(tim):
    a, b = chain(tim, "A"), chain(tim, "B")
    core = np.zeros(247, dtype=bool)
    core[10:60] = True
    result = compare_chains(a, b, core_residues=core, steps=(2,), depths=(1,))
    assert result.n_core == 50 and result.core_rule == "residues given by the user"
    with pytest.raises(ValueError, match="core set has 0"):
        compare_chains(a, b, core_residues=np.zeros(247, dtype=bool))
    with pytest.raises(ValueError, match="cutoff"):
        compare_chains(a, b, cutoff=0.0)
