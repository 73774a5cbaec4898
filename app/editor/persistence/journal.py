"""Crash recovery: the document's undo steps appended to a journal file as they happen.

A journal lives in :func:`~app.editor.persistence.folder.state_folder` from the first undo
step of a structure until the document is closed cleanly (saved, or its edits discarded). It
starts with the file as read (and where the undo history starts, once its oldest steps were
dropped) and then gets one record per step: each new undo step as the deltas of its
:class:`~core.protein.model.Edit`, each undo or redo as the new stack position, and the level
and segment shortly after they change (:mod:`app.editor.persistence.records`). Every record goes
to the operating system at once, so a kill loses at most the step being written, and to the
disk within :data:`SYNC_DELAY_MS` (in a background thread). A running editor holds a lock on
its journal; a journal nobody holds was left by a crash (:func:`orphans`). On a save, and when
the history drops its oldest steps, the journal is rewritten as the history then is, so that
it grows no larger than the history.
"""

from __future__ import annotations

import contextlib
import fcntl
import itertools
import os
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import shiboken6
from PySide6.QtCore import QObject, QTimer

from app.editor.document import Document
from app.editor.persistence import recording, records
from app.editor.persistence.folder import checked_folder, state_folder

SUFFIX = ".rwjournal"
SET_ASIDE = ".unreadable"
"""Added to the name of a journal that cannot be read (:func:`sweep`): kept for a newer
ribbonwave or a person to recover, never swept again."""
OPENING = ".opening"
"""Added to the name of a journal while it is created, locked and given its header: no sweep
sees it before its editor holds it."""
SYNC_DELAY_MS = 500
"""A written record reaches the disk (fsync) this long after it was written, at most."""
STATE_DELAY_MS = 500
"""The level and segment are journalled this long after they last changed."""


