"""Direct manipulation without Qt or VTK: plain pointer events and the drag controller.

:class:`PointerEvent` is all a drag needs to know about the mouse: the ray under the
pointer and the camera's viewing direction. :class:`DragController` picks what the press
ray hits (a control point of the curve shown at the current level, or that curve itself),
moves it in the plane through the grabbed point facing the camera, asks the document for
a preview of the edit relative to the state at the press, and ends the gesture with one
undo step. Presses that hit nothing, or come while nothing can be edited, are left to the camera.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Literal

import numpy as np

from app.editor.document import Document
from core.curves.splines import spline_space

PICK_PIXELS = 7.0
"""How close (in pixels) the pointer must come to a control point or the curve to grab it."""
CLICK_PIXELS = 3.0
"""A press and release that moves the pointer less than this (pixels) is a click: it picks
and edits nothing."""
HANDLE_RADIUS = 0.8
"""Smallest radius of the control-point spheres, Å: a press anywhere on a sphere grabs it."""
HANDLE_BOX = 3.0
"""Edge of the handle box around the picked point, in sphere radii: its faces stand clear of
the sphere, and a press on one moves the point in that face's plane."""


class Mode(StrEnum):
    """What a drag grabs."""

    POINT = "move control points"
    CURVE = "tug the curve"


