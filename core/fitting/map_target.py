"""A density map around a model and the model's density on the same grid: the correlation
(CC about the mean) a map fit climbs, and its exact gradient with respect to every atom.

The model's density is a sum of Gaussians, one per heavy atom (weighted by its occupancy),
of width ``σ = R / (π √2)`` for a map of resolution ``R`` (as Chimera's ``molmap`` simulates
maps), computed on an orthogonal grid by spreading the atoms by cubic B-splines (smooth as
they cross the grid) and blurring with :func:`scipy.ndimage.gaussian_filter` by what the
splines leave of the width; for a map cut sharply in Fourier space (an MTZ's) the
model's density is cut the same way. The map is resampled once onto that grid, in a box
around the model; a crystal's map is kept only around the model.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
from scipy import fft, ndimage

from core.protein.model import EditableModel
from core.surfaces.volume import DensityMap, MapError

SIGMA_PER_RESOLUTION = 1.0 / (np.pi * np.sqrt(2.0))
"""Gaussian width of an atom per Å of resolution (Chimera's ``molmap``)."""
RESOLUTION = (2.0, 30.0)
"""Å: the resolutions a fit takes."""
MIN_OVERLAP = 0.5
"""Fewest of the model's atoms that must lie inside the map."""
CRYSTAL_MASK = 3.0
"""Å beyond the atoms (and an atom's Gaussian width) that a crystal's map is kept around the
model for a fit: beyond, its neighbours' density, flattened to the solvent's level (the mean
of the map at the mask's edge)."""
CUT_MODEL_FROM = 6.0
"""Å: a map cut sharply in Fourier space at this resolution or coarser is fitted with the
model's density cut the same way: its ripples, a resolution wide, span residues and drew
ubiquitin 0.72 Å out of its own X-ray-like 10 Å map (0.27-0.36 Å cut as the map is); at
finer cuts they are atomic detail, the Gaussian model does as well (0.17 Å at 3 Å) and is
five times cheaper on the fine grid (an MTZ map at 2.5 Å)."""
SPREAD_VARIANCE = 1.0 / 3.0
"""Grid steps²: the variance that spreading an atom by a cubic B-spline adds along each axis,
taken from the blur that follows."""
ATOM_SIGMA = 0.6
"""Å: an atom's own width in a map cut sharply in Fourier space (B ≈ 30 Å²), before the cut."""


def file_resolution(density: DensityMap) -> tuple[float, str] | None:
    """The resolution a fit takes for ``density`` where its file gives one (bounded to
    :data:`RESOLUTION`), and where it comes from, for people; None where the file gives none."""
    if density.resolution is None:
        return None
    bounded = float(np.clip(density.resolution, *RESOLUTION))
    return bounded, "the file's" if bounded == density.resolution else f"the file's {density.resolution:.3g} Å, bounded"


def gaussian_sigma(resolution: float) -> float:
    """Å, the Gaussian width of an atom in a map of ``resolution`` Å."""
    return SIGMA_PER_RESOLUTION * resolution


class MapTarget:
    """A map around a model, resampled on an orthogonal grid, and the model's density on it.

    Parameters
    ----------
    density : the map.
    resolution : Å, the map's resolution (the model's density is blurred to it).
    around : (n, 3) atom positions the box is built around, Å.
    margin : Å beyond the atoms (default three Gaussian widths and 5 Å for the motion).
    """

    def __init__(self, density: DensityMap, resolution: float, around: np.ndarray, margin: float | None = None) -> None:
        if not RESOLUTION[0] <= resolution <= RESOLUTION[1]:
            raise ValueError(f"resolution must be in [{RESOLUTION[0]:g}, {RESOLUTION[1]:g}] Å; got {resolution:g}")
        self.resolution = float(resolution)
        self.sigma = gaussian_sigma(resolution)
        cut = density.resolution if density.cut_sharply else None
        self.cut = cut if cut is not None and cut >= CUT_MODEL_FROM else None
        """Å: where the map's transform ends sharply, the model's density cut there too (from
        :data:`CUT_MODEL_FROM` on), or None."""
        self.spacing = float(np.clip(resolution / 4.0, 0.5, 2.5))
        self._around, self._margin = around, margin
        self._blurred: dict[float, MapTarget] = {}
        margin = 3.0 * self.sigma + 5.0 if margin is None else margin
        inside = density.covers(around)
        if inside.mean() < MIN_OVERLAP:
            raise MapError(f"the map does not overlap the model: {inside.mean():.0%} of its atoms lie inside the map "
                           f"(at least {MIN_OVERLAP:.0%} must)")
        self.origin = around.min(axis=0) - margin
        self.shape = tuple(np.ceil((around.max(axis=0) + margin - self.origin) / self.spacing).astype(int) + 1)
        values = density.interpolate(self.points()).reshape(self.shape)
        if density.periodic:  # a crystal's map: the neighbours' density off, the model fitted into its own
            radius, distance = CRYSTAL_MASK + self.sigma, self.distances(around)
            edge = (distance > radius - 1.0) & (distance <= radius)  # the solvent's level, about
            values = np.where(distance <= radius, values, values[edge].mean())
        self._target = values - values.mean()
        self._target_norm = _norm(self._target)
        if self._target_norm == 0.0:
            raise MapError("the map is flat around the model: nothing to fit into")

    @property
    def target(self) -> np.ndarray:
        """The map on the grid, less its mean."""
        return self._target

    def points(self) -> np.ndarray:
        """(n, 3) the grid's points, Å, in the order of its flattened values."""
        return self.origin + np.stack(np.indices(self.shape), axis=-1).reshape(-1, 3) * self.spacing

    def distances(self, coords: np.ndarray) -> np.ndarray:
        """Å from each grid point to the nearest of the atoms at ``coords`` (to half a grid
        step), on the grid."""
        occupied = np.zeros(self.shape, dtype=bool)
        index = np.round((coords - self.origin) / self.spacing).astype(int)
        index = index[np.all((index >= 0) & (index < self.shape), axis=1)]
        occupied[tuple(index.T)] = True
        return ndimage.distance_transform_edt(~occupied, sampling=self.spacing)

    def blurred(self, resolution: float) -> MapTarget:
        """The map blurred to a coarser ``resolution`` (Å) and the model's density with it,
        on a grid to suit (itself where ``resolution`` is not coarser). The map is blurred
        on this target's grid, then resampled."""
        if resolution <= self.resolution:
            return self
        if resolution not in self._blurred:
            blur = np.sqrt(gaussian_sigma(resolution) ** 2 - self.sigma**2) / self.spacing
            values = ndimage.gaussian_filter(self._target, blur, mode="nearest")
            blurred = DensityMap(values, self.origin, self.spacing * np.eye(3), resolution=self.cut,
                                 cut_sharply=self.cut is not None)
            self._blurred[resolution] = MapTarget(blurred, resolution, self._around, self._margin)
        return self._blurred[resolution]

    def density(self, coords: np.ndarray, occupancy: np.ndarray | None = None) -> np.ndarray:
        """The model's density on the grid for atoms at ``coords`` (n, 3), each weighted by
        its ``occupancy`` (n,; default 1), as a map shows a partly occupied atom."""
        return self._spread(self._stencil(coords), occupancy)

    def correlation(self, coords: np.ndarray, occupancy: np.ndarray | None = None) -> float:
        """CC about the mean of the model's density (:meth:`density`) with the map."""
        model = self.density(coords, occupancy)
        model -= model.mean()
        norm = _norm(model)
        return float(np.sum(model * self._target) / (norm * self._target_norm)) if norm > 0 else 0.0

    def gradient(self, coords: np.ndarray, occupancy: np.ndarray | None = None) -> tuple[float, np.ndarray]:
        """The CC (as :meth:`correlation`) and its gradient (n, 3) with respect to each atom's
        position (1/Å).

        The density spreads each atom by a cubic B-spline and blurs; both are adjoint to what
        the gradient does (the blur is symmetric, the spreading the transpose of B-spline
        interpolation), so the exact gradient is that of the B-spline interpolant of the
        blurred ∂CC/∂density at each atom, smooth as the CC is (spread trilinearly, the CC
        was kinked at every grid plane, and L-BFGS ended wherever the last bits of the start
        led it among the kinks)."""
        stencil = self._stencil(coords)
        model = self._spread(stencil, occupancy)
        model -= model.mean()
        norm = _norm(model)
        if norm == 0.0:
            return 0.0, np.zeros_like(coords)
        cc = float(np.sum(model * self._target) / (norm * self._target_norm))
        field = self._blur(self._target / (norm * self._target_norm) - cc * model / norm**2).ravel()
        flat, keep, (x, y, z), (dx, dy, dz) = stencil
        n = len(coords)
        around = np.where(keep, field[flat], 0.0).reshape(n, 16, 4)
        along_z = (around @ np.stack([z, dz], axis=2)).reshape(n, 4, 4, 2)  # [atom, a, b, (z, dz)]
        along_yz = np.einsum("nabk,nbj->najk", along_z, np.stack([y, dy], axis=2))  # [atom, a, (y, dy), (z, dz)]
        gradient = np.stack([np.einsum("na,na->n", dx, along_yz[:, :, 0, 0]),
                             np.einsum("na,na->n", x, along_yz[:, :, 1, 0]),
                             np.einsum("na,na->n", x, along_yz[:, :, 0, 1])], axis=1) / self.spacing
        return cc, gradient if occupancy is None else gradient * occupancy[:, None]

    def _spread(self, stencil: tuple, occupancy: np.ndarray | None) -> np.ndarray:
        """The model's density on the grid from its atoms' :meth:`_stencil`."""
        flat, keep, (x, y, z), _ = stencil
        weight = (x[:, :, None, None] * y[:, None, :, None] * z[:, None, None, :]).reshape(len(x), -1)
        if occupancy is not None:
            weight = weight * occupancy[:, None]
        spread = np.bincount(flat[keep], weight[keep], int(np.prod(self.shape)))
        return self._blur(spread.reshape(self.shape).astype(np.float64))  # integers when no atom is on the grid

    def _blur(self, grid: np.ndarray) -> np.ndarray:
        """The model's density from its atoms spread on the grid: blurred by a Gaussian of
        the resolution's width, or for a map cut sharply in Fourier space, cut the same way
        (each atom :data:`ATOM_SIGMA` wide, and as much wider as the resolution asked is
        coarser than the cut), so that it ripples as the map does. Either is its own adjoint."""
        if self.cut is None:
            return ndimage.gaussian_filter(grid, np.sqrt(self.sigma**2 - SPREAD_VARIANCE * self.spacing**2) / self.spacing,
                                           mode="constant", truncate=3.0)
        padded = np.pad(grid, [(self._pad, m - n - self._pad) for n, m in zip(self.shape, self._padded)])
        filtered = fft.irfftn(fft.rfftn(padded) * self._cut_filter, self._padded, axes=(0, 1, 2))
        return filtered[tuple(slice(self._pad, self._pad + n) for n in self.shape)]

    @cached_property
    def _pad(self) -> int:
        return int(np.ceil(2.0 * self.cut / self.spacing))  # the ripples' reach, kept from wrapping around

    @cached_property
    def _padded(self) -> tuple[int, ...]:
        return tuple(fft.next_fast_len(n + 2 * self._pad, real=True) for n in self.shape)

    @cached_property
    def _cut_filter(self) -> np.ndarray:
        """The transform of the model's blur for a map cut sharply: a Gaussian, zero beyond 1/cut."""
        shape = self._padded
        frequency = np.meshgrid(*(np.fft.fftfreq(n, self.spacing) for n in shape[:2]),
                                np.fft.rfftfreq(shape[2], self.spacing), indexing="ij")
        squared = sum(f**2 for f in frequency)
        width = max(ATOM_SIGMA**2 + max(self.sigma**2 - gaussian_sigma(self.cut) ** 2, 0.0)
                    - SPREAD_VARIANCE * self.spacing**2, 0.0)
        return np.where(squared <= 1.0 / self.cut**2, np.exp(-2.0 * np.pi**2 * squared * width), 0.0)

    def _stencil(self, coords: np.ndarray) -> tuple[np.ndarray, np.ndarray, tuple, tuple]:
        """For the 4×4×4 grid points around every atom: their flat indices (n, 64), whether
        they lie on the grid (n, 64), and the cubic B-spline weights (3 of (n, 4), one per
        axis; a point's weight is their product) and their derivatives with respect to the
        atom's grid coordinates (likewise)."""
        index = (coords - self.origin) / self.spacing
        base = np.floor(index).astype(int) - 1
        t = index - base - 1
        weights = np.stack([(1 - t) ** 3, 3 * t**3 - 6 * t**2 + 4, -3 * t**3 + 3 * t**2 + 3 * t + 1, t**3], axis=-1) / 6
        slopes = np.stack([-((1 - t) ** 2), 3 * t**2 - 4 * t, -3 * t**2 + 2 * t + 1, t**2], axis=-1) / 2
        at = base[:, :, None] + np.arange(4)  # (n, 3 axes, 4)
        inside = (at >= 0) & (at < np.array(self.shape)[:, None])
        i, j, k = at[:, 0, :, None, None], at[:, 1, None, :, None], at[:, 2, None, None, :]
        keep = (inside[:, 0, :, None, None] & inside[:, 1, None, :, None] & inside[:, 2, None, None, :]).reshape(len(t), 64)
        flat = np.where(keep, ((i * self.shape[1] + j) * self.shape[2] + k).reshape(len(t), 64), 0)
        return (flat, keep, tuple(weights[:, axis] for axis in range(3)),
                tuple(slopes[:, axis] for axis in range(3)))


def _norm(grid: np.ndarray) -> float:
    """The 2-norm of a grid (as a sum: BLAS's, through np.linalg.norm, is slow with its threads busy)."""
    return float(np.sqrt(np.sum(grid * grid)))


def heavy_atoms(model: EditableModel) -> np.ndarray:
    """Rows of the model's heavy atoms (no hydrogens, no waters): those a map shows."""
    atoms = model.structure.atoms
    return np.flatnonzero(~np.isin(np.char.upper(atoms.element.astype(str)), ("H", "D")) & (atoms.category != "water"))


def occupancies(model: EditableModel, rows: np.ndarray) -> np.ndarray:
    """The occupancy of the atoms at ``rows`` of ``model``, in [0, 1]: how much of each a map
    shows (a side chain in two conformations, half each; a tail half ordered)."""
    return np.clip(np.nan_to_num(model.structure.atoms.occupancy[rows], nan=1.0), 0.0, 1.0)
