"""Finding your way in the editor (#17): hover names, go to residue, double-click centring,
clicks on other chains, the sequence bar, control points sized for big assemblies, the
handle box's faces and Shift, other chains dimmed or hidden. Real Qt and VTK events in a
window under Xvfb."""

from collections.abc import Callable

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QToolTip
from pytestqt.qtbot import QtBot

from app.editor.interaction.drag import HANDLE_BOX, HANDLE_RADIUS
from app.editor.main_window import MainWindow
from app.editor.scene.curves import SIDES
from app.editor.scene.layers.control_points import MIN_POINT_PIXELS
from app.editor.scene.layers.tube import TubeLayer
from app.editor.scene.scene import Layer, Others

Opener = Callable[[str], MainWindow]
"""The ``open_window`` fixture: a shown window on a file of tests/data."""


@pytest.fixture
def window(open_window: Opener) -> MainWindow:
    return open_window("1UBQ.pdb.gz")


def _display(window: MainWindow, point: np.ndarray) -> tuple[int, int]:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return round(x), round(y)


def _widget_point(window: MainWindow, point: np.ndarray) -> QPoint:
    """Where ``point`` is drawn, in the view widget's Qt coordinates (rows from the top)."""
    x, y = _display(window, point)
    scale = window.plotter.devicePixelRatioF()
    return QPoint(round(x / scale), round(window.plotter.height() - 1 - y / scale))


def _drawn(qtbot: QtBot, window: MainWindow) -> None:
    """Ask for a frame and wait until it is drawn (the view draws when the event loop turns)."""
    frames = window.plotter.frames
    window.plotter.render()
    qtbot.waitUntil(lambda: window.plotter.frames > frames)


def _ca(window: MainWindow, row: int) -> np.ndarray:
    return window.document.model.coords[window.document.ca_rows[row]]


def _front_residue(window: MainWindow, candidates: np.ndarray) -> int:
    """Of the residue rows ``candidates``, the one whose Cα is nearest the camera."""
    eye = np.array(window.plotter.camera.position)
    return int(candidates[np.argmin([np.linalg.norm(_ca(window, int(r)) - eye) for r in candidates])])


def _move(window: MainWindow, point: tuple[int, int]) -> None:
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*point)
    interactor.InvokeEvent("MouseMoveEvent")


def _focal(window: MainWindow) -> np.ndarray:
    return np.array(window.plotter.camera.focal_point)


# ------------------------------------------------------------------ hover


def test_hovering_names_the_residue_the_point_and_the_atom(window: MainWindow, qtbot: QtBot) -> None:
    document = window.document
    window.scene.set_layer(Layer.CONTROL_POINTS, False)
    row = _front_residue(window, np.arange(document.structure.n_residues))
    qtbot.mouseMove(window.plotter, _widget_point(window, _ca(window, row)))  # a real Qt move
    segment = document.structure.segments[0]
    expected = f"{segment.labels[row]} · {['helix', 'sheet', 'other']['HEC'.index(segment.ss[row])]}"
    assert window.status.labels["hover"].text() == expected
    qtbot.waitUntil(lambda: QToolTip.text() == expected)

    window.scene.set_layer(Layer.CONTROL_POINTS, True)
    curve = document.level_curve()
    index = int(window.scene.shown_control_points()[4])
    _move(window, _display(window, curve.control_points[index]))
    residues = document.point_residues(index)
    assert window.status.labels["hover"].text() == (
        f"control point {index} at level {document.shown_level():.2f}: moves "
        f"{document.residue_range(residues)} ({len(residues)} residues)")

    window.scene.set_layer(Layer.CONTROL_POINTS, False)
    window.scene.set_layer(Layer.ATOMS, True)
    table = document.structure.atoms
    lysines = np.flatnonzero((table.resname == "LYS") & (table.name == "NZ"))
    towards = -np.array(window.plotter.camera.GetDirectionOfProjection())
    nz = int(lysines[np.argmax(document.model.coords[lysines] @ towards)])  # the frontmost: nothing hides it
    window.scene.centre_on(document.model.coords[nz])
    window.plotter.camera.zoom(4.0)
    window.plotter.render()
    _move(window, _display(window, document.model.coords[nz]))
    assert window.status.labels["hover"].text().split(" · ")[0] == f"{document.structure.residue_label(table.residue[nz])} NZ"

    window.scene.reset_camera()
    window.plotter.render()
    _move(window, (2, 2))  # the corner: nothing
    assert window.status.labels["hover"].text() == ""


