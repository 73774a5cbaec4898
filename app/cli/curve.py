"""The headless ``curve`` command: the residue points C^r of a ribbon at a level.

``curve --csv`` is a contract for other programs: it keeps its columns.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

from app.arguments import LEVEL, bounded
from app.cli.structure import chain_segments, load, model_argument, segment_number
from core.protein.ribbon import RibbonKind, segment_ribbon

CURVE_COLUMNS = ("chain", "segment", "resseq", "icode", "resname", "ss",
                 "ca_x", "ca_y", "ca_z", "cr_x", "cr_y", "cr_z", "dist")


def curve_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    parser.add_argument("--chain", metavar="ID", help="only this chain (default: all)")
    model_argument(parser)
    ribbon_argument(parser)
    parser.add_argument(
        "--level", type=bounded(float, *LEVEL), metavar="L",
        help="Carson level: log2 N shows the original curve (default), lower levels smoother; "
        "levels above a segment's maximum mean full resolution",
    )
    parser.add_argument("--csv", action="store_true", help="comma-separated values with a header row")


def run_curve(args: argparse.Namespace) -> int:
    structure = load(args.file, args.model)
    numbers = chain_segments(structure, args.chain)
    rows = []
    for number in numbers:
        segment = structure.segments[number]
        ribbon = segment_ribbon(segment, args.ribbon)
        cr = ribbon.residue_points(args.level)
        dist = np.linalg.norm(cr - segment.ca, axis=1)
        for i in range(len(segment)):
            rows.append((segment.chain, segment_number(structure, number), int(segment.resseq[i]), segment.icode[i],
                         segment.resname[i], segment.ss[i], *segment.ca[i], *cr[i], dist[i]))
    if args.csv:
        writer = csv.writer(sys.stdout, lineterminator="\n")
        writer.writerow(CURVE_COLUMNS)
        writer.writerows([*row[:6], *(f"{x:.3f}" for x in row[6:])] for row in rows)
        return 0
    print(f"{'chain':<6}{'seg':>4}{'resseq':>7}{'':1} {'res':<4}{'ss':<3}{'Cα (Å)':>26}{'C^r (Å)':>27}{'|Cα-C^r|':>10}")
    for row in rows:
        ca, cr = row[6:9], row[9:12]
        print(f"{row[0]:<6}{row[1]:>4}{row[2]:>7}{row[3]:1} {row[4]:<4}{row[5]:<3}"
              f"{ca[0]:>9.3f}{ca[1]:>9.3f}{ca[2]:>9.3f} {cr[0]:>9.3f}{cr[1]:>9.3f}{cr[2]:>9.3f}{row[12]:>9.3f}")
    distances = np.array([row[12] for row in rows])
    print(f"rms |Cα - C^r| = {np.sqrt(np.mean(distances**2)):.3f} Å over {len(rows)} residues")
    return 0


def ribbon_argument(parser: argparse.ArgumentParser) -> None:
    """Declare ``--ribbon peptide|calpha`` (the curve of the commands on one ribbon)."""
    parser.add_argument("--ribbon", choices=[k.value for k in RibbonKind], default=RibbonKind.PEPTIDE.value,
                        help="peptide-plane ribbon (default) or the curve through the Cα atoms")
