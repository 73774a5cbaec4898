"""Crash recovery: every undo step journalled as it happens, restored bit for bit after a crash."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QMessageBox
from pytestqt.qtbot import QtBot
from test_window import _drag_control_point, _window

from app.editor.main_window import MainWindow
from app.editor.persistence import journal, records
from app.editor.persistence.schema import EDIT_ARRAYS
from core.protein.model import Edit

DATA = Path(__file__).resolve().parents[2] / "data"
ROOT = Path(__file__).resolve().parents[3]


def _edit(window: MainWindow, which: int, offset: tuple[int, int] = (30, 20)) -> None:
    _drag_control_point(window, which % len(window.scene.shown_control_points()), offset, steps=2)


def _journal_records(window: MainWindow) -> list[records.Record]:
    reading = records.read(window.journal.path)
    assert not reading.damaged
    return reading.records


# ---------------------------------------------------------------------------- the format


def test_records_round_trip_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    rows = np.arange(17, dtype=np.int64) * 3
    edit = Edit(2, rng.normal(size=(9, 3)), rng.normal(size=(9, 3)), np.arange(4), rows, rng.normal(size=(17, 3)),
                rng.normal(size=(17, 3)))
    empty = Edit(0, np.zeros((7, 3)), np.zeros((7, 3)), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                 np.zeros((0, 3)), np.zeros((0, 3)))
    for edits in ([edit], [edit, empty]):
        record = records.push(2, "Move point 3", edits)
        reading = records.decode(records.MAGIC + records.encode(records.header(Path("x.pdb"), "peptide", b"ab", 1))
                                 + records.encode(record))
        (back,) = reading.records[1:]
        assert back.kind == "push" and back.fields == record.fields and not reading.damaged
        for name, array in record.arrays.items():
            assert back.arrays[name].dtype == array.dtype and back.arrays[name].tobytes() == array.tobytes()
        assert all(a.segment == b.segment and all(np.array_equal(getattr(a, n), getattr(b, n)) for n in EDIT_ARRAYS)
                   for a, b in zip(records.edits_of(back), edits, strict=True))


def test_a_journal_cut_anywhere_gives_the_records_before_the_cut(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    for k in range(3):
        _edit(window, k + 2)
    data = window.journal.path.read_bytes()
    whole = records.decode(data).records
    assert [r.kind for r in whole].count("push") == 3
    ends = np.cumsum([len(records.MAGIC)] + [len(records.encode(r)) for r in whole])
    for cut in range(int(ends[0]) + 1, len(data), 97):  # every 97th byte: inside headers, JSON and arrays
        reading = records.decode(data[:cut])
        complete = int(np.searchsorted(ends, cut, side="right")) - 1
        assert reading.cut_off == (cut not in ends) and len(reading.records) == complete and not reading.skipped


def test_damage_mid_journal_is_passed_over_to_the_next_record(qtbot: QtBot) -> None:
    """One bad byte used to end the journal there: every later step was lost (#37, item 2). The
    reader now resynchronises on the next record whose CRC holds, and names what it passed over."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    for k in range(4):
        _edit(window, k + 2)
    data = window.journal.path.read_bytes()
    whole = records.decode(data).records
    ends = np.cumsum([len(records.MAGIC)] + [len(records.encode(r)) for r in whole])
    rng = np.random.default_rng(37)
    for k in range(2, len(whole)):  # a flipped byte anywhere in each record after the header
        flipped = bytearray(data)
        flipped[rng.integers(ends[k - 1], ends[k])] ^= 1 << int(rng.integers(8))
        reading = records.decode(bytes(flipped))
        assert [r.kind for r in reading.records] == [r.kind for j, r in enumerate(whole) if j != k - 1]
        assert len(reading.skipped) == 1 and "damaged bytes" in reading.skipped[0] and not reading.cut_off
    cut = bytearray(data)
    del cut[int(ends[3]) : int(ends[3]) + 50]  # bytes lost mid-file: the record they were part of is passed over
    assert len(records.decode(bytes(cut)).records) == len(whole) - 1


def test_not_a_journal_or_a_newer_one_is_refused() -> None:
    with pytest.raises(records.RecordError, match="not a ribbonwave"):
        records.decode(b"HEADER    PROTEIN\n")
    newer = records.Record("header", {"version": records.VERSION + 1, "path": "x", "kind": "peptide"})
    with pytest.raises(records.RecordError, match="newer ribbonwave"):
        records.decode(records.MAGIC + records.encode(newer))


# ---------------------------------------------------------------------------- journalling


def test_every_step_is_appended_as_a_delta(qtbot: QtBot, state_home: Path) -> None:
    window = _window(qtbot, DATA / "4YVS.cif.gz")
    assert window.journal.path is None  # nothing journalled before the first step
    _edit(window, 3)
    path = window.journal.path
    assert path.parent == state_home and path.stat().st_size > len(window.document.source)
    sizes = [path.stat().st_size]
    stack = window.document.undo_stack
    for k in range(3):
        _edit(window, 5 + k)
        sizes.append(path.stat().st_size)
        edit, = stack.command(stack.index() - 1).edits
        arrays = sum(a.nbytes for a in (edit.old_points, edit.new_points, edit.residues, edit.rows, edit.old_coords,
                                        edit.new_coords))
        assert arrays < sizes[-1] - sizes[-2] < arrays + 1024  # the edit's deltas and a line of JSON
        assert sizes[-1] - sizes[-2] < window.document.model.coords.nbytes / 10  # not the model
    window.editing.undo_action.trigger()
    kinds = [r.kind for r in _journal_records(window)]
    assert kinds == ["header", "push", "index", "push", "index", "push", "index", "push", "index", "index"]
    assert _journal_records(window)[-1].fields["index"] == 3


def test_level_and_segment_are_journalled_soon_after_they_change(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    _edit(window, 3)
    window.document.set_level(2.5)
    qtbot.waitUntil(lambda: _journal_records(window)[-1].kind == "state", timeout=1000)
    assert _journal_records(window)[-1].fields["level"] == 2.5


def test_a_clean_close_removes_the_journal(qtbot: QtBot, questions) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    _edit(window, 3)
    path = window.journal.path
    questions.answer = QMessageBox.StandardButton.Discard
    window.close()
    assert not path.exists()


def test_a_saved_document_closes_without_its_journal(qtbot: QtBot, tmp_path: Path) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    _edit(window, 3)
    path = window.journal.path
    window.document.save(tmp_path / "saved.pdb")
    window.close()
    assert not path.exists()


def test_an_unattended_close_keeps_unsaved_edits(qtbot: QtBot, questions) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    _edit(window, 3)
    window.files.unattended = True
    path = window.journal.path
    window.close()
    assert path.exists() and not questions.asked
    assert journal.orphans(path.parent) == [path]  # nobody holds it any more


def test_a_journal_kept_leaves_room_for_the_next_in_the_same_second(qtbot: QtBot) -> None:
    """A script that opens a session over unsaved edits keeps their journal and starts another
    at once: the new one gets a name of its own (it took the kept one's and failed)."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    _edit(window, 3)
    kept = window.journal.path
    window.journal.keep()
    _edit(window, 4)
    assert window.journal.path != kept and kept.exists() and window.journal.path.exists()
    assert [r.kind for r in _journal_records(window)].count("push") == 1


def test_the_next_start_offers_to_restore(qtbot: QtBot, questions) -> None:
    crashed = _window(qtbot, DATA / "1UBQ.pdb.gz")
    for k in range(4):
        _edit(crashed, k + 2)
    crashed.editing.undo_action.trigger()
    coords, history = crashed.document.model.coords.copy(), crashed.rw.history()
    crashed.files.unattended = True
    crashed.close()  # as a crash leaves it: the journal stays
    window = _window(qtbot, DATA / "3PTB.pdb.gz")
    questions.answer = QMessageBox.StandardButton.Yes
    window.sessions.offer_recovery()
    assert "did not close cleanly" in questions.asked[-1] and "unsaved edits of 1UBQ.pdb.gz (" in questions.asked[-1]
    assert questions.defaults[-1] == QMessageBox.StandardButton.Yes  # Enter restores
    assert window.rw.history() == history and np.array_equal(window.document.model.coords, coords)
    assert window.document.modified and window.document.path.name == "1UBQ.pdb.gz"
    window.editing.redo_action.trigger()
    window.editing.undo_action.trigger()
    assert np.array_equal(window.document.model.coords, coords)
    assert journal.orphans(window.journal.folder) == []  # the restored history is journalled anew, held
    questions.answer = QMessageBox.StandardButton.Discard  # for the windows' close after the test


def test_a_damaged_journal_restores_the_steps_before_the_damage(qtbot: QtBot) -> None:
    crashed = _window(qtbot, DATA / "1UBQ.pdb.gz")
    states = []
    for k in range(3):
        _edit(crashed, k + 2)
        states.append(crashed.document.model.coords.copy())
    path = crashed.journal.path
    crashed.files.unattended = True
    crashed.close()
    data = path.read_bytes()
    path.write_bytes(data[:-30])  # the last record cut off mid-write
    window = _window(qtbot, DATA / "3PTB.pdb.gz")
    message = window.sessions.restore_journal(path)
    assert "cut off" in message and window.rw.history()[1] == 3
    assert np.array_equal(window.document.model.coords, states[2])  # the cut-off record was the last index only
    path.write_bytes(data[: len(data) // 2])
    window.sessions.restore_journal(path)
    count = window.document.undo_stack.count()
    assert 0 < count < 3 and np.array_equal(window.document.model.coords, states[count - 1])


# ---------------------------------------------------------------------------- kill -9


STEPS = """
import json, os
import numpy as np
out = os.environ["RW_OUT"]
for k in range(40):
    if k % 5 == 4:
        rw.undo()
    else:
        rw.move(k % 7 + 2, [1.5 * (-1) ** k, 1.0, 0.5])
    name, index = rw.history()
    with open(f"{out}/report.tmp", "w") as f:  # one file, replaced at once: history and coordinates agree
        json.dump([name, index, k, rw.coords().tolist()], f)  # floats round-trip exactly through JSON
    os.replace(f"{out}/report.tmp", f"{out}/report.json")
"""
CHECK = """
import json, os
import numpy as np
out = os.environ["RW_OUT"]
np.save(f"{out}/recovered.npy", rw.coords())
name, index = rw.history()
rw.undo()
np.save(f"{out}/undone.npy", rw.coords())
rw.redo()
rw.redo()
np.save(f"{out}/redone.npy", rw.coords())
with open(f"{out}/recovered.json", "w") as f:
    json.dump([name, index], f)
rw.quit(discard=True)
"""


@pytest.mark.parametrize("after", [1, 9, 23])
def test_kill_9_at_any_moment_then_recover(tmp_path: Path, state_home: Path, after: int) -> None:
    """A scripted session killed (SIGKILL) while it works; ``--recover`` gives back the undo
    history and the coordinates exactly: those of the last step the script reported, or of
    the step in flight if it reached the journal (then undo gives the reported ones)."""
    env = {**os.environ, "RW_OUT": str(tmp_path), "XDG_STATE_HOME": str(state_home.parent)}
    (tmp_path / "steps.py").write_text(STEPS)
    (tmp_path / "check.py").write_text(CHECK)
    command = [sys.executable, "-m", "app", str(DATA / "1UBQ.pdb.gz"), "--script", str(tmp_path / "steps.py")]
    with (tmp_path / "stderr.txt").open("wb") as stderr:
        child = subprocess.Popen(command, cwd=ROOT, env=env, stderr=stderr)
        deadline = time.monotonic() + 120
        report = tmp_path / "report.json"
        while time.monotonic() < deadline and child.poll() is None:
            if report.exists() and json.loads(report.read_text())[2] >= after:
                break
            time.sleep(0.005)
        running = child.poll() is None
        os.kill(child.pid, signal.SIGKILL)
        child.wait()
    assert running, (tmp_path / "stderr.txt").read_text()[-2000:]
    names, index, _, coords = json.loads(report.read_text())
    reported = np.array(coords)
    result = subprocess.run([sys.executable, "-m", "app", "--recover", "--script", str(tmp_path / "check.py")],
                            cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    recovered_names, recovered_index = json.loads((tmp_path / "recovered.json").read_text())
    recovered = np.load(tmp_path / "recovered.npy")
    if (recovered_names, recovered_index) == (names, index):
        assert np.array_equal(recovered, reported)
    elif recovered_index == index + 1:  # a move in flight was journalled before the kill
        assert recovered_names[:index] == names[:index]
        assert np.array_equal(np.load(tmp_path / "undone.npy"), reported)
    else:  # an undo in flight was journalled before the kill
        assert (recovered_names, recovered_index) == (names, index - 1)
        assert np.array_equal(np.load(tmp_path / "redone.npy"), reported)
    assert list(state_home.glob("*.rwjournal")) == []  # restored, then discarded by the check script


@pytest.mark.parametrize("damage", ["newer format", "bad header byte"])
def test_a_journal_that_cannot_be_read_is_set_aside_never_deleted(qtbot: QtBot, damage: str,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """A journal of a newer ribbonwave, or with a damaged header, may hold steps a person or a
    newer version can restore: the start-up sweep renames it, keeps its bytes and says so (#37)."""
    crashed = _window(qtbot, DATA / "1UBQ.pdb.gz")
    _edit(crashed, 3)
    crashed.files.unattended = True
    path = crashed.journal.path
    crashed.close()
    data = bytearray(path.read_bytes())
    if damage == "newer format":
        entries = records.read(path).records
        entries[0].fields["version"] = records.VERSION + 1
        data = bytearray(records.MAGIC + b"".join(records.encode(entry) for entry in entries))
    else:
        data[len(records.MAGIC) + 12] ^= 0xFF  # inside the header record: its CRC fails
    path.write_bytes(bytes(data))
    warned: list[str] = []
    monkeypatch.setattr(QMessageBox, "warning", lambda parent, title, text, *args: warned.append(text))
    window = _window(qtbot, DATA / "3PTB.pdb.gz")
    window.sessions.offer_recovery()
    kept = path.with_name(path.name + journal.SET_ASIDE)
    assert not path.exists() and kept.read_bytes() == bytes(data)
    assert len(warned) == 1 and kept.name in warned[0] and "kept, not deleted" in warned[0]
    window.sessions.offer_recovery()  # set aside once: not swept, not announced again
    assert kept.exists() and len(warned) == 1


def test_a_new_journal_is_never_seen_by_a_sweep_before_it_is_held(qtbot: QtBot,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """Between its creation and its lock another editor's sweep used to find a journal with
    no step and delete it (#37): it now gets its name only once locked and given its header."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    seen: list[list[Path]] = []
    lock = journal.fcntl.flock

    def sweep_first(fd: int, operation: int) -> None:  # another editor sweeps just before the lock
        if not seen:
            seen.append(sorted(window.journal.folder.iterdir()))
            journal.orphans(window.journal.folder)
        lock(fd, operation)

    monkeypatch.setattr(journal.fcntl, "flock", sweep_first)
    _edit(window, 3)
    monkeypatch.setattr(journal.fcntl, "flock", lock)
    assert seen and all(p.name.endswith(journal.OPENING) for p in seen[0])
    assert window.journal.path.exists() and [r.kind for r in _journal_records(window)].count("push") == 1


def test_recover_with_nothing_to_restore_names_the_journals_set_aside(qtbot: QtBot, state_home: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    from app.main import main

    assert main(["--recover"]) == 1
    assert capsys.readouterr().err.strip().endswith(f"nothing to recover: no journal of an editor that did not "
                                                    f"close cleanly in {state_home}")
    state_home.mkdir(parents=True, exist_ok=True)
    (state_home / f"journal-1{journal.SUFFIX}{journal.SET_ASIDE}").write_bytes(records.MAGIC + b"\0" * 9)
    assert main(["--recover"]) == 1
    assert capsys.readouterr().err.strip().endswith(f"(kept there, unreadable here: journal-1{journal.SUFFIX}"
                                                    f"{journal.SET_ASIDE})")


@pytest.mark.parametrize("wrong", ["another owner", "writable by others"])
def test_a_state_folder_that_is_not_the_users_alone_is_refused(state_home: Path, tmp_path: Path, wrong: str,
                                                              capsys: pytest.CaptureFixture[str],
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """A journal found there is restored as the user's own work, and a sweep deletes files
    there: another user's folder, or one others may write in, is refused (#37, item 6)."""
    from app.main import main

    state_home.mkdir(parents=True, exist_ok=True)
    if wrong == "another owner":  # (as another user sees it: the folder's owner is not the process's user)
        uid = state_home.stat().st_uid
        monkeypatch.setattr(journal.os, "getuid", lambda: uid + 1)
    else:
        state_home.chmod(0o777)
    assert main([str(DATA / "1UBQ.pdb.gz"), "--screenshot", str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err
    assert f"the folder of recovery journals {state_home}" in err and "Traceback" not in err
    assert ("belongs to another user" if wrong == "another owner" else "chmod go-w") in err
    with pytest.raises(PermissionError):
        journal.sweep(state_home)
    assert not (tmp_path / "x.png").exists()


def test_a_new_state_folder_is_private(state_home: Path) -> None:
    assert journal.checked_folder(state_home) == state_home and state_home.stat().st_mode & 0o777 == 0o700
