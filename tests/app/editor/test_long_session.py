"""Long sessions do not crash: PySide6 6.12.0 aborted (``bool_dealloc``/``none_dealloc``) after a
few hundred emits of a signal without arguments, a few minutes into an editing session."""

import subprocess
import sys
from pathlib import Path

import numpy as np
from pytestqt.qtbot import QtBot
from test_window import _display, _window

from app.editor.main_window import MainWindow

DATA = Path(__file__).resolve().parents[2] / "data"
EMITS = """
from PySide6.QtCore import QObject, Signal
class A(QObject): s = Signal()
a = A(); [a.s.emit() for _ in range(200_000)]
print("ok")
"""


def test_argumentless_signals_survive_200000_emits() -> None:
    """The two lines that showed the fault, in the installed environment (a child process:
    the fault aborts the interpreter)."""
    result = subprocess.run([sys.executable, "-c", EMITS], capture_output=True, text=True, check=False, timeout=300)
    assert (result.returncode, result.stdout.strip()) == (0, "ok"), result.stderr[-2000:]


def test_5000_slider_and_drag_steps_with_undo(qtbot: QtBot) -> None:
    """2,500 slider moves and 2,500 drag previews (250 drags of 10 moves, each undone) in a
    real window: every step emits the document's signals and renders."""
    window: MainWindow = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.resize(700, 450)  # a smaller frame renders faster; the code paths are the same
    qtbot.wait(10)
    document, slider = window.document, window.dimension_panel.slider
    original = document.model.coords.copy()
    low, high = slider.minimum(), slider.maximum()
    steps = 0
    for k in range(2500):
        slider.setValue(low + (k * 37) % (high - low + 1))  # as a drag of the slider handle does
        steps += 1
    slider.setValue(round(0.6 * high))
    interactor = window.plotter.iren.interactor
    for drag in range(250):
        shown = window.scene.shown_control_points()
        start = _display(window, document.level_curve().control_points[shown[drag % len(shown)]])
        interactor.SetEventInformation(*start)
        interactor.InvokeEvent("LeftButtonPressEvent")
        for k in range(1, 11):
            interactor.SetEventInformation(start[0] + 3 * k, start[1] + 2 * k)
            interactor.InvokeEvent("MouseMoveEvent")
            steps += 1
        document.set_regularization(on_release=drag % 25 == 0)  # some releases regularize, as by default
        interactor.InvokeEvent("LeftButtonReleaseEvent")
        assert document.undo_stack.count() == 1 and not np.array_equal(document.model.coords, original)
        window.editing.undo_action.trigger()
        assert np.array_equal(document.model.coords, original)
    assert steps == 5000