# ------------------------------------------------------------------ go to residue, centring, selection


def test_go_to_residue_by_keyboard(window: MainWindow, qtbot: QtBot) -> None:
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    assert window.navigation.go_to_field.hasFocus()
    qtbot.keyClicks(window.navigation.go_to_field, "A:45")
    qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
    assert list(window.document.selection) == [44]
    np.testing.assert_allclose(_focal(window), _ca(window, 44), atol=1e-6)
    assert window.status.labels["pick"].text() == "selected A:PHE45; Esc clears"
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(window.navigation.go_to_field, "30-35")  # the field's text was selected: typing replaces it
    qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
    assert list(window.document.selection) == list(range(29, 35))
    np.testing.assert_allclose(_focal(window), np.mean([_ca(window, r) for r in range(29, 35)], axis=0), atol=1e-6)

    for typed in ("/A:30-35", "chain A and resi 30-35", "A/30-35/"):  # as ChimeraX and PyMOL users type them
        window.document.select([])
        qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
        qtbot.keyClicks(window.navigation.go_to_field, typed)
        qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
        assert list(window.document.selection) == list(range(29, 35)), typed
    for typed in ("A:30-32, 40", "/A:30-32,40", "resi 30-32+40"):  # lists, in each syntax
        qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
        qtbot.keyClicks(window.navigation.go_to_field, typed)
        qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
        assert list(window.document.selection) == [29, 30, 31, 39], typed
        assert window.status.labels["pick"].text() == ("selected 4 residues: A:ILE30, A:GLN31, A:ASP32, "
                                                       "A:GLN40; Esc clears"), typed
        np.testing.assert_allclose(_focal(window), np.mean([_ca(window, r) for r in (29, 30, 31, 39)], axis=0),
                                   atol=1e-6)
    window.navigation.go_to("30-35")

    before = _focal(window)
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(window.navigation.go_to_field, "A:999")
    qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
    assert window.statusBar().currentMessage() == "no residue A:999 in chain A"
    assert list(window.document.selection) == list(range(29, 35)) and np.array_equal(_focal(window), before)
    qtbot.keyClick(window.plotter, Qt.Key.Key_Escape)
    assert len(window.document.selection) == 0


