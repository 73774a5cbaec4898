"""What the layers share to make their pyvista meshes and rewrite them in place: glyphs (one
small sphere per centre, as one mesh), polylines and bond lines, pyvista's cell arrays, and
writes of rows straight into a mesh's VTK arrays (no copy, no new mesh)."""

from __future__ import annotations

from functools import cache
from itertools import pairwise

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import vtk_to_numpy

Rows = np.ndarray | slice
"""Rows of a mesh's points: sorted indices, or a slice (faster to read and write)."""


@cache
def unit_sphere() -> tuple[np.ndarray, np.ndarray]:
    """The sphere every glyph copies: its points (v, 3) on the unit sphere (its normals too) and
    its triangles (f, 3); read-only."""
    sphere = pv.Icosphere(radius=1.0, nsub=1)
    points, faces = np.array(sphere.points), np.array(sphere.regular_faces)
    points.flags.writeable = faces.flags.writeable = False
    return points, faces


def glyphs(centres: np.ndarray, radius: float, colours: np.ndarray) -> pv.PolyData:
    """Spheres of ``radius`` (Å) at ``centres`` (n, 3) as one mesh, coloured per sphere ((n, 3) uint8)."""
    sphere, sphere_faces = unit_sphere()
    n, v = len(centres), len(sphere)
    if n == 0:
        return pv.PolyData()
    faces = (sphere_faces[None] + v * np.arange(n)[:, None, None]).reshape(-1, 3)
    mesh = pv.PolyData.from_regular_faces(_glyph_points(centres, radius * sphere), faces)
    mesh.point_data["Normals"] = np.tile(sphere, (n, 1))
    mesh.point_data.active_normals_name = "Normals"
    mesh.point_data["colours"] = np.repeat(np.asarray(colours, dtype=np.uint8).reshape(-1, 3), v, axis=0)
    mesh.field_data["radius"] = [radius]
    return mesh


def glyph_rows(which: Rows, n: int, offset: int = 0) -> Rows:
    """Rows of the points of glyphs ``which`` of a block of ``n`` glyphs starting at glyph ``offset``."""
    return shift(which, offset, n, len(unit_sphere()[0]))


def move_glyphs(mesh: pv.PolyData, which: Rows, centres: np.ndarray) -> None:
    """Put glyphs ``which`` of ``mesh`` (made by :func:`glyphs`) at ``centres`` (k, 3), in place."""
    sphere = unit_sphere()[0]
    radius = float(mesh.field_data["radius"][0])
    write(mesh, glyph_rows(which, mesh.n_points // len(sphere)), _glyph_points(centres, radius * sphere))


def colour_glyphs(mesh: pv.PolyData, colours: np.ndarray) -> None:
    """Colour every glyph of ``mesh`` with its row of ``colours`` ((n, 3) uint8), in place."""
    write(mesh, slice(None), np.repeat(colours, len(unit_sphere()[0]), axis=0), "colours")


def write(mesh: pv.PolyData, where: Rows, values: np.ndarray, array: str | None = None) -> None:
    """Overwrite rows ``where`` of the points (or of point array ``array``) of ``mesh`` in place."""
    target = mesh.GetPoints().GetData() if array is None else mesh.GetPointData().GetArray(array)
    vtk_to_numpy(target)[where] = values
    target.Modified()
    mesh.Modified()


def collapse(mesh: pv.PolyData, rows: Rows) -> None:
    """Put the points ``rows`` of ``mesh`` onto the first of them: their faces and lines then
    cover no pixel."""
    points = vtk_to_numpy(mesh.GetPoints().GetData())
    if len(points[rows]):
        write(mesh, rows, points[rows][0])


def span(indices: np.ndarray) -> Rows:
    """Sorted ``indices`` as a slice when they are consecutive (faster to read and write)."""
    if len(indices) and indices[-1] - indices[0] + 1 == len(indices):
        return slice(int(indices[0]), int(indices[-1]) + 1)
    return indices


def shift(rows: Rows, offset: int, n: int, width: int = 1) -> Rows:
    """Rows ``rows`` of a block of ``n`` rows starting at ``offset``, each widened to ``width`` rows."""
    if isinstance(rows, slice):
        start, stop, _ = rows.indices(n)
        return slice((offset + start) * width, (offset + stop) * width)
    return ((offset + np.asarray(rows))[:, None] * width + np.arange(width)).ravel()


def compact(mesh: pv.PolyData) -> pv.PolyData:
    """``mesh`` with its faces stored in 32 bits (VTK's default is 64): half the memory of the
    faces of a large ribbon."""
    mesh.GetPolys().ConvertTo32BitStorage()
    return mesh


def cells(blocks: list[np.ndarray]) -> np.ndarray:
    """pyvista's flat cell array ``[n, i0, ..., n, j0, ...]`` from blocks of equal-size cells."""
    return np.concatenate([np.column_stack([np.full(len(b), b.shape[1]), b]).ravel() for b in blocks if len(b)])


def polylines(bounds: np.ndarray) -> np.ndarray:
    """One polyline per consecutive range ``bounds[k]:bounds[k+1]`` of points (a cell array)."""
    return np.concatenate([np.r_[stop - start, start:stop] for start, stop in pairwise(bounds)])


def polyline(points: np.ndarray) -> pv.PolyData:
    """One polyline through ``points`` (n, 3)."""
    return pv.PolyData(points.copy(), lines=polylines(np.array([0, len(points)])))


def bond_lines(coords: np.ndarray, bonds: np.ndarray, colours: np.ndarray) -> pv.PolyData:
    """Lines for ``bonds`` (b, 2) over all atoms (points in coordinate-row order, no vertex cells)."""
    if len(bonds) == 0:
        return pv.PolyData()
    mesh = pv.PolyData(coords.copy(), lines=np.column_stack([np.full(len(bonds), 2), bonds]).ravel())
    mesh.point_data["colours"] = colours
    return mesh


def box_edges(edge: float) -> pv.PolyData:
    """The twelve edges of a cube of side ``edge`` (Å) around the origin."""
    corners = 0.5 * edge * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    pairs = [(a, b) for a in range(8) for b in range(a + 1, 8) if (a ^ b).bit_count() == 1]
    return pv.PolyData(corners, lines=np.column_stack([np.full(len(pairs), 2), pairs]).ravel())


def _glyph_points(centres: np.ndarray, template: np.ndarray) -> np.ndarray:
    """``template`` (v, 3) placed at every centre (n, 3): (n * v, 3), one small product per centre."""
    v = len(template)
    placement = np.vstack([np.tile(np.eye(3), v), template.reshape(1, -1)])
    return (np.column_stack([centres, np.ones(len(centres))])[:, None, :] @ placement).reshape(-1, 3)
