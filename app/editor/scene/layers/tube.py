"""The ribbon tube: round rings swept along each segment's full-resolution curve
(:mod:`app.editor.scene.layers.swept`), of one radius or fat by secondary structure.

Ring normals come from parallel transport along the whole curve once (a rotation-minimising
frame, so the tube does not twist); after an edit each ring's normal is the stored one
turned by the smallest rotation that takes the stored tangent onto the new tangent.
"""

from __future__ import annotations

import itertools

import numpy as np

from app.editor.scene import tube
from app.editor.scene.curves import eased
from app.editor.scene.layers.base import Layer
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.meshes import Rows, shift
from app.editor.scene.layers.swept import SweptLayer

TUBE_RADIUS = 0.55
"""Å, the tube of the full-resolution ribbon."""
FAT_RADII = {"H": 1.5, "E": 1.8, "C": 0.45}
"""Å, tube radii by secondary structure with "fat helices" on (sheet > helix > other)."""


class TubeLayer(SweptLayer):
    """The ribbon tube, coloured per residue, uniform or fat by secondary structure."""

    switch = Layer.TUBE
    name = "tube"

    def build(self) -> None:
        paths = self.document.paths
        self._tangents = np.concatenate([path.centres(self.document.model.ribbons[g].points)[1]
                                         for g, path in enumerate(paths)])
        starts = np.cumsum([0] + [p.n_rings for p in paths])
        self._normals = np.concatenate([tube.transported_normals(self._tangents[a:b])
                                        for a, b in itertools.pairwise(starts)])
        self._radii = self._ring_radii()
        super().build()

    def reshape(self) -> None:
        self._radii = self._ring_radii()
        self.restore()
        if self.scene.others is Others.HIDDEN:
            self.conceal(self.scene.edited_chain())

    def rings(self, segment: int, rings: Rows) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        path = self.document.paths[segment]
        centres, tangents = path.centres(self.document.model.ribbons[segment].points, rings)
        rows = shift(rings, self.ring_start[segment], path.n_rings)
        normals = tube.minimal_rotation(self._normals[rows], self._tangents[rows], tangents)
        points, radial = tube.ring_vertices(centres, tangents, normals, self._radii[rows], self.sides)
        return centres, tangents, points, radial

    def _ring_radii(self) -> np.ndarray:
        """Tube radius of every ring: uniform, or by secondary structure, eased over a residue."""
        radii = []
        for segment, path in zip(self.document.structure.segments, self.document.paths):
            if not self.scene.fat_helices:
                radii.append(np.full(path.n_rings, TUBE_RADIUS))
                continue
            by_residue = np.array([FAT_RADII[s] for s in segment.ss])[path.owner]
            radii.append(eased(by_residue, path.rings_per_residue))
        return np.concatenate(radii)
