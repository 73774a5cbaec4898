"""Labels and measurements picked with the mouse: *View ▸ Label*, *Measure Distance*,
*Measure Angle* or *Measure Dihedral* makes the next clicks in the view pick atoms (a residue
clicked where no atom is drawn gives its Cα, and a label of the residue) until there are
enough; Esc or the same entry again stops. *Label Selection* labels the residues and ligands of
the selection at once (a binding site found with Go to Residue); *Show Polar Contacts* measures
the hydrogen-bonding distances from them to the atoms around (:mod:`core.geometry.contacts`):
of a ligand selected (``resn BEN``), its hydrogen bonds to the protein, whose residues join the
selection so that their atoms show; of a metal site, the bonds of its ion too.
They are listed in the *Measurements* dock and drawn in the view
(:mod:`app.editor.scene.layers.measurements`)."""

from __future__ import annotations

import numpy as np
from PySide6.QtGui import QActionGroup, QKeySequence
from PySide6.QtWidgets import QMainWindow

from app.editor.document import Document
from app.editor.features.menus import Menus
from app.editor.interaction.identify import Hit
from app.editor.measurements import KINDS, central_atom, checked
from app.editor.status_bar import selection_text
from core.geometry.contacts import POLAR_REACH, selection_contacts
from core.protein.lookup import Selected, group_starts, groups_of

MOST_AT_ONCE = 500
"""Most labels or contacts made at once: more would hide the molecule, each a text drawn."""
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
        self.label_selection_action = menus.action("Label &Selection", QKeySequence(), self.label_selection)
        self.contacts_action = menus.action("Show Polar &Contacts of Selection", QKeySequence(),
                                            self.show_polar_contacts)
        self.clear_action = menus.action("Clear Measurements", QKeySequence(),
                                         lambda: document.measurements.replace([]))
        menus.add("measure", *self.tools.actions(), self.label_selection_action, self.contacts_action,
                  self.clear_action)
        document.loaded.connect(lambda: self.use(0))

    def use(self, count: int) -> None:
        """Pick ``count`` atoms with the next clicks (0: stop)."""
        self.wanted, self.picked = count, []
        for action in self.tools.actions():
            action.setChecked(TOOLS.get(count, ("",))[0] == action.text())
        self._say()

    def label_selection(self) -> None:
        """Label each selected residue (at its Cα) and group (at its central atom) that has no
        label yet, all in one change."""
        if not self._selected():
            return
        document = self.document
        labelled = {m.atoms for m in document.measurements.items if m.residue}
        groups, coords = document.selected_groups, document.model.coords
        each = np.split(groups, group_starts(document.structure, groups)[1:]) if len(groups) else []
        centres = [central_atom(coords, group) for group in each]
        rows = [(row,) for row in document.ca_rows[document.selection].tolist() + centres if (row,) not in labelled]
        self._add(rows, "labels", residue=True)

    def show_polar_contacts(self) -> None:
        """Measure each polar contact (N and O within 3.5 Å) of the selected residues and
        groups, to the atoms around them and between the selected ligands, waters and residues
        (not between two selected residues: a selected chain shows its contacts to the rest;
        waters only when selected), and each bond of a metal ion among or around them, as the
        atoms are now; all in one change. The residues and groups contacted join the selection."""
        if not self._selected():
            return
        document = self.document
        polar, metal = selection_contacts(document.structure, document.model.coords,
                                          Selected(document.selection, document.selected_groups))
        pairs = np.concatenate([polar, metal])
        measured = {m.atoms for m in document.measurements.items}
        described = selection_text(document)
        if self._add([pair for pair in map(tuple, pairs.tolist()) if pair not in measured and pair[::-1] not in measured],
                     "polar contacts"):
            self._reveal(pairs.ravel())
            self.window.statusBar().showMessage(
                f"{len(polar)} polar contact{'' if len(polar) == 1 else 's'} (N and O {POLAR_REACH:g} Å apart or "
                f"nearer)" + (f" and {len(metal)} metal bond{'' if len(metal) == 1 else 's'}" if len(metal) else "")
                + f" of {described}", 8000)

    def _reveal(self, partners: np.ndarray) -> None:
        """Add the residues and groups of the atoms ``partners`` (the contacts' ends) to the
        selection, so that their atoms show (as ChimeraX's ``reveal``)."""
        document = self.document
        residues = document.structure.atom_residue[partners]
        document.select(np.union1d(document.selection, residues[residues >= 0]),
                        np.union1d(document.selected_groups, groups_of(document.structure, partners)))

    def _selected(self) -> bool:
        """Whether residues or groups are selected; if not, the status bar says how to select them."""
        document = self.document
        if document.model is None or not (len(document.selection) or len(document.selected_groups)):
            self.window.statusBar().showMessage("Select residues or a ligand first: click them, or Go to Residue "
                                                "(Ctrl+L)", 8000)
            return False
        return True

    def _add(self, atoms: list[tuple[int, ...]], what: str, residue: bool = False) -> bool:
        """New measurements of ``atoms`` (one tuple of rows each), all in one change; none, and
        the status bar says why, past :data:`MOST_AT_ONCE` (returns whether they were made)."""
        if len(atoms) > MOST_AT_ONCE:
            self.window.statusBar().showMessage(f"{len(atoms):,} {what} would hide the molecule: select fewer "
                                                f"residues (at most {MOST_AT_ONCE} at once)", 8000)
            return False
        document = self.document
        n_atoms = len(document.model.coords)
        document.measurements.replace(document.measurements.items + [checked(rows, n_atoms, residue=residue)
                                                                     for rows in atoms])
        return True

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
