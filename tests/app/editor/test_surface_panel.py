"""The surface panel in a real window under Xvfb: surfaces built in a process of their own from
the panel, their stages shown, stopped at once when another kind or file is chosen or the window
closes; levels and colourings shown in place, stale after edits, failures reported."""

import multiprocessing
import signal
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import pyvista as pv
from pytestqt.qtbot import QtBot

from app.editor.commands import EditCommand
from app.editor.docks.surfaces import COLOURING_NAMES, STEPS_PER_LEVEL, SurfacePanel
from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.scene.scene import Layer
from app.editor.surfaces.layer import KIND_NAMES
from core.surfaces.levelled import KINDS
from core.surfaces.molecular import COLOURINGS

DATA = Path(__file__).resolve().parents[2] / "data"
BUILD_TIMEOUT_MS = 120_000
GLOBE_FACES = 2 * 64 * 61 + 2 * 64
"""A 64 × 64 net with the pole rows collapsed: 61 bands of quads and two fans of 64."""
GLOBE_VERTICES = 62 * 64 + 2


def _window(qtbot: QtBot, document: Document) -> MainWindow:
    window = MainWindow(document)
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    return window


def _show(qtbot: QtBot, panel: SurfacePanel, kind: str) -> None:
    """Choose ``kind`` in the panel, tick "Show surface" and wait for the build."""
    panel.kind.setCurrentIndex(list(KIND_NAMES).index(kind))
    panel.show_box.setChecked(True)
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)


def _actor_mesh(window: MainWindow) -> pv.PolyData:
    return window.plotter.actors["surface"].mapper.dataset


def _view(window: MainWindow) -> np.ndarray:
    window.plotter.render()
    return np.asarray(window.plotter.screenshot(return_img=True), dtype=int)


def test_the_panel_offers_every_kind_and_colouring_of_the_surface_code(qtbot: QtBot, ubiquitin: Document) -> None:
    """The panel names the kinds and colourings itself (the surface code loads with the first
    surface): the same ones, and it refuses others."""
    assert set(KIND_NAMES) == set(KINDS)
    assert set(COLOURING_NAMES) == {None, *COLOURINGS}
    window = _window(qtbot, ubiquitin)
    with pytest.raises(ValueError, match="kind must be one of"):
        window.surface_layer.set_kind("cartoon")
    assert window.surface_layer.kind == "globe"


def test_globe_levels_colourings_and_screenshot(qtbot: QtBot, ubiquitin: Document, tmp_path: Path) -> None:
    window = _window(qtbot, ubiquitin)
    panel = window.surface_panel
    assert "surface" not in window.plotter.actors
    panel.kind.setCurrentIndex(list(KIND_NAMES).index("globe"))
    panel.show_box.setChecked(True)
    assert panel.layer.busy and panel.figures.text() == "Building the globe: starting…"  # in another process
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    assert "Building" not in panel.figures.text()
    surface = panel.layer.built.surface
    assert surface.kind == "globe" and surface.max_level == 5
    assert panel.slider.maximum() == 5 * STEPS_PER_LEVEL and panel.slider.value() == 5 * STEPS_PER_LEVEL

    mesh = _actor_mesh(window)
    points_array = mesh.GetPoints().GetData()
    shapes = {}
    for level in (5, 4, 3):
        panel.slider.setValue(level * STEPS_PER_LEVEL)
        assert _actor_mesh(window) is mesh and mesh.GetPoints().GetData() is points_array  # in place
        assert (mesh.n_cells, mesh.n_points) == (GLOBE_FACES, GLOBE_VERTICES)
        np.testing.assert_array_equal(mesh.points, surface.view(level)[0].vertices)
        shapes[level] = np.array(mesh.points)
        assert f"{dict(surface.errors)[level]:.3f}" in panel.figures.text()
    assert np.abs(shapes[5] - shapes[3]).max() > 2.0  # level 3 is a smoother globe
    errors = dict(surface.errors)
    assert errors[3] > errors[4] > errors[5]
    panel.slider.setValue(350)
    assert panel.layer.shown_level() == 3.5 and not np.array_equal(mesh.points, shapes[3])

    panel.slider.setValue(3 * STEPS_PER_LEVEL)
    window.scene.set_layer(Layer.CONTROL_POINTS, False)  # their purple would count as blue
    images = {}
    for colouring in COLOURING_NAMES:
        panel.colouring.setCurrentIndex(list(COLOURING_NAMES).index(colouring))
        images[colouring] = _view(window)
    plain, potential = images[None], images["potential"]
    assert np.mean(np.any(plain != potential, axis=2)) > 0.05
    assert np.mean(np.any(images["curvature"] != potential, axis=2)) > 0.05
    assert np.mean(np.any(images["bfactor"] != potential, axis=2)) > 0.05
    red = potential[..., 0] - potential[..., 2] > 60
    blue = potential[..., 2] - potential[..., 0] > 60
    assert blue.sum() > 10 * (images[None][..., 2] - images[None][..., 0] > 60).sum()
    assert red.sum() > 500 and blue.sum() > 500  # negative and positive patches of ubiquitin
    assert "kcal/(mol·e)" not in panel.figures.text()  # the B-factor colouring is last
    assert "Å²" in panel.figures.text()

    panel.colouring.setCurrentIndex(list(COLOURING_NAMES).index("potential"))
    panel.opacity.setValue(100)
    assert window.plotter.actors["surface"].prop.opacity == 1.0
    opaque = _view(window)
    assert np.mean(np.any(opaque != potential, axis=2)) > 0.02  # the ribbon no longer shows through
    panel.opacity.setValue(60)
    panel.parentWidget().raise_()  # the dock's tab
    shot = tmp_path / "surface.png"
    window.export.save_screenshot(shot)
    assert shot.stat().st_size > 50_000

    panel.show_box.setChecked(False)
    assert not window.plotter.actors["surface"].GetVisibility()
    panel.show_box.setChecked(True)  # cached: no new build
    assert not panel.layer.busy and window.plotter.actors["surface"].GetVisibility()


