"""Residues named as people type them, on real entries."""

import re
from pathlib import Path

import numpy as np
import pytest

from core.protein.lookup import find_atom, find_group, find_residues, find_selection
from core.protein.reading import read_structure
from core.protein.selection import read

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
    with pytest.raises(ValueError, match="no residue of a protein backbone is in 'resn HEM and chain A around 4'"):
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
    ("byres", "a selection is missing at the end"), ("chain A and chain B", "no residue of a protein backbone is in"),
    ("resn XYZ", "no residue XYZ"), ("(chain A or chain B", "expected a closing parenthesis at the end"),
    ("chain A and", "a selection is missing at the end"), ("chain A) or chain B", r"'\)' where an operator or the end"),
    ("resi 40 around", "a distance in Å is missing"), ("resi 40 around five", "not 'five'"),
    ("chain A and ss Q", "secondary structure is H"), ("resi 9998 or resi 9999", r"no residue of a protein backbone is in 'resi 9998 or resi 9999' \(no residue resi 9998 in any chain; no residue resi 9999 in any chain\)"),
    ("chain A or name CA", "cannot read 'name CA' as residues"), ("/Q | /R", r"\(no chain Q; no chain R\)"),
    ("within 5 of", "a selection is missing at the end"), ("(" * 5000 + "chain A" + ")" * 5000, "nested more than 100"),
    ("not " * 500 + "chain A", "nested more than 100"), ("A:40" + " around 1" * 200, "nested more than 100"),
    ("chain A or " * 3000 + "chain B", "more than 1,000 operators"), ("chain A within 5 resn HEM", "expected of before 'resn'"),
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
    with pytest.raises(ValueError, match=r"no chain A \(chains: none \(the file names no"):
        find_residues(adk, "chain A and resi 20-30")
    assert len(find_residues(adk, "resi 20-30")) == 11


def _rows_where(structure, keep) -> np.ndarray:
    """Brute force: the residue-table rows of the residues for which ``keep(segment, k)`` holds."""
    return np.array([int(s.residue_index[k]) for s in structure.segments for k in range(len(s)) if keep(s, k)],
                    dtype=np.int64)


@pytest.mark.parametrize(("text", "keep"), [
    ("chain A and ss H", lambda s, k: s.chain == "A" and s.ss[k] == "H"),
    ("helix & /B", lambda s, k: s.chain == "B" and s.ss[k] == "H"),  # ChimeraX
    ("ss L+S and chain C", lambda s, k: s.chain == "C" and s.ss[k] in "CE"),
    ("resi 40-45 or resi 90", lambda s, k: 40 <= s.resseq[k] <= 45 or s.resseq[k] == 90),  # in every chain
    ("not (chain A or chain B)", lambda s, k: s.chain in "CD"),
    ("!chain A & !chain B", lambda s, k: s.chain in "CD"),
    ("~/A & ~/B", lambda s, k: s.chain in "CD"),
    ("/A:40-50 & :HIS", lambda s, k: s.chain == "A" and 40 <= s.resseq[k] <= 50 and s.resname[k] == "HIS"),
    ("chain A and not resn HIS+LEU", lambda s, k: s.chain == "A" and s.resname[k] not in ("HIS", "LEU")),
    ("not chain A and ss H", lambda s, k: s.chain != "A" and s.ss[k] == "H"),  # not binds tightest
    ("resi 87 and chain A or resi 92 and chain B", lambda s, k: (s.chain, s.resseq[k]) in (("A", 87), ("B", 92))),
    ("polymer and (chain C or chain D) and resi 10-20", lambda s, k: s.chain in "CD" and 10 <= s.resseq[k] <= 20),
    ("all and not strand", lambda s, k: True),  # haemoglobin has no strand
    ("(chain A or chain Q) and resi 10-20 or resi 9999", lambda s, k: s.chain == "A" and 10 <= s.resseq[k] <= 20),
    ("not (chain Q or resn XYZ)", lambda s, k: True),  # what is not there selects nothing, as in PyMOL
    ("chain A or " * 900 + "chain B", lambda s, k: s.chain in "AB"),  # a long run of or is one operation
])
def test_selections_combined_by_operators(haemoglobin, text: str, keep) -> None:
    rows = find_residues(haemoglobin, text, "A")
    assert np.array_equal(rows, _rows_where(haemoglobin, keep)) and len(rows) >= 2


