"""CCP4/MRC map files read as the format says (MRC-2014 and CCP4's conventions), where each
voxel lies as ``mrcfile`` and ChimeraX place it.

- **Byte order** from the machine stamp, or, where a program wrote none (0, as iMOD and
  Situs do), from the header itself: the order in which the mode, the grid size and the
  axis order make sense.
- **Modes** 0 (int8), 1 (int16), 2 (float32), 6 (uint16) and 12 (float16).
- **Axis order** MAPC/MAPR/MAPS: the values come out indexed ``[x, y, z]``.
- **Placement**: voxel ``i`` (along x, y, z) lies at ``ORIGIN + i · step`` where the MRC-2014
  ORIGIN words are there ('MAP ' in word 53), not all zero and not so large that the grid's
  steps vanish in them (RELION 2.0 left them unset), else at ``(start + i) · step`` (at
  ``i · step`` where the start indices are unset: far beyond the grid), with the steps the
  cell's axes over their samplings (MX, MY, MZ), as ChimeraX places them.
- **Bytes** of mode 0 are signed, unsigned where IMOD's flags say so; a header that counts
  symmetry records the file lacks (some EMDB entries) is read as ChimeraX reads it.
- **Crystallographic maps**, a box smaller than its cell or a space group beyond P1, are
  periodic: they are expanded to the whole cell with the space group's symmetry (gemmi),
  and sampled around a model wherever it lies (:attr:`DensityMap.periodic`).
- gzipped files; the extended header skipped.
"""

from __future__ import annotations

import gzip
import os
import re
from pathlib import Path
from typing import BinaryIO

import gemmi
import numpy as np

from core.protein.input_files import GUNZIP_CHUNK, input_limit, limit_text
from core.surfaces.map_coefficients import is_mtz, read_mtz
from core.surfaces.volume import DensityMap, MapError

MAP_SUFFIXES = (".ccp4", ".map", ".mrc", ".mtz")
"""The file names (less a ``.gz``) that the command line reads as maps, not structures."""
MODES = {0: np.int8, 1: np.int16, 2: np.float32, 6: np.uint16, 12: np.float16}
"""The MRC modes of density values and their types (little-endian; swapped as the file says)."""
MAX_VOXELS = 1024**3
"""The largest map read (4 GiB as float32): a bigger header is refused before any data is read."""
HEADER_BYTES = 1024
IMOD_STAMP = 1146047817
"""Word 39 of a map IMOD wrote; bit 0 of word 40 set where its bytes (mode 0) are signed."""

_RESOLUTION_LABEL = re.compile(r"resolution[^0-9]{0,12}(\d+(?:\.\d+)?)", re.IGNORECASE)


def read_map(path: str | os.PathLike[str]) -> DensityMap:
    """Read the CCP4/MRC map at ``path`` (optionally gzipped), or the 2mFo−DFc map of an MTZ
    file (:func:`core.surfaces.map_coefficients.read_mtz`). A box is read as it lies; a
    crystallographic map becomes its whole unit cell, periodic. Raises :class:`MapError`
    saying why a file cannot be read."""
    path = Path(path)
    if not path.exists():
        raise MapError(f"{path}: no such file")
    if not path.is_file():
        raise MapError(f"{path}: not a regular file (a folder, device or FIFO is not read)")
    if is_mtz(path):
        return read_mtz(path).density
    with path.open("rb") as raw:
        gzipped = raw.read(2) == b"\x1f\x8b"
    try:
        with (gzip.open(path, "rb") if gzipped else path.open("rb")) as file:
            return _read(file)
    except MapError as error:
        raise MapError(f"{path}: {error}") from None
    except (OSError, EOFError, gzip.BadGzipFile) as error:
        raise MapError(f"{path}: not a readable CCP4/MRC map ({error})") from None


