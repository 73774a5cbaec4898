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
  way (:func:`~core.fitting.simulated_maps.xray_like`: each atom its electrons blurred by its B-factor, the Fourier
  transform cut sharply at the resolution, and noise), and into gemmi's electron density
  of the target (:func:`~core.fitting.simulated_maps.gemmi_like`). Anchor (published, not run here):
  iMODFIT fits GroEL (1AON into a 10 Å map of 1OEL) to 1.78 Å Cα rmsd, CC 0.982, in 244 s.
* Every map fit is judged independently too (:func:`judges`): king-probe's clashscore and
  mkdssp's helices and strands for the input, the target and the fitted model, beside the
  project's own counts (``apt install king-probe dssp``; without them it says so).
* Every figure is the fit of the files as read, on one BLAS thread; beside it its spread
  (``--starts N``, default 3): the same fit on two BLAS threads and from N starts whose
  coordinates are perturbed by up to ±0.001 Å, all run side by side in processes of
  their own (``--jobs``). The spread is the largest Cα rmsd between any two of the fitted
  models, and the range of the figure over them (#31: a fit is converged when that spread
  stays within 0.1 Å).
* ``--large DIR``: large domain motions (:data:`LARGE_MOTIONS`), made from entries of DIR:
  the smaller of the chain's two dynamic domains (the sign of the slowest mode of ProDy's
  Gaussian network model) turned rigidly by an angle about an axis through the hinge (the
  residues of the other domain nearest it), the axis of the domain's turn in the slowest
  mode of ProDy's anisotropic network model, the way that clashes less; and motions that
  no domain split made (:data:`BENT`): the chain moved along that slowest ANM mode, every
  residue with its Cα. The chain as read fitted into a 10 Å molmap map of the moved one.
  Printed beside iMODFIT's figure for GroEL (1.78 Å, 244 s), the goal 2.0 Å (#32).
* ``--others DIR``: the same for other pairs of conformations or homologues, files of DIR
  (:data:`OTHER_PAIRS`, chain A of each), the start first placed on the target by its
  paired Cα (as a rigid fit would place it), the Cα rmsd over the paired residues.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import gemmi
import numpy as np
import prody
from scipy import ndimage
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from core.analysis.superpose import superpose
from core.fitting.conformation import fit_conformation, pair_segments
from core.fitting.density import fit_map
from core.fitting.domains import DOMAINS
from core.fitting.map_target import MapTarget, heavy_atoms, occupancies
from core.fitting.simulated_maps import gemmi_like, molmap, xray_like
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.protein.secondary_structure import dssp
from core.protein.structure import Structure, ca_rows
from core.protein.writing import write_structure
from core.surfaces.volume import DensityMap

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
CLOSED, OPEN = "1AKE_adk_closed.pdb.gz", "4AKE_adk_open.pdb.gz"
LEVELS = range(7)
MAP_LEVELS = (DOMAINS, *LEVELS)
"""A map fit's: the smaller dynamic domain moved rigidly first, then levels 0-6."""
MODES = (1, 2, 3, 5, 10, 20, 50)
OTHER_PAIRS = (("1TIM.pdb.gz", "8TIM.pdb.gz"), ("2AKY.pdb.gz", "1AKE.pdb.gz"), ("1RX4.pdb.gz", "3NZD.cif.gz"),
               ("1POH.pdb.gz", "2HPR.pdb.gz"))
"""Triosephosphate isomerase (loop 6 closed onto open), yeast into E. coli adenylate kinase,
dihydrofolate reductase (E. coli into human) and HPr (E. coli into B. subtilis)."""
LARGE_MOTIONS = (("1ANF.pdb.gz", 35.0), ("1ANF.pdb.gz", 60.0), ("3VI4.pdb.gz", 40.0), ("1H2T.pdb.gz", 30.0))
"""Maltodextrin-binding protein (370 residues, its C-terminal domain turned 35° and 60°),
integrin α5 (601 residues, its thigh domain turned 40°) and the 80 kDa nuclear cap-binding
protein (its first 499 residues, 30°): a file and the angle its smaller domain turns. (α-Amylase,
2D0F, is left out: its smaller dynamic domain interleaves with the other, and turned 40°
either way it puts 300 atom pairs closer than 2.2 Å: no protein moves so.)"""
BENT = (("1ANF.pdb.gz", 4.0), ("3VI4.pdb.gz", 4.0))
"""A file and the Cα rmsd (Å) its chain moves along its slowest ANM mode."""
CLASH = 2.2
"""Å: atoms closer than this clash (a turned domain turns the way that clashes less)."""
GOAL_LARGE = 2.0
"""Å of Cα rmsd to the target that a large motion's fit should reach (#32)."""
PERTURBATION = 0.001
"""Å: how far each start coordinate moves, at most, in the runs of the spread."""
SPREAD_GOAL = 0.1
"""Å: the most two runs of one fit may end apart (#31)."""


