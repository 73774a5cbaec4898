"""``rw``, the scripting API: what the mouse and the menus do, for scripts and the Python console."""

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QTabBar
from pytestqt.qtbot import QtBot
from test_window import _drag_control_point, _window

from app.editor.persistence import journal
from app.main import main

DATA = Path(__file__).resolve().parents[2] / "data"


def test_move_is_what_a_drag_of_the_control_point_does(qtbot: QtBot) -> None:
    dragged = _window(qtbot, DATA / "1UBQ.pdb.gz")
    before = dragged.document.level_curve().control_points.copy()
    index = _drag_control_point(dragged, 5, (40, 25))  # regularized on release, as by default
    delta = dragged.document.level_curve().control_points[index] - before[index]
    scripted = _window(qtbot, DATA / "1UBQ.pdb.gz")
    scripted.rw.move(index, delta)
    assert scripted.rw.history() == dragged.rw.history()
    assert np.allclose(scripted.rw.coords(), dragged.rw.coords(), atol=1e-9, rtol=0)
    scripted.document.set_regularization(on_release=False)
    scripted.rw.move(index, delta)
    assert scripted.rw.history()[1] == 2 and not np.allclose(scripted.rw.coords(), dragged.rw.coords(), atol=1e-3)


def test_state_edits_and_history(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "1AYE.pdb.gz")
    rw = window.rw
    original = rw.coords()
    rw.level = 3.4
    assert rw.level == 3.4 == window.document.level
    assert window.dimension_panel.spin.value() == pytest.approx(3.4)  # the slider follows
    assert rw.points().shape == (len(window.document.level_curve().control_points), 3)
    labels = window.document.labels()  # 1AYE: insertion codes ('A:GLU5A')
    rw.tug(labels[40], [0.0, 0.0, 2.0])
    rw.tug(labels[60].split(":")[1].lstrip("ABCDEFGHIJKLMNOPQRSTUVWXYZ"), [0.0, 1.0, 0.0])  # '64A': a number
    rw.tug(10, [1.0, 0.0, 0.0])
    names, index = rw.history()
    assert index == 3 and [name.split(" at level")[0] for name in names] == [
        f"Tug curve at {labels[k]}" for k in (40, 60, 10)]
    for _ in range(3):
        rw.undo()
    assert np.array_equal(rw.coords(), original)
    rw.redo()
    assert rw.history()[1] == 1
    with pytest.raises(ValueError, match="no residue"):
        rw.tug("A:XYZ9999", [1, 0, 0])
    number = labels[60].split(":")[1].lstrip("ABCDEFGHIJKLMNOPQRSTUVWXYZ")  # one residue syntax everywhere
    for typed in (f"A:{number}", f"/A:{number}", f"A/{number}/", labels[40].split(":")[1][3:]):
        rw.tug(typed, [0.5, 0.0, 0.0])
    assert [name.split(" at level")[0] for name in rw.history()[0][1:5]] == [
        f"Tug curve at {labels[k]}" for k in (60, 60, 60, 40)]
    for _ in range(4):
        rw.undo()
    with pytest.raises(ValueError, match="is not one residue of the edited segment"):
        rw.tug("A:40-45", [1, 0, 0])
    with pytest.raises(IndexError):
        rw.move(10_000, [1, 0, 0])
    with pytest.raises(ValueError, match="three finite numbers"):
        rw.move(2, [1, 0])
    window.document.undo_stack.setClean()
    rw.open(DATA / "4HHB.pdb.gz")  # four chains
    rw.segment = 2
    assert window.document.segment == rw.segment == 2 and window.document.labels()[0] == "B:ASN80"  # B, second part
    with pytest.raises(ValueError, match="segment must be"):
        rw.segment = 9


def test_export_leaves_the_document_and_save_takes_the_file(qtbot: QtBot, tmp_path: Path) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    rw = window.rw
    rw.move(5, [3.0, 0.0, 0.0])
    rw.export(tmp_path / "copy.cif")
    assert window.document.modified and window.document.path.name == "1UBQ.pdb.gz"
    assert (tmp_path / "copy.cif").read_text().startswith("data_")
    with pytest.raises(FileExistsError):
        rw.export(tmp_path / "copy.cif")
    rw.save(tmp_path / "saved.pdb")
    assert not window.document.modified and window.document.path == tmp_path / "saved.pdb"
    with pytest.raises(FileExistsError):
        rw.save(tmp_path / "saved.pdb")


def test_screenshot_of_a_given_size(qtbot: QtBot, tmp_path: Path) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.rw.screenshot(tmp_path / "view.png", 320, 240)
    image = QImage(str(tmp_path / "view.png"))
    assert (image.width(), image.height()) == (320, 240)
    colours = {image.pixel(x, y) for x in range(0, 320, 8) for y in range(0, 240, 8)}
    assert len(colours) > 20  # a drawing, not a blank frame
    window.rw.screenshot(tmp_path / "clear.png", 320, supersample=4, transparent=True)  # as File ▸ Export Image
    image = QImage(str(tmp_path / "clear.png"))
    view_width, view_height = window.plotter.window_size
    assert (image.width(), image.height()) == (320, round(320 * view_height / view_width))
    assert image.hasAlphaChannel() and image.pixelColor(0, image.height() - 1).alpha() == 0
    with pytest.raises(ValueError, match="supersampling must be one of 1, 2, 4"):
        window.rw.screenshot(tmp_path / "odd.png", supersample=3)


