"""Fold search measured as the field measures it: Foldseek's sensitivity up to the first false
positive on a labelled SCOP set, beside exhaustive TM-align, and the cost of a query.

Usage: ``python benchmarks/bench_fold_search.py --scop FOLDER [--tm-align N] [--decoys FOLDER]``.

``FOLDER`` is laid out as the shared ``scop40-dev`` (``labels.tsv``, ``queries.txt``,
``domains/``). Every domain is indexed (as ``ribbonwave index`` does); for each query, every
other domain is ranked, and the share of its true positives (same family; same superfamily,
other family; same fold, other superfamily) ranked before the first domain of another fold is
averaged over the queries. One line per method, with the CPU seconds per query:

- ``search``: :func:`core.analysis.fold_search.search` with its defaults (the local alignment
  of 3Di states and amino acids of every domain, the best aligned by structure), its whole
  ranking (every domain, whatever its E-value);
- its first stage alone, the ranking by local alignment score;
- the curve descriptors alone (the screen of indexes larger than ``fold_search.SCORED``);
- exhaustive TM-align (``tmtools``, TM-score normalised by the query), on the first ``N``
  queries only (about a minute each on 556 domains), and ``search`` on the same queries.

``--decoys FOLDER``: the index padded with every protein chain of the structures in FOLDER
(the shared set's 255 entries), and ``search`` measured again. A decoy counts as a domain of
another fold unless exhaustive TM-align finds it of the query's fold (TM-score by the query
0.5 or more: a sialidase among the decoys is a true match of a sialidase domain); such decoys
are set aside, and counted.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import tmtools

from app.cli.batch import structure_paths
from core.analysis.compare import SAME_FOLD
from core.analysis.fold_search import (
    FoldIndex,
    alignment_scores,
    descriptor_distances,
    index_path,
    merge,
    query_profile,
    search,
    sensitivity,
)

LEVELS = ("family", "superfamily", "fold")


def build_index(paths: list[Path]) -> tuple[FoldIndex, float]:
    start = time.perf_counter()
    parts = [found for found in map(index_path, paths) if isinstance(found, FoldIndex) and len(found)]
    return merge(parts), time.perf_counter() - start


def chain(index: FoldIndex, row: int) -> tuple[np.ndarray, str]:
    ca, codes = index.chain(row)
    return ca, codes.tobytes().decode("ascii")


def measure(name: str, rank: Callable[[int], np.ndarray], queries: list[int], labels: dict[str, np.ndarray]) -> None:
    scores, cpu = [], []
    for row in queries:
        start = time.process_time()
        ranked = rank(row)
        cpu.append(time.process_time() - start)
        scores.append(sensitivity(ranked, *(labels[level] for level in LEVELS), row))
    found = np.array([score for score in scores if score is not None])
    print(f"{name:<52}{len(found):>8}" + "".join(f"{value:>{width}.3f}" for value, width in
                                                  zip(found.mean(axis=0), (8, 10, 7), strict=True))
          + f"{np.mean(cpu):>13.3f}", flush=True)


def scop_sensitivity(folder: Path, tm_align_queries: int, decoys: Path | None) -> None:
    table = {row[0]: row for row in (line.split("\t") for line in (folder / "labels.tsv").read_text().splitlines()[1:])}
    index, seconds = build_index(sorted((folder / "domains").glob("*.pdb.gz")))
    names = [str(entry) for entry in index.entries]
    labels = {level: np.array([table[name][2 + k] for name in names], dtype=object) for k, level in enumerate(LEVELS)}
    queries = [names.index(name) for name in (folder / "queries.txt").read_text().split()]
    chains = [chain(index, row) for row in range(len(index))]
    every = len(index)
    print(f"{folder}: {len(index)} domains indexed in {seconds:.1f} s, {len(queries)} queries; sensitivity up to "
          "the first false positive (another fold), family / superfamily / fold")
    search(index, *chains[queries[0]])  # loads the compiled kernels
    print(f"{'method':<52}{'queries':>8}{'family':>8}{'superfam.':>10}{'fold':>7}{'CPU s/query':>13}")

    def searched(row: int, within: FoldIndex = index) -> np.ndarray:
        return np.array([hit.row for hit in search(within, *chains[row], top=len(within), max_evalue=np.inf)])

    def scored(row: int) -> np.ndarray:
        rows = slice(int(index.starts[row]), int(index.starts[row] + index.lengths[row]))
        profile = query_profile(index.states[rows], index.sequences[rows])
        return np.argsort(-alignment_scores(index, profile, np.arange(every)), kind="stable")

    measure("search (defaults), every domain ranked", searched, queries, labels)
    measure("its local alignment of 3Di + amino acids alone", scored, queries, labels)
    measure("curve descriptors alone", lambda row: np.argsort(
        descriptor_distances(index.descriptors, index.descriptors[row]), kind="stable"), queries, labels)
    if tm_align_queries:
        asked = queries[:tm_align_queries]
        measure(f"search on the first {len(asked)} queries", searched, asked, labels)
        measure("exhaustive TM-align (tmtools, by the query)", lambda row: np.argsort(-np.array(
            [tmtools.tm_align(chains[row][0], other, chains[row][1], codes).tm_norm_chain1
             for other, codes in chains]), kind="stable"), asked, labels)
    if decoys is not None:
        padding, _ = build_index(structure_paths([decoys]))
        padded = merge([index, padding])
        other = {level: np.concatenate([labels[level], [f"decoy {k}" for k in range(len(padding))]])
                 for level in LEVELS}
        set_aside = []

        def unrelated(row: int) -> np.ndarray:
            """The padded ranking less the decoys ranked before the query's last true positive
            that exhaustive TM-align finds of the query's fold (TM-score by the query 0.5 or more)."""
            ranked = searched(row, padded)
            same_fold = np.flatnonzero(other["fold"][ranked] == labels["fold"][row])
            last = same_fold[-1] if len(same_fold) else 0
            kept = [k for position, k in enumerate(ranked.tolist()) if k < every or position > last
                    or tmtools.tm_align(chains[row][0], padded.chain(k)[0], chains[row][1],
                                        padded.chain(k)[1].tobytes().decode("ascii")).tm_norm_chain1 < SAME_FOLD]
            set_aside.append(len(ranked) - len(kept))
            return np.array(kept)

        measure(f"search, index padded with {len(padding)} decoy chains", unrelated, queries, other)
        print(f"  decoys of the query's fold by TM-align (TM-score >= {SAME_FOLD}), set aside: {sum(set_aside)} "
              f"({np.mean(set_aside):.1f} a query; the CPU above includes these TM-align runs)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scop", type=Path, metavar="FOLDER", required=True,
                        help="a labelled SCOP set (labels.tsv, queries.txt, domains/)")
    parser.add_argument("--tm-align", type=int, default=0, metavar="N",
                        help="also rank the first N queries by exhaustive TM-align (slow: about a minute each)")
    parser.add_argument("--decoys", type=Path, metavar="FOLDER", help="structures whose chains pad the index")
    args = parser.parse_args()
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    scop_sensitivity(args.scop, args.tm_align, args.decoys)


if __name__ == "__main__":
    main()
