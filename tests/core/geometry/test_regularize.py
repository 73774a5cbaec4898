"""Regularization after multiresolution edits: ideal junctions, no new clashes, on the curve."""

from pathlib import Path

import numpy as np
import pytest

from core.geometry.regularize import regularize_region, regularized
from core.geometry.topology import topology
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def ubiquitin():
    return read_structure(DATA / "1UBQ.pdb.gz")


def outward_edit(model, level, point, distance=5.0):
    """Move control ``point`` of the level-``level`` curve ``distance`` Å away from the protein centre."""
    points, _ = model.ribbons[0].control_points(level)
    direction = points[point] - model.structure.coords.mean(axis=0)
    return model.move_point(0, level, point, distance * direction / np.linalg.norm(direction))


def coords_after(model, edit):
    coords = model.coords.copy()
    coords[edit.rows] = edit.new_coords
    return coords


def backbone(structure, coords, name):
    """(n_residues, 3) positions of atom ``name`` of every residue, found by name here."""
    atoms = structure.atoms
    rows = [next(r for r in range(s.atom_start[i], s.atom_stop[i]) if atoms.name[r] == name)
            for s in structure.segments for i in range(len(s))]
    return coords[rows]


def junctions(structure, coords):
    """C–N and Cα–Cα distances of consecutive residues (one segment)."""
    c, n, ca = (backbone(structure, coords, name) for name in ("C", "N", "CA"))
    return np.linalg.norm(n[1:] - c[:-1], axis=1), np.linalg.norm(ca[1:] - ca[:-1], axis=1)


def calpha_steps(structure, coords):
    ca = backbone(structure, coords, "CA")
    return np.linalg.norm(ca[1:] - ca[:-1], axis=1)


def kabsch(a, b):
    """Rotation R and translation t with R a + t ≈ b (rows)."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    rotation = vt.T @ d @ u.T
    return rotation, cb - rotation @ ca


def clash_pairs(structure, coords):
    return {f.where for f in validate(structure, coords).flags if f.kind == "clash"}


def outliers(structure, coords):
    return {f.where for f in validate(structure, coords).flags if f.kind == "ramachandran"}


def test_regularization_fixes_a_five_angstrom_edit_of_ubiquitin(ubiquitin):
    """The issue's acceptance test: level 3, one control point moved 5 Å."""
    model = EditableModel(ubiquitin)
    edit = outward_edit(model, 3, 3)
    edited = coords_after(model, edit)
    c_n, ca_ca = junctions(ubiquitin, edited)
    outside = np.mean(np.abs(c_n - 1.33) > 0.05)
    assert outside > 0.1  # without regularization: 10 of 75 peptide bonds (13%)
    fixed = regularized(model, edit)
    after = coords_after(model, fixed)
    c_n, ca_ca = junctions(ubiquitin, after)
    assert np.all(np.abs(c_n - 1.33) <= 0.05)
    assert np.all(np.abs(ca_ca - 3.80) <= 0.1)  # 1UBQ has no cis peptide
    assert clash_pairs(ubiquitin, after) <= clash_pairs(ubiquitin, ubiquitin.coords)
    assert outliers(ubiquitin, after) <= outliers(ubiquitin, ubiquitin.coords)  # φ and ψ stay allowed
    # each residue carries its curve point C^r rigidly: it stays within 0.5 Å rms of the edited curve
    ribbon = model.ribbons[0]
    u = ribbon.residue_u[fixed.residues]
    carried = []
    for k, residue in enumerate(fixed.residues):
        rows = np.arange(ubiquitin.segments[0].atom_start[residue], ubiquitin.segments[0].atom_stop[residue])
        rows = rows[~np.isin(ubiquitin.atoms.name[rows], ("O", "OXT"))]  # the rigid part: the carbonyl turns
        rotation, shift = kabsch(edited[rows], after[rows])
        carried.append(rotation @ ribbon.space.evaluate(edit.new_points, u[k : k + 1])[0] + shift)
    curve = ribbon.space.evaluate(edit.new_points, np.linspace(0, 1, 40001))
    distances = [np.linalg.norm(curve - p, axis=1).min() for p in carried]
    assert np.sqrt(np.mean(np.square(distances))) < 0.5


