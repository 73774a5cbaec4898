"""The surface dock: kind, level, colouring and opacity of the
:class:`~app.editor.surfaces.layer.SurfaceLayer`'s surface, and its figures (the panel only
reads the layer and calls its mutators)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from app.editor.surfaces.layer import KIND_NAMES, SCALARS, SurfaceLayer

if TYPE_CHECKING:
    from core.surfaces.levelled import LevelledSurface

COLOURING_NAMES = {None: "Plain", "potential": "Electrostatic potential", "curvature": "Curvature",
                   "bfactor": "B-factor"}
STEPS_PER_LEVEL = 100
"""Slider positions per level of a spline surface (fractional levels in steps of 0.01)."""


class SurfacePanel(QWidget):
    """The dock: kind, level, colouring and opacity of the surface, and its figures."""

    def __init__(self, layer: SurfaceLayer, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.layer = layer
        self.show_box = QCheckBox("Show surface")
        self.kind = QComboBox()
        for kind, name in KIND_NAMES.items():
            self.kind.addItem(name, kind)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.level_text = QLabel()
        self.colouring = QComboBox()
        for colouring, name in COLOURING_NAMES.items():
            self.colouring.addItem(name, colouring)
        self.opacity = QSlider(Qt.Orientation.Horizontal)
        self.opacity.setRange(0, 100)
        self.opacity.setValue(round(layer.opacity * 100))
        self.figures = QLabel()
        """The figures of the surface shown, the stage of its build, or why it failed. No animated
        "working" bar: with the OpenGL view in the window, each of its frames is composited
        through OpenGL (1.5 of 2 cores with software OpenGL, taken from the build)."""
        self.figures.setWordWrap(True)
        self.stale_text = QLabel("Computed from the atoms before the last edits.")
        self.stale_text.setWordWrap(True)
        self.recompute = QPushButton("Recompute")

        level_row = QHBoxLayout()
        level_row.addWidget(self.slider, 1)
        level_row.addWidget(self.level_text)
        form = QFormLayout()
        form.addRow(self.show_box)
        form.addRow("Kind", self.kind)
        form.addRow("Level", level_row)
        form.addRow("Colour", self.colouring)
        form.addRow("Opacity", self.opacity)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.figures)
        layout.addWidget(self.stale_text)
        layout.addWidget(self.recompute)
        layout.addStretch(1)

        self.show_box.toggled.connect(layer.set_visible)
        self.kind.currentIndexChanged.connect(lambda: layer.set_kind(self.kind.currentData()))
        self.slider.valueChanged.connect(self._slider_moved)
        self.colouring.currentIndexChanged.connect(lambda: layer.set_colouring(self.colouring.currentData()))
        self.opacity.valueChanged.connect(lambda value: layer.set_opacity(value / 100))
        self.recompute.clicked.connect(layer.recompute)
        layer.updated.connect(self.refresh)
        layer.document.loaded.connect(self._loaded)
        self._loaded()

    def _loaded(self) -> None:
        """A new structure: the surface can be shown; the DNA cylinder is offered only where
        there are nucleic acids (for a protein it fails: no axis to cast from)."""
        document = self.layer.document
        nucleic = document.model is not None and bool((document.structure.atoms.category == "nucleic").any())
        item = self.kind.model().item(list(KIND_NAMES).index("dna"))
        item.setEnabled(nucleic)
        item.setToolTip("" if nucleic else "for DNA and RNA: this entry has none")
        if not nucleic and self.layer.kind == "dna":
            self.layer.set_kind("ses")
        self.refresh()

    def refresh(self) -> None:
        """Show the layer's state: the build's stage, level range, figures of the mesh, staleness."""
        layer = self.layer
        built = layer.built
        self.stale_text.setVisible(layer.stale)
        self.recompute.setVisible(layer.stale)
        self.show_box.setEnabled(layer.document.model is not None)
        with QSignalBlocker(self.show_box), QSignalBlocker(self.slider), QSignalBlocker(self.kind), \
                QSignalBlocker(self.colouring):
            self.show_box.setChecked(layer.visible)
            self.kind.setCurrentIndex(list(KIND_NAMES).index(layer.kind))
            self.colouring.setCurrentIndex(list(COLOURING_NAMES).index(layer.colouring))
            if built is not None:
                steps = STEPS_PER_LEVEL if built.surface.fractional else 1
                self.slider.setRange(0, built.surface.max_level * steps)
                self.slider.setValue(round(layer.shown_level() * steps))
        self.slider.setEnabled(built is not None and built.surface.max_level > 0)
        if layer.busy:
            self.figures.setText(f"Building the {KIND_NAMES[layer.kind].lower()}: {layer.stage}…")
        elif built is None:
            self.level_text.setText("")
            self.figures.setText(layer.message or "Not built yet: tick “Show surface”.")
        else:
            self.level_text.setText(f"{layer.shown_level():.2f} of {built.surface.max_level}")
            self.figures.setText("\n".join([*self._figures(built.surface), layer.message]).strip())

    def _figures(self, surface: LevelledSurface) -> list[str]:
        from core.surfaces.levelled import UNITS  # loaded by the build of ``surface``

        layer = self.layer
        lines = []
        if layer.mesh is not None and layer.visible:
            lines.append(f"{layer.mesh.n_cells} triangles, {layer.mesh.n_points} vertices")
        errors = dict(surface.errors)
        level = layer.shown_level()
        if level in errors:
            unit = "rms difference of map values" if surface.kind == "map" else "rms error (Å)"
            lines.append(f"{unit} at this level: {errors[level]:.3f}")
        if layer.visible and layer.colouring is not None and layer.mesh is not None and SCALARS in layer.mesh.point_data:
            low, high = layer.actor.mapper.scalar_range
            lines.append(f"{COLOURING_NAMES[layer.colouring]}: {low:.2f} … {high:.2f} {UNITS[layer.colouring]}")
        return lines

    def _slider_moved(self, value: int) -> None:
        built = self.layer.built
        if built is not None:
            self.layer.set_level(value / (STEPS_PER_LEVEL if built.surface.fractional else 1))
