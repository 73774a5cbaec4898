"""Multiresolution editing: locality, kept details, fractional levels, direct manipulation."""

import numpy as np
import pytest

from core.curves.editing import changed_segments, move_control_point, push_to_finest, tug_curve
from core.curves.filters import level_filters
from core.curves.splines import spline_space
from core.curves.wavelets import decompose, fractional_points, smooth

FINEST = 7


def points_at(level: int, closed: bool = False, seed: int = 0) -> np.ndarray:
    n = spline_space(level, closed).n_points
    return np.cumsum(np.random.default_rng(seed).normal(scale=2.0, size=(n, 3)), axis=0)


@pytest.mark.parametrize("level", range(FINEST, 2, -1))
def test_locality_doubles_with_each_level_down(level):
    index = spline_space(level).n_points // 2  # an interior control point
    delta = move_control_point(level, index, [1.0, -2.0, 0.5], FINEST)
    scale = 2 ** (FINEST - level)
    assert np.count_nonzero(np.abs(delta).max(axis=1)) == 4 * scale - 3
    assert len(changed_segments(delta)) == 4 * scale


def test_finest_edit_moves_exactly_four_segments():
    delta = move_control_point(FINEST, 40, [0.0, 0.0, 3.0], FINEST)
    assert changed_segments(delta).tolist() == [37, 38, 39, 40]


def test_closed_edits_wrap_around_the_seam():
    delta = move_control_point(4, 14, [1.0, 0.0, 0.0], 6, closed=True)  # support [14/16, 18/16]
    segments = changed_segments(delta, closed=True)
    assert len(segments) == 16 and 0 in segments and 63 in segments


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("level", [2, 4, 6])
def test_integer_edit_changes_the_level_points_and_keeps_the_details(level, closed):
    points = points_at(FINEST, closed)
    before = decompose(points, level, closed)
    index = 3
    delta = move_control_point(level, index, [2.0, -1.0, 4.0], FINEST, closed)
    after = decompose(points + delta, level, closed)
    expected = before.coarse.copy()
    expected[index] += [2.0, -1.0, 4.0]
    assert np.allclose(after.coarse, expected, atol=1e-10)
    for old, new in zip(before.details, after.details):
        assert np.allclose(old, new, atol=1e-10)
    u = np.random.default_rng(1).random(50)
    moved = spline_space(FINEST, closed).evaluate(delta, u)
    change = np.zeros_like(expected)
    change[index] = [2.0, -1.0, 4.0]
    assert np.allclose(moved, spline_space(level, closed).evaluate(change, u), atol=1e-12)


@pytest.mark.parametrize("level", [3, 4.5, 6.25])
def test_edit_and_inverse_edit_round_trip(level):
    points = points_at(FINEST, seed=2)
    forward = move_control_point(level, 5, [3.0, 1.0, -2.0], FINEST)
    backward = move_control_point(level, 5, [-3.0, -1.0, 2.0], FINEST)
    assert np.allclose(points + forward + backward, points, atol=1e-12)
    tug = tug_curve(level, 0.4, [1.0, 2.0, 3.0], FINEST)
    untug = tug_curve(level, 0.4, [-1.0, -2.0, -3.0], FINEST)
    assert np.allclose(points + tug + untug, points, atol=1e-12)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("t", [0.2, 0.5, 0.8])
def test_fractional_edit_moves_the_picked_point_exactly(t, closed):
    points = points_at(FINEST, closed, seed=3)
    level, index, move = 3 + t, 6, np.array([1.5, -0.5, 2.0])
    shown, _ = fractional_points(points, level, closed)
    delta = move_control_point(level, index, move, FINEST, closed)
    new_shown, _ = fractional_points(points + delta, level, closed)
    expected = shown.copy()
    expected[index] += move
    assert np.abs(new_shown[index] - expected[index]).max() < 1e-10
    # finer details are untouched: the pyramid above level j+1 is unchanged
    before, after = decompose(points, 4, closed), decompose(points + delta, 4, closed)
    for old, new in zip(before.details, after.details):
        assert np.allclose(old, new, atol=1e-10)


