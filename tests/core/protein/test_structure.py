"""Reading real PDB/mmCIF entries into arrays and writing edited coordinates back."""

from __future__ import annotations

import gzip
import os
import subprocess
import sys
from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.protein.input_files import StructureError
from core.protein.reading import read_structure
from core.protein.structure import MAX_CA_STEP, SS_COMPUTED, SS_FROM_MMCIF, SS_FROM_PDB_RECORDS, Structure, ca_rows
from core.protein.writing import write_structure

DATA = Path(__file__).resolve().parents[2] / "data"
PROTEINS = [
    "1UBQ.pdb.gz", "1TIM.pdb.gz", "4YVS.cif.gz", "2K39_CA-only.pdb.gz", "1F9V.pdb.gz", "3JQH.cif.gz",
    "1ORC.pdb.gz", "7Z9T.cif.gz", "4HHB.pdb.gz", "1L2Y.pdb.gz", "1BPI.pdb.gz",
]  # fmt: skip


def read(name: str) -> Structure:
    return read_structure(DATA / name)


def text_of(name: str) -> str:
    return gzip.decompress((DATA / name).read_bytes()).decode()


def record_lines(path: Path, record: str) -> list[str]:
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as handle:
        return [line.rstrip() for line in handle if line[:6].strip() == record]


# ----------------------------------------------------------------------------- reading


def test_ubiquitin_is_one_segment_of_76_residues_with_records_ss() -> None:
    s = read("1UBQ.pdb.gz")
    assert (s.entry_id, s.source_format, s.n_residues, len(s.segments)) == ("1UBQ", "pdb", 76, 1)
    seg = s.segments[0]
    assert seg.chain == "A" and np.array_equal(seg.resseq, np.arange(1, 77))
    assert np.isfinite(np.stack([seg.n, seg.ca, seg.c, seg.o])).all()
    assert s.ss_source == SS_FROM_PDB_RECORDS
    # HELIX records 23-34 (alpha) and 56-59 (3-10); SHEET strands 1-7, 10-17, 40-45, 48-49, 66-72.
    assert np.array_equal(seg.resseq[seg.ss == "H"], np.r_[23:35, 56:60])
    assert set(seg.resseq[seg.ss == "E"]) >= {1, 7, 10, 17, 40, 45, 48, 49, 66, 72}
    assert s.n_water_atoms == 58 and s.n_hetero_atoms == 0
    assert s.chains[0].name == "A" and s.chains[0].n_residues == 134 and s.chains[0].n_backbone == 76


def test_triosephosphate_isomerase_has_two_chains() -> None:
    s = read("1TIM.pdb.gz")
    assert [(c.name, c.n_backbone, c.n_segments) for c in s.chains] == [("A", 247, 1), ("B", 247, 1)]
    assert [seg.chain for seg in s.segments] == ["A", "B"]


def test_mmcif_with_15_chains() -> None:
    """(Its reading time is printed by benchmarks/bench_io.py: timed tests fail on a busy machine.)"""
    s = read("4YVS.cif.gz")
    assert s.source_format == "mmcif" and s.ss_source == SS_FROM_MMCIF
    assert len(s.chains) == 15 and s.n_atoms == 26430


def test_multi_character_chain_ids() -> None:
    s = read("7Z9T.cif.gz")
    assert [c.name for c in s.chains] == ["AAA", "BBB"]
    assert {seg.chain for seg in s.segments} == {"AAA", "BBB"}
    assert s.segments[0].labels[0].startswith("AAA:")


@pytest.mark.parametrize("name", PROTEINS)
def test_segments_never_jump_a_gap(name: str) -> None:
    s = read(name)
    for seg in s.segments:
        assert len(seg) >= 2 and np.isfinite(seg.ca).all()
        assert (np.linalg.norm(np.diff(seg.ca, axis=0), axis=1) <= MAX_CA_STEP).all()
    for before, after in zip(s.segments[:-1], s.segments[1:], strict=True):
        if before.chain == after.chain:
            assert np.linalg.norm(after.ca[0] - before.ca[-1]) > MAX_CA_STEP


def test_chain_with_missing_residues_is_split_at_each_gap() -> None:
    s = read("1F9V.pdb.gz")
    assert [seg.chain for seg in s.segments] == ["A"] * 5
    assert [(seg.resseq[0], seg.resseq[-1]) for seg in s.segments] == [
        (385, 532), (546, 582), (594, 612), (615, 667), (671, 726),
    ]  # fmt: skip
    assert s.n_residues == 313


def test_insertion_codes_are_in_the_labels() -> None:
    seg = read("1ORC.pdb.gz").segments[0]
    assert [lab for lab, ic in zip(seg.labels, seg.icode, strict=True) if ic] == [
        "A:ASP56A", "A:GLY56B", "A:GLU56C", "A:VAL56D", "A:LYS56E",
    ]  # fmt: skip
    assert seg.icode.dtype.kind == "U" and seg.icode[0] == ""


