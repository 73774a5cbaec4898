"""Polar contacts on real entries, against gemmi's own contact search."""

from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.geometry.contacts import (
    CLOSEST,
    METAL_BOND,
    POLAR_REACH,
    hydrogen_bond_role,
    metal_bonds,
    polar_contacts,
)
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def _category(name: str) -> str:
    """gemmi's category of a residue name, as the atom table's."""
    found = gemmi.find_tabulated_residue(name)
    return "ligand" if found is None else "protein" if found.is_amino_acid() else "nucleic" if found.is_nucleic_acid() \
        else "ligand"


def _label(atoms, row: int) -> str:
    return f"{atoms.chain[row]}:{atoms.resname[row]}{atoms.resseq[row]} {atoms.name[row]}"


def test_benzamidine_in_trypsins_pocket() -> None:
    """3PTB: the amidinium of the inhibitor bound to Asp189's carboxylate, Ser190 and Gly219,
    as the structure papers describe it."""
    trypsin = read_structure(DATA / "3PTB.pdb.gz")
    atoms = trypsin.atoms
    pairs = polar_contacts(atoms, trypsin.coords, np.flatnonzero(atoms.resname == "BEN"))
    named = {(_label(atoms, a), _label(atoms, b)) for a, b in pairs}
    assert {("A:ASP189 OD1", "A:BEN1 N1"), ("A:ASP189 OD2", "A:BEN1 N2"), ("A:SER190 OG", "A:BEN1 N2"),
            ("A:GLY219 O", "A:BEN1 N1")} <= named
    distances = np.linalg.norm(trypsin.coords[pairs[:, 0]] - trypsin.coords[pairs[:, 1]], axis=1)
    assert np.all((distances >= CLOSEST) & (distances <= POLAR_REACH))


@pytest.mark.parametrize(("name", "chain", "first", "last"), [("1UBQ.pdb.gz", "A", 40, 50), ("4HHB.pdb.gz", "B", 80, 95),
                                                              ("1F9V.pdb.gz", "A", 480, 490)])
def test_the_contacts_are_those_gemmi_finds(name: str, chain: str, first: int, last: int) -> None:
    """Every N and O pair 2.5-3.5 Å apart, one atom in the residues chosen, the other in another
    residue (not a water), first conformers, a donor and an acceptor by their roles, and no N
    bound to a metal (4HHB's His92 and haem): as gemmi's ContactSearch lists them."""
    structure = read_structure(DATA / name)
    atoms = structure.atoms
    chosen = np.flatnonzero((atoms.chain == chain) & (atoms.resseq >= first) & (atoms.resseq <= last)
                            & (atoms.category == "protein"))
    ours = {tuple(pair) for pair in polar_contacts(atoms, structure.coords, chosen).tolist()}
    st = gemmi.read_structure(str(DATA / name))
    st.remove_alternative_conformations()
    st.remove_waters()
    search = gemmi.ContactSearch(POLAR_REACH)
    search.ignore = gemmi.ContactSearch.Ignore.SameResidue
    ns = gemmi.NeighborSearch(st[0], gemmi.UnitCell(), 5).populate()  # the model alone: no crystal mates
    row_of = {(c, r, n): k for k, (c, r, n) in enumerate(zip(atoms.chain.tolist(), atoms.resseq.tolist(),
                                                            atoms.name.tolist(), strict=True))
              if atoms.altloc[k] in ("", "A")}
    theirs = set()
    for contact in search.find_contacts(ns):
        ends = [(c.chain.name, c.residue.seqid.num, c.atom.name) for c in (contact.partner1, contact.partner2)]
        partners = (contact.partner1, contact.partner2)
        if contact.dist < CLOSEST or not all(c.atom.element.name in ("N", "O") for c in partners):
            continue
        roles = [hydrogen_bond_role(_category(c.residue.name), c.residue.name, c.atom.name) for c in partners]
        if not ("d" in roles[0] and "a" in roles[1] or "a" in roles[0] and "d" in roles[1]):
            continue
        if any(c.atom.element.name == "N" and any(m.to_cra(st[0]).atom.element.is_metal
                                                  for m in ns.find_atoms(c.atom.pos, "\0", radius=METAL_BOND))
               for c in partners):
            continue
        rows = tuple(sorted(row_of[end] for end in ends))
        if np.isin(rows, chosen).any():
            theirs.add(rows)
    assert len(ours) > 5 and ours == theirs


def test_the_nitrogens_a_metal_holds_make_no_contact() -> None:
    """4HHB: of chain A's haem, the propionate's salt bridge to His45 is a polar contact; the
    pyrrole nitrogens and the proximal His87's NE2, all bound to the iron, make none."""
    haemoglobin = read_structure(DATA / "4HHB.pdb.gz")
    atoms, coords = haemoglobin.atoms, haemoglobin.coords
    haem = np.flatnonzero((atoms.resname == "HEM") & (atoms.chain == "A"))
    pairs = polar_contacts(atoms, coords, haem)
    named = {(_label(atoms, a), _label(atoms, b)) for a, b in pairs}
    assert ("A:HIS45 NE2", "A:HEM142 O2D") in named
    iron = haem[atoms.name[haem] == "FE"][0]
    held = np.flatnonzero((np.linalg.norm(coords - coords[iron], axis=1) <= METAL_BOND) & (atoms.element == "N"))
    assert len(held) == 5 and "A:HIS87 NE2" in {_label(atoms, row) for row in held}  # four pyrroles, one histidine
    assert not np.isin(pairs, held).any()


