"""The starts of the fit tests: a fit must reach its bound from the file as read and from
its coordinates moved in the last digits, not along one optimizer path that another
machine (another CPU, BLAS or library build) would not take."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from core.protein.reading import read_structure
from core.protein.structure import Structure
from core.protein.writing import write_structure

STARTS = (0, 1, 2)
"""Seeds of the starts: 0 is the file as read, the others its coordinates perturbed."""
PERTURBATION = 0.001
"""Å: how far each coordinate of a perturbed start moves, at most (uniformly)."""


def perturbed(structure: Structure, seed: int, folder: Path) -> Structure:
    """``structure`` itself for seed 0, else with every coordinate moved by up to
    :data:`PERTURBATION` Å, written to ``folder`` and read again (as another program's file
    would be)."""
    if seed == 0:
        return structure
    jitter = np.random.default_rng(seed).uniform(-PERTURBATION, PERTURBATION, structure.coords.shape)
    written = folder / f"{seed}_{structure.path.name.removesuffix('.gz')}"
    return read_structure(write_structure(structure, structure.coords + jitter, written))


@pytest.fixture(params=STARTS, ids=lambda seed: "as-read" if seed == 0 else f"perturbed-{seed}")
def fit_start(request: pytest.FixtureRequest, tmp_path: Path) -> Callable[[Path], Structure]:
    """Reads the start of a fit: the file as read, or :func:`perturbed`; a test using it runs
    from each of :data:`STARTS`."""
    return lambda path: perturbed(read_structure(path), request.param, tmp_path)


@pytest.fixture
def every_start(tmp_path: Path) -> Callable[[Structure], list[Structure]]:
    """The starts of a fit whose results are compared with each other: ``structure`` from
    each of :data:`STARTS` (:func:`perturbed`)."""
    return lambda structure: [perturbed(structure, seed, tmp_path) for seed in STARTS]
