"""Fitting adenylate kinase from one conformation onto the other, coarse to fine (#19)."""

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from core.analysis.superpose import superpose
from core.fitting.coarse_to_fine import pushed_to_finest
from core.fitting.conformation import SAME_FOLD, fit_conformation, fold_similarity, pair_segments
from core.fitting.morph import morph_frames
from core.fitting.settle import MIN_MARGIN
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
    result = fit_conformation(model, pairs, range(0, 7))
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


def test_a_homologue_keeps_the_levels_its_backbone_can_take() -> None:
    structure, model, pairs, pairing, rows = _setup("3PTB.pdb.gz", "3SGB.pdb.gz")
    assert pairing == "structure"
    result = fit_conformation(model, pairs, range(0, 7))
    assert result.dropped and result.dropped[-1] == 6 and result.levels[-1].level < 6
    before, after = validate(structure).counts, validate(structure, model.coords).counts
    assert after["peptide_bond"] + after["ca_ca"] <= before["peptide_bond"] + before["ca_ca"]
    assert superpose(model.coords[rows], pairs[0].target).rmsd < superpose(structure.coords[rows],
                                                                            pairs[0].target).rmsd


def test_the_morph_passes_level_by_level_with_ideal_junctions() -> None:
    structure, model, pairs, _, rows = _setup(CLOSED, OPEN)
    fits = fit_conformation(model, pairs, range(0, 7), regularize=False).levels
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
