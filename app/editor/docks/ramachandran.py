"""The Ramachandran dock: (φ, ψ) of the current segment's residues over the favoured and
allowed regions.

Each residue with both angles is a point (a circle, a triangle for glycine, a square for
proline), red when it lies outside the allowed region of its own class, dark grey
otherwise. An orange ring marks the residues the session's edits moved (atoms not where
the file put them), a blue one the residues of the picked control point. The background
shows the regions of one class, chosen in the panel (general residues by default).
Pointing at a point names it; clicking it emits :attr:`RamachandranPanel.residueActivated`.

The plot follows the document (a new structure, segment or pick) and the
:class:`~app.editor.live_validation.LiveValidation` updates (at most every 100 ms during a
drag), is redrawn at most every :data:`REDRAW_INTERVAL_MS`, and not at all while off
screen. matplotlib's Qt canvas is imported when the panel first comes on screen: an editor
whose dock stays hidden (or behind another dock's tab) never loads it.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QPaintEvent
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QVBoxLayout, QWidget

from app.editor.document import Document
from app.editor.live_validation import LiveValidation
from app.editor.scene.layers.control_points import PICKED_COLOUR
from core.geometry.ramachandran import OUTLIER, RAMACHANDRAN, RAMACHANDRAN_CLASSES, ramachandran_region
from core.geometry.topology import topology
from core.geometry.validation import phi_psi

if TYPE_CHECKING:
    from matplotlib.backend_bases import MouseEvent
    from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg

REDRAW_INTERVAL_MS = 100
"""Shortest time between two redraws."""
PICK_PIXELS = 5
"""How near (pixels) the pointer must be to a point to name or click it."""
REGION_COLOURS = ("#bcdcae", "#e8f3e1", "#ffffff")
"""Background of the favoured, allowed and outlier cells (indexed by region code)."""
POINT_COLOUR = "#3a3a3a"
OUTLIER_COLOUR = "#d62728"
MOVED_COLOUR = "#ff8c00"
PICKED_HEX = "#{:02x}{:02x}{:02x}".format(*PICKED_COLOUR)
"""The picked control point's colour in the 3D view."""
MARGINS = (0.52, 0.12, 0.1, 0.44)
"""Inches left, right, above and below the axes, for the tick and axis labels (a layout
engine would measure them at every redraw: half of its cost)."""
MARKERS = ("o", "^", "s")
"""Marker of each class of :data:`~core.geometry.ramachandran.RAMACHANDRAN_CLASSES`."""
CAPTION = (
    f"<span style='color:{OUTLIER_COLOUR}'>●</span> outlier &nbsp;"
    f"<span style='color:{POINT_COLOUR}'>●</span> allowed &nbsp;"
    f"<span style='color:{MOVED_COLOUR}'>◯</span> moved &nbsp;"
    f"<span style='color:{PICKED_HEX}'>◯</span> picked<br>"
    "● general ▲ Gly ■ Pro, each judged by its class; background: "
    f"<span style='background:{REGION_COLOURS[0]}'>&nbsp;favoured&nbsp;</span> "
    f"<span style='background:{REGION_COLOURS[1]}'>&nbsp;allowed&nbsp;</span>"
)
HINT = "Point at a residue to name it."


class Points(NamedTuple):
    """The plotted residues of a segment: those whose φ and ψ are both defined."""

    residues: np.ndarray
    """Indices within the segment."""
    rows: np.ndarray
    """Residue-table rows."""
    labels: tuple[str, ...]
    phi: np.ndarray
    """Degrees."""
    psi: np.ndarray
    """Degrees."""
    kind: np.ndarray
    """Index into RAMACHANDRAN_CLASSES."""
    outlier: np.ndarray
    """Outside the allowed region of the residue's class."""
    moved: np.ndarray
    """Some atom of the residue differs from the structure as read."""
    picked: np.ndarray
    """Among the residues of the picked control point."""


