"""The editor window under Xvfb: the view follows the document, mouse drags edit, files round-trip.

Drags go through the same path as the mouse: events invoked on the VTK interactor of the
3D view at the display position of a control-point sphere.
"""

import gzip
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDropEvent, QImage
from PySide6.QtWidgets import QApplication, QFileDialog, QMessageBox
from pytestqt.qtbot import QtBot

from app import DEFAULT_STRUCTURE
from app.editor.docks.layout import fit_frame
from app.editor.docks.panels import STEPS_PER_LEVEL
from app.editor.document import Document
from app.editor.features.files import RECENT_KEY
from app.editor.interaction.drag import Mode
from app.editor.main_window import MainWindow
from app.editor.scene import molecule
from app.editor.scene.curves import SIDES
from app.editor.scene.molecule import Colouring
from app.editor.scene.scene import Layer
from app.main import COMMANDS, main
from core.curves.splines import spline_space
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
SPHERE_VERTICES = 42


def _window(qtbot: QtBot, path: Path) -> MainWindow:
    document = Document()
    document.open(path)
    window = MainWindow(document)
    qtbot.addWidget(window)  # closed (answering 'Discard'), and so its plotter too, after the test
    window.show()
    qtbot.waitExposed(window)
    window.plotter.render()
    return window


@pytest.fixture
def window(qtbot: QtBot) -> MainWindow:
    return _window(qtbot, DATA / "1UBQ.pdb.gz")


def _display(window: MainWindow, point: np.ndarray) -> tuple[int, int]:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return round(x), round(y)


