"""Multi-model entries in the editor: the model chosen (document, spin box, script), edited and
saved without touching the other models, and restored by sessions and crash recovery."""

import gzip
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot
from test_window import _drag_control_point, _window

from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.persistence import records, session
from app.editor.persistence.recording import recording as recorded
from app.editor.persistence.recording import replay
from app.main import main
from core.protein.input_files import StructureError
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
NMR = DATA / "1L2Y.pdb.gz"


def _input_lines(path: Path) -> list[str]:
    return gzip.decompress(path.read_bytes()).decode().splitlines()


def _move(document: Document, index: int = 2, delta: tuple[float, float, float] = (0.0, 3.0, 1.0)) -> None:
    """One edit, as a drag of control point ``index`` is."""
    document.preview_move(index, np.array(delta))
    document.finish_drag(f"Move point {index}")


def _assert_only_model_moved(path: Path, source: Path, model: int, coords: np.ndarray) -> None:
    """``path`` holds model ``model`` at ``coords`` (as files round them) and every other model as ``source`` has it,
    and differs from ``source`` only in the lines of the atoms that moved."""
    written = read_structure(path, model=model)
    np.testing.assert_allclose(written.coords, coords, atol=5e-4 + 1e-9, rtol=0)
    moved = np.any(written.coords != read_structure(source, model=model).coords, axis=1)
    assert moved.sum() > 50
    for other in range(1, written.n_models + 1):
        if other != model:
            assert np.array_equal(read_structure(path, model=other).coords, read_structure(source, model=other).coords)
    lines, original = path.read_text().splitlines(), _input_lines(source)
    assert len(lines) == len(original) and sum(a != b for a, b in zip(lines, original)) == moved.sum()


# ------------------------------------------------------------------ the document


def test_a_document_opens_the_model_asked(qapp: QApplication, ubiquitin: Document) -> None:
    document = Document()
    document.open(NMR, model=7)
    assert document.model_number == 7 and document.structure.n_models == 38
    assert np.array_equal(document.model.coords, read_structure(NMR, model=7).coords)
    assert document.title == "1L2Y.pdb.gz (model 7 of 38)" and ubiquitin.title == "1UBQ.pdb.gz"
    with pytest.raises(StructureError, match="no model 39; the file has 38 model"):
        document.open(NMR, model=39)
    assert document.model_number == 7 and document.path == NMR  # the document as it was


def test_choosing_a_model_keeps_the_view_and_waits_for_no_edits_to_undo(qtbot: QtBot) -> None:
    document = Document()
    document.open(NMR)
    document.set_level(2.5)
    document.set_regularization(on_release=False)
    with qtbot.waitSignals([document.loaded, document.fileChanged]):
        document.set_model_number(4)
    assert document.model_number == 4 and document.level == 2.5 and document.title.endswith("(model 4 of 38)")
    assert np.array_equal(document.model.coords, read_structure(NMR, model=4).coords)
    _move(document)
    with pytest.raises(ValueError, match="no edits to undo"):
        document.set_model_number(5)
    assert document.model_number == 4 and document.undo_stack.count() == 1
    document.undo_stack.undo()
    document.set_model_number(5)
    assert document.model_number == 5 and document.undo_stack.count() == 0
    with pytest.raises(StructureError, match="no model 0"):
        document.set_model_number(0)


@pytest.mark.parametrize(("name", "model", "suffix"), [("1L2Y.pdb.gz", 9, ".pdb"), ("1LCD.cif.gz", 2, ".cif")])
def test_an_edit_of_the_chosen_model_saves_with_every_other_model_as_read(
        qapp: QApplication, tmp_path: Path, name: str, model: int, suffix: str) -> None:
    document = Document()
    document.open(DATA / name, model=model)
    unchanged = document.save(tmp_path / f"unchanged{suffix}")
    assert unchanged.read_text().splitlines() == _input_lines(DATA / name)
    document.set_regularization(on_release=False)
    _move(document, 3, (2.0, -1.0, 1.5))
    saved = document.save(tmp_path / f"edited{suffix}")
    _assert_only_model_moved(saved, DATA / name, model, document.model.coords)


def test_a_recording_replays_the_same_model_and_older_ones_read_as_model_1(qapp: QApplication) -> None:
    document = Document()
    document.open(NMR, model=9)
    document.set_regularization(on_release=False)
    _move(document)
    recording = recorded(document)
    assert recording[0].fields["model"] == 9 and recording[0].fields["version"] == records.VERSION == 3
    again = Document()
    replay(again, recording)
    assert again.model_number == 9 and np.array_equal(again.model.coords, document.model.coords)
    again.undo_stack.undo()
    assert np.array_equal(again.model.coords, read_structure(NMR, model=9).coords)

    first = Document()
    first.open(NMR)
    first.set_regularization(on_release=False)
    _move(first)
    old = recorded(first)
    fields = {k: v for k, v in old[0].fields.items() if k != "model"} | {"version": 1}  # as version 1 wrote it
    old[0] = records.Record("header", fields, old[0].arrays)
    decoded = records.decode(records.MAGIC + b"".join(records.encode(r) for r in old)).records
    replay(again, decoded)
    assert again.model_number == 1 and np.array_equal(again.model.coords, first.model.coords)


