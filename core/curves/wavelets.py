"""The O(n) B-spline wavelet filter bank: decomposition, reconstruction, fractional levels.

One analysis step solves the normal equations of the L2 projection with banded
factorisations cached per level (multiresolution mathematics document, section 5):

    I^{j-1} C^{j-1} = (P^j)^T I^j C^j          (coarse control points)
    (Q^j)^T I^j Q^j D^{j-1} = (Q^j)^T I^j C^j   (detail coefficients)

and synthesis is ``C^j = P^j C^{j-1} + Q^j D^{j-1}``. The coarse curve of every level is
the L2-best approximation of the finest curve. Control points are rows of ``(n, d)``
arrays (``(n,)`` works too); open curves have ``2**m + 3`` rows, closed ones ``2**m``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core import _validate
from core.curves.filters import level_filters


@dataclass(frozen=True)
class WaveletTransform:
    """Coarse control points ``C^level`` and details ``D^level ... D^(m-1)`` (coarse to fine)."""

    coarse: np.ndarray
    details: tuple[np.ndarray, ...]
    closed: bool = False

    @property
    def level(self) -> int:
        """Level of the coarse control points."""
        return _validate.level_of_size("coarse", len(self.coarse), closed=self.closed)

    @property
    def finest_level(self) -> int:
        """Level of the reconstructed control points."""
        return self.level + len(self.details)


def finest_level(points: object, closed: bool = False) -> int:
    """Level ``m`` of a control polygon with ``2**m + 3`` (open) or ``2**m`` (closed) rows."""
    return _validate.level_of_size("points", len(np.asarray(points)), closed=closed)


def analysis_step(points: np.ndarray, closed: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """One decomposition step ``C^j -> (C^{j-1}, D^{j-1})``."""
    points = _checked_points(points, closed, min_level=1)
    return _analyse(points, finest_level(points, closed), closed)


def synthesis_step(coarse: np.ndarray, details: np.ndarray, closed: bool = False) -> np.ndarray:
    """One reconstruction step ``(C^{j-1}, D^{j-1}) -> C^j``."""
    filters = level_filters(finest_level(coarse, closed) + 1, closed)
    return filters.P @ coarse + filters.Q @ details


def smooth(points: object, level: int, closed: bool = False) -> np.ndarray:
    """Control points of the L2-best approximation of the curve at a coarser ``level``."""
    points = _checked_points(points, closed)
    finest = finest_level(points, closed)
    _validate.integer_level("level", level, 0, finest)
    for j in range(finest, level, -1):
        points = _coarsen(points, j, closed)
    return points


def refine(points: object, level: int, closed: bool = False) -> np.ndarray:
    """Control points of the same curve at a finer ``level`` (exact knot insertion)."""
    points = _checked_points(points, closed)
    _validate.integer_level("level", level, finest_level(points, closed), 30)
    for j in range(finest_level(points, closed) + 1, level + 1):
        points = level_filters(j, closed).P @ points
    return points


def decompose(points: object, level: int = 0, closed: bool = False) -> WaveletTransform:
    """Wavelet transform of ``points`` down to ``level`` (0: the full transform).

    The full transform ``C^0, D^0, ..., D^(m-1)`` has as many rows in total as ``points``.
    """
    points = _checked_points(points, closed)
    finest = finest_level(points, closed)
    _validate.integer_level("level", level, 0, finest)
    details: list[np.ndarray] = []
    for j in range(finest, level, -1):
        points, detail = _analyse(points, j, closed)
        details.append(detail)
    return WaveletTransform(points, tuple(reversed(details)), closed)


def reconstruct(transform: WaveletTransform) -> np.ndarray:
    """Inverse of :func:`decompose`: the finest control points."""
    points = transform.coarse
    for j, detail in enumerate(transform.details, start=transform.level + 1):
        filters = level_filters(j, transform.closed)
        points = filters.P @ points + filters.Q @ detail
    return points


def split_level(level: float, finest: int) -> tuple[int, float]:
    """Split a level ``lambda`` in ``[0, finest]`` into ``(j, t)`` with ``0 <= t < 1``."""
    level = _validate.level_in_range("level", level, 0, finest)
    j = int(np.floor(level + 1e-9))
    t = level - j
    return (j, 0.0) if t < 1e-9 else (j, t)


def fractional_points(points: object, level: float, closed: bool = False) -> tuple[np.ndarray, int]:
    """Control points of the curve at a fractional ``level = j + t``.

    The curve ``(1 - t) f^j + t f^(j+1)`` is returned on level ``j + 1`` control points
    ``C^{j+t} = (1 - t) P^{j+1} C^j + t C^{j+1}`` (on ``C^j`` itself when ``t == 0``).

    Returns
    -------
    (control points, their integer level)
    """
    points = _checked_points(points, closed)
    j, t = split_level(level, finest_level(points, closed))
    if t == 0.0:
        return smooth(points, j, closed), j
    upper = smooth(points, j + 1, closed)
    lower = level_filters(j + 1, closed).P @ _coarsen(upper, j + 1, closed)
    return (1.0 - t) * lower + t * upper, j + 1


def _coarsen(points: np.ndarray, level: int, closed: bool) -> np.ndarray:
    """``C^{level-1} = A^level C^level`` by the normal equations."""
    filters = level_filters(level, closed)
    return filters.solve_coarse(filters.PtI @ points)


def _analyse(points: np.ndarray, level: int, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """``(C^{level-1}, D^{level-1})`` by the normal equations."""
    filters = level_filters(level, closed)
    return filters.solve_coarse(filters.PtI @ points), filters.solve_detail(filters.QtI @ points)


def _checked_points(points: object, closed: bool, min_level: int = 0) -> np.ndarray:
    points = _validate.finite_array("points", points)
    level = _validate.level_of_size("points", len(points), closed=closed)
    if level < min_level:
        raise ValueError(f"points must be at level >= {min_level} to decompose; got level {level}")
    return points