@dataclass(frozen=True)
class Run:
    """One run of a fit: ``seed`` 0 starts from the file as read, others from its
    coordinates perturbed; ``threads`` BLAS threads."""

    seed: int
    threads: int


def runs(starts: int) -> list[Run]:
    """The figure's run (as read, one thread), then two threads, then ``starts`` perturbed starts."""
    return [Run(0, 1), Run(0, 2)] + [Run(seed, 1) for seed in range(1, starts + 1)]


@dataclass(frozen=True)
class Outcome:
    """What a run of a fit ends with: the paired Cα (k, 3), its figures, and what it prints."""

    ca: np.ndarray
    figures: dict[str, float]
    text: str


def started(structure: Structure, seed: int, folder: Path) -> Structure:
    """``structure`` itself for seed 0, else with every coordinate moved by up to
    :data:`PERTURBATION` Å, written to ``folder`` and read again."""
    if seed == 0:
        return structure
    jitter = np.random.default_rng(seed).uniform(-PERTURBATION, PERTURBATION, structure.coords.shape)
    return read_structure(write_structure(structure, structure.coords + jitter, folder / f"start_{seed}.pdb",
                                          overwrite=True))


def side_by_side(jobs: Sequence[tuple[Callable[..., Outcome], tuple]], plan: Sequence[Run],
                 workers: int) -> list[list[Future]]:
    """Every job ``(function, args)`` submitted as ``function(*args, seed)`` for each run of
    ``plan``, each in a process of its own with the run's BLAS threads. Returns the futures
    of each job's outcomes, in the order of ``plan``."""
    futures = {}
    for threads in sorted({run.threads for run in plan}):
        for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ[name] = str(threads)  # read by the new processes' numpy when it loads
        pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
        for j, (function, args) in enumerate(jobs):
            for k, run in enumerate(plan):
                if run.threads == threads:
                    futures[j, k] = pool.submit(function, *args, run.seed)
        pool.shutdown(wait=False)
    return [[futures[j, k] for k in range(len(plan))] for j in range(len(jobs))]


def apart(outcomes: Sequence[Outcome]) -> float:
    """Å, the largest Cα rmsd between two of ``outcomes``."""
    return float(max(np.sqrt(np.mean(np.sum((a.ca - b.ca) ** 2, axis=1))) for a in outcomes for b in outcomes))


def spread(outcomes: Sequence[Outcome]) -> str:
    """The largest Cα rmsd between two outcomes, and the range of each figure over them."""
    distance = apart(outcomes)
    values = {name: [o.figures[name] for o in outcomes] for name in outcomes[0].figures}
    ranges = ", ".join(f"{name} {min(v):.3f}–{max(v):.3f}" for name, v in values.items())
    flag = "" if distance <= SPREAD_GOAL else f" (over {SPREAD_GOAL} Å)"
    return f"    spread over {len(outcomes)} runs: models {distance:.2f} Å apart at most{flag}; {ranges}"


def report(jobs: Sequence[tuple[Callable[..., Outcome], tuple]], plan: Sequence[Run], workers: int) -> list[float]:
    """Run ``jobs`` side by side, print each figure (its first run) and its spread; returns
    the spreads (Å)."""
    spreads = []
    for futures in side_by_side(jobs, plan, workers):
        outcomes = [future.result() for future in futures]
        print(outcomes[0].text, flush=True)
        print(spread(outcomes))
        spreads.append(apart(outcomes))
    return spreads


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


