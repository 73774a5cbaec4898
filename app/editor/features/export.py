"""Images: the 3D view as a PNG image of any size, supersampled, optionally on a transparent
background; and the whole window's screenshot.

File ▸ Export Image (:class:`ImageExport` and its :class:`ExportImageDialog`), ``rw.screenshot``
and ``--export-image`` all go through :func:`export_view`. A view supersampled N times is rendered N x N times at the
size asked for, the camera shifted each time to another point of an N x N grid inside the
pixel, and the frames are averaged: the same samples as a rendering N times larger averaged
over each N x N block (a box filter), which smooths edges whatever the OpenGL, while lines,
points and text keep their widths in pixels (a larger rendering would thin them) and memory
stays that of one frame. A transparent image is rendered on black of zero alpha, so its
colours come out premultiplied by their alpha and average correctly at the edges.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager, nullcontext
from numbers import Integral
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QBuffer, QByteArray, QIODevice, QPoint, QSignalBlocker, Qt
from PySide6.QtGui import QImage, QKeySequence, QPainter
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QMainWindow,
    QMessageBox,
    QPushButton,
    QSpinBox,
    QWidget,
)

from app.arguments import IMAGE_SIDE, SUPERSAMPLING
from core.protein.writing import atomic_write

if TYPE_CHECKING:
    from vtkmodules.vtkRenderingCore import vtkRenderer

    from app.editor.features.files import Files
    from app.editor.features.menus import Menus
    from app.editor.scene.view import View

MAX_PIXELS = 2**25
"""Most pixels of an image: 8K UHD (7680 x 4320) fits; it takes about 2 GiB of memory to render
with software OpenGL."""
DIALOG_SUPERSAMPLING = 2
"""The dialog's first choice of supersampling."""


def check_image_size(width: int, height: int, supersample: int = 1) -> None:
    """Raise ValueError, saying why, for an image size or supersampling the export refuses."""
    for name, value in (("width", width), ("height", height)):
        if not _whole(value) or not IMAGE_SIDE[0] <= value <= IMAGE_SIDE[1]:
            raise ValueError(f"{name} must be a whole number of pixels in [{IMAGE_SIDE[0]}, {IMAGE_SIDE[1]}]; "
                             f"got {value!r}")
    if not _whole(supersample) or supersample not in SUPERSAMPLING:
        raise ValueError(f"supersampling must be one of {', '.join(map(str, SUPERSAMPLING))}; got {supersample!r}")
    if width * height > MAX_PIXELS:
        raise ValueError(f"{width} x {height} is {width * height / 1e6:.0f} million pixels; at most "
                         f"{MAX_PIXELS / 1e6:.1f} million (7680 x 4320, 8K UHD, takes about 2 GiB of memory)")


def image_size(plotter: View, width: int | None = None, height: int | None = None) -> tuple[int, int]:
    """``width`` x ``height`` pixels, a missing one following the view's aspect ratio (both
    missing: the view's size)."""
    view_width, view_height = plotter.window_size
    if width is None and height is None:
        return view_width, view_height
    if height is None:
        return width, max(1, round(width * view_height / view_width))
    if width is None:
        return max(1, round(height * view_width / view_height)), height
    return width, height


