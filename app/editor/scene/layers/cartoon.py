"""The cartoon: helices as flat ribbons, strands as slabs ending in arrows, loops as tubes
(:mod:`app.editor.scene.cartoon`), swept along the rings of the tube
(:mod:`app.editor.scene.layers.swept`). The edited segment's follows the slider: its cartoon
is that of the level curve, so a coarse level shows what the slider does to the fold; the
other segments' stay at full resolution."""

from __future__ import annotations

import numpy as np

from app.editor.document import Change
from app.editor.scene import cartoon, tube
from app.editor.scene.layers.base import Layer
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.meshes import Rows
from app.editor.scene.layers.swept import SweptLayer
from core.geometry.topology import topology


class CartoonLayer(SweptLayer):
    """The cartoon of every segment, coloured per residue."""

    switch = Layer.CARTOON
    name = "cartoon"

    def build(self) -> None:
        structure, coords = self.document.structure, self.document.model.coords
        backbone = topology(structure).backbone
        self._backbone = [backbone[segment.residue_index] for segment in structure.segments]
        self._signs = [cartoon.agreeing_signs(cartoon.residue_guides(coords, rows))[:, None] for rows in self._backbone]
        self._levelled = self.document.segment
        """The segment drawn at the slider's level (the others at full resolution)."""
        self._shape()
        super().build()

    def reshape(self) -> None:
        self._shape()
        self.restore()
        if self.scene.others is Others.HIDDEN:
            self.conceal(self.scene.edited_chain())

    def _shape(self) -> None:
        """Every ring's section, and with helices as cylinders the rings of each helix."""
        cylinders = self.scene.helix_cylinders
        pairs = list(zip(self.document.structure.segments, self.document.paths))
        self._shapes = [cartoon.sections(segment.ss, path.rings_per_residue, cylinders) for segment, path in pairs]
        self._helices = [cartoon.helices(segment.ss, path.rings_per_residue) if cylinders else []
                         for segment, path in pairs]

    def update(self, change: Change) -> None:
        if len(change.residues) and not self.hidden():  # a guide reaches its neighbours' rings (and the average's)
            segment = change.segment
            n, reach = len(self._backbone[segment]), 1 + self._window(segment) // 2
            near = np.clip(np.arange(change.residues.min() - reach, change.residues.max() + reach + 1), 0, n - 1)
            rings = self.document.paths[segment].rings(np.unique(near))
            first, last = int(rings[0]), int(rings[-1])
            for start, stop in self._helices[segment]:  # a cylinder's axis is its whole helix's
                if start <= last and stop >= first:
                    first, last = min(first, start), max(last, stop)
            self.sweep(segment, slice(first, last + 1))

    def level_changed(self) -> None:
        segment, before = self.document.segment, self._levelled
        self._levelled = segment
        if self.hidden():
            return
        if before != segment and before < len(self.document.paths):
            self.sweep(before, slice(None))  # back to full resolution
            if self.scene.others is Others.HIDDEN:
                self.conceal(self.scene.edited_chain())
        self.sweep(segment, slice(None))

    def _window(self, segment: int) -> int:
        """Residues a control point of ``segment``'s curve carries, as drawn (1 at full resolution)."""
        if segment != self._levelled:
            return 1
        return max(1, round(len(self._backbone[segment]) / self.document.level_curve(segment).n_segments))

    def rings(self, segment: int, rings: Rows) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        path = self.document.paths[segment]
        if segment == self._levelled:
            curve = self.document.level_curve(segment)
            points, level = curve.control_points, curve.level
        else:
            points, level = self.document.model.ribbons[segment].points, None
        centres, tangents = path.centres(points, rings, level)
        index = np.arange(path.n_rings)[rings]
        for first, last in self._helices[segment]:  # cylinders: the rings of each helix on its axis
            inside = (index >= first) & (index <= last)
            if inside.any():
                axis, direction = cartoon.on_axis(path.centres(points, np.arange(first, last + 1), level)[0])
                centres[inside], tangents[inside] = axis[index[inside] - first], direction
        k, n, window = path.rings_per_residue, len(self._backbone[segment]), self._window(segment)
        margin = 2 + window // 2  # the guides of the residues a ring reaches, each averaged in full
        low, high = max(int(index[0]) // k - margin, 0), min(int(index[-1]) // k + margin + 1, n)
        guides = cartoon.residue_guides(self.document.model.coords, self._backbone[segment][low:high])
        guides = cartoon.smoothed(guides * self._signs[segment][low:high], window)
        along = cartoon.ring_guides(guides, k, index, low, n)
        points, normals = cartoon.section_vertices(centres, tangents, along, tube.perpendicular(tangents),
                                                   self._shapes[segment][index], self.sides)
        return centres, tangents, points, normals
