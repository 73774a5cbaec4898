"""Triangle meshes as arrays: vertices ``(n, 3)`` in Å and faces ``(m, 3)`` of vertex indices.

Faces are oriented counter-clockwise seen from outside, so that the normals point outwards
and the signed volume of a closed surface is positive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    """A triangulated surface.

    Attributes
    ----------
    vertices : (n_vertices, 3) float64, Å
    faces : (n_faces, 3) int64
        Vertex indices, counter-clockwise seen from outside.
    """

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]

    def __post_init__(self) -> None:
        vertices = np.asarray(self.vertices, dtype=np.float64)
        faces = np.asarray(self.faces, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"vertices must have shape (n, 3); got {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"faces must have shape (m, 3); got {faces.shape}")
        if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError(f"faces refer to vertices outside 0..{len(vertices) - 1}")
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    def face_normals(self) -> np.ndarray:
        """(n_faces, 3) unit normals (zero for degenerate faces)."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        cross = np.cross(b - a, c - a)
        norm = np.linalg.norm(cross, axis=1, keepdims=True)
        return np.divide(cross, norm, out=np.zeros_like(cross), where=norm > 0)

    def area(self) -> float:
        """Total area, Å²."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())

    def volume(self) -> float:
        """Signed enclosed volume, Å³ (divergence theorem; meaningful for closed meshes)."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)

    def is_closed(self) -> bool:
        """True for a watertight, consistently oriented surface: every edge joins exactly two
        faces that traverse it in opposite directions."""
        n = len(self.vertices)
        directed = self.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        if np.any(directed[:, 0] == directed[:, 1]):
            return False
        forward = directed[:, 0] * n + directed[:, 1]
        backward = directed[:, 1] * n + directed[:, 0]
        unique = np.unique(forward)
        return len(unique) == len(forward) and np.array_equal(unique, np.unique(backward))

    def boundary_edges(self) -> np.ndarray:
        """(k, 2) directed edges that have no opposite edge (the rim of an open surface)."""
        n = len(self.vertices)
        directed = self.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
        missing = ~np.isin(directed[:, 1] * n + directed[:, 0], directed[:, 0] * n + directed[:, 1])
        return directed[missing]
