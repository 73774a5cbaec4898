"""Maps as other programs write them: the same density written by ``mrcfile`` in every
convention of the CCP4/MRC format reads back with each voxel where the format puts it, so
that a model sits in its density (the map's values at the atoms are those of the map it
was cut from)."""

from __future__ import annotations

import gzip
import warnings
from pathlib import Path

import gemmi
import mrcfile
import numpy as np
import pytest

from core.protein.reading import read_atoms
from core.surfaces.map_file import read_map
from core.surfaces.volume import DensityMap, MapError, model_density
from tests.conftest import write_mrc

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.fixture(scope="module")
def placed() -> tuple[DensityMap, np.ndarray]:
    """Ubiquitin's density on a grid of about 1 Å whose corner lies on a multiple of the
    spacing, and the atoms (moved with it) that it is the density of."""
    atoms = read_atoms(DATA / "1UBQ.pdb.gz")
    density = model_density(atoms, spacing=1.0, resolution=4.0)
    step = np.diag(density.axes)
    corner = np.round(density.origin / step) * step
    return DensityMap(density.values, corner, density.axes), atoms.coords + corner - density.origin


def values_at_atoms(path: Path, atoms: np.ndarray) -> np.ndarray:
    return read_map(path).interpolate(atoms)


def step(density: DensityMap) -> np.ndarray:
    return np.diag(density.axes)


def start_of(density: DensityMap) -> tuple[int, int, int]:
    return tuple(int(i) for i in np.round(density.origin / step(density)))


CONVENTIONS = {
    "mrc2014-origin": lambda d: {"origin": tuple(d.origin)},
    "ccp4-start": lambda d: {"start": start_of(d)},
    "axes-312-start": lambda d: {"axis_order": (3, 1, 2), "start": start_of(d)},
    "axes-231-origin": lambda d: {"axis_order": (2, 3, 1), "origin": tuple(d.origin)},
    "cell-larger-than-box": lambda d: {"start": start_of(d), "sampling": tuple(np.array(d.values.shape) + 17)},
    "gzipped": lambda d: {"origin": tuple(d.origin), "gzipped": True},
    "machine-stamp-0": lambda d: {"start": start_of(d), "edit": lambda mrc: mrc.header.machst.fill(0)},
    "origin-wins-over-start": lambda d: {"origin": tuple(d.origin), "start": (7, -3, 11)},
}


@pytest.mark.parametrize("convention", CONVENTIONS)
def test_every_convention_puts_the_density_on_the_model(tmp_path: Path, placed, convention: str) -> None:
    density, atoms = placed
    path = write_mrc(tmp_path / "map.mrc", density.values, step=step(density), **CONVENTIONS[convention](density))
    with warnings.catch_warnings():  # (mrcfile warns of a zero machine stamp)
        warnings.simplefilter("ignore", RuntimeWarning)
        mrc = mrcfile.open(path, permissive=True)
    with mrc:  # mrcfile reads what was meant to be written
        assert mrc.data.shape == tuple(density.values.shape[a - 1] for a in (mrc.header.maps, mrc.header.mapr, mrc.header.mapc))
    expected = density.interpolate(atoms)
    assert np.median(expected) > density.sigma_level(3.0)
    assert np.allclose(values_at_atoms(path, atoms), expected, rtol=1e-5, atol=1e-6)


def test_a_box_smaller_than_its_cell_repeats_with_the_cell(tmp_path: Path, placed) -> None:
    density, atoms = placed
    sampling = np.array(density.values.shape) + 17
    path = write_mrc(tmp_path / "map.ccp4", density.values, start=start_of(density), sampling=tuple(sampling), step=step(density))
    read = read_map(path)
    assert read.periodic and read.values.shape == tuple(sampling)
    lattice = step(density) * sampling * np.array([1, -2, 3])  # one lattice vector of the cell
    assert np.allclose(read.interpolate(atoms + lattice), density.interpolate(atoms), rtol=1e-5, atol=1e-6)
    mesh = read.contour_around(density.sigma_level(1.0), atoms.mean(axis=0) + lattice, 12.0)
    assert mesh.n_faces > 0  # drawn around a centre in another cell


