"""The density map drawn as Coot and PyMOL draw maps: a contour mesh (the edges of the
marching-cubes triangles) within a radius of the view's centre, at a level in σ.

:class:`MapMesh` owns the open map. It contours only the block of the map around the
camera's focal point (:meth:`core.surfaces.volume.DensityMap.contour_around`), and checks at
every frame whether the focal point moved (centring on a residue, panning): then it contours
again, at most every :data:`RECONTOUR_MS`, between frames.
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
    from core.surfaces.volume import DensityMap

DEFAULT_SIGMA = 1.0
"""Contour level, in rms deviations (σ) above the map's mean."""
DEFAULT_RADIUS = 15.0
"""Å around the view's centre (a 30 Å box)."""
DEFAULT_COLOUR = (40, 90, 235)
"""The blue of a 2mFo–DFc map in Coot."""
RECONTOUR_MS = 100
"""Shortest time between two contours while the centre moves."""
ACTOR = "density_map"


class MapMesh(QObject):
    """The open map, contoured around the view's centre into ``plotter``."""

    changed = Signal()
    """A map was opened or closed, or its contour, radius or colour changed."""
    contoured = Signal()
    """The mesh was contoured again (around :attr:`centre`)."""

    def __init__(self, document: Document, plotter: pv.BasePlotter) -> None:
        super().__init__(document)
        self.plotter = plotter
        self.density: DensityMap | None = None
        self.path: Path | None = None
        self.sigma = DEFAULT_SIGMA
        self.radius = DEFAULT_RADIUS
        self.colour = DEFAULT_COLOUR
        self.centre: np.ndarray | None = None
        """Where the mesh was last contoured around (Å)."""
        self.mesh = pv.PolyData()
        self.actor: pv.Actor | None = None
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

    def open(self, path: Path) -> None:
        """Read the CCP4/MRC map at ``path`` (optionally gzipped; raises
        :class:`core.surfaces.volume.MapError`) and draw it instead of the one open."""
        from core.surfaces.map_file import (
            read_map,  # the map code (scikit-image, PyWavelets) loads with the first map
        )

        self.density, self.path = read_map(path), Path(path)
        self.contour()
        self.changed.emit()

    def close(self) -> None:
        """Show no map."""
        self.density = self.path = self.centre = None
        self.mesh.shallow_copy(pv.PolyData())
        self.plotter.render()
        self.changed.emit()

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
        self.mesh.shallow_copy(to_polydata(self.density.contour_around(self.value, self.centre, self.radius)))
        if self.actor is None and self.mesh.n_points:  # (pyvista draws no empty mesh)
            self._add_actor()
        self.plotter.render()
        self.contoured.emit()

    def _redraw(self) -> None:
        self.contour()
        self.changed.emit()

    def _focal_point(self) -> np.ndarray:
        return np.array(self.plotter.renderer.GetActiveCamera().GetFocalPoint())

    def _frame(self) -> None:
        """A frame is drawn: contour again soon where the centre moved."""
        if self.density is None or self._timer.isActive() or np.array_equal(self._focal_point(), self.centre):
            return
        wait = RECONTOUR_MS - 1000.0 * (time.perf_counter() - self._last)
        self._timer.start(int(np.ceil(max(0.0, wait))) + 2)  # Qt's timers may fire a millisecond or two early

    def _reload(self) -> None:
        """A new structure: the scene removed every actor."""
        self.actor = None
        if self.mesh.n_points:
            self._add_actor()

    def _add_actor(self) -> None:
        self.actor = self.plotter.add_mesh(self.mesh, name=ACTOR, style="wireframe", color=self.colour,
                                           line_width=1.0, lighting=False, pickable=False, reset_camera=False,
                                           render=False)
