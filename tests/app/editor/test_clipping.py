"""The clipping slab (#34): switched on by its key, its planes moved by Shift and the right
button as PyMOL moves them and by keys, the view clipped to it at every frame, kept in
sessions."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt
from pytestqt.qtbot import QtBot

from app.editor.features.clipping import DEFAULT, PIXELS_PER_ANGSTROM
from app.editor.main_window import MainWindow
from app.editor.scene.layers.base import Layer

Opener = Callable[[str], MainWindow]
BACKGROUND = 40
"""Colour distance from the background's gradient above which a pixel shows something."""


def _drawn(window: MainWindow) -> int:
    """Pixels of the view that show the structure (not the background gradient)."""
    image = window.plotter.screenshot(return_img=True).astype(int)
    background = image[:, :1]  # the left column: background only (the structure is in the middle)
    return int(np.count_nonzero(np.abs(image - background).sum(axis=2) > BACKGROUND))


def test_the_slab_clips_the_view_and_moves_as_in_pymol(open_window: Opener, qtbot: QtBot, tmp_path: Path) -> None:
    window = open_window("1TIM.pdb.gz")
    camera = window.plotter.renderer.GetActiveCamera()
    full = _drawn(window)
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.keyClick(window.plotter, Qt.Key.Key_K, Qt.KeyboardModifier.ControlModifier)
    assert window.scene.slab == (DEFAULT, DEFAULT) and window.clipping.toggle_action.isChecked()
    clipped = _drawn(window)  # (a frame drawn now)
    distance = camera.GetDistance()
    assert camera.GetClippingRange() == pytest.approx((distance - DEFAULT, distance + DEFAULT))
    assert clipped < 0.9 * full  # what lies outside the slab is not drawn

    interactor = window.plotter.iren.interactor  # Shift and the right button, up 40 pixels and right 20
    interactor.SetEventInformation(300, 300, 0, 1)
    interactor.InvokeEvent("RightButtonPressEvent")
    interactor.SetEventInformation(320, 340, 0, 1)
    interactor.InvokeEvent("MouseMoveEvent")
    interactor.InvokeEvent("RightButtonReleaseEvent")
    front, back = DEFAULT + 40 / PIXELS_PER_ANGSTROM, DEFAULT + 20 / PIXELS_PER_ANGSTROM
    assert window.scene.slab == pytest.approx((front, back))
    assert camera.GetDistance() == pytest.approx(distance)  # the camera did not zoom
    qtbot.keyClick(window.plotter, Qt.Key.Key_Down, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier)
    assert window.scene.slab == pytest.approx((front - 1.0, back - 1.0))
    _drawn(window)
    assert camera.GetClippingRange() == pytest.approx((distance - front + 1.0, distance + back - 1.0))

    saved = window.sessions.write_session(tmp_path / "slab")
    qtbot.keyClick(window.plotter, Qt.Key.Key_K, Qt.KeyboardModifier.ControlModifier)  # off
    assert window.scene.slab is None
    assert _drawn(window) == pytest.approx(full, rel=0.02)
    assert window.sessions.open_session(saved)
    assert window.scene.slab == pytest.approx((front - 1.0, back - 1.0)) and window.clipping.toggle_action.isChecked()


def test_rw_shows_the_layers_and_sets_the_slab_and_the_cylinders(open_window: Opener) -> None:
    window = open_window("1UBQ.pdb.gz")
    rw = window.rw
    rw.show("tube")
    rw.show("cartoon", on=False)
    assert window.display_panel.layer_boxes[Layer.TUBE].isChecked() and window.scene.actors["tube"].GetVisibility()
    assert not window.scene.actors["cartoon"].GetVisibility()
    with pytest.raises(ValueError, match="no layer 'ribbon'; layers: cartoon, tube"):
        rw.show("ribbon")
    rw.slab = (6, 8)
    assert rw.slab == (6.0, 8.0) == window.scene.slab and window.clipping.toggle_action.isChecked()
    rw.slab = None
    assert window.scene.slab is None and not window.clipping.toggle_action.isChecked()
    rw.cylinders = True
    assert window.scene.helix_cylinders and rw.cylinders


def test_back_faces_are_culled_unless_the_slab_cuts_the_ribbons_open(open_window: Opener, qtbot: QtBot) -> None:
    """Culling halves the triangles the software renderer rasterizes (its memory on a capsid);
    inside the slab a cut ribbon shows its inside, so both sides are drawn then."""
    window = open_window("1UBQ.pdb.gz")
    cartoon = window.scene.actors["cartoon"].GetProperty()
    assert cartoon.GetBackfaceCulling()
    for slab in (True, False):
        frames = window.plotter.frames
        window.clipping.toggle_action.trigger()
        qtbot.waitUntil(lambda frames=frames: window.plotter.frames > frames)
        assert (window.scene.slab is not None) == slab and cartoon.GetBackfaceCulling() != slab
