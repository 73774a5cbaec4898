"""Multiresolution editing of B-spline curves (Finkelstein & Salesin 1994, Carson 1996).

An edit at a coarse level is pushed to the finest control points through the synthesis
filters, which keeps every finer detail: ``dC^m = P^m ... P^(j+1) dC^j`` (Carson eq. 5).
Edits are linear in the displacement, so every function here returns the change of the
finest control points, ``(n_m, d)``, to be added to them; it does not need the points.

Fractional levels ``j + t`` follow FS94 eqs. 13-16 with the blend ``g(t) = t**2``
(mathematics document, section 9.3); tugging a point of the curve itself uses the
least-norm change of the control points (section 9.4).
"""

from __future__ import annotations

import numpy as np

from core import _validate
from core.curves.filters import level_filters
from core.curves.splines import spline_space
from core.curves.wavelets import smooth, split_level


def push_to_finest(delta: object, level: int, finest: int, closed: bool = False) -> np.ndarray:
    """Carry a change of level-``level`` control points to level ``finest`` (eq. 5).

    Parameters
    ----------
    delta : (n_level, d) change of the control points at ``level``.
    level, finest : integer levels, ``level <= finest``.
    """
    delta = _validate.finite_array("delta", delta, ndim=(2,))
    _validate.integer_level("level", level, 0, finest)
    if len(delta) != spline_space(level, closed).n_points:
        raise ValueError(
            f"delta must have {spline_space(level, closed).n_points} rows for level {level}; got {len(delta)}"
        )
    for j in range(level + 1, finest + 1):
        delta = level_filters(j, closed).P @ delta
    return delta


def move_control_point(
    level: float, index: int, displacement: object, finest: int, closed: bool = False
) -> np.ndarray:
    """Change of the finest control points when control point ``index`` of the curve at
    ``level`` moves by ``displacement``.

    At an integer level ``j`` the index refers to ``C^j``; at a fractional level ``j + t``
    it refers to the displayed control points ``C^{j+t}`` (level ``j + 1``), and that point
    moves by exactly ``displacement`` while the affected region narrows continuously
    from that of a level-``j`` edit (t -> 0) to a single level-``j+1`` point (t -> 1).
    """
    displacement = _validate.finite_array("displacement", displacement, ndim=(1,))
    j, t = split_level(level, finest)
    shown = spline_space(j if t == 0.0 else j + 1, closed)
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < shown.n_points:
        raise ValueError(f"index must be an integer in [0, {shown.n_points - 1}]; got {index!r}")
    picked = np.zeros((shown.n_points, len(displacement)))
    picked[index] = displacement
    if t == 0.0:
        return push_to_finest(picked, j, finest, closed)
    return _fractional_edit(j, t, _coarse_counterpart(j, index, displacement, closed), picked, finest, closed)


def tug_curve(level: float, u: float, displacement: object, finest: int, closed: bool = False) -> np.ndarray:
    """Change of the finest control points when the curve point at parameter ``u`` of the
    curve at ``level`` is dragged by ``displacement`` (least-norm change at that level).

    At an integer level the finest curve moves by exactly ``displacement`` at ``u``; at a
    fractional level the displayed curve does.
    """
    displacement = _validate.finite_array("displacement", displacement, ndim=(1,))
    j, t = split_level(level, finest)
    if t == 0.0:
        return push_to_finest(_least_norm(j, u, displacement, closed), j, finest, closed)
    coarse, fine = _least_norm(j, u, displacement, closed), _least_norm(j + 1, u, displacement, closed)
    return _fractional_edit(j, t, coarse, fine, finest, closed)


def changed_segments(delta: object, closed: bool = False, tolerance: float = 0.0) -> np.ndarray:
    """Indices of the segments moved by a change ``delta`` of control points (rows > tolerance)."""
    delta = _validate.finite_array("delta", delta)
    space = spline_space(_validate.level_of_size("delta", len(delta), closed=closed), closed)
    moved = np.abs(delta.reshape(len(delta), -1)).max(axis=1) > tolerance
    window = np.arange(4) - (3 if closed else 0)  # segment s depends on rows s..s+3 (open)
    rows = (np.arange(space.n_segments)[:, None] + window) % space.n_points
    return np.flatnonzero(moved[rows].any(axis=1))


def _fractional_edit(
    j: int, t: float, coarse: np.ndarray, fine: np.ndarray, finest: int, closed: bool
) -> np.ndarray:
    """FS94 eq. 14-16 with g = t**2: blend a level-j change and a level-(j+1) change.

    ``dC^{j+1} = (1 - t^2) P dC^j + t dC^{j+t} + (t^2 - t) P A dC^{j+t}``, then pushed up.
    """
    P = level_filters(j + 1, closed).P
    change = (1.0 - t * t) * (P @ coarse) + t * fine + (t * t - t) * (P @ smooth(fine, j, closed))
    return push_to_finest(change, j + 1, finest, closed)


def _coarse_counterpart(j: int, index: int, displacement: np.ndarray, closed: bool) -> np.ndarray:
    """A level-j change that moves row ``index`` of ``P^{j+1} C^j`` by ``displacement``.

    The largest entry of that row of ``P^{j+1}`` picks the coarse point; two equal largest
    entries share the move.
    """
    row = level_filters(j + 1, closed).P[[index], :].toarray().ravel()
    largest = np.flatnonzero(np.isclose(row, row.max()))
    change = np.zeros((len(row), len(displacement)))
    change[largest] = displacement / (len(largest) * row.max())
    return change


def _least_norm(level: int, u: float, displacement: np.ndarray, closed: bool) -> np.ndarray:
    """Smallest change of level-``level`` control points moving the curve at ``u`` by ``displacement``."""
    phi = spline_space(level, closed).design_matrix([u]).toarray().ravel()
    return np.outer(phi, displacement) / (phi @ phi)