def test_altlocs_all_atoms_kept_backbone_from_first_conformer() -> None:
    s = read("3JQH.cif.gz")
    st = gemmi.read_structure(str(DATA / "3JQH.cif.gz"))
    assert s.n_atoms == st[0].count_atom_sites() == 238
    assert s.n_altloc_atoms == sum(a.has_altloc() for ch in st[0] for r in ch for a in r) > 0
    seg = s.segments[0]
    # Residue 1 is PRO (altloc A, 7 atoms) or SER (altloc B, 6 atoms): one residue, 13 atoms.
    assert seg.labels[0] == "A:PRO1" and seg.atoms(0) == slice(0, 13)
    np.testing.assert_array_equal(seg.ca[0], [3.746, 20.507, 21.289])  # CA of conformer A
    # LYS 3 has CA A and CA B in one residue: the backbone uses A.
    lys3 = st[0]["A"]["3"][0]
    np.testing.assert_array_equal(seg.ca[2], lys3.find_atom("CA", "A").pos.tolist())
    assert np.array_equal(s.atom_residue[seg.atoms(2)], np.full(15, seg.residue_index[2]))
    # Residue 15 has three residue-level conformers (ARG/GLN/GLU): one residue, 29 atoms.
    k = seg.labels.index("A:ARG15")
    assert seg.atom_stop[k] - seg.atom_start[k] == 29


def test_ca_only_model() -> None:
    s = read("2K39_CA-only.pdb.gz")
    seg = s.segments[0]
    assert len(s.segments) == 1 and len(seg) == 76 and s.n_atoms == 76
    assert np.isfinite(seg.ca).all()
    assert np.isnan(np.stack([seg.n, seg.c, seg.o])).all()


def test_nmr_entry_uses_the_first_model_only() -> None:
    s = read("1L2Y.pdb.gz")
    assert s.n_models == 38 and s.n_atoms == 304 and s.n_residues == 20
    first_atom = next(line for line in text_of("1L2Y.pdb.gz").splitlines() if line.startswith("ATOM"))
    expected = [float(first_atom[30:38]), float(first_atom[38:46]), float(first_atom[46:54])]
    np.testing.assert_array_equal(s.coords[0], expected)


def test_dna_only_entry_has_no_protein_chain() -> None:
    with pytest.raises(StructureError, match=r"1BNA\.pdb\.gz: no protein chain"):
        read("1BNA.pdb.gz")


@pytest.mark.parametrize("name", ["1UBQ.pdb.gz", "3JQH.cif.gz", "4HHB.pdb.gz"])
def test_atom_residue_matches_segment_atom_ranges(name: str) -> None:
    s = read(name)
    expected = np.full(s.n_atoms, -1)
    for seg in s.segments:
        assert np.array_equal(
            seg.residue_index, np.arange(seg.residue_index[0], seg.residue_index[0] + len(seg))
        )
        for i in range(len(seg)):
            rows = s.coords[seg.atoms(i)]
            assert (np.abs(rows - seg.ca[i]).sum(axis=1) == 0).any()  # the Cα is one of its atoms
            expected[seg.atoms(i)] = seg.residue_index[i]
    assert np.array_equal(s.atom_residue, expected)
    assert (s.atom_residue == -1).sum() >= s.n_water_atoms + s.n_hetero_atoms


def test_arrays_are_read_only() -> None:
    s = read("1UBQ.pdb.gz")
    with pytest.raises(ValueError):
        s.coords[0, 0] = 0.0
    with pytest.raises(ValueError):
        s.segments[0].ca[0, 0] = 0.0


def test_residue_without_ca_is_skipped_with_a_warning(tmp_path: Path) -> None:
    lines = text_of("1UBQ.pdb.gz").splitlines()
    no_ca = [
        ln for ln in lines if not (ln.startswith("ATOM") and ln[12:16] == " CA " and ln[22:26] == "  40")
    ]
    path = tmp_path / "no_ca.pdb"
    path.write_text("\n".join(no_ca) + "\n")
    s = read_structure(path)
    assert [(seg.resseq[0], seg.resseq[-1]) for seg in s.segments] == [(1, 39), (41, 76)]
    assert any("A:GLN40" in w and "no CA" in w for w in s.warnings)


def test_single_residue_segment_is_dropped_with_a_warning(tmp_path: Path) -> None:
    lines = text_of("1UBQ.pdb.gz").splitlines()
    keep = [ln for ln in lines if not (ln.startswith("ATOM") and ln[22:26] in ("  39", "  41"))]
    path = tmp_path / "lonely.pdb"
    path.write_text("\n".join(keep) + "\n")
    s = read_structure(path)
    assert [(seg.resseq[0], seg.resseq[-1]) for seg in s.segments] == [(1, 38), (42, 76)]
    assert any("A:GLN40" in w for w in s.warnings)
    pro40 = [ln for ln in keep if ln.startswith("ATOM") and ln[22:26] == "  40"]
    assert (s.atom_residue == -1).sum() == len(pro40) + s.n_water_atoms


