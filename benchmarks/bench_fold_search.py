"""Fold search measured as the field measures it: Foldseek's sensitivity up to the first false
positive on a labelled SCOP set, beside exhaustive TM-align, and the cost of a query.

Usage: ``python benchmarks/bench_fold_search.py --scop FOLDER [--tm-align N [--jobs J]] [--decoys FOLDER]``,
or ``... --pdb-scale N --base FOLDER --scratch DIR``.

``FOLDER`` is laid out as the shared ``scop40-dev`` (``labels.tsv``, ``queries.txt``,
``domains/``). Every domain is indexed (as ``ribbonwave index`` does; ``--also FOLDER...``: with
the labelled domains of other such sets, as the benchmark's two halves in one index); for each
query, every other domain is ranked, and the share of its true positives (same family; same superfamily,
other family; same fold, other superfamily) ranked before the first domain of another fold is
averaged over the queries. One line per method, with the CPU seconds per query:

- ``search``: :func:`core.analysis.fold_search.search` with its defaults (the local alignment
  of 3Di states and amino acids of every domain, the best aligned by structure), its whole
  ranking (every domain, whatever its E-value);
- its first stage alone, the ranking by local alignment score made fair to length;
- the curve descriptors alone;
- the screen of a large index (the nearest by descriptor and by pair profile, half each, as
  many as ``fold_search.SCORED_CELLS`` holds) at the scale of the PDB: per query and level, the
  share of the true positives that would be scored among 800,000 chains of these domains' mean
  length (fewer domains of other folds ahead of them, by either summary, than the query's share
  of those here), averaged;
- exhaustive TM-align (``tmtools``, TM-score normalised by the query), on the first ``N``
  queries only (about a minute each on 556 domains), and ``search`` on the same queries.

``--decoys FOLDER``: the index padded with every protein chain of the structures in FOLDER
(the shared set's 255 entries), and ``search`` measured again. A decoy counts as a domain of
another fold unless exhaustive TM-align finds it of the query's fold (TM-score by the query
0.5 or more: a sialidase among the decoys is a true match of a sialidase domain); such decoys
are set aside, and counted. It prints the TM-scores (TM-align's, by the query) of the decoys
that were a query's first false positive, and of the true positives ranked behind them. With
``--tm-align N``, exhaustive TM-align ranks the padded index as well, its decoys judged by its
own TM-scores, and the search's padded line is repeated for those N queries.

``--pdb-scale N``: the cost at the size of the PDB. An index of ``N`` chains (800,000: the
PDB's protein chains) is written to ``DIR``: the chains of the structures in ``--base``
repeated, each copy perturbed (descriptors by 0.2 Å of noise, pair profiles by 0.05, a tenth of its 3Di states and a
third of its amino acids replaced at random; its Cα kept, so that the copies of a chain align
as it does). A fresh process then reads it and searches 20 of the base chains; it prints the
file's size, the resident memory after reading and at its peak, and the CPU and wall time of
a query.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import subprocess
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import tmtools

from app.cli.batch import structure_paths
from core.analysis.compare import SAME_FOLD
from core.analysis.fold_index import (
    FIELDS,
    FORMAT,
    FoldIndex,
    checksum,
    descriptor_distances,
    index_path,
    merge,
    profile_similarities,
)
from core.analysis.fold_search import (
    SCORED_CELLS,
    alignment_scores,
    length_fair,
    query_profile,
    search,
    sensitivity,
)

LEVELS = ("family", "superfamily", "fold")
PDB_CHAINS = 800_000


def build_index(paths: list[Path]) -> tuple[FoldIndex, float]:
    start = time.perf_counter()
    parts = [found for found in map(index_path, paths) if isinstance(found, FoldIndex) and len(found)]
    return merge(parts), time.perf_counter() - start


def chain(index: FoldIndex, row: int) -> tuple[np.ndarray, str]:
    ca, codes = index.chain(row)
    return ca, codes.tobytes().decode("ascii")


_TASK: Callable[[int], object] | None = None
"""What :func:`run_queries`' worker processes run (inherited by fork: closures do not pickle)."""


