"""How one backbone segment's ribbon is sampled for display (numpy only, no Qt or VTK).

The full-resolution tube has ``rings_per_residue`` rings per residue: residue ``i`` spans
the parameters ``residue_u[i] ± 1/2**(J+1)`` (its peptide-ribbon segment, or the two half
segments around its Cα), so an edit that moves some residues moves exactly their rings.
The thin curve of a slider level is sampled at every other ring parameter. Design
matrices of each integer level and the smoothed control points of the current ribbon are
cached, so moving the slider costs three sparse products per segment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse

from core.curves.filters import level_filters
from core.curves.splines import spline_space
from core.curves.wavelets import smooth, split_level
from core.protein.ribbon import Ribbon

RINGS_PER_RESIDUE = 6
"""Tube rings per residue (the thin level curve has half as many samples)."""
SIDES = 12
"""Vertices around each ring of the tube and the cartoon."""
LARGE_RESIDUES = 10_000
"""Residues above which a structure (a capsid, an assembly) is swept with
:data:`LARGE_RINGS_PER_RESIDUE` rings a residue of :data:`LARGE_SIDES` vertices: less than half
the vertices and triangles to hold and to draw, where a residue takes a few pixels."""
LARGE_RINGS_PER_RESIDUE = 4
LARGE_SIDES = 8


def sampling(n_residues: int) -> tuple[int, int]:
    """Tube rings per residue, and vertices around each ring, for a structure of ``n_residues``
    residues in all its segments."""
    return (RINGS_PER_RESIDUE, SIDES) if n_residues <= LARGE_RESIDUES else (LARGE_RINGS_PER_RESIDUE, LARGE_SIDES)


def segment_paths(ribbons: list[Ribbon]) -> list[SegmentPath]:
    """The sampling of every segment of a structure with these ``ribbons``, as fine as its size
    allows (:func:`sampling`)."""
    rings, sides = sampling(sum(len(ribbon.residue_u) for ribbon in ribbons))
    return [SegmentPath(ribbon, rings, sides) for ribbon in ribbons]


@dataclass(frozen=True, eq=False)
class LevelCurve:
    """The curve of one segment at a slider level.

    Attributes
    ----------
    control_points : (2**level + 3, 3) its control points (all of them, padding included).
    level : their integer Finkelstein–Salesin level (``floor(λ) + 1`` at fractional λ).
    samples : (m, 3) points of the curve at :attr:`SegmentPath.curve_u`.
    residue_points : (N, 3) ``C^r``, the curve at the residue parameters.
    visible : (2**level + 3,) bool, control points whose basis functions reach a residue
        (the others only shape the padding beyond the chain ends).
    """

    control_points: np.ndarray
    level: int
    samples: np.ndarray
    residue_points: np.ndarray
    visible: np.ndarray

    @property
    def n_segments(self) -> int:
        """Curve segments of the level, ``2**level``."""
        return 2**self.level


def eased(values: np.ndarray, rings_per_residue: int) -> np.ndarray:
    """Per-ring ``values`` (n_rings, ...) averaged over a residue's rings around each: steps
    from one residue to the next eased."""
    window = np.ones(rings_per_residue + 1) / (rings_per_residue + 1)
    padded = np.pad(values, [(rings_per_residue // 2,) * 2] + [(0, 0)] * (np.ndim(values) - 1), mode="edge")
    return np.apply_along_axis(lambda column: np.convolve(column, window, mode="valid"), 0, padded)


class SegmentPath:
    """Sampling parameters of one segment's ribbon: tube rings and level-curve samples.

    Parameters
    ----------
    ribbon : the segment's ribbon (only its layout is used; its points may change later).
    rings_per_residue : tube rings per residue, even.
    sides : vertices around each ring of a tube swept along it.
    """

    def __init__(self, ribbon: Ribbon, rings_per_residue: int = RINGS_PER_RESIDUE, sides: int = SIDES) -> None:
        n_residues = len(ribbon.residue_u)
        half = 0.5 / 2**ribbon.level
        steps = np.arange(n_residues * rings_per_residue + 1)
        self.finest = ribbon.level
        self.rings_per_residue = rings_per_residue
        self.sides = sides
        self.residue_u = ribbon.residue_u
        self.u = np.clip(ribbon.residue_u[0] - half + steps * (2 * half / rings_per_residue), 0.0, 1.0)
        """(R,) ring parameters, ``R = N * rings_per_residue + 1``."""
        self.owner = np.minimum(steps // rings_per_residue, n_residues - 1)
        """(R,) residue of each ring."""
        self.curve_u = self.u[::2]
        """(R // 2 + 1,) parameters of the level-curve samples."""
        self.span = (float(self.u[0]), float(self.u[-1]))
        self._matrices: dict[int, tuple[sparse.csr_array, sparse.csr_array]] = {}
        self._pyramid_of: Ribbon | None = None
        self._pyramid: dict[int, np.ndarray] = {}

    @property
    def n_rings(self) -> int:
        return len(self.u)

    def rings(self, residues: np.ndarray) -> np.ndarray:
        """Sorted indices of the rings of ``residues`` (each residue's span, both ends included)."""
        k = self.rings_per_residue
        ring = np.zeros(self.n_rings, dtype=bool)
        ring[(np.asarray(residues)[:, None] * k + np.arange(k + 1)).ravel()] = True
        return np.flatnonzero(ring)

    def centres(self, points: np.ndarray, rings: np.ndarray | slice = slice(None), level: int | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
        """Curve points (r, 3) and unit tangents (r, 3) at ``rings`` of the curve of control
        points ``points`` of ``level`` (default: the finest, the ribbon's).

        Where the first derivative vanishes (the curve's very ends, over the doubled
        terminal control points) the tangent is the direction from which the curve arrives
        there, given by the second derivative.
        """
        space = spline_space(self.finest if level is None else level)
        u = self.u[rings]
        derivative = space.evaluate(points, u, 1)
        length = np.linalg.norm(derivative, axis=1)
        flat = length <= 1e-9 * max(float(length.max(initial=0.0)), 1.0)
        if flat.any():
            derivative[flat] = space.evaluate(points, u[flat], 2) * np.where(u[flat] < 0.5, 1.0, -1.0)[:, None]
            length[flat] = np.linalg.norm(derivative[flat], axis=1)
        return space.evaluate(points, u), derivative / length[:, None]

    def level_curve(self, ribbon: Ribbon, level: float) -> LevelCurve:
        """The curve of ``ribbon`` at slider ``level`` sampled for display.

        Its control points equal ``ribbon.control_points(level)`` bit for bit; they are
        blended from this ribbon's smoothed control points of every integer level, which
        are kept until the ribbon changes.
        """
        j, t = split_level(ribbon.fs_level(level), ribbon.level)
        if t == 0.0:
            points = self._smoothed(ribbon, j)
        else:
            lower = level_filters(j + 1).P @ self._smoothed(ribbon, j)
            points, j = (1.0 - t) * lower + t * self._smoothed(ribbon, j + 1), j + 1
        curve_matrix, residue_matrix = self._level_matrices(j)
        return LevelCurve(points, j, curve_matrix @ points, residue_matrix @ points, self._visible(j))

    def _smoothed(self, ribbon: Ribbon, level: int) -> np.ndarray:
        """``ribbon``'s control points smoothed to integer ``level`` (cached per ribbon)."""
        if self._pyramid_of is not ribbon:
            self._pyramid_of = ribbon
            self._pyramid = {ribbon.level: ribbon.points}
        finer = min(j for j in self._pyramid if j >= level)
        for j in range(finer, level, -1):
            self._pyramid[j - 1] = smooth(self._pyramid[j], j - 1)
        return self._pyramid[level]

    def _level_matrices(self, level: int) -> tuple[sparse.csr_array, sparse.csr_array]:
        if level not in self._matrices:
            space = spline_space(level)
            self._matrices[level] = (space.design_matrix(self.curve_u), space.design_matrix(self.residue_u))
        return self._matrices[level]

    def _visible(self, level: int) -> np.ndarray:
        """Control points of ``level`` whose support (segments k-3 .. k) meets the residues."""
        n = 2**level
        first = min(int(np.floor(self.span[0] * n)), n - 1)
        last = max(int(np.ceil(self.span[1] * n)) - 1, first)
        index = np.arange(n + 3)
        return (index >= first) & (index - 3 <= last)