def test_bare_atom_records_without_header(tmp_path: Path) -> None:
    lines = text_of("1UBQ.pdb.gz").splitlines()
    path = tmp_path / "bare.pdb"
    path.write_text("\n".join(ln for ln in lines if ln.startswith(("ATOM", "HETATM"))) + "\n")
    s = read_structure(path)
    assert (s.entry_id, s.n_residues, len(s.segments), s.n_water_atoms) == ("bare", 76, 1, 58)
    assert s.ss_source == SS_COMPUTED


def test_secondary_structure_is_computed_without_records(tmp_path: Path) -> None:
    lines = text_of("1UBQ.pdb.gz").splitlines()
    path = tmp_path / "no_records.pdb"
    path.write_text("\n".join(ln for ln in lines if not ln.startswith(("HELIX", "SHEET"))) + "\n")
    s = read_structure(path)
    seg = s.segments[0]
    assert s.ss_source == SS_COMPUTED
    assert (seg.ss[(seg.resseq >= 24) & (seg.resseq <= 33)] == "H").all()
    assert (seg.ss[(seg.resseq >= 2) & (seg.resseq <= 7)] == "E").all()


@pytest.mark.parametrize("fmt", ["pdb", "mmcif"])
def test_records_that_match_no_residue_give_way_to_computed_secondary_structure(fmt: str, tmp_path: Path) -> None:
    """Atoms renumbered after the HELIX/SHEET records were written (as pdb-tools' pdb_reres
    does): the cartoon gets the computed assignment, not a chain of coil."""
    st = gemmi.read_structure(str(DATA / "1UBQ.pdb.gz"))
    renumbered = tmp_path / f"renumbered.{fmt}"
    if fmt == "pdb":
        for residue in st[0]["A"]:
            residue.seqid = gemmi.SeqId(residue.seqid.num + 1000, " ")
        st.write_pdb(str(renumbered))
    else:  # the atoms' author numbers only: gemmi's writer would drop records it cannot place
        document = st.make_mmcif_document()
        numbers = document[0].find("_atom_site.", ["auth_seq_id"])
        for row in numbers:
            row[0] = str(int(row[0]) + 1000)
        document.write_file(str(renumbered))
    lines = text_of("1UBQ.pdb.gz").splitlines()
    bare = tmp_path / "no_records.pdb"
    bare.write_text("\n".join(ln for ln in lines if not ln.startswith(("HELIX", "SHEET"))) + "\n")
    s = read_structure(renumbered)
    assert s.ss_source == SS_COMPUTED
    np.testing.assert_array_equal(s.segments[0].ss, read_structure(bare).segments[0].ss)
    assert [w for w in s.warnings if "record" in w] == [
        ("none of the file's 7 helix and sheet records matches a residue of the model (renumbered after they were "
         "written?): secondary structure computed instead")]
    one_off = tmp_path / "one_off.pdb"  # one record astray: the others still give the assignment
    one_off.write_text("\n".join(ln.replace(" ILE A   23 ", " ILE A  923 ") if ln.startswith("HELIX") else ln
                                  for ln in lines) + "\n")
    s = read_structure(one_off)
    assert s.ss_source == SS_FROM_PDB_RECORDS and (s.segments[0].ss == "E").sum() == 33
    assert [w for w in s.warnings if "record" in w] == ["helix record A:923(ILE)-34(GLU) does not match the model: ignored"]


def test_bad_inputs_raise_one_clear_error(tmp_path: Path) -> None:
    empty = tmp_path / "empty.pdb"
    empty.write_bytes(b"")
    text = tmp_path / "notes.pdb"
    text.write_text("hello\nthis is not a structure\n")
    nan = tmp_path / "nan.pdb"
    nan.write_text("ATOM      1  CA  GLY A   1         nan   1.000   2.000  1.00  0.00           C\n")
    corrupt = tmp_path / "corrupt.cif.gz"
    corrupt.write_bytes(b"\x1f\x8b\x08\x00garbage")
    cases = {
        tmp_path / "missing.pdb": "no such file",
        empty: "empty file",
        text: "not a structure file",
        nan: "non-finite coordinates",
        corrupt: "corrupt gzip",
        tmp_path: "is a directory",
    }
    for path, problem in cases.items():
        with pytest.raises(StructureError) as info:
            read_structure(path)
        message = str(info.value)
        assert message.startswith(str(path)) and problem in message and "\n" not in message


# ----------------------------------------------------------------------------- writing


