"""Less detail while something moves (#18): the camera's turn and zoom, a drag and the level
slider draw the segments not edited with a coarser cartoon, plain lines and no FXAA; full detail
comes back once nothing has moved for a moment, and before any screenshot."""

from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot

from app.editor.main_window import MainWindow
from app.editor.scene.curves import SIDES
from app.editor.scene.layers.swept import MOVING_RING_STEP, MOVING_SIDE_STEP
from app.editor.scene.scene import STILL_AFTER_MS, Layer

Opener = Callable[[str], MainWindow]
"""The ``open_window`` fixture: a shown window on a file of tests/data."""


def _widget_point(window: MainWindow, point: np.ndarray) -> QPoint:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    scale = window.plotter.devicePixelRatioF()
    return QPoint(round(x / scale), round(window.plotter.height() - 1 - y / scale))


def _full_detail(window: MainWindow) -> bool:
    """Whether the view is drawn as at rest (and not half of it so)."""
    scene, actors = window.scene, window.scene.actors
    full = [window.plotter.renderer.GetUseFXAA(), actors["cartoon"].GetVisibility(),
            actors["curve"].prop.render_lines_as_tubes]
    coarse = [actors[name].GetVisibility() for name in ("cartoon_edited", "cartoon_others") if name in actors]
    assert all(full) == all(full[:1]) and not (any(full) and any(coarse)), (full, coarse)
    return all(full) and not scene.moving


def test_a_drag_draws_the_other_chains_coarse_and_its_own_in_full(qtbot: QtBot, open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")  # four chains: the edited segment and the others
    document, scene, view = window.document, window.scene, window.plotter
    assert _full_detail(window)
    index = int(scene.shown_control_points()[4])
    at = _widget_point(window, document.level_curve().control_points[index])
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=at)
    assert document.pick is not None and scene.moving and not _full_detail(window)
    edited, others = scene.meshes["cartoon_edited"], scene.meshes["cartoon_others"]
    assert scene.actors["cartoon_edited"].GetVisibility() and scene.actors["cartoon_others"].GetVisibility()
    tube = scene.meshes["cartoon"]
    n_paths = len(document.paths)
    rings = [path.n_rings for path in document.paths]
    own = rings[document.segment] * SIDES + 2 * (SIDES + 1)  # every vertex, caps included
    assert edited.n_points == own
    coarse = sum(len(range(0, n, MOVING_RING_STEP)) + ((n - 1) % MOVING_RING_STEP != 0)
                 for g, n in enumerate(rings) if g != document.segment) * (SIDES // MOVING_SIDE_STEP)
    assert others.n_points == coarse and n_paths > 1
    assert others.n_points < (tube.n_points - own) / 5  # a sixth of the others' vertices, without caps

    qtbot.mouseMove(view, at + QPoint(30, 20))
    moved = document.model.coords != document.structure.coords
    assert moved.any()
    first = document.paths[: document.segment]
    start = sum(p.n_rings for p in first) * SIDES
    np.testing.assert_array_equal(edited.points[: rings[document.segment] * SIDES],
                                  tube.points[start: start + rings[document.segment] * SIDES])
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=at + QPoint(30, 20))
    assert document.undo_stack.count() == 1 and scene.moving  # the release's frame, then full detail
    qtbot.waitUntil(lambda: _full_detail(window), timeout=STILL_AFTER_MS * 8)
    assert not scene.actors["cartoon_others"].GetVisibility()


def test_the_camera_and_the_slider_draw_less_until_they_stop(qtbot: QtBot, open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")
    view = window.plotter
    corner = QPoint(12, view.height() - 12)  # nothing there: the press turns the camera
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=corner)
    for step in range(1, 4):
        qtbot.mouseMove(view, corner + QPoint(8 * step, -5 * step))
        assert not _full_detail(window)
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=corner + QPoint(24, -15))
    qtbot.waitUntil(lambda: _full_detail(window), timeout=STILL_AFTER_MS * 8)

    centre = QPointF(view.width() / 2, view.height() / 2)
    wheel = QWheelEvent(centre, view.mapToGlobal(centre), QPoint(), QPoint(0, 120), Qt.MouseButton.NoButton,
                        Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(view, wheel)
    assert not _full_detail(window)
    frames = view.frames
    qtbot.waitUntil(lambda: _full_detail(window), timeout=STILL_AFTER_MS * 8)
    qtbot.waitUntil(lambda: view.frames > frames + 1)  # the zoomed frame, then the one in full detail

    slider = window.dimension_panel.slider
    slider.setFocus()
    qtbot.keyClick(slider, Qt.Key.Key_Right)
    assert not _full_detail(window)
    window.scene.set_layer(Layer.CARTOON, False)  # hidden stays hidden, moving or not
    assert not window.scene.actors["cartoon_others"].GetVisibility()
    window.scene.set_layer(Layer.CARTOON, True)
    qtbot.waitUntil(lambda: _full_detail(window), timeout=STILL_AFTER_MS * 8)


def test_a_screenshot_while_moving_is_drawn_in_full(qtbot: QtBot, open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")
    still = window.plotter.screenshot(return_img=True).astype(int)
    window.scene.moved()
    assert not _full_detail(window)
    again = window.plotter.screenshot(return_img=True).astype(int)
    assert _full_detail(window)
    np.testing.assert_array_equal(again, still)


def test_one_chain_keeps_its_cartoon_while_moving(open_window: Opener) -> None:
    window = open_window("1UBQ.pdb.gz")
    window.scene.moved()
    assert window.scene.moving and not window.plotter.renderer.GetUseFXAA()
    assert window.scene.actors["cartoon"].GetVisibility() and "cartoon_others" not in window.scene.meshes
