"""What a layer of the scene is: the hooks the :class:`~app.editor.scene.scene.Scene` calls on each
of its layers, and what a layer may use of the scene (:class:`Stage`).

A layer draws one representation of the document (the tube, the level curve, the atoms, ...)
as named pyvista meshes in the scene's plotter: built once per structure, then rewritten in
place in their VTK arrays. The scene calls the same hook on every layer, in the order of its
list, and renders once per event; a layer renders only what changes outside the scene's events
(the validation markers after a deferred check), and never changes the document.
"""

from __future__ import annotations

from enum import StrEnum
from typing import TYPE_CHECKING, ClassVar, Protocol

import numpy as np
import pyvista as pv

from app.editor.scene.layers.meshes import Rows, write

if TYPE_CHECKING:
    from pyvista.plotting.plotter import BasePlotter

    from app.editor.document import Change, Document
    from app.editor.scene.layers.chains import Chains, Others
    from app.editor.scene.molecule import Colouring


SHINY = {"interpolation": "phong", "specular": 0.4, "specular_power": 25.0}
"""The look of the glyph spheres (Cα, ligand atoms, ions, the selection)."""


class Layer(StrEnum):
    """What can be shown, each switchable on its own."""

    CARTOON = "cartoon"
    TUBE = "ribbon tube"
    CURVE = "level curve"
    CONTROL_POINTS = "control points"
    CA_TRACE = "Cα trace"
    ATOMS = "atoms"
    NUCLEIC = "nucleic acids"
    MODELS = "other models"
    LIGANDS = "ligands"
    IONS = "ions"
    WATERS = "waters"
    VALIDATION = "validation markers"
    MEASUREMENTS = "measurements"


class Stage(Protocol):
    """The scene as its layers see it: what they draw and with which options."""

    @property
    def document(self) -> Document: ...
    @property
    def plotter(self) -> BasePlotter: ...
    @property
    def meshes(self) -> dict[str, pv.PolyData]:
        """Every layer's meshes by name (the plotter's actor names)."""
    @property
    def actors(self) -> dict[str, pv.Actor]: ...
    @property
    def layers(self) -> set[Layer]:
        """The layers switched on."""
    @property
    def colouring(self) -> Colouring: ...
    @property
    def fat_helices(self) -> bool: ...
    @property
    def helix_cylinders(self) -> bool: ...
    @property
    def others(self) -> Others: ...
    @property
    def chains(self) -> Chains: ...
    @property
    def slab(self) -> tuple[float, float] | None:
        """The clipping slab (Å in front of and behind the centre of the view), or None."""
    @property
    def moving(self) -> bool:
        """Whether something moves (the view is drawn with less detail)."""

    def edited_chain(self) -> str:
        """The edited segment's chain."""

    def residue_colours(self) -> np.ndarray:
        """(n_residues, 3) uint8, every residue's colour in the scheme, the other chains' faded when dimmed."""


class SceneLayer:
    """One representation of the document in the scene. Every hook does nothing unless a layer
    says otherwise; the scene calls them only on the layers it has built."""

    switch: ClassVar[Layer | None] = None
    """The :class:`Layer` that shows and hides it (None: shown whenever it has something to show)."""
    needs_backbone: ClassVar[bool] = True
    """Drawn only for a structure that can be edited (one with a backbone)."""
    names: ClassVar[tuple[str, ...]] = ()
    """Its meshes (and actors): :meth:`show` shows and hides these."""
    lines_as_tubes: ClassVar[tuple[str, ...]] = ()
    """Its meshes of lines that are shaded tubes at rest and plain lines while something moves."""

    def __init__(self, scene: Stage) -> None:
        self.scene = scene
        self.document = scene.document
        self.meshes = scene.meshes
        self.actors = scene.actors

    @property
    def visible(self) -> bool:
        """Whether its switch is on."""
        return self.switch is None or self.switch in self.scene.layers

    def build(self) -> None:
        """Make its meshes and actors for a new structure (the plotter and the scene's meshes were cleared)."""

    def update(self, change: Change) -> None:
        """Follow an edit, or its undo, that moved ``change``'s residues and atoms."""

    def level_changed(self) -> None:
        """Follow the level slider (also after a change of the edited segment)."""

    def segment_changed(self) -> None:
        """The edited segment is another one (the level follows with :meth:`level_changed`)."""

    def picked(self) -> None:
        """The picked control point changed."""

    def selection_changed(self) -> None:
        """The selected residues changed."""

    def recolour(self, residue_colours: np.ndarray) -> None:
        """The colouring or the dimming of the other chains changed; ``residue_colours`` is
        :meth:`Stage.residue_colours`."""

    def reshape(self) -> None:
        """The ribbons' sections changed (fat helices or not, helices as cylinders or not)."""

    def conceal(self, chain: str) -> None:
        """Collapse the vertices of the chains other than ``chain`` onto one point each (other chains hidden)."""

    def restore(self) -> None:
        """Put every vertex back where the model has it (after :meth:`conceal`)."""

    def set_detail(self, full: bool) -> None:
        """Draw in ``full`` detail (at rest) or with less (while something moves): lines of
        :attr:`lines_as_tubes` are plain lines while something moves."""
        for name in self.lines_as_tubes:
            if name in self.actors:
                self.actors[name].prop.render_lines_as_tubes = full

    def show(self, visible: bool) -> None:
        """Show or hide its actors."""
        for name in self.names:
            if name in self.actors:
                self.actors[name].SetVisibility(visible)

    def before_frame(self) -> None:
        """Called before each frame is drawn (cheap unless something must change)."""

    def atom_rows(self) -> np.ndarray:
        """Rows of the coordinates of the atoms it draws (none unless it draws atoms)."""
        return np.empty(0, dtype=np.int64)

    def add(self, name: str, **style: object) -> None:
        """Add mesh ``name`` to the plotter as actor ``name`` (not when it is empty: nothing to draw)."""
        if self.meshes[name].n_points == 0:  # e.g. no ions
            return
        self.actors[name] = self.scene.plotter.add_mesh(
            self.meshes[name], name=name, reset_camera=False, pickable=False, show_scalar_bar=False,
            smooth_shading=False, render=False, **style)

    def write(self, name: str, where: Rows, values: np.ndarray, array: str | None = None) -> None:
        """Overwrite rows ``where`` of the points (or of point array ``array``) of mesh ``name`` in place."""
        write(self.meshes[name], where, values, array)