@pytest.mark.parametrize(("level", "point"), [(2, 1), (2, 3), (3, 2), (3, 6), (4, 6), (4, 10), (4.5, 12), (5, 18)])
def test_regularized_edits_have_ideal_junctions_and_no_new_clashes(ubiquitin, level, point):
    model = EditableModel(ubiquitin)
    fixed = regularized(model, outward_edit(model, level, point))
    after = coords_after(model, fixed)
    report = validate(ubiquitin, after)
    assert sum(report.counts[k] for k in ("peptide_bond", "ca_ca", "angle_ca_c_n", "angle_c_n_ca", "omega")) == 0
    assert clash_pairs(ubiquitin, after) <= clash_pairs(ubiquitin, ubiquitin.coords)
    assert outliers(ubiquitin, after) <= outliers(ubiquitin, ubiquitin.coords)  # (5, 18): 2 without the Ramachandran term


def test_regularized_edit_is_one_exact_undo_step(ubiquitin):
    model = EditableModel(ubiquitin)
    edit = outward_edit(model, 4, 8)
    fixed = regularized(model, edit)
    assert fixed.segment == edit.segment
    assert np.array_equal(fixed.old_points, edit.old_points) and np.array_equal(fixed.new_points, edit.new_points)
    assert set(edit.residues) <= set(fixed.residues) and len(fixed.residues) == len(edit.residues) + 6  # 3 flanks
    model.apply(fixed)
    untouched = np.setdiff1d(np.arange(ubiquitin.n_atoms), fixed.rows)
    assert np.array_equal(model.coords[untouched], ubiquitin.coords[untouched])
    # the same result whether or not the plain edit was applied first
    model.revert(fixed)
    assert np.array_equal(model.coords, ubiquitin.coords)
    model.apply(edit)
    again = regularized(model, edit)
    assert np.array_equal(again.new_coords, fixed.new_coords) and np.array_equal(again.old_coords, fixed.old_coords)
    model.revert(edit)
    assert np.array_equal(model.coords, ubiquitin.coords)


def test_residues_keep_their_geometry_and_turn_only_about_two_bonds(ubiquitin):
    """Each residue moves rigidly but for its carbonyl O, which turns about the Cα–C bond
    (ψ), and, where it clashes, its side chain beyond Cβ, which turns about Cα–Cβ (χ1):
    every bond length and angle of the residue stays as it was. This inward edit still
    clashes once the backbone alone has settled, so side chains turn too."""
    model = EditableModel(ubiquitin)
    edit = outward_edit(model, 5, 9, distance=-9.0)  # (5 Å in: the backbone alone settles it)
    edited = coords_after(model, edit)
    fixed = regularized(model, edit)
    after = coords_after(model, fixed)
    segment, atoms = ubiquitin.segments[0], ubiquitin.atoms
    pairwise = lambda x: np.linalg.norm(x[:, None] - x[None], axis=-1)  # noqa: E731
    turned = {"psi": 0.0, "chi1": 0.0}
    for residue in fixed.residues:
        rows = np.arange(segment.atom_start[residue], segment.atom_stop[residue])
        names = atoms.name[rows]
        carbonyl = np.isin(names, ("O", "OXT"))
        side_chain = ~np.isin(names, ("N", "CA", "C", "O", "OXT", "CB"))
        frame = rows[~carbonyl & ~side_chain]
        for group, axis in ((frame, ()), (rows[carbonyl], ("CA", "C")), (rows[side_chain], ("CA", "CB"))):
            if len(group) == 0:
                continue
            ends = np.array([rows[names == name][0] for name in axis], dtype=int)  # on the bond it turns about
            together = np.concatenate([group, ends])
            assert np.abs(pairwise(after[together]) - pairwise(ubiquitin.coords[together])).max() < 1e-9
        rotation, shift = kabsch(edited[frame], after[frame])
        for key, group in (("psi", rows[carbonyl]), ("chi1", rows[side_chain])):
            if len(group):
                moved = np.linalg.norm(edited[group] @ rotation.T + shift - after[group], axis=1).max()
                turned[key] = max(turned[key], moved)
    assert turned["psi"] > 0.05 and turned["chi1"] > 0.05  # both kinds of turn were used


