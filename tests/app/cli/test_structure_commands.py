"""The headless commands ``info``, ``curve`` and ``edit`` on real entries, through ``main``."""

import csv
import gzip
import io
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from app.main import main
from core.protein.reading import read_structure
from core.protein.structure import ca_rows

DATA = Path(__file__).resolve().parents[2] / "data"
AWKWARD = ["1L2Y.pdb.gz", "2BEG.pdb.gz", "1LCD.cif.gz", "3JQH.cif.gz", "1EJG.pdb.gz", "1ORC.pdb.gz",
           "1F9V.pdb.gz", "4HHB.pdb.gz", "1BD2.pdb.gz", "7Z9T.cif.gz", "4YVS.cif.gz", "2K39_CA-only.pdb.gz"]


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_info_json_describes_ubiquitin(capsys):
    status, out, _ = run(capsys, "info", DATA / "1UBQ.pdb.gz", "--json")
    report = json.loads(out)
    assert status == 0
    assert report["residues"] == 76 and report["chains"][0]["chain"] == "A"
    assert sum(report["secondary_structure"].values()) == 76
    assert report["secondary_structure"]["H"] > 10 and report["secondary_structure"]["E"] > 10
    assert report["secondary_structure_source"] == "HELIX/SHEET records"
    assert (report["method"], report["resolution"]) == ("X-RAY DIFFRACTION", 1.8)
    (segment,) = report["segments"]
    assert segment["max_level_peptide"] == pytest.approx(math.log2(76), abs=1e-4)
    status, out, _ = run(capsys, "info", DATA / "2O9S_A.pdb.gz")  # no HELIX/SHEET records
    assert status == 0 and out.splitlines()[2].endswith(" other (computed by DSSP)")


def test_info_text_lists_every_segment_of_a_broken_chain(capsys):
    status, out, _ = run(capsys, "info", DATA / "1F9V.pdb.gz")
    assert status == 0
    structure = read_structure(DATA / "1F9V.pdb.gz")
    assert len(structure.segments) > 1
    for segment in structure.segments:
        assert segment.labels[0] in out and segment.labels[-1] in out


def test_info_says_how_the_structure_was_determined(capsys):
    status, out, _ = run(capsys, "info", DATA / "4HHB.pdb.gz")
    assert status == 0 and out.splitlines()[1] == "  X-RAY DIFFRACTION, 1.74 Å resolution"
    status, out, _ = run(capsys, "info", DATA / "1LCD.cif.gz", "--json")  # NMR: no resolution
    assert status == 0 and (json.loads(out)["method"], json.loads(out)["resolution"]) == ("SOLUTION NMR", None)
    status, out, _ = run(capsys, "info", DATA / "2K39_CA-only.pdb.gz")  # a file that says neither
    assert status == 0 and out.splitlines()[1].startswith("  76 atoms")


def test_info_lists_the_biological_assemblies(capsys):
    status, out, _ = run(capsys, "info", DATA / "4YVS.cif.gz")  # a capsid: 180 copies of its chains
    assert status == 0 and "  biological assemblies (--assembly N): 1: 180 chains, 317,160 atoms (180-meric)" in out
    status, out, _ = run(capsys, "info", DATA / "1TIM.pdb.gz", "--json")
    (assembly,) = json.loads(out)["assemblies"]
    structure = read_structure(DATA / "1TIM.pdb.gz")
    assert (assembly["number"], assembly["chains"], assembly["atoms"]) == (1, 2, structure.n_atoms)  # the dimer as read
    status, out, _ = run(capsys, "info", DATA / "2K39_CA-only.pdb.gz", "--json")  # no assembly records
    assert status == 0 and json.loads(out)["assemblies"] == []


def test_info_counts_the_ligands_and_ions_by_name(capsys):
    status, out, _ = run(capsys, "info", DATA / "4HHB.pdb.gz", "--json")
    assert status == 0 and json.loads(out)["ligands"] == [{"name": "HEM", "count": 4}, {"name": "PO4", "count": 2}]
    status, out, _ = run(capsys, "info", DATA / "3PTB.pdb.gz")  # trypsin's calcium and benzamidine
    assert status == 0 and "ligands and ions: CA (1), BEN (1)" in out
    status, out, _ = run(capsys, "info", DATA / "1UBQ.pdb.gz", "--json")  # waters only
    assert status == 0 and json.loads(out)["ligands"] == []


