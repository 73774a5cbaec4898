"""``ribbonwave FILE`` shows its window at once and the structure once it is read and drawn."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtWidgets import QApplication, QDockWidget, QLabel, QProgressBar
from pytestqt.qtbot import QtBot

from app.editor.document import Document
from app.main import main
from tests.conftest import DATA


def test_the_window_shows_before_the_structure_is_read(qtbot: QtBot, monkeypatch: pytest.MonkeyPatch) -> None:
    """While the file is read the window is on screen with its docks, the file's name in its
    title and "Opening …" with a busy bar in its status bar; then the molecule is drawn and
    the busy bar goes."""
    seen: dict[str, object] = {}
    read = Document.open

    def opened(document: Document, path: Path, *args: object, **kwargs: object) -> None:
        window = QApplication.activeWindow() or next(w for w in QApplication.topLevelWidgets() if w.isVisible())
        bar = window.statusBar()
        seen["while reading"] = (window.isVisible(), window.windowTitle(),
                                 [label.text() for label in bar.findChildren(QLabel) if label.isVisible()],
                                 len(bar.findChildren(QProgressBar)),
                                 sum(dock.isVisible() for dock in window.findChildren(QDockWidget)))
        read(document, path, *args, **kwargs)

    def run(app: QApplication) -> int:  # instead of the event loop: what a person sees once it runs
        window = next(w for w in QApplication.topLevelWidgets() if w.isVisible())
        qtbot.waitUntil(lambda: window.plotter.frames > 0)
        seen["then"] = (window.windowTitle(), len(window.scene.meshes["cartoon"].points),
                        [bar.isVisible() for bar in window.statusBar().findChildren(QProgressBar)],
                        [label.text() for label in window.statusBar().findChildren(QLabel) if label.isVisible()])
        window.quit_unattended(discard=True)
        return 0

    monkeypatch.setattr(Document, "open", opened)
    monkeypatch.setattr(QApplication, "exec", run)
    assert main([str(DATA / "1UBQ.pdb.gz")]) == 0
    visible, title, message, busy, docks = seen["while reading"]
    assert visible and title == "1UBQ.pdb.gz — ribbonwave" and "Opening 1UBQ.pdb.gz…" in message and busy == 1
    assert docks >= 3  # the level controls, the tabs under them and the sequence bar
    title, points, bars, labels = seen["then"]
    assert title == "1UBQ.pdb.gz[*] — ribbonwave" and points > 5000 and not any(bars)
    assert "1UBQ.pdb.gz  (1UBQ)" in labels and not any(text.startswith("Opening") for text in labels)


def test_a_bad_file_closes_the_staged_window_and_says_why(qtbot: QtBot, tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.pdb"
    bad.write_text("not a structure\n")
    assert main([str(bad)]) == 1
    assert capsys.readouterr().err.strip().endswith("bad.pdb: not a structure file (no atoms found)")
    assert not any(window.isVisible() for window in QApplication.topLevelWidgets())
