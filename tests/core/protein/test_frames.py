"""Residue frames: orthonormal, continuous, and rigid-body remapping that keeps residues intact."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.curves.splines import spline_space
from core.protein.frames import remap_atoms, residue_frames
from core.protein.reading import read_structure
from core.protein.ribbon import build_ribbon

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module", params=["1UBQ.pdb.gz", "1TIM.pdb.gz"])
def ribbon_and_segment(request):
    segment = read_structure(DATA / request.param).segments[0]
    return build_ribbon("peptide", segment.ca, n_start=segment.n[0], c_end=segment.c[-1]), segment


def test_frames_are_rotations(ribbon_and_segment):
    ribbon, _ = ribbon_and_segment
    frames = residue_frames(ribbon.space, ribbon.points, ribbon.residue_u)
    assert np.allclose(np.einsum("rji,rjk->rik", frames, frames), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(frames), 1.0, atol=1e-12)
    tangent = ribbon.space.evaluate(ribbon.points, ribbon.residue_u, 1)
    assert np.allclose(frames[:, :, 0], tangent / np.linalg.norm(tangent, axis=1, keepdims=True))


def test_frames_never_flip_along_the_chain(ribbon_and_segment):
    ribbon, segment = ribbon_and_segment
    frames = residue_frames(ribbon.space, ribbon.points, ribbon.residue_u)
    binormals = frames[:, :, 2]
    assert np.all(np.einsum("ij,ij->i", binormals[1:], binormals[:-1]) >= 0)
    # in helices the frame turns steadily about the helix axis, by about 100 degrees
    # (3.6 residues per turn) per residue
    helix = (segment.ss[1:] == "H") & (segment.ss[:-1] == "H")
    turn = np.degrees(Rotation.from_matrix(np.einsum("rij,rkj->rik", frames[1:], frames[:-1])).magnitude())
    assert 80 < np.median(turn[helix]) < 120 and np.percentile(turn[helix], 90) < 130


def test_straight_curves_get_well_defined_frames():
    space = spline_space(3)
    points = np.outer(np.linspace(0, 10, space.n_points), [1.0, 2.0, 2.0])
    frames = residue_frames(space, points, np.linspace(0.05, 0.95, 9))
    assert np.all(np.isfinite(frames))
    assert np.allclose(np.einsum("rji,rjk->rik", frames, frames), np.eye(3), atol=1e-12)
    assert np.allclose(frames[:, :, 1], frames[0, :, 1])  # one consistent normal


def test_frames_follow_their_reference_through_an_inflection():
    space = spline_space(4)
    x = np.linspace(-1, 1, space.n_points)
    points = np.column_stack([x, x**3, np.zeros_like(x)])  # inflection at the middle
    u = np.linspace(0.05, 0.95, 21)
    before = residue_frames(space, points, u)
    bent = points + np.array([0.0, 0.0, 1e-3]) * (x**2)[:, None]
    after = residue_frames(space, bent, u, reference=before)
    assert np.all(np.einsum("ij,ij->i", after[:, :, 2], before[:, :, 2]) > 0.9)


def test_remapping_keeps_every_residue_rigid(ribbon_and_segment):
    ribbon, segment = ribbon_and_segment
    rng = np.random.default_rng(0)
    new_points = ribbon.points + rng.normal(scale=1.5, size=ribbon.points.shape)
    before = residue_frames(ribbon.space, ribbon.points, ribbon.residue_u)
    after = residue_frames(ribbon.space, new_points, ribbon.residue_u, reference=before)
    structure_coords = read_structure(DATA / "1UBQ.pdb.gz").coords if len(segment) == 76 else None
    for i in range(0, len(segment), 7):
        if structure_coords is None:
            atoms = segment.ca[[i]] + rng.normal(scale=2.0, size=(12, 3))
        else:
            atoms = structure_coords[segment.atoms(i)]
        moved = remap_atoms(
            atoms,
            np.zeros(len(atoms), dtype=int),
            ribbon.space.evaluate(ribbon.points, ribbon.residue_u[[i]]),
            before[[i]],
            ribbon.space.evaluate(new_points, ribbon.residue_u[[i]]),
            after[[i]],
        )
        inside = lambda a: np.linalg.norm(a[:, None] - a[None], axis=-1)  # noqa: E731
        assert np.abs(inside(moved) - inside(atoms)).max() < 1e-9


def test_a_rigid_motion_of_the_curve_moves_atoms_by_the_same_motion(ribbon_and_segment):
    ribbon, segment = ribbon_and_segment
    rotation = Rotation.from_rotvec([0.3, -0.7, 1.1]).as_matrix()
    shift = np.array([4.0, -2.0, 7.5])
    moved_points = ribbon.points @ rotation.T + shift
    u = ribbon.residue_u
    before = residue_frames(ribbon.space, ribbon.points, u)
    after = residue_frames(ribbon.space, moved_points, u, reference=before)
    atoms = segment.ca + np.array([0.5, 0.2, -0.3])
    moved = remap_atoms(
        atoms, np.arange(len(atoms)), ribbon.space.evaluate(ribbon.points, u), before,
        ribbon.space.evaluate(moved_points, u), after,
    )
    assert np.abs(moved - (atoms @ rotation.T + shift)).max() < 1e-9
