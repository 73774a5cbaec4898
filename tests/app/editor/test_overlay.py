"""Structures for comparison in the editor window: superposed serine proteases at a common depth.

The edited structure is bovine trypsin (3PTB); chymotrypsin (1ACB, chain E beside the
inhibitor eglin c, chain I) and elastase (1BMA) are added, as in Carson's Fig. 8.
"""

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QCheckBox, QComboBox, QHeaderView, QToolButton
from pytestqt.qtbot import QtBot

from app.editor.docks.comparison import ALIGNED, REMOVE, RMS, STRUCTURE, TM_SCORE, WARNING_COLOUR
from app.editor.docks.panels import STEPS_PER_LEVEL
from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.scene.overlay import PALETTE, SAME_FOLD, TUBE_RADIUS, TUBE_SIDES
from app.editor.scene.scene import Layer
from app.main import main
from core.analysis.compare import pair_by_sequence
from core.analysis.fold_alignment import align_folds, tm_superpose
from core.curves.splines import spline_space
from core.protein.reading import read_structure
from core.protein.ribbon import segment_ribbon

DATA = Path(__file__).resolve().parents[2] / "data"
PROTEASES = [DATA / "1ACB.pdb.gz", DATA / "1BMA.pdb.gz"]


@pytest.fixture
def window(qtbot: QtBot) -> MainWindow:
    document = Document()
    document.open(DATA / "3PTB.pdb.gz")
    window = MainWindow(document)
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    assert window.comparison_panel.add_files(PROTEASES) == []
    return window


def _pixels(window: MainWindow) -> np.ndarray:
    return np.asarray(window.plotter.screenshot(return_img=True)).astype(int)


def _count(pixels: np.ndarray, rgb: tuple[int, int, int]) -> int:
    """Pixels of the hue of ``rgb`` whatever the shading (channels in the same proportions)."""
    colour = np.array(rgb, dtype=float)
    scale = pixels.sum(axis=2, keepdims=True) / colour.sum()
    return int(np.count_nonzero((np.abs(pixels - scale * colour).max(axis=2) < 14) & (scale[..., 0] > 0.35)))


def test_proteases_are_superposed_on_the_edited_chain(window: MainWindow) -> None:
    items = window.comparison.items
    assert [item.name for item in items] == ["1ACB E", "1BMA A"]  # chymotrypsin's longest chain, not eglin c
    trypsin = read_structure(DATA / "3PTB.pdb.gz")
    ca_a = np.concatenate([s.ca for s in trypsin.segments])
    for item in items:
        moving = [s for s in item.structure.segments if s.chain == item.chain]
        ca_b = np.concatenate([s.ca for s in moving])
        start_a, start_b, pairing = pair_by_sequence(list(trypsin.segments), moving)
        assert pairing == item.fit.pairing == "structure"  # other proteins: aligned by structure
        alignment = align_folds(ca_a, ca_b, start_a, start_b)
        np.testing.assert_allclose(item.fit.motion.rotation, alignment.motion.rotation, atol=1e-12)
        distance = np.linalg.norm(ca_a[alignment.pairs_a] - alignment.motion.apply(ca_b[alignment.pairs_b]), axis=1)
        d0 = 1.24 * (223 - 15) ** (1 / 3) - 1.8  # TM-align's, for trypsin's 223 residues
        assert item.fit.tm_score == pytest.approx(np.sum(1 / (1 + (distance / d0) ** 2)) / 223, abs=1e-12)
        assert item.fit.tm_score == pytest.approx(alignment.tm_score, abs=1e-12) and item.fit.tm_score > 0.9
        assert item.fit.length == 223 and item.fit.n_aligned == item.fit.n_pairs == len(distance) > 210
        assert item.fit.rms_aligned == pytest.approx(np.sqrt(np.mean(distance**2))) and item.fit.rms_aligned < 1.3
        for segment, ribbon in zip(moving, item.ribbons):  # the ribbons move rigidly with the Cα
            np.testing.assert_allclose(ribbon.points, item.fit.motion.apply(segment_ribbon(segment, "peptide").points),
                                       atol=1e-7)
    table = window.comparison_panel.table
    for row, item in enumerate(items):
        assert table.item(row, TM_SCORE).text() == f"{item.fit.tm_score:.2f}"  # no warning: the same fold
        assert table.item(row, ALIGNED).text() == f"{item.fit.n_aligned} of 223"
        assert table.item(row, RMS).text() == f"{item.fit.rms_aligned:.2f}"


