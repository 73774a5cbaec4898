"""What validation and regularization need of a structure besides coordinates: backbone
rows, junctions, Ramachandran classes, van der Waals radii and the atom pairs that are
bonded (at most three bonds apart), which never clash. Computed once per structure."""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import sparse
from scipy.spatial import cKDTree

from core.geometry.ideal import BOND_SLACK, COVALENT_RADIUS, POLAR_CONTACT, VDW_RADIUS
from core.geometry.vectors import dihedral, distance
from core.protein.structure import AtomTable, Structure


@dataclass(frozen=True, eq=False)
class Topology:
    """What validation needs of a structure besides coordinates (see :func:`topology`).

    Attributes
    ----------
    backbone : (n_residues, 4) int64
        Rows of N, Cα, C, O of every residue of the residue table, -1 where missing.
    labels : (n_residues,) str
        Residue labels ('A:LYS48').
    first, second : (n_junctions,) int64
        Residue-table rows of the two residues of each junction (same segment).
    cis : (n_junctions,) bool
        Junctions with |ω| < 90° in the structure as read.
    proline : (n_junctions,) bool
        Junctions whose second residue is a proline.
    rama_class : (n_residues,) int8
        Index into :data:`~core.geometry.ramachandran.RAMACHANDRAN_CLASSES`.
    checked : (n_atoms,) bool
        Atoms checked for clashes (heavy, not water, with a van der Waals radius).
    radius : (n_atoms,) float64
        Van der Waals radius, Å (0 where not checked).
    polar : (n_atoms,) bool
        N and O atoms.
    excluded : sorted int64
        Keys ``i * n_atoms + j`` (i < j) of atom pairs at most three bonds apart.
    conformer : (n_atoms,) int64
        Alternate location as a number, 0 where none.
    atoms : AtomTable
        The structure's atoms, and ``atom_residue`` their residue-table rows, -1 if none (for
        :meth:`atom_label`).
    """

    backbone: np.ndarray
    labels: np.ndarray
    first: np.ndarray
    second: np.ndarray
    cis: np.ndarray
    proline: np.ndarray
    rama_class: np.ndarray
    checked: np.ndarray
    radius: np.ndarray
    polar: np.ndarray
    excluded: np.ndarray
    conformer: np.ndarray = field(repr=False)
    atoms: AtomTable = field(repr=False)
    atom_residue: np.ndarray = field(repr=False)

    @property
    def n_atoms(self) -> int:
        return len(self.radius)

    def atom_label(self, row: int) -> str:
        """Label of atom ``row``: its residue's (``A:LYS48``; of a ligand or water ``A:HOH301``),
        its name, and its alternate location after a dot (``A:SER65 OG.B``)."""
        atoms, owner = self.atoms, int(self.atom_residue[row])
        residue = self.labels[owner] if owner >= 0 else f"{atoms.chain[row]}:{atoms.resname[row]}{atoms.resseq[row]}"
        return f"{residue} {atoms.name[row]}" + (f".{atoms.altloc[row]}" if atoms.altloc[row] else "")

    def around(self, rows: np.ndarray) -> Topology:
        """This topology with only the excluded pairs that have an atom in ``rows``: enough
        to :meth:`screen` such pairs, and faster for a few rows of a large structure."""
        touched = np.zeros(self.n_atoms, dtype=bool)
        touched[rows] = True
        i, j = np.divmod(self.excluded, self.n_atoms)
        return replace(self, excluded=self.excluded[touched[i] | touched[j]])

    def contact(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Contact distance (Å) of atom pairs ``(i, j)``: the sum of radii, or POLAR_CONTACT."""
        return np.where(self.polar[i] & self.polar[j], POLAR_CONTACT, self.radius[i] + self.radius[j])

    def search_radius(self, reach: float) -> float:
        """Distance (Å) within which a pair may be closer than its contact minus ``reach``."""
        return 2 * float(self.radius.max()) - reach

    def close_pairs(self, coords: np.ndarray, rows: np.ndarray | None, reach: float) -> tuple[np.ndarray, np.ndarray]:
        """Checked atom pairs (i < j), at least one in ``rows`` (all if None), not excluded,
        closer than their contact distance minus ``reach`` (Å)."""
        cutoff = self.search_radius(reach)
        atoms = np.flatnonzero(self.checked)
        if rows is None:
            pairs = cKDTree(coords[atoms]).query_pairs(cutoff, output_type="ndarray")
            return self.screen(coords, atoms[pairs[:, 0]], atoms[pairs[:, 1]], reach)
        rows = np.unique(rows)
        rows = rows[self.checked[rows]]
        if len(rows) == 0:
            return rows, rows
        low, high = coords[rows].min(axis=0) - cutoff, coords[rows].max(axis=0) + cutoff
        others = np.setdiff1d(atoms[np.all((coords[atoms] >= low) & (coords[atoms] <= high), axis=1)], rows)
        tree = cKDTree(coords[rows])
        inner = tree.query_pairs(cutoff, output_type="ndarray")
        outer = tree.sparse_distance_matrix(cKDTree(coords[others]), cutoff, output_type="ndarray")
        i = np.concatenate([rows[inner[:, 0]], rows[outer["i"]]])
        j = np.concatenate([rows[inner[:, 1]], others[outer["j"]]])
        return self.screen(coords, np.minimum(i, j), np.maximum(i, j), reach)

    def screen(self, coords: np.ndarray, i: np.ndarray, j: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
        """The pairs (i < j) that are neither excluded (bonded, other conformer) nor farther
        than their contact distance minus ``reach`` (Å)."""
        keys = i * self.n_atoms + j
        position = np.searchsorted(self.excluded, keys).clip(max=max(len(self.excluded) - 1, 0))
        bonded = self.excluded[position] == keys if len(self.excluded) else np.zeros(len(keys), dtype=bool)
        ci, cj = self.conformer[i], self.conformer[j]
        keep = ~bonded & ((ci == 0) | (cj == 0) | (ci == cj))
        i, j = i[keep], j[keep]
        near = distance(coords[i], coords[j]) < self.contact(i, j) - reach
        return i[near], j[near]


@functools.lru_cache(maxsize=8)
def topology(structure: Structure) -> Topology:
    """The validation set-up of ``structure`` (cached: structures are immutable)."""
    atoms = structure.atoms
    backbone = _backbone_rows(structure)
    segment_of = np.concatenate([np.full(len(s), k) for k, s in enumerate(structure.segments)] or [np.empty(0, int)])
    first = np.flatnonzero(segment_of[:-1] == segment_of[1:])
    second = first + 1
    resname = np.concatenate([s.resname for s in structure.segments] or [np.empty(0, str)])
    labels = np.concatenate([np.array(s.labels, dtype=str) for s in structure.segments] or [np.empty(0, str)])
    coords = structure.coords
    omega = _junction_dihedral(coords, backbone, first, second)
    rama_class = np.select([resname == "GLY", resname == "PRO"], [1, 2], 0).astype(np.int8)

    radius = np.array([VDW_RADIUS.get(e, 0.0) for e in atoms.element])
    checked = (radius > 0) & (atoms.category != "water")
    radius[~checked] = 0.0
    polar = np.isin(atoms.element, ("N", "O"))
    return Topology(
        backbone=backbone,
        labels=labels,
        first=first,
        second=second,
        cis=np.abs(np.nan_to_num(omega, nan=180.0)) < 90.0,
        proline=resname[second] == "PRO",
        rama_class=rama_class,
        checked=checked,
        radius=radius,
        polar=polar,
        excluded=_excluded_pairs(structure, backbone, first, second, checked),
        conformer=np.unique(np.append(atoms.altloc, ""), return_inverse=True)[1][:-1],  # '' sorts first: 0
        atoms=atoms,
        atom_residue=structure.atom_residue,
    )


def _backbone_rows(structure: Structure) -> np.ndarray:
    """(n_residues, 4) rows of the N, Cα, C, O atoms the segments were built from, -1 if none."""
    atoms, owner = structure.atoms, structure.atom_residue
    n_residues = structure.n_residues
    rows = np.full((n_residues, 4), -1, dtype=np.int64)
    for slot, name in enumerate(("N", "CA", "C", "O")):
        reference = np.concatenate([getattr(s, name.lower()) for s in structure.segments] or [np.empty((0, 3))])
        candidates = np.flatnonzero((atoms.name == name) & (owner >= 0))
        same = np.all(structure.coords[candidates] == reference[owner[candidates]], axis=1)
        candidates = candidates[same]
        residues, first = np.unique(owner[candidates], return_index=True)
        rows[residues, slot] = candidates[first]
    return rows


def _junction_dihedral(coords: np.ndarray, backbone: np.ndarray, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """ω (degrees) of each junction, NaN where an atom is missing."""
    quad = np.stack([backbone[first, 1], backbone[first, 2], backbone[second, 0], backbone[second, 1]], axis=1)
    xyz = np.where((quad >= 0)[..., None], coords[quad.clip(min=0)], np.nan)
    with np.errstate(invalid="ignore"):
        return dihedral(xyz[:, 0], xyz[:, 1], xyz[:, 2], xyz[:, 3])


def _excluded_pairs(
    structure: Structure, backbone: np.ndarray, first: np.ndarray, second: np.ndarray, checked: np.ndarray
) -> np.ndarray:
    """Sorted keys of the checked atom pairs at most three bonds apart.

    Bonds: atoms of one residue within covalent reach in the input, the peptide bonds of
    the segments, and between residues only disulfides and links that involve a
    non-protein group (ligands, glycans, nucleic acids): two amino acids close together
    in the file are a clash to report, not a bond.
    """
    n_atoms = structure.n_atoms
    table = structure.atoms
    atoms = np.flatnonzero(checked)
    covalent = np.array([COVALENT_RADIUS.get(e, 0.0) for e in table.element])
    tree = cKDTree(structure.coords[atoms])
    pairs = tree.query_pairs(2 * max(COVALENT_RADIUS.values()) + BOND_SLACK, output_type="ndarray")
    i, j = atoms[pairs[:, 0]], atoms[pairs[:, 1]]
    protein = table.category == "protein"
    # residue groups (alternative residues sharing a number are one group)
    group = np.where(structure.atom_residue >= 0, structure.atom_residue, structure.n_residues + table.residue)
    peptide_names = ((table.name[i] == "C") & (table.name[j] == "N")) | ((table.name[i] == "N") & (table.name[j] == "C"))
    linkable = (
        (group[i] == group[j])
        | (peptide_names & (np.abs(group[i] - group[j]) == 1))
        | ~protein[i]
        | ~protein[j]
        | ((table.element[i] == "S") & (table.element[j] == "S"))
    )
    bonded = linkable & (distance(structure.coords[i], structure.coords[j]) < covalent[i] + covalent[j] + BOND_SLACK)
    peptide = np.stack([backbone[first, 2], backbone[second, 0]], axis=1)
    peptide = peptide[(peptide >= 0).all(axis=1)]
    i = np.concatenate([i[bonded], peptide[:, 0]])
    j = np.concatenate([j[bonded], peptide[:, 1]])
    bonds = sparse.coo_matrix((np.ones(len(i)), (i, j)), shape=(n_atoms, n_atoms)).tocsr()
    bonds = ((bonds + bonds.T) > 0).astype(np.int32)
    reach = bonds + bonds @ bonds
    reach = reach + reach @ bonds
    reach = sparse.triu(reach, k=1).tocoo()
    return np.unique(reach.row.astype(np.int64) * n_atoms + reach.col)
