"""Fixtures of the editor tests: a shown window on an entry of tests/data."""

from collections.abc import Callable
from pathlib import Path

import pytest
from pytestqt.qtbot import QtBot

from app.editor.document import Document
from app.editor.main_window import MainWindow

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture
def open_window(qtbot: QtBot) -> Callable[[str], MainWindow]:
    """Opens ``name`` (a file of tests/data) in a shown, exposed and drawn window, closed after the test."""

    def open_(name: str) -> MainWindow:
        document = Document()
        document.open(DATA / name)
        window = MainWindow(document)
        qtbot.addWidget(window)  # closed (answering 'Discard'), and so its plotter too, after the test
        window.show()
        qtbot.waitExposed(window)
        window.plotter.render()
        qtbot.waitUntil(lambda: window.plotter.frames > 0)
        return window

    return open_


@pytest.fixture(params=["native", "widget"])
def view_kind(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Each of the two 3D views (``RIBBONWAVE_VIEW``): VTK's native window and pyvistaqt's
    ``QOpenGLWidget``; ask for it before ``open_window``."""
    monkeypatch.setenv("RIBBONWAVE_VIEW", request.param)
    return request.param