def _task(row: int) -> object:
    return _TASK(row)


def run_queries(task: Callable[[int], object], queries: list[int], jobs: int = 1) -> list:
    """``task(row)`` for each query, ``jobs`` at once in worker processes."""
    global _TASK
    _TASK = task
    if jobs > 1:
        with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork")) as pool:
            return list(pool.map(_task, queries))
    return [task(row) for row in queries]


def report(name: str, rankings: list[np.ndarray], cpu: list[float], queries: list[int],
           labels: dict[str, np.ndarray]) -> None:
    """Print one line of the table: the mean sensitivity of the ``rankings`` of ``queries`` and
    the mean CPU seconds per query."""
    scores = [sensitivity(ranked, *(labels[level] for level in LEVELS), row)
              for ranked, row in zip(rankings, queries, strict=True)]
    found = np.array([score for score in scores if score is not None])
    print(f"{name:<52}{len(found):>8}" + "".join(f"{value:>{width}.3f}" for value, width in
                                                  zip(found.mean(axis=0), (8, 10, 7), strict=True))
          + f"{np.mean(cpu):>13.3f}", flush=True)


def measure(name: str, rank: Callable[[int], np.ndarray], queries: list[int], labels: dict[str, np.ndarray],
            jobs: int = 1) -> tuple[list[np.ndarray], list[float]]:
    """Print one line of the table for ``rank``'s rankings of ``queries``, each timed in the
    process that ranks it (``jobs`` at once); return the rankings and their CPU seconds."""
    def timed(row: int) -> tuple[np.ndarray, float]:
        start = time.process_time()
        ranked = rank(row)
        return ranked, time.process_time() - start

    results = run_queries(timed, queries, jobs)
    rankings, cpu = [ranked for ranked, _ in results], [seconds for _, seconds in results]
    report(name, rankings, cpu, queries, labels)
    return rankings, cpu


def screen_kept(index: FoldIndex, queries: list[int], labels: dict[str, np.ndarray]) -> None:
    kept, cpu = [], []
    for row in queries:
        # the share of 800,000 chains like these that each summary lets the query score
        share = SCORED_CELLS / (index.lengths[row] * index.lengths.mean() * PDB_CHAINS) / 2
        start = time.process_time()
        nearness = (-descriptor_distances(index.descriptors, index.descriptors[row]),
                    profile_similarities(index.profiles, index.profiles[row].astype(np.float32)))
        cpu.append(time.process_time() - start)
        kinds = np.select([labels[level] == labels[level][row] for level in LEVELS], [0, 1, 2], 3)
        kinds[row] = -1
        other = kinds == 3
        ahead = [np.array([np.mean(score[other] >= score[k]) for k in range(len(kinds))]) for score in nearness]
        survives = (ahead[0] <= share) | (ahead[1] <= share)
        totals = np.bincount(kinds[kinds >= 0], minlength=4)[:3]
        if totals.all():
            kept.append(np.bincount(kinds[(kinds >= 0) & survives], minlength=4)[:3] / totals)
    print(f"{f'screen of a large index: kept at {PDB_CHAINS:,} chains':<52}{len(kept):>8}"
          + "".join(f"{value:>{width}.3f}" for value, width in zip(np.mean(kept, axis=0), (8, 10, 7), strict=True))
          + f"{np.mean(cpu):>13.3f}", flush=True)


