"""The Ramachandran dock on real entries: what it plots against phi_psi and validate, what it
rings after edits and picks, how often it redraws, clicks and hovering through the canvas,
and that the editor loads matplotlib's Qt canvas only once the dock comes on screen."""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba_array
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QDockWidget
from pytestqt.qtbot import QtBot
from test_window import _display, _mouse_drag, _window

from app.editor.docks import ramachandran
from app.editor.docks.ramachandran import (
    HINT,
    MOVED_COLOUR,
    OUTLIER_COLOUR,
    PICK_PIXELS,
    POINT_COLOUR,
    REDRAW_INTERVAL_MS,
    REGION_COLOURS,
    RamachandranPanel,
)
from app.editor.document import Document
from app.editor.live_validation import LiveValidation
from core.geometry.ramachandran import OUTLIER, RAMACHANDRAN, ramachandran_region
from core.geometry.validation import phi_psi, validate

DATA = Path(__file__).resolve().parents[2] / "data"
ROOT = Path(__file__).resolve().parents[3]


def _panel(qtbot: QtBot, document: Document) -> RamachandranPanel:
    panel = RamachandranPanel(document, LiveValidation(document))
    qtbot.addWidget(panel)
    panel.resize(380, 520)
    panel.show()
    qtbot.waitExposed(panel)
    qtbot.waitUntil(lambda: panel.redraws == 1)
    return panel


@pytest.fixture
def panel(qtbot: QtBot, ubiquitin: Document) -> RamachandranPanel:
    return _panel(qtbot, ubiquitin)


@pytest.fixture
def triosephosphate(qtbot: QtBot) -> RamachandranPanel:
    """1TIM, second chain: 247 residues, outliers, glycines and prolines, rows from 247 on."""
    document = Document()
    document.open(DATA / "1TIM.pdb.gz")
    panel = _panel(qtbot, document)
    document.set_segment(1)
    qtbot.waitUntil(lambda: panel.redraws == 2)
    return panel


def _offsets(collection) -> np.ndarray:
    return np.asarray(collection.get_offsets()).reshape(-1, 2)


def _classes(resname: np.ndarray) -> np.ndarray:
    return np.select([resname == "GLY", resname == "PRO"], [1, 2], 0)


def _rows_at(panel: RamachandranPanel, xy: np.ndarray) -> set[int]:
    """Residue-table rows of the plotted points at (φ, ψ) ``xy``."""
    points = panel.points
    plotted = np.column_stack([points.phi, points.psi])
    return {int(points.rows[np.flatnonzero(np.all(plotted == p, axis=1))[0]]) for p in xy}


def _moved_residues(document: Document) -> set[int]:
    """Rows of the current segment's residues with an atom not where the file put it."""
    segment = document.structure.segments[document.segment]
    now, read = document.model.coords, document.structure.coords
    return {int(segment.residue_index[i]) for i in range(len(segment))
            if not np.array_equal(now[segment.atoms(i)], read[segment.atoms(i)])}


def _widget_position(panel: RamachandranPanel, phi: float, psi: float) -> QPoint:
    """Where on the canvas (Qt coordinates) the point (φ, ψ) is drawn."""
    canvas = panel.canvas
    x, y = panel.axes.transData.transform((phi, psi))
    ratio = canvas.device_pixel_ratio
    return QPoint(round(x / ratio), round((canvas.figure.bbox.height - y) / ratio))


def _isolated_point(panel: RamachandranPanel) -> int:
    """Index of the plotted point farthest from its nearest neighbour (in pixels)."""
    points = panel.points
    xy = panel.axes.transData.transform(np.column_stack([points.phi, points.psi]))
    distance = np.linalg.norm(xy[:, None] - xy[None], axis=2)
    np.fill_diagonal(distance, np.inf)
    k = int(np.argmax(distance.min(axis=1)))
    assert distance[k].min() > 5 * PICK_PIXELS * panel.canvas.device_pixel_ratio
    return k


