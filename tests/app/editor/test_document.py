"""The document without widgets: levels, previews of a drag, undo commands, saving."""

from pathlib import Path

import numpy as np
import pytest
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot

from app.editor.document import Change, Document
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def test_opens_two_levels_below_full_resolution(ubiquitin: Document) -> None:
    assert ubiquitin.max_level == pytest.approx(np.log2(76))
    assert ubiquitin.level == 4.0 and ubiquitin.shown_level() == 4.0
    assert ubiquitin.level_curve().n_segments == 16
    assert not ubiquitin.modified and ubiquitin.save_path is None


def test_level_is_clipped_and_multiresolution_off_means_full_resolution(ubiquitin: Document, qtbot: QtBot) -> None:
    with qtbot.waitSignal(ubiquitin.levelChanged):
        ubiquitin.set_level(99.0)
    assert ubiquitin.level == ubiquitin.max_level
    ubiquitin.set_level(2.5)
    ubiquitin.set_multiresolution(False)
    assert ubiquitin.shown_level() == ubiquitin.max_level and ubiquitin.level == 2.5
    ubiquitin.set_multiresolution(True)
    assert ubiquitin.shown_level() == 2.5
    assert ubiquitin.level_curve().level == 3  # fractional 2.5 is shown on level-3 control points


def test_deviation_is_carsons_rms_of_ca_to_curve(ubiquitin: Document) -> None:
    ribbon = ubiquitin.model.ribbons[0]
    ca = ubiquitin.structure.segments[0].ca
    for level in (2.0, 3.3, 6.25):
        ubiquitin.set_level(level)
        expected = np.sqrt(np.mean(np.sum((ribbon.residue_points(level) - ca) ** 2, axis=1)))
        assert ubiquitin.deviation() == pytest.approx(expected, abs=1e-12)
    ubiquitin.set_kind("calpha")
    ubiquitin.set_level(ubiquitin.max_level)
    assert ubiquitin.deviation() < 1e-9  # the Cα ribbon passes through every Cα at full resolution


def test_a_drag_is_previewed_from_its_start_and_pushed_once(ubiquitin: Document, qtbot: QtBot) -> None:
    ubiquitin.set_regularization(on_release=False)  # Carson's plain edit (regularization: test_validation_panel)
    original = ubiquitin.model.coords.copy()
    changes: list[Change] = []
    ubiquitin.changed.connect(changes.append)
    for step in np.linspace(0.5, 4.0, 8):  # eight mouse moves
        ubiquitin.preview_move(7, np.array([step, -0.5 * step, 0.25]))
    assert ubiquitin.undo_stack.count() == 0 and len(changes) == 8
    ubiquitin.finish_drag("Move point 7 at level 4.00")
    assert ubiquitin.undo_stack.count() == 1 and ubiquitin.modified
    assert ubiquitin.undo_stack.text(0) == "Move point 7 at level 4.00"
    dragged = ubiquitin.model.coords.copy()

    # the result is that of one edit by the last displacement: no drift over the moves
    reference = EditableModel(ubiquitin.structure)
    reference.apply(reference.move_point(0, 4.0, 7, np.array([4.0, -2.0, 0.25])))
    np.testing.assert_allclose(dragged, reference.coords, atol=1e-12)
    moved = np.flatnonzero(np.any(dragged != original, axis=1))
    assert np.array_equal(moved, np.sort(changes[-1].rows))
    assert np.array_equal(dragged[np.setdiff1d(np.arange(len(original)), moved)],
                          original[np.setdiff1d(np.arange(len(original)), moved)])

    ubiquitin.undo_stack.undo()
    assert np.array_equal(ubiquitin.model.coords, original) and not ubiquitin.modified
    ubiquitin.undo_stack.redo()
    assert np.array_equal(ubiquitin.model.coords, dragged)


