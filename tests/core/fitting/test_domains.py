"""The rigid-domain stage of a map fit (#32): the smaller dynamic domain of a chain (its
Gaussian network's slowest mode) moved as a rigid body into the map before the levels."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from core.fitting.density import fit_map
from core.fitting.domains import DOMAINS, GAIN, dynamic_domains, fit_domain
from core.fitting.map_target import MapTarget, heavy_atoms, occupancies
from core.fitting.simulated_maps import molmap, xray_like
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.protein.structure import Structure, ca_rows

DATA = Path(__file__).resolve().parents[2] / "data"
OPEN, CLOSED = "4AKE_adk_open.pdb.gz", "1AKE_adk_closed.pdb.gz"
LID = np.arange(122, 160)
"""Adenylate kinase's LID domain, residues 122-159 (Müller et al. 1996)."""


def _ca(structure: Structure) -> np.ndarray:
    return structure.coords[ca_rows(structure)]


def _rmsd(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))))


@pytest.mark.parametrize("file", [OPEN, CLOSED])
def test_the_smaller_dynamic_domain_of_adenylate_kinase_is_its_lid(file: str, fit_start: Callable) -> None:
    structure = fit_start(DATA / file)
    domain = dynamic_domains(_ca(structure))
    resseq = structure.segments[0].resseq
    assert np.count_nonzero(np.diff(domain.astype(int))) == 2  # one piece of the chain
    assert np.isin(LID, resseq[domain]).mean() > 0.9 and domain.sum() < 1.8 * len(LID)


def test_a_short_chain_or_one_in_pieces_apart_has_no_domains() -> None:
    ca = _ca(read_structure(DATA / CLOSED))
    assert not dynamic_domains(ca[:35]).any()
    apart = ca.copy()
    apart[100:] += 200.0  # two networks that do not touch: no slowest mode joins them
    assert not dynamic_domains(apart).any()


@pytest.mark.parametrize("start_file, target_file", [(OPEN, CLOSED), (CLOSED, OPEN)])
def test_the_lid_turns_into_the_other_conformations_map_as_a_rigid_body(
        start_file: str, target_file: str, fit_start: Callable) -> None:
    """9.7 Å apart, about 3.8 Å after the stage (the LID turned 50-57°, the NMP domain left
    to the levels); inside the domain the atoms keep their distances, outside none moves."""
    start, end = fit_start(DATA / start_file), read_structure(DATA / target_file)
    model = EditableModel(start)
    heavy = heavy_atoms(model)
    target = MapTarget(xray_like(end, 10.0), 10.0, model.coords[heavy])
    before = target.blurred(20.0).correlation(model.coords[heavy], occupancies(model, heavy))
    stage = fit_domain(model, [0], target, heavy, occupancies(model, heavy))
    assert stage.level == DOMAINS and stage.name == "domains" and "turned" in stage.motion
    assert stage.score > before + GAIN
    assert _rmsd(_ca(start), _ca(end)) > 9.0
    assert _rmsd(model.coords[ca_rows(start)], _ca(end)) < 4.5
    (edit,) = stage.edits
    inside = edit.rows
    moved = model.coords[inside]
    distances = np.linalg.norm(moved[:, None] - moved[None], axis=2)
    original = np.linalg.norm(start.coords[inside][:, None] - start.coords[inside][None], axis=2)
    assert np.abs(distances - original).max() < 1e-9
    outside = np.setdiff1d(np.arange(len(start.coords)), inside)
    assert np.array_equal(model.coords[outside], start.coords[outside])
    assert validate(start, model.coords).counts["peptide_bond"] <= 2  # the two hinges, for the regularization
    model.revert(edit)
    assert np.array_equal(model.coords, start.coords)
    assert np.array_equal(model.ribbons[0].points, EditableModel(start).ribbons[0].points)


def test_a_model_in_its_own_density_moves_no_domain() -> None:
    structure = read_structure(DATA / OPEN)
    model = EditableModel(structure)
    heavy = heavy_atoms(model)
    target = MapTarget(molmap(structure, 10.0), 10.0, model.coords[heavy])
    stage = fit_domain(model, [0], target, heavy, occupancies(model, heavy))
    assert not stage.edits and stage.motion is None and stage.control_points == 0
    assert np.array_equal(model.coords, structure.coords)


def test_a_fit_with_the_domains_first_reaches_the_other_conformation(fit_start: Callable) -> None:
    """4AKE into a 10 Å map of 1AKE: the domains, then levels 0-6, regularized and refined."""
    start, end = fit_start(DATA / OPEN), read_structure(DATA / CLOSED)
    model = EditableModel(start)
    target = MapTarget(molmap(end, 10.0), 10.0, model.coords[heavy_atoms(model)])
    result = fit_map(model, [0], target, [DOMAINS, *range(7)])
    assert [fit.level for fit in result.levels][:2] == [DOMAINS, 0] and result.levels[0].edits
    assert _rmsd(model.coords[ca_rows(start)], _ca(end)) < 1.5
    assert validate(start, model.coords).counts["peptide_bond"] == 0