@pytest.mark.parametrize("dtype, mode", [(np.int8, 0), (np.int16, 1), (np.uint16, 6), (np.float16, 12)])
def test_integer_and_half_precision_modes(tmp_path: Path, placed, dtype: type, mode: int) -> None:
    density, atoms = placed
    top = {np.int8: 120, np.int16: 30000, np.uint16: 60000, np.float16: 1000}[dtype]
    scaled = np.round(density.values / density.values.max() * top) if dtype is not np.float16 else density.values
    path = write_mrc(tmp_path / "map.mrc", scaled, origin=tuple(density.origin), step=step(density), dtype=dtype)
    with mrcfile.open(path) as mrc:
        assert mrc.header.mode == mode
    read = read_map(path)
    assert np.corrcoef(read.interpolate(atoms), density.interpolate(atoms))[0, 1] > 0.999


def test_a_big_endian_map_with_no_machine_stamp(tmp_path: Path, placed) -> None:
    """Byte order guessed from the header, as permissive readers guess it."""
    density, atoms = placed
    little = write_mrc(tmp_path / "little.mrc", density.values, start=start_of(density), step=step(density))
    raw = bytearray(little.read_bytes())
    words = np.frombuffer(bytes(raw[:1024]), dtype="<i4").copy()
    words[:56].byteswap(inplace=True)  # numbers; the 'MAP ' word (52) and labels are text
    words[52] = np.frombuffer(b"MAP ", dtype="<i4")[0]
    words[53] = 0  # machine stamp
    header = bytearray(words.tobytes())
    header[224:] = raw[224:1024]
    body = np.frombuffer(bytes(raw[1024:]), dtype="<f4").astype(">f4").tobytes()
    big = tmp_path / "big.mrc"
    big.write_bytes(bytes(header) + body)
    assert np.allclose(values_at_atoms(big, atoms), density.interpolate(atoms), rtol=1e-5, atol=1e-6)


