"""Speed of remapping atoms after an edit (each residue's rotation from the old and new curve + rigid-body motion).

Usage: ``python benchmarks/bench_remap.py [STRUCTURE ...]`` (default: the test entries 1UBQ,
1TIM and 4YVS). The longest segment is edited at level 0, so every atom of it moves; the
last line remaps 100,000 atoms of one long chain (the largest structure's residues laid end
to end). Targets: under 5 ms for a 5,000-atom protein, under 50 ms for 100,000 atoms.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from timing import best_ms

from core.curves.editing import move_control_point
from core.protein.frames import remap_atoms, residue_rotations
from core.protein.model import EditableModel
from core.protein.reading import read_structure
from core.protein.ribbon import build_ribbon

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"


def longest_segment_edit(model: EditableModel) -> tuple[int, int, float]:
    """A level-0 edit of the longest segment (every residue moves): residues, atoms, ms."""
    segment = max(range(len(model.ribbons)), key=lambda s: len(model.segments[s]))
    edit = model.move_point(segment, 0, 1, [1.0, 0.5, -0.5])
    ms = best_ms(lambda: model.move_point(segment, 0, 1, [1.0, 0.5, -0.5]))
    return len(edit.residues), len(edit.rows), ms


def synthetic_chain_ms(model: EditableModel, n_atoms: int) -> tuple[int, float]:
    """Remap ``n_atoms`` atoms of one long chain (the structure's residues repeated end to end)."""
    ca = np.concatenate([s.ca for s in model.segments])
    residues = [(s, i) for s in model.segments for i in range(len(s))]
    rows = np.concatenate([np.arange(s.atom_start[i], s.atom_stop[i]) for s, i in residues])
    owner = np.concatenate([np.full(s.atom_stop[i] - s.atom_start[i], k) for k, (s, i) in enumerate(residues)])
    copies = -(-n_atoms // len(rows))
    shift = np.arange(copies)[:, None, None] * (ca[-1] - ca[0] + 3.8)  # lay the copies end to end
    long_ca = (ca[None] + shift).reshape(-1, 3)
    coords = (model.coords[rows][None] + shift).reshape(-1, 3)[:n_atoms]
    owners = (owner[None] + len(ca) * np.arange(copies)[:, None]).ravel()[:n_atoms]
    ribbon = build_ribbon("peptide", long_ca)
    moved = ribbon.with_points(ribbon.points + move_control_point(2, 3, [2.0, 0.0, 1.0], ribbon.level))

    def remap() -> np.ndarray:
        rotations = residue_rotations(ribbon.space, ribbon.points, moved.points, ribbon.residue_u)
        return remap_atoms(coords, owners, ribbon.residue_points(), moved.residue_points(), rotations)

    return len(long_ca), best_ms(remap)


def main(paths: list[str]) -> None:
    print("One edit at level 0 of the longest segment: every residue of it moves")
    print(f"{'structure':<16}{'atoms':>8}{'residues moved':>16}{'atoms moved':>13}{'ms':>8}")
    largest = None
    for path in paths or [DATA / "1UBQ.pdb.gz", DATA / "1TIM.pdb.gz", DATA / "4YVS.cif.gz"]:
        structure = read_structure(path)
        model = EditableModel(structure)
        residues, atoms, ms = longest_segment_edit(model)
        print(f"{Path(path).name:<16}{structure.n_atoms:>8}{residues:>16}{atoms:>13}{ms:>8.2f}")
        largest = model if largest is None or structure.n_atoms > largest.structure.n_atoms else largest
    residues, ms = synthetic_chain_ms(largest, 100_000)
    print(f"{'one long chain':<16}{100_000:>8}{residues:>16}{100_000:>13}{ms:>8.2f}"
          f"  ({largest.structure.entry_id} residues repeated end to end)")


if __name__ == "__main__":
    main(sys.argv[1:])
