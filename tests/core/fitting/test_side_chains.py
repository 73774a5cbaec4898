"""Side chains turned into a density map: χ rotors, their analytic gradient, the fit (#19)."""

from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from core.fitting.density import MapTarget, atom_correlation, gaussian_sigma, heavy_atoms
from core.fitting.side_chains import fit_side_chains, side_chain_rotors
from core.geometry.topology import topology
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.surfaces.volume import DensityMap

DATA = Path(__file__).resolve().parents[2] / "data"
RESOLUTION = 6.0


@pytest.fixture(scope="module")
def adk() -> EditableModel:
    return EditableModel(read_structure(DATA / "1AKE_adk_closed.pdb.gz"))


def _own_map(model: EditableModel) -> MapTarget:
    """The model's own heavy atoms at RESOLUTION, on a 1 Å grid."""
    coords = model.coords[heavy_atoms(model)]
    origin = np.floor(coords.min(axis=0)) - 12.0
    grid = np.zeros(tuple(int(n) for n in np.ceil(coords.max(axis=0) + 12.0 - origin)))
    np.add.at(grid, tuple(np.round(coords - origin).astype(int).T), 1.0)
    density = DensityMap(ndimage.gaussian_filter(grid, gaussian_sigma(RESOLUTION)), origin, np.eye(3))
    return MapTarget(density, RESOLUTION, coords)


def test_the_rotors_are_the_iupac_torsions_and_keep_every_bond(adk: EditableModel) -> None:
    rotors = side_chain_rotors(adk, [0])
    names = adk.structure.atoms.name
    lys = adk.segments[0].resname == "LYS"
    assert np.bincount(rotors.depth).tolist()[0] == np.isin(adk.segments[0].resname, (
        "ARG", "ASN", "ASP", "CYS", "GLN", "GLU", "HIS", "ILE", "LEU", "LYS", "MET", "PHE", "SER", "THR", "TRP",
        "TYR", "VAL")).sum()  # one χ1 a residue, none for Gly, Ala, Pro
    assert np.sum(rotors.depth == 3) >= lys.sum()  # χ4 of every lysine (and arginine)
    assert not np.isin(names[rotors.atoms], ("N", "CA", "C", "O", "CB")).any()
    turned = rotors.turned(adk.coords, np.random.default_rng(1).uniform(-np.pi, np.pi, len(rotors.bonds)))
    top = topology(adk.structure)
    i, j = np.divmod(top.excluded, top.n_atoms)
    before, after = (np.linalg.norm(c[i] - c[j], axis=1) for c in (adk.coords, turned))
    assert np.abs(after - before)[before < 1.9].max() < 1e-9  # bonds
    assert np.linalg.norm(turned - adk.coords, axis=1).max() > 3.0


def test_the_gradient_is_the_derivative_of_the_correlation(adk: EditableModel) -> None:
    rotors = side_chain_rotors(adk, [0])
    correlation = atom_correlation(adk, _own_map(adk))
    angles = np.random.default_rng(2).uniform(-0.5, 0.5, len(rotors.bonds))
    coords = rotors.turned(adk.coords, angles)
    gradient = rotors.gradient(coords, correlation(coords)[1])
    for k in np.argsort(-np.abs(gradient))[:5]:
        step = np.zeros_like(angles)
        step[k] = 1e-4
        numeric = (correlation(rotors.turned(adk.coords, angles + step))[0]
                   - correlation(rotors.turned(adk.coords, angles - step))[0]) / 2e-4
        assert numeric == pytest.approx(gradient[k], rel=0.1)


def test_side_chains_turned_away_turn_back_into_their_map_without_new_clashes(adk: EditableModel) -> None:
    model = EditableModel(adk.structure)
    target = _own_map(model)
    rotors = side_chain_rotors(model, [0])
    model.coords = rotors.turned(model.coords, np.random.default_rng(3).uniform(-0.8, 0.8, len(rotors.bonds)))
    rows = heavy_atoms(model)
    cc, clashes = target.correlation(model.coords[rows]), validate(model.structure, model.coords).counts["clash"]
    start = model.coords.copy()
    edits = fit_side_chains(model, [0], atom_correlation(model, target))
    assert len(edits) == 1 and np.array_equal(edits[0].old_points, edits[0].new_points)  # the backbone stays
    for edit in edits:
        model.apply(edit)
    assert target.correlation(model.coords[rows]) > cc + 0.015 and target.correlation(model.coords[rows]) > 0.99
    assert validate(model.structure, model.coords).counts["clash"] <= clashes
    main_chain = np.isin(model.structure.atoms.name, ("N", "CA", "C", "O", "CB"))
    assert np.array_equal(model.coords[main_chain], start[main_chain])
