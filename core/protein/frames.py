"""The rotation of each residue after an edit of its ribbon, and the rigid-body remapping.

Every atom ``x`` of residue ``i`` moves with the curve around it:

    x' = C^r'_i + R_i (x - C^r_i),

``C^r`` the residue's curve point before and after the edit, and ``R_i`` the least-squares
(Kabsch) rotation that carries the curve's stretch within :data:`REACH` residues either side
of ``i`` (sampled at :data:`SAMPLES` points, each sampling about its centroid), and the
curve's tangent at the residue (:data:`TANGENT_WEIGHT`), from before the edit to after it. A
rigid motion of the curve moves every residue by that motion; a curve left as it was turns
none.

This departs from the paper (and the mathematics document, section 10.4), which turns each
residue with the change of the curve's Frenet frame at its point. A Frenet normal rests on
the curve's second derivative: undefined on straight pieces, flipping at inflections, and
where a residue's curve hardly turns, control points moved by 0.001 Å swing it by tenths of
a degree, or by tens of degrees where it crosses the threshold below which a neighbour's
normal must stand in; a fit's result then hung on the last bits of floating point. This
rotation rests on positions and first derivatives only and changes in proportion to the
change of the curve.
"""

from __future__ import annotations

import numpy as np

from core.curves.splines import SplineSpace

REACH = 3
"""Finest curve segments (one per residue) on each side of a residue that turn it."""
PER_SEGMENT = 2
"""Curve points sampled per finest segment over a residue's stretch (at its knots and
midpoints: every residue's stretch on the same grid, so each point is evaluated once)."""
SAMPLES = 2 * REACH * PER_SEGMENT + 1
"""Curve points sampled over a residue's stretch, ends included."""
TANGENT_WEIGHT = 2.0
"""How much the residue's own tangent counts, against the spread of its stretch: the
rotation carries the old tangent nearly onto the new one, and the stretch sets the turn
about it. The stretch alone lagged where an edit bends the chain (a third more stretched
peptide bonds after a drag than the Frenet frames left; with the tangent as many); the
rotation's response to the last bits of the curve grows from 0.09° to 0.22° at most."""
WELL_CONDITIONED = 1e-6
"""Determinant (of the covariance scaled to unit norm) above which its nearest rotation is
found by Newton's iteration (:func:`_nearest_rotations`); the SVD below."""
NEWTON_STEPS = 30
"""Most steps of that iteration (it converges quadratically: 6-9 on real chains)."""


def stretches(u: np.ndarray, span: tuple[float, float], n_segments: int) -> np.ndarray:
    """(N, :data:`SAMPLES`) the stretch of curve that turns each residue at ``u`` (N,): the
    indices ``k`` of its sample points ``k / (PER_SEGMENT n_segments)``, :data:`REACH`
    segments either side of the grid point nearest ``u``, shifted to stay within ``span``
    (the chain's residues, not the padding beyond them, where the curve stands still) so
    that the ends of a chain turn with as much curve as its middle."""
    per = PER_SEGMENT * n_segments
    first, last = int(np.ceil(span[0] * per - 1e-9)), int(np.floor(span[1] * per + 1e-9))
    width = SAMPLES - 1
    low = np.clip(np.rint(np.asarray(u, dtype=float) * per).astype(np.int64) - width // 2,
                  first, max(first, last - width))
    return np.minimum(low[:, None] + np.arange(SAMPLES), max(first, last))


