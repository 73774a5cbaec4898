"""The B-spline spaces: basis values against an independent evaluator, derivatives, closed curves."""

import numpy as np
import pytest

from core.curves.splines import space_of, spline_space


def cox_de_boor(knots: np.ndarray, i: int, u: float, degree: int = 3) -> float:
    """Textbook recursion with half-open spans; u = 1 uses the last non-empty span."""
    if degree == 0:
        if knots[i] <= u < knots[i + 1]:
            return 1.0
        last = np.flatnonzero(knots < knots[-1])[-1]
        return float(u == knots[-1] and i == last)
    value = 0.0
    if knots[i + degree] > knots[i]:
        value += (u - knots[i]) / (knots[i + degree] - knots[i]) * cox_de_boor(knots, i, u, degree - 1)
    if knots[i + degree + 1] > knots[i + 1]:
        value += (
            (knots[i + degree + 1] - u)
            / (knots[i + degree + 1] - knots[i + 1])
            * cox_de_boor(knots, i + 1, u, degree - 1)
        )
    return value


@pytest.mark.parametrize("level", [0, 1, 2, 3, 5])
def test_open_basis_matches_cox_de_boor(level):
    space = spline_space(level)
    u = np.concatenate([np.random.default_rng(level).random(25), np.arange(space.n_segments + 1) / space.n_segments])
    expected = np.array([[cox_de_boor(space.knots, i, x) for i in range(space.n_points)] for x in u])
    assert np.abs(space.design_matrix(u).toarray() - expected).max() < 1e-12


def test_level_zero_is_bernstein():
    u = np.linspace(0, 1, 11)
    bernstein = np.column_stack([(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u**2 * (1 - u), u**3])
    assert np.allclose(spline_space(0).design_matrix(u).toarray(), bernstein, atol=1e-14)


def test_published_check_values():
    space = spline_space(4)
    h = 1 / 16
    rows = space.design_matrix([h / 2, 1.5 * h, h, 5.5 * h, 6 * h]).toarray()
    assert np.allclose(rows[0, :4], [1 / 8, 19 / 32, 25 / 96, 1 / 48], atol=1e-14)
    assert np.allclose(rows[1, 1:5], [1 / 32, 15 / 32, 23 / 48, 1 / 48], atol=1e-14)
    assert np.allclose(rows[2, 1:4], [1 / 4, 7 / 12, 1 / 6], atol=1e-14)
    assert np.allclose(rows[3, 5:9], np.array([1, 23, 23, 1]) / 48, atol=1e-14)
    assert np.allclose(rows[4, 6:9], np.array([1, 4, 1]) / 6, atol=1e-14)


@pytest.mark.parametrize("closed", [False, True])
def test_partition_of_unity_and_four_nonzeros(closed):
    space = spline_space(5, closed)
    matrix = space.design_matrix(np.random.default_rng(1).random(200))
    assert np.allclose(matrix.sum(axis=1), 1.0, atol=1e-14)
    assert np.all(np.diff(matrix.indptr) <= 4)


def test_open_curve_interpolates_ends_and_is_mirror_symmetric():
    space = spline_space(3)
    points = np.random.default_rng(2).normal(size=(space.n_points, 3))
    ends = space.evaluate(points, [0.0, 1.0])
    assert np.allclose(ends, points[[0, -1]], atol=1e-14)
    u = np.random.default_rng(3).random(30)
    assert np.allclose(space.design_matrix(u).toarray(), space.design_matrix(1 - u).toarray()[:, ::-1], atol=1e-13)


@pytest.mark.parametrize("closed", [False, True])
def test_derivatives_match_finite_differences(closed):
    space = spline_space(4, closed)
    points = np.random.default_rng(4).normal(size=(space.n_points, 3))
    u = np.array([0.13, 0.37, 0.61, 0.88])  # away from knots: the second derivative jumps there
    eps = 1e-6
    first = (space.evaluate(points, u + eps) - space.evaluate(points, u - eps)) / (2 * eps)
    second = (space.evaluate(points, u + eps, 1) - space.evaluate(points, u - eps, 1)) / (2 * eps)
    assert np.allclose(space.evaluate(points, u, 1), first, rtol=1e-6, atol=1e-6)
    assert np.allclose(space.evaluate(points, u, 2), second, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize("level", [0, 1, 2, 4])
def test_closed_basis_is_the_wrapped_cardinal_bspline(level):
    space = spline_space(level, closed=True)
    u = np.random.default_rng(level).random(40)
    cardinal_knots = np.arange(5.0)
    expected = np.zeros((len(u), space.n_points))
    for i in range(space.n_points):
        for shift in range(-4, 6):  # all wrapped copies N(2^j u - i + shift * 2^j)
            x = space.n_segments * u - i + shift * space.n_segments
            expected[:, i] += [cox_de_boor(cardinal_knots, 0, v) if 0 <= v < 4 else 0.0 for v in x]
    assert np.abs(space.design_matrix(u).toarray() - expected).max() < 1e-12


def test_closed_curve_has_no_seam():
    space = spline_space(3, closed=True)
    points = np.random.default_rng(5).normal(size=(space.n_points, 2))
    for derivative in (0, 1, 2):
        start, end = space.evaluate(points, [0.0, 1.0 - 1e-12], derivative)
        assert np.allclose(start, end, atol=1e-8)


@pytest.mark.parametrize("closed", [False, True])
def test_closest_parameter_recovers_a_curve_point(closed):
    space = spline_space(4, closed)
    rng = np.random.default_rng(6)
    points = np.cumsum(rng.normal(size=(space.n_points, 3)), axis=0)
    for u0 in (0.21, 0.5, 0.77):
        target = space.evaluate(points, u0) + 1e-3 * rng.normal(size=3)
        u = space.closest_parameter(points, target)
        assert np.linalg.norm(space.evaluate(points, u) - space.evaluate(points, u0)) < 5e-3


def test_space_of_reads_the_level_from_the_row_count():
    assert space_of(np.zeros((35, 3))).level == 5
    assert space_of(np.zeros((32, 3)), closed=True).level == 5


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: space_of(np.zeros((10, 3))), "points must have 2\\*\\*m \\+ 3 rows"),
        (lambda: spline_space(2).evaluate(np.zeros((6, 3)), 0.5), "points must have 7 rows"),
        (lambda: spline_space(2).evaluate(np.full((7, 3), np.nan), 0.5), "points contains 21 non-finite"),
        (lambda: spline_space(2).evaluate(np.zeros((7, 3)), 1.5), "u must lie in \\[0, 1\\]"),
        (lambda: spline_space(2).evaluate(np.zeros((7, 3)), 0.5, derivative=3), "derivative must be"),
        (lambda: spline_space(-1), "level must lie in"),
    ],
)
def test_bad_input_names_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()