def conformations(start_file: str, end_file: str, seed: int) -> Outcome:
    """Fit ``start_file`` onto ``end_file`` (from start ``seed``) level by level, beside ANM."""
    with tempfile.TemporaryDirectory() as scratch:
        start = started(read_structure(DATA / start_file), seed, Path(scratch))
    end = read_structure(DATA / end_file)
    name = f"{start_file.split('_')[0]} -> {end_file.split('_')[0]}"
    model = EditableModel(start)
    pairs, _ = pair_segments(model, [0], [end.segments[0]])
    rows = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]]
    target = pairs[0].target
    anm = anm_rmsd(start.coords[rows], target, MODES)
    began = time.perf_counter()
    result = fit_conformation(model, pairs, LEVELS)
    seconds = time.perf_counter() - began
    lines = [f"\n{name}: Cα rmsd {superpose(start.coords[rows], target).rmsd:.2f} Å at the start",
             f"  {'level':>5} {'control points':>15} {'unknowns':>9} {'rmsd Å':>7}    {'ANM modes':>9} {'rmsd Å':>7}"]
    for fit, modes in zip(result.levels, MODES):
        lines.append(f"  {fit.level:>5} {fit.control_points:>15} {3 * fit.control_points:>9} {fit.score:>7.2f}    "
                     f"{modes:>9} {anm[modes]:>7.2f}")
    final = superpose(model.coords[rows], target)
    lines.append(f"  regularized fit: Cα rmsd {final.rmsd:.2f} Å in {seconds:.1f} s; " + _checks(start, model.coords))
    return Outcome(model.coords[rows].copy(), {"Cα rmsd": final.rmsd}, "\n".join(lines))


def _checks(structure: Structure, coords: np.ndarray) -> str:
    before, after = validate(structure).counts, validate(structure, coords).counts
    per_k = 1000.0 / structure.n_atoms
    return (f"bad peptide bonds {before['peptide_bond']} -> {after['peptide_bond']}, bad Cα–Cα {before['ca_ca']} -> "
            f"{after['ca_ca']}, clashes per 1,000 atoms {before['clash'] * per_k:.1f} -> {after['clash'] * per_k:.1f}, "
            f"Ramachandran outliers {before['ramachandran']} -> {after['ramachandran']}")


JUDGES = ("king-probe", "mkdssp")
"""Independent judges of a model's geometry, from Debian's packages king-probe and dssp."""


def judges(models: dict[str, tuple[Structure, np.ndarray]]) -> str:
    """Each model (name: its structure and coordinates) as the independent judges see it
    beside the project's own counts: king-probe's clashscore (MolProbity's serious overlaps,
    0.4 Å or more, per 1,000 atoms; heavy atoms only, no hydrogens added) and clashes per
    1,000 atoms of :func:`core.geometry.validation.validate`; helix and strand residues by
    mkdssp and by :func:`core.protein.secondary_structure.dssp`, and the share of the
    ``"fitted"`` model's residues whose state is the ``"target"``'s."""
    missing = [tool for tool in JUDGES if shutil.which(tool) is None]
    if missing:
        return f"  judges: {', '.join(missing)} not installed (apt install king-probe dssp)"
    parts, states = [], {}
    with tempfile.TemporaryDirectory() as scratch:
        for name, (structure, coords) in models.items():
            pdb, heavy = _for_judges(structure, coords, Path(scratch) / name)
            probe = subprocess.run(["king-probe", "-u", "-q", "-mc", "-het", "-once", "-NOVDWOUT", "ogt0 not water",
                                    "ogt0", str(pdb)], capture_output=True, text=True, check=False).stdout
            fields = [line.split(":") for line in probe.splitlines() if line.count(":") > 6]
            pairs = {(f[3], f[4]) for f in fields if f[2] in ("so", "bo") and float(f[5]) <= -0.4}
            theirs = _mkdssp(pdb, Path(scratch) / f"{name}.dssp")
            ours = _own_ss(structure, coords)
            states[name] = theirs, ours
            own_clashes = validate(structure, coords).counts["clash"] * 1000.0 / structure.n_atoms
            parts.append(f"{name} clashscore {1000.0 * len(pairs) / heavy:.1f} (own {own_clashes:.1f}), H/E "
                         f"{np.sum(theirs == 'H')}/{np.sum(theirs == 'E')} (own {np.sum(ours == 'H')}/{np.sum(ours == 'E')})")
    (fitted_theirs, fitted_ours), (target_theirs, target_ours) = states["fitted"], states["target"]
    shares = [f"{judge} {np.mean(fitted == target):.0%}" for judge, fitted, target in
              (("mkdssp", fitted_theirs, target_theirs), ("own", fitted_ours, target_ours)) if len(fitted) == len(target)]
    same = f"; secondary structure as the target's: {', '.join(shares)}" if shares else ""
    return "  judges: " + "; ".join(parts) + same


