"""Maps from map coefficients: the Fourier transforms (gemmi) of an MTZ file's amplitude and
phase columns, the 2mFo−DFc map and the mFo−DFc difference map, chosen as Coot chooses
them (the column names refinement programs write) or named by the user.

Both are whole unit cells, periodic (:attr:`core.surfaces.volume.DensityMap.periodic`), their
resolution the file's high-resolution limit.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import gemmi
import numpy as np

from core.surfaces.volume import DensityMap, MapError

DENSITY_COLUMNS = (("FWT", "PHWT"), ("2FOFCWT", "PH2FOFCWT"), ("2FOFCWT_no_fill", "PH2FOFCWT_no_fill"),
                   ("FDM", "PHIDM"))
"""2mFo−DFc amplitude and phase columns, in the order they are looked for (Refmac and
Buster, Phenix, Phenix without missing reflections filled, density modification)."""
DIFFERENCE_COLUMNS = (("DELFWT", "PHDELWT"), ("FOFCWT", "PHFOFCWT"))
"""mFo−DFc columns (Refmac and Buster, Phenix)."""
SAMPLE_RATE = 3.0
"""Grid points per high-resolution limit (Coot samples at d_min / 3 too, about)."""
MTZ_MAGIC = b"MTZ "


@dataclass(frozen=True)
class MapCoefficients:
    """The maps of an MTZ file.

    Attributes
    ----------
    density : the 2mFo−DFc map (or the one pair of columns asked for).
    difference : the mFo−DFc map where the file has its columns, else None.
    columns : the amplitude and phase columns of ``density``.
    difference_columns : those of ``difference``, else None.
    """

    density: DensityMap
    difference: DensityMap | None
    columns: tuple[str, str]
    difference_columns: tuple[str, str] | None


def is_mtz(path: str | os.PathLike[str]) -> bool:
    """Whether the file at ``path`` is an MTZ file (by its first four bytes)."""
    with open(path, "rb") as file:
        return file.read(4) == MTZ_MAGIC


def column_pairs(path: str | os.PathLike[str]) -> list[tuple[str, str]]:
    """Every amplitude column of the MTZ file with the phase column that follows it: the
    pairs a user may choose from."""
    mtz = _read(Path(path))
    pairs, amplitude = [], None
    for column in mtz.columns:
        if column.type == "F":
            amplitude = column.label
        elif column.type == "P" and amplitude is not None:
            pairs.append((amplitude, column.label))
            amplitude = None
    return pairs


def read_mtz(path: str | os.PathLike[str], columns: tuple[str, str] | None = None) -> MapCoefficients:
    """The maps of the MTZ file at ``path``: of ``columns`` (amplitude, phase) or of the
    first of :data:`DENSITY_COLUMNS` it has, with the difference map of
    :data:`DIFFERENCE_COLUMNS` where it has one. Raises :class:`MapError` saying why not."""
    path = Path(path)
    mtz = _read(path)
    labels = {column.label: column.type for column in mtz.columns}
    if columns is None:
        columns = next((pair for pair in DENSITY_COLUMNS if _has(labels, pair)), None)
        if columns is None:
            raise MapError(f"{path}: no 2mFo−DFc columns ({', '.join('/'.join(p) for p in DENSITY_COLUMNS)}); "
                           f"name the amplitude and phase columns (the file has {', '.join(labels)})")
    elif not _has(labels, columns):
        raise MapError(f"{path}: no amplitude column {columns[0]!r} with a phase column {columns[1]!r} "
                       f"(the file has {', '.join(f'{k} ({t})' for k, t in labels.items())})")
    difference = next((pair for pair in DIFFERENCE_COLUMNS if _has(labels, pair) and pair != columns), None)
    return MapCoefficients(_map(mtz, columns), _map(mtz, difference) if difference else None, columns, difference)


def _read(path: Path) -> gemmi.Mtz:
    if not path.is_file():
        raise MapError(f"{path}: no such file" if not path.exists() else f"{path}: not a regular file")
    try:
        mtz = gemmi.read_mtz_file(str(path))
    except (RuntimeError, ValueError, OSError) as error:
        raise MapError(f"{path}: not a readable MTZ file ({error})") from None
    if mtz.nreflections == 0:
        raise MapError(f"{path}: the MTZ file holds no reflections")
    return mtz


def _has(labels: dict[str, str], pair: tuple[str, str]) -> bool:
    return labels.get(pair[0]) == "F" and labels.get(pair[1]) == "P"


def _map(mtz: gemmi.Mtz, columns: tuple[str, str]) -> DensityMap:
    grid = mtz.transform_f_phi_to_map(*columns, sample_rate=SAMPLE_RATE)
    values = np.array(grid.array, dtype=np.float32)
    axes = (np.array(grid.unit_cell.orth.mat.tolist()) / np.array(values.shape)).T
    return DensityMap(values, np.zeros(3), axes, periodic=True, resolution=float(mtz.resolution_high()),
                      cut_sharply=True)
