"""The judge of a fit: correlations over the box, in the mask and per residue, and the
residues outside the density, on ubiquitin in maps made three ways."""

from pathlib import Path

import numpy as np
import pytest

from core.fitting.map_quality import map_quality
from core.fitting.map_target import MapTarget, heavy_atoms
from core.fitting.simulated_maps import gemmi_like, molmap, xray_like
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
MOVED = np.arange(30, 36)
"""Residues (indices) moved out of the density."""


@pytest.mark.parametrize("made, resolution", [(molmap, 3.0), (gemmi_like, 6.0), (xray_like, 4.0)])
def test_a_loop_moved_out_of_its_density_is_found(made, resolution: float) -> None:
    structure = read_structure(DATA / "1UBQ.pdb.gz")
    rows = heavy_atoms(EditableModel(structure))
    rows = rows[structure.atom_residue[rows] >= 0]  # the chain's residues
    coords, residue = structure.coords[rows], structure.atom_residue[rows]
    target = MapTarget(made(structure, resolution), resolution, coords)
    count = int(residue.max()) + 1
    placed = map_quality(target, coords, residue, count)
    assert placed.cc_mask > 0.8 and placed.cc_box > 0.8 and placed.resolution == resolution
    assert set(placed.outside) <= {73, 74, 75}  # at most the tail, whose B-factors (31-36 Å²) blur it away
    assert np.nanmin(placed.residues) > 0.3
    moved = coords.copy()
    loop = np.isin(residue, MOVED)
    outward = coords[loop].mean(axis=0) - coords.mean(axis=0)
    moved[loop] += 10.0 * outward / np.linalg.norm(outward)  # 10 Å off, into the solvent
    off = map_quality(target, moved, residue, count)
    assert off.cc_mask < placed.cc_mask - 0.05
    assert set(off.outside) >= set(MOVED[1:-1]) and len(off.outside) <= len(MOVED) + 2
    others = np.setdiff1d(np.arange(count), np.arange(MOVED[0] - 3, MOVED[-1] + 4))
    assert np.nanmean(off.residues[MOVED]) < np.nanmean(off.residues[others]) - 0.3
    assert "outside the density (A 31" in off.summary([f"A {k + 1}" for k in range(count)])
