"""The ribbon tube: rings swept along each segment's full-resolution curve, with flat end caps.

One mesh, ``tube``: ring vertices segment by segment, then the caps (two per segment). An
edit sweeps again only the rings of the residues that moved. While something moves (see
:meth:`~app.editor.scene.scene.Scene.moved`) the tube is drawn from two other meshes cut from
it: the edited segment's in full (``tube_edited``) and the other segments' with a sixth of
their vertices (``tube_others``), whose vertices are copied from the full tube after an edit.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy

from app.editor.document import Change
from app.editor.scene import tube
from app.editor.scene.layers.base import Layer, SceneLayer, Stage
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.meshes import Rows, cells, collapse, shift, span

TUBE_SIDES = 12
TUBE_RADIUS = 0.55
"""Å, the tube of the full-resolution ribbon."""
FAT_RADII = {"H": 1.5, "E": 1.8, "C": 0.45}
"""Å, tube radii by secondary structure with "fat helices" on (sheet > helix > other)."""
MOVING_RING_STEP = 3
MOVING_SIDE_STEP = 2
"""While something moves, the tube of the segments not edited keeps every third ring and
every other side of its vertices: a sixth of them."""

_STYLE = {"scalars": "colours", "rgb": True, "interpolation": "phong", "specular": 0.35, "specular_power": 25.0,
          "diffuse": 0.8, "ambient": 0.18}
_MOVING = ("tube_edited", "tube_others")
"""The tube while something moves: the edited segment's in full, the others' coarse."""


class TubeLayer(SceneLayer):
    """The ribbon tube, coloured per residue, uniform or fat by secondary structure."""

    switch = Layer.TUBE
    names = ("tube", *_MOVING)

    def __init__(self, scene: Stage) -> None:
        super().__init__(scene)
        self._moving_rows: dict[str, np.ndarray] = {}
        """Rows of the full tube that each moving tube copies (none at rest)."""
        self._moving_segment: int | None = None  # the edited segment when the moving tube was cut

    def build(self) -> None:
        paths = self.document.paths
        self.ring_start = np.cumsum([0] + [p.n_rings for p in paths])
        """(n_segments + 1,) the first ring of each segment (and the number of rings)."""
        self._tangents = np.empty((self.ring_start[-1], 3))
        self._normals = np.empty((self.ring_start[-1], 3))
        for segment, path in enumerate(paths):
            _, tangents = path.centres(self.document.model.ribbons[segment].points)
            rows = slice(self.ring_start[segment], self.ring_start[segment + 1])
            self._tangents[rows] = tangents
            self._normals[rows] = tube.transported_normals(tangents)
        self._radii = self._ring_radii()
        n_ring_vertices = self.ring_start[-1] * TUBE_SIDES
        self._cap_start = n_ring_vertices + np.arange(len(paths)) * 2 * (TUBE_SIDES + 1)
        faces = [tube.tube_faces(p.n_rings, TUBE_SIDES, self.ring_start[g] * TUBE_SIDES) for g, p in enumerate(paths)]
        caps = [tube.cap_faces(TUBE_SIDES, start + end * (TUBE_SIDES + 1)) for start in self._cap_start for end in (0, 1)]
        n_vertices = n_ring_vertices + 2 * len(paths) * (TUBE_SIDES + 1)
        mesh = pv.PolyData(np.zeros((n_vertices, 3)), faces=cells(faces + caps))
        mesh.point_data["Normals"] = np.zeros((n_vertices, 3))
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["colours"] = np.zeros((n_vertices, 3), dtype=np.uint8)
        self.meshes["tube"] = mesh
        self._moving_rows.clear()
        self._moving_segment = None
        self.restore()
        self.recolour(self.scene.residue_colours())
        self.add("tube", **_STYLE)

    def update(self, change: Change) -> None:
        if len(change.residues):
            self._sweep(change.segment, span(self.document.paths[change.segment].rings(change.residues)))
            if self._moving_rows:
                self._copy_moving("tube_edited" if change.segment == self._moving_segment else "tube_others")

    def recolour(self, residue_colours: np.ndarray) -> None:
        offset = self.scene.chains.offset
        ring_colours = np.concatenate([residue_colours[offset[g] + path.owner]
                                       for g, path in enumerate(self.document.paths)])
        self.write("tube", slice(0, len(ring_colours) * TUBE_SIDES), np.repeat(ring_colours, TUBE_SIDES, axis=0),
                   "colours")
        for segment, path in enumerate(self.document.paths):
            first = self._cap_start[segment]
            ends = residue_colours[offset[segment] + path.owner[[0, -1]]]
            self.write("tube", slice(first, first + 2 * (TUBE_SIDES + 1)), np.repeat(ends, TUBE_SIDES + 1, axis=0),
                       "colours")

    def reshape(self) -> None:
        self._radii = self._ring_radii()
        self.restore()
        if self.scene.others is Others.HIDDEN:
            self.conceal(self.scene.edited_chain())

    def conceal(self, chain: str) -> None:
        mesh = self.meshes["tube"]
        for segment in self.scene.chains.other_segments(chain):
            n_rings = self.document.paths[segment].n_rings
            collapse(mesh, shift(slice(None), self.ring_start[segment], n_rings, TUBE_SIDES))
            collapse(mesh, slice(self._cap_start[segment], self._cap_start[segment] + 2 * (TUBE_SIDES + 1)))

    def restore(self) -> None:
        for segment in range(len(self.document.paths)):
            self._sweep(segment, slice(None))

    def set_detail(self, full: bool) -> None:
        self._moving_rows.clear()
        if not full and "tube" in self.actors and len(self.document.paths) > 1:
            self._cut_moving()
        self.show(self.visible)

    def show(self, visible: bool) -> None:
        """The full tube at rest; while something moves, the moving tube when there is one."""
        moving = bool(self._moving_rows)
        for name in self.names:
            if name in self.actors:
                self.actors[name].SetVisibility(visible and (name != "tube") == moving)

    def _cut_moving(self) -> None:
        """The tube while something moves, its vertices taken from the full tube's: the
        edited segment's all (caps included), the other segments' every third ring and
        every other side (no caps)."""
        segment = self.document.segment
        rows, faces = {}, {}
        first, last = self.ring_start[segment] * TUBE_SIDES, self.ring_start[segment + 1] * TUBE_SIDES
        caps = np.arange(self._cap_start[segment], self._cap_start[segment] + 2 * (TUBE_SIDES + 1))
        rows["tube_edited"] = np.r_[first:last, caps]
        n_rings = self.document.paths[segment].n_rings
        faces["tube_edited"] = [tube.tube_faces(n_rings, TUBE_SIDES)] + [
            tube.cap_faces(TUBE_SIDES, last - first + end * (TUBE_SIDES + 1)) for end in (0, 1)]
        others, others_faces, start = [], [], 0
        for g, path in enumerate(self.document.paths):
            if g != segment:
                kept, n_kept, sides = tube.coarse_rows(path.n_rings, TUBE_SIDES, MOVING_RING_STEP, MOVING_SIDE_STEP)
                others.append(kept + self.ring_start[g] * TUBE_SIDES)
                others_faces.append(tube.tube_faces(n_kept, sides, start))
                start += len(kept)
        rows["tube_others"], faces["tube_others"] = np.concatenate(others), others_faces
        full = self.meshes["tube"]
        for name in _MOVING:
            self._moving_rows[name] = rows[name]
            if self._moving_segment != segment or name not in self.meshes:
                mesh = pv.PolyData(np.asarray(full.points)[rows[name]], faces=cells(faces[name]))
                for array in ("Normals", "colours"):
                    mesh.point_data[array] = np.asarray(full.point_data[array])[rows[name]]
                mesh.point_data.active_normals_name = "Normals"
                if name in self.meshes:
                    self.meshes[name].shallow_copy(mesh)
                else:
                    self.meshes[name] = mesh
                    self.add(name, **_STYLE, culling="back")  # a third cheaper: no hidden side drawn
            else:
                self._copy_moving(name, colours=True)
        self._moving_segment = segment

    def _copy_moving(self, name: str, colours: bool = False) -> None:
        """Copy the vertices (and normals, and ``colours``) of the moving tube ``name`` from the full tube."""
        full, rows = self.meshes["tube"], self._moving_rows[name]
        for array in (None, "Normals", "colours") if colours else (None, "Normals"):
            source = full.GetPoints().GetData() if array is None else full.GetPointData().GetArray(array)
            self.write(name, slice(None), vtk_to_numpy(source)[rows], array)

    def _sweep(self, segment: int, rings: Rows) -> None:
        """Recompute the tube vertices of ``rings`` of ``segment`` (and its caps when they are touched)."""
        path = self.document.paths[segment]
        local = np.arange(path.n_rings)[rings]
        centres, tangents = path.centres(self.document.model.ribbons[segment].points, rings)
        rows = shift(rings, self.ring_start[segment], path.n_rings)
        normals = tube.minimal_rotation(self._normals[rows], self._tangents[rows], tangents)
        points, radial = tube.ring_vertices(centres, tangents, normals, self._radii[rows], TUBE_SIDES)
        vertices = shift(rings, self.ring_start[segment], path.n_rings, TUBE_SIDES)
        self.write("tube", vertices, points)
        self.write("tube", vertices, radial, "Normals")
        for end, ring in ((0, 0), (1, path.n_rings - 1)):
            where = np.flatnonzero(local == ring)
            if len(where):
                k = where[0]
                rim = points[k * TUBE_SIDES:(k + 1) * TUBE_SIDES]
                cap, cap_normals = tube.cap_vertices(centres[k], rim, tangents[k] * (1 if end else -1))
                first = self._cap_start[segment] + end * (TUBE_SIDES + 1)
                self.write("tube", slice(first, first + TUBE_SIDES + 1), cap)
                self.write("tube", slice(first, first + TUBE_SIDES + 1), cap_normals, "Normals")

    def _ring_radii(self) -> np.ndarray:
        """Tube radius of every ring: uniform, or by secondary structure, eased over a residue."""
        radii = []
        for segment, path in zip(self.document.structure.segments, self.document.paths):
            if not self.scene.fat_helices:
                radii.append(np.full(path.n_rings, TUBE_RADIUS))
                continue
            by_residue = np.array([FAT_RADII[s] for s in segment.ss])[path.owner]
            window = np.ones(path.rings_per_residue + 1) / (path.rings_per_residue + 1)
            padded = np.pad(by_residue, path.rings_per_residue // 2, mode="edge")
            radii.append(np.convolve(padded, window, mode="valid"))
        return np.concatenate(radii)
