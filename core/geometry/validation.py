"""Geometry validation of a protein model: peptide junctions, Ramachandran regions, clashes.

What is checked (ideal values: Engh & Huber 1991, the restraints of most refinement
programs; σ their standard deviations):

- every **junction** (consecutive residues i, i+1 of a backbone segment): the peptide bond
  C–N (1.329 Å, 1.341 before Pro; flagged beyond ±0.05 Å), the Cα–Cα distance (3.80 ± 0.1 Å
  across a trans peptide, 2.94 ± 0.25 Å across a cis one), the angles Cα–C–N (116.2°,
  116.9° before Pro) and C–N–Cα (121.7°, 122.6° at Pro), flagged beyond 4σ as MolProbity
  does, and the planarity of the peptide: ω more than 30° from 180° (trans) or 0° (cis).
  A junction is cis when |ω| < 90°, so real cis peptides are not flagged as compressed.
- every **residue** with both neighbours: (φ, ψ) against :data:`~core.geometry.ramachandran.RAMACHANDRAN`, a coarse
  20° grid of favoured and allowed regions for general, glycine and proline residues.
- every **pair of heavy atoms** closer than their contact distance by more than 0.4 Å
  (MolProbity's clash criterion), found with a k-d tree. Contact distances are sums of
  van der Waals radii (:data:`~core.geometry.ideal.VDW_RADIUS`), 2.8 Å for N/O pairs (which may hydrogen-bond).
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
The per-structure set-up (bonds, radii, backbone rows: :mod:`core.geometry.topology`) is
computed once and cached.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.geometry.ideal import (
    ANGLE_SIGMAS,
    C_N,
    C_N_CA,
    C_N_CA_PRO,
    C_N_PRO,
    CA_C_N,
    CA_C_N_PRO,
    CA_CA_CIS,
    CA_CA_CIS_TOLERANCE,
    CA_CA_TOLERANCE,
    CA_CA_TRANS,
    CLASH_OVERLAP,
    OMEGA_TOLERANCE,
    PEPTIDE_BOND_TOLERANCE,
)  # fmt: skip
from core.geometry.ramachandran import OUTLIER, RAMACHANDRAN_CLASSES, ramachandran_region
from core.geometry.topology import Topology, topology
from core.geometry.vectors import angle, dihedral, distance
from core.protein.structure import Structure

KINDS = ("peptide_bond", "ca_ca", "angle_ca_c_n", "angle_c_n_ca", "omega", "ramachandran", "clash")
"""The kinds of :class:`Flag`, in report order."""


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
            "peptide_bond": (distance(c1, n2), np.where(proline, C_N_PRO, C_N), PEPTIDE_BOND_TOLERANCE, " Å"),
            "ca_ca": (ca_ca, np.where(cis, CA_CA_CIS, CA_CA_TRANS), np.where(cis, CA_CA_CIS_TOLERANCE, CA_CA_TOLERANCE), " Å"),
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


def phi_psi(
    structure: Structure, coords: np.ndarray | None = None, residues: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """φ and ψ (degrees) of the residue-table rows ``residues`` (default: every residue), NaN
    where undefined (segment ends, missing atoms); ``coords`` default to the structure as read."""
    top = topology(structure)
    n_residues = len(top.backbone)
    rows = np.arange(n_residues) if residues is None else np.asarray(residues, dtype=np.int64)
    if rows.size and (rows.min() < 0 or rows.max() >= n_residues):
        raise ValueError(f"residues must lie in [0, {n_residues - 1}]")
    return _phi_psi(top, structure.coords if coords is None else np.asarray(coords, float), rows)


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
            "clash", f"{top.atom_label(a)} / {top.atom_label(b)}", float(d[k]), float(contact[k]),
            float(overlap / CLASH_OVERLAP), tuple((0.5 * (coords[a] + coords[b])).tolist()),
            tuple(int(r) for r in (atom_residue[a], atom_residue[b]) if r >= 0),
            f"{d[k]:.2f} Å apart, overlap {overlap:.2f} Å",
        ))
    return flags, checked
