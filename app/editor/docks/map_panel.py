"""The "Map" dock: the open density map, its contour in σ, the radius and colour of its mesh
(or the whole map), its resolution and where that comes from, the live correlation of the
edited segment with it, its judgement (CC_mask, CC_box, the residues outside the density)
and the fit commands. A typed value out of range is refused with a message, not clipped.

It reads the :class:`~app.editor.scene.map_mesh.MapMesh` and the
:class:`~app.editor.map_correlation.LiveCorrelation` and changes them only through their mutators.
"""

from __future__ import annotations

from collections.abc import Sequence

from PySide6.QtCore import QSignalBlocker, Qt, Signal
from PySide6.QtGui import QAction, QColor, QValidator
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.editor.map_correlation import LiveCorrelation
from app.editor.scene.map_mesh import MapMesh

SIGMA_RANGE = (0.2, 5.0)
"""The contour slider's range, σ."""
SIGMA_STEPS = 10
"""Slider positions per σ."""
RADIUS_RANGE = (3.0, 40.0)
"""Å around the view's centre."""
NO_MAP = "No map: File ▸ Open Map… reads a CCP4 or MRC map, or an MTZ file's map coefficients."


class StrictSpinBox(QDoubleSpinBox):
    """A spin box that refuses a typed value out of its range (:attr:`refused` says which),
    keeping its value, where Qt's would clip it silently. A typed value takes effect on
    Enter (or when the box loses focus), not digit by digit."""

    refused = Signal(str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setKeyboardTracking(False)

    def validate(self, text: str, position: int) -> object:  # noqa: D102 (Qt override)
        state, text, position = super().validate(text, position)
        if state == QValidator.State.Invalid and _number(text.removesuffix(self.suffix())) is not None:
            state = QValidator.State.Intermediate  # a number out of range: typed, then refused on Enter
        return state, text, position

    def fixup(self, text: str) -> str:  # noqa: D102 (Qt override: called with an unacceptable input)
        unit = self.suffix().strip()
        typed = text.removesuffix(self.suffix()).strip()
        if typed:
            self.refused.emit(f"{typed} {unit} is out of range ({self.minimum():g}–{self.maximum():g} {unit}): "
                              f"kept {self.value():g} {unit}")
        return self.textFromValue(self.value()) + self.suffix()


def _number(text: str) -> float | None:
    try:
        return float(text.strip())
    except ValueError:
        return None


class MapPanel(QWidget):
    """The dock's widget; ``actions`` (the fit commands) get buttons under the correlation."""

    def __init__(self, maps: MapMesh, correlation: LiveCorrelation, actions: Sequence[QAction] = (),
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.maps = maps
        self.correlation = correlation
        self.file_text = QLabel(NO_MAP)
        self.file_text.setWordWrap(True)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(round(SIGMA_RANGE[0] * SIGMA_STEPS), round(SIGMA_RANGE[1] * SIGMA_STEPS))
        self.slider.setToolTip("Contour level in rms deviations (σ) above the map's mean")
        self.sigma_text = QLabel()
        self.radius = StrictSpinBox()
        self.radius.setRange(*RADIUS_RANGE)
        self.radius.setSuffix(" Å")
        self.radius.setDecimals(0)
        self.radius.setToolTip("The map is drawn within this distance of the view's centre")
        self.colour = QPushButton()
        self.colour.setToolTip("Colour of the map's mesh")
        self.whole = QCheckBox("Whole map")
        self.whole.setToolTip("Contour the whole map (a crystal's map: around the whole model), not only around the "
                              "view's centre")
        self.resolution = StrictSpinBox()
        self.resolution.setSingleStep(0.5)
        self.resolution.setSuffix(" Å")
        self.resolution.setToolTip("The map's resolution: the model's density is blurred to it for the correlation "
                                   "and the fits")
        self.resolution_text = QLabel()
        self.refused_text = QLabel()
        self.refused_text.setWordWrap(True)
        self.refused_text.setStyleSheet("color: #c0392b")
        self.refused_text.hide()
        self.cc_text = QLabel()
        self.cc_text.setWordWrap(True)
        self.quality_text = QLabel()
        self.quality_text.setWordWrap(True)
        self.quality_text.setToolTip("How the edited segment fits the map, as phenix reports a fit: the correlation in "
                                     "a mask around its atoms and over the box; a residue whose atoms sit below 1σ "
                                     "lies outside the density")
        self.cc_text.setToolTip("Correlation about the mean of the edited segment's heavy atoms, blurred to the "
                                "resolution, with the map around them (updated during drags, ten times a second)")

        sigma_row = QHBoxLayout()
        sigma_row.addWidget(self.slider, 1)
        sigma_row.addWidget(self.sigma_text)
        form = QFormLayout()
        form.addRow(self.file_text)
        form.addRow("Contour", sigma_row)
        form.addRow("Radius", self.radius)
        form.addRow("", self.whole)
        form.addRow("Colour", self.colour)
        form.addRow("Resolution", self.resolution)
        form.addRow("", self.resolution_text)
        form.addRow(self.refused_text)
        form.addRow(self.cc_text)
        form.addRow(self.quality_text)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        for action in actions:
            button = QToolButton()
            button.setDefaultAction(action)
            button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
            layout.addWidget(button)
        layout.addStretch(1)

        self.slider.valueChanged.connect(lambda value: maps.set_sigma(value / SIGMA_STEPS))
        self.radius.valueChanged.connect(maps.set_radius)
        self.whole.toggled.connect(maps.set_whole)
        for box in (self.radius, self.resolution):
            box.refused.connect(self._refused)
            box.valueChanged.connect(self.refused_text.hide)
        self.colour.clicked.connect(self._choose_colour)
        self.resolution.valueChanged.connect(correlation.set_resolution)
        maps.changed.connect(self.refresh)
        correlation.updated.connect(self._show_correlation)
        correlation.judged.connect(self._show_quality)
        self.refresh()

    def refresh(self) -> None:
        """Show the map's state."""
        maps = self.maps
        density = maps.density
        for widget in (self.slider, self.radius, self.whole, self.colour, self.resolution):
            widget.setEnabled(density is not None)
        self.radius.setEnabled(density is not None and not maps.whole)
        with QSignalBlocker(self.slider), QSignalBlocker(self.radius), QSignalBlocker(self.whole):
            self.slider.setValue(round(maps.sigma * SIGMA_STEPS))
            self.radius.setValue(maps.radius)
            self.whole.setChecked(maps.whole)
        self.colour.setStyleSheet(f"background-color: {QColor(*maps.colour).name()}")
        if density is None:
            self.file_text.setText(NO_MAP)
            self.sigma_text.setText(f"{maps.sigma:.1f} σ")
        else:
            from core.fitting.map_target import RESOLUTION  # the fitting code loads with the first map

            self.resolution.setRange(*RESOLUTION)
            grid = " × ".join(map(str, density.values.shape))
            kind = ", a crystal's unit cell, repeated" if density.periodic else ""
            text = f"{maps.path.name}: {grid} grid points{kind}"
            if maps.columns is not None:
                (f, phi), difference = maps.columns
                text += f"<br>2mFo−DFc from {f}, {phi}"
                text += (f"; mFo−DFc from {difference[0]}, {difference[1]} at ±3σ (green, red)" if difference
                         else "; no difference map in the file")
            self.file_text.setText(text)
            self.sigma_text.setText(f"{maps.sigma:.1f} σ ({maps.value:.3g})")
        self._show_correlation()

    def _show_correlation(self) -> None:
        correlation = self.correlation
        with QSignalBlocker(self.resolution):
            self.resolution.setValue(correlation.resolution)  # (set by a script, too)
        self.resolution_text.setText(f"<i>{correlation.resolution_source}</i>" if self.maps.density is not None else "")
        if correlation.value is not None:
            self.cc_text.setText(f"Correlation of the edited segment at {correlation.resolution:.3g} Å: "
                                 f"<b>{correlation.value:.3f}</b>")
        else:
            self.cc_text.setText(correlation.message)

    def _show_quality(self) -> None:
        self.quality_text.setText(self.correlation.summary())

    def _refused(self, message: str) -> None:
        self.refused_text.setText(message)
        self.refused_text.show()

    def _choose_colour(self) -> None:
        colour = QColorDialog.getColor(QColor(*self.maps.colour), self, "Map colour")
        if colour.isValid():
            self.maps.set_colour((colour.red(), colour.green(), colour.blue()))