def test_regularize_region_after_a_plain_edit(ubiquitin):
    """The editor's "Regularize region": any stretch of the current model, tethered to its curve."""
    model = EditableModel(ubiquitin)
    edit = outward_edit(model, 4, 10)
    model.apply(edit)
    region = ubiquitin.segments[0].residue_index[edit.residues]
    assert validate(ubiquitin, model.coords, residues=region).counts["peptide_bond"] > 5
    fix = regularize_region(model, 0, edit.residues, flank=2)
    assert np.array_equal(fix.old_points, fix.new_points) and np.array_equal(fix.old_points, edit.new_points)
    model.apply(fix)
    report = validate(ubiquitin, model.coords, residues=region)
    assert sum(report.counts[k] for k in ("peptide_bond", "ca_ca", "angle_ca_c_n", "angle_c_n_ca", "omega")) == 0
    model.revert(fix)
    model.revert(edit)
    assert np.array_equal(model.coords, ubiquitin.coords)


def test_regularize_region_repairs_compressed_peptide_bonds():
    """4HHB (1984) has compressed peptide bonds; regularizing a stretch makes them ideal
    (its residues' own bond lengths stay as they are: residues are rigid)."""
    hemoglobin = read_structure(DATA / "4HHB.pdb.gz")
    model = EditableModel(hemoglobin)
    residues = np.arange(10, 30)
    inner = hemoglobin.segments[0].residue_index[residues][2:-2]  # away from the fixed neighbours
    assert validate(hemoglobin, residues=inner).counts["peptide_bond"] >= 5
    model.apply(regularize_region(model, 0, residues))
    after = validate(hemoglobin, model.coords, residues=inner)
    assert after.counts["peptide_bond"] == 0 and after.counts["omega"] == 0
    top = topology(hemoglobin)
    ca = top.backbone[hemoglobin.segments[0].residue_index[residues], 1]
    moved = np.linalg.norm(model.coords[ca] - hemoglobin.coords[ca], axis=1)
    assert np.sqrt(np.mean(moved**2)) < 1.5  # the worst bonds are 0.5 Å short


def test_calpha_only_models_keep_their_calpha_spacing():
    structure = read_structure(DATA / "2K39_CA-only.pdb.gz")
    model = EditableModel(structure)
    edit = outward_edit(model, 3, 4)
    stretched = calpha_steps(structure, coords_after(model, edit))
    fixed = regularized(model, edit)
    inside = fixed.residues[:-1]  # junctions (i, i + 1) with both residues free
    assert np.abs(stretched[inside] - 3.80).max() > 0.1
    ca_ca = calpha_steps(structure, coords_after(model, fixed))
    assert np.abs(ca_ca[inside] - 3.80).max() < 0.01


def test_nothing_to_regularize_and_bad_arguments(ubiquitin):
    model = EditableModel(ubiquitin)
    zero = model.move_point(0, 0, 1, [0.0, 0.0, 0.0])
    assert len(regularized(model, zero).rows) == 0
    with pytest.raises(ValueError, match="flank"):
        regularized(model, outward_edit(model, 4, 8), flank=-1)
    with pytest.raises(ValueError, match="residues"):
        regularize_region(model, 0, [80])


