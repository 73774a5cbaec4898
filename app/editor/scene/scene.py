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
from typing import TYPE_CHECKING

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject, QTimer
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkTextActor

from app.editor.document import Change, Document, Pick
from app.editor.interaction.drag import HANDLE_BOX, HANDLE_RADIUS
from app.editor.scene import molecule, tube
from app.editor.scene.molecule import Colouring

if TYPE_CHECKING:
    from app.editor.scene.view import View

TUBE_SIDES = 12
TUBE_RADIUS = 0.55
"""Å, the tube of the full-resolution ribbon."""
MOVING_RING_STEP = 3
MOVING_SIDE_STEP = 2
"""While something moves, the tube of the segments not edited keeps every third ring and
every other side of its vertices: a sixth of them."""
STILL_AFTER_MS = 250
"""Full detail comes back once nothing has moved for this long."""
FAT_RADII = {"H": 1.5, "E": 1.8, "C": 0.45}
"""Å, tube radii by secondary structure with "fat helices" on (sheet > helix > other)."""
CA_RADIUS = 0.45
LIGAND_ATOM_RADIUS = 0.35
ION_RADIUS = 1.1
POINT_SPACING_FRACTION = 0.04
"""Control-point spheres have this fraction of the level's median control-point spacing as
radius (at least HANDLE_RADIUS, at most MAX_POINT_RADIUS)..."""
MAX_POINT_RADIUS = 2.0
"""Å: coarse control polygons are wide (30 Å between points on ubiquitin at level 4)."""
MIN_POINT_PIXELS = 6.0
"""... and never less than this on screen (pixels), however far the camera is."""

CURVE_COLOUR = (40, 44, 52)
OTHER_CURVE_COLOUR = (120, 126, 136)
POINT_COLOUR = (140, 90, 220)
PICKED_COLOUR = (0, 170, 255)
SELECTION_COLOUR = (240, 40, 220)
SELECTION_RADIUS = 1.4
"""Å, the translucent balls around the Cα of selected residues."""
POLYGON_COLOUR = (110, 110, 120)
CA_STICK_COLOUR = (120, 124, 130)
CAPTION_COLOUR = "#2b2f36"
CAPTION_PIXELS = 15
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


class Others(StrEnum):
    """How the chains other than the edited one are drawn."""

    SHOWN = "shown"
    DIMMED = "dimmed"
    HIDDEN = "hidden"


DIM_TOWARD_WHITE = 0.7
"""Dimmed chains take this fraction of the way from their colour to white."""
DIM_ABOVE_CHAINS = 4
"""Entries with more chains than this open with the other chains dimmed."""
CONCEALED = ("tube", "curve", "ca_balls", "ca_sticks", "atoms", "ligand_sticks", "ions", "ligand_balls")
"""The meshes whose other chains are hidden."""

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
_TUBE_STYLE = {"scalars": "colours", "rgb": True, "interpolation": "phong", "specular": 0.35, "specular_power": 25.0,
               "diffuse": 0.8, "ambient": 0.18}
_MOVING_TUBES = ("tube_edited", "tube_others")
"""The tube while something moves: the edited segment's in full, the others' coarse."""
_LINES_AS_TUBES = ("curve", "ca_sticks", "ligand_sticks")
"""Meshes whose lines are shaded tubes at rest and plain lines while something moves."""


