"""One entry point for every kind of surface, level by level: what a surface panel or the
``surface`` command asks for (vertices, faces and per-vertex colours).

Kinds: ``ses`` (the molecular surface itself, one level), ``globe`` and ``dna`` (spline
surfaces, levels 0-5, fractional levels allowed, coloured by a 64 × 64 texture),
``remesh`` (6 · 4**level triangles) and ``map`` (a density map's wavelet levels,
contoured). A :class:`LevelledSurface` pickles (the editor builds it in another process),
and a build names its stages as it goes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from core.protein.structure import AtomTable
from core.surfaces.globe import ShapeSurface, cylinder, globe
from core.surfaces.mesh import TriangleMesh
from core.surfaces.molecular import COLOURINGS, MolecularSurface, molecular_surface
from core.surfaces.properties import atom_charges, electrostatic_potential, nearest_atom_values
from core.surfaces.remesh import remesh
from core.surfaces.tensor_spline import SplineSurface
from core.surfaces.volume import DensityMap, model_density

KINDS = ("ses", "globe", "dna", "remesh", "map")

UNITS = {"potential": "kcal/(mol·e)", "curvature": "1/Å", "bfactor": "Å²"}

Progress = Callable[[str], object]
"""Called with the name of each stage of a build as it starts ("molecular surface (distance transform)")."""


@dataclass(frozen=True, eq=False)
class LevelledSurface:
    """A surface of one kind at every level from 0 to ``max_level``.

    Attributes
    ----------
    kind : str
    max_level : int
        The finest level (the surface as built).
    errors : tuple of (level, rms error Å) pairs
        How far each level lies from what it approximates (empty for ``ses``); for
        ``map``, the rms difference of the map values at each level from the map.
    fractional : bool
        Whether levels between integers are defined (spline surfaces).
    """

    kind: str
    max_level: int
    errors: tuple[tuple[int, float], ...]
    fractional: bool
    _mesh: Callable[[float], TriangleMesh]
    _colour: Callable[[str, float, TriangleMesh], np.ndarray]

    def view(self, level: float | None = None, colouring: str | None = None) -> tuple[TriangleMesh, np.ndarray | None]:
        """The mesh at ``level`` (default the finest) and its per-vertex ``colouring``
        (one of :data:`core.surfaces.molecular.COLOURINGS`, or None)."""
        level = self.max_level if level is None else float(level)
        if not 0 <= level <= self.max_level or (not self.fractional and level != int(level)):
            kind = "a level" if self.fractional else "an integer level"
            raise ValueError(f"{self.kind}: level must be {kind} in [0, {self.max_level}]; got {level:g}")
        if colouring is not None and colouring not in COLOURINGS:
            raise ValueError(f"colouring must be one of {', '.join(COLOURINGS)}; got {colouring!r}")
        mesh = self._mesh(level)
        return mesh, None if colouring is None else self._colour(colouring, level, mesh)


def build_surface(
    kind: str,
    atoms: AtomTable | None = None,
    *,
    density: DensityMap | None = None,
    site: np.ndarray | None = None,
    contour: float = 1.0,
    probe: float = 1.4,
    spacing: float | None = None,
    progress: Progress | None = None,
) -> LevelledSurface:
    """Build the surface of ``kind`` (one of :data:`KINDS`).

    Parameters
    ----------
    kind : str
    atoms : AtomTable, optional
        The model (needed by every kind except ``map`` with a ``density``).
    density : DensityMap, optional
        For ``map``: the map to contour (default: computed from ``atoms``).
    site : (n_atoms,) bool, optional
        For ``remesh``: the site atoms (e.g. a ligand); they are left out of the surface
        and the patch within 10 Å of them is remeshed instead of the whole surface.
    contour : float
        For ``map``: the contour in rms deviations above the mean of the map.
    probe, spacing : float, Å
        Probe radius and grid step of the molecular surface.
    progress : callable, optional
        Told the name of each stage as it starts (see :data:`Progress`).
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}; got {kind!r}")
    report = progress or (lambda _stage: None)
    if kind == "map":
        if density is None:
            report("density map")
            density = model_density(_needed(atoms))
        return _map_surface(density, atoms, contour, report)
    atoms = _needed(atoms)
    exclude = site
    if kind == "dna" and (nucleic := atoms.category == "nucleic").any():  # the duplex alone, not what binds it
        exclude = ~nucleic if site is None else site | ~nucleic
    surface = molecular_surface(atoms, probe=probe, spacing=spacing, exclude=exclude,
                                progress=lambda stage: report(f"molecular surface ({stage})"))
    colour = partial(_surface_colour, surface)
    if kind == "ses":
        report("triangles")
        return LevelledSurface("ses", 0, (), False, partial(_only, surface.mesh), colour)
    if kind == "remesh":
        report("remeshing")
        result = remesh(surface, site=None if site is None else atoms.coords[site])
        return LevelledSurface(
            "remesh", len(result.meshes) - 1, tuple(enumerate(result.rms_error)), False,
            partial(_at_level, result.meshes), colour,
        )  # fmt: skip
    report("fitting the globe" if kind == "globe" else "fitting the cylinder")
    shape = globe(surface) if kind == "globe" else cylinder(surface)
    report("levels")
    return _spline_surface(kind, shape, surface)