def scop_sensitivity(folder: Path, tm_align_queries: int, decoys: Path | None, others: list[Path],
                     jobs: int = 1) -> None:
    table = {row[0]: row for labelled in [folder, *others]
             for row in (line.split("\t") for line in (labelled / "labels.tsv").read_text().splitlines()[1:])}
    index, seconds = build_index(sorted(path for labelled in [folder, *others]
                                        for path in (labelled / "domains").glob("*.pdb.gz")))
    names = [Path(str(path)).name.removesuffix(".pdb.gz") for path in index.paths]  # the domains, as labelled
    labels = {level: np.array([table[name][2 + k] for name in names], dtype=object) for k, level in enumerate(LEVELS)}
    queries = [names.index(name) for name in (folder / "queries.txt").read_text().split()]
    chains = [chain(index, row) for row in range(len(index))]
    every = len(index)
    print(f"{folder}{''.join(f' + {other}' for other in others)}: {len(index)} domains indexed in {seconds:.1f} s, "
          f"{len(queries)} queries of {folder}; sensitivity up to "
          "the first false positive (another fold), family / superfamily / fold")
    search(index, *chains[queries[0]])  # loads the compiled kernels
    print(f"{'method':<52}{'queries':>8}{'family':>8}{'superfam.':>10}{'fold':>7}{'CPU s/query':>13}")

    def searched(row: int, within: FoldIndex = index) -> np.ndarray:
        return np.array([hit.row for hit in search(within, *chains[row], top=len(within), max_evalue=np.inf)])

    def scored(row: int) -> np.ndarray:
        rows = slice(int(index.starts[row]), int(index.starts[row] + index.lengths[row]))
        profile = query_profile(index.states[rows], index.sequences[rows])
        scores = alignment_scores(index, profile, np.arange(every))
        return np.argsort(-length_fair(scores, int(index.lengths[row]), index.lengths), kind="stable")

    measure("search (defaults), every domain ranked", searched, queries, labels)
    measure("its local alignment of 3Di + amino acids alone", scored, queries, labels)
    measure("curve descriptors alone", lambda row: np.argsort(
        descriptor_distances(index.descriptors, index.descriptors[row]), kind="stable"), queries, labels)
    screen_kept(index, queries, labels)
    if decoys is not None:
        padding, _ = build_index(structure_paths([decoys]))
        padded = merge([index, padding])
        other = {level: np.concatenate([labels[level], [f"decoy {k}" for k in range(len(padding))]])
                 for level in LEVELS}
    else:
        padding, padded = None, index

    def judged(row: int, k: int) -> float:
        """TM-align's TM-score of chain ``k`` of the padded index by query ``row``."""
        ca, codes = chain(padded, k)
        return tmtools.tm_align(chains[row][0], ca, chains[row][1], codes).tm_norm_chain1

    asked = queries[:tm_align_queries]
    if tm_align_queries:
        measure(f"search on the first {len(asked)} queries", searched, asked, labels)

        def tm_aligned(row: int) -> tuple[np.ndarray, float, float]:
            """TM-align's TM-score by the query of every chain of the padded index; the CPU
            seconds for the labelled domains, and for all."""
            start = time.process_time()
            scores = [judged(row, k) for k in range(every)]
            labelled = time.process_time()
            scores += [judged(row, k) for k in range(every, len(padded))]
            return np.array(scores), labelled - start, time.process_time() - start

        aligned = run_queries(tm_aligned, asked, jobs)
        report("exhaustive TM-align (tmtools, by the query)",
               [np.argsort(-scores[:every], kind="stable") for scores, _, _ in aligned],
               [cpu for _, cpu, _ in aligned], asked, labels)
        if padding is not None:  # its decoys judged by its own TM-scores, as the search's are below
            kept = [ranked[(ranked < every) | (scores[ranked] < SAME_FOLD)] for scores, ranked in
                    ((scores, np.argsort(-scores, kind="stable")) for scores, _, _ in aligned)]
            report(f"exhaustive TM-align, padded with {len(padding)} decoys", kept,
                   [cpu for _, _, cpu in aligned], asked, other)
    if padding is not None:
        set_aside: list[int] = []
        outranking: list[tuple[float, list[float]]] = []

        def unrelated(row: int) -> np.ndarray:
            """The padded ranking less the decoys ranked before the query's last true positive
            that exhaustive TM-align finds of the query's fold (TM-score by the query 0.5 or more);
            when the first false positive left is a decoy, its TM-score and its victims' are kept."""
            ranked = searched(row, padded)
            same_fold = np.flatnonzero(other["fold"][ranked] == labels["fold"][row])
            last = same_fold[-1] if len(same_fold) else 0
            kept, first = [], None
            for position, k in enumerate(ranked.tolist()):
                if k >= every and position <= last:
                    score = judged(row, k)
                    if score >= SAME_FOLD:
                        continue
                    first = (score, position) if first is None else first
                elif first is None and k < every and labels["fold"][k] != labels["fold"][row]:
                    first = (np.nan, position)
                kept.append(k)
            victims = [] if first is None or np.isnan(first[0]) else [
                k for k in ranked[first[1]:last + 1].tolist() if k < every and k != row
                and labels["fold"][k] == labels["fold"][row]]
            if victims:
                outranking.append((first[0], [judged(row, k) for k in victims]))
            set_aside.append(len(ranked) - len(kept))
            return np.array(kept)

        rankings, cpu = measure(f"search, index padded with {len(padding)} decoy chains", unrelated, queries, other)
        if tm_align_queries:
            report(f"  the same on the first {len(asked)} queries", rankings[:len(asked)], cpu[:len(asked)], asked,
                   other)
        print(f"  decoys of the query's fold by TM-align (TM-score >= {SAME_FOLD}), set aside: {sum(set_aside)} "
              f"({np.mean(set_aside):.1f} a query; the CPU above includes these TM-align runs)")
        if outranking:
            decoy_scores = np.array([score for score, _ in outranking])
            victim_scores = np.array([score for _, scores in outranking for score in scores])
            print(f"  a decoy was the first false positive, ahead of {len(victim_scores)} true positives, "
                  f"in {len(outranking)} queries; TM-align by the query, median (range): those decoys "
                  f"{np.median(decoy_scores):.2f} ({decoy_scores.min():.2f}-{decoy_scores.max():.2f}), "
                  f"the true positives behind them {np.median(victim_scores):.2f} "
                  f"({victim_scores.min():.2f}-{victim_scores.max():.2f})")


