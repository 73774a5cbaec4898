"""The live correlation of the edited segment with the open map, and its judgement.

The segment's heavy atoms, blurred to the map's resolution, are correlated with the map in
a box around them (:class:`core.fitting.map_target.MapTarget`, built again when the segment,
the map or the resolution changes). Edits (a drag's previews included) ask for a new value;
it is computed between events, at most every :data:`INTERVAL_MS`. Once the edits pause for
:data:`JUDGE_MS` (a drag's previews never: only when it ends), the segment is judged as a modeller judges a fit
(:func:`core.fitting.map_quality.map_quality`: CC_mask, CC_box, each residue's CC, the
residues outside the density).

The resolution is the file's where it gives one (an MTZ's high-resolution limit, a map's
header label), bounded to what the fits take; else :data:`DEFAULT_RESOLUTION`, said to be
a guess until the user sets it.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QObject, Qt, QTimer, Signal

from app.editor.document import Document
from app.editor.scene.map_mesh import MapMesh

if TYPE_CHECKING:
    from core.fitting.map_quality import MapQuality
    from core.fitting.map_target import MapTarget

INTERVAL_MS = 100
"""Shortest time between two correlations."""
JUDGE_MS = 400
"""The edits' pause after which the segment is judged."""
DEFAULT_RESOLUTION = 5.0
"""Å, the map's resolution until it is set."""


class LiveCorrelation(QObject):
    """The map–model correlation (CC) of ``document``'s edited segment with ``maps``' map."""

    updated = Signal()
    """:attr:`value` or :attr:`message` changed."""
    judged = Signal()
    """:attr:`quality` changed."""

    def __init__(self, document: Document, maps: MapMesh) -> None:
        super().__init__(document)
        self.document = document
        self.maps = maps
        self.resolution = DEFAULT_RESOLUTION
        """Å: the model's density is blurred to it (as the fits do)."""
        self.resolution_source = "a guess: set it"
        """Where :attr:`resolution` comes from, for people."""
        self.quality: MapQuality | None = None
        """The segment's fit in the map (see :func:`core.fitting.map_quality.map_quality`), or None."""
        self.value: float | None = None
        """The CC, or None without a map (or where it cannot be computed: see :attr:`message`)."""
        self.message = ""
        self.updates = 0
        """Correlations computed so far."""
        self._target: tuple[tuple, MapTarget | ValueError | None] = ((), None)  # by (structure, segment, map, resolution)
        self._rows = np.empty(0, dtype=np.int64)
        self._occupancy = np.empty(0)
        self._last = -np.inf
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setTimerType(Qt.TimerType.PreciseTimer)
        self._timer.timeout.connect(self.update)
        self._judge_timer = QTimer(self)
        self._judge_timer.setSingleShot(True)
        self._judge_timer.timeout.connect(self.judge)
        for signal in (document.loaded, document.changed, document.segmentChanged, maps.changed):
            signal.connect(self._schedule)
        maps.opened.connect(self._map_opened)

    def set_resolution(self, resolution: float) -> None:
        """The map's resolution, Å (in :data:`core.fitting.map_target.RESOLUTION`, else ValueError)."""
        from core.fitting.map_target import RESOLUTION  # the fitting code loads with the first map

        if not RESOLUTION[0] <= resolution <= RESOLUTION[1]:
            raise ValueError(f"resolution must be in [{RESOLUTION[0]:g}, {RESOLUTION[1]:g}] Å; got {resolution:g}")
        self.resolution, self.resolution_source = float(resolution), "set"
        self.update()
        self._judge_timer.start(JUDGE_MS)

    def judge(self) -> None:
        """Judge the edited segment's fit in the map now (:attr:`quality`; None without one)."""
        from core.fitting.map_quality import map_quality

        self._judge_timer.stop()
        quality, document = None, self.document
        if self.maps.density is not None and document.editable:
            try:
                target = self._segment_target()
            except ValueError:
                target = None
            if target is not None:
                segment = document.structure.segments[document.segment]
                residue = document.structure.atom_residue[self._rows] - int(segment.residue_index[0])
                quality = map_quality(target, document.model.coords[self._rows], residue, len(segment),
                                      self._occupancy)
        self.quality = quality
        self.judged.emit()

    def summary(self) -> str:
        """The judgement in a line for people (empty without one), residues by their labels."""
        if self.quality is None:
            return ""
        document = self.document
        return self.quality.summary(list(document.structure.segments[document.segment].labels))

    def _map_opened(self) -> None:
        from core.fitting.map_target import file_resolution

        given = file_resolution(self.maps.density)
        if given is None:
            self.resolution_source = "not given by the file: set it"
        else:
            self.resolution, self.resolution_source = given

    def update(self) -> None:
        """Correlate now."""
        self._timer.stop()
        self._last = time.perf_counter()
        value, self.message = None, ""
        document = self.document
        if self.maps.density is not None and document.editable:
            try:
                target = self._segment_target()
                value = target.correlation(document.model.coords[self._rows], self._occupancy)
            except ValueError as error:  # a MapError: the map does not overlap the segment
                self.message = str(error)
        self.value = value
        self.updates += 1
        self.updated.emit()

    def _segment_target(self) -> MapTarget:
        """The map around the edited segment (raises MapError where the two do not overlap)."""
        from core.fitting.map_target import (  # (loads with the first map)
            MapTarget,
            heavy_atoms,
            occupancies,
        )

        document = self.document
        key = (document.structure, document.segment, self.maps.density, self.resolution)
        if self._target[0] != key:
            segment = document.structure.segments[document.segment]
            mine = np.zeros(document.structure.n_atoms, dtype=bool)
            for start, stop in zip(segment.atom_start, segment.atom_stop):
                mine[start:stop] = True
            rows = heavy_atoms(document.model)
            self._rows = rows[mine[rows]]
            self._occupancy = occupancies(document.model, self._rows)
            try:
                self._target = (key, MapTarget(self.maps.density, self.resolution, document.model.coords[self._rows]))
            except ValueError as error:  # a MapError
                self._target = (key, error)
        if isinstance(self._target[1], ValueError):
            raise self._target[1]
        return self._target[1]

    def _schedule(self, *_: object) -> None:
        if self.maps.density is None:
            if self.value is not None or self.message:
                self.update()
            if self.quality is not None:
                self.judge()
            return
        if not self._timer.isActive():
            self._timer.start(int(np.ceil(max(0.0, INTERVAL_MS - 1000.0 * (time.perf_counter() - self._last)))))
        if self.document.dragging:  # (judged when the drag ends: 0.1-0.3 s, no pause of the mouse should cost it)
            self._judge_timer.stop()
        else:
            self._judge_timer.start(JUDGE_MS)
