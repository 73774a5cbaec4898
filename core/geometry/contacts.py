"""Polar contacts: the nitrogen and oxygen atoms of two residues or groups close enough for a
hydrogen bond (2.5 to 3.5 Å between donor and acceptor), as PyMOL's *find polar contacts*
and ChimeraX's ``contacts`` show them around a binding site. By distance, between atoms that
can donate and accept a hydrogen bond: the roles of the atoms of the standard amino acids and
nucleotides are known (:data:`BACKBONE_ROLES`, :data:`BASE_ROLES`, ...: a backbone amide donates,
a carbonyl or a carboxylate accepts, a base pairs as Watson and Crick drew it, a proline's
nitrogen and a nitrogen bound to a metal, a haem's four, do neither), so two acceptors or two
donors make no contact; a ligand's atoms, whose hydrogens a crystal structure seldom gives,
may do either. The bonds of metal ions to the atoms around them are listed apart
(:func:`metal_bonds`)."""

from __future__ import annotations

import gemmi
import numpy as np
from scipy.spatial import cKDTree

from core.protein.lookup import Selected
from core.protein.structure import AtomTable, Structure, nucleotide_letter

POLAR_REACH = 3.5
"""Å: the farthest a donor and an acceptor of a hydrogen bond are apart."""
CLOSEST = 2.5
"""Å: nearer than this, two atoms are bonded or clash, not hydrogen-bonded."""
METAL_BOND = 2.6
"""Å: a nitrogen this near a metal is bound to it (Fe, Zn, Cu or Mg to N: 2.0-2.2 Å)."""
METAL_REACH = 3.1
"""Å: the farthest a metal ion and an N, O or S atom it binds are apart (Zn-N 2.1, Ca-O 2.4 to 3.1)."""

DONOR, ACCEPTOR, EITHER, NEITHER = "d", "a", "da", ""
"""The roles of an atom in hydrogen bonds (a role is the letters of what it can do)."""
BACKBONE_ROLES = {"N": DONOR, "O": ACCEPTOR, "OXT": ACCEPTOR}
"""An amino acid's backbone (a proline's N aside: :data:`SIDE_CHAIN_ROLES`)."""
SIDE_CHAIN_ROLES = {
    "ASP": {"OD1": ACCEPTOR, "OD2": ACCEPTOR}, "GLU": {"OE1": ACCEPTOR, "OE2": ACCEPTOR},
    "ASN": {"OD1": ACCEPTOR, "ND2": DONOR}, "GLN": {"OE1": ACCEPTOR, "NE2": DONOR},
    "HIS": {"ND1": EITHER, "NE2": EITHER}, "LYS": {"NZ": DONOR}, "ARG": {"NE": DONOR, "NH1": DONOR, "NH2": DONOR},
    "SER": {"OG": EITHER}, "THR": {"OG1": EITHER}, "TYR": {"OH": EITHER}, "TRP": {"NE1": DONOR},
    "PRO": {"N": NEITHER},
}
"""Each standard amino acid's side chain, by residue name (and a proline's N, which neither donates nor accepts)."""
BASE_ROLES = {
    "A": {"N1": ACCEPTOR, "N3": ACCEPTOR, "N6": DONOR, "N7": ACCEPTOR, "N9": NEITHER},
    "G": {"N1": DONOR, "N2": DONOR, "O6": ACCEPTOR, "N3": ACCEPTOR, "N7": ACCEPTOR, "N9": NEITHER},
    "C": {"N3": ACCEPTOR, "O2": ACCEPTOR, "N4": DONOR, "N1": NEITHER},
    "T": {"N3": DONOR, "O2": ACCEPTOR, "O4": ACCEPTOR, "N1": NEITHER},
    "U": {"N3": DONOR, "O2": ACCEPTOR, "O4": ACCEPTOR, "N1": NEITHER},
}
"""Nucleotides: each base's roles, by its one-letter code; the sugar-phosphate's are :data:`SUGAR_ROLES`."""
SUGAR_ROLES = {"OP1": ACCEPTOR, "OP2": ACCEPTOR, "OP3": ACCEPTOR, "O1P": ACCEPTOR, "O2P": ACCEPTOR,
               "O3'": ACCEPTOR, "O4'": ACCEPTOR, "O5'": ACCEPTOR, "O2'": EITHER}
"""A nucleotide's sugar and phosphate (the ester oxygens accept only: the pairs across a
phosphodiester, O3' to the next OP1, are bonded, not hydrogen-bonded)."""


def hydrogen_bond_role(category: str, resname: str, name: str, parents: dict[str, str] | None = None) -> str:
    """What an N or O atom can do in a hydrogen bond (:data:`DONOR`, :data:`ACCEPTOR`,
    :data:`EITHER` or :data:`NEITHER`), by its residue's category, name and its own name; an
    atom the tables do not name (a ligand's, a modified residue's side chain or base) may do either."""
    if category == "protein":
        return SIDE_CHAIN_ROLES.get(resname, {}).get(name, BACKBONE_ROLES.get(name, EITHER))
    if category == "nucleic":
        base = BASE_ROLES.get(nucleotide_letter(resname, parents), {})  # a modified base's (lower case): either
        return base.get(name, SUGAR_ROLES.get(name, EITHER))
    return EITHER


