"""The selection: translucent balls around the Cα of its residues and the centre of its groups
(``selection``) and their atoms as bond sticks coloured by element (``selection_atoms``: what
a validation flag involves shows without the whole Atoms layer), made again when the selection
changes and moved in place when an edit moves them."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from app.editor.document import Change
from app.editor.scene import molecule
from app.editor.scene.layers.base import SHINY, SceneLayer
from app.editor.scene.layers.meshes import bond_lines, glyphs, move_glyphs
from core.protein.lookup import group_starts

SELECTION_COLOUR = (240, 40, 220)
SELECTION_RADIUS = 1.4
"""Å, the translucent balls around the Cα of selected residues (and the centres of groups)."""


class SelectionLayer(SceneLayer):
    """Balls around the Cα of the selected residues and the centres of the selected groups, and
    their atoms (always shown)."""

    names = ("selection", "selection_atoms")
    lines_as_tubes = ("selection_atoms",)

    def build(self) -> None:
        self.meshes["selection"] = pv.PolyData()
        self.meshes["selection_atoms"] = pv.PolyData()
        self._atoms = np.empty(0, dtype=np.int64)
        self.selection_changed()

    def update(self, change: Change) -> None:
        if self.meshes["selection"].n_points:
            move_glyphs(self.meshes["selection"], slice(None), self._centres())
        if self.meshes["selection_atoms"].n_points and np.isin(change.rows, self._atoms).any():
            self.write("selection_atoms", slice(None), self.document.model.coords[self._atoms])

    def selection_changed(self) -> None:
        rows, groups = self.document.selection, self.document.selected_groups
        centres = self._centres()
        colours = np.tile(np.array(SELECTION_COLOUR, dtype=np.uint8), (len(centres), 1))
        self.meshes["selection"].shallow_copy(glyphs(centres, SELECTION_RADIUS, colours))
        if "selection" not in self.actors and len(centres):
            self.add("selection", scalars="colours", rgb=True, opacity=0.45, **SHINY)
        structure, coords = self.document.structure, self.document.model.coords
        self._atoms = np.union1d(np.flatnonzero(np.isin(structure.atom_residue, rows)) if len(rows) else [], groups
                                 ).astype(np.int64)
        table = structure.atoms
        bonds = np.searchsorted(self._atoms, molecule.bonds(coords, table.element, table.altloc, self._atoms))
        atoms = (bond_lines(coords[self._atoms], bonds, molecule.element_colours(table.element[self._atoms]))
                 if len(bonds) else pv.PolyData())
        self.meshes["selection_atoms"].shallow_copy(atoms)
        if "selection_atoms" not in self.actors and len(bonds):
            self.add("selection_atoms", scalars="colours", rgb=True, line_width=4.0, render_lines_as_tubes=True)

    def _centres(self) -> np.ndarray:
        """(k, 3) the Cα of the selected residues, then the centre of each selected group."""
        document = self.document
        coords, groups = document.model.coords, document.selected_groups
        starts = group_starts(document.structure, groups)
        centres = (np.add.reduceat(coords[groups], starts) / np.diff(np.r_[starts, len(groups)])[:, None]
                   if len(groups) else np.empty((0, 3)))
        return np.concatenate([coords[document.ca_rows[document.selection]], centres])
