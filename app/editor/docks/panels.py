"""Dock panels: the "ribbon dimension" controls and the display options.

Panels read the document and follow its signals (refreshing inside signal blockers);
they change it only through its mutators. Display options belong to the scene. A
structure that is only viewed (no backbone) leaves the ribbon's controls disabled and
shows its atoms.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtGui import QColor, QPixmap
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.editor.document import Change, Document
from app.editor.scene import molecule
from app.editor.scene.molecule import Colouring
from app.editor.scene.scene import DIM_ABOVE_CHAINS, Layer, Others, Scene
from core.protein.ribbon import RibbonKind

STEPS_PER_LEVEL = 100
"""Slider positions per level: fractional levels in steps of 0.01."""
KIND_NAMES = {RibbonKind.PEPTIDE: "peptide-plane ribbon", RibbonKind.CALPHA: "Cα ribbon"}
BACKBONE_LAYERS = (Layer.CARTOON, Layer.TUBE, Layer.CURVE, Layer.CONTROL_POINTS, Layer.CA_TRACE)
"""Layers drawn from the backbone: nothing to show for a structure that is only viewed."""


class RibbonDimensionPanel(QWidget):
    """The model of an ensemble, multiresolution analysis on/off, the level slider and what the level means."""

    def __init__(self, document: Document, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.document = document
        self.note = QLabel()
        self.note.setWordWrap(True)
        self.model_number = QSpinBox()
        self.model_number.setKeyboardTracking(False)  # a typed model number counts on Enter or focus-out
        self.model_number.setToolTip("Model of the multi-model entry (e.g. an NMR ensemble) shown and edited; "
                                     "can change while there are no edits to undo")
        self.segment = QComboBox()
        self.segment.setToolTip("Backbone segment whose control points are shown and edited")
        self.kind = QComboBox()
        for kind, name in KIND_NAMES.items():
            self.kind.addItem(name, kind)
        self.kind.setToolTip("Curve through peptide-plane centres (Carson's standard ribbon) or through the Cα atoms; "
                             "can change while there are no edits to undo")
        self.analysis = QCheckBox("Multiresolution analysis")
        self.analysis.setToolTip("Off: every segment at full resolution")
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setPageStep(STEPS_PER_LEVEL // 4)
        self.spin = QDoubleSpinBox()
        self.spin.setDecimals(2)
        self.spin.setSingleStep(0.05)
        self.spin.setKeyboardTracking(False)  # a typed level (2.5) counts on Enter or focus-out, not per digit
        self.integers = QCheckBox("Integer levels only")
        self.level_text = QLabel()
        self.segments_text = QLabel()
        self.points_text = QLabel()
        self.rms_text = QLabel()
        self.rms_text.setToolTip("Root-mean-square distance between each Cα and its residue point C^r on the curve "
                                 "of this level (Carson's measure of fit)")
        for label in (self.level_text, self.segments_text, self.points_text, self.rms_text):
            label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)

        slider_row = QHBoxLayout()
        slider_row.addWidget(self.slider, 1)
        slider_row.addWidget(self.spin)
        switches = QHBoxLayout()  # one row for both: the dock keeps its height with the model row shown
        switches.addWidget(self.analysis)
        switches.addWidget(self.integers)
        switches.addStretch(1)
        self.form = form = QFormLayout()
        form.addRow(self.note)
        form.addRow("Model", self.model_number)
        form.addRow("Segment", self.segment)
        form.addRow("Ribbon", self.kind)
        form.addRow(switches)
        form.addRow("Level", slider_row)
        form.addRow("Shown", self.level_text)
        form.addRow("Curve segments", self.segments_text)
        form.addRow("Control points", self.points_text)
        self.points_text.setToolTip("Control points whose basis functions reach a residue are shown; the others "
                                    "only shape the curve beyond the chain's ends")
        form.addRow("rms |Cα − C^r|", self.rms_text)
        form.setRowVisible(self.note, False)  # instead of the figures, for a structure that is only viewed
        form.setRowVisible(self.model_number, False)  # for a multi-model entry
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addStretch(1)

        self.model_number.valueChanged.connect(self._model_chosen)
        self.segment.currentIndexChanged.connect(self._segment_chosen)
        self.kind.currentIndexChanged.connect(self._kind_chosen)
        self.analysis.toggled.connect(document.set_multiresolution)
        self.slider.valueChanged.connect(self._slider_moved)
        self.spin.valueChanged.connect(self._set_level)
        self.integers.toggled.connect(self._integers_toggled)
        document.loaded.connect(self._reload)
        document.levelChanged.connect(self.refresh)
        document.segmentChanged.connect(self.refresh)
        document.changed.connect(self._changed)
        document.undo_stack.indexChanged.connect(self._history_moved)
        if document.model is not None:
            self._reload()

    def _reload(self) -> None:
        document = self.document
        structure = document.structure
        with QSignalBlocker(self.segment), QSignalBlocker(self.kind), QSignalBlocker(self.model_number):
            self.segment.clear()
            self.segment.addItems([segment.summary for segment in structure.segments])
            self.kind.setCurrentIndex(self.kind.findData(document.kind))
            self.model_number.setRange(1, structure.n_models)
            self.model_number.setSuffix(f" of {structure.n_models}")
            self.model_number.setValue(document.model_number)
        self.form.setRowVisible(self.model_number, structure.n_models > 1)
        self.note.setText(document.read_only_reason)
        self.form.setRowVisible(self.note, not document.editable)
        for label in (self.level_text, self.segments_text, self.points_text, self.rms_text):
            self.form.setRowVisible(label, document.editable)
        self.segment.setEnabled(self.segment.count() > 1)
        for widget in (self.kind, self.analysis, self.slider, self.spin, self.integers):
            widget.setEnabled(document.editable)
        self._history_moved(document.undo_stack.index())
        self.refresh()

    def refresh(self) -> None:
        """Show the document's level, segment and the figures of the shown curve."""
        document = self.document
        if not document.editable:
            return
        top = document.max_level
        level = document.shown_level()
        with QSignalBlocker(self.slider), QSignalBlocker(self.spin), QSignalBlocker(self.segment), \
                QSignalBlocker(self.analysis):
            self.segment.setCurrentIndex(document.segment)
            self.analysis.setChecked(document.multiresolution)
            self.slider.setRange(0, round(top * STEPS_PER_LEVEL))
            self.slider.setValue(round(level * STEPS_PER_LEVEL))
            self.spin.setRange(0.0, top)
            self.spin.setValue(level)
        for widget in (self.slider, self.spin, self.integers):
            widget.setEnabled(document.multiresolution)
        curve = document.level_curve()
        fraction = 2.0**level / len(document.structure.segments[document.segment])
        self.level_text.setText(f"{level:.2f} of {top:.2f} (log₂ N); about {min(fraction, 1.0):.0%} of the detail")
        self.segments_text.setText(f"{2**level:.1f} effective, on 2^{curve.level} = {curve.n_segments}")
        self.points_text.setText(f"{int(curve.visible.sum())} shown of {len(curve.control_points)}")
        self.rms_text.setText(f"{document.deviation():.2f} Å")

    def _model_chosen(self, number: int) -> None:
        self.document.set_model_number(number)

    def _segment_chosen(self, index: int) -> None:
        if index >= 0:
            self.document.set_segment(index)

    def _kind_chosen(self) -> None:
        self.document.set_kind(self.kind.currentData())

    def _slider_moved(self, value: int) -> None:
        top = value == self.slider.maximum()  # the end of the slider is the original curve, log2 N exactly
        self._set_level(self.document.max_level if top else value / STEPS_PER_LEVEL)

    def _changed(self, change: Change) -> None:
        if change.segment == self.document.segment:
            self.refresh()

    def _history_moved(self, index: int) -> None:
        """The ribbon kind and the model can change while there are no edits to undo."""
        self.kind.setEnabled(index == 0 and self.document.editable)
        self.model_number.setEnabled(index == 0)

    def _set_level(self, level: float) -> None:
        if self.integers.isChecked():
            level = self._integer_stop(level)
        before = self.document.level
        self.document.set_level(level)
        if self.document.level == before:
            self.refresh()  # no signal came: snap the widgets back to the document's level

    def _integer_stop(self, level: float) -> float:
        """The nearest of the integer levels 0, 1, ..., ⌊log2 N⌋ and log2 N (full resolution)."""
        top = self.document.max_level
        stops = np.append(np.arange(math.floor(top) + 1, dtype=float), top)
        return float(stops[np.argmin(np.abs(stops - level))])

    def _integers_toggled(self, on: bool) -> None:
        self.spin.setSingleStep(1.0 if on else 0.05)
        self.slider.setSingleStep(STEPS_PER_LEVEL if on else 1)
        if on:
            self._set_level(self.document.level)


