"""File ▸ Export Image, ``rw.screenshot`` and ``--export-image``: any size, supersampled,
on a transparent background, never over a file without asking."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QDialogButtonBox, QFileDialog, QMessageBox
from pytestqt.qtbot import QtBot

from app.editor.features.export import ExportImageDialog, export_view, render_view
from app.editor.main_window import MainWindow
from app.editor.scene.scene import Layer
from app.main import main

DATA = Path(__file__).resolve().parents[2] / "data"
CAPTION_ROWS = 40
"""Rows at the top of a 300-pixel-high image that hold the view's caption."""


@pytest.fixture
def window(open_window: Callable[[str], MainWindow]) -> MainWindow:
    return open_window("1UBQ.pdb.gz")


def _rgba(image: QImage) -> np.ndarray:
    """(h, w, 4) straight (not premultiplied) RGBA of ``image``, as ints."""
    image = image.convertToFormat(QImage.Format.Format_RGBA8888)
    rows = np.frombuffer(image.constBits(), dtype=np.uint8).reshape(image.height(), image.bytesPerLine())
    return rows[:, : 4 * image.width()].reshape(image.height(), image.width(), 4).astype(int)


def _helix(pixels: np.ndarray) -> np.ndarray:
    """Where ``pixels`` have the helix colour (222, 66, 91), whatever the shading."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (r > 90) & (r - g > 70) & (r - b > 50) & (b > g)


def _partial_alpha(pixels: np.ndarray) -> int:
    """Pixels below the caption neither transparent nor opaque: the smoothed edges."""
    alpha = pixels[CAPTION_ROWS:, :, 3]
    return int(np.count_nonzero((alpha > 0) & (alpha < 255)))


def _save_button(dialog: ExportImageDialog):
    return dialog.buttons.button(QDialogButtonBox.StandardButton.Save)


def test_an_image_of_the_size_asked_for_and_the_view_as_it_was(window: MainWindow, tmp_path: Path) -> None:
    plotter = window.plotter
    view_size, before = plotter.window_size, plotter.screenshot(return_img=True)
    image = QImage(str(export_view(plotter, tmp_path / "view.png", 333, 222)))
    assert (image.width(), image.height()) == (333, 222)
    assert np.count_nonzero(_helix(_rgba(image))) > 100
    wide = QImage(str(export_view(plotter, tmp_path / "wide.png", 500)))  # the height by the view's aspect ratio
    assert (wide.width(), wide.height()) == (500, round(500 * view_size[1] / view_size[0]))
    assert QImage(str(export_view(plotter, tmp_path / "as-shown.png"))).size().toTuple() == tuple(view_size)
    assert plotter.window_size == view_size and plotter.camera.GetWindowCenter() == (0.0, 0.0)
    np.testing.assert_array_equal(plotter.screenshot(return_img=True), before)
    with pytest.raises(FileExistsError):
        export_view(plotter, tmp_path / "view.png", 333, 222)
    with pytest.raises(ValueError, match="at most 33.6 million"):
        export_view(plotter, tmp_path / "huge.png", 16384, 16384)


def test_a_transparent_background_with_an_opaque_ribbon_and_the_view_as_it_was(window: MainWindow,
                                                                               tmp_path: Path) -> None:
    plotter = window.plotter
    before = plotter.screenshot(return_img=True)
    plain = _rgba(QImage(str(export_view(plotter, tmp_path / "plain.png", 400, 300))))
    assert (plain[..., 3] == 255).all()
    edges = {}
    for factor in (1, 2):
        image = QImage(str(export_view(plotter, tmp_path / f"clear{factor}.png", 400, 300, supersample=factor,
                                       transparent=True)))
        assert image.hasAlphaChannel() and (image.width(), image.height()) == (400, 300)
        pixels = _rgba(image)
        alpha = pixels[..., 3]
        assert (alpha[[0, 0, -1, -1], [0, -1, 0, -1]] == 0).all() and np.mean(alpha == 0) > 0.8
        helix = _helix(pixels)
        assert np.count_nonzero(helix) > 100 and np.median(alpha[helix]) == 255  # opaque but at smoothed edges
        assert (alpha[helix] == 255).all() if factor == 1 else set(np.unique(alpha[helix])) >= {64, 128, 191, 255}
        solid = alpha == 255
        assert np.median(np.abs(pixels[solid][:, :3] - plain[solid][:, :3])) <= 2  # the colours shown on the background
        edges[factor] = _partial_alpha(pixels)
    assert edges[1] < edges[2] / 10 and edges[2] > 1000, edges  # edges fade out only when supersampled
    np.testing.assert_array_equal(plotter.screenshot(return_img=True), before)  # the background is back


def test_supersampling_averages_n_by_n_samples_a_pixel(window: MainWindow) -> None:
    """N x N supersampling gives the view rendered N times larger and averaged over each N x N
    block (shown on the tube alone, drawn in Å: lines and text keep their widths in pixels),
    where a plain 1x image is far off along the edges."""
    for layer, box in window.display_panel.layer_boxes.items():
        box.setChecked(layer is Layer.TUBE)
    plotter = window.plotter
    plain = _rgba(render_view(plotter, 400, 300))[..., :3]
    for factor in (2, 4):
        image = render_view(plotter, 400, 300, supersample=factor)
        assert (image.width(), image.height()) == (400, 300)
        smooth = _rgba(image)[..., :3]
        plotter.renderer.SetUseFXAA(False)
        larger = np.asarray(plotter.screenshot(return_img=True, window_size=(400 * factor, 300 * factor)), dtype=float)
        blocks = larger.reshape(300, factor, 400, factor, 3)
        edges = blocks.std(axis=(1, 3)).max(axis=-1) > 20  # the blocks an edge crosses
        edges[:CAPTION_ROWS] = False
        averaged = blocks.mean(axis=(1, 3))
        off = {n: np.abs(pixels - averaged)[edges].mean() for n, pixels in ((1, plain), (factor, smooth))}
        assert np.count_nonzero(edges) > 500 and off[factor] < 2 and off[1] > 10, off
    with pytest.raises(ValueError, match="supersampling must be one of 1, 2, 4; got 3"):
        render_view(plotter, 400, 300, supersample=3)


def test_the_dialog_writes_what_its_fields_say(window: MainWindow, qtbot: QtBot, tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    file_menu = window.menuBar().actions()[0].menu()
    assert window.export.export_action in file_menu.actions() and window.export.export_action.shortcut().toString() == "Ctrl+E"
    window.export.export_action.trigger()
    dialog = window.findChild(ExportImageDialog)
    assert dialog.isVisible() and [dialog.width_box.value(), dialog.height_box.value()] == window.plotter.window_size
    assert dialog.path().name == "1UBQ.png" and dialog.supersampling.currentData() == 2
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *args, **kwargs: (str(tmp_path / "figure"), ""))
    qtbot.mouseClick(dialog.browse, Qt.MouseButton.LeftButton)
    assert dialog.path() == tmp_path / "figure.png"

    dialog.keep_aspect.setChecked(False)
    dialog.width_box.setValue(16384)
    dialog.height_box.setValue(16384)
    assert not _save_button(dialog).isEnabled() and "at most 33.6 million" in dialog.problem.text()
    dialog.width_box.selectAll()
    qtbot.keyClicks(dialog.width_box, "20000")  # too wide: kept as typed and refused, not cut to 2000
    assert dialog.width_box.value() == 20000 and not _save_button(dialog).isEnabled()
    assert dialog.problem.isVisible() and "Width must be a whole number of pixels in [1, 16384]; got 20000" in \
        dialog.problem.text()
    qtbot.keyClick(dialog.width_box, Qt.Key.Key_Return)  # Return does not save what the dialog refuses
    assert dialog.isVisible() and not list(tmp_path.iterdir())
    dialog.width_box.setValue(16384)
    dialog.keep_aspect.setChecked(True)  # the ratio of the fields from now on
    dialog.width_box.selectAll()
    qtbot.keyClicks(dialog.width_box, "480")
    assert (dialog.width_box.value(), dialog.height_box.value()) == (480, 480)
    dialog.height_box.selectAll()
    qtbot.keyClicks(dialog.height_box, "270")
    assert dialog.width_box.value() == 270 and _save_button(dialog).isEnabled() and not dialog.problem.isVisible()
    dialog.keep_aspect.setChecked(False)
    dialog.width_box.selectAll()
    qtbot.keyClicks(dialog.width_box, "480")
    assert dialog.height_box.value() == 270
    dialog.supersampling.setCurrentIndex(dialog.supersampling.findData(4))
    qtbot.mouseClick(dialog.transparent, Qt.MouseButton.LeftButton, pos=QPoint(8, dialog.transparent.height() // 2))
    assert dialog.transparent.isChecked()
    qtbot.mouseClick(_save_button(dialog), Qt.MouseButton.LeftButton)
    assert not dialog.isVisible()
    image = QImage(str(tmp_path / "figure.png"))
    assert (image.width(), image.height()) == (480, 270) and image.hasAlphaChannel()
    assert _partial_alpha(_rgba(image)) > 500  # supersampled 4x: edges fade out


def test_the_dialog_asks_before_it_replaces_a_file_and_says_why_it_cannot_write(
        window: MainWindow, qtbot: QtBot, tmp_path: Path, questions, errors: list[str]) -> None:
    dialog = window.export.export_image_dialog()
    missing = tmp_path / "no-such-folder" / "view.png"
    dialog.file.setText(str(missing))
    qtbot.mouseClick(_save_button(dialog), Qt.MouseButton.LeftButton)
    assert dialog.isVisible() and errors == [f"cannot write {missing}: No such file or directory"]
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"mine")
    dialog.file.setText(str(tmp_path / "mine"))  # .png added
    qtbot.mouseClick(_save_button(dialog), Qt.MouseButton.LeftButton)  # answered No
    assert questions.asked == ["mine.png exists. Replace it?"] and mine.read_bytes() == b"mine" and dialog.isVisible()
    questions.answer = QMessageBox.StandardButton.Yes
    qtbot.mouseClick(_save_button(dialog), Qt.MouseButton.LeftButton)
    assert not dialog.isVisible() and QImage(str(mine)).size().toTuple() == tuple(window.plotter.window_size)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.png"]  # no temporary left


# ------------------------------------------------------------------ the command line


def test_command_line_export_image(qtbot: QtBot, tmp_path: Path) -> None:
    out = tmp_path / "figure.png"
    assert main([str(DATA / "1UBQ.pdb.gz"), "--export-image", str(out), "--width", "300", "--height", "200",
                 "--supersample", "2", "--transparent"]) == 0
    image = QImage(str(out))
    assert (image.width(), image.height()) == (300, 200) and image.hasAlphaChannel()
    pixels = _rgba(image)
    assert pixels[0, 0, 3] == 0 and np.median(pixels[_helix(pixels), 3]) == 255 and _partial_alpha(pixels) > 300
    assert main([str(DATA / "1UBQ.pdb.gz"), "--export-image", str(out), "--width", "640", "--overwrite"]) == 0
    image = QImage(str(out))
    assert image.width() == 640 and 300 < image.height() < 640 and not image.hasAlphaChannel()


@pytest.mark.parametrize(("arguments", "status", "message"), [
    (["--width", "0"], 2, "argument --width: must lie in [1, 16384]; got 0"),
    (["--height", "20000"], 2, "argument --height: must lie in [1, 16384]; got 20000"),
    (["--width", "wide"], 2, "argument --width: expected a whole number; got 'wide'"),
    (["--supersample", "3"], 2, "argument --supersample: invalid choice: 3 (choose from 1, 2, 4)"),
    (["--width", "16384", "--height", "16384"], 1,
     "--export-image: 16384 x 16384 is 268 million pixels; at most 33.6 million"),
    (["existing"], 1, "refusing to overwrite an existing file (use --overwrite)"),
    (["no-image", "--width", "300", "--transparent"], 1, "--width, --transparent: only with --export-image"),
])
def test_command_line_export_image_refuses_bad_values(qtbot: QtBot, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                      arguments: list[str], status: int, message: str) -> None:
    out = tmp_path / "figure.png"
    if arguments[0] == "existing":
        out.write_bytes(b"mine")
    argv = [str(DATA / "1UBQ.pdb.gz")] + ([] if arguments[0] == "no-image" else ["--export-image", str(out)])
    argv += [a for a in arguments if a not in ("existing", "no-image")]
    if status == 2:
        with pytest.raises(SystemExit) as exit_info:
            main(argv)
        assert exit_info.value.code == 2
    else:
        assert main(argv) == 1
    last = capsys.readouterr().err.splitlines()[-1]  # after the usage, for a usage error
    assert last.startswith("ribbonwave") and message in last
    assert sorted(p.name for p in tmp_path.iterdir()) == (["figure.png"] if arguments[0] == "existing" else [])
