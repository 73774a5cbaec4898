"""The control points of the edited segment's level curve: spheres (the picked one in another
colour), the control polygon through them, and a box around the picked one (the handle).

The spheres are sized to the level's spacing and kept a few pixels wide on screen: before each
frame their radius is checked against the camera's distance, and the glyphs are made again
when it should change by more than 5%. Otherwise only the spheres that moved (or changed
colour) are rewritten in place.
"""

from __future__ import annotations

import numpy as np

from app.editor.document import Change, Pick
from app.editor.interaction.drag import HANDLE_BOX, HANDLE_RADIUS
from app.editor.scene.layers.base import Layer, SceneLayer, Stage
from app.editor.scene.layers.meshes import box_edges, colour_glyphs, glyphs, move_glyphs, polyline, span

POINT_COLOUR = (140, 90, 220)
PICKED_COLOUR = (0, 170, 255)
POLYGON_COLOUR = (110, 110, 120)
POINT_SPACING_FRACTION = 0.04
"""Control-point spheres have this fraction of the level's median control-point spacing as
radius (at least HANDLE_RADIUS, at most MAX_POINT_RADIUS)..."""
MAX_POINT_RADIUS = 2.0
"""Å: coarse control polygons are wide (30 Å between points on ubiquitin at level 4)."""
MIN_POINT_PIXELS = 6.0
"""... and never less than this on screen (pixels), however far the camera is."""


class ControlPointsLayer(SceneLayer):
    """The edited level curve's control points, their polygon and the picked point's handle."""

    switch = Layer.CONTROL_POINTS
    names = ("control_points", "control_polygon", "handle")

    def __init__(self, scene: Stage) -> None:
        super().__init__(scene)
        self.radius = HANDLE_RADIUS
        """Radius of the spheres, Å."""
        self.shown = np.empty(0, dtype=np.int64)
        """Indices (into the level curve's control points) of the spheres drawn."""
        self._xyz = np.empty((0, 3))
        self._pick: Pick | None = None

    def build(self) -> None:
        self.shown = np.empty(0, dtype=np.int64)
        self._update()

    def update(self, change: Change) -> None:
        if change.segment == self.document.segment:
            self._update()

    def level_changed(self) -> None:
        self._update()

    def picked(self) -> None:
        self._update()

    def show(self, visible: bool) -> None:
        """Show or hide the spheres and the polygon, and the handle when a point is picked."""
        for name in self.names:
            if name in self.actors:
                self.actors[name].SetVisibility(visible and (name != "handle" or self.document.pick is not None))

    def before_frame(self) -> None:
        """Resize the spheres and the handle box when the level's spacing or the camera's
        distance asks for another size (by more than 5%)."""
        if "control_points" not in self.meshes or not len(self._xyz):
            return
        radius = self._wanted_radius(self._xyz)
        if abs(radius - self.radius) > 0.05 * self.radius:
            self.radius = radius
            self._update(resized=True)

    def _wanted_radius(self, points: np.ndarray) -> float:
        """Å, the sphere radius for control points ``points`` seen from the camera now."""
        spacing = float(np.median(np.linalg.norm(np.diff(points, axis=0), axis=1))) if len(points) > 1 else 0.0
        renderer = self.scene.plotter.renderer
        camera = renderer.GetActiveCamera()
        height = max(renderer.GetSize()[1], 1)
        if camera.GetParallelProjection():
            pixel = 2.0 * camera.GetParallelScale() / height
        else:
            depth = float((points.mean(axis=0) - np.array(camera.GetPosition())) @ camera.GetDirectionOfProjection())
            pixel = 2.0 * np.tan(np.radians(camera.GetViewAngle()) / 2.0) * max(depth, 0.0) / height
        return max(HANDLE_RADIUS, min(POINT_SPACING_FRACTION * spacing, MAX_POINT_RADIUS), MIN_POINT_PIXELS * pixel)

    def _update(self, resized: bool = False) -> None:
        curve = self.document.level_curve()
        shown = np.flatnonzero(curve.visible)
        points = curve.control_points[shown]
        pick = self.document.pick
        colours = np.tile(np.array(POINT_COLOUR, dtype=np.uint8), (len(shown), 1))
        if pick is not None:
            colours[shown == pick.index] = PICKED_COLOUR
        if len(shown) == len(self.shown) and not resized:  # rewrite the spheres that moved or changed colour
            moved = span(np.flatnonzero(np.any(points != self._xyz, axis=1)))
            move_glyphs(self.meshes["control_points"], moved, points[moved])
            self.write("control_polygon", moved, points[moved])
            if pick is not self._pick:
                colour_glyphs(self.meshes["control_points"], colours)
        elif "control_points" in self.meshes:  # another level or size: new glyph data under the same actors
            if not resized:  # another level: its spacing asks for another size (not rebuilt again before the frame)
                radius = self._wanted_radius(points)
                if abs(radius - self.radius) > 0.05 * self.radius:
                    self.radius = radius
            self.meshes["control_points"].shallow_copy(glyphs(points, self.radius, colours))
            self.meshes["control_polygon"].shallow_copy(polyline(points))
            self._box_corners = np.array(box_edges(HANDLE_BOX * self.radius).points)
        else:
            self.meshes["control_points"] = glyphs(points, self.radius, colours)
            self.add("control_points", scalars="colours", rgb=True, interpolation="phong", specular=0.5,
                     specular_power=30.0)
            self.meshes["control_polygon"] = polyline(points)
            self.add("control_polygon", color=POLYGON_COLOUR, line_width=1.5)
            self.meshes["handle"] = box_edges(HANDLE_BOX * self.radius)
            self.add("handle", color=PICKED_COLOUR, line_width=2.0, render_lines_as_tubes=True)
            self._box_corners = np.array(self.meshes["handle"].points)
        self.shown, self._xyz, self._pick = shown, points, pick
        if pick is not None:
            self.write("handle", slice(None), curve.control_points[pick.index] + self._box_corners)
        self.actors["handle"].SetVisibility(pick is not None and self.visible)
