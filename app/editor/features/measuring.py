"""Labels and measurements picked with the mouse: *View ▸ Label*, *Measure Distance*,
*Measure Angle* or *Measure Dihedral* makes the next clicks in the view pick atoms (a residue
clicked where no atom is drawn gives its Cα, and a label of the residue) until there are
enough; Esc or the same entry again stops. *Label Selected Residues* labels the residues of the
selection at once (a binding site found with Go to Residue). They are listed in the
*Measurements* dock and drawn in the view (:mod:`app.editor.scene.layers.measurements`)."""

from __future__ import annotations

from PySide6.QtGui import QActionGroup, QKeySequence
from PySide6.QtWidgets import QMainWindow

from app.editor.document import Document
from app.editor.features.menus import Menus
from app.editor.interaction.identify import Hit
from app.editor.measurements import KINDS, checked

TOOLS = {1: ("&Label", "Ctrl+Shift+L"), 2: ("Measure &Distance", "Ctrl+Shift+D"),
         3: ("Measure &Angle", "Ctrl+Shift+A"), 4: ("Measure Di&hedral", "Ctrl+Shift+H")}
"""Each tool's entry and shortcut, by the atoms it picks."""


class Measuring:
    """The tools that pick atoms for a label or a measurement."""

    def __init__(self, window: QMainWindow, document: Document, menus: Menus) -> None:
        self.window = window
        self.document = document
        self.wanted = 0
        """Atoms the tool in use picks (0: none in use)."""
        self.picked: list[int] = []
        self.tools = QActionGroup(window)
        self.tools.setExclusionPolicy(QActionGroup.ExclusionPolicy.ExclusiveOptional)
        for count, (text, key) in TOOLS.items():
            action = menus.action(text, QKeySequence(key), lambda on, count=count: self.use(count if on else 0))
            action.setCheckable(True)
            self.tools.addAction(action)
        self.label_selection_action = menus.action("Label &Selected Residues", QKeySequence(), self.label_selection)
        self.clear_action = menus.action("Clear Measurements", QKeySequence(),
                                         lambda: document.measurements.replace([]))
        menus.add("measure", *self.tools.actions(), self.label_selection_action, self.clear_action)
        document.loaded.connect(lambda: self.use(0))

    def use(self, count: int) -> None:
        """Pick ``count`` atoms with the next clicks (0: stop)."""
        self.wanted, self.picked = count, []
        for action in self.tools.actions():
            action.setChecked(TOOLS.get(count, ("",))[0] == action.text())
        self._say()

    def label_selection(self) -> None:
        """Label each selected residue (at its Cα) that has no label yet, all in one change."""
        document = self.document
        if document.model is None or not len(document.selection):
            self.window.statusBar().showMessage("Select residues first: click them, or Go to Residue (Ctrl+L)", 8000)
            return
        labelled = {m.atoms[0] for m in document.measurements.items if m.residue}
        rows = [row for row in document.ca_rows[document.selection].tolist() if row not in labelled]
        n_atoms = len(document.model.coords)
        document.measurements.replace(document.measurements.items + [checked((row,), n_atoms, residue=True)
                                                                     for row in rows])

    def click(self, hit: Hit | None) -> bool:
        """A click in the view while a tool is in use picks the atom under it (a residue's Cα);
        returns whether the click was the tool's."""
        if not self.wanted:
            return False
        if hit is not None and hit.kind in ("atom", "residue"):
            row = hit.index if hit.kind == "atom" else int(self.document.ca_rows[hit.row])
            if row not in self.picked:
                self.picked.append(row)
            if len(self.picked) == self.wanted:  # a label of a residue clicked where no atom is drawn
                self.document.measurements.add(self.picked, len(self.document.model.coords),
                                               residue=self.wanted == 1 and hit.kind == "residue")
                self.picked = []
        self._say()
        return True

    def _say(self) -> None:
        if self.wanted:
            what = KINDS[self.wanted]
            self.window.statusBar().showMessage(
                f"{what.capitalize()}: click atom {len(self.picked) + 1} of {self.wanted} (Esc stops)"
                if self.wanted > 1 else "Label: click an atom (Esc stops)")
        else:
            self.window.statusBar().clearMessage()
