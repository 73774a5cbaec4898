"""A protein being edited: atom coordinates plus one multiresolution ribbon per backbone segment.

:class:`EditableModel` turns multiresolution edits of a ribbon (a control point moved at a
slider level, or a curve point tugged) into rigid-body motions of the affected residues.
Every change is an :class:`Edit` that holds exactly what it changed, so it can be undone
and redone bit for bit. Atoms of residues the edit does not reach are never rewritten.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from core.curves.editing import move_control_point, tug_curve
from core.protein.frames import remap_atoms
from core.protein.ribbon import Ribbon, RibbonKind, segment_ribbon
from core.protein.structure import BackboneSegment, Structure
from core.protein.writing import write_structure

CARRY_DISTANCE = 4.0
"""Å: a ligand or ion with an atom this near a residue's atom is bound to it (to the nearest such
residue) and, while :attr:`EditableModel.carry_ligands` is on, rides with it as a rigid body."""
NEGLIGIBLE_MOVE = 1e-6
"""Control-point changes up to this size (Å) move no residue: fractional-level edits have
exponentially decaying tails over the whole segment that would otherwise remap it all."""


@dataclass(frozen=True, eq=False)
class Edit:
    """One change of one segment: its ribbon control points and the atoms that moved.

    Attributes
    ----------
    segment : index into ``EditableModel.segments``.
    old_points, new_points : (2**J + 3, 3) finest control points before and after.
    residues : indices (within the segment) of the residues that moved.
    rows : rows of the coordinate array that moved (all atoms of those residues).
    old_coords, new_coords : (len(rows), 3) their coordinates before and after.
    """

    segment: int
    old_points: np.ndarray
    new_points: np.ndarray
    residues: np.ndarray
    rows: np.ndarray
    old_coords: np.ndarray
    new_coords: np.ndarray

    def then(self, later: Edit) -> Edit:
        """The single edit equivalent to this one followed by ``later`` (same segment)."""
        if later.segment != self.segment:
            raise ValueError(f"cannot merge edits of segments {self.segment} and {later.segment}")
        rows = np.union1d(self.rows, later.rows)
        old = np.empty((len(rows), 3))
        new = np.empty((len(rows), 3))
        old[np.searchsorted(rows, later.rows)] = later.old_coords  # rows first moved by `later`
        old[np.searchsorted(rows, self.rows)] = self.old_coords
        new[np.searchsorted(rows, self.rows)] = self.new_coords
        new[np.searchsorted(rows, later.rows)] = later.new_coords
        residues = np.union1d(self.residues, later.residues)
        return Edit(self.segment, self.old_points, later.new_points, residues, rows, old, new)


def per_segment(edits: Iterable[Edit]) -> list[Edit]:
    """``edits``, applied one after another, as one edit per segment (:meth:`Edit.then`), in
    the order the segments first appear."""
    total: dict[int, Edit] = {}
    for edit in edits:
        total[edit.segment] = total[edit.segment].then(edit) if edit.segment in total else edit
    return list(total.values())


class EditableModel:
    """Coordinates and ribbons of a structure under multiresolution editing.

    Parameters
    ----------
    structure : the structure read from a file (never modified).
    kind : 'peptide' (peptide-plane ribbon, the default) or 'calpha'.
    helix_offset : shift of helix guide points off the axis, Å (peptide ribbon only).
    """

    def __init__(self, structure: Structure, kind: RibbonKind | str = RibbonKind.PEPTIDE, helix_offset: float = 0.0):
        self.structure = structure
        self.kind = RibbonKind(kind)
        self.coords = np.array(structure.coords)
        self.ribbons = [segment_ribbon(s, self.kind, helix_offset) for s in structure.segments]
        self.carry_ligands = True
        """Whether the ligands and ions bound to a moved residue move with it (see :meth:`bound_ligands`)."""
        self._bound = _bound_ligands(structure)

    @property
    def segments(self) -> tuple[BackboneSegment, ...]:
        """The backbone segments, in the order of :attr:`ribbons`."""
        return self.structure.segments

    def move_point(self, segment: int, level: float, index: int, displacement: object) -> Edit:
        """Move control point ``index`` of the curve shown at slider ``level`` (planned, not applied)."""
        ribbon = self._ribbon(segment)
        delta = move_control_point(ribbon.fs_level(level), index, displacement, ribbon.level)
        return self.plan(segment, ribbon.points + delta)

    def tug(self, segment: int, level: float, u: float, displacement: object) -> Edit:
        """Drag the point at parameter ``u`` of the curve shown at slider ``level`` (planned)."""
        ribbon = self._ribbon(segment)
        delta = tug_curve(ribbon.fs_level(level), u, displacement, ribbon.level)
        return self.plan(segment, ribbon.points + delta)

    def bound_ligands(self, segment: int) -> tuple[np.ndarray, np.ndarray]:
        """The atom rows of the ligands and ions bound to residues of ``segment`` (see
        :data:`CARRY_DISTANCE`) and, per row, the residue (within the segment) it rides with."""
        return self._bound[segment]

    def plan(self, segment: int, new_points: np.ndarray) -> Edit:
        """The edit that gives segment ``segment`` the finest control points ``new_points``."""
        ribbon = self._ribbon(segment)
        new_ribbon = ribbon.with_points(new_points)
        residues = ribbon.residues_moved_by(np.abs(new_ribbon.points - ribbon.points).max(axis=1) > NEGLIGIBLE_MOVE)
        rows, owner = _residue_rows(self.segments[segment], residues)
        if self.carry_ligands:
            bound, host = self._bound[segment]
            riding = np.isin(host, residues)
            rows = np.concatenate([rows, bound[riding]])
            owner = np.concatenate([owner, np.searchsorted(residues, host[riding])])
            order = np.argsort(rows, kind="stable")
            rows, owner = rows[order], owner[order]
        u = ribbon.residue_u[residues]
        old_coords = self.coords[rows]
        new_coords = remap_atoms(
            old_coords,
            owner,
            ribbon.space.evaluate(ribbon.points, u),
            ribbon.space.evaluate(new_ribbon.points, u),
            ribbon.residue_rotations(new_ribbon.points, residues),
        )
        return Edit(segment, ribbon.points, new_ribbon.points, residues, rows, old_coords, new_coords)

    def apply(self, edit: Edit) -> None:
        """Carry out ``edit`` (redo)."""
        self.coords[edit.rows] = edit.new_coords
        self.ribbons[edit.segment] = self.ribbons[edit.segment].with_points(edit.new_points)

    def reset_to(self, coords: np.ndarray, points: Sequence[np.ndarray]) -> None:
        """Make ``coords`` the coordinates and ``points`` each segment's finest control points
        (where an undo history starts once its oldest steps were dropped)."""
        self.coords[:] = coords
        self.ribbons = [ribbon.with_points(p) for ribbon, p in zip(self.ribbons, points, strict=True)]

    def check(self, edit: Edit) -> None:
        """Raise ValueError unless ``edit`` was made on the model as it is now: its segment,
        residues and rows exist, and the control points and coordinates it starts from are
        these, bit for bit (an edit read from a file is checked before it is applied)."""
        if not 0 <= edit.segment < len(self.ribbons):
            raise ValueError(f"the structure has no segment {edit.segment + 1}")
        points = self.ribbons[edit.segment].points
        if edit.old_points.shape != points.shape:
            raise ValueError(f"segment {edit.segment + 1} has {len(points)} control points, not {len(edit.old_points)}")
        if len(edit.residues) and edit.residues.max() >= len(self.segments[edit.segment].ca):
            raise ValueError(f"segment {edit.segment + 1} has no residue {edit.residues.max() + 1}")
        if len(edit.rows) and edit.rows.max() >= len(self.coords):
            raise ValueError(f"the structure has no atom {edit.rows.max() + 1}")
        if not (np.array_equal(edit.old_points, points) and np.array_equal(edit.old_coords, self.coords[edit.rows])):
            raise ValueError("it was not made on these coordinates")

    def revert(self, edit: Edit) -> None:
        """Undo ``edit`` exactly."""
        self.coords[edit.rows] = edit.old_coords
        self.ribbons[edit.segment] = self.ribbons[edit.segment].with_points(edit.old_points)

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write the current coordinates (PDB or mmCIF by the extension), atomically."""
        return write_structure(self.structure, self.coords, path, overwrite=overwrite)

    def _ribbon(self, segment: int) -> Ribbon:
        if not 0 <= segment < len(self.ribbons):
            raise ValueError(f"segment must be in [0, {len(self.ribbons) - 1}]; got {segment}")
        return self.ribbons[segment]


