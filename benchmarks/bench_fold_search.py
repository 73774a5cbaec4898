"""Fold search against an exhaustive TM-align ranking of the same chains, and family
separation on a labelled set.

Usage: ``python benchmarks/bench_fold_search.py FOLDER [--queries N | --all] [--candidates C]
[--aligned A] [--labelled FOLDER]``, or ``... --scop FOLDER [--hits H] [--tm-align N]``. Indexes every protein chain of the structures in FOLDER (as ``ribbonwave
index`` does), then takes N chains spread evenly over the index (``--all``: every chain; the
exhaustive ranking of every chain against every chain takes hours on a small machine) as
queries. Each query is searched (:func:`core.analysis.fold_search.search`: the descriptor
ranking, ``C`` candidates screened by the alignment of every 4th Cα, the best ``A`` aligned in full) and aligned by TM-align (``tmtools``) with every
chain of the index; the TM-align top 10 (by TM-score normalised by the query; chains tied
with the tenth within 0.001 count too, as an entry's identical copies are) is compared with
the search's top 10. Prints the mean overlap and the cost of a query against the
exhaustive ranking, measured and extrapolated to the PDB (about 600,000 chains: the
exhaustive cost grows with the chains, the search's only by its descriptor ranking). A first
search, which loads the compiled kernels, is timed apart.

``--labelled FOLDER``: a folder whose subfolders are families (Debian's ``theseus-examples``
has ``cytochromes``, ``ldh`` (lactate/malate dehydrogenases) and ``trypsins``): for every
chain, the fraction of its 10 nearest chains by descriptor that are of its family, and how
well the descriptor distances alone separate pairs of one family from pairs of two (the
area under the ROC curve).

``--scop FOLDER``: a labelled SCOP set laid out as the shared ``scop40-dev`` (``labels.tsv``,
``queries.txt``, ``domains/``): Foldseek's measure, the share of each query's true positives
(same family; same superfamily, other family; same fold, other superfamily) ranked before the
first domain of another fold, averaged over the queries, for the descriptor ranking alone, the
search (its ``--hits`` best, ``--candidates`` screened, ``--aligned`` aligned in full) and, for
the first ``--tm-align N`` queries, exhaustive TM-align; and the CPU time per query.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
import tmtools

from app.cli.batch import structure_paths
from core.analysis.fold_search import FoldIndex, descriptor_distances, index_path, merge, search, sensitivity

PDB_CHAINS = 600_000
TOP = 10


def build_index(paths: list[Path]) -> tuple[FoldIndex, float]:
    start = time.perf_counter()
    parts = [found for found in map(index_path, paths) if isinstance(found, FoldIndex) and len(found)]
    return merge(parts), time.perf_counter() - start


def sequence(index: FoldIndex, row: int) -> tuple[np.ndarray, str]:
    ca, codes = index.chain(row)
    return ca, codes.tobytes().decode("ascii")


def versus_tm_align(index: FoldIndex, queries: np.ndarray, candidates: int, aligned: int) -> None:
    overlaps, ours, theirs, ranking, folds, found = [], [], [], [], [], []
    chains = [sequence(index, row) for row in range(len(index))]
    start = time.perf_counter()
    search(index, *chains[0], TOP, candidates, aligned)  # loads the compiled kernels
    print(f"first search (loading the compiled kernels): {time.perf_counter() - start:.2f} s")
    print(f"{'query':<12}{'length':>7}{'overlap':>9}{'search s':>10}{'TM-align s':>12}{'ratio':>9}   top hits")
    for row in queries.tolist():
        ca, codes = chains[row]
        start = time.perf_counter()
        descriptor_distances(index.descriptors, index.descriptors[row])
        ranking.append(time.perf_counter() - start)
        start = time.perf_counter()
        hits = search(index, ca, codes, TOP, candidates, aligned)
        ours.append(time.perf_counter() - start)
        start = time.perf_counter()
        scores = np.array([tmtools.tm_align(ca, other, codes, other_codes).tm_norm_chain1
                           for other, other_codes in chains])
        theirs.append(time.perf_counter() - start)
        tenth = np.sort(scores)[::-1][TOP - 1]
        best = set(np.flatnonzero(scores >= tenth - 0.001).tolist())
        overlaps.append(len({hit.row for hit in hits} & best) / TOP)
        same = set(np.argsort(scores)[::-1][:TOP][scores[np.argsort(scores)[::-1][:TOP]] >= 0.5].tolist())
        folds.append(len(same))
        found.append(len(same & {hit.row for hit in hits}))
        name = f"{index.entries[row]}:{index.chains[row]}"
        print(f"{name:<12}{len(ca):>7}{overlaps[-1]:>9.0%}{ours[-1]:>10.2f}{theirs[-1]:>12.1f}"
              f"{ours[-1] / theirs[-1]:>9.4f}   " + " ".join(f"{h.entry}:{h.chain} {h.match.tm_score_a:.2f}"
                                                      for h in hits[1:4]), flush=True)
    ours, theirs, ranking = np.array(ours), np.array(theirs), np.array(ranking)
    per_chain = ranking.mean() / len(index)
    extrapolated = (ours.mean() - ranking.mean() + per_chain * PDB_CHAINS) / (theirs.mean() / len(index) * PDB_CHAINS)
    print(f"\n{len(queries)} queries against {len(index)} chains: top-{TOP} overlap with TM-align "
          f"{np.mean(overlaps):.0%} (worst {min(overlaps):.0%}); of TM-align's hits of the same fold (TM-score >= 0.5) "
          f"among its top {TOP}, {sum(found) / max(sum(folds), 1):.0%} are in the search's; a query costs "
          f"{ours.mean():.2f} s against {theirs.mean():.1f} s, "
          f"{ours.sum() / theirs.sum():.4f} of the exhaustive ranking (1/{theirs.sum() / ours.sum():.0f})")
    print(f"descriptor ranking {1e9 * per_chain:.0f} ns a chain; extrapolated to {PDB_CHAINS:,} chains: "
          f"{extrapolated:.5f} of the exhaustive ranking (1/{1 / extrapolated:.0f})")


def family_separation(folder: Path) -> None:
    families = sorted(p for p in folder.iterdir() if p.is_dir())
    parts, labels = [], []
    for family in families:
        for path in structure_paths([family]):
            found = index_path(path)
            if isinstance(found, FoldIndex) and len(found):
                parts.append(found)
                labels += [family.name] * len(found)
    index, labels = merge(parts), np.array(labels)
    distance = np.array([descriptor_distances(index.descriptors, index.descriptors[k]) for k in range(len(index))])
    np.fill_diagonal(distance, np.inf)
    same = labels[:, None] == labels[None, :]
    nearest = np.argsort(distance, axis=1)[:, :TOP]
    precision = same[np.arange(len(index))[:, None], nearest].mean(axis=1)
    upper = np.triu_indices(len(index), 1)
    within, between = distance[upper][same[upper]], distance[upper][~same[upper]]
    ranks = np.argsort(np.argsort(np.concatenate([within, between])))  # Mann–Whitney: AUC from the ranks
    auc = 1.0 - (ranks[:len(within)].sum() - len(within) * (len(within) - 1) / 2) / (len(within) * len(between))
    print(f"\nlabelled set {folder.name}: {len(index)} chains in {len(families)} families "
          f"({', '.join(f'{f.name} {np.sum(labels == f.name)}' for f in families)})")
    for family in families:
        rows = labels == family.name
        inside = distance[np.ix_(rows, rows)]
        print(f"  {family.name:<12} of its {TOP} nearest by descriptor, of its family: {precision[rows].mean():.1%}; "
              f"median distance within {np.median(inside[np.isfinite(inside)]):.2f} Å, "
              f"to the others {np.median(distance[np.ix_(rows, ~rows)]):.2f} Å")
    print(f"  pairs of one family against pairs of two by descriptor distance: ROC AUC {auc:.3f}")


LEVELS = ("family", "superfamily", "fold")


def scop_sensitivity(folder: Path, candidates: int, aligned: int, hits: int, tm_align_queries: int) -> None:
    """The table of the measure of ``folder``'s README (``labels.tsv``, ``queries.txt``, ``domains/``):
    per method, family / superfamily / fold sensitivity to the first false positive and the CPU per query."""
    table = {row[0]: row for row in (line.split("\t") for line in (folder / "labels.tsv").read_text().splitlines()[1:])}
    paths = sorted((folder / "domains").glob("*.pdb.gz"))
    index, seconds = build_index(paths)
    names = [str(entry) for entry in index.entries]
    labels = {level: np.array([table[name][2 + k] for name in names]) for k, level in enumerate(LEVELS)}
    queries = [names.index(name) for name in (folder / "queries.txt").read_text().split()]
    chains = [sequence(index, row) for row in range(len(index))]
    print(f"{folder}: {len(index)} domains indexed in {seconds:.1f} s, {len(queries)} queries; sensitivity up to "
          "the first false positive (another fold), family / superfamily / fold")
    search(index, *chains[queries[0]], hits, candidates, aligned)  # loads the compiled kernels
    methods = {
        "descriptor ranking (all domains)": lambda row: np.argsort(
            descriptor_distances(index.descriptors, index.descriptors[row]), kind="stable"),
        f"search, {candidates} candidates, {aligned} aligned, {hits} hits": lambda row: np.array(
            [hit.row for hit in search(index, *chains[row], hits, candidates, aligned)], dtype=np.int64),
    }
    if tm_align_queries:
        methods["exhaustive TM-align (tmtools, by the query)"] = lambda row: np.argsort(-np.array(
            [tmtools.tm_align(chains[row][0], other, chains[row][1], codes).tm_norm_chain1 for other, codes in chains]),
            kind="stable")
    print(f"{'method':<48}{'queries':>8}{'family':>8}{'superfam.':>10}{'fold':>7}{'CPU s/query':>13}")
    for method, rank in methods.items():
        asked = queries[:tm_align_queries] if method.startswith("exhaustive") else queries
        scores, cpu = [], []
        for row in asked:
            start = time.process_time()
            ranked = rank(row)
            cpu.append(time.process_time() - start)
            scores.append(sensitivity(ranked, *(labels[level] for level in LEVELS), row))
        found = np.array([score for score in scores if score is not None])
        print(f"{method:<48}{len(found):>8}" + "".join(f"{value:>{width}.3f}" for value, width in
                                                      zip(found.mean(axis=0), (8, 10, 7), strict=True))
              + f"{np.mean(cpu):>13.3f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path, nargs="?", help="structures to index (not with --scop)")
    parser.add_argument("--queries", type=int, default=8, help="query chains spread over the index (default 8)")
    parser.add_argument("--all", action="store_true", help="every chain of the index as a query")
    parser.add_argument("--candidates", type=int, default=60, help="chains screened per query (default 60)")
    parser.add_argument("--aligned", type=int, default=15, help="chains aligned in full per query (default 15)")
    parser.add_argument("--labelled", type=Path, help="a folder of family subfolders")
    parser.add_argument("--scop", type=Path, metavar="FOLDER",
                        help="a labelled SCOP set (labels.tsv, queries.txt, domains/): Foldseek's sensitivity table")
    parser.add_argument("--hits", type=int, default=10, help="--scop: hits the search lists (default 10)")
    parser.add_argument("--tm-align", type=int, default=0, metavar="N",
                        help="--scop: also rank the first N queries by exhaustive TM-align (slow: about a minute each)")
    args = parser.parse_args()
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    if args.scop is not None:
        scop_sensitivity(args.scop, args.candidates, args.aligned, args.hits, args.tm_align)
        return
    if args.folder is None:
        parser.error("give a folder of structures, or --scop FOLDER")
    paths = structure_paths([args.folder])
    index, seconds = build_index(paths)
    print(f"indexed {len(index)} chains of {len(paths)} files in {seconds:.1f} s (one process); "
          f"descriptors {index.descriptors.nbytes / 1e3:.0f} kB, {index.descriptors.nbytes // len(index)} bytes "
          f"a chain (in memory); Cα and sequences {(index.coordinates.nbytes + index.sequences.nbytes) / 1e6:.1f} MB, "
          f"{(index.coordinates.nbytes + index.sequences.nbytes) / index.lengths.sum():.0f} bytes a residue "
          "(mapped from the file, read per candidate)")
    count = len(index) if args.all else min(args.queries, len(index))
    versus_tm_align(index, np.unique(np.linspace(0, len(index) - 1, count).round().astype(int)), args.candidates,
                    args.aligned)
    if args.labelled is not None:
        family_separation(args.labelled)


if __name__ == "__main__":
    main()
