"""The 3D view of the document: its layers (:mod:`app.editor.scene.layers`) drawn into a pyvista
plotter, and what they share: the display options, the camera, the caption, the level of
detail and one render per event.

Layers are built when a structure is loaded (or the ribbon kind changes). After that every
document signal becomes one hook called on each layer in turn, then one render: a
:class:`~app.editor.document.Change` rewrites only the vertices of the residues that moved,
straight into the VTK arrays; moving the slider rewrites the points of the level curves and
control points. A structure that is only viewed (no backbone) gets the layers that need none
(atoms, ligands, ions) and a caption saying why. Nothing here changes the document.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeVar

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject, QTimer
from vtkmodules.vtkRenderingCore import vtkTextActor

from app.editor.document import Change, Document
from app.editor.scene import molecule
from app.editor.scene.layers.atoms import AtomsLayer
from app.editor.scene.layers.base import Layer, SceneLayer
from app.editor.scene.layers.ca_trace import CaTraceLayer
from app.editor.scene.layers.cartoon import CartoonLayer
from app.editor.scene.layers.chains import DIM_ABOVE_CHAINS, Chains, Others, faded
from app.editor.scene.layers.control_points import ControlPointsLayer
from app.editor.scene.layers.level_curve import CurveLayer
from app.editor.scene.layers.ligands import IonsLayer, LigandsLayer, WatersLayer
from app.editor.scene.layers.measurements import MeasurementsLayer
from app.editor.scene.layers.models import ModelsLayer
from app.editor.scene.layers.nucleic import NucleicLayer
from app.editor.scene.layers.selection import SelectionLayer
from app.editor.scene.layers.tube import TubeLayer
from app.editor.scene.looks import BACKGROUND, FIT_CLOSER, VIEW_ANGLE
from app.editor.scene.molecule import Colouring
from core.geometry.principal import principal_directions

if TYPE_CHECKING:
    from app.editor.scene.view_base import View

LAYERS: tuple[type[SceneLayer], ...] = (
    CartoonLayer,
    TubeLayer,
    CurveLayer,
    CaTraceLayer,
    ControlPointsLayer,
    SelectionLayer,
    AtomsLayer,
    NucleicLayer,
    ModelsLayer,
    LigandsLayer,
    IonsLayer,
    WatersLayer,
    MeasurementsLayer,
)
"""The layers every scene draws, in this order (the validation markers add themselves)."""
DEFAULT_LAYERS = {Layer.CARTOON, Layer.CURVE, Layer.CONTROL_POINTS, Layer.NUCLEIC, Layer.LIGANDS, Layer.IONS,
                  Layer.VALIDATION, Layer.MEASUREMENTS, Layer.MODELS}
MIN_SLAB = 0.5
"""Å: the nearest a clipping plane comes to the centre of the view."""
STILL_AFTER_MS = 250
"""Full detail comes back once nothing has moved for this long."""
CAPTION_COLOUR = "#2b2f36"
CAPTION_PIXELS = 15

L = TypeVar("L", bound=SceneLayer)


class Scene(QObject):
    """Draws a :class:`Document` into a pyvista plotter, layer by layer, and follows its signals."""

    def __init__(self, document: Document, plotter: View) -> None:
        super().__init__(document)
        self.document = document
        self.plotter = plotter
        self.layers = set(DEFAULT_LAYERS)
        """The layers switched on."""
        self.colouring = Colouring.SECONDARY_STRUCTURE
        self.fat_helices = False
        self.helix_cylinders = False
        self.others = Others.SHOWN
        self.slab: tuple[float, float] | None = None
        """The clipping slab: how far (Å) its near and far planes lie in front of and behind the
        centre of the view (the camera's focal point), or None (nothing clipped)."""
        self.chains: Chains
        """The residues' chains (set when an editable structure is built)."""
        self.meshes: dict[str, pv.PolyData] = {}
        """Every layer's meshes by name, which is also their actor's name."""
        self.actors: dict[str, pv.Actor] = {}
        self.moving = False
        """Whether the view is drawn with less detail because something moves (see :meth:`moved`)."""
        self.parts: list[SceneLayer] = [kind(self) for kind in LAYERS]
        """The layers, in drawing order."""
        self._drawn: list[SceneLayer] = []
        """The layers built for the structure shown (those that need no backbone when it has none)."""
        self._unbuilt: list[SceneLayer] = []
        """The layers of the structure shown that stay unbuilt while they are hidden (a hidden
        layer costs no memory until it is first shown: the tube and Cα spheres of a capsid)."""
        self._control_points = self.part(ControlPointsLayer)
        self._concealed = False
        self._still_timer = QTimer(self, singleShot=True, interval=STILL_AFTER_MS)
        self._still_timer.timeout.connect(self.still)
        plotter.capturing.connect(lambda: self.still(render=False))
        plotter.set_background(BACKGROUND[0], top=BACKGROUND[1])
        plotter.renderer.AddObserver("StartEvent", lambda *_: self._before_frame())
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
        """Colour the ribbons and the Cα trace by secondary structure, residue type, chain, a
        rainbow along each chain or the Cα's B-factor (:class:`~app.editor.scene.molecule.Colouring`)."""
        self.colouring = Colouring(colouring)
        if self.document.editable:
            self._recolour()
            self.plotter.render()

    def set_fat_helices(self, on: bool) -> None:
        """Tube radius by secondary structure (sheet > helix > other) or uniform."""
        self.fat_helices = on
        self._reshape()

    def set_helix_cylinders(self, on: bool) -> None:
        """Helices of the cartoon as cylinders along their axes (Carson's Fig. 5), or spiral ribbons."""
        self.helix_cylinders = on
        self._reshape()

    def _reshape(self) -> None:
        """The ribbons' sections follow the options (:meth:`SceneLayer.reshape`)."""
        if self.document.editable:
            for layer in self._drawn:
                layer.reshape()
            self.plotter.render()

    def set_others(self, others: Others | str) -> None:
        """Show, dim or hide the chains other than the edited segment's."""
        self.others = Others(others)
        if self.document.editable:
            self._draw_others()
            self.plotter.render()

    def set_slab(self, slab: tuple[float, float] | None) -> None:
        """Clip the view to a slab about its centre (see :attr:`slab`; each plane at least
        :data:`MIN_SLAB` Å from the centre), or not."""
        self.slab = None if slab is None else (max(float(slab[0]), MIN_SLAB), max(float(slab[1]), MIN_SLAB))
        if slab is None:
            self.plotter.renderer.ResetCameraClippingRange()  # everything, as before
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

    # ------------------------------------------------------------------ camera

    def reset_camera(self) -> None:
        """Look at the structure (its Cα, or all atoms without a backbone) along its axis of
        least extent (the widest view of the fold)."""
        coords = self.document.model.coords
        ca = coords[self.document.ca_rows] if len(self.document.ca_rows) else coords
        centre = ca.mean(axis=0)
        least, middle, _ = principal_directions(((ca - centre).T @ (ca - centre)).tolist())  # as the sketch
        renderer = self.plotter.renderer
        renderer.camera_position = [tuple(centre + np.array(least) * 100.0), tuple(centre), middle]
        renderer.camera.SetViewAngle(VIEW_ANGLE)  # (a zoom that narrowed it compounded with every reset)
        renderer.reset_camera(render=False)
        renderer.camera.Dolly(FIT_CLOSER)  # (where the camera is says it all: sessions keep it)
        renderer.ResetCameraClippingRange()

    def frame_segment(self) -> None:
        """Centre the view on the edited segment and fit it in, looking from where the camera is
        (when the segment is chosen in the *Ribbon dimension* dock; a click on another chain
        leaves the camera where it is)."""
        structure = self.document.structure
        ca = self.document.model.coords[self.document.ca_rows[structure.segments[self.document.segment].residue_index]]
        low, high = ca.min(axis=0) - 2.0, ca.max(axis=0) + 2.0
        self.plotter.renderer.ResetCamera(low[0], high[0], low[1], high[1], low[2], high[2])

    def zoom_to(self, reach: float, share: float = 1.0 / 3.0) -> None:
        """Bring the camera closer to the centre of the view until ``reach`` Å around it fills
        ``share`` of the view's height (never further away)."""
        camera = self.plotter.renderer.GetActiveCamera()
        wanted = reach / share / np.tan(np.radians(camera.GetViewAngle()) / 2.0)
        if wanted < camera.GetDistance():  # the camera moves along its direction; the focal point stays
            focal = np.array(camera.GetFocalPoint())
            camera.SetPosition(*(focal - wanted * np.array(camera.GetDirectionOfProjection())))
            self.plotter.renderer.ResetCameraClippingRange()

    def centre_on(self, point: np.ndarray) -> None:
        """Turn the view about ``point`` (Å) from now on and bring it to the centre of the view:
        the camera keeps its direction and distance."""
        camera = self.plotter.renderer.GetActiveCamera()
        point = np.asarray(point, dtype=float)
        camera.SetPosition(*(np.array(camera.GetPosition()) + point - camera.GetFocalPoint()))
        camera.SetFocalPoint(*point)
        self.plotter.renderer.ResetCameraClippingRange()

    # ------------------------------------------------------------------ what is drawn

    def shown_atoms(self) -> np.ndarray:
        """Rows of the coordinates of the atoms drawn now (polymer atoms, ligands, ions)."""
        rows = [layer.atom_rows() for layer in self._drawn if layer.visible]
        return np.concatenate([np.empty(0, dtype=np.int64), *rows])

    def shown_control_points(self) -> np.ndarray:
        """Indices (into the level curve's control points) of the spheres on screen."""
        if self._control_points not in self._drawn:
            return np.empty(0, dtype=np.int64)
        return self._control_points.shown

    @property
    def point_radius(self) -> float:
        """Radius of the control-point spheres, Å."""
        return self._control_points.radius

    def part(self, kind: type[L]) -> L:
        """The layer of class ``kind``."""
        return next(layer for layer in self.parts if isinstance(layer, kind))

    def add_layer(self, layer: SceneLayer) -> None:
        """Draw ``layer`` too, after the others (a layer that draws more than the document, such
        as the validation markers, adds itself)."""
        self.parts.append(layer)
        if self.document.model is not None and (self.document.editable or not layer.needs_backbone):
            self._drawn.append(layer)
            layer.build()
            layer.show(layer.visible)

    def edited_chain(self) -> str:
        """The edited segment's chain."""
        return self.document.structure.segments[self.document.segment].chain

    def residue_colours(self) -> np.ndarray:
        """Every residue's colour in the scheme, the other chains' faded when they are dimmed."""
        colours = molecule.residue_colours(self.document.structure, self.colouring)
        if self.others is Others.DIMMED:
            colours = faded(colours, self.chains.residue_chain != self.edited_chain())
        return colours

    # ------------------------------------------------------------------ the document's signals

    def _build(self) -> None:
        editable = self.document.editable
        self.plotter.clear_actors()
        self.meshes.clear()
        self.actors.clear()
        self.others = Others.SHOWN
        kept = self.document.kept_view  # another model of the file: the same camera and slab
        self.slab = self.slab if kept else None
        self._concealed = False
        self.still(render=False)
        if editable:
            self.chains = Chains(self.document.structure)
            if self.chains.count > DIM_ABOVE_CHAINS:
                self.others = Others.DIMMED
        self._drawn = []
        self._unbuilt = [layer for layer in self.parts if editable or not layer.needs_backbone]
        self._show_layers()
        self._update_caption()
        if self.others is not Others.SHOWN:
            self._draw_others()
        if not kept:
            self.reset_camera()
        self.plotter.render()

    def _on_change(self, change: Change) -> None:
        for layer in self._drawn:
            layer.update(change)
        if self.chains.segment_chain[change.segment] != self.edited_chain():  # an undo in a hidden chain
            self._conceal()
        self.plotter.render()

    def _on_level(self) -> None:
        for layer in self._drawn:
            layer.level_changed()
        self._update_caption()
        self.plotter.render()

    def _on_segment(self) -> None:
        self.still(render=False)
        for layer in self._drawn:
            layer.segment_changed()
        if self.others is not Others.SHOWN:
            self._draw_others()
        self._on_level()  # (the camera stays: it moves only when asked, see frame_segment)

    def _on_pick(self) -> None:
        for layer in self._drawn:
            layer.picked()
        self.plotter.render()

    def _on_selection(self) -> None:
        for layer in self._drawn:
            layer.selection_changed()
        self.plotter.render()

    # ------------------------------------------------------------------ shared by the layers

    def _recolour(self) -> None:
        colours = self.residue_colours()
        for layer in self._drawn:
            layer.recolour(colours)

    def _draw_others(self) -> None:
        """Colours and positions of every chain as :attr:`others` says (after a change of it
        or of the edited chain)."""
        self._recolour()
        if self._concealed:
            for layer in self._drawn:
                layer.restore()
            self._concealed = False
        self._conceal()

    def _conceal(self) -> None:
        """With :attr:`others` hidden, collapse the other chains' vertices onto one point per
        chain and mesh: their faces and lines then cover no pixel."""
        if self.others is not Others.HIDDEN:
            return
        self._concealed = True
        chain = self.edited_chain()
        for layer in self._drawn:
            layer.conceal(chain)

    def _show_layers(self) -> None:
        """Show the layers switched on (built first if they never were), hide the others."""
        new = [layer for layer in self._unbuilt if layer.visible]
        for layer in new:
            self._unbuilt.remove(layer)
            layer.build()
            if self._concealed:
                layer.conceal(self.edited_chain())
        if new:
            self._drawn = [layer for layer in self.parts if layer in self._drawn or layer in new]
        for layer in self._drawn:
            layer.show(layer.visible)

    def _set_detail(self) -> None:
        full = not self.moving
        self.plotter.renderer.SetUseFXAA(full)
        for layer in self._drawn:
            layer.set_detail(full)

    def _before_frame(self) -> None:
        if self.slab is not None:  # (after the camera style's own reset of the clipping range)
            camera = self.plotter.renderer.GetActiveCamera()
            distance = camera.GetDistance()
            camera.SetClippingRange(max(distance - self.slab[0], 0.01 * distance), distance + self.slab[1])
        for layer in self._drawn:
            layer.before_frame()

    def _update_caption(self) -> None:
        document = self.document
        text = document.read_only_reason or (
            f"{document.structure.entry_id}   {document.structure.segments[document.segment].summary}\n"
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
