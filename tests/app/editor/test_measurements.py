"""Labels and measurements (#34): atoms picked with the mouse or named from ``rw``, drawn in the
view and listed in their dock, their values following a drag, kept in sessions; values as
gemmi computes them."""

from collections.abc import Callable
from pathlib import Path

import gemmi
import numpy as np
import pytest
from PySide6.QtCore import Qt
from pytestqt.qtbot import QtBot

from app.editor.main_window import MainWindow
from app.editor.scene.layers.base import Layer

Opener = Callable[[str], MainWindow]


def _display(window: MainWindow, point: np.ndarray) -> tuple[int, int]:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return round(x), round(y)


def _click(window: MainWindow, point: np.ndarray) -> None:
    """A left click at ``point`` (Å) on the view's VTK interactor, as the mouse gives it."""
    interactor = window.plotter.iren.interactor
    interactor.SetEventInformation(*_display(window, point))
    interactor.InvokeEvent("LeftButtonPressEvent")
    interactor.InvokeEvent("LeftButtonReleaseEvent")


def _position(coords: np.ndarray, row: int) -> gemmi.Position:
    return gemmi.Position(*map(float, coords[row]))


def _texts(window: MainWindow) -> list[str]:
    return [actor.GetInput() for name, actor in window.scene.actors.items() if name.startswith("measure_text_")]


def test_a_distance_picked_with_the_mouse_follows_a_drag(open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("1UBQ.pdb.gz")
    document = window.document
    document.set_regularization(on_release=False)
    window.display_panel.layer_boxes[Layer.ATOMS].setChecked(True)
    window.display_panel.layer_boxes[Layer.CONTROL_POINTS].setChecked(False)  # (no sphere in front of an atom)
    atoms = document.structure.atoms
    lysines = np.flatnonzero((atoms.resname == "LYS") & (atoms.name == "NZ"))
    towards = -np.array(window.plotter.camera.GetDirectionOfProjection())
    first, second = map(int, lysines[np.argsort(document.model.coords[lysines] @ towards)[::-1][:2]])  # the frontmost
    residue = int(document.structure.atom_residue[first])
    window.measuring.tools.actions()[1].trigger()  # View ▸ Measure Distance
    assert window.statusBar().currentMessage() == "Distance: click atom 1 of 2 (Esc stops)"
    _click(window, document.model.coords[first])
    assert window.statusBar().currentMessage() == "Distance: click atom 2 of 2 (Esc stops)"
    _click(window, document.model.coords[second])
    items = document.measurements.items
    assert len(items) == 1 and items[0].atoms == (first, second) and len(document.selection) == 0
    expected = _position(document.model.coords, first).dist(_position(document.model.coords, second))
    table = window.measurements_panel.table
    assert table.rowCount() == 1
    assert table.item(0, 1).text() == f"A:LYS{atoms.resseq[first]} NZ – A:LYS{atoms.resseq[second]} NZ"
    assert table.item(0, 2).text() == _texts(window)[0] == f"{expected:.2f} Å"

    before = document.model.coords[first].copy()
    window.rw.tug(residue, (3.0, 0.0, 0.0))  # the first lysine moves: the value follows in the view and the dock
    moved = _position(document.model.coords, first).dist(_position(document.model.coords, second))
    assert np.linalg.norm(document.model.coords[first] - before) > 1.0 and f"{moved:.2f}" != f"{expected:.2f}"
    assert table.item(0, 2).text() == _texts(window)[0] == f"{moved:.2f} Å"
    lines = window.scene.meshes["measure_lines"]  # dashes on the line between the atoms as they are now
    a, b = document.model.coords[[first, second]]
    along = (np.asarray(lines.points) - a) @ (b - a) / np.dot(b - a, b - a)
    np.testing.assert_allclose(np.asarray(lines.points), a + along[:, None] * (b - a), atol=1e-4)
    assert 0 < along.min() < 0.1 and 0.9 < along.max() < 1 and lines.n_lines == len(along) // 2 >= 5
    window.rw.undo()
    assert table.item(0, 2).text() == f"{expected:.2f} Å"

    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window.plotter, Qt.Key.Key_Escape)  # the tool stops: a click selects again
    assert window.measuring.wanted == 0
    _click(window, document.model.coords[first])
    assert len(document.measurements.items) == 1 and list(document.selection) == [residue]


