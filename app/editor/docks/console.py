"""An interactive Python console, as in PyMOL or ChimeraX: typed lines run in a given namespace and
their output, results and tracebacks are shown above the prompt."""

from __future__ import annotations

import code
import sys
import traceback
from collections.abc import Callable
from contextlib import redirect_stderr, redirect_stdout

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QFontDatabase, QKeyEvent, QTextCursor
from PySide6.QtWidgets import QHBoxLayout, QLabel, QLineEdit, QPlainTextEdit, QVBoxLayout, QWidget

PS1 = ">>>"
PS2 = "..."
SYSTEM_EXIT = "SystemExit ignored: the console cannot close the application.\n"


class _Writer:
    """A file-like object for ``sys.stdout`` and ``sys.stderr`` that hands its text to a callback."""

    def __init__(self, write: Callable[[str], None]) -> None:
        self._write = write

    def write(self, text: str) -> int:
        self._write(text)
        return len(text)

    def flush(self) -> None:
        pass


class _Interpreter(code.InteractiveConsole):
    """An interactive console whose errors always go to ``write``, whatever ``sys.excepthook`` is."""

    def __init__(self, namespace: dict, write: Callable[[str], None]) -> None:
        super().__init__(namespace)
        self._write = write

    def write(self, data: str) -> None:
        self._write(data)

    def showsyntaxerror(self, filename: str | None = None) -> None:
        kind, value, _ = sys.exc_info()
        self.write("".join(traceback.format_exception_only(kind, value)))

    def showtraceback(self) -> None:
        kind, value, trace = sys.exc_info()
        self.write("".join(traceback.format_exception(kind, value, trace.tb_next if trace else None)))


class PythonConsole(QWidget):
    """A read-only output above a prompt and an input line; Enter runs the line, Up and Down recall history."""

    def __init__(self, namespace: dict, parent: QWidget | None = None) -> None:
        """Typed code runs in ``namespace``, which the caller may fill beforehand."""
        super().__init__(parent)
        self.namespace = namespace
        self._interpreter = _Interpreter(namespace, self._write)
        self._writer = _Writer(self._write)
        self._history: list[str] = []
        self._recalled = 0

        font = QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
        self.output = QPlainTextEdit()
        self.output.setReadOnly(True)
        self.prompt = QLabel(PS1)
        self.input = QLineEdit()
        for widget in (self.output, self.prompt, self.input):
            widget.setFont(font)

        line = QHBoxLayout()
        line.addWidget(self.prompt)
        line.addWidget(self.input)
        layout = QVBoxLayout(self)
        layout.addWidget(self.output)
        layout.addLayout(line)

        self.input.returnPressed.connect(self._enter)
        self.input.installEventFilter(self)
        self.setFocusProxy(self.input)

    def run(self, line: str) -> bool:
        """Echo ``line`` with its prompt and push it to the interpreter; return whether more input is needed."""
        self._write(f"{self.prompt.text()} {line}\n")
        if line.strip():
            self._history.append(line)
        self._recalled = len(self._history)
        with redirect_stdout(self._writer), redirect_stderr(self._writer):
            try:
                more = bool(self._interpreter.push(line))
            except SystemExit:
                self._interpreter.resetbuffer()
                self._write(SYSTEM_EXIT)
                more = False
        self.prompt.setText(PS2 if more else PS1)
        return more

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """Up and Down in the input recall earlier and later lines of the history."""
        if watched is self.input and event.type() == QEvent.Type.KeyPress and isinstance(event, QKeyEvent):
            if event.key() == Qt.Key.Key_Up:
                self._recall(-1)
                return True
            if event.key() == Qt.Key.Key_Down:
                self._recall(1)
                return True
        return super().eventFilter(watched, event)

    def _enter(self) -> None:
        line = self.input.text()
        self.input.clear()
        self.run(line)

    def _recall(self, step: int) -> None:
        if not self._history:
            return
        self._recalled = min(max(self._recalled + step, 0), len(self._history))
        recalled = self._history[self._recalled] if self._recalled < len(self._history) else ""
        self.input.setText(recalled)

    def _write(self, text: str) -> None:
        self.output.moveCursor(QTextCursor.MoveOperation.End)
        self.output.insertPlainText(text)
        self.output.moveCursor(QTextCursor.MoveOperation.End)
