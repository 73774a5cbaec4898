"""Maps as other programs write them, in the editor: an MTZ's 2mFo−DFc and difference maps,
the file's resolution, the judgement of the fit in the Map dock and the sequence bar, the
whole map on request, and typed values out of range refused."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QInputDialog
from pytestqt.qtbot import QtBot

from app.editor.main_window import MainWindow
from app.editor.scene.map_mesh import (
    DIFFERENCE_ACTORS,
    DIFFERENCE_COLOURS,
    RECONTOUR_MS,
)
from core.fitting.map_target import RESOLUTION
from core.protein.reading import read_atoms
from core.surfaces.volume import model_density
from tests.conftest import D_MIN, DATA, MISSING, write_mrc, write_mtz


@pytest.fixture
def window(open_window: Callable[[str], MainWindow], tmp_path: Path) -> MainWindow:
    """Ubiquitin with the maps of its refinement open (residues 30-35 missing from the model
    the difference map was made for)."""
    window = open_window("1UBQ.pdb.gz")
    window.rw.open_map(write_mtz(tmp_path / "refined.mtz"))
    return window


def test_an_mtz_shows_both_maps_at_the_files_resolution(window: MainWindow, qtbot: QtBot) -> None:
    maps, panel = window.maps, window.map_panel
    assert maps.density.periodic and maps.columns == (("FWT", "PHWT"), ("DELFWT", "PHDELWT"))
    assert maps.mesh.n_cells > 500
    positive, negative = maps.difference_meshes
    assert positive.n_cells > 0  # green where residues 30-35 are missing from the model
    for name, colour in zip(DIFFERENCE_ACTORS, DIFFERENCE_COLOURS):
        assert name in window.plotter.actors
        assert np.allclose(window.plotter.actors[name].prop.color.float_rgb, np.array(colour) / 255, atol=0.01)
    assert window.correlation.resolution == pytest.approx(D_MIN, abs=0.01)
    assert "the file's" in panel.resolution_text.text()
    assert "DELFWT" in panel.file_text.text() and "±3σ" in panel.file_text.text()
    qtbot.waitUntil(lambda: window.correlation.value is not None)
    assert f"at {D_MIN:.3g} Å" in panel.cc_text.text()


def test_the_judgement_in_the_dock_and_the_sequence_bar(window: MainWindow, qtbot: QtBot) -> None:
    qtbot.waitUntil(lambda: window.correlation.quality is not None, timeout=5000)
    quality = window.correlation.quality
    assert quality.cc_mask > 0.7 and "CC_mask" in window.map_panel.quality_text.text()
    scores = window.sequence_bar.strip.scores
    assert scores is not None and len(scores) == 76 and np.nanmedian(scores) > 0.6
    window.maps.close()
    qtbot.waitUntil(lambda: window.sequence_bar.strip.scores is None)
    assert window.map_panel.quality_text.text() == ""


def test_the_whole_map_on_request(window: MainWindow) -> None:
    maps = window.maps
    around = maps.mesh.n_cells
    window.map_panel.whole.setChecked(True)  # the crystal's map around the whole model
    assert maps.whole and maps.mesh.n_cells > 2 * around and not window.map_panel.radius.isEnabled()
    coords = window.document.model.coords
    reach = np.linalg.norm(coords.max(axis=0) - coords.min(axis=0)) / 2 + 6.0
    assert np.linalg.norm(maps.mesh.points - (coords.min(axis=0) + coords.max(axis=0)) / 2, axis=1).max() <= reach
    window.map_panel.whole.setChecked(False)
    assert maps.mesh.n_cells == around


@pytest.mark.parametrize("box, typed, kept", [("radius", "500", 15.0), ("resolution", "0.5", D_MIN)])
def test_a_typed_value_out_of_range_is_refused_with_a_message(window: MainWindow, qtbot: QtBot, box: str,
                                                              typed: str, kept: float) -> None:
    spin = getattr(window.map_panel, box)
    spin.setFocus()
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), typed)
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_Return)
    assert spin.value() == pytest.approx(kept, abs=0.01)
    assert window.map_panel.refused_text.isVisibleTo(window.map_panel)
    assert f"{typed} Å is out of range" in window.map_panel.refused_text.text()
    assert RESOLUTION[0] <= window.correlation.resolution <= RESOLUTION[1]


def test_columns_refinement_does_not_name_are_chosen(open_window: Callable[[str], MainWindow], tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    window = open_window("1UBQ.pdb.gz")
    path = write_mtz(tmp_path / "odd.mtz", "FCALC PHCALC", "FDIFF PHDIFF")
    asked: list[list[str]] = []

    def choose(parent, title, label, items, *args):  # noqa: ANN001, ANN202 (QInputDialog.getItem)
        asked.append(list(items))
        return items[0], True

    monkeypatch.setattr(QInputDialog, "getItem", choose)
    assert window.maps_and_fits.open_map(path)  # as File ▸ Open Map… does
    assert asked == [["FCALC, PHCALC", "FDIFF, PHDIFF"]]
    assert window.maps.columns == (("FCALC", "PHCALC"), None)
    assert len(MISSING) == 6


def test_the_whole_of_a_box_is_contoured_once(open_window: Callable[[str], MainWindow], tmp_path: Path,
                                              qtbot: QtBot) -> None:
    """A box map drawn whole is the contour of all of it, not contoured again as the view pans."""
    window = open_window("1UBQ.pdb.gz")
    density = model_density(read_atoms(DATA / "1UBQ.pdb.gz"), spacing=1.0, resolution=4.0, margin=8.0)
    window.rw.open_map(write_mrc(tmp_path / "box.mrc", density.values, origin=tuple(density.origin),
                                 step=np.diag(density.axes)))
    maps = window.maps
    window.map_panel.whole.setChecked(True)
    whole = density.contour(maps.value)
    assert maps.mesh.n_cells == pytest.approx(whole.n_faces, rel=0.02)
    contoured = []
    maps.contoured.connect(lambda: contoured.append(1))
    frames = window.plotter.frames
    window.navigation.go_to("40")  # the view's centre moves
    qtbot.waitUntil(lambda: window.plotter.frames > frames)
    qtbot.wait(3 * RECONTOUR_MS)
    assert not contoured
