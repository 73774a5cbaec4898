"""Markers on the model at the bad peptide junctions and the clashes, coloured by severity.

A layer of the scene (:attr:`~app.editor.scene.layers.base.Layer.VALIDATION`) that adds itself
to it, since it draws the live report, which the scene does not know. One actor of its own
(``validation_markers``): a point set drawn as spheres, one point per junction or clash flag that the live
report's triage filter shows (:attr:`~app.editor.live_validation.LiveValidation.triaged`),
rewritten in place when the report or the filter changes. Ramachandran outliers are listed
in the validation panel but not marked (a residue, not a place between atoms).
"""

from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy

from app.editor.live_validation import LiveValidation
from app.editor.scene.layers.base import Layer, SceneLayer
from app.editor.scene.scene import Scene
from core.geometry.validation import Flag

NAME = "validation_markers"
MARKED = ("peptide_bond", "ca_ca", "angle_ca_c_n", "angle_c_n_ca", "omega", "clash")
"""Flag kinds that get a marker."""
MARKER_PIXELS = 10.0
"""Marker diameter on screen, pixels."""
MILD, SEVERE = np.array([250, 205, 40]), np.array([215, 25, 28])
"""Colours of a flag just over its tolerance (severity 1) and of one at :data:`SEVERE_AT` or more."""
SEVERE_AT = 4.0


def severity_colours(severity: np.ndarray) -> np.ndarray:
    """(n, 3) uint8 colours from yellow (severity 1) to red (severity >= :data:`SEVERE_AT`)."""
    t = np.clip((np.asarray(severity, dtype=float) - 1.0) / (SEVERE_AT - 1.0), 0.0, 1.0)[:, None]
    return np.rint((1.0 - t) * MILD + t * SEVERE).astype(np.uint8)


def marked(flags: tuple[Flag, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Positions (n, 3), Å, and severities (n,) of the flags that get a marker."""
    chosen = [f for f in flags if f.kind in MARKED]
    positions = np.array([f.position for f in chosen], dtype=float).reshape(-1, 3)
    return positions, np.array([f.severity for f in chosen], dtype=float)


class ValidationMarkers(SceneLayer):
    """Draws the junction and clash flags shown of the live report into the scene's plotter."""

    switch = Layer.VALIDATION
    needs_backbone = False
    names = (NAME,)

    def __init__(self, validation: LiveValidation, scene: Scene) -> None:
        super().__init__(scene)
        self.validation = validation
        self.mesh = pv.PolyData()
        validation.updated.connect(self.refresh)
        validation.triageChanged.connect(lambda: self.refresh(render=True))
        scene.add_layer(self)

    def build(self) -> None:
        """Draw the markers again (the scene's rebuild removed every actor)."""
        self.refresh()

    def refresh(self, render: bool = False) -> None:
        """Show the markers of the flags shown; render with ``render``, or after a deferred check
        that moved a marker when nothing moves (the scene renders after each change)."""
        triaged = self.validation.triaged
        if triaged is None:
            return
        if NAME not in self.scene.plotter.actors:
            self.mesh.shallow_copy(_points(np.zeros((1, 3)), np.zeros((1, 3), dtype=np.uint8)))  # not empty
            self.scene.actors[NAME] = self.scene.plotter.add_mesh(
                self.mesh, name=NAME, scalars="colours", rgb=True, render_points_as_spheres=True,
                point_size=MARKER_PIXELS, reset_camera=False, pickable=False, show_scalar_bar=False, render=False,
            )
        positions, severity = marked(triaged.flags)
        colours = severity_colours(severity)
        changed = True
        if len(positions) and len(positions) == self.mesh.n_points:
            targets = (self.mesh.GetPoints().GetData(), positions), (self.mesh.GetPointData().GetArray("colours"), colours)
            changed = not all(np.array_equal(vtk_to_numpy(target), values) for target, values in targets)
            if changed:
                for target, values in targets:
                    vtk_to_numpy(target)[:] = values
                    target.Modified()
                self.mesh.Modified()
        elif len(positions) or self.mesh.n_points:
            self.mesh.shallow_copy(_points(positions, colours))
        else:
            changed = False
        visible = self.visible
        self.scene.actors[NAME].SetVisibility(visible)
        if visible and (render or (self.validation.late and changed and not self.scene.moving)):
            self.scene.plotter.render()  # (while something moves, its next frame or the still one shows them)


def _points(positions: np.ndarray, colours: np.ndarray) -> pv.PolyData:
    """One vertex per position, coloured; an empty mesh (no colours array) for none."""
    if len(positions) == 0:
        return pv.PolyData()
    mesh = pv.PolyData(positions.copy())
    mesh.point_data["colours"] = colours
    return mesh