def test_a_script_runs_in_the_editor_with_a_screenshot(tmp_path: Path, state_home: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "bend.py"
    script.write_text("rw.level = 3\nrw.move(4, [4, 0, 0])\nprint(rw.history())\n"
                      f"rw.save_session({str(tmp_path / 'bent')!r})\n")
    shot = tmp_path / "shot.png"
    assert main([str(DATA / "1UBQ.pdb.gz"), "--script", str(script), "--screenshot", str(shot)]) == 0
    out, err = capsys.readouterr()
    assert "Move point 4 at level 3.00" in out and QImage(str(shot)).width() > 500
    kept = journal.orphans(state_home)
    assert len(kept) == 1 and str(kept[0]) in err and "--recover" in err  # unsaved edits stay in the journal
    assert (tmp_path / "bent.rwsession").exists()


def test_a_failing_script_prints_its_traceback_and_exits_1(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                           questions) -> None:
    script = tmp_path / "broken.py"
    script.write_text("rw.level = 2\n\ndef bend():\n    rw.move(99999, [1, 0, 0])\n\nbend()\n")
    assert main([str(DATA / "1UBQ.pdb.gz"), "--script", str(script)]) == 1
    err = capsys.readouterr().err
    assert f'File "{script}", line 6' in err and f'File "{script}", line 4, in bend' in err
    assert "IndexError: control point 99999 does not exist" in err
    assert "launch.py" not in err and not questions.asked  # no dialog waits for a person
    script.write_text("rw.quit(discard=True)\nraise SystemExit(3)\n")
    assert main([str(DATA / "1UBQ.pdb.gz"), "--script", str(script)]) == 3
    assert main([str(DATA / "1UBQ.pdb.gz"), "--script", str(tmp_path / "missing.py")]) == 1
    assert "cannot read" in capsys.readouterr().err


@pytest.mark.parametrize(("ending", "status", "said"), [
    ("sys.exit()", 0, ""), ("sys.exit(4)", 4, ""), ("sys.exit(256)", 1, ""), ("sys.exit(-1)", 1, ""),
    ("sys.exit('the map is missing')", 1, "the map is missing"),
])
def test_a_script_exit_status_is_one_the_shell_reads_as_given(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                              ending: str, status: int, said: str) -> None:
    """sys.exit(256) used to end the editor with status 0 (256 modulo 256), as a success (#37)."""
    script = tmp_path / "ends.py"
    script.write_text(f"import sys\nrw.quit(discard=True)\n{ending}\n")
    assert main([str(DATA / "1UBQ.pdb.gz"), "--script", str(script)]) == status
    assert capsys.readouterr().err.strip().endswith(said)


def test_the_python_console_drives_the_editor(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    assert not window.console_dock.isVisible()
    console_action = next(a for a in window.menuBar().actions()[2].menu().actions() if a.text() == "Python Console")
    console_action.trigger()
    assert window.console_dock.isVisible()
    shown = [{bar.tabText(k) for k in range(bar.count())} for bar in window.findChildren(QTabBar) if bar.isVisible()]
    assert not any(a < b for a in shown for b in shown)  # no stale tab bar left over by Qt above the console
    qtbot.keyClicks(window.console.input, "rw.level = 2.5")
    qtbot.keyClick(window.console.input, Qt.Key.Key_Return)
    qtbot.keyClicks(window.console.input, "rw.move(3, np.array([2.0, 0, 0])); rw.history()")
    qtbot.keyClick(window.console.input, Qt.Key.Key_Return)
    assert window.document.level == 2.5 and window.document.undo_stack.count() == 1
    assert "Move point 3 at level 2.50" in window.console.output.toPlainText()


def test_go_to_is_what_the_go_to_field_does(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "4HHB.pdb.gz")
    rw = window.rw
    assert rw.go_to("B:40-42") == rw.selection == ["B:ARG40", "B:PHE41", "B:PHE42"]
    assert window.document.structure.segments[rw.segment].chain == "B"
    typed = _window(qtbot, DATA / "4HHB.pdb.gz")
    typed.navigation.go_to_field.setText("B:40-42")
    typed.navigation.go_to_field.returnPressed.emit()  # as Enter in the field
    assert typed.rw.selection == rw.selection and typed.rw.segment == rw.segment
    assert np.allclose(typed.plotter.camera.focal_point, window.plotter.camera.focal_point)
    with pytest.raises(ValueError, match="no residue B:400"):
        rw.go_to("B:400")
