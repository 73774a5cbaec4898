"""Geometry validation against independent computations (gemmi, brute force) on real entries."""

from dataclasses import replace
from pathlib import Path

import gemmi
import numpy as np
import pytest
from scipy.sparse import csgraph, csr_matrix

from core.geometry.ramachandran import (
    FAVOURED,
    OUTLIER,
    RAMACHANDRAN,
    RAMACHANDRAN_CLASSES,
    nearest_allowed,
    ramachandran_region,
)
from core.geometry.topology import topology
from core.geometry.validation import KINDS, phi_psi, validate
from core.geometry.vectors import angle, dihedral
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
JUNCTION_KINDS = KINDS[:5]


@pytest.fixture(scope="module")
def ubiquitin():
    return read_structure(DATA / "1UBQ.pdb.gz")


def gemmi_residues(path: Path, structure):
    """gemmi residues (first model) of every residue of ``structure``'s residue table."""
    model = gemmi.read_structure(str(path))[0]
    found = {}
    for chain in model:
        for residue in chain:
            key = (chain.name, residue.seqid.num, residue.seqid.icode.strip())
            found.setdefault(key, residue)
    return [found[(s.chain, int(n), ic)] for s in structure.segments for n, ic in zip(s.resseq, s.icode, strict=True)]


def expected_junction_flags(path: Path, structure) -> set[tuple[str, str]]:
    """(kind, 'A:RES1-A:RES2') of the junctions outside tolerance, measured with gemmi."""
    residues = gemmi_residues(path, structure)
    labels = [label for s in structure.segments for label in s.labels]
    flags = set()
    start = 0
    for segment in structure.segments:
        for k in range(start, start + len(segment) - 1):
            here, after = residues[k], residues[k + 1]
            atoms = [here.find_atom("CA", "*"), here.find_atom("C", "*"), after.find_atom("N", "*"),
                     after.find_atom("CA", "*")]
            if any(a is None for a in atoms):
                continue
            ca1, c1, n2, ca2 = (a.pos for a in atoms)
            omega = np.degrees(gemmi.calculate_dihedral(ca1, c1, n2, ca2))
            cis = abs(omega) < 90
            proline = after.name == "PRO"
            where = f"{labels[k]}-{labels[k + 1]}"
            checks = {
                "peptide_bond": (c1.dist(n2), 1.341 if proline else 1.329, 0.05),
                "ca_ca": (ca1.dist(ca2), 2.94 if cis else 3.80, 0.25 if cis else 0.1),
                "angle_ca_c_n": (np.degrees(gemmi.calculate_angle(ca1, c1, n2)), 116.9 if proline else 116.2,
                                 6.0 if proline else 8.0),
                "angle_c_n_ca": (np.degrees(gemmi.calculate_angle(c1, n2, ca2)), 122.6 if proline else 121.7,
                                 20.0 if proline else 7.2),
                "omega": (180 - abs(omega) if not cis else abs(omega), 0.0, 30.0),
            }
            flags |= {(kind, where) for kind, (value, ideal, tolerance) in checks.items() if abs(value - ideal) > tolerance}
        start += len(segment)
    return flags


@pytest.mark.parametrize("name", ["4HHB.pdb.gz", "1TIM.pdb.gz", "1BD2.pdb.gz", "1ORC.pdb.gz"])
def test_junction_flags_agree_with_gemmi(name):
    structure = read_structure(DATA / name)
    report = validate(structure)
    got = {(f.kind, f.where) for f in report.flags if f.kind in JUNCTION_KINDS}
    assert got == expected_junction_flags(DATA / name, structure)
    if name == "4HHB.pdb.gz":  # an old entry with poor geometry: plenty to agree on
        assert len(got) > 500