def _mouse_drag(window: MainWindow, start: tuple[int, int], offset: tuple[int, int], steps: int = 6) -> None:
    """Press, move in ``steps`` and release the left button on the view's VTK interactor."""
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    for k in range(1, steps + 1):
        interactor.SetEventInformation(start[0] + offset[0] * k // steps, start[1] + offset[1] * k // steps)
        interactor.InvokeEvent("MouseMoveEvent")
    interactor.InvokeEvent("LeftButtonReleaseEvent")


def _drag_control_point(window: MainWindow, which: int, offset: tuple[int, int] = (40, 25), steps: int = 6) -> int:
    """Drag the ``which``-th shown control point; returns its index in the level curve."""
    curve = window.document.level_curve()
    shown = window.scene.shown_control_points()
    index = int(shown[which])
    _mouse_drag(window, _display(window, curve.control_points[index]), offset, steps)
    return index


def _moved_residues(document: Document, before: np.ndarray) -> np.ndarray:
    rows = np.flatnonzero(np.any(document.model.coords != before, axis=1))
    return np.unique(document.structure.atom_residue[rows])


def _pixels(image: QImage) -> np.ndarray:
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    rows = np.frombuffer(image.constBits(), dtype=np.uint8).reshape(image.height(), image.bytesPerLine())
    return rows[:, : 3 * image.width()].reshape(image.height(), image.width(), 3).astype(int)


def _colour_counts(pixels: np.ndarray) -> dict[str, int]:
    """Pixels of the secondary-structure colours, by hue whatever the shading."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    bright = r > 90
    return {
        "helix": int(np.count_nonzero(bright & (r - g > 70) & (r - b > 50) & (b > g))),  # (222, 66, 91)
        "sheet": int(np.count_nonzero(bright & (g > 0.65 * r) & (g < 0.9 * r) & (b < 0.2 * r))),  # (246, 190, 0)
    }


# ------------------------------------------------------------------ the view follows the document


def test_bundled_example_is_ubiquitin(qapp: QApplication) -> None:
    structure = read_structure(DEFAULT_STRUCTURE)
    assert structure.entry_id == "1UBQ" and structure.n_residues == 76


def test_window_shows_the_structure(window: MainWindow) -> None:
    assert window.windowTitle() == "1UBQ.pdb.gz[*] — ribbonwave" and not window.isWindowModified()
    cartoon = window.scene.meshes["cartoon"]
    assert cartoon.n_points == (76 * 6 + 1) * SIDES + 2 * (SIDES + 1)
    assert window.plotter.actors["cartoon"].GetVisibility() and "tube" not in window.plotter.actors  # (until shown)
    colours = {tuple(c) for c in cartoon.point_data["colours"]}
    assert set(molecule.SS_COLOURS.values()) <= colours
    assert "ions" not in window.plotter.actors  # ubiquitin has none
    assert window.status.labels["segment"].text() == "chain A  MET1–GLY76 (76 residues)"
    assert window.history.model().rowCount() == 1  # "<structure as read>"


@pytest.mark.parametrize("level", [0.0, 2.0, 3.0, 3.5, 5.0, "max"])
def test_slider_shows_the_curve_and_control_points_of_the_level(window: MainWindow, level: object) -> None:
    document, panel = window.document, window.dimension_panel
    value = round((document.max_level if level == "max" else level) * STEPS_PER_LEVEL)
    panel.slider.setValue(value)
    assert document.level == (document.max_level if level == "max" else value / STEPS_PER_LEVEL)
    ribbon = document.model.ribbons[0]
    points, j = ribbon.control_points(document.level)
    path = document.paths[0]
    np.testing.assert_allclose(window.scene.meshes["curve"].points, spline_space(j).evaluate(points, path.curve_u),
                               atol=1e-5)  # float32 in VTK
    shown = window.scene.shown_control_points()
    knots = spline_space(j).knots  # basis function k lives on [knots[k], knots[k + 4]]
    first, last = path.u[0], path.u[-1]  # the residues' stretch of the padded curve
    reach = np.flatnonzero((knots[4:] > first) & (knots[:-4] < last))
    assert np.array_equal(shown, reach)  # spheres for the points that shape residues, none for the padding
    expected = len(reach)
    if level == "max":
        assert expected == 76 + 3  # one per peptide plane and two per terminus
    if level in (0.0, 2.0):
        assert expected == 2**j + 3
    assert window.scene.meshes["control_points"].n_points == expected * SPHERE_VERTICES
    centres = window.scene.meshes["control_points"].points.reshape(expected, SPHERE_VERTICES, 3).mean(axis=1)
    np.testing.assert_allclose(centres, points[shown], atol=1e-4)
    assert panel.segments_text.text().endswith(f"2^{j} = {2**j}")
    assert panel.points_text.text() == f"{expected} shown of {2**j + 3}"


def test_integer_levels_only(window: MainWindow) -> None:
    panel = window.dimension_panel
    panel.integers.setChecked(True)
    panel.slider.setValue(round(2.7 * STEPS_PER_LEVEL))
    assert window.document.level == 3.0 and panel.slider.value() == 3 * STEPS_PER_LEVEL
    panel.slider.setValue(round(6.2 * STEPS_PER_LEVEL))
    assert window.document.level == window.document.max_level  # log2 76 = 6.25, the original curve
    panel.analysis.setChecked(False)
    assert not panel.slider.isEnabled() and window.document.shown_level() == window.document.max_level


def test_large_multichain_entry(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "4YVS.cif.gz")
    document, panel = window.document, window.dimension_panel
    assert panel.segment.count() == 20 and panel.segment.isEnabled()
    panel.segment.setCurrentIndex(5)  # chain G
    assert document.segment == 5 and window.status.labels["segment"].text().startswith("chain G")
    panel.slider.setValue(3 * STEPS_PER_LEVEL)
    samples = np.vstack([document.level_curve(g).samples for g in range(20)])
    np.testing.assert_allclose(window.scene.meshes["curve"].points, samples, atol=1e-4)
    assert all(document.level_curve(g).n_segments == 8 for g in range(20))
    assert len(window.scene.shown_control_points()) == 11
    points = document.model.ribbons[5].control_points(3.0)[0]
    centres = window.scene.meshes["control_points"].points.reshape(11, SPHERE_VERTICES, 3).mean(axis=1)
    np.testing.assert_allclose(centres, points, atol=1e-4)


def test_layers_colours_and_fat_helices(window: MainWindow) -> None:
    panel = window.display_panel
    panel.layer_boxes[Layer.ATOMS].setChecked(True)
    assert window.plotter.actors["atoms"].GetVisibility()
    panel.layer_boxes[Layer.TUBE].setChecked(True)  # swept now: it sweeps nothing while hidden
    assert window.plotter.actors["tube"].GetVisibility()
    panel.layer_boxes[Layer.TUBE].setChecked(False)
    assert not window.plotter.actors["tube"].GetVisibility()
    panel.layer_boxes[Layer.CONTROL_POINTS].setChecked(False)
    assert not window.plotter.actors["control_points"].GetVisibility()
    panel.colouring.setCurrentIndex(panel.colouring.findData(Colouring.RESIDUE_TYPE))
    colours = window.scene.meshes["cartoon"].point_data["colours"]
    assert tuple(colours[0]) == molecule.RESIDUE_CLASSES["hydrophobic"][0]  # Met1
    assert panel.legend_layout.rowCount() == len(molecule.RESIDUE_CLASSES)
    panel.colouring.setCurrentIndex(panel.colouring.findData(Colouring.RAINBOW))  # Met1 blue
    assert tuple(window.scene.meshes["cartoon"].point_data["colours"][0]) == (0, 0, 255)
    panel.colouring.setCurrentIndex(panel.colouring.findData(Colouring.B_FACTOR))
    assert panel.legend_layout.rowCount() == 3  # lowest, halfway, highest
    panel.colouring.setCurrentIndex(panel.colouring.findData(Colouring.RESIDUE_TYPE))
    panel.layer_boxes[Layer.TUBE].setChecked(True)  # swept and coloured as it is shown again
    tube = window.scene.meshes["tube"]
    assert tuple(tube.point_data["colours"][0]) == molecule.RESIDUE_CLASSES["hydrophobic"][0]
    centre = window.document.paths[0]
    before = np.array(tube.points)
    panel.fat.setChecked(True)
    helix = np.flatnonzero(window.document.structure.segments[0].ss == "H")[3]  # a residue inside the helix
    ring = helix * centre.rings_per_residue + centre.rings_per_residue // 2
    centres, _ = centre.centres(window.document.model.ribbons[0].points, np.array([ring]))
    radius = np.linalg.norm(tube.points[ring * SIDES] - centres[0])
    assert radius == pytest.approx(1.5, abs=1e-4) and not np.allclose(before, tube.points)


# ------------------------------------------------------------------ editing with the mouse


@pytest.mark.parametrize(("level", "expected"), [("max", 10), (5.0, 22), (4.0, 38)])
def test_dragging_a_control_point_edits_the_structure(
    window: MainWindow, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, level: object, expected: int
) -> None:
    document = window.document
    document.set_regularization(on_release=False)  # Carson's plain edit (regularization: test_validation_panel)
    for layer in (Layer.ATOMS, Layer.TUBE):
        window.display_panel.layer_boxes[layer].setChecked(True)
    document.set_level(document.max_level if level == "max" else level)
    window.plotter.render()
    original = document.model.coords.copy()
    index = _drag_control_point(window, len(window.scene.shown_control_points()) // 2)

    assert document.pick is not None and document.pick.index == index
    assert document.undo_stack.count() == 1  # one drag, one undo step
    assert document.undo_stack.text(0) == f"Move point {index} at level {document.shown_level():.2f}"
    moved = _moved_residues(document, original)
    assert len(moved) == expected  # the curve points of 4 residues at full resolution, twice as many one level
    # down (J = 7 here), and 3 more on each side turned with the curve
    assert np.array_equal(moved, document.structure.segments[0].residue_index[document.pick.residues])
    owned = np.isin(document.structure.atom_residue, moved)
    assert np.array_equal(document.model.coords[~owned], original[~owned])  # all other atoms bit-identical
    assert np.all(np.any(document.model.coords[owned] != original[owned], axis=1))
    # the view followed: the tube and the atoms of the moved residues
    atoms = window.scene.meshes["atoms"].points
    np.testing.assert_allclose(atoms, document.model.coords, atol=1e-4)
    assert window.isWindowModified()
    assert window.status.labels["pick"].text().startswith(f"point {index} moves {expected} residues")
    edited = document.model.coords.copy()
    tube_after = np.array(window.scene.meshes["tube"].points)

    window.editing.undo_action.trigger()
    assert np.array_equal(document.model.coords, original) and not window.isWindowModified()
    window.editing.redo_action.trigger()
    assert np.array_equal(document.model.coords, edited)
    np.testing.assert_array_equal(window.scene.meshes["tube"].points, tube_after)

    target = tmp_path / "edited.cif"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *args, **kwargs: (str(target), ""))
    window.files.save_action.trigger()  # the first Save asks for a file name
    np.testing.assert_allclose(read_structure(target).coords, edited, atol=6e-4)
    assert document.save_path == target and not window.isWindowModified()


def test_the_view_drawn_in_place_is_the_view_built_afresh(window: MainWindow) -> None:
    plotter = window.plotter
    before = plotter.screenshot(return_img=True).astype(int)
    _drag_control_point(window, 5, (90, 60))
    in_place = plotter.screenshot(return_img=True).astype(int)
    camera = plotter.camera_position
    window.scene._build()  # every mesh made again from the document
    plotter.camera_position = camera
    plotter.render()
    afresh = plotter.screenshot(return_img=True).astype(int)
    changed = np.count_nonzero(np.abs(in_place - before).sum(axis=2) > 30)
    different = np.count_nonzero(np.abs(in_place - afresh).sum(axis=2) > 30)
    assert changed > 5000  # the drag is on screen ...
    assert different < 0.1 * changed  # ... as it would be drawn from scratch (tube facets may turn a little)


def test_switching_to_the_ca_ribbon(window: MainWindow) -> None:
    panel, document = window.dimension_panel, window.document
    panel.kind.setCurrentIndex(panel.kind.findData("calpha"))
    assert document.kind == "calpha" and document.model.ribbons[0].n_curve_segments == 77
    np.testing.assert_allclose(window.scene.meshes["curve"].points, document.level_curve().samples, atol=1e-4)
    _drag_control_point(window, 4)
    assert not panel.kind.isEnabled()  # the kind cannot change under an edit
    window.editing.undo_action.trigger()
    assert panel.kind.isEnabled()


def test_a_drag_with_qt_mouse_events(qtbot: QtBot, window: MainWindow) -> None:
    """The whole way from Qt: QMouseEvents on the view widget, as the window system sends them."""
    document = window.document
    index = int(window.scene.shown_control_points()[5])
    start = document.level_curve().control_points[index].copy()
    x, y = _display(window, start)
    widget = window.plotter
    scale = widget.devicePixelRatioF()
    at = QPoint(round(x / scale), round(widget.height() - 1 - y / scale))  # VTK counts rows from the bottom
    qtbot.mousePress(widget, Qt.MouseButton.LeftButton, pos=at)
    for k in range(1, 5):
        qtbot.mouseMove(widget, at + QPoint(10 * k, -6 * k))
    qtbot.mouseRelease(widget, Qt.MouseButton.LeftButton, pos=at + QPoint(40, -24))
    assert document.undo_stack.count() == 1 and document.pick.index == index
    moved = document.level_curve().control_points[index] - start
    assert 1.0 < np.linalg.norm(moved) < 100.0
    np.testing.assert_allclose(moved @ np.array(window.plotter.camera.direction), 0.0, atol=1e-6)  # in the view plane


def test_undo_puts_the_tube_back_exactly(window: MainWindow) -> None:
    window.display_panel.layer_boxes[Layer.TUBE].setChecked(True)
    tube = np.array(window.scene.meshes["tube"].points)
    _drag_control_point(window, 4)
    assert not np.array_equal(window.scene.meshes["tube"].points, tube)
    window.editing.undo_action.trigger()
    np.testing.assert_array_equal(window.scene.meshes["tube"].points, tube)


def test_tugging_the_curve_with_the_mouse(window: MainWindow) -> None:
    document = window.document
    window.editing.mode_actions.actions()[1].trigger()
    assert window.controller.mode is Mode.CURVE
    original = document.model.coords.copy()
    sample = document.level_curve().samples[120]
    _mouse_drag(window, _display(window, sample), (0, 40))
    assert document.undo_stack.count() == 1 and document.undo_stack.text(0).startswith("Tug curve at A:")
    assert 0 < len(_moved_residues(document, original)) < 76


def test_a_drag_beside_the_points_turns_the_camera(window: MainWindow) -> None:
    camera = window.plotter.camera.position
    _mouse_drag(window, (5, 5), (120, 60))
    assert window.plotter.camera.position != camera
    assert window.document.undo_stack.count() == 0 and window.document.pick is None


def test_hidden_control_points_cannot_be_grabbed(window: MainWindow) -> None:
    point = window.document.level_curve().control_points[int(window.scene.shown_control_points()[5])]
    window.display_panel.layer_boxes[Layer.CONTROL_POINTS].setChecked(False)
    camera = window.plotter.camera.position
    _mouse_drag(window, _display(window, point), (40, 25))
    assert window.document.undo_stack.count() == 0 and window.plotter.camera.position != camera


def test_escape_cancels_a_drag(window: MainWindow) -> None:
    document = window.document
    original = document.model.coords.copy()
    point = document.level_curve().control_points[int(window.scene.shown_control_points()[6])]
    start = _display(window, point)
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*start)
    interactor.InvokeEvent("LeftButtonPressEvent")
    interactor.SetEventInformation(start[0] + 50, start[1])
    interactor.InvokeEvent("MouseMoveEvent")
    assert not np.array_equal(document.model.coords, original)
    window.editing.cancel_action.trigger()
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    assert np.array_equal(document.model.coords, original) and document.undo_stack.count() == 0


# ------------------------------------------------------------------ files


def test_closing_with_unsaved_edits_asks_first(qtbot: QtBot, window: MainWindow, questions) -> None:
    _drag_control_point(window, 3)
    questions.answer = questions.answer.Cancel
    window.close()
    assert window.isVisible() and questions.asked == ["Save the changes to 1UBQ.pdb.gz?"]
    questions.answer = questions.answer.Discard
    window.close()
    qtbot.waitUntil(lambda: not window.isVisible())
    assert window.plotter.render_window is None


def test_opening_another_file_asks_and_bad_files_are_reported(window: MainWindow, questions, errors) -> None:
    _drag_control_point(window, 3)
    questions.answer = questions.answer.Cancel
    assert not window.files.open_file(DATA / "1TIM.pdb.gz")
    assert window.document.structure.entry_id == "1UBQ"
    questions.answer = questions.answer.Discard
    assert not window.files.open_file(DATA / "missing.pdb")
    assert errors == [f"{DATA / 'missing.pdb'}: no such file"] and window.document.structure.entry_id == "1UBQ"
    assert window.files.open_file(DATA / "1TIM.pdb.gz")
    assert window.document.structure.entry_id == "1TIM" and window.document.undo_stack.count() == 0
    assert window.dimension_panel.segment.count() == 2
    assert window.windowTitle() == "1TIM.pdb.gz[*] — ribbonwave"
    assert window.files.recent_files()[0] == str((DATA / "1TIM.pdb.gz").resolve())  # kept in the temporary settings
    assert window.settings.value(RECENT_KEY)


def test_save_never_overwrites_without_asking(window: MainWindow, tmp_path: Path, monkeypatch, questions) -> None:
    source = tmp_path / "input.pdb"
    source.write_bytes((DATA / "1UBQ.pdb.gz").read_bytes())
    assert window.files.open_file(source)
    _drag_control_point(window, 3)
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *args, **kwargs: ("", ""))  # cancelled
    assert not window.files.save()
    assert source.read_bytes() == (DATA / "1UBQ.pdb.gz").read_bytes()
    mmcif = "mmCIF (*.cif *.cif.gz *.mmcif)"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *args, **kwargs: (str(tmp_path / "out"), mmcif))
    assert window.files.save()
    assert (tmp_path / "out.cif").exists() and window.document.save_path == tmp_path / "out.cif"
    (tmp_path / "out.cif").write_text("an older file")
    window.document.save_path = None  # as after opening a file: Save asks for a name again
    questions.answer = questions.answer.No
    assert not window.files.save()  # "out" + ".cif" exists: asked, and the answer was no
    assert questions.asked[-1] == "out.cif exists. Replace it?"
    assert (tmp_path / "out.cif").read_text() == "an older file"
    questions.answer = questions.answer.Yes
    assert window.files.save()
    _drag_control_point(window, 5)
    assert window.files.save()  # later saves go to the chosen file without asking
    np.testing.assert_allclose(read_structure(tmp_path / "out.cif").coords, window.document.model.coords, atol=6e-4)


def test_dropping_a_file_opens_it(window: MainWindow) -> None:
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(DATA / "4HHB.pdb.gz"))])
    event = QDropEvent(QPointF(20, 20), Qt.DropAction.CopyAction, mime, Qt.MouseButton.NoButton,
                       Qt.KeyboardModifier.NoModifier)
    window.dropEvent(event)
    assert window.document.structure.entry_id == "4HHB"
    assert window.plotter.actors["ligand_balls"].GetVisibility()  # the haems, ball-and-stick


# ------------------------------------------------------------------ the command line


def test_screenshot_shows_the_tube_in_its_colours(qapp: QApplication, tmp_path: Path) -> None:
    shot = tmp_path / "shot.png"
    assert main([str(DATA / "1UBQ.pdb.gz"), "--screenshot", str(shot), "--level", "3"]) == 0
    pixels = _pixels(QImage(str(shot)))
    assert pixels.shape[:2] == (900, 1400)
    counts = _colour_counts(pixels)
    assert counts["helix"] > 1000 and counts["sheet"] > 1000, counts


@pytest.mark.parametrize("content", [None, "not a structure\n"], ids=["missing", "not-a-structure"])
def test_unreadable_file_is_a_one_line_error(
    qapp: QApplication, tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str | None
) -> None:
    path = tmp_path / "input.pdb"
    if content is not None:
        path.write_text(content)
    assert main([str(path)]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith("ribbonwave: error: ") and str(path) in err and err.count("\n") == 1


def test_bad_level_and_unwritable_screenshot_are_one_line_errors(
    qapp: QApplication, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--level", "-1"])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err.endswith("ribbonwave open: error: argument --level: must lie in [0, 30]; got -1\n")
    shot = tmp_path / "no-such-folder" / "shot.png"
    assert main(["--screenshot", str(shot)]) == 1
    assert capsys.readouterr().err == f"ribbonwave: error: {shot}: no such folder {shot.parent}\n"


def test_screenshot_follows_the_rules_of_output_files(qapp: QApplication, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """Never over an existing file without --overwrite, never through a link (#16)."""
    shot = tmp_path / "shot.png"
    shot.write_bytes(b"mine")
    assert main([str(DATA / "1UBQ.pdb.gz"), "--screenshot", str(shot)]) == 1
    assert "refusing to overwrite an existing file (use --overwrite)" in capsys.readouterr().err
    assert shot.read_bytes() == b"mine"
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    link = tmp_path / "link.png"
    link.symlink_to(victim)
    assert main([str(DATA / "1UBQ.pdb.gz"), "--screenshot", str(link)]) == 1
    assert main([str(DATA / "1UBQ.pdb.gz"), "--screenshot", str(link), "--overwrite"]) == 0
    assert victim.read_text() == "precious\n" and not link.is_symlink() and QImage(str(link)).width() == 1400
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.png", "shot.png", "victim.txt"]  # no temporary left


def test_no_display_is_a_one_line_error(
    qapp: QApplication, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM"):
        monkeypatch.delenv(name, raising=False)
    assert main([str(DATA / "1UBQ.pdb.gz")]) == 1
    assert capsys.readouterr().err.startswith("ribbonwave: error: no display to open a window on")


def test_help_lists_the_commands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    out = capsys.readouterr().out
    for name in COMMANDS:
        assert f"    {name} " in out or f"    {name}\n" in out


def test_every_test_entry_opens_and_takes_a_drag(window: MainWindow, errors: list[str]) -> None:
    """Odd entries too: Cα-only, NMR with hydrogens, altlocs, gaps, insertion codes, ligands, DNA."""
    for path in sorted(DATA.glob("*.gz")):
        assert window.files.open_file(path), errors
        document = window.document
        if not document.editable:
            assert path.name == "1BNA.pdb.gz"  # DNA only: viewed, not edited (test_viewing_only.py)
            continue
        original = document.model.coords.copy()
        _drag_control_point(window, len(window.scene.shown_control_points()) // 2, (30, 20), steps=1)
        assert document.undo_stack.count() == 1, path.name
        assert len(_moved_residues(document, original)) > 0, path.name
        window.editing.undo_action.trigger()
        assert np.array_equal(document.model.coords, original), path.name


def test_an_empty_window_refuses_to_save(qtbot: QtBot, errors: list[str], tmp_path: Path) -> None:
    window = MainWindow()
    qtbot.addWidget(window)
    window.show()
    assert window.windowTitle() == "untitled[*] — ribbonwave" and window.status.labels["file"].text() == "no structure"
    unreadable = tmp_path / "notes.pdb"
    unreadable.write_text("not a structure\n")
    assert not window.files.open_file(unreadable)
    assert errors == [f"{unreadable}: not a structure file (no atoms found)"]
    assert not window.files.save() and not window.files.save_as()


@pytest.mark.parametrize("n_residues", [2, 3])
def test_a_chain_of_two_or_three_residues_opens_and_takes_a_drag(window: MainWindow, errors: list[str],
                                                                 tmp_path: Path, n_residues: int) -> None:
    text = gzip.decompress((DATA / "1UBQ.pdb.gz").read_bytes()).decode()
    lines = [line for line in text.splitlines() if line.startswith("ATOM") and int(line[22:26]) <= n_residues]
    path = tmp_path / f"short{n_residues}.pdb"
    path.write_text("\n".join(lines) + "\nEND\n")
    assert window.files.open_file(path) and errors == []
    assert len(window.document.ca_rows) == n_residues
    original = window.document.model.coords.copy()
    _drag_control_point(window, 1, (30, 20), steps=2)
    assert window.document.undo_stack.count() == 1 and not np.array_equal(window.document.model.coords, original)


@pytest.mark.parametrize("name, value, message", [
    ("DISPLAY", ":77", "cannot open the display DISPLAY=':77': no X server answers there"),
    ("QT_QPA_PLATFORM", "bogus", "QT_QPA_PLATFORM='bogus' is not a Qt platform here; known: "),
    ("QT_QPA_PLATFORM", "offscreen", "QT_QPA_PLATFORM='offscreen' cannot show the 3D view"),
])
def test_a_display_qt_cannot_use_is_a_one_line_error(qapp: QApplication, monkeypatch: pytest.MonkeyPatch,
                                                      capsys: pytest.CaptureFixture[str], name: str, value: str,
                                                      message: str) -> None:
    """Said before Qt would abort the process (#16)."""
    monkeypatch.setenv(name, value)
    assert main([str(DATA / "1UBQ.pdb.gz")]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"ribbonwave: error: {message}") and err.count("\n") == 1


def test_a_click_on_a_control_point_picks_and_edits_nothing(window: MainWindow) -> None:
    """A press and release without motion, or with a 2-pixel jitter, is a click (#17)."""
    document = window.document
    original = document.model.coords.copy()
    for jitter in ((0, 0), (2, 0), (1, 1)):
        index = _drag_control_point(window, 3, jitter, steps=1)
        assert document.pick is not None and document.pick.index == index
        assert document.undo_stack.count() == 0 and not document.modified
        assert np.array_equal(document.model.coords, original)
    _drag_control_point(window, 3, (12, 0), steps=3)  # a real drag is one undo step
    assert document.undo_stack.count() == 1


def test_redo_on_ctrl_shift_z_and_ctrl_y(window: MainWindow, qtbot: QtBot) -> None:
    document = window.document
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)  # shortcuts go to the active window
    _drag_control_point(window, 3, (30, 20), steps=2)
    moved = document.model.coords.copy()
    for keys in ((Qt.Key.Key_Z, Qt.KeyboardModifier.ShiftModifier | Qt.KeyboardModifier.ControlModifier),
                 (Qt.Key.Key_Y, Qt.KeyboardModifier.ControlModifier)):
        qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
        assert document.undo_stack.index() == 0
        qtbot.keyClick(window, *keys)
        assert document.undo_stack.index() == 1 and np.array_equal(document.model.coords, moved)


def test_the_level_box_takes_a_typed_fraction(window: MainWindow, qtbot: QtBot) -> None:
    spin = window.dimension_panel.spin
    spin.selectAll()
    qtbot.keyClicks(spin, "2.5")
    assert window.document.level != 2.5  # nothing happens per digit
    qtbot.keyClick(spin, Qt.Key.Key_Return)
    assert window.document.level == 2.5 and spin.value() == 2.5


def test_a_file_opened_from_the_command_line_is_a_recent_file(qapp: QApplication, tmp_path: Path,
                                                               private_settings: Path) -> None:
    assert main([str(DATA / "1UBQ.pdb.gz"), "--screenshot", str(tmp_path / "shot.png")]) == 0
    window = MainWindow()
    try:
        assert window.files.recent_files()[0] == str((DATA / "1UBQ.pdb.gz").resolve())
    finally:
        window.close()


def test_the_status_bar_follows_the_drag_mode(window: MainWindow, qtbot: QtBot) -> None:
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window, Qt.Key.Key_T)
    assert window.status.labels["pick"].text().startswith("Drag the curve to tug it.")
    qtbot.keyClick(window, Qt.Key.Key_M)
    assert window.status.labels["pick"].text().startswith("Click a control point to pick it")


def test_what_reading_skipped_is_a_click_away_in_the_status_bar(qtbot: QtBot, monkeypatch: pytest.MonkeyPatch) -> None:
    """4HHB's B:ASP79 has no bonded neighbour and is in no segment: the status bar says a note
    was made, its tooltip and a click say which; a file read without notes hides the button."""
    window = _window(qtbot, DATA / "4HHB.pdb.gz")
    notes = window.status.notes
    assert notes.isVisible() and notes.text() == "1 note on reading"
    note = "residue B:ASP79 has no bonded neighbour: not in any segment"
    assert note in notes.toolTip()
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "information", lambda parent, title, text: shown.append(text))
    qtbot.mouseClick(notes, Qt.MouseButton.LeftButton)
    assert shown == [f"Reading 4HHB.pdb.gz:\n\n• {note}"]
    window.document.open(DATA / "1UBQ.pdb.gz")
    assert not notes.isVisible()


def test_choosing_another_chain_frames_it(qtbot: QtBot) -> None:
    """4HHB: the segment box moves the camera to the chosen chain and fits it in the view (#17)."""
    window = _window(qtbot, DATA / "4HHB.pdb.gz")
    document = window.document
    combo = window.dimension_panel.segment
    combo.setFocus()
    for _ in range(4):  # a choice in the box, by the keyboard
        qtbot.keyClick(combo, Qt.Key.Key_Down)
    assert document.segment == 4
    segment = document.structure.segments[4]
    ca = document.model.coords[document.ca_rows[segment.residue_index]]
    camera = window.plotter.renderer.camera
    assert np.allclose(camera.focal_point, (ca.min(axis=0) + ca.max(axis=0)) / 2, atol=0.5)
    width, height = window.plotter.width(), window.plotter.height()
    pixels = np.array([_display(window, point) for point in ca])
    assert (pixels >= 0).all() and (pixels[:, 0] <= width).all() and (pixels[:, 1] <= height).all()
    assert np.ptp(pixels[:, 0]) > width / 4 or np.ptp(pixels[:, 1]) > height / 4  # framed, not a speck


def _laptop_screen(monkeypatch: pytest.MonkeyPatch, height: int) -> None:
    """The primary screen as a laptop's: 1366 pixels wide, ``height`` available."""
    from PySide6.QtCore import QRect

    class Laptop:
        def availableGeometry(self) -> QRect:  # noqa: N802 (Qt's name)
            return QRect(0, 0, 1366, height)

    monkeypatch.setattr(QApplication, "primaryScreen", staticmethod(lambda: Laptop()))


def test_the_window_fits_a_small_screen_and_keeps_its_layout(qtbot: QtBot, monkeypatch: pytest.MonkeyPatch) -> None:
    """On a 1366 x 768 laptop the window fits; its size and docks come back at the next start (#17)."""
    _laptop_screen(monkeypatch, 728)  # (less a panel)
    window = MainWindow()
    qtbot.addWidget(window)
    assert window.width() <= 1366 and window.height() <= 728 - 32  # room for a title bar
    window.resize(1000, 650)
    window.console_dock.show()
    qtbot.wait(10)
    size = window.size()  # (as near 1000 x 650 as the docks allow)
    window.close()
    again = MainWindow()
    qtbot.addWidget(again)
    assert again.size() == size and again.console_dock.isVisibleTo(again)


def test_the_window_frame_fits_the_screen(qtbot: QtBot, monkeypatch: pytest.MonkeyPatch) -> None:
    """A window manager's frame (a 40-pixel title bar here) is inside the available area: the
    status bar of a 1366 x 768 screen is not pushed off its bottom (#35)."""
    from PySide6.QtCore import QRect

    _laptop_screen(monkeypatch, 768)
    window = MainWindow()
    qtbot.addWidget(window)
    window.resize(1366, 768)
    window.move(30, 20)
    monkeypatch.setattr(window, "frameGeometry", lambda: window.geometry().adjusted(-4, -40, 4, 4))
    fit_frame(window)
    assert QRect(0, 0, 1366, 768).contains(window.frameGeometry())
    assert window.height() == 768 - 44 and window.width() == 1366 - 8


def test_vtk_one_letter_keys_leave_the_view_alone(qtbot: QtBot, view_kind: str, open_window) -> None:  # noqa: ANN001
    """'e' and 'q' would close VTK's or pyvista's window, 'w' draw wireframes, '3' stereo."""
    window = open_window("1UBQ.pdb.gz")
    view, tube = window.plotter, window.scene.actors["cartoon"]
    view.setFocus()
    for key in "wq3e":
        qtbot.keyClick(view, key)
    qtbot.wait(50)
    assert window.isVisible() and view.isVisible() and not view._closed
    assert tube.prop.style == "Surface" and not view.ren_win.GetStereoRender()
