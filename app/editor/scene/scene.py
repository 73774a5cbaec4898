"""The 3D view of the document: one named pyvista mesh per layer, updated in place.

Meshes are built when a structure is loaded (or the ribbon kind changes). After that a
:class:`~app.editor.document.Change` rewrites only the vertices of the residues that moved (tube
rings, Cα balls and sticks, atom rows) straight into the VTK arrays; moving the slider
rewrites the points of the level curves and control points; a change in the number of
shown control points swaps the data of their small glyph mesh under the same actor.
A structure that is only viewed (no backbone) gets the atom layers and a caption saying
why. Nothing here changes the document.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject
from vtkmodules.util.numpy_support import vtk_to_numpy

from app.editor.document import Change, Document, Pick
from app.editor.drag import HANDLE_RADIUS
from app.editor.scene import molecule, tube
from app.editor.scene.molecule import Colouring

TUBE_SIDES = 12
TUBE_RADIUS = 0.55
"""Å, the tube of the full-resolution ribbon."""
FAT_RADII = {"H": 1.5, "E": 1.8, "C": 0.45}
"""Å, tube radii by secondary structure with "fat helices" on (sheet > helix > other)."""
CA_RADIUS = 0.45
LIGAND_ATOM_RADIUS = 0.35
ION_RADIUS = 1.1
HANDLE_BOX = 2.2 * HANDLE_RADIUS
"""Edge of the handle box around the picked control point, Å."""

CURVE_COLOUR = (40, 44, 52)
OTHER_CURVE_COLOUR = (120, 126, 136)
POINT_COLOUR = (140, 90, 220)
PICKED_COLOUR = (0, 170, 255)
POLYGON_COLOUR = (110, 110, 120)
CA_STICK_COLOUR = (120, 124, 130)
CAPTION_COLOUR = "#2b2f36"
BACKGROUND = ("#ffffff", "#dfe5ec")


class Layer(StrEnum):
    """What can be shown, each switchable on its own."""

    TUBE = "ribbon tube"
    CURVE = "level curve"
    CONTROL_POINTS = "control points"
    CA_TRACE = "Cα trace"
    ATOMS = "atoms"
    LIGANDS = "ligands"
    IONS = "ions"
    VALIDATION = "validation markers"


DEFAULT_LAYERS = {Layer.TUBE, Layer.CURVE, Layer.CONTROL_POINTS, Layer.LIGANDS, Layer.IONS, Layer.VALIDATION}

_ACTORS: dict[Layer, tuple[str, ...]] = {
    Layer.TUBE: ("tube",),
    Layer.CURVE: ("curve",),
    Layer.CONTROL_POINTS: ("control_points", "control_polygon", "handle"),
    Layer.CA_TRACE: ("ca_balls", "ca_sticks"),
    Layer.ATOMS: ("atoms",),
    Layer.LIGANDS: ("ligand_balls", "ligand_sticks"),
    Layer.IONS: ("ions",),
    Layer.VALIDATION: ("validation_markers",),  # drawn by app.editor.scene.validation_markers
}
_SHINY = {"interpolation": "phong", "specular": 0.4, "specular_power": 25.0}


class Scene(QObject):
    """Draws a :class:`Document` into a pyvista plotter and follows its signals."""

    def __init__(self, document: Document, plotter: pv.BasePlotter) -> None:
        super().__init__(document)
        self.document = document
        self.plotter = plotter
        self.layers = set(DEFAULT_LAYERS)
        self.colouring = Colouring.SECONDARY_STRUCTURE
        self.fat_helices = False
        self.meshes: dict[str, pv.PolyData] = {}
        self.actors: dict[str, pv.Actor] = {}
        sphere = pv.Icosphere(radius=1.0, nsub=1)
        self._sphere = np.asarray(sphere.points)
        self._sphere_faces = sphere.regular_faces
        self._shown_points = np.empty(0, dtype=np.int64)
        self._shown_xyz = np.empty((0, 3))
        self._shown_pick: Pick | None = None
        plotter.set_background(BACKGROUND[0], top=BACKGROUND[1])
        document.loaded.connect(self._build)
        document.changed.connect(self._on_change)
        document.levelChanged.connect(self._on_level)
        document.segmentChanged.connect(self._on_segment)
        document.picked.connect(self._on_pick)
        if document.model is not None:
            self._build()

    # ------------------------------------------------------------------ options

    def set_layer(self, layer: Layer, visible: bool) -> None:
        """Show or hide a layer."""
        self.layers.discard(layer)
        if visible:
            self.layers.add(layer)
        self._show_layers()
        self.plotter.render()

    def set_colouring(self, colouring: Colouring | str) -> None:
        """Colour the tube and the Cα trace by secondary structure, residue type or chain."""
        self.colouring = Colouring(colouring)
        if self.document.editable:
            colours = molecule.residue_colours(self.document.structure, self.colouring)
            self._tube_colours(colours)
            self._write("ca_balls", slice(None), np.repeat(colours, len(self._sphere), axis=0), "colours")
            self.plotter.render()

    def set_fat_helices(self, on: bool) -> None:
        """Tube radius by secondary structure (sheet > helix > other) or uniform."""
        self.fat_helices = on
        if self.document.editable:
            self._ring_radii = self._radii()
            for segment in range(len(self.document.paths)):
                self._sweep(segment, slice(None))
            self.plotter.render()

    def reset_camera(self) -> None:
        """Look at the structure (its Cα, or all atoms without a backbone) along its axis of
        least extent (the widest view of the fold)."""
        coords = self.document.model.coords
        ca = coords[self.document.ca_rows] if len(self.document.ca_rows) else coords
        centre = ca.mean(axis=0)
        _, axes = np.linalg.eigh((ca - centre).T @ (ca - centre))  # by increasing extent; any number of atoms
        renderer = self.plotter.renderer
        renderer.camera_position = [tuple(centre + axes[:, 0] * 100.0), tuple(centre), tuple(axes[:, 1])]
        renderer.reset_camera(render=False)
        renderer.camera.zoom(1.15)

    def frame_segment(self) -> None:
        """Centre the view on the edited segment and fit it in, looking from where the camera is."""
        structure = self.document.structure
        ca = self.document.model.coords[self.document.ca_rows[structure.segments[self.document.segment].residue_index]]
        low, high = ca.min(axis=0) - 2.0, ca.max(axis=0) + 2.0
        self.plotter.renderer.ResetCamera(low[0], high[0], low[1], high[1], low[2], high[2])

    def shown_control_points(self) -> np.ndarray:
        """Indices (into the level curve's control points) of the spheres on screen."""
        return self._shown_points

    # ------------------------------------------------------------------ building

    def _build(self) -> None:
        structure = self.document.structure
        self.plotter.clear_actors()
        self.meshes.clear()
        self.actors.clear()
        self._shown_points = np.empty(0, dtype=np.int64)
        if self.document.editable:
            self._residue_offset = np.array([s.residue_index[0] for s in structure.segments])
            self._build_tube()
            self._build_curve()
            self._build_ca_trace()
            self._update_control_points()
        self._build_atoms()
        self._show_layers()
        self._update_caption()
        self.reset_camera()
        self.plotter.render()

    def _build_tube(self) -> None:
        paths = self.document.paths
        self._ring_start = np.cumsum([0] + [p.n_rings for p in paths])
        self._ring_tangents = np.empty((self._ring_start[-1], 3))
        self._ring_normals = np.empty((self._ring_start[-1], 3))
        for segment, path in enumerate(paths):
            _, tangents = path.centres(self.document.model.ribbons[segment].points)
            rows = slice(self._ring_start[segment], self._ring_start[segment + 1])
            self._ring_tangents[rows] = tangents
            self._ring_normals[rows] = tube.transported_normals(tangents)
        self._ring_radii = self._radii()
        n_ring_vertices = self._ring_start[-1] * TUBE_SIDES
        self._cap_start = n_ring_vertices + np.arange(len(paths)) * 2 * (TUBE_SIDES + 1)
        faces = [tube.tube_faces(p.n_rings, TUBE_SIDES, self._ring_start[g] * TUBE_SIDES) for g, p in enumerate(paths)]
        caps = [tube.cap_faces(TUBE_SIDES, start + end * (TUBE_SIDES + 1))
                for start in self._cap_start for end in (0, 1)]
        n_vertices = n_ring_vertices + 2 * len(paths) * (TUBE_SIDES + 1)
        mesh = pv.PolyData(np.zeros((n_vertices, 3)), faces=_cells(faces + caps))
        mesh.point_data["Normals"] = np.zeros((n_vertices, 3))
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["colours"] = np.zeros((n_vertices, 3), dtype=np.uint8)
        self.meshes["tube"] = mesh
        for segment in range(len(paths)):
            self._sweep(segment, slice(None))
        self._tube_colours(molecule.residue_colours(self.document.structure, self.colouring))
        self._add("tube", scalars="colours", rgb=True, interpolation="phong", specular=0.35, specular_power=25.0,
                  diffuse=0.8, ambient=0.18)

    def _build_curve(self) -> None:
        samples = [self.document.level_curve(g).samples for g in range(len(self.document.paths))]
        self._curve_start = np.cumsum([0] + [len(s) for s in samples])
        self.meshes["curve"] = pv.PolyData(np.vstack(samples), lines=_polylines(self._curve_start))
        self.meshes["curve"].point_data["colours"] = np.zeros((len(self.meshes["curve"].points), 3), dtype=np.uint8)
        self._colour_curves()
        self._add("curve", scalars="colours", rgb=True, line_width=3.0, render_lines_as_tubes=True)

    def _build_ca_trace(self) -> None:
        structure = self.document.structure
        ca = self.document.model.coords[self.document.ca_rows]
        self.meshes["ca_balls"] = self._glyphs(ca, CA_RADIUS, molecule.residue_colours(structure, self.colouring))
        self._add("ca_balls", scalars="colours", rgb=True, **_SHINY)
        bounds = np.cumsum([0] + [len(s) for s in structure.segments])
        self.meshes["ca_sticks"] = pv.PolyData(ca.copy(), lines=_polylines(bounds))
        self._add("ca_sticks", color=CA_STICK_COLOUR, line_width=4.0, render_lines_as_tubes=True)

    def _build_atoms(self) -> None:
        structure = self.document.structure
        table = structure.atoms
        coords = self.document.model.coords
        polymer = np.flatnonzero(np.isin(table.category, ("protein", "nucleic")))
        self.meshes["atoms"] = _bond_lines(coords, molecule.bonds(coords, table.element, table.altloc, polymer),
                                           molecule.element_colours(table.element))
        self._add("atoms", scalars="colours", rgb=True, line_width=1.5)
        ions, ligands = molecule.ions_and_ligands(structure)
        self.meshes["ions"] = self._glyphs(coords[ions], ION_RADIUS, molecule.element_colours(table.element[ions]))
        self._add("ions", scalars="colours", rgb=True, **_SHINY)
        carbon = molecule.LIGAND_CARBON
        self.meshes["ligand_balls"] = self._glyphs(
            coords[ligands], LIGAND_ATOM_RADIUS, molecule.element_colours(table.element[ligands], carbon)
        )
        self._add("ligand_balls", scalars="colours", rgb=True, **_SHINY)
        self.meshes["ligand_sticks"] = _bond_lines(coords, molecule.bonds(coords, table.element, table.altloc, ligands),
                                                   molecule.element_colours(table.element, carbon))
        self._add("ligand_sticks", scalars="colours", rgb=True, line_width=5.0, render_lines_as_tubes=True)

    # ------------------------------------------------------------------ updates

    def _on_change(self, change: Change) -> None:
        segment, residues = change.segment, change.residues
        model = self.document.model
        if len(residues):
            self._sweep(segment, _span(self.document.paths[segment].rings(residues)))
            table_rows = self._residue_offset[segment] + residues
            ca = model.coords[self.document.ca_rows[table_rows]]
            self._move_glyphs("ca_balls", _span(table_rows), ca)
            self._write("ca_sticks", _span(table_rows), ca)
        if len(change.rows) and self.meshes["atoms"].n_points:  # no bonds (a Cα-only model): no mesh
            rows = _span(np.sort(change.rows))
            self._write("atoms", rows, model.coords[rows])
        curve = slice(self._curve_start[segment], self._curve_start[segment + 1])
        self._write("curve", curve, self.document.level_curve(segment).samples)
        if segment == self.document.segment:
            self._update_control_points()
        self.plotter.render()

    def _on_segment(self) -> None:
        self._colour_curves()
        self.frame_segment()
        self._on_level()

    def _colour_curves(self) -> None:
        """The level curve of the edited segment in a dark colour, the others lighter."""
        colours = np.tile(np.array(OTHER_CURVE_COLOUR, dtype=np.uint8), (self._curve_start[-1], 1))
        segment = self.document.segment
        colours[self._curve_start[segment]:self._curve_start[segment + 1]] = CURVE_COLOUR
        self._write("curve", slice(None), colours, "colours")

    def _on_level(self) -> None:
        samples = np.vstack([self.document.level_curve(g).samples for g in range(len(self.document.paths))])
        self._write("curve", slice(None), samples)
        self._update_control_points()
        self._update_caption()
        self.plotter.render()

    def _on_pick(self) -> None:
        self._update_control_points()
        self.plotter.render()

    def _update_control_points(self) -> None:
        curve = self.document.level_curve()
        shown = np.flatnonzero(curve.visible)
        points = curve.control_points[shown]
        pick = self.document.pick
        colours = np.tile(np.array(POINT_COLOUR, dtype=np.uint8), (len(shown), 1))
        if pick is not None:
            colours[shown == pick.index] = PICKED_COLOUR
        if len(shown) == len(self._shown_points):  # rewrite only the spheres that moved or changed colour
            moved = _span(np.flatnonzero(np.any(points != self._shown_xyz, axis=1)))
            self._move_glyphs("control_points", moved, points[moved])
            self._write("control_polygon", moved, points[moved])
            if pick is not self._shown_pick:
                self._write("control_points", slice(None), np.repeat(colours, len(self._sphere), axis=0), "colours")
        elif "control_points" in self.meshes:  # another level: new glyph data under the same actors
            self.meshes["control_points"].shallow_copy(self._glyphs(points, HANDLE_RADIUS, colours))
            self.meshes["control_polygon"].shallow_copy(_polyline(points))
        else:
            self.meshes["control_points"] = self._glyphs(points, HANDLE_RADIUS, colours)
            self._add("control_points", scalars="colours", rgb=True, interpolation="phong", specular=0.5,
                      specular_power=30.0)
            self.meshes["control_polygon"] = _polyline(points)
            self._add("control_polygon", color=POLYGON_COLOUR, line_width=1.5)
            self.meshes["handle"] = _box_edges(HANDLE_BOX)
            self._add("handle", color=PICKED_COLOUR, line_width=2.0, render_lines_as_tubes=True)
            self._box_corners = np.array(self.meshes["handle"].points)
        self._shown_points, self._shown_xyz, self._shown_pick = shown, points, pick
        if pick is not None:
            self._write("handle", slice(None), curve.control_points[pick.index] + self._box_corners)
        self.actors["handle"].SetVisibility(pick is not None and Layer.CONTROL_POINTS in self.layers)

    def _update_caption(self) -> None:
        document = self.document
        text = document.read_only_reason or (
            f"{document.structure.entry_id}   {document.segment_label(document.segment)}\n"
            f"level {document.shown_level():.2f} of {document.max_level:.2f}   "
            f"{document.level_curve().n_segments} curve segments")
        if "caption" in self.actors:
            self.actors["caption"].SetText(2, text)  # the upper-left corner of a corner annotation
        else:
            self.actors["caption"] = self.plotter.add_text(text, position="upper_left", font_size=9,
                                                           color=CAPTION_COLOUR, name="caption", render=False)

    # ------------------------------------------------------------------ helpers

    def _sweep(self, segment: int, rings: np.ndarray | slice) -> None:
        """Recompute the tube vertices of ``rings`` of ``segment`` (and its caps when they are touched)."""
        path = self.document.paths[segment]
        local = np.arange(path.n_rings)[rings]
        centres, tangents = path.centres(self.document.model.ribbons[segment].points, rings)
        first_ring = self._ring_start[segment]
        rows = _shift(rings, first_ring, path.n_rings)
        normals = tube.minimal_rotation(self._ring_normals[rows], self._ring_tangents[rows], tangents)
        points, radial = tube.ring_vertices(centres, tangents, normals, self._ring_radii[rows], TUBE_SIDES)
        vertices = _shift(rings, first_ring, path.n_rings, TUBE_SIDES)
        self._write("tube", vertices, points)
        self._write("tube", vertices, radial, "Normals")
        for end, ring in ((0, 0), (1, path.n_rings - 1)):
            where = np.flatnonzero(local == ring)
            if len(where):
                k = where[0]
                rim = points[k * TUBE_SIDES:(k + 1) * TUBE_SIDES]
                cap, cap_normals = tube.cap_vertices(centres[k], rim, tangents[k] * (1 if end else -1))
                first = self._cap_start[segment] + end * (TUBE_SIDES + 1)
                self._write("tube", slice(first, first + TUBE_SIDES + 1), cap)
                self._write("tube", slice(first, first + TUBE_SIDES + 1), cap_normals, "Normals")

    def _radii(self) -> np.ndarray:
        """Tube radius of every ring: uniform, or by secondary structure, eased over a residue."""
        radii = []
        for segment, path in zip(self.document.structure.segments, self.document.paths):
            if not self.fat_helices:
                radii.append(np.full(path.n_rings, TUBE_RADIUS))
                continue
            by_residue = np.array([FAT_RADII[s] for s in segment.ss])[path.owner]
            window = np.ones(path.rings_per_residue + 1) / (path.rings_per_residue + 1)
            padded = np.pad(by_residue, path.rings_per_residue // 2, mode="edge")
            radii.append(np.convolve(padded, window, mode="valid"))
        return np.concatenate(radii)

    def _tube_colours(self, residue_colours: np.ndarray) -> None:
        ring_colours = np.concatenate([
            residue_colours[self._residue_offset[g] + path.owner] for g, path in enumerate(self.document.paths)
        ])
        self._write("tube", slice(0, len(ring_colours) * TUBE_SIDES), np.repeat(ring_colours, TUBE_SIDES, axis=0),
                    "colours")
        for segment, path in enumerate(self.document.paths):
            first = self._cap_start[segment]
            ends = residue_colours[self._residue_offset[segment] + path.owner[[0, -1]]]
            self._write("tube", slice(first, first + 2 * (TUBE_SIDES + 1)), np.repeat(ends, TUBE_SIDES + 1, axis=0),
                        "colours")

    def _glyphs(self, centres: np.ndarray, radius: float, colours: np.ndarray) -> pv.PolyData:
        """Spheres of ``radius`` (Å) at ``centres`` (n, 3) as one mesh, coloured per sphere."""
        n, v = len(centres), len(self._sphere)
        if n == 0:
            return pv.PolyData()
        faces = (self._sphere_faces[None] + v * np.arange(n)[:, None, None]).reshape(-1, 3)
        mesh = pv.PolyData.from_regular_faces(_glyph_points(centres, radius * self._sphere), faces)
        mesh.point_data["Normals"] = np.tile(self._sphere, (n, 1))
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["colours"] = np.repeat(np.asarray(colours, dtype=np.uint8).reshape(-1, 3), v, axis=0)
        mesh.field_data["radius"] = [radius]
        return mesh

    def _move_glyphs(self, name: str, which: np.ndarray | slice, centres: np.ndarray) -> None:
        radius = float(self.meshes[name].field_data["radius"][0])
        v = len(self._sphere)
        n = len(self.meshes[name].points) // v
        self._write(name, _shift(which, 0, n, v), _glyph_points(centres, radius * self._sphere))

    def _write(self, name: str, where: np.ndarray | slice, values: np.ndarray, array: str | None = None) -> None:
        """Overwrite rows ``where`` of the points (or of point array ``array``) of mesh ``name`` in place."""
        mesh = self.meshes[name]
        target = mesh.GetPoints().GetData() if array is None else mesh.GetPointData().GetArray(array)
        vtk_to_numpy(target)[where] = values
        target.Modified()
        mesh.Modified()

    def _add(self, name: str, **style: object) -> None:
        if self.meshes[name].n_points == 0:  # e.g. no ions: nothing to draw
            return
        self.actors[name] = self.plotter.add_mesh(self.meshes[name], name=name, reset_camera=False, pickable=False,
                                                  show_scalar_bar=False, smooth_shading=False, render=False, **style)

    def _show_layers(self) -> None:
        for layer, names in _ACTORS.items():
            for name in names:
                if name in self.actors:
                    self.actors[name].SetVisibility(layer in self.layers)
        if "handle" in self.actors:
            self.actors["handle"].SetVisibility(self.document.pick is not None and Layer.CONTROL_POINTS in self.layers)


def _span(indices: np.ndarray) -> np.ndarray | slice:
    """Sorted ``indices`` as a slice when they are consecutive (faster to read and write)."""
    if len(indices) and indices[-1] - indices[0] + 1 == len(indices):
        return slice(int(indices[0]), int(indices[-1]) + 1)
    return indices


def _shift(rows: np.ndarray | slice, offset: int, n: int, width: int = 1) -> np.ndarray | slice:
    """Rows ``rows`` of a block of ``n`` rows starting at ``offset``, each widened to ``width`` rows."""
    if isinstance(rows, slice):
        start, stop, _ = rows.indices(n)
        return slice((offset + start) * width, (offset + stop) * width)
    return ((offset + np.asarray(rows))[:, None] * width + np.arange(width)).ravel()


def _glyph_points(centres: np.ndarray, template: np.ndarray) -> np.ndarray:
    """``template`` (v, 3) placed at every centre (n, 3): (n * v, 3), one small product per centre."""
    v = len(template)
    placement = np.vstack([np.tile(np.eye(3), v), template.reshape(1, -1)])
    return (np.column_stack([centres, np.ones(len(centres))])[:, None, :] @ placement).reshape(-1, 3)


def _cells(blocks: list[np.ndarray]) -> np.ndarray:
    """pyvista's flat cell array ``[n, i0, ..., n, j0, ...]`` from blocks of equal-size cells."""
    return np.concatenate([np.column_stack([np.full(len(b), b.shape[1]), b]).ravel() for b in blocks if len(b)])


def _bond_lines(coords: np.ndarray, bonds: np.ndarray, colours: np.ndarray) -> pv.PolyData:
    """Lines for ``bonds`` (b, 2) over all atoms (points in coordinate-row order, no vertex cells)."""
    if len(bonds) == 0:
        return pv.PolyData()
    mesh = pv.PolyData(coords.copy(), lines=np.column_stack([np.full(len(bonds), 2), bonds]).ravel())
    mesh.point_data["colours"] = colours
    return mesh


def _polylines(bounds: np.ndarray) -> np.ndarray:
    """One polyline per consecutive range ``bounds[k]:bounds[k+1]`` of points."""
    return np.concatenate([np.r_[stop - start, start:stop] for start, stop in zip(bounds[:-1], bounds[1:])])


def _polyline(points: np.ndarray) -> pv.PolyData:
    return pv.PolyData(points.copy(), lines=_polylines(np.array([0, len(points)])))


def _box_edges(edge: float) -> pv.PolyData:
    """The twelve edges of a cube of side ``edge`` (Å) around the origin."""
    corners = 0.5 * edge * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    pairs = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
    return pv.PolyData(corners, lines=np.column_stack([np.full(len(pairs), 2), pairs]).ravel())