def test_tubes_follow_the_level_slider(window: MainWindow) -> None:
    document, view = window.document, window.comparison_view
    for level in (4.0, 2.5, document.max_level):
        window.dimension_panel.slider.setValue(round(level * STEPS_PER_LEVEL))
        depth = document.max_level - document.level
        assert window.comparison.depth == pytest.approx(depth)
        for index, item in enumerate(window.comparison.items):
            assert item.colour == PALETTE[index]
            actor = window.plotter.actors[view.actor_name(item)]
            assert tuple(round(255 * c) for c in actor.prop.GetColor()) == item.colour
            curves = window.comparison.level_curves(index)
            mesh = view.meshes[item.key]
            assert mesh.n_points == sum(len(p.curve_u) for p in item.paths) * TUBE_SIDES
            centres = mesh.points.reshape(-1, TUBE_SIDES, 3).mean(axis=1)
            start = 0
            for ribbon, path, curve in zip(item.ribbons, item.paths, curves):
                expected_level = max(ribbon.max_level - depth, 0.0)
                points, j = ribbon.control_points(expected_level)
                assert curve.level == j and curve.n_segments == 2**j
                assert len(curve.control_points) == 2**j + 3
                samples = spline_space(j).evaluate(points, path.curve_u)
                np.testing.assert_allclose(centres[start:start + len(samples)], samples, atol=1e-4)
                radii = np.linalg.norm(mesh.points[start * TUBE_SIDES:(start + len(samples)) * TUBE_SIDES]
                                       - np.repeat(samples, TUBE_SIDES, axis=0), axis=1)
                np.testing.assert_allclose(radii, TUBE_RADIUS, atol=1e-4)
                start += len(samples)
    window.dimension_panel.slider.setValue(4 * STEPS_PER_LEVEL)  # trypsin, 223 residues: 3.80 below log2 223
    assert "3.80 levels below" in window.comparison_panel.level_text.text()
    elastase = window.comparison.items[1]  # 240 residues in one segment: level log2 240 - 3.80 = 4.11
    assert len(elastase.ribbons) == 1 and window.comparison.level(elastase.ribbons[0]) == pytest.approx(4.11, abs=0.01)
    assert window.comparison.level_curves(1)[0].n_segments == 32  # a fractional level blends 2^4 and 2^5


def test_visibility_removal_and_screenshot(window: MainWindow) -> None:
    for layer in (Layer.TUBE, Layer.CONTROL_POINTS):  # only the compared tubes and the thin level curve
        window.display_panel.layer_boxes[layer].setChecked(False)
    window.dimension_panel.slider.setValue(4 * STEPS_PER_LEVEL)
    both = _pixels(window)
    assert _count(both, PALETTE[0]) > 500 and _count(both, PALETTE[1]) > 500
    table = window.comparison_panel.table
    visible = table.cellWidget(1, 0)
    assert isinstance(visible, QCheckBox) and visible.text().startswith("1BMA")
    visible.setChecked(False)
    item = window.comparison.items[1]
    assert not window.plotter.actors[window.comparison_view.actor_name(item)].GetVisibility()
    hidden = _pixels(window)
    assert _count(hidden, PALETTE[1]) < 0.05 * _count(both, PALETTE[1])
    assert _count(hidden, PALETTE[0]) >= _count(both, PALETTE[0])
    remove = table.cellWidget(0, REMOVE)
    assert isinstance(remove, QToolButton)
    name = window.comparison_view.actor_name(window.comparison.items[0])
    remove.click()
    assert name not in window.plotter.actors and table.rowCount() == 1
    assert [i.name for i in window.comparison.items] == ["1BMA A"]
    assert _count(_pixels(window), PALETTE[0]) < 0.05 * _count(both, PALETTE[0])


