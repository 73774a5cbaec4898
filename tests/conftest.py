"""What tests of the core and of the application share: maps written by mrcfile in any
convention of the CCP4/MRC format, and map coefficients written as refinement programs
write them."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import gemmi
import mrcfile
import numpy as np

DATA = Path(__file__).resolve().parent / "data"
D_MIN = 2.5
MISSING = range(30, 36)
"""Residues of ubiquitin left out of the model whose difference map is written."""


def _coefficients(structure: gemmi.Structure) -> gemmi.ComplexAsuData:
    calculator = gemmi.DensityCalculatorX()
    calculator.d_min = D_MIN
    calculator.grid.setup_from(structure, 0.6)
    calculator.put_model_density_on_grid(structure[0])
    return gemmi.transform_map_to_f_phi(calculator.grid).prepare_asu_data(dmin=D_MIN)


def write_mtz(path: Path, density: str = "FWT PHWT", difference: str | None = "DELFWT PHDELWT") -> Path:
    """An MTZ of ubiquitin (P 21 21 21) as refinement writes it: ``density`` the columns of
    the map of the whole model, ``difference`` those of the map of residues
    :data:`MISSING` alone (what a model without them lacks)."""
    structure = gemmi.read_structure(str(DATA / "1UBQ.pdb.gz"))
    structure.remove_waters()
    structure.setup_entities()
    partial = structure.clone()
    for residue in partial[0][0]:
        if residue.seqid.num not in MISSING:
            for _ in range(len(residue)):
                del residue[0]
    whole, lacking = _coefficients(structure), _coefficients(partial)
    assert np.array_equal(whole.miller_array, lacking.miller_array)
    mtz = gemmi.Mtz(with_base=True)
    mtz.spacegroup = structure.find_spacegroup()
    mtz.set_cell_for_all(structure.cell)
    mtz.add_dataset("refined")
    pairs = [(density.split(), whole.value_array)]
    if difference:
        pairs.append((difference.split(), lacking.value_array))
    columns = [whole.miller_array.astype(np.float32)]
    for (amplitude, phase), values in pairs:
        mtz.add_column(amplitude, "F")
        mtz.add_column(phase, "P")
        columns += [np.abs(values)[:, None], np.degrees(np.angle(values))[:, None]]
    mtz.set_data(np.hstack(columns).astype(np.float32))
    mtz.write_to_file(str(path))
    return path


def write_mrc(path: Path, values_xyz: np.ndarray, *, axis_order: tuple[int, int, int] = (1, 2, 3),
          start: tuple[int, int, int] = (0, 0, 0), origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
          sampling: tuple[int, int, int] | None = None, spacegroup: int = 1, gzipped: bool = False,
          step: np.ndarray | None = None, dtype: type = np.float32, edit: Callable[[mrcfile.mrcfile.MrcFile], None] = lambda mrc: None) -> Path:
    """Write ``values_xyz`` (indexed x, y, z) as ``mrcfile`` does, with columns, rows and
    sections along the axes ``axis_order`` (MAPC, MAPR, MAPS; 1 is x), ``start`` the
    first voxel's indices along x, y, z (written as NCSTART, NRSTART, NSSTART), ``sampling``
    the cell's samplings along x, y, z and the cell ``step`` (Å along x, y, z, default 1) times them."""
    columns, rows, sections = (a - 1 for a in axis_order)
    data = np.ascontiguousarray(values_xyz.transpose(sections, rows, columns)).astype(dtype)
    sampling = values_xyz.shape if sampling is None else sampling
    with mrcfile.new(path, overwrite=True, compression="gzip" if gzipped else None) as mrc:
        mrc.set_data(data)
        header = mrc.header
        header.mapc, header.mapr, header.maps = axis_order
        header.nxstart, header.nystart, header.nzstart = start[columns], start[rows], start[sections]
        header.mx, header.my, header.mz = sampling
        header.cella = tuple((1.0 if step is None else step) * np.array(sampling, dtype=float))
        header.origin = origin
        header.ispg = spacegroup
        edit(mrc)
    return path
