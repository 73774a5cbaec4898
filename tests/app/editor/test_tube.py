"""The numpy tube sweep: rotation-minimising normals, local re-orientation, ring geometry."""

import numpy as np
import pytest

from app.editor.scene import tube


def _helix(n: int, turns: float = 3.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 2 * np.pi * turns, n)
    points = np.column_stack([2.3 * np.cos(t), 2.3 * np.sin(t), 1.5 * t / (2 * np.pi)])
    tangents = np.gradient(points, axis=0)
    return points, tangents / np.linalg.norm(tangents, axis=1, keepdims=True)


def _sequential_transport(tangents: np.ndarray, first: np.ndarray) -> np.ndarray:
    """Reference: carry a normal ring by ring with the double-reflection-free Rodrigues step."""
    normals = [first]
    for a, b in zip(tangents[:-1], tangents[1:]):
        normals.append(tube.minimal_rotation(normals[-1][None], a[None], b[None])[0])
    return np.array(normals)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_minimal_rotation_takes_source_onto_target(seed: int) -> None:
    rng = np.random.default_rng(seed)
    source = rng.normal(size=(50, 3))
    target = rng.normal(size=(50, 3))
    source /= np.linalg.norm(source, axis=1, keepdims=True)
    target /= np.linalg.norm(target, axis=1, keepdims=True)
    np.testing.assert_allclose(tube.minimal_rotation(source, source, target), target, atol=1e-12)
    vectors = rng.normal(size=(50, 3))
    turned = tube.minimal_rotation(vectors, source, target)
    np.testing.assert_allclose(np.linalg.norm(turned, axis=1), np.linalg.norm(vectors, axis=1), rtol=1e-12)
    np.testing.assert_array_equal(tube.minimal_rotation(vectors, source, source), vectors)  # exact identity


def test_transported_normals_match_sequential_parallel_transport() -> None:
    _, tangents = _helix(400)
    normals = tube.transported_normals(tangents)
    np.testing.assert_allclose(np.einsum("ij,ij->i", normals, tangents), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(normals, _sequential_transport(tangents, normals[0]), atol=1e-9)


def test_transported_normals_do_not_jump_where_the_reference_axis_switches() -> None:
    angle = np.linspace(0.0, np.pi, 200)  # the tangent sweeps through all three axes' dominance
    tangents = np.column_stack([np.cos(angle), np.sin(angle) * np.cos(angle), np.sin(angle) ** 2])
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    normals = tube.transported_normals(tangents)
    step = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normals[1:], normals[:-1]), -1, 1)))
    turn = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", tangents[1:], tangents[:-1]), -1, 1)))
    assert np.all(step <= turn + 1e-6)  # a normal never turns more than its tangent: no twist


def test_ring_vertices_lie_on_circles_around_the_curve() -> None:
    centres, tangents = _helix(30)
    normals = tube.transported_normals(tangents)
    radii = np.linspace(0.5, 1.5, 30)
    points, radial = tube.ring_vertices(centres, tangents, normals, radii, 12)
    assert points.shape == radial.shape == (30 * 12, 3)
    offset = (points - np.repeat(centres, 12, axis=0)).reshape(30, 12, 3)
    np.testing.assert_allclose(np.linalg.norm(offset, axis=2), np.repeat(radii[:, None], 12, axis=1), atol=1e-12)
    np.testing.assert_allclose(np.einsum("rsk,rk->rs", offset, tangents), 0.0, atol=1e-12)
    np.testing.assert_allclose(radial.reshape(30, 12, 3) * radii[:, None, None], offset, atol=1e-12)


def test_faces_join_consecutive_rings_and_caps_close_the_ends() -> None:
    quads = tube.tube_faces(5, 8, first=100)
    assert quads.shape == (4 * 8, 4)
    assert quads.min() == 100 and quads.max() == 100 + 5 * 8 - 1
    ring = (quads - 100) // 8
    assert np.all(ring.max(axis=1) - ring.min(axis=1) == 1)
    cap = tube.cap_faces(8, first=40)
    assert cap.shape == (8, 3)
    assert set(cap[:, 2]) == {48} and set(cap[:, :2].ravel()) == set(range(40, 48))
    rim = np.arange(24.0).reshape(8, 3)
    points, normals = tube.cap_vertices(np.zeros(3), rim, np.array([0.0, 0.0, 1.0]))
    assert points.shape == (9, 3) and np.all(normals == [0.0, 0.0, 1.0])


def test_cross_is_numpys() -> None:
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(2, 40, 3))
    np.testing.assert_allclose(tube.cross(a, b), np.cross(a, b), rtol=1e-14, atol=1e-14)