def test_labels_angles_and_dihedrals_from_rw_are_gemmis_and_come_back_with_the_session(
        open_window: Opener, tmp_path: Path) -> None:
    window = open_window("4HHB.pdb.gz")
    rw, document = window.rw, window.document
    assert rw.measure("B:48 CA") is None  # a label
    assert rw.measure("C:LYS40") is None  # a residue's label
    angle = rw.measure("A:45 N", "A:45 CA", "A:45 C")
    phi = rw.measure("/A:44@C", "A/45/N", "chain A and resi 45 and name CA", "A:HIS45 C")
    coords = document.model.coords
    rows = [m.atoms for m in document.measurements.items]
    p = [_position(coords, row) for row in rows[3]]
    assert angle == pytest.approx(np.degrees(gemmi.calculate_angle(*[_position(coords, r) for r in rows[2]])))
    assert phi == pytest.approx(np.degrees(gemmi.calculate_dihedral(*p)))
    assert rw.measurements == ["B:LEU48 CA", "C:LYS40", f"A:HIS45 N – A:HIS45 CA – A:HIS45 C: {angle:.1f}°",
                               f"A:PRO44 C – A:HIS45 N – A:HIS45 CA – A:HIS45 C: {phi:.1f}°"]
    assert {"B:LEU48 CA", "C:LYS40"} <= set(_texts(window))
    with pytest.raises(ValueError, match="no atom XX in A:HIS45"):
        rw.measure("A:45 XX", "A:45 CA")
    with pytest.raises(ValueError, match="1 to 4 different atoms"):
        rw.measure("A:45 CA", "A:45 CA")
    iron = rw.measure("/A:HEM@FE", "A:87 NE2")  # a ligand's atom, typed as ChimeraX users do
    assert 1.9 < iron < 2.4 and rw.measurements[-1] == f"A:HEM142 FE – A:HIS87 NE2: {iron:.2f} Å"
    rw.measure("A:HEM142 FE")  # and labelled
    assert rw.measurements[-1] == "A:HEM142 FE"
    rw.measure("/B:HEM")  # the whole group labelled, at its centre: the iron
    assert rw.measurements[-1] == "B:HEM148"
    assert document.structure.atoms.name[document.measurements.items[-1].atoms[0]] == "FE"
    for _ in range(3):
        window.measurements_panel.table.selectRow(len(rw.measurements) - 1)
        window.measurements_panel.delete.click()
    saved = window.sessions.write_session(tmp_path / "measured")
    window.measurements_panel.table.selectRow(0)
    window.measurements_panel.delete.click()
    assert len(rw.measurements) == 3
    assert window.sessions.open_session(saved)
    assert rw.measurements[:2] == ["B:LEU48 CA", "C:LYS40"] and len(rw.measurements) == 4
    rw.open(Path(__file__).resolve().parents[2] / "data" / "1UBQ.pdb.gz")  # another structure: none
    assert rw.measurements == [] and window.measurements_panel.table.rowCount() == 0


def test_a_residue_clicked_with_the_label_tool_is_labelled(open_window: Opener) -> None:
    window = open_window("1UBQ.pdb.gz")  # the cartoon only: a click names a residue
    document = window.document
    window.display_panel.layer_boxes[Layer.CONTROL_POINTS].setChecked(False)
    window.measuring.tools.actions()[0].trigger()  # View ▸ Label
    assert window.statusBar().currentMessage() == "Label: click an atom (Esc stops)"
    towards = -np.array(window.plotter.camera.GetDirectionOfProjection())
    front = int(np.argmax(document.model.coords[document.ca_rows] @ towards))  # the frontmost: nothing hides it
    _click(window, document.model.coords[document.ca_rows[front]])
    label = document.structure.segments[0].labels[front]
    assert window.rw.measurements == [label] and _texts(window) == [label]
    assert window.measuring.wanted == 1  # still labelling