# ------------------------------------------------------------------ the window


def test_the_model_spin_box_chooses_the_model_to_edit_and_save(qtbot: QtBot, tmp_path: Path) -> None:
    single = _window(qtbot, DATA / "1UBQ.pdb.gz")
    assert single.dimension_panel.model_number.isHidden() and "model" not in single.windowTitle()
    window = _window(qtbot, NMR)
    spin = window.dimension_panel.model_number
    assert not spin.isHidden() and spin.isEnabled() and spin.text() == "1 of 38"
    assert window.windowTitle() == "1L2Y.pdb.gz (model 1 of 38)[*] — ribbonwave"
    window.document.set_regularization(on_release=False)
    spin.setValue(6)
    assert window.document.model_number == 6 and window.windowTitle().startswith("1L2Y.pdb.gz (model 6 of 38)")
    assert np.array_equal(window.document.model.coords, read_structure(NMR, model=6).coords)
    _drag_control_point(window, 2)
    assert window.document.undo_stack.count() == 1 and not spin.isEnabled()
    assert window.windowTitle() == "1L2Y.pdb.gz (model 6 of 38)[*] — ribbonwave" and window.isWindowModified()
    assert window.files.write(tmp_path / "edited.pdb")
    _assert_only_model_moved(tmp_path / "edited.pdb", NMR, 6, window.document.model.coords)
    assert window.windowTitle() == "edited.pdb (model 6 of 38)[*] — ribbonwave" and not window.isWindowModified()
    window.editing.undo_action.trigger()
    assert spin.isEnabled()


def _edited_window(qtbot: QtBot, model: int) -> MainWindow:
    window = _window(qtbot, NMR)
    window.dimension_panel.model_number.setValue(model)
    window.rw.move(3, [1.0, 2.5, -1.0])
    window.rw.move(5, [-1.0, 0.5, 2.0])
    window.rw.undo()
    return window


def test_a_session_restores_the_model(qtbot: QtBot, tmp_path: Path) -> None:
    window = _edited_window(qtbot, 4)
    history, coords = window.rw.history(), window.rw.coords()
    saved = window.sessions.write_session(tmp_path / "ensemble")
    assert session.read(saved).recording[0].fields["model"] == 4
    window.document.undo_stack.setClean()  # no question on the way out
    assert window.files.open_file(DATA / "1UBQ.pdb.gz") and window.sessions.open_session(saved)
    assert window.rw.model == 4 and window.dimension_panel.model_number.value() == 4
    assert window.windowTitle().startswith("1L2Y.pdb.gz (model 4 of 38)")
    assert window.rw.history() == history and np.array_equal(window.rw.coords(), coords)
    window.rw.redo()
    window.rw.undo()
    window.rw.undo()
    assert np.array_equal(window.rw.coords(), read_structure(NMR, model=4).coords)


def test_crash_recovery_restores_the_model(qtbot: QtBot) -> None:
    crashed = _edited_window(qtbot, 17)
    history, coords, path = crashed.rw.history(), crashed.rw.coords(), crashed.journal.path
    assert records.read(path).records[0].fields["model"] == 17
    crashed.files.unattended = True
    crashed.close()  # as a crash leaves it: the journal stays
    window = _window(qtbot, DATA / "3PTB.pdb.gz")
    window.sessions.restore_journal(path)
    assert window.rw.model == 17 and window.windowTitle().startswith("1L2Y.pdb.gz (model 17 of 38)")
    assert window.rw.history() == history and np.array_equal(window.rw.coords(), coords)


def test_scripts_and_the_command_line_choose_the_model(qapp: QApplication, tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "models.py"
    script.write_text("print(rw.model)\nrw.model = 12\nprint(rw.model)\nrw.move(2, [0, 2, 0])\n"
                      "try:\n    rw.model = 13\nexcept ValueError as error:\n    print(error)\n"
                      f"rw.export({str(tmp_path / 'out.pdb')!r})\nrw.quit(discard=True)\n")
    assert main([str(NMR), "--model", "3", "--script", str(script)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == ["3", "12", "another model can be chosen only while there are no edits to undo"]
    assert not np.array_equal(read_structure(tmp_path / "out.pdb", model=12).coords,
                              read_structure(NMR, model=12).coords)
    assert main([str(NMR), "--model", "39", "--screenshot", str(tmp_path / "x.png")]) == 1
    assert "no model 39; the file has 38 model(s)" in capsys.readouterr().err