def _for_judges(structure: Structure, coords: np.ndarray, stem: Path) -> tuple[Path, int]:
    """The model's heavy atoms written by gemmi as PDB for king-probe and mkdssp, and their count."""
    st = gemmi.read_structure(str(write_structure(structure, coords, stem.with_suffix(".in.pdb"), overwrite=True)))
    atoms = [atom for chain in st[0] for residue in chain for atom in residue]
    for atom, element in zip(atoms, structure.atoms.element, strict=True):  # (as read here: gemmi guesses otherwise
        atom.element = gemmi.Element(element)                              # from names out of their columns)
    for chain in st[0]:
        chain.name = chain.name.strip() or "A"
    st.remove_hydrogens()
    st.raw_remarks = []  # (mkdssp refuses free-text REMARK lines, and wants a HEADER first)
    st.helices.clear()  # (it computes its own, and refuses a file's sheets of chains left out)
    st.sheets.clear()
    pdb = stem.with_suffix(".pdb")
    text = st.make_pdb_string()
    pdb.write_text(text if text.startswith("HEADER") else f"{'HEADER':<80}\n" + text)
    return pdb, sum(len(residue) for chain in st[0] for residue in chain)


def _mkdssp(path: Path, out: Path) -> np.ndarray:
    """mkdssp's H (H, G, I), E (E, B) or C per residue of ``path``."""
    subprocess.run(["mkdssp", "--output-format", "dssp", str(path), str(out)], capture_output=True, check=False)
    lines = out.read_text().splitlines() if out.exists() else []
    start = next((k for k, line in enumerate(lines) if line.startswith("  #  RESIDUE")), len(lines))
    codes = [line[16] for line in lines[start + 1:] if len(line) > 16 and line[13] != "!"]
    return np.array(["H" if c in "HGI" else "E" if c in "EB" else "C" for c in codes])


def _own_ss(structure: Structure, coords: np.ndarray) -> np.ndarray:
    """The project's H, E or C per residue of every segment at ``coords``."""
    names, xyz, starts = structure.atoms.name, [], []
    for segment in structure.segments:
        for k in range(len(segment)):
            rows = segment.atoms(k)
            found = [np.flatnonzero(names[rows] == atom) for atom in ("N", "CA", "C", "O")]
            xyz.append([coords[rows.start + hit[0]] if len(hit) else np.full(3, np.nan) for hit in found])
            starts.append(k == 0)
    xyz = np.array(xyz)
    proline = np.concatenate([segment.resname == "PRO" for segment in structure.segments])
    return dssp(*xyz.transpose(1, 0, 2), chain_start=np.array(starts), proline=proline, helix_caps=True)


def map_fit(label: str, start: Structure, end: Structure, density: DensityMap, resolution: float) -> Outcome:
    """Fit ``start`` (its first segment) into ``density`` of ``end``: CC, Cα rmsd and time."""
    model = EditableModel(start)
    pairs, _ = pair_segments(model, [0], list(end.segments))  # (the target's chain may be broken)
    rows, target_ca = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]], pairs[0].target
    target = MapTarget(density, resolution, model.coords[heavy_atoms(model)])
    heavy = heavy_atoms(model)
    weights = occupancies(model, heavy)

    def rmsd() -> float:
        return float(np.sqrt(np.mean(np.sum((model.coords[rows] - target_ca) ** 2, axis=1))))

    first = target.correlation(model.coords[heavy], weights), rmsd()
    began = time.perf_counter()
    result = fit_map(model, [0], target, MAP_LEVELS)
    seconds = time.perf_counter() - began
    cc, final = target.correlation(model.coords[heavy], weights), rmsd()
    dropped = f", level {', '.join(map(str, result.dropped))} undone" if result.dropped else ""
    levels = ", ".join(f"{f.name.removeprefix('level ')}: {f.score:.3f}" for f in result.levels)
    motion = next((f"; {f.motion}" for f in result.levels if f.motion), "")
    text = (f"  {label} at {resolution:>4g} Å: CC {first[0]:.3f} -> {cc:.3f}, Cα rmsd {first[1]:.2f} -> {final:.2f} Å "
            f"({len(rows)} Cα), {seconds:.1f} s (levels {levels}{dropped}{motion})\n"
            + judges({"input": (start, start.coords), "target": (end, end.coords), "fitted": (start, model.coords)}))
    return Outcome(model.coords[rows].copy(), {"CC": cc, "Cα rmsd": final}, text)


