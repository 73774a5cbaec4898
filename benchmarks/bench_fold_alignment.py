"""The structural alignment side by side with TM-align (``tmtools``, a test and benchmark
dependency) on pairs of chains of a folder of structures.

Usage: ``python benchmarks/bench_fold_alignment.py FOLDER [--pairs N] [--all] [--seed S]``.
Each entry gives its longest protein chain; the pairs are every pair of the entries named in
``FAMILIES`` that the folder has (homologues, remote and close) and N random pairs of the
others (unrelated folds mostly; ``--all``: every pair, which takes hours). For every pair
both programs align the same Cα (chain a first), and the TM-scores compared are normalised
by chain a. The first alignment, which loads (or compiles) the compiled kernels, is timed apart.
Prints each pair, then the fraction of pairs within 0.02 of TM-align, the
fraction not lower by more than 0.02, the largest shortfall, and the time ratio (ours over
TM-align's, the sum over the pairs and the median pair). Goals: within 0.02 on 95% of the
pairs, never more than 0.05 lower, at most half TM-align's time.
"""

from __future__ import annotations

import argparse
import itertools
import os
import random
import time
from pathlib import Path

import numpy as np
import tmtools

from app.cli.batch import structure_paths
from core.analysis.fold_alignment import align_folds
from core.protein.reading import read_structure

FAMILIES = (("3PTB", "1GBT", "1ACB", "1BMA", "1AVG", "3SGB", "1FN8", "4ZHL"), ("1TIM", "8TIM", "1AFS"),
            ("171L", "1AM7"), ("1UBQ", "2K39"))
"""Entries of the shared set labelled as one family (serine proteases, TIM barrels, lysozymes, ubiquitin)."""


def longest_chain(path: Path) -> tuple[str, np.ndarray, str] | None:
    """(entry, Cα, one-letter sequence) of the longest protein chain, None without one."""
    try:
        structure = read_structure(path)
    except ValueError:
        return None
    chains: dict[str, list] = {}
    for segment in structure.segments:
        chains.setdefault(segment.chain, []).append(segment)
    if not chains:
        return None
    segments = max(chains.values(), key=lambda found: sum(len(s) for s in found))
    return structure.entry_id, np.concatenate([s.ca for s in segments]), "".join(s.sequence for s in segments)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--pairs", type=int, default=100, help="random pairs besides the families (default 100)")
    parser.add_argument("--all", action="store_true", help="every pair of entries")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    chains = {}
    for path in structure_paths([args.folder]):
        found = longest_chain(path)
        if found is not None and len(found[1]) >= 20:
            chains[found[0]] = found
    names = sorted(chains)
    family = [pair for members in FAMILIES for pair in itertools.combinations([m for m in members if m in chains], 2)]
    if args.all:
        pairs = list(itertools.combinations(names, 2))
    else:
        rng = random.Random(args.seed)
        others = set()
        while len(others) < min(args.pairs, len(names) * (len(names) - 1) // 2):
            others.add(tuple(rng.sample(names, 2)))
        pairs = family + sorted(others - set(family))
    (_, ca_a, _), (_, ca_b, _) = chains[pairs[0][0]], chains[pairs[0][1]]
    start = time.perf_counter()
    align_folds(ca_a, ca_b)  # loads the compiled kernels (compiles them on the first run after an install)
    print(f"first alignment (loading the compiled kernels): {time.perf_counter() - start:.2f} s")
    print(f"{len(chains)} chains, {len(pairs)} pairs ({len(family)} within families); load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    print(f"{'a':<13}{'b':<13}{'n_a':>5}{'n_b':>5}{'TM-align':>10}{'ours':>8}{'Δ':>8}{'TM-align ms':>13}{'ours ms':>9}")
    rows = []
    for a, b in pairs:
        (_, ca_a, seq_a), (_, ca_b, seq_b) = chains[a], chains[b]
        start = time.perf_counter()
        theirs = tmtools.tm_align(ca_a, ca_b, seq_a, seq_b).tm_norm_chain1
        middle = time.perf_counter()
        ours = align_folds(ca_a, ca_b).tm_score
        end = time.perf_counter()
        rows.append((theirs, ours, middle - start, end - middle))
        print(f"{a:<12} {b:<12} {len(ca_a):>5}{len(ca_b):>5}{theirs:>10.3f}{ours:>8.3f}{ours - theirs:>+8.3f}"
              f"{1e3 * (middle - start):>13.1f}{1e3 * (end - middle):>9.1f}", flush=True)
    in_family = np.array([pair in set(family) for pair in pairs])
    for name, chosen in (("all pairs", np.ones(len(rows), dtype=bool)), ("within families", in_family),
                         ("the others", ~in_family)):
        if chosen.any():
            summary(name, np.array(rows)[chosen])


def summary(name: str, rows: np.ndarray) -> None:
    theirs, ours, t_theirs, t_ours = rows.T
    delta = ours - theirs
    print(f"\n{name}: {len(rows)}; within 0.02 of TM-align: {np.mean(np.abs(delta) <= 0.02):.1%}; not lower by "
          f"more than 0.02: {np.mean(delta >= -0.02):.1%}; largest shortfall {delta.min():+.3f}, largest excess "
          f"{delta.max():+.3f}")
    print(f"same verdict at 0.5: {np.mean((ours >= 0.5) == (theirs >= 0.5)):.1%}; time per pair: TM-align "
          f"{1e3 * t_theirs.mean():.0f} ms, ours {1e3 * t_ours.mean():.0f} ms (ratio "
          f"{t_ours.sum() / t_theirs.sum():.2f}, median pair {np.median(t_ours / t_theirs):.2f})")

if __name__ == "__main__":
    main()
