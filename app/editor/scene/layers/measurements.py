"""Labels and measurements in the view (:mod:`app.editor.measurements`): a line through each
measurement's atoms (``measure_lines``: dashed for a distance, as PyMOL and Coot draw a
hydrogen bond) and its value, or a label's atom name, as text beside it drawn over the molecule
(as ChimeraX draws labels: a label inside a pocket is read through the cartoon); rewritten in
place when an edit moves their atoms."""

from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkTextActor

from app.editor.document import Change
from app.editor.measurements import Measurement
from app.editor.scene.layers.base import Layer, SceneLayer, Stage
from app.editor.scene.looks import BACKING_OPACITY

COLOUR = (20, 110, 150)
"""The lines' and the texts' colour."""
TEXT_PIXELS = 15
LABEL_OFFSET = 0.6
"""Å a label's text stands off its atom."""
DASH = 0.5
"""Å from one dash of a distance's line to the next (the dash 0.3 of it, the gap the rest)."""


class MeasurementsLayer(SceneLayer):
    """Every label and measurement of the document, drawn over the structure."""

    switch = Layer.MEASUREMENTS
    needs_backbone = False
    names = ("measure_lines",)
    lines_as_tubes = ("measure_lines",)

    def __init__(self, scene: Stage) -> None:
        super().__init__(scene)
        self._texts: list[vtkTextActor] = []
        self._rows = np.empty(0, dtype=np.int64)
        self._ends, self._along = np.empty((0, 2), dtype=np.int64), np.empty(0)
        """Each line point's two atoms and how far from the first to the second it lies."""
        self._places = np.empty((0, 3))
        """Where each text stands (Å)."""
        self.document.measurements.changed.connect(self._changed)

    def build(self) -> None:
        items = self.document.measurements.items
        coords = self.document.model.coords
        self._rows = np.array([row for m in items for row in m.atoms], dtype=np.int64)
        self._ends, self._along, lines = _line_points(items, coords)
        self.meshes["measure_lines"] = (pv.PolyData(self._points(coords), lines=lines)
                                        if len(self._rows) else pv.PolyData())
        self.add("measure_lines", color=COLOUR, line_width=3.0, render_lines_as_tubes=True)
        self._texts = []
        self._places = np.empty((len(items), 3))
        for k, measurement in enumerate(items):
            text = vtkTextActor()
            text.GetPositionCoordinate().SetCoordinateSystemToWorld()
            style = text.GetTextProperty()
            style.SetFontSize(TEXT_PIXELS)
            style.SetBold(True)
            style.SetColor(*(c / 255 for c in COLOUR))
            style.SetJustificationToCentered()
            style.SetVerticalJustificationToCentered()
            style.SetBackgroundColor(1.0, 1.0, 1.0)  # legible on the cartoon's colours too
            style.SetBackgroundOpacity(BACKING_OPACITY)
            self._texts.append(text)
            self.actors[f"measure_text_{k}"] = text
            self.scene.plotter.add_actor(text, name=f"measure_text_{k}", reset_camera=False, render=False,
                                         pickable=False)
            self._place(k, measurement, coords)
        self.show(self.visible)

    def update(self, change: Change) -> None:
        if len(self._rows) and np.isin(self._rows, change.rows).any():
            coords = self.document.model.coords
            self.write("measure_lines", slice(None), self._points(coords))
            for k, measurement in enumerate(self.document.measurements.items):
                self._place(k, measurement, coords)

    def show(self, visible: bool) -> None:
        super().show(visible)
        for text in self._texts:
            text.SetVisibility(visible)

    def before_frame(self) -> None:
        """Hide each text whose place the frame clips away: drawn over the molecule, the texts
        are not clipped with it (behind the camera; outside a clip slab, as PyMOL's labels)."""
        if not self._texts or not self.visible:
            return
        camera = self.scene.plotter.renderer.GetActiveCamera()
        depth = (self._places - np.array(camera.GetPosition())) @ np.array(camera.GetDirectionOfProjection())
        near, far = camera.GetClippingRange() if self.scene.slab is not None else (0.0, np.inf)
        for text, shown in zip(self._texts, ((depth > near) & (depth < far)).tolist(), strict=True):
            text.SetVisibility(shown)

    def _points(self, coords: np.ndarray) -> np.ndarray:
        """The lines' points as the atoms are now: each between two atoms (:func:`_line_points`)."""
        first, second = coords[self._ends[:, 0]], coords[self._ends[:, 1]]
        return first + self._along[:, None] * (second - first)

    def _place(self, k: int, measurement: Measurement, coords: np.ndarray) -> None:
        """Put text ``k``, ``measurement``'s, where it belongs: beside a label's atom, at the
        middle of a distance, at an angle's vertex, at the middle of a dihedral's axis."""
        text = self._texts[k]
        xyz = coords[list(measurement.atoms)]
        if len(xyz) == 1:
            where = xyz[0] + LABEL_OFFSET
        elif len(xyz) == 3:
            where = xyz[1]
        else:  # the middle of a distance, of a dihedral's axis
            where = xyz[len(xyz) // 2 - 1:len(xyz) // 2 + 1].mean(axis=0)
        self._places[k] = where
        text.GetPositionCoordinate().SetValue(*map(float, where))
        text.SetInput(measurement.text(self.document.structure, coords))

    def _changed(self) -> None:
        """A measurement was added or removed: drawn again (once the structure is drawn)."""
        if "measure_lines" not in self.meshes or self.document.model is None:
            return
        plotter = self.scene.plotter
        for k in range(len(self._texts)):
            plotter.remove_actor(f"measure_text_{k}", render=False)
            self.actors.pop(f"measure_text_{k}", None)
        plotter.remove_actor("measure_lines", render=False)
        self.actors.pop("measure_lines", None)
        self.build()
        plotter.render()


def _line_points(items: list[Measurement], coords: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lines of ``items``: each point's two atoms (p, 2) and how far along from the first to
    the second it lies (p,), and the cells: a distance a dash every :data:`DASH` Å, an angle or
    a dihedral a polyline through its atoms (a label none)."""
    ends, along, cells, start = [], [], [], 0
    for measurement in items:
        atoms = measurement.atoms
        if len(atoms) == 2:
            dashes = max(int(np.linalg.norm(coords[atoms[1]] - coords[atoms[0]]) / DASH), 1)
            steps = (np.arange(dashes)[:, None] + np.array([0.35, 0.65])) / dashes
            ends += [atoms] * (2 * dashes)
            along.append(steps.ravel())
            firsts = start + 2 * np.arange(dashes)
            cells.append(np.column_stack([np.full(dashes, 2), firsts, firsts + 1]).ravel())
            start += 2 * dashes
        elif len(atoms) > 2:
            ends += [(row, row) for row in atoms]
            along.append(np.zeros(len(atoms)))
            cells.append(np.r_[len(atoms), start:start + len(atoms)])
            start += len(atoms)
    if not ends:
        return np.empty((0, 2), dtype=np.int64), np.empty(0), np.empty(0, dtype=np.int64)
    return np.array(ends, dtype=np.int64), np.concatenate(along), np.concatenate(cells)