def test_fractional_edit_limits():
    index, move = 6, np.array([1.0, 2.0, -1.0])
    near_zero = move_control_point(3 + 1e-7, index, move, FINEST)
    coarse_change = np.zeros((spline_space(3).n_points, 3))
    row = level_filters(4).P[[index], :].toarray().ravel()  # row 6: two equal maxima 8/16
    largest = np.flatnonzero(row == row.max())
    assert len(largest) == 2
    coarse_change[largest] = move / (2 * row.max())
    assert np.allclose(near_zero, push_to_finest(coarse_change, 3, FINEST), atol=1e-5)
    near_one = move_control_point(4 - 1e-7, index, move, FINEST)
    assert np.allclose(near_one, move_control_point(4, index, move, FINEST), atol=1e-5)


def test_fractional_edit_breadth_shrinks_monotonically():
    """Finest segments moved by more than a quarter of the peak (mathematics document, 9.3)."""
    index = 8  # a row of P^4 with two equal largest entries
    counts = []
    for level in (3 + 1e-9, 3.25, 3.5, 3.75, 4.0):  # t -> 0, 1/4, 1/2, 3/4, 1
        delta = move_control_point(level, index, [1.0, 0.0, 0.0], FINEST)
        moved = np.abs(spline_space(FINEST).evaluate(delta, (np.arange(128) + 0.5) / 128))[:, 0]
        counts.append(int(np.count_nonzero(moved > 0.25 * moved.max())))
    assert counts == sorted(counts, reverse=True) and counts[0] > counts[-1]
    assert counts == [44, 43, 40, 30, 16]


def test_integer_tug_moves_the_finest_curve_exactly_with_least_norm():
    points, u0, move = points_at(FINEST, seed=4), 0.3721, np.array([2.0, -3.0, 1.0])
    space = spline_space(FINEST)
    for level in (2, 4, FINEST):
        delta = tug_curve(level, u0, move, FINEST)
        assert np.allclose(space.evaluate(points + delta, u0) - space.evaluate(points, u0), move, atol=1e-12)
        coarse_change = smooth(delta, level)  # the level-level change that was pushed up
        phi = spline_space(level).design_matrix([u0]).toarray()
        least_norm = np.linalg.pinv(phi) @ move[None, :]
        assert np.allclose(coarse_change, least_norm, atol=1e-10)


@pytest.mark.parametrize("t", [0.3, 0.6])
def test_fractional_tug_moves_the_displayed_curve_exactly(t):
    points, u0, move = points_at(FINEST, seed=5), 0.61, np.array([0.0, 1.0, 2.0])
    level = 4 + t
    shown, shown_level = fractional_points(points, level)
    delta = tug_curve(level, u0, move, FINEST)
    new_shown, _ = fractional_points(points + delta, level)
    space = spline_space(shown_level)
    assert np.allclose(space.evaluate(new_shown, u0) - space.evaluate(shown, u0), move, atol=1e-10)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: move_control_point(3, 11, [1, 0, 0], FINEST), "index must be an integer in \\[0, 10\\]"),
        (lambda: move_control_point(3.5, 19, [1, 0, 0], FINEST), "index must be an integer in \\[0, 18\\]"),
        (lambda: move_control_point(8, 0, [1, 0, 0], FINEST), "level must lie in \\[0, 7\\]"),
        (lambda: move_control_point(3, 0, [np.nan, 0, 0], FINEST), "displacement contains"),
        (lambda: tug_curve(3, 1.2, [1, 0, 0], FINEST), "u must lie in \\[0, 1\\]"),
        (lambda: push_to_finest(np.zeros((10, 3)), 3, FINEST), "delta must have 11 rows"),
    ],
)
def test_bad_edits_name_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()
