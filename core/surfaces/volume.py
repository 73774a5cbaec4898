"""Density maps: computed from a model (gemmi), 3-D wavelet levels (PyWavelets) and
contour surfaces (marching cubes); :mod:`core.surfaces.map_file` reads them.

A map is a grid of values with an affine map from grid indices to Å, so that skewed unit
cells need no resampling. Wavelet level ``L`` of a map with ``n`` levels keeps the
approximation at depth ``n`` and the ``L`` coarsest detail levels: level ``n`` is the map
itself, level 0 its coarsest approximation.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import gemmi
import numpy as np
import pywt
from numpy.typing import NDArray
from scipy import ndimage
from skimage.measure import marching_cubes

from core.protein.structure import AtomTable
from core.surfaces.mesh import TriangleMesh

WAVELET = "bior4.4"
"""The biorthogonal CDF 9/7 wavelet (symmetric filters, as in JPEG 2000)."""


class MapError(ValueError):
    """A file that cannot be read as a density map."""


UNKNOWN_B = 20.0
"""B-factor (Å²) used for atoms whose file gives none (0): a typical value for a protein."""


@dataclass(frozen=True, eq=False)
class DensityMap:
    """Values on a grid.

    Attributes
    ----------
    values : (nx, ny, nz) float32
    origin : (3,) float64, Å
        Position of grid point (0, 0, 0).
    axes : (3, 3) float64, Å
        Rows: the steps of the grid along its three axes (a diagonal of spacings for an
        orthogonal cell).
    periodic : whether the grid is one unit cell of a crystal, repeated through space.
    resolution : Å, the map's resolution where its file says it, else None.
    cut_sharply : whether its Fourier transform ends sharply at ``resolution`` (a map made
        from a crystal's coefficients), so that it ripples around dense parts.
    """

    values: NDArray[np.float32]
    origin: NDArray[np.float64]
    axes: NDArray[np.float64]
    periodic: bool = False
    resolution: float | None = None
    cut_sharply: bool = False

    @cached_property
    def _coefficients(self) -> list:
        return pywt.wavedecn(self.values, WAVELET, mode="symmetric", level=self.max_level)

    @property
    def max_level(self) -> int:
        """Number of wavelet levels of the grid (at least 1)."""
        return max(1, pywt.dwtn_max_level(self.values.shape, WAVELET))

    def at_level(self, level: int) -> DensityMap:
        """The map reconstructed from its approximation and ``level`` coarsest detail levels."""
        if isinstance(level, bool) or not isinstance(level, (int, np.integer)) or not 0 <= level <= self.max_level:
            raise ValueError(f"level must be an integer in [0, {self.max_level}]; got {level!r}")
        if level == self.max_level:
            return self
        kept = self._coefficients[: level + 1]
        dropped = [{key: np.zeros_like(c) for key, c in detail.items()} for detail in self._coefficients[level + 1 :]]
        values = pywt.waverecn(kept + dropped, WAVELET, mode="symmetric")
        values = values[tuple(slice(0, n) for n in self.values.shape)]
        return replace(self, values=values.astype(np.float32))

    @cached_property
    def moments(self) -> tuple[float, float]:
        """The map's mean and rms deviation (σ)."""
        return float(self.values.mean(dtype=np.float64)), float(self.values.std(dtype=np.float64))

    def sigma_level(self, contour: float) -> float:
        """The value ``mean + contour · rms deviation`` of the map."""
        mean, sigma = self.moments
        return mean + contour * sigma

    def contour(self, value: float) -> TriangleMesh:
        """Isosurface at ``value`` (normals towards lower density)."""
        if not self.values.min() < value < self.values.max():
            raise ValueError(f"contour {value:g} lies outside the map's range [{self.values.min():g}, {self.values.max():g}]")
        vertices, faces, _, _ = marching_cubes(self.values, value, allow_degenerate=False)
        return TriangleMesh(self.origin + vertices @ self.axes, faces[:, ::-1])

    def grid_index(self, points: np.ndarray) -> np.ndarray:
        """(n, 3) grid coordinates (fractional indices) of ``points`` (n, 3), Å."""
        return (np.asarray(points, dtype=np.float64) - self.origin) @ np.linalg.inv(self.axes)

    def covers(self, points: np.ndarray) -> np.ndarray:
        """Whether each of ``points`` (n, 3), Å, lies within the map (everywhere for a periodic map)."""
        index = self.grid_index(points)
        if self.periodic:
            return np.ones(len(index), dtype=bool)
        return np.all((index >= 0) & (index <= np.array(self.values.shape) - 1), axis=1)

    def interpolate(self, points: np.ndarray) -> np.ndarray:
        """The map's values at ``points`` (n, 3), Å, interpolated trilinearly (beyond a box,
        the value at its nearest face; a periodic map repeats)."""
        mode = "grid-wrap" if self.periodic else "nearest"
        return ndimage.map_coordinates(self.values.astype(np.float64), self.grid_index(points).T, order=1, mode=mode)

    def contour_around(self, value: float, centre: np.ndarray, radius: float) -> TriangleMesh:
        """Isosurface at ``value`` within ``radius`` Å of ``centre`` (Å), as maps are drawn in
        model building: marching cubes on the block of the grid that holds the sphere, the
        triangles reaching beyond it dropped (degenerate ones kept: this mesh is for drawing).
        Empty where the map does not reach or the block does not cross ``value``."""
        centre = np.asarray(centre, dtype=np.float64)
        corners = centre + radius * (2.0 * np.array(list(np.ndindex(2, 2, 2))) - 1.0)
        index = self.grid_index(corners)
        low, high = np.floor(index.min(axis=0)).astype(int), np.ceil(index.max(axis=0)).astype(int) + 1
        if self.periodic:  # the cell repeated around the centre, as Coot draws a crystal's map
            block = self.values[np.ix_(*[np.arange(a, b) % n for a, b, n in zip(low, high, self.values.shape)])]
        else:
            low, high = np.clip(low, 0, self.values.shape), np.clip(high, 0, self.values.shape)
            block = self.values[tuple(slice(a, b) for a, b in zip(low, high))]
        empty = TriangleMesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
        if min(block.shape) < 2 or not block.min() < value < block.max():
            return empty
        vertices, faces, _, _ = marching_cubes(block, value, allow_degenerate=True)  # (a third faster)
        vertices = self.origin + (vertices + low) @ self.axes
        inside = np.einsum("ij,ij->i", vertices - centre, vertices - centre) <= radius**2
        faces = faces[inside[faces].all(axis=1)]
        used = np.zeros(len(vertices), dtype=bool)
        used[faces] = True
        renumbered = np.cumsum(used) - 1
        return TriangleMesh(vertices[used], renumbered[faces[:, ::-1]])


def model_density(atoms: AtomTable, *, spacing: float = 0.75, resolution: float = 3.0, margin: float = 5.0) -> DensityMap:
    """Electron density of the non-water atoms of a model (gemmi's DensityCalculatorX:
    IT92 form factors, each atom blurred by its B-factor), in a box ``margin`` Å wider
    than the atoms, at a ``resolution`` (Å) and grid ``spacing`` (Å). Atoms without a
    B-factor (0, as in NMR models) get :data:`UNKNOWN_B`."""
    keep = atoms.category != "water"
    if not keep.any():
        raise ValueError(f"{atoms.entry_id}: no atoms to compute a density from")
    coords = atoms.coords[keep]
    low = coords.min(axis=0) - margin
    size = coords.max(axis=0) + margin - low
    st = gemmi.Structure()
    st.cell = gemmi.UnitCell(*size, 90, 90, 90)
    st.spacegroup_hm = "P 1"
    residue = gemmi.Residue()
    residue.name = "UNK"
    for xyz, element, b, occupancy in zip(coords - low, atoms.element[keep], atoms.b_factor[keep], atoms.occupancy[keep], strict=True):
        atom = gemmi.Atom()
        atom.pos = gemmi.Position(*xyz)
        atom.element = gemmi.Element(element)
        atom.b_iso = b if b > 0 else UNKNOWN_B  # a zero B gives NaN densities
        atom.occ = occupancy
        residue.add_atom(atom)
    chain = gemmi.Chain("A")
    chain.add_residue(residue)
    model = gemmi.Model("1")
    model.add_chain(chain)
    st.add_model(model)
    calculator = gemmi.DensityCalculatorX()
    calculator.d_min = resolution
    calculator.grid.set_unit_cell(st.cell)
    calculator.grid.spacegroup = gemmi.SpaceGroup("P 1")
    calculator.grid.set_size_from_spacing(spacing, gemmi.GridSizeRounding.Up)
    calculator.add_model_density_to_grid(st[0])
    values = np.array(calculator.grid.array, dtype=np.float32)
    return DensityMap(values, low, np.diag(size / np.array(values.shape)))