def test_points_are_the_segments_phi_psi_judged_by_their_own_class(triosephosphate: RamachandranPanel) -> None:
    panel = triosephosphate
    document = panel.document
    structure, segment = document.structure, document.structure.segments[1]
    phi, psi = phi_psi(structure, document.model.coords)
    rows = segment.residue_index[np.isfinite(phi[segment.residue_index]) & np.isfinite(psi[segment.residue_index])]
    assert rows[0] == 248 and len(rows) == 245  # the second chain, without its ends
    np.testing.assert_array_equal(panel.points.rows, rows)
    np.testing.assert_array_equal(panel.points.phi, phi[rows])
    np.testing.assert_array_equal(panel.points.psi, psi[rows])
    assert panel.points.labels == tuple(segment.labels[i] for i in rows - segment.residue_index[0])

    kind = _classes(segment.resname[rows - segment.residue_index[0]])
    outlier = ramachandran_region(phi[rows], psi[rows], kind) == OUTLIER
    as_general = ramachandran_region(phi[rows], psi[rows], 0) == OUTLIER
    assert outlier.sum() > 5 and np.any(as_general & ~outlier)  # glycines a general residue's map would flag
    for k, collection in enumerate(panel.scatters):
        mine = kind == k
        assert mine.sum() > 3
        np.testing.assert_array_equal(_offsets(collection), np.column_stack([phi[rows[mine]], psi[rows[mine]]]))
        expected = to_rgba_array([POINT_COLOUR, OUTLIER_COLOUR])[outlier[mine].astype(int)]
        np.testing.assert_array_equal(collection.get_facecolors(), expected)
    flagged = {f.residues[0] for f in validate(structure, document.model.coords).flags if f.kind == "ramachandran"}
    assert set(rows[outlier].tolist()) == flagged & set(segment.residue_index.tolist())  # the validation's outliers
    assert panel.counts.text() == f"245 residues, {outlier.sum()} outliers, 0 moved"
    assert len(_offsets(panel.moved_rings)) == len(_offsets(panel.picked_rings)) == 0


def test_an_edit_rings_the_moved_residues_during_and_after_the_drag(panel: RamachandranPanel, qtbot: QtBot) -> None:
    document = panel.document
    document.set_level(document.max_level)
    document.pick_point(60)
    qtbot.waitUntil(lambda: len(_offsets(panel.picked_rings)) > 0)
    document.preview_move(60, np.array([2.5, -1.5, 1.0]))
    qtbot.waitUntil(lambda: len(_offsets(panel.moved_rings)) > 0)  # validation.updated, then a redraw
    assert _rows_at(panel, _offsets(panel.moved_rings)) == _moved_residues(document)
    document.finish_drag("Move point 60")  # regularized: more residues move
    moved = _moved_residues(document)
    assert 4 < len(moved) < 30 and max(moved) < 75  # none at the ends, which have no point
    qtbot.waitUntil(lambda: _rows_at(panel, _offsets(panel.moved_rings)) == moved)
    phi, psi = phi_psi(document.structure, document.model.coords)
    np.testing.assert_array_equal(panel.points.phi, phi[panel.points.rows])  # the new angles
    np.testing.assert_array_equal(panel.points.psi, psi[panel.points.rows])
    assert panel.counts.text().endswith(f", {len(moved)} moved")
    document.undo_stack.undo()
    qtbot.waitUntil(lambda: len(_offsets(panel.moved_rings)) == 0)
    assert panel.counts.text().endswith(", 0 moved")


def test_picking_rings_the_picks_residues(panel: RamachandranPanel, qtbot: QtBot) -> None:
    document = panel.document
    document.pick_point(3)
    qtbot.waitUntil(lambda: len(_offsets(panel.picked_rings)) > 0)
    picked = set(document.structure.segments[0].residue_index[document.pick.residues].tolist())
    assert len(picked) > 4
    assert _rows_at(panel, _offsets(panel.picked_rings)) == picked & set(panel.points.rows.tolist())
    document.pick_point(None)
    qtbot.waitUntil(lambda: len(_offsets(panel.picked_rings)) == 0)


def test_redraws_are_at_most_ten_a_second(
    panel: RamachandranPanel, qtbot: QtBot, monkeypatch: pytest.MonkeyPatch
) -> None:
    times, original = [], ramachandran.segment_points

    def timed(document: Document) -> ramachandran.Points:
        times.append(time.perf_counter())
        return original(document)

    monkeypatch.setattr(ramachandran, "segment_points", timed)
    document = panel.document
    qtbot.wait(REDRAW_INTERVAL_MS + 20)
    before = panel.redraws
    for k in range(40):  # 40 refreshes, no event loop turn between them
        document.pick_point(3 + k % 10)
    assert panel.redraws == before + 1  # the first at once: the last redraw is old enough
    qtbot.waitUntil(lambda: panel.redraws == before + 2)  # then one for the rest
    qtbot.wait(3 * REDRAW_INTERVAL_MS)
    assert panel.redraws == before + 2
    assert len(times) == 2 and times[1] - times[0] >= REDRAW_INTERVAL_MS / 1e3 - 1e-3  # 1 ms: timing jitter
    picked = set(document.structure.segments[0].residue_index[document.pick.residues].tolist())
    assert _rows_at(panel, _offsets(panel.picked_rings)) == picked & set(panel.points.rows.tolist())  # the last


