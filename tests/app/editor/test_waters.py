"""Waters drawn on demand: a small red ball at each water oxygen, off at first, switched in the
Display dock, hidden with the other chains."""

from collections.abc import Callable

import numpy as np

from app.editor.main_window import MainWindow
from app.editor.scene.layers.base import Layer
from app.editor.scene.layers.chains import Others
from app.editor.scene.layers.meshes import unit_sphere

Opener = Callable[[str], MainWindow]


def test_the_waters_of_haemoglobin_are_balls_at_their_oxygens_when_asked_for(open_window: Opener) -> None:
    window = open_window("4HHB.pdb.gz")  # 221 waters, in all four chains
    scene, atoms = window.scene, window.document.structure.atoms
    assert Layer.WATERS not in scene.layers and "waters" not in scene.actors  # not even built
    box = window.display_panel.layer_boxes[Layer.WATERS]
    assert box.text() == "Waters" and not box.isChecked()
    box.setChecked(True)
    oxygens = np.flatnonzero((atoms.category == "water") & (atoms.element == "O"))
    assert len(oxygens) == 221 and scene.actors["waters"].GetVisibility()
    sphere = len(unit_sphere()[0])
    centres = np.asarray(scene.meshes["waters"].points).reshape(-1, sphere, 3).mean(axis=1)
    np.testing.assert_allclose(centres, atoms.coords[oxygens], atol=1e-3)
    colours = np.asarray(scene.meshes["waters"].point_data["colours"])
    assert colours[:, 0].min() > 150 and colours[:, 1].max() < 100  # red, as oxygen is

    scene.set_others(Others.HIDDEN)  # chain A edited: the other chains' waters collapse
    points = np.asarray(scene.meshes["waters"].points).reshape(-1, sphere, 3)
    other = atoms.chain[oxygens] != "A"
    assert other.any() and np.all(np.ptp(points[other], axis=1) == 0.0)
    np.testing.assert_allclose(points[~other].mean(axis=1), atoms.coords[oxygens[~other]], atol=1e-3)
    scene.set_others(Others.SHOWN)
    np.testing.assert_allclose(np.asarray(scene.meshes["waters"].points).reshape(-1, sphere, 3).mean(axis=1),
                               atoms.coords[oxygens], atol=1e-3)

    box.setChecked(False)
    assert not scene.actors["waters"].GetVisibility()
    window.rw.show("waters")  # as a script names it
    assert box.isChecked() and scene.actors["waters"].GetVisibility()
