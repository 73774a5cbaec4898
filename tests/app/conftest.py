"""Fixtures of the app tests: private settings, recorded message boxes, documents on real entries."""

from pathlib import Path

import pytest
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QApplication, QMessageBox

from app.editor.document import Document

DATA = Path(__file__).resolve().parent.parent / "data"


@pytest.fixture(autouse=True)
def private_settings(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Recent files and other settings go to a temporary folder, never the user's."""
    folder = tmp_path_factory.mktemp("settings")
    for fmt in (QSettings.Format.NativeFormat, QSettings.Format.IniFormat):
        QSettings.setPath(fmt, QSettings.Scope.UserScope, str(folder))
    return folder


class Questions:
    """Stands in for ``QMessageBox.question``: records the questions, gives a set answer."""

    def __init__(self) -> None:
        self.asked: list[str] = []
        self.defaults: list[object] = []
        """The button each question offers as its default (None where it names none)."""
        self.answer = QMessageBox.StandardButton.Discard

    def __call__(self, parent: object, title: str, text: str, *args: object) -> QMessageBox.StandardButton:
        self.asked.append(text)
        self.defaults.append(args[1] if len(args) > 1 else None)
        return self.answer


@pytest.fixture(autouse=True)
def state_home(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Recovery journals go to a temporary folder, never the user's."""
    folder = tmp_path_factory.mktemp("state")
    monkeypatch.setenv("XDG_STATE_HOME", str(folder))
    return folder / "ribbonwave"


@pytest.fixture(autouse=True)
def questions(monkeypatch: pytest.MonkeyPatch) -> Questions:
    """No modal dialog may block a test: questions are answered 'Discard' unless a test says otherwise."""
    recorder = Questions()
    monkeypatch.setattr(QMessageBox, "question", recorder)
    return recorder


@pytest.fixture(autouse=True)
def warned(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """No warning may block a test: the messages of ``QMessageBox.warning`` are recorded instead."""
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "warning", lambda parent, title, text, *args: shown.append(text))
    return shown


@pytest.fixture
def errors(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Messages of ``QMessageBox.critical`` dialogs, which are not shown."""
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", lambda parent, title, text, *args: shown.append(text))
    return shown


@pytest.fixture
def ubiquitin(qapp: QApplication) -> Document:
    document = Document()
    document.open(DATA / "1UBQ.pdb.gz")
    return document
