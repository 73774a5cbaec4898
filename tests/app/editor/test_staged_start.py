"""``ribbonwave FILE`` shows its window at once and the structure once it is read and drawn."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from PySide6.QtWidgets import QApplication, QDockWidget, QLabel, QProgressBar
from pytestqt.qtbot import QtBot

from app.editor import launch
from app.editor.document import Document
from app.main import main
from tests.conftest import DATA

ROOT = Path(__file__).resolve().parents[3]
FIRST_PAINT = """
import contextlib, json, sys
from PySide6.QtWidgets import QApplication, QDockWidget
from app.editor import busy, sketch
from app.main import main

opening, seen = busy.opening, {}

@contextlib.contextmanager
def watched(window, path):
    with opening(window, path):  # (the window painted, busy)
        seen.setdefault("window", {
            "visible": window.isVisible(), "title": window.windowTitle(),
            "menus": [action.text() for action in window.menuBar().actions()],
            "docks": sorted(dock.windowTitle() for dock in window.findChildren(QDockWidget) if dock.isVisible()),
            "loaded": sorted(name for name in sys.argv[2:] if name in sys.modules), "layout": layout(window)})
        yield

def layout(window):  # the right column's width, the sequence bar's height and the view's size
    return [window.docks["Display"].width(), window.docks["Sequence"].height(), window.centralWidget().width(),
            window.centralWidget().height()]

def run(app):
    window = next(w for w in QApplication.topLevelWidgets() if w.isVisible())
    app.processEvents()
    seen["then"] = {"loaded": sorted(name for name in sys.argv[2:] if name in sys.modules),
                    "residues": window.document.structure.n_residues, "layout": layout(window)}
    window.quit_unattended(discard=True)
    return 0

def sketched(self, event):
    paint(self, event)
    if self.trace is not None:
        seen.setdefault("sketch", {"residues": sum(len(run.positions) for run in self.trace.runs),
                                   "furnished": self.window().furnished,
                                   "loaded": sorted(name for name in sys.argv[2:] if name in sys.modules)})

paint = sketch.Sketch.paintEvent
sketch.Sketch.paintEvent, busy.opening, QApplication.exec = sketched, watched, run
seen["status"] = main([sys.argv[1]])
print(json.dumps(seen))
"""
"""A fresh ``ribbonwave FILE`` that tells what its window showed, and which of the modules named
after FILE were loaded, when it was first painted, and once the structure was read."""
HEAVY = ("app.editor.window_parts", "app.editor.document", "numpy", "scipy", "gemmi", "vtkmodules", "pyvista",
         "matplotlib")


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


def test_the_window_is_painted_before_the_editor_loads(tmp_path: Path) -> None:
    """In a fresh process the window is on screen, painted with its menus, its docks and the file's
    name, before numpy, scipy, gemmi, VTK, PyVista or the editor's own parts are imported: it
    needs Qt alone. Then the molecule is sketched, with gemmi alone more. The rest loads while it
    shows, and the structure follows in 3D. The docks keep their
    places as their panels come (the view, not the docks, takes the room), this run and the next,
    which starts from the layout this one kept."""
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path), "XDG_CONFIG_HOME": str(tmp_path)}
    layouts = []
    for _ in range(2):
        result = subprocess.run([sys.executable, "-c", FIRST_PAINT, str(DATA / "1UBQ.pdb.gz"), *HEAVY], cwd=ROOT,
                                env=env, capture_output=True, text=True, timeout=120, check=False)
        assert result.returncode == 0, result.stderr[-2000:]
        seen = json.loads(result.stdout.strip().splitlines()[-1])
        window = seen["window"]
        assert window["visible"] and window["title"] == "1UBQ.pdb.gz — ribbonwave" and window["loaded"] == []
        assert window["menus"] == ["&File", "&Edit", "&View", "&Help"]
        assert {"Ribbon dimension", "Display", "Sequence"} <= set(window["docks"])
        assert seen["sketch"] == {"residues": 76, "furnished": False, "loaded": ["gemmi"]}  # before numpy, VTK, ...
        assert seen["status"] == 0 and seen["then"]["loaded"] == sorted(HEAVY) and seen["then"]["residues"] > 70
        (column, sequence, _, _), (then_column, then_sequence, view_width, view_height) = (
            window["layout"], seen["then"]["layout"])
        assert abs(then_column - column) <= 8 and sequence <= then_sequence <= 100
        assert view_width > 1.5 * then_column and view_height > 600
        layouts.append(seen["then"]["layout"])
    assert layouts[1] == layouts[0]


def test_closing_the_window_while_the_editor_loads_ends_quietly(qtbot: QtBot, monkeypatch: pytest.MonkeyPatch) -> None:
    """Closed before the structure is read (the person changed their mind): exit status 0, the
    file never read, no dialog, nothing left open."""
    wait, read = launch._meanwhile, []

    def closed_meanwhile(work: object) -> object:
        for window in QApplication.topLevelWidgets():
            if hasattr(window, "menus") and window.isVisible():
                assert not window.furnished
                window.close()  # as the window's close button does while the editor loads
        return wait(work)

    monkeypatch.setattr(launch, "_meanwhile", closed_meanwhile)
    monkeypatch.setattr(Document, "open", lambda *args, **kwargs: read.append(args))
    assert main([str(DATA / "1UBQ.pdb.gz")]) == 0
    assert read == [] and not any(window.isVisible() for window in QApplication.topLevelWidgets())
