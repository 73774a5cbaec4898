"""3Di states from Cα alone: N and Cβ placed within a few tenths of an Å of where real entries
have them, the states mostly those of the full backbone, unchanged by a rigid motion."""

from pathlib import Path

import gemmi
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.analysis.structural_alphabet import AMINO_ACID_SCORES, STATE_SCORES, backbone_from_ca, states

DATA = Path(__file__).resolve().parents[2] / "data"


def backbone(name: str) -> np.ndarray:
    """(n, 4, 3) N, Cα, C, Cβ (NaN for glycine's) of the first chain's amino acids."""
    chain = gemmi.read_structure(str(DATA / name))[0][0]
    rows = []
    for residue in chain.get_polymer():
        atoms = {atom.name: atom.pos.tolist() for atom in residue}
        if all(name in atoms for name in ("N", "CA", "C")):
            rows.append([atoms[name] for name in ("N", "CA", "C")] + [atoms.get("CB", [np.nan] * 3)])
    return np.array(rows)


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "3PTB.pdb.gz", "1TIM.pdb.gz"])
def test_n_and_cb_are_placed_where_real_chains_have_them(name) -> None:
    atoms = backbone(name)
    n, cb = backbone_from_ca(atoms[:, 1])
    inner = slice(1, -1)  # the ends take their neighbour's frame
    assert np.sqrt(np.mean(np.sum((n - atoms[:, 0])[inner] ** 2, axis=1))) < 0.3
    has_cb = np.isfinite(atoms[inner, 3]).all(axis=1)
    assert np.sqrt(np.mean(np.sum((cb - atoms[:, 3])[inner][has_cb] ** 2, axis=1))) < 0.45  # 0.29 on the shared set


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "3PTB.pdb.gz", "1TIM.pdb.gz"])
def test_states_from_calpha_are_mostly_those_of_the_full_backbone(name) -> None:
    atoms = backbone(name)
    full = states(atoms[:, 1], (atoms[:, 0], atoms[:, 2], atoms[:, 3]))
    alone = states(atoms[:, 1])
    assert alone.dtype == np.uint8 and alone.shape == (len(atoms),) and alone.max() < 20
    assert np.mean(full == alone) > 0.8
    moved = atoms[:, 1] @ Rotation.from_euler("xyz", [10, -50, 80], degrees=True).as_matrix().T + [5.0, 90.0, -30.0]
    assert np.mean(states(moved) == alone) > 0.99  # rounding may tip a residue near a boundary


def test_the_substitution_scores_are_symmetric_and_reward_identity() -> None:
    for scores in (STATE_SCORES, AMINO_ACID_SCORES[:20, :20]):
        assert np.array_equal(scores, scores.T)
        assert (np.diag(scores) > 0).all() and (np.diag(scores)[:, None] >= scores).all()
