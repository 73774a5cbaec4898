"""The headless ``info`` command, and reading a structure for any command (core only, no Qt).

``info --json`` is a contract for other programs: it keeps its field names.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from app.arguments import bounded, chain_hint, writable_output
from app.errors import InputError
from core.protein.assembly import assemblies
from core.protein.input_files import StructureError
from core.protein.reading import read_structure
from core.protein.structure import SS_COMPUTED, Structure
from core.protein.writing import output_format

MAX_MODEL = 100_000
"""Largest ``--model`` accepted before the file is read (PDB model serials stop at 9999)."""


def load(path: Path, model: int = 1, require_protein: bool = True) -> Structure:
    """Read model ``model`` (from 1) of a structure, turning reader errors (a model the file
    does not have included; no protein chain, unless not ``require_protein``) into
    :class:`InputError`; print its warnings."""
    try:
        structure = read_structure(path, model=model, require_protein=require_protein)
    except StructureError as error:
        raise InputError(str(error) + chain_hint(path)) from None
    for warning in structure.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    return structure


def checked_output(path: Path, overwrite: bool) -> None:
    """Refuse, before any work, a structure file the command could not write at the end
    (:func:`~app.arguments.writable_output`) or of an unknown extension."""
    writable_output(path, overwrite)
    try:
        output_format(path)
    except StructureError as error:
        raise InputError(str(error)) from None


def model_argument(parser: argparse.ArgumentParser) -> None:
    """Declare ``--model N``: the model of a multi-model entry (an NMR ensemble) a command reads."""
    parser.add_argument("--model", type=bounded(int, 1, MAX_MODEL), default=1, metavar="N",
                        help="model of a multi-model entry (e.g. an NMR ensemble), counted from 1 in file order "
                             "(default 1)")


# ------------------------------------------------------------------------------ info


def info_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", type=Path, metavar="FILE", help="structure file (PDB or mmCIF, optionally gzipped)")
    model_argument(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON object instead of text")


def summary(structure: Structure) -> dict:
    """Chains (with their nucleotides), ligands and ions, segments, residues, secondary
    structure and maximum levels of a structure."""
    segments = []
    for number, segment in enumerate(structure.segments):
        segments.append({
            "chain": segment.chain,
            "segment": segment_number(structure, number),
            "first": segment.labels[0],
            "last": segment.labels[-1],
            "residues": len(segment),
            "max_level_peptide": round(float(np.log2(len(segment))), 4),
            "max_level_calpha": round(float(np.log2(len(segment) + 1)), 4),
        })
    ss = Counter(code for s in structure.segments for code in s.ss.tolist())
    return {
        "file": str(structure.path),
        "format": structure.source_format,
        "entry": structure.entry_id,
        "title": structure.title,
        "method": structure.method,
        "resolution": structure.resolution,
        "models": structure.n_models,
        "model": structure.model_number,
        "atoms": structure.n_atoms,
        "hetero_atoms": structure.n_hetero_atoms,
        "water_atoms": structure.n_water_atoms,
        "altloc_atoms": structure.n_altloc_atoms,
        "chains": [
            {"chain": c.name, "residues": c.n_residues, "backbone_residues": c.n_backbone, "segments": c.n_segments,
             "nucleotides": c.n_nucleotides, "nucleic_acid": c.nucleic_acid}
            for c in structure.chains
        ],
        "ligands": [{"name": name, "count": count} for name, count in _ligands(structure).items()],
        "segments": segments,
        "residues": structure.n_residues,
        "secondary_structure": {"H": ss["H"], "E": ss["E"], "C": ss["C"]},
        "secondary_structure_source": structure.ss_source,
        "warnings": list(structure.warnings),
    }


def biological_assemblies(path: Path, model: int) -> list[dict]:
    """Number, name, chains, atoms and description of each biological assembly of the file
    (none where it has no assembly records, or, with a warning, where one cannot be built)."""
    try:
        return [{"number": a.number, "name": a.name, "chains": a.chains, "atoms": a.atoms, "details": a.details}
                for a in assemblies(path, model=model)]
    except StructureError as error:
        print(f"warning: {error}", file=sys.stderr)
        return []


def run_info(args: argparse.Namespace) -> int:
    report = summary(load(args.file, args.model, require_protein=False))
    report["assemblies"] = biological_assemblies(args.file, args.model)
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    ss = report["secondary_structure"]
    print(f"{report['file']}: {report['entry']} ({report['format']}), {report['title'] or 'no title'}")
    if report["method"] or report["resolution"]:
        print("  " + ", ".join(filter(None, [report["method"], report["resolution"] and
                                             f"{report['resolution']:g} Å resolution"])))
    print(f"  {report['atoms']} atoms ({report['hetero_atoms']} hetero, {report['water_atoms']} water, "
          f"{report['altloc_atoms']} with altlocs); "
          + (f"model {report['model']} of {report['models']}" if report["models"] > 1 else "1 model"))
    if report["assemblies"]:
        listed = "; ".join(f"{a['number']}: {a['chains']} chain{'s' if a['chains'] != 1 else ''}, {a['atoms']:,} atoms"
                           + (f" ({a['details'].lower()})" if a["details"] else "") for a in report["assemblies"][:4])
        more = f"; ... ({len(report['assemblies'])} in all)" if len(report["assemblies"]) > 4 else ""
        print(f"  biological assemblies (--assembly N): {listed}{more}")
    if report["ligands"]:
        print("  ligands and ions: " + ", ".join(f"{ligand['name']} ({ligand['count']})"
                                                 for ligand in report["ligands"]))
    nucleic = [c for c in report["chains"] if c["nucleotides"]]
    if nucleic:
        print("  nucleic acids: " + ", ".join(f"chain {c['chain']} {c['nucleotides']} nucleotides"
                                              + (f" ({c['nucleic_acid']})" if c["nucleic_acid"] else "")
                                              for c in nucleic))
    if not report["segments"]:
        print("  no protein chain: no ribbon to decompose (the editor shows the entry)")
        return 0
    source = report["secondary_structure_source"]
    print(f"  {report['residues']} backbone residues: {ss['H']} helix, {ss['E']} sheet, {ss['C']} other "
          f"({'computed by DSSP' if source == SS_COMPUTED else f'from {source}'})")
    print(f"  {'chain':<6}{'seg':>4}  {'residues':>8}  {'from':<14}{'to':<14}{'max level':>10}")
    for s in report["segments"]:
        print(f"  {s['chain']:<6}{s['segment']:>4}  {s['residues']:>8}  {s['first']:<14}{s['last']:<14}"
              f"{s['max_level_peptide']:>10.2f}")
    return 0


# ------------------------------------------------------------------------------ helpers


def _ligands(structure: Structure) -> dict[str, int]:
    """How many groups of each name the ligands and ions are (no waters, no polymer), in file order."""
    atoms = structure.atoms
    ligand = np.flatnonzero(atoms.category == "ligand")
    _, first = np.unique(atoms.residue[ligand], return_index=True)
    return dict(Counter(atoms.resname[ligand[np.sort(first)]].tolist()))


def segment_number(structure: Structure, number: int) -> int:
    """Position of segment ``number`` among the segments of its chain."""
    chain = structure.segments[number].chain
    return sum(1 for s in structure.segments[:number] if s.chain == chain)


def chain_segments(structure: Structure, chain: str | None, segment: int | None = None) -> list[int]:
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
