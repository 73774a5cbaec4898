"""Geometry validation of a protein model: peptide junctions, Ramachandran regions, clashes.

What is checked (ideal values: Engh & Huber 1991, the restraints of most refinement
programs; σ their standard deviations):

- every **junction** (consecutive residues i, i+1 of a backbone segment): the peptide bond
  C–N (1.329 Å, 1.341 before Pro; flagged beyond ±0.05 Å), the Cα–Cα distance (3.80 ± 0.1 Å
  across a trans peptide, 2.94 ± 0.25 Å across a cis one), the angles Cα–C–N (116.2°,
  116.9° before Pro) and C–N–Cα (121.7°, 122.6° at Pro), flagged beyond 4σ as MolProbity
  does, and the planarity of the peptide: ω more than 30° from 180° (trans) or 0° (cis).
  A junction is cis when |ω| < 90°, so real cis peptides are not flagged as compressed.
- every **residue** with both neighbours: (φ, ψ) against :data:`RAMACHANDRAN`, a coarse
  20° grid of favoured and allowed regions for general, glycine and proline residues.
- every **pair of heavy atoms** closer than their contact distance by more than 0.4 Å
  (MolProbity's clash criterion), found with a k-d tree. Contact distances are sums of
  van der Waals radii (:data:`VDW_RADIUS`), 2.8 Å for N/O pairs (which may hydrogen-bond).
  Pairs at most three bonds apart never clash; the bonds are those within each residue
  of the structure as read (covalent radii + 0.45 Å), the peptide bonds of the segments,
  disulfides and links to non-protein groups, so an edit that stretches a bond does not
  turn it into a clash. Atoms of different alternate conformers
  never clash; hydrogens, waters (an edit makes the solvent model stale anyway) and
  elements without a radius (metals) are not checked.

:func:`validate` returns a :class:`ValidationReport`: counts, and every flag with its
value, ideal, severity (deviation / tolerance: above 1 is flagged) and a marker position.
Passing ``residues`` checks only what those residues take part in, cheaply enough to run
during a drag; :meth:`ValidationReport.updated` folds such a local report into a full one.
The per-structure set-up (bonds, radii, backbone rows) is computed once and cached.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage, sparse
from scipy.spatial import cKDTree

from .structure import Structure

# ---------------------------------------------------------------------------- ideals

C_N = 1.329
"""Peptide bond C–N, Å (Engh & Huber 1991); :data:`C_N_PRO` before a proline."""
C_N_PRO = 1.341
CA_C_N = 116.2
"""Angle Cα–C–N, degrees (σ 2.0); 116.9 (σ 1.5) before a proline."""
CA_C_N_PRO = 116.9
C_N_CA = 121.7
"""Angle C–N–Cα, degrees (σ 1.8); 122.6 (σ 5.0) at a proline."""
C_N_CA_PRO = 122.6
N_CA = 1.458
CA_C = 1.525

PEPTIDE_BOND_TOLERANCE = 0.05
"""Å either side of the ideal C–N length."""
CA_CA_TRANS = 3.80
"""Cα–Cα distance (Å) across a trans peptide, flagged beyond ±:data:`CA_CA_TOLERANCE`."""
CA_CA_CIS = 2.94
"""Cα–Cα distance (Å) across a cis peptide: the median of the 219 cis peptides of a
229-entry reference set (cis peptides open their angles, so this is not what the trans
angles give), flagged beyond ±:data:`CA_CA_CIS_TOLERANCE`."""
CA_CA_TOLERANCE = 0.1
CA_CA_CIS_TOLERANCE = 0.25
"""Å; 1–99% of the reference cis peptides lie within 2.78–3.20 Å."""
ANGLE_SIGMAS = 4.0
"""Angles are flagged beyond this many Engh & Huber σ."""
OMEGA_TOLERANCE = 30.0
"""Degrees of ω away from 180 (trans) or 0 (cis)."""
CLASH_OVERLAP = 0.4
"""Å by which two heavy atoms must overlap to clash."""
POLAR_CONTACT = 2.8
"""Contact distance (Å) of an N/O pair, which may be a hydrogen bond."""
BOND_SLACK = 0.45
"""Two atoms of the input closer than their covalent radii plus this (Å) are bonded."""

VDW_RADIUS = {"C": 1.70, "N": 1.55, "O": 1.40, "S": 1.80, "P": 1.80, "Se": 1.90,
              "F": 1.47, "Cl": 1.75, "Br": 1.85, "I": 1.98}  # fmt: skip
"""Van der Waals radii (Å) of the elements checked for clashes: those of MolProbity's Probe
(Word et al. 1999) for C, N, O, S, P, Bondi (1964) for the others."""
COVALENT_RADIUS = {"C": 0.76, "N": 0.71, "O": 0.66, "S": 1.05, "P": 1.07, "Se": 1.20,
                   "F": 0.57, "Cl": 1.02, "Br": 1.20, "I": 1.39}  # fmt: skip
"""Cordero et al. (2008) covalent radii, Å."""

# The grids: 18 x 18 cells of 20°, φ from -180 (left) to 180, ψ from 180 (top) to -180.
# '#' favoured, '+' allowed, '.' outlier. Favoured: the densest cells holding 98% of the
# (φ, ψ) of 25,000 residues with backbone B < 30 Å² in the 100-odd X-ray entries at
# <= 2.0 Å of a 229-entry diverse set (glycine symmetrised under (φ, ψ) -> (-φ, -ψ));
# allowed: favoured widened by one cell, roughly where Lovell et al. (2003) draw the
# allowed contour. Outside allowed lie 0.4% of those residues (0.9% of all 65,000).
_GRIDS = {
    "general": """
        ######++.........+
        #######+.........+
        #######+.........+
        +#####++.........+
        +####++...........
        ++#+#+....++++....
        +##+#+....+##+....
        ++###++...+##+....
        .+####+...++#+....
        .+####++...+++....
        .+#####+..........
        .++####+..........
        ..++++++..........
        ..................
        ..................
        ..................
        ++++++............
        +####++..........+""",
    "glycine": """
        ######++...+######
        #######+...++#####
        ++#####+....+##+++
        .+#+#+++....+##+..
        .+++++.....+++++..
        ...+++....++#+++..
        .+++#+....+####+..
        .+###++...+####++.
        .+####++..+#####+.
        .+#####+..++####+.
        .++####+...++###+.
        ..+####+....+#+++.
        ..+++#++....+++...
        ..+++++.....+++++.
        ..+##+....+++#+#+.
        +++##+....+#####++
        #####++...+#######
        ######+...++######""",
    "proline": """
        ...+###+..........
        ...+###+..........
        ..++###+..........
        ..+####+..........
        ..++##++..........
        ...+##+...........
        ...+##+...........
        ..+++#+...........
        ..+##+++..........
        ..++###+..........
        ...+###+..........
        ...++##+..........
        ....++++..........
        ..................
        ..................
        ..................
        ...+++............
        ...+#+++..........""",
}
RAMACHANDRAN_CLASSES = ("general", "glycine", "proline")
FAVOURED, ALLOWED, OUTLIER = 0, 1, 2
RAMACHANDRAN = np.stack([
    np.array([["#+.".index(ch) for ch in line.strip()] for line in _GRIDS[name].strip().splitlines()], dtype=np.int8)
    for name in RAMACHANDRAN_CLASSES
])
"""(3, 18, 18) region codes (FAVOURED, ALLOWED, OUTLIER) per class, ψ row (from +180 down),
φ column (from -180); see the module source for the maps and how they were made."""

