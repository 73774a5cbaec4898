"""Map headers someone else wrote, changed field by field (#37): every one is read as a map
whose grid, placement and values make sense, or refused with a MapError naming the file;
never a traceback, an abort (grid sampling 0 was a SIGFPE) or an allocation the file cannot
back (a 4 MB gzip claiming 4.29 GB)."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from core.surfaces.map_file import read_map
from core.surfaces.volume import MapError
from tests.conftest import write_mrc

WORDS = {"NX": 0, "NY": 1, "NZ": 2, "MODE": 3, "NXSTART": 4, "NYSTART": 5, "NZSTART": 6, "MX": 7, "MY": 8, "MZ": 9,
         "CELLA.X": 10, "CELLA.Y": 11, "CELLA.Z": 12, "ALPHA": 13, "BETA": 14, "GAMMA": 15, "MAPC": 16, "MAPR": 17,
         "MAPS": 18, "DMIN": 19, "DMAX": 20, "DMEAN": 21, "ISPG": 22, "NSYMBT": 23, "EXTTYP": 26, "NVERSION": 27,
         "ORIGIN.X": 49, "ORIGIN.Y": 50, "ORIGIN.Z": 51, "MAP": 52, "MACHST": 53, "RMS": 54, "NLABL": 55}
FLOAT_WORDS = {10, 11, 12, 13, 14, 15, 19, 20, 21, 49, 50, 51, 54}
INTS = st.one_of(st.sampled_from([0, 1, -1, 2, 3, 4, 12, 65536, 2**31 - 1, -(2**31), 230, 1024]),
                 st.integers(-(2**31), 2**31 - 1))
FLOATS = st.one_of(st.sampled_from([0.0, -1.0, 1e-30, 1e30, 180.0, 179.9, 0.001, 360.0]),
                   st.floats(width=32, allow_nan=True, allow_infinity=True))


@pytest.fixture(scope="module")
def good(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 10 × 12 × 14 map of a P1 cell twice its size, placed by its start indices, as mrcfile writes it."""
    values = np.random.default_rng(5).normal(size=(10, 12, 14)).astype(np.float32)
    path = write_mrc(tmp_path_factory.mktemp("maps") / "good.mrc", values, start=(3, -2, 5),
                     sampling=(20, 24, 28), step=np.array([1.1, 0.9, 1.0]))
    return path


def _checked(path: Path) -> None:
    """``path`` reads as a sensible map, or is refused naming it."""
    try:
        density = read_map(path)
    except MapError as error:
        assert str(error).startswith(str(path))
        return
    assert density.values.ndim == 3 and min(density.values.shape) >= 1
    assert density.values.nbytes <= 4 * 2**30 and np.isfinite(density.values).all()
    assert np.isfinite(density.origin).all() and np.isfinite(density.axes).all()
    assert abs(np.linalg.det(density.axes)) > 0
    level = density.sigma_level(1.0)
    mesh = density.contour(level)
    assert np.isfinite(mesh.vertices).all()


@settings(max_examples=500, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_a_map_header_changed_field_by_field_reads_sensibly_or_is_refused(good: Path, tmp_path: Path,
                                                                          data: st.DataObject) -> None:
    raw = bytearray(good.read_bytes())
    for _ in range(data.draw(st.integers(1, 4))):
        word = data.draw(st.sampled_from(sorted(WORDS.values())))
        value = data.draw(FLOATS) if word in FLOAT_WORDS and data.draw(st.booleans()) else data.draw(INTS)
        raw[4 * word : 4 * word + 4] = np.array(value, dtype="<f4" if isinstance(value, float) else "<i4").tobytes()
    if data.draw(st.booleans()):  # the machine stamp: little, big or none
        raw[212] = data.draw(st.sampled_from([0x44, 0x11, 0x00, 0x41]))
    size = data.draw(st.sampled_from([len(raw), len(raw) - 4, 1024, len(raw) + 4000, 1000]))
    raw = raw[:size] + bytes(max(0, size - len(raw)))
    path = tmp_path / ("fuzzed.mrc.gz" if data.draw(st.booleans()) else "fuzzed.mrc")
    path.write_bytes(gzip.compress(bytes(raw), compresslevel=1) if path.suffix == ".gz" else bytes(raw))
    _checked(path)


@pytest.mark.parametrize("case", ["sampling 0", "NaN cell", "zero cell", "flat cell angles", "65536 cubed",
                                  "4 MB gzip claiming 4.29 GB", "constant values", "NaN values"])
def test_the_headers_found_by_hand(good: Path, tmp_path: Path, case: str) -> None:
    header = np.frombuffer(good.read_bytes()[:1024], dtype="<i4").copy()
    floats = header.view("<f4")
    body = good.read_bytes()[1024:]
    if case == "sampling 0":
        header[7:10] = 0
    elif case == "NaN cell":
        floats[10:16] = np.nan
    elif case == "zero cell":
        floats[10:16] = 0.0
    elif case == "flat cell angles":
        floats[13:16] = (10.0, 10.0, 170.0)  # no cell has them (its volume would be imaginary)
    elif case == "65536 cubed":
        header[0:3] = 65536
    elif case == "4 MB gzip claiming 4.29 GB":
        header[0:3] = 1024
        body = bytes(4 * 2**20)
    elif case == "constant values":
        body = np.full(len(body) // 4, 2.5, dtype="<f4").tobytes()
    else:
        body = np.full(len(body) // 4, np.nan, dtype="<f4").tobytes()
    path = tmp_path / "case.mrc.gz"
    path.write_bytes(gzip.compress(header.tobytes() + body, compresslevel=1))
    _checked(path)
    if case in ("65536 cubed", "4 MB gzip claiming 4.29 GB", "NaN values", "flat cell angles"):
        with pytest.raises(MapError):
            read_map(path)