def _residue_rows(segment: BackboneSegment, residues: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coordinate rows of all atoms of ``residues`` and, per row, its position in ``residues``."""
    starts, stops = segment.atom_start[residues], segment.atom_stop[residues]
    lengths = stops - starts
    owner = np.repeat(np.arange(len(residues)), lengths)
    offsets = np.arange(lengths.sum()) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    return starts[owner] + offsets, owner


def _bound_ligands(structure: Structure) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per segment, the atom rows of the ligand and ion groups (:attr:`Structure.ligand_rows`)
    bound to it and the residue (within the segment) each rides with: the residue of the
    backbone atom nearest to the group, when that atom lies within :data:`CARRY_DISTANCE` of
    one of the group's atoms."""
    empty = np.empty(0, dtype=np.int64)
    bound: list[tuple[np.ndarray, np.ndarray]] = [(empty, empty)] * len(structure.segments)
    ligand = structure.ligand_rows
    polymer = np.flatnonzero(structure.atom_residue >= 0)
    if not len(ligand) or not len(polymer):
        return bound
    distance, nearest = cKDTree(structure.coords[polymer]).query(structure.coords[ligand],
                                                                 distance_upper_bound=CARRY_DISTANCE)
    group_of = np.unique(structure.atoms.residue[ligand], return_inverse=True)[1]
    order = np.lexsort((distance, group_of))  # group by group, the nearest atom first
    closest = order[np.r_[True, np.diff(group_of[order]) != 0]]  # each group's atom nearest to the polymer
    residue_row = np.where(np.isfinite(distance[closest]),
                           structure.atom_residue[polymer[np.minimum(nearest[closest], len(polymer) - 1)]], -1)
    host_row = residue_row[group_of]  # per ligand atom: the residue-table row it rides with, or -1
    riding = ligand[host_row >= 0]
    segment, host = structure.residue_place(host_row[host_row >= 0])
    for k in np.unique(segment).tolist():
        bound[k] = (riding[segment == k], host[segment == k])
    return bound