def test_the_residues_of_a_binding_site_are_labelled_at_once(open_window: Opener, qtbot: QtBot) -> None:
    """Go to Residue selects the haem pocket of chain A; *Label Selection* labels each of its
    residues at its Cα and its waters, in one change, and again only those not labelled yet."""
    window = open_window("4HHB.pdb.gz")
    action = window.measuring.label_selection_action
    action.trigger()  # nothing selected: it says how to select
    assert "Select residues or a ligand first" in window.statusBar().currentMessage() and window.rw.measurements == []
    pocket = window.rw.go_to("byres resn HEM and chain A around 4")
    changes: list[int] = []
    window.document.measurements.changed.connect(lambda: changes.append(1))
    action.trigger()
    assert window.rw.measurements == pocket and sorted(_texts(window)) == sorted(pocket) and changes == [1]
    assert window.measurements_panel.table.rowCount() == len(pocket) == 20
    assert pocket[-4:] == ["A:HOH144", "A:HOH159", "A:HOH166", "A:HOH174"]  # in the pocket too, as PyMOL's byres
    window.rw.go_to("A:85-89")  # two of them are in the pocket already
    action.trigger()
    added = window.rw.measurements[len(pocket):]
    assert added == [label for label in window.rw.selection if label not in pocket] and len(added) == 3
    everything = window.rw.go_to("all")  # every residue, haem and water: more labels than the view can show
    action.trigger()
    assert window.statusBar().currentMessage() == (f"{len(everything) - len(pocket) - 3} labels would hide the "
                                                   "molecule: select fewer residues (at most 500 at once)")
    assert len(everything) > 700
    assert len(window.rw.measurements) == len(pocket) + 3


def test_the_polar_contacts_of_a_residue_are_measured_at_once(open_window: Opener) -> None:
    """3PTB: Asp189 at the bottom of trypsin's pocket, selected with Go to Residue; *Show Polar
    Contacts* measures its hydrogen-bonding distances, the salt bridge to benzamidine among
    them, in one change; asked again, it adds none."""
    window = open_window("3PTB.pdb.gz")
    action, rw = window.measuring.contacts_action, window.rw
    window.rw.go_to("A:189")
    changes: list[int] = []
    window.document.measurements.changed.connect(lambda: changes.append(1))
    action.trigger()
    measured = rw.measurements
    assert {"A:ASP189 OD1 – A:BEN1 N1: 2.92 Å", "A:ASP189 OD2 – A:BEN1 N2: 2.87 Å"} <= set(measured) and changes == [1]
    assert all(" – " in item and "A:ASP189" in item for item in measured)  # each from Asp189 to another
    assert "2.92 Å" in _texts(window) and "2.87 Å" in _texts(window)
    assert window.statusBar().currentMessage() == (f"{len(measured)} polar contacts (N and O 3.5 Å apart or nearer) "
                                                   "of A:ASP189")
    assert rw.selection == ["A:VAL17", "A:ASP189", "A:SER190", "A:ALA221A", "A:GLY226", "A:BEN1"]  # what it reaches
    action.trigger()
    assert rw.measurements[:len(measured)] == measured


def test_a_ligand_is_selected_and_its_hydrogen_bonds_measured(open_window: Opener) -> None:
    """3PTB: benzamidine selected by name (``resn BEN``) or by a click on one of its atoms;
    *Show Polar Contacts* measures its hydrogen bonds to trypsin (the salt bridge to Asp189
    among them), and the residues at their other ends join the selection, their atoms drawn."""
    window = open_window("3PTB.pdb.gz")
    rw, document = window.rw, window.document
    atoms = document.structure.atoms
    benzamidine = np.flatnonzero(atoms.resname == "BEN")
    window.scene.centre_on(document.model.coords[benzamidine].mean(axis=0))
    window.plotter.camera.zoom(4.0)
    window.plotter.render()
    towards = -np.array(window.plotter.camera.GetDirectionOfProjection())
    front = benzamidine[np.argmax(document.model.coords[benzamidine] @ towards)]
    _click(window, document.model.coords[front])
    assert rw.selection == ["A:BEN1"] and np.array_equal(document.selected_groups, benzamidine)
    document.select([])
    assert rw.go_to("resn BEN") == ["A:BEN1"]
    window.measuring.label_selection_action.trigger()
    assert rw.measurements == ["A:BEN1"]
    window.measuring.contacts_action.trigger()
    measured = rw.measurements[1:]
    assert {"A:ASP189 OD1 – A:BEN1 N1: 2.92 Å", "A:ASP189 OD2 – A:BEN1 N2: 2.87 Å"} <= set(measured)
    assert all(item.endswith(" Å") and "A:BEN1 N" in item for item in measured)
    partners = {item.split(" ")[0] for item in measured}
    assert set(rw.selection) == partners | {"A:BEN1"} and {"A:ASP189", "A:GLY219"} <= partners
    assert window.statusBar().currentMessage() == (f"{len(measured)} polar contacts (N and O 3.5 Å apart or nearer) "
                                                   "of A:BEN1")
    drawn = np.asarray(window.scene.meshes["selection_atoms"].points)
    asp189 = document.model.coords[np.isin(document.structure.atom_residue, document.selection[:1])]
    for atom in np.concatenate([asp189, document.model.coords[benzamidine]]):  # both ends' atoms drawn
        assert np.linalg.norm(drawn - atom, axis=1).min() < 1e-3