def segment_points(document: Document) -> Points:
    """The Ramachandran points of the document's current segment, at its current coordinates."""
    structure, coords = document.structure, document.model.coords
    segment = structure.segments[document.segment]
    phi, psi = phi_psi(structure, coords, segment.residue_index)
    residues = np.flatnonzero(np.isfinite(phi) & np.isfinite(psi))
    rows = segment.residue_index[residues]
    phi, psi = phi[residues], psi[residues]
    kind = topology(structure).rama_class[rows]
    owners = structure.atom_residue[np.any(coords != structure.coords, axis=1)]
    moved = np.zeros(structure.n_residues, dtype=bool)
    moved[owners[owners >= 0]] = True
    pick = document.pick
    picked = np.isin(residues, pick.residues) if pick is not None else np.zeros(len(residues), dtype=bool)
    labels = tuple(segment.labels[i] for i in residues)
    return Points(residues, rows, labels, phi, psi, kind, ramachandran_region(phi, psi, kind) == OUTLIER,
                  moved[rows], picked)


class RamachandranPanel(QWidget):
    """The Ramachandran plot of the current segment (see the module docstring)."""

    residueActivated = Signal(int)
    """A point was clicked: the residue-table row of its residue."""

    def __init__(self, document: Document, validation: LiveValidation, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.document = document
        self.points: Points | None = None
        """What the plot shows (None before the first redraw and without a structure)."""
        self.redraws = 0
        """Redraws so far."""
        self.canvas: FigureCanvasQTAgg | None = None
        """The matplotlib canvas, made when the panel first comes on screen."""
        self._stale = True
        self._last = -np.inf  # time.perf_counter() of the last redraw
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)  # a coarse timer may fire 5% early
        self._timer.timeout.connect(self._redraw)
        self.regions = QComboBox()
        self.regions.addItems([name.capitalize() for name in RAMACHANDRAN_CLASSES])
        self.regions.setToolTip("Whose favoured and allowed regions fill the background")
        self.regions.currentIndexChanged.connect(self._show_regions)
        self.counts = QLabel()
        self.hover = QLabel(HINT)
        caption = QLabel(CAPTION)
        caption.setWordWrap(True)
        top = QHBoxLayout()
        top.addWidget(QLabel("Regions of"))
        top.addWidget(self.regions)
        top.addStretch(1)
        top.addWidget(self.counts)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(self.hover)
        layout.addWidget(caption)
        for signal in (document.loaded, document.segmentChanged, document.picked, validation.updated):
            signal.connect(self.refresh)

    def refresh(self) -> None:
        """Redraw: at once if the last redraw is :data:`REDRAW_INTERVAL_MS` old, else when it
        is; while off screen, once the panel comes on screen."""
        self._stale = True
        if not self.on_screen() or self._timer.isActive():
            return
        wait = REDRAW_INTERVAL_MS - 1e3 * (time.perf_counter() - self._last)
        if wait <= 0:
            self._redraw()
        else:
            self._timer.start(int(wait) + 1)

    def on_screen(self) -> bool:
        """Whether some of the panel is on screen. A dock behind another's tab is moved off
        screen, not hidden (Qt 6.11): it is "visible", with nothing of it to see."""
        return self.isVisible() and not self.visibleRegion().isEmpty()

    def paintEvent(self, event: QPaintEvent) -> None:  # noqa: N802 (Qt override)
        """Once painted (the panel came on screen), redraw what changed meanwhile, and make
        the plot the first time, from the event loop (not inside the paint)."""
        super().paintEvent(event)
        if self._stale and not self._timer.isActive():
            self._timer.start(0)

    def _make_plot(self) -> None:
        from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
        from matplotlib.colors import to_rgba_array
        from matplotlib.figure import Figure

        figure = Figure(figsize=(3.2, 3.2), facecolor=self.palette().window().color().name())
        self.canvas = FigureCanvasQTAgg(figure)
        self.canvas.setMinimumSize(200, 200)
        axes = self.axes = figure.add_subplot()
        self._region_images = to_rgba_array(REGION_COLOURS)[RAMACHANDRAN]  # (classes, 18, 18, 4)
        self._point_colours = to_rgba_array([POINT_COLOUR, OUTLIER_COLOUR])
        self._background = axes.imshow(self._region_images[self.regions.currentIndex()], extent=(-180, 180, -180, 180),
                                       interpolation="nearest", zorder=0)
        ticks = np.arange(-180, 181, 60)
        axes.set(xlim=(-180, 180), ylim=(-180, 180), xticks=ticks, yticks=ticks, aspect="equal")
        axes.set_xlabel("φ (°)", fontsize=9)
        axes.set_ylabel("ψ (°)", fontsize=9, labelpad=0)
        axes.tick_params(labelsize=8)
        axes.grid(color="white", linewidth=0.6)
        axes.set_axisbelow(False)  # the grid over the background, under the points
        self.scatters = [axes.scatter([], [], s=18, marker=marker, linewidths=0, zorder=3) for marker in MARKERS]
        """One collection per class of RAMACHANDRAN_CLASSES."""
        self.moved_rings = axes.scatter([], [], s=60, facecolors="none", edgecolors=MOVED_COLOUR, linewidths=1.2,
                                        zorder=4)
        self.picked_rings = axes.scatter([], [], s=110, facecolors="none", edgecolors=PICKED_HEX, linewidths=1.2,
                                         zorder=5)
        self._place_axes()
        self.canvas.mpl_connect("resize_event", lambda _: self._place_axes())
        self.canvas.mpl_connect("button_press_event", self._on_press)
        self.canvas.mpl_connect("motion_notify_event", self._on_motion)
        self.layout().insertWidget(1, self.canvas, 1)

    def _redraw(self) -> None:
        self._timer.stop()
        if not self.on_screen():
            return
        if self.canvas is None:
            self._make_plot()
        self._stale = False
        self._last = time.perf_counter()
        self.redraws += 1
        points = self.points = segment_points(self.document) if self.document.editable else None
        if points is None:
            empty = np.empty((0, 2))
            for collection in (*self.scatters, self.moved_rings, self.picked_rings):
                collection.set_offsets(empty)
            self.counts.setText("no structure")
        else:
            xy = np.column_stack([points.phi, points.psi])
            colours = self._point_colours[points.outlier.astype(int)]
            for kind, collection in enumerate(self.scatters):
                mine = points.kind == kind
                collection.set_offsets(xy[mine])
                collection.set_facecolors(colours[mine])
            self.moved_rings.set_offsets(xy[points.moved])
            self.picked_rings.set_offsets(xy[points.picked])
            self.counts.setText(f"{len(xy)} residues, {int(points.outlier.sum())} outliers, "
                                f"{int(points.moved.sum())} moved")
        self.canvas.draw_idle()

    def _place_axes(self) -> None:
        """The axes in the figure less the margins (a square in the middle: equal aspect)."""
        width, height = self.canvas.figure.get_size_inches()
        left, right, top, bottom = MARGINS
        self.axes.set_position((left / width, bottom / height, max(1 - (left + right) / width, 0.05),
                                max(1 - (top + bottom) / height, 0.05)))

    def _show_regions(self, kind: int) -> None:
        if self.canvas is not None:
            self._background.set_data(self._region_images[kind])
            self.canvas.draw_idle()

    def _nearest(self, event: MouseEvent) -> int | None:
        """The point (index into :attr:`points`) within PICK_PIXELS of the event, if any."""
        points = self.points
        if points is None or len(points.phi) == 0:
            return None
        xy = self.axes.transData.transform(np.column_stack([points.phi, points.psi]))
        distance = np.hypot(xy[:, 0] - event.x, xy[:, 1] - event.y)
        k = int(np.argmin(distance))
        return k if distance[k] <= PICK_PIXELS * self.canvas.device_pixel_ratio else None

    def _on_press(self, event: MouseEvent) -> None:
        k = self._nearest(event) if event.button == 1 else None  # MouseButton.LEFT
        if k is not None:
            self.residueActivated.emit(int(self.points.rows[k]))

    def _on_motion(self, event: MouseEvent) -> None:
        k = self._nearest(event)
        points = self.points
        text = "" if k is None else (f"{points.labels[k]}  φ {points.phi[k]:.0f}°, ψ {points.psi[k]:.0f}°"
                                     + (" (outlier)" if points.outlier[k] else ""))
        self.hover.setText(text or HINT)
        self.canvas.setToolTip(text)
