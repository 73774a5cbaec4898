"""The editor window on the bundled example, and the ``ribbonwave`` command that opens it."""

import re
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtGui import QAction, QImage
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot

from app import DEFAULT_STRUCTURE
from app.cli import COMMANDS, main
from app.main_window import CA_TRACE_ACTOR, MainWindow, read_ca_chains

UBIQUITIN_RESIDUES = 76
DATA = Path(__file__).resolve().parent.parent / "data"


def _pixels(image: QImage) -> np.ndarray:
    """RGB pixels of ``image``, shape (height, width, 3)."""
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    rows = np.frombuffer(image.constBits(), dtype=np.uint8).reshape(image.height(), image.bytesPerLine())
    return rows[:, : 3 * image.width()].reshape(image.height(), image.width(), 3)


def _count_blue(pixels: np.ndarray) -> int:
    """Number of pixels with the blue hue of the Cα trace (the background is white, the chrome grey)."""
    red, blue = pixels[..., 0].astype(int), pixels[..., 2].astype(int)
    return int(np.count_nonzero(blue - red > 40))


@pytest.fixture
def window(qtbot: QtBot) -> MainWindow:
    window = MainWindow(DEFAULT_STRUCTURE, read_ca_chains(DEFAULT_STRUCTURE))
    qtbot.addWidget(window)  # closed, and so its plotter too, after the test
    window.show()
    qtbot.waitExposed(window)
    return window


def test_bundled_example_is_ubiquitin() -> None:
    (chain,) = read_ca_chains(DEFAULT_STRUCTURE)
    assert chain.shape == (UBIQUITIN_RESIDUES, 3)


def test_one_trace_per_protein_chain() -> None:
    chains = read_ca_chains(DATA / "4HHB.pdb.gz")  # haemoglobin: two alpha and two beta chains
    assert [chain.shape for chain in chains] == [(141, 3), (146, 3), (141, 3), (146, 3)]


def test_window_renders_the_ca_trace(window: MainWindow) -> None:
    assert window.windowTitle() == "ribbonwave — 1UBQ.pdb"
    actor = window.plotter.actors[CA_TRACE_ACTOR]
    assert actor.GetVisibility()
    assert actor.GetMapper().GetInput().GetNumberOfPoints() == UBIQUITIN_RESIDUES
    window.plotter.render()
    assert _count_blue(window.plotter.screenshot(return_img=True)) > 1000


def test_quit_closes_window_and_plotter(qtbot: QtBot, window: MainWindow) -> None:
    (quit_action,) = [action for action in window.findChildren(QAction) if action.text() == "&Quit"]
    quit_action.trigger()
    qtbot.waitUntil(lambda: not window.isVisible())
    assert window.plotter.render_window is None


def test_screenshot_shows_the_trace(qapp: QApplication, tmp_path: Path) -> None:
    shot = tmp_path / "shot.png"
    assert main(["--screenshot", str(shot)]) == 0
    image = QImage(str(shot))
    assert not image.isNull()
    pixels = _pixels(image)
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 1
    assert _count_blue(pixels) > 1000


@pytest.mark.parametrize("content", [None, "not a structure\n"], ids=["missing", "not-a-structure"])
def test_unreadable_file_is_a_one_line_error(
    qapp: QApplication, tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str | None
) -> None:
    path = tmp_path / "input.pdb"
    if content is not None:
        path.write_text(content)
    assert main([str(path)]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith("ribbonwave: error: ")
    assert str(path) in err
    assert err.count("\n") == 1


def test_unwritable_screenshot_is_a_one_line_error(
    qapp: QApplication, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    shot = tmp_path / "no-such-folder" / "shot.png"
    assert main(["--screenshot", str(shot)]) == 1
    assert capsys.readouterr().err == f"ribbonwave: error: cannot write {shot}\n"


def test_help_lists_the_commands(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    out = capsys.readouterr().out
    for name in COMMANDS:
        assert re.search(rf"^ +{name} ", out, re.MULTILINE)
