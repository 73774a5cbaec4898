"""Sampling of ribbons for display: tube rings per residue and the curves of slider levels."""

from pathlib import Path

import numpy as np
import pytest

from app.editor.scene.curves import (
    LARGE_RESIDUES,
    LARGE_RINGS_PER_RESIDUE,
    LARGE_SIDES,
    RINGS_PER_RESIDUE,
    SIDES,
    SegmentPath,
    sampling,
)
from core.curves.splines import spline_space
from core.protein.reading import read_structure
from core.protein.ribbon import RibbonKind, segment_ribbon

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def ubiquitin():
    return read_structure(DATA / "1UBQ.pdb.gz").segments[0]


@pytest.mark.parametrize("kind", list(RibbonKind))
@pytest.mark.parametrize("k", [RINGS_PER_RESIDUE, LARGE_RINGS_PER_RESIDUE])
def test_rings_cover_each_residue_span(ubiquitin, kind: RibbonKind, k: int) -> None:
    ribbon = segment_ribbon(ubiquitin, kind)
    path = SegmentPath(ribbon, k)
    n = len(ubiquitin)
    assert path.n_rings == n * k + 1
    centre_rings = np.arange(n) * k + k // 2
    np.testing.assert_allclose(path.u[centre_rings], ribbon.residue_u, atol=1e-15)  # residue point mid-span
    assert np.array_equal(path.owner[centre_rings], np.arange(n))
    assert np.array_equal(path.rings(np.array([3])), np.arange(3 * k, 4 * k + 1))
    assert np.array_equal(path.rings(np.arange(n)), np.arange(path.n_rings))


def test_ring_centres_and_tangents_follow_the_finest_curve(ubiquitin) -> None:
    ribbon = segment_ribbon(ubiquitin, "peptide")
    path = SegmentPath(ribbon)
    centres, tangents = path.centres(ribbon.points, np.array([0, 10, path.n_rings - 1]))
    space = ribbon.space
    np.testing.assert_allclose(centres, space.evaluate(ribbon.points, path.u[[0, 10, -1]]), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(tangents, axis=1), 1.0, atol=1e-12)
    # the tube ends at the terminal backbone atoms' side of the first and last residue
    assert np.linalg.norm(centres[0] - ubiquitin.n[0]) < np.linalg.norm(centres[0] - ubiquitin.ca[1])


@pytest.mark.parametrize("level", [0.0, 2.0, 3.4, 4.0, 5.75, 6.25])
def test_level_curve_is_the_ribbon_at_that_level(ubiquitin, level: float) -> None:
    ribbon = segment_ribbon(ubiquitin, "peptide")
    path = SegmentPath(ribbon)
    curve = path.level_curve(ribbon, level)
    points, j = ribbon.control_points(level)
    assert curve.level == j and curve.n_segments == 2**j
    np.testing.assert_array_equal(curve.control_points, points)
    np.testing.assert_allclose(curve.samples, spline_space(j).evaluate(points, path.curve_u), atol=1e-12)
    np.testing.assert_allclose(curve.residue_points, ribbon.residue_points(level), atol=1e-12)


def test_visible_control_points_are_those_that_shape_residues(ubiquitin) -> None:
    ribbon = segment_ribbon(ubiquitin, "peptide")  # 76 residues padded to 128 segments
    path = SegmentPath(ribbon)
    full = path.level_curve(ribbon, ribbon.max_level)
    assert full.visible.sum() == len(ubiquitin) + 3  # one per peptide plane plus the terminal copies
    assert np.array_equal(np.flatnonzero(full.visible), np.arange(ribbon.front, ribbon.front + len(ubiquitin) + 3))
    assert path.level_curve(ribbon, 2.0).visible.all()  # coarse levels: every point reaches a residue


def test_tangents_at_a_curve_end_over_doubled_control_points() -> None:
    segment = read_structure(DATA / "1ORC.pdb.gz").segments[0]  # 64 residues: no padding, the tube starts at u = 0
    ribbon = segment_ribbon(segment, "peptide")
    path = SegmentPath(ribbon)
    assert ribbon.front == 0 and path.u[0] == 0.0 and path.u[-1] == 1.0
    centres, tangents = path.centres(ribbon.points, np.array([0, 1, path.n_rings - 2, path.n_rings - 1]))
    np.testing.assert_allclose(np.linalg.norm(tangents, axis=1), 1.0, atol=1e-12)
    assert tangents[0] @ tangents[1] > 0.95 and tangents[2] @ tangents[3] > 0.95  # continuous into the ends
    assert tangents[0] @ (centres[1] - centres[0]) > 0 and tangents[3] @ (centres[3] - centres[2]) > 0


def test_a_large_structure_is_swept_with_fewer_rings_of_fewer_vertices() -> None:
    """A capsid's 11,040 residues (2BUK's assembly) take 4 rings a residue of 8 vertices, ubiquitin's
    76 take 6 of 12."""
    assert sampling(76) == sampling(LARGE_RESIDUES) == (RINGS_PER_RESIDUE, SIDES) == (6, 12)
    assert sampling(LARGE_RESIDUES + 1) == sampling(11_040) == (LARGE_RINGS_PER_RESIDUE, LARGE_SIDES) == (4, 8)
