"""The rotation of each residue after an edit of its ribbon, and the rigid-body remapping.

Every atom ``x`` of residue ``i`` moves with the curve around it:

    x' = C^r'_i + R_i (x - C^r_i),

``C^r`` the residue's curve point before and after the edit, and ``R_i`` the least-squares
(Kabsch) rotation that carries the curve's stretch within :data:`REACH` residues either side
of ``i`` (sampled at :data:`SAMPLES` points, each sampling about its centroid) from before the
edit to after it. A rigid motion of the curve moves every residue by that motion; a curve
left as it was turns none.

This departs from the paper (and the mathematics document, section 10.4), which turns each
residue with the change of the curve's Frenet frame at its point. A Frenet normal rests on
the curve's second derivative: undefined on straight pieces, flipping at inflections, and
where a residue's curve hardly turns, control points moved by 0.001 Å swing it by tenths of
a degree, or by tens of degrees where it crosses the threshold below which a neighbour's
normal must stand in; a fit's result then hung on the last bits of floating point. The
stretch's rotation rests on positions only and changes in proportion to the change of the
curve (a third to a tenth of the Frenet frames' swing on real chains).
"""

from __future__ import annotations

import numpy as np

from core.curves.splines import SplineSpace

REACH = 3
"""Finest curve segments (one per residue) on each side of a residue that turn it."""
SAMPLES = 13
"""Curve points sampled over a residue's stretch, evenly, ends included."""


def stretches(u: np.ndarray, span: tuple[float, float], n_segments: int) -> np.ndarray:
    """(N, :data:`SAMPLES`) curve parameters sampling the stretch of each residue at ``u`` (N,):
    :data:`REACH` segments of ``n_segments`` either side, shifted to stay within ``span``
    (the chain's residues, not the padding beyond them, where the curve stands still) so
    that the ends of a chain turn with as much curve as its middle."""
    reach = REACH / n_segments
    low = np.clip(np.asarray(u, dtype=float) - reach, span[0], max(span[0], span[1] - 2 * reach))
    return np.minimum(low[:, None] + np.linspace(0.0, 2 * reach, SAMPLES), max(span[1], span[0]))


def residue_rotations(space: SplineSpace, old_points: np.ndarray, new_points: np.ndarray, u: np.ndarray,
                      span: tuple[float, float] = (0.0, 1.0)) -> np.ndarray:
    """(N, 3, 3) rotations (determinant +1) of the residues at parameters ``u`` (N,) when the
    curve's finest control points change from ``old_points`` to ``new_points``; ``span``, the
    parameters the chain's residues cover (:func:`stretches`)."""
    stretch = stretches(u, span, space.n_segments)
    before = space.evaluate(old_points, stretch.ravel()).reshape(*stretch.shape, 3)
    after = space.evaluate(new_points, stretch.ravel()).reshape(*stretch.shape, 3)
    before -= before.mean(axis=1, keepdims=True)
    after -= after.mean(axis=1, keepdims=True)
    covariance = np.einsum("nki,nkj->nij", after, before)
    left, _, right = np.linalg.svd(covariance)
    sign = np.sign(np.linalg.det(left @ right))
    sign[sign == 0] = 1.0
    left[:, :, 2] *= sign[:, None]
    return left @ right


def remap_atoms(
    coords: np.ndarray,
    atom_residue: np.ndarray,
    old_points: np.ndarray,
    new_points: np.ndarray,
    rotations: np.ndarray,
) -> np.ndarray:
    """Move atoms as rigid bodies with their residues.

    Parameters
    ----------
    coords : (M, 3) atoms to move, Å.
    atom_residue : (M,) index of each atom's residue into the residue arrays.
    old_points, new_points : (R, 3) residue points ``C^r`` before and after the edit.
    rotations : (R, 3, 3) the residues' rotations (:func:`residue_rotations`).

    Returns
    -------
    (M, 3) new coordinates.
    """
    local = coords - old_points[atom_residue]
    return new_points[atom_residue] + np.einsum("aij,aj->ai", rotations[atom_residue], local)
