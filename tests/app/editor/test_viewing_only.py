"""Entries without a protein backbone (the B-DNA dodecamer 1BNA) open for viewing and surfaces:
atoms drawn, the surface dock usable, every editing control disabled with the reason shown."""

import gzip
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot
from test_surface_panel import BUILD_TIMEOUT_MS, _show
from test_window import _mouse_drag, _pixels, _window

from app.editor.docks.panels import BACKBONE_LAYERS
from app.editor.document import Document
from app.editor.persistence.recording import recording, replay
from app.editor.scene.scene import Layer
from app.main import main
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
DNA = DATA / "1BNA.pdb.gz"
REASON = "1BNA has no protein backbone: viewing only"
DNA_ATOMS = 486
"""Atoms of the 24 nucleotides of 1BNA (the other 80 of its 566 are waters)."""


def test_the_document_views_dna_and_refuses_edits_with_the_reason(qapp: QApplication, tmp_path: Path) -> None:
    document = Document()
    document.open(DNA)
    assert not document.editable and document.read_only_reason == REASON
    assert document.model.ribbons == [] and len(document.model.coords) == 566 and document.max_level == 0.0
    for edit in (lambda: document.set_level(2.0), lambda: document.set_segment(0), lambda: document.pick_point(1),
                 lambda: document.preview_move(1, np.ones(3)), lambda: document.set_multiresolution(False),
                 lambda: document.regularize_region(np.arange(2))):
        with pytest.raises(ValueError, match=REASON):
            edit()
    document.pick_point(None)  # nothing to pick: fine
    saved = document.save(tmp_path / "copy.pdb")  # saving unchanged is allowed: a copy, byte for byte
    assert saved.read_bytes() == gzip.decompress(DNA.read_bytes()) and not document.modified
    again = Document()
    replay(again, recording(document))
    assert not again.editable and np.array_equal(again.model.coords, document.model.coords)


def test_a_protein_document_is_editable_with_no_reason(ubiquitin: Document) -> None:
    assert ubiquitin.editable and ubiquitin.read_only_reason == ""


