"""Residue rotations after an edit: rotations, exact for rigid motions, well conditioned,
and a remapping that keeps residues intact."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from core.curves.splines import spline_space
from core.protein.frames import remap_atoms, residue_rotations
from core.protein.reading import read_structure
from core.protein.ribbon import build_ribbon

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module", params=["1UBQ.pdb.gz", "1TIM.pdb.gz"])
def ribbon_and_segment(request):
    segment = read_structure(DATA / request.param).segments[0]
    return build_ribbon("peptide", segment.ca, n_start=segment.n[0], c_end=segment.c[-1]), segment


def _angles(rotations: np.ndarray) -> np.ndarray:
    return np.degrees(Rotation.from_matrix(rotations).magnitude())


def test_rotations_are_rotations_and_none_where_the_curve_stays(ribbon_and_segment):
    ribbon, _ = ribbon_and_segment
    new_points = ribbon.points + np.random.default_rng(1).normal(scale=1.5, size=ribbon.points.shape)
    rotations = ribbon.residue_rotations(new_points, np.arange(len(ribbon.residue_u)))
    assert np.allclose(np.einsum("rji,rjk->rik", rotations, rotations), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(rotations), 1.0, atol=1e-12)
    assert _angles(rotations).max() > 5.0  # they do turn
    unchanged = ribbon.residue_rotations(ribbon.points.copy(), np.arange(len(ribbon.residue_u)))
    assert np.allclose(unchanged, np.eye(3), atol=1e-12)
    assert ribbon.residue_rotations(new_points, np.zeros(0, dtype=int)).shape == (0, 3, 3)


@pytest.mark.parametrize("seed", range(4))
def test_a_last_bit_change_of_the_curve_hardly_turns_a_residue(ribbon_and_segment, seed):
    """Well conditioned: control points moved by up to 0.001 Å turn no residue by more than
    0.2 degrees, the chain's ends included (the Frenet frames turned residues whose curve
    hardly turns by up to 0.4 degrees, and by tens where it crossed their threshold), and a
    change 100 times larger turns them about 100 times as far: no threshold anywhere."""
    ribbon, _ = ribbon_and_segment
    rng = np.random.default_rng(seed)
    start = ribbon.points + (_moved_as_the_padding(ribbon, rng.normal(scale=0.3, size=ribbon.points.shape))
                             if seed else 0.0)  # the chain as read, then perturbed shapes
    jitter = _moved_as_the_padding(ribbon, rng.uniform(-1e-3, 1e-3, ribbon.points.shape))
    turned = ribbon.with_points(start).residue_rotations(start + jitter, np.arange(len(ribbon.residue_u)))
    assert _angles(turned).max() < 0.2
    bend = ribbon.with_points(start).residue_rotations(start + 100 * jitter, np.arange(len(ribbon.residue_u)))
    assert _angles(bend).max() < 150 * _angles(turned).max()


def test_a_residue_turns_with_the_curve_s_direction(ribbon_and_segment):
    """The rotation carries the curve's tangent at the residue nearly onto its new tangent
    (the stretch alone lagged where an edit bends the chain, and left more peptide bonds
    stretched than the Frenet frames did)."""
    ribbon, _ = ribbon_and_segment
    rng = np.random.default_rng(7)
    bent = ribbon.points + _moved_as_the_padding(ribbon, rng.normal(scale=1.0, size=ribbon.points.shape))
    rotations = ribbon.residue_rotations(bent, np.arange(len(ribbon.residue_u)))
    before, after = (ribbon.space.evaluate(p, ribbon.residue_u, 1) for p in (ribbon.points, bent))
    before, after = (t / np.linalg.norm(t, axis=1, keepdims=True) for t in (before, after))
    missed = np.degrees(np.arccos(np.clip(np.einsum("nij,nj,ni->n", rotations, before, after), -1.0, 1.0)))
    turned = np.degrees(np.arccos(np.clip(np.einsum("ni,ni->n", before, after), -1.0, 1.0)))
    assert np.median(turned) > 15.0 and np.median(missed) < 0.4 * np.median(turned)


def _moved_as_the_padding(ribbon, change: np.ndarray) -> np.ndarray:
    """``change`` with the padding's copies of each terminal point moved as that point."""
    first, last = ribbon.front + 1, ribbon.front + ribbon.n_curve_segments + 1
    change[:first] = change[first]
    change[last:] = change[last]
    return change


def test_straight_curves_get_well_defined_rotations():
    space = spline_space(3)
    points = np.outer(np.linspace(0, 10, space.n_points), [1.0, 2.0, 2.0])
    u = np.linspace(0.05, 0.95, 9)
    rotation = Rotation.from_rotvec([0.2, 0.4, -0.1]).as_matrix()
    rotations = residue_rotations(space, points, points @ rotation.T, u)
    assert np.all(np.isfinite(rotations))
    assert np.allclose(np.einsum("rji,rjk->rik", rotations, rotations), np.eye(3), atol=1e-12)
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    assert np.allclose(rotations @ axis, rotation @ axis, atol=1e-9)  # the line's direction follows it


def test_remapping_keeps_every_residue_rigid(ribbon_and_segment):
    ribbon, segment = ribbon_and_segment
    rng = np.random.default_rng(0)
    new_points = ribbon.points + rng.normal(scale=1.5, size=ribbon.points.shape)
    structure_coords = read_structure(DATA / "1UBQ.pdb.gz").coords if len(segment) == 76 else None
    for i in range(0, len(segment), 7):
        if structure_coords is None:
            atoms = segment.ca[[i]] + rng.normal(scale=2.0, size=(12, 3))
        else:
            atoms = structure_coords[segment.atoms(i)]
        u = ribbon.residue_u[[i]]
        moved = remap_atoms(
            atoms,
            np.zeros(len(atoms), dtype=int),
            ribbon.space.evaluate(ribbon.points, u),
            ribbon.space.evaluate(new_points, u),
            residue_rotations(ribbon.space, ribbon.points, new_points, u),
        )
        inside = lambda a: np.linalg.norm(a[:, None] - a[None], axis=-1)
        assert np.abs(inside(moved) - inside(atoms)).max() < 1e-9


def test_a_rigid_motion_of_the_curve_moves_atoms_by_the_same_motion(ribbon_and_segment):
    ribbon, segment = ribbon_and_segment
    rotation = Rotation.from_rotvec([0.3, -0.7, 1.1]).as_matrix()
    shift = np.array([4.0, -2.0, 7.5])
    moved_points = ribbon.points @ rotation.T + shift
    u = ribbon.residue_u
    atoms = segment.ca + np.array([0.5, 0.2, -0.3])
    moved = remap_atoms(
        atoms, np.arange(len(atoms)), ribbon.space.evaluate(ribbon.points, u),
        ribbon.space.evaluate(moved_points, u), residue_rotations(ribbon.space, ribbon.points, moved_points, u),
    )
    assert np.abs(moved - (atoms @ rotation.T + shift)).max() < 1e-9
