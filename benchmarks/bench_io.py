"""Reading and writing structures: milliseconds per file (targets for 4YVS, 26,430 atoms:
read in under 1 s, its secondary structure computed by DSSP in under 1 s).

Usage: ``python benchmarks/bench_io.py [STRUCTURE ...]`` (default: the test entries 1UBQ,
1TIM, 4HHB and 4YVS). For each it prints the best of 3 reads, of 3 DSSP runs on its
backbone, and of 3 writes as PDB and mmCIF of the structure moved by 0.1 Å (so that the
atoms are really rewritten).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
from timing import best_ms

from core.protein.input_files import StructureError
from core.protein.reading import read_structure
from core.protein.secondary_structure import dssp
from core.protein.writing import write_structure

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
DEFAULT = ("1UBQ.pdb.gz", "1TIM.pdb.gz", "4HHB.pdb.gz", "4YVS.cif.gz")


def main() -> None:
    paths = [Path(p) for p in sys.argv[1:]] or [DATA / name for name in DEFAULT]
    print(f"{'entry':<14}{'atoms':>8}{'read ms':>10}{'DSSP ms':>10}{'write PDB ms':>14}{'write mmCIF ms':>16}")
    with tempfile.TemporaryDirectory() as folder:
        for path in paths:
            structure = read_structure(path)
            moved = structure.coords + 0.1
            read = best_ms(lambda: read_structure(path), repeats=3)
            backbone = {k: np.concatenate([getattr(s, k) for s in structure.segments]) for k in ("n", "ca", "c", "o")}
            starts = np.concatenate([np.arange(len(s)) == 0 for s in structure.segments])
            ss = best_ms(lambda: dssp(**backbone, chain_start=starts), repeats=3)
            times = []
            for suffix in (".pdb", ".cif"):
                out = Path(folder) / f"out{suffix}"
                try:
                    times.append(f"{best_ms(lambda: write_structure(structure, moved, out, overwrite=True), 3):.0f}")
                except StructureError:  # e.g. chain ids PDB cannot hold
                    times.append("–")
            print(f"{path.name.split('.')[0]:<14}{structure.n_atoms:>8}{read:>10.0f}{ss:>10.0f}{times[0]:>14}"
                  f"{times[1]:>16}")


if __name__ == "__main__":
    main()
