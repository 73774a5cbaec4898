"""Structures for comparison in the editor window: superposed serine proteases at a common depth.

The edited structure is bovine trypsin (3PTB); chymotrypsin (1ACB, chain E beside the
inhibitor eglin c, chain I) and elastase (1BMA) are added, as in Carson's Fig. 8.
"""

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QCheckBox, QComboBox, QLabel, QPushButton
from pytestqt.qtbot import QtBot

from app.editor.docks.panels import STEPS_PER_LEVEL
from app.editor.document import Document
from app.editor.main_window import MainWindow
from app.editor.scene.overlay import CORE_CUTOFF, PALETTE, TUBE_RADIUS, TUBE_SIDES
from app.editor.scene.scene import Layer
from app.main import main
from core.analysis.compare import pair_residues
from core.analysis.superpose import superpose
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
    for item in items:
        fixed, moving = list(trypsin.segments), [s for s in item.structure.segments if s.chain == item.chain]
        pairs_a, pairs_b, pairing = pair_residues(fixed, moving)
        assert pairing == "structure" and item.fit.n_pairs == len(pairs_a) > 200
        ca_a = np.concatenate([s.ca for s in fixed])[pairs_a]
        ca_b = np.concatenate([s.ca for s in moving])[pairs_b]
        distance = np.linalg.norm(ca_a - item.fit.motion.apply(ca_b), axis=1)
        core = distance < CORE_CUTOFF
        assert item.fit.n_core == core.sum() > 0.8 * len(pairs_a)
        direct = superpose(ca_a[core], ca_b[core])  # the fit is gemmi's on its own core pairs
        np.testing.assert_allclose(item.fit.motion.rotation, direct.rotation, atol=1e-9)
        np.testing.assert_allclose(item.fit.motion.translation, direct.translation, atol=1e-7)
        assert item.fit.rms_core == pytest.approx(direct.rmsd, abs=1e-9) and item.fit.rms_core < 1.2
        assert item.fit.rms_all == pytest.approx(np.sqrt(np.mean(distance**2))) and item.fit.rms_all < 3.0
        assert superpose(ca_a, ca_b).rmsd < item.fit.rms_all + 0.1  # the refined fit loses little on all pairs
        for segment, ribbon in zip(moving, item.ribbons):  # the ribbons move rigidly with the Cα
            np.testing.assert_allclose(ribbon.points, direct.apply(segment_ribbon(segment, "peptide").points),
                                       atol=1e-7)
    labels = [window.comparison_panel.table.cellWidget(row, 2) for row in range(2)]
    assert all(isinstance(label, QLabel) and label.text().startswith(f"{item.fit.rms_core:.2f} Å on")
               for label, item in zip(labels, items))


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
    remove = table.cellWidget(0, 3)
    assert isinstance(remove, QPushButton)
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
    assert after.fit.rms_all > 2 * before.fit.rms_all


def test_new_structure_refits_and_bad_files_are_reported(window: MainWindow, tmp_path: Path) -> None:
    bad = tmp_path / "bad.pdb"
    bad.write_text("not a structure\n")
    problems = window.comparison_panel.add_files([bad, tmp_path / "missing.pdb"])
    assert len(problems) == 2 and problems[0].startswith("bad.pdb: ") and len(window.comparison.items) == 2
    window.open_file(DATA / "1TIM.pdb.gz")  # another protein: the proteases are refitted onto its chain A
    assert [i.fitted_to for i in window.comparison.items] == ["A", "A"]
    for item in window.comparison.items:
        assert window.comparison_view.actor_name(item) in window.plotter.actors
        assert item.fit.n_pairs < 40  # triosephosphate isomerase is not a serine protease: few equivalent Cα


def test_command_line_compare_screenshot(qtbot: QtBot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "fig8.png"
    status = main([str(DATA / "3PTB.pdb.gz"), "--level", "4", "--hide", "tube", "control-points",
                   "--compare", f"{PROTEASES[0]}:E", str(PROTEASES[1]), "--screenshot", str(out)])
    assert status == 0 and out.stat().st_size > 10_000
    other = tmp_path / "other.png"
    assert main([str(DATA / "3PTB.pdb.gz"), "--compare", f"{PROTEASES[0]}:Q", "--screenshot", str(other)]) == 1
    assert "has no protein chain 'Q'; chains: E, I" in capsys.readouterr().err
    assert main([str(DATA / "3PTB.pdb.gz"), "--hide", "nothing", "--screenshot", str(other)]) == 1
    assert "--hide: no layer 'nothing'" in capsys.readouterr().err


def test_compared_colours_are_distinct_from_every_editor_colour() -> None:
    """The third compared structure was the purple of the control points (#17)."""
    from app.editor.scene import molecule, overlay, scene

    editor = [*molecule.SS_COLOURS.values(), scene.CURVE_COLOUR, scene.OTHER_CURVE_COLOUR, scene.POINT_COLOUR,
              scene.PICKED_COLOUR, scene.POLYGON_COLOUR, scene.CA_STICK_COLOUR, (255, 255, 255), (223, 229, 236)]
    distances = np.linalg.norm(np.array(overlay.PALETTE)[:, None] - np.array(editor)[None], axis=2)
    assert distances.min() >= 60