def residue_rotations(space: SplineSpace, old_points: np.ndarray, new_points: np.ndarray, u: np.ndarray,
                      span: tuple[float, float] = (0.0, 1.0)) -> np.ndarray:
    """(N, 3, 3) rotations (determinant +1) of the residues at parameters ``u`` (N,) when the
    curve's finest control points change from ``old_points`` to ``new_points``; ``span``, the
    parameters the chain's residues cover (:func:`stretches`)."""
    stretch = stretches(u, span, space.n_segments)
    if stretch.size == 0:
        return np.zeros((0, 3, 3))
    low, high = int(stretch.min()), int(stretch.max())
    grid = np.arange(low, high + 1) / (PER_SEGMENT * space.n_segments)
    before = space.evaluate(old_points, grid)  # each grid point once, then summed over each stretch
    after = space.evaluate(new_points, grid)
    before -= before.mean(axis=0)  # (keeps the sums small)
    after -= after.mean(axis=0)
    outer = (after[:, :, None] * before[:, None, :]).reshape(-1, 9)
    rows = stretch - low
    products, sum_after, sum_before = outer[rows[:, 0]].copy(), after[rows[:, 0]].copy(), before[rows[:, 0]].copy()
    for k in range(1, SAMPLES):
        products += outer[rows[:, k]]
        sum_after += after[rows[:, k]]
        sum_before += before[rows[:, k]]
    products -= (sum_after[:, :, None] * sum_before[:, None, :]).reshape(-1, 9) / SAMPLES
    tangents = [space.evaluate(points, u, 1) for points in (new_points, old_points)]
    tangents = [t / np.linalg.norm(t, axis=1, keepdims=True) for t in tangents]
    weight = TANGENT_WEIGHT * np.linalg.norm(products, axis=1)
    products += weight[:, None] * (tangents[0][:, :, None] * tangents[1][:, None, :]).reshape(-1, 9)
    return _nearest_rotations(products.reshape(-1, 3, 3))


def _nearest_rotations(covariance: np.ndarray) -> np.ndarray:
    """(N, 3, 3) the rotations ``R`` that maximise ``trace(R^T H)`` for each ``H`` of
    ``covariance`` (N, 3, 3): its orthogonal polar factor, by Higham's scaled Newton
    iteration ``X <- (g X + X^-T / g) / 2`` on the nine entries as arrays (the inverse by
    cofactors; several times as fast as a batched SVD), where ``det H`` is clearly positive;
    elsewhere (a reflection nearer, or a straight stretch) by the SVD with the sign of its
    last axis fixed (Kabsch)."""
    size = np.linalg.norm(covariance, axis=(1, 2))
    x = covariance / np.where(size > 0, size, 1.0)[:, None, None]
    entries = x.reshape(-1, 9).T.copy()  # (9, N): row-major a b c / d e f / g h i
    newton = _cofactors_and_determinant(entries)[1] > WELL_CONDITIONED
    y = entries[:, newton]
    converged = False
    for _ in range(NEWTON_STEPS):
        cofactors, determinant = _cofactors_and_determinant(y)
        inverse_t = cofactors / determinant
        scale = np.sqrt(np.sqrt(np.sum(inverse_t**2, axis=0) / np.sum(y**2, axis=0)))
        y, last = 0.5 * (scale * y + inverse_t / scale), y
        if converged:
            break
        converged = np.abs(y - last).max(initial=0.0) < 1e-9  # then one more step is exact to rounding
    rotations = np.empty_like(x)
    rotations[newton] = y.T.reshape(-1, 3, 3)
    if not newton.all():
        left, _, right = np.linalg.svd(x[~newton])
        sign = np.where(np.linalg.det(left @ right) < 0, -1.0, 1.0)
        left[:, :, 2] *= sign[:, None]
        rotations[~newton] = left @ right
    return rotations


def _cofactors_and_determinant(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cofactor matrices (9, N) and determinants (N,) of the matrices whose entries,
    row by row, are the rows of ``m`` (9, N)."""
    a, b, c, d, e, f, g, h, i = m
    cofactors = np.stack([e * i - f * h, f * g - d * i, d * h - e * g,
                          c * h - b * i, a * i - c * g, b * g - a * h,
                          b * f - c * e, c * d - a * f, a * e - b * d])
    return cofactors, a * cofactors[0] + b * cofactors[1] + c * cofactors[2]


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