def render_view(plotter: View, width: int, height: int, supersample: int = 1, transparent: bool = False) -> QImage:
    """The 3D view rendered now at ``width`` x ``height`` pixels, the mean of ``supersample`` x
    ``supersample`` frames shifted over a grid inside the pixel; with ``transparent``, nothing
    behind the scene (alpha 0). Raises ValueError for a size :func:`check_image_size` refuses."""
    check_image_size(width, height, supersample)
    renderer, camera = plotter.renderer, plotter.camera
    centre = camera.GetWindowCenter()
    offsets = [(k + 0.5) / supersample - 0.5 for k in range(supersample)]  # pixels, about the pixel's centre
    total = np.zeros((height, width, 4 if transparent else 3), dtype=np.uint16)  # 16 frames of 255 fit
    # FXAA smooths a plain 1x image; it would blur a supersampled one, and blend the black of
    # a transparent background into the edges of what stands in front of it
    plotter.capturing.emit()  # the scene in full detail first (it turns FXAA back on)
    renderer.SetUseFXAA(supersample == 1 and not transparent)
    try:
        with plotter.window_size_context((width, height)), _on_nothing(renderer) if transparent else nullcontext():
            for dx in offsets:
                for dy in offsets:
                    camera.SetWindowCenter(centre[0] + 2 * dx / width, centre[1] + 2 * dy / height)
                    total += plotter.screenshot(return_img=True, transparent_background=transparent)
    finally:
        camera.SetWindowCenter(*centre)
        renderer.SetUseFXAA(True)  # the view's still frames are smoothed
    frames = supersample**2
    return _image(((total + frames // 2) // frames).astype(np.uint8))


def export_view(plotter: View, path: Path, width: int | None = None, height: int | None = None, *,
                supersample: int = 1, transparent: bool = False, overwrite: bool = False) -> Path:
    """Save the 3D view as a PNG image (size by :func:`image_size`, see :func:`render_view`),
    atomically; an existing file only with ``overwrite`` (else FileExistsError)."""
    path = Path(path)
    write_png(render_view(plotter, *image_size(plotter, width, height), supersample, transparent), path,
              overwrite=overwrite)
    return path


def write_png(image: QImage, path: Path, *, overwrite: bool = False) -> None:
    """Write ``image`` as PNG the way structures are written: to a temporary file beside
    ``path``, then renamed onto it (never through a link); an existing ``path`` only with
    ``overwrite`` (else FileExistsError)."""
    if not overwrite and (path.exists() or path.is_symlink()):
        raise FileExistsError(f"{path}: refusing to overwrite an existing file")
    data = QByteArray()
    buffer = QBuffer(data)
    buffer.open(QIODevice.OpenModeFlag.WriteOnly)
    if not image.save(buffer, "PNG"):
        raise OSError(f"{path}: cannot encode the image")
    atomic_write(path, bytes(data))


class ExportImageDialog(QDialog):
    """File ▸ Export Image: the size (the view's at first, its aspect ratio kept unless
    unticked), the supersampling, a transparent background and the file. Save asks before
    it replaces a file, writes the image and closes; a problem keeps the dialog open."""

    def __init__(self, plotter: View, path: Path, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export Image")
        self.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        self._plotter = plotter
        width, height = plotter.window_size
        self._aspect = width / height
        self.width_box, self.height_box = self._side_box(width), self._side_box(height)
        self.keep_aspect = QCheckBox("Keep the aspect ratio")
        self.keep_aspect.setChecked(True)
        self.supersampling = QComboBox()
        for factor in SUPERSAMPLING:
            self.supersampling.addItem("none" if factor == 1 else f"{factor}×", factor)
        self.supersampling.setCurrentIndex(SUPERSAMPLING.index(DIALOG_SUPERSAMPLING))
        self.supersampling.setToolTip("The mean of N × N renderings, each shifted within the pixel: smooth edges")
        self.transparent = QCheckBox("Transparent background")
        self.file = QLineEdit(str(path))
        self.file.setMinimumWidth(self.file.fontMetrics().averageCharWidth() * 48)
        self.browse = QPushButton("Browse…")
        self.browse.clicked.connect(self._browse)
        self.problem = QLabel()
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #b00020")
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Save | QDialogButtonBox.StandardButton.Cancel)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)

        file_row = QHBoxLayout()
        file_row.addWidget(self.file)
        file_row.addWidget(self.browse)
        form = QFormLayout(self)
        form.addRow("Width", self.width_box)
        form.addRow("Height", self.height_box)
        form.addRow("", self.keep_aspect)
        form.addRow("Supersampling", self.supersampling)
        form.addRow("", self.transparent)
        form.addRow("File", file_row)
        form.addRow(self.problem)
        form.addRow(self.buttons)

        self.width_box.valueChanged.connect(lambda value: self._follow(self.height_box, value / self._aspect))
        self.height_box.valueChanged.connect(lambda value: self._follow(self.width_box, value * self._aspect))
        self.keep_aspect.toggled.connect(self._lock_aspect)
        for signal in (self.width_box.valueChanged, self.height_box.valueChanged,
                       self.supersampling.currentIndexChanged, self.file.textChanged):
            signal.connect(self._check)
        self._check()

    def path(self) -> Path:
        """The file chosen, ``.png`` added when it has no such ending."""
        name = self.file.text().strip()
        return Path(name if name.lower().endswith(".png") else name + ".png")

    def accept(self) -> None:
        """Ask before replacing a file, then write the image; close unless that failed."""
        if not self.buttons.button(QDialogButtonBox.StandardButton.Save).isEnabled():
            return  # Return in a field while the choices have a problem
        path = self.path()
        yes, no = QMessageBox.StandardButton.Yes, QMessageBox.StandardButton.No
        if (path.exists() or path.is_symlink()) and QMessageBox.question(
                self, self.windowTitle(), f"{path.name} exists. Replace it?", yes | no) != yes:
            return
        QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)  # a large supersampled image takes seconds
        try:
            export_view(self._plotter, path, self.width_box.value(), self.height_box.value(),
                        supersample=self.supersampling.currentData(), transparent=self.transparent.isChecked(),
                        overwrite=True)
        except (OSError, ValueError) as error:
            reason = getattr(error, "strerror", None) or error
            QMessageBox.critical(self, self.windowTitle(), f"cannot write {path}: {reason}")
            return
        finally:
            QApplication.restoreOverrideCursor()
        super().accept()

    @staticmethod
    def _side_box(value: int) -> QSpinBox:
        """A box for a side that takes any size typed (Qt's would drop the digit that takes it
        out of range: 20000 became 2000); :meth:`_check` says which it refuses."""
        box = QSpinBox()
        box.setRange(IMAGE_SIDE[0], 2**31 - 1)
        box.setSuffix(" px")
        box.setValue(value)
        return box

    def _follow(self, box: QSpinBox, value: float) -> None:
        """With the aspect ratio kept, set the other side to ``value`` (rounded)."""
        if self.keep_aspect.isChecked():
            with QSignalBlocker(box):
                box.setValue(max(1, round(value)))

    def _lock_aspect(self, kept: bool) -> None:
        if kept:
            self._aspect = self.width_box.value() / self.height_box.value()

    def _browse(self) -> None:
        name, _ = QFileDialog.getSaveFileName(self, self.windowTitle(), str(self.path()), "PNG image (*.png)",
                                              options=QFileDialog.Option.DontConfirmOverwrite)  # Save asks
        if name:
            self.file.setText(name)

    def _check(self) -> None:
        """Say what is wrong with the choices, and allow Save only without a problem."""
        try:
            check_image_size(self.width_box.value(), self.height_box.value(), self.supersampling.currentData())
            problem = "" if self.file.text().strip() else "Choose a file."
        except ValueError as error:
            problem = str(error)[:1].upper() + str(error)[1:] + "."
        self.problem.setText(problem)
        if self.problem.isVisibleTo(self) != bool(problem):
            self.problem.setVisible(bool(problem))
            self.adjustSize()  # room for the message, or none left over
        self.buttons.button(QDialogButtonBox.StandardButton.Save).setEnabled(not problem)


class ImageExport:
    """File ▸ Export Image of ``window``'s 3D view ``plotter``, named after the structure by
    ``files``, and screenshots of the whole window."""

    def __init__(self, window: QMainWindow, plotter: View, files: Files, menus: Menus) -> None:
        self.window = window
        self.plotter = plotter
        self.files = files
        self.export_action = menus.action("&Export Image…", QKeySequence("Ctrl+E"), self.export_image_dialog)
        menus.add("save", self.export_action)

    def export_image_dialog(self) -> ExportImageDialog:
        """File ▸ Export Image: the dialog of size, supersampling and background, shown (not waited for)."""
        dialog = ExportImageDialog(self.plotter, self.files.suggested(".png"), self.window)
        dialog.open()
        return dialog

    def save_screenshot(self, path: Path, *, overwrite: bool = False) -> None:
        """Render the window, 3D view included, to a PNG image, atomically (raises OSError, or
        FileExistsError for an existing file unless ``overwrite``)."""
        write_png(self.grab_window(), Path(path), overwrite=overwrite)

    def grab_window(self) -> QImage:
        """An image of the whole window with the freshly rendered 3D view painted in."""
        image = self.window.grab().toImage()
        view = render_view(self.plotter, *self.plotter.window_size)
        painter = QPainter(image)
        corner = self.plotter.mapTo(self.window, QPoint(0, 0))
        painter.drawImage(corner, view.scaled(self.plotter.size()))
        painter.end()
        return image


@contextmanager
def _on_nothing(renderer: vtkRenderer) -> Iterator[None]:
    """Render on black of zero alpha: colours then come out premultiplied by their alpha."""
    background, alpha = renderer.GetBackground(), renderer.GetBackgroundAlpha()
    gradient = renderer.GetGradientBackground()
    renderer.SetBackground(0.0, 0.0, 0.0)
    renderer.SetGradientBackground(False)
    renderer.SetBackgroundAlpha(0.0)
    try:
        yield
    finally:
        renderer.SetBackground(background)
        renderer.SetGradientBackground(gradient)
        renderer.SetBackgroundAlpha(alpha)


def _whole(value: object) -> bool:
    return isinstance(value, Integral) and not isinstance(value, bool)


def _image(pixels: np.ndarray) -> QImage:
    """An (h, w, 3) RGB or (h, w, 4) premultiplied RGBA uint8 array as an image."""
    pixels = np.ascontiguousarray(pixels)
    height, width, channels = pixels.shape
    kind = QImage.Format.Format_RGB888 if channels == 3 else QImage.Format.Format_RGBA8888_Premultiplied
    return QImage(pixels.data, width, height, channels * width, kind).copy()
