"""Multi-model entries (NMR ensembles): any model reads, and writing replaces that model only."""

from __future__ import annotations

import gzip
from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.protein.input_files import StructureError
from core.protein.reading import read_atoms, read_structure
from core.protein.structure import Structure
from core.protein.writing import write_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def file_positions(path: Path, model: int) -> np.ndarray:
    """(n, 3) atom positions of model ``model`` (from 1) in the order of the file's atom records."""
    data = path.read_bytes()
    text = (gzip.decompress(data) if data[:2] == b"\x1f\x8b" else data).decode()
    if text.startswith("data_"):
        table = gemmi.cif.read_string(text).sole_block().find("_atom_site.", [
            "pdbx_PDB_model_num", "Cartn_x", "Cartn_y", "Cartn_z"])
        numbers = list(dict.fromkeys(row[0] for row in table))
        return np.array([[float(v) for v in list(row)[1:]] for row in table if row[0] == numbers[model - 1]])
    rows, current = [], 0
    for line in text.splitlines():
        current += line.startswith("MODEL ")
        if line.startswith(("ATOM  ", "HETATM")) and max(current, 1) == model:
            rows.append([float(line[c : c + 8]) for c in (30, 38, 46)])
    return np.array(rows)


def input_text(name: str) -> str:
    return gzip.decompress((DATA / name).read_bytes()).decode()


def bent(structure: Structure, residues: slice = slice(3, 9)) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates with the atoms of some residues of the first segment turned by 90° and shifted
    (to new positions of three decimals, as files hold them), and the mask of the atoms that moved."""
    segment = structure.segments[0]
    moved = np.isin(structure.atom_residue, segment.residue_index[residues])
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    coords = structure.coords.copy()
    centre = np.round(segment.ca[residues].mean(axis=0), 3)
    coords[moved] = (coords[moved] - centre) @ turn.T + centre + [1.25, -0.5, 2.0]
    return coords, moved


@pytest.mark.parametrize(("name", "model"), [("1L2Y.pdb.gz", 1), ("1L2Y.pdb.gz", 17), ("1L2Y.pdb.gz", 38),
                                             ("1LCD.cif.gz", 2), ("1LCD.cif.gz", 3)])
def test_each_model_reads_its_own_atoms(name: str, model: int) -> None:
    s = read_structure(DATA / name, model=model)
    first = read_structure(DATA / name)
    assert (s.model_number, first.model_number, s.n_models) == (model, 1, first.n_models)
    np.testing.assert_array_equal(s.coords, file_positions(DATA / name, model))
    assert [seg.labels for seg in s.segments] == [seg.labels for seg in first.segments]
    assert (model == 1) == np.array_equal(s.coords, first.coords)
    np.testing.assert_array_equal(read_atoms(DATA / name, model).coords, s.coords)


@pytest.mark.parametrize(("name", "model", "count"), [("1L2Y.pdb.gz", 39, 38), ("1L2Y.pdb.gz", 0, 38),
                                                      ("1LCD.cif.gz", 4, 3), ("1LCD.cif.gz", -1, 3),
                                                      ("2BEG.pdb.gz", 2, 1), ("1L2Y.pdb.gz", True, 38),
                                                      ("1L2Y.pdb.gz", "2", 38)])
def test_a_model_the_file_does_not_have_is_refused(name: str, model: object, count: int) -> None:
    """2BEG's NUMMDL says 10 models, but the file holds one: the models counted are those present."""
    with pytest.raises(StructureError, match=rf"{name.replace('.', '[.]')}: no model .*; the file has {count} "
                                             rf"model\(s\), numbered 1 to {count}"):
        read_structure(DATA / name, model=model)
    with pytest.raises(StructureError, match="no model"):
        read_atoms(DATA / name, model)


@pytest.mark.parametrize(("name", "model", "suffix"), [("1L2Y.pdb.gz", 1, ".pdb"), ("1L2Y.pdb.gz", 9, ".pdb"),
                                                       ("1L2Y.pdb.gz", 38, ".pdb.gz"), ("1LCD.cif.gz", 2, ".cif"),
                                                       ("1LCD.cif.gz", 3, ".cif"), ("2BEG.pdb.gz", 1, ".pdb")])
