"""Multiresolution editing of atoms on real structures: locality, rigidity, exact undo, save."""

import gzip
from pathlib import Path

import numpy as np
import pytest

from core.protein.frames import REACH
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def ubiquitin():
    return read_structure(DATA / "1UBQ.pdb.gz")


@pytest.fixture
def model(ubiquitin):
    return EditableModel(ubiquitin)


def moved_residues(model, edit):
    """Residues (within the segment) with at least one atom that changed position."""
    moved_rows = edit.rows[np.any(edit.new_coords != edit.old_coords, axis=1)]
    segment = model.segments[edit.segment]
    owners = np.searchsorted(segment.atom_start, moved_rows, side="right") - 1
    return np.unique(owners)


def test_locality_on_ubiquitin_doubles_per_level(model):
    """Carson's ubiquitin experiment: the curve points of 4 residues move at full resolution,
    8, 16, 32 below; each residue turns with the curve within REACH residues of it, so as
    many more on each side move (turned about their curve points)."""
    ribbon = model.ribbons[0]
    carried, counts = [], []
    for level in (ribbon.max_level, 6, 5, 4):
        points, _ = ribbon.control_points(level)
        edit = model.move_point(0, level, len(points) // 2, [1.5, -1.0, 2.0])
        residues = moved_residues(model, edit)
        assert np.array_equal(residues, edit.residues)
        assert np.all(np.diff(residues) == 1)  # one contiguous stretch
        counts.append(len(residues))
        shift = ribbon.space.evaluate(edit.new_points, ribbon.residue_u) - ribbon.residue_points()
        carried.append(int(np.count_nonzero(np.linalg.norm(shift, axis=1) > 1e-9)))
    assert carried == [4, 8, 16, 32]
    assert counts == [n + 2 * REACH for n in carried]


def test_unaffected_atoms_are_bit_identical(model, ubiquitin):
    edit = model.move_point(0, 5, 9, [3.0, 0.0, -1.0])
    model.apply(edit)
    untouched = np.setdiff1d(np.arange(ubiquitin.n_atoms), edit.rows)
    assert len(untouched) > 0.5 * ubiquitin.n_atoms
    assert np.array_equal(model.coords[untouched], ubiquitin.coords[untouched])
    assert not np.array_equal(model.coords[edit.rows], ubiquitin.coords[edit.rows])


def test_residues_move_rigidly(model, ubiquitin):
    edit = model.move_point(0, 3, 5, [4.0, 2.0, -3.0])
    model.apply(edit)
    segment = model.segments[0]
    for residue in edit.residues:
        rows = segment.atoms(residue)
        before, after = ubiquitin.coords[rows], model.coords[rows]
        distances = lambda a: np.linalg.norm(a[:, None] - a[None], axis=-1)  # noqa: E731
        assert np.abs(distances(after) - distances(before)).max() < 1e-9


def test_residue_points_follow_the_edited_curve(model):
    edit = model.move_point(0, 4, 8, [2.0, 2.0, 2.0])
    model.apply(edit)
    ribbon = model.ribbons[0]
    segment = model.segments[0]
    # the Cα keeps its offset from C^r in the residue frame, so |Cα - C^r| is unchanged
    ca_rows = [segment.atom_start[i] + 1 for i in edit.residues]  # atom order N, CA, ... in 1UBQ
    before = np.linalg.norm(edit.old_coords[np.searchsorted(edit.rows, ca_rows)] - ribbon.space.evaluate(
        edit.old_points, ribbon.residue_u[edit.residues]), axis=1)
    after = np.linalg.norm(model.coords[ca_rows] - ribbon.residue_points()[edit.residues], axis=1)
    assert np.allclose(before, after, atol=1e-9)


def test_zero_edit_changes_nothing(model, ubiquitin):
    edit = model.move_point(0, 3.5, 4, [0.0, 0.0, 0.0])
    model.apply(edit)
    assert len(edit.rows) == 0
    assert np.array_equal(model.coords, ubiquitin.coords)


def test_revert_restores_exactly_and_merged_edits_equal_the_sequence(model, ubiquitin):
    first = model.move_point(0, 5, 10, [1.0, 0.0, 0.0])
    model.apply(first)
    second = model.tug(0, 4, float(model.ribbons[0].residue_u[30]), [0.0, 2.0, 0.0])
    model.apply(second)
    after_both = model.coords.copy()
    points_after = model.ribbons[0].points.copy()
    model.revert(second)
    model.revert(first)
    assert np.array_equal(model.coords, ubiquitin.coords)
    merged = first.then(second)
    model.apply(merged)
    assert np.array_equal(model.coords, after_both)
    assert np.array_equal(model.ribbons[0].points, points_after)
    model.revert(merged)
    assert np.array_equal(model.coords, ubiquitin.coords)


def test_tugging_a_residue_moves_its_curve_point_by_the_displacement(model):
    ribbon = model.ribbons[0]
    residue = 40
    u = float(ribbon.residue_u[residue])
    before = ribbon.residue_points()[residue]
    model.apply(model.tug(0, 4, u, [0.0, 0.0, 3.0]))
    after = model.ribbons[0].residue_points()[residue]
    assert np.allclose(after - before, [0.0, 0.0, 3.0], atol=1e-10)


def test_saved_edit_reads_back(model, tmp_path):
    edit = model.move_point(0, 4, 6, [2.0, -2.0, 1.0])
    model.apply(edit)
    for name in ("edited.pdb", "edited.cif"):
        saved = model.save(tmp_path / name)
        again = read_structure(saved)
        assert np.allclose(again.coords, model.coords, atol=6e-4)
    with pytest.raises(FileExistsError):
        model.save(tmp_path / "edited.pdb")


def test_every_segment_of_a_multichain_entry_is_editable():
    structure = read_structure(DATA / "1TIM.pdb.gz")
    model = EditableModel(structure, kind="calpha")
    assert len(model.ribbons) == len(structure.segments) >= 2
    edit = model.move_point(1, 3, 4, [1.0, 1.0, 1.0])
    model.apply(edit)
    chain_a_rows = np.concatenate([np.arange(a, b) for a, b in zip(model.segments[0].atom_start, model.segments[0].atom_stop)])
    assert np.array_equal(model.coords[chain_a_rows], structure.coords[chain_a_rows])
    with pytest.raises(ValueError, match="segment must be in"):
        model.move_point(len(model.ribbons), 3, 0, [1.0, 0.0, 0.0])


def test_fractional_edits_stay_local():
    """The tails of a fractional-level edit below NEGLIGIBLE_MOVE move no residue."""
    structure = read_structure(DATA / "1TIM.pdb.gz")
    model = EditableModel(structure)
    ribbon = model.ribbons[0]  # 247 residues, J = 8, maximum level 7.95
    edit = model.move_point(0, 7.5, 60, [2.0, 0.0, 0.0])
    assert 4 < len(edit.residues) < len(ribbon.residue_u) // 2
    full = ribbon.residue_points()
    moved_curve = ribbon.with_points(edit.new_points).residue_points()
    still = np.setdiff1d(np.arange(len(full)), edit.residues)
    assert np.abs(moved_curve[still] - full[still]).max() < 1e-5


def _distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.norm(a[:, None] - b[None], axis=-1)


@pytest.mark.parametrize("shift", [(3.0, -2.0, 1.0), (-1.0, 4.0, 0.5)])
def test_a_bound_ligand_rides_with_its_residue_as_a_rigid_body(shift: tuple[float, float, float]) -> None:
    """Hemoglobin's α heme is bound to its proximal His87: an edit that moves His87 moves the
    heme with it (every distance within the heme and to His87 kept), undo puts it back bit for
    bit, and with carrying off it stays where it was."""
    structure = read_structure(DATA / "4HHB.pdb.gz")
    model = EditableModel(structure)
    rows, host = model.bound_ligands(0)
    his = structure.segments[0].labels.index("A:HIS87")
    assert set(host) == {his} and set(structure.atoms.resname[rows]) == {"HEM"} and len(rows) == 43
    his_rows = np.arange(structure.segments[0].atom_start[his], structure.segments[0].atom_stop[his])
    ribbon = model.ribbons[0]
    before = model.coords.copy()
    edit = model.tug(0, ribbon.max_level - 2, float(ribbon.residue_u[his]), np.array(shift))
    assert np.isin(rows, edit.rows).all() and np.array_equal(edit.rows, np.sort(edit.rows))
    model.apply(edit)
    heme, imidazole = model.coords[rows], model.coords[his_rows]
    assert np.linalg.norm(heme - before[rows], axis=1).min() > 0.5  # it moved ...
    np.testing.assert_allclose(_distances(heme, heme), _distances(before[rows], before[rows]), atol=1e-9)
    np.testing.assert_allclose(_distances(heme, imidazole), _distances(before[rows], before[his_rows]), atol=1e-9)
    model.revert(edit)
    assert np.array_equal(model.coords, before)
    model.carry_ligands = False
    left = model.tug(0, ribbon.max_level - 2, float(ribbon.residue_u[his]), np.array(shift))
    assert not np.isin(rows, left.rows).any() and np.array_equal(left.rows, edit.rows[~np.isin(edit.rows, rows)])


@pytest.mark.parametrize("name", ["3PTB.pdb.gz", "4HHB.pdb.gz", "1ACB.pdb.gz"])
def test_the_ligands_that_ride_are_those_within_4_angstroms(name: str) -> None:
    """Each ligand or ion group with an atom within 4 Å of a backbone residue's atom rides, whole,
    with one residue; the others and every water ride with nothing."""
    structure = read_structure(DATA / name)
    model = EditableModel(structure)
    riding = np.concatenate([model.bound_ligands(k)[0] for k in range(len(structure.segments))])
    atoms, polymer = structure.atoms, structure.coords[structure.atom_residue >= 0]
    for group in np.unique(atoms.residue[structure.ligand_rows]):
        rows = np.flatnonzero(atoms.residue == group)
        near = _distances(structure.coords[rows], polymer).min() <= 4.0
        assert np.isin(rows, riding).all() == near and (np.isin(rows, riding).any() == near), atoms.resname[rows[0]]
    assert len(riding) == len(np.unique(riding)) and not (atoms.category[riding] == "water").any()


def test_a_residue_the_ribbon_skips_is_drawn_and_carried_as_a_ligand(tmp_path: Path) -> None:
    """A protein residue no segment holds would be seen nowhere: one without a Cα (as GFP's
    chromophore CRO66; here ubiquitin's Gln40 without its Cα) and 4HHB's B:ASP79, which has no
    bonded neighbour, are among the ligand rows and ride with the residue nearest to them."""
    lines = gzip.decompress((DATA / "1UBQ.pdb.gz").read_bytes()).decode().splitlines()
    path = tmp_path / "no_ca.pdb"
    path.write_text("\n".join(ln for ln in lines if not (ln.startswith("ATOM") and ln[12:16] == " CA "
                                                       and ln[22:26] == "  40")) + "\n")
    for structure, chain, number, hosts in ((read_structure(path), "A", 40, {"A:ILE36", "A:PRO38", "A:GLN41"}),
                                            (read_structure(DATA / "4HHB.pdb.gz"), "B", 79, {"B:LEU78"})):
        atoms = structure.atoms
        skipped = np.flatnonzero((atoms.chain == chain) & (atoms.resseq == number))
        assert len(skipped) and (structure.atom_residue[skipped] < 0).all()
        assert np.isin(skipped, structure.ligand_rows).all() and set(atoms.category[skipped]) == {"protein"}
        model = EditableModel(structure)
        rides = [(k, host) for k in range(len(structure.segments))
                 for row, host in zip(*model.bound_ligands(k), strict=True) if row in skipped]
        assert len(rides) == len(skipped) and len({k for k, _ in rides}) == 1
        assert {structure.segments[k].labels[host] for k, host in rides} <= hosts
