"""Ligands (balls and sticks, carbon in green: ``ligand_balls``, ``ligand_sticks``), ions (a
large ball each: ``ions``) and waters (a small red ball at each oxygen: ``waters``, off at
first, as a crystal's hundreds crowd the view), three layers switched on their own; also drawn
for a structure that is only viewed (no backbone). An edit moves the ligands and ions bound to
the residues it moves (see :meth:`core.protein.model.EditableModel.bound_ligands`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

import numpy as np
import pyvista as pv

from app.editor.scene import molecule
from app.editor.scene.layers.base import SHINY, Layer, SceneLayer
from app.editor.scene.layers.meshes import bond_lines, collapse, glyph_rows, glyphs, move_glyphs

if TYPE_CHECKING:
    from app.editor.document import Change

LIGAND_ATOM_RADIUS = 0.35
ION_RADIUS = 1.1
WATER_RADIUS = 0.3


class LigandsLayer(SceneLayer):
    """The atoms of ligands (not ions, not water) as small balls and bond sticks."""

    switch = Layer.LIGANDS
    needs_backbone = False
    names = ("ligand_balls", "ligand_sticks")
    lines_as_tubes = ("ligand_sticks",)

    def build(self) -> None:
        table = self.document.structure.atoms
        coords = self.document.model.coords
        _, self._rows = molecule.ions_and_ligands(self.document.structure)
        carbon = molecule.LIGAND_CARBON
        self.meshes["ligand_balls"] = glyphs(coords[self._rows], LIGAND_ATOM_RADIUS,
                                             molecule.element_colours(table.element[self._rows], carbon))
        self.add("ligand_balls", scalars="colours", rgb=True, **SHINY)
        bonds = molecule.bonds(coords, table.element, table.altloc, self._rows)
        self.meshes["ligand_sticks"] = bond_lines(coords, bonds, molecule.element_colours(table.element, carbon))
        self.add("ligand_sticks", scalars="colours", rgb=True, line_width=5.0, render_lines_as_tubes=True)

    def atom_rows(self) -> np.ndarray:
        return self._rows

    def update(self, change: Change) -> None:
        moved = np.flatnonzero(np.isin(self._rows, change.rows))
        if len(moved):
            coords = self.document.model.coords
            move_glyphs(self.meshes["ligand_balls"], moved, coords[self._rows[moved]])
            if self.meshes["ligand_sticks"].n_points:
                self.write("ligand_sticks", self._rows[moved], coords[self._rows[moved]])

    def conceal(self, chain: str) -> None:
        other = self.document.structure.atoms.chain != chain
        if self.meshes["ligand_sticks"].n_points:
            collapse(self.meshes["ligand_sticks"], np.flatnonzero(other))
        _conceal_glyphs(self.meshes["ligand_balls"], other[self._rows])

    def restore(self) -> None:
        coords = self.document.model.coords
        if self.meshes["ligand_balls"].n_points:
            move_glyphs(self.meshes["ligand_balls"], slice(None), coords[self._rows])
        if self.meshes["ligand_sticks"].n_points:
            self.write("ligand_sticks", slice(None), coords)


class _BallsLayer(SceneLayer):
    """Atoms of one kind as balls of one radius, coloured by element."""

    needs_backbone = False
    radius: ClassVar[float]

    def chosen(self) -> np.ndarray:
        """Rows of the atoms it draws."""
        raise NotImplementedError

    def build(self) -> None:
        self._rows = self.chosen()
        self.meshes[self.names[0]] = glyphs(self.document.model.coords[self._rows], self.radius,
                                            molecule.element_colours(self.document.structure.atoms.element[self._rows]))
        self.add(self.names[0], scalars="colours", rgb=True, **SHINY)

    @property
    def _balls(self) -> pv.PolyData:
        return self.meshes[self.names[0]]

    def atom_rows(self) -> np.ndarray:
        return self._rows

    def update(self, change: Change) -> None:
        moved = np.flatnonzero(np.isin(self._rows, change.rows))
        if len(moved):
            move_glyphs(self._balls, moved, self.document.model.coords[self._rows[moved]])

    def conceal(self, chain: str) -> None:
        _conceal_glyphs(self._balls, self.document.structure.atoms.chain[self._rows] != chain)

    def restore(self) -> None:
        if self._balls.n_points:
            move_glyphs(self._balls, slice(None), self.document.model.coords[self._rows])


class IonsLayer(_BallsLayer):
    """Ions (a non-polymer, non-water group of one heavy atom) as balls."""

    switch = Layer.IONS
    names = ("ions",)
    radius = ION_RADIUS

    def chosen(self) -> np.ndarray:
        return molecule.ions_and_ligands(self.document.structure)[0]


class WatersLayer(_BallsLayer):
    """Waters as a small ball at each oxygen (every alternate location)."""

    switch = Layer.WATERS
    names = ("waters",)
    radius = WATER_RADIUS

    def chosen(self) -> np.ndarray:
        table = self.document.structure.atoms
        return np.flatnonzero((table.category == "water") & (np.char.upper(table.element.astype(str)) == "O"))


def _conceal_glyphs(mesh: pv.PolyData, other: np.ndarray) -> None:
    """Collapse the glyphs of ``mesh`` where ``other`` (one per glyph) is true."""
    rows = np.flatnonzero(other)
    if len(rows):
        collapse(mesh, glyph_rows(rows, len(other)))
