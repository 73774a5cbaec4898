"""Maps and fits in the editor: File ▸ Open Map draws the map as a mesh around the view's
centre, the Map dock's contour and radius, the live correlation, and Edit ▸ Fit to Map /
Fit to Compared Structure at the level shown and coarse to fine, each level one undo step.

The maps are simulated: the open form of adenylate kinase (4AKE), superposed on the closed
form (1AKE) that the window edits, as a blurred sum of Gaussians, written as CCP4."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import gemmi
import numpy as np
import pytest
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication, QFileDialog, QProgressDialog
from pytestqt.qtbot import QtBot
from scipy import ndimage

from app.editor.main_window import MainWindow
from app.editor.map_correlation import INTERVAL_MS, JUDGE_MS
from app.editor.scene.map_mesh import RECONTOUR_MS
from core.analysis.superpose import superpose
from core.fitting import settle as settle_module
from core.fitting.domains import DOMAINS
from core.fitting.map_target import gaussian_sigma
from core.fitting.settle import BACKBONE
from core.geometry.validation import validate
from core.protein.reading import read_structure
from core.protein.structure import ca_rows
from core.surfaces.volume import DensityMap

DATA = Path(__file__).resolve().parents[2] / "data"
CLOSED, OPEN = "1AKE_adk_closed.pdb.gz", "4AKE_adk_open.pdb.gz"
RESOLUTION = 8.0


def simulated_map(path: Path, resolution: float = RESOLUTION) -> Path:
    """Write the density of 4AKE's heavy atoms, superposed on 1AKE's Cα, at ``resolution`` Å."""
    closed, target = read_structure(DATA / CLOSED), read_structure(DATA / OPEN)
    fit = superpose(closed.coords[ca_rows(closed)], target.coords[ca_rows(target)])  # the same 214 residues
    return write_map(path, fit.apply(target.coords[target.atoms.element != "H"]), resolution)


def write_map(path: Path, coords: np.ndarray, resolution: float, spacing: float = 1.5) -> Path:
    """Write the density of atoms at ``coords`` at ``resolution`` Å as a CCP4 map."""
    origin = coords.min(axis=0) - 12.0
    shape = np.ceil((coords.max(axis=0) + 12.0 - origin) / spacing).astype(int)
    index = np.round((coords - origin) / spacing).astype(int)
    values = np.zeros(shape)
    np.add.at(values, tuple(index.T), 1.0)
    values = ndimage.gaussian_filter(values, gaussian_sigma(resolution) / spacing).astype(np.float32)
    ccp4 = gemmi.Ccp4Map()
    ccp4.grid = gemmi.FloatGrid(values, gemmi.UnitCell(*(shape * spacing), 90, 90, 90), gemmi.SpaceGroup("P1"))
    ccp4.update_ccp4_header()
    for word, value in zip((50, 51, 52), origin):  # the origin, in Å
        ccp4.set_header_float(word, float(value))
    ccp4.write_ccp4_map(str(path))
    return path


@pytest.fixture(scope="module")
def adk_map(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return simulated_map(tmp_path_factory.mktemp("maps") / "4AKE_8A.ccp4")


@pytest.fixture
def window(open_window: Callable[[str], MainWindow], adk_map: Path) -> MainWindow:
    """1AKE with the map of 4AKE open, the map's resolution set."""
    window = open_window(CLOSED)
    window.rw.open_map(adk_map)
    window.map_panel.resolution.setValue(RESOLUTION)
    return window


def _focal_point(window: MainWindow) -> np.ndarray:
    return np.array(window.plotter.renderer.GetActiveCamera().GetFocalPoint())


def _ca_rmsd(window: MainWindow, target: np.ndarray) -> float:
    document = window.document
    return superpose(document.model.coords[document.ca_rows], target).rmsd


def test_the_map_is_a_mesh_around_the_centre_that_follows_it(window: MainWindow, qtbot: QtBot) -> None:
    maps = window.maps
    assert maps.actor is not None and maps.actor.prop.style == "Wireframe"
    assert maps.mesh.n_cells > 500
    assert np.array_equal(maps.centre, _focal_point(window))
    assert np.linalg.norm(maps.mesh.points - maps.centre, axis=1).max() <= maps.radius
    assert "4AKE_8A.ccp4" in window.map_panel.file_text.text()
    before, frames = maps.mesh.points.copy(), window.plotter.frames
    window.navigation.go_to("150")  # centres the view on a residue at the edge of the chain
    qtbot.waitUntil(lambda: np.array_equal(maps.centre, _focal_point(window)))
    assert not np.array_equal(maps.mesh.points[:10], before[:10])
    assert np.linalg.norm(maps.mesh.points - maps.centre, axis=1).max() <= maps.radius
    qtbot.waitUntil(lambda: window.plotter.frames > frames)
    cells = maps.mesh.n_cells
    window.map_panel.slider.setValue(25)  # 2.5 σ: less of the map
    assert maps.sigma == 2.5 and 0 < maps.mesh.n_cells < cells
    window.map_panel.radius.setValue(8.0)
    assert np.linalg.norm(maps.mesh.points - maps.centre, axis=1).max() <= 8.0