def test_cancelled_or_motionless_drags_leave_no_trace(ubiquitin: Document) -> None:
    original = ubiquitin.model.coords.copy()
    points = ubiquitin.model.ribbons[0].points.copy()
    ubiquitin.preview_tug(0.5, np.array([3.0, 0.0, 0.0]))
    assert not np.array_equal(ubiquitin.model.coords, original)
    ubiquitin.cancel_drag()
    assert np.array_equal(ubiquitin.model.coords, original)
    assert np.array_equal(ubiquitin.model.ribbons[0].points, points)
    ubiquitin.preview_move(3, np.zeros(3))
    ubiquitin.finish_drag("Move point 3")
    ubiquitin.finish_drag("nothing")  # a release without a drag
    assert ubiquitin.undo_stack.count() == 0 and not ubiquitin.modified


def test_picking_tells_which_residues_a_point_moves(ubiquitin: Document, qtbot: QtBot) -> None:
    ubiquitin.set_level(ubiquitin.max_level)
    with qtbot.waitSignal(ubiquitin.picked):
        ubiquitin.pick_point(40)
    assert len(ubiquitin.pick.residues) == 10  # Carson's four at full resolution, three turned on each side
    ubiquitin.set_level(3.0)
    assert ubiquitin.pick is None  # a new level shows other control points
    ubiquitin.pick_point(5)
    assert len(ubiquitin.pick.residues) >= 32


def test_ribbon_kind_changes_only_without_edits(ubiquitin: Document) -> None:
    ubiquitin.set_kind("calpha")
    assert ubiquitin.kind == "calpha" and ubiquitin.model.ribbons[0].n_curve_segments == 77
    ubiquitin.preview_move(2, np.ones(3))
    ubiquitin.finish_drag("Move point 2")
    with pytest.raises(ValueError, match="no edits to undo"):
        ubiquitin.set_kind("peptide")
    ubiquitin.undo_stack.undo()
    ubiquitin.set_kind("peptide")
    assert ubiquitin.kind == "peptide" and ubiquitin.undo_stack.count() == 0


def test_a_file_opens_on_its_longest_segment(qapp: QApplication) -> None:
    document = Document()
    document.open(DATA / "1ACB.pdb.gz")  # chymotrypsin's 13-residue chain first, then 131, 97 and 63
    assert document.segment == 1 and document.structure.segments[1].summary.endswith("(131 residues)")
    assert document.level == round(np.log2(131) - 2)
    document.open(DATA / "4YVS.cif.gz")  # 226, 176, 48, 231, ...: the first of the longest
    assert document.segment == 3 and len(document.labels()) == 231


def test_segments_of_a_multichain_entry(qapp: QApplication) -> None:
    document = Document()
    document.open(DATA / "4YVS.cif.gz")
    assert len(document.paths) == 20
    document.set_segment(0)
    document.set_level(7.5)  # 0.32 below the top of segment 0 (226 residues)
    document.set_segment(2)  # chain B, residues 190-237: 48 residues
    assert document.max_level == pytest.approx(np.log2(48))
    assert document.level == pytest.approx(np.log2(48) - (np.log2(226) - 7.5))  # the same share of the detail
    document.set_level(2.0)  # a coarse level of the short chain: as far below the long one's top
    document.set_segment(0)
    assert document.level == pytest.approx(np.log2(226) - (np.log2(48) - 2.0))
    assert document.structure.segments[2].summary == "B  THR190–GLN237 (48 residues)"
    with pytest.raises(ValueError, match="segment must be in"):
        document.set_segment(20)


def test_save_writes_the_edit_and_never_overwrites_silently(ubiquitin: Document, tmp_path: Path) -> None:
    ubiquitin.preview_move(9, np.array([0.0, 2.0, 1.0]))
    ubiquitin.finish_drag("Move point 9")
    target = tmp_path / "edited.cif"
    target.write_text("keep me")
    with pytest.raises(FileExistsError):
        ubiquitin.save(target)
    assert target.read_text() == "keep me" and ubiquitin.modified
    written = ubiquitin.save(tmp_path / "edited.pdb")
    assert not ubiquitin.modified and ubiquitin.save_path == written == ubiquitin.path
    again = read_structure(written)
    np.testing.assert_allclose(again.coords, ubiquitin.model.coords, atol=6e-4)  # 3 decimals in PDB
