"""Maps of MTZ map coefficients: columns found as refinement programs name them, the
2mFo−DFc map on the model, the difference map's peaks where the model lacks atoms."""

from __future__ import annotations

from pathlib import Path

import gemmi
import numpy as np
import pytest

from core.surfaces.map_coefficients import column_pairs, read_mtz
from core.surfaces.map_file import read_map
from core.surfaces.volume import MapError
from tests.conftest import D_MIN, MISSING, write_mtz

DATA = Path(__file__).resolve().parents[2] / "data"
@pytest.fixture(scope="module")
def atoms() -> np.ndarray:
    structure = gemmi.read_structure(str(DATA / "1UBQ.pdb.gz"))
    structure.remove_waters()
    return np.array([[a.pos.x, a.pos.y, a.pos.z, r.seqid.num] for r in structure[0][0] for a in r])


@pytest.mark.parametrize("density, difference", [("FWT PHWT", "DELFWT PHDELWT"), ("2FOFCWT PH2FOFCWT", "FOFCWT PHFOFCWT"),
                                                 ("FWT PHWT", None)])
def test_the_maps_of_the_columns_refinement_writes(tmp_path: Path, atoms: np.ndarray, density: str,
                                                  difference: str | None) -> None:
    path = write_mtz(tmp_path / "refined.mtz", density, difference)
    maps = read_mtz(path)
    assert maps.columns == tuple(density.split())
    assert maps.density.periodic and maps.density.resolution == pytest.approx(D_MIN, abs=0.05)
    positions = atoms[:, :3]
    assert np.median(maps.density.interpolate(positions)) > maps.density.sigma_level(1.5)
    assert np.median(maps.density.interpolate(positions + [37.0, -11.0, 5.0])) < maps.density.sigma_level(1.0)
    if difference is None:
        assert maps.difference is None
        return
    assert maps.difference_columns == tuple(difference.split())
    missing = np.isin(atoms[:, 3], MISSING)
    at = maps.difference.interpolate(positions)
    assert np.median(at[missing]) > maps.difference.sigma_level(3.0)  # green where the model lacks atoms
    assert np.median(at[~missing]) < maps.difference.sigma_level(1.0)
    assert np.array_equal(read_map(path).values, maps.density.values)  # read_map takes an MTZ too


def test_columns_chosen_by_name_and_refused_with_those_there_are(tmp_path: Path) -> None:
    path = write_mtz(tmp_path / "odd.mtz", "FCALC PHCALC", "FDIFF PHDIFF")
    assert column_pairs(path) == [("FCALC", "PHCALC"), ("FDIFF", "PHDIFF")]
    with pytest.raises(MapError, match="no 2mFo−DFc columns.*FCALC"):
        read_mtz(path)
    chosen = read_mtz(path, ("FDIFF", "PHDIFF"))
    assert chosen.columns == ("FDIFF", "PHDIFF") and chosen.difference is None
    with pytest.raises(MapError, match="no amplitude column 'FOO'"):
        read_mtz(path, ("FOO", "PHCALC"))
    broken = tmp_path / "broken.mtz"
    broken.write_bytes(b"MTZ " + b"\0" * 300)
    with pytest.raises(MapError, match="not a readable MTZ file"):
        read_map(broken)
