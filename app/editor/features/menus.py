"""The menu bar and the tool bar in sections, which the features fill with their actions.

The window lays out the sections (:data:`MENUS`, :data:`TOOLBAR`); each feature adds its entries
to sections by name when it is built, so the window names no feature's actions. A section's
entries come in the order they are added; a separator lies between two sections.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QIcon, QKeySequence
from PySide6.QtWidgets import QMainWindow, QMenu, QWidget

MENUS = {
    "&File": ("open", "save", "session", "quit"),
    "&Edit": ("undo", "mode", "region", "fit"),
    "&View": ("camera", "measure", "docks", "console"),
    "&Help": ("help",),
}
"""Each menu's sections, top to bottom."""
TOOLBAR = ("file", "undo", "mode", "camera")
"""The tool bar's sections, left to right."""


class Menus:
    """The sections of ``window``'s menus and tool bar, and the window's actions."""

    def __init__(self, window: QMainWindow) -> None:
        self.window = window
        self._menus: dict[str, tuple[QMenu, QAction | None]] = {}  # a section's menu and the separator after it
        for title, sections in MENUS.items():
            menu = window.menuBar().addMenu(title)
            for section in sections:
                self._menus[section] = (menu, None if section == sections[-1] else menu.addSeparator())
        self.toolbar = window.addToolBar("Main")
        self.toolbar.setObjectName("Main")
        self.toolbar.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        self._tools = {section: None if section == TOOLBAR[-1] else self.toolbar.addSeparator() for section in TOOLBAR}

    def action(self, text: str, shortcut: QKeySequence | QKeySequence.StandardKey, slot: Callable[..., object],
               icon: QIcon | None = None) -> QAction:
        """A new action of the window: its shortcut works wherever the focus is, the 3D view included."""
        action = QAction(text, self.window)
        action.setShortcut(shortcut)
        action.triggered.connect(slot)
        if icon is not None:
            action.setIcon(icon)
        self.window.addAction(action)
        return action

    def add(self, section: str, *actions: QAction) -> None:
        """Put ``actions`` at the end of menu section ``section``."""
        menu, end = self._menus[section]
        menu.insertActions(end, list(actions))  # (before None: at the end of the menu)

    def add_entry(self, section: str, text: str, slot: Callable[[], object]) -> QAction:
        """A menu entry of its own (no shortcut) at the end of ``section``."""
        menu, _ = self._menus[section]
        action = QAction(text, menu)
        action.triggered.connect(slot)
        self.add(section, action)
        return action

    def add_menu(self, section: str, title: str) -> QMenu:
        """A submenu at the end of ``section``."""
        menu, _ = self._menus[section]
        submenu = QMenu(title, menu)
        self.add(section, submenu.menuAction())
        return submenu

    def add_tools(self, section: str, *tools: QAction | QWidget) -> None:
        """Put ``tools`` (actions, or widgets such as a line edit) at the end of tool bar section ``section``."""
        end = self._tools[section]
        for tool in tools:
            if isinstance(tool, QWidget):
                self.toolbar.insertWidget(end, tool)
            else:
                self.toolbar.insertAction(end, tool)