def selection_contacts(structure: Structure, coords: np.ndarray, selected: Selected) -> tuple[np.ndarray, np.ndarray]:
    """The polar contacts and the metal bonds (each (k, 2) coordinate rows, on ``coords``) of
    the atoms of ``selected``'s residues and groups (ligands, ions, waters, nucleotides), to
    the atoms around them and among them, but none between two of its residues (a chain
    selected shows its contacts to the rest, a ligand with its pocket its hydrogen bonds to
    the pocket)."""
    residues = np.flatnonzero(np.isin(structure.atom_residue, selected.residues))
    chosen = np.union1d(residues, selected.groups)
    return (polar_contacts(structure.atoms, coords, chosen, apart=residues),
            metal_bonds(structure.atoms, coords, chosen))


def polar_contacts(atoms: AtomTable, coords: np.ndarray, chosen: np.ndarray, reach: float = POLAR_REACH,
                   *, apart: np.ndarray | None = None) -> np.ndarray:
    """(k, 2) coordinate rows of the polar contacts of the atoms ``chosen`` (rows): pairs of a
    chosen N or O atom and an N or O atom of another residue or group (a water only if chosen;
    not both in ``apart``, as a chain's own when its contacts to the rest are asked)
    :data:`CLOSEST` to ``reach`` Å from it, on ``coords``, one able to donate a hydrogen bond
    and the other to accept it (:func:`hydrogen_bond_role`); the first alternate conformer
    only, each pair once, the lower row first, in increasing order."""
    element = np.char.upper(atoms.element.astype(str))
    water = atoms.category == "water"
    water[chosen] = False
    polar = np.flatnonzero(np.isin(element, ("N", "O")) & ~water & np.isin(atoms.altloc, ("", "A")))
    keys = np.stack([atoms.category[polar], atoms.resname[polar], atoms.name[polar]], axis=1).astype(str)
    kinds, which = np.unique(keys, axis=0, return_inverse=True)  # each kind of atom's role looked up once
    role = np.full(len(atoms), NEITHER, dtype="<U2")
    role[polar] = np.array([hydrogen_bond_role(*kind, atoms.parents) for kind in kinds.tolist()] or [NEITHER])[which]
    metals = _metals(atoms, element)
    if len(metals) and len(polar):  # the nitrogens a metal holds
        bound = cKDTree(coords[metals]).query(coords[polar], distance_upper_bound=METAL_BOND)[0] <= METAL_BOND
        role[polar[bound & (element[polar] == "N")]] = NEITHER
    polar = polar[role[polar] != NEITHER]
    donates, accepts = (np.char.find(role, letter) >= 0 for letter in (DONOR, ACCEPTOR))
    first, second = _near(atoms, coords, np.intersect1d(polar, chosen), polar, reach)
    keep = ((np.linalg.norm(coords[first] - coords[second], axis=1) >= CLOSEST)
            & (donates[first] & accepts[second] | accepts[first] & donates[second]))
    if apart is not None:
        keep &= ~(np.isin(first, apart) & np.isin(second, apart))
    return _pairs(first[keep], second[keep])


def metal_bonds(atoms: AtomTable, coords: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """(k, 2) coordinate rows of the bonds of metal ions to the N, O and S atoms around them
    (waters' too) within :data:`METAL_REACH` Å, on ``coords``, a metal or the atom it binds
    among ``chosen``, as ChimeraX draws a site's metal coordination; the first alternate
    conformer only, each pair once, the lower row first, in increasing order."""
    element = np.char.upper(atoms.element.astype(str))
    first_conformer = np.isin(atoms.altloc, ("", "A"))
    metals = _metals(atoms, element)
    metals = metals[first_conformer[metals]]
    binding = np.flatnonzero(np.isin(element, ("N", "O", "S")) & first_conformer)
    found = [_near(atoms, coords, np.intersect1d(metals, chosen), binding, METAL_REACH),
             _near(atoms, coords, np.intersect1d(binding, chosen), metals, METAL_REACH)]
    return _pairs(*(np.concatenate(ends) for ends in zip(*found, strict=True)))


def _metals(atoms: AtomTable, element: np.ndarray) -> np.ndarray:
    """The rows of the metal atoms (gemmi's elements: Fe, Zn, Mg, Ca, Na, ...)."""
    return np.flatnonzero(np.isin(element, [e for e in np.unique(element) if e and gemmi.Element(e).is_metal]))


def _near(atoms: AtomTable, coords: np.ndarray, source: np.ndarray, targets: np.ndarray, reach: float
          ) -> tuple[np.ndarray, np.ndarray]:
    """Rows of each ``source`` atom and each ``targets`` atom of another residue or group within ``reach`` Å of it."""
    if not len(source) or not len(targets):
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    near = cKDTree(coords[targets]).query_ball_point(coords[source], reach)
    first = np.repeat(source, [len(found) for found in near])
    second = targets[np.concatenate([np.asarray(found, dtype=np.int64) for found in near])]
    other = atoms.residue[first] != atoms.residue[second]
    return first[other], second[other]


def _pairs(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """(k, 2) each pair once, the lower row first, in increasing order (a pair may be found twice)."""
    pairs = np.sort(np.stack([first, second], axis=1), axis=1)
    return np.unique(pairs, axis=0) if len(pairs) else np.empty((0, 2), dtype=np.int64)
