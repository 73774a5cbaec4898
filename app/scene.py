"""The 3D view of the document: one named pyvista mesh per layer, updated in place.

Meshes are built when a structure is loaded (or the ribbon kind changes). After that a
:class:`~app.document.Change` rewrites only the vertices of the residues that moved (tube
rings, Cα balls and sticks, atom rows); moving the slider rewrites the points of the level
curves and control points; only a change in the number of shown control points rebuilds
their small glyph mesh. Nothing here changes the document.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject

from app import molecule, tube
from app.document import Change, Document
from app.drag import HANDLE_RADIUS
from app.molecule import Colouring

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
POINT_COLOUR = (140, 90, 220)
PICKED_COLOUR = (0, 170, 255)
POLYGON_COLOUR = (110, 110, 120)
CA_STICK_COLOUR = (120, 124, 130)
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


DEFAULT_LAYERS = {Layer.TUBE, Layer.CURVE, Layer.CONTROL_POINTS, Layer.LIGANDS, Layer.IONS}

_ACTORS: dict[Layer, tuple[str, ...]] = {
    Layer.TUBE: ("tube",),
    Layer.CURVE: ("curve",),
    Layer.CONTROL_POINTS: ("control_points", "control_polygon", "handle"),
    Layer.CA_TRACE: ("ca_balls", "ca_sticks"),
    Layer.ATOMS: ("atoms",),
    Layer.LIGANDS: ("ligand_balls", "ligand_sticks"),
    Layer.IONS: ("ions",),
}


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
        self._sphere = pv.Icosphere(radius=1.0, nsub=1)
        self._shown_points = np.empty(0, dtype=np.int64)
        plotter.set_background(BACKGROUND[0], top=BACKGROUND[1])
        document.loaded.connect(self._build)
        document.changed.connect(self._on_change)
        document.levelChanged.connect(self._on_level)
        document.segmentChanged.connect(self._on_level)
        document.picked.connect(self._on_pick)
        if document.model is not None:
            self._build()

    # ------------------------------------------------------------------ options

    def set_layer(self, layer: Layer, visible: bool) -> None:
        """Show or hide a layer."""
        self.layers.discard(layer)
        if visible:
            self.layers.add(layer)
        for name in _ACTORS[layer]:
            if name in self.plotter.actors:
                self.plotter.actors[name].SetVisibility(visible and self._has_content(name))
        self.plotter.render()

    def set_colouring(self, colouring: Colouring | str) -> None:
        """Colour the tube and the Cα trace by secondary structure, residue type or chain."""
        self.colouring = Colouring(colouring)
        if self.document.model is not None:
            colours = molecule.residue_colours(self.document.structure, self.colouring)
            self._tube_colours(colours)
            self.meshes["ca_balls"].point_data["colours"][:] = np.repeat(colours, self._sphere.n_points, axis=0)
            self.plotter.render()

    def set_fat_helices(self, on: bool) -> None:
        """Tube radius by secondary structure (sheet > helix > other) or uniform."""
        self.fat_helices = on
        if self.document.model is not None:
            self._ring_radii = self._radii()
            for segment in range(len(self.document.paths)):
                self._sweep(segment, slice(None))
            self.plotter.render()

    def shown_control_points(self) -> np.ndarray:
        """Indices (into the level curve's control points) of the spheres on screen."""
        return self._shown_points

    # ------------------------------------------------------------------ building

    def _build(self) -> None:
        document = self.document
        structure = document.structure
        self.plotter.clear_actors()
        self.meshes.clear()
        self._ca_rows = document.ca_rows
        self._residue_offset = np.array([s.residue_index[0] for s in structure.segments])
        self._build_tube()
        self._build_curve()
        self._build_ca_trace()
        self._build_atoms()
        self._shown_points = np.empty(0, dtype=np.int64)
        self._update_control_points()
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
        self._add("tube", Layer.TUBE, scalars="colours", rgb=True, interpolation="phong", specular=0.35,
                  specular_power=25, diffuse=0.8, ambient=0.18)

    def _build_curve(self) -> None:
        samples = [self.document.level_curve(g).samples for g in range(len(self.document.paths))]
        self._curve_start = np.cumsum([0] + [len(s) for s in samples])
        mesh = pv.PolyData(np.vstack(samples), lines=_polylines(self._curve_start))
        self.meshes["curve"] = mesh
        self._add("curve", Layer.CURVE, color=CURVE_COLOUR, line_width=3.0, render_lines_as_tubes=True)

    def _build_ca_trace(self) -> None:
        structure = self.document.structure
        ca = self.document.model.coords[self._ca_rows]
        colours = molecule.residue_colours(structure, self.colouring)
        self.meshes["ca_balls"] = self._glyphs(ca, CA_RADIUS, colours)
        self._add("ca_balls", Layer.CA_TRACE, scalars="colours", rgb=True, interpolation="phong", specular=0.3)
        bounds = np.cumsum([0] + [len(s) for s in structure.segments])
        self.meshes["ca_sticks"] = pv.PolyData(ca.copy(), lines=_polylines(bounds))
        self._add("ca_sticks", Layer.CA_TRACE, color=CA_STICK_COLOUR, line_width=4.0, render_lines_as_tubes=True)

    def _build_atoms(self) -> None:
        structure = self.document.structure
        table = structure.atoms
        coords = self.document.model.coords
        polymer = np.flatnonzero(np.isin(table.category, ("protein", "nucleic")))
        self.meshes["atoms"] = _bond_lines(coords, molecule.bonds(coords, table.element, table.altloc, polymer),
                                           molecule.element_colours(table.element))
        self._add("atoms", Layer.ATOMS, scalars="colours", rgb=True, line_width=1.5)
        ions, ligands = molecule.ions_and_ligands(structure)
        self.meshes["ions"] = self._glyphs(coords[ions], ION_RADIUS, molecule.element_colours(table.element[ions]))
        self._add("ions", Layer.IONS, scalars="colours", rgb=True, interpolation="phong", specular=0.4)
        carbon = molecule.LIGAND_CARBON
        self.meshes["ligand_balls"] = self._glyphs(
            coords[ligands], LIGAND_ATOM_RADIUS, molecule.element_colours(table.element[ligands], carbon)
        )
        self._add("ligand_balls", Layer.LIGANDS, scalars="colours", rgb=True, interpolation="phong", specular=0.3)
        self.meshes["ligand_sticks"] = _bond_lines(coords, molecule.bonds(coords, table.element, table.altloc, ligands),
                                                   molecule.element_colours(table.element, carbon))
        self._add("ligand_sticks", Layer.LIGANDS, scalars="colours", rgb=True, line_width=5.0,
                  render_lines_as_tubes=True)

    # ------------------------------------------------------------------ updates

    def _on_change(self, change: Change) -> None:
        segment, residues = change.segment, change.residues
        if len(residues):
            self._sweep(segment, self.document.paths[segment].rings(residues))
            table_rows = self._residue_offset[segment] + residues
            ca = self.document.model.coords[self._ca_rows[table_rows]]
            self._move_glyphs("ca_balls", table_rows, ca)
            self.meshes["ca_sticks"].points[table_rows] = ca
        if len(change.rows) and self._has_content("atoms"):
            self.meshes["atoms"].points[change.rows] = self.document.model.coords[change.rows]
        samples = self.document.level_curve(segment).samples
        self.meshes["curve"].points[self._curve_start[segment]:self._curve_start[segment + 1]] = samples
        if segment == self.document.segment:
            self._update_control_points()
        self.plotter.render()

    def _on_level(self) -> None:
        curve = self.meshes["curve"]
        curve.points[:] = np.vstack([self.document.level_curve(g).samples for g in range(len(self.document.paths))])
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
        if len(shown) != len(self._shown_points) or "control_points" not in self.meshes:
            self.meshes["control_points"] = self._glyphs(points, HANDLE_RADIUS, colours)
            self._add("control_points", Layer.CONTROL_POINTS, scalars="colours", rgb=True, interpolation="phong",
                      specular=0.5, specular_power=30)
            self.meshes["control_polygon"] = pv.PolyData(points.copy(), lines=_polylines(np.array([0, len(points)])))
            self._add("control_polygon", Layer.CONTROL_POINTS, color=POLYGON_COLOUR, line_width=1.5)
        else:
            self._move_glyphs("control_points", np.arange(len(shown)), points)
            self.meshes["control_points"].point_data["colours"][:] = np.repeat(colours, self._sphere.n_points, axis=0)
            self.meshes["control_polygon"].points[:] = points
        self._shown_points = shown
        box = _box_edges(curve.control_points[pick.index] if pick is not None else np.zeros(3), HANDLE_BOX)
        if "handle" not in self.meshes:
            self.meshes["handle"] = box
            self._add("handle", Layer.CONTROL_POINTS, color=PICKED_COLOUR, line_width=2.0,
                      render_lines_as_tubes=True)
        else:
            self.meshes["handle"].points[:] = box.points
        self.plotter.actors["handle"].SetVisibility(pick is not None and Layer.CONTROL_POINTS in self.layers)

    def _update_caption(self) -> None:
        document = self.document
        curve = document.level_curve()
        level = document.shown_level()
        text = (f"{document.structure.entry_id}   {document.segment_label(document.segment)}\n"
                f"level {level:.2f} of {document.max_level:.2f}   {curve.n_segments} curve segments")
        caption = self.plotter.actors.get("caption")
        if caption is None:
            self.plotter.add_text(text, position="upper_left", font_size=10, color="#2b2f36", name="caption",
                                  render=False)
        else:
            caption.SetText(2, text)  # the upper-left corner of a corner annotation

    # ------------------------------------------------------------------ helpers

    def _sweep(self, segment: int, rings: np.ndarray | slice) -> None:
        """Recompute the tube vertices of ``rings`` of ``segment`` (and its caps when they are touched)."""
        path = self.document.paths[segment]
        local = np.arange(path.n_rings)[rings]
        centres, tangents = path.centres(self.document.model.ribbons[segment].points, local)
        rows = self._ring_start[segment] + local
        normals = tube.minimal_rotation(self._ring_normals[rows], self._ring_tangents[rows], tangents)
        points, radial = tube.ring_vertices(centres, tangents, normals, self._ring_radii[rows], TUBE_SIDES)
        vertices = (rows[:, None] * TUBE_SIDES + np.arange(TUBE_SIDES)).ravel()
        mesh = self.meshes["tube"]
        mesh.points[vertices] = points
        mesh.point_data["Normals"][vertices] = radial
        for end, ring in ((0, 0), (1, path.n_rings - 1)):
            where = np.flatnonzero(local == ring)
            if len(where):
                k = where[0]
                rim = points[k * TUBE_SIDES:(k + 1) * TUBE_SIDES]
                cap, cap_normals = tube.cap_vertices(centres[k], rim, tangents[k] * (1 if end else -1))
                first = self._cap_start[segment] + end * (TUBE_SIDES + 1)
                mesh.points[first:first + TUBE_SIDES + 1] = cap
                mesh.point_data["Normals"][first:first + TUBE_SIDES + 1] = cap_normals

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
        colours = self.meshes["tube"].point_data["colours"]
        colours[: len(ring_colours) * TUBE_SIDES] = np.repeat(ring_colours, TUBE_SIDES, axis=0)
        for segment, path in enumerate(self.document.paths):
            first = self._cap_start[segment]
            ends = residue_colours[self._residue_offset[segment] + path.owner[[0, -1]]]
            colours[first:first + 2 * (TUBE_SIDES + 1)] = np.repeat(ends, TUBE_SIDES + 1, axis=0)

    def _glyphs(self, centres: np.ndarray, radius: float, colours: np.ndarray) -> pv.PolyData:
        """Spheres of ``radius`` (Å) at ``centres`` (n, 3) as one mesh, coloured per sphere."""
        template = np.asarray(self._sphere.points)
        faces = self._sphere.regular_faces
        n, v = len(centres), len(template)
        if n == 0:
            return pv.PolyData()
        points = (centres[:, None, :] + radius * template[None]).reshape(-1, 3)
        mesh = pv.PolyData.from_regular_faces(points, (faces[None] + v * np.arange(n)[:, None, None]).reshape(-1, 3))
        mesh.point_data["Normals"] = np.tile(template, (n, 1))
        mesh.point_data.active_normals_name = "Normals"
        mesh.point_data["colours"] = np.repeat(np.asarray(colours, dtype=np.uint8).reshape(-1, 3), v, axis=0)
        mesh.field_data["radius"] = [radius]
        return mesh

    def _move_glyphs(self, name: str, which: np.ndarray, centres: np.ndarray) -> None:
        mesh = self.meshes[name]
        template = np.asarray(self._sphere.points)
        v = len(template)
        radius = float(mesh.field_data["radius"][0])
        vertices = (np.asarray(which)[:, None] * v + np.arange(v)).ravel()
        mesh.points[vertices] = (centres[:, None, :] + radius * template[None]).reshape(-1, 3)

    def _add(self, name: str, layer: Layer, **style: object) -> None:
        mesh = self.meshes[name]
        if not self._has_content(name):  # e.g. no ions: nothing to draw
            return
        actor = self.plotter.add_mesh(mesh, name=name, reset_camera=False, pickable=False, show_scalar_bar=False,
                                      smooth_shading=False, **style)
        actor.SetVisibility(layer in self.layers)

    def _has_content(self, name: str) -> bool:
        mesh = self.meshes.get(name)
        return mesh is not None and mesh.n_points > 0 and mesh.n_cells > 0

    def reset_camera(self) -> None:
        """Look at the structure along its axis of least extent (the widest view of the fold)."""
        ca = self.document.model.coords[self._ca_rows]
        centre = ca.mean(axis=0)
        _, _, axes = np.linalg.svd(ca - centre, full_matrices=False)
        self.plotter.camera_position = [tuple(centre + axes[2] * 100.0), tuple(centre), tuple(axes[1])]
        self.plotter.reset_camera()
        self.plotter.camera.zoom(1.15)


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


def _box_edges(centre: np.ndarray, edge: float) -> pv.PolyData:
    """The twelve edges of a cube of side ``edge`` (Å) around ``centre``."""
    corners = centre + 0.5 * edge * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    pairs = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
    return pv.PolyData(corners, lines=np.column_stack([np.full(len(pairs), 2), pairs]).ravel())
