"""Database analysis on real entries: chain selection, gaps, termini, classes, pooled statistics."""

from pathlib import Path

import numpy as np
import pytest

from core.analysis.database import (
    CLASSES,
    REFERENCE_OPTIONS,
    UNCLASSIFIED,
    AnalysisOptions,
    FileAnalysis,
    PooledStatistics,
    SkippedFile,
    analyse_path,
    analyse_structure,
    rms_crossing,
    summarize,
)
from core.protein.reading import read_structure
from core.protein.ribbon import build_ribbon, segment_ribbon
from core.protein.structure import SS_COMPUTED

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def structures():
    names = ["1UBQ.pdb.gz", "1TIM.pdb.gz", "4HHB.pdb.gz", "1F9V.pdb.gz", "2K39_CA-only.pdb.gz", "2O9S_A.pdb.gz"]
    return {name.split(".")[0]: read_structure(DATA / name) for name in names}


def column(options: AnalysisOptions, ribbon: str, mode: str, depth: float) -> int:
    return next(k for k, c in enumerate(options.columns) if (c.ribbon, c.mode, c.depth) == (ribbon, mode, depth))


def test_options_list_the_depth_columns():
    options = AnalysisOptions(max_depth=3, fraction_step=0.5)
    assert options.integer_depths.tolist() == [0, 1, 2, 3]
    assert options.fractional_depths.tolist() == [0, 0.5, 1, 1.5, 2, 2.5, 3]
    names = [c.name for c in options.columns]
    assert len(names) == 2 * (4 + 7) and names[0] == "peptide_integer_0" and "calpha_fractional_2.5" in names
    with pytest.raises(ValueError, match="fraction_step"):
        AnalysisOptions(fraction_step=0)
    with pytest.raises(ValueError, match="max_depth"):
        AnalysisOptions(max_depth=-1)
    with pytest.raises(ValueError):
        AnalysisOptions(chains="some")


def test_every_residue_of_every_segment_is_analysed(structures):
    structure = structures["4HHB"]  # four chains
    options = AnalysisOptions(max_depth=4)
    result = analyse_structure(structure, options)
    assert len(result) == structure.n_residues and result.n_curves == len(structure.segments)
    assert result.deviations.shape == (structure.n_residues, len(options.columns))
    assert list(dict.fromkeys(result.chain.tolist())) == ["A", "B", "C", "D"]
    assert np.array_equal(result.resseq, np.concatenate([s.resseq for s in structure.segments]))
    # the product's ribbon: segment_ribbon with N and C atoms as terminal points
    segment = structure.segments[2]  # chain B is broken after LEU78: its second curve
    rows = np.flatnonzero((result.chain == "B") & (result.curve == 1))
    ribbon = segment_ribbon(segment, "peptide")
    expected = np.linalg.norm(ribbon.residue_points(ribbon.max_level - 2.5) - segment.ca, axis=1)
    assert np.allclose(result.deviations[rows, column(options, "peptide", "fractional", 2.5)], expected)


def test_longest_chain_counts_the_residues_of_all_its_pieces(structures):
    result = analyse_structure(structures["4HHB"], AnalysisOptions(chains="longest"))
    assert set(result.chain.tolist()) == {"D"} and len(result) == 146  # in three pieces; A has 141, B 145
    assert result.n_curves == 3


def test_gaps_split_a_chain_into_curves_or_join_it(structures):
    structure = structures["1F9V"]  # one chain with missing residues
    split = analyse_structure(structure, AnalysisOptions(max_depth=3))
    joined = analyse_structure(structure, AnalysisOptions(gaps="join", max_depth=3))
    assert split.n_curves == len(structure.segments) > 1 and joined.n_curves == 1
    assert np.array_equal(split.curve, np.concatenate([np.full(len(s), k) for k, s in enumerate(structure.segments)]))
    assert len(split) == len(joined) and np.all(joined.curve == 0)
    ca = np.concatenate([s.ca for s in structure.segments])
    ribbon = build_ribbon("peptide", ca, n_start=structure.segments[0].n[0], c_end=structure.segments[-1].c[-1])
    k = column(AnalysisOptions(max_depth=3), "peptide", "integer", 0)
    assert np.allclose(joined.deviations[:, k], np.linalg.norm(ribbon.residue_points() - ca, axis=1))
    assert not np.allclose(split.deviations[:, k], joined.deviations[:, k])


def test_terminal_points_from_atoms_or_from_the_calpha(structures):
    atoms = analyse_structure(structures["1UBQ"], AnalysisOptions(max_depth=2))
    calpha = analyse_structure(structures["1UBQ"], AnalysisOptions(termini="calpha", max_depth=2))
    first = atoms.deviations[0] - calpha.deviations[0]
    assert np.abs(first).max() > 0.01  # the first residue's curve point depends on the terminal point
    # a Cα-only model has no N and C atoms: both constructions are the same
    ca_only = [analyse_structure(structures["2K39_CA-only"], AnalysisOptions(termini=t, max_depth=2)) for t in ("atoms", "calpha")]
    assert np.array_equal(ca_only[0].deviations, ca_only[1].deviations)


