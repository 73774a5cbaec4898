"""Residue frames on a ribbon curve and the rigid-body remapping of residues after an edit.

Each residue carries the tangent–normal–binormal (Frenet) frame of the curve at its
parameter (mathematics document, section 10.4). After an edit every atom ``x`` of residue
``i`` moves with the change of that frame:

    x' = C^r'_i + F'_i F_i^T (x - C^r_i),     F = [T N B] (columns).

Frenet normals are undefined on straight pieces and flip sign at inflections, so frames
are made continuous: along the chain each binormal keeps the sign of its predecessor,
residues where the curve hardly turns take the normal of the nearest residue where it
does, and frames of an edited curve are oriented like those of the same residues before.
"""

from __future__ import annotations

import numpy as np

from core.curves.splines import SplineSpace

MIN_TURN = 0.05
"""Frenet normals are used where the tangent turns by more than this (radians) per curve
segment (``|f' x f''| / |f'|^2 / 2**J``): about 1 in helices, 0.1-0.6 in strands and
loops, 0 on straight pieces and at inflections, where the normal is unstable."""


def residue_frames(
    space: SplineSpace, points: np.ndarray, u: np.ndarray, reference: np.ndarray | None = None
) -> np.ndarray:
    """Rotation matrices ``[T N B]`` (columns) of the curve at the parameters ``u``.

    Where the curve turns too little (:data:`MIN_TURN`) the normal is that of the nearest
    residue with a usable Frenet frame, made perpendicular to the tangent; so a rigid
    motion of the curve moves every frame by the same motion.

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
    defined = strength > MIN_TURN * space.n_segments * np.einsum("ij,ij->i", d1, d1)
    binormal[defined] /= strength[defined, None]
    binormal[~defined] = 0.0
    if reference is None:
        binormal = _continuous_along_chain(binormal, defined)
    else:
        binormal *= np.where(np.einsum("ij,ij->i", binormal, reference[:, :, 2]) < 0, -1.0, 1.0)[:, None]
    normal = np.cross(binormal, tangent)
    if not defined.all():
        hint = normal[_nearest_defined(defined)] if defined.any() else (
            reference[:, :, 1] if reference is not None else np.zeros_like(normal)
        )
        normal[~defined] = _perpendicular(hint[~defined], tangent[~defined])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
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


def _nearest_defined(defined: np.ndarray) -> np.ndarray:
    """For every residue the index of the nearest residue with a defined frame (itself if defined)."""
    here = np.arange(len(defined))
    index = np.flatnonzero(defined)
    if len(index) == 0:
        return here
    position = np.searchsorted(index, here)
    before = index[np.maximum(position - 1, 0)]
    after = index[np.minimum(position, len(index) - 1)]
    return np.where(here - before <= after - here, before, after)


def _perpendicular(hint: np.ndarray, tangent: np.ndarray) -> np.ndarray:
    """Unit vectors perpendicular to ``tangent``, as close as possible to ``hint``."""
    vector = hint - np.einsum("ij,ij->i", hint, tangent)[:, None] * tangent
    weak = np.linalg.norm(vector, axis=1) < 1e-9  # no usable hint: any perpendicular
    if weak.any():
        axis = np.eye(3)[np.argmin(np.abs(tangent[weak]), axis=1)]
        vector[weak] = np.cross(tangent[weak], axis)
    return vector / np.linalg.norm(vector, axis=1, keepdims=True)
