"""Headless commands on one structure: ``info``, ``curve`` and ``edit`` (core only, no Qt).

Output formats are a contract for other programs: ``info --json`` and ``curve --csv`` keep
their field names.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from core.model import EditableModel
from core.regularize import regularized
from core.ribbon import RibbonKind, segment_ribbon
from core.structure import BackboneSegment, Structure, StructureError, read_structure
from core.validation import validate

CURVE_COLUMNS = ("chain", "segment", "resseq", "icode", "resname", "ss",
                 "ca_x", "ca_y", "ca_z", "cr_x", "cr_y", "cr_z", "dist")


class InputError(Exception):
    """Bad input the user can fix (any command): one line on stderr, exit status 1."""


def load(path: Path) -> Structure:
    """Read a structure, turning reader errors into :class:`InputError`; print its warnings."""
    try:
        structure = read_structure(path)
    except StructureError as error:
        raise InputError(str(error)) from None
    for warning in structure.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    return structure


# ------------------------------------------------------------------------------ info


def info_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of text")


def summary(structure: Structure) -> dict:
    """Chains, segments, residues, secondary structure and maximum levels of a structure."""
    segments = []
    for number, segment in enumerate(structure.segments):
        segments.append({
            "chain": segment.chain,
            "segment": _segment_number(structure, number),
            "first": segment.labels[0],
            "last": segment.labels[-1],
            "residues": len(segment),
            "max_level_peptide": round(float(np.log2(len(segment))), 4),
            "max_level_calpha": round(float(np.log2(len(segment) + 1)), 4),
        })
    ss = Counter(np.concatenate([s.ss for s in structure.segments]).tolist())
    return {
        "file": str(structure.path),
        "format": structure.source_format,
        "entry": structure.entry_id,
        "title": structure.title,
        "models": structure.n_models,
        "atoms": structure.n_atoms,
        "hetero_atoms": structure.n_hetero_atoms,
        "water_atoms": structure.n_water_atoms,
        "altloc_atoms": structure.n_altloc_atoms,
        "chains": [
            {"chain": c.name, "residues": c.n_residues, "backbone_residues": c.n_backbone, "segments": c.n_segments}
            for c in structure.chains
        ],
        "segments": segments,
        "residues": structure.n_residues,
        "secondary_structure": {"H": ss["H"], "E": ss["E"], "C": ss["C"]},
        "secondary_structure_source": structure.ss_source,
        "warnings": list(structure.warnings),
    }


def run_info(args: argparse.Namespace) -> int:
    report = summary(load(args.file))
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    ss = report["secondary_structure"]
    print(f"{report['file']}: {report['entry']} ({report['format']}), {report['title'] or 'no title'}")
    print(f"  {report['atoms']} atoms ({report['hetero_atoms']} hetero, {report['water_atoms']} water, "
          f"{report['altloc_atoms']} with altlocs); {report['models']} model(s), the first is used")
    print(f"  {report['residues']} backbone residues: {ss['H']} helix, {ss['E']} sheet, {ss['C']} other "
          f"(from {report['secondary_structure_source']})")
    print(f"  {'chain':<6}{'seg':>4}  {'residues':>8}  {'from':<14}{'to':<14}{'max level':>10}")
    for s in report["segments"]:
        print(f"  {s['chain']:<6}{s['segment']:>4}  {s['residues']:>8}  {s['first']:<14}{s['last']:<14}"
              f"{s['max_level_peptide']:>10.2f}")
    return 0


# ----------------------------------------------------------------------------- curve


def curve_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    parser.add_argument("--chain", metavar="ID", help="only this chain (default: all)")
    _ribbon_argument(parser)
    parser.add_argument(
        "--level", type=float, metavar="L",
        help="Carson level: log2 N shows the original curve (default), lower levels smoother; "
        "levels above a segment's maximum mean full resolution",
    )
    parser.add_argument("--csv", action="store_true", help="comma-separated values with a header row")


def run_curve(args: argparse.Namespace) -> int:
    structure = load(args.file)
    if args.level is not None and not args.level >= 0:
        raise InputError(f"--level must be >= 0; got {args.level:g}")
    numbers = _chain_segments(structure, args.chain)
    rows = []
    for number in numbers:
        segment = structure.segments[number]
        ribbon = segment_ribbon(segment, args.ribbon)
        cr = ribbon.residue_points(args.level)
        dist = np.linalg.norm(cr - segment.ca, axis=1)
        for i in range(len(segment)):
            rows.append((segment.chain, _segment_number(structure, number), int(segment.resseq[i]), segment.icode[i],
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


# ------------------------------------------------------------------------------ edit


def edit_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    parser.add_argument("--chain", required=True, metavar="ID", help="chain to edit")
    parser.add_argument("--segment", type=int, default=0, metavar="S",
                        help="segment of the chain (0-based, chains split at gaps; default 0)")
    parser.add_argument("--level", type=float, required=True, metavar="L", help="Carson level of the edit")
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument("--point", type=int, metavar="K",
                        help="control point to move (0-based, among those of the curve shown at L)")
    target.add_argument("--residue", metavar="RESSEQ[ICODE]", help="move the curve point of this residue instead")
    parser.add_argument("--move", required=True, type=_vector, metavar="DX,DY,DZ", help="displacement in Å")
    _ribbon_argument(parser)
    parser.add_argument("-o", "--output", required=True, type=Path, metavar="OUT",
                        help="output file; PDB or mmCIF by the extension (.pdb, .cif, optionally .gz)")
    parser.add_argument("--overwrite", action="store_true", help="replace OUT if it exists (even the input file)")
    parser.add_argument("--regularize", action="store_true",
                        help="then move the residues again (rigid, turning carbonyls and clashing side chains) "
                             "to ideal peptide junctions without new clashes or Ramachandran outliers")


def run_edit(args: argparse.Namespace) -> int:
    structure = load(args.file)
    number = _chain_segments(structure, args.chain, args.segment)[0]
    model = EditableModel(structure, RibbonKind(args.ribbon))
    ribbon = model.ribbons[number]
    try:
        if args.point is not None:
            edit = model.move_point(number, args.level, args.point, args.move)
        else:
            residue = _residue_index(structure.segments[number], args.residue)
            edit = model.tug(number, args.level, float(ribbon.residue_u[residue]), args.move)
        if args.regularize:
            plain, edit = edit, regularized(model, edit)
        model.apply(edit)
        written = model.save(args.output, overwrite=args.overwrite)
    except FileExistsError as error:
        raise InputError(f"{error} (pass --overwrite to replace it)") from None
    except (ValueError, OSError) as error:
        raise InputError(str(error)) from None
    labels = structure.segments[number].labels
    moved = f"{labels[edit.residues[0]]}-{labels[edit.residues[-1]]}" if len(edit.residues) else "none"
    print(f"moved {len(edit.residues)} residues ({moved}), {len(edit.rows)} atoms; "
          f"wrote {written}")
    if args.regularize:
        region = structure.segments[number].residue_index[edit.residues]
        before = np.array(structure.coords)
        before[plain.rows] = plain.new_coords  # the edit without regularization
        flagged = [validate(structure, coords, residues=region).counts for coords in (before, model.coords)]
        print("regularized: " + ", ".join(
            f"{flagged[0][kind]} -> {flagged[1][kind]} {name}" for kind, name in
            (("peptide_bond", "bad peptide bonds"), ("ca_ca", "bad Cα–Cα"), ("clash", "clashes"),
             ("ramachandran", "Ramachandran outliers"))))
    return 0


# ------------------------------------------------------------------------------ helpers


def _ribbon_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--ribbon", choices=[k.value for k in RibbonKind], default=RibbonKind.PEPTIDE.value,
                        help="peptide-plane ribbon (default) or the curve through the Cα atoms")


def _vector(text: str) -> np.ndarray:
    parts = text.split(",")
    try:
        vector = np.array([float(p) for p in parts])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers DX,DY,DZ; got {text!r}") from None
    if len(vector) != 3 or not np.all(np.isfinite(vector)):
        raise argparse.ArgumentTypeError(f"expected three finite numbers DX,DY,DZ; got {text!r}")
    return vector


def _segment_number(structure: Structure, number: int) -> int:
    """Position of segment ``number`` among the segments of its chain."""
    chain = structure.segments[number].chain
    return sum(1 for s in structure.segments[:number] if s.chain == chain)


def _chain_segments(structure: Structure, chain: str | None, segment: int | None = None) -> list[int]:
    """Indices of the segments of ``chain`` (all if None), or just its ``segment``-th one."""
    numbers = [i for i, s in enumerate(structure.segments) if chain is None or s.chain == chain]
    if not numbers:
        chains = ", ".join(dict.fromkeys(s.chain for s in structure.segments))
        raise InputError(f"{structure.path}: no protein chain {chain!r} (chains: {chains})")
    if segment is None:
        return numbers
    if not 0 <= segment < len(numbers):
        raise InputError(f"{structure.path}: chain {chain} has {len(numbers)} segment(s); --segment {segment} is out of range")
    return [numbers[segment]]


def _residue_index(segment: BackboneSegment, label: str) -> int:
    """Index in ``segment`` of the residue numbered ``label`` (e.g. '52' or '52A')."""
    for i, (number, icode) in enumerate(zip(segment.resseq.tolist(), segment.icode)):
        if f"{number}{icode}" == label.strip():
            return i
    raise InputError(f"no residue {label} in chain {segment.chain} segment {segment.labels[0]}-{segment.labels[-1]}")