ROUND_TRIPS = [
    ("1BPI.pdb.gz", ".pdb"), ("1BPI.pdb.gz", ".cif.gz"), ("4HHB.pdb.gz", ".ent.gz"),
    ("4HHB.pdb.gz", ".mmcif"), ("3JQH.cif.gz", ".cif"), ("3JQH.cif.gz", ".pdb.gz"),
    ("7Z9T.cif.gz", ".cif"), ("1L2Y.pdb.gz", ".pdb"),
]  # fmt: skip


@pytest.mark.parametrize(("name", "suffix"), ROUND_TRIPS)
def test_round_trip_without_edit(tmp_path: Path, name: str, suffix: str) -> None:
    s = read(name)
    out = write_structure(s, s.coords, tmp_path / f"out{suffix}")
    t = read_structure(out)
    np.testing.assert_allclose(t.coords, s.coords, atol=5e-4, rtol=0)
    for attr in (
        "n_atoms",
        "n_hetero_atoms",
        "n_water_atoms",
        "n_altloc_atoms",
        "n_models",
        "n_residues",
    ):
        assert getattr(t, attr) == getattr(s, attr), attr
    assert [c.name for c in t.chains] == [c.name for c in s.chains]
    for a, b in zip(s.segments, t.segments, strict=True):
        assert a.labels == b.labels and np.array_equal(a.ss, b.ss)


def test_pdb_output_keeps_the_header_records(tmp_path: Path) -> None:
    source = DATA / "1BPI.pdb.gz"
    s = read_structure(source)
    out = write_structure(s, s.coords, tmp_path / "1bpi.pdb")
    for record in (
        "SEQRES",
        "SHEET",
        "SSBOND",
        "HETATM",
        "CONECT",
        "CRYST1",
        "COMPND",
        "SOURCE",
        "AUTHOR",
        "JRNL",
    ):
        assert record_lines(out, record) == record_lines(source, record) != [], record
    # gemmi renumbers helix ids; the ranges and classes are kept.
    assert [ln[14:] for ln in record_lines(out, "HELIX")] == [
        ln[14:] for ln in record_lines(source, "HELIX")
    ]
    assert len(record_lines(out, "REMARK")) == len(record_lines(source, "REMARK"))
    assert read_structure(out).title == s.title


def test_mmcif_output_keeps_every_category_and_author_numbering(tmp_path: Path) -> None:
    s = read("7Z9T.cif.gz")
    out = write_structure(s, s.coords, tmp_path / "7z9t.cif")
    before = gemmi.cif.read(str(DATA / "7Z9T.cif.gz")).sole_block()
    after = gemmi.cif.read(str(out)).sole_block()
    assert after.get_mmcif_category_names() == before.get_mmcif_category_names()
    for tag in ("auth_seq_id", "auth_asym_id", "label_seq_id", "label_alt_id", "pdbx_PDB_ins_code"):
        assert list(after.find_values(f"_atom_site.{tag}")) == list(
            before.find_values(f"_atom_site.{tag}")
        ), tag
    for tag in ("B_iso_or_equiv", "occupancy"):
        values = [
            np.array(block.find_values(f"_atom_site.{tag}"), dtype=float) for block in (before, after)
        ]
        np.testing.assert_array_equal(*values)
    assert list(after.find_values("_struct_conn.id")) == list(before.find_values("_struct_conn.id"))


@pytest.mark.parametrize("suffix", [".pdb", ".cif"])
def test_moved_subset_is_written_and_others_unchanged(tmp_path: Path, suffix: str) -> None:
    s = read("1UBQ.pdb.gz")
    seg = s.segments[0]
    moved = np.isin(s.atom_residue, seg.residue_index[9:20])
    angle = 0.3
    rotation = np.array(
        [[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]]
    )
    coords = s.coords.copy()
    coords[moved] = (coords[moved] - seg.ca[14]) @ rotation.T + seg.ca[14] + [1.23456, -2.5, 0.75]
    t = read_structure(write_structure(s, coords, tmp_path / f"moved{suffix}"))
    np.testing.assert_allclose(t.coords[moved], np.round(coords[moved], 3), atol=1e-9, rtol=0)
    np.testing.assert_array_equal(t.coords[~moved], s.coords[~moved])
    assert moved.sum() == 81


def test_other_models_are_written_unchanged(tmp_path: Path) -> None:
    s = read("1L2Y.pdb.gz")
    out = write_structure(s, s.coords + 1.0, tmp_path / "nmr.pdb")
    st_in, st_out = (gemmi.read_structure(str(p)) for p in (DATA / "1L2Y.pdb.gz", out))
    assert len(st_out) == 38
    first_in, first_out = (
        np.array([cra.atom.pos.tolist() for cra in m.all()]) for m in (st_in[0], st_out[0])
    )
    np.testing.assert_allclose(first_out, first_in + 1.0, atol=1e-9)
    second_in, second_out = (
        np.array([cra.atom.pos.tolist() for cra in m.all()]) for m in (st_in[1], st_out[1])
    )
    np.testing.assert_array_equal(second_out, second_in)