def _read(file: BinaryIO) -> DensityMap:
    header = file.read(HEADER_BYTES)
    if len(header) < HEADER_BYTES:
        raise MapError(f"not a CCP4/MRC map: {len(header)} bytes, shorter than a map's {HEADER_BYTES}-byte header")
    order = _byte_order(header)
    words = np.frombuffer(header, dtype=order + "i4", count=56)
    floats = np.frombuffer(header, dtype=order + "f4", count=56)
    size_crs, mode, start_crs = words[0:3], int(words[3]), words[4:7]
    sampling, cell = words[7:10].astype(np.float64), floats[10:16].astype(np.float64)
    axis_crs = _axis_order(words[16:19])
    spacegroup, extended = int(words[22]), int(words[23])
    origin = floats[49:52].astype(np.float64) if header[208:212] == b"MAP " else np.zeros(3)

    if mode in (3, 4):
        raise MapError(f"mode {mode} holds complex (Fourier) values, not a density map")
    if mode not in MODES:
        raise MapError(f"mode {mode} is not a mode of density values (0, 1, 2, 6 or 12)")
    if np.any(size_crs <= 0):
        raise MapError(f"its grid size {' × '.join(map(str, size_crs))} is not a size")
    if np.any(size_crs < 2):
        raise MapError(f"its grid {' × '.join(map(str, size_crs))} is not a volume (2 voxels or more along each axis)")
    if np.prod(size_crs, dtype=np.int64) > MAX_VOXELS:
        raise MapError(f"a grid of {' × '.join(map(str, size_crs))} voxels is larger than the {MAX_VOXELS:,} read")
    if extended < 0:
        raise MapError(f"the extended header's length ({extended} bytes) is negative")
    unsigned = mode == 0 and words[38] == IMOD_STAMP and not words[39] & 1
    dtype = np.dtype(np.uint8 if unsigned else MODES[mode]).newbyteorder(order)
    count = int(np.prod(size_crs))
    if count * (dtype.itemsize + 4) > input_limit():  # the values as stored, and as float32
        raise MapError(f"a grid of {' × '.join(map(str, size_crs))} voxels needs "
                       f"{count * (dtype.itemsize + 4) / 2**20:,.0f} MiB, more than the input limit ({limit_text()})")
    records = _read_at_most(file, extended)
    data = _read_at_most(file, count * dtype.itemsize)
    if len(data) < count * dtype.itemsize and len(records) + len(data) == count * dtype.itemsize:
        data = records + data  # symmetry records counted in the header but not in the file
    if len(data) < count * dtype.itemsize:
        raise MapError(f"truncated: {len(data):,} bytes of values where its header asks for {count * dtype.itemsize:,}")
    sections = np.frombuffer(data, dtype=dtype).reshape(size_crs[::-1])  # [section, row, column]

    # To x, y, z: the array's axes are (section, row, column), lying along axes axis_crs[::-1].
    values = np.ascontiguousarray(sections.transpose(np.argsort(axis_crs[::-1])), dtype=np.float32)
    start = np.empty(3, dtype=np.int64)
    start[axis_crs] = start_crs
    finite = np.isfinite(values)
    if not finite.any():
        raise MapError("the map holds no finite values")
    if not finite.all():
        values[~finite] = values[finite].mean(dtype=np.float64)
    if values.min() == values.max():
        raise MapError(f"the map holds one value everywhere ({values.min():g}): nothing to contour or fit")

    cell, sampling = _cell(cell, sampling, values.shape)
    axes = (np.array(gemmi.UnitCell(*cell).orth.mat.tolist()) / sampling).T  # rows: the steps along x, y, z
    if not (np.isfinite(axes).all() and abs(np.linalg.det(axes)) > 1e-3 * np.prod(np.linalg.norm(axes, axis=1))):
        raise MapError(f"its cell angles {', '.join(f'{a:g}' for a in cell[3:])}° make no cell (they enclose no volume)")
    corner = origin if _placed_by(origin, axes) else start @ axes if _placed_by_start(start, values.shape, sampling) \
        else np.zeros(3)
    resolution = _resolution(header, words)
    if spacegroup > 1 or np.any(values.shape < sampling):
        whole = _unit_cell(values, start, sampling.astype(int), gemmi.UnitCell(*cell), spacegroup)
        return DensityMap(whole, corner - start @ axes, axes, periodic=True, resolution=resolution)
    return DensityMap(values, corner, axes, resolution=resolution)


def _read_at_most(file: BinaryIO, size: int) -> bytes:
    """Up to ``size`` bytes of ``file``, read in pieces: a header that claims more than a
    (gzipped) file holds never allocates what it claims."""
    chunks, left = [], size
    while left > 0 and (chunk := file.read(min(left, GUNZIP_CHUNK))):
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _placed_by(origin: np.ndarray, axes: np.ndarray) -> bool:
    """Whether the ORIGIN words place the map: not all zero, finite, and not so large that
    a grid step vanishes in them."""
    steps = np.linalg.norm(axes, axis=1)
    return bool(np.any(origin != 0) and np.all(np.isfinite(origin)) and np.all(origin + steps != origin))


