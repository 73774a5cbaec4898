"""The filter bank: perfect reconstruction, L2-best coarse curves, fractional levels."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from core.curves.filters import gram_matrix, level_filters, refinement_matrix, wavelet_matrix
from core.curves.splines import spline_space
from core.curves.wavelets import (
    WaveletTransform,
    analysis_step,
    decompose,
    finest_level,
    fractional_points,
    reconstruct,
    refine,
    smooth,
    synthesis_step,
)


def random_points(level: int, dim: int = 3, closed: bool = False, seed: int = 0) -> np.ndarray:
    n = spline_space(level, closed).n_points
    return np.random.default_rng(seed).normal(scale=10.0, size=(n, dim))


@settings(max_examples=60, deadline=None)
@given(
    level=st.integers(0, 9),
    dim=st.integers(1, 4),
    closed=st.booleans(),
    target=st.integers(0, 9),
    seed=st.integers(0, 2**32 - 1),
)
def test_perfect_reconstruction(level, dim, closed, target, seed):
    points = random_points(level, dim, closed, seed)
    transform = decompose(points, min(target, level), closed)
    assert transform.finest_level == level
    restored = reconstruct(transform)
    assert np.abs(restored - points).max() < 1e-10 * max(1.0, np.abs(points).max())


def test_full_transform_has_the_size_of_the_input():
    points = random_points(7)
    transform = decompose(points)
    assert transform.level == 0 and transform.coarse.shape == (4, 3)
    assert [len(d) for d in transform.details] == [2**k for k in range(7)]
    assert sum(len(d) for d in transform.details) + 4 == len(points)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("level", [1, 2, 3, 4, 6])
def test_normal_equations_equal_the_dense_analysis_filters(level, closed):
    points = random_points(level, closed=closed, seed=level)
    square = np.hstack([refinement_matrix(level, closed).toarray(), wavelet_matrix(level, closed).toarray()])
    dense = np.linalg.solve(square, points)  # [A; B] C: only acceptable as a small reference
    coarse, details = analysis_step(points, closed)
    n_coarse = len(coarse)
    assert np.abs(coarse - dense[:n_coarse]).max() < 1e-11 * np.abs(points).max()
    assert np.abs(details - dense[n_coarse:]).max() < 1e-11 * np.abs(points).max()
    assert np.abs(synthesis_step(coarse, details, closed) - points).max() < 1e-10


def gauss_samples(level: int, per_segment: int = 4) -> tuple[np.ndarray, np.ndarray]:
    nodes, weights = np.polynomial.legendre.leggauss(per_segment)
    h = 2.0**-level
    starts = np.arange(2**level) * h
    return (starts[:, None] + (nodes + 1) * h / 2).ravel(), np.tile(weights * h / 2, 2**level)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("depth", [1, 2, 4])
def test_coarse_curve_is_the_weighted_least_squares_fit(depth, closed):
    fine_level = 7
    points = random_points(fine_level, closed=closed, seed=depth)
    u, w = gauss_samples(fine_level)
    samples = spline_space(fine_level, closed).evaluate(points, u)
    basis = spline_space(fine_level - depth, closed).design_matrix(u).toarray()
    root = np.sqrt(w)[:, None]
    fit = np.linalg.lstsq(basis * root, samples * root, rcond=None)[0]
    assert np.abs(smooth(points, fine_level - depth, closed) - fit).max() < 1e-10


def test_coarse_curve_matches_dense_uniform_least_squares():
    fine_level, coarse_level = 6, 3
    points = random_points(fine_level, seed=11)
    u = (np.arange(100_000) + 0.5) / 100_000
    fit = np.linalg.lstsq(
        spline_space(coarse_level).design_matrix(u).toarray(), spline_space(fine_level).evaluate(points, u), rcond=None
    )[0]
    coarse = smooth(points, coarse_level)
    assert np.abs(coarse - fit).max() < 1e-5 * np.abs(coarse).max()


def l2_error(fine: np.ndarray, fine_level: int, coarse: np.ndarray, coarse_level: int) -> float:
    u, w = gauss_samples(fine_level)
    diff = spline_space(fine_level).evaluate(fine, u) - spline_space(coarse_level).evaluate(coarse, u)
    return float(np.sum(w[:, None] * diff**2))


def test_any_perturbation_of_the_coarse_points_increases_the_error():
    points = random_points(6, seed=3)
    coarse = smooth(points, 3)
    best = l2_error(points, 6, coarse, 3)
    rng = np.random.default_rng(4)
    for _ in range(50):
        assert l2_error(points, 6, coarse + 1e-3 * rng.normal(size=coarse.shape), 3) > best


@pytest.mark.parametrize("closed", [False, True])
def test_residual_is_orthogonal_to_the_coarse_space(closed):
    level = 6
    points = random_points(level, closed=closed, seed=5)
    coarse = smooth(points, level - 1, closed)
    P = refinement_matrix(level, closed)
    residual = points - P @ coarse
    assert np.abs(P.T @ (gram_matrix(level, closed) @ residual)).max() < 1e-12 * np.abs(points).max()


def test_coarse_curve_does_not_interpolate_the_ends():
    points = random_points(5, seed=6)
    coarse = smooth(points, 2)
    assert np.linalg.norm(coarse[0] - points[0]) > 1e-3


@pytest.mark.parametrize("closed", [False, True])
def test_refine_keeps_the_curve(closed):
    points = random_points(3, closed=closed, seed=7)
    fine = refine(points, 6, closed)
    u = np.random.default_rng(8).random(100)
    assert np.allclose(spline_space(6, closed).evaluate(fine, u), spline_space(3, closed).evaluate(points, u), atol=1e-12)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("t", [0.25, 0.5, 0.9])
def test_fractional_curve_blends_the_neighbouring_levels(t, closed):
    points = random_points(6, closed=closed, seed=9)
    j = 3
    shown, shown_level = fractional_points(points, j + t, closed)
    assert shown_level == j + 1
    u = np.random.default_rng(10).random(60)
    expected = (1 - t) * spline_space(j, closed).evaluate(smooth(points, j, closed), u) + t * spline_space(
        j + 1, closed
    ).evaluate(smooth(points, j + 1, closed), u)
    assert np.allclose(spline_space(j + 1, closed).evaluate(shown, u), expected, atol=1e-10)
    transform = decompose(points, j, closed)
    filters = level_filters(j + 1, closed)
    assert np.allclose(shown, filters.P @ transform.coarse + t * (filters.Q @ transform.details[0]), atol=1e-10)


def test_fractional_level_is_continuous_and_ends_at_the_original():
    points = random_points(5, seed=12)
    at_integer, level = fractional_points(points, 3.0)
    assert level == 3 and np.allclose(at_integer, smooth(points, 3))
    near, level = fractional_points(points, 3.0 - 1e-7)
    assert level == 3 and np.abs(near - at_integer).max() < 1e-5
    original, level = fractional_points(points, 5.0)
    assert level == 5 and np.array_equal(original, points)


def test_one_dimensional_curves_are_accepted():
    values = random_points(4, dim=1)[:, 0]
    transform = decompose(values)
    assert transform.coarse.shape == (4,)
    assert np.allclose(reconstruct(transform), values)


def test_transform_reports_levels():
    transform = WaveletTransform(np.zeros((11, 2)), (np.zeros((8, 2)),))
    assert (transform.level, transform.finest_level) == (3, 4)
    assert finest_level(np.zeros((16, 3)), closed=True) == 4


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: decompose(np.zeros((10, 3))), "points must have 2\\*\\*m \\+ 3 rows"),
        (lambda: decompose(np.zeros((11, 3)), level=4), "level must lie in \\[0, 3\\]"),
        (lambda: decompose(np.full((11, 3), np.inf)), "non-finite"),
        (lambda: analysis_step(np.zeros((4, 3))), "level >= 1"),
        (lambda: smooth(np.zeros((11, 3)), 1.5), "integer level"),
        (lambda: fractional_points(np.zeros((11, 3)), 3.5), "level must lie in \\[0, 3\\]"),
        (lambda: fractional_points(np.zeros((11, 3)), float("nan")), "level must lie"),
        (lambda: refine(np.zeros((11, 3)), 2), "level must lie in \\[3, 30\\]"),
        (lambda: decompose(np.zeros((12, 3)), closed=True), "2\\*\\*m rows"),
        (lambda: decompose(np.zeros((11, 3, 2))), "points must be 1-D or 2-D"),
    ],
)
def test_bad_input_names_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()
