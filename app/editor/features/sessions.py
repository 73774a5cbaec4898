"""Sessions and crash recovery: File ▸ Open Session and Save Session, and the unsaved edits
of an editor that did not close cleanly restored from its journal.

A session (:mod:`app.editor.persistence.session`) holds the document's recording and what the
window shows: the display layers and colouring, the camera and the compared structures. A
restored document is journalled anew; compared structures are dropped first.
"""

from __future__ import annotations

import errno
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import QFileDialog, QMainWindow, QMessageBox

from app import PROG
from app.editor.measurements import checked
from app.editor.persistence import journal, records, session
from app.editor.persistence.recording import recording, replay
from app.editor.scene.molecule import Colouring
from app.errors import printable
from core.protein.input_files import StructureError

if TYPE_CHECKING:
    from app.editor.docks.panels import DisplayPanel
    from app.editor.document import Document
    from app.editor.features.clipping import Clipping
    from app.editor.features.files import Files
    from app.editor.features.menus import Menus
    from app.editor.scene.overlay import Comparison
    from app.editor.scene.scene import Scene
    from app.editor.scene.view import View

SESSION_FILTER = f"ribbonwave sessions (*{session.SUFFIX});;All files (*)"


class Sessions:
    """Sessions of ``window``'s ``document`` and its recovery from ``journal``; the view of a
    session is that of ``plotter``, ``scene``, ``display_panel`` and ``comparison``."""

    def __init__(self, window: QMainWindow, document: Document, journal: journal.Journal, files: Files,
                 menus: Menus, *, plotter: View, scene: Scene, display_panel: DisplayPanel,
                 comparison: Comparison, clipping: Clipping) -> None:
        self.window = window
        self.document = document
        self.journal = journal
        self.files = files
        self.plotter = plotter
        self.scene = scene
        self.display_panel = display_panel
        self.comparison = comparison
        self.clipping = clipping
        self.open_session_action = menus.action("Open Sess&ion…", QKeySequence("Ctrl+Shift+O"),
                                                self._open_session_dialog)
        self.save_session_action = menus.action("Save Sessio&n…", QKeySequence("Ctrl+Alt+S"), self.save_session)
        menus.add("session", self.open_session_action, self.save_session_action)
        files.open_with(session.SUFFIX, self.open_session)

    def open_session(self, path: Path, *, raise_errors: bool = False) -> bool:
        """Open a session file after asking about unsaved edits: the structure, the undo history at
        its position, the view and the compared structures, as far as the file is valid (what was
        left out is named in a warning, or on standard error when unattended). A file that cannot
        be opened at all is reported in a dialog, or raised as SessionError with ``raise_errors``."""
        if not self.files.maybe_save():
            return False
        try:
            contents = session.read(Path(path))
            try:
                left_out = contents.left_out + self._replay(contents.recording)
            except StructureError as error:
                raise session.SessionError(f"{path}: its structure cannot be read ({error})") from None
        except session.SessionError as error:
            if raise_errors:
                raise
            QMessageBox.critical(self.window, PROG, str(error))
            return False
        if contents.view is not None:
            left_out += self._apply_view(contents.view)
        self.files.add_recent(Path(path))
        if left_out:
            self._warn(f"{Path(path).name} was opened as far as it is valid; left out: {left_out_text(left_out)}")
        return True

    def write_session(self, path: Path, *, overwrite: bool = False) -> Path:
        """Save the session to ``path`` (``.rwsession`` added if missing); an existing file only
        with ``overwrite`` (else FileExistsError); raises OSError."""
        if self.document.model is None:
            raise RuntimeError("no structure is open")
        path = Path(path) if Path(path).name.endswith(session.SUFFIX) else Path(f"{path}{session.SUFFIX}")
        if not overwrite and (path.exists() or path.is_symlink()):
            raise FileExistsError(errno.EEXIST, "refusing to overwrite an existing file (overwrite=True replaces it)",
                                  str(path))
        session.write(path, recording(self.document), self._view())
        return path

    def save_session(self) -> bool:
        """Ask for a file name and save the session there."""
        if self.document.model is None:
            return False
        name, _ = QFileDialog.getSaveFileName(self.window, "Save Session", str(self.files.suggested(session.SUFFIX)),
                                              SESSION_FILTER)
        if not name:
            return False
        path = Path(name) if name.endswith(session.SUFFIX) else Path(f"{name}{session.SUFFIX}")
        buttons = QMessageBox.StandardButton
        if path != Path(name) and path.exists() and QMessageBox.question(  # (the dialog asked about the name without it)
                self.window, PROG, f"{path.name} exists. Replace it?", buttons.Yes | buttons.No) != buttons.Yes:
            return False
        try:
            self.write_session(path, overwrite=True)
        except OSError as error:
            QMessageBox.critical(self.window, PROG, f"cannot write {name}: {error.strerror or error}")
            return False
        return True

    def restore_journal(self, path: Path) -> str:
        """Restore the document a crashed editor journalled at ``path`` as far as the journal is
        valid; returns what was restored (raises OSError, RecordError or StructureError). The
        journal is deleted, or set aside (``.unreadable``) where anything in it was left out."""
        reading = records.read(Path(path))
        if not reading.records:
            raise records.RecordError("it is cut off inside its header: it holds no step")
        left_out = reading.skipped + self._replay(reading.records)
        stack = self.document.undo_stack
        message = f"restored {stack.count()} undo step(s) of {self.document.path.name}, {stack.index()} done"
        if left_out:
            kept = Path(path).with_name(Path(path).name + journal.SET_ASIDE)
            Path(path).rename(kept)
            message += f"; left out: {left_out_text(left_out)} (the journal is kept as {kept})"
        else:
            Path(path).unlink(missing_ok=True)
        if reading.cut_off:
            message += "; the journal was cut off after them (the step in progress at the crash is lost)"
        self.window.statusBar().showMessage(message, 15000)
        return message

    def offer_recovery(self) -> None:
        """If an editor ended without closing cleanly, offer to restore its unsaved edits."""
        left, aside = journal.sweep(self.journal.folder)
        if aside:
            QMessageBox.warning(self.window, PROG, f"{len(aside)} journal(s) of unsaved edits could not be read "
                                "(written by a newer ribbonwave, or damaged) and are kept, not deleted: "
                                + ", ".join(path.name for path in aside) + f" in {self.journal.folder}.")
        if not left:
            return
        buttons = QMessageBox.StandardButton
        answer = QMessageBox.question(
            self.window, PROG, f"ribbonwave did not close cleanly last time. Restore the unsaved edits of "
            f"{journal_subject(left[0])} ({time_label(left[0])})? Discard deletes them; Ignore keeps them for later.",
            buttons.Yes | buttons.Discard | buttons.Ignore, buttons.Yes)
        if answer == buttons.Yes:
            try:
                self.restore_journal(left[0])
            except (OSError, records.RecordError, StructureError) as error:
                QMessageBox.critical(self.window, PROG, f"cannot restore {left[0].name}: {error}")
        elif answer == buttons.Discard:
            left[0].unlink(missing_ok=True)

    def _open_session_dialog(self) -> None:
        folder = str(self.document.path.parent) if self.document.path else str(Path.home())
        name, _ = QFileDialog.getOpenFileName(self.window, "Open Session", folder, SESSION_FILTER)
        if name:
            self.open_session(Path(name))

    def _replay(self, recorded: list[records.Record]) -> list[str]:
        """The document as ``recorded`` says, journalled anew; compared structures are dropped.
        Returns the steps left out (:func:`~app.editor.persistence.recording.replay`)."""
        self.journal.discard()
        while self.comparison.items:
            self.comparison.remove(0)
        left_out = replay(self.document, recorded)
        self.journal.write_all()
        return left_out

    def _warn(self, message: str) -> None:
        """``message`` in a warning, or on standard error when nobody watches (a script)."""
        if self.files.unattended:
            print(f"{PROG}: {printable(message)}", file=sys.stderr)
        else:
            QMessageBox.warning(self.window, PROG, message)

    def _view(self) -> session.View:
        compared = [session.ComparedFile(item.path, item.source, item.chain, item.visible)
                    for item in self.comparison.items]
        camera = [list(map(float, vector)) for vector in self.plotter.camera_position]
        return session.View(sorted(layer.name for layer in self.scene.layers), self.scene.colouring.value,
                            self.scene.fat_helices, camera, compared, self.scene.helix_cylinders,
                            [m.record() for m in self.document.measurements.items],
                            None if self.scene.slab is None else list(self.scene.slab),
                            (self.document.selection, self.document.selected_groups))

    def _apply_view(self, view: session.View) -> list[str]:
        """Show ``view``; returns the measurements, selection and compared structures left out, and why."""
        for layer, box in self.display_panel.layer_boxes.items():
            box.setChecked(layer.name in view.layers)
        panel = self.display_panel
        panel.colouring.setCurrentIndex(max(panel.colouring.findData(Colouring(view.colouring)), 0))
        panel.fat.setChecked(view.fat_helices)
        panel.cylinders.setChecked(view.helix_cylinders)
        self.clipping.set(None if view.slab is None else (view.slab[0], view.slab[1]))
        measured, left_out = [], []
        for kept in view.measurements:
            try:
                measured.append(checked(kept.get("atoms"), len(self.document.model.coords), bool(kept.get("residue"))))
            except (AttributeError, TypeError, ValueError) as error:  # a session written by hand, or damaged
                left_out.append(f"a measurement ({error})")
        self.document.measurements.replace(measured)  # drawn and listed once
        try:
            self.document.select(*view.selection)
        except ValueError as error:
            left_out.append(f"the selection ({error})")
        for item in view.compared:
            try:
                self.comparison.add(item.path, item.chain, item.source)
            except (StructureError, ValueError) as error:
                left_out.append(f"compared structure {item.path.name} ({error})")
                continue
            self.comparison.set_visible(len(self.comparison.items) - 1, item.visible)
        self.plotter.camera_position = [tuple(vector) for vector in view.camera]
        self.plotter.render()
        return left_out


def journal_subject(path: Path) -> str:
    """The name of the file whose edits the journal at ``path`` holds ('the edits' if unreadable)."""
    try:
        entries = records.read(path).records
    except (OSError, records.RecordError):
        return "a structure"
    return Path(entries[0].fields["path"]).name if entries else "a structure"


def time_label(path: Path) -> str:
    """When the journal at ``path`` was last written, for people."""
    return "last edit " + time.strftime("%Y-%m-%d %H:%M", time.localtime(path.stat().st_mtime))


def left_out_text(left_out: list[str], shown: int = 5) -> str:
    """What was left out of a file, for people: the first ``shown`` things and how many more."""
    more = len(left_out) - shown
    return "; ".join(left_out[:shown]) + (f"; and {more} more" if more > 0 else "")