def test_info_names_the_nucleic_acids_and_describes_an_entry_without_protein(capsys):
    status, out, _ = run(capsys, "info", DATA / "1BNA.pdb.gz")  # the Dickerson dodecamer: DNA only
    assert status == 0
    assert "chain A 12 nucleotides (DNA), chain B 12 nucleotides (DNA)" in out and "no protein chain" in out
    status, out, _ = run(capsys, "info", DATA / "1BNA.pdb.gz", "--json")
    report = json.loads(out)
    assert status == 0 and report["segments"] == [] and report["residues"] == 0
    assert [(c["chain"], c["nucleotides"], c["nucleic_acid"]) for c in report["chains"]] == [("A", 12, "DNA"),
                                                                                           ("B", 12, "DNA")]
    status, out, _ = run(capsys, "info", DATA / "4OPJ.pdb.gz", "--json")  # RNase H on DNA with a modified base
    chains = {c["chain"]: c for c in json.loads(out)["chains"]}
    assert status == 0 and chains["A"]["nucleotides"] == 0 and chains["A"]["segments"] == 1
    assert chains["B"]["nucleotides"] == chains["D"]["nucleotides"] == 12  # its TCY counted with the 11 others
    status, out, _ = run(capsys, "info", DATA / "1LCD.cif.gz")  # a protein beside its DNA operator
    assert status == 0 and "nucleic acids: chain B 11 nucleotides (DNA), chain C 11 nucleotides (DNA)" in out
    assert "A:MET1" in out


