"""Validation and regularization in the editor window: drags through the VTK interactor, as
the mouse sends them (the helpers of test_window), on ubiquitin at level 3 (a control point
there moves 64 residues, enough to stretch peptide bonds and push atoms together)."""

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot
from test_window import _display, _mouse_drag, _window

from app.editor import document as document_module, live_validation
from app.editor.docks.validation import CHECKED_NAMES, LISTED
from app.editor.main_window import MainWindow
from app.editor.scene.layers.validation_markers import MARKED, severity_colours
from app.editor.scene.scene import Layer
from core.geometry.topology import topology
from core.geometry.triage import Baseline, Triaged, triage
from core.geometry.validation import validate

DATA = Path(__file__).resolve().parents[2] / "data"
LEVEL = 3.0
OFFSET = (60, 40)
"""Pixels: about 7 Å at the default zoom."""


@pytest.fixture
def window(qtbot: QtBot) -> MainWindow:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.document.set_level(LEVEL)
    window.plotter.render()
    return window


def _press_point(window: MainWindow) -> tuple[int, int]:
    """Display position of the middle shown control point."""
    shown = window.scene.shown_control_points()
    return _display(window, window.document.level_curve().control_points[int(shown[len(shown) // 2])])


def _peptide_bonds(window: MainWindow) -> np.ndarray:
    """C–N length (Å) of every junction of the model."""
    top = topology(window.document.structure)
    coords = window.document.model.coords
    return np.linalg.norm(coords[top.backbone[top.first, 2]] - coords[top.backbone[top.second, 0]], axis=1)


def _marked_flags(window: MainWindow) -> list:
    return [f for f in validate(window.document.structure, window.document.model.coords).flags if f.kind in MARKED]


def _triaged(window: MainWindow) -> Triaged:
    """The model's flags that the default filter shows against the file, computed afresh."""
    structure = window.document.structure
    return triage(validate(structure, window.document.model.coords), Baseline.of(validate(structure)))


def _shown_marked(window: MainWindow) -> list:
    """The flags that should have a marker: of the marked kinds, shown by the default filter."""
    return [f for f in _triaged(window).flags if f.kind in MARKED]


def _assert_panel_matches_the_model(window: MainWindow) -> None:
    full = validate(window.document.structure, window.document.model.coords)
    report = window.validation.report
    assert report.counts == full.counts
    assert sorted((f.kind, f.where) for f in report.flags) == sorted((f.kind, f.where) for f in full.flags)
    expected, panel = _triaged(window), window.validation_panel
    for kind, label in panel.count_labels.items():
        changes = [f"{n} {what}" for n, what in ((expected.new[kind], "new"), (expected.worse[kind], "worse")) if n]
        total = f"{full.counts[kind]} of {full.checked[kind]} {CHECKED_NAMES.get(kind, 'junctions')}"
        assert label.text() == ", ".join(changes + [total])
    triaged, shown = window.validation.triaged, len(expected.flags)
    assert sorted((f.kind, f.where) for f in triaged.flags) == sorted((f.kind, f.where) for f in expected.flags)
    assert panel.listed == triaged.flags[:LISTED]
    assert panel.offenders.topLevelItemCount() == min(LISTED, shown) + (shown > LISTED)
    if shown:
        assert panel.offenders.topLevelItem(0).text(2) == expected.flags[0].where


def test_a_drag_is_regularized_on_release_in_one_undo_step(window: MainWindow) -> None:
    document = window.document
    assert window.validation_panel.on_release.isChecked() and not window.validation_panel.while_dragging.isChecked()
    original = document.model.coords.copy()
    _mouse_drag(window, _press_point(window), OFFSET)
    assert document.undo_stack.count() == 1
    assert np.all(np.abs(_peptide_bonds(window) - 1.33) <= 0.05)
    assert not np.array_equal(document.model.coords, original)
    regularized = document.model.coords.copy()
    window.display_panel.layer_boxes[Layer.ATOMS].setChecked(True)  # built as first shown: from the coordinates now
    np.testing.assert_allclose(window.scene.meshes["atoms"].points, regularized, atol=1e-4)  # the view shows it
    window.editing.undo_action.trigger()
    assert np.array_equal(document.model.coords, original)
    window.editing.redo_action.trigger()
    assert np.array_equal(document.model.coords, regularized)

    # the same drag without regularization stretches bonds: the check above can fail
    window.editing.undo_action.trigger()
    window.validation_panel.on_release.setChecked(False)
    _mouse_drag(window, _press_point(window), OFFSET)
    assert document.undo_stack.count() == 1
    assert np.any(np.abs(_peptide_bonds(window) - 1.33) > 0.05)


def test_the_cursor_waits_while_a_release_or_region_is_regularized(
    window: MainWindow, monkeypatch: pytest.MonkeyPatch
) -> None:
    cursors = []

    def spy(function):
        def called(*args, **kwargs):
            cursor = QApplication.overrideCursor()
            cursors.append(None if cursor is None else cursor.shape())
            return function(*args, **kwargs)
        return called

    monkeypatch.setattr(document_module, "regularized", spy(document_module.regularized))
    monkeypatch.setattr(document_module, "regularize_region", spy(document_module.regularize_region))
    _mouse_drag(window, _press_point(window), OFFSET)
    window.editing.regularize_action.trigger()
    assert cursors == [Qt.CursorShape.WaitCursor, Qt.CursorShape.WaitCursor]
    assert QApplication.overrideCursor() is None  # restored afterwards
    assert window.document.undo_stack.count() == 2


def test_regularize_while_dragging_shows_regular_previews(window: MainWindow, qtbot: QtBot) -> None:
    document = window.document
    window.validation_panel.while_dragging.setChecked(True)
    original = document.model.coords.copy()
    start = _press_point(window)
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    interactor.SetEventInformation(start[0] + OFFSET[0], start[1] + OFFSET[1])
    interactor.InvokeEvent("MouseMoveEvent")
    assert not np.array_equal(document.model.coords, original)
    assert np.all(np.abs(_peptide_bonds(window) - 1.33) <= 0.05)  # mid-drag
    qtbot.waitUntil(lambda: not window.validation.pending, timeout=2000)
    _assert_panel_matches_the_model(window)
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    assert document.undo_stack.count() == 1 and np.all(np.abs(_peptide_bonds(window) - 1.33) <= 0.05)
    window.editing.undo_action.trigger()
    assert np.array_equal(document.model.coords, original)


def test_panel_counts_follow_the_model_during_and_after_drags(window: MainWindow, qtbot: QtBot) -> None:
    window.validation_panel.on_release.setChecked(False)
    _assert_panel_matches_the_model(window)
    start = _press_point(window)
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    for k in (1, 2, 3):  # 64 of 76 residues move: each preview is checked in full
        interactor.SetEventInformation(start[0] + OFFSET[0] * k // 3, start[1] + OFFSET[1] * k // 3)
        interactor.InvokeEvent("MouseMoveEvent")
        qtbot.waitUntil(lambda: not window.validation.pending, timeout=2000)  # checked at most every 100 ms
        _assert_panel_matches_the_model(window)
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    assert sum(window.validation.report.counts.values()) > 10
    _assert_panel_matches_the_model(window)
    window.editing.undo_action.trigger()
    _assert_panel_matches_the_model(window)
    window.editing.redo_action.trigger()
    _assert_panel_matches_the_model(window)
    window.document.set_level(window.document.max_level)
    window.plotter.render()
    for offset in ((20, 10), (-30, 25)):  # 4 residues move: local checks folded into the report
        _mouse_drag(window, _press_point(window), offset)
        assert window.validation.local
        _assert_panel_matches_the_model(window)
    window.editing.undo_action.trigger()
    assert window.validation.local
    _assert_panel_matches_the_model(window)
    assert window.files.open_file(DATA / "1TIM.pdb.gz")  # a new structure: a full check
    assert not window.validation.local
    _assert_panel_matches_the_model(window)


def test_markers_show_a_bad_edit_until_the_region_is_regularized(window: MainWindow) -> None:
    document, mesh = window.document, window.markers.mesh
    assert not window.editing.regularize_action.isEnabled()  # nothing picked
    before = _marked_flags(window)
    assert mesh.n_points == len(_shown_marked(window)) == 0  # the file's one clash is mild
    window.validation_panel.on_release.setChecked(False)
    _mouse_drag(window, _press_point(window), OFFSET)
    bad = _marked_flags(window)
    assert len(bad) > len(before) + 10
    assert {f.kind for f in bad} >= {"peptide_bond", "clash"}
    shown = _shown_marked(window)
    assert len(shown) >= len(bad) - len(before)  # everything the edit made
    np.testing.assert_allclose(mesh.points, [f.position for f in shown], atol=1e-4)
    np.testing.assert_array_equal(mesh.point_data["colours"], severity_colours([f.severity for f in shown]))
    assert window.plotter.actors["validation_markers"].GetVisibility()

    edited = document.model.coords.copy()
    assert window.editing.regularize_action.isEnabled()
    window.editing.regularize_action.trigger()  # Edit > Regularize Region: the picked point's residues
    assert document.undo_stack.count() == 2 and document.undo_stack.text(1).startswith("Regularize A:")
    after = _marked_flags(window)
    assert not any(f.kind != "clash" for f in after)  # every junction is ideal again
    assert {f.where for f in after} <= {f.where for f in before}  # at most the clash of the file is left
    assert mesh.n_points == len(_shown_marked(window))
    window.editing.undo_action.trigger()
    assert np.array_equal(document.model.coords, edited) and mesh.n_points == len(shown)


def test_the_layer_toggle_hides_the_markers(window: MainWindow) -> None:
    window.validation_panel.on_release.setChecked(False)
    box = window.display_panel.layer_boxes[Layer.VALIDATION]
    assert box.isChecked()
    box.setChecked(False)
    actor = window.plotter.actors["validation_markers"]
    assert not actor.GetVisibility()
    _mouse_drag(window, _press_point(window), OFFSET)
    assert not actor.GetVisibility() and window.markers.mesh.n_points == len(_shown_marked(window))  # kept up to date
    assert window.markers.mesh.n_points > 10
    box.setChecked(True)
    assert actor.GetVisibility()
    assert window.files.open_file(DATA / "1TIM.pdb.gz")  # the scene's rebuild keeps the markers
    assert window.plotter.actors["validation_markers"].GetVisibility()
    assert window.markers.mesh.n_points == len(_shown_marked(window))


def test_severity_colours_run_from_yellow_to_red() -> None:
    colours = severity_colours([1.0, 2.5, 4.0, 40.0])
    assert tuple(colours[0]) == (250, 205, 40) and tuple(colours[2]) == tuple(colours[3]) == (215, 25, 28)
    assert colours[0, 1] > colours[1, 1] > colours[2, 1]


def test_checks_during_a_drag_wait_for_the_interval_and_the_release_catches_up(
    window: MainWindow, monkeypatch
) -> None:
    monkeypatch.setattr(live_validation, "DRAG_INTERVAL_MS", 60_000)  # no deferred check fires in this test
    window.validation_panel.on_release.setChecked(False)
    start = _press_point(window)
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    for k in (1, 2, 3):
        interactor.SetEventInformation(start[0] + OFFSET[0] * k // 3, start[1] + OFFSET[1] * k // 3)
        interactor.InvokeEvent("MouseMoveEvent")
        assert window.validation.pending  # the check on opening the file was less than a minute ago
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    assert not window.validation.pending
    _assert_panel_matches_the_model(window)
