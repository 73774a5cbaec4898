"""A tube swept along a sampled curve, computed with numpy (no VTK filter).

The curve is given as rings: a centre, a unit tangent and a unit normal per ring. Ring
vertices lie at ``centre + radius (cos a normal + sin a binormal)`` for ``n_sides`` angles
``a``, so any ring can be recomputed on its own: during a drag only the rings of the
residues that moved are swept again and written into the existing mesh arrays.

Normals come from parallel transport along the whole curve once (a rotation-minimising
frame, so the tube does not twist); after an edit each ring's normal is the stored one
turned by the smallest rotation that takes the stored tangent onto the new tangent.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (n, 3) arrays (``np.cross`` without its axis handling: faster)."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    return np.column_stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def perpendicular(tangents: np.ndarray) -> np.ndarray:
    """Unit vectors perpendicular to the unit ``tangents`` (n, 3), built from the least aligned axis."""
    axis = np.eye(3)[np.argmin(np.abs(tangents), axis=1)]
    vectors = cross(tangents, axis)
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


def minimal_rotation(vectors: np.ndarray, source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Turn each of ``vectors`` (n, 3) by the smallest rotation taking unit ``source[i]`` onto
    unit ``target[i]`` (Rodrigues' formula). Where ``source == target`` the vector is unchanged."""
    axis = cross(source, target)
    cosine = np.einsum("ij,ij->i", source, target)
    scale = 1.0 / np.maximum(1.0 + cosine, 1e-12)
    along = np.einsum("ij,ij->i", axis, vectors)
    turned = vectors * cosine[:, None] + cross(axis, vectors) + axis * (along * scale)[:, None]
    return np.where(np.all(source == target, axis=1)[:, None], vectors, turned)


def transported_normals(tangents: np.ndarray) -> np.ndarray:
    """Normals of a rotation-minimising frame along unit ``tangents`` (n, 3) (parallel transport).

    Each ring starts from an arbitrary perpendicular; the twist between a ring's
    transported predecessor and its own normal is accumulated and undone, all vectorised.
    """
    normals = perpendicular(tangents)
    if len(tangents) < 2:
        return normals
    carried = minimal_rotation(normals[:-1], tangents[:-1], tangents[1:])
    own = normals[1:]
    twist = np.arctan2(np.einsum("ij,ij->i", cross(own, carried), tangents[1:]), np.einsum("ij,ij->i", own, carried))
    angle = np.concatenate([[0.0], np.cumsum(twist)])
    binormals = cross(tangents, normals)
    return normals * np.cos(angle)[:, None] + binormals * np.sin(angle)[:, None]


def ring_vertices(
    centres: np.ndarray, tangents: np.ndarray, normals: np.ndarray, radii: np.ndarray, n_sides: int
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and vertex normals of tube rings.

    Parameters
    ----------
    centres, tangents, normals : (r, 3) ring centres (Å), unit tangents and unit normals.
    radii : (r,) tube radius per ring, Å.
    n_sides : vertices per ring.

    Returns
    -------
    points, vertex_normals : (r * n_sides, 3), ring by ring.
    """
    frames = np.concatenate([normals, cross(tangents, normals)], axis=1)  # (r, 6): normal, binormal
    circle, placed = _ring_matrices(n_sides)
    # one small product per ring (a stack of 1-row matrices): fast, never split over BLAS threads,
    # and each ring's vertices come out the same bit for bit however many rings are swept together
    radial = frames[:, None, :] @ circle
    points = np.concatenate([frames * radii[:, None], centres], axis=1)[:, None, :] @ placed
    return points.reshape(-1, 3), radial.reshape(-1, 3)


@lru_cache(maxsize=8)
def _ring_matrices(n_sides: int) -> tuple[np.ndarray, np.ndarray]:
    """Matrices taking a ring's (normal, binormal) (6,) to its radial unit vectors (3 n_sides,),
    and (radius normal, radius binormal, centre) (9,) to its vertices: one matrix product per
    ring (much faster than broadcasting over the short xyz axis)."""
    angle = 2.0 * np.pi * np.arange(n_sides) / n_sides
    circle = np.zeros((6, n_sides, 3))
    for axis in range(3):
        circle[axis, :, axis] = np.cos(angle)
        circle[3 + axis, :, axis] = np.sin(angle)
    circle = circle.reshape(6, -1)
    return circle, np.vstack([circle, np.tile(np.eye(3), n_sides)])


def coarse_rows(n_rings: int, n_sides: int, ring_step: int, side_step: int) -> tuple[np.ndarray, int, int]:
    """Rows of a tube's vertices that make a coarser tube of the same curve: every
    ``ring_step``-th ring (the last one always) and every ``side_step``-th side (a divisor of
    ``n_sides``: the sides kept still make a regular polygon). Returns the rows, ring by ring,
    and the numbers of rings and sides kept."""
    rings = np.unique(np.r_[np.arange(0, n_rings, ring_step), n_rings - 1])
    sides = np.arange(0, n_sides, side_step)
    return (rings[:, None] * n_sides + sides).ravel(), len(rings), len(sides)


def tube_faces(n_rings: int, n_sides: int, first: int = 0) -> np.ndarray:
    """Quads (n, 4) joining consecutive rings of a tube whose vertices start at ``first``."""
    ring = np.arange(n_rings - 1)[:, None] * n_sides
    side = np.arange(n_sides)[None, :]
    following = (side + 1) % n_sides
    quads = np.stack([ring + side, ring + following, ring + n_sides + following, ring + n_sides + side], axis=-1)
    return quads.reshape(-1, 4) + first


def cap_vertices(centre: np.ndarray, rim: np.ndarray, outward: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A flat end cap: the rim vertices (n_sides, 3) again plus the centre, all with normal ``outward``."""
    points = np.vstack([rim, centre])
    return points, np.repeat(outward[None, :], len(points), axis=0)


def cap_faces(n_sides: int, first: int) -> np.ndarray:
    """Triangles (n_sides, 3) of a cap whose rim starts at ``first`` and whose centre follows the rim."""
    side = np.arange(n_sides)
    return np.stack([side, (side + 1) % n_sides, np.full(n_sides, n_sides)], axis=-1) + first
