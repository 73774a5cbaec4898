"""Fitting one conformation onto another, and into a density map, coarse to fine (#19),
side by side with ProDy's anisotropic network model (ANM) in the same run.

Usage: ``python benchmarks/bench_fit.py [--maps]`` (ProDy is a benchmark dependency:
``pip install prody``). Adenylate kinase, closed (1AKE) and open (4AKE), chain A, 214
residues paired by number, in both directions.

* Conformations: Cα rmsd to the target after each level of ``fit`` (levels 0-6; the
  control points are the unknowns) next to the rmsd after moving along the first k ANM
  modes (Cα, cutoff 15 Å, the target superposed on the start and its displacement
  projected on the modes), the anchor of the issue. Then the regularized fit: rmsd, time,
  and the geometry checks (bad peptide bonds, bad Cα–Cα, clashes per 1,000 atoms,
  Ramachandran outliers) against the input.
* ``--maps``: the target's density simulated at 10 Å and at 6 Å (heavy atoms on a 1 Å
  grid, blurred as Chimera's molmap does), the other conformation fitted into it (levels
  0-6): correlation, Cα rmsd to the target (no superposition: the map sets the frame) and
  time. Anchor (published, not run here): iMODFIT fits GroEL (1AON into a 10 Å map of
  1OEL) to 1.78 Å Cα rmsd, CC 0.982, in 244 s.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
import prody
from scipy import ndimage

from core.analysis.superpose import superpose
from core.fitting.conformation import fit_conformation, pair_segments
from core.fitting.density import MapTarget, fit_map, gaussian_sigma, heavy_atoms
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.protein.structure import Structure, ca_rows
from core.surfaces.volume import DensityMap

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
CLOSED, OPEN = "1AKE_adk_closed.pdb.gz", "4AKE_adk_open.pdb.gz"
LEVELS = range(0, 7)
MODES = (1, 2, 3, 5, 10, 20, 50)


def anm_rmsd(start: np.ndarray, target: np.ndarray, modes: tuple[int, ...]) -> dict[int, float]:
    """Cα rmsd to ``target`` after moving ``start`` along its first k ANM modes (ProDy, cutoff 15 Å)."""
    anm = prody.ANM("start")
    anm.buildHessian(start, cutoff=15.0)
    anm.calcModes(n_modes=max(modes), zeros=False)
    placed = superpose(start, target).apply(target)
    displacement = (placed - start).ravel()
    vectors = anm.getEigvecs()  # (3n, k), orthonormal
    result = {}
    for k in modes:
        moved = start.ravel() + vectors[:, :k] @ (vectors[:, :k].T @ displacement)
        result[k] = superpose(moved.reshape(-1, 3), target).rmsd
    return result


def conformations(start_file: str, end_file: str) -> None:
    start, end = read_structure(DATA / start_file), read_structure(DATA / end_file)
    name = f"{start_file.split('_')[0]} -> {end_file.split('_')[0]}"
    model = EditableModel(start)
    pairs, _ = pair_segments(model, [0], [end.segments[0]])
    rows = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]]
    target = pairs[0].target
    anm = anm_rmsd(start.coords[rows], target, MODES)
    began = time.perf_counter()
    result = fit_conformation(model, pairs, LEVELS)
    seconds = time.perf_counter() - began
    print(f"\n{name}: Cα rmsd {superpose(start.coords[rows], target).rmsd:.2f} Å at the start")
    print(f"  {'level':>5} {'control points':>15} {'unknowns':>9} {'rmsd Å':>7}    {'ANM modes':>9} {'rmsd Å':>7}")
    for fit, modes in zip(result.levels, MODES):
        print(f"  {fit.level:>5} {fit.control_points:>15} {3 * fit.control_points:>9} {fit.score:>7.2f}    "
              f"{modes:>9} {anm[modes]:>7.2f}")
    final = superpose(model.coords[rows], target).rmsd
    print(f"  regularized fit: Cα rmsd {final:.2f} Å in {seconds:.1f} s; " + _checks(start, model.coords))


def _checks(structure: Structure, coords: np.ndarray) -> str:
    before, after = validate(structure).counts, validate(structure, coords).counts
    per_k = 1000.0 / structure.n_atoms
    return (f"bad peptide bonds {before['peptide_bond']} -> {after['peptide_bond']}, bad Cα–Cα {before['ca_ca']} -> "
            f"{after['ca_ca']}, clashes per 1,000 atoms {before['clash'] * per_k:.1f} -> {after['clash'] * per_k:.1f}, "
            f"Ramachandran outliers {before['ramachandran']} -> {after['ramachandran']}")


def simulated_map(structure: Structure, resolution: float) -> DensityMap:
    """The heavy atoms on a 1 Å grid, blurred to ``resolution`` (Chimera's molmap width)."""
    coords = structure.coords[heavy_atoms(EditableModel(structure))]
    origin = np.floor(coords.min(axis=0)) - 15.0
    shape = tuple(int(n) for n in np.ceil(coords.max(axis=0) + 15.0 - origin))
    grid = np.zeros(shape)
    np.add.at(grid, tuple(np.round(coords - origin).astype(int).T), 1.0)
    values = ndimage.gaussian_filter(grid, gaussian_sigma(resolution)).astype(np.float32)
    return DensityMap(values, origin, np.eye(3))


def maps(start_file: str, end_file: str, resolution: float) -> None:
    start, end = read_structure(DATA / start_file), read_structure(DATA / end_file)
    model = EditableModel(start)
    target = MapTarget(simulated_map(end, resolution), resolution, model.coords[heavy_atoms(model)])
    rows, ca = heavy_atoms(model), ca_rows(start)

    def rmsd() -> float:
        return float(np.sqrt(np.mean(np.sum((model.coords[ca] - end.segments[0].ca) ** 2, axis=1))))

    first = target.correlation(model.coords[rows]), rmsd()
    began = time.perf_counter()
    result = fit_map(model, [0], target, LEVELS)
    seconds = time.perf_counter() - began
    print(f"  {start_file.split('_')[0]} into {end_file.split('_')[0]} at {resolution:>4g} Å: "
          f"CC {first[0]:.3f} -> {target.correlation(model.coords[rows]):.3f}, Cα rmsd {first[1]:.2f} -> "
          f"{rmsd():.2f} Å, {seconds:.1f} s (levels " + ", ".join(f"{f.level}: {f.score:.3f}" for f in result.levels)
          + ")")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", action="store_true", help="also fit into simulated maps (a minute or two)")
    args = parser.parse_args()
    prody.confProDy(verbosity="none")
    print(f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores; "
          f"ProDy {prody.__version__}")
    for pair in ((OPEN, CLOSED), (CLOSED, OPEN)):
        conformations(*pair)
    if args.maps:
        print("\nInto simulated maps (anchor: iMODFIT, GroEL at 10 Å: 1.78 Å, CC 0.982, 244 s):")
        for resolution in (10.0, 6.0):
            for pair in ((OPEN, CLOSED), (CLOSED, OPEN)):
                maps(*pair, resolution)


if __name__ == "__main__":
    main()