def test_a_label_the_clip_slab_leaves_out_is_not_drawn(open_window: Opener, qtbot: QtBot) -> None:
    """Labels are drawn over the molecule, not clipped with it: the one of a residue outside the
    slab (Ctrl+K) is hidden, as PyMOL hides it, and shown again with the slab off."""
    window = open_window("1TIM.pdb.gz")
    rw, camera = window.rw, window.plotter.renderer.GetActiveCamera()
    centre = np.array(camera.GetFocalPoint())
    towards = np.array(camera.GetDirectionOfProjection())
    document = window.document
    depth = (document.model.coords[document.ca_rows] - centre) @ towards  # along the view, from its centre
    near, far = int(np.argmin(np.abs(depth))), int(np.argmax(np.abs(depth)))
    assert abs(depth[far]) > 20.0
    for row in (near, far):
        rw.measure(document.structure.residue_label(row))
    texts = [window.scene.actors[f"measure_text_{k}"] for k in range(2)]
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    for shown in ([True, False], [True, True]):  # a slab 10 Å either side, then none
        frames = window.plotter.frames
        qtbot.keyClick(window.plotter, Qt.Key.Key_K, Qt.KeyboardModifier.ControlModifier)
        qtbot.waitUntil(lambda frames=frames: window.plotter.frames > frames)
        assert [bool(text.GetVisibility()) for text in texts] == shown


def test_a_metal_sites_bonds_are_measured_with_the_polar_contacts(open_window: Opener) -> None:
    """1AYE: carboxypeptidase's zinc selected; *Show Polar Contacts* measures its bonds to
    His69, Glu72 (both oxygens), His196 and a water, as the file's LINK records give them,
    and they join the selection."""
    window = open_window("1AYE.pdb.gz")
    rw = window.rw
    assert rw.go_to("resn ZN") == ["A:ZN400"]
    window.measuring.contacts_action.trigger()
    assert rw.measurements == ["A:HIS69 ND1 – A:ZN400 ZN: 2.11 Å", "A:GLU72 OE1 – A:ZN400 ZN: 2.08 Å",
                               "A:GLU72 OE2 – A:ZN400 ZN: 2.11 Å", "A:HIS196 ND1 – A:ZN400 ZN: 2.12 Å",
                               "A:ZN400 ZN – A:HOH401 O: 1.98 Å"]
    assert window.statusBar().currentMessage() == ("0 polar contacts (N and O 3.5 Å apart or nearer) and 5 metal "
                                                   "bonds of A:ZN400")
    assert rw.selection == ["A:HIS69", "A:GLU72", "A:HIS196", "A:ZN400", "A:HOH401"]


def test_a_pockets_contacts_join_its_ligand_its_waters_and_its_residues(open_window: Opener) -> None:
    """3PTB: benzamidine and its pocket selected together (waters included, as PyMOL's byres):
    the ligand's hydrogen bonds to the selected residues and waters are measured with the
    pocket's contacts to the rest, but none between two selected residues."""
    window = open_window("3PTB.pdb.gz")
    rw, document = window.rw, window.document
    pocket = rw.go_to("resn BEN or byres resn BEN around 4")
    assert {"A:BEN1", "A:HOH416", "A:ASP189"} <= set(pocket)
    residues = set(document.structure.residue_labels(document.selection))
    window.measuring.contacts_action.trigger()
    measured = rw.measurements
    assert {"A:ASP189 OD1 – A:BEN1 N1: 2.92 Å", "A:BEN1 N2 – A:HOH416 O: 3.13 Å"} <= set(measured)
    ends = [{end.split(" ")[0] for end in item.rsplit(":", 1)[0].split(" – ")} for item in measured]
    assert not any(pair <= residues and len(pair) == 2 for pair in ends)  # none between two selected residues
    assert any(len(pair & set(pocket)) == 1 for pair in ends)  # and the pocket's to the rest