class Journal(QObject):
    """Journals every step of ``document`` to a file of its own in ``folder``."""

    def __init__(self, document: Document, folder: Path | None = None) -> None:
        super().__init__(document)
        self.document = document
        self.folder = state_folder() if folder is None else Path(folder)
        self.path: Path | None = None
        """The journal file; None until the first step of the current structure."""
        self.kept: Path | None = None
        """The last journal closed and left for ``--recover`` (:meth:`keep`)."""
        self._fd: int | None = None
        self._mirror: list[object] = []  # the undo commands journalled, by stack position
        self._last: dict | None = None  # the state of the last index record
        self._stopped = False
        self._sync = ThreadPoolExecutor(max_workers=1, thread_name_prefix="journal-sync")
        self._sync_timer = QTimer(self, singleShot=True, interval=SYNC_DELAY_MS)
        self._sync_timer.timeout.connect(self._schedule_sync)
        self._state_timer = QTimer(self, singleShot=True, interval=STATE_DELAY_MS)
        self._state_timer.timeout.connect(self._write_state)
        document.loaded.connect(self._restart)
        document.undo_stack.indexChanged.connect(self._step)
        document.undo_stack.cleanChanged.connect(self._step)
        document.levelChanged.connect(self._state_changed)
        document.segmentChanged.connect(self._state_changed)
        document.history.trimmed.connect(self._compact)
        document.saved.connect(self._compact)

    def discard(self) -> None:
        """Close and delete the journal (the document was closed cleanly)."""
        path = self.path
        self._close()
        if path is not None:
            with contextlib.suppress(FileNotFoundError):
                path.unlink()

    def keep(self) -> None:
        """Close the journal and leave it for ``ribbonwave --recover``."""
        if self.path is not None:
            self.kept = self.path
        self._close()

    def stop(self) -> None:
        """Stop journalling (the window closes): the file is kept as it is, if any."""
        self.keep()
        if not self._stopped:
            self._stopped = True
            stack = self.document.undo_stack
            stack.indexChanged.disconnect(self._step)
            stack.cleanChanged.disconnect(self._step)

    def write_all(self) -> None:
        """Journal the whole document at once (after a restore: the history is not new)."""
        self.discard()
        stack = self.document.undo_stack
        if self.document.model is not None and stack.count():
            self._open_file()
            self._write(*recording.recording(self.document)[1:])
            self._mirror = [stack.command(k) for k in range(stack.count())]
            self._last = recording.state(self.document)

    # ------------------------------------------------------------------ internals

    def _compact(self) -> None:
        """The journal rewritten as the history now is (after a save, or once its oldest steps
        were dropped): steps undone and replaced, and older positions, are left behind."""
        if self._fd is not None and not self.document.replaying:
            self.write_all()

    def _restart(self) -> None:
        """A new structure: the old journal is done with (the window asked about its edits)."""
        if not self.document.replaying:
            self.discard()

    def _step(self) -> None:
        document = self.document
        stack = document.undo_stack
        if not shiboken6.isValid(stack) or document.replaying or document.model is None:
            return  # a stack being destroyed (its document dropped) reports its last changes
        if self._fd is None:
            if stack.count() == 0:
                return
            self._open_file()
        entries = []
        count = stack.count()  # a push replaces the commands above the position with one
        top = stack.command(count - 1) if count else None
        if count and (len(self._mirror) < count or self._mirror[count - 1] is not top):
            entries.append(records.push(count - 1, top.text(), top.edits))
            self._mirror[count - 1 :] = [top]
        del self._mirror[count:]
        state = recording.state(document)
        if entries or state != self._last:  # indexChanged and cleanChanged may both report one step
            self._state_timer.stop()
            self._write(*entries, records.Record("index", state))
            self._last = state

    def _state_changed(self) -> None:
        if self._fd is not None and not self.document.replaying:
            self._state_timer.start()

    def _write_state(self) -> None:
        if self._fd is not None:
            state = recording.state(self.document)
            self._write(records.Record("state", {k: state[k] for k in ("level", "segment", "multiresolution")}))

    def _open_file(self) -> None:
        self.folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        stem = f"journal-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}-{id(self):x}"
        for again in itertools.count():  # a journal kept within the same second keeps its name
            self.path = self.folder / f"{stem}{f'-{again}' if again else ''}{SUFFIX}"
            try:
                self._fd = os.open(self.path.with_name(self.path.name + OPENING),
                                   os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_APPEND, 0o600)
            except FileExistsError:
                continue
            if not self.path.exists():
                break
            os.close(self._fd)
            os.unlink(self.path.with_name(self.path.name + OPENING))
        fcntl.flock(self._fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # held while this editor runs
        document = self.document
        os.write(self._fd, records.MAGIC + records.encode(records.header(document.path, document.kind.value,
                                                                             document.source, document.model_number)))
        os.rename(self.path.with_name(self.path.name + OPENING), self.path)  # (the lock goes with the file)
        self._mirror = []

    def _write(self, *entries: records.Record) -> None:
        os.write(self._fd, b"".join(records.encode(record) for record in entries))
        if not self._sync_timer.isActive():
            self._sync_timer.start()

    def _schedule_sync(self) -> None:
        if self._fd is not None:
            self._sync.submit(os.fsync, self._fd)

    def _close(self) -> None:
        self._state_timer.stop()
        self._sync_timer.stop()
        if self._fd is not None:
            self._sync.submit(os.fsync, self._fd).result()
            os.close(self._fd)  # releases the lock
        self._fd, self.path, self._mirror, self._last = None, None, [], None


def orphans(folder: Path | None = None) -> list[Path]:
    """Journals left by editors that ended without closing cleanly, newest first (see :func:`sweep`)."""
    return sweep(folder)[0]


def sweep(folder: Path | None = None) -> tuple[list[Path], list[Path]]:
    """The journals left by editors that ended without closing cleanly, newest first, and those
    set aside now: a journal nobody holds that holds no undo step is deleted; one whose steps
    cannot be read (a newer format, a damaged header) is renamed with :data:`SET_ASIDE`, never
    deleted. Raises PermissionError for a folder that is not the user's alone (:func:`checked_folder`)."""
    folder = checked_folder(state_folder() if folder is None else Path(folder))
    found, aside = [], []
    for path in folder.glob(f"*{SUFFIX}"):
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # (a FIFO never blocks the start)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            continue  # a running editor holds it
        finally:
            os.close(fd)
        try:
            reading = records.read(path)
            recording, damaged = reading.records, reading.damaged
        except OSError:
            continue  # (unreadable now: left for the next sweep)
        except records.RecordError:
            recording, damaged = [], True
        if any(record.kind == "push" for record in recording):
            found.append(path)
        elif damaged:  # (its steps may lie past the damage: a person or a newer version may restore them)
            aside.append(path.with_name(path.name + SET_ASIDE))
            path.rename(aside[-1])
        else:
            path.unlink(missing_ok=True)
    return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True), aside
