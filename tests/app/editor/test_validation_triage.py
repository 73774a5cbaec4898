"""Triage in the validation dock, in a shown window driven by mouse and key events: what the file
had is not shown unless severe, what an edit makes is shown and marked new, the filter changes
the list and the markers, and a click on a row centres the view on the problem."""

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QCheckBox
from pytestqt.qtbot import QtBot
from test_validation_panel import LEVEL, OFFSET, _press_point
from test_window import _mouse_drag, _window

from app.editor.docks.validation import LISTED
from app.editor.main_window import MainWindow
from app.editor.persistence.recording import recording, replay
from app.editor.scene.layers.validation_markers import MARKED
from core.geometry.triage import EDITED_OR_SEVERE, SEVERE, TriageFilter

DATA = Path(__file__).resolve().parents[2] / "data"


def _markers(window: MainWindow) -> int:
    return window.markers.mesh.n_points


def _marked(flags: tuple, *, kinds: tuple[str, ...] = MARKED, above: float = 0.0) -> list:
    return [f for f in flags if f.kind in kinds and f.severity > above]


def _click_box(qtbot: QtBot, box: QCheckBox) -> None:
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton, pos=QPoint(box.height() // 2, box.height() // 2))


def _click_row(qtbot: QtBot, window: MainWindow, row: int) -> None:
    tree = window.validation_panel.offenders
    item = tree.topLevelItem(row)
    tree.scrollToItem(item)
    qtbot.mouseClick(tree.viewport(), Qt.MouseButton.LeftButton, pos=tree.visualItemRect(item).center())


def _segment_of(window: MainWindow, flag) -> set[int]:
    starts = [s.residue_index[0] for s in window.document.structure.segments]
    return {int(k) for k in np.searchsorted(starts, flag.residues, side="right") - 1}


@pytest.mark.parametrize("name", ["4HHB.pdb.gz", "1TIM.pdb.gz"])
def test_a_file_as_read_shows_only_its_severe_problems(qtbot: QtBot, name: str) -> None:
    window = _window(qtbot, DATA / name)
    report, panel = window.validation.report, window.validation_panel
    severe = _marked(report.flags, above=SEVERE)
    assert 0 < _markers(window) == len(severe) < 0.4 * len(_marked(report.flags))  # 4HHB: 493 of 1300
    np.testing.assert_allclose(window.markers.mesh.points, [f.position for f in severe])
    shown = [f for f in report.flags if f.severity > SEVERE]
    assert panel.listed == tuple(shown[:LISTED])
    assert panel.shown.text() == f"{len(shown)} of {len(report.flags)} shown"
    rows = panel.offenders.topLevelItemCount()
    assert rows == min(len(shown), LISTED) + (len(shown) > LISTED)
    if len(shown) > LISTED:
        assert panel.offenders.topLevelItem(rows - 1).text(2) == f"… and {len(shown) - LISTED} more"
    first = panel.offenders.topLevelItem(0)
    assert first.text(1) == "" and not first.font(0).bold()  # as read
    for kind, label in panel.count_labels.items():  # totals, nothing new
        assert label.text().startswith(f"{report.counts[kind]} of {report.checked[kind]} ")


def test_filters_change_the_list_and_the_markers(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "4HHB.pdb.gz")
    report, panel = window.validation.report, window.validation_panel
    clash_count = panel.count_labels["clash"].text()
    qtbot.keyClick(panel.scope, Qt.Key.Key_Down)  # edits only: none yet
    assert _markers(window) == 0 and panel.offenders.topLevelItemCount() == 0
    qtbot.keyClick(panel.scope, Qt.Key.Key_Down)  # everything
    assert _markers(window) == len(_marked(report.flags)) == 1300
    assert panel.listed == report.flags[:LISTED]
    qtbot.keyClick(panel.severity, Qt.Key.Key_Down)
    qtbot.keyClick(panel.severity, Qt.Key.Key_Down)  # severity > 4
    assert panel.severity.currentText() == "severity > 4"
    assert _markers(window) == len(_marked(report.flags, above=4.0)) == 60
    assert panel.listed == tuple(f for f in report.flags if f.severity > 4.0)
    _click_box(qtbot, panel.kind_boxes["clash"])
    assert window.validation.triage_filter.kinds == frozenset(MARKED[:5]) | {"ramachandran"}
    no_clash = _marked(report.flags, kinds=MARKED[:5], above=4.0)
    assert _markers(window) == len(no_clash) < 60 and panel.listed == tuple(no_clash)
    np.testing.assert_allclose(window.markers.mesh.points, [f.position for f in no_clash])
    assert panel.count_labels["clash"].text() == clash_count  # the counts keep their totals
    for kind in MARKED[:5]:
        _click_box(qtbot, panel.kind_boxes[kind])
    assert _markers(window) == 0 and panel.offenders.topLevelItemCount() == 0
    qtbot.keyClick(panel.scope, Qt.Key.Key_Home)  # back to edits and severe ones, with only Ramachandran kept
    assert panel.scope.currentData() == EDITED_OR_SEVERE
    assert panel.shown.text() == f"0 of {len(report.flags)} shown"  # 4HHB's one outlier is mild

    window.validation.set_triage(TriageFilter(min_severity=3.0))  # as a script would: the widgets follow
    assert panel.severity.currentText() == "severity > 3" and panel.scope.currentData() == EDITED_OR_SEVERE
    assert all(box.isChecked() for box in panel.kind_boxes.values())
    assert _markers(window) == len(_marked(report.flags, above=3.0))


def test_an_edit_s_problems_are_shown_as_new_until_undone(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.document.set_level(LEVEL)
    window.plotter.render()
    panel = window.validation_panel
    assert _markers(window) == 0 and panel.offenders.topLevelItemCount() == 0  # its one clash is mild
    _click_box(qtbot, panel.on_release)
    assert not window.document.regularize_on_release
    _mouse_drag(window, _press_point(window), OFFSET)
    triaged = window.validation.triaged
    made = [f for f in window.validation.report.flags if f.kind != "clash" or f.where != "A:ARG72 O / A:ARG72 CG"]
    assert len(made) > 10 and any(f.severity < SEVERE for f in made)
    assert set(triaged.flags) >= set(made)
    assert {n for f, n in zip(triaged.flags, triaged.novelty) if f in made} == {"new"}
    assert _markers(window) == len(_marked(triaged.flags)) >= len(_marked(tuple(made)))
    rows = [panel.offenders.topLevelItem(k) for k in range(panel.offenders.topLevelItemCount())]
    assert {row.text(1) for row in rows if row.text(2) in {f.where for f in made}} == {"new"}
    assert all(row.font(2).bold() for row in rows if row.text(1))
    new_bonds = sum(f.kind == "peptide_bond" for f in made)
    assert panel.count_labels["peptide_bond"].text().startswith(f"{new_bonds} new, {new_bonds} of 75 junctions")

    replay(window.document, recording(window.document))  # a restored session: the baseline is still the file
    assert window.validation.triaged.new == triaged.new and len(window.validation.triaged.flags) == len(triaged.flags)

    window.editing.undo_action.trigger()
    assert set(window.validation.triaged.novelty) <= {"as read"} and _markers(window) == 0
    assert panel.offenders.topLevelItemCount() == 0
    assert panel.count_labels["peptide_bond"].text() == "0 of 75 junctions"


def test_clicking_a_row_centres_the_view_on_the_problem(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "4HHB.pdb.gz")
    document, panel, camera = window.document, window.validation_panel, window.plotter.camera
    flag = panel.listed[0]  # B:VAL1-B:HIS2, not in the first segment (chain A)
    assert document.segment == 0 and _segment_of(window, flag) == {1}
    with qtbot.waitSignal(panel.flagActivated) as activated:
        _click_row(qtbot, window, 0)
    assert activated.args == [flag]
    assert document.segment == 1  # the segment framed first, then centred on the flag
    np.testing.assert_allclose(camera.focal_point, flag.position, atol=1e-9)
    assert list(document.selection) == sorted(flag.residues)  # and its residues selected
    atoms = np.isin(document.structure.atom_residue, flag.residues)  # their atoms shown (#35), zoomed in on
    shown = window.scene.meshes["selection_atoms"]
    np.testing.assert_allclose(shown.points, document.model.coords[atoms], atol=1e-4)
    assert shown.n_lines > atoms.sum() / 2 and window.scene.actors["selection_atoms"].GetVisibility()  # bonds
    reach = np.linalg.norm(document.model.coords[atoms] - flag.position, axis=1).max() + 4.0
    assert camera.distance <= 3.0 * reach / np.tan(np.radians(camera.view_angle) / 2.0) + 1e-6

    def view() -> np.ndarray:
        return np.subtract(camera.position, camera.focal_point)

    def unit(v: np.ndarray) -> np.ndarray:
        return v / np.linalg.norm(v)

    same = next(k for k, f in enumerate(panel.listed) if k > 0 and _segment_of(window, f) == {1})
    other = next(k for k, f in enumerate(panel.listed) if not f.residues)  # a clash inside a haem
    for row in (same, other):
        before = view()
        _click_row(qtbot, window, row)
        assert document.segment == 1
        np.testing.assert_allclose(camera.focal_point, panel.listed[row].position, atol=1e-9)
        np.testing.assert_allclose(unit(view()), unit(before), atol=1e-9)  # same direction,
        assert np.linalg.norm(view()) <= np.linalg.norm(before) + 1e-9  # never further away

    focal = camera.focal_point
    _click_row(qtbot, window, panel.offenders.topLevelItemCount() - 1)  # "… and N more"
    assert camera.focal_point == focal