def test_choosing_another_chain_refits(window: MainWindow) -> None:
    chain = window.comparison_panel.table.cellWidget(0, 1)
    assert isinstance(chain, QComboBox) and [chain.itemText(k) for k in range(chain.count())] == ["E", "I"]
    before = window.comparison.items[0]
    chain.setCurrentText("I")  # eglin c is no protease: its fit is poor, but it is the chain asked for
    after = window.comparison.items[0]
    assert after.chain == "I" and after.colour == before.colour and after.key == before.key
    assert len(after.ribbons) == len([s for s in after.structure.segments if s.chain == "I"])
    assert after.fit.tm_score < SAME_FOLD < before.fit.tm_score
    assert window.comparison_panel.table.item(0, TM_SCORE).text().endswith("different folds")


def test_new_structure_refits_and_bad_files_are_reported(window: MainWindow, tmp_path: Path) -> None:
    bad = tmp_path / "bad.pdb"
    bad.write_text("not a structure\n")
    problems = window.comparison_panel.add_files([bad, tmp_path / "missing.pdb"])
    assert len(problems) == 2 and problems[0].startswith("bad.pdb: ") and len(window.comparison.items) == 2
    window.files.open_file(DATA / "1TIM.pdb.gz")  # another protein: the proteases are refitted onto its chain A
    assert [i.fitted_to for i in window.comparison.items] == ["A", "A"]
    for row, item in enumerate(window.comparison.items):
        assert window.comparison_view.actor_name(item) in window.plotter.actors
        assert item.fit.length == 247 and item.fit.tm_score < 0.35  # triosephosphate isomerase is no serine protease
        tm = window.comparison_panel.table.item(row, TM_SCORE)
        assert tm.text() == f"{item.fit.tm_score:.2f} — different folds"


