"""Uniform cubic B-spline spaces at dyadic levels: open (endpoint-interpolating) and closed.

Level ``j`` has ``2**j`` segments of equal length on ``u in [0, 1]``. An open curve has
``2**j + 3`` control points on the clamped knot vector ``(0,0,0,0, 1/2**j, ..., 1,1,1,1)``;
a closed curve has ``2**j`` control points and basis ``phi_i(u) = N(2**j u - i)`` wrapped
modulo 1 (``N`` the cardinal cubic B-spline on [0, 4]). Control points are rows: a curve
is ``f(u) = Phi(u) @ C`` with ``C`` of shape ``(n, d)``.

Evaluation is delegated to :class:`scipy.interpolate.BSpline`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np
from scipy import sparse
from scipy.interpolate import BSpline

from core import _validate

DEGREE = 3


@dataclass(frozen=True)
class SplineSpace:
    """The cubic B-spline space ``V^j`` of one level, open or closed."""

    level: int
    closed: bool = False

    @property
    def n_segments(self) -> int:
        """Number of curve segments, ``2**level``."""
        return 2**self.level

    @property
    def n_points(self) -> int:
        """Number of control points: ``2**level + 3`` (open) or ``2**level`` (closed)."""
        return self.n_segments + (0 if self.closed else 3)

    @cached_property
    def knots(self) -> np.ndarray:
        """Knot vector handed to scipy (clamped for open curves, extended for closed)."""
        s = self.n_segments
        if self.closed:
            return np.arange(-DEGREE, s + DEGREE + 1, dtype=np.float64) / s
        inner = np.arange(1, s, dtype=np.float64) / s
        return np.concatenate([np.zeros(DEGREE + 1), inner, np.ones(DEGREE + 1)])

    @cached_property
    def _wrap(self) -> sparse.csr_array:
        """Fold the ``n + 3`` extended coefficients of a closed curve onto its ``n`` points."""
        n = self.n_points
        rows = np.arange(n + DEGREE)
        cols = (rows - DEGREE) % n
        return sparse.csr_array((np.ones(n + DEGREE), (rows, cols)), shape=(n + DEGREE, n))

    def parameters(self, u: object) -> np.ndarray:
        """Check curve parameters (any shape, in [0, 1]; closed curves wrap) and return them."""
        u = _validate.finite_array("u", u, ndim=(0, 1))
        if self.closed:
            return np.mod(u, 1.0)
        if np.any((u < -1e-12) | (u > 1 + 1e-12)):
            raise ValueError(f"u must lie in [0, 1] for an open curve; got [{u.min():g}, {u.max():g}]")
        return np.clip(u, 0.0, 1.0)

    def design_matrix(self, u: object) -> sparse.csr_array:
        """Basis values ``Phi(u)``: sparse ``(len(u), n_points)``, four non-zeros per row."""
        u = np.atleast_1d(self.parameters(u))
        matrix = BSpline.design_matrix(u, self.knots, DEGREE)
        return sparse.csr_array(matrix @ self._wrap) if self.closed else sparse.csr_array(matrix)

    def evaluate(self, points: object, u: object, derivative: int = 0) -> np.ndarray:
        """Curve points (or derivatives with respect to u) at parameters ``u``.

        Parameters
        ----------
        points : (n_points, d) or (n_points,) control points.
        u : scalar or (m,) parameters.
        derivative : 0, 1 or 2.

        Returns
        -------
        (m, d) or (d,) array (shape follows ``u`` and ``points``).
        """
        points = self._check_points(points)
        if derivative not in (0, 1, 2):
            raise ValueError(f"derivative must be 0, 1 or 2; got {derivative!r}")
        coefficients = points[np.arange(-DEGREE, self.n_points) % self.n_points] if self.closed else points
        spline = BSpline(self.knots, coefficients, DEGREE, extrapolate=False)
        return spline(self.parameters(u), nu=derivative)

    def closest_parameter(self, points: object, target: object, samples_per_segment: int = 8) -> float:
        """Parameter ``u`` of the curve point closest to ``target`` (a (d,) point).

        The curve is sampled, then the best sample is refined by Newton steps on
        ``(f(u) - p) . f'(u) = 0``.
        """
        points = self._check_points(points)
        target = _validate.finite_array("target", target, ndim=(1,))
        grid = np.linspace(0.0, 1.0, self.n_segments * samples_per_segment + 1)
        u = float(grid[np.argmin(np.linalg.norm(self.evaluate(points, grid) - target, axis=-1))])
        for _ in range(6):
            offset = self.evaluate(points, u) - target
            d1, d2 = self.evaluate(points, u, 1), self.evaluate(points, u, 2)
            slope = d1 @ d1 + offset @ d2
            if slope <= 0:
                break
            step = (offset @ d1) / slope
            u = float(self.parameters(u - step))
            if abs(step) < 1e-12:
                break
        return u

    def _check_points(self, points: object) -> np.ndarray:
        points = _validate.finite_array("points", points)
        if points.shape[0] != self.n_points:
            raise ValueError(
                f"points must have {self.n_points} rows for level {self.level}; got {points.shape[0]}"
            )
        return points


@lru_cache(maxsize=None)
def spline_space(level: int, closed: bool = False) -> SplineSpace:
    """The (cached) spline space of ``level``."""
    _validate.integer_level("level", level, 0, 30)
    return SplineSpace(level, closed)


def space_of(points: np.ndarray, closed: bool = False) -> SplineSpace:
    """The spline space whose control polygon has as many rows as ``points``."""
    return spline_space(_validate.level_of_size("points", len(points), closed=closed), closed)
