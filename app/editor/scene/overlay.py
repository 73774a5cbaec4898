"""Structures shown for comparison: superposed on the edited chain, drawn at the same depth.

Each compared structure is read once; one of its chains (the longest unless chosen) is
paired with the document's current chain and superposed on it (:func:`fit_chain`). A chain
of the same protein is paired by numbering or by sequence
(:func:`core.analysis.compare.pair_by_sequence`) and superposed on the paired Cα, refined
on the pairs within :data:`CORE_CUTOFF` (a few loops that moved would pull a fit on all
pairs). A chain of another protein is aligned by structure and given the superposition
that maximises its TM-score (:func:`core.analysis.fold_alignment.align_folds`, as
TM-align does). Either way the fit reports the TM-score of that superposition, normalised
by the edited chain's length: below 0.5 the folds differ, and an rms on the few pairs that
happen to lie close says nothing. Its ribbons are built in the document's ribbon kind and
moved by that motion (a B-spline curve moves with its control points).

Levels: every chain has its own top level log2 N, so the compared chains are shown at the
same *depth* below their top as the edited segment, ``log2 N_k - (log2 N - λ)``, and so
with the same fraction of their detail. They are read-only.

:class:`Comparison` (no widgets) holds them and says what changed; :class:`ComparisonView`
draws each as a thin tube of its own colour and rewrites the tube vertices in place when
the level changes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyvista as pv
from PySide6.QtCore import QObject, Signal
from vtkmodules.util.numpy_support import vtk_to_numpy

from app.editor.document import Document
from app.editor.scene import tube
from app.editor.scene.curves import LevelCurve, SegmentPath
from core.analysis.superpose import MIN_PAIRS, Superposition, fit_closest
from core.protein.input_files import read_bytes
from core.protein.reading import read_structure
from core.protein.ribbon import Ribbon, segment_ribbon
from core.protein.structure import BackboneSegment, Structure

CORE_CUTOFF = 3.0
"""Å: the fit of a chain of the same protein is refined on the paired Cα closer than this
after fitting on themselves."""
SAME_FOLD = 0.5
"""TM-score from which two chains have the same fold (Xu & Zhang 2010: below it, mostly not)."""
PALETTE: tuple[tuple[int, int, int], ...] = (
    (31, 119, 180), (44, 160, 44), (0, 128, 128), (227, 119, 194), (200, 80, 0),
    (170, 0, 120), (60, 60, 160), (188, 189, 34), (150, 70, 40),
)  # fmt: skip
"""Colours of the compared structures, in the order they are added: each at least 60 (RGB
distance) from every colour of the editor (the tube's secondary structure, the curves,
control points, the picked point and the background)."""
TUBE_RADIUS = 0.35
"""Å, the thin tubes of the compared structures."""
TUBE_SIDES = 8


@dataclass(frozen=True)
class ChainFit:
    """A superposition of a compared chain on the edited chain, and how well the two agree.

    Attributes
    ----------
    motion : moves the compared chain onto the edited one.
    pairing : 'numbering' or 'alignment' (the same protein, paired by sequence) or
        'structure' (another protein, aligned by structure); see :func:`fit_chain`.
    length : residues of the edited chain, by which the TM-score is normalised.
    n_pairs : residue pairs (with both Cα).
    cutoff : Å, TM-align's cutoff of the aligned pairs (:func:`~core.analysis.fold_alignment.tm_d8`
        of the shorter chain).
    n_aligned : pairs closer than ``cutoff`` after the motion.
    rms_aligned : rms Cα distance over those pairs after the motion, Å.
    tm_score : TM-score of the pairs after the motion (TM-align's d0 for ``length``).
    """

    motion: Superposition
    pairing: str
    length: int
    n_pairs: int
    cutoff: float
    n_aligned: int
    rms_aligned: float
    tm_score: float

    @property
    def same_fold(self) -> bool:
        """Whether the TM-score says the folds are the same (at least :data:`SAME_FOLD`)."""
        return self.tm_score >= SAME_FOLD


def chain_segments(structure: Structure, chain: str) -> list[BackboneSegment]:
    """The backbone segments of ``chain``, in order (raises ValueError when it has none)."""
    found = [s for s in structure.segments if s.chain == chain]
    if not found:
        raise ValueError(f"{structure.entry_id} has no protein chain {chain!r}; chains: {', '.join(chains(structure))}")
    return found


def chains(structure: Structure) -> list[str]:
    """Chains with backbone segments, longest first (ties in file order)."""
    length: dict[str, int] = {}
    for segment in structure.segments:
        length[segment.chain] = length.get(segment.chain, 0) + len(segment)
    return sorted(length, key=lambda chain: -length[chain])


def fit_chain(fixed_ca: np.ndarray, fixed: Sequence[BackboneSegment], moving: Sequence[BackboneSegment]) -> ChainFit:
    """Superpose the chain ``moving`` on the chain ``fixed``, whose Cα are now at ``fixed_ca``.

    A chain of the same protein (:func:`core.analysis.compare.pair_by_sequence`) is fitted on
    its paired Cα, refined on the pairs within :data:`CORE_CUTOFF`; a chain of another
    protein gets the structural alignment and the superposition of highest TM-score of
    :func:`core.analysis.fold_alignment.align_folds` (so unrelated folds get one too).

    Parameters
    ----------
    fixed_ca : (n_fixed_residues, 3) current Cα of ``fixed`` (edits included), Å.
    fixed, moving : backbone segments of each chain, in order.

    Raises
    ------
    ValueError
        Fewer than 3 residue pairs (chains of fewer than 3 residues).
    """
    # the pairing and the structural alignment load with the first compared structure, not with the editor
    from core.analysis.compare import pair_by_sequence, tm_score
    from core.analysis.fold_alignment import align_folds, tm_d8

    moving_ca = np.concatenate([s.ca for s in moving])
    pairs_a, pairs_b, pairing = pair_by_sequence(fixed, moving)
    if pairing == "structure":
        start = (pairs_a, pairs_b) if len(pairs_a) >= MIN_PAIRS else (None, None)
        alignment = align_folds(fixed_ca, moving_ca, *start)
        pairs_a, pairs_b, motion = alignment.pairs_a, alignment.pairs_b, alignment.motion
    elif len(pairs_a) >= MIN_PAIRS:
        motion, _ = fit_closest(fixed_ca[pairs_a], moving_ca[pairs_b], CORE_CUTOFF)
    else:
        raise ValueError(f"only {len(pairs_a)} residue pair(s) with the edited chain; at least {MIN_PAIRS} are needed")
    distance = np.linalg.norm(fixed_ca[pairs_a] - motion.apply(moving_ca[pairs_b]), axis=1)
    cutoff = tm_d8(min(len(fixed_ca), len(moving_ca)))
    aligned = distance < cutoff
    rms = float(np.sqrt(np.mean(distance[aligned] ** 2))) if aligned.any() else float("nan")
    return ChainFit(motion, pairing, len(fixed_ca), len(distance), cutoff, int(aligned.sum()), rms,
                    tm_score(distance, len(fixed_ca))[0])


@dataclass(eq=False)
class Compared:
    """One compared structure: its chain, its superposition and its moved ribbons."""

    path: Path
    source: bytes
    """The file's bytes as read (sessions embed them)."""
    structure: Structure
    chain: str
    colour: tuple[int, int, int]
    fit: ChainFit
    fitted_to: str
    """The edited structure's chain it was superposed on."""
    ribbons: list[Ribbon]
    paths: list[SegmentPath]
    visible: bool = True
    key: int = field(default=0)
    """Unique among the compared structures of a :class:`Comparison` (names its actor)."""

    @property
    def name(self) -> str:
        return f"{self.structure.entry_id} {self.chain}"


class Comparison(QObject):
    """The structures compared with a :class:`Document`'s current chain (a QObject without widgets).

    Follows the document: a new structure, ribbon kind or chain refits every compared
    structure (keeping the previous fit where the new chain cannot be paired); a structure
    without a backbone, which nothing can be superposed on, drops them.
    """

    changed = Signal()
    """Structures were added or removed, or refitted: everything is new."""
    visibilityChanged = Signal(int)
    """The visibility of the structure at this index changed."""

    def __init__(self, document: Document) -> None:
        super().__init__(document)
        self.document = document
        self.items: list[Compared] = []
        self._keys = 0
        self._chain: str | None = None
        document.loaded.connect(self._refit_all)
        document.segmentChanged.connect(self._segment_changed)

    @property
    def depth(self) -> float:
        """Levels below the top at which the edited segment, and so every compared chain, is shown."""
        return self.document.max_level - self.document.shown_level()

    def level(self, ribbon: Ribbon) -> float:
        """The level at which a compared ``ribbon`` is shown: the same depth below its own log2 N."""
        return float(np.clip(ribbon.max_level - self.depth, 0.0, ribbon.max_level))

    def level_curves(self, index: int) -> list[LevelCurve]:
        """The curves of every segment of compared structure ``index`` at its level."""
        item = self.items[index]
        return [path.level_curve(ribbon, self.level(ribbon)) for ribbon, path in zip(item.ribbons, item.paths)]

    def add(self, path: Path, chain: str | None = None, data: bytes | None = None) -> Compared:
        """Read ``path`` (or its content ``data``), superpose ``chain`` (default: its longest) on the
        edited chain and show it.

        Raises :class:`core.protein.input_files.StructureError` (unreadable file) or ValueError (no such
        chain, no protein, too few residue pairs, no structure open).
        """
        if not self.document.editable:
            raise ValueError(f"{self.document.read_only_reason or 'no structure is open'}: "
                             "there is no chain to compare with")
        data = read_bytes(path) if data is None else data
        structure = read_structure(path, data)
        if not structure.segments:
            raise ValueError(f"{Path(path).name}: no protein chain to compare")
        colour = PALETTE[self._keys % len(PALETTE)]
        self._chain = self.document.structure.segments[self.document.segment].chain
        item = self._fitted(Path(path), data, structure, chain or chains(structure)[0], colour)
        item.key = self._keys
        self._keys += 1
        self.items.append(item)
        self.changed.emit()
        return item

    def set_chain(self, index: int, chain: str) -> None:
        """Compare chain ``chain`` of structure ``index`` instead (raises ValueError as :meth:`add`)."""
        item = self.items[index]
        if chain != item.chain:
            fitted = self._fitted(item.path, item.source, item.structure, chain, item.colour)
            fitted.key, fitted.visible = item.key, item.visible
            self.items[index] = fitted
            self.changed.emit()

    def set_visible(self, index: int, visible: bool) -> None:
        if self.items[index].visible != visible:
            self.items[index].visible = visible
            self.visibilityChanged.emit(index)

    def remove(self, index: int) -> None:
        del self.items[index]
        self.changed.emit()

    # ------------------------------------------------------------------ internals

    def _fitted(self, path: Path, source: bytes, structure: Structure, chain: str, colour: tuple[int, int, int],
                previous: ChainFit | None = None, previous_to: str = "") -> Compared:
        document = self.document
        segments = chain_segments(structure, chain)
        edited = document.structure.segments[document.segment].chain
        try:
            fit, fitted_to = fit_chain(*self._edited_chain(), segments), edited
        except ValueError:
            if previous is None:
                raise
            fit, fitted_to = previous, previous_to
        ribbons = [segment_ribbon(s, document.kind) for s in segments]
        moved = [r.with_points(fit.motion.apply(r.points)) for r in ribbons]
        return Compared(path, source, structure, chain, colour, fit, fitted_to, moved, [SegmentPath(r) for r in moved])

    def _edited_chain(self) -> tuple[np.ndarray, list[BackboneSegment]]:
        document = self.document
        segments = chain_segments(document.structure, document.structure.segments[document.segment].chain)
        rows = np.concatenate([s.residue_index for s in segments])
        return document.model.coords[document.ca_rows[rows]], segments

    def _refit_all(self) -> None:
        if not self.document.editable:
            self.items, self._chain = [], None
            self.changed.emit()
            return
        self._chain = self.document.structure.segments[self.document.segment].chain
        refitted = []
        for item in self.items:
            fitted = self._fitted(item.path, item.source, item.structure, item.chain, item.colour, item.fit, item.fitted_to)
            fitted.key, fitted.visible = item.key, item.visible
            refitted.append(fitted)
        self.items = refitted
        self.changed.emit()

    def _segment_changed(self) -> None:
        if self.document.structure.segments[self.document.segment].chain != self._chain:
            self._refit_all()


class ComparisonView(QObject):
    """Draws the compared structures of a :class:`Comparison` as thin tubes into a plotter."""

    def __init__(self, comparison: Comparison, plotter: pv.BasePlotter) -> None:
        super().__init__(comparison)
        self.comparison = comparison
        self.plotter = plotter
        self.meshes: dict[int, pv.PolyData] = {}
        """Tube mesh of each compared structure, by its key."""
        self.actors: dict[int, pv.Actor] = {}
        comparison.changed.connect(self._rebuild)
        comparison.visibilityChanged.connect(self._show)
        comparison.document.levelChanged.connect(self._update)  # a new segment changes the level too

    def actor_name(self, item: Compared) -> str:
        """Name of the plotter actor of ``item``'s tube."""
        return f"compared_{item.key}"

    def _rebuild(self) -> None:
        for key in list(self.actors):
            self.plotter.remove_actor(self.actors.pop(key), render=False)
        self.meshes.clear()
        for index, item in enumerate(self.comparison.items):
            rings = [len(path.curve_u) for path in item.paths]
            start = np.cumsum([0] + rings) * TUBE_SIDES
            faces = np.vstack([tube.tube_faces(n, TUBE_SIDES, first) for n, first in zip(rings, start)])
            mesh = pv.PolyData(np.zeros((start[-1], 3)), faces=np.column_stack([np.full(len(faces), 4), faces]).ravel())
            mesh.point_data["Normals"] = np.zeros((start[-1], 3))
            mesh.point_data.active_normals_name = "Normals"
            self.meshes[item.key] = mesh
            self._sweep(index)
            self.actors[item.key] = self.plotter.add_mesh(
                mesh, name=self.actor_name(item), color=item.colour, reset_camera=False, pickable=False,
                smooth_shading=False, render=False, interpolation="phong", specular=0.3, specular_power=20.0,
            )
            self.actors[item.key].SetVisibility(item.visible)
        self.plotter.render()

    def _update(self) -> None:
        for index in range(len(self.comparison.items)):
            self._sweep(index)
        self.plotter.render()

    def _show(self, index: int) -> None:
        item = self.comparison.items[index]
        self.actors[item.key].SetVisibility(item.visible)
        self.plotter.render()

    def _sweep(self, index: int) -> None:
        """Rewrite the tube of compared structure ``index`` around its curves at the current level."""
        curves = self.comparison.level_curves(index)
        points, normals = [], []
        for curve in curves:
            tangents = _tangents(curve.samples)
            ring_points, radial = tube.ring_vertices(curve.samples, tangents, tube.transported_normals(tangents),
                                                     np.full(len(tangents), TUBE_RADIUS), TUBE_SIDES)
            points.append(ring_points)
            normals.append(radial)
        mesh = self.meshes[self.comparison.items[index].key]
        arrays = (mesh.GetPoints().GetData(), mesh.GetPointData().GetArray("Normals"))
        for target, values in zip(arrays, (points, normals)):
            vtk_to_numpy(target)[:] = np.vstack(values)
            target.Modified()
        mesh.Modified()


def _tangents(samples: np.ndarray) -> np.ndarray:
    """Unit tangents (n, 3) of a sampled curve (n, 3) by central differences; where samples
    coincide (the clipped ends of a ribbon) the nearest defined tangent is used."""
    step = np.gradient(samples, axis=0)
    length = np.linalg.norm(step, axis=1)
    defined = np.flatnonzero(length > 1e-9 * max(float(length.max(initial=0.0)), 1.0))
    nearest = defined[np.clip(np.searchsorted(defined, np.arange(len(samples))), 0, len(defined) - 1)]
    return step[nearest] / length[nearest, None]
