"""Maps simulated from a model in three unlike ways, to fit into and to test fits with:
Gaussians on a grid as Chimera's ``molmap`` makes them (:func:`molmap`), an X-ray-like map
cut sharply in Fourier space and noisy (:func:`xray_like`), and gemmi's electron density
blurred (:func:`gemmi_like`). Each is a box ``margin`` Å around the heavy atoms on a 1 Å grid
(gemmi's about 1 Å)."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from core.fitting.map_target import gaussian_sigma, heavy_atoms, occupancies
from core.protein.model import EditableModel
from core.protein.structure import Structure
from core.surfaces.volume import DensityMap, model_density

ELECTRONS = {"C": 6, "N": 7, "O": 8, "S": 16}
"""Electrons of the elements of a protein's heavy atoms (others count as carbon)."""
MARGIN = 15.0
"""Å of box around the atoms, by default."""


def _box(coords: np.ndarray, margin: float) -> tuple[np.ndarray, tuple[int, ...]]:
    origin = np.floor(coords.min(axis=0)) - margin
    return origin, tuple(int(n) for n in np.ceil(coords.max(axis=0) + margin - origin))


def molmap(structure: Structure, resolution: float, margin: float = MARGIN) -> DensityMap:
    """The heavy atoms counted on a 1 Å grid (each by its occupancy), blurred to ``resolution``
    Å (Chimera's molmap width)."""
    model = EditableModel(structure)
    rows = heavy_atoms(model)
    coords = structure.coords[rows]
    origin, shape = _box(coords, margin)
    grid = np.zeros(shape)
    np.add.at(grid, tuple(np.round(coords - origin).astype(int).T), occupancies(model, rows))
    values = ndimage.gaussian_filter(grid, gaussian_sigma(resolution)).astype(np.float32)
    return DensityMap(values, origin, np.eye(3))


def xray_like(structure: Structure, resolution: float, noise: float = 0.3, seed: int = 0,
              margin: float = MARGIN) -> DensityMap:
    """Each heavy atom a Gaussian of its electrons (times its occupancy) blurred by its B-factor (σ² = B / 8π²) on a
    1 Å grid, the Fourier transform cut sharply at 1/``resolution`` (the ripples of a real
    map), and white noise of ``noise`` times the map's standard deviation."""
    model = EditableModel(structure)
    rows = heavy_atoms(model)
    coords = structure.coords[rows]
    origin, shape = _box(coords, margin)
    grid = np.zeros(shape)
    weight = np.array([ELECTRONS.get(e.upper(), 6) for e in structure.atoms.element[rows]]) * occupancies(model, rows)
    sigma = np.sqrt(np.maximum(structure.atoms.b_factor[rows], 2.0) / (8 * np.pi**2))
    for width in np.unique(np.round(sigma, 1)):  # atoms of like B-factor blurred together
        layer = np.zeros(shape)
        take = np.round(sigma, 1) == width
        np.add.at(layer, tuple(np.round(coords[take] - origin).astype(int).T), weight[take])
        grid += ndimage.gaussian_filter(layer, max(width, 0.3))
    spectrum = np.fft.rfftn(grid)
    k = np.meshgrid(*(np.fft.fftfreq(n) for n in shape[:2]), np.fft.rfftfreq(shape[2]), indexing="ij")
    spectrum[np.sqrt(sum(f**2 for f in k)) > 1.0 / resolution] = 0.0
    values = np.fft.irfftn(spectrum, shape, axes=(0, 1, 2))
    values += noise * values.std() * np.random.default_rng(seed).standard_normal(shape)
    return DensityMap(values.astype(np.float32), origin, np.eye(3), resolution=resolution, cut_sharply=True)


def gemmi_like(structure: Structure, resolution: float, margin: float = MARGIN) -> DensityMap:
    """gemmi's electron density of the model (IT92 form factors, each atom blurred by its
    B-factor, hydrogens included), blurred by a Gaussian to ``resolution`` Å."""
    density = model_density(structure.atoms, spacing=1.0, margin=margin)
    values = ndimage.gaussian_filter(density.values, gaussian_sigma(resolution) / np.diag(density.axes))
    return DensityMap(values.astype(np.float32), density.origin, density.axes)