def test_existing_files_and_the_input_are_not_overwritten(tmp_path: Path) -> None:
    source = tmp_path / "1ubq.pdb"
    source.write_bytes(gzip.decompress((DATA / "1UBQ.pdb.gz").read_bytes()))
    original = source.read_bytes()
    s = read_structure(source)
    with pytest.raises(FileExistsError, match="input file"):
        write_structure(s, s.coords + 1.0, source)
    assert source.read_bytes() == original
    target = tmp_path / "edit.pdb"
    target.write_text("precious\n")
    with pytest.raises(FileExistsError, match="existing file"):
        write_structure(s, s.coords, target)
    assert target.read_text() == "precious\n"
    write_structure(s, s.coords + 1.0, target, overwrite=True)
    np.testing.assert_allclose(read_structure(target).coords, s.coords + 1.0, atol=5e-4)
    write_structure(s, s.coords + 2.0, source, overwrite=True)
    np.testing.assert_allclose(read_structure(source).coords, s.coords + 2.0, atol=5e-4)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "1ubq.pdb",
        "edit.pdb",
    ]  # no temporary files left


@pytest.mark.parametrize(("umask", "mode"), [(0o022, 0o644), (0o077, 0o600), (0o027, 0o640)])
def test_a_new_file_gets_what_the_umask_allows_and_a_replaced_one_keeps_its_mode(tmp_path: Path, umask: int,
                                                                                mode: int) -> None:
    """Outputs are written to a temporary file and renamed: a new one takes the umask's
    permissions (a private umask keeps the edits private, #37), a replaced one keeps its own."""
    structure = read_structure(DATA / "1UBQ.pdb.gz")
    before = os.umask(umask)
    try:
        new = write_structure(structure, structure.coords, tmp_path / "new.pdb")
        old = tmp_path / "old.pdb"
        old.write_text("old\n")
        old.chmod(0o664)
        write_structure(structure, structure.coords, old, overwrite=True)
    finally:
        os.umask(before)
    assert new.stat().st_mode & 0o777 == mode and old.stat().st_mode & 0o777 == 0o664


def test_failed_write_leaves_nothing_behind(tmp_path: Path) -> None:
    s = read("7Z9T.cif.gz")
    with pytest.raises(StructureError, match="chain name too long"):
        write_structure(s, s.coords, tmp_path / "7z9t.pdb")
    assert list(tmp_path.iterdir()) == []


def test_write_rejects_bad_arguments(tmp_path: Path) -> None:
    s = read("1UBQ.pdb.gz")
    with pytest.raises(StructureError, match=r"shape \(660, 3\)"):
        write_structure(s, s.coords[:-1], tmp_path / "a.pdb")
    bad = s.coords.copy()
    bad[3, 1] = np.nan
    with pytest.raises(StructureError, match="non-finite"):
        write_structure(s, bad, tmp_path / "a.pdb")
    with pytest.raises(StructureError, match="unknown extension"):
        write_structure(s, s.coords, tmp_path / "a.xyz")
    assert list(tmp_path.iterdir()) == []


def test_ncs_operators_and_other_multi_line_records_keep_their_order(tmp_path: Path) -> None:
    """MTRIX1-3 of each operator (and ORIGX, SCALE, DBREF1/2) stay together, in input order (#16)."""
    text = gzip.decompress((DATA / "1UBQ.pdb.gz").read_bytes()).decode()
    rng = np.random.default_rng(4)
    operators = []
    for serial in range(1, 8):
        rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        rotation *= np.sign(np.linalg.det(rotation))
        shift = rng.normal(scale=30, size=3)
        operators.append((rotation, shift))
        operators_lines = [f"MTRIX{row + 1} {serial:3d}{rotation[row, 0]:10.6f}{rotation[row, 1]:10.6f}"
                           f"{rotation[row, 2]:10.6f}     {shift[row]:10.5f}    1" for row in range(3)]
        text = text.replace("ATOM      1 ", "\n".join(operators_lines) + "\nATOM      1 ", 1)
    path = tmp_path / "ncs.pdb"
    path.write_text(text)
    out = write_structure(read_structure(path), read_structure(path).coords, tmp_path / "out.pdb")
    records = ("MTRIX", "ORIGX", "SCALE")
    assert ([line.rstrip() for line in out.read_text().splitlines() if line.startswith(records)]
            == [line.rstrip() for line in text.splitlines() if line.startswith(records)])
    ncs = gemmi.read_structure(str(out)).ncs
    assert len(ncs) == 7
    for op, (rotation, shift) in zip(ncs, operators, strict=True):
        assert np.allclose(op.tr.mat.tolist(), rotation, atol=1e-6) and np.allclose(op.tr.vec.tolist(), shift, atol=1e-5)
        assert np.linalg.det(op.tr.mat.tolist()) == pytest.approx(1.0, abs=1e-5)


