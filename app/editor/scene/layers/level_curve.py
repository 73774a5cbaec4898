"""The thin level curve of every segment at the slider's level: the edited segment's dark, the
others lighter. One mesh, ``curve``, one polyline per segment, rewritten in place when the
level or the ribbon changes."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from app.editor.document import Change
from app.editor.scene.layers.base import Layer, SceneLayer
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.meshes import collapse, polylines

CURVE_COLOUR = (40, 44, 52)
OTHER_CURVE_COLOUR = (120, 126, 136)


class CurveLayer(SceneLayer):
    """The level curves of all segments, as lines (shaded tubes at rest)."""

    switch = Layer.CURVE
    names = ("curve",)
    lines_as_tubes = ("curve",)

    def build(self) -> None:
        samples = [self.document.level_curve(g).samples for g in range(len(self.document.paths))]
        self._start = np.cumsum([0] + [len(s) for s in samples])
        mesh = pv.PolyData(np.vstack(samples), lines=polylines(self._start))
        mesh.point_data["colours"] = np.zeros((mesh.n_points, 3), dtype=np.uint8)
        self.meshes["curve"] = mesh
        self.segment_changed()
        self.add("curve", scalars="colours", rgb=True, line_width=3.0, render_lines_as_tubes=True)

    def update(self, change: Change) -> None:
        segment = change.segment
        self.write("curve", slice(self._start[segment], self._start[segment + 1]),
                   self.document.level_curve(segment).samples)

    def level_changed(self) -> None:
        self.restore()
        if self.scene.others is Others.HIDDEN:
            self.conceal(self.scene.edited_chain())

    def segment_changed(self) -> None:
        """The level curve of the edited segment in a dark colour, the others lighter."""
        colours = np.tile(np.array(OTHER_CURVE_COLOUR, dtype=np.uint8), (self._start[-1], 1))
        segment = self.document.segment
        colours[self._start[segment]:self._start[segment + 1]] = CURVE_COLOUR
        self.write("curve", slice(None), colours, "colours")

    def conceal(self, chain: str) -> None:
        for segment in self.scene.chains.other_segments(chain):
            collapse(self.meshes["curve"], slice(self._start[segment], self._start[segment + 1]))

    def restore(self) -> None:
        samples = np.vstack([self.document.level_curve(g).samples for g in range(len(self.document.paths))])
        self.write("curve", slice(None), samples)