def test_angles_and_dihedrals_match_gemmi():
    rng = np.random.default_rng(3)
    points = rng.normal(scale=2.0, size=(50, 4, 3))
    mine_angle = angle(points[:, 0], points[:, 1], points[:, 2])
    mine_dihedral = dihedral(points[:, 0], points[:, 1], points[:, 2], points[:, 3])
    for k, quad in enumerate(points):
        p = [gemmi.Position(*x) for x in quad]
        assert mine_angle[k] == pytest.approx(np.degrees(gemmi.calculate_angle(p[0], p[1], p[2])), abs=1e-9)
        assert mine_dihedral[k] == pytest.approx(np.degrees(gemmi.calculate_dihedral(*p)), abs=1e-9)


def test_phi_psi_match_gemmi(ubiquitin):
    phi, psi = phi_psi(ubiquitin)
    residues = gemmi_residues(DATA / "1UBQ.pdb.gz", ubiquitin)
    for k in range(1, len(residues) - 1):
        expected = np.degrees(gemmi.calculate_phi_psi(residues[k - 1], residues[k], residues[k + 1]))
        assert (phi[k], psi[k]) == pytest.approx(tuple(expected), abs=1e-9)
    assert np.isnan(phi[0]) and np.isnan(psi[-1])



def test_phi_psi_of_some_residues_are_those_of_the_whole_table():
    structure = read_structure(DATA / "1TIM.pdb.gz")
    coords = structure.coords + np.random.default_rng(0).normal(scale=0.3, size=structure.coords.shape)
    phi, psi = phi_psi(structure, coords)
    rows = structure.segments[1].residue_index[[0, 5, 3, 246]]  # the second chain, its ends included
    some_phi, some_psi = phi_psi(structure, coords, rows)
    np.testing.assert_array_equal(some_phi, phi[rows])
    np.testing.assert_array_equal(some_psi, psi[rows])
    assert np.isnan(some_phi[0]) and np.isnan(some_psi[-1]) and np.isfinite(some_phi[1:]).all()
    assert [len(a) for a in phi_psi(structure, coords, np.empty(0, dtype=int))] == [0, 0]
    with pytest.raises(ValueError, match="residues must lie in"):
        phi_psi(structure, coords, [structure.n_residues])

def test_ramachandran_regions():
    general, glycine, proline = (RAMACHANDRAN_CLASSES.index(c) for c in ("general", "glycine", "proline"))
    assert ramachandran_region(-63, -43, general) == FAVOURED  # α helix
    assert ramachandran_region(-120, 130, general) == FAVOURED  # β strand
    assert ramachandran_region(60, 40, general) != OUTLIER  # left-handed helix
    assert ramachandran_region(60, -120, general) == OUTLIER
    assert ramachandran_region(-80, -120, general) == OUTLIER
    assert ramachandran_region(80, 180, glycine) == FAVOURED
    assert ramachandran_region(60, 40, proline) == OUTLIER  # φ of proline is held near -65°
    assert ramachandran_region(-65, 140, proline) == FAVOURED
    # glycine is achiral: its map is symmetric under (φ, ψ) -> (-φ, -ψ)
    assert np.array_equal(RAMACHANDRAN[glycine], RAMACHANDRAN[glycine][::-1, ::-1])


def test_nearest_allowed_is_the_closest_allowed_point_across_the_wrap():
    """Against a brute-force search over allowed points every degree (distances wrap at ±180°)."""
    rng = np.random.default_rng(3)
    phi, psi = rng.uniform(-180, 180, size=(2, 400))
    kind = rng.integers(0, len(RAMACHANDRAN_CLASSES), size=400)
    to_phi, to_psi = nearest_allowed(phi, psi, kind)
    wrap = lambda a: (a + 180.0) % 360.0 - 180.0  # noqa: E731
    allowed = ramachandran_region(phi, psi, kind) != OUTLIER
    assert np.array_equal(to_phi[allowed], phi[allowed]) and np.array_equal(to_psi[allowed], psi[allowed])
    assert np.all(ramachandran_region(wrap(to_phi), wrap(to_psi), kind) != OUTLIER)
    grid_phi, grid_psi = np.meshgrid(np.arange(-179.5, 180), np.arange(-179.5, 180))
    for k in np.flatnonzero(~allowed):
        inside = ramachandran_region(grid_phi, grid_psi, kind[k]) != OUTLIER
        nearest = np.hypot(wrap(grid_phi[inside] - phi[k]), wrap(grid_psi[inside] - psi[k])).min()
        found = np.hypot(wrap(to_phi[k] - phi[k]), wrap(to_psi[k] - psi[k]))
        assert nearest - 1.0 <= found <= nearest + 2.5  # found lies 1° inside, on a 2° grid


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "1EJG.pdb.gz", "3JQH.cif.gz", "1F9V.pdb.gz", "1BD2.pdb.gz",
                                  "7Z9T.cif.gz", "4YVS.cif.gz", "1LCD.cif.gz"])
