"""Cα–C^r deviations of a ribbon at decomposition depths (mathematics document §8.1, §10.3).

The measure of fit of a low-resolution curve: evaluate it at the residue parameters
``u_i`` of the original ribbon and take ``|Cα_i − C^r_i|``. Depths follow the x-axis of
Carson's Fig. 7:

* **integer** depth ``d``: the Finkelstein–Salesin level ``J − d`` of the padded curve
  (1/2, 1/4, 1/8, … of its segments); defined while ``J − d >= 0``;
* **fractional** depth ``x``: Carson's slider level ``log2 N − x`` (mapped onto F&S levels
  by :meth:`core.protein.ribbon.Ribbon.fs_level`); defined while ``log2 N − x >= 0``.

Every coarse curve is computed once per ribbon: the fractional curve of level ``j + t`` is
``(1 − t) f^j + t f^(j+1)`` (§7), so its residue points mix those of two integer levels.
"""

from __future__ import annotations

import numpy as np

from core import _validate
from core.curves.filters import level_filters
from core.curves.splines import spline_space
from core.curves.wavelets import smooth, split_level
from core.protein.ribbon import Ribbon


def level_residue_points(ribbon: Ribbon) -> np.ndarray:
    """Residue points of the L2-best curve of every integer level.

    Every coarse control polygon ``C^j`` is refined back to the finest level (exact knot
    insertion, ``P^J … P^(j+1) C^j``) in one upward sweep over all levels at once, so a
    single evaluation at the residue parameters gives all the curves.

    Returns
    -------
    (J + 1, N, 3) float64, Å
        Row ``j`` holds ``C^r`` evaluated on the level-``j`` curve; row ``J`` is the
        original curve.
    """
    finest = ribbon.level
    coarse = [ribbon.points]  # C^J, C^(J-1), ..., C^0
    for j in range(finest - 1, -1, -1):
        coarse.append(smooth(coarse[-1], j))
    refined = coarse[-1]  # columns: C^0, C^1, ... each refined to the current level
    for j in range(1, finest + 1):
        refined = np.hstack([level_filters(j).P @ refined, coarse[finest - j]])
    values = spline_space(finest).design_matrix(ribbon.residue_u) @ refined
    return values.reshape(len(ribbon.residue_u), finest + 1, 3).transpose(1, 0, 2)


def depth_deviations(
    ribbon: Ribbon, ca: np.ndarray, integer_depths: np.ndarray, fractional_depths: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``|Cα − C^r|`` of every residue at integer and fractional decomposition depths.

    Parameters
    ----------
    ribbon : the ribbon built from ``ca``.
    ca : (N, 3) Cα positions, Å.
    integer_depths : (a,) non-negative integers.
    fractional_depths : (b,) non-negative numbers.

    Returns
    -------
    (N, a) and (N, b) float64, Å
        NaN in the columns of depths beyond the ribbon's lowest level.
    """
    ca = _validate.finite_array("ca", ca, ndim=(2,))
    if ca.shape != (len(ribbon.residue_u), 3):
        raise ValueError(f"ca must have shape ({len(ribbon.residue_u)}, 3); got {ca.shape}")
    integer_depths = np.asarray(integer_depths, dtype=np.int64)
    fractional_depths = _validate.finite_array("fractional_depths", fractional_depths, ndim=(1,))
    if np.any(integer_depths < 0) or np.any(fractional_depths < 0):
        raise ValueError("depths must be >= 0")
    levels = level_residue_points(ribbon)
    distances = np.linalg.norm(levels - ca, axis=2).T  # (N, J + 1)
    whole = np.full((len(ca), len(integer_depths)), np.nan)
    reached = integer_depths <= ribbon.level
    whole[:, reached] = distances[:, ribbon.level - integer_depths[reached]]
    fractional = np.full((len(ca), len(fractional_depths)), np.nan)
    for column, depth in enumerate(fractional_depths):
        slider = ribbon.max_level - depth
        if slider < -1e-9:
            continue
        j, t = split_level(ribbon.fs_level(max(slider, 0.0)), ribbon.level)
        points = levels[j] if t == 0.0 else (1.0 - t) * levels[j] + t * levels[j + 1]
        fractional[:, column] = np.linalg.norm(points - ca, axis=1)
    return whole, fractional