def maps(start_file: str, end_file: str, resolution: float, made: str, seed: int) -> Outcome:
    """Fit ``start_file`` (from start ``seed``) into a map of ``end_file`` made by ``made``."""
    end = read_structure(DATA / end_file)
    density = {"molmap": molmap, "x-ray-like": xray_like, "gemmi": gemmi_like}[made](end, resolution)
    with tempfile.TemporaryDirectory() as scratch:
        start = started(read_structure(DATA / start_file), seed, Path(scratch))
    label = f"{start_file.split('_')[0]} into {end_file.split('_')[0]} ({made})"
    return map_fit(label, start, end, density, resolution)


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


def other(folder: Path, start_file: str, end_file: str, resolution: float, seed: int) -> Outcome:
    """Fit chain A of ``start_file``, placed on chain A of ``end_file`` by their paired Cα,
    into a molmap map of it (from start ``seed``)."""
    with tempfile.TemporaryDirectory() as scratch:
        start, end = chain_a(folder / start_file, Path(scratch)), chain_a(folder / end_file, Path(scratch))
        model = EditableModel(start)
        pairs, _ = pair_segments(model, [0], [end.segments[0]])
        rows = ca_rows(start)[start.segments[0].residue_index[pairs[0].residues]]
        placed = superpose(pairs[0].target, start.coords[rows]).apply(start.coords)  # rigid, onto the target
        moved = read_structure(write_structure(start, placed, Path(scratch) / f"placed_{start_file}.pdb",
                                               overwrite=True))
        moved = started(moved, seed, Path(scratch))
    name = f"{start_file.split('.')[0]} into {end_file.split('.')[0]}"
    return map_fit(name, moved, end, molmap(end, resolution), resolution)


def turned(structure: Structure, angle: float, folder: Path) -> tuple[Structure, int]:
    """``structure`` with its smaller dynamic domain turned by ``angle`` degrees about its
    hinge (see ``--large``), and the domain's size in residues."""
    ca = structure.coords[ca_rows(structure)[structure.segments[0].residue_index]]
    gnm = prody.GNM()
    gnm.buildKirchhoff(ca, cutoff=7.3)
    gnm.calcModes(1)
    sign = np.sign(gnm.getEigvecs()[:, 0])
    small = sign == (1.0 if np.sum(sign > 0) < np.sum(sign < 0) else -1.0)
    small = ndimage.median_filter(small, size=15, mode="nearest")  # no stray pieces: the chain crosses few times
    nearest = np.linalg.norm(ca[~small][:, None] - ca[small][None], axis=2).min(axis=1)
    hinge = ca[~small][np.argsort(nearest)[:10]].mean(axis=0)
    anm = prody.ANM()
    anm.buildHessian(ca, cutoff=15.0)
    anm.calcModes(1)
    mode = anm.getEigvecs()[:, 0].reshape(-1, 3)
    axis = _turn(mode[small], ca[small]) - _turn(mode[~small], ca[~small])  # the domain's turn in the slowest mode
    axis /= np.linalg.norm(axis)
    segment = structure.segments[0]
    rows = np.concatenate([np.arange(segment.atom_start[k], segment.atom_stop[k]) for k in np.flatnonzero(small)])
    others = cKDTree(np.delete(structure.coords, rows, axis=0))
    turns = [Rotation.from_rotvec(way * np.radians(angle) * axis) for way in (1.0, -1.0)]
    placed = [turn.apply(structure.coords[rows] - hinge) + hinge for turn in turns]
    clashes = [others.query_ball_point(xyz, CLASH, return_length=True).sum() for xyz in placed]
    coords = structure.coords.copy()
    coords[rows] = placed[int(np.argmin(clashes))]  # the way that clashes less (opens rather than closes)
    return read_structure(write_structure(structure, coords, folder / "turned.pdb", overwrite=True)), int(small.sum())