def test_unedited_structures_validate_with_few_flags(name):
    """Well-refined entries are what normal looks like: junction flags on at most 1% of
    junctions, Ramachandran outliers on at most 3% of residues, clashes under 10 per 1000 atoms."""
    structure = read_structure(DATA / name)
    report = validate(structure)
    counts, checked = report.counts, report.checked
    junction_flags = sum(counts[k] for k in JUNCTION_KINDS)
    assert junction_flags <= 0.01 * checked["peptide_bond"] + 1
    assert counts["ramachandran"] <= 0.03 * checked["ramachandran"] + 1
    assert counts["clash"] <= 10 * checked["clash"] / 1000


def test_cis_peptides_are_not_flagged():
    structure = read_structure(DATA / "4YVS.cif.gz")
    report = validate(structure)
    top = topology(structure)
    assert len(report.cis) == 20  # a cis peptide in each of the 15 chains and a few more
    cis_labels = {f"{top.labels[i]}-{top.labels[i + 1]}" for i in report.cis}
    assert not {f.where for f in report.flags if f.kind in ("ca_ca", "omega")} & cis_labels


def brute_force_clashes(structure, coords):
    """Clashing atom pairs by an all-pairs computation with a bond graph of the input."""
    atoms = structure.atoms
    radius = {"C": 1.70, "N": 1.55, "O": 1.40, "S": 1.80}
    covalent = {"C": 0.76, "N": 0.71, "O": 0.66, "S": 1.05}
    heavy = np.flatnonzero(np.isin(atoms.element, list(radius)) & (atoms.category != "water"))
    r = np.array([radius[e] for e in atoms.element[heavy]])
    cov = np.array([covalent[e] for e in atoms.element[heavy]])
    original = structure.coords[heavy]
    d0 = np.linalg.norm(original[:, None] - original[None], axis=-1)
    bonded = d0 < cov[:, None] + cov[None] + 0.45
    np.fill_diagonal(bonded, False)
    hops = csgraph.shortest_path(csr_matrix(bonded), unweighted=True)
    xyz = coords[heavy]
    d = np.linalg.norm(xyz[:, None] - xyz[None], axis=-1)
    polar = np.isin(atoms.element[heavy], ["N", "O"])
    contact = np.where(polar[:, None] & polar[None], 2.8, r[:, None] + r[None])
    i, j = np.nonzero(np.triu((contact - d > 0.4) & (hops > 3), k=1))
    return {(int(heavy[a]), int(heavy[b])) for a, b in zip(i, j, strict=True)}


def test_clashes_agree_with_brute_force(ubiquitin):
    model = EditableModel(ubiquitin)
    edit = model.move_point(0, 4, 8, [-3.0, 4.0, -6.0])  # pushes a loop into the protein
    model.apply(edit)
    top = topology(ubiquitin)
    report = validate(ubiquitin, model.coords)
    got = {f.where for f in report.flags if f.kind == "clash"}
    expected = brute_force_clashes(ubiquitin, model.coords)
    assert len(expected) > 20
    assert got == {f"{top.atom_label(a)} / {top.atom_label(b)}" for a, b in expected}
    assert report.counts["clash"] == len(expected)
    overlaps = sorted((f.severity for f in report.flags if f.kind == "clash"), reverse=True)
    assert report.worst(1, "clash")[0].severity == overlaps[0] > 1


