"""Structure files: File ▸ Open, Open Recent, Save, Save As and Quit, files dropped on the
window, the window's title, and the question before unsaved edits would be lost.

Unsaved edits are never lost silently: :meth:`Files.maybe_save` asks whether to save them
(unattended, they stay in the recovery journal instead). Open Recent lists structures and
sessions; a kind of file another feature opens (sessions) registers its opener
(:meth:`Files.open_with`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import (
    QFileDialog,
    QInputDialog,
    QMainWindow,
    QMessageBox,
    QStyle,
)

from app import EXAMPLES_DIR, PROG
from app.editor import busy
from core.protein.assembly import assemblies, assembly_path
from core.protein.input_files import StructureError

if TYPE_CHECKING:
    from PySide6.QtCore import QSettings

    from app.editor.document import Document
    from app.editor.features.menus import Menus
    from app.editor.persistence.journal import Journal

RECENT_KEY = "recentFiles"
MAX_RECENT = 8
STRUCTURE_FILTER = "Structures (*.pdb *.ent *.cif *.mmcif *.gz);;All files (*)"
SAVE_FILTERS = {"PDB (*.pdb *.pdb.gz *.ent)": ".pdb", "mmCIF (*.cif *.cif.gz *.mmcif)": ".cif"}
SAVE_SUFFIXES = (".pdb", ".ent", ".cif", ".mmcif", ".pdb.gz", ".ent.gz", ".cif.gz", ".mmcif.gz")


class Files:
    """The structure files of ``window``'s ``document``, recent ones kept in ``settings``."""

    def __init__(self, window: QMainWindow, document: Document, journal: Journal, settings: QSettings,
                 menus: Menus) -> None:
        self.window = window
        self.document = document
        self.journal = journal
        self.settings = settings
        self.unattended = False
        """Run by a script: no dialog waits for a person, and unsaved edits stay in the journal."""
        self._openers: dict[str, Callable[[Path], object]] = {}
        icon, pixmap = window.style().standardIcon, QStyle.StandardPixmap
        self.open_action = menus.action("&Open…", QKeySequence.StandardKey.Open, self._open_dialog,
                                        icon(pixmap.SP_DialogOpenButton))
        self.save_action = menus.action("&Save", QKeySequence.StandardKey.Save, self.save,
                                        icon(pixmap.SP_DialogSaveButton))
        self.save_as_action = menus.action("Save &As…", QKeySequence.StandardKey.SaveAs, self.save_as)
        self.quit_action = menus.action("&Quit", QKeySequence.StandardKey.Quit, window.close)
        menus.add("open", self.open_action)
        self.assembly_action = menus.add_entry("open", "Open Biological &Assembly…", self.open_assembly_dialog)
        self.recent_menu = menus.add_menu("open", "Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        menus.add("save", self.save_action, self.save_as_action)
        menus.add("quit", self.quit_action)
        menus.add_tools("file", self.open_action, self.save_action)
        document.fileChanged.connect(self._update_title)
        self._update_title()

    @contextmanager
    def opening(self, path: Path) -> Iterator[None]:
        """While ``path`` is read and drawn, the window busy with it (:func:`app.editor.busy.opening`);
        then its title names the document."""
        try:
            with busy.opening(self.window, path):
                yield
        finally:
            self._update_title()

    def open_file(self, path: Path, *, raise_errors: bool = False) -> bool:
        """Open ``path`` after asking about unsaved edits; a bad file is reported in a dialog
        (or raised as StructureError with ``raise_errors``)."""
        if not self.maybe_save():
            return False
        try:
            with self.opening(Path(path)):
                self.document.open(Path(path))
        except StructureError as error:
            if raise_errors:
                raise
            QMessageBox.critical(self.window, PROG, str(error))
            return False
        self.add_recent(Path(path))
        return True

    def open_assembly_dialog(self) -> bool:
        """Choose one of the biological assemblies of the structure's file and open it (after
        asking about unsaved edits); a file without assembly records is answered so."""
        document = self.document
        if document.model is None or document.path is None:
            return False
        try:
            choices = assemblies(document.path, document.source, model=document.model_number)
        except StructureError as error:
            QMessageBox.critical(self.window, PROG, str(error))
            return False
        if not choices:
            QMessageBox.information(self.window, PROG, f"{document.path.name} has no biological assembly records "
                                    "(REMARK 350 or _pdbx_struct_assembly).")
            return False
        items = [choice.describe() + (f" ({choice.details})" if choice.details else "") for choice in choices]
        item, chosen = QInputDialog.getItem(self.window, "Open Biological Assembly",
                                            f"Assemblies of {document.path.name}:", items, 0, False)
        if not chosen or not self.maybe_save():
            return False
        path, source, model, number = document.path, document.source, document.model_number, items.index(item) + 1
        try:
            with self.opening(assembly_path(path, number)):  # a capsid takes seconds
                document.open(path, document.kind, data=source, model=model, assembly=number)
        except StructureError as error:
            QMessageBox.critical(self.window, PROG, str(error))
            return False
        return True

    def open_with(self, suffix: str, open_: Callable[[Path], object]) -> None:
        """Open files whose names end with ``suffix`` with ``open_`` when chosen in Open Recent."""
        self._openers[suffix] = open_

    def save(self) -> bool:
        """Save to the file chosen by the last Save As; the first Save of a file asks where."""
        if self.document.model is None:
            return False
        if self.document.save_path is None:
            return self.save_as()
        return self.write(self.document.save_path)

    def save_as(self) -> bool:
        """Ask for a file name (PDB or mmCIF by its extension) and save there."""
        if self.document.model is None:
            return False
        suffix = ".cif" if self.document.structure.source_format == "mmcif" else ".pdb"
        name, chosen = QFileDialog.getSaveFileName(self.window, "Save As", str(self.suggested(f"_edited{suffix}")),
                                                   ";;".join(SAVE_FILTERS))
        if not name:
            return False
        path = Path(name)
        if not path.name.lower().endswith(SAVE_SUFFIXES):  # the dialog asked about the name without it
            path = path.with_name(path.name + SAVE_FILTERS.get(chosen, suffix))
            replace = QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No
            if path.exists() and QMessageBox.question(self.window, PROG, f"{path.name} exists. Replace it?",
                                                      replace) != QMessageBox.StandardButton.Yes:
                return False
        return self.write(path)

    def write(self, path: Path) -> bool:
        """Save the structure to ``path`` (it becomes the document's file); a failure is
        reported in a dialog."""
        try:
            self.document.save(path, overwrite=True)
        except (StructureError, OSError) as error:
            QMessageBox.critical(self.window, PROG, str(error))
            return False
        self.add_recent(path)
        return True

    def maybe_save(self) -> bool:
        """True when it is fine to drop the document: no unsaved edits, saved, or discarded
        (unattended, the edits stay in the journal). The journal of a document dropped
        without unsaved edits is deleted."""
        if not self.document.modified:
            self.journal.discard()
            return True
        if self.unattended:
            self.journal.keep()
            return True
        name = self.document.path.name if self.document.path else "the structure"
        answer = QMessageBox.question(
            self.window, PROG, f"Save the changes to {name}?",
            QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard | QMessageBox.StandardButton.Cancel,
        )
        if answer == QMessageBox.StandardButton.Save:
            saved = self.save()
            if saved:
                self.journal.discard()
            return saved
        if answer == QMessageBox.StandardButton.Discard:
            self.journal.discard()
            return True
        return False

    def suggested(self, ending: str) -> Path:
        """A file name to offer for saving: the structure's name with ``ending``, beside it
        (in the home folder for the bundled examples)."""
        source = self.document.path
        folder = Path.home() if source is None or source.parent == EXAMPLES_DIR else source.parent
        return folder / f"{source.name.split('.')[0] if source is not None else 'structure'}{ending}"

    def recent_files(self) -> list[str]:
        """Files opened or saved lately, newest first (absolute paths)."""
        value = self.settings.value(RECENT_KEY, [])
        return [value] if isinstance(value, str) else list(value or [])

    def add_recent(self, path: Path) -> None:
        """Put ``path`` first in File ▸ Open Recent."""
        name = str(path.resolve())
        files = [name] + [f for f in self.recent_files() if f != name]
        self.settings.setValue(RECENT_KEY, files[:MAX_RECENT])

    def _open_dialog(self) -> None:
        folder = str(self.document.path.parent) if self.document.path else str(Path.home())
        name, _ = QFileDialog.getOpenFileName(self.window, "Open Structure", folder, STRUCTURE_FILTER)
        if name:
            self.open_file(Path(name))

    def _open_recent(self, path: Path) -> None:
        opener = next((open_ for suffix, open_ in self._openers.items() if path.name.endswith(suffix)),
                      self.open_file)
        opener(path)

    def _fill_recent_menu(self) -> None:
        self.recent_menu.clear()
        for name in self.recent_files():
            action = self.recent_menu.addAction(name)
            action.triggered.connect(lambda _=False, name=name: self._open_recent(Path(name)))
        self.recent_menu.addSeparator()
        clear = self.recent_menu.addAction("Clear Menu")
        clear.triggered.connect(lambda: self.settings.setValue(RECENT_KEY, []))

    def _update_title(self) -> None:
        self.window.setWindowTitle(f"{self.document.title}[*] — {PROG}")
        self.window.setWindowModified(self.document.modified)
