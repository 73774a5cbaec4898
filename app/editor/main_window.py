"""The editor's main window: the 3D view, the docks, menus, toolbar and status bar.

The window wires the pieces together: a :class:`~app.editor.document.Document`, the
:class:`~app.editor.scene.scene.Scene` drawing it into the :class:`~app.editor.scene.view.View`, the
:class:`~app.editor.picking.PointerAdapter` feeding mouse events to the
:class:`~app.editor.drag.DragController`, and the dock panels. It also owns the file dialogs
(open, save, recent files, drag-and-drop; image export is :mod:`app.editor.export_image`'s)
and asks before unsaved edits would be lost.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QPoint, QSettings, QSize, Qt
from PySide6.QtGui import (
    QAction,
    QActionGroup,
    QCloseEvent,
    QCursor,
    QDragEnterEvent,
    QDropEvent,
    QImage,
    QKeySequence,
    QPainter,
)
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QFileDialog,
    QInputDialog,
    QLabel,
    QLineEdit,
    QMainWindow,
    QMenu,
    QMessageBox,
    QScrollArea,
    QStyle,
    QTabBar,
    QToolTip,
    QUndoView,
    QWidget,
)

from app import EXAMPLES_DIR
from app.editor import help
from app.editor.composition import compose_once
from app.editor.docks.comparison import ComparisonPanel
from app.editor.docks.console import PythonConsole
from app.editor.docks.map_panel import MapPanel
from app.editor.docks.panels import DisplayPanel, RibbonDimensionPanel
from app.editor.docks.ramachandran import RamachandranPanel
from app.editor.docks.sequence import SequenceBar
from app.editor.docks.surfaces import SurfaceLayer, SurfacePanel
from app.editor.docks.validation import ValidationPanel
from app.editor.document import Document
from app.editor.drag import CLICK_PIXELS, DragController, Mode, PointerEvent
from app.editor.export_image import ExportImageDialog, render_view, write_png
from app.editor.identify import Hit, describe, identify
from app.editor.live_validation import LiveValidation
from app.editor.map_correlation import LiveCorrelation
from app.editor.persistence import journal, records, session
from app.editor.picking import PRIORITY, PointerAdapter
from app.editor.scene.layers.validation_markers import ValidationMarkers
from app.editor.scene.map_mesh import MapMesh
from app.editor.scene.molecule import Colouring
from app.editor.scene.overlay import Compared, Comparison, ComparisonView
from app.editor.scene.scene import Layer, Scene
from app.editor.scene.view import new_view
from app.editor.scripting import EditorAPI
from core.geometry.validation import Flag
from core.protein.lookup import find_residues
from core.protein.structure import StructureError

if TYPE_CHECKING:
    from core.fitting.coarse_to_fine import LevelFit

APP_NAME = "ribbonwave"
RECENT_KEY = "recentFiles"
GEOMETRY_KEY = "windowGeometry"
LAYOUT_KEY = "windowLayout"
DEFAULT_SIZE = QSize(1400, 900)
"""The window's first size, where the screen has room for it."""
MAX_RECENT = 8
STRUCTURE_FILTER = "Structures (*.pdb *.ent *.cif *.mmcif *.gz);;All files (*)"
SAVE_FILTERS = {"PDB (*.pdb *.pdb.gz *.ent)": ".pdb", "mmCIF (*.cif *.cif.gz *.mmcif)": ".cif"}
SAVE_SUFFIXES = (".pdb", ".ent", ".cif", ".mmcif", ".pdb.gz", ".ent.gz", ".cif.gz", ".mmcif.gz")
SESSION_FILTER = f"ribbonwave sessions (*{session.SUFFIX});;All files (*)"
MAP_FILTER = "Density maps and map coefficients (*.ccp4 *.mrc *.map *.mtz *.gz);;All files (*)"


