"""The per-atom table (names, elements, B-factors, categories) that surfaces and maps use."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.protein.input_files import StructureError
from core.protein.reading import read_atoms, read_structure
from core.protein.structure import ATOM_CATEGORIES

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "4HHB.pdb.gz", "4YVS.cif.gz", "1LCD.cif.gz"])
def test_atom_table_holds_the_atoms_gemmi_reads(name: str) -> None:
    atoms = read_structure(DATA / name).atoms
    model = gemmi.read_structure(str(DATA / name))[0]
    expected = [(cra.atom.name, cra.atom.element.name, cra.residue.name, cra.chain.name,
                 cra.residue.seqid.num, cra.atom.b_iso, cra.atom.occ) for cra in model.all()]
    got = list(zip(atoms.name, atoms.element, atoms.resname, atoms.chain, atoms.resseq.tolist(),
                   atoms.b_factor.tolist(), atoms.occupancy.tolist(), strict=True))
    assert sorted(got) == sorted(expected)  # gemmi may order chain parts differently
    assert np.array_equal(atoms.coords, read_structure(DATA / name).coords)
    assert set(atoms.category) <= set(ATOM_CATEGORIES)


def test_categories_of_hemoglobin() -> None:
    atoms = read_structure(DATA / "4HHB.pdb.gz").atoms
    counts = Counter(atoms.category.tolist())
    assert counts["water"] == 221
    assert set(atoms.resname[atoms.category == "ligand"]) == {"HEM", "PO4"}
    assert counts["protein"] == 4384
    # residue ordinals run over the model in file order
    assert atoms.residue[0] == 0 and np.all(np.diff(atoms.residue) >= 0)


def test_read_atoms_accepts_dna_without_protein() -> None:
    with pytest.raises(StructureError, match="no protein chain"):
        read_structure(DATA / "1BNA.pdb.gz")
    atoms = read_atoms(DATA / "1BNA.pdb.gz")
    assert Counter(atoms.category.tolist()) == {"nucleic": 486, "water": 80}
    assert atoms.entry_id == "1BNA"
    assert not atoms.coords.flags.writeable and not atoms.b_factor.flags.writeable


def test_a_modified_nucleotide_of_a_dna_strand_is_a_nucleotide() -> None:
    structure = read_structure(DATA / "4OPJ.pdb.gz")  # two DNA strands, the sixth nucleotide of each modified (TCY)
    atoms = structure.atoms
    tcy = atoms.resname == "TCY"
    assert tcy.any() and set(atoms.category[tcy].tolist()) == {"nucleic"}
    assert set(atoms.category[atoms.resname == "GOL"].tolist()) == {"ligand"}  # a glycerol stays a ligand
    strands = {c.name: (c.n_nucleotides, c.nucleic_acid) for c in structure.chains}
    assert strands == {"A": (0, ""), "B": (12, "DNA"), "C": (0, ""), "D": (12, "DNA")}


@pytest.mark.parametrize("fmt", ["pdb", "mmcif"])
def test_modified_residues_gemmi_does_not_know_take_their_parent_from_the_file(fmt: str, tmp_path: Path) -> None:
    """PDB MODRES and mmCIF _pdbx_struct_mod_residue name the parent: 4OPJ's TCY is a dA,
    1AM7's TRN a Trp (gemmi's residue table has neither)."""
    paths = [DATA / "4OPJ.pdb.gz", DATA / "1AM7.pdb.gz"]
    if fmt == "mmcif":
        for k, path in enumerate(paths):
            st = gemmi.read_structure(str(path))
            st.setup_entities()
            st.make_mmcif_document().write_file(str(tmp_path / f"{k}.cif"))
            paths[k] = tmp_path / f"{k}.cif"
    dna, lysozyme = read_structure(paths[0]), read_structure(paths[1])
    assert dna.atoms.parents == {"TCY": "DA"} and lysozyme.atoms.parents == {"TRN": "TRP"}
    for segment in lysozyme.segments:
        trn = segment.resname == "TRN"
        assert trn.sum() == 4 and set(np.array(list(segment.sequence))[trn]) == {"W"} and "X" not in segment.sequence


def test_altlocs_are_recorded() -> None:
    atoms = read_structure(DATA / "1EJG.pdb.gz").atoms
    assert {"", "A", "B"} <= set(atoms.altloc.tolist())


def test_read_atoms_reports_bad_files(tmp_path: Path) -> None:
    (tmp_path / "empty.pdb").write_text("")
    with pytest.raises(StructureError, match="empty file"):
        read_atoms(tmp_path / "empty.pdb")


def test_elements_of_a_file_without_element_columns_follow_the_names() -> None:
    """A CHARMM file (adenylate kinase, hydrogens, no element columns, HSD histidines): gemmi's
    guesses from the names (CA calcium, HG1 mercury, CB unknown) are the standard residues'
    elements again (files with element columns keep gemmi's: the test above)."""
    atoms = read_structure(DATA / "1AKE_adk_closed.pdb.gz").atoms
    model = gemmi.read_structure(str(DATA / "1AKE_adk_closed.pdb.gz"))[0]
    guessed = Counter(cra.atom.element.name for cra in model.all())
    assert guessed["Ca"] > 0 and guessed["Hg"] > 0 and guessed["X"] > 0
    assert Counter(atoms.element.tolist()) == {"H": 1685, "C": 1040, "O": 320, "N": 289, "S": 7}
    assert set(atoms.element[atoms.name == "CA"]) == {"C"} and set(atoms.element[atoms.name == "HG1"]) == {"H"}
    assert set(atoms.element[atoms.resname == "HSD"]) == {"C", "N", "H", "O"}
