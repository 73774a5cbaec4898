"""Colours, bonds, ions and ligands of real structures."""

from pathlib import Path

import numpy as np
import pytest

from app.editor.scene import molecule
from app.editor.scene.molecule import Colouring
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def ubiquitin():
    return read_structure(DATA / "1UBQ.pdb.gz")


def _bond_names(structure, bonds: np.ndarray) -> set[tuple[int, str, int, str]]:
    table = structure.atoms
    return {tuple(sorted([(int(table.resseq[a]), str(table.name[a])), (int(table.resseq[b]), str(table.name[b]))]))
            for a, b in bonds}


def test_polymer_bonds_of_ubiquitin(ubiquitin) -> None:
    table = ubiquitin.atoms
    protein = np.flatnonzero(table.category == "protein")
    bonds = molecule.bonds(ubiquitin.coords, table.element, table.altloc, protein)
    names = _bond_names(ubiquitin, bonds)
    assert ((1, "CA"), (1, "N")) in names and ((1, "C"), (1, "CA")) in names and ((1, "C"), (1, "O")) in names
    assert all(((i, "C"), (i + 1, "N")) in names for i in range(1, 76))  # every peptide bond
    assert ((1, "CA"), (1, "O")) not in names  # 2.4 Å: not bonded
    length = np.linalg.norm(ubiquitin.coords[bonds[:, 0]] - ubiquitin.coords[bonds[:, 1]], axis=1)
    assert length.max() < 2.0 and length.min() > 1.1
    # a heavy-atom protein without rings closing elsewhere: bonds = atoms - 1 + one per ring (Phe, Tyr, His, Pro)
    rings = sum(name in ("PHE", "TYR", "HIS", "PRO", "TRP") for name in ubiquitin.segments[0].resname)
    assert len(bonds) == len(protein) - 1 + rings + sum(name == "TRP" for name in ubiquitin.segments[0].resname)


def test_alternate_conformers_are_never_bonded_to_each_other() -> None:
    crambin = read_structure(DATA / "1EJG.pdb.gz")  # 0.54 Å structure with many altlocs
    table = crambin.atoms
    bonds = molecule.bonds(crambin.coords, table.element, table.altloc, np.arange(len(table)))
    first, second = table.altloc[bonds[:, 0]], table.altloc[bonds[:, 1]]
    assert np.any(first != "")
    assert not np.any((first != "") & (second != "") & (first != second))


def test_ions_and_ligands() -> None:
    structure = read_structure(DATA / "1F9V.pdb.gz")  # kinesin-like motor with ADP and Mg
    ions, ligands = molecule.ions_and_ligands(structure)
    table = structure.atoms
    assert set(table.element[ions]) == {"Mg"}
    assert set(table.resname[ligands]) == {"ADP"}
    assert len(ligands) == 27 * 2  # two ADP molecules
    bonds = molecule.bonds(structure.coords, table.element, table.altloc, ligands)
    assert len(bonds) >= len(ligands) - 2  # each ADP is connected
    haemoglobin = read_structure(DATA / "4HHB.pdb.gz")  # B:ASP79 is in no segment: drawn as a ligand is
    _, ligands = molecule.ions_and_ligands(haemoglobin)
    table = haemoglobin.atoms
    names = {(str(table.chain[row]), str(table.resname[row]), int(table.resseq[row])) for row in ligands}
    assert ("B", "ASP", 79) in names and {name for _, name, _ in names} == {"HEM", "ASP"}


def test_colour_schemes(ubiquitin) -> None:
    ss = molecule.residue_colours(ubiquitin, Colouring.SECONDARY_STRUCTURE)
    assert ss.shape == (76, 3) and ss.dtype == np.uint8
    helix = ubiquitin.segments[0].ss == "H"
    assert np.all(ss[helix] == molecule.SS_COLOURS["H"])
    kinds = molecule.residue_colours(ubiquitin, Colouring.RESIDUE_TYPE)
    lysine = ubiquitin.segments[0].resname == "LYS"
    assert np.all(kinds[lysine] == molecule.RESIDUE_CLASSES["basic"][0])
    haemoglobin = read_structure(DATA / "4HHB.pdb.gz")
    chains = molecule.residue_colours(haemoglobin, Colouring.CHAIN)
    assert len({tuple(c) for c in chains}) == 4
    assert [name for name, _ in molecule.legend(haemoglobin, Colouring.CHAIN)] == [f"chain {c}" for c in "ABCD"]
    assert [name for name, _ in molecule.legend(ubiquitin, Colouring.SECONDARY_STRUCTURE)] == ["helix", "sheet", "other"]
