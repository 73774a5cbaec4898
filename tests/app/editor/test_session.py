"""Session files: the structure as read, the undo history at its position and the view, bit for bit."""

import shutil
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QFileDialog, QMessageBox
from pytestqt.qtbot import QtBot
from test_window import _window

from app.editor.main_window import MainWindow
from app.editor.persistence import records
from app.editor.scene.molecule import Colouring
from app.editor.scene.scene import Layer
from app.main import main

DATA = Path(__file__).resolve().parents[2] / "data"
PROTEINS = sorted(p for p in DATA.glob("*.gz") if p.name != "1BNA.pdb.gz")  # 1BNA: DNA only


def _states(window: MainWindow) -> list[np.ndarray]:
    """The coordinates at every position of the undo history (the stack left where it was)."""
    stack, states = window.document.undo_stack, []
    index = stack.index()
    for k in range(stack.count() + 1):
        stack.setIndex(k)
        states.append(window.document.model.coords.copy())
    stack.setIndex(index)
    return states


@pytest.mark.parametrize("path", PROTEINS, ids=[p.name.split(".")[0] for p in PROTEINS])
def test_a_session_round_trips_bit_for_bit(qtbot: QtBot, tmp_path: Path, path: Path) -> None:
    window = _window(qtbot, path)
    rw = window.rw
    window.document.set_regularization(on_release=path.name == "1UBQ.pdb.gz")  # the regularized steps of one
    if path.name == "1L2Y.pdb.gz":
        window.document.set_kind("calpha")  # and the Cα ribbon of another
    kind = window.document.kind
    rw.level = max(rw.level - 1, 0)
    n = len(rw.points())
    rw.move(n // 2, [2.0, -1.0, 0.5])
    rw.move(n // 3, [0.0, 1.5, 1.0])
    rw.undo()
    rw.tug(len(window.document.labels()) // 2, [1.0, 1.0, -1.0])
    rw.move(n - 1, [0.5, 0.5, 0.5])
    rw.undo()
    history, states, level = rw.history(), _states(window), rw.level
    saved = window.sessions.write_session(tmp_path / "work")
    assert saved.name == "work.rwsession"
    window.document.undo_stack.setClean()  # no question on the way out
    assert window.files.open_file(DATA / "3PTB.pdb.gz")
    assert window.sessions.open_session(saved)
    assert rw.history() == history and rw.level == level and window.document.modified
    assert window.document.kind is kind
    assert all(np.array_equal(a, b) for a, b in zip(_states(window), states, strict=True))
    rw.redo()
    assert np.array_equal(rw.coords(), states[-1])


def test_the_view_and_compared_structures_come_back(qtbot: QtBot, tmp_path: Path) -> None:
    compared = tmp_path / "elastase.pdb.gz"
    shutil.copy(DATA / "1BMA.pdb.gz", compared)
    window = _window(qtbot, DATA / "3PTB.pdb.gz")
    window.comparison.add(compared)
    window.comparison.set_visible(0, False)
    window.display_panel.layer_boxes[Layer.CARTOON].setChecked(False)
    window.display_panel.layer_boxes[Layer.TUBE].setChecked(True)
    window.display_panel.layer_boxes[Layer.ATOMS].setChecked(True)
    panel = window.display_panel
    panel.colouring.setCurrentIndex(panel.colouring.findData(Colouring.CHAIN))
    panel.fat.setChecked(True)
    panel.cylinders.setChecked(True)
    selection = window.rw.go_to("resn BEN or byres resn BEN around 4")  # a ligand and its pocket, selected
    window.plotter.camera.azimuth = 40
    camera = np.array([tuple(v) for v in window.plotter.camera_position])
    layers = set(window.scene.layers)
    saved = window.sessions.write_session(tmp_path / "view.rwsession")
    compared.unlink()  # the session embeds the compared structure too
    other = _window(qtbot, DATA / "1UBQ.pdb.gz")
    assert other.sessions.open_session(saved)
    assert other.scene.layers == layers and other.scene.colouring is Colouring.CHAIN and other.scene.fat_helices
    assert other.scene.helix_cylinders and other.display_panel.cylinders.isChecked()
    assert np.allclose([tuple(v) for v in other.plotter.camera_position], camera)
    assert other.rw.selection == selection and "A:BEN1" in selection and "A:ASP189" in selection
    assert other.plotter.camera.view_angle == window.plotter.camera.view_angle == 30.0  # the same zoom (#35)
    assert [(item.structure.entry_id, item.visible) for item in other.comparison.items] == [("1BMA", False)]
    before, after = window.comparison.items[0].fit, other.comparison.items[0].fit
    assert (after.tm_score, after.n_aligned) == (pytest.approx(before.tm_score), before.n_aligned)


def test_a_session_opens_when_the_structure_file_has_moved(qtbot: QtBot, tmp_path: Path) -> None:
    original = tmp_path / "ubiquitin.pdb.gz"
    shutil.copy(DATA / "1UBQ.pdb.gz", original)
    window = _window(qtbot, original)
    window.rw.move(5, [3.0, 0.0, 0.0])
    coords = window.rw.coords()
    saved = window.sessions.write_session(tmp_path / "s.rwsession")
    original.unlink()
    window.document.undo_stack.setClean()
    assert window.sessions.open_session(saved)
    assert np.array_equal(window.rw.coords(), coords) and window.document.path == original


def test_bad_sessions_give_a_message(qtbot: QtBot, tmp_path: Path, errors: list[str], warned: list[str],
                                     capsys: pytest.CaptureFixture[str]) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.rw.move(5, [3.0, 0.0, 0.0])
    saved = window.sessions.write_session(tmp_path / "s.rwsession")
    data = saved.read_bytes()
    newer = records.Record("header", {"version": records.VERSION + 1, "path": "x.pdb", "kind": "peptide"})
    cases = {
        "newer.rwsession": (records.MAGIC + records.encode(newer), "newer ribbonwave"),
        "cut.rwsession": (data[:100], "damaged"),
        "text.rwsession": (b"HEADER    not a session\n", "not a ribbonwave"),
    }
    for name, (content, message) in cases.items():
        (tmp_path / name).write_bytes(content)
        window.document.undo_stack.setClean()
        assert not window.sessions.open_session(tmp_path / name)
        assert message in errors[-1] and name in errors[-1]
        assert main([str(tmp_path / name), "--screenshot", str(tmp_path / "x.png")]) == 1
        err = capsys.readouterr().err
        assert err.startswith("ribbonwave: error:") and message in err and "Traceback" not in err
    (tmp_path / "cut.rwsession").write_bytes(data[: len(data) - 100])  # the view lost: the rest opens, and it says so
    window.document.undo_stack.setClean()
    assert window.sessions.open_session(tmp_path / "cut.rwsession") and window.rw.history()[1] == 1
    assert "cut.rwsession was opened as far as it is valid; left out: the file is cut off" in warned[-1]
    assert main([str(tmp_path / "cut.rwsession"), "--screenshot", str(tmp_path / "x.png")]) == 0
    assert "left out: the file is cut off" in capsys.readouterr().err


def test_saving_a_session_is_atomic(qtbot: QtBot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    saved = window.sessions.write_session(tmp_path / "s.rwsession")
    before = saved.read_bytes()
    window.rw.move(5, [3.0, 0.0, 0.0])

    def full_disk(*args: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("core.protein.writing.os.replace", full_disk)
    with pytest.raises(OSError):
        window.sessions.write_session(saved)
    assert saved.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["s.rwsession"]


def test_the_file_menu_saves_and_opens_sessions(qtbot: QtBot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.rw.move(5, [3.0, 0.0, 0.0])
    coords = window.rw.coords()
    target = tmp_path / "menu"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(target), ""))
    window.sessions.save_session_action.trigger()
    monkeypatch.setattr(QFileDialog, "getOpenFileName", lambda *a, **k: (str(target) + ".rwsession", ""))
    window.rw.undo()
    window.sessions.open_session_action.trigger()  # the conftest answers 'Discard' to the unsaved edits
    assert np.array_equal(window.rw.coords(), coords) and window.rw.history()[1] == 1


def test_a_session_never_points_save_at_a_file(qtbot: QtBot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A session records where its author saved; opened (by anyone, anywhere) its Save asks for
    a name instead of writing there (#37: a shared session could overwrite any file)."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    precious = tmp_path / "precious.pdb"
    precious.write_text("mine\n")
    window.rw.move(5, [3.0, 0.0, 0.0])
    window.document.save(precious, overwrite=True)  # the author's Save As there
    window.rw.move(6, [0.0, 2.0, 0.0])
    saved = window.sessions.write_session(tmp_path / "shared")
    precious.write_text("mine\n")  # (the recipient's file of that name)
    other = _window(qtbot, DATA / "3PTB.pdb.gz")
    assert other.sessions.open_session(saved) and other.document.save_path is None
    asked: list[str] = []

    def cancel(parent: object, title: str, suggested: str, *args: object) -> tuple[str, str]:
        asked.append(suggested)
        return "", ""

    monkeypatch.setattr(QFileDialog, "getSaveFileName", cancel)
    assert not other.files.save() and asked  # Save asked (and was cancelled)
    assert precious.read_text() == "mine\n"


def test_a_session_replaces_a_file_only_when_told(qtbot: QtBot, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                  questions) -> None:
    """rw.save_session, like every output of ribbonwave, refuses an existing file unless told to
    replace it; the menu asks when it added the ending to the name it was given (#37)."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.rw.move(5, [3.0, 0.0, 0.0])
    mine = tmp_path / "mine.rwsession"
    mine.write_bytes(b"mine")
    with pytest.raises(FileExistsError, match="refusing to overwrite"):
        window.rw.save_session(tmp_path / "mine")
    assert mine.read_bytes() == b"mine"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(tmp_path / "mine"), ""))
    questions.answer = QMessageBox.StandardButton.No
    assert not window.sessions.save_session() and questions.asked[-1] == "mine.rwsession exists. Replace it?"
    assert mine.read_bytes() == b"mine"
    questions.answer = QMessageBox.StandardButton.Yes
    assert window.sessions.save_session() and mine.read_bytes().startswith(records.MAGIC)
    assert window.rw.save_session(mine, overwrite=True) == mine
    questions.answer = QMessageBox.StandardButton.Discard  # for the window's close after the test