def test_a_hidden_panel_redraws_once_shown(panel: RamachandranPanel, qtbot: QtBot) -> None:
    document = panel.document
    panel.hide()
    before = panel.redraws
    for k in (5, 7, 9):
        document.pick_point(k)
    qtbot.wait(2 * REDRAW_INTERVAL_MS)
    assert panel.redraws == before and len(_offsets(panel.picked_rings)) == 0
    panel.show()
    qtbot.waitUntil(lambda: panel.redraws == before + 1)
    assert len(_offsets(panel.picked_rings)) > 0
    qtbot.wait(2 * REDRAW_INTERVAL_MS)
    assert panel.redraws == before + 1


def test_an_empty_document_then_a_loaded_one(qtbot: QtBot) -> None:
    document = Document()
    panel = _panel(qtbot, document)
    assert panel.points is None and panel.counts.text() == "no structure"
    document.open(DATA / "1UBQ.pdb.gz")
    qtbot.waitUntil(lambda: panel.points is not None)
    assert len(panel.points.rows) == 74 and panel.counts.text() == "74 residues, 0 outliers, 0 moved"
    document.open(DATA / "2K39_CA-only.pdb.gz")  # no N or C: no φ, no ψ
    qtbot.waitUntil(lambda: panel.counts.text() == "0 residues, 0 outliers, 0 moved")
    assert all(len(_offsets(c)) == 0 for c in (*panel.scatters, panel.moved_rings, panel.picked_rings))


def test_clicking_a_point_activates_its_residue(triosephosphate: RamachandranPanel, qtbot: QtBot) -> None:
    panel = triosephosphate
    k = _isolated_point(panel)
    phi, psi = panel.points.phi[k], panel.points.psi[k]
    all_phi, all_psi = phi_psi(panel.document.structure, panel.document.model.coords)
    row = int(np.flatnonzero((all_phi == phi) & (all_psi == psi))[0])
    assert row >= 247  # a row of the residue table, not an index within the segment
    position = _widget_position(panel, phi, psi)
    with qtbot.waitSignal(panel.residueActivated, timeout=1000) as signal:
        qtbot.mouseClick(panel.canvas, Qt.MouseButton.LeftButton, pos=position + QPoint(2, -1))
    assert signal.args == [row]
    with qtbot.assertNotEmitted(panel.residueActivated, wait=50):
        qtbot.mouseClick(panel.canvas, Qt.MouseButton.RightButton, pos=position)
        qtbot.mouseClick(panel.canvas, Qt.MouseButton.LeftButton, pos=position + QPoint(3 * PICK_PIXELS, 0))


def test_pointing_at_a_point_names_it(triosephosphate: RamachandranPanel, qtbot: QtBot) -> None:
    panel = triosephosphate
    k = _isolated_point(panel)
    points = panel.points
    position = _widget_position(panel, points.phi[k], points.psi[k])
    qtbot.mouseMove(panel.canvas, position)
    expected = f"{points.labels[k]}  φ {points.phi[k]:.0f}°, ψ {points.psi[k]:.0f}°"
    qtbot.waitUntil(lambda: panel.hover.text().startswith(expected))
    assert panel.canvas.toolTip() == panel.hover.text()
    assert panel.hover.text().endswith("(outlier)") == bool(points.outlier[k])
    qtbot.mouseMove(panel.canvas, position + QPoint(3 * PICK_PIXELS, 0))
    qtbot.waitUntil(lambda: panel.hover.text() == HINT)
    assert panel.canvas.toolTip() == ""


def test_the_background_shows_the_chosen_class_regions(panel: RamachandranPanel) -> None:
    canvas = panel.canvas
    colours = to_rgba_array(REGION_COLOURS)
    spots = {"glycine only": (90.0, -170.0), "empty": (10.0, -90.0)}  # centres of 20° cells
    xy = panel.axes.transData.transform(np.column_stack([panel.points.phi, panel.points.psi]))

    def pixel(spot: str) -> np.ndarray:
        """The colour drawn at ``spot``, where no residue lies."""
        x, y = panel.axes.transData.transform(spots[spot])
        assert np.min(np.hypot(*(xy - (x, y)).T)) > 12 * canvas.device_pixel_ratio
        canvas.draw()
        image = np.asarray(canvas.buffer_rgba())
        return image[round(canvas.figure.bbox.height - y), round(x)] / 255.0

    np.testing.assert_allclose(pixel("glycine only"), colours[2], atol=0.01)  # general: an outlier's white
    np.testing.assert_allclose(pixel("empty"), colours[2], atol=0.01)
    np.testing.assert_array_equal(panel.axes.images[0].get_array(), colours[RAMACHANDRAN[0]])
    panel.regions.setCurrentIndex(1)  # glycine
    np.testing.assert_array_equal(panel.axes.images[0].get_array(), colours[RAMACHANDRAN[1]])
    np.testing.assert_allclose(pixel("glycine only"), colours[0], atol=0.01)
    np.testing.assert_allclose(pixel("empty"), colours[2], atol=0.01)
    assert [t.get_text() for t in panel.axes.get_xticklabels()] == ["−180", "−120", "−60", "0", "60", "120", "180"]
    assert panel.axes.get_xlabel() == "φ (°)" and panel.axes.get_ylabel() == "ψ (°)"
    assert panel.moved_rings.get_edgecolors()[0].tolist() == to_rgba_array(MOVED_COLOUR)[0].tolist()