def test_an_asymmetric_unit_is_completed_by_its_symmetry(tmp_path: Path) -> None:
    """A map of one asymmetric unit of a P 21 21 21 crystal (0 ≤ x, y ≤ ½) reads as the
    whole cell: the density of every symmetry mate is there, in any cell."""
    structure = gemmi.read_structure(str(DATA / "1UBQ.pdb.gz"))
    structure.remove_waters()
    structure.setup_entities()
    calculator = gemmi.DensityCalculatorX()
    calculator.d_min = 4.0
    calculator.grid.setup_from(structure, 1.0)
    calculator.put_model_density_on_grid(structure[0])
    grid = calculator.grid
    assert grid.spacegroup.number == 19
    whole = np.array(grid.array, dtype=np.float32)
    shape = np.array(whole.shape)
    half = whole[: shape[0] // 2 + 1, : shape[1] // 2 + 1, :]
    cell = grid.unit_cell
    path = write_mrc(tmp_path / "asu.ccp4", half, sampling=tuple(shape), spacegroup=19,
                 edit=lambda mrc: setattr(mrc.header, "cella", (cell.a, cell.b, cell.c)))
    read = read_map(path)
    assert read.periodic and read.values.shape == tuple(shape)
    assert np.allclose(read.values, whole, atol=1e-4 * whole.max())
    atoms = [atom.pos for residue in structure[0][0] for atom in residue][:50]
    fractional = np.array([cell.fractionalize(position).tolist() for position in atoms])
    orth = np.array(cell.orth.mat.tolist())
    operations = list(grid.spacegroup.operations())
    assert len(operations) == 4
    at_atoms = read.interpolate(fractional @ orth.T)
    assert np.median(at_atoms) > read.sigma_level(1.0)
    for op in operations:
        mates = np.array([op.apply_to_xyz(f.tolist()) for f in fractional]) + [1, -1, 2]  # in another cell
        assert np.allclose(read.interpolate(mates @ orth.T), at_atoms, atol=1e-4 * whole.max())


def test_the_resolution_in_a_header_label(tmp_path: Path, placed) -> None:
    density, _ = placed

    def label(mrc: mrcfile.mrcfile.MrcFile) -> None:
        mrc.header.label[0] = b"relion_postprocess: final resolution 3.4 Angstroms"
        mrc.header.nlabl = 1

    assert read_map(write_mrc(tmp_path / "labelled.mrc", density.values, edit=label)).resolution == 3.4
    assert read_map(write_mrc(tmp_path / "plain.mrc", density.values)).resolution is None


def test_what_cannot_be_read_is_refused_saying_why(tmp_path: Path, placed) -> None:
    density, _ = placed
    good = write_mrc(tmp_path / "good.mrc", density.values).read_bytes()

    def refused(name: str, content: bytes, reason: str) -> None:
        path = tmp_path / name
        path.write_bytes(content)
        with pytest.raises(MapError, match=reason):
            read_map(path)

    with pytest.raises(MapError, match="no such file"):
        read_map(tmp_path / "missing.ccp4")
    with pytest.raises(MapError, match="not a regular file"):
        read_map(tmp_path)
    refused("short.mrc", good[:500], "shorter than a map's 1024-byte header")
    refused("truncated.mrc", good[:-4000], "truncated")
    refused("truncated.mrc.gz", gzip.compress(good[:-4000]), "truncated")
    refused("junk.map", b"not a map at all" * 100, "in neither byte order")
    refused("not-gzip.mrc.gz", b"\x1f\x8b" + good[2:], "not a readable CCP4/MRC map")

    def patched(**words: int) -> bytes:
        header = np.frombuffer(good[:1024], dtype="<i4").copy()
        for word, value in words.items():
            header[int(word.removeprefix("w"))] = value
        return header.tobytes() + good[1024:]

    refused("complex.mrc", patched(w3=4), "complex")
    refused("mode-9.mrc", patched(w3=9), "not a mode of density values")
    refused("axes.mrc", patched(w16=2), "not an order of 1, 2, 3")
    refused("huge.mrc", patched(w0=60000, w1=60000, w2=60000), "larger than")
    refused("extended.mrc", patched(w23=4000)[:-100], "truncated")
    refused("empty-grid.mrc", patched(w1=0), "is not a size")


def test_what_other_readers_forgive_is_forgiven(tmp_path: Path, placed) -> None:
    """As ChimeraX reads them: ORIGIN words left unset (huge, as RELION 2.0 left them) or in
    a file without the MRC-2014 'MAP ' word place nothing; start indices far beyond the grid
    are unset; a header counting symmetry records the file lacks; IMOD's unsigned bytes."""
    density, atoms = placed
    expected = density.interpolate(atoms)
    start = start_of(density)

    def patched(path: Path, **words: float) -> Path:
        raw = bytearray(path.read_bytes())
        for word, value in words.items():
            k = int(word.removeprefix("w"))
            raw[4 * k : 4 * k + 4] = np.array(value, dtype="<f4" if isinstance(value, float) else "<i4").tobytes()
        path.write_bytes(bytes(raw))
        return path

    unset = write_mrc(tmp_path / "unset.mrc", density.values, start=start, step=step(density))
    patched(unset, w49=1e30, w50=1e30, w51=1e30)
    assert np.allclose(read_map(unset).interpolate(atoms), expected, rtol=1e-5, atol=1e-6)
    old_style = write_mrc(tmp_path / "old.mrc", density.values, start=start, origin=(500.0, 500.0, 500.0),
                          step=step(density))
    patched(old_style, w52=0)  # no 'MAP ': the words are not an origin
    assert np.allclose(read_map(old_style).interpolate(atoms), expected, rtol=1e-5, atol=1e-6)
    garbage = write_mrc(tmp_path / "garbage.mrc", density.values, start=(10**8, 0, 0), step=step(density))
    assert np.allclose(read_map(garbage).origin, 0.0)
    lacking = patched(write_mrc(tmp_path / "lacking.mrc", density.values, start=start, step=step(density)), w23=800)
    assert np.allclose(read_map(lacking).interpolate(atoms), expected, rtol=1e-5, atol=1e-6)
    scaled = np.round(density.values / density.values.max() * 250).astype(np.uint8)
    imod = tmp_path / "imod.mrc"
    write_mrc(imod, scaled.view(np.int8), start=start, step=step(density), dtype=np.int8)
    patched(imod, w38=1146047817, w39=0)  # IMOD's stamp, its bytes unsigned
    assert read_map(imod).values.max() == 250 and read_map(imod).values.min() >= 0
