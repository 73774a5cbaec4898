"""Surfaces of the document's atoms: a globe, DNA cylinder, molecular surface, remeshed
surface or density contour, shown with the ribbon at any of its levels.

A :class:`SurfaceLayer` builds surfaces in a process of their own
(:class:`~app.editor.surfaces.build.SurfaceBuild`: as fast as on the command line, and never
holding up the view), one at a time: the build of the kind chosen for the open structure.
Choosing another kind, opening another file or closing the window kills the running build at
once. The build's stages ("molecular surface (distance transform)") show in the panel as they
start. Surfaces are cached per kind for the open structure, so moving the level slider or
changing the colouring only asks the cached :class:`~core.surfaces.levelled.LevelledSurface`
for another view. A view with the same triangles as the one on screen is written into the
existing VTK arrays; any other goes under the same actor. Surfaces are computed from the
atoms: after an edit the surface is stale until it is recomputed (or the edit undone). The
:class:`~app.editor.docks.surfaces.SurfacePanel` dock only reads the layer and calls its
mutators. The surface code (scikit-image, PyWavelets, ...) loads in the build's process, not
with the editor.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject, QSocketNotifier, Signal
from vtkmodules.util.numpy_support import vtk_to_numpy

from app.editor.document import Document
from app.editor.surfaces.build import SurfaceBuild, start_server
from app.polydata import scalar_style, to_polydata
from core.geometry.vectors import summed_rows
from core.surfaces.mesh import TriangleMesh

if TYPE_CHECKING:
    from core.surfaces.levelled import LevelledSurface

KIND_NAMES = {"globe": "Globe", "dna": "DNA cylinder", "ses": "Molecular surface (SES)",
              "remesh": "Remeshed surface", "map": "Density map (from the model)"}
SURFACE_COLOUR = (176, 196, 222)
DEFAULT_OPACITY = 0.6
SCALARS = "values"


@dataclasses.dataclass(frozen=True, eq=False)
class Built:
    """A surface and the atom coordinates (n_atoms, 3), Å, it was built from."""

    surface: LevelledSurface
    coords: np.ndarray


@dataclasses.dataclass(eq=False)
class _Running:
    """The build under way, the notifier of its pipe, the coordinates it builds from and its stage."""

    build: SurfaceBuild
    notifier: QSocketNotifier
    coords: np.ndarray
    stage: str = "starting"


class SurfaceLayer(QObject):
    """Builds, caches and draws the surfaces of a document's atoms into ``plotter``."""

    updated = Signal()
    """Anything shown about the surface changed: built, drawn, busy (or its stage), stale or failed."""

    def __init__(self, document: Document, plotter: pv.BasePlotter) -> None:
        super().__init__(document)
        self.document = document
        self.plotter = plotter
        self.visible = False
        self.kind = "globe"
        self.level: float | None = None
        """Requested level (None: the finest); views clip it to the surface's levels."""
        self.colouring: str | None = None
        self.opacity = DEFAULT_OPACITY
        self.message = ""
        """Why the current kind could not be built or coloured ('' when nothing failed)."""
        self.mesh: pv.PolyData | None = None
        self.actor: pv.Actor | None = None
        self._drawn: tuple[LevelledSurface, str | None] | None = None
        self._faces = np.empty((0, 3), dtype=np.int64)
        self._cache: dict[str, Built] = {}
        self._failed: dict[str, str] = {}
        self._running: _Running | None = None
        self._structure = document.structure if document.model is not None else None
        self._stale = False
        start_server()
        document.loaded.connect(self._on_loaded)
        document.changed.connect(self._on_changed)

    # ------------------------------------------------------------------ state

    @property
    def built(self) -> Built | None:
        """The cached surface of the current kind, if built."""
        return self._cache.get(self.kind)

    @property
    def busy(self) -> bool:
        """Whether the current kind is being built."""
        return self._running is not None and self._running.build.kind == self.kind

    @property
    def stage(self) -> str:
        """The stage of the build of the current kind ('' when none runs)."""
        return self._running.stage if self.busy else ""

    @property
    def stale(self) -> bool:
        """Whether the atoms moved since the current kind was built."""
        return self._stale

    def shown_level(self) -> float:
        """The level of the current surface that is (or would be) shown."""
        surface = self.built.surface
        level = surface.max_level if self.level is None else min(self.level, surface.max_level)
        return level if surface.fractional else float(round(level))

    # ------------------------------------------------------------------ mutators

    def set_visible(self, on: bool) -> None:
        """Show the surface of the current kind (building it first when needed) or hide it."""
        self.visible = on
        self._update()

    def set_kind(self, kind: str) -> None:
        if kind not in KIND_NAMES:
            raise ValueError(f"kind must be one of {', '.join(KIND_NAMES)}; got {kind!r}")
        self.kind = kind
        self._update()

    def set_level(self, level: float | None) -> None:
        """Show ``level`` of the surface (None: the finest)."""
        self.level = level
        self._update()

    def set_colouring(self, colouring: str | None) -> None:
        """Colour by 'potential', 'curvature', 'bfactor' or one colour (None)."""
        self.colouring = colouring
        self._update()

    def set_opacity(self, opacity: float) -> None:
        self.opacity = float(np.clip(opacity, 0.0, 1.0))
        if self.actor is not None:
            self.actor.prop.opacity = self.opacity
            self.plotter.render()

    def recompute(self) -> None:
        """Build the current kind again from the atoms as they are now."""
        self._cache.pop(self.kind, None)
        self._failed.pop(self.kind, None)
        self._update()

    def shutdown(self) -> None:
        """Stop the running build at once (call before the plotter closes)."""
        self._stop()

    # ------------------------------------------------------------------ internals

    def _update(self) -> None:
        """Draw what the state asks for, starting a build when the surface is missing."""
        self.message = self._failed.get(self.kind, "")
        built = self.built
        if self._running is not None and not self.busy:
            self._stop()  # of a kind no longer chosen
        if self.visible and built is None and not self.busy and not self.message and self.document.model is not None:
            self._start()
        if self.visible and built is not None:
            self._draw(built.surface)
            self.plotter.render()
        elif self.actor is not None and self.actor.GetVisibility():
            self.actor.SetVisibility(False)
            self.plotter.render()  # only when the view changed: a frame takes 0.1-0.3 s with software OpenGL
        self._stale = built is not None and not np.array_equal(built.coords, self.document.model.coords)
        self.updated.emit()

    def _start(self) -> None:
        coords = self.document.model.coords.copy()
        build = SurfaceBuild(self.kind, dataclasses.replace(self.document.structure.atoms, coords=coords))
        notifier = QSocketNotifier(build.fileno(), QSocketNotifier.Type.Read, self)
        notifier.activated.connect(lambda: self._receive(build))
        self._running = _Running(build, notifier, coords)

    def _receive(self, build: SurfaceBuild) -> None:
        """A message from the build: a stage, or the end."""
        running = self._running
        if running is None or running.build is not build:
            return  # stopped while the message was on its way
        message = build.receive()
        if isinstance(message, str):
            running.stage = message
            self.updated.emit()
            return
        self._stop()
        if isinstance(message, Exception):
            self._failed[build.kind] = f"{KIND_NAMES[build.kind]}: {message}"
        else:
            self._cache[build.kind] = Built(message, running.coords)
        self._update()

    def _stop(self) -> None:
        """Kill the running build, if any."""
        if self._running is not None:
            self._running.notifier.setEnabled(False)
            self._running.notifier.deleteLater()
            self._running.build.close()
            self._running = None

    def _draw(self, surface: LevelledSurface) -> None:
        for colouring in dict.fromkeys((self.colouring, None)):  # plain when the colouring fails
            try:
                mesh, scalars = surface.view(self.shown_level(), colouring)
                break
            except ValueError as error:  # e.g. a map has no curvature
                self.message = self.message or str(error)
        else:
            if self.actor is not None:
                self.actor.SetVisibility(False)
            return
        polydata = to_polydata(mesh, scalars, SCALARS)
        polydata.point_data["Normals"] = _vertex_normals(mesh)
        polydata.point_data.active_normals_name = "Normals"
        same_faces = self.mesh is not None and self._drawn == (surface, colouring) and \
            np.array_equal(self._faces, mesh.faces)
        if same_faces:  # another level of a spline net: new vertex values in the existing arrays
            for name in ("Normals", SCALARS) if scalars is not None else ("Normals",):
                _assign(self.mesh.GetPointData().GetArray(name), polydata.point_data[name])
            _assign(self.mesh.GetPoints().GetData(), polydata.points)
            self.mesh.Modified()
        elif self.mesh is not None and self._drawn is not None and self._drawn[1] == colouring:
            self.mesh.shallow_copy(polydata)  # other triangles under the same actor
        else:
            self.mesh = polydata
            style = {"color": SURFACE_COLOUR} if scalars is None else {"scalars": SCALARS}
            self.actor = self.plotter.add_mesh(self.mesh, name="surface", reset_camera=False, pickable=False,
                                               show_scalar_bar=False, smooth_shading=False, render=False,
                                               interpolation="phong", specular=0.3, specular_power=20.0, **style)
        if scalars is not None:
            cmap, clim = scalar_style(colouring, scalars)
            self.actor.mapper.lookup_table.cmap = cmap
            self.actor.mapper.scalar_range = clim
        self.actor.prop.opacity = self.opacity
        self.actor.SetVisibility(True)
        self._drawn, self._faces = (surface, colouring), mesh.faces

    def _on_loaded(self) -> None:
        """A new structure, or a new ribbon kind: the scene removed every actor."""
        self.mesh = self.actor = self._drawn = None
        if self.document.structure is not self._structure:
            self._structure = self.document.structure
            self._stop()
            self._cache.clear()
            self._failed.clear()
        if self.visible:
            self._update()

    def _on_changed(self, _change: object) -> None:
        built = self.built
        stale = built is not None and not np.array_equal(built.coords, self.document.model.coords)
        if stale != self._stale:
            self._stale = stale
            self.updated.emit()


def _vertex_normals(mesh: TriangleMesh) -> np.ndarray:
    """(n_vertices, 3) unit normals: the area-weighted mean of the adjacent face normals."""
    a, b, c = (mesh.vertices[mesh.faces[:, k]] for k in range(3))
    weighted = np.repeat(np.cross(b - a, c - a), 3, axis=0)
    normals = summed_rows(mesh.faces.ravel(), weighted, len(mesh.vertices))
    norm = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, norm, out=np.zeros_like(normals), where=norm > 0)


def _assign(target: object, values: np.ndarray) -> None:
    """Overwrite a VTK data array with ``values`` of the same shape, in place."""
    vtk_to_numpy(target)[:] = values
    target.Modified()  # type: ignore[attr-defined]