def test_ses_and_remesh_from_the_panel(qtbot: QtBot, ubiquitin: Document) -> None:
    window = _window(qtbot, ubiquitin)
    panel = window.surface_panel
    _show(qtbot, panel, "ses")
    mesh = _actor_mesh(window)
    assert panel.layer.built.surface.max_level == 0 and not panel.slider.isEnabled()
    assert mesh.n_open_edges == 0 and mesh.n_cells > 20_000
    assert abs(mesh.area - 3700) < 500  # Å², ubiquitin's solvent-excluded surface
    assert f"{mesh.n_cells} triangles" in panel.figures.text()

    _show(qtbot, panel, "remesh")
    assert _actor_mesh(window) is mesh  # other triangles under the same actor
    for level in (5, 4, 3):
        panel.slider.setValue(level)
        assert mesh.n_cells == 6 * 4**level
    ses = panel.layer._cache["ses"]
    panel.kind.setCurrentIndex(list(KIND_NAMES).index("ses"))  # cached: shown at once
    assert not panel.layer.busy and panel.layer.built is ses and mesh.n_cells > 20_000


def test_edits_make_the_surface_stale_until_recomputed(qtbot: QtBot, ubiquitin: Document) -> None:
    window = _window(qtbot, ubiquitin)
    panel = window.surface_panel
    _show(qtbot, panel, "globe")
    before = np.array(_actor_mesh(window).points)
    assert panel.recompute.isHidden()
    edit = ubiquitin.model.move_point(0, 3.0, 5, np.array([6.0, 0.0, 0.0]))
    ubiquitin.undo_stack.push(EditCommand(ubiquitin, edit, "move"))
    assert panel.layer.stale and not panel.recompute.isHidden() and not panel.stale_text.isHidden()
    ubiquitin.undo_stack.undo()  # the atoms as the surface was built from: fresh again
    assert not panel.layer.stale and panel.recompute.isHidden()
    ubiquitin.undo_stack.redo()
    assert panel.layer.stale
    panel.recompute.click()
    assert panel.layer.busy
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    assert not panel.layer.stale and panel.recompute.isHidden()
    np.testing.assert_array_equal(panel.layer.built.coords, ubiquitin.model.coords)
    assert np.abs(_actor_mesh(window).points - before).max() > 1.0  # the globe follows the moved residues


