"""Side-chain torsions and overlaps, for refinement into a map (:mod:`core.fitting.real_space`).

:class:`Rotors` are the χ1 … χ4 of the side chains (the IUPAC bonds of :data:`CHI_BONDS`),
each turning the atoms beyond its bond, with the analytic gradient: for a turn about the
unit axis ``a`` through ``p``, an atom at ``x`` moves by ``a × (x − p)`` per radian, so
``∂E/∂χ = Σ (a × (x − p)) · ∂E/∂x`` over the atoms beyond the bond. :class:`Clashes` is a
one-sided penalty that keeps moved atoms from overlapping others by more than they did at
the start (or than :data:`~core.geometry.clash_list.CLASH_TARGET`). Residues with alternate
conformers keep their side chains.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.geometry.clash_list import CLASH_TARGET
from core.geometry.topology import topology
from core.geometry.vectors import distance, lengths, pair_gradient, unit
from core.protein.model import EditableModel

CHI_BONDS = {
    "ARG": (("CA", "CB"), ("CB", "CG"), ("CG", "CD"), ("CD", "NE")),
    "ASN": (("CA", "CB"), ("CB", "CG")),
    "ASP": (("CA", "CB"), ("CB", "CG")),
    "CYS": (("CA", "CB"),),
    "GLN": (("CA", "CB"), ("CB", "CG"), ("CG", "CD")),
    "GLU": (("CA", "CB"), ("CB", "CG"), ("CG", "CD")),
    "HIS": (("CA", "CB"), ("CB", "CG")),
    "ILE": (("CA", "CB"), ("CB", "CG1")),
    "LEU": (("CA", "CB"), ("CB", "CG")),
    "LYS": (("CA", "CB"), ("CB", "CG"), ("CG", "CD"), ("CD", "CE")),
    "MET": (("CA", "CB"), ("CB", "CG"), ("CG", "SD")),
    "PHE": (("CA", "CB"), ("CB", "CG")),
    "SER": (("CA", "CB"),),
    "THR": (("CA", "CB"),),
    "TRP": (("CA", "CB"), ("CB", "CG")),
    "TYR": (("CA", "CB"), ("CB", "CG")),
    "VAL": (("CA", "CB"),),
}
"""The bond of each side-chain torsion χ1, χ2, … (the middle two atoms of its IUPAC definition)."""
REMOTE = "ABGDEZH"
"""The remoteness letters of side-chain atom names, from Cα outward."""
CLASH_WEIGHT = 0.01
"""CC per Å² of overlap beyond what is allowed, summed over pairs."""


@dataclass(frozen=True)
class Rotors:
    """The side-chain torsions of some residues.

    Attributes
    ----------
    bonds : (m, 2) rows of the two atoms of each rotor's bond (the axis runs from the first).
    depth : (m,) 0 for χ1, 1 for χ2, …: rotors are applied deepest first.
    atoms : (k,) rows of the atoms each rotor turns, concatenated …
    owner : (k,) … and the rotor of each.
    """

    bonds: np.ndarray
    depth: np.ndarray
    atoms: np.ndarray
    owner: np.ndarray

    def turned(self, coords: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """``coords`` with each rotor turned by ``angles`` (m,) radians."""
        coords = coords.copy()
        for depth in range(int(self.depth.max(initial=-1)), -1, -1):  # deepest first: the axes stay put
            take = self.depth[self.owner] == depth
            atoms, owner = self.atoms[take], self.owner[take]
            pivot = coords[self.bonds[owner, 1]]
            axis = unit(pivot - coords[self.bonds[owner, 0]])
            coords[atoms] = pivot + _rotate(coords[atoms] - pivot, axis, angles[owner])
        return coords

    def gradient(self, coords: np.ndarray, per_atom: np.ndarray) -> np.ndarray:
        """∂E/∂χ (m,) of each rotor at ``coords``, from ∂E/∂x ``per_atom`` (n, 3)."""
        pivot = coords[self.bonds[self.owner, 1]]
        axis = unit(pivot - coords[self.bonds[self.owner, 0]])
        moves = np.cross(axis, coords[self.atoms] - pivot)
        return np.bincount(self.owner, np.einsum("ij,ij->i", moves, per_atom[self.atoms]), minlength=len(self.bonds))


def side_chain_rotors(model: EditableModel, segments: Sequence[int]) -> Rotors:
    """The χ rotors of the side chains of ``segments`` (complete up to each bond, no alternate
    conformers); hydrogens turn with the heavy atom they are bonded to."""
    structure = model.structure
    names, elements = structure.atoms.name.astype(str), np.char.upper(structure.atoms.element.astype(str))
    bonds, depth, atoms, owner = [], [], [], []
    for s in segments:
        segment = model.segments[s]
        for start, stop, resname in zip(segment.atom_start, segment.atom_stop, segment.resname):
            chis = CHI_BONDS.get(str(resname), ())
            rows = np.arange(start, stop)
            if not chis or np.any(structure.atoms.altloc[rows] != ""):
                continue
            row_of = {names[r]: r for r in rows}
            hydrogen = np.isin(elements[rows], ("H", "D"))
            remote = np.array([_remoteness(n) for n in names[rows]])
            parent = _parents(model.coords, rows, hydrogen)
            for k, (first, second) in enumerate(chis):
                if first not in row_of or second not in row_of:
                    break
                level = _remoteness(second)
                heavy = ~hydrogen & (remote > level)
                moving = heavy | (hydrogen & np.isin(parent, np.append(rows[heavy], row_of[second])))
                if not heavy.any():
                    break
                bonds.append((row_of[first], row_of[second]))
                depth.append(k)
                atoms.append(rows[moving])
                owner.append(np.full(moving.sum(), len(bonds) - 1))
    if not bonds:
        empty = np.empty(0, dtype=np.int64)
        return Rotors(np.empty((0, 2), dtype=np.int64), empty, empty, empty)
    return Rotors(np.array(bonds), np.array(depth), np.concatenate(atoms), np.concatenate(owner))


class Clashes:
    """A one-sided penalty on the overlap of the pairs with an atom of ``rows`` that come
    within reach of clashing: each may overlap by CLASH_TARGET, or by what it did at the start."""

    REACH = 4.0
    """Å: pairs this much short of clashing at the start are watched (a turn moves atoms a few Å)."""

    def __init__(self, model: EditableModel, rows: np.ndarray) -> None:
        top = topology(model.structure)
        self.i, self.j = top.close_pairs(model.coords, rows, -self.REACH)
        self.contact = top.contact(self.i, self.j)
        start = self.contact - distance(model.coords[self.i], model.coords[self.j])
        self.limit = self.contact - np.maximum(start, CLASH_TARGET)  # Å: closer, a pair overlaps more than allowed

    def penalty(self, coords: np.ndarray) -> tuple[float, np.ndarray]:
        """Σ excess², and its gradient (n, 3)."""
        vector = coords[self.i] - coords[self.j]
        length = np.maximum(lengths(vector), 1e-9)
        hit = np.flatnonzero(length < self.limit)
        excess = self.limit[hit] - length[hit]
        force = (-2.0 * excess / length[hit])[:, None] * vector[hit]
        return float(excess @ excess), pair_gradient(self.i[hit], self.j[hit], force, len(coords))


def _rotate(vectors: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues: each of ``vectors`` turned about its unit ``axis`` by ``angle`` radians."""
    cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
    along = np.einsum("ij,ij->i", axis, vectors)[:, None] * axis
    return vectors * cos + np.cross(axis, vectors) * sin + along * (1.0 - cos)


def _remoteness(name: str) -> int:
    """0 for Cα, 1 for Cβ, … from the atom name's second letter (-1 for the main chain)."""
    return REMOTE.find(name[1]) if len(name) > 1 and name not in ("N", "C", "O", "OXT") else -1


def _parents(coords: np.ndarray, rows: np.ndarray, hydrogen: np.ndarray) -> np.ndarray:
    """Per atom of ``rows``: for a hydrogen, the row of the nearest heavy atom; else -1."""
    parent = np.full(len(rows), -1)
    heavy = rows[~hydrogen]
    if hydrogen.any() and len(heavy):
        near = np.linalg.norm(coords[rows[hydrogen]][:, None] - coords[heavy][None], axis=2).argmin(axis=1)
        parent[hydrogen] = heavy[near]
    return parent
