"""A day of editing in bounded memory (#37): past its budget the undo history drops its oldest
steps, their result becomes where it starts, and the journal and sessions record that start,
so that a restore is still bit for bit; a save compacts the journal."""

from pathlib import Path

import numpy as np
import pytest
from pytestqt.qtbot import QtBot
from test_window import _window

from app.editor import history
from app.editor.main_window import MainWindow
from app.editor.persistence import journal, records

DATA = Path(__file__).resolve().parents[2] / "data"


def _steps(window: MainWindow, count: int, start: int = 0) -> list[np.ndarray]:
    """``count`` moves at changing levels (every fifth an undo), the coordinates after each."""
    rw, states = window.rw, []
    for k in range(start, start + count):
        if k % 5 == 4:
            rw.undo()
        else:
            rw.level = 2 + k % 3
            rw.move(k % len(rw.points()), [0.4 * (-1) ** k, 0.3, -0.2])
        states.append(rw.coords())
    return states


@pytest.fixture
def small_budget(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(history, "MIN_UNDO_STEPS", 4)


def test_the_oldest_steps_go_past_the_budget_and_the_rest_undo_exactly(qtbot: QtBot, small_budget: None) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.document.set_regularization(on_release=False)
    window.document.history.budget = 300_000
    states = _steps(window, 60)
    document, stack = window.document, window.document.undo_stack
    assert document.history.base is not None and 4 <= stack.count() < 36  # 36 steps were made, 12 undone
    assert document.history.nbytes == sum(stack.command(k).nbytes for k in range(stack.count())) <= 300_000
    assert np.array_equal(document.model.coords, states[-1])  # dropping steps moves nothing
    index = stack.index()
    stack.setIndex(0)
    assert np.array_equal(document.model.coords, document.history.base.coords)
    assert all(np.array_equal(r.points, p) for r, p in zip(document.model.ribbons, document.history.base.points))
    stack.setIndex(index)
    assert np.array_equal(document.model.coords, states[-1]) and document.modified


def test_a_journal_and_a_session_restore_a_trimmed_history_bit_for_bit(qtbot: QtBot, tmp_path: Path,
                                                                       small_budget: None) -> None:
    crashed = _window(qtbot, DATA / "1UBQ.pdb.gz")
    crashed.document.set_regularization(on_release=False)
    crashed.document.history.budget = 300_000
    _steps(crashed, 60)
    stack = crashed.document.undo_stack
    history_before, base = crashed.rw.history(), crashed.document.history.base
    states, index = [], stack.index()
    for k in range(stack.count() + 1):
        stack.setIndex(k)
        states.append(crashed.document.model.coords.copy())
    stack.setIndex(index)
    saved = crashed.sessions.write_session(tmp_path / "trimmed")
    entries = records.read(crashed.journal.path).records
    assert [e.kind for e in entries][:2] == ["header", "base"]  # rewritten when the history was trimmed
    assert [e.kind for e in entries].count("push") <= stack.count() + 12
    path = crashed.journal.path
    crashed.files.unattended = True
    crashed.close()
    for restore in ("journal", "session"):
        window = _window(qtbot, DATA / "3PTB.pdb.gz")
        if restore == "journal":
            window.sessions.restore_journal(path)
        else:
            assert window.sessions.open_session(saved)
        document = window.document
        assert window.rw.history() == history_before and document.history.base is not None
        assert np.array_equal(document.history.base.coords, base.coords)
        for k in range(document.undo_stack.count() + 1):
            document.undo_stack.setIndex(k)
            assert np.array_equal(document.model.coords, states[k])


def test_a_save_kept_in_the_history_stays_marked_and_compacts_the_journal(qtbot: QtBot, tmp_path: Path,
                                                                          small_budget: None) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.document.set_regularization(on_release=False)
    document, stack = window.document, window.document.undo_stack
    _steps(window, 20)
    pushes = [e.kind for e in records.read(window.journal.path).records].count("push")
    window.rw.save(tmp_path / "saved.pdb")
    compacted = records.read(window.journal.path).records
    assert [e.kind for e in compacted].count("push") == stack.count() < pushes  # the steps undone and replaced go
    saved_at = stack.index()
    document.history.budget = document.history.nbytes + 1  # the next steps drop the oldest, not the saved one
    _steps(window, 3, start=1)
    assert document.history.base is not None and 0 <= stack.cleanIndex() < saved_at
    stack.setIndex(stack.cleanIndex())
    assert not document.modified
    assert journal.orphans(window.journal.folder) == []


def test_the_history_dock_names_its_start_and_stays_fast(qtbot: QtBot, small_budget: None) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.document.set_regularization(on_release=False)
    assert window.history.emptyLabel() == "<structure as read>" and window.history.uniformItemSizes()
    window.document.history.budget = 300_000
    _steps(window, 40)
    assert window.document.history.base is not None and window.history.emptyLabel() == "<older steps dropped>"
    assert window.history.model().rowCount() == window.document.undo_stack.count() + 1
    window.files.open_file(DATA / "1L2Y.pdb.gz")
    assert window.history.emptyLabel() == "<structure as read>"
