"""Residue frames on a ribbon curve and the rigid-body remapping of residues after an edit.

Each residue carries the tangent–normal–binormal (Frenet) frame of the curve at its
parameter (mathematics document, section 10.4). After an edit every atom ``x`` of residue
``i`` moves with the change of that frame:

    x' = C^r'_i + F'_i F_i^T (x - C^r_i),     F = [T N B] (columns).

Frenet normals are undefined on straight pieces and flip sign at inflections, so frames
are made continuous: along the chain each binormal keeps the sign of its predecessor,
residues where the curve hardly turns take the normal of their neighbours where it does
(the nearer the more), and frames of an edited curve are oriented like those of the same
residues before. Between turning enough and not the two are blended, so a curve moved a
little never turns a residue a lot. (Switched at one threshold, the frame of a residue
whose curve crossed it turned 20-75° for a 0.005 Å move, and adenylate kinase fitted into
a map from starts 0.001 Å apart had one residue's frame 35° apart, which the regularization
that followed made two closures of its loop, 3 Å apart.)
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_banded

from core.curves.splines import SplineSpace

MIN_TURN = 0.05
"""Frenet normals are used where the tangent turns by more than this (radians) per curve
segment (``|f' x f''| / |f'|^2 / 2**J``): about 1 in helices, 0.1-0.6 in strands and
loops, 0 on straight pieces and at inflections, where the normal is unstable. Below half of
it the neighbours' normals are used, in between a blend of both."""


def residue_frames(
    space: SplineSpace, points: np.ndarray, u: np.ndarray, reference: np.ndarray | None = None
) -> np.ndarray:
    """Rotation matrices ``[T N B]`` (columns) of the curve at the parameters ``u``.

    Where the curve turns less than :data:`MIN_TURN` the normal is a hint from the residues
    around that turn more, each weighted by how clearly (from ``MIN_TURN`` to twice that)
    and halved with every residue between, made perpendicular to the tangent, and turned
    towards the line of the residue's own Frenet normal as far as the residue turns (from
    ``MIN_TURN / 2`` to ``MIN_TURN``); so a rigid motion of the curve moves every frame by the
    same motion, and the frames change continuously with ``points`` (but where a binormal
    turns 90° from its reference's).

    Parameters
    ----------
    space, points : the curve (finest control points).
    u : (N,) residue parameters, in chain order.
    reference : (N, 3, 3) frames of the same residues before an edit; the new binormals
        take their signs from these (instead of from the previous residue), and if no
        residue has a usable Frenet frame the reference normals are used.

    Returns
    -------
    (N, 3, 3) float64, orthonormal with determinant +1.
    """
    d1 = space.evaluate(points, u, 1)
    d2 = space.evaluate(points, u, 2)
    tangent = d1 / np.linalg.norm(d1, axis=1, keepdims=True)
    binormal = np.cross(d1, d2)
    strength = np.linalg.norm(binormal, axis=1)
    turn = strength / (space.n_segments * np.einsum("ij,ij->i", d1, d1))
    own = _smoothstep(2.0 * turn / MIN_TURN - 1.0)  # the Frenet normal's share in the frame
    share = _smoothstep(turn / MIN_TURN - 1.0)  # and in the neighbours' hints
    if not share.any():
        share = own
    defined = own > 0
    binormal[defined] /= strength[defined, None]
    binormal[~defined] = 0.0
    chained = share > 0
    if reference is None:
        binormal = _continuous_along_chain(binormal, chained)
    else:
        binormal *= np.where(np.einsum("ij,ij->i", binormal, reference[:, :, 2]) < 0, -1.0, 1.0)[:, None]
    normal = np.cross(binormal, tangent)
    weak = ~chained
    if weak.any():
        hint = _neighbours(share[:, None] * normal) if chained.any() else (
            reference[:, :, 1] if reference is not None else np.zeros_like(normal)
        )
        hint = _perpendicular(hint[weak], tangent[weak])
        along = np.einsum("ij,ij->i", normal[weak], hint)[:, None] * normal[weak]  # the hint on the Frenet normal's line
        normal[weak] = own[weak, None] * along + (1.0 - own[weak, None]) * hint
    normal = _perpendicular(normal, tangent)
    return np.stack([tangent, normal, np.cross(tangent, normal)], axis=2)


def remap_atoms(
    coords: np.ndarray,
    atom_residue: np.ndarray,
    old_points: np.ndarray,
    old_frames: np.ndarray,
    new_points: np.ndarray,
    new_frames: np.ndarray,
) -> np.ndarray:
    """Move atoms as rigid bodies with their residues' frames.

    Parameters
    ----------
    coords : (M, 3) atoms to move, Å.
    atom_residue : (M,) index of each atom's residue into the residue arrays.
    old_points, new_points : (R, 3) residue points ``C^r`` before and after the edit.
    old_frames, new_frames : (R, 3, 3) residue frames before and after.

    Returns
    -------
    (M, 3) new coordinates.
    """
    rotation = np.einsum("rij,rkj->rik", new_frames, old_frames)  # F' F^T
    local = coords - old_points[atom_residue]
    return new_points[atom_residue] + np.einsum("aij,aj->ai", rotation[atom_residue], local)


def _continuous_along_chain(binormal: np.ndarray, defined: np.ndarray) -> np.ndarray:
    """Flip binormals so consecutive well-defined ones never point apart (no 180° jumps)."""
    index = np.flatnonzero(defined)
    if len(index) < 2:
        return binormal
    agree = np.einsum("ij,ij->i", binormal[index[1:]], binormal[index[:-1]]) >= 0
    signs = np.ones(len(binormal))
    signs[index[1:]] = np.cumprod(np.where(agree, 1.0, -1.0))
    return binormal * signs[:, None]


def _smoothstep(x: np.ndarray) -> np.ndarray:
    """0 below 0, 1 above 1, and ``3x² - 2x³`` (smooth at both ends) between."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _neighbours(values: np.ndarray) -> np.ndarray:
    """For every row of ``values`` (N, 3) the sum of the others, each halved with every row
    between (``Σ_{j≠i} 2^-|i-j| values_j``), by two bidiagonal solves; each sum scaled to its
    largest component, so that sums of far, small terms keep their direction."""
    bands = np.zeros((2, len(values)))
    bands[0], bands[1, :-1] = 1.0, -0.5

    def halved(x: np.ndarray) -> np.ndarray:  # y_i = (y_{i-1} + x_{i-1}) / 2, y_0 = 0
        return solve_banded((1, 0), bands, np.vstack([np.zeros((1, 3)), 0.5 * x[:-1]]))

    total = halved(values) + halved(values[::-1])[::-1]
    scale = np.abs(total).max(axis=1, keepdims=True)
    return np.divide(total, scale, out=np.zeros_like(total), where=scale > 0)


def _perpendicular(hint: np.ndarray, tangent: np.ndarray) -> np.ndarray:
    """Unit vectors perpendicular to ``tangent``, as close as possible to ``hint``."""
    vector = hint - np.einsum("ij,ij->i", hint, tangent)[:, None] * tangent
    weak = np.linalg.norm(vector, axis=1) < 1e-9  # no usable hint: any perpendicular
    if weak.any():
        axis = np.eye(3)[np.argmin(np.abs(tangent[weak]), axis=1)]
        vector[weak] = np.cross(tangent[weak], axis)
    return vector / np.linalg.norm(vector, axis=1, keepdims=True)
