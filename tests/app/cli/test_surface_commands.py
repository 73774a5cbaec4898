"""``ribbonwave surface``: every kind written as .vtp/.ply/.png, read back with pyvista;
bad input gives one line and exit status 1."""

from __future__ import annotations

from pathlib import Path

import gemmi
import numpy as np
import pytest
import pyvista as pv

from app.main import main
from core.protein.reading import read_atoms
from core.surfaces.volume import model_density
from tests.conftest import write_mtz

DATA = Path(__file__).resolve().parents[2] / "data"


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    status = main(["surface", *args])
    out, err = capsys.readouterr()
    return status, out, err


def test_ses_of_ubiquitin_as_vtp_with_potential(tmp_path: Path, capsys) -> None:
    out = tmp_path / "ubq.vtp"
    status, text, _ = run(capsys, str(DATA / "1UBQ.pdb.gz"), "--color", "potential", "-o", str(out))
    assert status == 0 and "closed" in text
    mesh = pv.read(out)
    assert mesh.n_open_edges == 0 and mesh.is_manifold
    potential = mesh.point_data["potential"]
    assert potential.min() < -5 < 5 < potential.max()
    assert abs(mesh.area - 3700) < 500


@pytest.mark.parametrize("level", ["5", "4", "3"])
def test_globe_levels_of_tim_as_ply(tmp_path: Path, capsys, level: str) -> None:
    out = tmp_path / f"globe{level}.ply"
    status, text, _ = run(capsys, str(DATA / "1TIM.pdb.gz"), "--kind", "globe", "--level", level, "-o", str(out))
    assert status == 0
    mesh = pv.read(out)
    assert mesh.n_open_edges == 0 and mesh.n_cells == 7936
    rms = {int(line.split()[0]): float(line.split()[1]) for line in text.splitlines() if line.strip()[:1].isdigit()}
    assert list(rms) == [0, 1, 2, 3, 4, 5] and rms[5] < rms[3] < rms[0]


def test_ideal_dna_png_is_rendered(tmp_path: Path, capsys) -> None:
    out = tmp_path / "dna.png"
    status, text, _ = run(capsys, "--ideal-dna", "32", "--kind", "dna", "--level", "3", "--color", "curvature", "-o", str(out))
    assert status == 0 and "open" in text
    image = pv.read(out)
    pixels = np.asarray(image.point_data[image.point_data.keys()[0]])
    assert image.dimensions[:2] == (900, 900)
    assert len(np.unique(pixels.reshape(len(pixels), -1)[:, :3], axis=0)) > 100  # a coloured surface, not a blank


def test_remesh_of_the_trypsin_pocket(tmp_path: Path, capsys) -> None:
    out = tmp_path / "pocket.vtp"
    status, text, _ = run(capsys, str(DATA / "3PTB.pdb.gz"), "--kind", "remesh", "--site", "BEN", "--level", "2", "-o", str(out))
    assert status == 0
    assert pv.read(out).n_cells == 96
    assert "rms error" in text


def test_map_from_a_ccp4_file(tmp_path: Path, capsys) -> None:
    density = model_density(read_atoms(DATA / "1UBQ.pdb.gz"))
    ccp4 = gemmi.Ccp4Map()
    size = np.diag(density.axes) * density.values.shape
    ccp4.grid = gemmi.FloatGrid(density.values, gemmi.UnitCell(*size, 90, 90, 90), gemmi.SpaceGroup("P1"))
    ccp4.update_ccp4_header()
    ccp4.write_ccp4_map(str(tmp_path / "ubq.ccp4"))
    out = tmp_path / "map.vtp"
    status, text, _ = run(capsys, str(tmp_path / "ubq.ccp4"), "--kind", "map", "--level", "0", "-o", str(out))
    assert status == 0 and pv.read(out).n_cells > 1000
    status, _, _ = run(capsys, str(DATA / "1UBQ.pdb.gz"), "--kind", "map", "--color", "bfactor", "-o", str(tmp_path / "m.vtp"))
    assert status == 0 and "bfactor" in pv.read(tmp_path / "m.vtp").point_data


def test_map_from_an_mtz_file(tmp_path: Path, capsys) -> None:
    """The 2mFo−DFc map of an MTZ, its unit cell contoured (the crystal's molecules in it)."""
    out = tmp_path / "mtz.vtp"
    status, _, _ = run(capsys, str(write_mtz(tmp_path / "refined.mtz")), "--kind", "map", "--contour", "1.5", "-o", str(out))
    mesh = pv.read(out)
    assert status == 0 and mesh.n_cells > 1000
    cell = np.array(gemmi.read_mtz_file(str(tmp_path / "refined.mtz")).cell.parameters[:3])
    assert np.all(mesh.points.min(axis=0) >= -1.0) and np.all(mesh.points.max(axis=0) <= cell + 1.0)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["1UBQ.pdb.gz", "--kind", "dna"], "rays towards the axis miss"),
        (["1UBQ.pdb.gz", "--kind", "globe", "--level", "7"], "level must be a level in [0, 5]"),
        (["1UBQ.pdb.gz", "--kind", "remesh", "--level", "2.5"], "integer level"),
        (["1UBQ.pdb.gz", "--kind", "remesh", "--site", "HEM"], "no ligand 'HEM'"),
        (["1UBQ.pdb.gz", "--site", "HEM"], "--site only applies"),
        (["missing.pdb"], "no such file"),
        (["1BNA.pdb.gz", "--kind", "map", "--color", "curvature"], "not by curvature"),
    ],
)
def test_bad_input_is_one_line_and_status_1(tmp_path: Path, capsys, args: list[str], message: str) -> None:
    args = [str(DATA / args[0]), *args[1:]]
    status, _, err = run(capsys, *args, "-o", str(tmp_path / "out.vtp"))
    assert status == 1
    assert err.count("\n") == 1 and message in err
    assert not list(tmp_path.iterdir())  # nothing written, no temporary file left


def test_output_is_never_overwritten_without_consent(tmp_path: Path, capsys) -> None:
    out = tmp_path / "keep.ply"
    out.write_text("precious")
    status, _, err = run(capsys, str(DATA / "1UBQ.pdb.gz"), "-o", str(out))
    assert status == 1 and "refusing to overwrite" in err and out.read_text() == "precious"
    status, _, _ = run(capsys, str(DATA / "1UBQ.pdb.gz"), "-o", str(out), "--overwrite")
    assert status == 0 and pv.read(out).n_cells > 1000


def test_usage_errors_exit_2(capsys) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["surface", "x.pdb", "--kind", "cube", "-o", "out.vtp"])
    assert exit_info.value.code == 2
    status, _, err = run(capsys, "-o", "out.obj")
    assert status == 1 and "unknown output type" in err
