"""Fitting into density maps (#19): the map blurred for the levels; the refinement, every
residue a rigid body with its side chains' χ rotors (their analytic gradients, the fit)."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage, sparse

from core.analysis.superpose import superpose
from core.fitting.conformation import pair_segments
from core.fitting.density import atom_correlation, fit_map, refine, resolved_levels
from core.fitting.domains import DOMAINS
from core.fitting.map_target import MapTarget, gaussian_sigma, heavy_atoms
from core.fitting.real_space import ResidueBodies, refine_real_space
from core.fitting.side_chains import side_chain_rotors
from core.fitting.simulated_maps import molmap, xray_like
from core.geometry.topology import topology
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.protein.structure import ca_rows
from core.protein.writing import write_structure
from core.surfaces.volume import DensityMap

DATA = Path(__file__).resolve().parents[2] / "data"
RESOLUTION = 6.0


@pytest.fixture(scope="module")
def adk() -> EditableModel:
    return EditableModel(read_structure(DATA / "1AKE_adk_closed.pdb.gz"))


def _atoms_on_grid(model: EditableModel) -> tuple[np.ndarray, np.ndarray]:
    """The model's heavy atoms counted on a 1 Å grid with 12 Å around them, and its origin."""
    coords = model.coords[heavy_atoms(model)]
    origin = np.floor(coords.min(axis=0)) - 12.0
    grid = np.zeros(tuple(int(n) for n in np.ceil(coords.max(axis=0) + 12.0 - origin)))
    np.add.at(grid, tuple(np.round(coords - origin).astype(int).T), 1.0)
    return grid, origin


def _own_map(model: EditableModel, resolution: float = RESOLUTION, around: EditableModel | None = None) -> MapTarget:
    """The model's own heavy atoms at ``resolution`` Å, on a 1 Å grid, around the heavy atoms
    of ``around`` (the model itself by default)."""
    grid, origin = _atoms_on_grid(model)
    density = DensityMap(ndimage.gaussian_filter(grid, gaussian_sigma(resolution)), origin, np.eye(3))
    around = model if around is None else around
    return MapTarget(density, resolution, around.coords[heavy_atoms(around)])


def test_a_map_blurred_for_the_levels_is_the_map_at_that_resolution(adk: EditableModel) -> None:
    fine, coarse = _own_map(adk, 6.0), _own_map(adk, 10.0)
    blurred = fine.blurred(10.0)
    assert fine.blurred(5.0) is fine and blurred.resolution == 10.0 and blurred.spacing == coarse.spacing
    rows = heavy_atoms(adk)
    rng = np.random.default_rng(4)
    for shift in (0.0, 1.5, 4.0):  # the model in place and moved off it
        coords = adk.coords[rows] + shift * rng.normal(size=3)
        assert blurred.correlation(coords) == pytest.approx(coarse.correlation(coords), abs=0.005)
    assert fine.correlation(adk.coords[rows] + 2.0) < blurred.correlation(adk.coords[rows] + 2.0)  # wider basin


def test_a_fit_into_a_6_angstrom_map_takes_the_levels_through_it_blurred(adk: EditableModel,
                                                                         fit_start: Callable) -> None:
    """4AKE into a 6 Å map of 1AKE: the levels fitted into it as it is stall 2.5 Å from the
    target (the finer map's detail traps the coarse control points); blurred, they do not."""
    start = EditableModel(fit_start(DATA / "4AKE_adk_open.pdb.gz"))
    target = _own_map(adk, 6.0, around=start)
    ca = start.structure.atoms.name == "CA"
    result = fit_map(start, [0], target, range(0, 7))
    assert [fit.level for fit in result.levels] == list(range(7)) and not result.dropped and result.refinement
    rmsd = np.sqrt(np.mean(np.sum((start.coords[ca] - adk.coords[ca]) ** 2, axis=1)))
    assert rmsd < 2.0 and target.correlation(start.coords[heavy_atoms(start)]) > 0.94
    assert validate(start.structure, start.coords).counts["peptide_bond"] == 0


