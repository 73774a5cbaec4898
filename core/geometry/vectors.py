"""Row-wise vector geometry on (n, 3) arrays: lengths, distances, angles, dihedrals and
turns, written out with einsum (``np.linalg.norm`` and ``np.cross`` cost several times
more along a short last axis)."""

from __future__ import annotations

import numpy as np


def lengths(v: np.ndarray) -> np.ndarray:
    """Row-wise lengths |v| of (n, 3) arrays (``np.linalg.norm`` is several times slower
    along a short last axis)."""
    return np.sqrt(np.einsum("...i,...i", v, v))


def distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise distances |a - b| of (n, 3) arrays, Å."""
    return lengths(a - b)


def angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Row-wise angles a–b–c of (n, 3) arrays, degrees."""
    u, v = a - b, c - b
    cos = np.einsum("...i,...i", u, v) / (lengths(u) * lengths(v))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def dihedral(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Row-wise dihedral angles a–b–c–d of (n, 3) arrays, degrees in (-180, 180]."""
    b1, b2, b3 = b - a, c - b, d - c
    n1, n2 = np.cross(b1, b2), np.cross(b2, b3)
    m = np.cross(n1, b2 / lengths(b2)[..., None])
    return np.degrees(np.arctan2(-np.einsum("...i,...i", m, n2), np.einsum("...i,...i", n1, n2)))


def unit(v: np.ndarray) -> np.ndarray:
    """Rows of ``v`` (n, 3) scaled to length 1."""
    return v / lengths(v)[:, None]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products of (k, 3) arrays (``np.cross`` costs more for short arrays)."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0], out[:, 1], out[:, 2] = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return out


def summed_rows(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(n, 3): the rows of ``values`` (m, 3) added up by ``index`` (m,), as
    ``np.add.at(out, index, values)`` does (as bincounts, several times faster)."""
    return np.stack([np.bincount(index, values[:, k], n) for k in range(3)], axis=1)


def pair_gradient(i: np.ndarray, j: np.ndarray, force: np.ndarray, n: int) -> np.ndarray:
    """(n, 3): ``force`` (m, 3) on atoms ``i`` and its opposite on atoms ``j``, added up."""
    return summed_rows(np.concatenate([i, j]), np.concatenate([force, -force]), n)


def dihedral_gradients(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, ...]:
    """Dihedral angles a–b–c–d (radians; rows of (k, 3) arrays, as :func:`dihedral`) and
    their gradients (per Å) with respect to a and d."""
    b1, b2, b3 = b - a, c - b, d - c
    n1, n2 = cross(b1, b2), cross(b2, b3)
    length = lengths(b2)
    value = np.arctan2(length * np.einsum("ij,ij->i", b1, n2), np.einsum("ij,ij->i", n1, n2))
    first = -length[:, None] * n1 / np.einsum("ij,ij->i", n1, n1)[:, None]
    last = length[:, None] * n2 / np.einsum("ij,ij->i", n2, n2)[:, None]
    return value, first, last


def off_axis(points: np.ndarray, through: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Distances (Å) of ``points`` from the lines through ``through`` along unit ``axis`` (all (k, 3))."""
    arm = points - through
    return lengths(arm - np.einsum("ij,ij->i", arm, axis)[:, None] * axis)


def turned(v: np.ndarray, axis: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Vectors ``v`` (k, 3) turned by ``theta`` (k,, radians) about unit vectors ``axis`` (k, 3) (Rodrigues)."""
    cos, sin = np.cos(theta)[:, None], np.sin(theta)[:, None]
    return v * cos + cross(axis, v) * sin + axis * np.einsum("ij,ij->i", axis, v)[:, None] * (1.0 - cos)