def test_an_unmoved_model_is_written_byte_for_byte(tmp_path: Path, name: str, model: int, suffix: str) -> None:
    s = read_structure(DATA / name, model=model)
    out = write_structure(s, s.coords, tmp_path / f"out{suffix}")
    data = out.read_bytes()
    assert (gzip.decompress(data) if suffix.endswith(".gz") else data).decode() == input_text(name)


@pytest.mark.parametrize(("name", "model", "suffix"), [("1L2Y.pdb.gz", 5, ".pdb"), ("1L2Y.pdb.gz", 38, ".pdb"),
                                                       ("1L2Y.pdb.gz", 1, ".pdb"), ("1LCD.cif.gz", 2, ".cif"),
                                                       ("1LCD.cif.gz", 3, ".cif"), ("2BEG.pdb.gz", 1, ".pdb")])
def test_an_edited_model_changes_only_its_moved_atom_lines(tmp_path: Path, name: str, model: int,
                                                           suffix: str) -> None:
    """Edit model k, save in the input's format, read every model back: model k moved, every
    other model (and every other line of the file) as read."""
    s = read_structure(DATA / name, model=model)
    coords, moved = bent(s)
    out = write_structure(s, coords, tmp_path / f"out{suffix}")
    back = read_structure(out, model=model)
    assert back.model_number == model and back.n_models == s.n_models
    np.testing.assert_allclose(back.coords[moved], coords[moved], atol=1e-9, rtol=0)
    np.testing.assert_array_equal(back.coords[~moved], s.coords[~moved])
    for other in range(1, s.n_models + 1):
        if other != model:
            np.testing.assert_array_equal(read_structure(out, model=other).coords,
                                          read_structure(DATA / name, model=other).coords)
    written, original = out.read_text().splitlines(), input_text(name).splitlines()
    assert len(written) == len(original)
    changed = [k for k, (a, b) in enumerate(zip(written, original)) if a != b]
    assert len(changed) == moved.sum() > 0  # the moved atoms' lines, nothing else


@pytest.mark.parametrize(("name", "model", "suffix"), [("1L2Y.pdb.gz", 12, ".cif"), ("1LCD.cif.gz", 3, ".pdb")])
def test_an_edited_model_written_in_the_other_format(tmp_path: Path, name: str, model: int, suffix: str) -> None:
    s = read_structure(DATA / name, model=model)
    coords, moved = bent(s)
    out = write_structure(s, coords, tmp_path / f"out{suffix}")
    np.testing.assert_allclose(read_structure(out, model=model).coords, coords, atol=1e-9, rtol=0)
    for other in (1, s.n_models):
        if other != model:
            np.testing.assert_array_equal(file_positions(out, other), file_positions(DATA / name, other))


def test_a_pdb_edit_recomputes_the_disulfide_distances_it_changes(tmp_path: Path) -> None:
    """The SSBOND records of the cysteines moved get new distances; the others stay as read."""
    s = read_structure(DATA / "1BPI.pdb.gz")
    segment = s.segments[0]
    coords = s.coords.copy()
    cys5 = np.isin(s.atom_residue, segment.residue_index[segment.resseq == 5])
    coords[cys5] += [0.0, 0.0, 1.5]
    written = write_structure(s, coords, tmp_path / "out.pdb").read_text().splitlines()
    original = input_text("1BPI.pdb.gz").splitlines()
    changed = [(a, b) for a, b in zip(original, written) if a != b]
    assert len(changed) == cys5.sum() + 1
    ssbond = [pair for pair in changed if pair[0].startswith("SSBOND")]
    assert len(ssbond) == 1 and "CYS A    5" in ssbond[0][0] and ssbond[0][0][:70] == ssbond[0][1][:70]
    assert float(ssbond[0][0][73:78]) == 2.01 != float(ssbond[0][1][73:78])


def test_an_entry_without_protein_reads_for_viewing_when_asked(tmp_path: Path) -> None:
    with pytest.raises(StructureError, match="no protein chain"):
        read_structure(DATA / "1BNA.pdb.gz")
    s = read_structure(DATA / "1BNA.pdb.gz", require_protein=False)
    assert s.segments == () and s.n_residues == 0 and s.ss_source == ""
    assert s.n_atoms == len(read_atoms(DATA / "1BNA.pdb.gz")) == 566
    assert (s.atom_residue == -1).all() and set(s.atoms.category) == {"nucleic", "water"}
    out = write_structure(s, s.coords, tmp_path / "1bna.pdb")
    assert out.read_text() == input_text("1BNA.pdb.gz")
