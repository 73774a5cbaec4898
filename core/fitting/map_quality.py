"""How well a model fits a map, as a modeller judges a fit: the correlation over the box
and in a mask around the model (phenix's CC_box and CC_mask), the correlation of each
residue in its own part of the mask, and the residues that lie outside the density.

The mask is the grid points within :func:`mask_radius` of an atom; each of its points
belongs to the residue of its nearest atom.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from core.fitting.map_target import MapTarget
from core.surfaces.volume import DensityMap

OUTSIDE_SIGMA = 1.0
"""A residue whose atoms sit, on average, below this many rms deviations above the map's
mean (over the box) lies outside the density."""


def mask_radius(resolution: float) -> float:
    """Å around each atom that the mask takes: half the resolution, 2 Å at least."""
    return max(2.0, 0.5 * resolution)


@dataclass(frozen=True)
class MapQuality:
    """The fit of a model's atoms in a map.

    Attributes
    ----------
    resolution : Å, the model's density is blurred to it.
    cc_box : CC about the mean over the whole box around the model.
    cc_mask : CC over the mask around the atoms.
    residues : (m,) CC of each residue within its part of the mask (NaN where it has none).
    outside : (k,) indices of the residues that lie outside the density.
    """

    resolution: float
    cc_box: float
    cc_mask: float
    residues: np.ndarray
    outside: np.ndarray

    def summary(self, names: list[str] | None = None, at_most: int = 8) -> str:
        """One line for people: ``CC_mask 0.81, CC_box 0.74 at 3.0 Å; 2 residues outside the density (A 72, A 73)``."""
        text = f"CC_mask {self.cc_mask:.3f}, CC_box {self.cc_box:.3f} at {self.resolution:.3g} Å"
        if len(self.outside) == 0:
            return text + "; every residue in density"
        listed = "" if names is None else " (" + ", ".join(names[k] for k in self.outside[:at_most]) + \
            (", …" if len(self.outside) > at_most else "") + ")"
        return text + f"; {len(self.outside)} residue(s) outside the density{listed}"


def map_quality(target: MapTarget, coords: np.ndarray, residue_of_atom: np.ndarray, residues: int,
                occupancy: np.ndarray | None = None) -> MapQuality:
    """The fit of atoms at ``coords`` (n, 3) in ``target``, each weighted by its ``occupancy``
    (n,; default 1); ``residue_of_atom`` (n,) gives each atom's residue in ``range(residues)``."""
    model = target.density(coords, occupancy).ravel()
    mapped = target.target.ravel()
    cc_box = _cc(model - model.mean(), mapped)
    distance, nearest = cKDTree(coords).query(target.points(), distance_upper_bound=mask_radius(target.resolution))
    inside = np.isfinite(distance)
    owner = residue_of_atom[nearest[inside]]
    m, t = model[inside], mapped[inside]
    cc_mask = _cc(m - m.mean(), t - t.mean())
    per_residue = _grouped_cc(m, t, owner, residues)
    level = OUTSIDE_SIGMA * mapped.std()  # (the target is the map less its mean)
    on_grid = DensityMap(target.target, target.origin, target.spacing * np.eye(3))
    at_atoms = np.bincount(residue_of_atom, on_grid.interpolate(coords), residues)
    counts = np.bincount(residue_of_atom, minlength=residues)
    with np.errstate(invalid="ignore", divide="ignore"):
        outside = np.flatnonzero((counts > 0) & (at_atoms / counts < level))
    return MapQuality(target.resolution, cc_box, cc_mask, per_residue, outside)


def _cc(a: np.ndarray, b: np.ndarray) -> float:
    norm = np.sqrt(np.sum(a * a) * np.sum(b * b))
    return float(np.sum(a * b) / norm) if norm > 0 else 0.0


def _grouped_cc(a: np.ndarray, b: np.ndarray, group: np.ndarray, groups: int) -> np.ndarray:
    """The CC of ``a`` with ``b`` within each group, about the group's means."""
    n = np.bincount(group, minlength=groups).astype(np.float64)
    sums = [np.bincount(group, x, groups) for x in (a, b, a * a, b * b, a * b)]
    with np.errstate(invalid="ignore", divide="ignore"):
        sa, sb, saa, sbb, sab = sums
        covariance = sab - sa * sb / n
        spread = np.sqrt((saa - sa * sa / n) * (sbb - sb * sb / n))
        return np.where((n > 1) & (spread > 0), covariance / spread, np.nan)

