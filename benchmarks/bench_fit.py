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
  0-6, then regularized and refined): correlation, Cα rmsd to the target (no
  superposition: the map sets the frame) and time. Then the same into maps made another
  way (:func:`xray_like_map`: each atom its electrons blurred by its B-factor, the Fourier
  transform cut sharply at the resolution, and noise), and into gemmi's electron density
  of the target (:func:`gemmi_map`). Anchor (published, not run here):
  iMODFIT fits GroEL (1AON into a 10 Å map of 1OEL) to 1.78 Å Cα rmsd, CC 0.982, in 244 s.
* ``--others DIR``: the same for other pairs of conformations or homologues, files of DIR
  (:data:`OTHER_PAIRS`, chain A of each), the start first placed on the target by its
  paired Cα (as a rigid fit would place it), the Cα rmsd over the paired residues.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import gemmi
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
from core.protein.writing import write_structure
from core.surfaces.volume import DensityMap, model_density

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
CLOSED, OPEN = "1AKE_adk_closed.pdb.gz", "4AKE_adk_open.pdb.gz"
LEVELS = range(0, 7)
MODES = (1, 2, 3, 5, 10, 20, 50)
OTHER_PAIRS = (("1TIM.pdb.gz", "8TIM.pdb.gz"), ("2AKY.pdb.gz", "1AKE.pdb.gz"), ("1RX4.pdb.gz", "3NZD.cif.gz"),
               ("1POH.pdb.gz", "2HPR.pdb.gz"))
"""Triosephosphate isomerase (loop 6 closed onto open), yeast into E. coli adenylate kinase,
dihydrofolate reductase (E. coli into human) and HPr (E. coli into B. subtilis)."""
ELECTRONS = {"C": 6, "N": 7, "O": 8, "S": 16}


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


def xray_like_map(structure: Structure, resolution: float, noise: float = 0.3, seed: int = 0) -> DensityMap:
    """A map made another way than the fit's model density: each heavy atom a Gaussian of
    its electrons blurred by its B-factor (σ² = B / 8π²) on a 1 Å grid, the Fourier
    transform cut sharply at 1/``resolution`` (the ripples of a real map), and white noise
    of ``noise`` times the map's standard deviation."""
    rows = heavy_atoms(EditableModel(structure))
    coords = structure.coords[rows]
    origin = np.floor(coords.min(axis=0)) - 15.0
    shape = tuple(int(n) for n in np.ceil(coords.max(axis=0) + 15.0 - origin))
    grid = np.zeros(shape)
    weight = np.array([ELECTRONS.get(e.upper(), 6) for e in structure.atoms.element[rows]], dtype=float)
    sigma = np.sqrt(np.maximum(structure.atoms.b_factor[rows], 2.0) / (8 * np.pi**2))
    for width in np.unique(np.round(sigma, 1)):  # atoms of like B-factor blurred together
        layer = np.zeros(shape)
        take = np.round(sigma, 1) == width
        np.add.at(layer, tuple(np.round(coords[take] - origin).astype(int).T), weight[take])
        grid += ndimage.gaussian_filter(layer, max(width, 0.3))
    spectrum = np.fft.rfftn(grid)
    k = np.meshgrid(*(np.fft.fftfreq(n) for n in shape[:2]), np.fft.rfftfreq(shape[2]), indexing="ij")
    spectrum[np.sqrt(sum(f**2 for f in k)) > 1.0 / resolution] = 0.0
    values = np.fft.irfftn(spectrum, shape, axes=(0, 1, 2))
    values += noise * values.std() * np.random.default_rng(seed).standard_normal(shape)
    return DensityMap(values.astype(np.float32), origin, np.eye(3))


def gemmi_map(structure: Structure, resolution: float) -> DensityMap:
    """A map made by another program: gemmi's electron density of the model (IT92 form
    factors, each atom blurred by its B-factor, hydrogens included), blurred by a Gaussian
    to ``resolution``."""
    density = model_density(structure.atoms, spacing=1.0, margin=15.0)
    values = ndimage.gaussian_filter(density.values, gaussian_sigma(resolution) / np.diag(density.axes))
    return DensityMap(values.astype(np.float32), density.origin, density.axes)


