"""The density map drawn as Coot and PyMOL draw maps: a contour mesh (the edges of the
marching-cubes triangles) within a radius of the view's centre, at a level in σ; an MTZ's
difference map beside it at ±3σ, green and red.

:class:`MapMesh` owns the open map. It contours only the block of the map around the
camera's focal point (:meth:`core.surfaces.volume.DensityMap.contour_around`), and checks at
every frame whether the focal point moved (centring on a residue, panning): then it contours
again, at most every :data:`RECONTOUR_MS`, between frames. Asked for the whole map, it
contours the whole box once (a crystal's map: the box around the model).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject, Qt, QTimer, Signal

from app.editor.document import Document
from app.polydata import to_polydata

if TYPE_CHECKING:
    from core.surfaces.mesh import TriangleMesh
    from core.surfaces.volume import DensityMap

DEFAULT_SIGMA = 1.0
"""Contour level, in rms deviations (σ) above the map's mean."""
DEFAULT_RADIUS = 15.0
"""Å around the view's centre (a 30 Å box)."""
DEFAULT_COLOUR = (40, 90, 235)
"""The blue of a 2mFo–DFc map in Coot."""
RECONTOUR_MS = 100
"""Shortest time between two contours while the centre moves."""
DIFFERENCE_SIGMA = 3.0
"""The difference map's contours, in its rms deviations: +3σ and −3σ."""
DIFFERENCE_COLOURS = ((0, 200, 0), (220, 30, 30))
"""Coot's green (atoms missing from the model) and red (atoms the map does not hold)."""
WHOLE_MARGIN = 5.0
"""Å around the model that the whole of a crystal's (periodic) map is drawn."""
ACTOR = "density_map"
DIFFERENCE_ACTORS = ("difference_map_positive", "difference_map_negative")