def test_command_line_compare_screenshot(qtbot: QtBot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "fig8.png"
    status = main([str(DATA / "3PTB.pdb.gz"), "--level", "4", "--hide", "cartoon", "control-points",
                   "--compare", f"{PROTEASES[0]}:E", str(PROTEASES[1]), "--screenshot", str(out)])
    assert status == 0 and out.stat().st_size > 10_000
    other = tmp_path / "other.png"
    assert main([str(DATA / "3PTB.pdb.gz"), "--compare", f"{PROTEASES[0]}:Q", "--screenshot", str(other)]) == 1
    assert "has no protein chain 'Q'; chains: E, I" in capsys.readouterr().err
    assert main([str(DATA / "3PTB.pdb.gz"), "--hide", "nothing", "--screenshot", str(other)]) == 1
    assert "--hide: no layer 'nothing'" in capsys.readouterr().err


@pytest.fixture
def ubiquitin(qtbot: QtBot) -> MainWindow:
    """1UBQ edited; trypsin, ubiquitin's Cα in another model (2K39), 1UBQ itself and the
    Trp-cage (1L2Y, 20 residues) compared, the dock in front."""
    document = Document()
    document.open(DATA / "1UBQ.pdb.gz")
    window = MainWindow(document)
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    names = ["3PTB.pdb.gz", "2K39_CA-only.pdb.gz", "1UBQ.pdb.gz", "1L2Y.pdb.gz"]
    assert window.comparison_panel.add_files([DATA / name for name in names]) == []
    window.comparison_panel.parentWidget().raise_()
    qtbot.waitUntil(window.comparison_panel.table.isVisible)
    return window


def test_an_unrelated_fold_is_flagged_and_its_relatives_are_not(ubiquitin: MainWindow) -> None:
    trypsin, relative, itself, trp_cage = (item.fit for item in ubiquitin.comparison.items)
    table = ubiquitin.comparison_panel.table
    assert trypsin.pairing == "structure" and trypsin.tm_score < SAME_FOLD  # TM-align: 0.367
    assert trypsin.tm_score == pytest.approx(0.367, abs=0.03) and 30 < trypsin.n_aligned < 76
    cell = table.item(0, TM_SCORE)
    assert cell.text() == f"{trypsin.tm_score:.2f} — different folds" and cell.text().startswith("0.3")
    assert cell.foreground().color() == WARNING_COLOUR and not cell.icon().isNull()
    assert "below 0.5 means the folds differ" in cell.toolTip() and "not meaningful" in cell.toolTip()
    assert table.item(0, ALIGNED).text() == f"{trypsin.n_aligned} of 76"
    assert trp_cage.pairing == "structure" and trp_cage.tm_score < 0.3 and trp_cage.n_aligned < 20  # too small to fail
    assert table.item(3, TM_SCORE).text().endswith("different folds")

    assert relative.pairing == "numbering" and relative.tm_score > 0.9  # TM-align: 0.916
    assert relative.tm_score == pytest.approx(0.916, abs=0.01)
    ubiquitin_ca, model_ca = (np.concatenate([s.ca for s in read_structure(DATA / name).segments])
                              for name in ("1UBQ.pdb.gz", "2K39_CA-only.pdb.gz"))
    _, best = tm_superpose(ubiquitin_ca, model_ca, 76)  # the TM-score search on the same pairs (by numbering)
    assert best - 0.01 < relative.tm_score <= best + 1e-12  # the fit on the core is nearly TM-score's optimum
    assert itself.tm_score == pytest.approx(1.0, abs=1e-12) and (itself.n_aligned, itself.rms_aligned) == (76, 0.0)
    for row, fit in ((1, relative), (2, itself)):
        cell = table.item(row, TM_SCORE)
        assert cell.text() == f"{fit.tm_score:.2f}" and cell.icon().isNull()
        assert cell.foreground().color() != WARNING_COLOUR and "differ" not in cell.toolTip()
    assert [table.item(row, ALIGNED).text() for row in (1, 2)] == [f"{relative.n_aligned} of 76", "76 of 76"]
    assert table.item(2, TM_SCORE).text() == "1.00" and table.item(2, RMS).text() == "0.00"


def test_the_columns_fit_their_content_and_names_are_whole(ubiquitin: MainWindow) -> None:
    table = ubiquitin.comparison_panel.table
    header = table.horizontalHeader()
    assert header.sectionResizeMode(STRUCTURE) == QHeaderView.ResizeMode.Stretch and not header.stretchLastSection()
    assert all(header.sectionResizeMode(c) == QHeaderView.ResizeMode.ResizeToContents
               for c in range(table.columnCount()) if c != STRUCTURE)
    names = []
    for row in range(table.rowCount()):
        box = table.cellWidget(row, STRUCTURE)
        assert isinstance(box, QCheckBox) and box.toolTip() == str(ubiquitin.comparison.items[row].path)
        names.append(box.text())
        assert header.sectionSize(STRUCTURE) >= box.sizeHint().width() > box.fontMetrics().horizontalAdvance(box.text())
        button = table.cellWidget(row, REMOVE)
        assert isinstance(button, QToolButton)
        assert button.sizeHint().width() <= header.sectionSize(REMOVE) <= button.sizeHint().width() + 12
    assert names == ["3PTB.pdb.gz", "2K39_CA-only.pdb.gz", "1UBQ.pdb.gz", "1L2Y.pdb.gz"]
    for column in (TM_SCORE, ALIGNED, RMS):  # every cell is wide enough for its text
        width = max(table.fontMetrics().horizontalAdvance(table.item(row, column).text())
                    for row in range(table.rowCount()))
        assert header.sectionSize(column) > width


def test_compared_colours_are_distinct_from_every_editor_colour() -> None:
    """The third compared structure was the purple of the control points (#17)."""
    from app.editor.scene import molecule, overlay
    from app.editor.scene.layers import ca_trace, control_points, level_curve, selection

    editor = [*molecule.SS_COLOURS.values(), level_curve.CURVE_COLOUR, level_curve.OTHER_CURVE_COLOUR,
              control_points.POINT_COLOUR, control_points.PICKED_COLOUR, selection.SELECTION_COLOUR,
              control_points.POLYGON_COLOUR, ca_trace.CA_STICK_COLOUR, (255, 255, 255), (223, 229, 236)]
    distances = np.linalg.norm(np.array(overlay.PALETTE)[:, None] - np.array(editor)[None], axis=2)
    assert distances.min() >= 60