def test_the_centre_is_contoured_at_most_ten_times_a_second(
    window: MainWindow, qtbot: QtBot, monkeypatch: pytest.MonkeyPatch
) -> None:
    maps, times = window.maps, []
    maps.contour()
    contour_around = DensityMap.contour_around

    def timed(*args: object) -> object:  # the throttle spaces the starts; how long each takes varies
        times.append(time.perf_counter())
        return contour_around(*args)

    monkeypatch.setattr(DensityMap, "contour_around", timed)
    ca = window.document.model.coords[window.document.ca_rows]
    for k in range(40):  # a fast pan: the centre moves at each of 40 frames within a few milliseconds
        window.scene.centre_on(ca[5 * k])
        window.plotter.ren_win.InvokeEvent("StartEvent")
        QApplication.processEvents()
    qtbot.waitUntil(lambda: np.array_equal(maps.centre, ca[195]))
    assert 0 < len(times) < 40 and np.all(np.diff(times) >= RECONTOUR_MS / 1e3)


def test_a_broken_map_file_gives_a_dialog(
    open_window: Callable[[str], MainWindow], tmp_path: Path, errors: list[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    window = open_window(CLOSED)
    junk = tmp_path / "broken.map"
    junk.write_bytes(b"not a map" * 200)
    monkeypatch.setattr(QFileDialog, "getOpenFileName", lambda *args: (str(junk), ""))
    window.maps_and_fits.open_map_action.trigger()  # File ▸ Open Map…
    assert len(errors) == 1 and "not a CCP4/MRC map" in errors[0]
    assert window.maps.density is None and not window.maps_and_fits.fit_actions[0].isEnabled()


def test_the_correlation_shows_and_follows_edits_ten_times_a_second(window: MainWindow, qtbot: QtBot) -> None:
    correlation, document = window.correlation, window.document
    qtbot.waitUntil(lambda: correlation.value is not None)
    assert 0.3 < correlation.value < 0.95
    assert f"{correlation.value:.3f}" in window.map_panel.cc_text.text()
    assert window.status.labels["map"].text() == f"map CC {correlation.value:.3f}"
    qtbot.wait(INTERVAL_MS + 20)
    before, first = correlation.updates, correlation.value
    document.pick_point(5)
    for k in range(30):  # a drag's previews without a turn of the event loop between them
        document.preview_move(5, np.array([0.2 * k, 0.0, 0.0]))
    qtbot.waitUntil(lambda: correlation.updates == before + 1)
    qtbot.wait(2 * INTERVAL_MS)
    assert correlation.updates == before + 1 and correlation.value != first
    document.cancel_drag()


def test_a_drag_is_judged_when_it_ends_not_while_the_mouse_rests(window: MainWindow, qtbot: QtBot) -> None:
    correlation, document = window.correlation, window.document
    qtbot.waitUntil(lambda: correlation.quality is not None, timeout=5000)
    judged = []
    correlation.judged.connect(lambda: judged.append(correlation.quality))
    document.pick_point(5)
    document.preview_move(5, np.array([3.0, 0.0, 0.0]))
    qtbot.wait(3 * JUDGE_MS)  # the mouse held still in the middle of the drag
    assert not judged
    document.finish_drag("Move control point")
    qtbot.waitUntil(lambda: len(judged) == 1, timeout=5000)


def test_fit_to_map_at_this_level_is_one_undo_step(window: MainWindow) -> None:
    document = window.document
    document.set_level(2)
    cc = window.rw.map_correlation
    window.maps_and_fits.fit_actions[0].trigger()  # Edit ▸ Fit to Map at This Level
    assert document.undo_stack.count() == 1
    assert document.undo_stack.text(0).startswith("Fit to map at level 2 (CC ")
    assert window.rw.map_correlation > cc + 0.05
    window.rw.undo()
    assert np.array_equal(document.model.coords, document.structure.coords)
    assert window.rw.map_correlation == cc


def test_fit_to_map_coarse_to_fine_is_one_step_a_level_and_a_regularization(window: MainWindow) -> None:
    document = window.document
    document.set_level(3)
    target = read_structure(DATA / OPEN)
    target_ca = target.coords[ca_rows(target)]
    rmsd, cc = _ca_rmsd(window, target_ca), window.rw.map_correlation
    fitted = window.rw.fit_to_map(resolution=8.5)
    assert window.map_panel.resolution.value() == 8.5
    assert [level for level, _ in fitted] == [DOMAINS, 0, 1, 2, 3]
    steps, index = window.rw.history()
    assert index == 7 and steps[0].startswith("Fit to map: the domains (CC ")  # the LID or NMP domain turned
    assert "the smaller dynamic domain, 5" in steps[0] and "residues, turned" in steps[0]
    assert [s.split(" (")[0] for s in steps[1:5]] == [f"Fit to map at level {k}" for k in range(4)]
    assert steps[5] == "Regularize the fit to map"
    assert steps[6] == "Refine the fit to map (each residue, side chains)"
    assert window.rw.map_correlation > cc + 0.1
    assert _ca_rmsd(window, target_ca) < rmsd - 2.0  # towards the open form whose map it is
    window.rw.undo()  # the refinement: the residues and side chains back, as regularized
    regularized = document.model.coords.copy()
    window.rw.redo()
    side_chain = ~np.isin(document.structure.atoms.name, ("N", "CA", "C", "O", "CB"))
    assert np.abs(document.model.coords - regularized)[side_chain].max() > 1.0  # side chains turned
    for _ in range(7):
        window.rw.undo()
    assert np.array_equal(document.model.coords, document.structure.coords)


def test_levels_finer_than_the_map_resolves_are_left_out_and_the_status_bar_says_so(window: MainWindow) -> None:
    """At 30 Å the map resolves adenylate kinase's level 4 (its control points 13 residues,
    27 Å apart), not level 5 (13 Å, less than half the resolution): coarse to fine from
    level 6, levels 5-6 are left out and each residue is refined after level 4."""
    window.document.set_level(6)
    fitted = window.rw.fit_to_map(resolution=30.0)
    assert [level for level, _ in fitted] == [DOMAINS, 0, 1, 2, 3, 4]
    assert "levels 5–6 left out: finer than the map resolves at 30 Å" in window.statusBar().currentMessage()
    steps, index = window.rw.history()
    assert steps[index - 1] == "Refine the fit to map (each residue, side chains)"


def test_a_fit_moves_every_segment_of_the_edited_chain_in_one_step_a_level(
    open_window: Callable[[str], MainWindow], tmp_path: Path
) -> None:
    window = open_window("1F9V.pdb.gz")  # chain A in five segments (chain breaks)
    document = window.document
    structure = document.structure
    shift = np.array([2.0, 0.0, 0.0])
    window.rw.open_map(write_map(tmp_path / "1F9V_moved.ccp4", structure.coords[structure.atoms.element != "H"]
                                 + shift, RESOLUTION))
    window.map_panel.resolution.setValue(RESOLUTION)
    document.set_level(1)
    window.maps_and_fits.fit_actions[0].trigger()  # Edit ▸ Fit to Map at This Level
    assert window.rw.history()[1] == 1  # one step
    ca = ca_rows(structure)
    for segment in structure.segments:
        moved = document.model.coords[ca[segment.residue_index]] - structure.coords[ca[segment.residue_index]]
        assert np.mean(moved @ shift) / 2.0 > 1.0  # every segment towards the map, not the edited one alone
    window.rw.undo()
    assert np.array_equal(document.model.coords, structure.coords)


def test_cancel_during_the_levels_undoes_the_whole_fit(window: MainWindow, qtbot: QtBot) -> None:
    """The levels' steps are not regularized yet: a Cancel among them leaves the model as it
    was, never with stretched junctions."""
    document = window.document
    document.set_level(3)

    def cancel() -> None:
        dialog = window.findChild(QProgressDialog)
        if dialog is not None:
            dialog.cancel()  # Cancel pressed once level 0 is done

    document.undo_stack.indexChanged.connect(cancel)
    window.maps_and_fits.fit_actions[1].trigger()  # Edit ▸ Fit to Map Coarse to Fine
    document.undo_stack.indexChanged.disconnect(cancel)
    assert window.rw.history()[1] == 0
    assert np.array_equal(document.model.coords, document.structure.coords)


def test_cancel_during_the_refinement_keeps_a_regularized_model(window: MainWindow, qtbot: QtBot) -> None:
    """The progress dialog stays up through the regularization and the refinement; a Cancel
    in the refinement keeps the residues refined so far, regularized: no junction broken."""
    document = window.document
    document.set_level(3)
    seen: list[tuple[bool, int, int]] = []

    def regularized() -> None:
        if document.undo_stack.text(document.undo_stack.index() - 1).startswith("Regularize"):
            dialog = window.findChild(QProgressDialog)
            seen.append((dialog.isVisible(), dialog.value(), dialog.maximum()))
            QTimer.singleShot(400, dialog.cancel)  # in the middle of the refinement

    document.undo_stack.indexChanged.connect(regularized)
    window.maps_and_fits.fit_actions[1].trigger()
    document.undo_stack.indexChanged.disconnect(regularized)
    assert seen and seen[0][0] and seen[0][1] < seen[0][2]  # the dialog still up, the refinement to come
    steps, index = window.rw.history()
    assert steps[index - 1].startswith(("Refine the fit", "Regularize the fit"))
    before, after = validate(document.structure).counts, validate(document.structure, document.model.coords).counts
    assert after["peptide_bond"] <= before["peptide_bond"] + 2 and after["clash"] <= before["clash"] + 5


def test_fit_to_compared_structure_brings_the_ca_rmsd_down(open_window: Callable[[str], MainWindow]) -> None:
    window = open_window(CLOSED)
    assert not window.maps_and_fits.fit_actions[3].isEnabled()
    window.comparison.add(DATA / OPEN)
    target = read_structure(DATA / OPEN)
    target_ca = target.coords[ca_rows(target)]
    rmsd = _ca_rmsd(window, target_ca)
    window.maps_and_fits.fit_actions[2].trigger()  # at this level (6)
    assert window.rw.history() == ([window.document.undo_stack.text(0)], 1)
    assert window.document.undo_stack.text(0).startswith("Fit to 4AKE_adk_open at level 6 (Cα rmsd ")
    assert _ca_rmsd(window, target_ca) < rmsd / 2
    window.rw.undo()
    fitted = window.rw.fit_to_compared()  # coarse to fine, levels 0 to 6
    assert [level for level, _ in fitted] == list(range(7))
    steps, index = window.rw.history()
    assert index == 8 and steps[-1] == "Regularize the fit to 4AKE_adk_open"
    assert rmsd > 6.0 and _ca_rmsd(window, target_ca) < 1.5


def test_a_homologue_keeps_every_level_and_its_backbone(open_window: Callable[[str], MainWindow]) -> None:
    window = open_window("3PTB.pdb.gz")  # trypsin, onto another serine protease's backbone
    window.comparison.add(DATA / "3SGB.pdb.gz")
    document = window.document
    before = validate(document.structure).counts
    fitted = window.rw.fit_to_compared()  # levels 0 to 6
    steps, index = window.rw.history()
    assert [level for level, _ in fitted] == list(range(7)) and fitted[-1][1] < 0.7 * fitted[0][1]
    assert index == 8 and steps[-1] == "Regularize the fit to 3SGB E"  # (its chain E)
    after = validate(document.structure, document.model.coords).counts
    assert sum(after[k] for k in BACKBONE) <= sum(before[k] for k in BACKBONE)


def test_coarse_to_fine_undoes_the_finest_levels_the_backbone_cannot_take(
    open_window: Callable[[str], MainWindow], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Allowed fewer flags than any model has, the fit undoes its levels down to the coarsest
    one, each undone level's step off the undo stack, and says so in History."""
    monkeypatch.setattr(settle_module, "MIN_MARGIN", -1000)
    monkeypatch.setattr(settle_module, "MARGIN", -1.0)
    window = open_window("3PTB.pdb.gz")
    window.comparison.add(DATA / "3SGB.pdb.gz")
    structure = window.document.structure
    fitted = window.rw.fit_to_compared([0, 1, 2])
    steps, index = window.rw.history()
    assert [level for level, _ in fitted] == [0]
    assert index == 2 and steps[-1].startswith("Regularize the fit to 3SGB") and "level 1, 2 undone" in steps[-1]
    window.rw.undo()
    window.rw.undo()
    assert np.array_equal(window.document.model.coords, structure.coords)


def test_fits_need_a_target(open_window: Callable[[str], MainWindow], errors: list[str]) -> None:
    window = open_window(CLOSED)
    with pytest.raises(ValueError, match="no map is open"):
        window.rw.fit_to_map()
    with pytest.raises(ValueError, match="no compared structure"):
        window.rw.fit_to_compared()
    window.comparison.add(DATA / "1UBQ.pdb.gz")  # another protein
    window.maps_and_fits.fit("compared", False)
    assert len(errors) == 1 and "another fold" in errors[0]
    assert window.document.undo_stack.count() == 0
