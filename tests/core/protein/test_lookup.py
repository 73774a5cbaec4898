"""Residues named as people type them, on real entries."""

from pathlib import Path

import numpy as np
import pytest

from core.protein.lookup import find_atom, find_group, find_residues
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def haemoglobin():
    return read_structure(DATA / "4HHB.pdb.gz")


def _label(structure, row: int) -> str:
    segment = next(s for s in structure.segments if s.residue_index[0] <= row <= s.residue_index[-1])
    return segment.labels[row - segment.residue_index[0]]


@pytest.mark.parametrize(("text", "chain", "label"), [
    ("A:45", None, "A:HIS45"), ("B:45", "A", "B:PHE45"), ("45", "C", "C:HIS45"), ("45", None, "A:HIS45"),
    ("D45", None, "D:PHE45"), ("B:PHE45", None, "B:PHE45"), ("phe45", "B", "B:PHE45"), (" C / 3 ", None, "C:SER3"),
])
def test_one_residue(haemoglobin, text: str, chain: str | None, label: str) -> None:
    rows = find_residues(haemoglobin, text, chain)
    assert len(rows) == 1 and _label(haemoglobin, int(rows[0])) == label


@pytest.mark.parametrize(("text", "chain", "labels"), [
    ("/B:40-50", "A", ("B:ARG40", "B:THR50", 11)), (":45", "C", ("C:HIS45", "C:HIS45", 1)),  # ChimeraX
    ("#1/D:45", None, ("D:PHE45", "D:PHE45", 1)), ("/C", "A", ("C:VAL1", "C:ARG141", 141)),
    ("chain B and resi 40-50", "A", ("B:ARG40", "B:THR50", 11)), ("resi 45", "D", ("D:PHE45", "D:PHE45", 1)),  # PyMOL
    ("resi 45 and chain C", None, ("C:HIS45", "C:HIS45", 1)), ("c. B & i. 45", None, ("B:PHE45", "B:PHE45", 1)),
    ("RESN PHE AND RESI 45 AND CHAIN D", None, ("D:PHE45", "D:PHE45", 1)), ("chain D", "A", ("D:VAL1", "D:HIS146", 146)),
    ("/4hhb//B/40-50/CA", None, ("B:ARG40", "B:THR50", 11)), ("A/45/", "C", ("A:HIS45", "A:HIS45", 1)),
    ("B/PHE`45/CA", None, ("B:PHE45", "B:PHE45", 1)), ("/4hhb//C", None, ("C:VAL1", "C:ARG141", 141)),
])
def test_chimerax_and_pymol_forms(haemoglobin, text: str, chain: str | None, labels: tuple[str, str, int]) -> None:
    rows = find_residues(haemoglobin, text, chain)
    assert (_label(haemoglobin, int(rows[0])), _label(haemoglobin, int(rows[-1])), len(rows)) == labels
    assert np.array_equal(rows, np.arange(rows[0], rows[-1] + 1))


@pytest.mark.parametrize(("text", "chain", "labels"), [
    ("A:40-42, B:45", None, ["A:LYS40", "A:THR41", "A:TYR42", "B:PHE45"]),
    ("A:40-42, 50", "C", ["A:LYS40", "A:THR41", "A:TYR42", "A:HIS50"]),  # 50 in the chain before it
    ("45, 50", "C", ["C:HIS45", "C:HIS50"]),
    ("/A,B:41,50", None, ["A:THR41", "A:HIS50", "B:PHE41", "B:THR50"]),  # ChimeraX
    ("/A:40-41 /B:45", None, ["A:LYS40", "A:THR41", "B:PHE45"]), ("#1/C,D:3", None, ["C:SER3", "D:LEU3"]),
    ("resi 10+12+14", "C", ["C:VAL10", "C:ALA12", "C:TRP14"]),  # PyMOL
    ("chain A+B and resi 5", None, ["A:ALA5", "B:PRO5"]),
    ("resi 40-41+50 and c. D", None, ["D:ARG40", "D:PHE41", "D:THR50"]),
    ("B:45, B:44-46", None, ["B:SER44", "B:PHE45", "B:GLY46"]),  # overlapping parts: each residue once
])
def test_lists_of_residues_ranges_and_chains(haemoglobin, text: str, chain: str | None, labels: list[str]) -> None:
    rows = find_residues(haemoglobin, text, chain)
    assert [_label(haemoglobin, int(row)) for row in rows] == labels


