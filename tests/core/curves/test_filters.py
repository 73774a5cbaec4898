"""Synthesis filters P, Q and Gram matrices I against the published tables and identities."""

from fractions import Fraction

import numpy as np
import pytest

from core.curves.filters import gram_matrix, level_filters, refinement_matrix, wavelet_matrix
from core.curves.splines import spline_space

LEVELS = range(1, 9)


def boehm_refinement(level: int) -> np.ndarray:
    """P^j by exact knot insertion of the midpoints into the level-(j-1) knots (Boehm 1980)."""
    knots = [Fraction(x).limit_denominator(2**level) for x in spline_space(level - 1).knots]
    coarse = spline_space(level - 1).n_points
    points = [[Fraction(int(r == c)) for c in range(coarse)] for r in range(coarse)]
    for k in range(2 ** (level - 1)):
        x = Fraction(2 * k + 1, 2**level)
        mu = max(i for i in range(len(knots) - 1) if knots[i] <= x < knots[i + 1])
        new = []
        for i in range(len(points) + 1):
            if i <= mu - 3:
                new.append(points[i])
            elif i >= mu + 1:
                new.append(points[i - 1])
            else:
                alpha = (x - knots[i]) / (knots[i + 3] - knots[i])
                new.append([(1 - alpha) * a + alpha * b for a, b in zip(points[i - 1], points[i])])
        points = new
        knots = sorted(knots + [x])
    return np.array(points, dtype=np.float64)


@pytest.mark.parametrize("level", range(1, 7))
def test_refinement_equals_knot_insertion(level):
    assert np.array_equal(refinement_matrix(level).toarray(), boehm_refinement(level))


def test_refinement_published_tables():
    assert np.array_equal(
        16 * refinement_matrix(2).toarray(),
        [[16, 0, 0, 0, 0], [8, 8, 0, 0, 0], [0, 12, 4, 0, 0], [0, 3, 10, 3, 0], [0, 0, 4, 12, 0], [0, 0, 0, 8, 8], [0, 0, 0, 0, 16]],
    )
    top_left = 16 * refinement_matrix(5).toarray()[:6, :4]
    assert np.array_equal(
        top_left, [[16, 0, 0, 0], [8, 8, 0, 0], [0, 12, 4, 0], [0, 3, 11, 2], [0, 0, 8, 8], [0, 0, 2, 12]]
    )
    assert np.array_equal(16 * refinement_matrix(6).toarray()[7:12, 5], [2, 8, 12, 8, 2])


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("level", LEVELS)
def test_refinement_identity(level, closed):
    fine, coarse = spline_space(level, closed), spline_space(level - 1, closed)
    P = refinement_matrix(level, closed).toarray()
    u = np.concatenate([np.random.default_rng(level).random(50), np.arange(fine.n_segments + 1) / fine.n_segments])
    assert np.abs(fine.design_matrix(u).toarray() @ P - coarse.design_matrix(u).toarray()).max() < 1e-13
    assert np.allclose(P.sum(axis=1), 1.0, atol=1e-15)
    assert np.array_equal(16 * P, np.round(16 * P))
    if not closed:
        assert np.array_equal(P, P[::-1, ::-1])


def test_gram_published_pattern():
    for level in (3, 4, 7):
        scaled = gram_matrix(level).toarray() * 2**level * 10080
        assert np.allclose(scaled[:4, :7], [
            [1440, 882, 186, 12, 0, 0, 0],
            [882, 2232, 1575, 348, 3, 0, 0],
            [186, 1575, 3294, 2264, 239, 2, 0],
            [12, 348, 2264, 4832, 2382, 240, 2],
        ], atol=1e-9)
        if level > 3:
            assert np.allclose(scaled[5, 2:9], [2, 240, 2382, 4832, 2382, 240, 2], atol=1e-9)
        assert np.allclose(scaled, scaled[::-1, ::-1], atol=1e-9)
    bernstein = [[720, 360, 144, 36], [360, 432, 324, 144], [144, 324, 432, 360], [36, 144, 360, 720]]
    assert np.allclose(gram_matrix(0).toarray() * 5040, bernstein, atol=1e-10)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("level", LEVELS)