def test_go_to_another_chain_makes_it_the_edited_segment(open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")
    rows = window.navigation.go_to("C:87").residues
    document = window.document
    assert document.structure.segments[document.segment].chain == "C"
    assert document.structure.residue_label(int(rows[0])) == "C:HIS87"
    np.testing.assert_allclose(_focal(window), _ca(window, int(rows[0])), atol=1e-6)


def test_go_to_a_binding_site_measures_the_atoms_where_they_are_now(open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("4HHB.pdb.gz")
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    field, document = window.navigation.go_to_field, window.document
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(field, "byres resn HEM and chain A around 4")  # as a PyMOL user types it
    qtbot.keyClick(field, Qt.Key.Key_Return)
    pocket = [document.structure.residue_label(int(row)) for row in document.selection]
    assert len(pocket) == 16 and "A:HIS87" in pocket and all(label.startswith("A:") for label in pocket)
    np.testing.assert_allclose(_focal(window), np.mean([_ca(window, r) for r in document.selection], axis=0), atol=1e-6)
    window.rw.level = document.max_level
    document.set_carry_ligands(False)  # the haem stays where it is
    window.rw.tug("A:HIS87", [0.0, 0.0, 12.0])  # the proximal histidine pulled out of the pocket
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(field, ":HEM :<4")
    qtbot.keyClick(field, Qt.Key.Key_Return)
    assert "A:HIS87" not in [document.structure.residue_label(int(row)) for row in document.selection]


def test_go_to_takes_selections_combined_as_pymol_and_chimerax_combine_them(open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("4HHB.pdb.gz")
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    field, document = window.navigation.go_to_field, window.document
    for typed in ("chain B and ss H and not resn LEU", "/B & helix & ~:LEU"):
        qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
        qtbot.keyClicks(field, typed)
        qtbot.keyClick(field, Qt.Key.Key_Return)
        expected = np.concatenate([s.residue_index[(s.ss == "H") & (s.resname != "LEU")]
                                   for s in document.structure.segments if s.chain == "B"])  # (two: B:ASP79 is apart)
        assert np.array_equal(document.selection, expected) and len(expected) > 50
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(field, "(chain A or chain B")
    qtbot.keyClick(field, Qt.Key.Key_Return)
    assert "expected a closing parenthesis at the end" in window.statusBar().currentMessage()
    assert np.array_equal(document.selection, expected)  # a typing slip changes nothing


def test_go_to_zooms_in_on_what_it_names_and_never_out(open_window: Opener) -> None:
    """The haem pocket of chain A is brought close enough to fill most of the view, every atom
    of it inside the view; naming a whole chain afterwards centres on it without moving back."""
    window = open_window("4HHB.pdb.gz")
    camera, document = window.plotter.camera, window.document
    far = camera.distance
    rows = window.navigation.go_to("byres resn HEM and chain A around 4").residues
    pocket = document.model.coords[np.isin(document.structure.atom_residue, rows)]
    assert camera.distance < 0.6 * far
    width, height = window.plotter.width(), window.plotter.height()
    points = [_widget_point(window, atom) for atom in pocket]
    assert all(0 <= p.x() < width and 0 <= p.y() < height for p in points)
    assert max(p.y() for p in points) - min(p.y() for p in points) > 0.4 * height  # most of the view
    near = camera.distance
    window.navigation.go_to("chain A")
    assert camera.distance == pytest.approx(near)


def test_go_to_a_ligand_or_a_nucleotide_selects_it(open_window: Opener, qtbot: QtBot) -> None:
    """A ligand named (``/B:HEM``, ``resn HEM`` in the edited chain) is selected and centred on;
    every group of a name in a chain (``/A:HOH``), and the groups a combined selection holds, are
    selected too; Esc clears them with the residues."""
    window = open_window("4HHB.pdb.gz")
    atoms, coords, document = window.document.structure.atoms, window.document.model.coords, window.document
    window.navigation.go_to("A:45")
    selected = window.navigation.go_to("/B:HEM")
    haem = (atoms.resname == "HEM") & (atoms.chain == "B")
    assert selected.residues.size == 0 and len(document.selection) == 0
    assert np.array_equal(document.selected_groups, np.flatnonzero(haem)) and window.rw.selection == ["B:HEM148"]
    assert window.status.labels["pick"].text() == "selected B:HEM148; Esc clears"
    np.testing.assert_allclose(_focal(window), coords[haem].mean(axis=0), atol=1e-6)
    window.navigation.go_to("resn HEM")  # the edited chain's (A's, since A:45)
    np.testing.assert_allclose(_focal(window), coords[(atoms.resname == "HEM") & (atoms.chain == "A")].mean(axis=0),
                               atol=1e-6)
    assert window.rw.go_to("/A:HOH") == [f"A:HOH{n}" for n in atoms.resseq[(atoms.chain == "A")
                                                                         & (atoms.resname == "HOH")]]
    assert window.status.labels["pick"].text() == "selected 56 groups: A:HOH143 … A:HOH198; Esc clears"
    pocket = window.rw.go_to("resn HEM and chain A or byres resn HEM and chain A around 4")
    assert pocket[:2] == ["A:TYR42", "A:PHE43"] and pocket[-5:] == ["A:HEM142", "A:HOH144", "A:HOH159", "A:HOH166",
                                                                      "A:HOH174"]
    assert window.status.labels["pick"].text() == ("selected 16 residues: A:TYR42, A:PHE43, A:HIS45, A:PHE46 … "
                                                   "A:LEU136 and 5 groups: A:HEM142 … A:HOH174; Esc clears")
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window.plotter, Qt.Key.Key_Escape)
    assert len(document.selection) == 0 and len(document.selected_groups) == 0 and window.rw.selection == []

    window = open_window("1BNA.pdb.gz")  # DNA only: no residue of a backbone to select, its nucleotides to go to
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(window.navigation.go_to_field, "B:20")
    qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
    atoms = window.document.structure.atoms
    np.testing.assert_allclose(_focal(window), atoms.coords[(atoms.chain == "B") & (atoms.resseq == 20)].mean(axis=0),
                               atol=1e-6)
    qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(window.navigation.go_to_field, "A:500")
    qtbot.keyClick(window.navigation.go_to_field, Qt.Key.Key_Return)
    assert window.statusBar().currentMessage() == "no residue A:500 in chain A (it has no protein backbone)"
    assert window.rw.go_to("chain A")[:2] == ["A:DC1", "A:DG2"]  # a strand, selected by its chain


def test_double_click_centres_on_what_is_under_the_pointer(window: MainWindow, qtbot: QtBot) -> None:
    window.scene.set_layer(Layer.CONTROL_POINTS, False)
    row = _front_residue(window, np.arange(40, 60))
    distance = window.plotter.camera.distance
    qtbot.mouseDClick(window.plotter, Qt.MouseButton.LeftButton, pos=_widget_point(window, _ca(window, row)))
    assert list(window.document.selection) == [row]
    np.testing.assert_allclose(_focal(window), _ca(window, row), atol=1e-6)
    assert window.plotter.camera.distance == pytest.approx(distance)  # centred, not zoomed
    assert window.document.undo_stack.count() == 0


def test_a_click_on_another_chain_edits_that_chain(open_window: Opener, qtbot: QtBot) -> None:
    """4HHB: a click (no motion) on chain B's ribbon makes it the edited segment; the camera
    stays where it is (it moves only when asked: choosing the segment in the dock frames it)."""
    window = open_window("4HHB.pdb.gz")
    document = window.document
    window.scene.set_layer(Layer.CONTROL_POINTS, False)
    segment_b = next(k for k, s in enumerate(document.structure.segments) if s.chain == "B")
    rows = document.structure.segments[segment_b].residue_index
    row = _front_residue(window, rows)
    at = _widget_point(window, _ca(window, row))
    before = window.plotter.camera_position
    qtbot.mousePress(window.plotter, Qt.MouseButton.LeftButton, pos=at)
    qtbot.mouseRelease(window.plotter, Qt.MouseButton.LeftButton, pos=at)
    assert document.segment == segment_b and list(document.selection) == [row]
    assert window.plotter.camera_position == before
    assert document.undo_stack.count() == 0
    camera = window.plotter.camera_position
    qtbot.mousePress(window.plotter, Qt.MouseButton.LeftButton, pos=at)  # a real drag turns the camera only
    qtbot.mouseMove(window.plotter, at + QPoint(40, 10))
    qtbot.mouseRelease(window.plotter, Qt.MouseButton.LeftButton, pos=at + QPoint(40, 10))
    assert window.plotter.camera_position != camera and document.segment == segment_b
    combo = window.dimension_panel.segment  # chosen in the dock: framed
    combo.setFocus()
    qtbot.keyClick(combo, Qt.Key.Key_Down)
    assert document.segment == segment_b + 1
    ca = _ca(window, document.structure.segments[segment_b + 1].residue_index)
    np.testing.assert_allclose(_focal(window), (ca.min(axis=0) + ca.max(axis=0)) / 2, atol=0.5)


# ------------------------------------------------------------------ the sequence bar


def test_sequence_bar_selects_centres_and_marks_the_pick(window: MainWindow, qtbot: QtBot) -> None:
    strip = window.sequence_bar.strip
    document = window.document
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, pos=strip.cell_rect(9).center())
    assert list(document.selection) == [9]
    np.testing.assert_allclose(_focal(window), _ca(window, 9), atol=1e-6)
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.ShiftModifier,
                     pos=strip.cell_rect(14).center())
    assert list(document.selection) == list(range(9, 15))
    image = strip.grab().toImage()
    cell = strip.cell_rect(12)
    assert image.pixelColor(cell.center().x(), cell.top()).name() != image.pixelColor(
        strip.cell_rect(20).center().x(), cell.top()).name()  # the selection's frame
    index = int(window.scene.shown_control_points()[3])
    document.pick_point(index)
    image = strip.grab().toImage()
    moved, still = document.pick.residues, np.setdiff1d(np.arange(76), document.pick.residues)
    underline = [image.pixelColor(strip.cell_rect(int(k)).center().x(), strip.cell_rect(int(k)).bottom() - 1).name()
                 for k in (moved[0], still[-1])]
    assert underline[0] == "#00aaff" and underline[1] != "#00aaff"


