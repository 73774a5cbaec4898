"""The ``fit`` and ``morph`` commands on adenylate kinase's two conformations (#19)."""

import json
from pathlib import Path

import gemmi
import numpy as np

from app.main import main
from core.analysis.superpose import superpose
from core.protein.reading import read_structure
from core.protein.structure import ca_rows

DATA = Path(__file__).resolve().parents[2] / "data"
CLOSED, OPEN = DATA / "1AKE_adk_closed.pdb.gz", DATA / "4AKE_adk_open.pdb.gz"


def run(capsys, *argv: object) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_fit_prints_a_line_per_level_and_writes_the_moved_model(capsys, tmp_path: Path) -> None:
    out = tmp_path / "fitted.cif"
    status, text, _ = run(capsys, "fit", CLOSED, "--to", OPEN, "--levels", "2-5", "-o", out)
    assert status == 0
    lines = [line for line in text.splitlines() if line.strip().startswith("level")]
    assert [line.split()[1] for line in lines] == ["2:", "3:", "4:", "5:"]
    assert "11 control points" in lines[1] and f"wrote {out}" in text
    fitted, target = read_structure(out), read_structure(OPEN)
    rows = ca_rows(fitted)
    assert superpose(fitted.coords[rows], target.segments[0].ca).rmsd < 2.5
    assert fitted.n_atoms == read_structure(CLOSED).n_atoms  # ligand and waters kept


def test_fit_json_and_refusals(capsys, tmp_path: Path) -> None:
    out = tmp_path / "fitted.pdb"
    status, text, _ = run(capsys, "fit", OPEN, "--to", CLOSED, "-o", out, "--json")
    report = json.loads(text)
    assert status == 0 and report["pairing"] == "numbering" and report["pairs"] == 214
    assert [level["level"] for level in report["levels"]] == list(range(7))
    assert report["rmsd"] <= 1.5 and report["validation"]["peptide_bond"]["after"] == 0
    status, _, err = run(capsys, "fit", OPEN, "--to", CLOSED, "-o", out)
    assert status == 1 and "pass --overwrite" in err
    status, _, err = run(capsys, "fit", OPEN, "--to", DATA / "1UBQ.pdb.gz", "-o", tmp_path / "x.pdb")
    assert status == 1 and "another fold" in err and not (tmp_path / "x.pdb").exists()
    status, _, err = run(capsys, "fit", OPEN, "--to", CLOSED, "--chain", "Q", "-o", tmp_path / "y.pdb")
    assert status == 1 and "no protein chain 'Q'" in err


def test_morph_writes_a_movie_that_ends_at_the_target(capsys, tmp_path: Path) -> None:
    movie = tmp_path / "morph.pdb"
    status, text, _ = run(capsys, "morph", CLOSED, OPEN, "--frames", "10", "--levels", "0-6", "-o", movie)
    assert status == 0 and "wrote 11 frames" in text
    models = gemmi.read_structure(str(movie))
    assert len(models) == 11
    first = np.array([cra.atom.pos.tolist() for cra in models[0].all()])
    np.testing.assert_allclose(first, read_structure(CLOSED).coords, atol=1e-3)
    last = read_structure(movie, model=11)
    assert superpose(last.coords[ca_rows(last)], read_structure(OPEN).segments[0].ca).rmsd < 1.5


def test_morph_refuses_bad_frames_and_chains(capsys, tmp_path: Path) -> None:
    status, _, err = run(capsys, "morph", CLOSED, OPEN, "--frames", "0", "-o", tmp_path / "m.pdb")
    assert status == 1 and "--frames" in err
    status, _, err = run(capsys, "morph", CLOSED, OPEN, "--chains", "A", "-o", tmp_path / "m.pdb")
    assert status == 1 and "X:Y" in err