class MapMesh(QObject):
    """The open map, contoured around the view's centre into ``plotter``."""

    changed = Signal()
    """A map was opened or closed, or its contour, radius or colour changed."""
    opened = Signal()
    """Another map was opened."""
    contoured = Signal()
    """The mesh was contoured again (around :attr:`centre`)."""

    def __init__(self, document: Document, plotter: pv.BasePlotter) -> None:
        super().__init__(document)
        self.plotter = plotter
        self.document = document
        self.density: DensityMap | None = None
        self.difference: DensityMap | None = None
        """An MTZ's mFo−DFc map, else None."""
        self.columns: tuple[tuple[str, str], tuple[str, str] | None] | None = None
        """An MTZ's columns of :attr:`density` and :attr:`difference`, else None."""
        self.path: Path | None = None
        self.whole = False
        """Whether the whole map is drawn (else within :attr:`radius` of the view's centre)."""
        self.sigma = DEFAULT_SIGMA
        self.radius = DEFAULT_RADIUS
        self.colour = DEFAULT_COLOUR
        self.centre: np.ndarray | None = None
        """Where the mesh was last contoured around (Å)."""
        self.mesh = pv.PolyData()
        self.actor: pv.Actor | None = None
        self.difference_meshes = (pv.PolyData(), pv.PolyData())
        self.difference_actors: list[pv.Actor | None] = [None, None]
        self._last = -np.inf  # time.perf_counter() of the last contour
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.timeout.connect(self.contour)
        document.loaded.connect(self._reload)
        plotter.ren_win.AddObserver("StartEvent", lambda *_: self._frame())

    @property
    def value(self) -> float:
        """The contour level in the map's units."""
        return self.density.sigma_level(self.sigma)

    def open(self, path: Path, columns: tuple[str, str] | None = None) -> None:
        """Read the CCP4/MRC map at ``path`` (optionally gzipped), or the maps of an MTZ file
        (of ``columns``, amplitude and phase, or those Coot would take), and draw them instead
        of those open. Raises :class:`core.surfaces.volume.MapError`."""
        # The map code (scikit-image, PyWavelets) loads with the first map.
        from core.surfaces.map_coefficients import is_mtz, read_mtz
        from core.surfaces.map_file import read_map

        if Path(path).is_file() and is_mtz(path):
            maps = read_mtz(path, columns)
            density, difference, self.columns = maps.density, maps.difference, (maps.columns, maps.difference_columns)
        else:
            density, difference, self.columns = read_map(path), None, None
        self.density, self.difference, self.path = density, difference, Path(path)
        self.contour()
        self.opened.emit()
        self.changed.emit()

    def close(self) -> None:
        """Show no map."""
        self.density = self.difference = self.columns = self.path = self.centre = None
        for mesh in (self.mesh, *self.difference_meshes):
            mesh.shallow_copy(pv.PolyData())
        self.plotter.render()
        self.changed.emit()

    def set_whole(self, whole: bool) -> None:
        """Draw the whole map (``True``) or the map around the view's centre."""
        self.whole = bool(whole)
        self._redraw()

    def set_sigma(self, sigma: float) -> None:
        """Contour at ``sigma`` rms deviations above the mean."""
        self.sigma = float(sigma)
        self._redraw()

    def set_radius(self, radius: float) -> None:
        """Draw the map within ``radius`` Å of the view's centre."""
        self.radius = float(radius)
        self._redraw()

    def set_colour(self, colour: tuple[int, int, int]) -> None:
        self.colour = tuple(int(c) for c in colour)
        if self.actor is not None:
            self.actor.prop.color = self.colour
            self.plotter.render()
        self.changed.emit()

    def contour(self) -> None:
        """Contour the map again around the camera's focal point."""
        self._timer.stop()
        if self.density is None:
            return
        self._last = time.perf_counter()
        self.centre = self._focal_point()
        self.mesh.shallow_copy(to_polydata(self._contour(self.density, self.value)))
        if self.difference is not None:
            mean, sigma = self.difference.moments
            for mesh, sign in zip(self.difference_meshes, (1.0, -1.0)):
                mesh.shallow_copy(to_polydata(self._contour(self.difference, mean + sign * DIFFERENCE_SIGMA * sigma)))
        else:
            for mesh in self.difference_meshes:
                mesh.shallow_copy(pv.PolyData())
        self._add_actors()
        self.plotter.render()
        self.contoured.emit()

    def _contour(self, density: DensityMap, value: float) -> TriangleMesh:
        """``density``'s contour at ``value``: around the view's centre, or the whole of it
        (a crystal's map: the box around the model), as the sphere that holds it."""
        if not self.whole:
            return density.contour_around(value, self.centre, self.radius)
        if density.periodic:  # around the model
            held = self.document.model.coords if self.document.editable else np.zeros((1, 3))
            margin = WHOLE_MARGIN
        else:  # the box's corners
            corners = np.array(list(np.ndindex(2, 2, 2))) * (np.array(density.values.shape) - 1)
            held, margin = density.origin + corners @ density.axes, 0.0
        low, high = held.min(axis=0), held.max(axis=0)
        return density.contour_around(value, (low + high) / 2.0, np.linalg.norm(high - low) / 2.0 + margin)

    def _redraw(self) -> None:
        self.contour()
        self.changed.emit()

    def _focal_point(self) -> np.ndarray:
        return np.array(self.plotter.renderer.GetActiveCamera().GetFocalPoint())

    def _frame(self) -> None:
        """A frame is drawn: contour again soon where the centre moved."""
        if (self.density is None or self.whole or self._timer.isActive()
                or np.array_equal(self._focal_point(), self.centre)):
            return
        wait = RECONTOUR_MS - 1000.0 * (time.perf_counter() - self._last)
        self._timer.start(int(np.ceil(max(0.0, wait))) + 2)  # Qt's timers may fire a millisecond or two early

    def _reload(self) -> None:
        """A new structure: the scene removed every actor."""
        self.actor = None
        self.difference_actors = [None, None]
        self._add_actors()

    def _add_actors(self) -> None:
        """Actors for the meshes that have none yet and have points (pyvista draws no empty mesh)."""
        if self.actor is None and self.mesh.n_points:
            self.actor = self._add(self.mesh, ACTOR, self.colour)
        for k, (mesh, name, colour) in enumerate(zip(self.difference_meshes, DIFFERENCE_ACTORS, DIFFERENCE_COLOURS)):
            if self.difference_actors[k] is None and mesh.n_points:
                self.difference_actors[k] = self._add(mesh, name, colour)

    def _add(self, mesh: pv.PolyData, name: str, colour: tuple[int, int, int]) -> pv.Actor:
        return self.plotter.add_mesh(mesh, name=name, style="wireframe", color=colour, line_width=1.0, lighting=False,
                                     pickable=False, reset_camera=False, render=False)
