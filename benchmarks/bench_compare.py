"""Speed of fitting a compared chain on the edited chain (what the editor does when a
structure is added, and again when the edited chain changes).

Usage: ``python benchmarks/bench_compare.py``. The edited chain is 4YVS chain A (226
residues) and, apart, ubiquitin (1UBQ, 76); the compared chains are of other proteins, so
each fit is a full structural alignment (:func:`core.analysis.fold_alignment.align_folds`).
Prints the best of 3 fits, the TM-score and the aligned pairs, and the load average (other
programs on the machine slow the figures down; so does a multithreaded BLAS competing with
them: ``OPENBLAS_NUM_THREADS=1`` gives the single-core figure). Target: well under 1 s for
4YVS against a chain of about 300 residues.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from timing import best_ms

from app.editor.scene.overlay import chain_segments, chains, fit_chain
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
PAIRS = (("4YVS.cif.gz", "A", "1F9V.pdb.gz"), ("4YVS.cif.gz", "A", "7Z9T.cif.gz"), ("4YVS.cif.gz", "A", "1AYE.pdb.gz"),
         ("4YVS.cif.gz", "A", "3PTB.pdb.gz"), ("1UBQ.pdb.gz", "A", "3PTB.pdb.gz"), ("1UBQ.pdb.gz", "A", "1UBQ.pdb.gz"))


def main() -> None:
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    print(f"{'edited':<12}{'compared':<14}{'residues':>10}{'pairing':>11}{'TM-score':>10}{'aligned':>10}{'ms':>8}")
    for edited, chain, compared in PAIRS:
        fixed = chain_segments(read_structure(DATA / edited), chain)
        other = read_structure(DATA / compared)
        moving = chain_segments(other, chains(other)[0])
        fixed_ca = np.concatenate([s.ca for s in fixed])
        fit = fit_chain(fixed_ca, fixed, moving)
        ms = best_ms(lambda: fit_chain(fixed_ca, fixed, moving), repeats=3)
        sizes = f"{len(fixed_ca)}/{sum(len(s) for s in moving)}"
        print(f"{edited.split('.')[0] + ' ' + chain:<12}{compared.split('.')[0] + ' ' + moving[0].chain:<14}"
              f"{sizes:>10}{fit.pairing:>11}{fit.tm_score:>10.3f}{fit.n_aligned:>10}{ms:>8.0f}")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
