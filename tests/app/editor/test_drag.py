"""The drag controller fed plain pointer events (no Qt widgets, no VTK)."""

import numpy as np
import pytest

from app.editor.document import Document
from app.editor.interaction.drag import DragController, Mode, PointerEvent
from core.curves.splines import spline_space

VIEW = np.array([0.0, 0.0, -1.0])  # the camera looks down -z


def _event(kind: str, through: np.ndarray) -> PointerEvent:
    """A ray along the viewing direction through ``through`` (perspective-like pixel sizes)."""
    return PointerEvent(kind, through - 60.0 * VIEW, VIEW, VIEW, 0.05, 0.002)


def _shown_point(document: Document, which: int) -> tuple[int, np.ndarray]:
    curve = document.level_curve()
    index = int(np.flatnonzero(curve.visible)[which])
    return index, curve.control_points[index].copy()


@pytest.mark.parametrize("level", [2.0, 4.0, 5.5, "max"])
def test_dragging_a_control_point_moves_it_in_the_view_plane(ubiquitin: Document, level: object) -> None:
    ubiquitin.set_level(ubiquitin.max_level if level == "max" else level)
    controller = DragController(ubiquitin)
    index, start = _shown_point(ubiquitin, 5)
    grab = start + np.array([0.3, -0.2, 0.0])  # anywhere on the sphere
    assert controller.handle(_event("press", grab))
    assert ubiquitin.pick.index == index
    assert controller.handle(_event("move", grab + [1.0, 0.5, 0.0]))
    assert controller.handle(_event("move", grab + [2.0, 1.0, 0.0]))
    assert controller.handle(_event("release", grab + [2.5, 1.5, 0.0]))
    assert not controller.dragging
    moved = ubiquitin.level_curve().control_points[index]
    np.testing.assert_allclose(moved, start + [2.5, 1.5, 0.0], atol=1e-9)  # exactly where it was dragged
    assert ubiquitin.undo_stack.count() == 1
    assert ubiquitin.undo_stack.text(0) == f"Move point {index} at level {ubiquitin.shown_level():.2f}"


def test_a_release_where_the_last_move_left_the_pointer_previews_nothing_again(ubiquitin: Document) -> None:
    controller = DragController(ubiquitin)
    index, start = _shown_point(ubiquitin, 4)
    changes = []
    ubiquitin.changed.connect(changes.append)
    controller.handle(_event("press", start))
    controller.handle(_event("move", start + [2.0, 1.0, 0.0]))
    controller.handle(_event("move", start + [2.0, 1.0, 0.0]))  # the same pixel again
    assert len(changes) == 1
    controller.handle(_event("release", start + [2.0, 1.0, 0.0]))
    assert len(changes) == 2  # the undo step only (regularized)
    assert ubiquitin.undo_stack.count() == 1
    ubiquitin.undo_stack.undo()
    np.testing.assert_allclose(ubiquitin.level_curve().control_points[index], start, atol=1e-9)


def test_a_slanted_view_moves_the_point_in_the_plane_facing_the_camera(ubiquitin: Document) -> None:
    controller = DragController(ubiquitin)
    index, start = _shown_point(ubiquitin, 3)
    view = np.array([1.0, 1.0, -1.0]) / np.sqrt(3)
    ray = lambda kind, target: PointerEvent(kind, target - 80 * view, view, view, 0.05, 0.0)  # noqa: E731
    controller.handle(ray("press", start))
    target = start + np.array([3.0, -3.0, 0.0])  # in the plane: perpendicular to the view
    controller.handle(ray("release", target + 10 * view))  # any point of the ray through the target
    np.testing.assert_allclose(ubiquitin.level_curve().control_points[index], target, atol=1e-9)


def test_a_press_beside_every_point_is_left_to_the_camera(ubiquitin: Document) -> None:
    controller = DragController(ubiquitin)
    far = ubiquitin.level_curve().control_points.max(axis=0) + 20.0
    assert not controller.handle(_event("press", far))
    assert not controller.handle(_event("move", far + 1.0))
    assert not controller.handle(_event("release", far + 2.0))
    assert ubiquitin.pick is None and ubiquitin.undo_stack.count() == 0


def test_hidden_padding_points_are_never_grabbed(ubiquitin: Document) -> None:
    ubiquitin.set_level(ubiquitin.max_level)
    curve = ubiquitin.level_curve()
    front = ubiquitin.model.ribbons[0].front
    assert np.array_equal(np.flatnonzero(~curve.visible)[:front], np.arange(front))
    start = curve.control_points[0]  # padding copies of the N-terminal point lie on the shown ones
    assert DragController(ubiquitin).handle(_event("press", start))
    assert ubiquitin.pick.index in (front, front + 1)  # a shown copy, whose move reaches residue 1
    assert 0 in ubiquitin.pick.residues


@pytest.mark.parametrize("level", [3.0, 4.6])
def test_tugging_the_curve_moves_the_shown_curve_point_by_the_drag(ubiquitin: Document, level: float) -> None:
    ubiquitin.set_level(level)
    controller = DragController(ubiquitin, Mode.CURVE)
    curve = ubiquitin.level_curve()
    sample = curve.samples[100]
    assert controller.handle(_event("press", sample))
    assert controller.handle(_event("release", sample + [0.0, 2.0, 0.0]))
    assert ubiquitin.undo_stack.count() == 1
    assert ubiquitin.undo_stack.text(0).startswith("Tug curve at A:")
    after = ubiquitin.level_curve()
    space = spline_space(after.level)
    u = space.closest_parameter(curve.control_points, sample)
    np.testing.assert_allclose(space.evaluate(after.control_points, u) - space.evaluate(curve.control_points, u),
                               [0.0, 2.0, 0.0], atol=1e-6)


def test_cancel_restores_the_state_at_the_press(ubiquitin: Document) -> None:
    original = ubiquitin.model.coords.copy()
    controller = DragController(ubiquitin)
    _, start = _shown_point(ubiquitin, 4)
    controller.handle(_event("press", start))
    controller.handle(_event("move", start + [3.0, 0.0, 0.0]))
    controller.cancel()
    assert not controller.dragging
    assert np.array_equal(ubiquitin.model.coords, original) and ubiquitin.undo_stack.count() == 0
    assert not controller.handle(_event("release", start))