@pytest.mark.parametrize(("text", "chain", "names", "chains"), [
    ("resn HIS", None, "HIS", "ABCD"), ("r. his", "A", "HIS", "ABCD"), (":his", "A", "HIS", "ABCD"),
    ("resn HIS and chain B", None, "HIS", "B"), ("/B:his", None, "HIS", "B"), ("resn HIS+TRP", "C", "HIS TRP", "ABCD"),
    ("chain A+C and resn TRP", None, "TRP", "AC"),
])
def test_the_residues_of_a_name(haemoglobin, text: str, chain: str | None, names: str, chains: str) -> None:
    rows = find_residues(haemoglobin, text, chain)  # in every chain where the text names none
    expected = np.concatenate([s.residue_index[np.isin(s.resname, names.split())]
                               for s in haemoglobin.segments if s.chain in chains])
    assert len(rows) >= 2 and np.array_equal(rows, np.sort(expected))


def _within(structure, reference: np.ndarray, reach: float, coords: np.ndarray) -> np.ndarray:
    """Brute force: the backbone residues with an atom within ``reach`` of an atom of ``reference``."""
    backbone = np.flatnonzero(structure.atom_residue >= 0)
    distance = np.linalg.norm(coords[backbone][:, None] - coords[reference][None], axis=2).min(axis=1)
    return np.unique(structure.atom_residue[backbone[distance <= reach]])


@pytest.mark.parametrize("text", ["byres resn HEM around 5", "resn HEM expand 5", "within 5 of resn HEM", ":HEM :<5",
                                  ":hem @< 5.0", "byres (r. hem) around 5"])
def test_a_binding_site_in_each_syntax(haemoglobin, text: str) -> None:
    rows = find_residues(haemoglobin, text)
    expected = _within(haemoglobin, np.flatnonzero(haemoglobin.atoms.resname == "HEM"), 5.0, haemoglobin.coords)
    assert len(rows) > 40 and np.array_equal(rows, expected)  # each haem's pocket, in all four chains


def test_around_leaves_out_the_residues_it_is_around_and_expand_keeps_them(haemoglobin) -> None:
    his87 = find_residues(haemoglobin, "A:87")
    around, expand = find_residues(haemoglobin, "A:87 around 6"), find_residues(haemoglobin, "A:87 expand 6")
    assert his87[0] not in around and np.array_equal(expand, np.union1d(around, his87))
    assert np.array_equal(expand, _within(haemoglobin, np.flatnonzero(haemoglobin.atom_residue == his87[0]), 6.0,
                                          haemoglobin.coords))
    in_a = find_residues(haemoglobin, "resn HEM and chain A around 4")
    assert np.array_equal(in_a, find_residues(haemoglobin, "/A:HEM :<4")) and "A:HIS87" in [
        haemoglobin.residue_label(int(row)) for row in in_a]  # the proximal histidine


def test_a_binding_site_is_measured_on_the_coordinates_given(haemoglobin) -> None:
    moved = haemoglobin.coords.copy()
    haem_a = (haemoglobin.atoms.resname == "HEM") & (haemoglobin.atoms.chain == "A")
    moved[haem_a] += 200.0  # far from every chain
    assert len(find_residues(haemoglobin, "resn HEM and chain A around 4")) == 16
    with pytest.raises(ValueError, match="no residue within 4 Å of resn HEM and chain A"):
        find_residues(haemoglobin, "resn HEM and chain A around 4", coords=moved)


def test_a_range_in_either_order(haemoglobin) -> None:
    rows = find_residues(haemoglobin, "B:40-50")
    assert [_label(haemoglobin, int(r)) for r in rows[[0, -1]]] == ["B:ARG40", "B:THR50"] and len(rows) == 11
    assert np.array_equal(find_residues(haemoglobin, "B:50..40"), rows)


def test_insertion_codes() -> None:
    trypsin = read_structure(DATA / "3PTB.pdb.gz")
    segment = trypsin.segments[0]
    k = int(np.flatnonzero(segment.icode != "")[0])
    text = f"{segment.chain}:{segment.resseq[k]}{segment.icode[k]}"
    assert np.array_equal(find_residues(trypsin, text), [segment.residue_index[k]])