def test_the_dock_in_the_window_follows_a_drag_once_raised(qtbot: QtBot) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    panel = window.ramachandran_panel
    dock = window.findChild(QDockWidget, "Ramachandran")
    validation = window.findChild(QDockWidget, "Validation")
    assert dock in window.tabifiedDockWidgets(validation)
    assert dock.toggleViewAction() in window.menuBar().actions()[2].menu().actions()  # View
    assert not panel.on_screen() and panel.canvas is None and panel.redraws == 0  # behind the Validation tab
    shown = window.scene.shown_control_points()
    start = _display(window, window.document.level_curve().control_points[int(shown[len(shown) // 2])])
    _mouse_drag(window, start, (40, 25))
    assert window.document.undo_stack.count() == 1
    qtbot.wait(2 * REDRAW_INTERVAL_MS)
    assert panel.redraws == 0
    dock.raise_()
    qtbot.waitUntil(lambda: panel.redraws == 1)
    moved = _moved_residues(window.document)
    assert moved and _rows_at(panel, _offsets(panel.moved_rings)) == moved & set(panel.points.rows.tolist())
    validation.raise_()
    qtbot.waitUntil(lambda: not panel.on_screen())
    window.editing.undo_action.trigger()
    qtbot.wait(2 * REDRAW_INTERVAL_MS)
    assert panel.redraws == 1 and len(_offsets(panel.moved_rings)) > 0  # off screen: not redrawn
    dock.raise_()
    qtbot.waitUntil(lambda: panel.redraws == 2)
    assert len(_offsets(panel.moved_rings)) == 0


LAZY = """
import json, sys, time
from pathlib import Path
from PySide6.QtWidgets import QApplication, QDockWidget
app = QApplication([])
from app.editor.docks.ramachandran import RamachandranPanel
from app.editor.document import Document
from app.editor.live_validation import LiveValidation
document = Document()
document.open(Path(sys.argv[1]))
RamachandranPanel(document, LiveValidation(document))
alone = sorted(name for name in sys.modules if name.startswith("matplotlib"))
from app.editor.main_window import MainWindow
window = MainWindow(document)
window.show()
panel = window.ramachandran_panel

def settle(done, seconds):
    deadline = time.monotonic() + seconds
    while not done() and time.monotonic() < deadline:
        app.processEvents()
        time.sleep(0.01)

settle(lambda: False, 1.0)
canvas = "matplotlib.backends.backend_qtagg" in sys.modules
shown = panel.isVisible(), panel.on_screen(), panel.canvas is not None
window.findChild(QDockWidget, "Ramachandran").raise_()
settle(lambda: panel.redraws > 0, 10.0)
raised = "matplotlib.backends.backend_qtagg" in sys.modules, panel.canvas is not None, panel.redraws
window.quit_unattended(discard=True)
print(json.dumps({"alone": alone, "canvas": canvas, "shown": shown, "raised": raised}))
"""


def test_the_editor_loads_the_matplotlib_canvas_only_once_the_dock_is_on_screen(tmp_path: Path) -> None:
    """pyvista itself imports matplotlib (its colours): the dock defers the Qt canvas, the
    figure and everything else; on its own it loads no matplotlib at all."""
    env = {**os.environ, "XDG_CONFIG_HOME": str(tmp_path / "config"), "XDG_STATE_HOME": str(tmp_path / "state")}
    result = subprocess.run([sys.executable, "-c", LAZY, str(DATA / "1UBQ.pdb.gz")], cwd=ROOT, env=env,
                            capture_output=True, text=True, check=False, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    found = json.loads(result.stdout.splitlines()[-1])
    assert found["alone"] == []
    assert found["canvas"] is False
    assert found["shown"] == [True, False, False]  # "visible" behind the Validation tab, yet off screen
    assert found["raised"] == [True, True, 1]
