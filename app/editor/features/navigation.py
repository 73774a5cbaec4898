"""Navigation and selection: View ▸ Reset View and Go to Residue (with its field in the tool
bar), and residues selected and centred from the docks (the sequence bar, the Ramachandran
plot, the validation list)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import QLineEdit, QMainWindow, QStyle

from core.protein.lookup import Selected, find_selection

if TYPE_CHECKING:
    from app.editor.document import Document
    from app.editor.features.menus import Menus
    from app.editor.scene.scene import Scene
    from app.editor.scene.view import View
    from core.geometry.validation import Flag


FLAG_MARGIN = 4.0
"""Å around the atoms of a flag, or of what Go to Residue names, kept in view."""
GO_TO_SHARE = 0.8
"""Of the view's height that what Go to Residue names fills, at most (a flag fills a third)."""


class Navigation:
    """Selecting residues of ``document`` and turning ``plotter``'s view, drawn by ``scene``, to them."""

    def __init__(self, window: QMainWindow, document: Document, scene: Scene, plotter: View, menus: Menus) -> None:
        self.window = window
        self.document = document
        self.scene = scene
        self.plotter = plotter
        self.go_to_action = menus.action("&Go to Residue…", QKeySequence("Ctrl+L"), self._focus_go_to)
        self.go_to_action.setToolTip("Select residues and centre the view on them: A:45, 45, A:40-50, A:40-42, B:45; "
                                      "as in ChimeraX (/A:40-50, :45, /A, :his, :HEM :<5) or PyMOL (chain A and "
                                      "resi 40-50+60, resi 45, A/45/, byres resn HEM around 5); combined by and, or, "
                                      "not and parentheses, with ss H, helix, polymer, organic or solvent (chain A "
                                      "and ss H, /A:40-60 & :HIS); ligands too (A:HEM, resn BEN, organic)")
        self.reset_view_action = menus.action("&Reset View", QKeySequence("Ctrl+R"), self._reset_view,
                                              window.style().standardIcon(QStyle.StandardPixmap.SP_BrowserReload))
        self.go_to_field = QLineEdit()
        self.go_to_field.setPlaceholderText("Go to residue (Ctrl+L)")
        self.go_to_field.setToolTip(self.go_to_action.toolTip())
        self.go_to_field.setClearButtonEnabled(True)
        self.go_to_field.setMaximumWidth(190)
        self.go_to_field.returnPressed.connect(self._go_to_typed)
        menus.add("camera", self.reset_view_action, self.go_to_action)
        menus.add_tools("camera", self.reset_view_action, self.go_to_field)

    def select(self, rows: np.ndarray | list[int], groups: np.ndarray | list[int] = ()) -> None:
        """Select residues ``rows`` and groups ``groups`` (coordinate rows of ligands, ions,
        waters or nucleotides); where the residues lie in one segment, that segment becomes the
        edited one (framed: centre afterwards)."""
        segments = set(self.document.structure.residue_place(rows)[0].tolist())
        if len(segments) == 1:
            self.document.set_segment(segments.pop())
        self.document.select(rows, groups)

    def select_and_centre(self, rows: np.ndarray, point: np.ndarray | None = None) -> None:
        """Select residues ``rows`` (residue-table rows; see :meth:`select`) and centre the view
        on ``point`` (Å; default: their Cα's mean)."""
        rows = np.asarray(rows, dtype=np.int64)
        if point is None and not len(rows):
            return
        self.select(rows)
        self.scene.centre_on(self.document.model.coords[self.document.ca_rows[rows]].mean(axis=0)
                             if point is None else point)
        self.plotter.render()

    def select_group_and_centre(self, group: np.ndarray) -> None:
        """Select a nucleotide, ligand or ion (``group``: its coordinate rows) and centre the view on it."""
        self.select([], group)
        self.scene.centre_on(self.document.model.coords[group].mean(axis=0))
        self.plotter.render()

    def show_flag(self, flag: Flag) -> None:
        """Centre the view on ``flag``'s marker, select its residues (their atoms show: see
        :mod:`app.editor.scene.layers.selection`) and zoom in until they fill about a third of
        the view (never out)."""
        residues = np.array(flag.residues, dtype=np.int64)
        self.select_and_centre(residues, np.array(flag.position))
        atoms = self.document.model.coords[np.isin(self.document.structure.atom_residue, residues)]
        if len(atoms):
            reach = float(np.linalg.norm(atoms - np.array(flag.position), axis=1).max()) + FLAG_MARGIN
            self.scene.zoom_to(reach)
            self.plotter.render()

    def go_to(self, text: str) -> Selected:
        """Select and centre on the residues and groups named by ``text`` (``A:45``, ``45`` in
        the edited chain, ``A:40-50``, ``A:40-42, B:45``, a ligand, ion, water or nucleotide,
        ``A:HEM``, ``/B:20``, or as ChimeraX and PyMOL name them, a binding site too, measured
        as the atoms are now: :mod:`core.protein.lookup`); zoom in (never out) until their
        atoms fill most of the view. Returns what was selected (raises ValueError)."""
        if self.document.model is None:
            raise ValueError("no structure is open")
        structure, coords = self.document.structure, self.document.model.coords
        chain = structure.segments[self.document.segment].chain if structure.segments else None
        selected = find_selection(structure, text, chain, coords)
        self.select(selected.residues, selected.groups)
        atoms = np.union1d(np.flatnonzero(np.isin(structure.atom_residue, selected.residues)), selected.groups)
        centre = (coords[self.document.ca_rows[selected.residues]] if len(selected.residues)
                  else coords[selected.groups]).mean(axis=0)
        self._frame(centre, coords[atoms])
        return selected

    def _frame(self, centre: np.ndarray, atoms: np.ndarray) -> None:
        """Centre the view on ``centre`` (Å) and zoom in until ``atoms`` and a margin fill
        :data:`GO_TO_SHARE` of its height (never out), as PyMOL's ``zoom`` and ChimeraX's
        ``view`` do."""
        self.scene.centre_on(centre)
        self.scene.zoom_to(float(np.linalg.norm(atoms - centre, axis=1).max()) + FLAG_MARGIN, GO_TO_SHARE)
        self.plotter.render()

    def _go_to_typed(self) -> None:
        try:
            self.go_to(self.go_to_field.text())
        except ValueError as error:
            self.window.statusBar().showMessage(str(error), 8000)
            self.go_to_field.selectAll()
            return
        self.plotter.setFocus()  # the keys act on the view again

    def _focus_go_to(self) -> None:
        self.go_to_field.setFocus()
        self.go_to_field.selectAll()

    def _reset_view(self) -> None:
        self.scene.reset_camera()
        self.plotter.render()
