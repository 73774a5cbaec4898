"""The Cα trace: a ball on every residue's Cα, coloured as the tube, and sticks joining the Cα of
each segment (``ca_balls``, ``ca_sticks``), rewritten in place for the residues an edit moved."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from app.editor.document import Change
from app.editor.scene.layers.base import SHINY, Layer, SceneLayer
from app.editor.scene.layers.meshes import collapse, colour_glyphs, glyph_rows, glyphs, move_glyphs, polylines, span

CA_RADIUS = 0.45
CA_STICK_COLOUR = (120, 124, 130)


class CaTraceLayer(SceneLayer):
    """Balls and sticks on the Cα of every backbone residue."""

    switch = Layer.CA_TRACE
    names = ("ca_balls", "ca_sticks")
    lines_as_tubes = ("ca_sticks",)

    def build(self) -> None:
        ca = self.document.model.coords[self.document.ca_rows]
        self.meshes["ca_balls"] = glyphs(ca, CA_RADIUS, self.scene.residue_colours())
        self.add("ca_balls", scalars="colours", rgb=True, **SHINY)
        bounds = np.cumsum([0] + [len(s) for s in self.document.structure.segments])
        self.meshes["ca_sticks"] = pv.PolyData(ca.copy(), lines=polylines(bounds))
        self.add("ca_sticks", color=CA_STICK_COLOUR, line_width=4.0, render_lines_as_tubes=True)

    def update(self, change: Change) -> None:
        if len(change.residues):
            rows = self.scene.chains.offset[change.segment] + change.residues
            ca = self.document.model.coords[self.document.ca_rows[rows]]
            move_glyphs(self.meshes["ca_balls"], span(rows), ca)
            self.write("ca_sticks", span(rows), ca)

    def recolour(self, residue_colours: np.ndarray) -> None:
        colour_glyphs(self.meshes["ca_balls"], residue_colours)

    def conceal(self, chain: str) -> None:
        for segment in self.scene.chains.other_segments(chain):
            first, n_residues = self.scene.chains.offset[segment], len(self.document.structure.segments[segment])
            collapse(self.meshes["ca_balls"], glyph_rows(slice(None), n_residues, first))
            collapse(self.meshes["ca_sticks"], slice(first, first + n_residues))

    def restore(self) -> None:
        ca = self.document.model.coords[self.document.ca_rows]
        move_glyphs(self.meshes["ca_balls"], slice(None), ca)
        self.write("ca_sticks", slice(None), ca)
