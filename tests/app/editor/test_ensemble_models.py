"""The models of an NMR ensemble (#34): the others drawn as thin Cα traces behind the one
edited, and played in turn in the same view."""

from collections.abc import Callable

import gemmi
import numpy as np
from pytestqt.qtbot import QtBot

from app.editor.main_window import MainWindow

Opener = Callable[[str], MainWindow]


def _ca(model: gemmi.Model) -> np.ndarray:
    return np.array([[a.pos.x, a.pos.y, a.pos.z] for chain in model for r in chain for a in r if a.name == "CA"])


def test_the_other_models_are_drawn_behind_the_edited_one_and_play_in_the_same_view(
        open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("1L2Y.pdb.gz")  # trp-cage: 38 models of 20 residues
    document, scene = window.document, window.scene
    ensemble = gemmi.read_structure(str(document.structure.path))
    traces = np.asarray(scene.meshes["other_models"].points)
    assert scene.actors["other_models"].GetVisibility() and len(traces) == 37 * 20
    np.testing.assert_allclose(traces[:20], _ca(ensemble[1]), atol=1e-5)  # model 2 first
    camera = window.plotter.camera_position
    window.models.play_action.trigger()
    qtbot.waitUntil(lambda: document.model_number >= 3, timeout=5000)
    assert window.plotter.camera_position == camera  # the same view
    shown = document.model_number
    window.models.play_action.trigger()  # stop
    qtbot.wait(600)
    assert document.model_number in (shown, shown % 38 + 1) and not window.models.timer.isActive()
    traces = np.asarray(scene.meshes["other_models"].points)
    np.testing.assert_allclose(traces[:20], _ca(ensemble[0]), atol=1e-5)  # model 1 is among the others now
    np.testing.assert_allclose(document.model.coords[document.ca_rows], _ca(ensemble[document.model_number - 1]),
                               atol=1e-3)

    window.rw.tug(10, (1.0, 0.0, 0.0))  # an edit: the models stay
    window.models.play_action.trigger()
    assert not window.models.timer.isActive() and "no edits to undo" in window.statusBar().currentMessage()


def test_a_single_model_has_nothing_to_play(open_window: Opener) -> None:
    window = open_window("1UBQ.pdb.gz")
    assert not window.models.play_action.isEnabled() and window.scene.meshes["other_models"].n_points == 0


def test_rw_plays_the_models(open_window: Opener, qtbot: QtBot) -> None:
    window = open_window("1L2Y.pdb.gz")
    window.rw.play_models()
    qtbot.waitUntil(lambda: window.rw.model >= 2, timeout=5000)
    window.rw.play_models(False)
    assert not window.models.timer.isActive()