@pytest.mark.parametrize("column, value", [("x", 1e6), ("x", 6.7e29), ("x", -1000.0), ("b", 1e30), ("b", 1000.0)])
def test_values_pdb_columns_cannot_hold_are_refused(tmp_path: Path, column: str, value: float) -> None:
    """PDB writes cut off or scramble them; mmCIF holds them (#16)."""
    s = read_structure(DATA / "1UBQ.pdb.gz")
    coords = s.coords.copy()
    if column == "x":
        coords[10, 0] = value
    else:  # the first atom's B-factor, in an mmCIF
        cif = write_structure(s, s.coords, tmp_path / "b.cif")
        doc = gemmi.cif.read(str(cif))
        doc[0].find("_atom_site.", ["B_iso_or_equiv"])[0][0] = f"{value:g}"
        doc.write_file(str(cif))
        s = read_structure(cif)
        coords = s.coords
    with pytest.raises(StructureError, match="PDB columns cannot hold.*write mmCIF"):
        write_structure(s, coords, tmp_path / "out.pdb")
    assert not (tmp_path / "out.pdb").exists()
    back = read_structure(write_structure(s, coords, tmp_path / "out.cif"))
    if column == "x":
        assert back.coords[10, 0] == pytest.approx(value, rel=1e-6)
    else:
        assert back.atoms.b_factor[0] == pytest.approx(value, rel=1e-6)


@pytest.mark.parametrize("suffix", [".pdb", ".cif"])
def test_header_bytes_that_are_not_utf8_are_written_as_read(tmp_path: Path, suffix: str) -> None:
    """A Latin-1 byte (\\xcd) in a header line comes back as that byte, not re-encoded (#16)."""
    s = read_structure(DATA / "1UBQ.pdb.gz")
    source = write_structure(s, s.coords, tmp_path / f"source{suffix}")
    data = source.read_bytes()
    if suffix == ".pdb":
        line = b"COMPND    MOL_ID: 1; MOLECULE: CAF\xcd;"
        data = data.replace(b"COMPND ", line + b"\nCOMPND ", 1) if b"COMPND " in data else line + b"\n" + data
    else:
        line = b"_local_note.text 'CAF\xcd'"  # a category of the input: written as it was
        data = data.replace(b"_entry.id 1UBQ\n", b"_entry.id 1UBQ\n" + line + b"\n", 1)
    source.write_bytes(data)
    assert line in source.read_bytes()
    out = write_structure(read_structure(source), read_structure(source).coords, tmp_path / f"out{suffix}")
    assert line in out.read_bytes() and "\u00cd".encode() not in out.read_bytes()


def _without_atom_site_columns(source: Path, path: Path, drop: object) -> Path:
    doc = gemmi.cif.read(str(source))
    table = doc[0].get_mmcif_category("_atom_site.")
    for tag in [tag for tag in table if drop(tag)]:
        del table[tag]
    doc[0].set_mmcif_category("_atom_site.", table)
    doc.write_file(str(path))
    return path


@pytest.mark.parametrize("drop", ["auth_seq_id", "every auth_ column"])
def test_mmcif_without_author_columns_falls_back_to_the_label_columns(tmp_path: Path, drop: str) -> None:
    """1LCD (protein, DNA, waters) with its author numbering removed reads by the label_* columns (#16)."""
    path = _without_atom_site_columns(DATA / "1LCD.cif.gz", tmp_path / "noauth.cif",
                                      (lambda tag: tag == "auth_seq_id") if drop == "auth_seq_id"
                                      else (lambda tag: tag.startswith("auth_")))
    full, s = read_structure(DATA / "1LCD.cif.gz"), read_structure(path)
    assert s.n_atoms == full.n_atoms and np.array_equal(s.coords, full.coords)
    assert [len(seg) for seg in s.segments] == [len(seg) for seg in full.segments]
    assert s.segments[0].labels[0].endswith("MET1")
    residues = [len(np.unique(x.atoms.residue[x.atoms.category == "water"])) for x in (s, full)]
    assert residues[0] == residues[1] > 10  # each water its own residue, as with the author numbers
    back = read_structure(write_structure(s, s.coords, tmp_path / "out.cif"))
    assert np.array_equal(back.coords, s.coords)