def test_failures_are_reported_and_a_new_file_drops_the_cache(qtbot: QtBot, ubiquitin: Document) -> None:
    window = _window(qtbot, ubiquitin)
    panel = window.surface_panel
    dna = panel.kind.model().item(list(KIND_NAMES).index("dna"))
    assert not dna.isEnabled() and "has none" in dna.toolTip()  # not offered: ubiquitin has no double helix
    panel.layer.set_kind("dna")  # asked all the same (as a script may): the failure is reported
    panel.show_box.setChecked(True)
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    assert panel.layer.built is None and "DNA cylinder: 1UBQ" in panel.figures.text()
    assert "surface" not in window.plotter.actors
    panel.kind.setCurrentIndex(list(KIND_NAMES).index("map"))
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    panel.colouring.setCurrentIndex(list(COLOURING_NAMES).index("curvature"))
    assert "not by curvature" in panel.figures.text()  # drawn plain instead
    assert window.plotter.actors["surface"].GetVisibility()

    panel.kind.setCurrentIndex(list(KIND_NAMES).index("globe"))
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    window.files.open_file(DATA / "1L2Y.pdb.gz")  # Trp-cage, 20 residues
    qtbot.waitUntil(lambda: panel.layer.built is not None and not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    vertices = _actor_mesh(window).points
    ca = window.document.model.coords[window.document.ca_rows]
    assert np.linalg.norm(vertices.mean(axis=0) - ca.mean(axis=0)) < 5.0  # around the new structure
    assert window.plotter.actors["surface"].GetVisibility()


def _building(qtbot: QtBot, window: MainWindow, kind: str, stage: str) -> multiprocessing.Process:
    """Start building ``kind`` from the panel; return the build's process once it reports ``stage``."""
    panel = window.surface_panel
    panel.kind.setCurrentIndex(list(KIND_NAMES).index(kind))
    panel.show_box.setChecked(True)
    qtbot.waitUntil(lambda: panel.layer.stage.startswith(stage), timeout=BUILD_TIMEOUT_MS)
    [process] = multiprocessing.active_children()
    return process


def test_the_stages_of_a_build_are_shown(qtbot: QtBot, ubiquitin: Document) -> None:
    window = _window(qtbot, ubiquitin)
    panel = window.surface_panel
    shown: list[str] = []
    panel.layer.updated.connect(lambda: shown.append(panel.figures.text()))
    _show(qtbot, panel, "globe")
    stages = [text.removeprefix("Building the globe: ") for text in dict.fromkeys(shown) if text.startswith("Building")]
    ses = [f"molecular surface ({stage})…" for stage in
           ("distances to the atoms", "the solvent", "distance transform", "refinement")]
    assert stages == ["starting…", *ses, "fitting the globe…", "levels…"]
    assert "triangles, " in shown[-1]


def test_quitting_stops_a_running_build_at_once(qtbot: QtBot, open_window: Callable[[str], MainWindow]) -> None:
    window = open_window("4YVS.cif.gz")  # 3,405 residues: a globe takes 10-20 s
    process = _building(qtbot, window, "globe", "molecular surface (distance transform)")  # one long call into scipy
    start = time.perf_counter()
    window.files.quit_action.trigger()
    seconds = time.perf_counter() - start
    assert not window.isVisible() and seconds < 0.5
    assert process.exitcode == -signal.SIGKILL and not multiprocessing.active_children()


def test_another_kind_stops_the_running_build(qtbot: QtBot, open_window: Callable[[str], MainWindow]) -> None:
    window = open_window("1AYE.pdb.gz")  # 401 residues: a globe takes 2-5 s, a density map a fraction of a second
    panel = window.surface_panel
    globe = _building(qtbot, window, "globe", "molecular surface")
    panel.kind.setCurrentIndex(list(KIND_NAMES).index("map"))
    assert globe.exitcode == -signal.SIGKILL
    assert panel.layer.busy and panel.figures.text().startswith("Building the density map")
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    assert panel.layer.built.surface.kind == "map" and window.plotter.actors["surface"].GetVisibility()
    panel.kind.setCurrentIndex(list(KIND_NAMES).index("globe"))
    assert panel.layer.built is None and panel.layer.busy  # the stopped globe left nothing: built again
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    assert panel.layer.built.surface.kind == "globe"


def test_opening_another_file_drops_the_running_build(qtbot: QtBot, open_window: Callable[[str], MainWindow]) -> None:
    window = open_window("1AYE.pdb.gz")
    panel = window.surface_panel
    old = _building(qtbot, window, "globe", "molecular surface")
    window.files.open_file(DATA / "1L2Y.pdb.gz")  # Trp-cage, 20 residues
    assert old.exitcode == -signal.SIGKILL
    [new] = multiprocessing.active_children()
    qtbot.waitUntil(lambda: not panel.layer.busy, timeout=BUILD_TIMEOUT_MS)
    assert not new.is_alive() and panel.layer.built.surface.kind == "globe"
    ca = window.document.model.coords[window.document.ca_rows]
    assert np.linalg.norm(_actor_mesh(window).points.mean(axis=0) - ca.mean(axis=0)) < 5.0  # around the Trp-cage


def test_show_surface_can_be_ticked_after_every_load_and_dna_is_offered_for_dna(qtbot: QtBot) -> None:
    """#35: the box stayed greyed out after a load into an empty window until the kind changed."""
    window = _window(qtbot, Document())
    panel = window.surface_panel
    assert not panel.show_box.isEnabled()
    window.files.open_file(DATA / "1UBQ.pdb.gz")
    assert panel.show_box.isEnabled()
    dna = panel.kind.model().item(list(KIND_NAMES).index("dna"))
    assert not dna.isEnabled()
    window.document.undo_stack.setClean()
    window.files.open_file(DATA / "1BNA.pdb.gz")
    assert panel.show_box.isEnabled() and dna.isEnabled()
