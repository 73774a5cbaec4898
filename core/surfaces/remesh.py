"""Progressive remeshing: a base mesh of 6 triangles refined by 4-to-1 subdivision, every
new vertex projected onto the molecular surface (6, 24, 96, ... triangles).

Projection is along rays from outside: towards a centre inside the molecule for the whole
surface (base mesh: a triangular bipyramid about the longest principal axis), or along
the inward normal of a site (base mesh: a hexagon of 6 triangles around the site, e.g. a
ligand, seen from outside). A new vertex lies where the ray through the midpoint of its
edge first meets the surface. The error of a level is measured along the rays through the
centres of the faces of the finest level: the distance between the surface and the plane
of the face of that level that the ray crosses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.surfaces.globe import principal_axes
from core.surfaces.mesh import TriangleMesh
from core.surfaces.molecular import MolecularSurface


@dataclass(frozen=True, eq=False)
class Remesh:
    """The meshes of levels 0, 1, ... (6 · 4**level triangles) and their errors.

    Attributes
    ----------
    meshes : tuple of TriangleMesh
    rms_error, max_error : tuple of float, Å
        Distance along the projection rays between each level and the molecular surface.
    """

    meshes: tuple[TriangleMesh, ...]
    rms_error: tuple[float, ...]
    max_error: tuple[float, ...]


@dataclass(frozen=True)
class _Rays:
    """How parameters (unit directions, or points of a plane) become rays from outside."""

    centre: np.ndarray
    normal: np.ndarray | None  # None: radial rays towards the centre
    reach: float

    def cast(self, surface: MolecularSurface, params: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(origins, unit directions, distance to the surface) of the rays of ``params``."""
        if self.normal is None:
            origins, directions = self.centre + self.reach * params, -params
        else:
            origins, directions = params + self.reach * self.normal, np.broadcast_to(-self.normal, params.shape)
        depth = surface.field.cast_rays(origins, directions, 2 * self.reach)
        if np.isnan(depth).any():
            raise ValueError(
                f"{surface.atoms.entry_id}: {int(np.isnan(depth).sum())} of {len(depth)} remeshing rays "
                "miss the molecular surface (the site patch reaches beyond the molecule?)"
            )
        return origins, np.array(directions), depth

    def midpoint(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        mid = (a + b) / 2
        return mid / np.linalg.norm(mid, axis=-1, keepdims=True) if self.normal is None else mid


def remesh(
    surface: MolecularSurface, levels: int = 5, *, site: np.ndarray | None = None, site_radius: float = 10.0
) -> Remesh:
    """Remesh the whole molecular surface, or the patch around ``site``, to ``levels``.

    Parameters
    ----------
    surface : MolecularSurface
    levels : int
        Finest level (``6 · 4**levels`` triangles), 0 to 7.
    site : (k, 3) float, Å, optional
        Atoms of the site (e.g. a ligand, left out of ``surface``); the patch covers the
        surface within ``site_radius`` Å of them, seen from outside.
    """
    if not 0 <= levels <= 7:
        raise ValueError(f"levels must lie in [0, 7]; got {levels}")
    coords = surface.atoms.coords[surface.mask]
    centroid, axes = principal_axes(coords)
    inner = surface.field.inside_point_near(centroid)
    reach = float(np.linalg.norm(coords - inner, axis=1).max() + 10.0)
    if site is None:
        rays = _Rays(inner, None, reach)
        params = np.array([axes[2], -axes[2], *(np.cos(a) * axes[0] + np.sin(a) * axes[1] for a in np.radians([0, 120, 240]))])
        faces = np.array([[0, 2, 3], [0, 3, 4], [0, 4, 2], [1, 3, 2], [1, 4, 3], [1, 2, 4]])
    else:
        site = np.asarray(site, dtype=np.float64).reshape(-1, 3)
        centre = site.mean(axis=0)
        normal = centre - inner
        normal /= np.linalg.norm(normal)
        b1 = np.cross(normal, axes[0] if abs(normal @ axes[0]) < 0.9 else axes[1])
        b1 /= np.linalg.norm(b1)
        b2 = np.cross(normal, b1)
        offsets = site - centre
        radius = site_radius + np.linalg.norm(offsets - np.outer(offsets @ normal, normal), axis=1).max()
        rim = [centre + radius * (np.cos(a) * b1 + np.sin(a) * b2) for a in np.radians(np.arange(0, 360, 60))]
        rays = _Rays(centre, normal, reach)
        params = np.array([centre, *rim])
        faces = np.array([[0, k, k % 6 + 1] for k in range(1, 7)])
    origins, directions, depth = rays.cast(surface, params)
    vertices = origins + depth[:, None] * directions
    levels_faces = [faces]
    for _ in range(levels):
        params, vertices, faces = _subdivide(surface, rays, params, vertices, faces)
        levels_faces.append(faces)
    meshes = tuple(TriangleMesh(vertices[: f.max() + 1], f) for f in levels_faces)
    rms, worst = _errors(surface, rays, params, vertices, levels_faces)
    return Remesh(meshes, rms, worst)


def _subdivide(
    surface: MolecularSurface, rays: _Rays, params: np.ndarray, vertices: np.ndarray, faces: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """4-to-1 split: children of face f are faces 4f .. 4f+3; new vertices are appended."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    if rays.normal is None:
        new_params = rays.midpoint(vertices[unique[:, 0]] - rays.centre, vertices[unique[:, 1]] - rays.centre)
    else:
        new_params = rays.midpoint(params[unique[:, 0]], params[unique[:, 1]])
    origins, directions, depth = rays.cast(surface, new_params)
    mid = len(vertices) + inverse.reshape(-1, 3)  # midpoints of edges ab, bc, ca
    a, b, c = faces.T
    ab, bc, ca = mid.T
    children = np.stack([np.stack(f, axis=1) for f in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))], axis=1)
    return (
        np.concatenate([params, new_params]),
        np.concatenate([vertices, origins + depth[:, None] * directions]),
        children.reshape(-1, 3),
    )


def _errors(
    surface: MolecularSurface, rays: _Rays, params: np.ndarray, vertices: np.ndarray, levels_faces: list[np.ndarray]
) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Distances along the rays through the centres of the finest faces to the surface and
    to the plane of the face of each level that contains them."""
    finest = levels_faces[-1]
    corners = params[finest]
    if rays.normal is None:
        query = corners.sum(axis=1)
        query /= np.linalg.norm(query, axis=1, keepdims=True)
    else:
        query = corners.mean(axis=1)
    origins, directions, depth = rays.cast(surface, query)
    rms, worst = [], []
    for level, faces in enumerate(levels_faces):
        ancestor = faces[np.arange(len(finest)) // 4 ** (len(levels_faces) - 1 - level)]
        a, b, c = (vertices[ancestor[:, k]] for k in range(3))
        normal = np.cross(b - a, c - a)
        t = np.einsum("ij,ij->i", a - origins, normal) / np.einsum("ij,ij->i", directions, normal)
        error = np.abs(t - depth)
        rms.append(float(np.sqrt(np.mean(error**2))))
        worst.append(float(error.max()))
    return tuple(rms), tuple(worst)
