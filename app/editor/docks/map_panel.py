"""The "Map" dock: the open density map, its contour in σ, the radius and colour of its mesh,
its resolution, the live correlation of the edited segment with it and the fit commands.

It reads the :class:`~app.editor.scene.map_mesh.MapMesh` and the
:class:`~app.editor.map_correlation.LiveCorrelation` and changes them only through their mutators.
"""

from __future__ import annotations

from collections.abc import Sequence

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtGui import QAction, QColor
from PySide6.QtWidgets import (
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
NO_MAP = "No map: File ▸ Open Map… reads a CCP4 or MRC map."


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
        self.radius = QDoubleSpinBox()
        self.radius.setRange(*RADIUS_RANGE)
        self.radius.setSuffix(" Å")
        self.radius.setDecimals(0)
        self.radius.setToolTip("The map is drawn within this distance of the view's centre")
        self.colour = QPushButton()
        self.colour.setToolTip("Colour of the map's mesh")
        self.resolution = QDoubleSpinBox()
        self.resolution.setSingleStep(0.5)
        self.resolution.setSuffix(" Å")
        self.resolution.setToolTip("The map's resolution: the model's density is blurred to it for the correlation "
                                   "and the fits")
        self.cc_text = QLabel()
        self.cc_text.setWordWrap(True)
        self.cc_text.setToolTip("Correlation about the mean of the edited segment's heavy atoms, blurred to the "
                                "resolution, with the map around them (updated during drags, ten times a second)")

        sigma_row = QHBoxLayout()
        sigma_row.addWidget(self.slider, 1)
        sigma_row.addWidget(self.sigma_text)
        form = QFormLayout()
        form.addRow(self.file_text)
        form.addRow("Contour", sigma_row)
        form.addRow("Radius", self.radius)
        form.addRow("Colour", self.colour)
        form.addRow("Resolution", self.resolution)
        form.addRow(self.cc_text)
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
        self.colour.clicked.connect(self._choose_colour)
        self.resolution.valueChanged.connect(correlation.set_resolution)
        maps.changed.connect(self.refresh)
        correlation.updated.connect(self._show_correlation)
        self.refresh()

    def refresh(self) -> None:
        """Show the map's state."""
        maps = self.maps
        density = maps.density
        for widget in (self.slider, self.radius, self.colour, self.resolution):
            widget.setEnabled(density is not None)
        with QSignalBlocker(self.slider), QSignalBlocker(self.radius):
            self.slider.setValue(round(maps.sigma * SIGMA_STEPS))
            self.radius.setValue(maps.radius)
        self.colour.setStyleSheet(f"background-color: {QColor(*maps.colour).name()}")
        if density is None:
            self.file_text.setText(NO_MAP)
            self.sigma_text.setText(f"{maps.sigma:.1f} σ")
        else:
            from core.fitting.density import RESOLUTION  # the fitting code loads with the first map

            self.resolution.setRange(*RESOLUTION)
            grid = " × ".join(map(str, density.values.shape))
            self.file_text.setText(f"{maps.path.name}: {grid} grid points")
            self.sigma_text.setText(f"{maps.sigma:.1f} σ ({maps.value:.3g})")
        self._show_correlation()

    def _show_correlation(self) -> None:
        correlation = self.correlation
        with QSignalBlocker(self.resolution):
            self.resolution.setValue(correlation.resolution)  # (set by a script, too)
        if correlation.value is not None:
            self.cc_text.setText(f"Correlation of the edited segment: <b>{correlation.value:.3f}</b>")
        else:
            self.cc_text.setText(correlation.message)

    def _choose_colour(self) -> None:
        colour = QColorDialog.getColor(QColor(*self.maps.colour), self, "Map colour")
        if colour.isValid():
            self.maps.set_colour((colour.red(), colour.green(), colour.blue()))
