"""The editor's main window, the composition root: it builds the 3D view, the docks and the
features, and wires them together.

A :class:`~app.editor.document.Document` is drawn by the :class:`~app.editor.scene.scene.Scene`
into the :class:`~app.editor.scene.view.View`; :class:`~app.editor.interaction.gestures.Gestures`
route the pointer to the :class:`~app.editor.interaction.drag.DragController` and the camera.
Each feature (:mod:`app.editor.features`: files, sessions, editing, navigation, maps and fits,
image export, help) builds its own actions and slots and puts them in the menus
(:class:`~app.editor.features.menus.Menus`); the window only lays out the docks, keeps its
layout between runs and closes in order.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QSettings, QSize, Qt, QTimer
from PySide6.QtGui import QCloseEvent, QDragEnterEvent, QDropEvent, QKeySequence, QShowEvent
from PySide6.QtWidgets import QDockWidget, QMainWindow, QUndoView, QWidget

from app import PROG
from app.editor.composition import compose_once
from app.editor.docks.comparison import ComparisonPanel
from app.editor.docks.console import PythonConsole
from app.editor.docks.layout import (
    add_dock,
    fit_frame,
    fitted,
    restore_layout,
    save_layout,
    scrolled,
    tidy_tab_bars,
)
from app.editor.docks.map_panel import MapPanel
from app.editor.docks.measurements import MeasurementsPanel
from app.editor.docks.panels import DisplayPanel, RibbonDimensionPanel
from app.editor.docks.ramachandran import RamachandranPanel
from app.editor.docks.sequence import SequenceBar
from app.editor.docks.surfaces import SurfacePanel
from app.editor.docks.validation import ValidationPanel
from app.editor.document import Document
from app.editor.features.clipping import Clipping
from app.editor.features.editing import Editing
from app.editor.features.export import ImageExport
from app.editor.features.files import Files
from app.editor.features.help import Help
from app.editor.features.maps import MapsAndFits
from app.editor.features.measuring import Measuring
from app.editor.features.menus import Menus
from app.editor.features.models import Models
from app.editor.features.navigation import Navigation
from app.editor.features.sessions import Sessions
from app.editor.interaction.drag import DragController
from app.editor.interaction.gestures import Gestures
from app.editor.live_validation import LiveValidation
from app.editor.map_correlation import LiveCorrelation
from app.editor.persistence import journal
from app.editor.scene.layers.validation_markers import ValidationMarkers
from app.editor.scene.map_mesh import MapMesh
from app.editor.scene.overlay import Comparison, ComparisonView
from app.editor.scene.scene import Scene
from app.editor.scene.view import new_view
from app.editor.scripting import EditorAPI
from app.editor.status_bar import StatusBar
from app.editor.surfaces.layer import SurfaceLayer

DEFAULT_SIZE = QSize(1400, 900)
"""The window's first size, where the screen has room for it."""


