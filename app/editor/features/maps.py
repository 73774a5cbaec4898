"""Maps and fits: File ▸ Open Map (a density map, or an MTZ file's map coefficients), and
Edit ▸ Fit to Map and Fit to Compared Structure, at the level shown or coarse to fine (the
fits themselves: :mod:`app.editor.features.fitting`, loaded with the first)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import QFileDialog, QInputDialog, QMainWindow, QMessageBox

from app import PROG

if TYPE_CHECKING:
    from app.editor.document import Document
    from app.editor.features.menus import Menus
    from app.editor.map_correlation import LiveCorrelation
    from app.editor.scene.map_mesh import MapMesh
    from app.editor.scene.overlay import Compared, Comparison
    from core.fitting.coarse_to_fine import LevelFit

MAP_FILTER = "Density maps and map coefficients (*.ccp4 *.mrc *.map *.mtz *.gz);;All files (*)"


class MapsAndFits:
    """The maps of ``window``'s ``document`` (drawn by ``maps``, correlated by ``correlation``)
    and its fits to them or to the structures of ``comparison``."""

    def __init__(self, window: QMainWindow, document: Document, maps: MapMesh, correlation: LiveCorrelation,
                 comparison: Comparison, menus: Menus) -> None:
        self.window = window
        self.document = document
        self.maps = maps
        self.correlation = correlation
        self.comparison = comparison
        self.open_map_action = menus.action("Open &Map…", QKeySequence("Ctrl+Shift+M"), self._open_map_dialog)
        self.open_map_action.setToolTip("Read a CCP4 or MRC density map and draw it around the view's centre")
        self.fit_actions = [
            menus.action(text, QKeySequence(), lambda _=False, t=target, c=coarse: self.fit(t, c))
            for target, name in (("map", "Map"), ("compared", "Compared Structure"))
            for coarse, text in ((False, f"Fit to {name} at This Level"), (True, f"Fit to {name} Coarse to Fine"))
        ]
        """Fit to the map at this level and coarse to fine, then to the compared structure likewise."""
        for action in self.fit_actions:
            action.setToolTip("Move the edited segment's control points " + (
                "at every level from 0 up to the one shown, coarse first, then regularize; each level one undo step"
                if "Coarse" in action.text() else "at the level shown (one undo step)"))
        menus.add("open", self.open_map_action)
        menus.add("fit", *self.fit_actions)
        for signal in (document.loaded, maps.changed, comparison.changed):
            signal.connect(self._update_fit_actions)
        self._update_fit_actions()

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
                name, chosen = QInputDialog.getItem(self.window, "Map Coefficients", f"{Path(path).name} has no "
                                                    "columns named as refinement names 2mFo−DFc. Amplitude and phase:",
                                                    names, 0, False)
                if not chosen:
                    return False
                self.maps.open(Path(path), pairs[names.index(name)])
        except ValueError as error:  # a MapError
            if raise_errors:
                raise
            QMessageBox.critical(self.window, PROG, str(error))
            return False
        return True

    def fit(self, target: str, coarse_to_fine: bool, levels: list[int] | None = None, *,
            raise_errors: bool = False) -> list[LevelFit]:
        """Fit the edited chain to the ``'map'`` or the ``'compared'`` structure (the first
        shown) at ``levels`` (default: the level shown, or coarse to fine every level up to it),
        each level one undo step (see :mod:`app.editor.features.fitting`). Returns the levels
        fitted; what prevents a fit is said in a dialog (or raised as ValueError with ``raise_errors``)."""
        # the fitting code loads with the first fit
        from app.editor.features.fitting import (
            compared_target,
            levels_to_fit,
            map_target,
            run_fit,
        )

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
            QMessageBox.critical(self.window, PROG, str(error))
            return []
        shown, unheld = math.floor(document.shown_level()), ""
        if levels is None:
            levels = levels_to_fit(document, fit_target, coarse_to_fine)
            if max(levels) < shown:
                unheld = (f" (levels {max(levels) + 1}–{shown} left out: finer than the map resolves at "
                          f"{self.correlation.resolution:.3g} Å; each residue refined instead)")
        kept = run_fit(document, fit_target, levels, self.window)
        if target == "map" and kept:
            self.correlation.judge()  # now, not after the edits' pause
            judged = f": {self.correlation.summary()}" if self.correlation.quality is not None else ""
            self.window.statusBar().showMessage(f"Fitted to the map{judged}{unheld}", 30000)
        return kept

    def _compared(self) -> Compared:
        """The compared structure fits go to: the first shown (else the first)."""
        items = self.comparison.items
        if not items:
            raise ValueError("no compared structure: File ▸ Add Structures for Comparison… first")
        return next((item for item in items if item.visible), items[0])

    def _open_map_dialog(self) -> None:
        document = self.document
        folder = str(self.maps.path.parent if self.maps.path else document.path.parent if document.path
                     else Path.home())
        name, _ = QFileDialog.getOpenFileName(self.window, "Open Map", folder, MAP_FILTER)
        if name:
            self.open_map(Path(name))

    def _update_fit_actions(self) -> None:
        editable = self.document.editable
        for action in self.fit_actions[:2]:
            action.setEnabled(editable and self.maps.density is not None)
        for action in self.fit_actions[2:]:
            action.setEnabled(editable and bool(self.comparison.items))