@pytest.mark.parametrize("field, axis", [("  abc.de", "x"), ("        ", "y"), ("1.2.3   ", "z")])
def test_a_coordinate_that_is_not_a_number_is_refused(tmp_path: Path, field: str, axis: str) -> None:
    """gemmi reads such a field as 0.000: the reader names the line instead (#16)."""
    lines = gzip.decompress((DATA / "1UBQ.pdb.gz").read_bytes()).decode().splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("ATOM")) + 5
    start = {"x": 30, "y": 38, "z": 46}[axis]
    lines[k] = lines[k][:start] + field + lines[k][start + 8 :]
    path = tmp_path / "bad.pdb"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(StructureError, match=rf"line {k + 1}: the {axis} coordinate .* is not a number"):
        read_structure(path)


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_devices_and_fifos_are_never_read(tmp_path: Path, device: str) -> None:
    with pytest.raises(StructureError, match="not a regular file"):
        read_structure(device)
    fifo = tmp_path / "fifo.pdb"
    os.mkfifo(fifo)
    with pytest.raises(StructureError, match="not a regular file"):
        read_structure(fifo)  # would block for ever if opened


def test_a_gzip_bomb_stops_at_the_input_limit_within_bounded_memory(tmp_path: Path) -> None:
    """29 MB of gzip that inflate to 6.25 GiB, read under a 1.5 GiB address-space limit (#16)."""
    member = gzip.compress(b"\0" * 2**26, compresslevel=1)  # 64 MiB of zeros in 0.3 MB
    bomb = tmp_path / "bomb.pdb.gz"
    bomb.write_bytes(member * 100)
    script = ("import resource; resource.setrlimit(resource.RLIMIT_AS, (3 * 2**29, 3 * 2**29)); "
              "import sys; from core.protein.reading import read_structure\n"
              "try:\n    read_structure(sys.argv[1])\nexcept Exception as error:\n    print(error)")
    result = subprocess.run([sys.executable, "-c", script, str(bomb)], capture_output=True, text=True, timeout=120,
                            env={**os.environ, "RIBBONWAVE_MAX_INPUT_MB": "512"})
    assert result.returncode == 0, result.stderr[-2000:]
    assert "decompresses to more than the input limit (512 MiB; set $RIBBONWAVE_MAX_INPUT_MB" in result.stdout


def test_a_gzipped_file_reads_in_the_memory_it_needs_not_the_limit() -> None:
    """Under the default limit (4 GiB) a small gzipped entry reads within a 1.5 GiB address
    space: the decompression never asks for a buffer as large as the limit."""
    script = ("import resource; resource.setrlimit(resource.RLIMIT_AS, (3 * 2**29, 3 * 2**29)); "
              "import sys; from core.protein.reading import read_structure\n"
              "print(read_structure(sys.argv[1]).n_atoms)")
    environment = {key: value for key, value in os.environ.items() if key != "RIBBONWAVE_MAX_INPUT_MB"}
    result = subprocess.run([sys.executable, "-c", script, str(DATA / "1UBQ.pdb.gz")], capture_output=True, text=True,
                            timeout=120, env=environment, check=False)
    assert result.returncode == 0 and result.stdout.split() == ["660"], result.stderr[-2000:]