def test_a_topology_around_some_atoms_screens_their_pairs_like_the_whole():
    structure = read_structure(DATA / "1BPI.pdb.gz")  # disulfides 5-55, 14-38, 30-51
    top = topology(structure)
    rows = np.flatnonzero(np.isin(structure.atom_residue, np.arange(49, 56)))  # Cys51, Cys55: partners before
    local = top.around(rows)
    assert 0 < len(local.excluded) < len(top.excluded) / 5
    for reach in (-2.0, -0.5):  # near pairs; bonded ones among them must be excluded
        expected = top.close_pairs(structure.coords, rows, reach)
        got = local.close_pairs(structure.coords, rows, reach)
        assert len(expected[0]) > 0
        np.testing.assert_array_equal(np.sort(got[0] * top.n_atoms + got[1]), np.sort(expected[0] * top.n_atoms + expected[1]))
    unscreened = replace(local, excluded=local.excluded[:0]).close_pairs(structure.coords, rows, -2.0)
    assert len(unscreened[0]) > len(top.close_pairs(structure.coords, rows, -2.0)[0])


def test_hydrogens_waters_and_other_conformers_never_clash():
    structure = read_structure(DATA / "1L2Y.pdb.gz")  # NMR model with hydrogens
    assert not [f for f in validate(structure).flags if f.kind == "clash"]
    structure = read_structure(DATA / "1EJG.pdb.gz")  # alternate conformers at 0.54 Å
    clashes = [f for f in validate(structure).flags if f.kind == "clash"]
    top = topology(structure)
    alt = {label for label in map(top.atom_label, range(top.n_atoms)) if "." in label}
    for flag in clashes:
        a, b = flag.where.split(" / ")
        assert not (a in alt and b in alt and a[-1] != b[-1])
    hemoglobin = read_structure(DATA / "4HHB.pdb.gz")
    assert not [f for f in validate(hemoglobin).flags if f.kind == "clash" and "HOH" in f.where]


def test_local_report_updates_the_full_one(ubiquitin):
    model = EditableModel(ubiquitin)
    full = validate(ubiquitin)
    edit = model.move_point(0, 4, 8, [-3.0, 4.0, -6.0])
    model.apply(edit)
    region = ubiquitin.segments[0].residue_index[edit.residues]
    local = validate(ubiquitin, model.coords, residues=region)
    assert local.checked["peptide_bond"] < full.checked["peptide_bond"]
    merged = full.updated(local)
    fresh = validate(ubiquitin, model.coords)
    assert sorted((f.kind, f.where) for f in merged.flags) == sorted((f.kind, f.where) for f in fresh.flags)
    assert merged.counts == fresh.counts and merged.cis == fresh.cis


def test_report_as_dict_and_bad_arguments(ubiquitin):
    report = validate(ubiquitin)
    data = report.to_dict(worst=3)
    assert set(data) == {"checked", "counts", "cis_peptides", "flags"}
    assert data["checked"]["peptide_bond"] == 75 and data["checked"]["ramachandran"] == 74
    assert len(data["flags"]) == min(3, len(report.flags))
    with pytest.raises(ValueError, match="shape"):
        validate(ubiquitin, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="residues"):
        validate(ubiquitin, residues=[76])


def test_a_saved_edit_validates_like_the_model(ubiquitin, tmp_path):
    """Bonds come from residues and names, not from whatever is close in the file: the
    clashes of an edited model read back from disk are the clashes of the model."""
    model = EditableModel(ubiquitin)
    model.apply(model.move_point(0, 3, 3, [5.0, 0.0, 0.0]))
    in_memory = validate(ubiquitin, model.coords)
    from_file = validate(read_structure(model.save(tmp_path / "bent.pdb")))
    assert in_memory.counts["clash"] > 20
    assert {(f.kind, f.where) for f in from_file.flags} == {(f.kind, f.where) for f in in_memory.flags}
