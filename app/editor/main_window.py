"""The editor's main window, the composition root: it builds the 3D view, the docks and the
features, and wires them together.

A :class:`~app.editor.document.Document` is drawn by the :class:`~app.editor.scene.scene.Scene`
into the :class:`~app.editor.scene.view.View`; :class:`~app.editor.interaction.gestures.Gestures`
route the pointer to the :class:`~app.editor.interaction.drag.DragController` and the camera.
Each feature (:mod:`app.editor.features`: files, sessions, editing, navigation, maps and fits,
image export, help) builds its own actions and slots and puts them in the menus
(:class:`~app.editor.features.menus.Menus`); the window only lays out the docks, keeps its
layout between runs and closes in order.

The window is built in two steps. Its frame (menus, tool bar, the docks in their places, where
the view will be its background, and the molecule once :meth:`MainWindow.sketch` is given its
trace) needs Qt alone and shows at once; :meth:`MainWindow.furnish` then builds the rest from
:mod:`app.editor.window_parts`, which loads numpy, scipy, VTK and PyVista. A window made with
``MainWindow()`` is furnished at once; ``ribbonwave FILE`` shows the frame first
(:func:`app.editor.launch.run_open`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QSettings, QSize, Qt, QTimer
from PySide6.QtGui import QCloseEvent, QDragEnterEvent, QDropEvent, QKeySequence, QShowEvent
from PySide6.QtWidgets import QDockWidget, QMainWindow, QUndoView, QWidget

from app import PROG
from app.editor.composition import compose_once
from app.editor.docks.layout import (
    LAYOUT_KEY,
    Pending,
    fit_frame,
    fitted,
    new_dock,
    restore_layout,
    save_layout,
    scrolled,
    tidy_tab_bars,
)
from app.editor.features.menus import Menus
from app.editor.sketch import Sketch
from app.editor.source_reads import forget_sources_read_by_pyside

if TYPE_CHECKING:
    from app.editor.document import Document
    from app.editor.sketch import Trace

forget_sources_read_by_pyside()  # before the window's parts are imported

DEFAULT_SIZE = QSize(1400, 900)
"""The window's first size, where the screen has room for it."""
LEVELS_DOCK = "Ribbon dimension"
TABBED_DOCKS = ("Display", "Surface", "Validation", "Ramachandran", "Compare", "Map", "Measurements", "History")
"""The docks in one group of tabs under the level controls, the first in front."""
SEQUENCE_DOCK = "Sequence"
CONSOLE_DOCK = "Python Console"
DOCK_AREAS = {LEVELS_DOCK: Qt.DockWidgetArea.RightDockWidgetArea,
              **dict.fromkeys(TABBED_DOCKS, Qt.DockWidgetArea.RightDockWidgetArea),
              SEQUENCE_DOCK: Qt.DockWidgetArea.TopDockWidgetArea, CONSOLE_DOCK: Qt.DockWidgetArea.BottomDockWidgetArea}
"""Each dock's side of the window, in the order they are placed."""
PENDING_SIZES = {LEVELS_DOCK: QSize(480, 234), **dict.fromkeys(TABBED_DOCKS, QSize(480, 600)),
                 SEQUENCE_DOCK: QSize(70, 44), CONSOLE_DOCK: QSize(480, 200)}
"""About the size of each dock's panel, for the docks' layout while the editor loads (the tabs
under the level controls take the rest of the column)."""