def test_the_input_limit_can_be_raised_or_lowered(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RIBBONWAVE_MAX_INPUT_MB", "0.01")  # 10 kB: 1UBQ is more
    with pytest.raises(StructureError, match="more than the input limit"):
        read_structure(DATA / "1UBQ.pdb.gz")
    monkeypatch.setenv("RIBBONWAVE_MAX_INPUT_MB", "1")
    assert read_structure(DATA / "1UBQ.pdb.gz").n_atoms == 660
    monkeypatch.setenv("RIBBONWAVE_MAX_INPUT_MB", "lots")
    with pytest.raises(StructureError, match="must be a number of MiB"):
        read_structure(DATA / "1UBQ.pdb.gz")


@pytest.mark.parametrize("name", ["1LCD.cif.gz", "3JQH.cif.gz", "4YVS.cif.gz", "7Z9T.cif.gz"])
def test_mmcif_written_unmoved_is_the_input_byte_for_byte(tmp_path: Path, name: str) -> None:
    s = read_structure(DATA / name)
    out = write_structure(s, s.coords, tmp_path / "out.cif")
    assert out.read_bytes() == gzip.decompress((DATA / name).read_bytes())


def test_mmcif_keeps_the_decimals_of_its_coordinates(tmp_path: Path) -> None:
    """An mmCIF with 7-decimal coordinates: unmoved atoms keep their text, moved ones get 7
    decimals too; nothing else of the file changes (#16)."""
    doc = gemmi.cif.read(str(DATA / "7Z9T.cif.gz"))
    table = doc[0].find("_atom_site.", ["Cartn_x", "Cartn_y", "Cartn_z"])
    rng = np.random.default_rng(2)
    for row in table:
        for k in range(3):
            row[k] = f"{float(row[k]) + rng.uniform(-4e-4, 4e-4):.7f}"
    seven = tmp_path / "seven.cif"
    doc.write_file(str(seven))
    source = read_structure(seven)
    moved = source.coords.copy()
    moved[50:80] += [0.12345678, -1.0, 2.5]
    out = write_structure(source, moved, tmp_path / "out.cif")
    back = read_structure(out)
    assert np.allclose(back.coords, moved, atol=6e-8) and np.array_equal(back.coords[:50], source.coords[:50])
    written, before = out.read_text().splitlines(), seven.read_text().splitlines()
    changed = [k for k, (a, b) in enumerate(zip(written, before, strict=True)) if a != b]
    assert len(changed) == 30  # the 30 moved atoms' lines, nothing else
    assert all(len(token.partition(".")[2]) == 7 for k in changed for token in written[k].split()[10:13])


PROTEIN_ENTRIES = sorted(p.name for p in DATA.glob("*.gz") if p.name != "1BNA.pdb.gz")
PDB_GROUPS = ("MTRIX", "ORIGX", "SCALE", "LINK", "SSBOND", "CISPEP", "HET")


def _atoms(path: Path) -> list[tuple]:
    st = gemmi.read_structure(str(path))
    return [(m.num, ch.name, str(r.seqid), r.name, a.name, a.altloc, round(a.pos.x, 3),
             round(a.pos.y, 3), round(a.pos.z, 3), round(a.occ, 2), round(a.b_iso, 2))
            for m in st for ch in m for r in ch for a in r]


@pytest.mark.parametrize("name", PROTEIN_ENTRIES)
def test_an_unmoved_structure_reads_back_record_by_record(tmp_path: Path, name: str) -> None:
    """What ``edit --move 0,0,0`` writes: the atoms of every model, the MTRIX, ORIGX, SCALE,
    LINK, SSBOND, CISPEP and HET records of PDB input, and mmCIF input byte for byte (#16)."""
    s = read_structure(DATA / name)
    source = _atoms(DATA / name)
    cif = write_structure(s, s.coords, tmp_path / "out.cif")
    assert _atoms(cif) == source and np.array_equal(read_structure(cif).atoms.element, s.atoms.element)
    if s.source_format == "mmcif":
        assert cif.read_bytes() == gzip.decompress((DATA / name).read_bytes())
        return
    try:
        pdb = write_structure(s, s.coords, tmp_path / "out.pdb")
    except StructureError as error:
        assert "cannot" in str(error)  # a chain id PDB cannot hold: refused, not mangled
        return
    assert _atoms(pdb) == source and np.array_equal(read_structure(pdb).atoms.element, s.atoms.element)
    original, written = text_of(name).splitlines(), pdb.read_text().splitlines()
    for group in PDB_GROUPS:
        def lines(text: list[str]) -> list[str]:
            return [line.rstrip() for line in text if line[:6].strip().rstrip("123") == group]
        assert lines(written) == lines(original), group


def test_ca_rows_point_at_the_backbone_ca() -> None:
    for name in ("1UBQ.pdb.gz", "4HHB.pdb.gz"):
        structure = read_structure(DATA / name)
        rows = ca_rows(structure)
        assert np.array_equal(structure.coords[rows], np.concatenate([s.ca for s in structure.segments]))
        assert set(structure.atoms.name[rows]) == {"CA"}


def test_a_file_without_element_columns_is_converted_with_the_elements_read(tmp_path: Path) -> None:
    """CHARMM's adenylate kinase has no element columns: written as mmCIF (gemmi writes it),
    its Cα are carbon, not calcium, and its hydrogens hydrogen; written as PDB it stays as read."""
    structure = read_structure(DATA / "1AKE_adk_closed.pdb.gz")
    written = read_structure(write_structure(structure, structure.coords, tmp_path / "adk.cif"))
    block = gemmi.cif.read(str(tmp_path / "adk.cif")).sole_block()
    symbols = dict(zip(block.find_values("_atom_site.label_atom_id"), block.find_values("_atom_site.type_symbol")))
    assert symbols["CA"] == "C" and symbols["HG1"] == "H" and symbols["CB"] == "C"
    assert np.array_equal(written.atoms.element, structure.atoms.element)
    pdb = write_structure(structure, structure.coords, tmp_path / "adk.pdb")
    assert pdb.read_bytes() == gzip.decompress((DATA / "1AKE_adk_closed.pdb.gz").read_bytes())


def test_residue_rows_are_placed_in_their_segments_and_named() -> None:
    """Every row of the residue table lies in the segment whose residue_index holds it."""
    structure = read_structure(DATA / "4YVS.cif.gz")
    rows = np.arange(structure.n_residues)
    segment, index = structure.residue_place(rows)
    for k, s in enumerate(structure.segments):
        assert np.array_equal(segment[s.residue_index], np.full(len(s), k))
        assert np.array_equal(index[s.residue_index], np.arange(len(s)))
    assert structure.residue_label(int(structure.segments[2].residue_index[0])) == "B:THR190"
    assert structure.segments[2].summary == "B  THR190–GLN237 (48 residues)"
