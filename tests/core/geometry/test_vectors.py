"""Row sums by index: what ``np.add.at`` gives, on the atoms of a real structure."""

from pathlib import Path

import numpy as np

from core.geometry.vectors import pair_gradient, summed_rows
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def test_atoms_summed_by_residue_and_pair_forces_are_those_of_add_at() -> None:
    structure = read_structure(DATA / "1UBQ.pdb.gz")
    owned = structure.atom_residue >= 0  # atoms of the polymer's residues
    coords, residue = structure.coords[owned], structure.atom_residue[owned]
    expected = np.zeros((residue.max() + 2, 3))  # one residue more: a row no atom adds to stays 0
    np.add.at(expected, residue, coords)
    assert np.array_equal(summed_rows(residue, coords, len(expected)), expected)

    i, j = np.arange(len(coords) - 1), np.arange(1, len(coords))  # each atom and the next
    force = coords[i] - coords[j]
    expected = np.zeros_like(coords)
    np.add.at(expected, i, force)
    np.add.at(expected, j, -force)
    got = pair_gradient(i, j, force, len(coords))
    assert np.allclose(got, expected, atol=1e-12) and np.allclose(got.sum(axis=0), 0.0, atol=1e-9)