def _spline_surface(kind: str, shape: ShapeSurface, surface: MolecularSurface) -> LevelledSurface:
    spline = shape.surface
    errors = tuple((level, spline.rms_error(level)) for level in range(spline.level + 1))
    return LevelledSurface(kind, spline.level, errors, True, spline.mesh, partial(_texture, spline, surface, {}))


def _map_surface(density: DensityMap, atoms: AtomTable | None, contour: float, report: Progress) -> LevelledSurface:
    value = density.sigma_level(contour)
    report("wavelet levels")
    levels = tuple(density.at_level(level) for level in range(density.max_level + 1))
    errors = tuple(
        (level, float(np.sqrt(np.mean((m.values - density.values) ** 2)))) for level, m in enumerate(levels)
    )
    return LevelledSurface("map", density.max_level, errors, False, partial(_contour, levels, value),
                           partial(_map_colour, atoms))


# The views of a LevelledSurface: module functions bound with functools.partial, so that it pickles.

def _only(mesh: TriangleMesh, _level: float) -> TriangleMesh:
    return mesh


def _at_level(meshes: tuple[TriangleMesh, ...], level: float) -> TriangleMesh:
    return meshes[int(level)]


def _contour(levels: tuple[DensityMap, ...], value: float, level: float) -> TriangleMesh:
    return levels[int(level)].contour(value)


def _surface_colour(surface: MolecularSurface, colouring: str, _level: float, mesh: TriangleMesh) -> np.ndarray:
    return surface.colour(colouring, mesh.vertices)


def _texture(spline: SplineSurface, surface: MolecularSurface, textures: dict[str, np.ndarray], colouring: str,
             _level: float, _mesh: TriangleMesh) -> np.ndarray:
    """The colouring at the samples, one value per vertex of a spline mesh (computed once per colouring)."""
    if colouring not in textures:
        textures[colouring] = surface.colour(colouring, spline.samples)
    values = textures[colouring]
    if not spline.poles:
        return values.reshape(-1)
    return np.concatenate([values[0, :1], values[1:-1].reshape(-1), values[-1, :1]])


def _map_colour(atoms: AtomTable | None, colouring: str, _level: float, mesh: TriangleMesh) -> np.ndarray:
    if atoms is None or colouring == "curvature":
        raise ValueError(f"a map can be coloured by the potential or B-factors of a model, not by {colouring}")
    keep = atoms.category != "water"
    if colouring == "potential":
        return electrostatic_potential(mesh.vertices, atoms.coords[keep], atom_charges(atoms)[keep])
    return nearest_atom_values(mesh.vertices, atoms.coords[keep], atoms.b_factor[keep])


def _needed(atoms: AtomTable | None) -> AtomTable:
    if atoms is None:
        raise ValueError("this kind of surface needs a model (atoms)")
    return atoms
