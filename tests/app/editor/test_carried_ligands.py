"""Ligands and ions bound to a moved residue move with it in the view, as Edit ▸ Carry Bound Ligands says."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from app.editor.main_window import MainWindow
from app.editor.scene import molecule
from app.editor.scene.layers.meshes import unit_sphere

Opener = Callable[[str], MainWindow]


def _ball_centres(window: MainWindow) -> np.ndarray:
    mesh = window.scene.meshes["ligand_balls"]
    return np.asarray(mesh.points).reshape(-1, len(unit_sphere()[0]), 3).mean(axis=1)


def test_a_heme_follows_its_histidine_and_stays_when_told(open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")
    document, rw = window.document, window.rw
    action = window.editing.carry_action
    edit_menu = window.menuBar().actions()[1].menu()
    assert action in edit_menu.actions() and action.isCheckable() and action.isChecked()
    rw.go_to("A:87")
    heme, _ = document.model.bound_ligands(document.segment)
    assert len(_ligand_rows(window)) > len(heme)  # the other hemes and the phosphates stay
    before = document.model.coords.copy()
    rw.tug("A:87", [2.0, -3.0, 1.0])
    moved = np.flatnonzero(np.any(document.model.coords != before, axis=1))
    assert np.isin(heme, moved).all()
    centres = _ball_centres(window)
    np.testing.assert_allclose(centres, document.model.coords[_ligand_rows(window)], atol=1e-4)  # drawn where they are
    rw.undo()
    assert np.array_equal(document.model.coords, before)

    action.trigger()  # off: the next edit leaves the heme where it is
    assert not action.isChecked() and not document.carry_ligands and not document.model.carry_ligands
    rw.tug("A:87", [2.0, -3.0, 1.0])
    assert np.array_equal(document.model.coords[heme], before[heme])
    assert not np.array_equal(document.model.coords, before)


def _ligand_rows(window: MainWindow) -> np.ndarray:
    return molecule.ions_and_ligands(window.document.structure)[1]