def pdb_scale(chains: int, base: Path, scratch: Path, keep: bool = False) -> None:
    index, _ = build_index(structure_paths([base]))
    rng = np.random.default_rng(1)
    copies = rng.integers(0, len(index), chains)
    copies[:len(index)] = np.arange(len(index))  # every base chain once, unchanged, first
    lengths = index.lengths[copies]
    residues = np.concatenate([np.arange(index.starts[k], index.starts[k] + index.lengths[k]) for k in copies])
    states = index.states[residues]
    changed = rng.random(len(states)) < 0.1
    changed[:index.lengths.sum()] = False
    states[changed] = rng.integers(0, 20, changed.sum())
    sequences = index.sequences[residues]
    changed = rng.random(len(sequences)) < 1 / 3
    changed[:index.lengths.sum()] = False
    sequences[changed] = np.frombuffer(b"ACDEFGHIKLMNPQRSTVWY", dtype="S1")[rng.integers(0, 20, changed.sum())]
    coordinates = index.coordinates[residues]
    descriptors = (index.descriptors[copies].astype(np.float32)
                   + rng.normal(0.0, 0.2, (chains, index.descriptors.shape[1])).astype(np.float32)).astype(np.float16)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    sums = np.array([checksum(coordinates[a:a + n], sequences[a:a + n], states[a:a + n])
                     for a, n in zip(starts.tolist(), lengths.tolist())], dtype=np.uint32)
    path = scratch / f"pdb-scale-{chains}.npz"
    profiles = (index.profiles[copies].astype(np.float32)
                + rng.normal(0.0, 0.05, (chains, index.profiles.shape[1])).astype(np.float32)).astype(np.float16)
    arrays = {"entries": index.entries[copies], "chains": index.chains[copies], "paths": index.paths[copies],
              "lengths": lengths, "descriptors": descriptors, "profiles": profiles, "checksums": sums,
              "coordinates": coordinates, "sequences": sequences, "states": states}
    assert set(arrays) == set(FIELDS[1:])
    np.savez(path, format=np.array(FORMAT), **arrays)
    del arrays, coordinates, sequences, states, descriptors, profiles
    print(f"{chains:,} chains ({len(index)} of {base} repeated), {lengths.sum() / 1e6:.0f} million residues: "
          f"{path.stat().st_size / 1e9:.2f} GB on disk")
    queries = np.linspace(0, len(index) - 1, 20).round().astype(int).tolist()
    found = json.loads(subprocess.run([sys.executable, __file__, "--measure", str(path), *map(str, queries)],
                                      check=True, capture_output=True, text=True).stdout)
    print(f"read in {found['read_s']:.2f} s; resident {found['resident_mb']:.0f} MB after reading, "
          f"{found['peak_mb']:.0f} MB at the peak of {len(queries)} searches (the process, Python and its libraries "
          f"included: {found['empty_mb']:.0f} MB before reading)")
    print(f"a query: {np.mean(found['cpu']):.2f} s CPU (at most {np.max(found['cpu']):.2f}), "
          f"{np.mean(found['wall']):.2f} s wall; the query's own chain first in "
          f"{sum(found['self_first'])} of {len(queries)}")
    if not keep:
        path.unlink()


