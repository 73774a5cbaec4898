"""Carson's ribbons: a protein backbone segment as a multiresolution B-spline curve.

Two constructions (mathematics document, section 10):

* **peptide** — the peptide-plane ribbon: one control point per peptide plane (the
  midpoint of consecutive Cα, optionally shifted off the helix axis) plus two copies of a
  terminal point at each end; ``N + 3`` control points, one segment per residue, and the
  residue point ``C^r_i`` is the centre of residue i's segment.
* **calpha** — the Cα ribbon: ``N + 4`` control points fitted so that the curve passes
  through every Cα at the interior knots, ``N + 1`` segments; ``C^r_i = Cα_i`` at full
  resolution.

Both are padded with copies of the terminal points to ``2**J`` segments (``⌊p/2⌋`` in
front, ``⌈p/2⌉`` at the back) so the wavelet filter bank applies. Levels are Carson's
slider levels ``ℓ ∈ [0, log2 N]`` (section 8.1), mapped onto Finkelstein–Salesin levels
``λ ∈ [0, J]`` by :meth:`Ribbon.fs_level`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np
from scipy import linalg

from core import _validate
from core.curves.splines import SplineSpace, spline_space
from core.curves.wavelets import fractional_points
from core.protein.frames import PER_SEGMENT, residue_rotations, stretches
from core.protein.structure import BackboneSegment


class RibbonKind(StrEnum):
    """The two ribbon constructions."""

    PEPTIDE = "peptide"
    CALPHA = "calpha"


@dataclass(frozen=True, eq=False)
class Ribbon:
    """One backbone segment as a padded multiresolution curve.

    Attributes
    ----------
    kind : RibbonKind
    points : (2**J + 3, 3) float64, Å
        Control points at the finest (padded) level J; edits change these.
    residue_u : (N,) float64
        Curve parameter of every residue.
    n_curve_segments : int
        Segments before padding: N (peptide) or N + 1 (calpha); ``log2`` of it is the
        maximum slider level.
    front : int
        Padding copies of the first point in front of the layout.
    """

    kind: RibbonKind
    points: np.ndarray
    residue_u: np.ndarray
    n_curve_segments: int
    front: int

    @property
    def level(self) -> int:
        """The finest (padded) Finkelstein–Salesin level J."""
        return _validate.level_of_size("points", len(self.points), closed=False)

    @property
    def space(self) -> SplineSpace:
        """The spline space of the finest control points."""
        return spline_space(self.level)

    @property
    def max_level(self) -> float:
        """Carson's maximum fractional level ``log2 N`` (shows the original curve)."""
        return math.log2(self.n_curve_segments)

    def fs_level(self, level: float) -> float:
        """Finkelstein–Salesin level λ of slider level ``level`` (section 8.1).

        Identity up to ``J - 1``; the last partial interval ``(J - 1, log2 N]`` is stretched
        onto ``(J - 1, J]``. Levels above ``log2 N`` mean full resolution.
        """
        level = _validate.level_in_range("level", level, 0.0, math.inf)
        top = self.level - 1
        if level >= self.max_level:
            return float(self.level)
        if level <= top or self.max_level <= top:
            return level
        return top + (level - top) / (self.max_level - top)

    def control_points(self, level: float) -> tuple[np.ndarray, int]:
        """Control points of the curve shown at slider ``level`` and their integer F&S level."""
        return fractional_points(self.points, self.fs_level(level))

    def residue_points(self, level: float | None = None) -> np.ndarray:
        """``C^r``: the curve point of every residue at slider ``level`` (default: full), (N, 3)."""
        if level is None:
            return self.space.evaluate(self.points, self.residue_u)
        points, j = self.control_points(level)
        return spline_space(j).evaluate(points, self.residue_u)

    @property
    def span(self) -> tuple[float, float]:
        """The parameters the residues' curve covers (half a segment beyond the first and last
        residue point), without the padding."""
        half = 0.5 / 2**self.level
        return float(self.residue_u[0] - half), float(self.residue_u[-1] + half)

    def residue_rotations(self, new_points: np.ndarray, residues: np.ndarray) -> np.ndarray:
        """How ``residues`` turn when the finest control points become ``new_points``
        (:func:`core.protein.frames.residue_rotations`)."""
        return residue_rotations(self.space, self.points, new_points, self.residue_u[residues], self.span)

    def residues_moved_by(self, moved: np.ndarray) -> np.ndarray:
        """Residues whose curve point or rotation (:func:`core.protein.frames.stretches`)
        depends on the finest control points flagged in ``moved`` ((n_points,) bool)."""
        per = PER_SEGMENT * 2**self.level
        stretch = stretches(self.residue_u, self.span, 2**self.level)
        own = np.rint(self.residue_u * per).astype(np.int64)  # the residue point, on the same grid
        low, high = np.minimum(stretch[:, 0], own), np.maximum(stretch[:, -1], own)
        # a curve point inside segment s depends on rows s..s+3, one on the knot s on rows s..s+2
        first = low // PER_SEGMENT
        last = np.minimum(high // PER_SEGMENT + np.where(high % PER_SEGMENT == 0, 2, 3), len(moved) - 1)
        count = np.concatenate([[0], np.cumsum(moved)])
        return np.flatnonzero(count[last + 1] > count[first])

    def with_points(self, points: np.ndarray) -> Ribbon:
        """The same ribbon with new finest control points (after an edit)."""
        points = _validate.finite_array("points", points, ndim=(2,))
        if points.shape != self.points.shape:
            raise ValueError(f"points must have shape {self.points.shape}; got {points.shape}")
        return replace(self, points=points)


def build_ribbon(
    kind: RibbonKind | str,
    ca: np.ndarray,
    *,
    n_start: np.ndarray | None = None,
    c_end: np.ndarray | None = None,
    o: np.ndarray | None = None,
    helix: np.ndarray | None = None,
    helix_offset: float = 0.0,
    level: int | None = None,
) -> Ribbon:
    """Build the ribbon of one backbone segment.

    Parameters
    ----------
    kind : 'peptide' or 'calpha'.
    ca : (N, 3) Cα positions, N >= 2, Å.
    n_start, c_end : (3,) the N atom of the first residue and the C atom of the last, used
        as terminal points when finite; otherwise half-bond extrapolations of the Cα.
    o : (N, 3) carbonyl O positions (NaN where missing); needed only for ``helix_offset``.
    helix : (N,) bool, residues in helices; planes between two helix residues are shifted
        by ``helix_offset`` Å along the peptide-plane normal (away from the helix axis).
    level : pad to ``2**level`` segments instead of the smallest power of two that fits.
    """
    kind = RibbonKind(kind)
    ca = _validate.finite_array("ca", ca, ndim=(2,))
    if ca.shape[0] < 2 or ca.shape[1] != 3:
        raise ValueError(f"ca must have shape (N >= 2, 3); got {ca.shape}")
    start = _terminal(n_start, 1.5 * ca[0] - 0.5 * ca[1])
    end = _terminal(c_end, 1.5 * ca[-1] - 0.5 * ca[-2])
    n_residues = len(ca)
    if kind is RibbonKind.PEPTIDE:
        planes = _peptide_planes(ca, o, helix, helix_offset)
        n_curve = n_residues
        layout = np.vstack([start, start, planes, end, end])
    else:
        n_curve = n_residues + 1
        layout = np.vstack([start, start, ca, end, end])  # interior rows are refitted below
    fits = math.ceil(math.log2(n_curve))
    level = fits if level is None else _validate.integer_level("level", level, fits, 30)
    padding = 2**level - n_curve
    front = padding // 2
    points = np.vstack([np.repeat(start[None], front, 0), layout, np.repeat(end[None], padding - front, 0)])
    if kind is RibbonKind.PEPTIDE:
        residue_u = (front + np.arange(n_residues) + 0.5) / 2**level
    else:
        residue_u = (front + np.arange(1, n_residues + 1)) / 2**level
        _interpolate(points, residue_u, ca, first=front + 2, level=level)
    return Ribbon(kind, points, residue_u, n_curve, front)


def segment_ribbon(segment: BackboneSegment, kind: RibbonKind | str, helix_offset: float = 0.0) -> Ribbon:
    """The ribbon of a backbone segment read from a file (N and C atoms as terminal points)."""
    return build_ribbon(
        kind,
        segment.ca,
        n_start=segment.n[0],
        c_end=segment.c[-1],
        o=segment.o,
        helix=segment.ss == "H",
        helix_offset=helix_offset,
    )


def _terminal(atom: np.ndarray | None, fallback: np.ndarray) -> np.ndarray:
    if atom is None:
        return fallback
    atom = np.asarray(atom, dtype=np.float64)
    return atom if atom.shape == (3,) and np.all(np.isfinite(atom)) else fallback


def _peptide_planes(ca: np.ndarray, o: np.ndarray | None, helix: np.ndarray | None, offset: float) -> np.ndarray:
    """Central guide points ``(Cα_k + Cα_k+1)/2``, shifted along the plane normal in helices."""
    planes = 0.5 * (ca[:-1] + ca[1:])
    if offset == 0.0 or o is None or helix is None:
        return planes
    along = ca[1:] - ca[:-1]
    normal = np.cross(along, np.asarray(o, dtype=np.float64)[:-1] - ca[:-1])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    helix = np.asarray(helix, dtype=bool)
    shift = helix[:-1] & helix[1:] & np.isfinite(length[:, 0]) & (length[:, 0] > 1e-9)
    planes[shift] += offset * normal[shift] / length[shift]
    return planes


def _interpolate(points: np.ndarray, u: np.ndarray, targets: np.ndarray, first: int, level: int) -> None:
    """Refit rows ``first .. first + N - 1`` of ``points`` in place so the curve passes
    through ``targets`` at the knots ``u`` (a tridiagonal, banded solve)."""
    n = len(targets)
    basis = spline_space(level).design_matrix(u).tocsc()
    fixed = np.r_[0:first, first + n : len(points)]
    rhs = targets - basis[:, fixed] @ points[fixed]
    square = basis[:, first : first + n]
    band = np.zeros((3, n))
    for offset in (-1, 0, 1):  # LAPACK band storage of the tridiagonal collocation matrix
        band[1 - offset, max(offset, 0) : n + min(offset, 0)] = square.diagonal(offset)
    points[first : first + n] = linalg.solve_banded((1, 1), band, rhs)
