"""Fold search commands: ``index`` (the 3Di states, sequence, Cα and curve descriptors of every
protein chain of many files, in one file) and ``search`` (the chains of an index most like a
query's fold, with E-values and TM-scores).
Core does the science (:mod:`core.analysis.fold_search`); this module reads arguments, runs
files in parallel as ``analyze`` does, writes the index and prints.

The field names of ``search --json`` are a contract for other programs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
from tqdm import tqdm

from app.arguments import bounded, file_and_chain, writable_output
from app.cli.batch import batch_arguments, run_tasks, structure_paths
from app.cli.structure import load
from app.errors import InputError
from core.analysis.database import SkippedFile
from core.analysis.fold_index import DESCRIPTOR_SIZE, MIN_RESIDUES, PROFILE_SIZE, FoldIndex, index_path, merge
from core.analysis.fold_search import ALIGNED, MAX_EVALUE, PROFILED, TOP, Hit, chains_scored, search
from core.protein.structure import Structure
from core.protein.writing import atomic_write

# --------------------------------------------------------------------------- index


def index_arguments(parser: argparse.ArgumentParser) -> None:
    batch_arguments(parser)
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="DB", help="the index file to write (.npz)")
    parser.add_argument("--overwrite", action="store_true", help="replace DB if it exists")


def run_index(args: argparse.Namespace) -> int:
    output: Path = args.output
    writable_output(output, args.overwrite)
    paths = structure_paths(args.paths)
    start = time.perf_counter()
    found: dict[int, FoldIndex] = {}
    skipped: dict[int, SkippedFile] = {}
    with tqdm(total=len(paths), unit="file", desc="indexing", file=sys.stderr, mininterval=0.5) as progress:
        for k, result in run_tasks(index_path, paths, args.jobs, args.scheduler, SkippedFile):
            progress.update()
            if isinstance(result, SkippedFile):
                progress.write(f"skipped {result.path}: {result.reason}", file=sys.stderr)
                skipped[k] = result
            elif len(result):
                found[k] = result
    if not found:
        raise InputError(f"no protein chain of {MIN_RESIDUES} residues or more in the {len(paths)} file(s)"
                         + (f" ({len(skipped)} skipped)" if skipped else ""))
    index = merge([found[k] for k in sorted(found)])  # in input order, whatever order the workers finished in
    data = index.to_bytes()
    try:
        atomic_write(output, data)
    except OSError as error:
        raise InputError(f"{output}: cannot write ({error.strerror or error})") from None
    print(f"indexed {len(index)} chains of {len(found)} file(s) in {time.perf_counter() - start:.1f} s"
          + (f"; skipped {len(skipped)} file(s)" if skipped else ""))
    print(f"wrote {output} ({len(data) / 1e6:.2f} MB; {2 * (DESCRIPTOR_SIZE + PROFILE_SIZE)} bytes a chain and 14 a residue)")
    return 0


# --------------------------------------------------------------------------- search


def search_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("query", metavar="QUERY[:CHAIN]",
                        help="structure file of the query, optionally with a chain (default: its longest chain)")
    parser.add_argument("index", type=Path, metavar="DB", help="an index written by 'ribbonwave index'")
    parser.add_argument("--top", type=bounded(int, 1, 100000), default=TOP, metavar="K",
                        help="hits to list at most (default %(default)s)")
    parser.add_argument("--aligned", type=bounded(int, 1, 100000), default=ALIGNED, metavar="A",
                        help="chains of best alignment score (made fair to length) aligned by structure, besides the "
                        f"{PROFILED} nearest by pair profile (default %(default)s)")
    parser.add_argument("--max-evalue", type=bounded(float, 0.0, 1e9), default=MAX_EVALUE, metavar="E",
                        help="leave out hits of a larger E-value, unless their TM-score is 0.5 or more "
                        "(default %(default)s)")
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of the table")


def run_search(args: argparse.Namespace) -> int:
    path, chain = file_and_chain(args.query)
    if zipfile.is_zipfile(path):  # (an index is a zip archive; no structure file is)
        raise InputError(f"{path}: a fold index, not a structure: give the query's structure first, then the index "
                         "(ribbonwave search QUERY DB)")
    structure = load(path)
    chain = chain or _longest_chain(structure)
    segments = [s for s in structure.segments if s.chain == chain]
    if not segments:
        chains = ", ".join(dict.fromkeys(s.chain for s in structure.segments))
        raise InputError(f"{path}: no protein chain {chain!r} (chains: {chains})")
    residues = sum(len(s) for s in segments)
    if residues < MIN_RESIDUES:  # (its TM-scores and E-values would mean little; the index holds none either)
        raise InputError(f"{path}: chain {chain} has {residues} residue(s): a fold search needs a chain of "
                         f"{MIN_RESIDUES} or more (a peptide has no fold to search)")
    if not args.index.exists():
        raise InputError(f"{args.index}: no such file")
    if not args.index.is_file():
        raise InputError(f"{args.index}: not a regular file (a folder, device or FIFO is not a fold index)")
    try:
        index = FoldIndex.read(args.index)
    except ValueError as error:
        raise InputError(str(error)) from None
    start = time.perf_counter()
    ca = np.concatenate([s.ca for s in segments])
    try:
        hits = search(index, ca, "".join(s.sequence for s in segments), args.top, args.aligned, args.max_evalue)
    except ValueError as error:  # a chain of the index found damaged as it is read
        raise InputError(f"{args.index}: {error}") from None
    seconds = time.perf_counter() - start
    report = {
        "query": f"{path} chain {chain}",
        "query_length": len(ca),
        "searched": len(index),
        "scored": chains_scored(index, len(ca)),
        "aligned": min(args.aligned + PROFILED, len(index)),
        "max_evalue": args.max_evalue,
        "seconds": round(seconds, 3),
        "hits": [_hit(hit) for hit in hits],
    }
    print(json.dumps(report, indent=2) if args.json else _table(report))
    return 0


def _hit(hit: Hit) -> dict:
    found = {"entry": hit.entry, "chain": hit.chain, "path": hit.path, "length": hit.length,
             "evalue": float(f"{hit.evalue:.3g}"), "bits": round(hit.score / 2, 1)}
    match = hit.match
    return found | {
        "tm_score": None if match is None else round(match.tm_score_a, 4),
        "tm_score_hit": None if match is None else round(match.tm_score_b, 4),
        "n_aligned": None if match is None else match.n_aligned,
        "rms": None if match is None else round(match.rms_aligned, 3),
        "identity": None if match is None else round(match.identity, 4),
        "fold_score": None if hit.fold_score is None else round(hit.fold_score, 4),
    }


def _table(report: dict) -> str:
    lines = [(f"{report['query']} ({report['query_length']} residues) against {report['searched']} chains: "
              f"{report['scored']} scored by the alignment of 3Di states and amino acids, {report['aligned']} (the best "
              f"and the nearest by pair profile) aligned by structure, in {report['seconds']:.2f} s; "
              f"{len(report['hits'])} hits of E-value {report['max_evalue']:g} or less or TM-score 0.5 or more"),
             ("TM-score normalised by the query (and by the hit); below 0.5 the folds differ; E-value: the unrelated "
              "chains expected to score as high"),
             (f"{'rank':>4}  {'entry':<12} {'chain':<6}{'length':>7}{'E-value':>10}{'bits':>7}{'TM-score':>10}"
              f"{'(hit)':>8}{'aligned':>9}{'rms Å':>8}{'identity':>10}")]
    for rank, hit in enumerate(report["hits"], 1):
        line = (f"{rank:>4}  {hit['entry']:<12} {hit['chain']:<6}{hit['length']:>7}{hit['evalue']:>10.2g}"
                f"{hit['bits']:>7.1f}")
        if hit["tm_score"] is not None:
            line += (f"{hit['tm_score']:>10.4f}{hit['tm_score_hit']:>8.4f}{hit['n_aligned']:>9}{hit['rms']:>8.2f}"
                     f"{100 * hit['identity']:>9.1f}%")
        lines.append(line)
    return "\n".join(lines)


def _longest_chain(structure: Structure) -> str:
    length: dict[str, int] = {}
    for segment in structure.segments:
        length[segment.chain] = length.get(segment.chain, 0) + len(segment)
    if not length:
        raise InputError(f"{structure.path}: no protein chain")
    return max(length, key=lambda chain: length[chain])
