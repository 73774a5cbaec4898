"""Carson's ribbons on real structures: layouts, padding, residue points, levels."""

import math
from pathlib import Path

import numpy as np
import pytest

from core.curves.splines import spline_space
from core.protein.reading import read_structure
from core.protein.ribbon import RibbonKind, build_ribbon

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def ubiquitin():
    return read_structure(DATA / "1UBQ.pdb.gz").segments[0]


@pytest.fixture(scope="module")
def tim():
    return read_structure(DATA / "1TIM.pdb.gz").segments[0]


def ribbon_of(segment, kind, **options):
    return build_ribbon(kind, segment.ca, n_start=segment.n[0], c_end=segment.c[-1], **options)


def test_peptide_layout_and_padding(ubiquitin):
    ribbon = ribbon_of(ubiquitin, "peptide")
    n = len(ubiquitin)  # 76 residues: 79 control points, padded to 2**7 + 3 = 131
    assert ribbon.level == 7 and ribbon.points.shape == (131, 3)
    assert ribbon.n_curve_segments == n and ribbon.max_level == pytest.approx(math.log2(76))
    padding = 128 - n
    assert ribbon.front == padding // 2
    front = ribbon.front
    assert np.array_equal(ribbon.points[: front + 2], np.repeat(ubiquitin.n[:1], front + 2, axis=0))
    assert np.array_equal(ribbon.points[-(padding - front + 2) :], np.repeat(ubiquitin.c[-1:], padding - front + 2, axis=0))
    planes = ribbon.points[front + 2 : front + 2 + n - 1]
    assert np.allclose(planes, (ubiquitin.ca[:-1] + ubiquitin.ca[1:]) / 2)
    assert np.allclose(ribbon.residue_u, (front + np.arange(n) + 0.5) / 128)


def test_peptide_residue_points_are_segment_centres(ubiquitin):
    ribbon = ribbon_of(ubiquitin, "peptide")
    p = ribbon.points[ribbon.front + 2 : ribbon.front + 2 + len(ubiquitin) - 1]  # P_1 .. P_{N-1}
    cr = ribbon.residue_points()
    i = np.arange(2, len(ubiquitin) - 2)  # 0-based residues with four planes around them
    assert np.allclose(cr[i], (p[i - 2] + 23 * p[i - 1] + 23 * p[i] + p[i + 1]) / 48, atol=1e-12)
    distance = np.linalg.norm(cr - ubiquitin.ca, axis=1)
    assert 0.8 < np.sqrt(np.mean(distance**2)) < 1.6  # about 1.2 Å over a database (math doc 10.1)


@pytest.mark.parametrize("segment_name", ["ubiquitin", "tim"])
def test_calpha_ribbon_interpolates_every_calpha(segment_name, request):
    segment = request.getfixturevalue(segment_name)
    ribbon = ribbon_of(segment, "calpha")
    n = len(segment)
    assert ribbon.n_curve_segments == n + 1
    assert ribbon.level == math.ceil(math.log2(n + 1))
    assert np.allclose(ribbon.residue_u, (ribbon.front + np.arange(1, n + 1)) / 2**ribbon.level)
    assert np.abs(ribbon.residue_points() - segment.ca).max() < 1e-10


@pytest.mark.parametrize("kind", list(RibbonKind))
def test_more_padding_leaves_the_residue_curve_unchanged(ubiquitin, kind):
    tight = ribbon_of(ubiquitin, kind)
    loose = ribbon_of(ubiquitin, kind, level=tight.level + 1)
    assert len(loose.points) == 2 ** (tight.level + 1) + 3
    assert np.abs(tight.residue_points() - loose.residue_points()).max() < 1e-12


def test_calpha_only_chains_use_half_bond_terminal_points():
    segment = read_structure(DATA / "2K39_CA-only.pdb.gz").segments[0]
    assert np.isnan(segment.n).all()
    ribbon = build_ribbon("peptide", segment.ca, n_start=segment.n[0], c_end=segment.c[-1])
    assert np.allclose(ribbon.points[0], 1.5 * segment.ca[0] - 0.5 * segment.ca[1])
    assert np.allclose(ribbon.points[-1], 1.5 * segment.ca[-1] - 0.5 * segment.ca[-2])


def test_slider_levels_map_onto_fs_levels(ubiquitin):
    ribbon = ribbon_of(ubiquitin, "peptide")  # J = 7, log2 76 = 6.248
    assert ribbon.fs_level(0) == 0 and ribbon.fs_level(4.5) == 4.5 and ribbon.fs_level(6) == 6
    assert ribbon.fs_level(ribbon.max_level) == 7
    assert ribbon.fs_level(10) == 7  # above the maximum: full resolution
    middle = (6 + ribbon.max_level) / 2
    assert ribbon.fs_level(middle) == pytest.approx(6.5)


def test_low_levels_deviate_more(ubiquitin):
    ribbon = ribbon_of(ubiquitin, "peptide")
    rms = [np.sqrt(np.mean(np.sum((ribbon.residue_points(l) - ubiquitin.ca) ** 2, axis=1))) for l in (6.25, 6, 5, 4, 3)]
    assert rms == sorted(rms)
    points, level = ribbon.control_points(4)
    assert level == 4 and len(points) == 2**4 + 3
    points, level = ribbon.control_points(4.5)
    assert level == 5 and len(points) == 2**5 + 3
    assert np.allclose(spline_space(level).evaluate(points, ribbon.residue_u), ribbon.residue_points(4.5))


def test_helix_offset_shifts_only_helix_planes(ubiquitin):
    helix = ubiquitin.ss == "H"
    plain = ribbon_of(ubiquitin, "peptide", o=ubiquitin.o, helix=helix)
    shifted = ribbon_of(ubiquitin, "peptide", o=ubiquitin.o, helix=helix, helix_offset=1.5)
    moved = np.linalg.norm(shifted.points - plain.points, axis=1)
    planes = slice(plain.front + 2, plain.front + 2 + len(ubiquitin) - 1)
    in_helix = helix[:-1] & helix[1:]
    assert np.allclose(moved[planes][in_helix], 1.5) and np.all(moved[planes][~in_helix] == 0)
    # away from the helix axis: the shifted guide points are further from the helix centroid
    centre = ubiquitin.ca[helix].mean(axis=0)
    radius = lambda p: np.linalg.norm(p[planes][in_helix] - centre, axis=1).mean()  # noqa: E731
    assert radius(shifted.points) > radius(plain.points)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: build_ribbon("peptide", np.zeros((1, 3))), "ca must have shape"),
        (lambda: build_ribbon("peptide", np.full((5, 3), np.nan)), "ca contains"),
        (lambda: build_ribbon("helical", np.zeros((5, 3))), "helical"),
        (lambda: build_ribbon("peptide", np.random.default_rng(0).random((9, 3)), level=2), "level must lie in \\[4, 30\\]"),
    ],
)
def test_bad_ribbon_input(call, message):
    with pytest.raises(ValueError, match=message):
        call()