def test_a_fit_into_a_map_cut_sharply_in_fourier_space_is_not_held_by_its_ripples(adk: EditableModel) -> None:
    """4AKE into a 10 Å map of 1AKE whose transform is cut at 1/10 Å⁻¹, as an X-ray map's is:
    its ripples held the LID domain 5 Å short (3.5 Å overall) while the finest levels saw
    the map at 10 Å; at 12 Å they do not."""
    start = EditableModel(read_structure(DATA / "4AKE_adk_open.pdb.gz"))
    grid, origin = _atoms_on_grid(adk)
    spectrum = np.fft.rfftn(grid)
    frequency = np.meshgrid(*(np.fft.fftfreq(n) for n in grid.shape[:2]), np.fft.rfftfreq(grid.shape[2]),
                            indexing="ij")
    spectrum[np.sqrt(sum(f**2 for f in frequency)) > 1.0 / 10.0] = 0.0
    density = DensityMap(np.fft.irfftn(spectrum, grid.shape, axes=(0, 1, 2)), origin, np.eye(3))
    target = MapTarget(density, 10.0, start.coords[heavy_atoms(start)])
    assert not fit_map(start, [0], target, range(0, 7)).dropped
    ca = start.structure.atoms.name == "CA"
    assert np.sqrt(np.mean(np.sum((start.coords[ca] - adk.coords[ca]) ** 2, axis=1))) < 2.0


def test_the_levels_fitted_into_a_map_are_those_it_resolves(adk: EditableModel) -> None:
    """Two Å per residue of a span between control points, at least half the resolution:
    adenylate kinase's level 6 spans 3.3 residues (6.7 Å), level 5 6.7 (13 Å), level 4 13
    (27 Å); the domain stage and the coarsest level asked for stay."""
    every = [DOMAINS, *range(7)]
    assert resolved_levels(adk, [0], every, 6.0) == resolved_levels(adk, [0], every, 10.0) == every
    assert resolved_levels(adk, [0], every, 20.0) == [DOMAINS, 0, 1, 2, 3, 4, 5]
    assert resolved_levels(adk, [0], every, 30.0) == [DOMAINS, 0, 1, 2, 3, 4]
    assert resolved_levels(adk, [0], [5, 6], 30.0) == [5]


def test_a_homologue_fitted_into_a_10_angstrom_map_ends_at_one_model_from_every_start(
        every_start: Callable, tmp_path: Path) -> None:
    """HPr of *E. coli* (1POH) into a 10 Å map of *B. subtilis*'s (2HPR), placed on it by their
    paired Cα: with level 6 (1.4 residues a span) the backbone bent into the other protein's
    side chains, 57 junctions broke, and the regularization closed them one of two ways as
    the last bits of the start fell (fits 0.36 Å apart). The map resolves levels 0-5; fitted
    from starts 0.001 Å apart, the models end within 0.1 Å of each other."""
    start, end = read_structure(DATA / "1POH_A.pdb.gz"), read_structure(DATA / "2HPR_A.pdb.gz")
    pairs, _ = pair_segments(EditableModel(start), [0], [end.segments[0]])
    rows = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]]
    placed = read_structure(write_structure(start, superpose(pairs[0].target, start.coords[rows]).apply(start.coords),
                                            tmp_path / "1POH_placed.pdb"))
    target = MapTarget(molmap(end, 10.0), 10.0, placed.coords[heavy_atoms(EditableModel(placed))])
    fitted = []
    for structure in every_start(placed):
        model = EditableModel(structure)
        result = fit_map(model, [0], target, [DOMAINS, *range(7)])
        assert [fit.level for fit in result.levels] == [DOMAINS, 0, 1, 2, 3, 4, 5] and result.refinement
        assert target.correlation(model.coords[heavy_atoms(model)]) > 0.99
        fitted.append(model.coords[rows])
    apart = max(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))) for a in fitted for b in fitted)
    assert 0.0 < apart <= 0.1  # (0: the starts were not perturbed)


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