def _placed_by_start(start: np.ndarray, shape: tuple[int, ...], sampling: np.ndarray) -> bool:
    """Whether the start indices are set: within ten grids of 0 (as ChimeraX judges them)."""
    return bool(np.all(np.abs(start) <= 10 * max(max(shape), sampling.max())))


def _byte_order(header: bytes) -> str:
    """``"<"`` or ``">"``: from the machine stamp (word 54), else the order in which the
    header reads as a map."""
    stamp = header[212]
    if stamp in (0x44, 0x41):
        return "<"
    if stamp == 0x11:
        return ">"
    for order in ("<", ">"):
        words = np.frombuffer(header, dtype=order + "i4", count=19)
        if words[3] in MODES and np.all((words[:3] > 0) & (words[:3] < 2**16)) and set(words[16:19]) <= {0, 1, 2, 3}:
            return order
    raise MapError("not a CCP4/MRC map: its header reads as a map in neither byte order")


def _axis_order(mapcrs: np.ndarray) -> np.ndarray:
    """0-based spatial axes (x 0, y 1, z 2) of the columns, rows and sections."""
    if np.all(mapcrs == 0):  # (old files leave them unset: x, y, z)
        return np.arange(3)
    if sorted(mapcrs.tolist()) != [1, 2, 3]:
        raise MapError(f"its axis order MAPC, MAPR, MAPS = {', '.join(map(str, mapcrs))} is not an order of 1, 2, 3")
    return mapcrs.astype(np.int64) - 1


def _cell(cell: np.ndarray, sampling: np.ndarray, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The cell (a, b, c in Å, angles in degrees) and its samplings along x, y, z: a map
    without them gets a 1 Å grid of its own size, angles of 0 are right angles (as ChimeraX
    reads them)."""
    sampling = np.where(sampling > 0, sampling, shape)
    lengths = np.where((cell[:3] > 0) & np.isfinite(cell[:3]), cell[:3], sampling)
    angles = np.where((cell[3:] > 0) & (cell[3:] < 180), cell[3:], 90.0)
    return np.concatenate([lengths, angles]), sampling


def _unit_cell(values: np.ndarray, start: np.ndarray, sampling: np.ndarray, cell: gemmi.UnitCell, spacegroup: int) -> np.ndarray:
    """The whole unit cell (sampling) of a box of a periodic map that starts at ``start``:
    the box wrapped into the cell, the rest filled from its symmetry mates in
    ``spacegroup`` (gemmi), where none reaches with the box's mean."""
    if np.any(sampling < 2):
        raise MapError(f"its cell's sampling {' × '.join(map(str, sampling))} is not a grid (2 or more along each axis)")
    voxels = int(np.prod(sampling, dtype=np.int64))
    if voxels > MAX_VOXELS or voxels * 8 > input_limit():  # the cell, and gemmi's copy to symmetrize
        raise MapError(f"a unit cell of {' × '.join(map(str, sampling))} voxels is larger than is read "
                       f"({MAX_VOXELS:,} voxels and the input limit, {limit_text()})")
    whole = np.full(sampling, -np.inf, dtype=np.float32)
    index = np.ix_(*[(s + np.arange(n)) % m for s, n, m in zip(start, values.shape, sampling)])
    whole[index] = values
    group = gemmi.find_spacegroup_by_number(spacegroup) if 1 < spacegroup <= 230 else None
    if group is not None:
        grid = gemmi.FloatGrid(whole, cell, group)
        try:
            grid.symmetrize_max()
            whole = np.array(grid.array, dtype=np.float32)
        except RuntimeError:  # a sampling the symmetry cannot map onto itself: the box alone
            pass
    whole[np.isneginf(whole)] = values.mean(dtype=np.float64)
    return whole


def _resolution(header: bytes, words: np.ndarray) -> float | None:
    """Å, where one of the header's text labels gives it ("... resolution 3.2 ...")."""
    labels = min(max(int(words[55]), 0), 10)
    for k in range(labels):
        text = header[224 + 80 * k : 304 + 80 * k].decode("ascii", errors="replace")
        if match := _RESOLUTION_LABEL.search(text):
            value = float(match.group(1))
            if 0.5 <= value <= 100.0:
                return value
    return None
