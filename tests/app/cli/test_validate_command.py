"""``ribbonwave validate`` and ``ribbonwave edit --regularize`` on real entries, through ``main``."""

import json
from pathlib import Path

import numpy as np

from app.main import main
from core.geometry.validation import validate
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


def run(capsys, *argv: object) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_validate_json_is_the_core_report(capsys):
    status, out, _ = run(capsys, "validate", DATA / "4HHB.pdb.gz", "--json", "--worst", "-1")
    assert status == 0
    data = json.loads(out)
    report = validate(read_structure(DATA / "4HHB.pdb.gz"))
    assert data["counts"] == report.counts and data["checked"] == report.checked
    assert len(data["flags"]) == len(report.flags) > 1000
    severities = [f["severity"] for f in data["flags"]]
    assert severities == sorted(severities, reverse=True)
    assert data["flags"][0]["where"] == "B:VAL1-B:HIS2" and data["flags"][0]["kind"] == "peptide_bond"


def test_validate_text_lists_counts_and_worst(capsys):
    status, out, _ = run(capsys, "validate", DATA / "1BD2.pdb.gz", "--worst", "3")
    assert status == 0
    lines = out.splitlines()
    assert lines[0].startswith(f"{DATA / '1BD2.pdb.gz'}: 1BD2, 808 junctions")
    assert any("cis peptides" in line and line.split()[0] == "5" for line in lines)
    worst = lines[lines.index("worst 3:") + 1 :]
    assert len(worst) == 3 and "D:ASN194 O / D:ASN195 CG" in worst[0]


def test_validate_bad_input_is_one_line(capsys, tmp_path):
    status, out, err = run(capsys, "validate", tmp_path / "missing.pdb")
    assert status == 1 and out == "" and err.count("\n") == 1 and "no such file" in err
    status, _, err = run(capsys, "validate", DATA / "1UBQ.pdb.gz", "--worst", "-1")
    assert status == 1 and "--worst" in err


def test_edit_regularize_writes_a_chemically_sensible_model(capsys, tmp_path):
    out_plain, out_regular = tmp_path / "plain.pdb", tmp_path / "regular.pdb"
    argv = ("edit", DATA / "1UBQ.pdb.gz", "--chain", "A", "--level", "3", "--point", "4", "--move=-3,4,0")
    status, _, _ = run(capsys, *argv, "-o", out_plain)
    assert status == 0
    status, out, _ = run(capsys, *argv, "-o", out_regular, "--regularize")
    assert status == 0 and "regularized:" in out
    plain, regular = validate(read_structure(out_plain)), validate(read_structure(out_regular))
    original = validate(read_structure(DATA / "1UBQ.pdb.gz"))
    assert plain.counts["peptide_bond"] > 5
    assert regular.counts["peptide_bond"] == regular.counts["ca_ca"] == 0
    assert {f.where for f in regular.flags if f.kind == "clash"} <= {f.where for f in original.flags if f.kind == "clash"}
    # only coordinates change: same atoms in the same order
    a, b = read_structure(out_plain).atoms, read_structure(out_regular).atoms
    assert np.array_equal(a.name, b.name) and not np.allclose(a.coords, b.coords)
