"""Tensor-product spline nets (open × closed): perfect reconstruction, L2-best coarse nets,
no seam in the closed direction, least-squares fits with collapsed poles."""

from __future__ import annotations

import numpy as np
import pytest

from core.curves.filters import gram_matrix, refinement_matrix
from core.surfaces.tensor_spline import (
    analysis_step2,
    decompose2,
    evaluate_grid,
    fit_surface,
    grid_mesh,
    reconstruct2,
    refine2,
    smooth2,
    synthesis_step2,
)

CLOSED = [(False, True), (True, True), (False, False), (True, False)]


def random_net(level: int, closed: tuple[bool, bool], seed: int, d: int = 3) -> np.ndarray:
    sizes = [2**level + (0 if c else 3) for c in closed]
    return np.random.default_rng(seed).normal(size=(*sizes, d))


@pytest.mark.parametrize("closed", CLOSED)
@pytest.mark.parametrize("level", [1, 2, 3, 5, 6])
@pytest.mark.parametrize("seed", [0, 1])
def test_perfect_reconstruction(closed: tuple[bool, bool], level: int, seed: int) -> None:
    net = random_net(level, closed, seed)
    transform = decompose2(net, 0, closed)
    assert np.allclose(reconstruct2(transform), net, atol=1e-11, rtol=0)
    sizes = transform.coarse.shape[0] * transform.coarse.shape[1] + sum(
        d.shape[0] * d.shape[1] for triple in transform.details for d in triple
    )
    assert sizes == net.shape[0] * net.shape[1]  # the transform has as many coefficients as the net


@pytest.mark.parametrize("closed", CLOSED)
def test_one_step_is_the_l2_projection(closed: tuple[bool, bool]) -> None:
    """The residual of a step is orthogonal to the coarse product space:
    (P_u^T I_u) (C - P_u C' P_v^T) (I_v P_v) = 0."""
    net = random_net(4, closed, 3, d=2)
    coarse, _ = analysis_step2(net, closed)
    pu, pv = (refinement_matrix(4, c).toarray() for c in closed)
    iu, iv = (gram_matrix(4, c).toarray() for c in closed)
    residual = net - np.einsum("ia,abd,kb->ikd", pu, coarse, pv)
    assert np.abs(np.einsum("ai,ikd,kb->abd", pu.T @ iu, residual, iv @ pv)).max() < 1e-12
    # and a step of details alone reconstructs to the orthogonal complement
    zero = tuple(np.zeros_like(d) for d in analysis_step2(net, closed)[1])
    assert np.allclose(synthesis_step2(coarse, zero, closed), net - residual)


def test_coarse_net_approximates_better_than_any_perturbation() -> None:
    closed = (False, True)
    net = random_net(5, closed, 4)
    u, v = np.linspace(0, 1, 257), np.arange(256) / 256
    fine = evaluate_grid(net, u, v, closed)
    coarse = smooth2(net, 3, closed)
    best = np.mean((evaluate_grid(coarse, u, v, closed) - fine) ** 2)
    for seed in range(5):
        moved = coarse + 0.05 * np.random.default_rng(seed).normal(size=coarse.shape)
        assert np.mean((evaluate_grid(moved, u, v, closed) - fine) ** 2) > best


def test_error_decreases_with_level() -> None:
    closed = (False, True)
    net = random_net(6, closed, 5)
    u, v = np.linspace(0, 1, 200), np.arange(200) / 200
    fine = evaluate_grid(net, u, v, closed)
    errors = [np.sqrt(np.mean((evaluate_grid(smooth2(net, j, closed), u, v, closed) - fine) ** 2)) for j in range(7)]
    assert all(a > b for a, b in zip(errors, errors[1:]))
    assert errors[-1] < 1e-12


def test_refinement_keeps_the_surface() -> None:
    closed = (False, True)
    net = random_net(3, closed, 6)
    u, v = np.linspace(0, 1, 50), np.linspace(0, 1, 50)
    assert np.allclose(evaluate_grid(refine2(net, closed), u, v, closed), evaluate_grid(net, u, v, closed), atol=1e-12)


def test_closed_direction_has_no_seam() -> None:
    closed = (False, True)
    net = random_net(4, closed, 7)
    u = np.linspace(0, 1, 9)
    eps = 1e-7
    before, after = evaluate_grid(net, u, [1 - eps], closed), evaluate_grid(net, u, [eps], closed)
    assert np.abs(before - after).max() < 1e-5
    assert np.allclose(evaluate_grid(net, u, [0.0], closed), evaluate_grid(net, u, [1.0], closed), atol=1e-13)
    # the tangent across the seam is continuous too (C2 closed B-spline)
    slope_before = (evaluate_grid(net, u, [1 - eps], closed) - evaluate_grid(net, u, [1 - 2 * eps], closed)) / eps
    slope_after = (evaluate_grid(net, u, [eps], closed) - evaluate_grid(net, u, [0.0], closed)) / eps
    assert np.abs(slope_before - slope_after).max() < 1e-3 * np.abs(slope_after).max()


def test_grid_mesh_of_a_closed_globe_is_watertight() -> None:
    u, v = np.linspace(0, np.pi, 17), np.arange(24) / 24 * 2 * np.pi
    theta, phi = np.meshgrid(u, v, indexing="ij")
    points = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
    mesh = grid_mesh(points, closed_v=True, poles=True)
    assert mesh.is_closed()
    assert len(mesh.vertices) == 15 * 24 + 2
    assert mesh.volume() > 0  # outward normals
    assert abs(mesh.volume() - 4 / 3 * np.pi) < 0.1
    open_mesh = grid_mesh(points[1:-1], closed_v=True)
    assert not open_mesh.is_closed() and len(open_mesh.boundary_edges()) == 2 * 24


def test_fit_reproduces_a_surface_of_the_same_level_and_pins_poles() -> None:
    closed = (False, True)
    net = random_net(3, closed, 8)
    net[0], net[-1] = net[0, 0], net[-1, 0]  # collapsed pole rows
    u, v = np.linspace(0, 1, 32), np.arange(32) / 32
    samples = evaluate_grid(net, u, v, closed)
    fitted = fit_surface(samples, 3, closed, poles=True)
    assert np.allclose(fitted.net, net, atol=1e-10)
    assert fitted.rms_error(3) < 1e-10
    for level in (0, 1, 2, 2.5):
        coarse = fitted.net_at(level)
        assert np.ptp(coarse[0], axis=0).max() < 1e-12 and np.ptp(coarse[-1], axis=0).max() < 1e-12


def test_fractional_levels_blend_continuously() -> None:
    closed = (False, True)
    net = random_net(4, closed, 9)
    surface = fit_surface(evaluate_grid(net, np.linspace(0, 1, 40), np.arange(40) / 40, closed), 4, closed)
    for j in range(4):
        near_next = surface.points(j + 1 - 1e-7)
        assert np.abs(near_next - surface.points(j + 1)).max() < 1e-5
        assert np.allclose(surface.points(j + 0.5), (surface.points(j) + surface.points(j + 1)) / 2, atol=1e-10)


def test_bad_nets_are_rejected() -> None:
    with pytest.raises(ValueError, match="same level"):
        decompose2(np.zeros((11, 16, 3)), 0, (False, True))
    with pytest.raises(ValueError, match="rows"):
        decompose2(np.zeros((10, 16, 3)), 0, (False, True))
    with pytest.raises(ValueError, match="at least"):
        fit_surface(np.zeros((8, 8, 3)), 3)