@pytest.mark.parametrize("cut", [False, True])
def test_the_correlation_is_smooth_as_atoms_cross_the_grid(adk: EditableModel, cut: bool) -> None:
    """An atom moved in small steps across several grid planes: its gradient changes a
    little each step, never jumps (spread trilinearly, it jumped at every plane, where
    L-BFGS ends up wherever the last bits of its start lead it)."""
    structure = read_structure(DATA / "1AKE_adk_closed.pdb.gz")
    density = xray_like(structure, 10.0) if cut else molmap(structure, 6.0)
    target = MapTarget(density, 10.0 if cut else 6.0, adk.coords[heavy_atoms(adk)])
    correlation = atom_correlation(adk, target)
    for atom in heavy_atoms(adk)[::600]:
        coords = adk.coords.copy()
        path = coords[atom] + np.linspace(0.0, 3.0 * target.spacing, 151)[:, None] * np.array([1.0, 0.7, 0.4])
        gradients = []
        for point in path:
            coords[atom] = point
            gradients.append(correlation(coords)[1][atom])
        change = np.linalg.norm(np.diff(gradients, axis=0), axis=1)
        assert change.max() < 3.0 * np.median(change) + 1e-12


def test_the_real_space_gradient_is_the_derivative_of_what_it_climbs(adk: EditableModel) -> None:
    """Shifts, rotations (through the right Jacobian of SO(3)) and torsions, at a state far
    from the start, for a function of the atoms (the CC) and of the ideal junction points."""
    bodies = ResidueBodies(adk, [0])
    correlation = atom_correlation(adk, _own_map(adk))
    pull = np.random.default_rng(5).normal(size=bodies.ideal.shape)

    def value(x: np.ndarray) -> float:
        coords, ideal, _ = bodies.place(x)
        return correlation(coords)[0] + 1e-3 * np.sum(pull * ideal)

    x = np.random.default_rng(6).normal(0.0, 0.5, bodies.size)
    coords, _, placed = bodies.place(x)
    gradient = bodies.gradient(correlation(coords)[1], 1e-3 * pull, placed)
    n = bodies.n
    for part in (slice(0, 3 * n), slice(3 * n, 6 * n), slice(6 * n, None)):
        direction = np.zeros(bodies.size)
        direction[part] = np.random.default_rng(7).normal(size=direction[part].shape)
        numeric = (value(x + 1e-5 * direction) - value(x - 1e-5 * direction)) / 2e-5
        assert numeric == pytest.approx(gradient @ direction, rel=1e-3)


def test_residues_moved_off_their_map_refine_back_into_it_each_as_it_was(adk: EditableModel) -> None:
    """Every residue of 1AKE shifted, turned and its side chains turned away from its own 6 Å
    map: the refinement brings them back, each residue exactly its shape, junctions closed."""
    model = EditableModel(adk.structure)
    target = _own_map(model)
    bodies = ResidueBodies(model, [0])
    rng = np.random.default_rng(3)
    n = bodies.n
    away = np.concatenate([rng.normal(0.0, 0.4, 3 * n), rng.normal(0.0, 0.4, 3 * n),
                           rng.uniform(-2.0, 2.0, bodies.size - 6 * n)])  # about 0.7 Å, 13°; χ ±38°
    model.coords = bodies.place(away)[0]
    rows, ca = heavy_atoms(model), model.structure.atoms.name == "CA"
    moved = target.correlation(model.coords[rows])

    def rmsd() -> float:
        return float(np.sqrt(np.mean(np.sum((model.coords[ca] - adk.coords[ca]) ** 2, axis=1))))

    off = rmsd()
    edits = refine(model, [0], target, cycles=1)
    assert edits and all(np.array_equal(e.old_points, e.new_points) for e in edits)  # the curve stays
    assert moved < 0.97 and target.correlation(model.coords[rows]) > 0.99
    assert rmsd() < off / 2
    counts = validate(model.structure, model.coords).counts
    read = validate(model.structure, adk.coords).counts
    assert counts["peptide_bond"] == 0 and counts["clash"] <= read["clash"]
    top = topology(model.structure)
    i, j = np.divmod(top.excluded, top.n_atoms)
    bonded = np.linalg.norm(adk.coords[i] - adk.coords[j], axis=1) < 1.9
    i, j = i[bonded], j[bonded]
    bonds = sparse.coo_matrix((np.ones(len(i)), (i, j)), shape=(top.n_atoms,) * 2)
    i, j = sparse.triu((bonds + bonds.T) + (bonds + bonds.T) @ (bonds + bonds.T), k=1).nonzero()  # bonds, angles
    same = model.structure.atom_residue[i] == model.structure.atom_residue[j]
    before, after = (np.linalg.norm(c[i[same]] - c[j[same]], axis=1) for c in (adk.coords, model.coords))
    assert len(before) > len(rows) and np.abs(after - before).max() < 1e-9  # no residue changes shape