@pytest.mark.parametrize("turn", [0.05, 0.3])
def test_analytic_jacobian_matches_finite_differences(ubiquitin, turn):
    """Junction, tether, torsion, Ramachandran, clash and carbonyl-turn terms are
    differentiated by hand; check against numbers (the larger turns make Ramachandran
    outliers, whose rows are zero elsewhere)."""
    from scipy.spatial.transform import Rotation

    from core.geometry.restraints import CHI1, PSI, BodyState, Restraints

    model = EditableModel(ubiquitin)
    edit = outward_edit(model, 4, 8)
    ribbon, segment = model.ribbons[0], ubiquitin.segments[0]
    coords = coords_after(model, edit)
    u = ribbon.residue_u[edit.residues]
    problem = Restraints(ubiquitin, coords, segment.residue_index[edit.residues],
                       ribbon.space.evaluate(edit.new_points, u), ribbon.space.evaluate(edit.new_points, u, 1),
                       ubiquitin.coords, side_chains=True)
    rng = np.random.default_rng(5)
    n = problem.n_bodies
    state = BodyState(Rotation.from_rotvec(rng.normal(scale=turn, size=(n, 3))).as_matrix(),
                   rng.normal(scale=0.1, size=(n, 3)), rng.normal(scale=0.2, size=(n, 2)))
    residual, terms = problem.evaluate(state)
    analytic = problem.jacobian(terms).toarray()
    pairs, _, _ = problem.clashes.pairs(problem.atoms(state))
    assert len(pairs) > 10  # clash terms are part of the check
    for rotor in (PSI, CHI1):  # and so are the turns of the carbonyls and (clashing) side chains
        columns = problem.column[:, 6 + rotor]
        assert np.abs(analytic[:, columns[columns >= 0]]).max() > 1.0
    rama, _, _ = problem.ramachandran(problem.atoms(state))
    assert np.count_nonzero(rama) > (5 if turn > 0.1 else -1)
    h = 1e-6
    numeric = np.empty_like(analytic)
    for column in range(analytic.shape[1]):
        step = np.zeros(analytic.shape[1])
        step[column] = h
        moved, _ = problem.evaluate(state.moved(problem.per_body(step)))
        numeric[:, column] = (moved - residual) / h
    assert np.abs(analytic - numeric).max() < 1e-3 * np.abs(analytic).max()


def test_the_clash_candidate_list_misses_no_pair(ubiquitin):
    """The Verlet list is kept while the two free atoms that moved most have moved less than
    SKIN in all; over a walk of random steps it must give exactly the pairs a new list gives,
    and it must be kept for some steps and made again for others."""
    from core.geometry.clash_list import SKIN
    from core.geometry.restraints import PARAMETERS, BodyState, Restraints

    model = EditableModel(ubiquitin)
    edit = outward_edit(model, 4, 8)
    ribbon, segment = model.ribbons[0], ubiquitin.segments[0]
    u = ribbon.residue_u[edit.residues]
    problem, fresh_problem = (
        Restraints(ubiquitin, coords_after(model, edit), segment.residue_index[edit.residues],
                 ribbon.space.evaluate(edit.new_points, u), ribbon.space.evaluate(edit.new_points, u, 1),
                 ubiquitin.coords, side_chains=True)
        for _ in range(2)
    )
    rng = np.random.default_rng(11)
    n = problem.n_bodies
    state = BodyState.start(n)
    kept = listed = 0
    for _ in range(30):
        step = np.zeros((n, PARAMETERS))
        step[:, :3] = rng.normal(scale=0.15, size=(n, 3))
        step[:, 3:] = rng.normal(scale=0.03, size=(n, PARAMETERS - 3))
        state = state.moved(step)
        current = problem.atoms(state)
        before = problem.clashes.listed_at
        pairs = problem.clashes.pairs(current)
        kept += problem.clashes.listed_at is before
        listed += problem.clashes.listed_at is not before
        if problem.clashes.listed_at is before:  # the two largest moves since the list add up to less than SKIN
            moves = np.sort(np.linalg.norm(current[problem.free_atoms] - before, axis=1))
            assert moves[-2:].sum() <= SKIN
        fresh_problem.clashes.listed_at = None  # a new list here
        fresh = fresh_problem.clashes.pairs(current)
        assert {tuple(p) for p in np.column_stack(pairs[:2])} == {tuple(p) for p in np.column_stack(fresh[:2])}
        assert np.array_equal(np.sort(pairs[2]), np.sort(fresh[2]))
    assert kept > 3 and listed > 3
