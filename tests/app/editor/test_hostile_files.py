"""Sessions and journals someone else wrote (a newer or buggy writer, a damaged disk, an
attacker): each is refused with a message or restored as far as it is valid, never a traceback
or an abort (#37). A corpus of the cases found by hand, then hypothesis mutating valid files at
the level of their fields, arrays and records (re-framed, so the CRC holds and the content is
what is tested)."""

import json
import os
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PySide6.QtWidgets import QMessageBox
from pytestqt.qtbot import QtBot
from test_window import _window

from app.editor.main_window import MainWindow
from app.editor.persistence import journal, records
from core.protein.input_files import StructureError
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
FUZZ = settings(max_examples=300, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.fixture
def shown(warned: list[str], monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Messages of ``QMessageBox.warning`` and ``critical`` dialogs, which are not shown."""
    monkeypatch.setattr(QMessageBox, "critical", lambda parent, title, text, *args: warned.append(text))
    return warned


def _edited(qtbot: QtBot) -> MainWindow:
    """Ubiquitin with five steps (one undone, one a tug, one of two segments' worth of moves)."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    rw = window.rw
    window.document.set_regularization(on_release=False)
    n = len(rw.points())
    rw.move(n // 2, [2.0, -1.0, 0.5])
    rw.move(n // 3, [0.0, 1.5, 1.0])
    rw.tug("A:30", [1.0, 1.0, -1.0])
    rw.move(n - 1, [0.5, 0.5, 0.5])
    rw.undo()
    window.document.undo_stack.setClean()
    return window


def _frame(payload: bytes) -> bytes:
    return struct.pack("<II", len(payload), zlib.crc32(payload)) + payload


def _file(entries: list[records.Record]) -> bytes:
    return records.MAGIC + b"".join(records.encode(entry) for entry in entries)


def _consistent(window: MainWindow) -> None:
    """The document's history is one that can be walked: undo to the start gives the embedded
    file's coordinates bit for bit, redo to the end and back to where it was works."""
    document, stack = window.document, window.document.undo_stack
    index = stack.index()
    stack.setIndex(0)
    original = read_structure(document.path, document.source, model=document.model_number,
                              require_protein=False).coords
    assert np.array_equal(document.model.coords, original)
    stack.setIndex(stack.count())
    stack.setIndex(index)
    assert np.isfinite(document.model.coords).all()


# ---------------------------------------------------------------------------- the corpus


def _set(kind: str, name: str, value: object):
    """A change of field ``name`` of the first record of ``kind``."""
    def change(entries: list[records.Record]) -> list[records.Record]:
        k = next(k for k, e in enumerate(entries) if e.kind == kind)
        entries[k] = records.Record(kind, {**entries[k].fields, name: value}, entries[k].arrays)
        return entries
    return change


def _drop(kind: str, name: str):
    def change(entries: list[records.Record]) -> list[records.Record]:
        k = next(k for k, e in enumerate(entries) if e.kind == kind)
        entries[k] = records.Record(kind, {f: v for f, v in entries[k].fields.items() if f != name}, entries[k].arrays)
        return entries
    return change


def _array(kind: str, name: str, make):
    """A change of array ``name`` of the first record of ``kind`` to ``make(array)``."""
    def change(entries: list[records.Record]) -> list[records.Record]:
        k = next(k for k, e in enumerate(entries) if e.kind == kind)
        entries[k] = records.Record(kind, entries[k].fields, {**entries[k].arrays, name: make(entries[k].arrays[name])})
        return entries
    return change


def _kind(kind: str, new: str):
    def change(entries: list[records.Record]) -> list[records.Record]:
        k = next(k for k, e in enumerate(entries) if e.kind == kind)
        entries[k] = records.Record(new, entries[k].fields, entries[k].arrays)
        return entries
    return change


def _other_structure(entries: list[records.Record]) -> list[records.Record]:
    source = (DATA / "1L2Y.pdb.gz").read_bytes()
    entries[0] = records.Record("header", {**entries[0].fields, "path": "1L2Y.pdb.gz"},
                                {"source": np.frombuffer(source, dtype=np.uint8)})
    return entries


CORPUS = {  # field missing, of another type, an unknown enum value, NaN or wrongly shaped points, ...
    "no step text": _drop("push", "text"),
    "position as text": _set("push", "at", "3"),
    "position as bool": _set("push", "at", True),
    "negative position": _set("push", "at", -1),
    "huge position": _set("push", "at", 10**30),
    "segment that does not exist": _set("push", "segment", 7),
    "segments as a dict": _set("push", "segments", {"0": 1}),
    "unknown ribbon kind": _set("header", "kind", "beta"),
    "model 0": _set("header", "model", 0),
    "model the file lacks": _set("header", "model", 5),
    "version as a list": _set("header", "version", [3]),
    "version as text": _set("header", "version", "3"),
    "path with NUL": _set("header", "path", "1UBQ\0.pdb"),
    "NaN points": _array("push", "new_points", lambda a: np.full_like(a, np.nan)),
    "points of another shape": _array("push", "old_points", lambda a: a[:, :2].copy()),
    "points as integers": _array("push", "new_points", lambda a: a.astype(np.int64)),
    "rows past the atoms": _array("push", "rows", lambda a: a + 10**6),
    "negative rows": _array("push", "rows", lambda a: a - 10**6),
    "rows as floats": _array("push", "rows", lambda a: a.astype(np.float64)),
    "residues past the segment": _array("push", "residues", lambda a: a + 5000),
    "coordinates that do not match the rows": _array("push", "new_coords", lambda a: a[1:]),
    "infinite coordinates": _array("push", "old_coords", lambda a: a * np.inf),
    "an unknown record kind": _kind("push", "pull"),
    "an index without its level": _drop("index", "level"),
    "index past the steps": _set("index", "index", 99),
    "clean past the steps": _set("index", "clean", 99),
    "level NaN": _set("index", "level", float("nan")),
    "multiresolution as text": _set("index", "multiresolution", "yes"),
    "unknown colouring": _set("view", "colouring", "plaid"),
    "camera of two points": _set("view", "camera", [[0, 0, 1], [0, 0, 0]]),
    "camera with NaN": _set("view", "camera", [[float("nan")] * 3, [0, 0, 0], [0, 1, 0]]),
    "camera on its focal point": _set("view", "camera", [[1, 2, 3], [1, 2, 3], [0, 1, 0]]),
    "layers as text": _set("view", "layers", "cartoon"),
    "compared without its bytes": _set("view", "compared", [{"path": "x.pdb", "chain": "A", "visible": True}]),
    "measurement of no atoms": _set("view", "measurements", [{"atoms": [10**9]}]),
    "a selected residue past the residues": _array("view", "selected_residues", lambda a: np.array([10**6])),
    "a protein atom selected as a group": _array("view", "selected_groups", lambda a: np.array([0])),
    "a selection of floats": _array("view", "selected_groups", lambda a: np.array([0.5])),
    "a selection of negative rows": _array("view", "selected_residues", lambda a: np.array([-3])),
    "edits made on another structure": _other_structure,
}


def _deep(entries: list[records.Record]) -> bytes:
    """A push record whose position is nested 100,000 lists deep (json's recursion limit)."""
    return _file(entries[:2]) + _frame(b'{"record":"push","at":' + b"[" * 100_000 + b"]" * 100_000 + b"}\n")


def _long(entries: list[records.Record]) -> bytes:
    """A record whose length field claims 4 GiB."""
    return _file(entries[:2]) + struct.pack("<II", 2**32 - 1, 0) + b'{"record":"index"}\n'


@pytest.mark.parametrize("case", [*CORPUS, "deep nesting", "a length past memory"])
def test_a_hostile_session_is_refused_or_opened_as_far_as_it_is_valid(qtbot: QtBot, tmp_path: Path,
                                                                       shown: list[str], case: str) -> None:
    window = _edited(qtbot)
    saved = window.sessions.write_session(tmp_path / "good")
    entries = records.read(saved).records
    data = {"deep nesting": _deep, "a length past memory": _long}.get(case, lambda e: _file(CORPUS[case](e)))(entries)
    hostile = tmp_path / "hostile.rwsession"
    hostile.write_bytes(data)
    opened = window.sessions.open_session(hostile)
    assert len(shown) == 1  # a message either way: what was left out, or why nothing could be opened
    if opened:
        _consistent(window)
        assert "opened as far as it is valid; left out:" in shown[0]
    else:
        assert shown[0].startswith(str(hostile))
    if case == "edits made on another structure":
        assert opened and window.document.undo_stack.count() == 0 and "step 1 (" in shown[0]
    if case in ("rows past the atoms", "an unknown record kind"):  # the later steps built on it go too
        assert opened and window.document.undo_stack.count() == 0


def test_an_unknown_record_kind_never_shifts_the_history(qtbot: QtBot, tmp_path: Path, shown: list[str]) -> None:
    """A step renamed to a kind this version does not know used to be skipped while the steps
    after it were pushed on the wrong state: undo-all left 74 atoms off (#37, item 7)."""
    window = _edited(qtbot)
    entries = records.read(window.sessions.write_session(tmp_path / "good")).records
    pushes = [k for k, e in enumerate(entries) if e.kind == "push"]
    entries[pushes[1]] = records.Record("pull", entries[pushes[1]].fields, entries[pushes[1]].arrays)
    (tmp_path / "renamed.rwsession").write_bytes(_file(entries))
    assert window.sessions.open_session(tmp_path / "renamed.rwsession")
    assert window.document.undo_stack.count() == 1  # the first step; the rest were built on the renamed one
    assert "unknown record kind 'pull'" in shown[0] and "a step before it is missing" in shown[0]
    _consistent(window)


# ---------------------------------------------------------------------------- fuzzing

HOSTILE = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(), st.text(max_size=12),
    st.lists(st.integers(-3, 3), max_size=4), st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    st.sampled_from(["peptide", "calpha", "chain", "\x1b[2J", [[0, 0, 1], [0, 0, 0], [0, 1, 0]], [[[[]]]]]),
)
DTYPES = st.sampled_from(["<f8", ">f8", "<f4", "<i8", ">i4", "|u1", "|b1"])


@st.composite
def _mutation(draw: st.DrawFn, entries: list[records.Record]) -> list[records.Record]:
    """``entries`` with one to three changes of a field, an array or a record."""
    entries = list(entries)
    for _ in range(draw(st.integers(1, 3))):
        k = draw(st.integers(0, len(entries) - 1))
        entry = entries[k]
        what = draw(st.sampled_from(["field", "drop field", "array", "array values", "kind", "record"]))
        fields, arrays = dict(entry.fields), dict(entry.arrays)
        if what == "field":
            fields[draw(st.sampled_from([*fields, "extra"]))] = draw(HOSTILE)
        elif what == "drop field" and fields:
            del fields[draw(st.sampled_from(sorted(fields)))]
        elif what == "array" and arrays:
            name = draw(st.sampled_from(sorted(arrays)))
            shape = draw(st.lists(st.integers(0, 5), min_size=1, max_size=3))
            arrays[name] = np.zeros(shape, dtype=np.dtype(draw(DTYPES)))
        elif what == "array values" and arrays:
            name = draw(st.sampled_from(sorted(arrays)))
            values = arrays[name].copy()
            if values.size:
                choices = [0, 1, -1, 255, 10**6, *([np.nan] if values.dtype.kind == "f" else [])]
                value = np.array(draw(st.sampled_from(choices))).astype(values.dtype)
                values.flat[draw(st.integers(0, values.size - 1))] = value  # (wrapped into the array's type)
            arrays[name] = values
        elif what == "kind":
            entry = records.Record(draw(st.sampled_from(["header", "base", "push", "index", "state", "view", "x"])),
                                   fields, arrays)
            entries[k] = entry
            continue
        elif what == "record":
            j = draw(st.integers(0, len(entries) - 1))
            action = draw(st.sampled_from(["drop", "repeat", "swap"]))
            if action == "drop" and len(entries) > 1:
                del entries[k]
            elif action == "repeat":
                entries.insert(j, entry)
            else:
                entries[k], entries[j] = entries[j], entries[k]
            continue
        entries[k] = records.Record(entry.kind, fields, arrays)
    return entries


@pytest.fixture
def edited_files(qtbot: QtBot, tmp_path: Path) -> tuple[MainWindow, list[records.Record], list[records.Record]]:
    """A window with the records of a session of its edits and of its journal."""
    window = _edited(qtbot)
    session_entries = records.read(window.sessions.write_session(tmp_path / "good")).records
    journal_entries = records.read(window.journal.path).records
    return window, session_entries, journal_entries


@FUZZ
@given(data=st.data())
def test_mutated_sessions_never_crash(edited_files, tmp_path: Path, shown: list[str], data: st.DataObject) -> None:
    window, entries, _ = edited_files
    mutated = data.draw(_mutation(entries))
    path = tmp_path / "fuzzed.rwsession"
    path.write_bytes(_file(mutated))
    shown.clear()
    if window.sessions.open_session(path):
        _consistent(window)
    else:
        assert len(shown) == 1 and shown[0].startswith(str(path))


@FUZZ
@given(data=st.data())
def test_mutated_journals_restore_as_far_as_valid_or_are_kept(edited_files, tmp_path: Path, shown: list[str],
                                                              data: st.DataObject) -> None:
    window, _, entries = edited_files
    folder = tmp_path / "journals"
    folder.mkdir(exist_ok=True)
    for left in folder.iterdir():
        left.unlink()
    raw = _file(data.draw(_mutation(entries)))
    if data.draw(st.booleans()):  # and damage at the byte level: bytes flipped, lost, or a cut
        raw = bytearray(raw)
        at = data.draw(st.integers(len(records.MAGIC), len(raw) - 1))
        action = data.draw(st.sampled_from(["flip", "lose", "cut"]))
        if action == "flip":
            raw[at] ^= data.draw(st.integers(1, 255))
        elif action == "lose":
            del raw[at : at + data.draw(st.integers(1, 300))]
        else:
            del raw[at:]
        raw = bytes(raw)
    path = folder / f"journal-fuzzed{journal.SUFFIX}"
    path.write_bytes(raw)
    left, aside = journal.sweep(folder)
    files = sorted(p.name for p in folder.iterdir())
    assert files in ([path.name], [path.name + journal.SET_ASIDE], [])  # never renamed elsewhere
    if not files:  # deleted only where nothing can be read past its header and it holds no step
        assert "push" not in [e.kind for e in _readable(raw)]
        return
    if left:
        try:
            message = window.sessions.restore_journal(path)
        except (OSError, records.RecordError, StructureError) as error:  # what the recovery prompt reports
            assert str(error)
            assert path.exists()  # not restored: kept as it was
            return
        assert message.startswith("restored")
        _consistent(window)
        kept = path.with_name(path.name + journal.SET_ASIDE)
        assert kept.read_bytes() == raw if "left out" in message else not kept.exists()
    else:
        assert aside or not files


def _readable(raw: bytes) -> list[records.Record]:
    try:
        return records.decode(raw).records
    except records.RecordError:
        return []


def test_a_restored_journal_with_damage_mid_file_keeps_every_later_step(qtbot: QtBot, tmp_path: Path) -> None:
    """33 journals with one bad byte gave back 28 of 150 intact steps (#37, item 2): the steps
    after the damage that were made on what was restored now come back, and the file is kept."""
    crashed = _window(qtbot, DATA / "1UBQ.pdb.gz")
    crashed.document.set_regularization(on_release=False)
    n = len(crashed.rw.points())
    for k in range(6):
        crashed.rw.move((k * 5) % n, [1.0, -0.5 * k, 0.5])
    history, coords = crashed.rw.history(), crashed.rw.coords()
    path = crashed.journal.path
    crashed.files.unattended = True
    crashed.close()
    entries = records.read(path).records
    ends = np.cumsum([len(records.MAGIC)] + [len(records.encode(e)) for e in entries])
    index_records = [k for k, e in enumerate(entries) if e.kind == "index"]
    data = bytearray(path.read_bytes())
    data[int(ends[index_records[2] + 1]) - 3] ^= 0x40  # inside the third index record: only a position is lost
    path.write_bytes(bytes(data))
    window = _window(qtbot, DATA / "3PTB.pdb.gz")
    message = window.sessions.restore_journal(path)
    assert window.rw.history() == history and np.array_equal(window.rw.coords(), coords)
    kept = path.with_name(path.name + journal.SET_ASIDE)
    assert "damaged bytes" in message and str(kept) in message and kept.read_bytes() == bytes(data)


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_session_that_is_not_a_regular_file_is_refused_at_once(qtbot: QtBot, tmp_path: Path, shown: list[str],
                                                                 kind: str) -> None:
    """A FIFO named ``.rwsession`` hung the editor; /dev/zero exhausted its memory (#37, item 8)."""
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    path = tmp_path / "odd.rwsession"
    if kind == "fifo":
        os.mkfifo(path)
    else:
        path.symlink_to("/dev/zero")
    assert not window.sessions.open_session(path)
    assert "not a regular file" in shown[0]
    folder = tmp_path / "state"
    folder.mkdir()
    os.mkfifo(folder / f"journal-1{journal.SUFFIX}")
    assert journal.sweep(folder)[0] == []  # a FIFO among the journals never blocks the start


def test_the_schema_takes_what_this_version_writes_and_names_what_it_refuses() -> None:
    from app.editor.persistence import schema

    rng = np.random.default_rng(0)
    edit_arrays = {name: rng.normal(size=(4, 3)) for name in ("old_points", "new_points")}
    edit_arrays |= {"residues": np.arange(2), "rows": np.arange(3), "old_coords": np.zeros((3, 3)),
                    "new_coords": np.ones((3, 3))}
    push = records.Record("push", {"at": 0, "text": "Move", "segment": 0}, edit_arrays)
    assert schema.problem(push.kind, push.fields, push.arrays) is None
    assert "'at' must be an integer" in schema.problem("push", {**push.fields, "at": 1.5}, push.arrays)
    assert json.loads(records.encode(push)[8:].partition(b"\n")[0])["record"] == "push"
