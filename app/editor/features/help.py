"""The Help menu: the mouse and keyboard reference and About with the versions in use, each
in a box that does not block the editor.

The keyboard table is read from the window's actions, so it always names the keys bound.
"""

from __future__ import annotations

import platform
from importlib.metadata import version
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt, qVersion
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMainWindow, QMenu, QMessageBox

from app import PROG

if TYPE_CHECKING:
    from app.editor.features.menus import Menus

MOUSE = (
    ("Drag a control point", "move it in the plane facing you (one undo step)"),
    ("Drag a face of the handle box", "move the picked point in that face's plane"),
    ("Shift while dragging", "keep to the one axis the pointer moves most along"),
    ("Click a control point", "pick it: the status bar names the residues it moves"),
    ("Click a residue", "select it; on another chain, edit that chain"),
    ("Double click", "centre the view on what is under the pointer"),
    ("Drag elsewhere", "turn the view; wheel: zoom"),
    ("Middle-button drag (or Shift+drag elsewhere)", "pan the view"),
    ("Right-button drag", "zoom"),
    ("Shift+right-button drag", "move the clipping slab's near (up, down) and far (left, right) planes"),
    ("View ▸ Label, Measure …, then click atoms", "label them, or measure distance, angle, dihedral"),
    ("Point at anything", "name it in a tooltip and the status bar"),
    ("Sequence bar: click, drag, Shift+click", "select residues and centre on them"),
)


class Help:
    """Help ▸ Mouse and Keyboard and About of ``window``."""

    def __init__(self, window: QMainWindow, menus: Menus) -> None:
        self.window = window
        menus.add("help", menus.action("&Mouse and Keyboard", QKeySequence.StandardKey.HelpContents,
                                       self.show_reference),
                  menus.action(f"&About {PROG}", QKeySequence(), self.show_about))

    def show_reference(self) -> QMessageBox:
        """Help ▸ Mouse and Keyboard: the gestures and the keys bound (a window-modal box)."""
        window = self.window
        menus = [action for menu in window.menuBar().findChildren(QMenu) for action in menu.actions()]
        return self._message("Mouse and keyboard", reference_html(list(dict.fromkeys(menus + window.actions()))))

    def show_about(self) -> QMessageBox:
        """Help ▸ About: what ribbonwave is and the versions of what it runs on."""
        return self._message(f"About {PROG}", "<p><b>ribbonwave</b>: multiresolution (wavelet) analysis and "
                             "editing of protein structures, after M. Carson, <i>Wavelets and molecular structure</i> "
                             "(1996).</p><pre>" + about_text() + "</pre>")

    def _message(self, title: str, html: str) -> QMessageBox:
        box = QMessageBox(QMessageBox.Icon.NoIcon, title, html, QMessageBox.StandardButton.Close, self.window)
        box.setTextFormat(Qt.TextFormat.RichText)
        box.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        box.open()  # not blocking: the editor goes on behind it
        return box


def reference_html(actions: list[QAction]) -> str:
    """An HTML table of the mouse gestures and of the keys bound to ``actions``."""
    rows = [f"<tr><td><b>{gesture}</b></td><td>{effect}</td></tr>" for gesture, effect in MOUSE]
    keys = []
    for action in actions:
        shortcuts = [s.toString(QKeySequence.SequenceFormat.NativeText) for s in action.shortcuts() if not s.isEmpty()]
        if shortcuts:
            name = action.text().replace("&", "").rstrip("…")
            keys.append(f"<tr><td><b>{' or '.join(shortcuts)}</b></td><td>{name}</td></tr>")
    return (f"<h3>Mouse</h3><table cellspacing='4'>{''.join(rows)}</table>"
            f"<h3>Keyboard</h3><table cellspacing='4'>{''.join(keys)}</table>")


def about_text() -> str:
    """One line per component: ribbonwave, Python, Qt, VTK, pyvista, gemmi, numpy, scipy."""
    from vtkmodules.vtkCommonCore import vtkVersion

    versions = {"ribbonwave": version("ribbonwave"), "Python": platform.python_version(), "Qt": qVersion(),
                "PySide6": version("PySide6-Essentials"), "VTK": vtkVersion.GetVTKVersion(),
                "pyvista": version("pyvista"), "gemmi": version("gemmi"), "numpy": version("numpy"),
                "scipy": version("scipy")}
    return "\n".join(f"{name} {value}" for name, value in versions.items())
