"""End to end: a real Qt event sent to a real editor window, timed until its frame is drawn.

Usage: ``xvfb-run -a python benchmarks/bench_interaction.py [--steps N] [--views KIND ...] [--shown REP ...]
[--assembly N] [STRUCTURE ...]`` (default: 1UBQ, 1AYE, 4YVS from tests/data, each in both 3D views: VTK's native window and
pyvistaqt's OpenGL widget, and with the cartoon or the tube shown, side by side). Each event goes through Qt as the mouse or the
keyboard sends it (QTest), and the clock stops once the event loop has nothing left to do,
the render included; a counter on the render window says how many frames each event drew,
and, in the OpenGL widget, one on the view how many times the window was composed (with
that widget in it, every event-loop turn that repaints a widget composes the whole window).

Events: a level-slider step (the Right key on the slider), a pick (a click on a control
point), a drag step (a mouse move while a control point is held), a release (regularized,
as by default), a camera rotation step (a mouse move while the left button turns the view)
and a zoom step (one wheel notch). While something moves the scene draws less detail; after
each rotation step the same view is drawn at rest, in full detail ("at rest"), and the ratio
of the render times says how much cheaper the frames in motion are. Medians and 90th
percentiles in ms; "render ms" is the time in VTK's render, the rest is Python and Qt.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PySide6.QtCore import QPoint, QPointF, QSettings, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.scene.layers.base import Layer

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
DEFAULT = ("1UBQ.pdb.gz", "1AYE.pdb.gz", "4YVS.cif.gz")
SHOWN = {"cartoon": Layer.CARTOON, "tube": Layer.TUBE}
"""The ribbon shown (the other hidden) in a run."""


class Frames:
    """Counts the frames the render window draws, the time spent drawing them, and the
    window's compositions."""

    def __init__(self, window: MainWindow) -> None:
        self.count = 0
        self.seconds = 0.0
        self.compositions = 0
        self._started = 0.0
        if hasattr(type(window.plotter), "aboutToCompose"):  # the OpenGL widget
            window.plotter.aboutToCompose.connect(self._composed)
        window.plotter.ren_win.AddObserver("StartEvent", lambda *_: self._start())
        window.plotter.ren_win.AddObserver("EndEvent", lambda *_: self._drawn())

    def _start(self) -> None:
        self._started = time.perf_counter()

    def _drawn(self) -> None:
        self.count += 1
        self.seconds += time.perf_counter() - self._started

    def _composed(self) -> None:
        self.compositions += 1


def _settle(app: QApplication) -> None:
    """Run the event loop until nothing is left (deferred renders and checks included)."""
    for _ in range(3):
        app.processEvents()


