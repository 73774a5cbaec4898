"""Tensor-product cubic B-spline surfaces and their non-standard wavelet decomposition.

A control net ``C`` of shape ``(n_u, n_v, d)`` defines ``S(u, v) = Φ_u(u) C Φ_v(v)^T``;
each direction is open (``2**j + 3`` rows) or closed (``2**j``), both at the same level
``j`` (``2**j × 2**j`` patches). One decomposition step applies the curve filter bank of
:mod:`core.curves.wavelets` along u and then along v (multiresolution mathematics document §11.1):

    C' = A_u C A_v^T,  details (A_u C B_v^T, B_u C A_v^T, B_u C B_v^T),

so ``C'`` is the L2-best approximation of the surface at the coarser level.
:class:`SplineSurface` adds what the globe and the DNA cylinder need: a least-squares fit
to a grid of samples, pole rows kept collapsed, and evaluation as a triangle mesh.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from core import _validate
from core.curves.filters import level_filters
from core.curves.splines import spline_space
from core.curves.wavelets import analysis_step, finest_level
from core.surfaces.mesh import TriangleMesh

Closed = tuple[bool, bool]
Details = tuple[np.ndarray, np.ndarray, np.ndarray]


def _along(net: np.ndarray, axis: int, step: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Apply a map of ``(n, k)`` column blocks along ``axis`` of a net."""
    moved = np.moveaxis(net, axis, 0)
    result = step(moved.reshape(len(moved), -1))
    return np.moveaxis(result.reshape(len(result), *moved.shape[1:]), 0, axis)


def net_level(net: object, closed: Closed) -> int:
    """Common level ``j`` of both directions of a control net ``(n_u, n_v, d)``."""
    net = np.asarray(net)
    if net.ndim != 3:
        raise ValueError(f"net must have shape (n_u, n_v, d); got {net.shape}")
    levels = [finest_level(np.empty(n), c) for n, c in zip(net.shape[:2], closed, strict=True)]
    if levels[0] != levels[1]:
        raise ValueError(f"both directions of the net must be at the same level; got {levels[0]} and {levels[1]}")
    return levels[0]


def analysis_step2(net: object, closed: Closed) -> tuple[np.ndarray, Details]:
    """One non-standard step: ``(C', (A_u C B_v^T, B_u C A_v^T, B_u C B_v^T))``."""
    net = _validate.finite_array("net", net, ndim=(3,))
    net_level(net, closed)
    low_u = _along(net, 0, lambda c: analysis_step(c, closed[0])[0])
    high_u = _along(net, 0, lambda c: analysis_step(c, closed[0])[1])
    coarse = _along(low_u, 1, lambda c: analysis_step(c, closed[1])[0])
    d1 = _along(low_u, 1, lambda c: analysis_step(c, closed[1])[1])
    d2 = _along(high_u, 1, lambda c: analysis_step(c, closed[1])[0])
    d3 = _along(high_u, 1, lambda c: analysis_step(c, closed[1])[1])
    return coarse, (d1, d2, d3)


def synthesis_step2(coarse: np.ndarray, details: Details, closed: Closed) -> np.ndarray:
    """Inverse of :func:`analysis_step2`: ``P_u C' P_v^T + P_u D1 Q_v^T + Q_u D2 P_v^T + Q_u D3 Q_v^T``."""
    j = net_level(coarse, closed) + 1
    fu, fv = level_filters(j, closed[0]), level_filters(j, closed[1])
    d1, d2, d3 = details
    low_u = _along(coarse, 1, lambda c: fv.P @ c) + _along(d1, 1, lambda c: fv.Q @ c)
    high_u = _along(d2, 1, lambda c: fv.P @ c) + _along(d3, 1, lambda c: fv.Q @ c)
    return _along(low_u, 0, lambda c: fu.P @ c) + _along(high_u, 0, lambda c: fu.Q @ c)


