"""What the tube and the cartoon share: rings of vertices swept along each segment's curve, at
the rings of :class:`~app.editor.scene.curves.SegmentPath`, with flat end caps.

One mesh named as the layer (``tube``, ``cartoon``): ring vertices segment by segment, then
the caps (two per segment), its faces stored in 32 bits (:func:`~app.editor.scene.layers.meshes.compact`). An edit sweeps again only the rings of the residues that moved.
While something moves (see :meth:`~app.editor.scene.scene.Scene.moved`) the layer is drawn
from two other meshes cut from it: the edited segment's in full (``<name>_edited``) and the
other segments' with a sixth of their vertices (``<name>_others``), whose vertices are copied
from the full mesh after an edit. A hidden layer sweeps nothing: it is swept in full when
shown again. A layer says how its rings look (:meth:`SweptLayer.rings`).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy

from app.editor.document import Change
from app.editor.scene import tube
from app.editor.scene.layers.base import SceneLayer, Stage
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.meshes import Rows, cells, collapse, compact, shift, span

MOVING_RING_STEP = 3
MOVING_SIDE_STEP = 2
"""While something moves, the segments not edited keep every third ring and every other side
of their vertices: a sixth of them."""
STYLE = {"scalars": "colours", "rgb": True, "interpolation": "phong", "specular": 0.35, "specular_power": 25.0,
         "diffuse": 0.8, "ambient": 0.18}


class SweptLayer(SceneLayer):
    """Rings swept along every segment's curve, coloured per residue."""

    name: ClassVar[str]
    """Its full mesh; the moving ones add ``_edited`` and ``_others``."""

    def __init__(self, scene: Stage) -> None:
        super().__init__(scene)
        self.moving_names = (f"{self.name}_edited", f"{self.name}_others")
        self._moving_rows: dict[str, np.ndarray] = {}
        """Rows of the full mesh that each moving mesh copies (none at rest)."""
        self._moving_segment: int | None = None  # the edited segment when the moving meshes were cut
        self._stale = False
        """Whether the mesh missed changes while hidden."""

    @property
    def sides(self) -> int:
        """Vertices around each ring, as the segments' paths are sampled (all alike)."""
        return self.document.paths[0].sides

    def rings(self, segment: int, rings: Rows) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The centres (r, 3) and unit tangents (r, 3) of ``rings`` of ``segment``, and their
        vertices and vertex normals (r * :attr:`sides`, 3), ring by ring."""
        raise NotImplementedError

    def build(self) -> None:
        paths = self.document.paths
        self.ring_start = np.cumsum([0] + [p.n_rings for p in paths])
        """(n_segments + 1,) the first ring of each segment (and the number of rings)."""
        sides = self.sides
        n_ring_vertices = self.ring_start[-1] * sides
        self._cap_start = n_ring_vertices + np.arange(len(paths)) * 2 * (sides + 1)
        faces = [tube.tube_faces(p.n_rings, sides, self.ring_start[g] * sides) for g, p in enumerate(paths)]
        caps = [tube.cap_faces(sides, start + end * (sides + 1)) for start in self._cap_start for end in (0, 1)]
        n_vertices = n_ring_vertices + 2 * len(paths) * (sides + 1)
        # single precision, as the renderer takes them: half the memory of a capsid's ribbons
        mesh = compact(pv.PolyData(np.zeros((n_vertices, 3), np.float32), faces=cells(faces + caps)))
        mesh.point_data["Normals"] = np.zeros((n_vertices, 3), np.float32)
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["colours"] = np.zeros((n_vertices, 3), dtype=np.uint8)
        self.meshes[self.name] = mesh
        self._moving_rows.clear()
        self._moving_segment = None
        self._stale = False
        self.restore()
        self.recolour(self.scene.residue_colours())
        self.add(self.name, **STYLE)

    def before_frame(self) -> None:
        """Back faces are culled (half the triangles rasterized: the software renderer's memory
        and time) except while the slab clips the view, where a cut ribbon shows its inside."""
        cull = self.scene.slab is None
        for name in self.names:
            if name in self.actors:
                self.actors[name].GetProperty().SetBackfaceCulling(cull)

    def hidden(self) -> bool:
        """Whether it is hidden, and so must be swept in full once shown (:meth:`show`)."""
        if not self.visible:
            self._stale = True
        return self._stale

    @property
    def names(self) -> tuple[str, ...]:  # type: ignore[override]
        return (self.name, *self.moving_names)

    def update(self, change: Change) -> None:
        if len(change.residues) and not self.hidden():
            self.sweep(change.segment, span(self.document.paths[change.segment].rings(change.residues)))

    def recolour(self, residue_colours: np.ndarray) -> None:
        if self.hidden():
            return
        offset = self.scene.chains.offset
        ring_colours = np.concatenate([residue_colours[offset[g] + path.owner]
                                       for g, path in enumerate(self.document.paths)])
        sides = self.sides
        self.write(self.name, slice(0, len(ring_colours) * sides), np.repeat(ring_colours, sides, axis=0), "colours")
        for segment, path in enumerate(self.document.paths):
            first = self._cap_start[segment]
            ends = residue_colours[offset[segment] + path.owner[[0, -1]]]
            self.write(self.name, slice(first, first + 2 * (sides + 1)), np.repeat(ends, sides + 1, axis=0),
                       "colours")
        if self._moving_rows:
            for name in self.moving_names:
                self._copy_moving(name, colours=True)

    def conceal(self, chain: str) -> None:
        if self.hidden():
            return
        mesh = self.meshes[self.name]
        for segment in self.scene.chains.other_segments(chain):
            n_rings = self.document.paths[segment].n_rings
            collapse(mesh, shift(slice(None), self.ring_start[segment], n_rings, self.sides))
            collapse(mesh, slice(self._cap_start[segment], self._cap_start[segment] + 2 * (self.sides + 1)))

    def restore(self) -> None:
        if self.hidden():
            return
        for segment in range(len(self.document.paths)):
            self.sweep(segment, slice(None))

    def set_detail(self, full: bool) -> None:
        self._moving_rows.clear()
        if not full and self.visible and self.name in self.actors and len(self.document.paths) > 1:
            self._cut_moving()
        self.show(self.visible)

    def show(self, visible: bool) -> None:
        """The full mesh at rest; while something moves, the moving meshes when there are some
        (swept first where it missed changes while hidden)."""
        if visible and self._stale:
            self._stale = False
            self.restore()
            self.recolour(self.scene.residue_colours())
            if self.scene.others is Others.HIDDEN:
                self.conceal(self.scene.edited_chain())
        moving = bool(self._moving_rows)
        for name in self.names:
            if name in self.actors:
                self.actors[name].SetVisibility(visible and (name != self.name) == moving)

    def sweep(self, segment: int, rings: Rows) -> None:
        """Recompute the vertices of ``rings`` of ``segment`` (and its caps when they are
        touched), in the full mesh and in the moving one that copies them."""
        path = self.document.paths[segment]
        local = np.arange(path.n_rings)[rings]
        centres, tangents, points, normals = self.rings(segment, rings)
        vertices = shift(rings, self.ring_start[segment], path.n_rings, self.sides)
        self.write(self.name, vertices, points)
        self.write(self.name, vertices, normals, "Normals")
        for end, ring in ((0, 0), (1, path.n_rings - 1)):
            where = np.flatnonzero(local == ring)
            if len(where):
                k = where[0]
                rim = points[k * self.sides:(k + 1) * self.sides]
                cap, cap_normals = tube.cap_vertices(centres[k], rim, tangents[k] * (1 if end else -1))
                first = self._cap_start[segment] + end * (self.sides + 1)
                self.write(self.name, slice(first, first + self.sides + 1), cap)
                self.write(self.name, slice(first, first + self.sides + 1), cap_normals, "Normals")
        if self._moving_rows:
            self._copy_moving(self.moving_names[segment != self._moving_segment])

    def _cut_moving(self) -> None:
        """The meshes while something moves, their vertices taken from the full mesh's: the
        edited segment's all (caps included), the other segments' every third ring and
        every other side (no caps)."""
        segment = self.document.segment
        rows, faces = {}, {}
        edited, others_name = self.moving_names
        first, last = self.ring_start[segment] * self.sides, self.ring_start[segment + 1] * self.sides
        caps = np.arange(self._cap_start[segment], self._cap_start[segment] + 2 * (self.sides + 1))
        rows[edited] = np.r_[first:last, caps]
        n_rings = self.document.paths[segment].n_rings
        faces[edited] = [tube.tube_faces(n_rings, self.sides)] + [
            tube.cap_faces(self.sides, last - first + end * (self.sides + 1)) for end in (0, 1)]
        others, others_faces, start = [], [], 0
        for g, path in enumerate(self.document.paths):
            if g != segment:
                kept, n_kept, sides = tube.coarse_rows(path.n_rings, self.sides, MOVING_RING_STEP, MOVING_SIDE_STEP)
                others.append(kept + self.ring_start[g] * self.sides)
                others_faces.append(tube.tube_faces(n_kept, sides, start))
                start += len(kept)
        rows[others_name], faces[others_name] = np.concatenate(others), others_faces
        full = self.meshes[self.name]
        for name in self.moving_names:
            self._moving_rows[name] = rows[name]
            if self._moving_segment != segment or name not in self.meshes:
                mesh = compact(pv.PolyData(np.asarray(full.points)[rows[name]], faces=cells(faces[name])))
                for array in ("Normals", "colours"):
                    mesh.point_data[array] = np.asarray(full.point_data[array])[rows[name]]
                mesh.point_data.active_normals_name = "Normals"
                if name in self.meshes:
                    self.meshes[name].shallow_copy(mesh)
                else:
                    self.meshes[name] = mesh
                    self.add(name, **STYLE)
            else:
                self._copy_moving(name, colours=True)
        self._moving_segment = segment

    def _copy_moving(self, name: str, colours: bool = False) -> None:
        """Copy the vertices (and normals, and ``colours``) of the moving mesh ``name`` from the full mesh."""
        full, rows = self.meshes[self.name], self._moving_rows[name]
        for array in (None, "Normals", "colours") if colours else (None, "Normals"):
            source = full.GetPoints().GetData() if array is None else full.GetPointData().GetArray(array)
            self.write(name, slice(None), vtk_to_numpy(source)[rows], array)