@pytest.mark.parametrize(("text", "message"), [
    ("A:999", "no residue A:999 in chain A"), ("Z:5", "no chain Z"), ("A:ALA45", "no residue A:ALA45"),
    ("hello world", "cannot read 'hello world'"), ("", "cannot read"),
    ("resi 45+", r"cannot read 'resi 45\+' as residues: type e.g. A:45.*ChimeraX /A:45-50.*PyMOL chain A and resi"),
    ("A:40-42, 999", "no residue 999 in chain A"), ("A:40,,", "cannot read"), ("/A,Z:5", "no chain Z"),
    ("resi " + "+".join(["45"] * 10_001), "names more than 10,000"),
    ("A:87 around 99", "a distance of 99 Å: give one above 0 and at most 50 Å"),
    ("resn XYZ around 5", "no residue or ligand XYZ"),
    ("resn HEM and chain Q around 5", "no residue or ligand HEM in chain Q"), ("A:999 around 5", "no residue A:999"),
    ("byres all", "cannot read 'byres all'"), ("chain A and chain B", "cannot read"), ("resn XYZ", "no residue XYZ"),
    ("chain A and resn ILE", "no residue ILE in chain A"),
    ("#1", "cannot read"), ("/Z:5", "no chain Z"), ("chain B and resi 400", "no residue chain B and resi 400 in chain B"),
])
def test_clear_messages(haemoglobin, text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        find_residues(haemoglobin, text)


def test_one_letter_sequence() -> None:
    ubiquitin = read_structure(DATA / "1UBQ.pdb.gz")
    assert ubiquitin.segments[0].sequence == "MQIFVKTLTGKTITLEVEPSDTIENVKAKIQDKEGIPPDQQRLIFAGKQLEDGRTLSDYNIQKESTLHLVLRLRGG"


@pytest.mark.parametrize(("text", "chain", "atom"), [
    ("A:45 CA", None, "A:HIS45 CA"), ("45 NE2", "A", "A:HIS45 NE2"), ("/B:45@CB", None, "B:PHE45 CB"),
    ("B/45/CB", "A", "B:PHE45 CB"), ("/4hhb//C/45/N", None, "C:HIS45 N"),
    ("chain D and resi 45 and name CA", None, "D:PHE45 CA"), ("resi 45 & n. CA", "C", "C:HIS45 CA"),
])
def test_atoms_named_as_people_type_them(haemoglobin, text: str, chain: str | None, atom: str) -> None:
    row = find_atom(haemoglobin, text, chain)
    assert f"{_label(haemoglobin, int(haemoglobin.atom_residue[row]))} {haemoglobin.atoms.name[row]}" == atom


@pytest.mark.parametrize(("text", "message"), [
    ("A:45", "cannot read 'A:45' as an atom"), ("A:45 XX", "no atom XX in A:HIS45"),
    ("A:40-45 CA", "names 6 residues"), ("Z:45 CA", "no chain Z"),
])
def test_atoms_that_are_not_there_are_said_so(haemoglobin, text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        find_atom(haemoglobin, text)


@pytest.mark.parametrize(("text", "chain"), [("/A:HEM@FE", None), ("A:HEM FE", None), ("A:HEM142 FE", None),
                                             ("A:142 FE", None), ("A/HEM`142/FE", None), ("resn HEM and name FE", "A"),
                                             ("/A:142@FE", "C")])
def test_an_atom_of_a_ligand_in_each_syntax(haemoglobin, text: str, chain: str | None) -> None:
    row = find_atom(haemoglobin, text, chain)
    atoms = haemoglobin.atoms
    assert (atoms.chain[row], atoms.resname[row], atoms.resseq[row], atoms.name[row]) == ("A", "HEM", 142, "FE")
    ne2 = find_atom(haemoglobin, "A:87 NE2")  # the proximal histidine binds the iron
    assert 1.9 < np.linalg.norm(haemoglobin.coords[row] - haemoglobin.coords[ne2]) < 2.4


@pytest.mark.parametrize(("text", "message"), [
    ("resn HEM and name FE", r"names 4 groups \(A:HEM142, B:HEM148, C:HEM142, D:HEM148\): name one"),
    ("A:HEM XX", "no atom XX in A:HEM142"), ("A:PO4 P", "no residue or group PO4 in chain A"),
    ("/A:HOH@O", "names 56 groups"),
])
def test_a_ligand_atom_not_named_once_is_said_so(haemoglobin, text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        find_atom(haemoglobin, text)


def test_a_nucleotide_and_an_ion_named_like_a_residue() -> None:
    dna = read_structure(DATA / "1BNA.pdb.gz", require_protein=False)
    row = find_atom(dna, "B:DG16 P")  # a two-letter name
    assert (dna.atoms.chain[row], dna.atoms.resname[row], dna.atoms.resseq[row]) == ("B", "DG", 16)
    assert find_atom(dna, "/B:16@P") == row and set(dna.atoms.resseq[find_group(dna, "A:DA5")].tolist()) == {5}
    with pytest.raises(ValueError, match="no residue DA"):  # no backbone to find residues in
        find_residues(dna, "resn DA")
    haemoglobin = read_structure(DATA / "4HHB.pdb.gz")
    phosphorus = find_atom(haemoglobin, "B:PO4 P")  # read as the group PO4 when no residue 4 is named PO
    assert (haemoglobin.atoms.chain[phosphorus], haemoglobin.atoms.resname[phosphorus]) == ("B", "PO4")


def test_a_file_that_names_no_chain_says_so() -> None:
    adk = read_structure(DATA / "1AKE_adk_closed.pdb.gz")  # chain column blank
    with pytest.raises(ValueError, match=r"no chain A with a protein backbone \(chains: none \(the file names no"):
        find_residues(adk, "chain A and resi 20-30")
    assert len(find_residues(adk, "resi 20-30")) == 11