class Scene(QObject):
    """Draws a :class:`Document` into a pyvista plotter and follows its signals."""

    def __init__(self, document: Document, plotter: View) -> None:
        super().__init__(document)
        self.document = document
        self.plotter = plotter
        self.layers = set(DEFAULT_LAYERS)
        self.colouring = Colouring.SECONDARY_STRUCTURE
        self.fat_helices = False
        self.others = Others.SHOWN
        self._concealed = False
        self.point_radius = HANDLE_RADIUS
        """Radius of the control-point spheres, Å."""
        self.meshes: dict[str, pv.PolyData] = {}
        self.actors: dict[str, pv.Actor] = {}
        sphere = pv.Icosphere(radius=1.0, nsub=1)
        self._sphere = np.asarray(sphere.points)
        self._sphere_faces = sphere.regular_faces
        self._shown_points = np.empty(0, dtype=np.int64)
        self._shown_xyz = np.empty((0, 3))
        self._shown_pick: Pick | None = None
        self.moving = False
        """Whether the view is drawn with less detail because something moves (see :meth:`moved`)."""
        self._still_timer = QTimer(self, singleShot=True, interval=STILL_AFTER_MS)
        self._still_timer.timeout.connect(self.still)
        self._moving_rows: dict[str, np.ndarray] = {}
        self._moving_segment: int | None = None  # the edited segment when the moving tube was cut
        plotter.capturing.connect(lambda: self.still(render=False))
        plotter.set_background(BACKGROUND[0], top=BACKGROUND[1])
        plotter.renderer.AddObserver("StartEvent", lambda *_: self._size_points())
        document.loaded.connect(self._build)
        document.changed.connect(self._on_change)
        document.levelChanged.connect(self._on_level)
        document.segmentChanged.connect(self._on_segment)
        document.picked.connect(self._on_pick)
        document.selectionChanged.connect(self._on_selection)
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
            self._residue_colours_changed()
            self.plotter.render()

    def set_fat_helices(self, on: bool) -> None:
        """Tube radius by secondary structure (sheet > helix > other) or uniform."""
        self.fat_helices = on
        if self.document.editable:
            self._ring_radii = self._radii()
            for segment in range(len(self.document.paths)):
                self._sweep(segment, slice(None))
            self._conceal()
            self.plotter.render()

    def set_others(self, others: Others | str) -> None:
        """Show, dim or hide the chains other than the edited segment's."""
        self.others = Others(others)
        if self.document.editable:
            self._draw_others()
            self.plotter.render()

    def moved(self) -> None:
        """Something moves (the camera, a dragged point, the level slider): draw with less
        detail until nothing has moved for :data:`STILL_AFTER_MS`, then once in full. Less
        detail is: no FXAA, plain lines instead of shaded tubes, and the tube of the segments
        not edited with a sixth of its vertices."""
        self._still_timer.start()
        if not self.moving:
            self.moving = True
            self._set_detail()

    def still(self, render: bool = True) -> None:
        """Full detail from now on (at once, as before a screenshot, or once nothing moves)."""
        self._still_timer.stop()
        if self.moving:
            self.moving = False
            self._set_detail()
            if render:
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

    def centre_on(self, point: np.ndarray) -> None:
        """Turn the view about ``point`` (Å) from now on and bring it to the centre of the view:
        the camera keeps its direction and distance."""
        camera = self.plotter.renderer.GetActiveCamera()
        point = np.asarray(point, dtype=float)
        camera.SetPosition(*(np.array(camera.GetPosition()) + point - camera.GetFocalPoint()))
        camera.SetFocalPoint(*point)
        self.plotter.renderer.ResetCameraClippingRange()

    def shown_atoms(self) -> np.ndarray:
        """Rows of the coordinates of the atoms drawn now (polymer atoms, ligands, ions)."""
        rows = [rows for layer, rows in self._atom_rows.items() if layer in self.layers]
        return np.concatenate(rows) if rows else np.empty(0, dtype=np.int64)

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
        self.others = Others.SHOWN
        self._concealed = False
        self.still(render=False)
        self._moving_rows.clear()
        self._moving_segment = None
        if self.document.editable:
            self._residue_offset = np.array([s.residue_index[0] for s in structure.segments])
            self._residue_chain = np.concatenate([np.full(len(s), s.chain) for s in structure.segments])
            if len(set(self._residue_chain)) > DIM_ABOVE_CHAINS:
                self.others = Others.DIMMED
            self._build_tube()
            self._build_curve()
            self._build_ca_trace()
            self._update_control_points()
            self.meshes["selection"] = pv.PolyData()
            self._on_selection(render=False)
        self._build_atoms()
        self._show_layers()
        self._update_caption()
        if self.others is not Others.SHOWN:
            self._draw_others()
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
        self._tube_colours(self._residue_colours())
        self._add("tube", **_TUBE_STYLE)

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
        self.meshes["ca_balls"] = self._glyphs(ca, CA_RADIUS, self._residue_colours())
        self._add("ca_balls", scalars="colours", rgb=True, **_SHINY)
        bounds = np.cumsum([0] + [len(s) for s in structure.segments])
        self.meshes["ca_sticks"] = pv.PolyData(ca.copy(), lines=_polylines(bounds))
        self._add("ca_sticks", color=CA_STICK_COLOUR, line_width=4.0, render_lines_as_tubes=True)

    def _build_atoms(self) -> None:
        structure = self.document.structure
        table = structure.atoms
        coords = self.document.model.coords
        polymer = np.flatnonzero(np.isin(table.category, ("protein", "nucleic")))
        self._atom_colours = molecule.element_colours(table.element)
        self.meshes["atoms"] = _bond_lines(coords, molecule.bonds(coords, table.element, table.altloc, polymer),
                                           self._atom_colours)
        self._add("atoms", scalars="colours", rgb=True, line_width=1.5)
        ions, ligands = molecule.ions_and_ligands(structure)
        self._atom_rows = {Layer.ATOMS: polymer, Layer.LIGANDS: ligands, Layer.IONS: ions}
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
            if self._moving_rows:
                self._copy_moving_tube("tube_edited" if segment == self._moving_segment else "tube_others")
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
        if len(self.document.selection):
            self._move_glyphs("selection", slice(None), model.coords[self.document.ca_rows[self.document.selection]])
        if self._residue_chain[self._residue_offset[segment]] != self._chain():  # an undo in a hidden chain
            self._conceal()
        self.plotter.render()

    def _on_selection(self, render: bool = True) -> None:
        """Translucent balls around the selected residues' Cα (one small mesh, rebuilt)."""
        rows = self.document.selection
        ca = self.document.model.coords[self.document.ca_rows[rows]]
        colours = np.tile(np.array(SELECTION_COLOUR, dtype=np.uint8), (len(rows), 1))
        self.meshes["selection"].shallow_copy(self._glyphs(ca, SELECTION_RADIUS, colours))
        if "selection" not in self.actors and len(rows):
            self._add("selection", scalars="colours", rgb=True, opacity=0.45, **_SHINY)
        if render:
            self.plotter.render()

    def _on_segment(self) -> None:
        self.still(render=False)
        self._colour_curves()
        if self.others is not Others.SHOWN:
            self._draw_others()
        self.frame_segment()
        self._on_level()

    def _chain(self) -> str:
        """The edited segment's chain."""
        return self.document.structure.segments[self.document.segment].chain

    def _residue_colours(self) -> np.ndarray:
        """Every residue's colour in the scheme, the other chains' faded when they are dimmed."""
        colours = molecule.residue_colours(self.document.structure, self.colouring)
        if self.others is Others.DIMMED:
            colours = _faded(colours, self._residue_chain != self._chain())
        return colours

    def _residue_colours_changed(self) -> None:
        colours = self._residue_colours()
        self._tube_colours(colours)
        self._write("ca_balls", slice(None), np.repeat(colours, len(self._sphere), axis=0), "colours")

    def _draw_others(self) -> None:
        """Colours and positions of every chain as :attr:`others` says (after a change of it
        or of the edited chain)."""
        self._residue_colours_changed()
        if self.meshes["atoms"].n_points:
            table = self.document.structure.atoms
            fade = self.others is Others.DIMMED
            self._write("atoms", slice(None), _faded(self._atom_colours, fade & (table.chain != self._chain())),
                        "colours")
        if self._concealed:  # put every vertex back where the model has it
            model = self.document.model
            for segment in range(len(self.document.paths)):
                self._sweep(segment, slice(None))
            ca = model.coords[self.document.ca_rows]
            self._move_glyphs("ca_balls", slice(None), ca)
            self._write("ca_sticks", slice(None), ca)
            ions, ligands = self._atom_rows[Layer.IONS], self._atom_rows[Layer.LIGANDS]
            for name, centres in (("ions", model.coords[ions]), ("ligand_balls", model.coords[ligands])):
                if self.meshes[name].n_points:
                    self._move_glyphs(name, slice(None), centres)
            for name in ("atoms", "ligand_sticks"):
                if self.meshes[name].n_points:
                    self._write(name, slice(None), model.coords)
            self._write("curve", slice(None), np.vstack([self.document.level_curve(g).samples
                                                         for g in range(len(self.document.paths))]))
            self._concealed = False
        self._conceal()

    def _conceal(self, names: tuple[str, ...] = CONCEALED) -> None:
        """With :attr:`others` hidden, collapse the other chains' vertices in meshes ``names``
        onto one point each: their faces and lines then cover no pixel."""
        if self.others is not Others.HIDDEN:
            return
        self._concealed = True
        chain = self._chain()
        for segment, path in enumerate(self.document.paths):
            first = self._residue_offset[segment]
            if self._residue_chain[first] == chain:
                continue
            n_residues = len(self.document.structure.segments[segment])
            rows = {"tube": _shift(slice(None), self._ring_start[segment], path.n_rings, TUBE_SIDES),
                    "curve": slice(self._curve_start[segment], self._curve_start[segment + 1]),
                    "ca_balls": _shift(slice(None), first, n_residues, len(self._sphere)),
                    "ca_sticks": slice(first, first + n_residues)}
            for name in names:
                if name in rows:
                    self._collapse(name, rows[name])
            if "tube" in names:
                caps = slice(self._cap_start[segment], self._cap_start[segment] + 2 * (TUBE_SIDES + 1))
                self._collapse("tube", caps)
        other = self.document.structure.atoms.chain != chain
        for name in ("atoms", "ligand_sticks"):
            if name in names and self.meshes[name].n_points:
                self._collapse(name, np.flatnonzero(other))
        for name, layer in (("ions", Layer.IONS), ("ligand_balls", Layer.LIGANDS)):
            rows = np.flatnonzero(other[self._atom_rows[layer]])
            if name in names and len(rows):
                self._collapse(name, _shift(rows, 0, len(self._atom_rows[layer]), len(self._sphere)))

    def _collapse(self, name: str, rows: np.ndarray | slice) -> None:
        points = vtk_to_numpy(self.meshes[name].GetPoints().GetData())
        if len(points[rows]):
            self._write(name, rows, points[rows][0])

    def _colour_curves(self) -> None:
        """The level curve of the edited segment in a dark colour, the others lighter."""
        colours = np.tile(np.array(OTHER_CURVE_COLOUR, dtype=np.uint8), (self._curve_start[-1], 1))
        segment = self.document.segment
        colours[self._curve_start[segment]:self._curve_start[segment + 1]] = CURVE_COLOUR
        self._write("curve", slice(None), colours, "colours")

    def _on_level(self) -> None:
        samples = np.vstack([self.document.level_curve(g).samples for g in range(len(self.document.paths))])
        self._write("curve", slice(None), samples)
        self._conceal(("curve",))
        self._update_control_points()
        self._update_caption()
        self.plotter.render()

    def _on_pick(self) -> None:
        self._update_control_points()
        self.plotter.render()

    def _size_points(self) -> None:
        """Before each frame: resize the control-point spheres and the handle box when the
        level's spacing or the camera's distance asks for another size (by more than 5%)."""
        if "control_points" not in self.meshes or not len(self._shown_xyz):
            return
        radius = self._wanted_radius(self._shown_xyz)
        if abs(radius - self.point_radius) > 0.05 * self.point_radius:
            self.point_radius = radius
            self._update_control_points(resized=True)

    def _wanted_radius(self, points: np.ndarray) -> float:
        """Å, the sphere radius for control points ``points`` seen from the camera now."""
        spacing = float(np.median(np.linalg.norm(np.diff(points, axis=0), axis=1))) if len(points) > 1 else 0.0
        camera = self.plotter.renderer.GetActiveCamera()
        height = max(self.plotter.renderer.GetSize()[1], 1)
        if camera.GetParallelProjection():
            pixel = 2.0 * camera.GetParallelScale() / height
        else:
            depth = float((points.mean(axis=0) - np.array(camera.GetPosition())) @ camera.GetDirectionOfProjection())
            pixel = 2.0 * np.tan(np.radians(camera.GetViewAngle()) / 2.0) * max(depth, 0.0) / height
        return max(HANDLE_RADIUS, min(POINT_SPACING_FRACTION * spacing, MAX_POINT_RADIUS), MIN_POINT_PIXELS * pixel)

    def _update_control_points(self, resized: bool = False) -> None:
        curve = self.document.level_curve()
        shown = np.flatnonzero(curve.visible)
        points = curve.control_points[shown]
        pick = self.document.pick
        colours = np.tile(np.array(POINT_COLOUR, dtype=np.uint8), (len(shown), 1))
        if pick is not None:
            colours[shown == pick.index] = PICKED_COLOUR
        if len(shown) == len(self._shown_points) and not resized:  # rewrite the spheres that moved or changed colour
            moved = _span(np.flatnonzero(np.any(points != self._shown_xyz, axis=1)))
            self._move_glyphs("control_points", moved, points[moved])
            self._write("control_polygon", moved, points[moved])
            if pick is not self._shown_pick:
                self._write("control_points", slice(None), np.repeat(colours, len(self._sphere), axis=0), "colours")
        elif "control_points" in self.meshes:  # another level or size: new glyph data under the same actors
            if not resized:  # another level: its spacing asks for another size (not rebuilt again before the frame)
                radius = self._wanted_radius(points)
                if abs(radius - self.point_radius) > 0.05 * self.point_radius:
                    self.point_radius = radius
            self.meshes["control_points"].shallow_copy(self._glyphs(points, self.point_radius, colours))
            self.meshes["control_polygon"].shallow_copy(_polyline(points))
            self._box_corners = np.array(_box_edges(HANDLE_BOX * self.point_radius).points)
        else:
            self.meshes["control_points"] = self._glyphs(points, self.point_radius, colours)
            self._add("control_points", scalars="colours", rgb=True, interpolation="phong", specular=0.5,
                      specular_power=30.0)
            self.meshes["control_polygon"] = _polyline(points)
            self._add("control_polygon", color=POLYGON_COLOUR, line_width=1.5)
            self.meshes["handle"] = _box_edges(HANDLE_BOX * self.point_radius)
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
        if "caption" not in self.actors:  # a text actor of one font size (a corner annotation fits its
            actor = vtkTextActor()        # size to the view at every frame: slow with software OpenGL)
            style = actor.GetTextProperty()
            style.SetFontSize(CAPTION_PIXELS)
            style.SetColor(pv.Color(CAPTION_COLOUR).float_rgb)
            style.SetVerticalJustificationToTop()
            actor.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
            actor.SetPosition(0.008, 0.99)
            self.actors["caption"] = actor
            self.plotter.add_actor(actor, name="caption", reset_camera=False, render=False)
        self.actors["caption"].SetInput(text)

    # ------------------------------------------------------------------ level of detail

    def _set_detail(self) -> None:
        full = not self.moving
        self.plotter.renderer.SetUseFXAA(full)
        for name in _LINES_AS_TUBES:
            if name in self.actors:
                self.actors[name].prop.render_lines_as_tubes = full
        self._moving_rows.clear()
        if self.moving and "tube" in self.actors and len(self.document.paths) > 1:
            self._cut_moving_tube()
        self._show_tube()

    def _cut_moving_tube(self) -> None:
        """The tube while something moves, its vertices taken from the full tube's: the
        edited segment's all (caps included), the other segments' every third ring and
        every other side (no caps)."""
        segment = self.document.segment
        rows, faces = {}, {}
        first, last = self._ring_start[segment] * TUBE_SIDES, self._ring_start[segment + 1] * TUBE_SIDES
        caps = np.arange(self._cap_start[segment], self._cap_start[segment] + 2 * (TUBE_SIDES + 1))
        rows["tube_edited"] = np.r_[first:last, caps]
        n_rings = self.document.paths[segment].n_rings
        faces["tube_edited"] = [tube.tube_faces(n_rings, TUBE_SIDES)] + [
            tube.cap_faces(TUBE_SIDES, last - first + end * (TUBE_SIDES + 1)) for end in (0, 1)]
        others, others_faces, start = [], [], 0
        for g, path in enumerate(self.document.paths):
            if g != segment:
                kept, n_kept, sides = tube.coarse_rows(path.n_rings, TUBE_SIDES, MOVING_RING_STEP, MOVING_SIDE_STEP)
                others.append(kept + self._ring_start[g] * TUBE_SIDES)
                others_faces.append(tube.tube_faces(n_kept, sides, start))
                start += len(kept)
        rows["tube_others"], faces["tube_others"] = np.concatenate(others), others_faces
        full = self.meshes["tube"]
        for name in _MOVING_TUBES:
            self._moving_rows[name] = rows[name]
            if self._moving_segment != segment or name not in self.meshes:
                mesh = pv.PolyData(np.asarray(full.points)[rows[name]], faces=_cells(faces[name]))
                for array in ("Normals", "colours"):
                    mesh.point_data[array] = np.asarray(full.point_data[array])[rows[name]]
                mesh.point_data.active_normals_name = "Normals"
                if name in self.meshes:
                    self.meshes[name].shallow_copy(mesh)
                else:
                    self.meshes[name] = mesh
                    self._add(name, **_TUBE_STYLE, culling="back")  # a third cheaper: no hidden side drawn
            else:
                self._copy_moving_tube(name, colours=True)
        self._moving_segment = segment

    def _copy_moving_tube(self, name: str, colours: bool = False) -> None:
        """Copy the vertices (and normals, and ``colours``) of the moving tube ``name`` from the full tube."""
        full, rows = self.meshes["tube"], self._moving_rows[name]
        for array in (None, "Normals", "colours") if colours else (None, "Normals"):
            source = full.GetPoints().GetData() if array is None else full.GetPointData().GetArray(array)
            self._write(name, slice(None), vtk_to_numpy(source)[rows], array)

    def _show_tube(self) -> None:
        """The full tube at rest; while something moves, the moving tube when there is one."""
        moving = bool(self._moving_rows)
        for name in ("tube", *_MOVING_TUBES):
            if name in self.actors:
                self.actors[name].SetVisibility(Layer.TUBE in self.layers and (name != "tube") == moving)

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
        self._show_tube()


def _faded(colours: np.ndarray, which: np.ndarray) -> np.ndarray:
    """(n, 3) uint8 ``colours`` with rows ``which`` (a mask) taken toward white."""
    colours = np.array(colours, dtype=np.uint8)
    colours[which] = np.rint(colours[which] + DIM_TOWARD_WHITE * (255 - colours[which].astype(float)))
    return colours


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
