"""Speed of ``ribbonwave analyze`` on a folder of structures, and the reference table it reproduces.

Usage: ``python benchmarks/bench_analysis.py FOLDER [--jobs N]``. Prints the wall-clock time of
the whole command (start-up, reading, analysis on N processes, CSV and PNG output) on the
folder, the time of reading and of analysing every file in one process, and the load
average (other programs on the machine slow the figures down).

When FOLDER has a ``MANIFEST.tsv`` whose ``category`` column marks ``diverse`` entries (the
project's shared structure set), the command is also run on those with the selection of
the mathematics document §12.2 (longest chain, one curve across gaps, Cα-only terminal
points, classes from HELIX/SHEET records only) and its pooled rms are printed next to the
document's table. Target: about 250 entries in under 20 s on 2 cores.
"""

from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from core.analysis.database import AnalysisOptions, analyse_structure
from core.protein.reading import read_structure

COMMAND = [sys.executable, "-c", "import sys; from app.main import main; sys.exit(main())"]
# Math doc §12.2: (mode, depth) -> rms all, helix, sheet, other (peptide ribbon), all (Cα ribbon).
REFERENCE = {
    ("integer", "0"): (1.22, 1.39, 0.93, 1.18, 0.00),
    ("integer", "1"): (1.57, 1.93, 1.03, 1.38, 1.45),
    ("integer", "2"): (2.07, 2.39, 1.40, 2.03, 2.05),
    ("integer", "3"): (3.22, 3.06, 2.75, 3.61, 3.22),
    ("integer", "4"): (6.71, 5.31, 6.61, 7.85, 6.73),
    ("fractional", "1"): (1.80, 2.14, 1.18, 1.69, 1.70),
    ("fractional", "2"): (2.57, 2.64, 1.96, 2.75, 2.55),
    ("fractional", "2.5"): (3.34, 3.05, 2.82, 3.79, 3.36),
    ("fractional", "2.6"): (3.56, 3.17, 3.06, 4.08, 3.60),
    ("fractional", "3"): (4.84, 3.92, 4.46, 5.61, 4.92),
}


def analyze(paths: list[Path], out: Path, jobs: int, *options: str) -> float:
    """Seconds of one ``ribbonwave analyze`` run in a fresh interpreter."""
    start = time.perf_counter()
    subprocess.run([*COMMAND, "analyze", *map(str, paths), "-o", str(out), "--jobs", str(jobs), *options],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def one_process(folder: Path) -> tuple[int, int, float, float]:
    """Files, residues, seconds reading and seconds analysing every file in this process."""
    from app.cli.batch import structure_paths

    structures, reading = [], time.perf_counter()
    for path in structure_paths([folder]):
        try:
            structures.append(read_structure(path))
        except ValueError:
            pass
    reading = time.perf_counter() - reading
    analysing = time.perf_counter()
    residues = sum(len(analyse_structure(s, AnalysisOptions())) for s in structures)
    return len(structures), residues, reading, time.perf_counter() - analysing


def reference_table(folder: Path, out: Path, jobs: int) -> None:
    """Run the §12.2 selection on the 'diverse' entries and print it next to the document's table."""
    with (folder / "MANIFEST.tsv").open() as handle:
        diverse = [folder / row["file"] for row in csv.DictReader(handle, delimiter="\t") if row["category"] == "diverse"]
    seconds = analyze(diverse, out, jobs, "--chains", "longest", "--gaps", "join", "--termini", "calpha",
                      "--ss", "records", "--max-depth", "4", "--fraction-step", "0.1")
    with (out / "summary.csv").open() as handle:
        rms = {(r["ribbon"], r["mode"], r["depth"], r["class"]): float(r["rms"]) for r in csv.DictReader(handle)}
    print(f"\nmath doc §12.2 selection: {len(diverse)} 'diverse' entries in {seconds:.1f} s; "
          "pooled rms in Å, this run / the document")
    print(f"{'depth':<16}{'all':>13}{'helix':>13}{'sheet':>13}{'other':>13}{'Cα all':>13}   largest |difference|")
    worst = 0.0
    for (mode, depth), expected in REFERENCE.items():
        keys = [("peptide", c) for c in ("all", "helix", "sheet", "other")] + [("calpha", "all")]
        got = [rms[(ribbon, mode, depth, name)] for ribbon, name in keys]
        difference = max(abs(g - e) for g, e in zip(got, expected))
        worst = max(worst, difference)
        print(f"{mode + ' ' + depth:<16}" + "".join(f"{g:>7.2f}/{e:<5.2f}" for g, e in zip(got, expected))
              + f"   {difference:.3f}")
    print(f"largest difference {worst:.3f} Å")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        seconds = analyze([args.folder], Path(tmp) / "all", args.jobs)
        files, residues, reading, analysing = one_process(args.folder)
        print(f"ribbonwave analyze {args.folder} --jobs {args.jobs}: {seconds:.1f} s for {files} files, "
              f"{residues} residues (target < 20 s on 2 cores)")
        print(f"one process: reading {reading:.1f} s, analysing {analysing:.1f} s "
              f"({1e3 * analysing / residues * 1000:.1f} ms per 1000 residues, both ribbons, all depths)")
        if (args.folder / "MANIFEST.tsv").exists():
            reference_table(args.folder, Path(tmp) / "reference", args.jobs)
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
