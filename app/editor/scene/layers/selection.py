"""The selected residues: translucent balls around their Cα (``selection``), one small mesh made
again when the selection changes and moved in place when an edit moves them."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from app.editor.document import Change
from app.editor.scene.layers.base import SHINY, SceneLayer
from app.editor.scene.layers.meshes import glyphs, move_glyphs

SELECTION_COLOUR = (240, 40, 220)
SELECTION_RADIUS = 1.4
"""Å, the translucent balls around the Cα of selected residues."""


class SelectionLayer(SceneLayer):
    """Balls around the Cα of the selected residues (always shown)."""

    names = ("selection",)

    def build(self) -> None:
        self.meshes["selection"] = pv.PolyData()
        self.selection_changed()

    def update(self, change: Change) -> None:
        if len(self.document.selection):
            move_glyphs(self.meshes["selection"], slice(None), self._centres())

    def selection_changed(self) -> None:
        rows = self.document.selection
        colours = np.tile(np.array(SELECTION_COLOUR, dtype=np.uint8), (len(rows), 1))
        self.meshes["selection"].shallow_copy(glyphs(self._centres(), SELECTION_RADIUS, colours))
        if "selection" not in self.actors and len(rows):
            self.add("selection", scalars="colours", rgb=True, opacity=0.45, **SHINY)

    def _centres(self) -> np.ndarray:
        """(k, 3) the Cα of the selected residues."""
        return self.document.model.coords[self.document.ca_rows[self.document.selection]]