def test_secondary_structure_policy(structures):
    structure = structures["2O9S_A"]  # no HELIX/SHEET records: DSSP computes them
    assert structure.ss_source == SS_COMPUTED
    auto = analyse_structure(structure, AnalysisOptions(max_depth=2))
    records = analyse_structure(structure, AnalysisOptions(ss="records", max_depth=2))
    assert set(auto.ss_class.tolist()) <= {"helix", "sheet", "other"} and "sheet" in auto.ss_class
    assert set(records.ss_class.tolist()) == {UNCLASSIFIED}
    assert np.array_equal(auto.ss, records.ss) and np.array_equal(auto.deviations, records.deviations)
    rows = summarize([records], AnalysisOptions(max_depth=2))
    assert {r.ss_class for r in rows} == {"all"}
    with_records = analyse_structure(structures["1UBQ"], AnalysisOptions(ss="records"))
    assert np.array_equal(with_records.ss_class, auto_classes(structures["1UBQ"]))


def auto_classes(structure):
    return np.array([{"H": "helix", "E": "sheet", "C": "other"}[c] for c in structure.segments[0].ss])


def test_summary_pools_residues_per_column_and_class(structures):
    options = AnalysisOptions(max_depth=4)
    analyses = [analyse_structure(structures[name], options) for name in ("1UBQ", "1TIM", "4HHB")]
    rows = summarize(analyses, options)
    deviations = np.vstack([a.deviations for a in analyses])
    classes = np.concatenate([a.ss_class for a in analyses])
    assert {(r.ribbon, r.mode) for r in rows} == {(k, m) for k in ("peptide", "calpha") for m in ("integer", "fractional")}
    for row in rows:
        k = column(options, row.ribbon, row.mode, row.depth)
        values = deviations[:, k] if row.ss_class == "all" else deviations[classes == row.ss_class, k]
        values = values[np.isfinite(values)]
        assert row.n_residues == len(values)
        assert row.rms == pytest.approx(np.sqrt(np.mean(values**2)))
        assert row.sd == pytest.approx(np.std(values))
    by_class = {(r.ribbon, r.mode, r.depth): {} for r in rows}
    for r in rows:
        by_class[(r.ribbon, r.mode, r.depth)][r.ss_class] = r.n_residues
    for counts in by_class.values():  # every residue has one class when the files have records
        assert set(counts) == set(CLASSES) and counts["all"] == counts["helix"] + counts["sheet"] + counts["other"]


def test_rms_crossing_interpolates_between_depths(structures):
    options = AnalysisOptions(max_depth=5)
    rows = summarize([analyse_structure(structures["1TIM"], options)], options)
    series = {r.depth: r.rms for r in rows if (r.ribbon, r.mode, r.ss_class) == ("peptide", "fractional", "all")}
    depth = rms_crossing(rows, 3.8)
    below = max(d for d, rms in series.items() if rms < 3.8)
    above = min(d for d, rms in series.items() if rms >= 3.8)
    assert below < depth <= above == below + 0.5
    t = (depth - below) / 0.5
    assert (1 - t) * series[below] + t * series[above] == pytest.approx(3.8)
    assert rms_crossing(rows, 1000.0) is None


def test_reference_options_follow_the_math_document(structures):
    # Longest chain, one curve across gaps, Cα-only terminal points (math doc 12.2).
    structure = structures["1F9V"]
    result = analyse_structure(structure, REFERENCE_OPTIONS)
    ca = np.concatenate([s.ca for s in structure.segments])
    ribbon = build_ribbon("peptide", ca)  # no n_start / c_end: half-bond extrapolation
    k = column(REFERENCE_OPTIONS, "peptide", "fractional", 2.5)
    expected = np.linalg.norm(ribbon.residue_points(ribbon.max_level - 2.5) - ca, axis=1)
    assert np.allclose(result.deviations[:, k], expected)


def test_files_that_cannot_be_used_are_skipped_with_a_reason(tmp_path):
    garbage = tmp_path / "garbage.pdb"
    garbage.write_text("this is not a structure\n")
    results = {
        name: analyse_path(path)
        for name, path in [("dna", DATA / "1BNA.pdb.gz"), ("missing", tmp_path / "nothing.cif"), ("garbage", garbage)]
    }
    assert all(isinstance(r, SkippedFile) for r in results.values())
    assert "no protein chain" in results["dna"].reason
    assert "no such file" in results["missing"].reason
    assert results["garbage"].reason and str(tmp_path) not in results["garbage"].reason
    assert isinstance(analyse_path(DATA / "1UBQ.pdb.gz"), FileAnalysis)


def test_pooled_statistics_add_file_by_file(structures):
    options = AnalysisOptions(max_depth=3)
    pooled = PooledStatistics(options)
    for name in ("1UBQ", "4HHB"):
        pooled.add(analyse_structure(structures[name], options))
    assert (pooled.n_files, pooled.n_residues) == (2, 76 + structures["4HHB"].n_residues)
    assert pooled.n_curves == 1 + len(structures["4HHB"].segments)
    assert (pooled.n_files_without_records, pooled.n_residues_without_records) == (0, 0)
    pooled.add(analyse_structure(structures["2O9S_A"], options))
    assert (pooled.n_files_without_records, pooled.n_residues_without_records) == (1, 67)
    with pytest.raises(ValueError, match="other depths"):
        pooled.add(analyse_structure(structures["1UBQ"], AnalysisOptions(max_depth=2)))