def map_fit(label: str, start: Structure, end: Structure, density: DensityMap, resolution: float) -> None:
    """Fit ``start`` (its first segment) into ``density`` of ``end`` and print CC, Cα rmsd and time."""
    model = EditableModel(start)
    pairs, _ = pair_segments(model, [0], [end.segments[0]])
    rows, target_ca = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]], pairs[0].target
    target = MapTarget(density, resolution, model.coords[heavy_atoms(model)])
    heavy = heavy_atoms(model)

    def rmsd() -> float:
        return float(np.sqrt(np.mean(np.sum((model.coords[rows] - target_ca) ** 2, axis=1))))

    first = target.correlation(model.coords[heavy]), rmsd()
    began = time.perf_counter()
    result = fit_map(model, [0], target, LEVELS)
    seconds = time.perf_counter() - began
    print(f"  {label} at {resolution:>4g} Å: CC {first[0]:.3f} -> {target.correlation(model.coords[heavy]):.3f}, "
          f"Cα rmsd {first[1]:.2f} -> {rmsd():.2f} Å ({len(rows)} Cα), {seconds:.1f} s (levels "
          + ", ".join(f"{f.level}: {f.score:.3f}" for f in result.levels) + ")")


def maps(start_file: str, end_file: str, resolution: float, made: str = "molmap") -> None:
    start, end = read_structure(DATA / start_file), read_structure(DATA / end_file)
    density = {"molmap": simulated_map, "x-ray-like": xray_like_map, "gemmi": gemmi_map}[made](end, resolution)
    map_fit(f"{start_file.split('_')[0]} into {end_file.split('_')[0]} ({made})", start, end, density, resolution)


def chain_a(path: Path, folder: Path) -> Structure:
    """The first chain of ``path``'s first model, protein only, as a structure."""
    st = gemmi.read_structure(str(path))
    st.remove_waters()
    st.remove_hydrogens()
    model = st[0]
    for name in [chain.name for chain in model][1:]:
        model.remove_chain(name)
    chain = model[0]
    for k in reversed(range(len(chain))):
        if chain[k].het_flag == "H":
            del chain[k]
    del st[1:]
    out = folder / f"{path.name.split('.')[0]}_A.pdb"
    st.write_pdb(str(out))
    return read_structure(out)


def others(folder: Path, resolution: float) -> None:
    with tempfile.TemporaryDirectory() as scratch:
        for start_file, end_file in OTHER_PAIRS:
            start, end = chain_a(folder / start_file, Path(scratch)), chain_a(folder / end_file, Path(scratch))
            model = EditableModel(start)
            pairs, _ = pair_segments(model, [0], [end.segments[0]])
            rows = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]]
            placed = superpose(pairs[0].target, start.coords[rows]).apply(start.coords)  # rigid, onto the target
            moved = read_structure(write_structure(start, placed, Path(scratch) / f"placed_{start_file}.pdb",
                                                   overwrite=True))
            name = f"{start_file.split('.')[0]} into {end_file.split('.')[0]}"
            map_fit(name, moved, end, simulated_map(end, resolution), resolution)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", action="store_true", help="also fit into simulated maps (several minutes)")
    parser.add_argument("--others", type=Path, metavar="DIR", help="also fit other pairs (OTHER_PAIRS) from DIR")
    args = parser.parse_args()
    prody.confProDy(verbosity="none")
    print(f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores; "
          f"ProDy {prody.__version__}")
    for pair in ((OPEN, CLOSED), (CLOSED, OPEN)):
        conformations(*pair)
    if args.maps:
        print("\nInto simulated maps (anchor: iMODFIT, GroEL at 10 Å: 1.78 Å, CC 0.982, 244 s):")
        for made in ("molmap", "x-ray-like", "gemmi"):
            for resolution in (10.0, 6.0):
                for pair in ((OPEN, CLOSED), (CLOSED, OPEN)):
                    maps(*pair, resolution, made)
    if args.others:
        print("\nOther proteins, into molmap maps of the target:")
        for resolution in (10.0, 6.0):
            others(args.others, resolution)


if __name__ == "__main__":
    main()
