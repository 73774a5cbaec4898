"""Principal directions in plain Python: LAPACK's eigenvectors, each with one sign everywhere."""

from __future__ import annotations

import numpy as np
import pytest

from core.geometry.principal import principal_directions
from core.protein.reading import read_structure
from tests.conftest import DATA


def _scatter(points: np.ndarray) -> np.ndarray:
    centred = points - points.mean(axis=0)
    return centred.T @ centred


def test_the_directions_are_the_eigenvectors_by_increasing_eigenvalue() -> None:
    """Over clouds of every shape and turn: an orthonormal frame that diagonalises the scatter,
    its eigenvalues rising, the same directions as numpy's ``eigh`` (up to sign)."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        turn = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        points = rng.normal(size=(int(rng.integers(4, 200)), 3)) * rng.uniform(0.05, 20.0, 3) @ turn
        scatter = _scatter(points)
        frame = np.array(principal_directions(scatter.tolist()))
        values, vectors = np.linalg.eigh(scatter)
        np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(frame @ scatter @ frame.T, np.diag(values), atol=1e-9 * values[-1])
        np.testing.assert_allclose(np.abs(frame @ vectors), np.eye(3), atol=1e-6)


def test_each_direction_has_one_sign_whatever_the_turn_of_the_numbers() -> None:
    """Each direction's largest component is positive, so a cloud and the same cloud scaled,
    shifted or listed in another order give the same frame (a view that never flips)."""
    ca = read_structure(DATA / "1UBQ.pdb.gz").segments[0].ca
    frame = np.array(principal_directions(_scatter(ca).tolist()))
    assert all(row[np.argmax(np.abs(row))] > 0 for row in frame)
    rng = np.random.default_rng(3)
    for _ in range(20):
        moved = ca[rng.permutation(len(ca))] * rng.uniform(0.5, 2.0) + rng.normal(scale=50.0, size=3)
        np.testing.assert_allclose(principal_directions(_scatter(moved).tolist()), frame, atol=1e-9)


@pytest.mark.parametrize("values", [(1.0, 1.0, 1.0), (1.0, 1.0, 5.0), (0.0, 2.0, 2.0), (0.0, 0.0, 0.0)])
def test_equal_eigenvalues_still_give_an_orthonormal_frame(values: tuple[float, float, float]) -> None:
    turn = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    frame = np.array(principal_directions((turn @ np.diag(values) @ turn.T).tolist()))
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