@pytest.mark.parametrize(("text", "reference", "chain", "reach"), [
    ("byres organic around 5", "HEM", None, 5.0),  # PO4 is no organic group: it has no carbon
    ("resn HEM and chain A around 4", "HEM", "A", 4.0),  # the distances bind last: chain A's haem
    ("(resn HEM and chain A) around 4", "HEM", "A", 4.0),
    (":HEM :<4.5 & /C", "HEM", "CC", 4.5),  # the zone, then the chain
    ("chain B within 6 of solvent", "HOH", "BB", 6.0),
])
def test_binding_sites_combined_by_operators(haemoglobin, text: str, reference: str, chain, reach: float) -> None:
    """Against brute force; a chain of two letters keeps the residues of that chain of the site
    of every chain's reference (e.g. C's residues near any haem)."""
    atoms = haemoglobin.atoms
    near = (atoms.resname == reference) & ((atoms.chain == chain) if chain and len(chain) == 1 else True)
    expected = _within(haemoglobin, np.flatnonzero(near), reach, haemoglobin.coords)
    if "around" in text:
        expected = np.setdiff1d(expected, np.unique(haemoglobin.atom_residue[near]))
    if chain and len(chain) == 2:
        expected = np.intersect1d(expected, _rows_where(haemoglobin, lambda s, k: s.chain == chain[0]))
    assert len(expected) > 5 and np.array_equal(find_residues(haemoglobin, text), expected)


@pytest.mark.parametrize("seed", range(6))
def test_the_operators_obey_the_laws_of_sets(haemoglobin, seed: int) -> None:
    """For random ranges X and Y: X or Y, X and Y, not X, and De Morgan's laws, as numpy's set
    operations on X's and Y's own rows give them."""
    random = np.random.default_rng(seed)
    x, y = (f"{random.choice(list('ABCD'))}:{a}-{a + random.integers(5, 60)}" for a in random.integers(1, 80, 2))
    rows_x, rows_y, every = find_residues(haemoglobin, x), find_residues(haemoglobin, y), np.arange(573)
    assert np.array_equal(find_residues(haemoglobin, f"{x} or {y}"), np.union1d(rows_x, rows_y))
    assert np.array_equal(find_residues(haemoglobin, f"not {x}"), np.setdiff1d(every, rows_x))
    assert np.array_equal(find_residues(haemoglobin, f"not ({x} or {y})"),
                          find_residues(haemoglobin, f"not {x} and not {y}"))
    both = np.intersect1d(rows_x, rows_y)
    if len(both):
        assert np.array_equal(find_residues(haemoglobin, f"{x} and {y}"), both)
        assert np.array_equal(find_residues(haemoglobin, f"not ({x} and {y})"),
                              find_residues(haemoglobin, f"not {x} or not {y}"))


@pytest.mark.parametrize("text", ["A:45", "/B:40-50", "chain A and ss H", "byres resn HEM around 5",
                                  "resi 40-45 or resi 90", ":HEM :<4.5 & /C", "not chain A"])
def test_a_selection_holds_the_residues_find_residues_names(haemoglobin, text: str) -> None:
    assert np.array_equal(find_selection(haemoglobin, text, "A").residues, find_residues(haemoglobin, text, "A"))


@pytest.mark.parametrize(("text", "chain", "labels"), [
    ("/B:HEM", "A", ["B:HEM148"]), ("resn HEM", "C", ["C:HEM142"]),  # one group: in the edited chain
    ("A:HEM", None, ["A:HEM142"]), ("resn HEM and chain D", None, ["D:HEM148"]),
    ("resn HEM", None, ["A:HEM142", "B:HEM148", "C:HEM142", "D:HEM148"]),  # combined, or none named: every one
    ("resn HEM and chain A or byres resn HEM and chain A around 4", None,
     None),  # a ligand and its pocket, waters too, as PyMOL's byres
    ("/A:HOH", None, [f"A:HOH{n}" for n in range(143, 199)]), ("solvent and chain A", None,
                                                                [f"A:HOH{n}" for n in range(143, 199)]),
    ("inorganic", None, ["B:PO4147", "D:PO4147"]),
])
def test_a_selection_holds_whole_groups(haemoglobin, text: str, chain: str | None, labels: list[str] | None) -> None:
    """Ligands, ions and waters named are selected whole, each group once in its labels."""
    selected = find_selection(haemoglobin, text, chain)
    atoms = haemoglobin.atoms
    group = atoms.residue[selected.groups]
    assert np.array_equal(selected.groups, np.flatnonzero(np.isin(atoms.residue, group)
                                                         & (haemoglobin.atom_residue < 0)))  # whole, sorted
    named = selected.labels(haemoglobin)[len(selected.residues):]
    if labels is None:
        pocket = find_residues(haemoglobin, "byres resn HEM and chain A around 4")
        assert np.array_equal(selected.residues, pocket) and len(pocket) == 16
        assert named[0] == "A:HEM142" and len(named) > 1 and all(name.startswith("A:HOH") for name in named[1:])
    else:
        assert named == labels and not len(selected.residues)