@dataclass(frozen=True)
class TensorTransform:
    """Coarse net at ``level`` and the detail triples of each finer level (coarse to fine)."""

    coarse: np.ndarray
    details: tuple[Details, ...]
    closed: Closed

    @property
    def level(self) -> int:
        return net_level(self.coarse, self.closed)


def decompose2(net: object, level: int = 0, closed: Closed = (False, True)) -> TensorTransform:
    """Non-standard wavelet transform of a control net down to ``level``."""
    net = _validate.finite_array("net", net, ndim=(3,))
    _validate.integer_level("level", level, 0, net_level(net, closed))
    details: list[Details] = []
    while net_level(net, closed) > level:
        net, detail = analysis_step2(net, closed)
        details.append(detail)
    return TensorTransform(net, tuple(reversed(details)), closed)


def reconstruct2(transform: TensorTransform) -> np.ndarray:
    """Inverse of :func:`decompose2`: the finest control net."""
    net = transform.coarse
    for detail in transform.details:
        net = synthesis_step2(net, detail, transform.closed)
    return net


def smooth2(net: object, level: int, closed: Closed = (False, True)) -> np.ndarray:
    """Control net of the L2-best approximation at a coarser ``level``."""
    return decompose2(net, level, closed).coarse


def refine2(net: np.ndarray, closed: Closed) -> np.ndarray:
    """The same surface on the net one level finer (knot insertion in both directions)."""
    j = net_level(net, closed) + 1
    fu, fv = level_filters(j, closed[0]), level_filters(j, closed[1])
    return _along(_along(net, 0, lambda c: fu.P @ c), 1, lambda c: fv.P @ c)


def evaluate_grid(net: object, u: object, v: object, closed: Closed) -> np.ndarray:
    """Surface points ``S(u_i, v_k)``: ``(len(u), len(v), d)``."""
    net = _validate.finite_array("net", net, ndim=(3,))
    j = net_level(net, closed)
    phi_u = spline_space(j, closed[0]).design_matrix(u).toarray()
    phi_v = spline_space(j, closed[1]).design_matrix(v).toarray()
    return np.einsum("ia,abd,kb->ikd", phi_u, net, phi_v)


def grid_mesh(points: np.ndarray, closed_v: bool = True, poles: bool = False) -> TriangleMesh:
    """Triangles of a grid of surface points ``(n_u, n_v, 3)``, normals along ``∂u × ∂v``.

    With ``closed_v`` the last column joins the first (no seam); with ``poles`` the first
    and last rows are single points (each becomes one vertex), which closes a globe.
    """
    n_u, n_v = points.shape[:2]
    index = np.arange(n_u * n_v).reshape(n_u, n_v)
    vertices = points.reshape(-1, 3)
    if poles:
        index[0] = 0
        index[-1] = (n_u - 2) * n_v + 1
        index[1:-1] = np.arange(1, (n_u - 2) * n_v + 1).reshape(n_u - 2, n_v)
        vertices = np.concatenate([points[0, :1], points[1:-1].reshape(-1, 3), points[-1, :1]])
    right = np.roll(index, -1, axis=1) if closed_v else index[:, 1:]
    left = index if closed_v else index[:, :-1]
    a, b, c, d = left[:-1], left[1:], right[1:], right[:-1]
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])]
    return TriangleMesh(vertices, faces)


def sample_parameters(n_u: int, n_v: int, closed: Closed) -> tuple[np.ndarray, np.ndarray]:
    """Sample parameters of a grid: ``n`` points from 0 to 1 in an open direction, ``n``
    points ``k/n`` in a closed one."""
    return tuple(np.arange(n) / n if c else np.linspace(0.0, 1.0, n) for n, c in zip((n_u, n_v), closed, strict=True))


