"""The polymer atoms as thin bond lines coloured by element (``atoms``): one point per atom of
the structure, in coordinate-row order, so that an edit rewrites the rows of the atoms it
moved. Also drawn for a structure that is only viewed (no backbone)."""

from __future__ import annotations

import numpy as np

from app.editor.document import Change
from app.editor.scene import molecule
from app.editor.scene.layers.base import Layer, SceneLayer
from app.editor.scene.layers.chains import Others, faded
from app.editor.scene.layers.meshes import bond_lines, collapse, span


class AtomsLayer(SceneLayer):
    """Bond lines between the atoms of proteins and nucleic acids."""

    switch = Layer.ATOMS
    needs_backbone = False
    names = ("atoms",)

    def build(self) -> None:
        table = self.document.structure.atoms
        coords = self.document.model.coords
        self._rows = np.flatnonzero(np.isin(table.category, ("protein", "nucleic")))
        self._colours = molecule.element_colours(table.element)
        bonds = molecule.bonds(coords, table.element, table.altloc, self._rows)
        self.meshes["atoms"] = bond_lines(coords, bonds, self._colours)
        self.add("atoms", scalars="colours", rgb=True, line_width=1.5)

    def atom_rows(self) -> np.ndarray:
        return self._rows

    def update(self, change: Change) -> None:
        if len(change.rows) and self.meshes["atoms"].n_points:  # no bonds (a Cα-only model): no mesh
            rows = span(np.sort(change.rows))
            self.write("atoms", rows, self.document.model.coords[rows])

    def recolour(self, residue_colours: np.ndarray) -> None:
        """The other chains' atoms faded when they are dimmed (atoms are coloured by element)."""
        if self.meshes["atoms"].n_points:
            other = self.document.structure.atoms.chain != self.scene.edited_chain()
            self.write("atoms", slice(None), faded(self._colours, (self.scene.others is Others.DIMMED) & other),
                       "colours")

    def conceal(self, chain: str) -> None:
        if self.meshes["atoms"].n_points:
            collapse(self.meshes["atoms"], np.flatnonzero(self.document.structure.atoms.chain != chain))

    def restore(self) -> None:
        if self.meshes["atoms"].n_points:
            self.write("atoms", slice(None), self.document.model.coords)
