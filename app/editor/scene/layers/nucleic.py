"""Nucleic acids (:mod:`app.editor.scene.nucleic`): the strands' backbone tube
(``nucleic_tube``), the bases' slabs (``nucleic_bases``) and the sticks that join them
(``nucleic_sticks``), coloured by base; also drawn for a structure that is only viewed (a
DNA duplex). Edits move none of their atoms."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from app.editor.scene import nucleic
from app.editor.scene.layers.base import Layer, SceneLayer
from app.editor.scene.layers.meshes import cells, collapse
from app.editor.scene.looks import NUCLEIC_BACKBONE

"""The grey of the backbone tube."""
_STYLE = {"scalars": "colours", "rgb": True, "interpolation": "phong", "specular": 0.3, "specular_power": 20.0,
          "diffuse": 0.8, "ambient": 0.2}


class NucleicLayer(SceneLayer):
    """DNA and RNA as a backbone tube and a slab per base."""

    switch = Layer.NUCLEIC
    needs_backbone = False
    names = ("nucleic_tube", "nucleic_bases", "nucleic_sticks")
    lines_as_tubes = ("nucleic_sticks",)

    def build(self) -> None:
        self.found = nucleic.nucleotides(self.document.structure.atoms)
        """The nucleotides drawn."""
        coords = self.document.model.coords
        points, normals, quads, self._tube_owner = nucleic.backbone_tube(coords, self.found)
        self.meshes["nucleic_tube"] = _mesh(points, quads, np.full((len(points), 3), NUCLEIC_BACKBONE), normals)
        self.add("nucleic_tube", **_STYLE)
        points, triangles, self._base_owner = nucleic.base_slabs(coords, self.found)
        self.meshes["nucleic_bases"] = _mesh(points, triangles, self.found.colours[self._base_owner])
        self.add("nucleic_bases", **_STYLE)
        ends = np.column_stack([self.found.backbone, self.found.glycosidic])  # anchor, C1', N
        keep = np.all(ends >= 0, axis=1)
        self._stick_rows = ends[keep].ravel()
        self.meshes["nucleic_sticks"] = _mesh(coords[self._stick_rows], None, np.repeat(self.found.colours[keep], 3, axis=0),
                                              lines=_stick_lines(int(keep.sum())))
        self.add("nucleic_sticks", scalars="colours", rgb=True, line_width=5.0, render_lines_as_tubes=True)

    def conceal(self, chain: str) -> None:
        other = self.found.chain != chain
        for name, owner in (("nucleic_tube", self._tube_owner), ("nucleic_bases", self._base_owner)):
            if self.meshes[name].n_points:
                collapse(self.meshes[name], np.flatnonzero(other[owner]))
        if self.meshes["nucleic_sticks"].n_points:
            chains = self.document.structure.atoms.chain[self._stick_rows]
            collapse(self.meshes["nucleic_sticks"], np.flatnonzero(chains != chain))

    def restore(self) -> None:
        coords = self.document.model.coords
        if self.meshes["nucleic_tube"].n_points:
            self.write("nucleic_tube", slice(None), nucleic.backbone_tube(coords, self.found)[0])
        if self.meshes["nucleic_bases"].n_points:
            self.write("nucleic_bases", slice(None), nucleic.base_slabs(coords, self.found)[0])
        if self.meshes["nucleic_sticks"].n_points:
            self.write("nucleic_sticks", slice(None), coords[self._stick_rows])


def _mesh(points: np.ndarray, faces: np.ndarray | None, colours: np.ndarray, normals: np.ndarray | None = None,
          lines: np.ndarray | None = None) -> pv.PolyData:
    """A mesh of ``points`` with ``faces`` (f, k) or ``lines`` (a cell array), coloured per point;
    empty without points."""
    if not len(points):
        return pv.PolyData()
    mesh = pv.PolyData(points.copy(), faces=None if faces is None else cells([faces]), lines=lines)
    mesh.point_data["colours"] = np.asarray(colours, dtype=np.uint8)
    if normals is not None:
        mesh.point_data["Normals"] = normals
        mesh.point_data.active_normals_name = "Normals"
    return mesh


def _stick_lines(n: int) -> np.ndarray:
    """Two lines per stick of three points (anchor to C1', C1' to the base's N), as a cell array."""
    first = 3 * np.arange(n)
    return np.column_stack([np.full(n, 2), first, first + 1, np.full(n, 2), first + 1, first + 2]).ravel()