class DisplayPanel(QWidget):
    """Layers, colouring and tube radius, with a legend of the colours."""

    def __init__(self, scene: Scene, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.scene = scene
        layers = QGroupBox("Layers")
        layer_box = QGridLayout(layers)  # three columns, rows close together: the dock fits a laptop's height
        layer_box.setVerticalSpacing(2)
        self.layer_boxes: dict[Layer, QCheckBox] = {}
        for k, layer in enumerate(Layer):
            box = QCheckBox(layer.value[0].upper() + layer.value[1:])
            box.setChecked(layer in scene.layers)
            box.toggled.connect(lambda on, layer=layer: scene.set_layer(layer, on))
            layer_box.addWidget(box, k // 3, k % 3)
            self.layer_boxes[layer] = box
        self.colouring = QComboBox()
        for colouring in Colouring:
            self.colouring.addItem(colouring.value[0].upper() + colouring.value[1:], colouring)
        self.fat = QCheckBox("Fat tube")
        self.fat.setToolTip("The tube's radius by secondary structure: sheet > helix > other")
        self.cylinders = QCheckBox("Helices as cylinders")
        self.cylinders.setToolTip("The cartoon's helices as cylinders along their axes (Carson's Fig. 5), not spiral "
                                  "ribbons")
        self.others = QComboBox()
        for others in Others:
            self.others.addItem(f"Other chains {others.value}", others)
        self.others.setToolTip("How the chains other than the edited one are drawn (dimmed at first in entries "
                               f"of more than {DIM_ABOVE_CHAINS} chains)")
        self.legend = QWidget()
        self.legend_layout = QFormLayout(self.legend)
        self.legend_layout.setContentsMargins(0, 0, 0, 0)
        colours = QGroupBox("Ribbon colours")
        colour_box = QVBoxLayout(colours)
        colour_box.addWidget(self.colouring)
        shapes = QHBoxLayout()
        shapes.addWidget(self.cylinders)
        shapes.addWidget(self.fat)
        colour_box.addLayout(shapes)
        colour_box.addWidget(self.others)
        colour_box.addWidget(self.legend)
        layout = QVBoxLayout(self)
        layout.addWidget(layers)
        layout.addWidget(colours)
        layout.addStretch(1)
        self.colouring.currentIndexChanged.connect(self._colouring_changed)
        self.fat.toggled.connect(scene.set_fat_helices)
        self.cylinders.toggled.connect(scene.set_helix_cylinders)
        self.others.currentIndexChanged.connect(lambda: scene.set_others(self.others.currentData()))
        self.colours = colours
        scene.document.loaded.connect(self._loaded)
        if scene.document.model is not None:
            self._loaded()

    def _loaded(self) -> None:
        """The backbone's layers and colours apply to a structure with a backbone only; one
        without shows its atoms."""
        editable = self.scene.document.editable
        for layer in BACKBONE_LAYERS:
            self.layer_boxes[layer].setEnabled(editable)
        self.colours.setEnabled(editable)
        if not editable:
            self.layer_boxes[Layer.ATOMS].setChecked(True)
        self._update_legend()

    def _colouring_changed(self) -> None:
        self.scene.set_colouring(self.colouring.currentData())
        self._update_legend()

    def _update_legend(self) -> None:
        with QSignalBlocker(self.others):  # a new structure: the scene chose how to draw the other chains
            self.others.setCurrentIndex(self.others.findData(self.scene.others))
        while self.legend_layout.rowCount():
            self.legend_layout.removeRow(0)
        for name, rgb in molecule.legend(self.scene.document.structure, self.scene.colouring):
            swatch = QPixmap(14, 14)
            swatch.fill(QColor(*rgb))
            icon = QLabel()
            icon.setPixmap(swatch)
            self.legend_layout.addRow(icon, QLabel(name))
