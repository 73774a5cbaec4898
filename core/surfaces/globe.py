"""Spline surfaces of Carson's paper: the globe (sphere topology) and the DNA cylinder.

Both cast rays onto the molecular surface from outside, towards a centre (globe) or the
helix axis (cylinder), on a ``64 × 64`` grid of directions, and fit a control net of
``32 × 32`` patches (level 5) by least squares: open along latitude (globe) or along the
axis (cylinder), closed around. Each ray stops at the first point of the surface it meets
(the outermost crossing), so a crevice that opens away from the centre is bridged.
The colour of the molecular surface at the sample points is the surface's texture.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.surfaces.molecular import MolecularSurface
from core.surfaces.tensor_spline import SplineSurface, fit_surface, sample_parameters

SAMPLES = 64
"""Samples (rays) per direction, as in the paper's 64 × 64 textures."""

LEVEL = 5
"""Finest level of the fitted nets: 32 × 32 patches."""


@dataclass(frozen=True, eq=False)
class ShapeSurface:
    """A globe or cylinder fitted to a molecular surface.

    Attributes
    ----------
    surface : SplineSurface
        Net, samples and levels; ``surface.samples`` are the ray hits on the SES.
    centre : (3,) float64, Å
        Centroid of the surface atoms (globe) or of the axis (cylinder).
    axes : (3, 3) float64
        Rows e1, e2, e3 (right-handed); e3 is the polar axis or the helix axis.
    """

    surface: SplineSurface
    centre: np.ndarray
    axes: np.ndarray

    def radial_distance(self, level: float) -> np.ndarray:
        """(m_u, m_v) distances (Å) of the surface points at ``level`` from the polar or
        helix axis."""
        offset = self.surface.points(level) - self.centre
        return np.linalg.norm(offset - np.outer(offset.reshape(-1, 3) @ self.axes[2], self.axes[2]).reshape(offset.shape), axis=-1)

    def groove_depth(self, level: float) -> float:
        """Mean over the rings around the axis (the outer quarter at each end left out) of
        the spread max − min of the radial distance, Å: the depth of the grooves of DNA."""
        rho = self.radial_distance(level)
        inner = rho[len(rho) // 4 : -(len(rho) // 4)]
        return float(np.mean(inner.max(axis=1) - inner.min(axis=1)))


def principal_axes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centroid and right-handed principal axes (rows, increasing variance) of points."""
    centre = points.mean(axis=0)
    _, vectors = np.linalg.eigh(np.cov((points - centre).T))
    axes = vectors.T.copy()
    if np.linalg.det(axes) < 0:
        axes[0] *= -1
    return centre, axes


def globe(surface: MolecularSurface, *, level: int = LEVEL, samples: int = SAMPLES) -> ShapeSurface:
    """Globe of a globular molecule: rays along 64 latitudes (pole to pole, about the
    longest principal axis) × 64 longitudes towards the centre, the point 1 Å inside the
    surface nearest to the centroid (so that every ray meets the surface).
    """
    centroid, axes = principal_axes(surface.atoms.coords[surface.mask])
    centre = surface.field.inside_point_near(centroid)
    u, v = sample_parameters(samples, samples, (False, True))
    theta, phi = np.meshgrid(np.pi * u, 2 * np.pi * v, indexing="ij")
    local = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
    directions = local @ axes
    reach = _reach(surface, centre)
    depth = surface.field.cast_rays((centre + reach * directions).reshape(-1, 3), -directions.reshape(-1, 3), reach)
    points = centre + (reach - depth.reshape(theta.shape))[..., None] * directions
    return ShapeSurface(fit_surface(points, level, (False, True), poles=True), centre, axes)


def cylinder(surface: MolecularSurface, *, level: int = LEVEL, samples: int = SAMPLES, margin: float = 3.0) -> ShapeSurface:
    """Cylinder about the longest principal axis (the helix axis of a DNA duplex): rays
    perpendicular to the axis, at 64 heights from ``margin`` Å inside the first atom to
    ``margin`` Å inside the last × 64 angles; open along the axis, closed around it."""
    coords = surface.atoms.coords[surface.mask]
    centre, axes = principal_axes(coords)
    height = (coords - centre) @ axes[2]
    low, high = height.min() + margin, height.max() - margin
    if not high > low:
        raise ValueError(f"{surface.atoms.entry_id}: too short for a cylinder ({high - low + 2 * margin:.1f} Å along its axis)")
    u, v = sample_parameters(samples, samples, (False, True))
    z, phi = np.meshgrid(low + (high - low) * u, 2 * np.pi * v, indexing="ij")
    radial = np.cos(phi)[..., None] * axes[0] - np.sin(phi)[..., None] * axes[1]
    foot = centre + z[..., None] * axes[2]
    reach = _reach(surface, centre)
    depth = surface.field.cast_rays((foot + reach * radial).reshape(-1, 3), -radial.reshape(-1, 3), reach)
    _check_hits(depth, surface, "the axis",
                ": a cylinder fits one straight duplex (or molecule) along its longest axis")
    points = foot + (reach - depth.reshape(z.shape))[..., None] * radial
    return ShapeSurface(fit_surface(points, level, (False, True)), centre + (low + high) / 2 * axes[2], axes)


def _reach(surface: MolecularSurface, centre: np.ndarray) -> float:
    """A distance from ``centre`` beyond every point of the surface, Å."""
    coords = surface.atoms.coords[surface.mask]
    return float(np.linalg.norm(coords - centre, axis=1).max() + 10.0)


def _check_hits(depth: np.ndarray, surface: MolecularSurface, target: str, hint: str = "") -> None:
    missed = int(np.isnan(depth).sum())
    if missed:
        raise ValueError(
            f"{surface.atoms.entry_id}: {missed} of {len(depth)} rays towards {target} miss the molecular surface{hint}"
        )