@pytest.mark.parametrize(("text", "message"), [
    ("A:999", "no residue A:999 in chain A"), ("resn XYZ", "no residue XYZ"),
    ("resn XYZ or chain Q", "'resn XYZ or chain Q' selects nothing here (no residue or ligand XYZ; no chain Q)"),
])
def test_a_selection_of_nothing_is_said_so(haemoglobin, text: str, message: str) -> None:
    with pytest.raises(ValueError, match=re.escape(message)):
        find_selection(haemoglobin, text, "A")


@pytest.mark.parametrize("text", ["all", "*", "not resn XYZ"])
def test_everything_selected_holds_every_residue_and_group(haemoglobin, text: str) -> None:
    selected = find_selection(haemoglobin, text)
    assert np.array_equal(selected.residues, np.arange(haemoglobin.n_residues))
    assert np.array_equal(selected.groups, np.flatnonzero(haemoglobin.atom_residue < 0)) and len(selected.groups) > 200


@pytest.mark.parametrize(("text", "chain", "labels"), [
    ("A:140-145", None, ["A:TYR140", "A:ARG141", "A:HEM142", "A:HOH143", "A:HOH144", "A:HOH145"]),  # past the end
    ("resi 184-186", "C", ["C:HOH184", "C:HOH185", "C:HOH186"]),  # in the edited chain
    ("/A:45,HEM", None, ["A:HIS45", "A:HEM142"]), ("A:45, A:HEM142, A:999", None, ["A:HIS45", "A:HEM142"]),
    ("resn HIS+HEM and chain D", None, [f"D:HIS{n}" for n in (2, 63, 77, 92, 97, 116, 117, 143, 146)] + ["D:HEM148"]),
    ("(resi 184-186 or resi 45) and chain B", None, ["B:PHE45", "B:HOH184", "B:HOH185", "B:HOH186"]),  # as PyMOL's resi
    ("chain A and resi 142", None, ["A:HEM142"]),
])
def test_numbers_ranges_and_lists_name_groups_as_they_name_residues(haemoglobin, text: str, chain: str | None,
                                                                     labels: list[str]) -> None:
    assert find_selection(haemoglobin, text, chain).labels(haemoglobin) == labels


@pytest.mark.parametrize("name", ["4HHB.pdb.gz", "1BMA.pdb.gz", "1F9V.pdb.gz", "7Z9T.cif.gz", "1BNA.pdb.gz",
                                  "1AKE_adk_closed.pdb.gz", "3PTB.pdb.gz"])
def test_every_label_names_what_it_labels(name: str) -> None:
    """What the editor lists as selected (``rw.selection``) can be typed back: residues and
    groups whose names hold digits (1BMA's SO4290 and 0QH256, 7Z9T's BBB:87B401) and those of a
    file that names no chain (1F9V's :ADP999, 1AKE's :MET1)."""
    structure = read_structure(DATA / name, require_protein=False)
    labels = find_selection(structure, "all").labels(structure)
    assert len(labels) > 20
    for label in labels:
        assert find_selection(structure, label).labels(structure) == [label], label


@pytest.mark.parametrize(("text", "name", "number", "icode"), [
    ("A:M3L72", "M3L", 72, ""), ("A:K45", "K", 45, ""), ("A:45A", None, 45, "A"), ("A:HIS45A", "HIS", 45, "A"),
    ("A:5CM12", "5CM", 12, ""), ("A:0QH256", "0QH", 256, ""),
])
def test_names_with_digits_and_insertion_codes(text: str, name: str | None, number: int, icode: str) -> None:
    named = read(text)
    assert (named.chain, named.name, named.first, named.icode) == ("A", name, number, icode)
