"""Speed of regularization after an edit, and of validation (full and local).

Usage: ``python benchmarks/bench_regularize.py [STRUCTURE ...]`` (default: the test entries
1UBQ, 4YVS, 7Z9T and 1AYE). In the longest segment of each structure, every integer-level
control point is moved 5 Å away from the segment's centre; the edits that move 20 ± 25%
and 200 ± 25% residues are regularized (the moved residues plus three on each side). A
line gives, for one structure and target, the number of such edits and the residues they
move, the median, 90th percentile and largest time of ``regularized`` (best of 3 runs each; the
per-structure set-up of bonds and radii is built once before, its time on its own), the
peptide bonds outside 1.33 ± 0.05 Å before and after (summed over the edits), the clashes
and Ramachandran outliers not in the input after, and the rms distance from the edited
curve of the curve points C^r that the residues carry. The last line of a structure times validation of the whole
structure and of 20 residues (what the editor runs during a drag).
Targets: under 50 ms for 20 moved residues, under 500 ms for 200.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from timing import best_ms

from core.geometry.regularize import regularized
from core.geometry.topology import topology
from core.geometry.validation import validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
TARGETS = (20, 200)


def edits_moving(model: EditableModel, segment: int, target: int) -> list:
    """Every 5 Å outward integer-level control-point edit of ``segment`` that moves between
    0.75 and 1.25 times ``target`` residues (away from the centre of the segment's Cα)."""
    ribbon = model.ribbons[segment]
    centre = model.segments[segment].ca.mean(axis=0)
    edits = []
    for level in range(int(ribbon.max_level) + 1):
        points, _ = ribbon.control_points(level)
        for k in range(len(points)):
            direction = points[k] - centre
            edit = model.move_point(segment, level, k, 5.0 * direction / np.linalg.norm(direction))
            if 0.75 * target <= len(edit.residues) <= 1.25 * target:
                edits.append(edit)
    return edits


def carried_curve_distance(model: EditableModel, edit, fixed) -> float:
    """Rms distance (Å) from the edited curve of the curve points the residues carry rigidly."""
    ribbon, segment = model.ribbons[edit.segment], model.segments[edit.segment]
    before = model.coords.copy()
    before[edit.rows] = edit.new_coords
    after = model.coords.copy()
    after[fixed.rows] = fixed.new_coords
    curve = ribbon.space.evaluate(edit.new_points, np.linspace(0.0, 1.0, 20 * 2**ribbon.level + 1))
    distances = []
    atoms = model.structure.atoms
    for residue in fixed.residues:
        rows = np.arange(segment.atom_start[residue], segment.atom_stop[residue])
        rows = rows[~np.isin(atoms.name[rows], ("O", "OXT"))]  # the rigid part (the carbonyl turns)
        a, b = before[rows], after[rows]
        u, _, vt = np.linalg.svd((a - a.mean(0)).T @ (b - b.mean(0)))
        rotation = vt.T @ np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))]) @ u.T
        point = ribbon.space.evaluate(edit.new_points, ribbon.residue_u[residue : residue + 1])[0]
        carried = rotation @ (point - a.mean(0)) + b.mean(0)
        distances.append(np.linalg.norm(curve - carried, axis=1).min())
    return float(np.sqrt(np.mean(np.square(distances))))


def peptide_bonds_outside(structure, coords, residues) -> int:
    return validate(structure, coords, residues=residues).counts["peptide_bond"]


def main(paths: list[str]) -> None:
    print(f"{'structure':<14}{'atoms':>7}{'set-up ms':>10}{'target':>7}{'edits':>6}{'moved':>8}"
          f"{'median ms':>10}{'p90 ms':>8}{'max ms':>8}{'bad C-N before':>15}{'after':>6}{'new clashes':>12}{'new Rama':>9}"
          f"{'C^r rms Å':>10}")
    for path in paths or [DATA / name for name in ("1UBQ.pdb.gz", "4YVS.cif.gz", "7Z9T.cif.gz", "1AYE.pdb.gz")]:
        structure = read_structure(path)
        start = time.perf_counter()
        topology(structure)
        setup = 1e3 * (time.perf_counter() - start)
        model = EditableModel(structure)
        segment = max(range(len(model.segments)), key=lambda s: len(model.segments[s]))
        report = validate(structure)
        clashes = {f.where for f in report.flags if f.kind == "clash"}
        outliers = {f.where for f in report.flags if f.kind == "ramachandran"}
        for target in TARGETS:
            edits = edits_moving(model, segment, target)
            if not edits:
                continue
            times, bad_before, bad_after, new_clashes, new_outliers, drift = [], 0, 0, 0, 0, []
            for edit in edits:
                fixed = regularized(model, edit)
                times.append(best_ms(lambda edit=edit: regularized(model, edit), repeats=3))
                region = model.segments[segment].residue_index[fixed.residues]
                before = model.coords.copy()
                before[edit.rows] = edit.new_coords
                after = model.coords.copy()
                after[fixed.rows] = fixed.new_coords
                bad_before += peptide_bonds_outside(structure, before, region)
                bad_after += peptide_bonds_outside(structure, after, region)
                flags = validate(structure, after, residues=region).flags
                new_clashes += len({f.where for f in flags if f.kind == "clash"} - clashes)
                new_outliers += len({f.where for f in flags if f.kind == "ramachandran"} - outliers)
                drift.append(carried_curve_distance(model, edit, fixed))
            moved = f"{min(len(e.residues) for e in edits)}-{max(len(e.residues) for e in edits)}"
            print(f"{Path(path).name:<14}{structure.n_atoms:>7}{setup:>10.0f}{target:>7}{len(edits):>6}{moved:>8}"
                  f"{np.median(times):>10.1f}{np.percentile(times, 90):>8.1f}{max(times):>8.1f}{bad_before:>15}{bad_after:>6}{new_clashes:>12}{new_outliers:>9}"
                  f"{np.sqrt(np.mean(np.square(drift))):>10.2f}")
        local = model.segments[segment].residue_index[np.arange(20)]
        full_ms = best_ms(lambda: validate(structure, model.coords), repeats=5)
        local_ms = best_ms(lambda: validate(structure, model.coords, residues=local), repeats=5)
        print(f"{'':<14}validation: whole structure {full_ms:.1f} ms, 20 residues {local_ms:.1f} ms")


if __name__ == "__main__":
    main(sys.argv[1:])
