"""Solvent-excluded surfaces from the grid, and the properties they are coloured by."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from core.protein.reading import read_atoms
from core.surfaces.molecular import COLOURINGS, molecular_surface, ses_field, surface_atoms, vdw_radii
from core.surfaces.properties import atom_charges, electrostatic_potential, nearest_atom_values

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def ubiquitin():
    return molecular_surface(read_atoms(DATA / "1UBQ.pdb.gz"))


@pytest.mark.parametrize("radius", [1.7, 5.0])
def test_single_sphere_is_exact_to_a_few_hundredths(radius: float) -> None:
    centre = np.array([0.3, 0.1, -0.2])
    field = ses_field([centre], [radius])
    mesh = field.mesh()
    distance = np.linalg.norm(mesh.vertices - centre, axis=1)
    assert np.abs(distance - radius).max() < 0.03
    assert mesh.is_closed()
    assert mesh.volume() == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.06)
    assert np.median(field.mean_curvature(mesh.vertices)) == pytest.approx(1 / radius, rel=0.05)


def test_two_spheres_are_bridged_by_the_reentrant_surface() -> None:
    """The probe cannot enter between two atoms 3 Å apart: the SES saddle lies at
    sqrt((r + p)² − 1.5²) − p from the axis, not at the atoms' own surfaces."""
    field = ses_field([[0, 0, 0], [3.0, 0, 0]], [1.7, 1.7])
    expected = np.sqrt(3.1**2 - 1.5**2) - 1.4
    depth = field.cast_rays(np.array([[1.5, 10, 0], [1.5, 0, -10]]), np.array([[0, -1, 0], [0, 0, 1.0]]), 20)
    assert np.allclose(10 - depth, expected, atol=0.1)
    assert field.mesh().is_closed()
    # a saddle: convex around the axis, concave along it; far flatter than the atom caps
    saddle, cap = field.mean_curvature([[1.5, expected, 0], [-1.7, 0, 0]])
    assert abs(saddle) < 0.5 * cap and cap == pytest.approx(1 / 1.7, rel=0.1)


def test_ubiquitin_surface_is_closed_and_outside_every_atom(ubiquitin) -> None:
    mesh = ubiquitin.mesh
    assert mesh.is_closed()
    atoms = ubiquitin.atoms
    coords, radii = atoms.coords[ubiquitin.mask], vdw_radii(atoms.element[ubiquitin.mask])
    distance, nearest = cKDTree(coords).query(mesh.vertices)
    gap = distance - radii[nearest]
    assert gap.min() > -0.15  # no vertex inside an atom
    assert np.median(gap) < 0.15  # most of the surface is contact surface
    assert gap.max() < 2 * 1.4  # a point of a probe ball is within 2p of the atoms it touches
    # the SES of ubiquitin: about 3,700 Å² and 9,600 Å³ (MSMS gives similar figures)
    assert 3300 < mesh.area() < 4300
    assert 8500 < mesh.volume() < 10500


def test_surface_atoms_leave_out_water_hydrogens_and_second_conformers() -> None:
    atoms = read_atoms(DATA / "1EJG.pdb.gz")
    mask = surface_atoms(atoms)
    assert not np.isin(atoms.element[mask], ["H", "D"]).any()
    assert not (atoms.category[mask] == "water").any()
    assert set(atoms.altloc[mask].tolist()) <= {"", "A"}
    assert mask.sum() > 300


def test_cavities_add_inner_surfaces() -> None:
    atoms = read_atoms(DATA / "1TIM.pdb.gz")
    filled = molecular_surface(atoms)
    hollow = molecular_surface(atoms, cavities=True)
    assert filled.mesh.is_closed() and hollow.mesh.is_closed()
    assert hollow.mesh.area() > filled.mesh.area()
    assert hollow.mesh.volume() < filled.mesh.volume()


def test_ubiquitin_charges() -> None:
    atoms = read_atoms(DATA / "1UBQ.pdb.gz")
    charges = atom_charges(atoms)
    assert charges.sum() == pytest.approx(0.0, abs=1e-12)  # 7 Lys + 4 Arg + termini against 5 Asp + 6 Glu + C-terminus
    assert charges[(atoms.resname == "LYS") & (atoms.name == "NZ")].tolist() == [1.0] * 7
    first = atoms.residue[atoms.category == "protein"].min()
    assert charges[(atoms.residue == first) & (atoms.name == "N")] == [1.0]


def test_dna_phosphates_are_negative() -> None:
    atoms = read_atoms(DATA / "1BNA.pdb.gz")
    charges = atom_charges(atoms)
    assert charges.sum() == pytest.approx(-0.5 * np.isin(atoms.name, ["OP1", "OP2"]).sum())
    assert charges.sum() < -10


def test_potential_is_coulomb_with_distance_dependent_dielectric() -> None:
    coords, charges = np.array([[0.0, 0, 0], [10.0, 0, 0]]), np.array([1.0, -1.0])
    points = np.array([[0, 3.0, 0], [10, 0, 4.0]])
    expected = 332.0637 / 4 * np.array([1 / 9 - 1 / 109, 1 / 116 - 1 / 16])
    assert np.allclose(electrostatic_potential(points, coords, charges), expected)


def test_colourings_of_ubiquitin(ubiquitin) -> None:
    vertices = ubiquitin.mesh.vertices
    atoms = ubiquitin.atoms
    potential = ubiquitin.colour("potential", vertices)
    lys = atoms.coords[(atoms.resname == "LYS") & (atoms.name == "NZ")]
    near_lys = cKDTree(lys).query(vertices)[0] < 3.5
    assert np.median(potential[near_lys]) > 5 > np.median(potential)
    bfactor = ubiquitin.colour("bfactor", vertices)
    assert set(np.unique(bfactor)) <= set(atoms.b_factor.tolist())
    assert np.array_equal(bfactor, nearest_atom_values(vertices, atoms.coords[ubiquitin.mask], atoms.b_factor[ubiquitin.mask]))
    curvature = ubiquitin.colour("curvature", vertices)
    assert np.isfinite(curvature).all() and np.median(curvature) > 0  # a globule is convex overall
    assert set(COLOURINGS) == {"potential", "curvature", "bfactor"}
    with pytest.raises(ValueError, match="colouring must be one of"):
        ubiquitin.colour("hydrophobicity", vertices)


def test_bad_input_is_rejected() -> None:
    with pytest.raises(ValueError, match="radii"):
        ses_field([[0, 0, 0]], [1.0, 2.0])
    with pytest.raises(ValueError, match="non-finite"):
        ses_field([[0, np.nan, 0]], [1.0])
    with pytest.raises(ValueError, match="positive"):
        ses_field([[0, 0, 0]], [1.0], probe=0)


def test_atoms_spread_past_any_sensible_grid_are_refused_at_once() -> None:
    """A coordinate of 1e8 Å made the default grid step 400 km and the surface run for minutes
    (or try 1 TiB at a fixed step); it is refused before any grid is made (#37)."""
    coords = np.array([[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [1e8, 0.0, 0.0]])
    with pytest.raises(ValueError, match="the atoms span 1e\\+08 × 0 × 0 Å.*far off"):
        ses_field(coords, np.full(3, 1.7))
    assert ses_field(coords[:2], np.full(2, 1.7)).spacing == 0.5