def _widget_point(window: MainWindow, point: np.ndarray) -> QPoint:
    renderer = window.plotter.renderer
    renderer.SetWorldPoint(*point, 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    scale = window.plotter.devicePixelRatioF()
    return QPoint(round(x / scale), round(window.plotter.height() - 1 - y / scale))


def _timed(app: QApplication, frames: Frames, send) -> tuple[float, float, int, int]:  # noqa: ANN001 (a callable)
    """Milliseconds from ``send()`` to an idle event loop, of them rendering, the frames drawn
    and the window's compositions."""
    before, drawing, composed = frames.count, frames.seconds, frames.compositions
    start = time.perf_counter()
    send()
    _settle(app)
    return (1e3 * (time.perf_counter() - start), 1e3 * (frames.seconds - drawing), frames.count - before,
            frames.compositions - composed)


def measure(app: QApplication, path: Path, steps: int, view_kind: str, shown: str, assembly: int | None = None
            ) -> dict[str, list[tuple[float, float, int, int]]]:
    """Times and frame counts of every kind of event on the structure at ``path`` (its biological
    ``assembly`` if given), in the 3D view ``view_kind``, with the ribbon ``shown`` (:data:`SHOWN`)."""
    os.environ["RIBBONWAVE_VIEW"] = view_kind
    document = Document()
    document.open(path, assembly=assembly)
    window = MainWindow(document)
    window.resize(1400, 900)
    window.show()
    QTest.qWaitForWindowExposed(window)
    for name, layer in SHOWN.items():
        window.scene.set_layer(layer, name == shown)
    _settle(app)
    frames = Frames(window)
    view = window.plotter
    results: dict[str, list[tuple[float, float, int, int]]] = {}

    def record(kind: str, sample: tuple[float, float, int, int]) -> None:
        results.setdefault(kind, []).append(sample)

    slider = window.dimension_panel.slider
    slider.setFocus()
    for k in range(steps):
        key = Qt.Key.Key_Right if k % 2 == 0 else Qt.Key.Key_Left
        record("slider step", _timed(app, frames, lambda key=key: QTest.keyClick(slider, key)))

    for k in range(steps):
        shown = window.scene.shown_control_points()
        index = int(shown[(3 + k) % len(shown)])
        at = _widget_point(window, document.level_curve().control_points[index])
        record("pick", _timed(app, frames, lambda at=at: (QTest.mousePress(view, Qt.MouseButton.LeftButton, pos=at),
                                                           QTest.mouseRelease(view, Qt.MouseButton.LeftButton, pos=at))))
        QTest.mousePress(view, Qt.MouseButton.LeftButton, pos=at)
        for m in range(1, 6):
            record("drag step", _timed(app, frames, lambda m=m, at=at: QTest.mouseMove(view, at + QPoint(4 * m, 3 * m))))
        record("release", _timed(app, frames, lambda at=at: QTest.mouseRelease(
            view, Qt.MouseButton.LeftButton, pos=at + QPoint(20, 15))))
        document.undo_stack.undo()
        _settle(app)

    corner = QPoint(12, view.height() - 12)  # nothing there: the press turns the camera
    QTest.mousePress(view, Qt.MouseButton.LeftButton, pos=corner)
    for m in range(1, steps + 1):
        record("rotate step", _timed(app, frames, lambda m=m: QTest.mouseMove(view, corner + QPoint(3 * m, -2 * m))))
        record("at rest", _timed(app, frames, window.scene.still))  # the same view in full detail
    QTest.mouseRelease(view, Qt.MouseButton.LeftButton, pos=corner + QPoint(3 * steps, -2 * steps))
    _settle(app)

    centre = QPointF(view.width() / 2, view.height() / 2)
    for m in range(steps):
        delta = 120 if m % 2 == 0 else -120

        def wheel(delta: int = delta) -> None:
            event = QWheelEvent(centre, view.mapToGlobal(centre), QPoint(), QPoint(0, delta), Qt.MouseButton.NoButton,
                                Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
            QApplication.sendEvent(view, event)

        record("zoom step", _timed(app, frames, wheel))
    window.quit_unattended(discard=True)
    _settle(app)
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("structures", nargs="*", default=list(DEFAULT))
    parser.add_argument("--steps", type=int, default=20)
    parser.add_argument("--views", nargs="+", choices=("native", "widget"), default=["native", "widget"])
    parser.add_argument("--shown", nargs="+", choices=tuple(SHOWN), default=list(SHOWN))
    parser.add_argument("--assembly", type=int, help="open each structure's biological assembly N (e.g. 1)")
    args = parser.parse_args()
    app = QApplication.instance() or QApplication(sys.argv[:1])
    QSettings.setPath(QSettings.Format.NativeFormat, QSettings.Scope.UserScope, tempfile.mkdtemp())  # not the user's
    print(f"{'structure':<12} {'view':<7} {'shown':<8} {'event':<12} {'median ms':>10} {'p90 ms':>8} {'render ms':>10} "
          f"{'frames/event':>13} {'compositions/event':>19}")
    for name in args.structures:
        path = Path(name) if Path(name).exists() else DATA / name
        entry = path.name.split('.')[0] + ("" if args.assembly is None else f"-a{args.assembly}")
        for view_kind in args.views:
            for shown in args.shown:
                results = measure(app, path, args.steps, view_kind, shown, args.assembly)
                for kind, samples in results.items():
                    times, drawing, counts, compositions = np.array(samples).T
                    composed = f"{np.mean(compositions):.2f}" if view_kind == "widget" else "-"
                    print(f"{entry:<12} {view_kind:<7} {shown:<8} {kind:<12} {np.median(times):>10.1f} "
                          f"{np.percentile(times, 90):>8.1f} {np.median(drawing):>10.1f} {np.mean(counts):>13.2f} "
                          f"{composed:>19}")
                moving, rest = (np.median(np.array(results[kind])[:, 1]) for kind in ("rotate step", "at rest"))
                print(f"{entry:<12} {view_kind:<7} {shown:<8} frames in motion {rest / moving:.1f}x cheaper than at "
                      "rest")


if __name__ == "__main__":
    main()