def test_a_refinement_cancelled_stops_at_once_with_the_best_point_it_reached(adk: EditableModel) -> None:
    """Cancel, asked at every evaluation, stops L-BFGS at the evaluation it says so; the
    edits are those of the best point seen so far, between the start and a whole refinement."""
    model = EditableModel(adk.structure)
    target = _own_map(model)
    bodies = ResidueBodies(model, [0])
    model.coords = bodies.place(np.random.default_rng(5).normal(0.0, 0.3, bodies.size))[0]
    rows = heavy_atoms(model)
    correlation = atom_correlation(model, target)
    evaluations = []

    def score(coords: np.ndarray) -> tuple[float, np.ndarray]:
        evaluations.append(1)
        return correlation(coords)

    def after(n: int | None) -> float:
        evaluations.clear()
        edits = refine_real_space(model, [0], score, cancelled=lambda: n is not None and len(evaluations) >= n)
        coords = model.coords.copy()
        for edit in edits:
            coords[edit.rows] = edit.new_coords
        return target.correlation(coords[rows])

    start = target.correlation(model.coords[rows])
    stopped = after(15)
    assert len(evaluations) == 15  # no evaluation after Cancel
    whole = after(None)
    assert len(evaluations) > 50 and start < stopped < whole


def test_a_partly_occupied_atom_weighs_its_occupancy_in_the_models_density(adk: EditableModel) -> None:
    """As a map shows it: the density of atoms at half occupancy is half theirs, and the
    gradient of the CC so weighted is its derivative."""
    target = _own_map(adk)
    coords = adk.coords[heavy_atoms(adk)] + np.random.default_rng(3).normal(scale=0.5, size=(len(heavy_atoms(adk)), 3))
    occupancy = np.random.default_rng(4).choice([0.25, 0.5, 1.0], len(coords))
    assert np.allclose(target.density(coords, np.full(len(coords), 0.5)), 0.5 * target.density(coords))
    cc, gradient = target.gradient(coords, occupancy)
    assert cc == target.correlation(coords, occupancy) != target.correlation(coords)
    for atom in np.argsort(-np.linalg.norm(gradient, axis=1))[:5]:
        for axis in range(3):
            step = np.zeros_like(coords)
            step[atom, axis] = 1e-4
            numeric = (target.correlation(coords + step, occupancy) - target.correlation(coords - step, occupancy)) / 2e-4
            assert numeric == pytest.approx(gradient[atom, axis], rel=0.05, abs=1e-7)


def test_for_a_map_cut_sharply_the_models_density_is_cut_the_same_way(adk: EditableModel) -> None:
    """Its transform ends at 1/resolution, as the map's does (it ripples as the map does),
    and the gradient of the CC is still its derivative (the filter is its own adjoint)."""
    rows = heavy_atoms(adk)
    density = xray_like(adk.structure, 8.0, noise=0.0)
    assert density.cut_sharply and density.resolution == 8.0
    target = MapTarget(density, 8.0, adk.coords[rows])
    model = target.density(adk.coords[rows])
    frequency = np.meshgrid(*(np.fft.fftfreq(n, target.spacing) for n in model.shape), indexing="ij")
    beyond = np.sqrt(sum(f**2 for f in frequency)) > 1.0 / 8.0 + 1.0 / (min(model.shape) * target.spacing)
    power = np.abs(np.fft.fftn(model)) ** 2
    assert power[beyond].sum() < 0.02 * power.sum()  # (what is left: the cut box's edges)
    assert target.correlation(adk.coords[rows]) > 0.99 > MapTarget(
        DensityMap(density.values, density.origin, density.axes), 8.0, adk.coords[rows]).correlation(adk.coords[rows])
    coords = adk.coords[rows] + np.random.default_rng(6).normal(scale=0.5, size=(len(rows), 3))
    cc, gradient = target.gradient(coords)
    for atom in np.argsort(-np.linalg.norm(gradient, axis=1))[:4]:
        for axis in range(3):
            step = np.zeros_like(coords)
            step[atom, axis] = 1e-4
            numeric = (target.correlation(coords + step) - target.correlation(coords - step)) / 2e-4
            assert numeric == pytest.approx(gradient[atom, axis], rel=0.05, abs=1e-7)
