"""Solvent-excluded molecular surfaces from grid distance transforms.

The solvent-excluded surface (SES) of spheres of van der Waals radius ``r_i`` for a probe of
radius ``p`` is the boundary of the region no probe ball reaches. On a grid:

1. ``s(x) = min_i (|x - a_i| - r_i) - p``, the distance beyond the solvent-accessible surface
   (SAS), is splatted around every atom; the probe centres can go where ``s >= 0`` (the
   accessible region ``A``; by default only its part connected to the outside, so that
   buried cavities are filled).
2. A Euclidean distance transform gives, for every point, the nearest accessible voxel
   ``c``; the distance to ``A`` is ``|x - c| - s(c)`` (the ball of radius ``s(c)`` around
   ``c`` lies in ``A``), which removes most of the grid quantisation.
3. ``F(x) = dist(x, A) - p`` is positive inside the SES and equals the distance to the
   surface there; marching cubes (scikit-image) extracts ``F = 0``.

:class:`SurfaceField` keeps ``F`` and answers the questions the other surface modules ask:
values and mean curvature at any point, rays cast onto the surface, the triangle mesh.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from skimage.measure import marching_cubes

from core import _validate
from core.protein.structure import AtomTable
from core.surfaces.mesh import TriangleMesh
from core.surfaces.properties import atom_charges, electrostatic_potential, nearest_atom_values

PROBE_RADIUS = 1.4
"""Water probe radius, Å."""

MAX_GRID_POINTS = 12_000_000
"""The default grid spacing grows beyond 0.5 Å when a finer grid would have more points."""
MAX_SPACING = 4.0
"""Å: the coarsest default grid step; atoms spread wider than it can serve are refused."""

BONDI_RADII = {
    "H": 1.20, "C": 1.70, "N": 1.55, "O": 1.52, "F": 1.47, "P": 1.80, "S": 1.80, "CL": 1.75,
    "BR": 1.85, "I": 1.98, "SE": 1.90, "NA": 2.27, "K": 2.75, "MG": 1.73, "ZN": 1.39,
    "CU": 1.40, "NI": 1.63,
}  # fmt: skip
"""Van der Waals radii (Å, Bondi 1964); other elements get :data:`DEFAULT_RADIUS`."""

DEFAULT_RADIUS = 1.80


def vdw_radii(elements: NDArray[np.str_]) -> np.ndarray:
    """(n,) van der Waals radii in Å of element symbols (any case)."""
    return np.array([BONDI_RADII.get(e.upper(), DEFAULT_RADIUS) for e in np.asarray(elements)], dtype=np.float64)


def surface_atoms(atoms: AtomTable, *, exclude: NDArray[np.bool_] | None = None) -> np.ndarray:
    """Mask of the atoms that make the molecular surface.

    Every non-water heavy atom of the first conformer (altloc '' or the first altloc met
    under its chain and residue number), minus ``exclude`` (e.g. a ligand whose pocket
    should be seen).
    """
    keep = (atoms.category != "water") & ~np.isin(np.char.upper(atoms.element), ("H", "D"))
    has_alt = np.flatnonzero(atoms.altloc != "")
    if len(has_alt):  # residue-level alternates are separate residues with one number
        numbers = list(zip(atoms.chain[has_alt].tolist(), atoms.resseq[has_alt].tolist(), strict=True))
        first_alt: dict[tuple[str, int], str] = {}
        for number, alt in zip(numbers, atoms.altloc[has_alt].tolist(), strict=True):
            first_alt.setdefault(number, alt)
        keep[has_alt] &= atoms.altloc[has_alt] == np.array([first_alt[n] for n in numbers])
    if exclude is not None:
        keep &= ~np.asarray(exclude, dtype=bool)
    return keep


@dataclass(frozen=True, eq=False)
class SurfaceField:
    """The SES as a grid function ``F`` (positive inside, zero on the surface).

    Attributes
    ----------
    values : (nx, ny, nz) float32, Å
        ``F`` at grid points ``origin + spacing * (i, j, k)``; inside the SES it is the
        distance to the surface.
    origin : (3,) float64, Å
    spacing : float, Å
    probe : float, Å
    """

    values: NDArray[np.float32]
    origin: NDArray[np.float64]
    spacing: float
    probe: float

    def sample(self, points: object, field: NDArray[np.float32] | None = None) -> np.ndarray:
        """``F`` at ``points`` (..., 3) by trilinear interpolation (``-probe`` off the grid)."""
        points = np.asarray(points, dtype=np.float64)
        index = ((points - self.origin) / self.spacing).reshape(-1, 3).T
        grid = self.values if field is None else field
        values = ndimage.map_coordinates(grid, index, order=1, mode="constant", cval=-self.probe)
        return values.reshape(points.shape[:-1])

    @cached_property
    def _smooth(self) -> NDArray[np.float32]:
        """``F`` smoothed over one grid step, for derivatives."""
        return ndimage.gaussian_filter(self.values, 1.0)

    def mean_curvature(self, points: object) -> np.ndarray:
        """Mean curvature (1/Å, positive where convex) of the level sets of ``F`` at ``points``.

        A sphere of radius r has 1/r. Central differences of the field smoothed over one
        grid step.
        """
        points = np.asarray(points, dtype=np.float64)
        flat = points.reshape(-1, 3)
        h = self.spacing
        eye = np.eye(3) * h
        f0 = self.sample(flat, self._smooth)
        plus = np.stack([self.sample(flat + e, self._smooth) for e in eye], axis=1)
        minus = np.stack([self.sample(flat - e, self._smooth) for e in eye], axis=1)
        grad = (plus - minus) / (2 * h)
        hess = np.empty((len(flat), 3, 3))
        hess[:, range(3), range(3)] = (plus - 2 * f0[:, None] + minus) / h**2
        for a, b in ((0, 1), (0, 2), (1, 2)):
            pp, pm = self.sample(flat + eye[a] + eye[b], self._smooth), self.sample(flat + eye[a] - eye[b], self._smooth)
            mp, mm = self.sample(flat - eye[a] + eye[b], self._smooth), self.sample(flat - eye[a] - eye[b], self._smooth)
            hess[:, a, b] = hess[:, b, a] = (pp - pm - mp + mm) / (4 * h**2)
        norm = np.maximum(np.linalg.norm(grad, axis=1), 1e-9)
        trace = np.trace(hess, axis1=1, axis2=2)
        ghg = np.einsum("ni,nij,nj->n", grad, hess, grad)
        curvature = -(norm**2 * trace - ghg) / (2 * norm**3)
        return curvature.reshape(points.shape[:-1])

    def inside_point_near(self, point: object, depth: float = 1.0) -> np.ndarray:
        """(3,) the grid point at least ``depth`` Å inside the SES nearest to ``point``."""
        inside = np.argwhere(self.values >= depth)
        if not len(inside):
            raise ValueError(f"no point lies {depth:g} Å inside the surface")
        positions = self.origin + self.spacing * inside
        return positions[np.argmin(np.linalg.norm(positions - np.asarray(point, dtype=np.float64), axis=1))]

    def mesh(self) -> TriangleMesh:
        """The surface ``F = 0`` triangulated by marching cubes (watertight, outward normals)."""
        vertices, faces, _, _ = marching_cubes(self.values, 0.0, spacing=(self.spacing,) * 3, allow_degenerate=False)
        return TriangleMesh(vertices + self.origin, faces[:, ::-1])

    def cast_rays(self, origins: object, directions: object, length: float) -> np.ndarray:
        """Distance along each ray to its first entry into the SES (NaN for a miss).

        Parameters
        ----------
        origins, directions : (n, 3) float; directions need not be unit vectors
        length : float, Å
            How far each ray is followed.

        Returns
        -------
        (n,) float64, Å, measured along the unit direction.
        """
        origins = _validate.finite_array("origins", origins, ndim=(2,))
        directions = _validate.finite_array("directions", directions, ndim=(2,))
        directions = directions / np.linalg.norm(directions, axis=1, keepdims=True)
        step = self.spacing / 2
        t = np.arange(0.0, length + step, step)
        result = np.full(len(origins), np.nan)
        for chunk in np.array_split(np.arange(len(origins)), max(1, len(origins) * len(t) // 2_000_000)):
            o, d = origins[chunk, None, :], directions[chunk, None, :]
            inside = self.sample(o + t[None, :, None] * d) > 0
            hit = inside.any(axis=1)
            first = inside.argmax(axis=1)
            low, high = t[np.maximum(first - 1, 0)], t[first]
            for _ in range(10):  # bisection on the trilinear field
                mid = (low + high) / 2
                mid_inside = self.sample(o[:, 0] + mid[:, None] * d[:, 0]) > 0
                high = np.where(mid_inside, mid, high)
                low = np.where(mid_inside, low, mid)
            result[chunk] = np.where(hit & (first > 0), (low + high) / 2, np.nan)
        return result


COLOURINGS = ("potential", "curvature", "bfactor")
"""Surface colourings: electrostatic potential (kcal/(mol·e)), mean curvature (1/Å) and the
B-factor of the nearest atom (Å²)."""


@dataclass(frozen=True, eq=False)
class MolecularSurface:
    """The SES of the atoms ``atoms[mask]`` with what is needed to colour it.

    Attributes
    ----------
    atoms : AtomTable
    mask : (n_atoms,) bool
        The atoms that make the surface (and whose charges make the potential).
    field : SurfaceField
    """

    atoms: AtomTable
    mask: NDArray[np.bool_]
    field: SurfaceField

    @cached_property
    def mesh(self) -> TriangleMesh:
        """The triangulated surface."""
        return self.field.mesh()

    @cached_property
    def centre(self) -> np.ndarray:
        """(3,) centroid of the surface atoms, Å."""
        return self.atoms.coords[self.mask].mean(axis=0)

    @cached_property
    def _charges(self) -> np.ndarray:
        return atom_charges(self.atoms)[self.mask]

    def colour(self, kind: str, points: object) -> np.ndarray:
        """Values of the colouring ``kind`` (one of :data:`COLOURINGS`) at ``points`` (..., 3)."""
        coords = self.atoms.coords[self.mask]
        if kind == "potential":
            return electrostatic_potential(points, coords, self._charges)
        if kind == "curvature":
            return self.field.mean_curvature(points)
        if kind == "bfactor":
            return nearest_atom_values(points, coords, self.atoms.b_factor[self.mask])
        raise ValueError(f"colouring must be one of {', '.join(COLOURINGS)}; got {kind!r}")


def molecular_surface(
    atoms: AtomTable,
    *,
    probe: float = PROBE_RADIUS,
    spacing: float | None = None,
    exclude: NDArray[np.bool_] | None = None,
    cavities: bool = False,
    progress: Callable[[str], object] | None = None,
) -> MolecularSurface:
    """The SES of the :func:`surface_atoms` of ``atoms`` (see :func:`ses_field`)."""
    mask = surface_atoms(atoms, exclude=exclude)
    if not mask.any():
        raise ValueError(f"{atoms.entry_id}: no atoms to build a surface from (only water or hydrogens)")
    field = ses_field(atoms.coords[mask], vdw_radii(atoms.element[mask]), probe=probe, spacing=spacing,
                      cavities=cavities, progress=progress)
    return MolecularSurface(atoms, mask, field)


def ses_field(
    coords: object,
    radii: object,
    *,
    probe: float = PROBE_RADIUS,
    spacing: float | None = None,
    cavities: bool = False,
    progress: Callable[[str], object] | None = None,
) -> SurfaceField:
    """Solvent-excluded region of spheres, as a :class:`SurfaceField`.

    Parameters
    ----------
    coords : (n, 3) float, Å
    radii : (n,) float, Å
    probe : float, Å
        Probe radius (1.4 Å, water).
    spacing : float, Å, optional
        Grid step; default 0.5 Å, coarser when the grid would exceed :data:`MAX_GRID_POINTS`.
    cavities : bool
        Keep buried cavities that the probe fits into (as inner surfaces); by default they
        are filled and only the outer surface remains.
    progress : callable, optional
        Told the name of each stage as it starts: "distances to the atoms", "the solvent" (not
        with ``cavities``), "distance transform", "refinement".
    """
    coords = _validate.finite_array("coords", coords, ndim=(2,))
    radii = _validate.finite_array("radii", radii, ndim=(1,))
    if coords.shape[1] != 3 or len(radii) != len(coords) or len(coords) == 0:
        raise ValueError(f"coords must be (n, 3) with n >= 1 and radii (n,); got {coords.shape} and {radii.shape}")
    if not probe > 0 or np.any(radii <= 0):
        raise ValueError("probe and radii must be positive")
    size = coords.max(axis=0) - coords.min(axis=0)
    if spacing is None:
        spacing = max(0.5, float(np.cbrt(np.prod(size + 2 * (radii.max() + probe + 3)) / MAX_GRID_POINTS)))
        if spacing > MAX_SPACING:
            raise ValueError(f"the atoms span {' × '.join(f'{v:.3g}' for v in size)} Å: a surface with a grid step of "
                             f"{MAX_SPACING:g} Å or finer would need more than {MAX_GRID_POINTS:,} points (is a "
                             "coordinate far off?); surface a chain or a part of it instead")
    if not spacing > 0:
        raise ValueError(f"spacing must be positive; got {spacing}")
    cap = 3 * spacing
    margin = radii.max() + probe + cap + 3 * spacing
    origin = coords.min(axis=0) - margin
    shape = tuple(int(n) for n in np.ceil((size + 2 * margin) / spacing).astype(int) + 1)
    report = progress or (lambda _stage: None)
    report("distances to the atoms")
    sas = _sas_distance(coords, radii + probe, origin, spacing, shape, cap)
    buried = sas < 0
    if not cavities:
        report("the solvent")
        labels, _ = ndimage.label(~buried)
        buried |= labels != labels[0, 0, 0]  # the corner is always in the solvent
    report("distance transform")
    distance, nearest = ndimage.distance_transform_edt(buried, sampling=spacing, return_indices=True)
    to_accessible = distance - sas[tuple(nearest)]
    report("refinement")
    band = np.flatnonzero(buried & (np.abs(to_accessible - probe) < 2 * spacing))
    nearest = np.ravel_multi_index(tuple(n.reshape(-1)[band] for n in nearest), shape)
    to_accessible.reshape(-1)[band] = _descend(band, nearest, sas, buried, spacing)
    values = np.where(buried, to_accessible - probe, -probe - sas).astype(np.float32)
    return SurfaceField(values, origin, float(spacing), float(probe))


def _descend(points: np.ndarray, start: np.ndarray, sas: np.ndarray, buried: np.ndarray, h: float) -> np.ndarray:
    """``min_c |x - c| - s(c)`` over accessible voxels ``c`` for the grid points ``x``
    (flat indices), by steepest descent over the 26 neighbours from the voxel ``start``."""
    shape = sas.shape
    strides = np.array([shape[1] * shape[2], shape[2], 1])
    sas, accessible = sas.reshape(-1), ~buried.reshape(-1)
    x = np.stack(np.unravel_index(points, shape), axis=1) * h
    steps = np.stack(np.meshgrid(*[[-1, 0, 1]] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    steps = steps[np.any(steps != 0, axis=1)]
    best = start
    for _ in range(4):
        dx, dy, dz = (x - np.stack(np.unravel_index(best, shape), axis=1) * h).T
        value = np.sqrt(dx**2 + dy**2 + dz**2) - sas[best]
        moved = best
        for (sx, sy, sz), step in zip(steps * h, steps @ strides, strict=True):
            candidate = best + step
            g = np.sqrt((dx - sx) ** 2 + (dy - sy) ** 2 + (dz - sz) ** 2) - sas[candidate]
            better = (g < value) & accessible[candidate]
            value = np.where(better, g, value)
            moved = np.where(better, candidate, moved)
        if np.array_equal(moved, best):
            break
        best = moved
    return value


def _sas_distance(
    coords: np.ndarray, reach: np.ndarray, origin: np.ndarray, h: float, shape: tuple[int, ...], cap: float
) -> np.ndarray:
    """``min_i (|x - a_i| - reach_i)`` on the grid, clipped at ``cap``: one vectorised pass
    over the atoms per stencil offset, atoms sharing a base voxel in separate passes."""
    field = np.full(shape, cap, dtype=np.float32)
    flat = field.reshape(-1)
    strides = np.array([shape[1] * shape[2], shape[2], 1])
    base = np.floor((coords - origin) / h).astype(np.int64)
    frac = (coords - origin) / h - base
    half = int(np.ceil((reach.max() + cap) / h)) + 1
    grid = np.arange(-half, half + 2)
    offsets = np.stack(np.meshgrid(grid, grid, grid, indexing="ij"), axis=-1).reshape(-1, 3)
    offsets = offsets[np.linalg.norm(offsets - 0.5, axis=1) * h <= reach.max() + cap + h]
    remaining = np.arange(len(coords))
    while len(remaining):
        key = base[remaining] @ strides
        _, first = np.unique(key, return_index=True)
        batch = remaining[first]
        remaining = np.setdiff1d(remaining, batch)
        key, (fx, fy, fz), r = base[batch] @ strides, frac[batch].T * h, reach[batch]
        for (ox, oy, oz), step in zip(offsets * h, offsets @ strides, strict=True):
            distance = np.sqrt((ox - fx) ** 2 + (oy - fy) ** 2 + (oz - fz) ** 2) - r
            index = key + step
            flat[index] = np.minimum(flat[index], distance)
    return field
