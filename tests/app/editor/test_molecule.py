"""Colours, bonds, ions and ligands of real structures."""

from pathlib import Path

import numpy as np
import pytest

from app.editor.scene import molecule
from app.editor.scene.molecule import Colouring
from core.protein.reading import read_structure
from core.protein.structure import ca_rows

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


def _hue(rgb: np.ndarray) -> np.ndarray:
    """Degrees of hue of (n, 3) colours."""
    red, green, blue = (rgb.astype(float) / 255).T
    return np.degrees(np.arctan2(np.sqrt(3) * (green - blue), 2 * red - green - blue)) % 360


def test_rainbow_runs_from_blue_to_red_along_each_chain() -> None:
    """As PyMOL's spectrum and ChimeraX's rainbow: each chain of 4HHB (chain B in two segments:
    its Asp79 is apart) from blue at its first residue to red at its last, the hue falling all the way."""
    haemoglobin = read_structure(DATA / "4HHB.pdb.gz")
    colours = molecule.residue_colours(haemoglobin, Colouring.RAINBOW)
    chain = np.concatenate([[s.chain] * len(s) for s in haemoglobin.segments])
    for name in "ABCD":
        rows = np.flatnonzero(chain == name)
        assert tuple(colours[rows[0]]) == (0, 0, 255) and tuple(colours[rows[-1]]) == (255, 0, 0)
        assert np.all(np.diff(_hue(colours[rows])) <= 1e-9)
    assert [name for name, _ in molecule.legend(haemoglobin, Colouring.RAINBOW)] == ["N-terminus", "C-terminus"]


def test_b_factor_colours_each_residue_by_its_calpha(ubiquitin) -> None:
    """Blue at the lowest Cα B-factor, white halfway, red at the highest; redder with B (the
    red share rises, the blue falls); one B for every Cα (an entry without them): all white."""
    colours = molecule.residue_colours(ubiquitin, Colouring.B_FACTOR).astype(int)
    b = ubiquitin.atoms.b_factor[ca_rows(ubiquitin)]
    assert tuple(colours[np.argmin(b)]) == (0, 0, 255) and tuple(colours[np.argmax(b)]) == (255, 0, 0)
    order = np.argsort(b, kind="stable")
    assert np.all(np.diff(colours[order, 0] - colours[order, 2]) >= 0)
    legend = molecule.legend(ubiquitin, Colouring.B_FACTOR)
    assert [name for name, _ in legend] == [f"B {b.min():.0f} Å²", f"B {(b.min() + b.max()) / 2:.0f} Å²",
                                            f"B {b.max():.0f} Å²"]
    flat = read_structure(DATA / "1TIM.pdb.gz")  # every B-factor 0
    assert np.all(molecule.residue_colours(flat, Colouring.B_FACTOR) == 255)
    assert molecule.legend(flat, Colouring.B_FACTOR) == [("B 0 Å² (every Cα)", (255, 255, 255))]
