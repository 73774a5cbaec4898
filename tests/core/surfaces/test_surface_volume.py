"""Density maps: computed from a model, written and read back as CCP4, wavelet levels and
contours."""

from __future__ import annotations

from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.protein.reading import read_atoms
from core.surfaces.map_file import read_map
from core.surfaces.volume import DensityMap, model_density

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def density() -> DensityMap:
    return model_density(read_atoms(DATA / "1UBQ.pdb.gz"))


def write_ccp4(density: DensityMap, path: Path) -> None:
    ccp4 = gemmi.Ccp4Map()
    size = np.diag(density.axes) * density.values.shape
    ccp4.grid = gemmi.FloatGrid(density.values, gemmi.UnitCell(*size, 90, 90, 90), gemmi.SpaceGroup("P1"))
    ccp4.update_ccp4_header()
    ccp4.write_ccp4_map(str(path))


def test_model_density_peaks_at_the_atoms(density: DensityMap) -> None:
    atoms = read_atoms(DATA / "1UBQ.pdb.gz")
    index = np.round((atoms.coords - density.origin) @ np.linalg.inv(density.axes)).astype(int)
    at_atoms = density.values[tuple(index.T)]
    assert np.median(at_atoms) > density.sigma_level(3.0)  # atoms sit in strong density
    assert density.values.min() >= 0 and density.values[0, 0, 0] < 0.01  # empty box corners


def test_ccp4_round_trip(tmp_path: Path, density: DensityMap) -> None:
    path = tmp_path / "ubiquitin.ccp4"
    write_ccp4(density, path)
    back = read_map(path)
    assert np.array_equal(back.values, density.values)
    assert np.allclose(back.axes, density.axes, atol=1e-5)


def test_wavelet_levels(density: DensityMap) -> None:
    top = density.max_level
    assert top >= 2
    assert density.at_level(top) is density
    errors = [np.sqrt(np.mean((density.at_level(level).values - density.values) ** 2)) for level in range(top + 1)]
    assert all(a > b for a, b in zip(errors, errors[1:]))
    assert errors[-1] == 0.0
    assert density.at_level(0).values.shape == density.values.shape
    with pytest.raises(ValueError, match="level must be an integer"):
        density.at_level(top + 1)


def test_contours_enclose_the_protein(density: DensityMap) -> None:
    value = density.sigma_level(1.0)
    fine, coarse = density.contour(value), density.at_level(0).contour(value)
    assert fine.is_closed() and fine.volume() > 0
    assert coarse.n_faces < fine.n_faces  # the coarse map has fewer details to contour
    atoms = read_atoms(DATA / "1UBQ.pdb.gz").coords
    lo, hi = fine.vertices.min(axis=0), fine.vertices.max(axis=0)
    assert np.all(lo > atoms.min(axis=0) - 4) and np.all(hi < atoms.max(axis=0) + 4)
    with pytest.raises(ValueError, match="outside the map"):
        density.contour(1e6)


def test_contour_around_a_point_is_the_contour_near_it(density: DensityMap) -> None:
    value = density.sigma_level(1.0)
    whole = density.contour(value)
    centre = read_atoms(DATA / "1UBQ.pdb.gz").coords[300]
    near = density.contour_around(value, centre, 8.0)
    assert 0 < near.n_faces < whole.n_faces / 4
    assert np.all(np.linalg.norm(near.vertices - centre, axis=1) <= 8.0)
    inner = np.linalg.norm(whole.vertices - centre, axis=1) < 7.0  # every vertex well inside is drawn
    assert np.min(np.linalg.norm(whole.vertices[inner][:, None] - near.vertices[None], axis=2), axis=1).max() < 1e-4
    assert density.contour_around(value, centre + 500.0, 8.0).n_faces == 0  # outside the map
    assert density.contour_around(1e6, centre, 8.0).n_faces == 0  # no density that high


def test_models_without_b_factors_give_a_finite_density() -> None:
    atoms = read_atoms(DATA / "1L2Y.pdb.gz")  # NMR: every B-factor is 0, hydrogens included
    assert np.all(atoms.b_factor == 0)
    values = model_density(atoms).values
    assert np.all(np.isfinite(values)) and values.max() > 1.0
