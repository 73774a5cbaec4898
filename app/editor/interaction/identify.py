"""What is under the pointer: a control point, an atom or a residue, and its name for people.

:func:`identify` casts the pointer's ray (a :class:`~app.editor.interaction.drag.PointerEvent`) at what
the view shows: the control points of the edited level curve first, then the atoms drawn
(polymer atoms, ligands, ions), then the residues (their Cα, which the tube and the Cα
trace pass through). Among the things the ray passes close to, the one nearest the eye
wins. No Qt or VTK here: the window feeds it the same events as the drag controller.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from app.editor.document import Document
from app.editor.interaction.drag import PICK_PIXELS, PointerEvent
from app.editor.scene.molecule import SS_NAMES

RESIDUE_RADIUS = 2.0
"""Å around a Cα within which the ray names its residue (the tube passes between Cα)."""
ATOM_RADIUS = 0.6
"""Å around an atom within which the ray names it."""


@dataclass(frozen=True, eq=False)
class Hit:
    """Something under the pointer.

    Attributes
    ----------
    kind : 'point' (a control point), 'atom' or 'residue'.
    position : (3,) where it is, Å.
    row : residue-table row of its residue (-1 for an atom outside the backbone segments).
    index : the control point's index, or the atom's row of the coordinates (-1 for a residue).
    """

    kind: Literal["point", "atom", "residue"]
    position: np.ndarray
    row: int
    index: int = -1


def identify(document: Document, event: PointerEvent, *, points: bool, point_radius: float,
             atoms: np.ndarray) -> Hit | None:
    """What ``event``'s ray meets first: a shown control point (when ``points``; spheres of
    ``point_radius`` Å), one of the atoms of rows ``atoms``, or a residue."""
    if document.model is None:
        return None
    if points and document.editable:
        curve = document.level_curve()
        index = _front_hit(event, curve.control_points, point_radius, curve.visible)
        if index is not None:
            centre = curve.control_points[index]
            rows = document.structure.segments[document.segment].residue_index
            return Hit("point", centre, int(rows[0]), index)
    coords = document.model.coords
    atom = _front_hit(event, coords[atoms], ATOM_RADIUS)
    if atom is not None:
        row = int(atoms[atom])
        return Hit("atom", coords[row], int(document.structure.atom_residue[row]), row)
    if not document.editable:
        return None
    ca = coords[document.ca_rows]
    residue = _front_hit(event, ca, RESIDUE_RADIUS)
    return None if residue is None else Hit("residue", ca[residue], residue)


def describe(document: Document, hit: Hit) -> str:
    """One line naming ``hit``: e.g. ``A:LYS48 NZ · helix``, or for a control point the
    residues it moves."""
    structure = document.structure
    if hit.kind == "point":
        pick = document.pick if document.pick is not None and document.pick.index == hit.index else None
        residues = pick.residues if pick is not None else document.point_residues(hit.index)
        return (f"control point {hit.index} at level {document.shown_level():.2f}: moves "
                f"{document.residue_range(residues)} ({len(residues)} residues)")
    if hit.row < 0:  # a ligand, an ion or a nucleotide
        table = structure.atoms
        k = hit.index
        drawn = " · nucleic acid: drawn, not edited (no curve)" if table.category[k] == "nucleic" else ""
        return f"{table.chain[k]}:{table.resname[k]}{table.resseq[k]} {table.name[k]} ({table.element[k]}){drawn}"
    segment = structure.segments[int(structure.residue_place(hit.row)[0])]
    name = structure.residue_label(hit.row) + (f" {structure.atoms.name[hit.index]}" if hit.kind == "atom" else "")
    return f"{name} · {SS_NAMES[segment.ss[hit.row - int(segment.residue_index[0])]]}"


def _front_hit(event: PointerEvent, points: np.ndarray, radius: float, allowed: np.ndarray | None = None) -> int | None:
    """The point nearest the eye among those whose sphere of ``radius`` Å the ray meets, or
    that pass within :data:`~app.editor.interaction.drag.PICK_PIXELS` of it."""
    if len(points) == 0:
        return None
    depth, off, pixel = event.distances(points)
    hit = (depth > 0) & (off <= np.maximum(radius, PICK_PIXELS * pixel))
    if allowed is not None:
        hit &= allowed
    if not hit.any():
        return None
    candidates = np.flatnonzero(hit)
    return int(candidates[np.argmin(depth[candidates] - np.sqrt(np.maximum(radius**2 - off[candidates]**2, 0)))])