KINDS = ("peptide_bond", "ca_ca", "angle_ca_c_n", "angle_c_n_ca", "omega", "ramachandran", "clash")
"""The kinds of :class:`Flag`, in report order."""

# ------------------------------------------------------------------------- geometry


def lengths(v: np.ndarray) -> np.ndarray:
    """Row-wise lengths |v| of (n, 3) arrays (``np.linalg.norm`` is several times slower
    along a short last axis)."""
    return np.sqrt(np.einsum("...i,...i", v, v))


def distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise distances |a - b| of (n, 3) arrays, Å."""
    return lengths(a - b)


def angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Row-wise angles a–b–c of (n, 3) arrays, degrees."""
    u, v = a - b, c - b
    cos = np.einsum("...i,...i", u, v) / (lengths(u) * lengths(v))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def dihedral(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Row-wise dihedral angles a–b–c–d of (n, 3) arrays, degrees in (-180, 180]."""
    b1, b2, b3 = b - a, c - b, d - c
    n1, n2 = np.cross(b1, b2), np.cross(b2, b3)
    m = np.cross(n1, b2 / lengths(b2)[..., None])
    return np.degrees(np.arctan2(-np.einsum("...i,...i", m, n2), np.einsum("...i,...i", n1, n2)))


def ramachandran_region(phi: np.ndarray, psi: np.ndarray, kind: np.ndarray) -> np.ndarray:
    """Region code (FAVOURED, ALLOWED, OUTLIER) of (φ, ψ) in degrees for class indices ``kind``
    (0 general, 1 glycine, 2 proline; see :data:`RAMACHANDRAN_CLASSES`)."""
    column = np.clip(((np.asarray(phi) + 180.0) // 20).astype(np.int64), 0, 17)
    row = np.clip(((180.0 - np.asarray(psi)) // 20).astype(np.int64), 0, 17)
    return RAMACHANDRAN[np.asarray(kind), row, column]


def nearest_allowed(phi: np.ndarray, psi: np.ndarray, kind: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The allowed (φ, ψ) nearest to each (φ, ψ) in degrees, to 2° (itself where allowed;
    the values may lie beyond ±180 on the other side of the wrap)."""
    column = ((np.asarray(phi) + 180.0) // 2).astype(np.int64) % 180
    row = ((180.0 - np.asarray(psi)) // 2).astype(np.int64) % 180
    target = _nearest_allowed_cells()[np.asarray(kind), row, column]
    allowed = ramachandran_region(phi, psi, kind) != OUTLIER
    return np.where(allowed, phi, target[..., 0]), np.where(allowed, psi, target[..., 1])


@functools.lru_cache(maxsize=1)
def _nearest_allowed_cells() -> np.ndarray:
    """(classes, 180, 180, 2): per class and 2° cell (ψ row from +180 down, φ column from
    -180), the (φ, ψ) centre of the nearest allowed 2° cell, across the periodic wrap."""
    fine = np.repeat(np.repeat(RAMACHANDRAN == OUTLIER, 10, axis=1), 10, axis=2)
    out = np.empty((len(fine), 180, 180, 2))
    for k, outlier in enumerate(fine):
        _, (row, column) = ndimage.distance_transform_edt(np.tile(outlier, (3, 3)), return_indices=True)
        row, column = row[180:360, 180:360] - 180, column[180:360, 180:360] - 180
        out[k, ..., 0] = -180.0 + 2 * column + 1
        out[k, ..., 1] = 180.0 - 2 * row - 1
    return out


# ------------------------------------------------------------------------- topology


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
        Index into :data:`RAMACHANDRAN_CLASSES`.
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
    atom_labels : (n_atoms,) str
        Label ('A:LYS48 NZ') of every atom.
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
    atom_labels: np.ndarray = field(repr=False)

    @property
    def n_atoms(self) -> int:
        return len(self.radius)

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
    segment_of = np.concatenate([np.full(len(s), k) for k, s in enumerate(structure.segments)])
    first = np.flatnonzero(segment_of[:-1] == segment_of[1:])
    second = first + 1
    resname = np.concatenate([s.resname for s in structure.segments])
    labels = np.concatenate([np.array(s.labels, dtype=str) for s in structure.segments])
    coords = structure.coords
    omega = _junction_dihedral(coords, backbone, first, second)
    rama_class = np.select([resname == "GLY", resname == "PRO"], [1, 2], 0).astype(np.int8)

    radius = np.array([VDW_RADIUS.get(e, 0.0) for e in atoms.element])
    checked = (radius > 0) & (atoms.category != "water")
    radius[~checked] = 0.0
    polar = np.isin(atoms.element, ("N", "O"))
    atom_labels = _atom_labels(structure, labels)
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
        atom_labels=atom_labels,
    )


def _backbone_rows(structure: Structure) -> np.ndarray:
    """(n_residues, 4) rows of the N, Cα, C, O atoms the segments were built from, -1 if none."""
    atoms, owner = structure.atoms, structure.atom_residue
    n_residues = structure.n_residues
    rows = np.full((n_residues, 4), -1, dtype=np.int64)
    for slot, name in enumerate(("N", "CA", "C", "O")):
        reference = np.concatenate([getattr(s, name.lower()) for s in structure.segments])
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


def _atom_labels(structure: Structure, residue_labels: np.ndarray) -> np.ndarray:
    atoms, owner = structure.atoms, structure.atom_residue
    residue = np.where(
        owner >= 0,
        residue_labels[owner.clip(min=0)],
        np.char.add(np.char.add(np.char.add(atoms.chain, ":"), atoms.resname), atoms.resseq.astype(str)),
    )
    alt = np.where(atoms.altloc != "", np.char.add(".", atoms.altloc), "")
    return np.char.add(np.char.add(np.char.add(residue, " "), atoms.name), alt)


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


# --------------------------------------------------------------------------- report


@dataclass(frozen=True)
class Flag:
    """One geometry problem.

    Attributes
    ----------
    kind : one of :data:`KINDS`.
    where : 'A:LYS48-A:GLY49' (junction), 'A:LYS48' (residue) or 'A:LYS48 NZ / A:GLU51 OE1'.
    value : the measured length (Å) or angle (degrees); φ for a Ramachandran outlier.
    ideal : the ideal value (the contact distance for a clash); None for Ramachandran.
    severity : |value - ideal| / tolerance (> 1: flagged); 1 for Ramachandran outliers.
    position : (3,) where to draw a marker, Å.
    residues : residue-table rows involved (atoms outside the segments are left out).
    detail : one line for people.
    """

    kind: str
    where: str
    value: float
    ideal: float | None
    severity: float
    position: tuple[float, float, float]
    residues: tuple[int, ...]
    detail: str

    def to_dict(self) -> dict:
        """A JSON-ready dictionary (numbers rounded to 3 decimals)."""
        return {
            "kind": self.kind,
            "where": self.where,
            "value": round(self.value, 3),
            "ideal": None if self.ideal is None else round(self.ideal, 3),
            "severity": round(self.severity, 3),
            "position": [round(x, 3) for x in self.position],
            "detail": self.detail,
        }


@dataclass(frozen=True)
class ValidationReport:
    """Counts and flags of one validation, worst first.

    Attributes
    ----------
    checked : items checked per kind (junctions, residues with φ/ψ, atoms for clashes).
    flags : every flag, by decreasing severity.
    cis : residue-table rows i of the cis junctions (i, i+1) among those checked.
    region, neighbourhood : for a local report, the residues asked for and those plus their
        neighbours (whose φ/ψ they change); None for the whole structure.
    """

    checked: dict[str, int]
    flags: tuple[Flag, ...]
    cis: tuple[int, ...]
    region: frozenset[int] | None = None
    neighbourhood: frozenset[int] | None = None

    @property
    def counts(self) -> dict[str, int]:
        """Flags per kind, every kind of :data:`KINDS` present."""
        counts = dict.fromkeys(KINDS, 0)
        for flag in self.flags:
            counts[flag.kind] += 1
        return counts

    def worst(self, n: int = 10, kind: str | None = None) -> tuple[Flag, ...]:
        """The ``n`` most severe flags (of one ``kind`` if given)."""
        return tuple(f for f in self.flags if kind is None or f.kind == kind)[:n]

    def updated(self, local: ValidationReport) -> ValidationReport:
        """This whole-structure report with what ``local`` (a report of a region of newer
        coordinates) covers replaced by ``local``'s flags."""
        if local.region is None:
            return local
        kept = tuple(f for f in self.flags if not local.covers(f))
        cis = tuple(sorted({i for i in self.cis if not {i, i + 1} & local.region} | set(local.cis)))
        flags = tuple(sorted(kept + local.flags, key=lambda f: -f.severity))
        return ValidationReport(self.checked, flags, cis, self.region, self.neighbourhood)

    def covers(self, flag: Flag) -> bool:
        """Whether this report checked what ``flag`` is about."""
        if self.region is None:
            return True
        if flag.kind == "ramachandran":
            return flag.residues[0] in self.neighbourhood
        return any(r in self.region for r in flag.residues)

    def to_dict(self, worst: int | None = None) -> dict:
        """A JSON-ready dictionary: checked, counts, cis peptides and the flags (the
        ``worst`` most severe if given)."""
        flags = self.flags if worst is None else self.flags[:worst]
        return {
            "checked": dict(self.checked),
            "counts": self.counts,
            "cis_peptides": len(self.cis),
            "flags": [f.to_dict() for f in flags],
        }


def validate(structure: Structure, coords: np.ndarray | None = None, residues: object = None) -> ValidationReport:
    """Check the geometry of ``structure`` with atoms at ``coords`` (default: as read).

    Parameters
    ----------
    structure : the structure (its bonds, names and segments).
    coords : (n_atoms, 3) atom positions, Å, e.g. ``EditableModel.coords``.
    residues : residue-table rows; if given, only the junctions, φ/ψ and clashes these
        residues take part in are checked (a local report, see
        :meth:`ValidationReport.updated`).

    Returns
    -------
    ValidationReport
    """
    top = topology(structure)
    coords = structure.coords if coords is None else np.asarray(coords, dtype=np.float64)
    if coords.shape != structure.coords.shape:
        raise ValueError(f"coords must have shape {structure.coords.shape}; got {coords.shape}")
    n_residues = len(top.backbone)
    if residues is None:
        junctions = np.arange(len(top.first))
        rama = np.arange(n_residues)
        rows = None
        region = neighbourhood = None
    else:
        region_rows = np.unique(np.asarray(residues, dtype=np.int64))
        if len(region_rows) and (region_rows[0] < 0 or region_rows[-1] >= n_residues):
            raise ValueError(f"residues must lie in [0, {n_residues - 1}]")
        junctions = np.flatnonzero(np.isin(top.first, region_rows) | np.isin(top.second, region_rows))
        rama = np.union1d(region_rows, np.concatenate([top.first[junctions], top.second[junctions]]))
        rows = np.flatnonzero(np.isin(structure.atom_residue, region_rows))
        region, neighbourhood = frozenset(region_rows.tolist()), frozenset(rama.tolist())
    junction_flags, cis, checked = _junction_flags(top, coords, junctions)
    rama_flags, checked["ramachandran"] = _ramachandran_flags(top, coords, rama)
    clash_flags, checked["clash"] = _clash_flags(top, structure.atom_residue, coords, rows)
    flags = tuple(sorted(junction_flags + rama_flags + clash_flags, key=lambda f: -f.severity))
    return ValidationReport(checked, flags, cis, region, neighbourhood)


def _xyz(coords: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Coordinates of ``rows``, NaN where a row is -1."""
    return np.where((rows >= 0)[..., None], coords[rows.clip(min=0)], np.nan)


def _junction_flags(
    top: Topology, coords: np.ndarray, junctions: np.ndarray
) -> tuple[list[Flag], tuple[int, ...], dict[str, int]]:
    first, second = top.first[junctions], top.second[junctions]
    ca1, c1 = _xyz(coords, top.backbone[first, 1]), _xyz(coords, top.backbone[first, 2])
    n2, ca2 = _xyz(coords, top.backbone[second, 0]), _xyz(coords, top.backbone[second, 1])
    proline = top.proline[junctions]
    with np.errstate(invalid="ignore"):
        omega = dihedral(ca1, c1, n2, ca2)
        ca_ca = distance(ca1, ca2)
        cis = np.where(np.isnan(omega), ca_ca < 0.5 * (CA_CA_CIS + CA_CA_TRANS), np.abs(omega) < 90)
        measures = {
            "peptide_bond": (distance(c1, n2), np.where(proline, C_N_PRO, C_N), PEPTIDE_BOND_TOLERANCE, "Å"),
            "ca_ca": (ca_ca, np.where(cis, CA_CA_CIS, CA_CA_TRANS), np.where(cis, CA_CA_CIS_TOLERANCE, CA_CA_TOLERANCE), "Å"),
            "angle_ca_c_n": (angle(ca1, c1, n2), np.where(proline, CA_C_N_PRO, CA_C_N),
                             ANGLE_SIGMAS * np.where(proline, 1.5, 2.0), "°"),
            "angle_c_n_ca": (angle(c1, n2, ca2), np.where(proline, C_N_CA_PRO, C_N_CA),
                             ANGLE_SIGMAS * np.where(proline, 5.0, 1.8), "°"),
            "omega": (omega, np.where(cis, 0.0, 180.0), OMEGA_TOLERANCE, "°"),
        }
    names = {"peptide_bond": "C–N", "ca_ca": "Cα–Cα", "angle_ca_c_n": "Cα–C–N", "angle_c_n_ca": "C–N–Cα", "omega": "ω"}
    marker = np.where(np.isnan(c1 + n2), 0.5 * (ca1 + ca2), 0.5 * (c1 + n2))
    flags = []
    checked = {kind: int(np.isfinite(value).sum()) for kind, (value, *_) in measures.items()}
    for kind, (value, ideal, tolerance, unit) in measures.items():
        ideal = np.broadcast_to(ideal, value.shape)
        deviation = value - ideal
        if kind == "omega":
            deviation = (deviation + 180.0) % 360.0 - 180.0
        severity = np.abs(deviation) / tolerance
        for k in np.flatnonzero(np.nan_to_num(severity) > 1.0):
            where = f"{top.labels[first[k]]}-{top.labels[second[k]]}"
            flags.append(Flag(
                kind, where, float(value[k]), float(ideal[k]), float(severity[k]), tuple(marker[k].tolist()),
                (int(first[k]), int(second[k])),
                f"{names[kind]} {value[k]:.2f}{unit}, ideal {ideal[k]:.2f}{unit}"
                + (" (cis)" if cis[k] and kind in ("ca_ca", "omega") else ""),
            ))
    return flags, tuple(int(i) for i in first[cis]), checked


def phi_psi(structure: Structure, coords: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """φ and ψ (degrees) of every residue of the residue table, NaN where undefined
    (segment ends, missing atoms); ``coords`` default to the structure as read."""
    top = topology(structure)
    return _phi_psi(top, structure.coords if coords is None else np.asarray(coords, float), np.arange(len(top.backbone)))


def _phi_psi(top: Topology, coords: np.ndarray, residues: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    before = np.full(len(top.backbone), -1)
    after = np.full(len(top.backbone), -1)
    before[top.second], after[top.first] = top.first, top.second
    bb = top.backbone
    c0 = _xyz(coords, np.where(before[residues] >= 0, bb[before[residues], 2], -1))
    n, ca, c = (_xyz(coords, bb[residues, k]) for k in range(3))
    n2 = _xyz(coords, np.where(after[residues] >= 0, bb[after[residues], 0], -1))
    with np.errstate(invalid="ignore"):
        return dihedral(c0, n, ca, c), dihedral(n, ca, c, n2)


def _ramachandran_flags(top: Topology, coords: np.ndarray, residues: np.ndarray) -> tuple[list[Flag], int]:
    phi, psi = _phi_psi(top, coords, residues)
    known = np.isfinite(phi) & np.isfinite(psi)
    residues, phi, psi = residues[known], phi[known], psi[known]
    ca = coords[top.backbone[residues, 1]]
    kind = top.rama_class[residues]
    outliers = np.flatnonzero(ramachandran_region(phi, psi, kind) == OUTLIER)
    flags = [
        Flag("ramachandran", str(top.labels[residues[k]]), float(phi[k]), None, 1.0, tuple(ca[k].tolist()),
             (int(residues[k]),), f"φ {phi[k]:.0f}°, ψ {psi[k]:.0f}°: outlier ({RAMACHANDRAN_CLASSES[kind[k]]})")
        for k in outliers
    ]
    return flags, len(residues)


def _clash_flags(
    top: Topology, atom_residue: np.ndarray, coords: np.ndarray, rows: np.ndarray | None
) -> tuple[list[Flag], int]:
    i, j = top.close_pairs(coords, rows, CLASH_OVERLAP)
    checked = int(top.checked.sum()) if rows is None else int(top.checked[rows].sum())
    contact = top.contact(i, j)
    d = distance(coords[i], coords[j])
    flags = []
    for k in range(len(i)):
        a, b = int(i[k]), int(j[k])
        overlap = contact[k] - d[k]
        flags.append(Flag(
            "clash", f"{top.atom_labels[a]} / {top.atom_labels[b]}", float(d[k]), float(contact[k]),
            float(overlap / CLASH_OVERLAP), tuple((0.5 * (coords[a] + coords[b])).tolist()),
            tuple(int(r) for r in (atom_residue[a], atom_residue[b]) if r >= 0),
            f"{d[k]:.2f} Å apart, overlap {overlap:.2f} Å",
        ))
    return flags, checked
