"""Labels and measurements on atoms (no widgets): a label names one atom, two atoms give a
distance, three an angle, four a dihedral. They are kept by atom rows, so their values
follow the model as edits, undos and fits move the atoms; a new structure clears them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QObject, Signal

from core.geometry.topology import topology
from core.geometry.vectors import angle, dihedral, distance
from core.protein.structure import Structure

KINDS = {1: "label", 2: "distance", 3: "angle", 4: "dihedral"}
"""A measurement's kind by its number of atoms."""


@dataclass(frozen=True)
class Measurement:
    """Atoms (coordinate rows, in order) and what they measure (:data:`KINDS`); a label of one
    atom names it, or with ``residue`` its residue (the atom is its Cα)."""

    atoms: tuple[int, ...]
    residue: bool = False

    @property
    def kind(self) -> str:
        return KINDS[len(self.atoms)]

    def value(self, coords: np.ndarray) -> float | None:
        """Å for a distance, degrees for an angle or a dihedral, None for a label."""
        xyz = [coords[row][None, :] for row in self.atoms]
        measure = {2: distance, 3: angle, 4: dihedral}.get(len(xyz))
        return None if measure is None else float(measure(*xyz)[0])

    def text(self, structure: Structure, coords: np.ndarray) -> str:
        """Its value for people (``3.21 Å``, ``109.5°``), or for a label the atom's name."""
        value = self.value(coords)
        if value is None:
            return self.names(structure)
        return f"{value:.2f} Å" if self.kind == "distance" else f"{value:.1f}°"

    def names(self, structure: Structure) -> str:
        """The atoms' names, joined by dashes: ``A:LYS48 NZ – A:GLU50 OE1``."""
        label = topology(structure).atom_label
        if self.residue:
            return label(self.atoms[0]).rsplit(" ", 1)[0]
        return " – ".join(label(row) for row in self.atoms)

    def record(self) -> dict:
        """What a session keeps of it."""
        return {"atoms": list(self.atoms), "residue": self.residue}


def checked(atoms: object, n_atoms: int, residue: bool = False) -> Measurement:
    """The measurement of ``atoms``: 1 to 4 distinct rows below ``n_atoms`` (with ``residue``,
    one: a label of its residue); ValueError or TypeError for anything else."""
    atoms = tuple(int(row) for row in atoms) if isinstance(atoms, (list, tuple)) else ()
    if len(atoms) not in KINDS or len(set(atoms)) != len(atoms) or not all(0 <= a < n_atoms for a in atoms):
        raise ValueError(f"a label or a measurement takes 1 to 4 different atoms; got {list(atoms)}")
    if residue and len(atoms) != 1:
        raise ValueError("a residue's label takes one atom, its Cα")
    return Measurement(atoms, bool(residue))


def central_atom(coords: np.ndarray, rows: np.ndarray) -> int:
    """The row among ``rows`` (a group's atoms) nearest their centre, where its label goes (a haem's iron)."""
    rows = np.asarray(rows)
    return int(rows[np.argmin(np.linalg.norm(coords[rows] - coords[rows].mean(axis=0), axis=1))])


class Measurements(QObject):
    """The labels and measurements of a document, in the order they were made."""

    changed = Signal()
    """One was added or removed (their values change with the document's ``changed``)."""

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.items: list[Measurement] = []

    def add(self, atoms: tuple[int, ...] | list[int], n_atoms: int, residue: bool = False) -> Measurement:
        """A new measurement of ``atoms`` (see :func:`checked`)."""
        measurement = checked(atoms, n_atoms, residue)
        self.items.append(measurement)
        self.changed.emit()
        return measurement

    def remove(self, index: int) -> None:
        del self.items[index]
        self.changed.emit()

    def replace(self, items: list[Measurement]) -> None:
        """Every measurement at once (a new structure: none; a session: its own)."""
        self.items = list(items)
        self.changed.emit()