def read_csv(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_curve_csv_has_the_contract_header_and_consistent_rows(capsys):
    status, out, _ = run(capsys, "curve", DATA / "1UBQ.pdb.gz", "--level", "3.5", "--csv")
    assert status == 0
    assert out.splitlines()[0] == "chain,segment,resseq,icode,resname,ss,ca_x,ca_y,ca_z,cr_x,cr_y,cr_z,dist"
    rows = read_csv(out)
    assert len(rows) == 76 and {r["ss"] for r in rows} <= {"H", "E", "C"}
    ca = np.array([[float(r[f"ca_{a}"]) for a in "xyz"] for r in rows])
    cr = np.array([[float(r[f"cr_{a}"]) for a in "xyz"] for r in rows])
    assert np.allclose(np.linalg.norm(ca - cr, axis=1), [float(r["dist"]) for r in rows], atol=2e-3)
    assert np.sqrt(np.mean(np.sum((ca - cr) ** 2, axis=1))) > 2.0  # a smooth low-resolution curve


def test_curve_defaults_to_full_resolution_and_calpha_passes_through_calpha(capsys):
    _, out, _ = run(capsys, "curve", DATA / "1UBQ.pdb.gz", "--ribbon", "calpha", "--csv")
    assert max(float(r["dist"]) for r in read_csv(out)) < 1e-3
    _, above, _ = run(capsys, "curve", DATA / "1UBQ.pdb.gz", "--csv", "--level", "20")
    _, full, _ = run(capsys, "curve", DATA / "1UBQ.pdb.gz", "--csv")
    assert above == full


def test_curve_uses_each_segments_own_maximum_level(capsys):
    _, out, _ = run(capsys, "curve", DATA / "1F9V.pdb.gz", "--chain", "A", "--csv", "--level", "5.5")
    rows = read_csv(out)
    segments = {r["segment"] for r in rows}
    assert len(segments) == len(read_structure(DATA / "1F9V.pdb.gz").segments)
    # a segment shorter than 2**5.5 residues is at full resolution at level 5.5
    short = [r for r in rows if r["segment"] == "2"]  # 19 residues: log2 19 < 5.5
    _, full, _ = run(capsys, "curve", DATA / "1F9V.pdb.gz", "--chain", "A", "--csv")
    assert short == [r for r in read_csv(full) if r["segment"] == "2"]


def test_curve_of_multicharacter_chains(capsys):
    status, out, _ = run(capsys, "curve", DATA / "7Z9T.cif.gz", "--chain", "BBB", "--csv")
    assert status == 0 and {r["chain"] for r in read_csv(out)} == {"BBB"}


@pytest.mark.parametrize("name", AWKWARD)
def test_zero_edit_reproduces_every_awkward_entry(capsys, tmp_path, name):
    structure = read_structure(DATA / name)
    segment = structure.segments[0]
    suffix = ".cif" if name.endswith(".cif.gz") else ".pdb"
    out = tmp_path / f"same{suffix}"
    status, printed, err = run(capsys, "edit", DATA / name, "--chain", segment.chain, "--level", "2",
                               "--point", "3", "--move", "0,0,0", "-o", out)
    assert status == 0, err
    assert "moved 0 residues" in printed
    assert np.allclose(read_structure(out).coords, structure.coords, atol=5e-4)


def test_edit_at_the_finest_level_moves_four_residues_and_turns_their_neighbours(capsys, tmp_path):
    """A finest control point carries the curve points of four residues; the three on each
    side turn with the curve around them, about their own curve points."""
    out = tmp_path / "edited.pdb"
    status, printed, _ = run(capsys, "edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "6.25",
                             "--point", "65", "--move", "2,0,-1", "-o", out)
    assert status == 0 and "moved 10 residues" in printed
    before, after = read_structure(DATA / "1UBQ.pdb.gz"), read_structure(out)
    moved = np.flatnonzero(np.linalg.norm(after.coords - before.coords, axis=1) > 1e-3)
    residues = np.unique(before.atom_residue[moved])
    assert len(residues) == 10 and np.all(np.diff(residues) == 1)
    ca = ca_rows(before)[residues]
    shift = np.linalg.norm(after.coords[ca] - before.coords[ca], axis=1)
    assert shift.argmax() in (4, 5) and shift[4:6].min() > 5.0 * shift[[0, 1, 2, 7, 8, 9]].max()


def test_edit_of_a_residue_curve_point(capsys, tmp_path):
    out = tmp_path / "tugged.cif"
    status, printed, _ = run(capsys, "edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "4",
                             "--residue", "35", "--move", "0,3,0", "-o", out)
    assert status == 0 and "moved" in printed
    assert not np.allclose(read_structure(out).coords, read_structure(DATA / "1UBQ.pdb.gz").coords, atol=1e-2)


def test_edit_never_overwrites_without_asking(capsys, tmp_path):
    out = tmp_path / "existing.pdb"
    out.write_text("keep me")
    status, _, err = run(capsys, "edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "3",
                         "--point", "2", "--move", "1,0,0", "-o", out)
    assert status == 1 and "--overwrite" in err and out.read_text() == "keep me"
    status, _, _ = run(capsys, "edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "3",
                       "--point", "2", "--move", "1,0,0", "-o", out, "--overwrite")
    assert status == 0 and read_structure(out).n_atoms == read_structure(DATA / "1UBQ.pdb.gz").n_atoms


@pytest.mark.parametrize(
    "argv, message",
    [
        (["info", "missing.pdb"], "no such file"),
        (["curve", DATA / "1BNA.pdb.gz"], "no protein chain"),
        (["curve", DATA / "1UBQ.pdb.gz", "--chain", "Z"], "no protein chain 'Z'"),
        (["edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "3", "--point", "99", "--move", "1,0,0", "-o", "x.pdb"],
         "index must be an integer in \\[0, 10\\]"),
        (["edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--segment", "3", "--level", "3", "--point", "1", "--move",
          "1,0,0", "-o", "x.pdb"], "has 1 segment"),
        (["edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "3", "--residue", "500", "--move", "1,0,0", "-o",
          "x.pdb"], "no residue 500"),
        (["info", DATA / "1L2Y.pdb.gz", "--model", "39"], "no model 39; the file has 38 model"),
        (["edit", DATA / "1LCD.cif.gz", "--model", "4", "--chain", "A", "--level", "3", "--point", "1", "--move",
          "1,0,0", "-o", "x.pdb"], "no model 4; the file has 3 model"),
        (["curve", DATA / "2BEG.pdb.gz", "--model", "2"], "no model 2; the file has 1 model"),
        (["validate", DATA / "1L2Y.pdb.gz", "--model", "100"], "no model 100"),
        (["surface", DATA / "1L2Y.pdb.gz", "--model", "40", "-o", "x.vtp"], "no model 40"),
    ],
)
def test_bad_input_is_one_line_and_exit_status_1(capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    status, _, err = run(capsys, *argv)
    assert status == 1
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert re.search(message, err)


def test_negative_displacements_need_no_equals_sign(capsys, tmp_path):
    out = tmp_path / "left.pdb"
    status, printed, _ = run(capsys, "edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "4",
                             "--point", "8", "--move", "-3,4,-0.5", "-o", out)
    assert status == 0 and "moved 38 residues" in printed


def test_usage_errors_exit_2(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["edit", str(DATA / "1UBQ.pdb.gz"), "--chain", "A", "--level", "3", "--point", "1", "--move", "1,0",
              "-o", "x.pdb"])
    assert exit_info.value.code == 2
    assert "DX,DY,DZ" in capsys.readouterr().err


@pytest.mark.parametrize("model", ["0", "-2", "1.5", "one"])
def test_a_model_that_is_not_a_positive_whole_number_is_a_usage_error(capsys, model):
    with pytest.raises(SystemExit) as exit_info:
        main(["info", str(DATA / "1L2Y.pdb.gz"), f"--model={model}"])
    assert exit_info.value.code == 2 and "--model" in capsys.readouterr().err


# ----------------------------------------------------------------------------- ensembles


def test_info_says_which_model_of_how_many(capsys):
    _, first, _ = run(capsys, "info", DATA / "1L2Y.pdb.gz")
    _, seventh, _ = run(capsys, "info", DATA / "1L2Y.pdb.gz", "--model", "7")
    _, single, _ = run(capsys, "info", DATA / "1UBQ.pdb.gz")
    assert "model 1 of 38" in first and "model 7 of 38" in seventh and "; 1 model" in single
    status, out, _ = run(capsys, "info", DATA / "1LCD.cif.gz", "--model", "3", "--json")
    report = json.loads(out)
    assert status == 0 and (report["model"], report["models"]) == (3, 3)
    assert report["atoms"] == read_structure(DATA / "1LCD.cif.gz", model=3).n_atoms == 1122  # model 1 has 1137


def test_curve_and_validate_read_the_model_asked(capsys):
    model = read_structure(DATA / "1L2Y.pdb.gz", model=12)
    _, out, _ = run(capsys, "curve", DATA / "1L2Y.pdb.gz", "--model", "12", "--csv")
    ca = np.array([[float(r[f"ca_{a}"]) for a in "xyz"] for r in read_csv(out)])
    np.testing.assert_allclose(ca, model.segments[0].ca, atol=5e-4)
    assert not np.allclose(ca, read_structure(DATA / "1L2Y.pdb.gz").segments[0].ca, atol=0.1)
    _, out, _ = run(capsys, "validate", DATA / "1LCD.cif.gz", "--model", "2", "--json")
    assert json.loads(out)["model"] == 2
    _, text, _ = run(capsys, "validate", DATA / "1LCD.cif.gz", "--model", "2")
    assert text.startswith(f"{DATA / '1LCD.cif.gz'}: 1LCD model 2 of 3, ")


@pytest.mark.parametrize(("name", "model", "suffix"), [("1L2Y.pdb.gz", 5, ".pdb"), ("1LCD.cif.gz", 2, ".cif")])
def test_edit_of_one_model_leaves_every_other_model_as_read(capsys, tmp_path, name, model, suffix):
    out = tmp_path / f"edited{suffix}"
    status, printed, _ = run(capsys, "edit", DATA / name, "--model", str(model), "--chain", "A", "--level", "2",
                             "--point", "2", "--move", "1.5,0,-1", "-o", out)
    assert status == 0 and f"atoms of model {model}; wrote {out}" in printed
    before, after = read_structure(DATA / name, model=model), read_structure(out, model=model)
    moved = np.any(after.coords != before.coords, axis=1)
    assert np.any(np.abs(after.coords - before.coords) > 0.5, axis=1).sum() > 100
    for other in (1, model - 1, model + 1, before.n_models):
        if other != model:
            np.testing.assert_array_equal(read_structure(out, model=other).coords,
                                          read_structure(DATA / name, model=other).coords)
    original = gzip.decompress((DATA / name).read_bytes()).decode().splitlines()
    written = out.read_text().splitlines()
    assert len(written) == len(original)
    assert sum(a != b for a, b in zip(written, original)) == moved.sum()  # the moved atoms' lines alone


def test_a_message_quoting_a_name_never_sends_it_raw_to_the_terminal(tmp_path, capsys):
    """A file named with an escape sequence (as a folder of downloads may hold) is quoted in the
    message escaped, so it cannot clear or recolour the user's terminal (#37)."""
    path = tmp_path / "\x1b[2J\x1b[31mentry.pdb"
    path.write_text("not a structure\n")
    assert main(["info", str(path)]) == 1
    err = capsys.readouterr().err
    assert "\x1b" not in err and "\\x1b[2J\\x1b[31mentry.pdb" in err and "not a structure file" in err
