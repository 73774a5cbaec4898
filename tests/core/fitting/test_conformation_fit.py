"""Fitting adenylate kinase from one conformation onto the other, coarse to fine (#19)."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from core.analysis.superpose import superpose
from core.fitting import settle as settle_module
from core.fitting.coarse_to_fine import pushed_to_finest
from core.fitting.conformation import SAME_FOLD, fit_conformation, fold_similarity, pair_segments
from core.fitting.morph import morph_frames
from core.fitting.settle import BACKBONE, MIN_MARGIN
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.protein.structure import Structure, ca_rows

DATA = Path(__file__).resolve().parents[2] / "data"
CLOSED, OPEN = "1AKE_adk_closed.pdb.gz", "4AKE_adk_open.pdb.gz"


def _setup(model_file: str, target_file: str, read: Callable[[Path], Structure] = read_structure):
    structure, target = read(DATA / model_file), read_structure(DATA / target_file)
    model = EditableModel(structure)
    pairs, pairing = pair_segments(model, [0], [target.segments[0]])
    rows = ca_rows(structure)[structure.segments[0].residue_index[pairs[0].residues]]
    return structure, model, pairs, pairing, rows


@pytest.mark.parametrize(("start", "end"), [(CLOSED, OPEN), (OPEN, CLOSED)])
def test_adenylate_kinase_reaches_the_other_conformation(start: str, end: str, fit_start: Callable) -> None:
    structure, model, pairs, pairing, rows = _setup(start, end, fit_start)
    assert pairing == "numbering" and len(pairs[0].residues) == 214
    initial = superpose(structure.coords[rows], pairs[0].target).rmsd
    assert initial > 6.5  # the LID and NMP domains close over the site
    result = fit_conformation(model, pairs, range(7))
    rmsd = [fit.score for fit in result.levels]
    assert [fit.level for fit in result.levels] == list(range(7)) and not result.dropped
    assert [fit.control_points for fit in result.levels] == [2**j + 3 for j in range(7)]
    assert all(b <= a + 1e-9 for a, b in zip(rmsd, rmsd[1:]))  # each level only adds detail
    assert rmsd[0] < 0.7 * initial and rmsd[-1] < 1.0
    final = superpose(model.coords[rows], pairs[0].target).rmsd
    assert final <= 1.5
    before, after = validate(structure).counts, validate(structure, model.coords).counts
    # a whole chain's junctions close in one of many minima: from some starts one or two stay open
    assert after["peptide_bond"] + after["ca_ca"] <= before["peptide_bond"] + before["ca_ca"] + MIN_MARGIN
    assert after["clash"] - before["clash"] <= 2 * structure.n_atoms / 1000
    assert after["ramachandran"] - before["ramachandran"] <= 0.01 * structure.n_residues


def test_each_level_changes_only_its_own_control_points_and_undoes_exactly() -> None:
    structure, model, pairs, _, _ = _setup(CLOSED, OPEN)
    result = fit_conformation(model, pairs, range(2, 5), regularize=False)
    finest = model.ribbons[0].level
    for fit in result.levels:
        (edit,) = fit.edits
        push = pushed_to_finest(fit.level, finest).toarray()
        change, *_ = np.linalg.lstsq(push, edit.new_points - edit.old_points, rcond=None)
        np.testing.assert_allclose(push @ change, edit.new_points - edit.old_points, atol=1e-9)
    for fit in reversed(result.levels):
        for edit in reversed(fit.edits):
            model.revert(edit)
    np.testing.assert_array_equal(model.coords, structure.coords)


def test_another_fold_is_told_apart() -> None:
    structure = read_structure(DATA / CLOSED)
    model = EditableModel(structure)
    same, _ = pair_segments(model, [0], [read_structure(DATA / OPEN).segments[0]])
    other, _ = pair_segments(model, [0], [read_structure(DATA / "1UBQ.pdb.gz").segments[0]])
    assert fold_similarity(model, same) > 0.6 > SAME_FOLD > fold_similarity(model, other)


@pytest.mark.parametrize(("start", "end"), [("3PTB.pdb.gz", "3SGB.pdb.gz"), ("1BMA.pdb.gz", "3SGB.pdb.gz")])
def test_a_homologue_reaches_its_partner_with_its_unpaired_residues_in_place(start: str, end: str,
                                                                             fit_start: Callable) -> None:
    """Trypsin and elastase onto another serine protease's backbone (137 and 140 residues
    paired by structure): every level kept, the paired Cα nearer the partner, no more bad
    junctions or Ramachandran outliers than the input, and the residues without a partner
    (insertions, tails) kept with the chain (trypsin's first twelve swung up to 118 Å)."""
    structure, model, pairs, pairing, rows = _setup(start, end, fit_start)
    assert pairing == "structure" and len(pairs[0].residues) < 0.7 * len(structure.segments[0])
    result = fit_conformation(model, pairs, range(7))
    assert [fit.level for fit in result.levels] == list(range(7)) and not result.dropped
    before, after = validate(structure).counts, validate(structure, model.coords).counts
    assert sum(after[k] for k in BACKBONE) <= sum(before[k] for k in BACKBONE)
    initial = superpose(structure.coords[rows], pairs[0].target).rmsd
    assert superpose(model.coords[rows], pairs[0].target).rmsd < 0.7 * initial
    ca = ca_rows(structure)[structure.segments[0].residue_index]
    assert np.linalg.norm(model.coords[ca] - structure.coords[ca], axis=1).max() < 10.0
    steps = np.linalg.norm(np.diff(model.coords[ca], axis=0), axis=1)
    assert steps.max() < 4.2


def test_a_fit_undoes_its_finest_levels_while_the_backbone_cannot_take_them(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the regularized model keeps more bad junctions and outliers than allowed, the
    finest level is undone and the rest regularized again, down to the coarsest level that
    moved: here the allowance is below what any model has, so only level 0 stays."""
    structure, model, pairs, _, _ = _setup("3PTB.pdb.gz", "3SGB.pdb.gz")
    monkeypatch.setattr(settle_module, "MIN_MARGIN", -1000)
    monkeypatch.setattr(settle_module, "MARGIN", -1.0)
    result = fit_conformation(model, pairs, range(4))
    assert [fit.level for fit in result.levels] == [0] and result.dropped == [1, 2, 3]
    reverted = model.coords.copy()
    for edit in reversed(result.regularization):
        model.revert(edit)
    for edit in reversed(result.levels[0].edits):
        model.revert(edit)
    np.testing.assert_array_equal(model.coords, structure.coords)  # nothing of the undone levels is left
    assert not np.array_equal(reverted, structure.coords)


def test_the_morph_passes_level_by_level_with_ideal_junctions() -> None:
    structure, model, pairs, _, rows = _setup(CLOSED, OPEN)
    fits = fit_conformation(model, pairs, range(7), regularize=False).levels
    frames = morph_frames(EditableModel(structure), fits, 8)
    assert len(frames) == 9
    np.testing.assert_array_equal(frames[0], structure.coords)
    target = pairs[0].target
    to_target = [superpose(frame[rows], target).rmsd for frame in frames]
    assert to_target[-1] < 1.5 < to_target[0] and to_target[4] < to_target[0]
    ca = ca_rows(structure)
    trans = np.linalg.norm(np.diff(structure.coords[ca], axis=0), axis=1) > 3.3  # cis peptides are shorter
    clashes = validate(structure).counts["clash"]
    for frame in frames[1:]:
        steps = np.linalg.norm(np.diff(frame[ca], axis=0), axis=1)[trans]
        assert np.all(np.abs(steps - 3.80) <= 0.1)
        assert validate(structure, frame).counts["clash"] <= clashes