def test_sequence_bar_follows_the_edited_segment(open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("4HHB.pdb.gz")
    strip = window.sequence_bar.strip
    window.document.set_segment(1)
    assert strip.width() >= len(window.document.structure.segments[1]) * strip.cell
    qtbot.mouseClick(strip, Qt.MouseButton.LeftButton, pos=strip.cell_rect(0).center())
    assert list(window.document.selection) == [window.document.structure.segments[1].residue_index[0]]


# ------------------------------------------------------------------ big assemblies


def test_control_points_keep_a_size_on_screen(open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("4YVS.cif.gz")
    scene = window.scene
    camera = window.plotter.camera
    height = window.plotter.renderer.GetSize()[1]

    def pixels() -> float:
        points = scene.shown_control_points()
        centre = window.document.level_curve().control_points[points].mean(axis=0)
        depth = (centre - np.array(camera.position)) @ np.array(camera.direction)
        return scene.point_radius * height / (2.0 * np.tan(np.radians(camera.view_angle) / 2.0) * depth)

    assert scene.point_radius > HANDLE_RADIUS and pixels() >= MIN_POINT_PIXELS * 0.95
    camera.zoom(0.3)
    _drawn(qtbot, window)  # the spheres are sized as a frame is drawn
    assert pixels() >= MIN_POINT_PIXELS * 0.95
    sphere = window.scene.meshes["control_points"].points[:42]
    assert np.linalg.norm(sphere - sphere.mean(axis=0), axis=1).max() == pytest.approx(scene.point_radius)
    curve = window.document.level_curve()
    shown = scene.shown_control_points()
    on_screen = np.array([_display(window, curve.control_points[k]) for k in shown], dtype=float)
    apart = np.linalg.norm(on_screen[:, None] - on_screen[None], axis=2) + 1e9 * np.eye(len(shown))
    index = int(shown[np.argmax(apart.min(axis=1))])  # the loneliest sphere: a press on its rim grabs it
    centre = curve.control_points[index]
    right = np.cross(camera.direction, camera.up)
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*_display(window, centre + 0.8 * scene.point_radius * right / np.linalg.norm(right)))
    interactor.InvokeEvent("LeftButtonPressEvent")
    interactor.InvokeEvent("LeftButtonReleaseEvent")
    assert window.document.pick is not None and window.document.pick.index == index


def test_handle_box_faces_move_in_their_plane_and_shift_keeps_one_axis(window: MainWindow) -> None:
    document = window.document
    index = int(window.scene.shown_control_points()[5])
    document.pick_point(index)
    centre = document.level_curve().control_points[index].copy()
    window.plotter.camera_position = [tuple(centre + [12.0, 9.0, 40.0]), tuple(centre), (0.0, 1.0, 0.0)]
    window.plotter.render()  # looking mostly down z: a press on the +z face enters the box there
    half = 0.5 * HANDLE_BOX * window.scene.point_radius
    axis = 2
    face = centre + [0.9 * half, -0.9 * half, half]  # on the face, the ray clear of the sphere
    interactor = window.plotter.iren.interactor
    start = _display(window, face)

    def drag(offset: tuple[int, int], shift: bool) -> np.ndarray:
        before = document.level_curve().control_points[index].copy()
        interactor.SetEventInformation(*start, 0, int(shift))
        interactor.InvokeEvent("LeftButtonPressEvent")
        interactor.SetEventInformation(start[0] + offset[0], start[1] + offset[1], 0, int(shift))
        interactor.InvokeEvent("MouseMoveEvent")
        interactor.InvokeEvent("LeftButtonReleaseEvent")
        return document.level_curve().control_points[index] - before

    moved = drag((80, 60), shift=False)
    assert np.linalg.norm(moved) > 1.0 and abs(moved[axis]) < 1e-6  # in the face's plane
    assert document.undo_stack.count() == 1 and document.undo_stack.text(0).endswith(
        f"in {'xyz'.replace('xyz'[axis], '')} at level {document.shown_level():.2f}")
    document.undo_stack.undo()
    window.plotter.render()
    moved = drag((80, 60), shift=True)
    assert np.count_nonzero(np.abs(moved) > 1e-6) == 1 and abs(moved[axis]) < 1e-6  # one axis of that plane
    along = "xyz"[int(np.flatnonzero(np.abs(moved) > 1e-6)[0])]
    assert document.undo_stack.text(0).endswith(f" along {along} at level {document.shown_level():.2f}")  # named


def test_other_chains_dimmed_hidden_and_shown(open_window: Opener) -> None:
    window = open_window("4YVS.cif.gz")
    scene = window.scene
    assert scene.others is Others.DIMMED and Others(window.display_panel.others.currentData()) is Others.DIMMED
    document = window.document
    window.scene.set_layer(Layer.CARTOON, False)  # the tube: its layout does not follow the level
    window.scene.set_layer(Layer.TUBE, True)
    tube = window.scene.meshes["tube"]
    rings = window.scene.part(TubeLayer).ring_start
    chains = [s.chain for s in document.structure.segments]
    k = next(k for k, chain in enumerate(chains) if chain != chains[document.segment])
    edited, other = (slice(rings[g] * SIDES, rings[g + 1] * SIDES) for g in (document.segment, k))
    colours = np.array(tube.point_data["colours"])
    assert colours[other].min() > colours[edited].min() + 60  # faded toward white
    points = np.array(tube.points)
    window.display_panel.others.setCurrentIndex(window.display_panel.others.findData(Others.HIDDEN))
    hidden = np.array(tube.points)
    assert np.array_equal(hidden[edited], points[edited])
    assert np.ptp(hidden[other], axis=0).max() == 0.0  # collapsed: nothing drawn
    document.set_segment(k)  # the new edited chain appears, the old one goes
    assert np.array_equal(np.array(tube.points)[other], points[other])
    assert np.ptp(np.array(tube.points)[edited], axis=0).max() == 0.0
    window.display_panel.others.setCurrentIndex(window.display_panel.others.findData(Others.SHOWN))
    assert np.array_equal(np.array(tube.points), points)
    assert np.array_equal(np.array(tube.point_data["colours"])[edited], colours[edited])  # in full colour


def test_small_entries_open_with_every_chain_shown(open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")
    assert window.scene.others is Others.SHOWN


def test_the_docks_fit_a_laptop_screen_without_scrolling(open_window: Opener, qtbot: QtBot) -> None:
    """1366 x 768 (less a panel): the level controls, the display options, the validation list
    and the Ramachandran plot each show whole in their place."""
    from PySide6.QtWidgets import QDockWidget, QScrollArea

    window = open_window("4HHB.pdb.gz")
    window.resize(1366, 728)
    qtbot.wait(50)
    docks = {dock.windowTitle(): dock for dock in window.findChildren(QDockWidget)}
    for title in ("Ribbon dimension", "Display", "Validation", "Ramachandran"):
        docks[title].raise_()
        qtbot.wait(20)
        area = docks[title].widget()
        assert isinstance(area, QScrollArea)
        assert not area.verticalScrollBar().isVisible(), title
    assert window.plotter.width() >= 800 and window.plotter.height() >= 450


def test_reset_view_twice_gives_the_same_view(window: MainWindow) -> None:
    """Reset View fits the structure and comes a little closer by moving the camera, so a
    second reset (or a session reopened) shows it at the same size (#35: 14% closer each time)."""
    window.navigation.reset_view_action.trigger()
    first = np.array([tuple(v) for v in window.plotter.camera_position])
    window.plotter.camera.Zoom(1.5)  # whatever zoom came since
    window.navigation.reset_view_action.trigger()
    assert np.allclose([tuple(v) for v in window.plotter.camera_position], first, atol=1e-6)
    assert window.plotter.camera.view_angle == 30.0