class MainWindow(QMainWindow):
    """The editor window on a :class:`Document` (a new, empty one when none is given)."""

    def __init__(self, document: Document | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        compose_once(self)
        self.document = document if document is not None else Document()
        self.document.setParent(self)
        self.settings = QSettings(PROG, PROG)
        self.resize(fitted(DEFAULT_SIZE))
        self.setAcceptDrops(True)
        self.journal = journal.Journal(self.document)

        self.plotter = new_view(self)
        self.plotter.setAcceptDrops(False)  # dropped files go to the window, which opens them
        self.plotter.iren.clear_key_event_callbacks()  # no pyvista key bindings ('q' would close the view)
        self.plotter.enable_anti_aliasing("fxaa")
        self.setCentralWidget(self.plotter)
        self.validation = LiveValidation(self.document)  # before the scene: its report is new when the scene renders
        self.scene = Scene(self.document, self.plotter)
        self.markers = ValidationMarkers(self.validation, self.scene)
        self.controller = DragController(self.document)
        self.menus = Menus(self)
        self.navigation = Navigation(self, self.document, self.scene, self.plotter, self.menus)
        self.clipping = Clipping(self, self.scene, self.plotter, self.menus)
        self.models = Models(self, self.document, self.menus)

        self.dimension_panel = RibbonDimensionPanel(self.document)
        self.dimension_panel.slider.valueChanged.connect(self.scene.moved)  # less detail while the level slides
        self.dimension_panel.segment.activated.connect(lambda _: (self.scene.frame_segment(), self.plotter.render()))
        self.display_panel = DisplayPanel(self.scene)
        self.comparison = Comparison(self.document)  # after the scene: it redraws once the scene is rebuilt
        self.comparison_view = ComparisonView(self.comparison, self.plotter)
        self.comparison_panel = ComparisonPanel(self.comparison)
        self.validation_panel = ValidationPanel(self.validation)
        self.ramachandran_panel = RamachandranPanel(self.document, self.validation)
        self.surface_layer = SurfaceLayer(self.document, self.plotter)  # after the scene, which clears the view on load
        self.surface_panel = SurfacePanel(self.surface_layer)
        self.maps = MapMesh(self.document, self.plotter)  # after the scene, which clears the view on load
        self.correlation = LiveCorrelation(self.document, self.maps)
        self.files = Files(self, self.document, self.journal, self.settings, self.menus)
        self.menus.add_entry("open", "Add Structures for &Comparison…", self.comparison_panel.add_dialog)
        self.maps_and_fits = MapsAndFits(self, self.document, self.maps, self.correlation, self.comparison,
                                         self.menus)
        self.map_panel = MapPanel(self.maps, self.correlation, self.maps_and_fits.fit_actions)
        self.export = ImageExport(self, self.plotter, self.files, self.menus)
        self.sessions = Sessions(self, self.document, self.journal, self.files, self.menus, plotter=self.plotter,
                                 scene=self.scene, display_panel=self.display_panel, comparison=self.comparison,
                                 clipping=self.clipping)
        self.editing = Editing(self, self.document, self.controller, self.menus)
        self.measuring = Measuring(self, self.document, self.menus)
        self.editing.cancel_action.triggered.connect(lambda: self.measuring.use(0))  # Esc stops a tool too
        self.measurements_panel = MeasurementsPanel(self.document)
        self.help = Help(self, self.menus)
        self.history = QUndoView(self.document.undo_stack)
        self.history.setUniformItemSizes(True)  # (one line a step: a history of thousands lays out at once)
        self._name_history_start()
        self.document.loaded.connect(self._name_history_start)
        self.document.history.trimmed.connect(self._name_history_start)
        self.rw = EditorAPI(self)
        """The ``rw`` object of scripts and of the Python console."""
        self.console = PythonConsole({"rw": self.rw, "np": np})
        self.sequence_bar = SequenceBar(self.document)
        self._wire_selection()
        self._lay_out_docks()
        self.status = StatusBar(self.statusBar(), self.document, self.controller, self.correlation)
        self.editing.modeChanged.connect(self.status.update)
        self.gestures = Gestures(self.document, self.plotter, self.scene, self.controller,
                                 select=self.navigation.select, name=self.status.labels["hover"].setText,
                                 measure=self.measuring.click)
        restore_layout(self, self.settings)

    def _name_history_start(self) -> None:
        """The History dock's first row: the structure as read, or where the history starts now."""
        dropped = self.document.history.base is not None
        self.history.setEmptyLabel("<older steps dropped>" if dropped else "<structure as read>")

    def quit_unattended(self, discard: bool = False) -> None:
        """Close without asking: unsaved edits are kept in the journal unless ``discard``."""
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
        if any(url.isLocalFile() for url in event.mimeData().urls()):
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
        self.correlation.judged.connect(lambda: self.sequence_bar.strip.set_scores(
            None if self.correlation.quality is None else self.correlation.quality.residues))

    def _lay_out_docks(self) -> None:
        """The level controls at the top of the right column, the other panels in tabs under them,
        the sequence bar above the view and the Python console (hidden) below it; each dock in
        View ▸ too."""
        # the right column runs from the toolbar to the status bar; the sequence bar spans the view only
        self.setCorner(Qt.Corner.TopRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        dimension = add_dock(self, "Ribbon dimension", scrolled(self.dimension_panel))
        tabs = [add_dock(self, "Display", scrolled(self.display_panel)), add_dock(self, "Surface", self.surface_panel),
                add_dock(self, "Validation", scrolled(self.validation_panel)),
                add_dock(self, "Ramachandran", scrolled(self.ramachandran_panel)),
                add_dock(self, "Compare", self.comparison_panel), add_dock(self, "Map", scrolled(self.map_panel)),
                add_dock(self, "Measurements", self.measurements_panel), add_dock(self, "History", self.history)]
        for dock in tabs[1:]:  # one group of tabs under the level controls: each gets the column's height
            self.tabifyDockWidget(tabs[0], dock)
        tabs[0].raise_()
        docks: list[QDockWidget] = [dimension, *tabs,
                                    add_dock(self, "Sequence", self.sequence_bar, Qt.DockWidgetArea.TopDockWidgetArea)]
        self.console_dock = add_dock(self, "Python Console", self.console, Qt.DockWidgetArea.BottomDockWidgetArea)
        self.console_dock.hide()
        self.resizeDocks([dimension], [self.dimension_panel.sizeHint().height() + 30], Qt.Orientation.Vertical)
        tidy_tab_bars(self)
        self.console_dock.visibilityChanged.connect(lambda: tidy_tab_bars(self))
        self.menus.add("docks", *(dock.toggleViewAction() for dock in docks))
        console = self.console_dock.toggleViewAction()
        console.setShortcut(QKeySequence("Ctrl+Shift+P"))
        self.menus.add("console", console)