@dataclass(frozen=True, eq=False)
class SplineSurface:
    """A fitted spline surface with its samples and texture.

    Attributes
    ----------
    net : (n_u, n_v, 3) float64, Å
        Control net at the finest level.
    closed : (bool, bool)
    poles : bool
        The first and last rows collapse to points (a globe); every coarser net is
        re-collapsed to the row means.
    samples : (m_u, m_v, 3) float64, Å
        The surface points the net was fitted to, at :func:`sample_parameters`.
    """

    net: np.ndarray
    closed: Closed
    poles: bool
    samples: np.ndarray

    @property
    def level(self) -> int:
        return net_level(self.net, self.closed)

    @property
    def parameters(self) -> tuple[np.ndarray, np.ndarray]:
        """(u, v) of the samples (and of the texture)."""
        return sample_parameters(*self.samples.shape[:2], self.closed)

    def net_at(self, level: float) -> np.ndarray:
        """Control net at ``level`` (fractional levels blend ``(1 - t) C^j + t C^(j+1)`` on
        the level ``j + 1`` net)."""
        level = _validate.level_in_range("level", level, 0, self.level)
        j = int(np.floor(level + 1e-9))
        t = level - j
        lower = self._collapsed(smooth2(self.net, j, self.closed))
        if t < 1e-9:
            return lower
        upper = self._collapsed(smooth2(self.net, j + 1, self.closed))
        return (1.0 - t) * refine2(lower, self.closed) + t * upper

    def points(self, level: float) -> np.ndarray:
        """Surface points at ``level`` at the sample parameters: ``(m_u, m_v, 3)``."""
        return evaluate_grid(self.net_at(level), *self.parameters, self.closed)

    def mesh(self, level: float) -> TriangleMesh:
        """Triangle mesh at ``level`` with one vertex per sample (texture) point."""
        return grid_mesh(self.points(level), closed_v=self.closed[1], poles=self.poles)

    def rms_error(self, level: float) -> float:
        """Root-mean-square distance (Å) from the samples to the surface at ``level``,
        at the same parameters."""
        return float(np.sqrt(np.mean(np.sum((self.points(level) - self.samples) ** 2, axis=-1))))

    def _collapsed(self, net: np.ndarray) -> np.ndarray:
        if not self.poles:
            return net
        net = net.copy()
        net[0] = net[0].mean(axis=0)
        net[-1] = net[-1].mean(axis=0)
        return net


def fit_surface(samples: object, level: int, closed: Closed = (False, True), poles: bool = False) -> SplineSurface:
    """Least-squares fit of a spline surface at ``level`` to a grid of samples.

    Parameters
    ----------
    samples : (m_u, m_v, 3) float, Å
        Points at :func:`sample_parameters`; at least as many per direction as control points.
    level : int
        Level of the net in both directions (``2**level`` patches each way).
    closed : (bool, bool)
    poles : bool
        The first and last sample rows are single points (the u direction must be open):
        the first and last net rows are pinned to them, so the surface passes through
        both poles.
    """
    samples = _validate.finite_array("samples", samples, ndim=(3,))
    u, v = sample_parameters(*samples.shape[:2], closed)
    phi_u = spline_space(level, closed[0]).design_matrix(u).toarray()
    phi_v = spline_space(level, closed[1]).design_matrix(v).toarray()
    if len(u) < phi_u.shape[1] or len(v) < phi_v.shape[1]:
        raise ValueError(f"need at least {phi_u.shape[1]} x {phi_v.shape[1]} samples for level {level}; got {samples.shape[:2]}")
    rows = _along(samples, 1, lambda c: linalg.lstsq(phi_v, c)[0])  # fit each u-row along v
    if poles:
        if closed[0]:
            raise ValueError("poles need an open u direction")
        ends = rows[[0, -1]].mean(axis=1, keepdims=True).repeat(rows.shape[1], axis=1)
        rest = rows - np.einsum("ie,ekd->ikd", phi_u[:, [0, -1]], ends)
        inner = _along(rest, 0, lambda c: linalg.lstsq(phi_u[:, 1:-1], c)[0])
        net = np.concatenate([ends[:1], inner, ends[1:]])
    else:
        net = _along(rows, 0, lambda c: linalg.lstsq(phi_u, c)[0])
    return SplineSurface(net, closed, poles, samples)
