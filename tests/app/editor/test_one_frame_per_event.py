"""One frame per event (#18): a slider step, a pick, a drag step, an undo and a zoom each draw
the view once, however many views change; a screenshot shows the current state at once."""

from collections.abc import Callable

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot

from app.editor import live_validation
from app.editor.live_validation import DRAG_INTERVAL_MS
from app.editor.main_window import MainWindow
from app.editor.scene import view as view_module
from app.editor.scene.scene import STILL_AFTER_MS, Layer

Opener = Callable[[str], MainWindow]
"""The ``open_window`` fixture: a shown window on a file of tests/data."""


def _still(qtbot: QtBot, window: MainWindow) -> None:
    """Wait until the view is drawn in full detail again and nothing is pending."""
    qtbot.waitUntil(lambda: not window.scene.moving, timeout=2000)
    qtbot.wait(100)  # its frame, and the deferred validation check


def _frames_of(qtbot: QtBot, window: MainWindow, send) -> int:  # noqa: ANN001 (a callable)
    """Frames the view draws for the event ``send`` sends, before full detail comes back."""
    _still(qtbot, window)
    before = window.plotter.frames
    send()
    qtbot.wait(STILL_AFTER_MS // 2)
    return window.plotter.frames - before


def _point_of(window: MainWindow, index: int) -> QPoint:
    """Where control point ``index`` of the level shown lies in the view."""
    view = window.plotter
    view.renderer.SetWorldPoint(*window.document.level_curve().control_points[index], 1.0)
    view.renderer.WorldToDisplay()
    x, y, _ = view.renderer.GetDisplayPoint()
    return QPoint(round(x / view.devicePixelRatioF()), round(view.height() - 1 - y / view.devicePixelRatioF()))


def test_each_event_draws_one_frame(qtbot: QtBot, view_kind: str, open_window: Opener) -> None:
    window = open_window("1AYE.pdb.gz")
    assert type(window.plotter).__name__ == {"native": "NativeView", "widget": "WidgetView"}[view_kind]
    document = window.document
    window.scene.set_layer(Layer.CA_TRACE, True)  # more views to change
    view = window.plotter
    slider = window.dimension_panel.slider
    assert _frames_of(qtbot, window, lambda: qtbot.keyClick(slider, Qt.Key.Key_Right)) == 1

    index = int(window.scene.shown_control_points()[4])
    at = _point_of(window, index)
    assert _frames_of(qtbot, window, lambda: qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=at)) == 1
    assert document.pick is not None and document.pick.index == index
    assert _frames_of(qtbot, window, lambda: qtbot.mouseMove(view, at + QPoint(30, 20))) == 1
    assert _frames_of(qtbot, window, lambda: qtbot.mouseRelease(view, Qt.MouseButton.LeftButton,
                                                                pos=at + QPoint(30, 20))) == 1
    assert document.undo_stack.count() == 1
    assert _frames_of(qtbot, window, window.editing.undo_action.trigger) == 1

    centre = QPointF(view.width() / 2, view.height() / 2)
    wheel = QWheelEvent(centre, view.mapToGlobal(centre), QPoint(), QPoint(0, 120), Qt.MouseButton.NoButton,
                        Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    distance = view.camera.distance
    assert _frames_of(qtbot, window, lambda: QApplication.sendEvent(view, wheel)) == 1
    assert view.camera.distance < distance


@pytest.mark.parametrize("view_kind", ["widget"], indirect=True)
def test_a_drag_step_changes_the_validation_dock_with_its_frame(qtbot: QtBot, view_kind: str, open_window: Opener,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """With the view in a ``QOpenGLWidget``, each event-loop turn that changes a widget
    composes the whole window once more: a drag
    step checks the moved residues itself once the interval is over, and the list of flags
    changes its texts in place, so the dock changes in the step's one composition. The
    release, whose regularization refills the list and lays out the docks, composes once too."""
    window = open_window("1UBQ.pdb.gz")
    view, document, tree = window.plotter, window.document, window.validation_panel.offenders
    compositions = []
    view.aboutToCompose.connect(lambda: compositions.append(1))
    at = _point_of(window, int(window.scene.shown_control_points()[3]))
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=at)
    qtbot.mouseMove(view, at + QPoint(4, 0))  # past a click's reach: a drag
    alike = 0
    for m in range(1, 7):
        qtbot.wait(DRAG_INTERVAL_MS + 20)  # the check is due
        rows, first = tree.topLevelItemCount(), tree.topLevelItem(0)
        compositions.clear()
        qtbot.mouseMove(view, at + QPoint(4 + m, 0))
        assert not window.validation.pending and not window.validation.late  # checked within the step
        qtbot.wait(60)
        assert window.plotter.frames and len(compositions) >= 1
        if tree.topLevelItemCount() == rows:
            alike += 1
            assert tree.topLevelItem(0) is first and len(compositions) == 1
    assert alike >= 3
    monkeypatch.setattr(live_validation, "DRAG_INTERVAL_MS", 1000)  # however slow the machine
    qtbot.mouseMove(view, at + QPoint(50, 35))  # right after a check: left for later
    assert window.validation.pending
    qtbot.waitUntil(lambda: not window.validation.pending, timeout=5000)  # the drag paused: checked
    assert window.validation.late
    qtbot.wait(STILL_AFTER_MS + 100)
    rows = tree.topLevelItemCount()
    compositions.clear()
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=at + QPoint(50, 35))
    qtbot.wait(STILL_AFTER_MS // 2)
    assert document.undo_stack.count() == 1
    assert tree.topLevelItemCount() != rows  # the regularization fixed what the drag broke: the list refilled
    # no column resized, the docks and the main window laid out before the paint, no dock animated: one composition
    assert len(compositions) == 1


def test_a_screenshot_shows_a_change_not_drawn_yet(view_kind: str, open_window: Opener) -> None:
    window = open_window("1UBQ.pdb.gz")
    before = window.plotter.screenshot(return_img=True).astype(int)
    window.scene.set_layer(Layer.CARTOON, False)  # asks for a frame; none is drawn before the loop turns
    after = window.plotter.screenshot(return_img=True).astype(int)
    assert np.count_nonzero(np.abs(after - before).sum(axis=2) > 30) > 5000


def test_the_view_is_a_native_window_where_vtk_can_draw_into_one(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RIBBONWAVE_VIEW", raising=False)
    assert QApplication.platformName() == "xcb" and view_module.view_kind() == "native"
    monkeypatch.setattr(view_module.QGuiApplication, "platformName", staticmethod(lambda: "wayland"))
    assert view_module.view_kind() == "widget"
    monkeypatch.setenv("RIBBONWAVE_VIEW", "Native")
    assert view_module.view_kind() == "native"


def test_help_names_the_keys_bound_and_the_versions(qtbot: QtBot) -> None:
    """Help ▸ Mouse and Keyboard lists the window's own shortcuts; About gives the versions (#18)."""
    import gemmi
    import vtkmodules.vtkCommonCore as vtk
    from PySide6.QtCore import qVersion

    window = MainWindow()
    qtbot.addWidget(window)
    window.show()
    reference = window.help.show_reference()
    assert reference.isVisible()
    assert "Go to Residue" in reference.text() and "Ctrl+L" in reference.text() and "Ctrl+Y" in reference.text()
    assert "Double click" in reference.text()
    for gesture in ("Middle-button drag", "Right-button drag", "Shift+right-button drag", "Clip Slab", "Ctrl+K",
                    "Measure Distance"):  # (#35: the pan and zoom drags were missing)
        assert gesture in reference.text(), gesture
    reference.close()
    about = window.help.show_about()
    for part in (f"Qt {qVersion()}", f"VTK {vtk.vtkVersion.GetVTKVersion()}", f"gemmi {gemmi.__version__}"):
        assert part in about.text()
    about.close()