class MainWindow(QMainWindow):
    """The editor window on a :class:`Document` (a new, empty one when none is given); with
    ``furnish=False`` only its frame, until :meth:`furnish` builds the rest."""

    def __init__(self, document: Document | None = None, parent: QWidget | None = None, *,
                 furnish: bool = True) -> None:
        super().__init__(parent)
        compose_once(self)
        self.settings = QSettings(PROG, PROG)
        self.resize(fitted(DEFAULT_SIZE))
        self.setAcceptDrops(True)
        self.furnished = False
        self.menus = Menus(self)
        self.setCentralWidget(Sketch())  # where the 3D view will be, its background and the molecule sketched
        self.docks = self._make_docks()
        self.console_dock = self.docks[CONSOLE_DOCK]
        self._place_docks()
        self._size_column(PENDING_SIZES[LEVELS_DOCK])
        restore_layout(self, self.settings)
        if furnish:
            self.furnish(document)

    def sketch(self, trace: Trace) -> None:
        """Sketch ``trace`` where the 3D view will be, until the window is furnished."""
        if not self.furnished:
            self.centralWidget().draw(trace)

    def furnish(self, document: Document | None = None) -> None:
        """Build the 3D view, the features and the docks' panels on ``document`` (a new one when
        none is given)."""
        import numpy as np

        from app.editor import window_parts as parts

        self.document = document if document is not None else parts.Document()
        self.document.setParent(self)
        self.journal = parts.Journal(self.document)

        self.plotter = parts.new_view(self)
        self.plotter.setAcceptDrops(False)  # dropped files go to the window, which opens them
        self.plotter.iren.clear_key_event_callbacks()  # no pyvista key bindings ('q' would close the view)
        self.plotter.enable_anti_aliasing("fxaa")
        self.setCentralWidget(self.plotter)
        self.plotter.show()  # (a widget put in a shown window stays hidden until shown: the docks took its room)
        self.validation = parts.LiveValidation(self.document)  # before the scene: its report is new when it renders
        self.scene = parts.Scene(self.document, self.plotter)
        self.markers = parts.ValidationMarkers(self.validation, self.scene)
        self.controller = parts.DragController(self.document)
        self.navigation = parts.Navigation(self, self.document, self.scene, self.plotter, self.menus)
        self.clipping = parts.Clipping(self, self.scene, self.plotter, self.menus)
        self.models = parts.Models(self, self.document, self.menus)

        self.dimension_panel = parts.RibbonDimensionPanel(self.document)
        self.dimension_panel.slider.valueChanged.connect(self.scene.moved)  # less detail while the level slides
        self.dimension_panel.segment.activated.connect(lambda _: (self.scene.frame_segment(), self.plotter.render()))
        self.display_panel = parts.DisplayPanel(self.scene)
        self.comparison = parts.Comparison(self.document)  # after the scene: it redraws once the scene is rebuilt
        self.comparison_view = parts.ComparisonView(self.comparison, self.plotter)
        self.comparison_panel = parts.ComparisonPanel(self.comparison)
        self.validation_panel = parts.ValidationPanel(self.validation)
        self.ramachandran_panel = parts.RamachandranPanel(self.document, self.validation)
        self.surface_layer = parts.SurfaceLayer(self.document, self.plotter)  # after the scene, which clears the view
        self.surface_panel = parts.SurfacePanel(self.surface_layer)
        self.maps = parts.MapMesh(self.document, self.plotter)  # after the scene, which clears the view on load
        self.correlation = parts.LiveCorrelation(self.document, self.maps)
        self.files = parts.Files(self, self.document, self.journal, self.settings, self.menus)
        self.menus.add_entry("open", "Add Structures for &Comparison…", self.comparison_panel.add_dialog)
        self.maps_and_fits = parts.MapsAndFits(self, self.document, self.maps, self.correlation, self.comparison,
                                               self.menus)
        self.map_panel = parts.MapPanel(self.maps, self.correlation, self.maps_and_fits.fit_actions)
        self.export = parts.ImageExport(self, self.plotter, self.files, self.menus)
        self.sessions = parts.Sessions(self, self.document, self.journal, self.files, self.menus,
                                       plotter=self.plotter, scene=self.scene, display_panel=self.display_panel,
                                       comparison=self.comparison, clipping=self.clipping)
        self.editing = parts.Editing(self, self.document, self.controller, self.menus)
        self.measuring = parts.Measuring(self, self.document, self.menus)
        self.editing.cancel_action.triggered.connect(lambda: self.measuring.use(0))  # Esc stops a tool too
        self.measurements_panel = parts.MeasurementsPanel(self.document)
        self.help = parts.Help(self, self.menus)
        self.history = QUndoView(self.document.undo_stack)
        self.history.setUniformItemSizes(True)  # (one line a step: a history of thousands lays out at once)
        self._name_history_start()
        self.document.loaded.connect(self._name_history_start)
        self.document.history.trimmed.connect(self._name_history_start)
        self.rw = parts.EditorAPI(self)
        """The ``rw`` object of scripts and of the Python console."""
        self.console = parts.PythonConsole({"rw": self.rw, "np": np})
        self.sequence_bar = parts.SequenceBar(self.document)
        self._wire_selection()
        self._fill_docks()
        self.status = parts.StatusBar(self.statusBar(), self.document, self.controller, self.correlation)
        self.editing.modeChanged.connect(self.status.update)
        self.gestures = parts.Gestures(self.document, self.plotter, self.scene, self.controller,
                                       select=self.navigation.select, name=self.status.labels["hover"].setText,
                                       measure=self.measuring.click)
        self.furnished = True

    def _name_history_start(self) -> None:
        """The History dock's first row: the structure as read, or where the history starts now."""
        dropped = self.document.history.base is not None
        self.history.setEmptyLabel("<older steps dropped>" if dropped else "<structure as read>")

    def quit_unattended(self, discard: bool = False) -> None:
        """Close without asking: unsaved edits are kept in the journal unless ``discard``."""
        if not self.furnished:  # (nothing read yet)
            self.close()
            return
        self.files.unattended = True
        if discard:
            self.journal.discard()
            self.document.undo_stack.setClean()
        self.close()

    # ------------------------------------------------------------------ events

    def showEvent(self, event: QShowEvent) -> None:  # noqa: N802 (Qt override)
        """Once the window manager has framed the window: its frame fits the screen."""
        super().showEvent(event)
        if not event.spontaneous():
            QTimer.singleShot(0, self, lambda: fit_frame(self))

    def closeEvent(self, event: QCloseEvent) -> None:  # noqa: N802 (Qt override)
        """Ask about unsaved edits; then release the VTK render window with the window."""
        if not self.furnished:  # closed while the editor loads: nothing to ask or release
            save_layout(self, self.settings)
            super().closeEvent(event)
            return
        if not self.files.maybe_save():
            event.ignore()
            return
        self.journal.stop()  # deleted by maybe_save unless it holds unsaved edits
        save_layout(self, self.settings)
        self.surface_layer.shutdown()
        self.gestures.close()
        self.plotter.close()
        super().closeEvent(event)

    def dragEnterEvent(self, event: QDragEnterEvent) -> None:  # noqa: N802 (Qt override)
        if self.furnished and any(url.isLocalFile() for url in event.mimeData().urls()):
            event.acceptProposedAction()

    def dropEvent(self, event: QDropEvent) -> None:  # noqa: N802 (Qt override)
        files = [Path(url.toLocalFile()) for url in event.mimeData().urls() if url.isLocalFile()]
        if files:
            event.acceptProposedAction()
            self.files.open_file(files[0])

    # ------------------------------------------------------------------ building

    def _wire_selection(self) -> None:
        """Residues chosen in the docks are selected and centred; the sequence bar shows the map's scores."""
        navigation = self.navigation
        self.ramachandran_panel.residueActivated.connect(lambda row: navigation.select_and_centre([row]))
        self.validation_panel.flagActivated.connect(navigation.show_flag)
        self.sequence_bar.strip.residuesActivated.connect(navigation.select_and_centre)
        self.sequence_bar.strip.groupsActivated.connect(navigation.select_group_and_centre)
        self.correlation.judged.connect(lambda: self.sequence_bar.strip.set_scores(
            None if self.correlation.quality is None else self.correlation.quality.residues))

    def _make_docks(self) -> dict[str, QDockWidget]:
        """The docks by title, each with an empty panel until the editor has loaded; each in View ▸."""
        docks = {title: new_dock(self, title, Pending(PENDING_SIZES[title])) for title in DOCK_AREAS}
        console = docks[CONSOLE_DOCK]
        console.visibilityChanged.connect(lambda: tidy_tab_bars(self))
        self.menus.add("docks", *(dock.toggleViewAction() for dock in docks.values() if dock is not console))
        console.toggleViewAction().setShortcut(QKeySequence("Ctrl+Shift+P"))
        self.menus.add("console", console.toggleViewAction())
        return docks

    def _place_docks(self) -> None:
        """The level controls at the top of the right column, the other panels in tabs under
        them, the sequence bar above the view and the Python console (hidden) below it."""
        # the right column runs from the toolbar to the status bar; the sequence bar spans the view only
        self.setCorner(Qt.Corner.TopRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        for title, area in DOCK_AREAS.items():
            self.addDockWidget(area, self.docks[title])
        self.docks[CONSOLE_DOCK].hide()
        tabs = [self.docks[title] for title in TABBED_DOCKS]
        for dock in tabs[1:]:  # one group of tabs under the level controls: each gets the column's height
            self.tabifyDockWidget(tabs[0], dock)
        tabs[0].raise_()
        tidy_tab_bars(self)

    def _fill_docks(self) -> None:
        """Each panel in its dock; on a first run, the right column as wide as its widest panel asks
        and the level controls as tall as they need."""
        panels = {LEVELS_DOCK: scrolled(self.dimension_panel), "Display": scrolled(self.display_panel),
                  "Surface": self.surface_panel, "Validation": scrolled(self.validation_panel),
                  "Ramachandran": scrolled(self.ramachandran_panel), "Compare": self.comparison_panel,
                  "Map": scrolled(self.map_panel), "Measurements": self.measurements_panel, "History": self.history,
                  SEQUENCE_DOCK: self.sequence_bar, CONSOLE_DOCK: self.console}
        for title, panel in panels.items():
            self.docks[title].widget().deleteLater()
            self.docks[title].setWidget(panel)
        column = [dock for title, dock in self.docks.items() if DOCK_AREAS[title] == DOCK_AREAS[LEVELS_DOCK]]
        self._size_column(QSize(max(dock.sizeHint().width() for dock in column),
                                self.dimension_panel.sizeHint().height() + 30))

    def _size_column(self, size: QSize) -> None:
        """On a first run (no layout kept, whose sizes the person chose): the right column as wide,
        and the level controls as tall, as ``size``."""
        if self.settings.value(LAYOUT_KEY) is None:
            self.resizeDocks([self.docks[LEVELS_DOCK]], [size.width()], Qt.Orientation.Horizontal)
            self.resizeDocks([self.docks[LEVELS_DOCK]], [size.height()], Qt.Orientation.Vertical)