@pytest.mark.parametrize("name", ["1AYE.pdb.gz", "3PTB.pdb.gz", "4HHB.pdb.gz", "1BMA.pdb.gz"])
def test_the_metal_bonds_are_those_the_file_records(name: str) -> None:
    """The bonds of carboxypeptidase's zinc, trypsin's and elastase's calcium (one of them
    3.09 Å long) and haemoglobin's iron to the atoms around them, found from the metals or
    from the atoms they bind, are the file's own metal links (LINK, read by gemmi)."""
    structure = read_structure(DATA / name)
    atoms, coords = structure.atoms, structure.coords
    st = gemmi.read_structure(str(DATA / name))
    links = {tuple(sorted(f"{p.chain_name}:{p.res_id.name}{p.res_id.seqid.num} {p.atom_name}"
                          for p in (c.partner1, c.partner2)))
             for c in st.connections if c.type == gemmi.ConnectionType.MetalC}
    element = np.char.upper(atoms.element.astype(str))
    metal = np.flatnonzero(np.isin(element, ("ZN", "CA", "FE")) & (atoms.category != "protein"))
    for chosen in (metal, np.flatnonzero(atoms.category == "protein")):
        pairs = metal_bonds(atoms, coords, chosen)
        found = {tuple(sorted((_label(atoms, a), _label(atoms, b)))) for a, b in pairs}
        expected = links if len(chosen) == len(metal) else {pair for pair in links if "HOH" not in " ".join(pair)}
        assert found == expected and len(expected) >= 2


def test_the_base_pairs_of_a_double_helix() -> None:
    """1BNA, the Dickerson dodecamer: every Watson-Crick hydrogen bond between its strands
    (three a G-C pair, two an A-T pair) and nothing of the sugars and phosphates, whose ester
    oxygens, 2.5 Å from the next phosphate's, are bonded, not hydrogen-bonded."""
    dna = read_structure(DATA / "1BNA.pdb.gz", require_protein=False)
    atoms = dna.atoms
    strand = np.flatnonzero(atoms.chain == "A")
    pairs = polar_contacts(atoms, dna.coords, strand, apart=strand)
    found = {(int(atoms.resseq[a]), str(atoms.name[a]), int(atoms.resseq[b]), str(atoms.name[b])) for a, b in pairs}
    watson_crick = {"G": [("N1", "N3"), ("N2", "O2"), ("O6", "N4")], "C": [("N3", "N1"), ("O2", "N2"), ("N4", "O6")],
                    "A": [("N1", "N3"), ("N6", "O4")], "T": [("N3", "N1"), ("O4", "N6")]}
    for number, letter in enumerate("CGCGAATTCGCG", start=1):
        assert {(number, mine, 25 - number, theirs) for mine, theirs in watson_crick[letter]} <= found
    assert len(found) < 45 and not any("'" in name or "P" in name for pair in found for name in pair[1::2])


def test_apart_leaves_out_the_pairs_within_it_and_chosen_waters_take_part() -> None:
    """A helix's contacts with its own left apart are those to the rest; waters make contacts
    only when chosen (3PTB: a water bridging benzamidine to the protein)."""
    ubiquitin = read_structure(DATA / "1UBQ.pdb.gz")
    atoms = ubiquitin.atoms
    helix = np.flatnonzero((atoms.resseq >= 23) & (atoms.resseq <= 34) & (atoms.category == "protein"))
    every, outward = (polar_contacts(atoms, ubiquitin.coords, helix, apart=apart) for apart in (None, helix))
    inside = np.isin(every, helix).all(axis=1)
    assert inside.sum() >= 8  # the helix's own i -> i+4 hydrogen bonds
    assert np.array_equal(outward, every[~inside])
    trypsin = read_structure(DATA / "3PTB.pdb.gz")
    atoms = trypsin.atoms
    benzamidine = np.flatnonzero(atoms.resname == "BEN")
    alone = polar_contacts(atoms, trypsin.coords, benzamidine)
    assert not (atoms.category[alone] == "water").any()
    near = np.linalg.norm(trypsin.coords[:, None] - trypsin.coords[benzamidine], axis=2).min(axis=1) < 3.5
    waters = np.flatnonzero(near & (atoms.category == "water"))
    bridged = polar_contacts(atoms, trypsin.coords, np.concatenate([benzamidine, waters]))
    assert len(waters) and (atoms.category[bridged] == "water").any(axis=1).sum() > len(waters)  # to both sides