def test_dna_opens_in_the_window_for_viewing_and_surfaces(qtbot: QtBot, tmp_path: Path, errors: list[str]) -> None:
    window = _window(qtbot, DATA / "1UBQ.pdb.gz")
    window.comparison.add(DATA / "1UBQ.pdb.gz")
    assert window.files.open_file(DNA) and errors == []
    assert window.comparison.items == []  # nothing to superpose them on
    document, scene = window.document, window.scene
    assert window.windowTitle() == "1BNA.pdb.gz[*] — ribbonwave"

    # the atoms are drawn, the backbone's layers are not
    atoms = scene.meshes["atoms"]
    assert atoms.n_points == 566 and atoms.n_lines > DNA_ATOMS  # bonds of every nucleotide (rings close)
    bonded = np.unique(atoms.lines.reshape(-1, 3)[:, 1:])
    assert len(bonded) == DNA_ATOMS and set(document.structure.atoms.category[bonded]) == {"nucleic"}
    np.testing.assert_array_equal(atoms.points, read_structure(DNA, require_protein=False).coords)
    assert Layer.ATOMS in scene.layers and scene.actors["atoms"].GetVisibility()  # shown: all there is to see
    assert window.display_panel.layer_boxes[Layer.ATOMS].isChecked()
    assert not {"tube", "curve", "control_points", "ca_balls"} & set(scene.meshes)
    assert scene.actors["caption"].GetInput() == REASON

    # editing is off, and the window says why
    panel = window.dimension_panel
    assert window.status.labels["pick"].text() == REASON and window.status.labels["level"].text() == ""
    assert not panel.note.isHidden() and panel.note.text() == REASON
    for widget in (panel.slider, panel.spin, panel.segment, panel.kind, panel.analysis, panel.integers):
        assert not widget.isEnabled()
    assert panel.model_number.isHidden()  # one model
    assert not any(action.isEnabled() for action in window.editing.mode_actions.actions())
    assert not window.editing.regularize_action.isEnabled()
    assert all(not window.display_panel.layer_boxes[layer].isEnabled() for layer in BACKBONE_LAYERS)
    assert window.display_panel.layer_boxes[Layer.ATOMS].isEnabled()
    assert window.validation.report is None and window.validation_panel.timing.text() == REASON
    assert not window.comparison_panel.add_button.isEnabled()
    with pytest.raises(ValueError, match=REASON):
        window.comparison.add(DATA / "1UBQ.pdb.gz")

    # a drag over the molecule turns the camera and edits nothing
    camera = window.plotter.camera.position
    width, height = window.plotter.width(), window.plotter.height()
    _mouse_drag(window, (width // 2, height // 2), (80, 40))
    assert window.plotter.camera.position != camera and not window.controller.dragging
    assert document.undo_stack.count() == 0 and not document.modified and window.history.model().rowCount() == 1
    assert np.array_equal(document.model.coords, document.structure.coords)

    # the surface dock builds the DNA cylinder of the atoms
    surfaces = window.surface_panel
    _show(qtbot, surfaces, "dna")
    assert surfaces.layer.message == "" and surfaces.layer.built.surface.kind == "dna"
    mesh = window.plotter.actors["surface"].mapper.dataset
    assert mesh.n_cells > 1000 and window.plotter.actors["surface"].GetVisibility()
    assert f"{mesh.n_cells} triangles" in surfaces.figures.text()
    centre = document.model.coords[bonded].mean(axis=0)
    assert np.linalg.norm(np.asarray(mesh.points).mean(axis=0) - centre) < 5.0  # around the duplex
    _show(qtbot, surfaces, "ses")
    qtbot.waitUntil(lambda: surfaces.layer.built is not None, timeout=BUILD_TIMEOUT_MS)
    assert window.plotter.actors["surface"].mapper.dataset.n_cells > 1000

    # its atoms are measured, labelled and gone to by name, as a protein's are
    rw = window.rw
    rise = rw.measure("A:DG4 P", "/A:5@P")  # one phosphate to the next along a strand
    assert 5.5 < rise < 7.5 and rw.measure("B:DT20") is None
    assert rw.measurements == [f"A:DG4 P – A:DA5 P: {rise:.2f} Å", "B:DT20"]
    assert window.measurements_panel.table.rowCount() == 2
    assert rw.go_to("B:20") == ["B:DT20"] and len(document.selection) == 0  # the nucleotide, selected
    assert np.array_equal(document.selected_groups, np.flatnonzero((document.structure.atoms.chain == "B")
                                                                   & (document.structure.atoms.resseq == 20)))
    for _ in range(2):
        window.measurements_panel.table.selectRow(0)
        window.measurements_panel.delete.click()

    # saving unchanged writes the file as read
    assert window.files.write(tmp_path / "1bna.pdb")
    assert (tmp_path / "1bna.pdb").read_bytes() == gzip.decompress(DNA.read_bytes())
    assert window.files.write(tmp_path / "1bna.cif")
    np.testing.assert_array_equal(read_structure(tmp_path / "1bna.cif", require_protein=False).coords,
                                  document.structure.coords)

    # a session of it opens again for viewing; a protein makes everything editable again
    saved = window.sessions.write_session(tmp_path / "dna")
    assert window.files.open_file(DATA / "1UBQ.pdb.gz") and document.editable
    assert panel.slider.isEnabled() and panel.note.isHidden() and "cartoon" in scene.meshes
    assert all(action.isEnabled() for action in window.editing.mode_actions.actions())
    assert all(window.display_panel.layer_boxes[layer].isEnabled() for layer in BACKBONE_LAYERS)
    assert window.sessions.open_session(saved) and not document.editable
    assert window.status.labels["pick"].text() == REASON and errors == []


def test_the_command_line_opens_dna_but_not_at_a_level(qapp: QApplication, tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(DNA), "--screenshot", str(tmp_path / "dna.png")]) == 0
    rgb = _pixels(QImage(str(tmp_path / "dna.png")))
    vivid = rgb.max(axis=2) - rgb.min(axis=2) > 120  # the atoms' oxygen, nitrogen and phosphorus colours
    assert vivid.sum() > 2000
    assert main([str(DNA), "--level", "2", "--screenshot", str(tmp_path / "level.png")]) == 1
    assert capsys.readouterr().err == f"ribbonwave: error: --level: {REASON}\n"
