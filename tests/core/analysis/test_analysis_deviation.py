"""Cα–C^r deviations at decomposition depths, checked against the ribbon's own level API."""

from pathlib import Path

import numpy as np
import pytest

from core.analysis.deviation import depth_deviations, level_residue_points
from core.curves.splines import spline_space
from core.curves.wavelets import smooth
from core.protein.reading import read_structure
from core.protein.ribbon import build_ribbon, segment_ribbon

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def segments():
    return {
        "ubiquitin": read_structure(DATA / "1UBQ.pdb.gz").segments[0],  # 76 residues
        "tim": read_structure(DATA / "1TIM.pdb.gz").segments[0],  # 247 residues
        "trp-cage": read_structure(DATA / "1L2Y.pdb.gz").segments[0],  # 20 residues
    }


@pytest.mark.parametrize("name", ["ubiquitin", "tim", "trp-cage"])
@pytest.mark.parametrize("kind", ["peptide", "calpha"])
def test_every_level_matches_the_l2_best_curve(segments, name, kind):
    segment = segments[name]
    ribbon = segment_ribbon(segment, kind)
    levels = level_residue_points(ribbon)
    assert levels.shape == (ribbon.level + 1, len(segment), 3)
    assert np.allclose(levels[-1], ribbon.residue_points(), atol=1e-10)
    for j in range(ribbon.level):
        direct = spline_space(j).evaluate(smooth(ribbon.points, j), ribbon.residue_u)
        assert np.allclose(levels[j], direct, atol=1e-9)


@pytest.mark.parametrize("name", ["ubiquitin", "tim", "trp-cage"])
@pytest.mark.parametrize("kind", ["peptide", "calpha"])
def test_fractional_depths_match_the_slider_levels(segments, name, kind):
    segment = segments[name]
    ribbon = segment_ribbon(segment, kind)
    depths = np.arange(0, 5.01, 0.25)
    _, fractional = depth_deviations(ribbon, segment.ca, np.array([0]), depths)
    for column, depth in enumerate(depths):
        slider = ribbon.max_level - depth
        if slider < 0:
            assert np.isnan(fractional[:, column]).all()
            continue
        expected = np.linalg.norm(ribbon.residue_points(slider) - segment.ca, axis=1)
        assert np.allclose(fractional[:, column], expected, atol=1e-9), depth


def test_integer_depths_halve_the_segments_and_stop_at_level_zero(segments):
    segment = segments["trp-cage"]  # 20 residues: J = 5, log2 N = 4.32
    ribbon = segment_ribbon(segment, "peptide")
    whole, fractional = depth_deviations(ribbon, segment.ca, np.arange(8), np.array([4.0, 4.32, 4.5]))
    assert ribbon.level == 5
    assert np.isfinite(whole[:, :6]).all() and np.isnan(whole[:, 6:]).all()
    assert np.isfinite(fractional[:, :2]).all() and np.isnan(fractional[:, 2]).all()
    for depth in range(6):
        expected = spline_space(5 - depth).evaluate(smooth(ribbon.points, 5 - depth), ribbon.residue_u)
        assert np.allclose(whole[:, depth], np.linalg.norm(expected - segment.ca, axis=1), atol=1e-9)


def test_calpha_ribbon_passes_through_the_calpha_at_full_resolution(segments):
    segment = segments["tim"]
    ribbon = segment_ribbon(segment, "calpha")
    whole, fractional = depth_deviations(ribbon, segment.ca, np.array([0, 1]), np.array([0.0, 0.5]))
    assert np.abs(whole[:, 0]).max() < 1e-9 and np.abs(fractional[:, 0]).max() < 1e-9
    assert whole[:, 1].mean() > 0.5 and fractional[:, 1].mean() > 0.3  # coarser curves leave the atoms


def test_deviation_grows_with_depth_and_matches_the_papers_scale(segments):
    segment = segments["tim"]
    whole, fractional = depth_deviations(
        segment_ribbon(segment, "peptide"), segment.ca, np.arange(5), np.arange(0, 4.01, 0.5)
    )
    rms = np.sqrt(np.mean(whole**2, axis=0))
    assert np.all(np.diff(rms) > 0)
    assert 0.9 < rms[0] < 1.5 and 1.5 < rms[2] < 2.7 and 2.5 < rms[3] < 4.0  # paper: 2.1 and 3.3 Å
    assert np.all(np.diff(np.sqrt(np.mean(fractional**2, axis=0))) > 0)


def test_last_partial_interval_is_stretched_onto_the_last_level(segments):
    segment = segments["ubiquitin"]  # log2 76 = 6.25 and J = 7: slider levels (6, 6.25] map onto (6, 7]
    ribbon = build_ribbon("peptide", segment.ca)
    depth = 0.1
    t = (ribbon.max_level - depth - 6) / (ribbon.max_level - 6)
    levels = level_residue_points(ribbon)
    expected = (1 - t) * levels[6] + t * levels[7]  # f^(6+t) = (1 - t) f^6 + t f^7 (math doc 7)
    _, fractional = depth_deviations(ribbon, segment.ca, np.array([0]), np.array([depth]))
    assert 0.5 < t < 0.7
    assert np.allclose(fractional[:, 0], np.linalg.norm(expected - segment.ca, axis=1), atol=1e-12)


def test_bad_arguments_are_named(segments):
    segment = segments["ubiquitin"]
    ribbon = segment_ribbon(segment, "peptide")
    with pytest.raises(ValueError, match="ca must have shape"):
        depth_deviations(ribbon, segment.ca[:-1], np.array([0]), np.array([0.0]))
    with pytest.raises(ValueError, match="depths must be >= 0"):
        depth_deviations(ribbon, segment.ca, np.array([-1]), np.array([0.0]))