def measure_scale(path: Path, queries: list[int]) -> None:
    """In a fresh process: read the index and search it; print a JSON object of the figures."""
    def resident(field: str = "VmRSS") -> float:  # VmHWM: the peak (getrusage's counts the parent's, before exec)
        with open("/proc/self/status") as status:
            return next(int(line.split()[1]) for line in status if line.startswith(field)) / 1024

    empty = resident()
    start = time.perf_counter()
    index = FoldIndex.read(path)
    read = time.perf_counter() - start
    after = resident()
    cpu, wall, first = [], [], []
    search(index, *chain(index, queries[0]))  # loads the compiled kernels
    for row in queries:
        query = chain(index, row)
        start, clock = time.perf_counter(), time.process_time()
        hits = search(index, *query)
        cpu.append(time.process_time() - clock)
        wall.append(time.perf_counter() - start)
        first.append(bool(hits) and hits[0].row == row)
    print(json.dumps({"read_s": read, "empty_mb": empty, "resident_mb": after, "cpu": cpu, "wall": wall,
                      "peak_mb": resident("VmHWM"), "self_first": first}))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scop", type=Path, metavar="FOLDER",
                        help="a labelled SCOP set (labels.tsv, queries.txt, domains/)")
    parser.add_argument("--tm-align", type=int, default=0, metavar="N",
                        help="also rank the first N queries by exhaustive TM-align (slow: about a minute each)")
    parser.add_argument("--jobs", type=int, default=1, metavar="N",
                        help="--tm-align: rank N queries at once, in worker processes (CPU is still per query)")
    parser.add_argument("--decoys", type=Path, metavar="FOLDER", help="structures whose chains pad the index")
    parser.add_argument("--also", type=Path, nargs="*", default=[], metavar="FOLDER",
                        help="--scop: other labelled sets whose domains join the index (their queries are not run)")
    parser.add_argument("--pdb-scale", type=int, metavar="N", help="time a query against an index of N chains")
    parser.add_argument("--base", type=Path, metavar="FOLDER", help="--pdb-scale: the structures to repeat")
    parser.add_argument("--scratch", type=Path, metavar="DIR", help="--pdb-scale: where to write the index")
    parser.add_argument("--measure", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure:
        measure_scale(Path(args.measure[0]), [int(row) for row in args.measure[1:]])
        return
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    if args.pdb_scale:
        if args.base is None or args.scratch is None:
            parser.error("--pdb-scale needs --base and --scratch")
        pdb_scale(args.pdb_scale, args.base, args.scratch)
    elif args.scop is not None:
        scop_sensitivity(args.scop, args.tm_align, args.decoys, args.also, args.jobs)
    else:
        parser.error("give --scop FOLDER or --pdb-scale N")


if __name__ == "__main__":
    main()