def _turn(displacement: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """The rotation vector of the rigid motion (about the centroid) closest to ``displacement`` of ``xyz``."""
    arm = xyz - xyz.mean(axis=0)
    design = np.zeros((len(xyz), 3, 6))
    for k, unit in enumerate(np.eye(3)):
        design[:, :, k] = np.cross(unit, arm)
        design[:, k, 3 + k] = 1.0
    solution, *_ = np.linalg.lstsq(design.reshape(-1, 6), displacement.ravel(), rcond=None)
    return solution[:3]


def bent(structure: Structure, rmsd: float, folder: Path) -> Structure:
    """``structure`` moved along the slowest mode of its Cα's anisotropic network (cutoff
    15 Å), each residue with its Cα, by ``rmsd`` Å of Cα rmsd."""
    segment = structure.segments[0]
    ca = structure.coords[ca_rows(structure)[segment.residue_index]]
    anm = prody.ANM()
    anm.buildHessian(ca, cutoff=15.0)
    anm.calcModes(1)
    mode = anm.getEigvecs()[:, 0].reshape(-1, 3)
    mode *= rmsd / np.sqrt(np.mean(np.sum(mode**2, axis=1)))
    coords = structure.coords.copy()
    for k in range(len(segment)):
        rows = segment.atoms(k)
        coords[rows] += mode[k]
    return read_structure(write_structure(structure, coords, folder / "bent.pdb", overwrite=True))


def large(folder: Path, file: str, motion: str, size: float, seed: int) -> Outcome:
    """Fit chain A of ``file`` (from start ``seed``) into a 10 Å molmap map of itself with
    its smaller domain turned ``size`` degrees (``motion`` 'turn') or moved along its
    slowest ANM mode by ``size`` Å ('bend')."""
    with tempfile.TemporaryDirectory() as scratch:
        start = chain_a(folder / file, Path(scratch))
        if motion == "turn":
            end, turned_residues = turned(start, size, Path(scratch))
            how = f"{turned_residues} turned {size:g}°"
        else:
            end, how = bent(start, size, Path(scratch)), f"moved {size:g} Å along its slowest ANM mode"
        start = started(start, seed, Path(scratch))
    name = f"{file.split('.')[0]} ({len(start.segments[0])} residues), {how}"
    return map_fit(name, start, end, molmap(end, 10.0), 10.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", action="store_true", help="also fit into simulated maps (several minutes)")
    parser.add_argument("--large", type=Path, metavar="DIR",
                        help="also fit large domain motions (LARGE_MOTIONS) made from entries of DIR")
    parser.add_argument("--others", type=Path, metavar="DIR", help="also fit other pairs (OTHER_PAIRS) from DIR")
    parser.add_argument("--starts", type=int, default=3, metavar="N",
                        help="perturbed starts of each fit for its spread (default 3; 0: two thread counts only)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count(), help="fits run side by side (default: the cores)")
    args = parser.parse_args()
    prody.confProDy(verbosity="none")
    plan = runs(args.starts)
    print(f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores; "
          f"ProDy {prody.__version__}; {len(plan)} runs of each fit ({args.jobs} side by side): as read on 1 and 2 "
          f"BLAS threads, {args.starts} starts perturbed by up to ±{PERTURBATION} Å")
    spreads = report([(conformations, pair) for pair in ((OPEN, CLOSED), (CLOSED, OPEN))], plan, args.jobs)
    if args.maps:
        print("\nInto simulated maps (anchor: iMODFIT, GroEL at 10 Å: 1.78 Å, CC 0.982, 244 s):")
        spreads += report([(maps, (*pair, resolution, made)) for made in ("molmap", "x-ray-like", "gemmi")
                           for resolution in (10.0, 6.0) for pair in ((OPEN, CLOSED), (CLOSED, OPEN))], plan, args.jobs)
    if args.large:
        print(f"\nLarge domain motions into 10 Å molmap maps (goal {GOAL_LARGE} Å; iMODFIT, GroEL at 10 Å: 1.78 Å, "
              "CC 0.982, 244 s):")
        spreads += report([(large, (args.large, file, "turn", angle)) for file, angle in LARGE_MOTIONS]
                          + [(large, (args.large, file, "bend", rmsd)) for file, rmsd in BENT], plan, args.jobs)
    if args.others:
        print("\nOther proteins, into molmap maps of the target:")
        spreads += report([(other, (args.others, *pair, resolution)) for resolution in (10.0, 6.0)
                           for pair in OTHER_PAIRS], plan, args.jobs)
    within = sum(s <= SPREAD_GOAL for s in spreads)
    print(f"\nspread: {within} of {len(spreads)} fits end within {SPREAD_GOAL} Å of themselves over every run; "
          f"the largest {max(spreads):.2f} Å")


if __name__ == "__main__":
    main()