def test_gram_is_banded_spd_and_consistent_across_levels(level, closed):
    fine = gram_matrix(level, closed).toarray()
    P = refinement_matrix(level, closed).toarray()
    assert np.abs(P.T @ fine @ P - gram_matrix(level - 1, closed).toarray()).max() < 1e-15
    assert np.all(np.linalg.eigvalsh(fine) > 0)
    if not closed:
        rows, cols = np.nonzero(fine)
        assert np.abs(rows - cols).max() == min(3, fine.shape[0] - 1)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("level", LEVELS)
def test_wavelets_are_orthogonal_and_complete(level, closed):
    P, Q = refinement_matrix(level, closed).toarray(), wavelet_matrix(level, closed).toarray()
    assert np.abs(P.T @ gram_matrix(level, closed).toarray() @ Q).max() < 1e-14
    square = np.hstack([P, Q])
    assert square.shape[0] == square.shape[1]
    assert np.linalg.matrix_rank(square) == square.shape[0]
    assert np.linalg.cond(square) < 10
    assert np.allclose(np.abs(Q).max(axis=0), 1.0) and np.allclose(Q[np.argmax(np.abs(Q), axis=0), range(Q.shape[1])], 1.0)


def support(column: np.ndarray) -> tuple[int, int]:
    rows = np.flatnonzero(column)
    return int(rows[0]), int(rows[-1])


def test_wavelet_supports_are_minimal():
    assert [support(c) for c in wavelet_matrix(1).toarray().T] == [(0, 4)]
    assert [support(c) for c in wavelet_matrix(2).toarray().T] == [(0, 5), (1, 6)]
    assert [support(c) for c in wavelet_matrix(3).toarray().T] == [(0, 7), (1, 8), (2, 9), (3, 10)]
    for level in (4, 5, 8):
        Q = wavelet_matrix(level).toarray()
        n = Q.shape[0]
        expected = [(0, 7), (1, 9), (2, 11)] + [(2 * k - 3, 2 * k + 7) for k in range(3, Q.shape[1] - 3)]
        expected += [(n - 1 - b, n - 1 - a) for a, b in reversed(expected[:3])]
        assert [support(c) for c in Q.T] == expected
        assert np.array_equal(Q, Q[::-1, ::-1])


def test_wavelet_published_values():
    assert np.allclose(wavelet_matrix(1).toarray().ravel(), np.array([1, -2, 3, -2, 1]) / 3, atol=1e-14)
    assert np.allclose(wavelet_matrix(2).toarray()[:6, 0], np.array([-1368, 2064, -1793, 1053, -691, 240]) / 2064, atol=1e-13)
    q3 = wavelet_matrix(3).toarray()
    assert np.allclose(q3[:8, 0], [-0.686823310396, 1, -0.798166762841, 0.382459693068, -0.138341619328,
                                   0.0282842468468, -0.00208826167603, 1.68408199681e-05], atol=1e-11)
    assert np.allclose(q3[1:9, 1], [-0.254803476984, 0.697529839166, -0.921763179652, 1, -0.720754630766,
                                    0.314093457311, -0.0781581756733, 0.0144491838616], atol=1e-11)
    assert q3[0, 0] == pytest.approx(-394762 / 574765, abs=1e-12)
    for level in (4, 6):
        q = wavelet_matrix(level).toarray()
        assert np.allclose(q[:8, 0], q3[:8, 0], atol=1e-12)
        assert np.allclose(q[1:10, 1], [-0.256325676077, 0.701421597346, -0.925780775345, 1, -0.711467208509,
                                        0.297590960564, -0.062855678205, 0.00464681584536, -3.74743213335e-05], atol=1e-11)
        assert np.allclose(q[2:12, 2], [0.0158817839625, -0.0858950762746, 0.343711666365, -0.771596865306, 1,
                                        -0.758321787936, 0.323843171404, -0.0686905128049, 0.00507902647235,
                                        -4.0959890906e-05], atol=1e-11)
        interior = np.array([-1, 124, -1677, 7904, -18482, 24264, -18482, 7904, -1677, 124, -1]) / 24264
        assert np.allclose(q[3:14, 3], interior, atol=1e-15)


def test_filters_are_cached_per_level():
    assert level_filters(7) is level_filters(7)
    assert level_filters(7, True) is not level_filters(7)


@pytest.mark.parametrize("bad", [0, -1, 2.5, True])
def test_filter_levels_are_checked(bad):
    with pytest.raises(ValueError, match="level"):
        refinement_matrix(bad)