class MainWindow(QMainWindow):
    """The editor window on a :class:`Document` (a new, empty one when none is given)."""

    def __init__(self, document: Document | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        compose_once(self)
        self.document = document if document is not None else Document()
        self.document.setParent(self)
        self.settings = QSettings(APP_NAME, APP_NAME)
        self.resize(_fitted(DEFAULT_SIZE))
        self.setAcceptDrops(True)
        self.unattended = False
        """Run by a script: no dialog waits for a person, and unsaved edits stay in the journal."""
        self.journal = journal.Journal(self.document)

        self.plotter = new_view(self)
        self.plotter.setAcceptDrops(False)  # dropped files go to the window, which opens them
        self.plotter.iren.clear_key_event_callbacks()  # no pyvista key bindings ('q' would close the view)
        self._swallow_style_keys()
        self.plotter.enable_anti_aliasing("fxaa")
        self.setCentralWidget(self.plotter)
        self.validation = LiveValidation(self.document)  # before the scene: its report is new when the scene renders
        self.scene = Scene(self.document, self.plotter)
        self.markers = ValidationMarkers(self.validation, self.scene)
        self.controller = DragController(self.document)
        self.pointer = PointerAdapter(self.plotter, self._on_pointer)
        self._press_at: tuple[int, int] | None = None  # where a press the camera took began (display pixels)
        self._hovered: tuple | None = None  # what the hover names now

        self.dimension_panel = RibbonDimensionPanel(self.document)
        self._less_detail_while_moving()
        self.display_panel = DisplayPanel(self.scene)
        self.comparison = Comparison(self.document)  # after the scene: it redraws once the scene is rebuilt
        self.comparison_view = ComparisonView(self.comparison, self.plotter)
        self.comparison_panel = ComparisonPanel(self.comparison)
        self.validation_panel = ValidationPanel(self.validation)
        self.ramachandran_panel = RamachandranPanel(self.document, self.validation)
        self.ramachandran_panel.residueActivated.connect(lambda row: self.select_and_centre([row]))
        self.validation_panel.flagActivated.connect(self.show_flag)
        self.surface_layer = SurfaceLayer(self.document, self.plotter)  # after the scene, which clears the view on load
        self.surface_panel = SurfacePanel(self.surface_layer)
        self.maps = MapMesh(self.document, self.plotter)  # after the scene, which clears the view on load
        self.correlation = LiveCorrelation(self.document, self.maps)
        self._create_fit_actions()
        self.map_panel = MapPanel(self.maps, self.correlation, self.fit_actions)
        self.history = QUndoView(self.document.undo_stack)
        self.history.setEmptyLabel("<structure as read>")
        self.rw = EditorAPI(self)
        """The ``rw`` object of scripts and of the Python console."""
        self.console = PythonConsole({"rw": self.rw, "np": np})
        self.sequence_bar = SequenceBar(self.document)
        self.sequence_bar.strip.residuesActivated.connect(self.select_and_centre)
        self.correlation.judged.connect(lambda: self.sequence_bar.strip.set_scores(
            None if self.correlation.quality is None else self.correlation.quality.residues))
        # the right column runs from the toolbar to the status bar; the sequence bar spans the view only
        self.setCorner(Qt.Corner.TopRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        dimension = self._dock("Ribbon dimension", _scrolled(self.dimension_panel))
        tabs = [self._dock("Display", _scrolled(self.display_panel)), self._dock("Surface", self.surface_panel),
                self._dock("Validation", _scrolled(self.validation_panel)),
                self._dock("Ramachandran", _scrolled(self.ramachandran_panel)),
                self._dock("Compare", self.comparison_panel), self._dock("Map", _scrolled(self.map_panel)),
                self._dock("History", self.history)]
        for dock in tabs[1:]:  # one group of tabs under the level controls: each gets the column's height
            self.tabifyDockWidget(tabs[0], dock)
        tabs[0].raise_()
        docks = [dimension, *tabs, self._dock("Sequence", self.sequence_bar, Qt.DockWidgetArea.TopDockWidgetArea)]
        self.console_dock = self._dock("Python Console", self.console, Qt.DockWidgetArea.BottomDockWidgetArea)
        self.console_dock.hide()
        self.resizeDocks([dimension], [self.dimension_panel.sizeHint().height() + 30], Qt.Orientation.Vertical)
        self._tidy_tab_bars()
        self.console_dock.visibilityChanged.connect(self._tidy_tab_bars)
        self._create_actions()
        self._create_menus(docks)
        self._create_status_bar()

        self.document.fileChanged.connect(self._update_title)
        self.document.loaded.connect(self._update_status)
        self.document.levelChanged.connect(self._update_status)
        self.document.segmentChanged.connect(self._update_status)
        self.document.picked.connect(self._update_status)
        self.document.selectionChanged.connect(self._update_status)
        self.document.picked.connect(self._update_regularize_action)
        for signal in (self.document.loaded, self.maps.changed, self.comparison.changed):
            signal.connect(self._update_fit_actions)
        self.correlation.updated.connect(self._update_correlation)
        self._update_fit_actions()
        self._update_title()
        self._update_status()
        self._restore_layout()

    # ------------------------------------------------------------------ files

    def open_file(self, path: Path, *, raise_errors: bool = False) -> bool:
        """Open ``path`` after asking about unsaved edits; a bad file is reported in a dialog
        (or raised as StructureError with ``raise_errors``)."""
        if not self.maybe_save():
            return False
        try:
            self.document.open(Path(path))
        except StructureError as error:
            if raise_errors:
                raise
            QMessageBox.critical(self, APP_NAME, str(error))
            return False
        self.add_recent(Path(path))
        return True

    def open_session(self, path: Path, *, raise_errors: bool = False) -> bool:
        """Open a session file after asking about unsaved edits: the structure, the undo history at
        its position, the view and the compared structures (errors as for :meth:`open_file`,
        raised as SessionError)."""
        if not self.maybe_save():
            return False
        try:
            recording, view = session.read(Path(path))
            self._replay(recording)
        except (session.SessionError, StructureError) as error:
            if raise_errors:
                raise session.SessionError(str(error)) from None
            QMessageBox.critical(self, APP_NAME, str(error))
            return False
        self._apply_view(view)
        self.add_recent(Path(path))
        return True

    def write_session(self, path: Path) -> Path:
        """Save the session to ``path`` (``.rwsession`` added if missing); raises OSError."""
        if self.document.model is None:
            raise RuntimeError("no structure is open")
        path = Path(path) if Path(path).name.endswith(session.SUFFIX) else Path(f"{path}{session.SUFFIX}")
        session.write(path, self.document.recording(), self._view())
        return path

    def save_session(self) -> bool:
        """Ask for a file name and save the session there."""
        if self.document.model is None:
            return False
        name, _ = QFileDialog.getSaveFileName(self, "Save Session", str(self._suggested(session.SUFFIX)),
                                              SESSION_FILTER)
        if not name:
            return False
        try:
            self.write_session(Path(name))
        except OSError as error:
            QMessageBox.critical(self, APP_NAME, f"cannot write {name}: {error.strerror or error}")
            return False
        return True

    def restore_journal(self, path: Path) -> str:
        """Restore the document a crashed editor journalled at ``path``; returns what was
        restored (raises OSError, RecordError or StructureError)."""
        recording, damaged = records.read(Path(path))
        self._replay(recording)
        Path(path).unlink(missing_ok=True)
        stack = self.document.undo_stack
        message = f"restored {stack.count()} undo step(s) of {self.document.path.name}, {stack.index()} done"
        if damaged:
            message += "; the journal was cut off after them (the step in progress at the crash is lost)"
        self.statusBar().showMessage(message, 15000)
        return message

    def offer_recovery(self) -> None:
        """If an editor ended without closing cleanly, offer to restore its unsaved edits."""
        left = journal.orphans(self.journal.folder)
        if not left:
            return
        buttons = QMessageBox.StandardButton
        answer = QMessageBox.question(
            self, APP_NAME, "ribbonwave did not close cleanly last time. Restore the unsaved edits "
            f"({time_label(left[0])})? Discard deletes them; Ignore keeps them for later.",
            buttons.Yes | buttons.Discard | buttons.Ignore)
        if answer == buttons.Yes:
            try:
                self.restore_journal(left[0])
            except (OSError, records.RecordError, StructureError) as error:
                QMessageBox.critical(self, APP_NAME, f"cannot restore {left[0].name}: {error}")
        elif answer == buttons.Discard:
            left[0].unlink(missing_ok=True)

    def quit_unattended(self, discard: bool = False) -> None:
        """Close without asking: unsaved edits are kept in the journal unless ``discard``."""
        self.unattended = True
        if discard:
            self.journal.discard()
            self.document.undo_stack.setClean()
        self.close()

    def save(self) -> bool:
        """Save to the file chosen by the last Save As; the first Save of a file asks where."""
        if self.document.model is None:
            return False
        if self.document.save_path is None:
            return self.save_as()
        return self._write(self.document.save_path)

    def save_as(self) -> bool:
        """Ask for a file name (PDB or mmCIF by its extension) and save there."""
        if self.document.model is None:
            return False
        suffix = ".cif" if self.document.structure.source_format == "mmcif" else ".pdb"
        name, chosen = QFileDialog.getSaveFileName(self, "Save As", str(self._suggested(f"_edited{suffix}")),
                                                   ";;".join(SAVE_FILTERS))
        if not name:
            return False
        path = Path(name)
        if not path.name.lower().endswith(SAVE_SUFFIXES):  # the dialog asked about the name without it
            path = path.with_name(path.name + SAVE_FILTERS.get(chosen, suffix))
            replace = QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No
            if path.exists() and QMessageBox.question(self, APP_NAME, f"{path.name} exists. Replace it?",
                                                      replace) != QMessageBox.StandardButton.Yes:
                return False
        return self._write(path)

    def export_image_dialog(self) -> ExportImageDialog:
        """File ▸ Export Image: the dialog of size, supersampling and background, shown (not waited for)."""
        dialog = ExportImageDialog(self.plotter, self._suggested(".png"), self)
        dialog.open()
        return dialog

    def recent_files(self) -> list[str]:
        """Files opened or saved lately, newest first (absolute paths)."""
        value = self.settings.value(RECENT_KEY, [])
        return [value] if isinstance(value, str) else list(value or [])

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
            self, APP_NAME, f"Save the changes to {name}?",
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

    def save_screenshot(self, path: Path, *, overwrite: bool = False) -> None:
        """Render the window, 3D view included, to a PNG image, atomically (raises OSError, or
        FileExistsError for an existing file unless ``overwrite``)."""
        write_png(self.grab_window(), Path(path), overwrite=overwrite)

    def grab_window(self) -> QImage:
        """An image of the whole window with the freshly rendered 3D view painted in."""
        image = self.grab().toImage()
        view = render_view(self.plotter, *self.plotter.window_size)
        painter = QPainter(image)
        corner = self.plotter.mapTo(self, QPoint(0, 0))
        painter.drawImage(corner, view.scaled(self.plotter.size()))
        painter.end()
        return image

    def show_flag(self, flag: Flag) -> None:
        """Centre the view on ``flag``'s marker and select its residues (see :meth:`select_and_centre`)."""
        self.select_and_centre(np.array(flag.residues, dtype=np.int64), np.array(flag.position))

    def open_map(self, path: Path, columns: tuple[str, str] | None = None, *, raise_errors: bool = False) -> bool:
        """Show the density map at ``path`` (CCP4/MRC, optionally gzipped), or an MTZ file's
        2mFo−DFc and mFo−DFc maps (of ``columns``, amplitude and phase, else as Coot finds
        them; where it finds none, the user chooses a pair). A bad file is reported in a
        dialog (or raised as MapError with ``raise_errors``)."""
        from core.surfaces.map_coefficients import column_pairs, is_mtz

        try:
            try:
                self.maps.open(Path(path), columns)
            except ValueError:
                if raise_errors or columns is not None or not Path(path).is_file() or not is_mtz(path):
                    raise
                pairs = column_pairs(path)
                if not pairs:
                    raise
                names = [f"{f}, {phi}" for f, phi in pairs]
                name, chosen = QInputDialog.getItem(self, "Map Coefficients", f"{Path(path).name} has no columns named "
                                                    "as refinement names 2mFo−DFc. Amplitude and phase:", names, 0,
                                                    False)
                if not chosen:
                    return False
                self.maps.open(Path(path), pairs[names.index(name)])
        except ValueError as error:  # a MapError
            if raise_errors:
                raise
            QMessageBox.critical(self, APP_NAME, str(error))
            return False
        return True

    def fit(self, target: str, coarse_to_fine: bool, levels: list[int] | None = None, *,
            raise_errors: bool = False) -> list[LevelFit]:
        """Fit the edited chain to the ``'map'`` or the ``'compared'`` structure (the first
        shown) at ``levels`` (default: the level shown, or coarse to fine every level up to it),
        each level one undo step (see :mod:`app.editor.fitting`). Returns the levels fitted;
        what prevents a fit is said in a dialog (or raised as ValueError with ``raise_errors``)."""
        from app.editor.fitting import compared_target, levels_to_fit, map_target, run_fit  # loads with the first fit

        document = self.document
        try:
            if not document.editable:
                raise ValueError(document.read_only_reason or "no structure is open")
            if target == "map":
                if self.maps.density is None:
                    raise ValueError("no map is open: File ▸ Open Map… first")
                fit_target = map_target(document, self.maps.density, self.correlation.resolution)
            else:
                fit_target = compared_target(document, self._compared())
        except ValueError as error:  # MapError included
            if raise_errors:
                raise
            QMessageBox.critical(self, APP_NAME, str(error))
            return []
        if levels is None:
            levels = levels_to_fit(document, fit_target, coarse_to_fine)
        kept = run_fit(document, fit_target, levels, self)
        if target == "map" and kept:
            self.correlation.judge()  # now, not after the edits' pause
            if self.correlation.quality is not None:
                self.statusBar().showMessage(f"Fitted to the map: {self.correlation.summary()}", 30000)
        return kept

    def _compared(self) -> Compared:
        """The compared structure fits go to: the first shown (else the first)."""
        items = self.comparison.items
        if not items:
            raise ValueError("no compared structure: File ▸ Add Structures for Comparison… first")
        return next((item for item in items if item.visible), items[0])

    # ------------------------------------------------------------------ events

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 (Qt override)
        """Ask about unsaved edits; then release the VTK render window with the window."""
        if not self.maybe_save():
            event.ignore()
            return
        self.journal.stop()  # deleted by maybe_save unless it holds unsaved edits
        self.settings.setValue(GEOMETRY_KEY, self.saveGeometry())
        self.settings.setValue(LAYOUT_KEY, self.saveState())
        self.surface_layer.shutdown()
        self.pointer.close()
        self.plotter.close()
        super().closeEvent(event)

    def dragEnterEvent(self, event: QDragEnterEvent) -> None:  # noqa: N802 (Qt override)
        if any(url.isLocalFile() for url in event.mimeData().urls()):
            event.acceptProposedAction()

    def dropEvent(self, event: QDropEvent) -> None:  # noqa: N802 (Qt override)
        files = [Path(url.toLocalFile()) for url in event.mimeData().urls() if url.isLocalFile()]
        if files:
            event.acceptProposedAction()
            self.open_file(files[0])

    # ------------------------------------------------------------------ building

    def _dock(self, title: str, widget: QWidget,
              area: Qt.DockWidgetArea = Qt.DockWidgetArea.RightDockWidgetArea) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setWidget(widget)
        self.addDockWidget(area, dock)
        return dock

    def _create_actions(self) -> None:
        style = self.style()
        icon = style.standardIcon
        pixmap = QStyle.StandardPixmap
        self.open_action = self._action("&Open…", QKeySequence.StandardKey.Open, self._open_dialog,
                                        icon(pixmap.SP_DialogOpenButton))
        self.save_action = self._action("&Save", QKeySequence.StandardKey.Save, self.save,
                                        icon(pixmap.SP_DialogSaveButton))
        self.save_as_action = self._action("Save &As…", QKeySequence.StandardKey.SaveAs, self.save_as)
        self.open_session_action = self._action("Open Sess&ion…", QKeySequence("Ctrl+Shift+O"),
                                                self._open_session_dialog)
        self.save_session_action = self._action("Save Sessio&n…", QKeySequence("Ctrl+Alt+S"), self.save_session)
        self.export_action = self._action("&Export Image…", QKeySequence("Ctrl+E"), self.export_image_dialog)
        self.quit_action = self._action("&Quit", QKeySequence.StandardKey.Quit, self.close)
        stack = self.document.undo_stack
        self.undo_action = stack.createUndoAction(self, "&Undo")
        self.undo_action.setShortcut(QKeySequence.StandardKey.Undo)
        self.undo_action.setIcon(icon(pixmap.SP_ArrowBack))
        self.undo_action.setIconText("Undo")  # the toolbar keeps a short label; the menu names the edit
        self.redo_action = stack.createRedoAction(self, "&Redo")
        # each key once: QKeySequence.StandardKey.Redo is Ctrl+Shift+Z on Linux, and a key bound
        # twice is an "ambiguous shortcut" that does nothing
        self.redo_action.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
        self.redo_action.setIcon(icon(pixmap.SP_ArrowForward))
        self.redo_action.setIconText("Redo")
        self.cancel_action = self._action("Cancel Drag / Deselect", QKeySequence(Qt.Key.Key_Escape), self._cancel)
        self.regularize_action = self._action("Re&gularize Region", QKeySequence("Ctrl+G"), self._regularize_region)
        self.regularize_action.setToolTip("Ideal peptide junctions and no new clashes for the residues of the picked "
                                          "point and three on each side (one undo step)")
        self.regularize_action.setEnabled(False)
        self.go_to_action = self._action("&Go to Residue…", QKeySequence("Ctrl+L"), self._focus_go_to)
        self.go_to_action.setToolTip("Select a residue or a range and centre the view on it: A:45, 45, A:40-50")
        self.reset_view_action = self._action("&Reset View", QKeySequence("Ctrl+R"), self._reset_view,
                                              icon(pixmap.SP_BrowserReload))
        self.mode_actions = QActionGroup(self)
        for mode, key in ((Mode.POINT, "M"), (Mode.CURVE, "T")):
            action = self._action(mode.value[0].upper() + mode.value[1:], QKeySequence(key),
                                  lambda _=False, mode=mode: self._set_mode(mode))
            action.setCheckable(True)
            action.setChecked(mode is self.controller.mode)
            self.mode_actions.addAction(action)

    def _create_fit_actions(self) -> None:
        self.open_map_action = self._action("Open &Map…", QKeySequence("Ctrl+Shift+M"), self._open_map_dialog)
        self.open_map_action.setToolTip("Read a CCP4 or MRC density map and draw it around the view's centre")
        self.fit_actions = [
            self._action(text, QKeySequence(), lambda _=False, t=target, c=coarse: self.fit(t, c))
            for target, name in (("map", "Map"), ("compared", "Compared Structure"))
            for coarse, text in ((False, f"Fit to {name} at This Level"), (True, f"Fit to {name} Coarse to Fine"))
        ]
        for action in self.fit_actions:
            action.setToolTip("Move the edited segment's control points " + (
                "at every level from 0 up to the one shown, coarse first, then regularize; each level one undo step"
                if "Coarse" in action.text() else "at the level shown (one undo step)"))

    def _update_fit_actions(self) -> None:
        editable = self.document.editable
        for action in self.fit_actions[:2]:
            action.setEnabled(editable and self.maps.density is not None)
        for action in self.fit_actions[2:]:
            action.setEnabled(editable and bool(self.comparison.items))

    def _update_correlation(self) -> None:
        value = self.correlation.value
        self.status_labels["map"].setText("" if value is None else f"map CC {value:.3f}")

    def _action(self, text: str, shortcut: QKeySequence | QKeySequence.StandardKey, slot: object,
                icon: object = None) -> QAction:
        action = QAction(text, self)
        action.setShortcut(shortcut)
        action.triggered.connect(slot)
        if icon is not None:
            action.setIcon(icon)
        self.addAction(action)  # shortcuts work wherever the focus is, the 3D view included
        return action

    def _create_menus(self, docks: list[QDockWidget]) -> None:
        menu = self.menuBar()
        file_menu = menu.addMenu("&File")
        file_menu.addAction(self.open_action)
        self.recent_menu = file_menu.addMenu("Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent_menu)
        file_menu.addAction("Add Structures for &Comparison…", self.comparison_panel.add_dialog)
        file_menu.addAction(self.open_map_action)
        file_menu.addSeparator()
        file_menu.addActions([self.save_action, self.save_as_action, self.export_action])
        file_menu.addSeparator()
        file_menu.addActions([self.open_session_action, self.save_session_action])
        file_menu.addSeparator()
        file_menu.addAction(self.quit_action)
        edit_menu = menu.addMenu("&Edit")
        edit_menu.addActions([self.undo_action, self.redo_action, self.cancel_action])
        edit_menu.addSeparator()
        edit_menu.addActions(self.mode_actions.actions())
        edit_menu.addSeparator()
        edit_menu.addAction(self.regularize_action)
        edit_menu.addSeparator()
        edit_menu.addActions(self.fit_actions)
        view_menu = menu.addMenu("&View")
        view_menu.addActions([self.reset_view_action, self.go_to_action])
        view_menu.addSeparator()
        view_menu.addActions([dock.toggleViewAction() for dock in docks])
        view_menu.addSeparator()
        console = self.console_dock.toggleViewAction()
        console.setShortcut(QKeySequence("Ctrl+Shift+P"))
        view_menu.addAction(console)
        help_menu = menu.addMenu("&Help")
        help_menu.addAction(self._action("&Mouse and Keyboard", QKeySequence.StandardKey.HelpContents,
                                         self.show_reference))
        help_menu.addAction(self._action(f"&About {APP_NAME}", QKeySequence(), self.show_about))
        toolbar = self.addToolBar("Main")
        toolbar.setObjectName("Main")
        toolbar.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        toolbar.addActions([self.open_action, self.save_action])
        toolbar.addSeparator()
        toolbar.addActions([self.undo_action, self.redo_action])
        toolbar.addSeparator()
        toolbar.addActions(self.mode_actions.actions())
        toolbar.addSeparator()
        toolbar.addAction(self.reset_view_action)
        self.go_to_field = QLineEdit()
        self.go_to_field.setPlaceholderText("Go to residue (Ctrl+L)")
        self.go_to_field.setToolTip(self.go_to_action.toolTip())
        self.go_to_field.setClearButtonEnabled(True)
        self.go_to_field.setMaximumWidth(190)
        self.go_to_field.returnPressed.connect(self._go_to_typed)
        toolbar.addWidget(self.go_to_field)

    def _create_status_bar(self) -> None:
        self.status_labels = {key: QLabel() for key in ("file", "segment", "level", "pick", "map", "hover")}
        for key, label in self.status_labels.items():
            self.statusBar().addWidget(label, 1 if key == "pick" else 0)

    def _restore_layout(self) -> None:
        """The size, place and dock layout the window had when it last closed (kept on screen)."""
        geometry, layout = self.settings.value(GEOMETRY_KEY), self.settings.value(LAYOUT_KEY)
        if geometry is not None:
            self.restoreGeometry(geometry)
            self.resize(_fitted(self.size()))
        if layout is not None:
            self.restoreState(layout)
            self._tidy_tab_bars()

    def _tidy_tab_bars(self) -> None:
        """Dock tabs show their whole titles (scroll buttons when they do not fit). Qt (6.11)
        also leaves the tab bar of a two-dock group visible, under the docks, once a third
        dock joins the group; a bottom dock uncovers it: hide every tab bar whose tabs another
        one shows too."""
        bars = [bar for bar in self.findChildren(QTabBar) if bar.parent() is self]
        tabs = {bar: {bar.tabText(k) for k in range(bar.count())} for bar in bars}
        for bar in bars:
            bar.setElideMode(Qt.TextElideMode.ElideNone)
            bar.setUsesScrollButtons(True)
            if any(other is not bar and tabs[bar] < tabs[other] for other in bars):
                bar.hide()

    def _swallow_style_keys(self) -> None:
        """Keep VTK's one-letter camera-style keys ('w' wireframe, 'e' exit, ...) away from the view."""
        interactor = self.plotter.iren.interactor
        tag = interactor.AddObserver("CharEvent", lambda caller, _: caller.GetCommand(tag).SetAbortFlag(1), PRIORITY)

    def _less_detail_while_moving(self) -> None:
        """The scene draws less while the camera turns or zooms and while the level slides
        (drags tell it in :meth:`_on_pointer`): frames at rest are drawn in full."""
        style = self.plotter.iren.interactor.GetInteractorStyle()
        for event in ("StartInteractionEvent", "InteractionEvent"):
            style.AddObserver(event, lambda *_: self.scene.moved())
        style.AddObserver("EndInteractionEvent", lambda *_: self._end_interaction())
        self.dimension_panel.slider.valueChanged.connect(self.scene.moved)

    def _end_interaction(self) -> None:
        """The camera's gesture ended; one that moved less than a click's pixels was a click."""
        x, y = self.plotter.iren.interactor.GetEventPosition()
        press, self._press_at = self._press_at, None
        if press is not None and max(abs(x - press[0]), abs(y - press[1])) < CLICK_PIXELS:
            self._click(self.pointer.event_at("release", x, y))
        self.plotter.render()

    # ------------------------------------------------------------------ slots

    def _on_pointer(self, event: PointerEvent) -> bool:
        if event.kind == "press" and event.double:
            self._centre_on_pointer(event)
            return True
        if event.kind == "move" and not self.controller.dragging:
            if self._press_at is None:
                self._hover(event)
            return False
        grabs = Layer.CONTROL_POINTS if self.controller.mode is Mode.POINT else Layer.CURVE
        if event.kind == "press" and grabs not in self.scene.layers:
            used = False  # what is hidden cannot be grabbed: the press turns the camera
        elif event.kind == "release" and self.controller.dragging:
            with _busy():  # the release regularizes: a hard edit takes a few tenths of a second
                used = self.controller.handle(event)
            self.scene.moved()  # full detail a moment after the release
            return used
        else:
            self.controller.point_radius = self.scene.point_radius  # as drawn
            used = self.controller.handle(event)
            if used:
                self.scene.moved()
        if event.kind == "press":
            # a press the camera takes: its release ends the camera's interaction (the camera
            # style holds the interactor's focus until then, so no release comes here)
            self._press_at = None if used else self.plotter.iren.interactor.GetEventPosition()
        return used

    def _hit(self, event: PointerEvent) -> Hit | None:
        """What is drawn under the pointer of ``event``."""
        return identify(self.document, event, points=Layer.CONTROL_POINTS in self.scene.layers,
                        point_radius=self.scene.point_radius, atoms=self.scene.shown_atoms())

    def _hover(self, event: PointerEvent) -> None:
        """Name what is under the pointer in a tooltip and the status bar (when it changes)."""
        hit = self._hit(event) if self.document.model is not None else None
        key = None if hit is None else (hit.kind, hit.index, hit.row, self.document.shown_level())
        if key == self._hovered:  # the same thing: no new name (a point's costs an edit plan)
            return
        self._hovered = key
        text = "" if hit is None else describe(self.document, hit)
        self.status_labels["hover"].setText(text)
        if hit is None:
            QToolTip.hideText()
        else:
            QToolTip.showText(QCursor.pos(), text, self.plotter)

    def _click(self, event: PointerEvent) -> None:
        """A click that no drag took: select the residue under the pointer (see :meth:`_select`)."""
        hit = self._hit(event)
        if hit is not None and hit.row >= 0 and hit.kind != "point":
            self._select([hit.row])

    def _centre_on_pointer(self, event: PointerEvent) -> None:
        """Double click: turn the view about what is under the pointer (and select its residue)."""
        hit = self._hit(event)
        if hit is None:
            return
        if hit.row >= 0 and hit.kind != "point":
            self._select([hit.row])
        self.scene.centre_on(hit.position)
        self.plotter.render()

    def select_and_centre(self, rows: np.ndarray, point: np.ndarray | None = None) -> None:
        """Select residues ``rows`` (residue-table rows; see :meth:`_select`) and centre the view
        on ``point`` (Å; default: their Cα's mean)."""
        rows = np.asarray(rows, dtype=np.int64)
        if point is None and not len(rows):
            return
        self._select(rows)
        self.scene.centre_on(self.document.model.coords[self.document.ca_rows[rows]].mean(axis=0)
                             if point is None else point)
        self.plotter.render()

    def _select(self, rows: np.ndarray | list[int]) -> None:
        """Select residues ``rows``; where they lie in one segment, that segment becomes the
        edited one (framed: centre afterwards)."""
        segments = {self.document.segment_of(int(row)) for row in rows}
        if len(segments) == 1:
            self.document.set_segment(segments.pop())
        self.document.select(rows)

    def go_to(self, text: str) -> np.ndarray:
        """Select and centre on the residues named by ``text`` (``A:45``, ``45`` in the edited
        chain, ``A:40-50``); returns their residue-table rows (raises ValueError)."""
        if self.document.model is None:
            raise ValueError("no structure is open")
        chain = self.document.structure.segments[self.document.segment].chain
        rows = find_residues(self.document.structure, text, chain)
        self.select_and_centre(rows)
        return rows

    def _go_to_typed(self) -> None:
        try:
            self.go_to(self.go_to_field.text())
        except ValueError as error:
            self.statusBar().showMessage(str(error), 8000)
            self.go_to_field.selectAll()
            return
        self.plotter.setFocus()  # the keys act on the view again

    def _set_mode(self, mode: Mode) -> None:
        self.controller.mode = mode
        self._update_status()

    def _cancel(self) -> None:
        if self.controller.dragging:
            self.controller.cancel()
        elif self.document.model is not None:
            self.document.pick_point(None)
            self.document.select([])

    def _regularize_region(self) -> None:
        if self.document.pick is not None:
            with _busy():
                self.document.regularize_region(self.document.pick.residues)

    def _update_regularize_action(self) -> None:
        self.regularize_action.setEnabled(self.document.pick is not None)

    def show_reference(self) -> QMessageBox:
        """Help ▸ Mouse and Keyboard: the gestures and the keys bound (a window-modal box)."""
        menus = [action for menu in self.menuBar().findChildren(QMenu) for action in menu.actions()]
        return self._message("Mouse and keyboard", help.reference_html(list(dict.fromkeys(menus + self.actions()))))

    def show_about(self) -> QMessageBox:
        """Help ▸ About: what ribbonwave is and the versions of what it runs on."""
        return self._message(f"About {APP_NAME}", "<p><b>ribbonwave</b>: multiresolution (wavelet) analysis and "
                             "editing of protein structures, after M. Carson, <i>Wavelets and molecular structure</i> "
                             "(1996).</p><pre>" + help.about_text() + "</pre>")

    def _message(self, title: str, html: str) -> QMessageBox:
        box = QMessageBox(QMessageBox.Icon.NoIcon, title, html, QMessageBox.StandardButton.Close, self)
        box.setTextFormat(Qt.TextFormat.RichText)
        box.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        box.open()  # not blocking: the editor goes on behind it
        return box

    def _focus_go_to(self) -> None:
        self.go_to_field.setFocus()
        self.go_to_field.selectAll()

    def _reset_view(self) -> None:
        self.scene.reset_camera()
        self.plotter.render()

    def _open_dialog(self) -> None:
        folder = str(self.document.path.parent) if self.document.path else str(Path.home())
        name, _ = QFileDialog.getOpenFileName(self, "Open Structure", folder, STRUCTURE_FILTER)
        if name:
            self.open_file(Path(name))

    def _suggested(self, ending: str) -> Path:
        """A file name to offer for saving: the structure's name with ``ending``, beside it
        (in the home folder for the bundled examples)."""
        source = self.document.path
        folder = Path.home() if source is None or source.parent == EXAMPLES_DIR else source.parent
        return folder / f"{source.name.split('.')[0] if source is not None else 'structure'}{ending}"

    def _open_map_dialog(self) -> None:
        folder = str(self.maps.path.parent if self.maps.path else self.document.path.parent if self.document.path
                     else Path.home())
        name, _ = QFileDialog.getOpenFileName(self, "Open Map", folder, MAP_FILTER)
        if name:
            self.open_map(Path(name))

    def _open_session_dialog(self) -> None:
        folder = str(self.document.path.parent) if self.document.path else str(Path.home())
        name, _ = QFileDialog.getOpenFileName(self, "Open Session", folder, SESSION_FILTER)
        if name:
            self.open_session(Path(name))

    def _replay(self, recording: list[records.Record]) -> None:
        """The document as ``recording`` says, journalled anew; compared structures are dropped."""
        self.journal.discard()
        while self.comparison.items:
            self.comparison.remove(0)
        self.document.replay(recording)
        self.journal.write_all()

    def _view(self) -> session.View:
        compared = [session.ComparedFile(item.path, item.source, item.chain, item.visible)
                    for item in self.comparison.items]
        camera = [list(map(float, vector)) for vector in self.plotter.camera_position]
        return session.View(sorted(layer.name for layer in self.scene.layers), self.scene.colouring.value,
                            self.scene.fat_helices, camera, compared)

    def _apply_view(self, view: session.View) -> None:
        for layer, box in self.display_panel.layer_boxes.items():
            box.setChecked(layer.name in view.layers)
        panel = self.display_panel
        panel.colouring.setCurrentIndex(max(panel.colouring.findData(Colouring(view.colouring)), 0))
        panel.fat.setChecked(view.fat_helices)
        for item in view.compared:
            try:
                self.comparison.add(item.path, item.chain, item.source)
            except (StructureError, ValueError) as error:
                self.statusBar().showMessage(f"compared structure {item.path.name} left out: {error}", 15000)
                continue
            self.comparison.set_visible(len(self.comparison.items) - 1, item.visible)
        self.plotter.camera_position = [tuple(vector) for vector in view.camera]
        self.plotter.render()

    def _write(self, path: Path) -> bool:
        try:
            self.document.save(path, overwrite=True)
        except (StructureError, OSError) as error:
            QMessageBox.critical(self, APP_NAME, str(error))
            return False
        self.add_recent(path)
        return True

    def add_recent(self, path: Path) -> None:
        """Put ``path`` first in File ▸ Open Recent."""
        name = str(path.resolve())
        files = [name] + [f for f in self.recent_files() if f != name]
        self.settings.setValue(RECENT_KEY, files[:MAX_RECENT])

    def _open_recent(self, path: Path) -> None:
        if path.name.endswith(session.SUFFIX):
            self.open_session(path)
        else:
            self.open_file(path)

    def _fill_recent_menu(self) -> None:
        self.recent_menu.clear()
        for name in self.recent_files():
            action = self.recent_menu.addAction(name)
            action.triggered.connect(lambda _=False, name=name: self._open_recent(Path(name)))
        self.recent_menu.addSeparator()
        clear = self.recent_menu.addAction("Clear Menu")
        clear.triggered.connect(lambda: self.settings.setValue(RECENT_KEY, []))

    def _update_title(self) -> None:
        self.setWindowTitle(f"{self.document.title}[*] — {APP_NAME}")
        self.setWindowModified(self.document.modified)
        self._update_status()

    def _update_status(self) -> None:
        document = self.document
        labels = self.status_labels
        if document.model is None:
            labels["file"].setText("no structure")
            return
        structure = document.structure
        labels["file"].setText(f"{document.path.name if document.path else ''}  ({structure.entry_id})")
        self.mode_actions.setEnabled(document.editable)
        if not document.editable:  # only viewed: say why instead of the segment, level and pick
            labels["segment"].clear()
            labels["level"].clear()
            labels["pick"].setText(document.read_only_reason)
            return
        labels["segment"].setText(f"chain {document.segment_label(document.segment)}")
        labels["level"].setText(f"level {document.shown_level():.2f} / {document.max_level:.2f}")
        pick = document.pick
        if len(document.selection) and pick is None:
            first, last = (document.row_label(int(r)) for r in document.selection[[0, -1]])
            labels["pick"].setText(f"selected {first if first == last else f'{first}–{last}'} "
                                   f"({len(document.selection)} residues); Esc clears")
            return
        idle = ("Click a control point to pick it; drag it to edit." if self.controller.mode is Mode.POINT
                else "Drag the curve to tug it.")
        labels["pick"].setText(
            f"{idle} Drag elsewhere to turn the view." if pick is None
            else f"point {pick.index} moves {len(pick.residues)} residues: {document.residue_range(pick.residues)}"
        )


def _fitted(size: QSize) -> QSize:
    """``size`` shrunk to the available area of the screen (a 1366 x 768 laptop shows it all)."""
    screen = QApplication.primaryScreen()
    if screen is None:
        return size
    room = screen.availableGeometry()
    return QSize(min(size.width(), room.width()), min(size.height(), room.height()))


def time_label(path: Path) -> str:
    """When the journal at ``path`` was last written, for people."""
    return "last edit " + time.strftime("%Y-%m-%d %H:%M", time.localtime(path.stat().st_mtime))


def _scrolled(widget: QWidget) -> QScrollArea:
    """``widget`` in a scroll area: a tall panel does not make the window taller."""
    area = QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    return area


@contextmanager
def _busy() -> Iterator[None]:
    """A wait cursor while the window works without returning to the event loop."""
    QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
    try:
        yield
    finally:
        QApplication.restoreOverrideCursor()