@dataclass(frozen=True, eq=False)
class PointerEvent:
    """A left-button event as a ray in world coordinates (Å).

    Attributes
    ----------
    kind : 'press', 'move' or 'release'.
    origin : (3,) the point of the ray on the camera's near plane.
    direction : (3,) unit direction of the ray.
    view : (3,) unit viewing direction of the camera (direction of projection).
    pixel : world size of one pixel at ``origin``.
    pixel_growth : growth of the pixel size per Å along the ray (0 for parallel projection).
    shift : whether Shift is held.
    double : whether a press is the second of a double click.
    """

    kind: Literal["press", "move", "release"]
    origin: np.ndarray
    direction: np.ndarray
    view: np.ndarray
    pixel: float
    pixel_growth: float
    shift: bool = False
    double: bool = False

    def distances(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Depth along the ray, distance from the ray (both Å) and the size of a pixel there
        (Å), for ``points`` (n, 3)."""
        offset = points - self.origin
        depth = offset @ self.direction
        off_ray = np.linalg.norm(offset - depth[:, None] * self.direction, axis=1)
        return depth, off_ray, self.pixel + self.pixel_growth * np.maximum(depth, 0.0)

    def on_plane(self, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """Where the ray meets the plane through ``point`` with ``normal``."""
        along = float(self.direction @ normal)
        if abs(along) < 1e-9:  # ray parallel to the plane: stay at the closest point of the ray
            return self.origin + ((point - self.origin) @ self.direction) * self.direction
        return self.origin + ((point - self.origin) @ normal / along) * self.direction


@dataclass
class _Grab:
    start: np.ndarray
    """Where the press ray met the drag plane."""
    normal: np.ndarray
    index: int | None
    """Control point, or None when the curve is tugged."""
    u: float
    label: str
    pixel: float
    """World size of a pixel at the grabbed point, Å."""
    axes: np.ndarray
    """(k, 3) the axes Shift may constrain the motion to: x, y, z, or those of a box face's plane."""
    moved: bool = False
    """Whether the pointer has gone CLICK_PIXELS from the press (a drag, not a click)."""
    shown: np.ndarray | None = None
    """The displacement previewed last (a release where the last move left the pointer shows nothing new)."""
    along: str | None = None
    """The axis Shift kept the motion to at the last event ('x', 'y', 'z'), or None."""


class DragController:
    """Turns pointer events into previews and undo steps of a :class:`Document`."""

    def __init__(self, document: Document, mode: Mode = Mode.POINT) -> None:
        self.document = document
        self.mode = mode
        self.point_radius = HANDLE_RADIUS
        """Radius of the control-point spheres as drawn, Å (the view sizes them)."""
        self._grab: _Grab | None = None

    @property
    def dragging(self) -> bool:
        return self._grab is not None

    def handle(self, event: PointerEvent) -> bool:
        """Process ``event``; True when it was used (the camera must then ignore it)."""
        if event.kind == "press":
            self._grab = self._press(event)
            return self._grab is not None
        grab = self._grab
        if grab is None:
            return False
        displacement = event.on_plane(grab.start, grab.normal) - grab.start
        grab.along = None
        if event.shift:  # along the one allowed axis the pointer moves most along
            axis = grab.axes[np.argmax(np.abs(grab.axes @ displacement))]
            displacement = axis * float(axis @ displacement)
            grab.along = "xyz"[int(np.argmax(np.abs(axis)))]
        grab.moved = grab.moved or float(np.linalg.norm(displacement)) >= CLICK_PIXELS * grab.pixel
        if grab.moved and not (grab.shown is not None and np.array_equal(displacement, grab.shown)):
            grab.shown = displacement
            if grab.index is not None:
                self.document.preview_move(grab.index, displacement)
            else:
                self.document.preview_tug(grab.u, displacement)
        if event.kind == "release":
            self._grab = None
            if grab.moved:  # named with the axis Shift kept it to, as History shows it
                along = f" along {grab.along}" if grab.along else ""
                self.document.finish_drag(f"{grab.label}{along} at level {self.document.shown_level():.2f}")
        return True

    def cancel(self) -> None:
        """Abandon the drag in progress, restoring the state at its start."""
        if self._grab is not None:
            self._grab = None
            self.document.cancel_drag()

    def _press(self, event: PointerEvent) -> _Grab | None:
        if not self.document.editable:
            return None
        curve = self.document.level_curve()
        if self.mode is Mode.POINT:
            face = self._press_box(event)
            if face is not None:
                return face
            index = _nearest_hit(event, curve.control_points, curve.visible, self.point_radius)
            if index is None:
                return None
            self.document.pick_point(index)
            centre = curve.control_points[index]
            _, _, pixel = event.distances(centre[None])
            return _Grab(event.on_plane(centre, event.view), event.view, index, 0.0, f"Move point {index}",
                         float(pixel[0]), np.eye(3))
        path = self.document.paths[self.document.segment]
        sample = _nearest_hit(event, curve.samples, np.ones(len(curve.samples), dtype=bool), 0.0)
        if sample is None:
            return None
        depth, _, _ = event.distances(curve.samples[sample][None])
        under_pointer = event.origin + depth[0] * event.direction  # the ray's point nearest that sample
        u = spline_space(curve.level).closest_parameter(curve.control_points, under_pointer)
        u = float(np.clip(u, *path.span))
        point = spline_space(curve.level).evaluate(curve.control_points, u)
        residue = int(np.argmin(np.abs(path.residue_u - u)))
        label = self.document.labels()[residue]
        _, _, pixel = event.distances(point[None])
        return _Grab(event.on_plane(point, event.view), event.view, None, u, f"Tug curve at {label}", float(pixel[0]),
                     np.eye(3))

    def _press_box(self, event: PointerEvent) -> _Grab | None:
        """A press on a face of the picked point's handle box, off its sphere: the point moves
        in that face's plane."""
        pick = self.document.pick
        if pick is None:
            return None
        centre = self.document.level_curve().control_points[pick.index]
        entry = _box_entry(event, centre, 0.5 * HANDLE_BOX * self.point_radius)
        _, off_ray, _ = event.distances(centre[None])
        if entry is None or off_ray[0] <= self.point_radius:
            return None
        point, axis = entry
        normal = np.eye(3)[axis]
        _, _, pixel = event.distances(point[None])
        plane = "xyz".replace("xyz"[axis], "")
        return _Grab(point, normal, pick.index, 0.0, f"Move point {pick.index} in {plane}", float(pixel[0]),
                     np.delete(np.eye(3), axis, axis=0))


def _box_entry(event: PointerEvent, centre: np.ndarray, half: float) -> tuple[np.ndarray, int] | None:
    """Where the ray enters the axis-aligned cube of half-edge ``half`` (Å) around ``centre``,
    and the axis of the face it enters through; None if it misses (slab method)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (centre - half - event.origin) / event.direction
        t2 = (centre + half - event.origin) / event.direction
    near, far = np.where(np.isnan(t1), -np.inf, np.minimum(t1, t2)), np.where(np.isnan(t2), np.inf, np.maximum(t1, t2))
    enter, leave = near.max(), far.min()
    if not np.isfinite(enter) or enter > leave or leave < 0:
        return None
    return event.origin + enter * event.direction, int(np.argmax(near))


def _nearest_hit(event: PointerEvent, points: np.ndarray, allowed: np.ndarray, radius: float) -> int | None:
    """The allowed point whose sphere of ``radius`` (Å) the ray hits, or that passes within
    :data:`PICK_PIXELS` of the ray: the one closest to the ray, then to the eye."""
    depth, off, pixel = event.distances(points)
    hit = allowed & (depth > 0) & (off <= np.maximum(radius, PICK_PIXELS * pixel))
    if not hit.any():
        return None
    candidates = np.flatnonzero(hit)
    return int(candidates[np.lexsort((depth[candidates], off[candidates]))[0]])
